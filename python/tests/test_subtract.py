"""subtract(): the command line's `subtract` from Python, with the same report and files; a
measured record made from the tilt through the model gives back unit gains and no delay."""

import json

import numpy as np
import pytest

import tiltnoise
from conftest import LAB_TILT

START = "2024-03-20T00:00:00Z"
# Six hours of the bundled record at 1 Hz: enough Welch segments for the fit, quick to run.
SAMPLES = 6 * 3600


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """The first hours of the lab tilt (HDF5) and X of the pendulum driven by it through the
    model (circularly, in the frequency domain) plus white readout noise (CSV), both stating
    the same start time."""
    h5py = pytest.importorskip("h5py")
    with h5py.File(LAB_TILT, "r") as f:
        theta, eta = f["theta_t"][:SAMPLES], f["eta_t"][:SAMPLES]
        fs = float(f.attrs["sample_rate_hz"])
    d = tmp_path_factory.mktemp("subtract")
    tilt = d / "tilt.h5"
    with h5py.File(tilt, "w") as f:
        f["theta_t"], f["eta_t"] = theta, eta
        f.attrs.update(sample_rate_hz=fs, schema="tiltnoise.tilt_series", schema_version=1,
                       start_time=START)
    n = len(eta)
    freqs = np.fft.rfftfreq(n, 1 / fs)
    h = tiltnoise.Model().transfer(freqs[1:], inputs=["theta_t", "eta_t"], outputs="X")
    spectrum = np.zeros(len(freqs), complex)
    spectrum[1:] = h[:, 0, 0] * np.fft.rfft(theta)[1:] + h[:, 0, 1] * np.fft.rfft(eta)[1:]
    x = np.fft.irfft(spectrum, n) + np.random.default_rng(11).normal(0, 1e-9, n)
    measured = d / "pendulum.csv"
    t = np.arange(n) / fs
    measured.write_text(f"# start_time: {START}\ntime_s,X\n"
                        + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), x.tolist())))
    return tilt, measured


@pytest.fixture(scope="module")
def result(records):
    tilt, measured = records
    return tiltnoise.subtract(tilt, measured, readout={"X": 1e-9})


def test_report_and_files_equal_the_command_lines(result, records, cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    tilt, measured = records
    report, h5 = tmp_path / "cli.json", tmp_path / "cli.h5"
    printed = cli("subtract", "--tilt", tilt, "--measured", measured, "--readout", "X=1e-9",
                  "--format", "json", "--save", report, "--save", h5)
    assert result.report == json.loads(printed)
    mine = tmp_path / "mine.json"
    result.save(mine)
    assert mine.read_bytes() == report.read_bytes()
    mine = tmp_path / "mine.h5"
    result.save(mine)
    with h5py.File(h5, "r") as a, h5py.File(mine, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert "X" in names or any(n.endswith("X") for n in names), names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        for key in ("schema", "start_time", "measured_path", "input_path"):
            if key in a.attrs:
                assert a.attrs[key] == b.attrs[key], key


def test_a_record_made_through_the_model_gives_unit_gains_and_no_delay(result):
    estimates = {e["name"]: e for e in result.estimates}
    assert set(estimates) >= {"gain.theta_t", "gain.eta_t", "delay_s"}, estimates
    # X follows eta_t: its gain and the delay are constrained; theta_t's may not be.
    assert estimates["gain.eta_t"]["status"] == "fitted", estimates
    assert estimates["delay_s"]["status"] == "fitted", estimates
    truth = {"gain.theta_t": 1.0, "gain.eta_t": 1.0, "delay_s": 0.0}
    for name, e in estimates.items():
        assert e["status"] in ("fitted", "at_bound", "not_constrained"), e
        if e["status"] == "fitted":
            assert e["sigma"] > 0, e
            # The truth within 5 sigma: a test that cannot flake.
            assert abs(e["value"] - truth[name]) < 5 * e["sigma"], e
    assert [r["observable"] for r in result.report["residuals"]] == ["X"]


def test_errors_say_what_the_command_line_says(records, cli_error, tmp_path):
    tilt, measured = records
    spectra = tmp_path / "asd.csv"
    spectra.write_text("freq_hz,X\n0.01,1e-9\n0.02,1e-9\n")
    with pytest.raises(ValueError) as e:
        tiltnoise.subtract(tilt, spectra)
    assert str(e.value) == cli_error("subtract", "--tilt", tilt, "--measured",
                                     spectra).replace("--measured", "measured")
    with pytest.raises(ValueError) as e:
        tiltnoise.subtract(tilt, measured, observables="phi")
    assert str(e.value) == cli_error(
        "subtract", "--tilt", tilt, "--measured", measured, "--observables", "phi"
    ).replace("--observables", "observables").replace("--measured", "measured")
    three = [tilt, tilt, tilt]
    with pytest.raises(ValueError) as e:
        tiltnoise.subtract(tilt, measured, colocated=three)
    args = [a for p in three for a in ("--colocated", p)]
    assert str(e.value) == cli_error(
        "subtract", "--tilt", tilt, "--measured", measured, *args
    ).replace("--colocated", "colocated")


def test_save_never_replaces_an_input(result, records):
    tilt, _ = records
    before = tilt.read_bytes()
    with pytest.raises(OSError):
        result.save(tilt)
    assert tilt.read_bytes() == before
    with pytest.raises(ValueError, match="allowed are .h5, .hdf5, .json"):
        result.save(tilt.with_suffix(".txt"))
