"""Keyword arguments are converted by one rule in every call, and every call raises the
exception classes the README's table promises.

The list keywords are found in the type stubs (every parameter of a public call annotated as a
sequence of names, paths or numbers, or as a pair of numbers), so that a new call or keyword is
checked without being listed here: a single str (a path for a path list, a number for a number
list) is a one-item list, giving what the one-item list gives; a pair is two numbers of any
kind (NumPy scalars, an array); any other type is a TypeError naming the keyword."""

import ast
import inspect
import os
import pathlib
import re
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import tiltnoise
from conftest import LAB_TILT, REPO, write_subtract_records
from test_boundary import run_limited

STUBS = REPO / "python" / "tiltnoise" / "_tiltnoise.pyi"


def kind_of(annotation):
    """`names`, `paths`, `numbers` or `pair` for a list-typed annotation, else None."""
    text = ast.unparse(annotation)
    if "Tuple[float, float]" in text:
        return "pair"
    if "Sequence[_Path]" in text:
        return "paths"
    if "Sequence[float]" in text:
        return "numbers"
    if "_Names" in text or "Sequence[str]" in text:
        return "names"
    return None


def list_keywords():
    """{call: {keyword: kind}} of the stubs' public functions and methods."""
    found = {}
    tree = ast.parse(STUBS.read_text())

    def visit(node, prefix):
        for item in node.body:
            if isinstance(item, ast.ClassDef) and not item.name.startswith("_"):
                visit(item, f"{item.name}.")
            elif isinstance(item, ast.FunctionDef) and not item.name.startswith("_"):
                args = item.args.args + item.args.kwonlyargs
                kinds = {a.arg: kind_of(a.annotation) for a in args if a.annotation is not None}
                kinds = {k: v for k, v in kinds.items() if v}
                if kinds:
                    found[prefix + item.name] = kinds
    visit(tree, "")
    return found


@pytest.fixture(scope="module")
def calls(tmp_path_factory):
    """A call of each public function or method with list keywords: `calls[name](**kw)`."""
    d = tmp_path_factory.mktemp("args")
    tilt, measured = write_subtract_records(d, 4096)
    model = tiltnoise.Model()
    rng = np.random.default_rng(3)
    series = {"theta_t": rng.normal(0, 1e-8, 2048), "eta_t": rng.normal(0, 1e-8, 2048)}
    b = tiltnoise.budget(series, 1.0, nperseg=256)
    return {
        # `axes` names the rows of a 2-D array (a dict names its own).
        "budget": lambda **kw: tiltnoise.budget(
            series["theta_t"][None, :] if "axes" in kw else series, 1.0, nperseg=256, **kw),
        "budget_from_file": lambda **kw: tiltnoise.budget_from_file(LAB_TILT, nperseg=256, **kw),
        "coherence": lambda **kw: tiltnoise.coherence(tilt, measured, nperseg=512, **kw),
        "subtract": lambda **kw: tiltnoise.subtract(tilt, measured, nperseg=512, **kw),
        "Model.transfer": lambda **kw: model.transfer([1e-3, 1.0], **kw),
        "Model.transfer_function": lambda **kw: model.transfer_function([1e-3, 1.0], **kw),
        "Model.explain": lambda **kw: model.explain([1e-3, 1.0], **kw),
        "Model.methods": lambda **kw: model.methods([1e-3, 1.0], **kw),
        "Model.save_methods": lambda **kw: model.save_methods(d / "m.svg", [1e-3, 1.0], **kw),
        "Model.fit": lambda **kw: model.fit(**kw),
        "Budget.plot": lambda **kw: b.plot(**kw),
    }


# A value each list keyword may hold (valid or not: a one-item list must give the same).
ONE = {"corrected": "x_t", "pendulum_tiltmeter": "theta_t", "observables": "X",
       "inputs": "eta_t", "outputs": "phi", "fit": "not.a_key", "free": "not.a_key",
       "axes": "theta_t", "colocated": "no_such_record.h5", "at": 2e-3}
# Exact in float32, so that a float32 pair is the same band.
PAIRS = {"band": (2**-8, 2**-5), "report_band": (2**-8, 2**-5), "fit_band": (2**-8, 2**-5),
         "percentiles": (10.0, 90.0)}


def without_timings(value):
    """`value` without what is measured in time (`Model.methods`' `ns_per_point`)."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k != "ns_per_point"}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def outcome(call, **kw):
    """What a call gives: the result's type and value, or the exception's type and message."""
    try:
        result = call(**kw)
    except Exception as e:  # noqa: BLE001 - every outcome is compared
        return ("raised", type(e), str(e))
    if type(result).__module__.startswith("matplotlib"):
        return ("returned", type(result))
    if isinstance(result, np.ndarray):
        return ("returned", result.dtype, result.tobytes())
    return ("returned", type(result), without_timings(result))


def test_the_stubs_list_keywords_are_those_checked_here(calls):
    keywords = list_keywords()
    assert set(keywords) == set(calls), "a public call with list keywords needs a call here"
    for name, kinds in keywords.items():
        for kw, kind in kinds.items():
            assert kw in (PAIRS if kind == "pair" else ONE), (name, kw)
    # The audit's keywords are among them.
    assert keywords["subtract"]["colocated"] == "paths"
    assert keywords["Model.fit"]["free"] == "names"
    assert keywords["budget"]["corrected"] == "names"


def cases():
    return [(name, kw, kind) for name, kinds in sorted(list_keywords().items())
            for kw, kind in sorted(kinds.items())]


@pytest.mark.parametrize("name, kw, kind", cases())
def test_a_single_item_is_a_one_item_list_and_a_wrong_type_a_type_error_naming_it(
        calls, name, kw, kind):
    call = calls[name]
    if kind == "pair":
        lo, hi = PAIRS[kw]
        given = outcome(call, **{kw: (lo, hi)})
        assert given[0] == "returned" or given[1] is not TypeError, given
        for same in (np.array([lo, hi]), [np.float64(lo), np.array(hi)], (np.float32(lo), hi)):
            assert outcome(call, **{kw: same}) == given, (kw, same)
        for count in ((lo,), (lo, hi, hi), ()):
            with pytest.raises(ValueError, match=rf"^{kw}=.*expected two numbers"):
                call(**{kw: count})
    else:
        one = ONE[kw]
        singles = [one]
        if kind == "paths":
            singles.append(pathlib.Path(one))
        if kind == "numbers":
            singles += [np.float64(one), np.array(one)]
        listed = outcome(call, **{kw: [one]})
        assert listed[0] == "returned" or listed[1] is not TypeError, listed
        for single in singles:
            assert outcome(call, **{kw: single}) == listed, (kw, single)
    wrong = [object(), {"a": 1}, b"X"] + ([3.5] if kind != "numbers" else ["X", True])
    if kind != "pair":
        wrong.append([ONE[kw], object()])
    for value in wrong:
        with pytest.raises(TypeError, match=rf"^{kw}=.*expected "):
            call(**{kw: value})


def readme_exceptions():
    """(class, raised when, example) of the README's table of exceptions."""
    text = (REPO / "README.md").read_text()
    head = "| exception class | raised when | example call |"
    assert head in text, "README.md: the table of exceptions"
    rows = []
    for line in text.split(head, 1)[1].splitlines()[2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip() for c in line.strip("|").split(" | ")]
        classes = re.findall(r"`([\w.]+)`", cells[0])
        example = re.match(r"`([^`]+)`(.*)", cells[2])
        rows.append((classes, example.group(1), example.group(2).strip()))
    return rows


def test_the_readme_table_of_exceptions_holds():
    rows = readme_exceptions()
    promised = {c for classes, _, _ in rows for c in classes}
    assert {"ValueError", "TypeError", "FileNotFoundError", "tiltnoise.InputFileError",
            "MemoryError", "KeyboardInterrupt"} <= promised
    for classes, example, condition in rows:
        names = {c.rsplit(".", 1)[-1] for c in classes}
        if "ulimit" in condition:
            out, rc, err = run_limited(f"import tiltnoise\n{example}", limit="mapped + (768 << 20)")
            assert rc == 0, err[-500:]
            assert out.split(":")[0] in names, (example, out)
            continue
        if "interrupted" in condition:
            child = textwrap.dedent(f"""
                import os, signal, threading
                import numpy as np, tiltnoise
                threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
                try:
                    {example}
                    print("finished")
                except BaseException as e:
                    print(type(e).__name__)
            """)
            done = subprocess.run([sys.executable, "-c", child], capture_output=True,
                                  text=True, timeout=120, cwd=REPO)
            assert done.stdout.strip() in names, (example, done.stdout, done.stderr[-300:])
            continue
        cwd = os.getcwd()
        os.chdir(REPO)
        try:
            eval(example, {"tiltnoise": tiltnoise, "np": np})
        except BaseException as e:  # noqa: BLE001 - PanicException is a BaseException
            assert any(c.__name__ in names for c in type(e).__mro__), (example, repr(e))
        else:
            pytest.fail(f"README.md: {example} raised nothing, the table says {classes}")
        finally:
            os.chdir(cwd)


def readme_input_keywords():
    """The keywords that name input files, as the README's FileNotFoundError row lists them."""
    for classes, _, _ in readme_exceptions():
        if classes == ["FileNotFoundError"]:
            break
    text = (REPO / "README.md").read_text()
    row = next(line for line in text.splitlines() if line.startswith("| `FileNotFoundError` |"))
    listed = re.search(r"an input file of any call \(([^)]*)\)", row).group(1)
    return set(re.findall(r"`([\w.]+)`", listed))


@pytest.fixture(scope="module")
def input_file_calls(tmp_path_factory):
    """{keyword: [call(path) for each call that reads an input file named by it]}, every other
    argument valid."""
    d = tmp_path_factory.mktemp("inputs")
    tilt, measured = write_subtract_records(d, 4096)
    model = tiltnoise.Model()
    series = {"theta_t": np.random.default_rng(2).normal(0, 1e-8, 2048)}
    return {
        "path": [lambda p: tiltnoise.budget_from_file(p)],
        "tilt": [lambda p: tiltnoise.coherence(p, measured),
                 lambda p: tiltnoise.subtract(p, measured)],
        "measured": [lambda p: model.fit(measured=p),
                     lambda p: tiltnoise.visibility(p),
                     lambda p: tiltnoise.budget(series, 1.0, measured=p),
                     lambda p: tiltnoise.budget_from_file(LAB_TILT, measured=p),
                     lambda p: tiltnoise.coherence(tilt, p),
                     lambda p: tiltnoise.subtract(tilt, p)],
        "visibility": [lambda p: model.fit(visibility=p)],
        "colocated": [lambda p: tiltnoise.subtract(tilt, measured, colocated=p)],
        "readout": [lambda p: tiltnoise.budget(series, 1.0, readout={"X": p}),
                    lambda p: tiltnoise.budget_from_file(LAB_TILT, readout={"X": p})],
        "term": [lambda p: tiltnoise.budget(series, 1.0, term={"t": ("phi", p)})],
        "witness_noise": [lambda p: tiltnoise.budget(series, 1.0, witness_noise={"theta_t": p}),
                          lambda p: tiltnoise.subtract(tilt, measured,
                                                       witness_noise={"theta_t": p})],
        "Params.from_toml": [lambda p: tiltnoise.Params.from_toml(pathlib.Path(p))],
    }


def test_the_readme_lists_every_input_file_keyword(input_file_calls):
    assert readme_input_keywords() == set(input_file_calls)
    # Every path keyword of the stubs but a save's output is one of them.
    paths = {kw for name, kinds in scalar_keywords().items() for kw, kind in kinds.items()
             if kind == "path" and not name.endswith(("save", "save_methods"))}
    paths |= {kw for kinds in list_keywords().values() for kw, k in kinds.items()
              if k == "paths"}
    assert paths - {"source"} <= set(input_file_calls), paths


def file_cases():
    return sorted(readme_input_keywords())


@pytest.mark.parametrize("kw", file_cases())
def test_a_missing_input_file_is_a_file_not_found_error_in_every_call(input_file_calls, kw,
                                                                      tmp_path):
    missing = tmp_path / "missing.csv"
    for call in input_file_calls[kw]:
        with pytest.raises(FileNotFoundError, match="missing.csv"):
            call(str(missing))


@pytest.mark.parametrize("kw", file_cases())
def test_a_directory_given_as_an_input_file_is_an_is_a_directory_error(input_file_calls, kw,
                                                                       tmp_path):
    directory = tmp_path / "records.csv"
    directory.mkdir()
    for call in input_file_calls[kw]:
        with pytest.raises(IsADirectoryError, match="records.csv"):
            call(str(directory))


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads a file of mode 000")
@pytest.mark.parametrize("kw", file_cases())
def test_an_unreadable_input_file_is_a_permission_error(input_file_calls, kw, tmp_path):
    locked = tmp_path / "locked.csv"
    locked.write_text("frequency_hz,X\n1,1\n")
    locked.chmod(0)
    for call in input_file_calls[kw]:
        with pytest.raises(PermissionError, match="locked.csv"):
            call(str(locked))


@pytest.mark.parametrize("kw", file_cases())
def test_a_text_input_that_is_not_utf8_is_an_input_file_error(input_file_calls, kw, tmp_path):
    """Read, but not valid: `InputFileError`, never a bare OSError."""
    garbled = tmp_path / "garbled.csv"
    garbled.write_bytes(b"frequency_hz,X\n\xff\xfe,\x80\n")
    for call in input_file_calls[kw]:
        with pytest.raises(tiltnoise.InputFileError, match="garbled.csv"):
            call(str(garbled))


@pytest.fixture(scope="module")
def saved_inputs(tmp_path_factory):
    """(result, input file, the keyword that named it) of each call that reads a file."""
    d = tmp_path_factory.mktemp("saved")
    tilt, measured = write_subtract_records(d, 4096)
    series = {"theta_t": np.random.default_rng(4).normal(0, 1e-8, 2048)}
    asd = d / "readout.csv"
    asd.write_text("frequency_hz,X\n1e-4,1e-9\n10,1e-9\n")
    toml = d / "params.csv"  # a parameter file by any name, so that a budget file may be saved
    toml.write_text(tiltnoise.Params().to_toml())
    from_file = tiltnoise.Params.from_toml(toml)
    return [
        (tiltnoise.budget_from_file(LAB_TILT, nperseg=256), LAB_TILT, "path"),
        (tiltnoise.coherence(tilt, measured, nperseg=512), tilt, "tilt"),
        (tiltnoise.subtract(tilt, measured, nperseg=512), tilt, "tilt"),
        (tiltnoise.budget(series, 1.0, nperseg=256, measured=asd), asd, "measured"),
        (tiltnoise.budget(series, 1.0, nperseg=256, readout={"X": asd}), asd, "readout"),
        (tiltnoise.budget(series, 1.0, nperseg=256, params=from_file), toml,
         "Params.from_toml"),
    ]


def test_a_save_onto_an_input_names_it_by_its_own_keyword(saved_inputs):
    """Each call names the file by the keyword that call took it with: the tilt record is
    `path=` in budget_from_file and `tilt=` in coherence and subtract."""
    for result, path, kw in saved_inputs:
        said = "(Params.from_toml)" if kw == "Params.from_toml" else f"({kw}=)"
        with pytest.raises(OSError, match=rf"it is the \w[\w ]* input {re.escape(said)} "
                                          rf".*{re.escape(path.name)}; an output must "
                                          r"not replace an input of the run"
                           if kw != "Params.from_toml" else
                           rf"it is the parameter file {re.escape(said)} "
                           rf".*{re.escape(path.name)}; an output must not replace"):
            result.save(path)


# Scalar and mapping keywords: every public call of the stubs, each keyword's kind read from
# its annotation, so that a new call or keyword is walked without being listed here.

def scalar_kind(annotation):
    """`number`, `integer`, `flag`, `name`, `path`, `mapping` or `params` of a scalar or
    mapping annotation (optional or not), else None (lists, arrays, unions of kinds)."""
    text = ast.unparse(annotation)
    inner = re.fullmatch(r"Optional\[(.*)\]", text)
    text = inner.group(1) if inner else text
    if text.startswith(("Mapping[", "Optional[Mapping[")):
        return "mapping"
    if re.fullmatch(r"Literal\[('[^']*'(, )?)+\]", text):
        return "name"
    return {"float": "number", "int": "integer", "bool": "flag", "str": "name",
            "_Path": "path", "Union[str, os.PathLike[str]]": "path", "Params": "params",
            "Union[Params, Model, None]": "params"}.get(text)


# Keywords of public calls whose annotation is none of those kinds, each converted by a rule
# of its own (checked elsewhere): a list keyword (the walk above), an array, or a union.
NOT_SCALAR = {"freq_hz", "x", "y", "tilt", "freq", "detrend", "init", "init_rate", "out"}


def scalar_keywords():
    """{call: {keyword: kind}} of the stubs' public functions, constructors and methods."""
    found = {}
    tree = ast.parse(STUBS.read_text())

    def visit(node, prefix):
        for item in node.body:
            if isinstance(item, ast.ClassDef) and not item.name.startswith("_"):
                visit(item, f"{item.name}.")
            elif isinstance(item, ast.FunctionDef) and (
                    not item.name.startswith("_") or item.name in ("__init__", "__new__")):
                name = prefix.rstrip(".") if item.name.startswith("__") else prefix + item.name
                if any(isinstance(d, ast.Name) and d.id == "property"
                       for d in item.decorator_list):
                    continue
                kinds = {}
                for a in item.args.args + item.args.kwonlyargs:
                    if a.annotation is None or a.arg in ("self", "cls"):
                        continue
                    kind = scalar_kind(a.annotation)
                    if kind is None:
                        assert a.arg in NOT_SCALAR or kind_of(a.annotation), (name, a.arg)
                    else:
                        kinds[a.arg] = kind
                if kinds:
                    found[name] = kinds
    visit(tree, "")
    return found


@pytest.fixture(scope="module")
def scalar_calls(tmp_path_factory):
    """(function, arguments) of each public call with scalar or mapping keywords: the call with
    `{**arguments, kw: value}` gets `kw` by keyword."""
    d = tmp_path_factory.mktemp("scalars")
    tilt, measured = write_subtract_records(d, 4096)
    model = tiltnoise.Model()
    rng = np.random.default_rng(5)
    series = {"theta_t": rng.normal(0, 1e-8, 2048), "eta_t": rng.normal(0, 1e-8, 2048)}
    b = tiltnoise.budget(series, 1.0, nperseg=256)
    sim = model.simulate(4000.0, 0.5, seed=2)
    record = d / "free.h5"
    sim.save(record)
    x = rng.normal(size=1024)
    toml = d / "p.toml"
    toml.write_text(tiltnoise.Params().to_toml())
    results = {"Simulation": sim, "MonteCarlo": model.monte_carlo(samples=20),
               "Fit": model.fit(), "Visibilities": tiltnoise.visibility(record),
               "Coherence": tiltnoise.coherence(tilt, measured, nperseg=512),
               "Subtraction": tiltnoise.subtract(tilt, measured, nperseg=512)}
    grid = [1e-3, 1.0]
    calls = {
        "welch": (tiltnoise.welch, {"x": x}),
        "csd": (tiltnoise.csd, {"x": x, "y": x}),
        "budget": (tiltnoise.budget, {"tilt": series, "fs": 1.0, "nperseg": 256}),
        "budget_from_file": (tiltnoise.budget_from_file, {"path": LAB_TILT, "nperseg": 256}),
        "coherence": (tiltnoise.coherence, {"tilt": tilt, "measured": measured,
                                            "nperseg": 512}),
        "subtract": (tiltnoise.subtract, {"tilt": tilt, "measured": measured, "nperseg": 512}),
        "visibility": (tiltnoise.visibility, {"measured": record}),
        "Params.from_toml": (tiltnoise.Params.from_toml, {"source": toml}),
        "Params.set": (tiltnoise.Params().set, {"key": "length.h_m", "value": 1.5}),
        "Params.update": (tiltnoise.Params().update, {"values": {"length.h_m": 1.5}}),
        "Params.get": (tiltnoise.Params().get, {"key": "length.h_m"}),
        "Model": (tiltnoise.Model, {}),
        "Model.transfer": (model.transfer, {"freq_hz": grid}),
        "Model.transfer_function": (model.transfer_function, {"freq_hz": grid}),
        "Model.explain": (model.explain, {"freq_hz": grid}),
        "Model.monte_carlo": (model.monte_carlo, {"samples": 20}),
        "Model.save_methods": (model.save_methods, {"path": d / "m.svg", "freq_hz": grid}),
        "Model.fit": (model.fit, {}),
        "Model.simulate": (model.simulate, {"duration": 200.0, "step": 1.0}),
        "Budget.psd": (b.psd, {"observable": "X"}),
        "Budget.asd": (b.asd, {"observable": "X"}),
        "Budget.to_csv": (b.to_csv, {}),
        "Budget.save": (b.save, {"path": d / "b.csv"}),
    }
    for name, result in results.items():
        calls[f"{name}.save"] = (result.save, {"path": d / f"{name}.h5"})
    return calls


def test_the_stubs_scalar_keywords_are_those_walked_here(scalar_calls):
    keywords = scalar_keywords()
    assert set(keywords) == set(scalar_calls), "a public call with scalar keywords needs one here"
    # The keywords of the report are among them, of their kind.
    assert keywords["subtract"]["holdout"] == "number"
    assert keywords["welch"]["nperseg"] == "integer"
    assert keywords["Model.monte_carlo"]["seed"] == "integer"
    assert keywords["Model.fit"]["prior"] == "flag"
    assert keywords["Model.fit"]["visibility"] == "path"
    assert keywords["budget_from_file"]["scale"] == "mapping"


# Values of the wrong type for each kind, and what the message says is expected.
WRONG = {"number": ["0.25", b"1", True, [0.25], object()],
         "integer": [4096.0, "4096", True, [1], object()],
         "flag": [1, "True", [True], object()],
         "name": [1, b"X", ["X"], object()],
         "path": [1, b"a.csv", ["a.csv"], object()],
         "mapping": [[("X", 1.0)], "X=1", 1.0, object()],
         "params": [1, "length.h_m=1.5", object()]}
EXPECTED = {"number": "a number (int or float)", "integer": "an integer",
            "flag": "a bool (True or False)", "name": "a str",
            "path": "a path (str or os.PathLike)", "mapping": "a dict", "params": "a tiltnoise.Params"}


def scalar_cases():
    return [(name, kw, kind) for name, kinds in sorted(scalar_keywords().items())
            for kw, kind in sorted(kinds.items())]


@pytest.mark.parametrize("name, kw, kind", scalar_cases())
def test_a_scalar_keyword_of_the_wrong_type_is_a_type_error_naming_it(
        scalar_calls, name, kw, kind):
    call, given = scalar_calls[name]
    default = inspect.signature(call).parameters[kw].default
    for value in WRONG[kind]:
        with pytest.raises(TypeError) as e:
            call(**{**given, kw: value})
        message = str(e.value)
        assert message.startswith(f"{kw}={value!r}"[:40]), (name, kw, message)
        assert f": expected {EXPECTED[kind]}" in message, (name, kw, message)
        assert message.endswith(f", got {type(value).__name__}") or "; " in message, message
        if default is None:
            assert " or None" in message, (name, kw, message)


@pytest.mark.parametrize("name, kw", [(n, k) for n, k, kind in scalar_cases()
                                      if kind == "integer"])
def test_an_integer_keyword_out_of_range_is_a_value_error_naming_it(scalar_calls, name, kw):
    call, given = scalar_calls[name]
    for value in (-1, 2**64, np.int64(-3)):
        with pytest.raises(ValueError, match=rf"^{kw}={re.escape(repr(value))}: expected an "
                                              r"integer from 0 to \d+"):
            call(**{**given, kw: value})


@pytest.mark.parametrize("name, kw", [(n, k) for n, k, kind in scalar_cases()
                                      if kind == "number"])
def test_a_number_keyword_that_is_not_finite_is_a_value_error_naming_it(scalar_calls, name, kw):
    """A NaN is a number of the right type and never an allowed value: the call's own check
    refuses it, naming the keyword (or, for a parameter, its key)."""
    call, given = scalar_calls[name]
    named = given.get("key", kw)
    for value in (float("nan"), np.float64("nan")):
        with pytest.raises(ValueError, match=re.escape(named)):
            call(**{**given, kw: value})


@pytest.mark.parametrize("name", sorted(scalar_keywords()))
def test_a_scalar_keyword_takes_numpy_scalars_and_path_likes_as_python_values(scalar_calls, name):
    """The conversions are of the value, not of its Python type: a NumPy scalar is the number
    it holds and a path given as str the same path, as in the one-item lists above."""
    call, given = scalar_calls[name]
    kinds = scalar_keywords()[name]
    alike = {float: np.float64, int: np.int64, pathlib.PosixPath: str}
    walked = [kw for kw, value in given.items() if kw in kinds and type(value) in alike]
    for kw in walked:
        value = given[kw]
        other = alike[type(value)](value)
        assert outcome(call, **{**given, kw: other}) == outcome(call, **given), (name, kw)


def test_an_entry_of_the_wrong_type_in_a_mapping_is_a_type_error_naming_the_keyword(tmp_path):
    """A mapping keyword's key must be a str and its value of the keyword's kind: anything
    else is a TypeError naming the keyword and the entry, as for a list's item."""
    series = {"theta_t": np.zeros(2048)}
    model = tiltnoise.Model()
    path = str(tmp_path / "asd.csv")
    cases = [
        ("readout", lambda v: tiltnoise.budget(series, 1.0, readout=v),
         [{"X": object()}, {1: 1e-9}, {"X": b"asd.csv"}]),
        ("term", lambda v: tiltnoise.budget(series, 1.0, term=v),
         [{"t": "phi"}, {"t": ("phi", 3)}, {"t": (3, path)}, {2: ("phi", path)}]),
        ("witness_noise", lambda v: tiltnoise.budget(series, 1.0, witness_noise=v),
         [{"theta_t": object()}, {"theta_t": (1e-9, "0.1")}, {None: 1e-9}]),
        ("units", lambda v: tiltnoise.budget(series, 1.0, units=v), [{"theta_t": 1}]),
        ("scale", lambda v: tiltnoise.budget_from_file(LAB_TILT, scale=v), [{"E": "1"}]),
        ("colocated_ratio", lambda v: tiltnoise.subtract(LAB_TILT, path, colocated_ratio=v),
         [{"eta_t": "2"}]),
        ("readout", lambda v: model.simulate(100.0, 1.0, readout=v), [{"X": "9e-9"}]),
        ("init", lambda v: model.simulate(100.0, 1.0, init=v), [{"theta_a": "1e-5"}, 3]),
        ("values", lambda v: tiltnoise.Params().update(v), [{"length.h_m": "1.5"}, [1]]),
        ("tilt", lambda v: tiltnoise.budget(v, 1.0), [{1: np.zeros(2048)}]),
    ]
    for kw, call, values in cases:
        for value in values:
            with pytest.raises(TypeError, match=rf"^{kw}=.*: expected a dict ") as e:
                call(value)
            assert ("; a key is" in str(e.value) or "; the value of" in str(e.value)
                    or str(e.value).endswith(f", got {type(value).__name__}")), str(e.value)
