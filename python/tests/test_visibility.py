"""visibility(): the command line's `visibility` from Python, with the same numbers and file;
the visibilities of a simulated record are what Model.fit reads back."""

import pytest

import tiltnoise


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    """A free motion of the Table I model (every mode excited, readout on X), as an HDF5
    record."""
    path = tmp_path_factory.mktemp("visibility") / "free.h5"
    tiltnoise.Model().simulate(4000.0, 0.5, seed=2).save(path)
    return path


@pytest.fixture(scope="module")
def result(record):
    return tiltnoise.visibility(record)


def test_the_file_and_the_table_equal_the_command_lines(result, record, cli, tmp_path):
    theirs, mine = tmp_path / "cli.csv", tmp_path / "mine.csv"
    printed = cli("visibility", "--measured", record, "--format", "csv", "--save", theirs)
    result.save(mine)
    assert mine.read_text() == theirs.read_text() == result.to_csv()
    assert printed == result.to_csv()
    table = cli("visibility", "--measured", record).splitlines()
    # The table prints 7 significant digits of each peak, 6 of each ratio (Rust's exponent
    # spelling, so compared as numbers).
    peaks = {r[0]: r[1:3] for r in (l.split() for l in table) if len(r) >= 3 and "/" not in r[1]}
    for p in result.peaks:
        row = [float(x) for x in peaks[f"nu_{p['mode']}"]]
        assert row == [float(f"{p['expected_hz']:.6e}"), float(f"{p['frequency_hz']:.6e}")]
    ratios = {tuple(r[:2]): r[2:4] for r in (l.split() for l in table) if len(r) == 4}
    for v in result.items:
        row = [float(x) for x in ratios[(f"nu_{v['mode']}", f"{v['observable']}/{v['reference']}")]]
        assert row == [float(f"{v['ratio']:.5e}"), float(f"{v['sigma']:.2e}")]


def test_names_and_values_are_the_csvs(result, record):
    assert result.origin == str(record)
    assert result.channels == ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"]
    assert result.items, "the free motion shows its modes"
    rows = [l.split(",") for l in result.to_csv().splitlines() if not l.startswith("#")]
    assert rows[0] == ["mode", "observable", "reference", "ratio", "sigma"]
    for v, row in zip(result.items, rows[1:], strict=True):
        assert (str(v["mode"]), v["observable"], v["reference"]) == tuple(row[:3])
        assert (float(row[3]), float(row[4])) == (v["ratio"], v["sigma"])
        assert v["sigma"] > 0
    for p in result.peaks:
        assert set(p["snr"]) == set(result.channels)
        assert abs(p["frequency_hz"] - p["expected_hz"]) < 0.01 * p["expected_hz"]


def test_the_fit_reads_them_back(result, tmp_path):
    path = tmp_path / "vis.csv"
    result.save(path)
    fit = tiltnoise.Model().fit(visibility=path, free=["length.d_m"])
    assert fit.measured_origin == "no frequency file"
    assert [(v["mode"], v["observable"], v["reference"]) for v in fit.visibilities] == [
        (v["mode"], v["observable"], v["reference"]) for v in result.items]
    assert [v["measured"] for v in fit.visibilities] == [v["ratio"] for v in result.items]


def test_errors_say_what_the_command_line_says(record, cli_error, tmp_path):
    spectra = tmp_path / "asd.csv"
    spectra.write_text("frequency_hz,X\n0.01,1e-9\n0.02,1e-9\n")
    with pytest.raises(ValueError) as e:
        tiltnoise.visibility(spectra)
    assert str(e.value) == cli_error("visibility", "--measured", spectra).replace(
        "--measured", "measured")
    with pytest.raises(FileNotFoundError):
        tiltnoise.visibility(tmp_path / "missing.h5")
    with pytest.raises(ValueError, match=r"\.csv"):
        tiltnoise.visibility(record).save(tmp_path / "v.json")
    with pytest.raises(OSError):
        tiltnoise.visibility(record).save(tmp_path / "missing" / "v.csv")


def test_arrays_and_json_are_the_items(result, record, cli, tmp_path):
    import json

    import numpy as np

    items = result.items
    assert result.mode.tolist() == [v["mode"] for v in items]
    assert result.ratio.tolist() == [v["ratio"] for v in items]
    assert result.sigma.tolist() == [v["sigma"] for v in items]
    assert not result.ratio.flags.writeable
    doc = json.loads(result.to_json())
    assert doc["origin"] == str(record) and doc["channels"] == result.channels
    assert [(v["mode"], v["observable"], v["reference"], v["ratio"], v["sigma"])
            for v in doc["visibilities"]] == [
        (v["mode"], v["observable"], v["reference"], v["ratio"], v["sigma"]) for v in items]
    assert doc["peaks"] == result.peaks
    assert [[s["mode"], s["reason"]] for s in doc["skipped"]] == [list(s) for s in result.skipped]
    # The CSV the command line writes for the same record holds the same ratios.
    theirs = tmp_path / "cli.csv"
    cli("visibility", "--measured", record, "--save", theirs)
    rows = [l.split(",") for l in theirs.read_text().splitlines() if not l.startswith("#")][1:]
    np.testing.assert_array_equal(np.array([float(r[3]) for r in rows]), result.ratio)
    np.testing.assert_array_equal(np.array([float(r[4]) for r in rows]), result.sigma)
    # The command line's `--format json` is the same document.
    assert json.loads(cli("visibility", "--measured", record, "--format", "json")) == doc
