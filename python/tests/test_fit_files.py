"""Fit.to_json and Fit.save: the command line's `fit --format json` and `fit --save` files."""

import json

import numpy as np
import pytest

import tiltnoise

FREE = "mass.m_b_kg,length.d_m"


@pytest.fixture(scope="module")
def fit():
    return tiltnoise.Model().fit(free=FREE.split(","), prior=True)


def test_the_report_and_files_are_the_command_lines(fit, cli, tmp_path):
    theirs_json, theirs_h5 = tmp_path / "cli.json", tmp_path / "cli.h5"
    printed = cli("fit", "--free", FREE, "--prior", "--format", "json",
                  "--save", theirs_json, "--save", theirs_h5)
    assert fit.to_json() + "\n" == printed
    mine_json, mine_h5 = tmp_path / "mine.json", tmp_path / "mine.h5"
    fit.save(mine_json)
    fit.save(mine_h5)
    assert mine_json.read_text() == theirs_json.read_text()
    report = json.loads(mine_json.read_text())
    assert report["chi2"] == fit.chi2 and report["measured_origin"] == fit.measured_origin
    h5py = pytest.importorskip("h5py")
    with h5py.File(theirs_h5, "r") as a, h5py.File(mine_h5, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)


def test_save_refuses_another_extension_and_the_files_read(fit, tmp_path):
    with pytest.raises(ValueError, match=r"\.json"):
        fit.save(tmp_path / "fit.csv")
    measured = tmp_path / "modes.json"
    measured.write_text("mode,frequency_hz\n1,1.31e-3\n")
    with pytest.raises(OSError):
        tiltnoise.Model().fit(measured=measured, free=["length.d_m"]).save(measured)
