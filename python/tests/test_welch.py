"""tiltnoise.welch / csd against scipy.signal on random data: the same grid and values."""

import numpy as np
import pytest

import tiltnoise

signal = pytest.importorskip("scipy.signal")

EPS = np.finfo(float).eps


def rounding_tol(n_samples, kw):
    """Relative to the largest value: two FFT implementations (realfft here, pocketfft in
    scipy) each err by about log2(nperseg) eps normwise (Higham, Accuracy and Stability of
    Numerical Algorithms, 24.1), the average over K segments adds rounding errors of random
    sign, about sqrt(K) eps; a factor 2 for the product of two transforms and 2 for the two
    implementations."""
    n = kw["nperseg"]
    step = n - kw.get("noverlap", n // 2)
    k = (n_samples - n) // step + 1
    return 4 * EPS * (np.log2(n) + np.sqrt(k))


def close(a, b, rtol):
    """Equal to `rtol` relative to the largest value (bins near a spectral null are tiny)."""
    np.testing.assert_allclose(a, b, rtol=rtol, atol=rtol * np.abs(b).max())


CASES = [
    dict(nperseg=256),
    dict(nperseg=1000, noverlap=250),
    dict(nperseg=513, noverlap=0),
    dict(nperseg=2048, average="median"),
    dict(nperseg=300, noverlap=299, detrend=False),
]


@pytest.mark.parametrize("kw", CASES)
def test_welch_equals_scipy(kw):
    rng = np.random.default_rng(20240301)
    x = np.cumsum(rng.standard_normal(40_000)) * 1e-9 + 3e-7
    f, p = tiltnoise.welch(x, fs=10.0, **kw)
    fs, ps = signal.welch(x, fs=10.0, window="hann", **kw)
    np.testing.assert_allclose(f, fs, rtol=2 * EPS, atol=0)  # k fs / n vs scipy's k / (n / fs)
    close(p, ps, rounding_tol(len(x), kw))


@pytest.mark.parametrize("kw", CASES)
def test_csd_equals_scipy(kw):
    rng = np.random.default_rng(7)
    x = rng.standard_normal(30_000)
    y = 0.3 * np.roll(x, 5) + rng.standard_normal(30_000)
    f, p = tiltnoise.csd(x, y, fs=2.5, **kw)
    fs, ps = signal.csd(x, y, fs=2.5, window="hann", **kw)
    np.testing.assert_allclose(f, fs, rtol=2 * EPS, atol=0)  # k fs / n vs scipy's k / (n / fs)
    assert p.dtype == np.complex128
    close(p, ps, rounding_tol(len(x), kw))


def test_unsupported_settings_raise_value_error():
    x = np.zeros(1000)
    with pytest.raises(ValueError, match="window"):
        tiltnoise.welch(x, window="hamming")
    with pytest.raises(ValueError, match="shorter than one Welch segment"):
        tiltnoise.welch(x[:100], nperseg=256)
    with pytest.raises(ValueError, match="overlap"):
        tiltnoise.welch(x, nperseg=64, noverlap=64)
    with pytest.raises(ValueError, match="average"):
        tiltnoise.welch(x, average="max")
    with pytest.raises(ValueError, match="1-D"):
        tiltnoise.csd(x, np.zeros((2, 500)))
