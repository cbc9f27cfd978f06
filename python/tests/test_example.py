"""examples/budget_matplotlib.py runs against the installed package and writes its figure (the
README's budget figure drawn with matplotlib)."""

import subprocess
import sys

import pytest

from conftest import REPO


def test_budget_example_writes_its_figure(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "budget.png"
    done = subprocess.run(
        [sys.executable, REPO / "examples" / "budget_matplotlib.py", out],
        capture_output=True, text=True, timeout=600,
    )
    assert done.returncode == 0, done.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.stat().st_size > 50_000
