"""Results carry their names and units: gwpy series and pandas frames with the same values,
matplotlib figures, the command line's figure from Budget.save, and values that cannot be
edited where an edit would be lost."""

import pickle
import sys

import numpy as np
import pytest

import tiltnoise
from conftest import LAB_TILT

FIG_ARGS = ("--nperseg", 4096, "--segment-duration", 14400)


@pytest.fixture(scope="module")
def lab_budget():
    return tiltnoise.budget_from_file(LAB_TILT, nperseg=4096, segment_duration=14400)


@pytest.fixture(scope="module")
def sim():
    return tiltnoise.Model().simulate(duration=20_000.0, step=0.5, seed=2)


@pytest.fixture(scope="module")
def tf():
    return tiltnoise.Model().transfer_function(np.logspace(-4, 1, 400), inputs=["eta_t", "M_b.z"],
                                               outputs=["X", "phi"])


def without(monkeypatch, *modules):
    for m in modules:
        monkeypatch.setitem(sys.modules, m, None)


# --- transfer functions ---------------------------------------------------------------------

def test_transfer_function_holds_transfers_values_names_and_units(tf):
    f = np.logspace(-4, 1, 400)
    h = tiltnoise.Model().transfer(f, inputs=["eta_t", "M_b.z"], outputs=["X", "phi"])
    assert np.asarray(tf).tobytes() == h.tobytes() and tf.freq_hz.tobytes() == f.tobytes()
    assert (tf.outputs, tf.inputs) == (("X", "phi"), ("eta_t", "M_b.z"))
    assert tf.units == {("X", "eta_t"): "m/rad", ("X", "M_b.z"): "m/(N m)",
                        ("phi", "eta_t"): "rad/rad", ("phi", "M_b.z"): "rad/(N m)"}
    assert tf["phi", "M_b.z"].tobytes() == h[:, 1, 1].tobytes()
    with pytest.raises(KeyError, match="input 'x_t' is not in the transfer function"):
        tf["X", "x_t"]
    with pytest.raises(ValueError, match="read-only"):
        tf.values[0, 0, 0] = 0
    assert pickle.loads(pickle.dumps(tf)) == tf
    assert tf != tiltnoise.Model().transfer_function(f[::-1], inputs=["eta_t", "M_b.z"],
                                                     outputs=["X", "phi"])


def test_transfer_function_to_gwpy_and_pandas(tf):
    pytest.importorskip("gwpy")
    pd = pytest.importorskip("pandas")
    g = tf.to_gwpy()
    s = g["X", "eta_t"]
    assert s.value.tobytes() == tf["X", "eta_t"].tobytes()
    assert np.array_equal(s.frequencies.value, tf.freq_hz)
    assert str(s.unit) == "m / rad" and s.name == "X/eta_t"
    u = pytest.importorskip("astropy.units")
    assert g["phi", "M_b.z"].unit == u.rad / (u.N * u.m)
    df = tf.to_pandas()
    assert isinstance(df, pd.DataFrame) and df.index.name == "frequency_hz"
    assert list(df.columns) == ["X/eta_t", "X/M_b.z", "phi/eta_t", "phi/M_b.z"]
    assert df["phi/M_b.z"].to_numpy().tobytes() == tf["phi", "M_b.z"].tobytes()
    assert df.attrs["units"]["X/M_b.z"] == "m/(N m)"


# --- budgets --------------------------------------------------------------------------------

def test_budget_to_pandas_has_the_csvs_columns_and_units(lab_budget):
    pd = pytest.importorskip("pandas")
    df = lab_budget.to_pandas()
    assert df.index.name == "frequency_hz"
    assert df.index.to_numpy().tobytes() == lab_budget.frequency_hz.tobytes()
    csv = lab_budget.to_csv(keep_zero_columns=True).splitlines()
    header = next(l for l in csv if not l.startswith("#")).split(",")
    assert set(df.columns) == set(header[1:])
    for obs in lab_budget.observables:
        assert df[f"{obs}.total"].to_numpy().tobytes() == lab_budget.total[obs].tobytes()
        for term, asd in lab_budget.terms[obs].items():
            assert df[f"{obs}.{term}"].to_numpy().tobytes() == asd.tobytes()
            assert df.attrs["units"][f"{obs}.{term}"] == lab_budget.units[obs]
    # The CSV's values, read back, are the frame's.
    back = pd.read_csv(__import__("io").StringIO(lab_budget.to_csv(keep_zero_columns=True)),
                       comment="#", index_col=0)
    np.testing.assert_array_equal(back["X.total"].to_numpy(), df["X.total"].to_numpy())


def test_budget_to_gwpy_names_and_units(lab_budget):
    pytest.importorskip("gwpy")
    s = lab_budget.to_gwpy()["phi_a"]["tilt"]
    assert s.name == "phi_a.tilt" and str(s.unit) in ("rad / Hz(1/2)", "rad / Hz1/2")
    assert s.value.tobytes() == lab_budget.terms["phi_a"]["tilt"].tobytes()


@pytest.mark.parametrize("method, package", [("to_pandas", "pandas"), ("to_gwpy", "gwpy")])
def test_conversions_without_their_package_say_how_to_get_it(lab_budget, sim, monkeypatch,
                                                             method, package):
    without(monkeypatch, package, f"{package}.frequencyseries", f"{package}.timeseries")
    for obj in (lab_budget, sim):
        with pytest.raises(ImportError, match=f"pip install {package}"):
            getattr(obj, method)()


def test_budget_values_cannot_be_edited_and_lost(lab_budget):
    before = lab_budget.to_csv()
    with pytest.raises(TypeError):
        lab_budget.terms["X"]["tilt"] = np.zeros(3)
    with pytest.raises(TypeError):
        lab_budget.total["X"] = np.zeros(3)
    for a in (lab_budget.terms["X"]["tilt"], lab_budget.total["X"], lab_budget.frequency_hz):
        with pytest.raises(ValueError, match="read-only"):
            a[0] = 1.0
        with pytest.raises(ValueError, match="read-only"):
            a *= 2
    assert lab_budget.to_csv() == before
    # A copy is the user's to change.
    mine = np.array(lab_budget.total["X"])
    mine[0] = 0.0
    # The methods' arrays are new arrays each call, the caller's.
    psd = lab_budget.psd("X")
    psd[0] = 0.0
    assert lab_budget.psd("X")[0] != 0.0
    mc = tiltnoise.Model().monte_carlo(samples=20)
    with pytest.raises(ValueError, match="read-only"):
        mc.freqs_hz[0, 0] = 0


# --- simulations ----------------------------------------------------------------------------

def test_simulation_and_budget_frequencies_are_frequency_hz_and_its_alias_freq_hz(sim, lab_budget):
    f = sim.frequency_hz
    # k fs / nperseg, DC included, up to at most the Nyquist frequency.
    np.testing.assert_allclose(f, np.arange(f.size) * f[1], rtol=1e-12, atol=0)
    assert f[0] == 0.0 and f[-1] <= 0.5 / sim.dt_s
    for result in (sim, lab_budget):
        assert result.freq_hz.tobytes() == result.frequency_hz.tobytes()
        assert result.frequency_hz.size > 100

def test_simulation_to_gwpy_and_pandas(sim):
    pytest.importorskip("gwpy")
    pytest.importorskip("pandas")
    g = sim.to_gwpy()
    x = g["observables"]["X"]
    assert x.value.tobytes() == sim.observables["X"].tobytes()
    assert x.dt.value == sim.dt_s and x.t0.value == 0.0 and str(x.unit) == "m"
    assert str(g["observables"]["phi"].unit) == "rad"
    a = g["asd"]["phi"]
    assert a.value.tobytes() == sim.asd["phi"].tobytes()
    np.testing.assert_allclose(a.frequencies.value, sim.frequency_hz, rtol=1e-12, atol=0)
    d = sim.to_pandas()
    assert d["observables"].index.name == "time_s" and d["asd"].index.name == "frequency_hz"
    assert d["asd"].attrs["units"]["X"] == "m/sqrt(Hz)"
    assert d["observables"]["eta"].to_numpy().tobytes() == sim.observables["eta"].tobytes()


# --- figures --------------------------------------------------------------------------------

def test_plots_are_matplotlib_figures(lab_budget, sim, tf, tmp_path):
    mpl = pytest.importorskip("matplotlib")
    mpl.use("Agg")
    from matplotlib.figure import Figure

    fig = lab_budget.plot()
    assert isinstance(fig, Figure) and len(fig.axes) == len(lab_budget.observables)
    labels = [l.get_label() for l in fig.axes[0].get_lines()]
    assert labels[0] == "total" and "tilt" in labels
    assert fig.axes[0].get_yscale() == "log" and "m/sqrt(Hz)" in fig.axes[0].get_ylabel()
    np.testing.assert_array_equal(fig.axes[0].get_lines()[0].get_ydata(), lab_budget.total["X"])
    assert len(lab_budget.plot(observables=["phi"]).axes) == 1
    with pytest.raises(KeyError, match="'Y' is not in the budget"):
        lab_budget.plot(observables=["Y"])
    for obj, name in ((lab_budget, "budget"), (sim, "simulation"), (tf, "transfer")):
        fig = obj.plot()
        assert isinstance(fig, Figure)
        fig.savefig(tmp_path / f"{name}.png", dpi=60)
        assert (tmp_path / f"{name}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    import matplotlib.pyplot as plt
    plt.close("all")


def test_plots_without_matplotlib_say_how_to_get_it(lab_budget, sim, tf, monkeypatch):
    without(monkeypatch, "matplotlib", "matplotlib.pyplot")
    for obj in (lab_budget, sim, tf):
        with pytest.raises(ImportError, match="pip install matplotlib"):
            obj.plot()


@pytest.mark.parametrize("ext", ["png", "svg"])
def test_budget_figure_is_the_command_lines(cli, tmp_path, ext):
    """Budget.save("x.png") draws the command line's figure: the same bytes."""
    mine, theirs = tmp_path / f"mine.{ext}", tmp_path / f"cli.{ext}"
    b = tiltnoise.budget_from_file(LAB_TILT, nperseg=4096, segment_duration=14400)
    b.save(mine)
    cli("budget", "--tilt", LAB_TILT, *FIG_ARGS, "--save", theirs)
    assert mine.read_bytes() == theirs.read_bytes()
    assert mine.stat().st_size > 10_000


def test_a_figure_that_cannot_be_written_leaves_nothing(tmp_path):
    b = tiltnoise.budget({"eta_t": 1e-9 * np.random.default_rng(1).standard_normal(4096)}, 1.0,
                         nperseg=512)
    with pytest.raises(OSError, match="missing_dir"):
        b.save(tmp_path / "missing_dir" / "b.png")
    b.save(tmp_path / "b.svg")
    assert [p.name for p in tmp_path.iterdir()] == ["b.svg"]
    assert (tmp_path / "b.svg").read_text().startswith("<svg")
