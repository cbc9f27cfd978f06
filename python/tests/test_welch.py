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
    assert_same_bits(f, fs)
    close(p, ps, rounding_tol(len(x), kw))


def assert_same_bits(f, f_scipy):
    """The frequencies are scipy's, bit for bit (not within an ulp)."""
    assert f.dtype == f_scipy.dtype == np.float64 and f.shape == f_scipy.shape
    differ = np.flatnonzero(f.view(np.int64) != f_scipy.view(np.int64))
    assert differ.size == 0, (
        f"{differ.size} of {f.size} bins differ, first at {differ[0]}: "
        f"{f[differ[0]]!r} vs scipy's {f_scipy[differ[0]]!r}")


# Segments and rates whose k fs / n rounds differently from scipy's k * (1 / (n * (1 / fs))) in
# many bins (1000 at 1 Hz: 62 of 501), and rates that are not binary fractions.
@pytest.mark.parametrize("nperseg", [1000, 256, 513, 4096, 3])
@pytest.mark.parametrize("fs", [1.0, 10.0, 2.5, 1 / 3, 200.0, 0.1, 16384.0, 1e-3, 7.3])
def test_frequencies_are_scipys_bit_for_bit(nperseg, fs):
    x = np.random.default_rng(nperseg).standard_normal(2 * nperseg)
    f, _ = tiltnoise.welch(x, fs=fs, nperseg=nperseg)
    assert_same_bits(f, signal.welch(x, fs=fs, nperseg=nperseg)[0])
    f, _ = tiltnoise.csd(x, x[::-1], fs=fs, nperseg=nperseg)
    assert_same_bits(f, signal.csd(x, x[::-1], fs=fs, nperseg=nperseg)[0])


@pytest.mark.parametrize("kw", CASES)
def test_csd_equals_scipy(kw):
    rng = np.random.default_rng(7)
    x = rng.standard_normal(30_000)
    y = 0.3 * np.roll(x, 5) + rng.standard_normal(30_000)
    f, p = tiltnoise.csd(x, y, fs=2.5, **kw)
    fs, ps = signal.csd(x, y, fs=2.5, window="hann", **kw)
    assert_same_bits(f, fs)
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
