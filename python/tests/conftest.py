"""Shared fixtures: the repository's files and the command-line program to compare with."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def without_command_line(csv_text):
    """A CSV written by tiltnoise without its `# created_by:` line: the command line that
    wrote it, which differs between this process and the command line's."""
    return "".join(l for l in csv_text.splitlines(keepends=True)
                   if not l.startswith("# created_by:"))
LAB_TILT = REPO / "tilt_data" / "lab_tilt_24h.h5"


def _cli():
    """The `tiltnoise` binary: $TILTNOISE_BIN (which must then exist: CI sets it so that the
    comparisons cannot be skipped), else target/release of this checkout (or of
    $CARGO_TARGET_DIR), else one on PATH."""
    given = os.environ.get("TILTNOISE_BIN")
    if given:
        if not (Path(given).is_file() and os.access(given, os.X_OK)):
            raise pytest.UsageError(f"TILTNOISE_BIN={given} is not an executable file")
        return given
    candidates = []
    for target in (os.environ.get("CARGO_TARGET_DIR"), REPO / "target"):
        if target:
            candidates.append(Path(target) / "release" / "tiltnoise")
    candidates.append(shutil.which("tiltnoise"))
    for c in candidates:
        if c and Path(c).is_file() and os.access(c, os.X_OK):
            return str(c)
    return None


@pytest.fixture(scope="session")
def cli():
    """Runs the command line: `cli(*args)` returns its stdout. Skips the test without the
    binary (build it with `cargo build --release`, or set TILTNOISE_BIN)."""
    exe = _cli()
    if exe is None:
        pytest.skip("no tiltnoise binary (cargo build --release, or set TILTNOISE_BIN)")

    def run(*args, cwd=None):
        done = subprocess.run(
            [exe, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600
        )
        assert done.returncode == 0, f"tiltnoise {' '.join(map(str, args))}: {done.stderr}"
        return done.stdout

    return run


@pytest.fixture(scope="session")
def cli_error(cli):
    """Runs the command line where it must fail: `cli_error(*args)` returns its one-line error
    message without the `tiltnoise: error: ` prefix, after checking the exit code 2."""
    exe = _cli()

    def run(*args, cwd=None):
        done = subprocess.run(
            [exe, *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=600
        )
        assert done.returncode == 2, f"tiltnoise {' '.join(map(str, args))}: {done.returncode}"
        lines = done.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("tiltnoise: error: "), done.stderr
        return lines[0][len("tiltnoise: error: "):]

    return run
