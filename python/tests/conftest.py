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
# The start time both records of a subtraction state.
SUBTRACT_START = "2024-03-20T00:00:00Z"


def write_subtract_records(directory, samples):
    """A witness and a measured record for `subtract`, in `directory`: the first `samples` of
    the lab tilt (HDF5, 1 Hz) and X of the pendulum driven by it through the model (circularly,
    in the frequency domain) plus white readout noise of 1e-9 m (CSV), both stating
    SUBTRACT_START. Returns the paths (tilt, measured)."""
    import numpy as np
    import tiltnoise
    h5py = pytest.importorskip("h5py")
    with h5py.File(LAB_TILT, "r") as f:
        theta, eta = f["theta_t"][:samples], f["eta_t"][:samples]
        fs = float(f.attrs["sample_rate_hz"])
    tilt = Path(directory) / "tilt.h5"
    with h5py.File(tilt, "w") as f:
        f["theta_t"], f["eta_t"] = theta, eta
        f.attrs.update(sample_rate_hz=fs, schema="tiltnoise.tilt_series", schema_version=1,
                       start_time=SUBTRACT_START)
    n = len(eta)
    freqs = np.fft.rfftfreq(n, 1 / fs)
    h = tiltnoise.Model().transfer(freqs[1:], inputs=["theta_t", "eta_t"], outputs="X")
    spectrum = np.zeros(len(freqs), complex)
    spectrum[1:] = h[:, 0, 0] * np.fft.rfft(theta)[1:] + h[:, 0, 1] * np.fft.rfft(eta)[1:]
    x = np.fft.irfft(spectrum, n) + np.random.default_rng(11).normal(0, 1e-9, n)
    measured = Path(directory) / "pendulum.csv"
    t = np.arange(n) / fs
    measured.write_text(f"# start_time: {SUBTRACT_START}\ntime_s,X\n"
                        + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), x.tolist())))
    return tilt, measured


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
