"""Model.simulate: the same series, ASDs and files as the command line's `tiltnoise simulate`,
the physics of the kick, and errors."""

import numpy as np
import pytest

import tiltnoise
from conftest import without_command_line


@pytest.fixture(scope="module")
def kick():
    return tiltnoise.Model().simulate(3600, 0.1, kick_x=1e-6, seed=3)


def test_simulation_equals_the_command_lines_files(kick, cli, tmp_path):
    theirs_csv, mine_csv = tmp_path / "cli.csv", tmp_path / "mine.csv"
    theirs_h5, mine_h5 = tmp_path / "cli.h5", tmp_path / "mine.h5"
    out = cli("simulate", "--duration", 3600, "--kick-x", 1e-6, "--seed", 3,
              "--save", theirs_csv, "--save", theirs_h5)
    kick.save(mine_csv)
    kick.save(mine_h5)
    assert without_command_line(mine_csv.read_text()) == without_command_line(theirs_csv.read_text())
    assert kick.resonance_check in out
    h5py = pytest.importorskip("h5py")
    with h5py.File(theirs_h5, "r") as a, h5py.File(mine_h5, "r") as b:
        for key in ("schema", "sample_rate_hz", "description", "init_source", "seed"):
            if key in a.attrs:
                assert a.attrs[key] == b.attrs[key], key
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        for name, x in kick.observables.items():
            np.testing.assert_array_equal(b[name][()], x, err_msg=name)


@pytest.mark.parametrize("ext", ["png", "svg"])
def test_the_figure_is_the_command_lines(kick, cli, tmp_path, ext):
    theirs, mine = tmp_path / f"cli.{ext}", tmp_path / f"mine.{ext}"
    cli("simulate", "--duration", 3600, "--kick-x", 1e-6, "--seed", 3, "--save", theirs)
    kick.save(mine)
    assert mine.read_bytes() == theirs.read_bytes()


def test_kick_starts_at_rest_at_the_displacement(kick):
    x = kick.observables["X"]
    assert kick.n_samples == 36_000 and len(x) == 36_000 and kick.dt_s == 0.1
    assert kick.time_s[-1] == pytest.approx(3599.9, rel=1e-12)
    assert all(v == 0 for v in kick.initial_state["qdot"].values())
    # X(0) is the kick plus one readout-noise sample (9e-9 m/sqrt(Hz) at 10 Hz: sigma 2e-8 m).
    sigma = 9e-9 * np.sqrt(kick.fs_hz / 2)
    assert abs(x[0] - 1e-6) < 6 * sigma
    # A force along x moves the swing about y and the torsion; the other block (Y, theta) and
    # the bouncing (Z) are not excited at all, and have no readout noise.
    assert kick.coordinates["eta_b"][0] != 0
    for name in ("Y", "Z", "theta"):
        assert np.all(kick.observables[name] == 0), name
    assert kick.resonances_agree


def test_simulated_record_is_a_measured_input_of_the_budget(kick, tmp_path):
    path = tmp_path / "sim.h5"
    kick.save(path)
    fs = kick.fs_hz
    rng = np.random.default_rng(1)
    tilt = {"eta_t": 1e-8 * rng.standard_normal(kick.n_samples)}
    b = tiltnoise.budget(tilt, fs, nperseg=kick.nperseg, measured=path)
    assert "measured" in b.terms["X"] and "residual" in b.terms["X"]


def test_simulate_errors():
    model = tiltnoise.Model()
    with pytest.raises(ValueError, match="damped"):
        tiltnoise.Model(tiltnoise.Params().set("loss.torsion_b_rad", 1e-3)).simulate(100)
    with pytest.raises(ValueError, match="either kick_x or init/init_rate"):
        model.simulate(100, kick_x=1e-6, init={"phi_b": 1e-3})
    with pytest.raises(TypeError, match=r"^init=\[1, 2\]: expected a dict"):
        model.simulate(100, init=[1, 2])
    with pytest.raises(ValueError, match=r"init: phi_b is given twice"):
        model.simulate(100, init="phi_b=1,phi_b=2")
    with pytest.raises(ValueError, match="unknown extension"):
        model.simulate(100, init={"phi_b": 1e-3}).save("sim.json")
