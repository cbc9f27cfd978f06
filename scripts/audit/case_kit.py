"""The kit the case builders of the hostile-input audit share: the repository inputs, the case
timeouts, the case type and its constructor `C`, and the writers of input files and scratch
directory setups.

Imported by hostile_cli.py (the runner and the first categories) and surfaces.py (the surfaces
added since); it imports neither. See README.md.
"""
from __future__ import annotations

import os
import shutil
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import h5py
import numpy as np

REPO = Path(__file__).resolve().parents[2]
LAB_H5 = str(REPO / "tilt_data" / "lab_tilt_24h.h5")
PETERSON = str(REPO / "tilt_data" / "peterson_tilt_asd.csv")
DAMPED = str(REPO / "examples" / "damped.toml")

SHORT_TIMEOUT = 10.0
QUICK_TIMEOUT = 4.0  # inputs that must be handled quickly (endless devices, 100 MB of spaces)


class ArgFromFile(str):
    """An argument whose value is read from a file the setup wrote (see execute())."""


@dataclass
class Ctx:
    """What a case's setup sees: its scratch directory and the binary under test."""

    dir: Path
    bin: str
    finalizers: list = field(default_factory=list)


@dataclass
class Case:
    cat: str
    name: str
    args: list
    setup: Callable[[Ctx], None] | None = None
    desc: str = ""
    timeout: float | None = None
    must_fail: bool = False
    must_succeed: bool = False
    huge: bool = False
    stdin: str = "devnull"  # devnull | closed
    stdout: str = "pipe"  # pipe | closed | devfull | close_after_1 | broken_pipe
    stderr: str = "pipe"  # pipe | closed | devfull
    sig: int | None = None  # signal to send
    sig_when: object = "tempfile"  # "tempfile" (a temporary output appears) or seconds
    artifacts: list = field(default_factory=list)  # files (relative to the scratch dir) to keep
    serial: bool = False
    culprit: str | None = None  # regex the one-line error must match (what it must name)
    python: str | None = None  # a Python snippet run by py_case.py instead of the binary
    # The culprit is also wanted when a case that may fail or succeed fails (e.g. a value that
    # may be refused but must then be named).
    culprit_if_fails: bool = False
    # A must_fail case whose option names something the run does not have: exit 0 counts as
    # `ignored option` (an accepted bad input) rather than `accepted bad`.
    ignored_option: bool = False
    # Regex of JSON keys whose `null` values (stdout, written .json) count as non-finite.
    null_keys: str | None = None
    # Regex: only non-finite evidence matching it counts (outputs with documented NaN elsewhere).
    nonfinite_only: str | None = None


def C(cat, name, args, **kw) -> Case:
    """A case; an option value that starts with '-' is joined to its option (`--x=-1`) so that
    it reaches the program's validation instead of the argument parser's."""
    out: list = []
    for a in args:
        if isinstance(a, ArgFromFile):
            out.append(a)
            continue
        a = str(a)
        if (out and a.startswith("-") and len(a) > 1 and not a.startswith("--")
                and isinstance(out[-1], str) and out[-1].startswith("--") and "=" not in out[-1]):
            out[-1] = f"{out[-1]}={a}"
        else:
            out.append(a)
    return Case(cat, name, out, **kw)


# --------------------------------------------------------------------------------------------
# Helpers to write inputs


def write(path: Path, data) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    path.write_bytes(data)
    return path


def series_lines(n=4096, fs=1.0, seed=11, header="time_s,theta_t,eta_t", scale=1e-9):
    rng = np.random.default_rng(seed)
    a = scale * rng.standard_normal(n)
    b = scale * rng.standard_normal(n)
    dt = 1.0 / fs
    rows = [f"{i * dt!r},{float(a[i])!r},{float(b[i])!r}" for i in range(n)]
    return [header] + rows


def spectrum_lines(n=60, header="freq_hz,theta_t,eta_t"):
    f = np.logspace(-5, 1, n)
    asd = 1e-9 * (f / 1e-3) ** -1.0
    f, asd = f.tolist(), asd.tolist()
    return [header] + [f"{f[i]!r},{asd[i]!r},{0.7 * asd[i]!r}" for i in range(n)]


def measured_lines(n=60, header="freq_hz,X,phi,phi_a"):
    f = np.logspace(-4, 0, n)
    x = 1e-8 * (f / 1e-3) ** -1.0
    f, x = f.tolist(), x.tolist()
    return [header] + [f"{f[i]!r},{x[i]!r},{1e-9 * x[i]!r},{1e-9 * x[i]!r}" for i in range(n)]


def joined(lines, eol="\n") -> str:
    return eol.join(lines) + eol


def h5_series(path: Path, n=4096, fs=1.0, channels=("theta_t", "eta_t"), edit=None, seed=7,
              data=None):
    path.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    with h5py.File(path, "w") as f:
        f.attrs["sample_rate_hz"] = fs
        for ch in channels:
            d = f.create_dataset(ch, data=1e-9 * rng.standard_normal(n) if data is None else data)
            d.attrs["units"] = "rad"
        if edit:
            edit(f)
    return path


def h5_spectra(path: Path, n=60, edit=None, csd=False):
    path.parent.mkdir(parents=True, exist_ok=True)
    f_hz = np.logspace(-5, 1, n)
    asd = 1e-9 * (f_hz / 1e-3) ** -1.0
    with h5py.File(path, "w") as f:
        f.attrs["schema"] = "tiltnoise.tilt_spectra"
        f.attrs["axes"] = np.array(["theta_t", "eta_t"], dtype=h5py.string_dtype())
        f.create_dataset("frequency_hz", data=f_hz)
        if csd:
            s = np.zeros((n, 2, 2), dtype=np.complex128)
            s[:, 0, 0] = asd ** 2
            s[:, 1, 1] = 0.5 * asd ** 2
            c = 0.3 * np.sqrt(s[:, 0, 0].real * s[:, 1, 1].real)
            s[:, 0, 1] = c
            s[:, 1, 0] = c
            f.create_dataset("csd", data=s)
        else:
            f.create_dataset("asd", data=np.stack([asd, 0.7 * asd], axis=1))
        if edit:
            edit(f)
    return path


def h5_measured(path: Path, n=86400, fs=1.0, edit=None, names=("X", "phi", "phi_a")):
    path.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(5)
    with h5py.File(path, "w") as f:
        f.attrs["schema"] = "tiltnoise.observable_series"
        f.attrs["sample_rate_hz"] = fs
        for name in names:
            d = f.create_dataset(name, data=(1e-8 if name == "X" else 1e-12)
                                 * rng.standard_normal(n))
            d.attrs["units"] = "m" if name in ("X", "Y", "Z") else "rad"
        if edit:
            edit(f)
    return path


def replace_dataset(f, name, data=None, **kw):
    if name in f:
        del f[name]
    if data is None:
        return f.create_dataset(name, **kw)
    return f.create_dataset(name, data=data, **kw)


def fifo_setup(name: str, content: bytes):
    """A FIFO in the scratch directory, fed `content` once by a writer thread."""

    def setup(ctx: Ctx):
        p = ctx.dir / name
        os.mkfifo(p)

        def writer():
            try:
                fd = os.open(p, os.O_WRONLY)
                try:
                    view = memoryview(content)
                    while view:
                        k = os.write(fd, view[:65536])
                        view = view[k:]
                finally:
                    os.close(fd)
            except OSError:
                pass

        t = threading.Thread(target=writer, daemon=True)
        t.start()

        def finish():
            if t.is_alive():
                try:
                    fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK)
                    time.sleep(0.05)
                    os.close(fd)
                except OSError:
                    pass
            t.join(2)

        ctx.finalizers.append(finish)

    return setup


def copy_setup(*pairs):
    """Copies (source, name) pairs into the scratch directory; also makes dirs ending in '/'."""

    def setup(ctx: Ctx):
        for src, name in pairs:
            dst = ctx.dir / name
            if src is None:
                dst.mkdir(parents=True, exist_ok=True)
            else:
                dst.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(src, dst)

    return setup


def chain(*setups):
    def setup(ctx):
        for s in setups:
            if s:
                s(ctx)

    return setup
