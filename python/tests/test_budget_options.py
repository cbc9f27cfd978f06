"""The budget's options that the command line has, from Python: any observables, white and
coloured readout, user-named terms, the budget read at chosen frequencies. Each gives the
command line's numbers and files for the same inputs."""

import json

import numpy as np
import pytest

import tiltnoise
from conftest import LAB_TILT, REPO, without_command_line


def write_asd_csv(path, column, a, p):
    """A power law a (f / 1 mHz)^p on 40 log-spaced points from 1e-5 to 1 Hz."""
    f = 1e-5 * 1e5 ** (np.arange(40) / 39)
    rows = "".join(f"{float(x)!r},{float(a * (x / 1e-3) ** p)!r}\n" for x in f)
    path.write_text(f"# a test spectrum\nfreq_hz,{column}\n{rows}")
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("asd")
    return {
        "readout": write_asd_csv(d / "phi_readout.csv", "phi", 3e-10, -0.5),
        "magnetic": write_asd_csv(d / "phi_mag.csv", "phi", 1e-10, -1.0),
        "force": write_asd_csv(d / "force.csv", "F_b.x", 1e-13, 0.0),
    }


def cli_args(files):
    return ["budget", "--tilt", LAB_TILT, "--nperseg", 4096,
            "--observables", "X,Y,phi,phi_a",
            "--readout", f"phi={files['readout']}", "--readout", "Y=2e-9",
            "--term", f"magnetic=phi:{files['magnetic']}",
            "--term", f"actuation=F_b.x:{files['force']}",
            "--at", "2e-3,5e-3", "--at-band", "0.2"]


@pytest.fixture(scope="module")
def budget(files):
    return tiltnoise.budget_from_file(
        LAB_TILT, nperseg=4096, observables=["X", "Y", "phi", "phi_a"],
        readout={"phi": files["readout"], "Y": 2e-9},
        term={"magnetic": ("phi", files["magnetic"]),
               "actuation": ("F_b.x", str(files["force"]))},
        at=[2e-3, 5e-3], at_band=0.2)


def test_files_equal_the_command_lines(budget, files, cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    csv, h5 = tmp_path / "cli.csv", tmp_path / "cli.h5"
    cli(*cli_args(files), "--save", csv, "--save", h5)
    assert without_command_line(budget.to_csv()) == without_command_line(csv.read_text())
    mine = tmp_path / "mine.h5"
    budget.save(mine)
    with h5py.File(h5, "r") as a, h5py.File(mine, "r") as b:
        for group in ("X", "Y", "phi", "phi_a"):
            assert dict(a[group].attrs) .keys() == dict(b[group].attrs).keys(), group
            for key, value in a[group].attrs.items():
                np.testing.assert_array_equal(value, b[group].attrs[key], err_msg=key)
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert "phi/user.magnetic/psd" in names and "Y/user.actuation/psd" in names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)


def test_summary_equals_the_command_lines_json(budget, files, cli):
    theirs = json.loads(cli(*cli_args(files), "--format", "json"))
    assert budget.summary == theirs
    assert [s["frequency_hz"] for s in budget.summary["summary"]] == [2e-3, 5e-3]
    phi = budget.summary["summary"][0]["observables"][2]
    assert phi["observable"] == "phi"
    assert "user.magnetic" in [t["term"] for t in phi["terms"]]


def test_the_terms_are_the_given_spectra(budget):
    f = budget.frequency_hz
    # A power law is reproduced to rounding by log-log interpolation between its points.
    np.testing.assert_allclose(budget.asd("phi", "readout"), 3e-10 * (f / 1e-3) ** -0.5,
                               rtol=1e-12)
    np.testing.assert_allclose(budget.asd("phi", "user.magnetic"), 1e-10 * (f / 1e-3) ** -1,
                               rtol=1e-12)
    assert np.all(budget.asd("Y", "readout") == 2e-9)
    # F_b.x drives the x-phi block only: exactly 0 on Y.
    assert np.all(budget.asd("Y", "user.actuation") == 0.0)
    assert budget.observables == ["X", "Y", "phi", "phi_a"]


def test_arrays_take_the_same_options(budget, files):
    h5py = pytest.importorskip("h5py")
    with h5py.File(LAB_TILT, "r") as f:
        tilt = {k: f[k][()] for k in ("theta_t", "eta_t")}
        fs = float(f.attrs["sample_rate_hz"])
    b = tiltnoise.budget(
        tilt, fs, nperseg=4096, observables="X,Y,phi,phi_a",
        readout={"phi": files["readout"], "Y": 2e-9},
        term={"magnetic": ("phi", files["magnetic"]), "actuation": ("F_b.x", files["force"])},
        at=[2e-3, 5e-3], at_band=0.2)
    for o in budget.observables:
        for term, asd in budget.terms[o].items():
            np.testing.assert_array_equal(b.terms[o][term], asd, err_msg=f"{o} {term}")
    assert b.summary["summary"] == budget.summary["summary"]


@pytest.mark.parametrize(
    "cli_extra, kwargs, pairs",
    [
        (["--term", "9x=phi:{magnetic}"], dict(term={"9x": ("phi", "{magnetic}")}),
         [("--term", "term")]),
        (["--term", "m=Y:{magnetic}"], dict(term={"m": ("Y", "{magnetic}")}),
         [("--term", "term"), ("--observables", "observables")]),
        (["--at", "1e-3,1e-3"], dict(at=[1e-3, 1e-3]), [("--at", "at")]),
        (["--at", "50"], dict(at=[50.0]), [("--at", "at")]),
    ],
)
def test_option_errors_say_what_the_command_line_says(files, cli_error, cli_extra, kwargs,
                                                      pairs):
    fill = lambda v: v.format(**files) if isinstance(v, str) else v
    cli_extra = [fill(a) for a in cli_extra]
    kwargs = {k: ({n: tuple(fill(x) for x in t) for n, t in v.items()}
                  if isinstance(v, dict) else v) for k, v in kwargs.items()}
    with pytest.raises(ValueError) as e:
        tiltnoise.budget_from_file(LAB_TILT, nperseg=4096, **kwargs)
    expected = cli_error("budget", "--tilt", LAB_TILT, "--nperseg", 4096, *cli_extra)
    for flag, keyword in pairs:
        expected = expected.replace(flag, keyword)
    assert str(e.value) == expected


def test_a_missing_readout_file_is_a_file_not_found_error(tmp_path):
    with pytest.raises(FileNotFoundError) as e:
        tiltnoise.budget_from_file(LAB_TILT, readout={"phi": tmp_path / "none.csv"})
    assert str(e.value).startswith(f"readout phi={tmp_path / 'none.csv'}: ")


def test_witness_noise_equals_the_command_lines(files, cli, tmp_path, tmp_path_factory):
    noise = write_asd_csv(tmp_path_factory.mktemp("witness") / "eta.csv", "eta_t", 6e-8, -0.5)
    csv = tmp_path / "cli.csv"
    cli("budget", "--tilt", LAB_TILT, "--nperseg", 4096, "--witness-noise", f"eta_t={noise}:0.1",
        "--witness-noise", "theta_t=6e-8", "--save", csv)
    b = tiltnoise.budget_from_file(LAB_TILT, nperseg=4096,
                                   witness_noise={"eta_t": (noise, 0.1), "theta_t": 6e-8})
    assert without_command_line(b.to_csv()) == without_command_line(csv.read_text())
    assert "witness_noise" in b.terms["X"]
    with pytest.raises(ValueError) as e:
        tiltnoise.budget_from_file(LAB_TILT, witness_noise={"eta_t": 1e300})
    assert str(e.value).startswith("witness_noise eta_t: the ASD 1e300")
