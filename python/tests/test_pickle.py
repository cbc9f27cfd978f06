"""Every object of the package pickles and unpickles to an equal one (every value bit for bit),
with every pickle protocol, through copy, and through a pool of worker processes as
multiprocessing and joblib use it; an unknown state is refused, never misread."""

import copy
import pickle
import tempfile
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import tiltnoise
from tiltnoise import _tiltnoise
from conftest import write_subtract_records

PROTOCOLS = range(2, pickle.HIGHEST_PROTOCOL + 1)


def params():
    return tiltnoise.Params().set("length.h_m", 1.5).set("loss.torsion_b_rad", 1e-3)


def budget():
    rng = np.random.default_rng(3)
    tilt = {"eta_t": 1e-9 * rng.standard_normal(4096), "theta_t": 1e-9 * rng.standard_normal(4096)}
    return tiltnoise.budget(tilt, fs=1.0, nperseg=512, segment_duration=1024.0,
                            params=tiltnoise.Model(params()))


def fit():
    return tiltnoise.Model().fit(free=["mass.m_b_kg", "length.d_m"], prior=True)


def coherence():
    """The coherence of a small pair of records written for it: X partly eta_t, partly noise."""
    rng = np.random.default_rng(5)
    n = 8192
    theta, eta = 1e-9 * rng.standard_normal(n), 1e-9 * rng.standard_normal(n)
    x = 1e-3 * eta + 1e-13 * rng.standard_normal(n)
    d = Path(tempfile.mkdtemp())
    tilt, measured = d / "tilt.csv", d / "measured.csv"
    tilt.write_text("time_s,theta_t,eta_t\n" + "".join(
        f"{i},{a!r},{b!r}\n" for i, (a, b) in enumerate(zip(theta.tolist(), eta.tolist()))))
    measured.write_text("time_s,X\n" + "".join(f"{i},{a!r}\n" for i, a in enumerate(x.tolist())))
    return tiltnoise.coherence(tilt, measured, nperseg=1024)


def subtraction():
    """A subtraction of six hours of the lab tilt from X driven by it through the model."""
    tilt, measured = write_subtract_records(tempfile.mkdtemp(), 6 * 3600)
    return tiltnoise.subtract(tilt, measured, readout={"X": 1e-9})
def visibilities():
    """The visibilities of a short free motion written for them."""
    path = Path(tempfile.mkdtemp()) / "free.h5"
    tiltnoise.Model().simulate(duration=4000.0, step=0.5, seed=2).save(path)
    return tiltnoise.visibility(path)


MAKERS = {
    "Params": params,
    "Model": lambda: tiltnoise.Model(params()),
    "Mode": lambda: tiltnoise.Model().modes()[3],
    "MonteCarlo": lambda: tiltnoise.Model().monte_carlo(samples=50, seed=4),
    "Fit": fit,
    "Simulation": lambda: tiltnoise.Model().simulate(duration=2000.0, step=1.0, seed=9),
    "Budget": budget,
    "Coherence": coherence,
    "Subtraction": subtraction,
    "Visibilities": visibilities,
}


@pytest.fixture(scope="module", params=list(MAKERS))
def made(request):
    return request.param, MAKERS[request.param]()


def test_every_class_of_the_module_is_covered():
    classes = {n for n in _tiltnoise.__all__
               if isinstance(getattr(_tiltnoise, n), type)
               and not issubclass(getattr(_tiltnoise, n), BaseException)}
    assert classes == set(MAKERS)


@pytest.mark.parametrize("protocol", PROTOCOLS)
def test_pickle_round_trip_is_equal(made, protocol):
    name, obj = made
    back = pickle.loads(pickle.dumps(obj, protocol=protocol))
    assert type(back) is type(obj)
    assert back == obj, name
    assert repr(back) == repr(obj)


def test_copies_are_equal_and_a_different_object_is_not(made):
    name, obj = made
    assert copy.copy(obj) == obj and copy.deepcopy(obj) == obj
    assert obj != object() and obj != None  # noqa: E711 - the comparison is the test


def test_equality_sees_every_value():
    a, b = tiltnoise.Model().modes()[:2]
    assert a != b
    m = tiltnoise.Model()
    assert m.monte_carlo(samples=50, seed=4) != m.monte_carlo(samples=50, seed=5)
    assert tiltnoise.Model() != tiltnoise.Model(params())
    assert budget() == budget()  # recomputed from the same inputs: the same bits


def test_unpickled_results_work_as_the_originals(tmp_path):
    b = budget()
    back = pickle.loads(pickle.dumps(b))
    assert back.to_csv() == b.to_csv()
    for obs in b.observables:
        for term, asd in b.terms[obs].items():
            np.testing.assert_array_equal(back.terms[obs][term], asd)
    back.save(tmp_path / "b.h5")
    s = MAKERS["Simulation"]()
    back = pickle.loads(pickle.dumps(s))
    for obs, x in s.observables.items():
        assert back.observables[obs].tobytes() == x.tobytes()
    f = fit()
    back = pickle.loads(pickle.dumps(f))
    assert back.params == f.params and back.chi2 == f.chi2
    sub = subtraction()
    back = pickle.loads(pickle.dumps(sub))
    assert back.report == sub.report
    for obs, x in sub.cleaned.items():
        assert back.cleaned[obs].tobytes() == x.tobytes()
    back.save(tmp_path / "s.h5")
    back.save(tmp_path / "s.svg")
    sub.save(tmp_path / "t.svg")
    assert (tmp_path / "s.svg").read_bytes() == (tmp_path / "t.svg").read_bytes()
    m = tiltnoise.Model(params())
    back = pickle.loads(pickle.dumps(m))
    f = np.logspace(-4, 1, 50)
    np.testing.assert_array_equal(back.transfer(f), m.transfer(f))


def test_infinities_survive():
    mode = tiltnoise.Model().modes()[0]
    assert np.isinf(mode.quality_factor)
    assert pickle.loads(pickle.dumps(mode)).quality_factor == np.inf


def _transfer_in_worker(model, f):
    """Runs in a worker process: the model arrives pickled."""
    return model.transfer(f, inputs="eta_t", outputs="X")


def _identity(obj):
    return obj


def test_objects_cross_process_pools():
    model = tiltnoise.Model(params())
    f = np.logspace(-4, 1, 100)
    objs = [MAKERS[n]() for n in ("Model", "Mode", "MonteCarlo", "Budget", "Simulation")]
    with ProcessPoolExecutor(max_workers=2) as pool:
        h = pool.submit(_transfer_in_worker, model, f).result(timeout=300)
        back = list(pool.map(_identity, objs, timeout=300))
    np.testing.assert_array_equal(h, model.transfer(f, inputs="eta_t", outputs="X"))
    assert back == objs


def test_a_state_of_another_version_is_refused():
    b = budget()
    constructor, (version, state) = b.__reduce__()
    with pytest.raises(ValueError, match="state version 999 cannot be read by this tiltnoise"):
        constructor(999, state)
    with pytest.raises(ValueError, match="not the state of a tiltnoise.Budget"):
        constructor(version, state[: len(state) // 2])
    with pytest.raises(ValueError, match="not the state of a tiltnoise.Budget"):
        type(b)._from_state(version, tiltnoise.Model().__reduce__()[1][1])


def test_a_save_guard_survives_pickling(tmp_path):
    toml = tmp_path / "params.csv"  # a parameter file any name: a save must not replace it
    toml.write_text(params().to_toml())
    p = tiltnoise.Params.from_toml(toml)
    rng = np.random.default_rng(0)
    b = tiltnoise.budget({"eta_t": 1e-9 * rng.standard_normal(2048)}, fs=1.0, nperseg=256,
                         params=tiltnoise.Model(p))
    back = pickle.loads(pickle.dumps(b))
    with pytest.raises(OSError, match="params.csv"):
        back.save(toml)
    assert toml.read_text() == params().to_toml()
