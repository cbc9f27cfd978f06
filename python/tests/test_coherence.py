"""coherence(): the command line's `coherence` from Python, with the same numbers and files;
a measured record made from the tilt through the model gives back the model."""

import sys

import numpy as np
import pytest

import tiltnoise
from conftest import LAB_TILT, without_command_line


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    """X of the pendulum driven by the lab tilt through the model (circularly, in the
    frequency domain), plus white readout noise: a record whose transfer function from the
    tilt is the model's."""
    h5py = pytest.importorskip("h5py")
    with h5py.File(LAB_TILT, "r") as f:
        theta, eta = f["theta_t"][()], f["eta_t"][()]
        fs = float(f.attrs["sample_rate_hz"])
    n = len(eta)
    freqs = np.fft.rfftfreq(n, 1 / fs)
    h = tiltnoise.Model().transfer(freqs[1:], inputs=["theta_t", "eta_t"], outputs="X")
    spectrum = np.zeros(len(freqs), complex)
    spectrum[1:] = h[:, 0, 0] * np.fft.rfft(theta)[1:] + h[:, 0, 1] * np.fft.rfft(eta)[1:]
    x = np.fft.irfft(spectrum, n) + np.random.default_rng(7).normal(0, 1e-9, n)
    path = tmp_path_factory.mktemp("coherence") / "pendulum.csv"
    t = np.arange(n) / fs
    path.write_text("time_s,X\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), x.tolist())))
    return path


@pytest.fixture(scope="module")
def result(measured):
    return tiltnoise.coherence(LAB_TILT, measured, nperseg=4096, fit_band=(1e-3, 0.1))


def test_files_equal_the_command_lines(result, measured, cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    csv, h5 = tmp_path / "cli.csv", tmp_path / "cli.h5"
    cli("coherence", "--tilt", LAB_TILT, "--measured", measured, "--nperseg", 4096,
        "--fit-band", "1e-3:0.1", "--save", csv, "--save", h5)
    assert without_command_line(result.to_csv()) == without_command_line(csv.read_text())
    mine = tmp_path / "mine.h5"
    result.save(mine)
    with h5py.File(h5, "r") as a, h5py.File(mine, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        for key in ("schema", "input_path", "measured_path"):
            if key in a.attrs:
                assert a.attrs[key] == b.attrs[key], key


@pytest.mark.parametrize("ext", ["png", "svg"])
def test_the_figure_is_the_command_lines(result, measured, cli, tmp_path, ext):
    theirs, mine = tmp_path / f"cli.{ext}", tmp_path / f"mine.{ext}"
    cli("coherence", "--tilt", LAB_TILT, "--measured", measured, "--nperseg", 4096,
        "--fit-band", "1e-3:0.1", "--save", theirs)
    result.save(mine)
    assert mine.read_bytes() == theirs.read_bytes()


def test_plot_draws_every_observable(result):
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    fig = result.plot()
    assert len(fig.axes) == 2 * len(result.observables)
    labels = {line.get_label() for ax in fig.axes for line in ax.get_lines()}
    assert {"multiple", "eta_t measured", "eta_t model"} <= labels


def test_a_record_made_through_the_model_gives_the_model_back(result):
    assert result.observables == ["X"] and result.axes == ["theta_t", "eta_t"]
    assert result.units == {"X": "m/rad"}
    g = result.agreement["X"]["eta_t"]
    # Measured over model: 1 within its statistical error (5 sigma: a test that cannot flake).
    assert abs(g["gain"] - 1) < 5 * g["gain_sigma"], g
    assert abs(g["phase_deg"]) < 5 * g["phase_sigma_deg"], g
    f = result.frequency_hz
    band = (f > 1e-3) & (f < 0.1)
    # X is the tilt through the model plus white noise: its multiple coherence with both axes
    # is above what noise alone reaches (at the confidence level) nearly everywhere in the band.
    significant = result.multiple_coherence["X"][band] > result.multiple_coherence_threshold
    assert significant.mean() > 0.95, significant.mean()


def test_errors_say_what_the_command_line_says(measured, cli_error, tmp_path):
    spectra = tmp_path / "asd.csv"
    spectra.write_text("freq_hz,X\n0.01,1e-9\n0.02,1e-9\n")
    with pytest.raises(ValueError) as e:
        tiltnoise.coherence(LAB_TILT, spectra)
    assert str(e.value) == cli_error("coherence", "--tilt", LAB_TILT, "--measured",
                                     spectra).replace("--measured", "measured")
    with pytest.raises(ValueError) as e:
        tiltnoise.coherence(LAB_TILT, measured, observables="phi")
    assert str(e.value) == cli_error("coherence", "--tilt", LAB_TILT, "--measured", measured,
                                     "--observables", "phi").replace("--observables",
                                                                     "observables")
    with pytest.raises(ValueError) as e:
        tiltnoise.coherence(LAB_TILT, measured, fit_band=(0.1, 0.01))
    assert str(e.value) == cli_error("coherence", "--tilt", LAB_TILT, "--measured", measured,
                                     "--fit-band", "0.1:0.01").replace("--fit-band", "fit_band")
    with pytest.raises(OSError):
        tiltnoise.coherence(LAB_TILT, measured).save(measured.with_suffix(".csv"))


def test_to_gwpy_and_pandas_hold_the_values_with_names_and_units(result):
    pytest.importorskip("gwpy")
    pd = pytest.importorskip("pandas")
    g = result.to_gwpy()
    c = g["coherence"]["X"]["eta_t"]
    assert c.value.tobytes() == result.coherence["X"]["eta_t"].tobytes()
    assert c.name == "X.eta_t.coherence" and c.unit.to_string() == ""
    np.testing.assert_allclose(c.frequencies.value, result.frequency_hz, rtol=1e-12, atol=0)
    t = g["transfer"]["X"]["theta_t"]
    assert t.value.tobytes() == result.transfer["X"]["theta_t"].tobytes()
    assert t.unit.to_string() == "m / rad"
    assert g["psd"]["X"].unit.to_string() == "m2 / Hz"
    assert g["multiple_coherence"]["X"].value.tobytes() == result.multiple_coherence["X"].tobytes()
    df = result.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.index.name == "frequency_hz"
    assert df["X.eta_t.model"].to_numpy().tobytes() == result.model["X"]["eta_t"].tobytes()
    assert df["X.psd"].to_numpy().tobytes() == result.psd["X"].tobytes()
    assert df.attrs["units"]["X.theta_t.transfer"] == "m/rad"
    assert df.attrs["units"]["X.psd"] == "m^2/Hz"
    assert df.attrs["units"]["frequency_hz"] == "Hz"


@pytest.mark.parametrize("method, package", [("to_pandas", "pandas"), ("to_gwpy", "gwpy")])
def test_conversions_without_their_package_say_how_to_get_it(result, monkeypatch, method,
                                                             package):
    for m in (package, f"{package}.frequencyseries", f"{package}.timeseries"):
        monkeypatch.setitem(sys.modules, m, None)
    with pytest.raises(ImportError, match=f"pip install {package}"):
        getattr(result, method)()
