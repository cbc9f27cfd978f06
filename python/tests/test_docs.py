"""The Python examples of README.md and docs/*.md run as written.

Every ```python block runs in a fresh directory that holds the repository's committed inputs
(`tilt_data/`, `examples/`). A block that reads files the command line writes says so on the
line before it, `<!-- docs-run: after `tiltnoise ARGS` -->` (one or more such commands, joined
by ` && `): they run first, with the built binary. `<!-- docs-run: skip (why) -->` skips a
block. The command blocks run in tests/it/docs_run.rs, under `cargo test`, without Python.
"""

import os
import runpy
import shlex
from pathlib import Path

import pytest

from conftest import REPO

MARKER = "<!-- docs-run:"


def python_blocks():
    """(place, code, marker) of every ```python block, the marker without its brackets."""
    docs = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]
    for doc in docs:
        lines = doc.read_text(encoding="utf-8").splitlines()
        i = 0
        while i < len(lines):
            if lines[i].strip() != "```python":
                i += 1
                continue
            start = i
            i += 1
            while i < len(lines) and not lines[i].startswith("```"):
                i += 1
            before = lines[start - 1].strip() if start else ""
            marker = None
            if before.startswith(MARKER) and before.endswith("-->"):
                marker = before[len(MARKER):-3].strip()
            place = f"{doc.relative_to(REPO)}:{start + 1}"
            yield place, "\n".join(lines[start + 1:i]), marker
            i += 1


def setup_commands(marker):
    """The `tiltnoise ...` commands of an `after` marker, as argument lists."""
    if not marker or not marker.startswith("after `"):
        return []
    text = marker[len("after `"):marker.rindex("`")]
    commands = [shlex.split(c) for c in text.split(" && ")]
    for c in commands:
        assert c[0] == "tiltnoise", f"a setup command runs tiltnoise: {c}"
    return [c[1:] for c in commands]


BLOCKS = list(python_blocks())


def test_there_are_python_examples():
    assert BLOCKS, "no ```python block found in README.md or docs/*.md"


@pytest.mark.parametrize("place, code, marker", BLOCKS, ids=[b[0] for b in BLOCKS])
def test_python_block_runs(place, code, marker, tmp_path, request, monkeypatch):
    if marker and marker.startswith("skip"):
        pytest.skip(f"{place}: {marker[len('skip'):].strip()}")
    for inputs in ("tilt_data", "examples"):
        os.symlink(REPO / inputs, tmp_path / inputs)
    (tmp_path / "plots").mkdir()
    commands = setup_commands(marker)
    if commands:
        cli = request.getfixturevalue("cli")
        for args in commands:
            cli(*args, cwd=tmp_path)
    script = tmp_path / "block.py"
    script.write_text(code + "\n", encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    try:
        runpy.run_path(str(script), run_name="__main__")
    except ModuleNotFoundError as e:
        # Optional packages a block shows (pandas, gwpy) are not dependencies of tiltnoise.
        if e.name in ("pandas", "gwpy", "matplotlib"):
            pytest.skip(f"{place}: needs {e.name}, not installed")
        raise
