"""A Rust panic is a Python exception (pyo3's PanicException, a BaseException) and never ends
the interpreter: raised while holding the GIL, with the GIL released, or in a worker thread of
a computation. Each case runs in a child interpreter, which must go on after the exception."""

import subprocess
import sys

import pytest

CHILD = """
import tiltnoise._tiltnoise as t
try:
    t._panic_for_tests({where!r})
except BaseException as e:
    print(type(e).__name__, "|", e)
import numpy as np, tiltnoise
print("alive", tiltnoise.Model().transfer(1e-5, inputs="eta_t", outputs="X")[0, 0, 0].real)
"""


@pytest.mark.parametrize("where", ["here", "detached", "thread"])
def test_a_panic_is_an_exception_and_the_interpreter_goes_on(where):
    done = subprocess.run(
        [sys.executable, "-c", CHILD.format(where=where)], capture_output=True, text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("PanicException |"), done.stdout
    assert lines[1].startswith("alive -1.66"), done.stdout
