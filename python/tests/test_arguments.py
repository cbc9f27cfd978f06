"""Keyword arguments are converted by one rule in every call, and every call raises the
exception classes the README's table promises.

The list keywords are found in the type stubs (every parameter of a public call annotated as a
sequence of names, paths or numbers, or as a pair of numbers), so that a new call or keyword is
checked without being listed here: a single str (a path for a path list, a number for a number
list) is a one-item list, giving what the one-item list gives; a pair is two numbers of any
kind (NumPy scalars, an array); any other type is a TypeError naming the keyword."""

import ast
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


def test_every_missing_input_file_is_a_file_not_found_error(tmp_path):
    """Each keyword that names an input file, given a file that does not exist."""
    missing = str(tmp_path / "missing.csv")
    model = tiltnoise.Model()
    series = {"theta_t": np.zeros(2048)}
    for call in (
        lambda: model.fit(visibility=missing),
        lambda: model.fit(measured=missing),
        lambda: tiltnoise.Params.from_toml(pathlib.Path(missing)),
        lambda: tiltnoise.visibility(missing),
        lambda: tiltnoise.budget_from_file(missing),
        lambda: tiltnoise.budget(series, 1.0, measured=missing),
        lambda: tiltnoise.budget(series, 1.0, readout={"X": missing}),
        lambda: tiltnoise.budget(series, 1.0, term={"t": ("phi", missing)}),
        lambda: tiltnoise.budget(series, 1.0, witness_noise={"theta_t": missing}),
        lambda: tiltnoise.coherence(missing, missing),
        lambda: tiltnoise.subtract(missing, missing),
        lambda: tiltnoise.subtract(LAB_TILT, missing),
    ):
        with pytest.raises(FileNotFoundError, match="missing.csv"):
            call()


def test_a_save_onto_an_input_names_it_plainly(tmp_path):
    b = tiltnoise.budget_from_file(LAB_TILT, nperseg=256)
    with pytest.raises(OSError, match=r"it is the tilt input .*lab_tilt_24h\.h5; an output must "
                                      r"not replace an input of the run"):
        b.save(LAB_TILT)
