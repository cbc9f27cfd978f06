"""The finiteness policy of the newest calls, one test per class: an input that would make a
number of `subtract` (a co-located record's noise ratio) or of a fit with visibilities (an
offset's error bar, a visibility's error) infinite is refused where it enters, with the
README's exception class (`ValueError` for a keyword's value, `tiltnoise.InputFileError` for a
value in a file) naming the keyword or file, key or line, the value and the range; at the ends
of the ranges every number is finite."""
import math
import shutil

import pytest

import tiltnoise
from conftest import write_subtract_records

SAMPLES = 6 * 3600


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    d = tmp_path_factory.mktemp("finiteness")
    tilt, measured = write_subtract_records(d, SAMPLES)
    np = pytest.importorskip("numpy")
    h5py = pytest.importorskip("h5py")
    co = d / "co.h5"
    shutil.copyfile(tilt, co)
    rng = np.random.default_rng(5)
    with h5py.File(co, "r+") as f:
        for ch in ("theta_t", "eta_t"):
            x = f[ch][...]
            f[ch][...] = x + 0.1 * np.std(x) * rng.standard_normal(x.size)
    return tilt, measured, co


def test_noise_ratio_out_of_its_range_or_for_an_unrecorded_input_is_refused(records):
    tilt, measured, co = records
    for bad in (1e150, 1e300, 1001.0, -1e-3, math.nan):
        with pytest.raises(ValueError, match=r"colocated_ratio.*eta_t.*from 0 to 1e3"):
            tiltnoise.subtract(tilt, measured, colocated=[co], colocated_ratio={"eta_t": bad})
    with pytest.raises(ValueError, match=r"colocated_ratio.*x_t.*has no input x_t"):
        tiltnoise.subtract(tilt, measured, colocated=[co], colocated_ratio={"x_t": 1.0})
    for r in (0.0, 1e-300, 1e3):
        s = tiltnoise.subtract(tilt, measured, colocated=[co], colocated_ratio={"eta_t": r})
        gains = [g for w in s.report["witness_noise"] for g in (w.get("relative_gains") or [])]
        assert gains and all(math.isfinite(g) and abs(g - 1) < 0.1 for g in gains), gains


def test_error_bars_outside_their_ranges_are_refused_in_files(tmp_path):
    table = tiltnoise.Params().to_toml()
    for sigma in ("1e-310", "2"):
        p = tmp_path / f"p_{sigma}.toml"
        p.write_text(f'{table}\n[uncertainty]\n"asymmetry.tm_com_x_m" = {{ sigma = {sigma} }}\n')
        with pytest.raises(tiltnoise.InputFileError, match=r"tm_com_x_m.*from 1e-20 to 1e0"):
            tiltnoise.Params.from_toml(p)
    vis = tmp_path / "vis.csv"
    vis.write_text("mode,observable,reference,ratio,sigma\n1,phi_a,phi,0.6458,1e-310\n")
    with pytest.raises(tiltnoise.InputFileError, match=r"vis\.csv, line 2.*1e-310.*1e-40 to 2e6"):
        tiltnoise.Model().fit(visibility=vis, free=["length.d_m"])
