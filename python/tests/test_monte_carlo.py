"""Model.monte_carlo(): the command line's `mc` from Python, with the same report, files and
figure, whatever the threads."""

import json

import numpy as np
import pytest

import tiltnoise

ARGS = {"samples": 300, "seed": 7}


@pytest.fixture(scope="module")
def mc():
    return tiltnoise.Model().monte_carlo(threads=1, **ARGS)


def _cli_args(*saves):
    args = ["mc", "--samples", ARGS["samples"], "--seed", ARGS["seed"], "--format", "json"]
    return args + [a for p in saves for a in ("--save", p)]


def test_report_and_figures_equal_the_command_lines(mc, cli, tmp_path):
    theirs = {ext: tmp_path / f"cli.{ext}" for ext in ("png", "svg")}
    printed = cli(*_cli_args(*theirs.values()))
    assert mc.to_json() + "\n" == printed
    assert mc.summary == json.loads(printed)
    assert [m["nominal_hz"] for m in mc.summary["modes"]] == mc.nominal_hz
    assert mc.summary["seed"] == mc.seed == ARGS["seed"]
    for ext, path in theirs.items():
        mine = tmp_path / f"mine.{ext}"
        mc.save(mine)
        assert mine.read_bytes() == path.read_bytes(), ext


def test_hdf5_equals_the_command_lines(mc, cli, tmp_path):
    h5py = pytest.importorskip("h5py")
    theirs, mine = tmp_path / "cli.h5", tmp_path / "mine.h5"
    cli(*_cli_args(theirs))
    mc.save(mine)
    with h5py.File(theirs, "r") as a, h5py.File(mine, "r") as b:
        names = []
        a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
        assert names
        for name in names:
            np.testing.assert_array_equal(a[name][()], b[name][()], err_msg=name)
        for key in ("schema", "parameters_toml", "seed", "samples", "rejected", "accepted"):
            assert a.attrs[key] == b.attrs[key], key
        assert b.attrs["rejected"] == mc.rejected


def test_the_draws_do_not_depend_on_the_threads_and_survive_pickling(mc):
    import pickle

    again = tiltnoise.Model().monte_carlo(threads=2, **ARGS)
    assert again.to_json() == mc.to_json()
    np.testing.assert_array_equal(again.freqs_hz, mc.freqs_hz)
    back = pickle.loads(pickle.dumps(mc))
    assert back == mc and back.to_json() == mc.to_json()


def test_save_refuses_other_formats_and_the_parameter_file(mc, tmp_path):
    with pytest.raises(ValueError, match=r"\.h5, \.hdf5, \.png, \.svg"):
        mc.save(tmp_path / "mc.csv")
    assert not (tmp_path / "mc.csv").exists()
    params = tmp_path / "params.svg"  # a parameter file any name: a save must not replace it
    params.write_text(tiltnoise.Params().to_toml())
    from_file = tiltnoise.Model(tiltnoise.Params.from_toml(params)).monte_carlo(samples=20)
    with pytest.raises(OSError, match="params.svg"):
        from_file.save(params)
    assert params.read_text() == tiltnoise.Params().to_toml()


def test_plot_draws_a_histogram_per_mode(mc):
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    fig = mc.plot()
    assert len(fig.axes) == 8
    assert fig.axes[0].patches, "no histogram bars"
