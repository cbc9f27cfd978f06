"""subtract(): the command line's `subtract` from Python, with the same report, files and
figure; the result carries names and units, and its cleaned record is the measured one minus
the prediction; a measured record made from the tilt through the model gives back unit gains
and no delay."""

import json
import sys

import numpy as np
import pytest

import tiltnoise
from conftest import write_subtract_records

# Six hours of the bundled record at 1 Hz: enough Welch segments for the fit, quick to run.
SAMPLES = 6 * 3600


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    return write_subtract_records(tmp_path_factory.mktemp("subtract"), SAMPLES)


@pytest.fixture(scope="module")
def result(records):
    tilt, measured = records
    return tiltnoise.subtract(tilt, measured, readout={"X": 1e-9})


def test_report_files_and_figures_equal_the_command_lines(result, records, cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    tilt, measured = records
    cli_files = {ext: tmp_path / f"cli.{ext}" for ext in ("json", "h5", "png", "svg")}
    saves = [a for p in cli_files.values() for a in ("--save", p)]
    printed = cli("subtract", "--tilt", tilt, "--measured", measured, "--readout", "X=1e-9",
                  "--format", "json", *saves)
    assert result.report == json.loads(printed)
    for ext in ("json", "png", "svg"):
        mine = tmp_path / f"mine.{ext}"
        result.save(mine)
        assert mine.read_bytes() == cli_files[ext].read_bytes(), ext
    mine = tmp_path / "mine.h5"
    result.save(mine)
    with h5py.File(cli_files["h5"], "r") as a, h5py.File(mine, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert any(n.split("/")[-1] == "X" for n in names), names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        for key in ("schema", "start_time", "measured_path", "input_path"):
            if key in a.attrs:
                assert a.attrs[key] == b.attrs[key], key


def test_names_units_and_the_cleaned_record_against_the_raw_one(result, records):
    _, measured = records
    assert result.observables == ["X"]
    assert result.units == {"X": "m"}
    assert result.sample_rate_hz == 1.0
    assert result.start_time is not None and result.start_time.startswith("2024-03-20T00:00:00")
    raw = np.loadtxt(measured, delimiter=",", skiprows=2)[:, 1]
    alignment = result.report["alignment"]
    first, n = alignment["measured_first_sample"], alignment["samples"]
    cleaned, predicted = result.cleaned["X"], result.predicted["X"]
    assert len(cleaned) == len(predicted) == n
    # cleaned = measured - predicted, sample by sample: the sum gives back the raw record to
    # the rounding of one subtraction and one addition.
    scale = np.max(np.abs(raw))
    np.testing.assert_allclose(cleaned + predicted, raw[first:first + n], rtol=0,
                               atol=4 * np.finfo(float).eps * scale)
    f = result.frequency_hz
    assert f[0] == 0 and np.all(np.diff(f) > 0)
    curves = result.asd["X"]
    assert set(curves) == {"measured", "predicted", "cleaned", "wiener", "coherence_limit",
                           "witness_limited"}
    for name, asd in curves.items():
        assert asd.shape == f.shape and np.all(np.isfinite(asd)) and np.all(asd >= 0), name
    # The report's band means are the means of these PSDs over the report band.
    lo, hi = result.report_band_hz
    band = (f >= lo) & (f <= hi)
    row = result.report["residuals"][0]
    for curve, key in (("measured", "measured_asd"), ("cleaned", "cleaned_asd")):
        np.testing.assert_allclose(np.sqrt(np.mean(curves[curve][band] ** 2)), row[key],
                                   rtol=1e-12, err_msg=curve)
    # Removing the tilt part leaves less in the report band.
    assert row["cleaned_asd"] < row["measured_asd"], row
    assert result.fitted_params.get("length.h_m") == tiltnoise.Params().get("length.h_m")


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
    with pytest.raises(ValueError) as e:
        tiltnoise.subtract(tilt, measured, colocated_ratio={"eta_t": 2.0})
    assert str(e.value) == cli_error(
        "subtract", "--tilt", tilt, "--measured", measured, "--colocated-ratio", "eta_t=2"
    ).replace("--colocated-ratio", "colocated_ratio").replace("--colocated", "colocated")


def test_messages_use_keyword_spellings(records, cli_error):
    tilt, measured = records
    cases = [
        (dict(band=(3e-2, 3e-3)), ["--band", "3e-2:3e-3"], "band (0.03, 0.003): "),
        (dict(report_band=(0.0, 3e-2)), ["--report-band", "0:3e-2"], "report_band (0, 0.03): "),
        (dict(colocated=[tilt], colocated_ratio={"F_b.x": 2.0}),
         ["--colocated", tilt, "--colocated-ratio", "F_b.x=2"], "colocated_ratio F_b.x=2: "),
        (dict(colocated=[tilt], colocated_ratio={"eta_t": -1.0}),
         ["--colocated", tilt, "--colocated-ratio", "eta_t=-1"], "colocated_ratio eta_t=-1: "),
        (dict(fit=["length.h_m", "length.h_m"]), ["--fit", "length.h_m,length.h_m"],
         "fit: length.h_m is given twice"),
    ]
    for kwargs, flags, start in cases:
        with pytest.raises(ValueError) as e:
            tiltnoise.subtract(tilt, measured, **kwargs)
        message = str(e.value)
        assert message.startswith(start), (kwargs, message)
        assert "--" not in message, message
        flag_message = cli_error("subtract", "--tilt", tilt, "--measured", measured, *flags)
        assert flag_message.startswith(str(flags[-2])), flag_message
        # The same words after the option and its value.
        assert flag_message.split(": ", 1)[1] == message.split(": ", 1)[1], (flag_message,
                                                                             message)


def test_save_never_replaces_an_input(result, records):
    tilt, _ = records
    before = tilt.read_bytes()
    with pytest.raises(OSError):
        result.save(tilt)
    assert tilt.read_bytes() == before
    with pytest.raises(ValueError, match="allowed are .h5, .hdf5, .json, .png, .svg"):
        result.save(tilt.with_suffix(".txt"))


def test_plot_draws_a_panel_per_observable(result):
    pytest.importorskip("matplotlib")
    import matplotlib
    matplotlib.use("Agg")
    fig = result.plot()
    (ax,) = fig.axes
    labels = [line.get_label() for line in ax.get_lines()]
    assert {"measured", "cleaned", "predicted tilt part", "readout"} <= set(labels), labels
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    assert "m/sqrt(Hz)" in ax.get_ylabel()


def test_to_gwpy_and_pandas_hold_the_series_and_spectra_with_names_and_units(result):
    gwpy = pytest.importorskip("gwpy")
    pd = pytest.importorskip("pandas")
    from gwpy.time import to_gps

    g = result.to_gwpy()
    assert set(g) == {"cleaned", "predicted", "asd"}
    for kind, series in (("cleaned", result.cleaned), ("predicted", result.predicted)):
        d = g[kind]
        assert isinstance(d, gwpy.timeseries.TimeSeriesDict) and list(d) == result.observables
        x = d["X"]
        assert x.value.tobytes() == series["X"].tobytes()
        assert x.name == f"X.{kind}" and str(x.unit) == "m"
        assert x.dt.value == 1.0 / result.sample_rate_hz
        assert x.t0.value == float(to_gps(result.start_time))
    a = g["asd"]["X"]["cleaned"]
    assert a.value.tobytes() == result.asd["X"]["cleaned"].tobytes()
    assert a.name == "X.cleaned" and a.unit.to_string() == "m / Hz(1/2)"
    np.testing.assert_allclose(a.frequencies.value, result.frequency_hz, rtol=1e-12, atol=0)
    frames = result.to_pandas()
    cleaned = frames["cleaned"]
    assert isinstance(cleaned, pd.DataFrame) and cleaned.index.name == "time_s"
    assert cleaned["X"].to_numpy().tobytes() == result.cleaned["X"].tobytes()
    assert cleaned.index[1] - cleaned.index[0] == 1.0 / result.sample_rate_hz
    assert frames["predicted"]["X"].to_numpy().tobytes() == result.predicted["X"].tobytes()
    asd = frames["asd"]
    assert asd.index.name == "frequency_hz"
    assert asd["X.wiener"].to_numpy().tobytes() == result.asd["X"]["wiener"].tobytes()
    assert asd.attrs["units"]["X.measured"] == "m/sqrt(Hz)"
    assert cleaned.attrs["units"] == {"X": "m", "time_s": "s"}


@pytest.mark.parametrize("method, package", [("to_pandas", "pandas"), ("to_gwpy", "gwpy")])
def test_conversions_without_their_package_say_how_to_get_it(result, monkeypatch, method,
                                                             package):
    for m in (package, f"{package}.frequencyseries", f"{package}.timeseries"):
        monkeypatch.setitem(sys.modules, m, None)
    with pytest.raises(ImportError, match=f"pip install {package}"):
        getattr(result, method)()
