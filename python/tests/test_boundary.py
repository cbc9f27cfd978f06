"""The Python boundary holds: every array is size-checked before it is copied (ValueError over a
documented limit, MemoryError over the memory available, never an abort of the interpreter),
views are read in place, float32 and integer arrays are converted, other dtypes are refused
naming the dtype needed, values outside the finiteness policy (docs/limits.md) are refused
naming the argument, index and value, and no save replaces an input of its result.

The property tests (hypothesis) draw arrays of every dtype, shape and stride and check the one
promise that covers them all: a result that is finite, or one of the documented exceptions with
a message; a float64 copy of an accepted array gives the same result.
"""

import math
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import tiltnoise as tn

REPO = Path(__file__).resolve().parents[2]
SPECTRA = REPO / "tilt_data" / "peterson_tilt_asd.csv"
MAX_SAMPLE = 1e40
MIN_SAMPLE = 1e-40
DOCUMENTED = (ValueError, TypeError, MemoryError)

# Values that break number handling, besides ordinary ones.
EDGE = [0.0, -0.0, 1e-9, -3.5, MIN_SAMPLE, MAX_SAMPLE, 1e-41, 1e41, 1e308, -1e308, 5e-324,
        math.nan, math.inf, -math.inf]


def run_limited(code, limit="4 << 30"):
    """Runs `code` in a child interpreter whose address space is then limited to `limit` (an
    expression; `mapped` is what the child has mapped once NumPy and tiltnoise are loaded);
    its stdout, exit code and stderr."""
    child = "\n".join([
        "import resource",
        "import numpy as np, tiltnoise as tn",
        "status = open('/proc/self/status').read()",
        "mapped = int(status.split('VmSize:')[1].split()[0]) * 1024",
        f"resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))",
        "try:",
        textwrap.indent(code, "    "),
        "    print('returned')",
        "except (ValueError, MemoryError, TypeError) as e:",
        "    print(type(e).__name__ + ': ' + str(e))",
    ])
    done = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True,
                          timeout=300)
    return done.stdout.strip(), done.returncode, done.stderr


@pytest.mark.parametrize("code, needle", [
    ("tn.Model().transfer(np.broadcast_to(np.float64(1e-3), (10**9,)))",
     "1000000000 frequencies, more than the 1000000 allowed"),
    ("tn.welch(np.broadcast_to(np.float64(1.0), (2**31,)), 1.0)",
     "2147483648 samples, more than the 33554432 allowed"),
    ("x = np.broadcast_to(np.float64(1.0), (2**31,)); tn.csd(x, x, 1.0)",
     "2147483648 samples, more than the 33554432 allowed"),
    ("x = np.broadcast_to(np.float64(1e-9), (2**31,)); tn.budget({'eta_t': x}, fs=1.0)",
     "2147483648 samples, more than the 33554432 allowed"),
    ("tn.welch(np.ones(300_000_000, dtype=np.float32), 1.0)",
     "300000000 samples, more than the 33554432 allowed"),
])
def test_sizes_are_checked_before_any_copy_under_a_memory_limit(code, needle):
    out, rc, err = run_limited(code)
    assert rc == 0, f"the interpreter died (exit {rc}): {err[-500:]}"
    assert out.startswith("ValueError: ") and needle in out, out


# Every call whose size the caller chooses, at sizes that would not fit into a 6 GiB address
# space: refused before anything is allocated, naming the argument and the limit.
@pytest.mark.parametrize("code, needle", [
    ("tn.Model().transfer(np.broadcast_to(np.float64(1e-3), (10**8,)), inputs='forces')",
     "freq_hz: 100000000 frequencies, more than the 1000000 allowed"),
    ("tn.Model().transfer_function(np.broadcast_to(np.float64(1e-3), (10**9,)))",
     "freq_hz: 1000000000 frequencies, more than the 1000000 allowed"),
    ("tn.Model().explain(np.broadcast_to(np.float64(1e-3), (10**9,)))",
     "freq_hz: 1000000000 frequencies, more than the 1000000 allowed"),
    ("tn.Model().monte_carlo(10**12)", "samples 1000000000000: 1000000000000 Monte Carlo draws, "
                                       "more than the 10000000 allowed"),
    ("tn.Model().simulate(duration=1e12, step=0.1)",
     "duration 1e12 s at step 0.1 s: 10000000010000 samples, more than the 16777216 allowed"),
    ("tn.budget_from_file(REPO + '/tilt_data/peterson_tilt_asd.csv', freq=np.broadcast_to("
     "np.float64(1e-2), (10**9,)))", "1000000000 frequencies, more than the 1000000 allowed"),
])
def test_absurd_sizes_are_refused_under_a_6_gib_address_space(code, needle):
    out, rc, err = run_limited(f"REPO = {str(REPO)!r}\n{code}", limit="6 << 30")
    assert rc == 0, f"the interpreter died (exit {rc}): {err[-500:]}"
    assert out.startswith(("ValueError: ", "MemoryError: ")) and needle in out, out


def test_memory_beyond_the_address_space_left_is_a_memory_error():
    # 2^25 samples (at the count limit) plan 512 MiB, more than half of the 768 MiB of address
    # space left to the child.
    out, rc, err = run_limited("tn.welch(np.broadcast_to(np.float64(1.0), (2**25,)), 1.0)",
                               limit="mapped + (768 << 20)")
    assert rc == 0, err[-500:]
    assert out.startswith("MemoryError: x: 33554432 samples: needs about"), out


def welch_or_error(x):
    try:
        return tn.welch(x, 1.0, nperseg=16)
    except DOCUMENTED as e:
        assert str(e), f"{type(e).__name__} without a message"
        return e


def accepted_as_float64(x):
    """Whether the boundary takes `x` (dtype, shape, values) as a series."""
    if x.ndim != 1 or x.dtype.kind not in "fiu" or x.size < 16:
        return False
    v = x.astype(np.float64)
    return bool(np.all(np.isfinite(v) & ((v == 0) | ((np.abs(v) >= MIN_SAMPLE)
                                                       & (np.abs(v) <= MAX_SAMPLE)))))


dtypes = st.sampled_from([np.float64, np.float32, np.float16, np.int8, np.int16, np.int64,
                          np.uint8, np.uint64, np.bool_, np.complex128, ">f8", "<i4"])


@st.composite
def arrays(draw):
    dtype = np.dtype(draw(dtypes))
    shape = draw(st.sampled_from([(), (0,), (7,), (40,), (64,), (3, 32)]))
    if dtype.kind == "f" and dtype.itemsize == 8:
        elements = st.sampled_from(EDGE) | st.floats(-1e3, 1e3)
    elif dtype.kind == "f":
        elements = st.floats(width=dtype.itemsize * 8)
    elif dtype.kind == "c":
        elements = st.complex_numbers(max_magnitude=1e3)
    else:
        elements = None
    a = draw(hnp.arrays(dtype, shape, elements=elements))
    view = draw(st.sampled_from(["as is", "every other", "reversed", "broadcast", "list"]))
    if a.ndim == 1 and view == "every other":
        return a[::2]
    if a.ndim == 1 and view == "reversed":
        return a[::-1]
    if a.ndim == 1 and a.size and view == "broadcast":
        return np.broadcast_to(a[:1], (64,))
    if view == "list":
        return a.tolist()
    return a


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(arrays())
def test_welch_takes_any_array_or_refuses_it_with_a_documented_exception(x):
    got = welch_or_error(x)
    a = np.asarray(x)
    if isinstance(got, Exception):
        assert not accepted_as_float64(a), f"refused a valid series: {got}"
        if a.dtype.kind not in "fiu" and a.ndim == 1:
            assert isinstance(got, TypeError) and "float64" in str(got), got
        return
    assert accepted_as_float64(a), f"accepted {a.dtype} {a.shape}: {a[:5]}"
    f, p = got
    assert np.all(np.isfinite(f)) and np.all(np.isfinite(p))
    f64, p64 = tn.welch(np.ascontiguousarray(a, dtype=np.float64), 1.0, nperseg=16)
    assert np.array_equal(f, f64) and np.array_equal(p, p64)


@settings(max_examples=100, deadline=None)
@given(arrays(), st.sampled_from([1.0, 1e-6, 2e6, 0.0, -1.0, 1e308, 1e-300, math.nan]))
def test_budget_of_arrays_is_finite_or_refused(x, fs):
    try:
        b = tn.budget({"eta_t": x}, fs=fs, nperseg=16)
    except DOCUMENTED as e:
        assert str(e)
        return
    a = np.asarray(x)
    assert accepted_as_float64(a) and 1e-6 <= fs <= 2e6
    for ob, terms in b.terms.items():
        for name, asd in terms.items():
            assert np.all(np.isfinite(asd)), (ob, name)
    for asd in b.total.values():
        assert np.all(np.isfinite(asd))


@settings(max_examples=150, deadline=None)
@given(st.one_of(arrays(), st.floats(allow_nan=True, allow_infinity=True)))
def test_transfer_takes_any_grid_or_refuses_it(f):
    model = tn.Model()
    try:
        h = model.transfer(f, inputs="eta_t", outputs="X", method="polezero")
    except DOCUMENTED as e:
        assert str(e)
        return
    assert np.all(np.isfinite(h))
    grid = np.atleast_1d(np.asarray(f, dtype=np.float64))
    assert h.shape == (grid.size, 1, 1)


def test_views_are_read_in_place_and_equal_their_copies():
    x = np.random.default_rng(3).standard_normal(8192) * 1e-9
    for view in (x[::2], x[::-1], x[1::3], np.broadcast_to(x[:1], (4096,))):
        f, p = tn.welch(view, 1.0)
        f2, p2 = tn.welch(np.ascontiguousarray(view), 1.0)
        assert np.array_equal(p, p2)
    ints = (np.arange(4096) % 17).astype(np.int32)
    assert np.array_equal(tn.welch(ints, 1.0)[1], tn.welch(ints.astype(float), 1.0)[1])
    f32 = x.astype(np.float32)
    assert np.array_equal(tn.welch(f32, 1.0)[1], tn.welch(f32.astype(float), 1.0)[1])


@pytest.mark.parametrize("make, dtype", [
    (lambda: np.zeros(4096, complex), "complex128"),
    (lambda: np.zeros(4096, bool), "bool"),
    (lambda: np.array(["1"] * 4096), "<U1"),
    (lambda: np.array([1.0] * 4096, dtype=object), "object"),
    (lambda: np.zeros(4096, "datetime64[s]"), "datetime64[s]"),
])
def test_other_dtypes_are_refused_naming_the_dtype_needed(make, dtype):
    with pytest.raises(TypeError, match=rf"x: dtype {re.escape(dtype)} is not allowed: give "
                                        "numbers as float64"):
        tn.welch(make(), 1.0)


@pytest.mark.parametrize("value, index", [(1e308, 100), (math.nan, 7), (1e-310, 4000),
                                          (-1e41, 0)])
def test_samples_outside_the_policy_are_refused_naming_index_and_value(value, index):
    x = np.random.default_rng(1).standard_normal(4096) * 1e-9
    x[index] = value
    with pytest.raises(ValueError, match=rf"x\[{index}\] = "):
        tn.welch(x, 1.0)
    with pytest.raises(ValueError, match=rf"y\[{index}\] = "):
        tn.csd(np.ones(4096), x, 1.0)
    if math.isfinite(value):
        with pytest.raises(ValueError, match=rf'tilt\["eta_t"\]\[{index}\] is '):
            tn.budget({"eta_t": x}, fs=1.0)


@pytest.mark.parametrize("fs", [1e308, 0.0, -1.0, math.nan, 1e-300, 2.1e6])
def test_fs_outside_its_range_is_named(fs):
    x = np.random.default_rng(1).standard_normal(4096) * 1e-9
    for call in (lambda: tn.welch(x, fs), lambda: tn.csd(x, x, fs),
                 lambda: tn.budget({"eta_t": x}, fs=fs)):
        with pytest.raises(ValueError, match=r"^fs = .* Hz is not allowed: the sample rate must "
                                             r"be from 1e-6 to 2e6 Hz"):
            call()


def test_out_must_be_a_contiguous_complex128_array_of_the_result_shape():
    m = tn.Model()
    f = np.array([1e-3, 1e-2])
    with pytest.raises(TypeError, match=r"out: a 3-D array of dtype float64 is not allowed: "
                                        r"must be complex128 of shape \[2, 7, 3\]"):
        m.transfer(f, out=np.zeros((2, 7, 3)))
    with pytest.raises(TypeError, match=r"out: expected a NumPy array"):
        m.transfer(f, out=[[0j]])
    with pytest.raises(ValueError, match=r"out: shape \[2, 7, 4\] does not fit"):
        m.transfer(f, out=np.zeros((2, 7, 4), complex))
    with pytest.raises(ValueError, match=r"out: must be C-contiguous"):
        m.transfer(f, out=np.zeros((2, 7, 6), complex)[:, :, ::2])
    out = np.empty((2, 7, 3), complex)
    assert m.transfer(f, out=out) is out and np.array_equal(out, m.transfer(f))


def test_a_save_never_replaces_an_input(tmp_path):
    shutil.copyfile(SPECTRA, tmp_path / "in.csv")
    before = (tmp_path / "in.csv").read_bytes()
    b = tn.budget_from_file(tmp_path / "in.csv")
    (tmp_path / "link.csv").symlink_to("in.csv")
    for target in ("in.csv", "link.csv", "./sub/../in.csv"):
        (tmp_path / "sub").mkdir(exist_ok=True)
        with pytest.raises(OSError, match=r"replace an input"):
            b.save(tmp_path / target)
    assert (tmp_path / "in.csv").read_bytes() == before
    # A gwpy address reads the file it addresses; a save there is refused too.
    rng = np.random.default_rng(2)
    import h5py
    with h5py.File(tmp_path / "gw.h5", "w") as f:
        d = f.create_dataset("theta", data=rng.standard_normal(8192) * 1e-3)
        d.attrs.update({"x0": 0.0, "dx": 1.0, "xunit": "s", "unit": "urad"})
    gw = (tmp_path / "gw.h5").read_bytes()
    b = tn.budget_from_file(f"{tmp_path / 'gw.h5'}:/theta", axes="theta_t=theta")
    with pytest.raises(OSError, match=r"replace an input"):
        b.save(tmp_path / "gw.h5")
    assert (tmp_path / "gw.h5").read_bytes() == gw
    # The parameter file of a simulation's model.
    (tmp_path / "p.csv").write_text(tn.Params().to_toml())
    sim = tn.Model(tn.Params.from_toml(str(tmp_path / "p.csv")).set("length.h_m", 1.0))
    run = sim.simulate(1000.0)
    with pytest.raises(OSError, match=r"the parameter file \(Params.from_toml\) .*p\.csv"):
        run.save(tmp_path / "p.csv")
    run.save(tmp_path / "sim.h5")


@pytest.mark.parametrize("call, needle", [
    (lambda m: m.transfer(1e-3, inputs=["eta_t", "eta_t"]), "inputs: eta_t is given twice"),
    (lambda m: m.simulate(1000.0, init="theta_a=1e-5,theta_a=2e-5"),
     "init: theta_a is given twice"),
    (lambda m: m.fit(free=["mass.m_a_kg", "mass.m_a_kg"]), "free: mass.m_a_kg is given twice"),
    (lambda m: tn.budget(np.ones((2, 64)), fs=1.0, axes=("eta_t", "eta_t"), params=m),
     "axes: eta_t is given twice"),
])
def test_repeated_names_are_refused(call, needle):
    with pytest.raises(ValueError, match=needle):
        call(tn.Model())
