"""The type stubs (tiltnoise/_tiltnoise.pyi) describe the extension module as it is: every
public name and member on both sides, and, with mypy installed, every signature
(`mypy.stubtest`)."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import tiltnoise
from tiltnoise import _tiltnoise

STUB = Path(tiltnoise.__file__).with_name("_tiltnoise.pyi")


def stub_names():
    """({name: set of member names (classes) or None} of the stub's top level, its __all__)."""
    tree = ast.parse(STUB.read_text())
    names, all_ = {}, None
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[node.name] = {
                n.name if isinstance(n, ast.FunctionDef) else n.target.id
                for n in node.body
                if isinstance(n, (ast.FunctionDef, ast.AnnAssign))
            }
        elif isinstance(node, ast.FunctionDef):
            names[node.name] = None
        elif isinstance(node, ast.AnnAssign):
            names[node.target.id] = None
        elif isinstance(node, ast.Assign) and node.targets[0].id == "__all__":
            all_ = ast.literal_eval(node.value)
    return names, all_


def test_stub_names_equal_the_modules():
    stub, stub_all = stub_names()
    runtime = set(_tiltnoise.__all__)
    assert set(stub_all) == runtime
    assert runtime <= set(stub)
    # The package adds its pure-Python classes to the extension's names.
    python_side = {"TransferFunction"}
    assert set(tiltnoise.__all__) == {n for n in runtime if not n.startswith("_p")} | python_side
    for name in runtime:
        members = stub[name]
        if members is None or name == "InputFileError":
            continue
        public = {m for m in dir(getattr(_tiltnoise, name)) if not m.startswith("_")}
        assert public == {m for m in members if not m.startswith("_")}, name


def test_stubtest_passes():
    pytest.importorskip("mypy")
    done = subprocess.run(
        [sys.executable, "-m", "mypy.stubtest", "tiltnoise._tiltnoise"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout + done.stderr
