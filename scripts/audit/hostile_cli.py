#!/usr/bin/env python3
"""Hostile-input audit of the `tiltnoise` command line.

Runs a few hundred scripted cases and a seeded mutation fuzz against one or more binaries and
classifies every outcome. It is a report, not a test: the exit code is 0 unless the audit itself
cannot run.

    python3 scripts/audit/hostile_cli.py --bin /work/before/tiltnoise \\
        --bin target/release/tiltnoise --fuzz-iterations 1000 --seed 1 \\
        --out /tmp/hostile-cli --json /tmp/hostile-cli/records.json

Needs Python 3.11 with numpy and h5py. See scripts/audit/README.md.

How a case runs
---------------
* Every case runs in a fresh scratch directory, which is its working directory and its output
  directory (`--save` paths are relative to it). Hostile input files that do not need to be in
  that directory are generated once per audit into `OUT/inputs/` and passed by absolute path;
  the repository's `tilt_data/lab_tilt_24h.h5`, `tilt_data/peterson_tilt_asd.csv` and
  `examples/damped.toml` are referenced by absolute path.
* The child gets `RLIMIT_AS` = 4 GiB (so an allocation blow-up aborts instead of eating the
  machine), no core dumps, its own session, `RUST_BACKTRACE=0` (panic messages are short and
  alike for every binary) and `LC_ALL=C`. stdin is /dev/null unless the case says otherwise.
* A case is killed (SIGKILL to its process group) after its timeout: 20 s by default (`--timeout`),
  10 s for fuzz cases and 1 GB sparse files, 4 s for inputs that must be handled quickly
  (/dev/zero, /dev/urandom, 100 MB of spaces, a 5 MB CSV with 100 000 columns).
* stdout is streamed and scanned as it arrives (only its first 64 kB is kept), stderr is kept up
  to 1 MB.
* Cases run on up to `--jobs` workers (default 2); the cases that send signals run one at a
  time at the end.

Per-case classification (flags; a case can have several)
---------------------------------------------------------
Let `rc` be the exit status. A run *fails* if it was killed by a signal, timed out, or exited
non-zero. A *controlled failure* is a failure that is none of crash, abort/oom, panic, hang.

crash       killed by a signal other than SIGABRT/SIGKILL (SIGSEGV, SIGBUS, SIGILL, SIGFPE,
            SIGXFSZ, ...), with no panic message. Not counted: the signal the case itself sent
            (process cases) and SIGPIPE when stdout is a pipe without reader (a tool that dies
            quietly of SIGPIPE there behaves like `cat`).
abort/oom   SIGABRT without a panic message, "memory allocation of ... failed" in stderr, or a
            SIGKILL the audit did not send (the kernel's OOM killer).
panic       exit code 101, or "panicked at" in stderr (also when the panic aborts).
hang        still running at the timeout (killed by the audit).
non-finite  exit 0, but a number written to stdout or to a new or changed file in the scratch
            directory is nan/inf (CSV/JSON/SVG/TOML/text: a token nan, inf, infinity in any case,
            optionally signed; HDF5: any non-finite element of a float or complex dataset or
            numeric attribute). For cases marked "huge" (inputs that make values near the
            overflow limit) a printed `0.000e0` also counts. Allowed by design and therefore not
            counted: the quality factor `inf` of an undamped mode (the Q column of `modes`,
            `"quality_factor": "inf"`), NaN in the `measured`/`residual` terms of a budget
            (documented as NaN outside the band the measured file covers; also the note
            "(NaN outside)"), and NaN in a fit's `fitted_sigma` (documented for a parameter on
            a bound). A case may name JSON keys whose `null` counts as non-finite
            (`null_keys`) and restrict the evidence to named values (`nonfinite_only`).
leftover    after a failing run, any file or directory in the scratch directory that was not
            there before; after any run, a new temporary-looking name (`*.tmp`, `.tmpXXXXXX`,
            the staging directory `.<name>.XXXXXX.tmp`, or the former `.<name>.XXXXXX[.<ext>]`).
multi-line  controlled failure whose stderr has more than one line.
silent      controlled failure with nothing on stderr.
exit!=2     controlled failure with an exit code other than 2 (cases that sent a signal are
            exempt: any status is acceptable after SIGINT/SIGTERM/SIGHUP).
accepted    the case must be refused (documented error, destroys its input, or output that
            could not be written) and the run exited 0.
ignored     as accepted, for a case whose option names an input the run does not have (an
            `ignored option`; counted with accepted bad in the compact table).
refused     the case must succeed (a valid but unusual input) and the run failed in a
            controlled way.

The single `classification` of a record is its most severe flag in the order crash, abort/oom,
panic, hang, non-finite, leftover, accepted, ignored, refused, multi-line, silent, exit!=2;
otherwise
`error` (controlled failure, exit 2, one line) or `ok` (exit 0).

Categories
----------
parameters         --set KEY=VALUE for every key of `tiltnoise params` with hostile values, and
                   --params FILE with malformed, mistyped, oversized or device files; run with
                   `modes`, `tf --freq 1e-3:10:1` and `budget --tilt lab_tilt_24h.h5`.
tilt inputs        `budget --tilt FILE` with damaged CSV/HDF5 series and spectra, wrong kinds of
                   file, `--measured FILE` damage, Welch/band options that do not apply.
frequency options  tf/budget/methods --freq, tf --freq-file (including every mode frequency as
                   printed by `modes --format json`, which must be refused), mc/simulate/fit
                   sizes and numbers.
outputs            --save into missing, read-only (chattr +i), existing-directory, over-long,
                   same-as-input paths; several --save where the last fails; stdout to /dev/full,
                   to a pipe whose reader has already exited, and `| head -c 1` for outputs
                   larger than a pipe buffer (so the program must write after the reader left).
process            SIGINT/SIGTERM/SIGHUP during a long write, closed stdin/stdout/stderr, stderr
                   on /dev/full.
fuzz               seeded byte-level mutations of a small corpus (CSV series and spectrum, HDF5
                   series, parameter TOML, frequency file, measured spectrum, fit input). Every
                   crashing, aborting, panicking or hanging input is kept in OUT/crashers/ with
                   its command line.
"""
from __future__ import annotations

import argparse
import json
import os
import random
import re
import resource
import shlex
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import threading
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import h5py
import numpy as np

import newest
import surfaces
from case_kit import (DAMPED, LAB_H5, PETERSON, QUICK_TIMEOUT, REPO, SHORT_TIMEOUT, ArgFromFile,
                      Case, Ctx, C, copy_setup, fifo_setup, h5_measured, h5_series, h5_spectra,
                      joined, measured_lines, replace_dataset, series_lines, spectrum_lines,
                      write)

MEM_LIMIT = 4 << 30
DEFAULT_TIMEOUT = 20.0
STDOUT_HEAD = 64 << 10
STDERR_CAP = 1 << 20
TEXT_SCAN_CAP = 256 << 20
H5_SCAN_CAP = 50_000_000  # elements per file
ARTIFACT_CAP = 4 << 20

CATEGORIES = ["parameters", "tilt inputs", "frequency options", "outputs", "miniseed",
              "gwpy addressing", "coherence/subtract pairs", "option edges", "python",
              *newest.CATEGORIES, "process", "fuzz"]
# The categories of the surfaces added after the first audit (surfaces.py); they need the valid
# pair of records made by the first binary.
NEW_SURFACES = ["miniseed", "gwpy addressing", "coherence/subtract pairs", "option edges",
                "python", *newest.CATEGORIES]
FLAGS = ["crash", "abort_oom", "panic", "hang", "overwrote", "nonfinite", "leftover", "accepted",
         "ignored", "refused", "unclear", "multiline", "silent", "exit_not_2"]
FLAG_TITLES = {
    "crash": "crash", "abort_oom": "abort/oom", "panic": "panic", "hang": "hang",
    "overwrote": "overwrote input", "nonfinite": "non-finite", "leftover": "leftover files",
    "accepted": "accepted bad", "ignored": "ignored option", "refused": "refused valid",
    "unclear": "unclear err",
    "multiline": "multi-line err", "silent": "silent fail", "exit_not_2": "exit!=2",
}
TABLE_FLAGS = ["crash", "abort_oom", "panic", "overwrote", "nonfinite", "leftover", "unclear",
               "multiline", "exit_not_2", "hang", "silent", "accepted", "ignored", "refused"]
# The defect kinds of the compact table: flags summed per kind.
KINDS = {
    "crashes": ["crash", "abort_oom", "panic", "hang"],
    "overwritten inputs": ["overwrote"],
    "silent non-finite": ["nonfinite"],
    "unclear errors": ["unclear", "multiline", "silent", "exit_not_2"],
    "accepted bad": ["accepted", "ignored"],
    "other (leftover, refused valid)": ["leftover", "refused"],
}
PY_CASE = str(Path(__file__).resolve().parent / "py_case.py")
# The Python interpreter of each binary's slot (--python), for the cases of category python.
PYTHONS: dict[str, tuple[str, dict]] = {}

NONFINITE_RE = re.compile(r"(?<![A-Za-z0-9_])[-+]?(?:nan|inf(?:inity)?)(?![A-Za-z0-9_])", re.I)
NONFINITE_FIELD_RE = re.compile(r"^\s*\"?[-+]?(?:nan|inf(?:inity)?)\"?\s*$", re.I)
HUGE_ZERO_RE = re.compile(r"(?<![0-9.])[-+]?0\.000e[-+]?0(?![0-9])")
# Allowed by design: Q = inf of an undamped mode.
ALLOWED_STDOUT = [
    re.compile(r"(?m)^(\s*nu_\d+\s+\S+\s+\S+\s+)inf\b"),
    re.compile(r"\"quality_factor\"\s*:\s*\"inf\""),  # before JSON numbers became null
    re.compile(r"\(NaN outside\)"),
    # Notes that name NaN or infinity as words: gaps filled with NaN before the gap policy, an
    # unconstrained parameter "the data would give +/- infinity".
    re.compile(r"filled with NaN before the gap policy"),
    re.compile(r"\+/- infinity"),
]
ALLOWED_NONFINITE_NAMES = re.compile(r"measured|residual|fitted_sigma")
TEMP_NAME_RES = [
    re.compile(r".*\.tmp$"),
    re.compile(r"^\.tmp[A-Za-z0-9]{6}.*"),
    re.compile(r"^\..+\.[A-Za-z0-9]{6}(\.[A-Za-z0-9]+)?$"),
]


# --------------------------------------------------------------------------------------------
# How a case is shown


def shown(arg: str) -> str:
    if len(arg) > 120:
        arg = f"{arg[:24]}...<{len(arg)} chars>"
    return arg.replace("\n", "\\n")


def display_command(case: Case, binary: str) -> str:
    if case.python is not None:
        cmd = "python: " + "; ".join(line for line in case.python.splitlines()
                                     if not line.startswith("import "))
    else:
        cmd = shlex.join([binary] + [shown(a) for a in case.args])
    redirs = {
        ("stdin", "closed"): "<&-", ("stdout", "closed"): ">&-",
        ("stdout", "devfull"): "> /dev/full", ("stdout", "close_after_1"): "| head -c 1",
        ("stdout", "broken_pipe"): "| (a pipe whose reader has already exited)",
        ("stderr", "closed"): "2>&-", ("stderr", "devfull"): "2> /dev/full",
    }
    for key in ("stdin", "stdout", "stderr"):
        r = redirs.get((key, getattr(case, key)))
        if r:
            cmd += " " + r
    if case.sig:
        when = ("when its output file appears" if case.sig_when == "tempfile"
                else f"after {case.sig_when} s")
        cmd += f"   # {signal.Signals(case.sig).name} {when}"
    return cmd


_MODES_CACHE: dict[str, list[float]] = {}
_MODES_LOCK = threading.Lock()


def mode_frequencies(binary: str) -> list[float]:
    with _MODES_LOCK:
        if binary not in _MODES_CACHE:
            out = subprocess.run([binary, "modes", "--format", "json"], capture_output=True,
                                 timeout=60, check=True).stdout
            _MODES_CACHE[binary] = [m["frequency_hz"] for m in json.loads(out)["modes"]]
        return _MODES_CACHE[binary]


def params_text(binary: str) -> str:
    """The complete parameter file as `tiltnoise params` prints it (Table I if that fails)."""
    try:
        out = subprocess.run([binary, "params"], capture_output=True, timeout=60).stdout.decode()
        tomllib.loads(out)
        if "m_a_kg = 1.2\n" in out:
            return out
    except Exception:  # noqa: BLE001
        pass
    return (REPO / "crates" / "tiltnoise-core" / "src" / "params" / "table1.toml").read_text()


def param_keys(binaries) -> list[str]:
    keys = set()
    for b in binaries:
        try:
            out = subprocess.run([b, "params"], capture_output=True, timeout=60).stdout
            doc = tomllib.loads(out.decode())
        except Exception:  # noqa: BLE001 - a binary that cannot print params adds no keys
            continue
        for table, values in doc.items():
            if table == "uncertainty" or not isinstance(values, dict):
                continue
            for k in values:
                keys.add(f"{table}.{k}")
    return sorted(keys)


# --------------------------------------------------------------------------------------------
# Category 1: parameters

SET_VALUES = ["0", "-1", "-0", "1e-300", "4.9e-324", "1e300", "nan", "inf", "-inf", "",
              "x" * 100_000, "1\n2"]
POSITIVE_KEYS = re.compile(r"^(mass\.|torsion\.|bouncing\.|inertia\.(a11|a22|a33|b11|b22|b33)|"
                           r"length\.(d_m|z_m|z_a_m|z_b_m|h_m)$|environment\.)")


def set_must_fail(key: str, value: str) -> bool:
    if value in ("nan", "inf", "-inf", "") or len(value) > 1000 or "\n" in value:
        return True
    v = float(value)
    if v < 0 and not key.startswith("inertia.a23"):
        return True
    if POSITIVE_KEYS.match(key) and v <= 0:
        return True
    if key.startswith("length.") and v > 1000:
        return True
    if key.startswith("loss.dilution") and v < 1:
        return True
    if key.startswith("loss.") and not key.startswith("loss.dilution") and v >= 1:
        return True
    if key == "inertia.a23_kg_m2" and abs(v) > 0.06:  # tensor no longer positive definite
        return True
    return False


def cases_parameters(inputs: Path, keys: list[str], params_text: str) -> list[Case]:
    cat = "parameters"
    cases = []
    tf = ["tf", "--freq", "1e-3:10:1"]
    budget = ["budget", "--tilt", LAB_H5, "--nperseg", "4096"]
    for key in keys:
        for value in SET_VALUES:
            mf = set_must_fail(key, value)
            huge = False
            tag = {"x" * 100_000: "100kB", "1\n2": "newline", "": "empty"}.get(value, value)
            cases.append(C(cat, f"set {key}={tag} modes", ["--set", f"{key}={value}", "modes"],
                           must_fail=mf, huge=huge))
            if value in ("0", "-1", "1e-300", "4.9e-324", "1e300"):
                cases.append(C(cat, f"set {key}={tag} tf", ["--set", f"{key}={value}"] + tf,
                               must_fail=mf, huge=huge))
            if value in ("1e-300", "1e300"):
                cases.append(C(cat, f"set {key}={tag} budget",
                               ["--set", f"{key}={value}"] + budget, must_fail=mf, huge=huge))
    for bad in ["foo=1", "mass.foo=1", "mass=1", "mass.m_a_kg", "=1", "mass.m_a_kg==1",
                "mass.m_a_kg=1=2", " mass.m_a_kg = 1", "MASS.M_A_KG=1", "mass..m_a_kg=1",
                "mass.m_a_kg=1.2kg", "mass.m_a_kg=1,2", "mass.m_a_kg=0x10", "mass.m_a_kg=1e",
                "uncertainty.mass.m_a_kg=0.1", "mass.m_a_kg=\u00a01", "mass.m_a_kg=+1",
                "mass.m_a_kg=1_000", "mass.m_a_kg=1e99999"]:
        ok_values = {" mass.m_a_kg = 1", "mass.m_a_kg=+1", "mass.m_a_kg=\u00a01"}
        cases.append(C(cat, f"set {bad!r} modes", ["--set", bad, "modes"],
                       must_fail=bad not in ok_values))
    cases.append(C(cat, "set same key twice", ["--set", "mass.m_a_kg=1", "--set",
                                               "mass.m_a_kg=2", "modes"]))

    # --params FILE
    d = inputs / "params"
    # Every file is the complete parameter set printed by `tiltnoise params` with one change,
    # so that the change (not a missing key) is what the reader meets.
    valid = params_text
    files: dict[str, tuple[bytes | str, bool, bool]] = {}  # name -> (content, must_fail, heavy)

    def add(name, content, must_fail=True, heavy=True):
        files[name] = (content, must_fail, heavy)

    def with_m_a(literal: str) -> str:
        return valid.replace("m_a_kg = 1.2\n", f"m_a_kg = {literal}\n", 1)

    add("valid.toml", valid, must_fail=False)
    add("unclosed_table.toml", valid.replace("[mass]", "[mass", 1))
    add("missing_value.toml", with_m_a(""))
    add("duplicate_key.toml", with_m_a("1.2\nm_a_kg = 1.3"))
    add("duplicate_table.toml", valid + "\n[mass]\nm_b_kg = 0.1\n")
    add("unterminated_string.toml", valid + 'x = "abc\n')
    add("bad_number.toml", with_m_a("1.2.3"))
    add("bare_equals.toml", valid + "= 1\n")
    add("array_of_tables.toml", valid.replace("[mass]", "[[mass]]", 1))
    add("bad_escape.toml", valid + 'x = "\\q"\n')
    add("nul_byte.toml", with_m_a("1.2\x00"))
    add("deep_arrays.toml", "a = " + "[" * 100_000 + "]" * 100_000 + "\n" + valid)
    add("deep_inline_tables.toml", "a = " + "{b = " * 20_000 + "1" + "}" * 20_000 + "\n" + valid)
    add("deep_dotted_key.toml", ".".join(["a"] * 50_000) + " = 1\n" + valid)
    add("unknown_top.toml", "foo = 1\n" + valid)
    add("unknown_in_table.toml", valid.replace("[mass]\n", "[mass]\nfoo_kg = 1\n", 1))
    add("unknown_table.toml", valid + "\n[nonsense]\na = 1\n")
    add("missing_key.toml", valid.replace("m_a_kg = 1.2\n", "", 1))
    add("missing_table.toml", valid.replace("[environment]", "[environment_]", 1))
    for label, lit in [("string", '"1.2"'), ("bool", "true"), ("array", "[1.2]"),
                       ("inline_table", "{ v = 1.2 }"), ("datetime", "1979-05-27T07:32:00Z"),
                       ("int_overflow", "99999999999999999999"), ("nan", "nan"),
                       ("inf", "inf"), ("neg_inf", "-inf"), ("plus_nan", "+nan"),
                       ("float_overflow", "1e400"), ("hex", "0x10"), ("int", "1"),
                       ("zero", "0.0"), ("negative", "-1.2"), ("tiny", "1e-300"),
                       ("huge", "1e300")]:
        mf = label not in ("hex", "int", "tiny", "huge")
        add(f"m_a_kg_{label}.toml", with_m_a(lit), must_fail=mf)
    for label, body in [("nan", "rel_sigma = nan"), ("negative", "rel_sigma = -0.1"),
                        ("huge", "rel_sigma = 1e300"), ("gaussian_0.3", "rel_sigma = 0.3"),
                        ("uniform_0.6", 'rel_sigma = 0.6, distribution = "uniform"'),
                        ("cauchy", 'rel_sigma = 0.1, distribution = "cauchy"'),
                        ("string", 'rel_sigma = "x"'), ("extra_key", "rel_sigma = 0.1, foo = 1"),
                        ("missing", 'distribution = "gaussian"'),
                        ("unknown_parameter", None)]:
        entry = ('"foo.bar" = { rel_sigma = 0.1 }' if body is None
                 else f'"mass.m_a_kg" = {{ {body} }}')
        add(f"uncertainty_{label}.toml", valid + f"\n[uncertainty]\n{entry}\n")
    add("empty.toml", "")
    add("comments_only.toml", "# nothing here\n# at all\n")
    add("bom.toml", "\ufeff" + valid, must_fail=False)
    add("crlf.toml", valid.replace("\n", "\r\n"), must_fail=False)
    add("invalid_utf8_comment.toml", b"# \xff\xfe\n" + valid.encode())
    add("invalid_utf8_string.toml", valid.encode() + b'x = "\xff"\n')
    add("invalid_utf8_key.toml", valid.encode().replace(b"m_a_kg", b"m_a_\xffkg", 1))
    add("utf16.toml", valid.encode("utf-16"))
    # Over the documented 1 MiB limit of a parameter file (docs/limits.md): refused, naming it.
    add("long_comment_10MB.toml", "#" + "x" * 10_000_000 + "\n" + valid, heavy=False)
    for name, (content, mf, heavy) in files.items():
        p = write(d / name, content)
        cases.append(C(cat, f"params {name} modes", ["--params", p, "modes"], must_fail=mf,
                       must_succeed=name in ("valid.toml", "crlf.toml")))
        if heavy:
            cases.append(C(cat, f"params {name} tf", ["--params", p] + tf, must_fail=mf))
            cases.append(C(cat, f"params {name} budget", ["--params", p] + budget, must_fail=mf))
    spaces = d / "spaces_100MB.toml"
    with open(spaces, "wb") as fh:
        block = b" " * (1 << 20)
        for _ in range(100):
            fh.write(block)
    sparse = d / "sparse_1GB.toml"
    with open(sparse, "wb") as fh:
        fh.truncate(1 << 30)
    for name, path, to in [("100 MB of spaces", spaces, QUICK_TIMEOUT),
                           ("1 GB sparse file (NUL bytes)", sparse, SHORT_TIMEOUT),
                           ("/dev/zero", "/dev/zero", QUICK_TIMEOUT),
                           ("/dev/urandom", "/dev/urandom", QUICK_TIMEOUT),
                           ("/dev/null", "/dev/null", None),
                           ("a directory", d, None),
                           ("a missing file", d / "missing.toml", None)]:
        mf = True
        cases.append(C(cat, f"params {name} modes", ["--params", path, "modes"], timeout=to,
                       must_fail=mf))
    cases.append(C(cat, "params damped.toml with --set override budget",
                   ["--params", DAMPED, "--set", "loss.torsion_a_rad=0.9999999999999999"]
                   + budget, huge=True))
    cases.append(C(cat, "params given twice", ["--params", DAMPED, "--params", DAMPED, "modes"]))
    return cases


# --------------------------------------------------------------------------------------------
# Category 2: tilt inputs


def cases_tilt(inputs: Path) -> list[Case]:
    cat = "tilt inputs"
    d = inputs / "tilt"
    cases: list[Case] = []

    def budget(name, path, extra=(), must_fail=True, huge=False, timeout=None, must_succeed=False):
        cases.append(C(cat, name, ["budget", "--tilt", path, *extra], must_fail=must_fail,
                       huge=huge, timeout=timeout, must_succeed=must_succeed))

    # ---- CSV series
    base = series_lines()

    def csv_variant(name, lines=None, text=None, eol="\n", **kw):
        content = text if text is not None else joined(lines, eol)
        p = write(d / f"series_{name}.csv", content)
        budget(f"csv series: {name}", p, **kw)
        return p

    def row_edit(idx, col, value, src=None):
        lines = list(src or base)
        fields = lines[idx].split(",")
        fields[col] = value
        lines[idx] = ",".join(fields)
        return lines

    csv_variant("valid", base, must_fail=False, must_succeed=True)
    for label, value in [("nan", "nan"), ("NaN", "NaN"), ("inf", "inf"), ("-inf", "-inf"),
                         ("Infinity", "Infinity"), ("empty field", ""), ("non-numeric", "abc"),
                         ("hex float", "0x1p-30"), ("1e400", "1e400"), ("trailing junk", "1e-9x")]:
        csv_variant(f"sample {label}", row_edit(100, 1, value))
    csv_variant("sample 1e200", row_edit(100, 1, "1e200"), must_fail=False, huge=True)
    csv_variant("sample -1e200", row_edit(100, 2, "-1e200"), must_fail=False, huge=True)
    big = ["time_s,theta_t,eta_t"] + [f"{i}.0,{float(v)!r},{float(w)!r}" for i, (v, w) in enumerate(
        zip(np.full(4096, 1e200) * np.cos(np.arange(4096)), np.full(4096, -1e200)))]
    csv_variant("all samples ~1e200", big, must_fail=False, huge=True)
    big = ["time_s,theta_t,eta_t"] + [f"{i}.0,{1.7e308 * (-1) ** i!r},{1e-9!r}"
                                      for i in range(4096)]
    csv_variant("samples +-1.7e308", big, must_fail=False, huge=True)
    tiny = ["time_s,theta_t,eta_t"] + [f"{i}.0,{5e-324 * (i % 3)!r},0.0" for i in range(4096)]
    csv_variant("subnormal samples", tiny, must_fail=False)
    zeros = ["time_s,theta_t,eta_t"] + [f"{i}.0,0.0,0.0" for i in range(4096)]
    csv_variant("all zeros", zeros, must_fail=False)
    lines = list(base)
    lines[100] = ",".join(lines[100].split(",")[:2])
    csv_variant("row missing a column", lines)
    lines = list(base)
    lines[100] += ",1e-9"
    csv_variant("row with an extra column", lines)
    csv_variant("header missing a column", ["time_s,theta_t"] + base[1:])
    csv_variant("header with an extra column", ["time_s,theta_t,eta_t,phi_t"] + base[1:])
    csv_variant("duplicated column", ["time_s,theta_t,theta_t"] + base[1:])
    csv_variant("two channels for one axis (E, LJE)", ["time_s,E,LJE"] + base[1:])
    csv_variant("no mapped channel", ["time_s,foo,bar"] + base[1:])
    csv_variant("first column not time_s", ["theta_t,time_s,eta_t"] + base[1:])
    csv_variant("empty column name", ["time_s,,eta_t"] + base[1:])
    csv_variant("quoted names", ['"time_s","theta_t","eta_t"'] + base[1:], must_fail=False)
    csv_variant("unterminated quote", ['"time_s,theta_t,eta_t'] + base[1:])
    csv_variant("crlf", base, eol="\r\n", must_fail=False, must_succeed=True)
    csv_variant("cr only", base, eol="\r")
    csv_variant("bom", text="\ufeff" + joined(base), must_fail=False, must_succeed=True)
    csv_variant("bom twice", text="\ufeff\ufeff" + joined(base))
    csv_variant("tab separated", [ln.replace(",", "\t") for ln in base])
    csv_variant("semicolon separated", [ln.replace(",", ";") for ln in base])
    csv_variant("blank and whitespace lines", base[:50] + ["", "   ", "\t"] + base[50:],
                must_fail=False)
    csv_variant("non-monotonic time", row_edit(200, 0, "198.0"))
    csv_variant("repeated time (zero spacing)", row_edit(201, 0, "199.0"))
    all_zero_t = ["time_s,theta_t,eta_t"] + [f"0.0,{1e-9 * i!r},0.0" for i in range(4096)]
    csv_variant("all times equal", all_zero_t)
    rev = ["time_s,theta_t,eta_t"] + [f"{-float(i)!r},{1e-9 * (i % 7)!r},0.0" for i in range(4096)]
    csv_variant("decreasing time (negative spacing)", rev)
    csv_variant("non-uniform time", row_edit(201, 0, "200.3"))
    csv_variant("time nan", row_edit(10, 0, "nan"))
    csv_variant("time inf", row_edit(10, 0, "inf"))
    huge_t = ["time_s,theta_t,eta_t"] + [f"{1e300 + i * 1e290!r},{1e-9 * (i % 5)!r},0.0"
                                        for i in range(4096)]
    csv_variant("times near 1e300", huge_t, must_fail=False)
    tiny_t = ["time_s,theta_t,eta_t"] + [f"{i * 1e-300!r},{1e-9 * (i % 5)!r},0.0"
                                        for i in range(4096)]
    csv_variant("spacing 1e-300 s (rate 1e300 Hz)", tiny_t, must_fail=False)
    for rows in (0, 1, 2, 3):
        csv_variant(f"{rows} data rows", base[: rows + 1], must_fail=rows < 2)
    csv_variant("empty file", text="")
    csv_variant("comments only", text="# just a comment\n# and another\n")
    csv_variant("huge data line (10 MB number)", base[:100] + ["100.0," + "1" * 10_000_000
                                                               + ",0.0"] + base[101:])
    csv_variant("long number (1 MB of zeros)", base[:100] + ["99.0,0." + "0" * 1_000_000 + "1,0.0"]
                + base[101:], must_fail=False)
    csv_variant("NUL byte in a value", text=joined(base).replace("\n5.0,", "\n5.0\x00,", 1))
    csv_variant("invalid UTF-8 in header", text=b"time_s,theta_t,\xff\xfe\n"
                + joined(base[1:]).encode())
    csv_variant("invalid UTF-8 in comment", text=b"# \xff\xfe\n" + joined(base).encode(),
                must_fail=False)
    csv_variant("invalid UTF-8 in a value", text=joined(base).encode().replace(
        b"\n5.0,", b"\n5.0\xff,", 1))
    for label, meta, mf in [("units unknown", "# units: furlong", True),
                            ("units for a missing column", "# units: foo=rad", True),
                            ("units twice", "# units: rad\n# units: rad/s", True),
                            ("axes syntax error", "# axes: theta_t=--E", True),
                            ("axes names a missing column", "# axes: theta_t=-Q", True),
                            ("axes target twice", "# axes: theta_t=theta_t,theta_t=eta_t", True),
                            ("start_time invalid", "# start_time: 2024-13-45T99:99:99Z", True),
                            ("start_time year 99999999999", "# start_time: 99999999999-01-01",
                             True),
                            ("start_time 100 kB", "# start_time: " + "9" * 100_000, True),
                            ("description 1 MB", "# description: " + "d" * 1_000_000, False)]:
        csv_variant(f"metadata: {label}", [meta] + base, must_fail=mf)
    hdr = d / "series_header_50MB.csv"
    with open(hdr, "wb") as fh:
        fh.write(b"time_s,theta_t,eta_t," + b"c" * (50 << 20) + b"\n")
        fh.write(joined([ln + ",0" for ln in base[1:]]).encode())
    budget("csv series: 50 MB header line", hdr, must_fail=False)
    wide = write(d / "series_100k_columns.csv", joined(
        ["time_s,theta_t,eta_t," + ",".join(f"c{i}" for i in range(100_000))]
        + [ln + "," * 100_000 for ln in base[1:50]]))
    budget("csv series: 100 000 columns (5 MB, must take well under a second)", wide,
           must_fail=False, timeout=QUICK_TIMEOUT)
    # gaps and quantity
    p = write(d / "series_gap_interior.csv", joined(row_edit(100, 1, "nan")))
    budget("csv series: interior NaN with --gaps interpolate", p, ["--gaps", "interpolate"],
           must_fail=False, must_succeed=True)
    p = write(d / "series_gap_first.csv", joined(row_edit(1, 1, "nan")))
    budget("csv series: NaN at the first sample with --gaps interpolate", p,
           ["--gaps", "interpolate"])
    p = write(d / "series_gap_last.csv", joined(row_edit(len(base) - 1, 2, "")))
    budget("csv series: empty last sample with --gaps interpolate", p, ["--gaps", "interpolate"])
    all_nan = ["time_s,theta_t,eta_t"] + [f"{i}.0,nan,nan" for i in range(4096)]
    p = write(d / "series_all_nan.csv", joined(all_nan))
    budget("csv series: all NaN with --gaps interpolate", p, ["--gaps", "interpolate"])
    p = write(d / "series_huge_rate.csv", joined(big))
    budget("csv series: rate +-1.7e308 with --quantity rate", p, ["--quantity", "rate"],
           must_fail=False, huge=True)
    # ---- CSV spectra
    sbase = spectrum_lines()

    def spec_variant(name, lines=None, text=None, **kw):
        content = text if text is not None else joined(lines)
        p = write(d / f"spectrum_{name}.csv", content)
        budget(f"csv spectrum: {name}", p, **kw)
        return p

    def srow(idx, col, value, src=None):
        lines = list(src or sbase)
        fields = lines[idx].split(",")
        fields[col] = value
        lines[idx] = ",".join(fields)
        return lines

    spec_path = spec_variant("valid", sbase, must_fail=False, must_succeed=True)
    for label, value in [("nan", "nan"), ("inf", "inf"), ("negative", "-1e-9"),
                         ("empty field", ""), ("non-numeric", "abc"), ("1e400", "1e400")]:
        spec_variant(f"ASD {label}", srow(20, 1, value))
    spec_variant("ASD 1e200", srow(20, 1, "1e200"), must_fail=False, huge=True)
    spec_variant("all ASD 1e200", [sbase[0]] + [",".join([ln.split(",")[0], "1e200", "1e200"])
                                                for ln in sbase[1:]], must_fail=False, huge=True)
    spec_variant("all ASD 1.7e308", [sbase[0]] + [",".join([ln.split(",")[0], "1.7e308", "0"])
                                                  for ln in sbase[1:]], must_fail=False, huge=True)
    spec_variant("all ASD zero", [sbase[0]] + [ln.split(",")[0] + ",0,0" for ln in sbase[1:]],
                 must_fail=False)
    for label, value in [("zero", "0"), ("negative", "-1"), ("nan", "nan"), ("inf", "inf")]:
        spec_variant(f"frequency {label}", srow(1, 0, value))
    spec_variant("frequency repeated", srow(20, 0, sbase[19].split(",")[0]))
    spec_variant("frequency decreasing", [sbase[0]] + sbase[:0:-1])
    spec_variant("frequency 1e300", srow(len(sbase) - 1, 0, "1e300"), must_fail=False)
    spec_variant("frequencies tiny (1e-300 .. 1e-290)", [sbase[0]] + [
        f"{1e-300 * 10 ** (i / 6)!r},1e-9,1e-9" for i in range(60)])
    spec_variant("band above the model grid (1e5..1e6 Hz)", [sbase[0]] + [
        f"{1e5 * 10 ** (i / 59)!r},1e-9,1e-9" for i in range(60)])
    spec_variant("1 row", sbase[:2])
    spec_variant("2 rows", sbase[:3], must_fail=False)
    spec_variant("header only", sbase[:1])
    spec_variant("missing column in a row", srow(20, 2, "x")[:20] + [",".join(
        sbase[20].split(",")[:2])] + sbase[21:])
    spec_variant("extra column in a row", sbase[:20] + [sbase[20] + ",1"] + sbase[21:])
    spec_variant("duplicated column", ["freq_hz,theta_t,theta_t"] + sbase[1:])
    spec_variant("units rate", ["# units: rad/s/sqrt(Hz)"] + sbase, must_fail=False)
    spec_variant("units series unit", ["# units: rad"] + sbase)
    spec_variant("crlf", text=joined(sbase, "\r\n"), must_fail=False, must_succeed=True)
    spec_variant("bom", text="\ufeff" + joined(sbase), must_fail=False, must_succeed=True)
    # options that do not apply
    for label, extra in [("--nperseg with spectra", ["--nperseg", "1024"]),
                         ("--segment-duration with spectra", ["--segment-duration", "3600"]),
                         ("--average median with spectra", ["--average", "median"]),
                         ("--gaps interpolate with spectra", ["--gaps", "interpolate"]),
                         ("--overlap with spectra", ["--overlap", "0.75"]),
                         ("--percentiles with spectra", ["--percentiles", "5,95"]),
                         ("--quantity rate with an ASD in rad", ["--quantity", "rate"]),
                         ("--readout Y (not budgeted)", ["--readout", "Y=1e-9"])]:
        budget(f"options: {label}", spec_path, extra, must_fail=label.find("quantity") < 0)
    for label, extra, mf, huge in [
            ("--freq with a series", ["--freq", "1e-3:10:1"], True, False),
            ("--readout Y=1e-9 (not budgeted)", ["--readout", "Y=1e-9"], True, False),
            ("--readout X=nan", ["--readout", "X=nan"], True, False),
            ("--readout X=-1", ["--readout", "X=-1"], True, False),
            ("--readout X=1e300", ["--readout", "X=1e300"], True, True),
            ("--readout X=1e200", ["--readout", "X=1e200"], False, True),
            ("--readout X=0", ["--readout", "X=0"], False, False),
            ("--readout junk", ["--readout", "X"], True, False),
            ("--segment-duration longer than the record", ["--segment-duration", "1e9"], True,
             False),
            ("--segment-duration 0", ["--segment-duration", "0"], True, False),
            ("--segment-duration -1", ["--segment-duration", "-1"], True, False),
            ("--segment-duration nan", ["--segment-duration", "nan"], True, False),
            ("--segment-duration 1e-300", ["--segment-duration", "1e-300"], True, False),
            ("--nperseg 0", ["--nperseg", "0"], True, False),
            ("--nperseg 1", ["--nperseg", "1"], True, False),
            ("--nperseg 3 (odd, tiny)", ["--nperseg", "3"], False, False),
            ("--nperseg 2^40", ["--nperseg", str(1 << 40)], True, False),
            ("--nperseg 2^64-1", ["--nperseg", str(2 ** 64 - 1)], True, False),
            ("--nperseg longer than the record", ["--nperseg", "1000000"], True, False),
            ("--overlap 1", ["--overlap", "1"], True, False),
            ("--overlap -0.5", ["--overlap", "-0.5"], True, False),
            ("--overlap nan", ["--overlap", "nan"], True, False),
            ("--overlap 0.999999999", ["--overlap", "0.999999999", "--nperseg", "4096"], False,
             False),
            ("--percentiles 90,10", ["--segment-duration", "14400", "--percentiles", "90,10"],
             True, False),
            ("--percentiles nan,50", ["--segment-duration", "14400", "--percentiles", "nan,50"],
             True, False),
            ("--percentiles 0,100", ["--segment-duration", "14400", "--percentiles", "0,100"],
             False, False),
            ("--percentiles -5,200", ["--segment-duration", "14400", "--percentiles", "-5,200"],
             True, False),
            ("--percentiles without --segment-duration", ["--percentiles", "5,95"], True, False),
            ("--axes syntax error", ["--axes", "theta_t=--eta_t"], True, False),
            ("--axes unknown target", ["--axes", "foo=theta_t"], True, False),
            ("--axes missing channel", ["--axes", "theta_t=-Q"], True, False),
            ("--axes same source twice", ["--axes", "theta_t=eta_t,eta_t=eta_t"], True, False),
            ("--axes empty", ["--axes", ""], True, False),
            ("--axes 100 kB", ["--axes", "theta_t=" + "E" * 100_000], True, False),
            ("--segment-duration 1 s (86400 segments)", ["--segment-duration", "1"], True,
             False),
            ("--segment-duration 64 s with --nperseg 64", ["--segment-duration", "64",
                                                         "--nperseg", "64"], False, False)]:
        budget(f"options: {label} (lab series)", LAB_H5, extra if "--nperseg" in extra
               else ["--nperseg", "4096", *extra], must_fail=mf, huge=huge)

    # ---- HDF5 series
    def h5_variant(name, edit=None, must_fail=True, huge=False, timeout=None, extra=(), **kw):
        p = h5_series(d / f"series_{name.replace(' ', '_').replace('/', '_')}.h5", edit=edit,
                      **kw)
        budget(f"h5 series: {name}", p, extra, must_fail=must_fail, huge=huge, timeout=timeout)
        return p

    h5_variant("valid", must_fail=False)
    utf8 = h5py.string_dtype("utf-8")
    for attr, obj, good in [("units", "theta_t", b"r\xffd"), ("start_time", None, b"2024\xff"),
                            ("axis_map", None, b"theta_t=theta_\xff"),
                            ("description", None, b"lab \xff floor"),
                            ("schema", None, b"tiltnoise.tilt_\xffseries")]:
        for kind in ("vlen", "fixed"):
            def edit(f, attr=attr, obj=obj, good=good, kind=kind):
                target = f[obj] if obj else f
                if kind == "vlen":
                    target.attrs.create(attr, good, dtype=utf8)
                else:
                    target.attrs.create(attr, np.bytes_(good))
            h5_variant(f"invalid UTF-8 {attr} ({kind})", edit,
                       must_fail=attr != "description")

    def dangling(f):
        del f["theta_t"]
        f["theta_t"] = h5py.SoftLink("/nowhere")

    h5_variant("dangling soft link for a mapped channel", dangling)

    def self_link(f):
        del f["theta_t"]
        f["theta_t"] = h5py.SoftLink("/theta_t")

    h5_variant("soft link to itself", self_link)

    def ext_link(f):
        del f["theta_t"]
        f["theta_t"] = h5py.ExternalLink("/nonexistent/file.h5", "/theta_t")

    h5_variant("external link to a missing file", ext_link)

    def ext_link_self(f):
        del f["theta_t"]
        f["theta_t"] = h5py.ExternalLink(str(d / "series_valid.h5"), "/theta_t")

    h5_variant("external link to another valid file", ext_link_self, must_fail=False)

    def group_channel(f):
        del f["theta_t"]
        f.create_group("theta_t")

    h5_variant("mapped channel is a group (groups are ignored)", group_channel, must_fail=False)

    def hard_link(f):
        del f["eta_t"]
        f["eta_t"] = f["theta_t"]

    h5_variant("both channels one dataset (hard link)", hard_link, must_fail=False)
    rng = np.random.default_rng(3)
    for label, data, mf in [
            ("int32", (rng.standard_normal(4096) * 1e3).astype("i4"), True),
            ("int64", (rng.standard_normal(4096) * 1e3).astype("i8"), True),
            ("uint8", rng.integers(0, 255, 4096).astype("u1"), True),
            ("float16", rng.standard_normal(4096).astype("f2"), True),
            ("float32", (1e-9 * rng.standard_normal(4096)).astype("f4"), False),
            ("big-endian float64", (1e-9 * rng.standard_normal(4096)).astype(">f8"), False),
            ("bool", rng.integers(0, 2, 4096).astype(bool), True),
            ("complex128", (rng.standard_normal(4096) + 1j).astype("c16"), True),
            ("fixed string", np.array([b"1e-9"] * 4096, dtype="S8"), True),
            ("compound", np.zeros(4096, dtype=[("a", "f8"), ("b", "f8")]), True),
            ("2-D (4096, 2)", 1e-9 * rng.standard_normal((4096, 2)), True),
            ("2-D (1, 4096)", 1e-9 * rng.standard_normal((1, 4096)), True),
            ("scalar", np.float64(1e-9), True),
            ("zero length", np.zeros(0), True),
            ("1 sample", np.zeros(1), True),
            ("all NaN", np.full(4096, np.nan), True),
            ("one NaN", np.where(np.arange(4096) == 100, np.nan, 1e-9), True),
            ("one inf", np.where(np.arange(4096) == 100, np.inf, 1e-9), True),
            ("values 1e200", 1e200 * rng.standard_normal(4096), False),
            ("values +-1.7e308", 1.7e308 * np.sign(rng.standard_normal(4096)), False)]:
        def edit(f, data=data):
            attrs = dict(f["theta_t"].attrs)
            replace_dataset(f, "theta_t", data)
            for k, v in attrs.items():
                f["theta_t"].attrs[k] = v
        h5_variant(f"theta_t {label}", edit, must_fail=mf,
                   huge=label.startswith("values"))

    def vlen_str(f):
        replace_dataset(f, "theta_t", np.array(["1e-9"] * 4096, dtype=object), dtype=utf8)

    h5_variant("theta_t variable-length strings", vlen_str)

    def refs(f):
        replace_dataset(f, "theta_t", shape=(16,), dtype=h5py.ref_dtype)

    h5_variant("theta_t object references", refs)
    for label, value, mf in [("NaN", np.nan, True), ("0", 0.0, True), ("-1", -1.0, True),
                             ("1e308", 1e308, False), ("inf", np.inf, True),
                             ("5e-324", 5e-324, False), ("string", "1.0", True),
                             ("array", np.array([1.0, 2.0]), True), ("bool", np.bool_(True), False),
                             ("complex", np.complex128(1.0), True), ("int 1", np.int64(1), False),
                             ("uint64 max", np.uint64(2 ** 64 - 1), False)]:
        def edit(f, value=value):
            del f.attrs["sample_rate_hz"]
            f.attrs["sample_rate_hz"] = value
        h5_variant(f"sample_rate_hz {label}", edit, must_fail=mf)

    def no_rate(f):
        del f.attrs["sample_rate_hz"]

    h5_variant("sample_rate_hz missing", no_rate)
    h5_variant("channels of different lengths",
               lambda f: replace_dataset(f, "eta_t", np.zeros(4000)))
    h5_variant("no mapped channel", channels=("foo", "bar"))
    h5_variant("E and LJE both", channels=("E", "LJE", "N"))
    h5_variant("schema spectra on a series",
               lambda f: f.attrs.__setitem__("schema", "tiltnoise.tilt_spectra"))
    h5_variant("schema unknown", lambda f: f.attrs.__setitem__("schema", "something.else"))
    h5_variant("schema an integer", lambda f: f.attrs.__setitem__("schema", 5))
    h5_variant("schema_version 99", lambda f: f.attrs.__setitem__("schema_version", 99))
    h5_variant("axis_map names a missing channel",
               lambda f: f.attrs.__setitem__("axis_map", "theta_t=-Q"))
    h5_variant("axis_map syntax error", lambda f: f.attrs.__setitem__("axis_map", "theta_t=="))
    h5_variant("units unknown", lambda f: f["theta_t"].attrs.__setitem__("units", "furlong"))
    h5_variant("units mixed (rad, rad/s)",
               lambda f: f["theta_t"].attrs.__setitem__("units", "rad/s"))
    h5_variant("units an integer", lambda f: f["theta_t"].attrs.__setitem__("units", 3))
    h5_variant("start_time 2024-02-30", lambda f: f.attrs.__setitem__("start_time",
                                                                      "2024-02-30T00:00:00Z"))
    h5_variant("start_time array", lambda f: f.attrs.__setitem__(
        "start_time", np.array(["a", "b"], dtype=h5py.string_dtype())))
    h5_variant("description 1 MB", lambda f: f.attrs.__setitem__("description", "d" * 1_000_000),
               must_fail=False)
    h5_variant("gzip compressed channels", lambda f: [
        replace_dataset(f, ch, 1e-9 * np.ones(4096), compression="gzip", chunks=(512,))
        for ch in ("theta_t", "eta_t")], must_fail=False)
    h5_variant("lzf compressed channel (filter not in libhdf5)", lambda f: replace_dataset(
        f, "theta_t", 1e-9 * np.ones(4096), compression="lzf", chunks=(512,)))
    h5_variant("declared 1e10 samples, nothing written", lambda f: [
        replace_dataset(f, ch, shape=(10 ** 10,), dtype="f8", chunks=(1 << 16,))
        for ch in ("theta_t", "eta_t")], must_fail=False)
    h5_variant("resizable, zero length", lambda f: [
        replace_dataset(f, ch, shape=(0,), maxshape=(None,), dtype="f8", chunks=(64,))
        for ch in ("theta_t", "eta_t")])
    h5_variant("gaps interpolate with NaN at the start", lambda f: f["theta_t"].__setitem__(
        0, np.nan), extra=["--gaps", "interpolate"])
    h5_variant("1000 unmapped datasets", lambda f: [f.create_dataset(f"x{i}", data=np.zeros(2))
                                                    for i in range(1000)], must_fail=False)
    valid_h5 = d / "series_valid.h5"
    raw = valid_h5.read_bytes()
    for name, content in [("empty file", b""), ("first 1 KB", raw[:1024]),
                          ("first 4 KB", raw[:4096]), ("last 100 bytes cut", raw[:-100]),
                          ("random bytes", random.Random(1).randbytes(65536)),
                          ("HDF5 signature then random", raw[:8] + random.Random(2).randbytes(8192)),
                          ("superblock then zeros", raw[:96] + bytes(len(raw) - 96))]:
        p = write(d / f"series_{name.replace(' ', '_')}.h5", content)
        budget(f"h5 damaged: {name}", p)
    # ---- HDF5 spectra
    def sp_variant(name, edit=None, must_fail=True, huge=False, csd=False):
        p = h5_spectra(d / f"spectra_{name.replace(' ', '_').replace('/', '_')}.h5", edit=edit,
                       csd=csd)
        budget(f"h5 spectra: {name}", p, must_fail=must_fail, huge=huge)

    sp_variant("valid asd", must_fail=False)
    sp_variant("valid csd", csd=True, must_fail=False)

    def setasd(value, idx=(10, 0)):
        def edit(f):
            a = f["asd"][...]
            a[idx] = value
            replace_dataset(f, "asd", a)
        return edit

    sp_variant("asd NaN", setasd(np.nan))
    sp_variant("asd negative", setasd(-1e-9))
    sp_variant("asd inf", setasd(np.inf))
    sp_variant("asd all 1e200", lambda f: replace_dataset(f, "asd", np.full((60, 2), 1e200)),
               must_fail=False, huge=True)

    def setfreq(value, idx=10):
        def edit(f):
            a = f["frequency_hz"][...]
            a[idx] = value
            replace_dataset(f, "frequency_hz", a)
        return edit

    sp_variant("frequency NaN", setfreq(np.nan))
    sp_variant("frequency zero", setfreq(0.0, 0))
    sp_variant("frequency not increasing", setfreq(1e-6, 30))
    sp_variant("asd shape (59, 2)", lambda f: replace_dataset(f, "asd", np.ones((59, 2)) * 1e-9))
    sp_variant("asd shape (60, 3) for 2 axes", lambda f: replace_dataset(f, "asd",
                                                                          np.ones((60, 3)) * 1e-9))
    sp_variant("asd 1-D", lambda f: replace_dataset(f, "asd", np.ones(60) * 1e-9))
    sp_variant("axes missing", lambda f: f.attrs.__delitem__("axes"))
    sp_variant("axes duplicated", lambda f: f.attrs.__setitem__(
        "axes", np.array(["theta_t", "theta_t"], dtype=h5py.string_dtype())))
    sp_variant("axes invalid UTF-8", lambda f: f.attrs.create(
        "axes", [b"theta_t", b"eta_\xff"], dtype=utf8))
    sp_variant("axes integers", lambda f: f.attrs.__setitem__("axes", np.array([1, 2])))
    sp_variant("both asd and csd", lambda f: f.create_dataset("csd", data=np.zeros(
        (60, 2, 2), dtype=np.complex128)))
    sp_variant("neither asd nor csd", lambda f: f.__delitem__("asd"))

    def csd_edit(fn):
        def edit(f):
            s = f["csd"][...]
            fn(s)
            replace_dataset(f, "csd", s)
        return edit

    def nonherm(s):
        s[:, 1, 0] = -s[:, 0, 1]

    def coh(s):
        s[:, 0, 1] *= 10
        s[:, 1, 0] *= 10

    def csd_nan(s):
        s[5, 0, 1] = np.nan

    def csd_negdiag(s):
        s[5, 0, 0] = -1e-18

    sp_variant("csd not Hermitian", csd_edit(nonherm), csd=True)
    sp_variant("csd coherence > 1", csd_edit(coh), csd=True)
    sp_variant("csd NaN", csd_edit(csd_nan), csd=True)
    sp_variant("csd negative diagonal", csd_edit(csd_negdiag), csd=True)
    sp_variant("csd real float64", lambda f: replace_dataset(f, "csd", np.ones((60, 2, 2))),
               csd=True)
    sp_variant("csd compound with wrong fields", lambda f: replace_dataset(
        f, "csd", np.zeros((60, 2, 2), dtype=[("re", "f8"), ("im", "f8")])), csd=True)
    # ---- files of the wrong kind
    wrong = d / "wrong"
    wrong.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(valid_h5, wrong / "valid_series.csv")
    shutil.copyfile(d / "series_valid.csv", wrong / "valid_series.h5")
    shutil.copyfile(d / "series_valid.csv", wrong / "valid_series.txt")
    shutil.copyfile(d / "series_valid.csv", wrong / "valid_series")
    shutil.copyfile(d / "series_valid.csv", wrong / "valid_series.CSV")
    shutil.copyfile(valid_h5, wrong / "valid_series.hdf5")
    (wrong / "dir.csv").mkdir(exist_ok=True)
    (wrong / "dir.h5").mkdir(exist_ok=True)
    for name, target in [("zero.csv", "/dev/zero"), ("urandom.csv", "/dev/urandom"),
                         ("zero.h5", "/dev/zero"), ("null.csv", "/dev/null")]:
        if not (wrong / name).is_symlink():
            os.symlink(target, wrong / name)
    for name, mf, to in [("valid_series.csv", True, None), ("valid_series.h5", True, None),
                         ("valid_series.txt", True, None), ("valid_series", True, None),
                         ("valid_series.CSV", False, None), ("valid_series.hdf5", False, None),
                         ("dir.csv", True, None), ("dir.h5", True, None),
                         ("zero.csv", True, QUICK_TIMEOUT), ("urandom.csv", True, QUICK_TIMEOUT),
                         ("zero.h5", True, QUICK_TIMEOUT), ("null.csv", True, None),
                         ("missing.csv", True, None)]:
        budget(f"wrong file: {name}", wrong / name, must_fail=mf, timeout=to,
               must_succeed=not mf)
    csv_text = (d / "series_valid.csv").read_bytes()
    cases.append(C(cat, "csv series through a FIFO", ["budget", "--tilt", "fifo.csv"],
                   setup=fifo_setup("fifo.csv", csv_text), timeout=SHORT_TIMEOUT))
    cases.append(C(cat, "hdf5 series through a FIFO", ["budget", "--tilt", "fifo.h5"],
                   setup=fifo_setup("fifo.h5", raw), timeout=SHORT_TIMEOUT))
    # ---- --measured
    mbase = measured_lines()
    lab = ["budget", "--tilt", LAB_H5, "--nperseg", "4096", "--measured"]

    def measured(name, path, must_fail=True, huge=False, tilt=None):
        args = (lab if tilt is None else ["budget", "--tilt", tilt, "--measured"]) + [path]
        cases.append(C(cat, f"measured: {name}", args, must_fail=must_fail, huge=huge))

    def mrow(idx, col, value):
        lines = list(mbase)
        fields = lines[idx].split(",")
        fields[col] = value
        lines[idx] = ",".join(fields)
        return lines

    mpath = write(d / "measured_valid.csv", joined(mbase))
    measured("valid spectrum", mpath, must_fail=False)
    measured("valid spectrum with spectra input", mpath, must_fail=False, tilt=spec_path)
    for label, lines in [("NaN", mrow(10, 1, "nan")), ("negative", mrow(10, 1, "-1")),
                         ("inf", mrow(10, 1, "inf")), ("empty field", mrow(10, 2, "")),
                         ("frequency zero", mrow(1, 0, "0")),
                         ("frequency decreasing", [mbase[0]] + mbase[:0:-1]),
                         ("unknown column", ["freq_hz,X,foo"] + [",".join(ln.split(",")[:3])
                                                                for ln in mbase[1:]]),
                         ("tilt columns", ["freq_hz,theta_t,eta_t"] + [
                             ",".join(ln.split(",")[:3]) for ln in mbase[1:]]),
                         ("header only", mbase[:1]), ("1 row", mbase[:2]),
                         ("duplicated column", ["freq_hz,X,X,phi_a"] + mbase[1:])]:
        measured(f"csv {label}", write(d / f"measured_{label.replace(' ', '_')}.csv",
                                       joined(lines)))
    measured("csv ASD 1e200", write(d / "measured_1e200.csv", joined(
        [mbase[0]] + [ln.split(",")[0] + ",1e200,1e200,1e200" for ln in mbase[1:]])),
        must_fail=False, huge=True)
    measured("csv band outside the budget (1e3..1e4 Hz)", write(d / "measured_outside.csv",
                                                               joined([mbase[0]] + [
        f"{1e3 * 10 ** (i / 59)!r},1e-8,1e-9,1e-9" for i in range(60)])), must_fail=False)
    mts = ["time_s,X,phi,phi_a"] + [f"{i}.0,{1e-8 * float(np.sin(i))!r},0.0,0.0" for i in range(86400)]
    measured("csv series valid", write(d / "measured_series.csv", joined(mts)), must_fail=False)
    measured("csv series too short", write(d / "measured_series_short.csv", joined(mts[:50])))
    measured("csv series NaN", write(d / "measured_series_nan.csv", joined(
        mts[:100] + ["99.0,nan,0.0,0.0"] + mts[101:])))

    def mh5(name, edit=None, must_fail=True, **kw):
        p = h5_measured(d / f"measured_{name.replace(' ', '_')}.h5", edit=edit, **kw)
        measured(f"h5 {name}", p, must_fail=must_fail)

    mh5("valid", must_fail=False)
    mh5("schema tilt_series", lambda f: f.attrs.__setitem__("schema", "tiltnoise.tilt_series"))
    mh5("units wrong", lambda f: f["X"].attrs.__setitem__("units", "rad"))
    mh5("units invalid UTF-8", lambda f: f["X"].attrs.create("units", b"\xff", dtype=utf8))
    mh5("X int32", lambda f: replace_dataset(f, "X", np.ones(86400, dtype="i4")))
    mh5("X NaN", lambda f: f["X"].__setitem__(5, np.nan))
    mh5("X 2-D", lambda f: replace_dataset(f, "X", np.zeros((43200, 2))))
    mh5("lengths differ", lambda f: replace_dataset(f, "phi", np.zeros(1000)))
    mh5("sample_rate_hz 0", lambda f: f.attrs.__setitem__("sample_rate_hz", 0.0))
    mh5("sample_rate_hz NaN", lambda f: f.attrs.__setitem__("sample_rate_hz", np.nan))
    mh5("sample_rate_hz 1e308", lambda f: f.attrs.__setitem__("sample_rate_hz", 1e308))
    mh5("too short (10 samples)", n=10)
    mh5("no observable", names=("foo",))

    def mdangling(f):
        del f["X"]
        f["X"] = h5py.SoftLink("/nowhere")

    mh5("dangling link X", mdangling)
    mraw = (d / "measured_valid.h5").read_bytes()
    for name, content in [("truncated 1 KB", mraw[:1024]),
                          ("random bytes", random.Random(3).randbytes(20000))]:
        measured(f"h5 {name}", write(d / f"measured_{name.replace(' ', '_')}.h5", content))
    measured("a directory", wrong / "dir.csv")
    measured("a missing file", d / "measured_missing.csv")
    measured("wrong extension", write(d / "measured.txt", joined(mbase)))
    return cases


# --------------------------------------------------------------------------------------------
# Category 3: frequency options and sizes


def resonance_setup(index: int, style: str):
    def setup(ctx: Ctx):
        f = mode_frequencies(ctx.bin)[index]
        if style == "file":
            write(ctx.dir / "resonance.txt", f"# mode {index + 1}\n{f!r}\n")
        elif style == "argfile":
            write(ctx.dir / "freq_arg.txt", f"{f!r}:1:{f!r}")
    return setup


def cases_frequency(inputs: Path) -> list[Case]:
    cat = "frequency options"
    d = inputs / "freq"
    cases: list[Case] = []
    small = ["--input", "theta_t", "--output", "X"]
    for spec, mf in [("-1:10:1", True), ("1e-3:0:1", True), ("1e-3:18446744073709551615:1", True),
                     ("1e-3:18446744073709551616:1", True), ("1e-4:1000000000:30", True),
                     ("nan:10:1", True), ("1:10:nan", True),
                     ("1:10:1e300", True), ("1e300:2:1e301", True), ("inf:2:inf", True),
                     ("0:10:1", True), ("1:10:0.5", True), ("1:1:1", False), ("1:2:1", False),
                     ("1e-300:10:1e-299", False), ("4.9e-324:3:1e-323", False),
                     ("1e-3:10", True), ("1e-3::1", True), ("::", True), ("", True),
                     ("a:b:c", True), ("1e-3:-5:1", True), ("1e-3:1.5:1", True),
                     ("1e-3:10:1:5", True), (" 1e-3:10:1", False), ("1e-3:10:1e20", False),
                     ("1e-3:1e3:1", True), ("1e-3:0x10:1", True)]:
        cases.append(C(cat, f"tf --freq {spec!r}", ["tf", "--freq", spec] + small, must_fail=mf,
                       huge="e300" in spec or "e20" in spec))
    # 1e8 points is the documented limit of a streamed grid: about 10 minutes by design, so the
    # timeout stops it (a hang flag here is expected, not a defect; --fast leaves it out).
    cases.append(C(cat, "tf --freq '1e-4:100000000:30' (streamed, 10 min by design)",
                   ["tf", "--freq", "1e-4:100000000:30"] + small, serial=True))
    for spec, mf in [("nan:10:1", True), ("1e-4:1000000000:30", True), ("1e-3:0:1", True),
                     ("1e300:2:1e301", True), ("1e-3:18446744073709551615:1", True)]:
        cases.append(C(cat, f"budget spectra --freq {spec!r}",
                       ["budget", "--tilt", PETERSON, "--freq", spec], must_fail=mf))
    for spec, mf in [("1e-3:1000000000:1", True), ("1e-3:18446744073709551615:1", True),
                     ("nan:10:1", True), ("1e-3:0:1", True), ("1e300:2:1e301", True)]:
        cases.append(C(cat, f"methods --freq {spec!r}", ["methods", "--freq", spec],
                       must_fail=mf))
    # --freq-file
    files = {
        "empty.txt": ("", True), "comments_only.txt": ("# a\n# b\n", True),
        "nan.txt": ("1e-3\nnan\n1\n", True), "negative.txt": ("1e-3\n-1\n1\n", True),
        "zero.txt": ("0\n1\n", False), "1e300.txt": ("1e-3\n1e300\n", True),
        "inf.txt": ("1e-3\ninf\n", True), "duplicates.txt": ("1e-3\n1e-3\n1\n", False),
        "descending.txt": ("1\n1e-2\n1e-3\n", False), "single.txt": ("1e-3\n", False),
        "text.txt": ("one millihertz\n", True), "two_per_line.txt": ("1e-3 2e-3\n", True),
        "comma.txt": ("1e-3,2e-3\n", True), "inline_comment.txt": ("1e-3 # one mHz\n1\n", False),
        "crlf.txt": ("1e-3\r\n1\r\n", False), "bom.txt": ("\ufeff1e-3\n1\n", False),
        "blank_lines.txt": ("\n\n1e-3\n\n1\n\n", False), "nul.txt": (b"1e-3\x00\n1\n", True),
        "invalid_utf8.txt": (b"1e-3\n\xff\n", True), "utf16.txt": ("1e-3\n1\n".encode("utf-16"),
                                                                True),
        "long_line_10MB.txt": ("1" + "0" * 10_000_000 + "\n", True),
        "subnormal.txt": ("4.9e-324\n", False), "huge_exponent.txt": ("1e99999\n", True),
        "100k_lines.txt": ("\n".join(repr(x) for x in np.logspace(-4, 1, 100_000).tolist()) + "\n",
                           False),
    }
    for name, (content, mf) in files.items():
        p = write(d / name, content)
        cases.append(C(cat, f"tf --freq-file {name}", ["tf", "--freq-file", p] + small,
                       must_fail=mf, huge=name == "1e300.txt"))
    sparse = d / "sparse_1GB.txt"
    with open(sparse, "wb") as fh:
        fh.truncate(1 << 30)
    for name, path, to in [("1 GB sparse file", sparse, SHORT_TIMEOUT),
                           ("/dev/urandom", "/dev/urandom", QUICK_TIMEOUT),
                           ("/dev/zero", "/dev/zero", QUICK_TIMEOUT), ("a directory", d, None),
                           ("a missing file", d / "missing.txt", None),
                           ("/dev/null", "/dev/null", None)]:
        cases.append(C(cat, f"tf --freq-file {name}", ["tf", "--freq-file", path] + small,
                       must_fail=True, timeout=to))
    cases.append(C(cat, "tf --freq and --freq-file together",
                   ["tf", "--freq", "1e-3:10:1", "--freq-file", d / "single.txt"]))
    for i in range(8):
        cases.append(C(cat, f"tf --freq-file at mode {i + 1} (repr of modes --format json)",
                       ["tf", "--freq-file", "resonance.txt"], setup=resonance_setup(i, "file"),
                       must_fail=True))
        cases.append(C(cat, f"tf --freq f:1:f at mode {i + 1}",
                       ["tf", "--freq", ArgFromFile("freq_arg.txt")],
                       setup=resonance_setup(i, "argfile"), must_fail=True))
        cases.append(C(cat, f"budget spectra --freq f:1:f at mode {i + 1}",
                       ["budget", "--tilt", PETERSON, "--freq", ArgFromFile("freq_arg.txt")],
                       setup=resonance_setup(i, "argfile"), must_fail=True))
    # mc
    for extra, mf, to in [(["--samples", "18446744073709551615"], True, None),
                          (["--samples", "1000000000000"], True, None),
                          (["--samples", "0"], True, None), (["--samples", "-1"], True, None),
                          (["--samples", "1e3"], True, None), (["--samples", "1"], False, None),
                          (["--samples", "100", "--threads", "0"], False, None),
                          (["--samples", "100", "--threads", "100000"], False, None),
                          (["--samples", "100", "--threads", "18446744073709551615"], False, None),
                          (["--samples", "100", "--seed", "18446744073709551616"], True, None),
                          (["--samples", "100", "--seed", "18446744073709551615"], False, None)]:
        cases.append(C(cat, "mc " + " ".join(extra), ["mc", *extra], must_fail=mf, timeout=to))
    # simulate (the step option is --step)
    for extra, mf in [(["--duration", "9e7"], True), (["--step", "0"], True),
                      (["--step", "-1"], True), (["--duration", "nan"], True),
                      (["--duration", "inf"], True), (["--duration", "-1"], True),
                      (["--duration", "0"], True), (["--step", "1e-300"], True),
                      (["--step", "nan"], True), (["--step", "1e300"], True),
                      (["--duration", "1e300"], True), (["--duration", "0.05"], True),
                      (["--duration", "1000", "--init", "phi_a=nan"], True),
                      (["--duration", "1000", "--init", "phi_a=1e300"], False),
                      (["--duration", "1000", "--init", "foo=1"], True),
                      (["--duration", "1000", "--init", "phi_a"], True),
                      (["--duration", "1000", "--init-rate", "phi_a=inf"], True),
                      (["--duration", "1000", "--kick-x", "nan"], True),
                      (["--duration", "1000", "--kick-x", "1e300"], False),
                      (["--duration", "1000", "--mode-energy", "-1"], True),
                      (["--duration", "1000", "--mode-energy", "1e300"], False),
                      (["--duration", "1000", "--readout", "X=inf"], True),
                      (["--duration", "1000", "--readout", "Q=1"], True),
                      (["--duration", "1000", "--nperseg", "0"], True),
                      (["--duration", "1000", "--nperseg", "1000000"], True),
                      (["--duration", "1000", "--seed", "-1"], True),
                      (["--duration", "1000", "--step", "0.3"], False)]:
        cases.append(C(cat, "simulate " + " ".join(extra), ["simulate", *extra], must_fail=mf,
                       huge="1e300" in extra))
    # fit
    fd = inputs / "fit"
    fit_files = {
        "valid.csv": ("mode,frequency_hz,sigma_hz\n1,1.331e-3,1e-5\n2,2.117e-3,1e-5\n", False),
        "nan.csv": ("mode,frequency_hz\n1,nan\n", True),
        "negative.csv": ("mode,frequency_hz\n1,-1e-3\n", True),
        "inf.csv": ("mode,frequency_hz\n1,inf\n", True),
        "1e300.csv": ("mode,frequency_hz\n1,1e300\n", True),
        "mode_0.csv": ("mode,frequency_hz\n0,1e-3\n", True),
        "mode_9.csv": ("mode,frequency_hz\n9,1e-3\n", True),
        "mode_huge.csv": ("mode,frequency_hz\n18446744073709551616,1e-3\n", True),
        "mode_twice.csv": ("mode,frequency_hz\n1,1.3e-3\n1,1.4e-3\n", True),
        "sigma_zero.csv": ("mode,frequency_hz,sigma_hz\n1,1.3e-3,0\n", True),
        "sigma_negative.csv": ("mode,frequency_hz,sigma_hz\n1,1.3e-3,-1\n", True),
        "sigma_nan.csv": ("mode,frequency_hz,sigma_hz\n1,1.3e-3,nan\n", True),
        "sigma_tiny.csv": ("mode,frequency_hz,sigma_hz\n1,1.3e-3,1e-300\n", False),
        "empty.csv": ("", True), "header_only.csv": ("mode,frequency_hz\n", True),
        "invalid_utf8.csv": (b"mode,frequency_hz\n1,\xff\n", True),
        "extra_column.csv": ("mode,frequency_hz,sigma_hz,x\n1,1.3e-3,1e-5,1\n", True),
    }
    for name, (content, mf) in fit_files.items():
        p = write(fd / name, content)
        cases.append(C(cat, f"fit --measured {name}", ["fit", "--measured", p, "--free",
                                                         "torsion.k_a_n_m_per_rad"], must_fail=mf,
                       huge=name == "sigma_tiny.csv"))
    for extra, mf in [(["--free", "foo"], True), (["--free", ""], True),
                      (["--free", "mass.m_a_kg,mass.m_a_kg"], True),
                      (["--free", "environment.g_m_per_s2"], True),
                      (["--bound-sigmas", "nan"], True), (["--bound-sigmas", "-1"], True),
                      (["--bound-sigmas", "0"], True), (["--bound-sigmas", "1e300"], True),
                      (["--bound-sigmas", "inf"], True)]:
        cases.append(C(cat, "fit " + " ".join(extra), ["fit", *extra], must_fail=mf))
    return cases


# --------------------------------------------------------------------------------------------
# Category 4: outputs

OUT_COMMANDS = {
    "tf": (["tf", "--freq", "1e-3:10:1"], ["h5", "csv", "png", "svg"]),
    "budget": (["budget", "--tilt", PETERSON], ["h5", "csv", "png", "svg"]),
    "mc": (["mc", "--samples", "20"], ["h5", "svg"]),
    "fit": (["fit"], ["json", "h5"]),
    "simulate": (["simulate", "--duration", "1000"], ["h5", "csv", "svg"]),
    "methods": (["methods", "--freq", "1e-3:5:1"], ["svg", "png"]),
}


def ro_setup(ctx: Ctx):
    (ctx.dir / "ro").mkdir()
    subprocess.run(["chattr", "+i", str(ctx.dir / "ro")], check=True, capture_output=True)


def chattr_available() -> bool:
    probe = Path(tempfile.mkdtemp(prefix="chattr-probe-"))
    try:
        sub = probe / "d"
        sub.mkdir()
        r = subprocess.run(["chattr", "+i", str(sub)], capture_output=True)
        if r.returncode != 0:
            return False
        try:
            (sub / "x").write_bytes(b"")
            ok = False
        except OSError:
            ok = True
        subprocess.run(["chattr", "-i", str(sub)], capture_output=True)
        return ok
    except FileNotFoundError:
        return False
    finally:
        shutil.rmtree(probe, ignore_errors=True)


def cases_outputs(inputs: Path, have_chattr: bool) -> list[Case]:
    cat = "outputs"
    cases: list[Case] = []
    for cmd, (base, exts) in OUT_COMMANDS.items():
        for ext in exts:
            other = next(e for e in exts if e != ext) if len(exts) > 1 else ext

            def add(label, saves, must_fail=True, setup=None, must_succeed=False):
                args = list(base)
                for s in saves:
                    args += ["--save", s]
                cases.append(C(cat, f"{cmd} .{ext}: {label}", args, setup=setup,
                               must_fail=must_fail, must_succeed=must_succeed))

            add("into a missing directory", [f"nodir/out.{ext}"])
            if have_chattr:
                add("into a read-only (immutable) directory", [f"ro/out.{ext}"], setup=ro_setup)
            add("path is an existing directory", [f"exists.{ext}"],
                setup=copy_setup((None, f"exists.{ext}")))
            add("parent is a file", [f"file.txt/out.{ext}"],
                setup=lambda c: write(c.dir / "file.txt", "x"))
            add("trailing slash", [f"out.{ext}/"])
            add("empty path", [""])
            add("255-byte file name", ["a" * (254 - len(ext)) + "." + ext], must_fail=False,
                must_succeed=True)
            add("256-byte file name", ["a" * (255 - len(ext)) + "." + ext])
            add("same path twice", [f"out.{ext}", f"out.{ext}"], must_fail=False)
            add("last of two fails (missing directory)", [f"out.{other}", f"nodir/b.{ext}"])
            add("last of two fails (existing directory)", [f"out.{other}", f"exists.{ext}"],
                setup=copy_setup((None, f"exists.{ext}")))
            add("symlink to a missing directory", [f"link/out.{ext}"],
                setup=lambda c: os.symlink("/nonexistent/dir", c.dir / "link"))
            add("dangling symlink as the target", [f"dangling.{ext}"], must_fail=False,
                setup=lambda c, ext=ext: os.symlink(f"/nonexistent/x.{ext}",
                                                     c.dir / f"dangling.{ext}"))
            add("uppercase extension", [f"out.{ext.upper()}"], must_fail=False)
        add_ = cases.append
        for label, saves in [("unknown extension", ["out.xyz"]), ("no extension", ["out"]),
                             ("double extension .bak", [f"out.{exts[0]}.bak"]),
                             ("extension of another command", ["out.json" if cmd != "fit"
                                                                else "out.csv"]),
                             ("unknown extension after a valid one",
                              [f"ok.{exts[0]}", "bad.xyz"]),
                             ("hidden name '.csv'", [f".{exts[0]}"])]:
            args = list(base)
            for s in saves:
                args += ["--save", s]
            add_(C(cat, f"{cmd}: {label}", args, must_fail=label != "hidden name '.csv'"))
        add_(C(cat, f"{cmd}: stdout to /dev/full", base, stdout="devfull", must_fail=True))
        add_(C(cat, f"{cmd}: stdout to a pipe without reader", base, stdout="broken_pipe"))
    # multi-save where the last fails, explicitly as in the brief
    cases.append(C(cat, "tf --save out/a.h5 --save nodir/b.svg",
                   ["tf", "--freq", "1e-3:10:1", "--save", "out/a.h5", "--save", "nodir/b.svg"],
                   setup=copy_setup((None, "out")), must_fail=True))
    for extra in (["params"], ["modes"], ["modes", "--format", "json"],
                  ["methods", "--freq", "1e-3:5:1"], ["mc", "--samples", "20", "--format", "json"]):
        cases.append(C(cat, f"{' '.join(extra)}: stdout to /dev/full", extra, stdout="devfull",
                       must_fail=True))
        cases.append(C(cat, f"{' '.join(extra)}: stdout to a pipe without reader", extra,
                       stdout="broken_pipe"))
    # `| head -c 1` is deterministic only when the output is larger than a pipe buffer (64 kB):
    # the program must write after the reader has gone.
    for extra in (["tf", "--freq", "1e-4:20000:30"], ["tf", "--freq", "1e-4:20000:30",
                                                      "--output", "X", "--input", "theta_t"],
                  ["--params", DAMPED, "tf", "--freq", "1e-4:5000:30"]):
        cases.append(C(cat, f"{' '.join(extra)}: stdout to /dev/full", extra, stdout="devfull",
                       must_fail=True))
        cases.append(C(cat, f"{' '.join(extra)}: stdout | head -c 1", extra,
                       stdout="close_after_1"))
    # same path as the input
    pairs = [
        ("budget --tilt in.csv --save in.csv", ["budget", "--tilt", "in.csv", "--save", "in.csv"],
         [(PETERSON, "in.csv")]),
        ("budget --tilt in.csv --save ./in.csv", ["budget", "--tilt", "in.csv", "--save",
                                                  "./in.csv"], [(PETERSON, "in.csv")]),
        ("budget --tilt ./in.csv --save in.csv", ["budget", "--tilt", "./in.csv", "--save",
                                                  "in.csv"], [(PETERSON, "in.csv")]),
        ("budget --tilt in.csv --save sub/../in.csv", ["budget", "--tilt", "in.csv", "--save",
                                                       "sub/../in.csv"],
         [(PETERSON, "in.csv"), (None, "sub")]),
        ("budget --tilt in.h5 --save in.h5", ["budget", "--tilt", "in.h5", "--nperseg", "4096",
                                              "--save", "in.h5"], [(LAB_H5, "in.h5")]),
        ("budget --tilt in.csv --measured m.csv --save m.csv",
         ["budget", "--tilt", "in.csv", "--measured", "m.csv", "--save", "m.csv"],
         [(PETERSON, "in.csv"), (str(write(inputs / "outputs" / "measured.csv",
                                           joined(measured_lines()))), "m.csv")]),
    ]
    for label, args, files in pairs:
        cases.append(C(cat, f"same path as input: {label}", args, setup=copy_setup(*files),
                       must_fail=True))

    def link_setup(ctx):
        shutil.copyfile(PETERSON, ctx.dir / "in.csv")
        os.symlink("in.csv", ctx.dir / "link.csv")

    cases.append(C(cat, "same path as input via a symlink: --tilt in.csv --save link.csv",
                   ["budget", "--tilt", "in.csv", "--save", "link.csv"], setup=link_setup,
                   must_fail=True))
    cases.append(C(cat, "same path as input via a symlink: --tilt link.csv --save in.csv",
                   ["budget", "--tilt", "link.csv", "--save", "in.csv"], setup=link_setup,
                   must_fail=True))

    def hardlink_setup(ctx):
        shutil.copyfile(PETERSON, ctx.dir / "in.csv")
        os.link(ctx.dir / "in.csv", ctx.dir / "hard.csv")

    cases.append(C(cat, "same file as input via a hard link",
                   ["budget", "--tilt", "in.csv", "--save", "hard.csv"], setup=hardlink_setup))
    return cases


# --------------------------------------------------------------------------------------------
# Category 5: process conditions


def cases_process() -> list[Case]:
    cat = "process"
    cases: list[Case] = []
    long_writes = [
        ("tf 3e6 points to HDF5", ["tf", "--freq", "1e-4:3000000:30", "--save", "big.h5"]),
        ("tf 1e6 points to CSV", ["tf", "--freq", "1e-4:1000000:30", "--save", "big.csv"]),
        ("simulate 2e6 s to HDF5", ["simulate", "--duration", "2e6", "--save", "sim.h5"]),
    ]
    for label, args in long_writes:
        for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
            cases.append(C(cat, f"{sig.name} during a long write: {label}", args, sig=sig,
                           sig_when="tempfile", timeout=60, serial=True))
    for sig in (signal.SIGINT, signal.SIGTERM):
        cases.append(C(cat, f"{sig.name} at 0.2 s: tf 3e6 points", long_writes[0][1], sig=sig,
                       sig_when=0.2, timeout=60, serial=True))
        cases.append(C(cat, f"{sig.name} at 0.05 s: budget with a saved figure",
                       ["budget", "--tilt", LAB_H5, "--save", "b.png", "--save", "b.h5"],
                       sig=sig, sig_when=0.05, timeout=60, serial=True))
    commands = [("params", ["params"]), ("modes", ["modes"]),
                ("tf to stdout", ["tf", "--freq", "1e-3:10:1"]),
                ("tf --save", ["tf", "--freq", "1e-3:10:1", "--save", "o.csv"]),
                ("budget", ["budget", "--tilt", PETERSON]),
                ("mc", ["mc", "--samples", "50"]),
                ("error (unknown key)", ["--set", "foo=1", "modes"]),
                ("error (missing input)", ["budget", "--tilt", "missing.csv"]),
                ("usage error", ["budget"])]
    for label, args in commands:
        err = label.startswith(("error", "usage"))
        cases.append(C(cat, f"stdin closed: {label}", args, stdin="closed", must_fail=err))
        cases.append(C(cat, f"stdout closed: {label}", args, stdout="closed", must_fail=err))
        cases.append(C(cat, f"stderr closed: {label}", args, stderr="closed", must_fail=err))
        if err:
            cases.append(C(cat, f"stderr to /dev/full: {label}", args, stderr="devfull",
                           must_fail=True))
    return cases


# --------------------------------------------------------------------------------------------
# Category 6: fuzz

INTERESTING_NUMBERS = [b"1e308", b"-1e308", b"1.7976931348623157e308", b"nan", b"NaN", b"-nan",
                       b"inf", b"-inf", b"-0", b"0", b"4.9e-324", b"1e-320", b"1e400", b"-1",
                       b"18446744073709551616", b"9" * 400, b"", b"1e", b".", b"0x10", b"1e-300",
                       b"2147483648", b"-9223372036854775809"]
NUMBER_RE = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
INTERESTING_WORDS = [0, 1, 0x7F, 0x80, 0xFF, 0x7FFF, 0xFFFF, 0x7FFFFFFF, 0xFFFFFFFF,
                     0x7FFFFFFFFFFFFFFF, 0xFFFFFFFFFFFFFFFF, 1 << 40, 1 << 31]
INTERESTING_BYTES = [0x00, 0xFF, 0x0A, 0x0D, 0x2C, 0x22, 0x23, 0x2D, 0x2E, 0x65, 0x3D, 0x5B,
                     0x7B, 0x80]


def fuzz_corpus(first_bin: str) -> dict[str, tuple[bytes, str, list[str]]]:
    """kind -> (seed content, file name, arguments)."""
    rng = np.random.default_rng(20240301)
    n = 512
    series = ["# units: rad", "time_s,theta_t,eta_t"] + [
        f"{i}.0,{1e-9 * float(rng.standard_normal())!r},{1e-9 * float(rng.standard_normal())!r}"
        for i in range(n)]
    spectrum = spectrum_lines(40)
    with tempfile.TemporaryDirectory() as t:
        p = Path(t) / "s.h5"
        with h5py.File(p, "w") as f:
            f.attrs["schema"] = "tiltnoise.tilt_series"
            f.attrs["sample_rate_hz"] = 1.0
            f.attrs["start_time"] = "2024-03-01T00:00:00Z"
            f.attrs["axis_map"] = "theta_t=-E,eta_t=-N"
            for ch in ("E", "N"):
                ds = f.create_dataset(ch, data=1e-9 * rng.standard_normal(256))
                ds.attrs["units"] = "rad"
        h5 = p.read_bytes()
    try:
        params = subprocess.run([first_bin, "params"], capture_output=True, timeout=60).stdout
    except Exception:  # noqa: BLE001
        params = b""
    if not params:
        params = b"[mass]\nm_a_kg = 1.2\nm_b_kg = 0.11\n"
    freq = b"# frequencies in Hz\n" + b"\n".join(
        repr(float(x)).encode() for x in np.logspace(-4, 1, 20)) + b"\n# end\n"
    fit = (b"mode,frequency_hz,sigma_hz\n1,1.331e-3,1e-5\n2,2.117e-3,1e-5\n3,0.406,0.002\n"
           b"4,0.4065,0.002\n5,0.58815,0.001\n6,0.617,0.001\n7,7.926,0.05\n8,10.393,0.05\n")
    # The readers added since: miniSEED, gwpy addresses, HDF5 spectra, ASD files.
    x = (1e-9 * rng.standard_normal(200)).tolist()
    mseed = (surfaces.mseed_records("XX.TILT.00.BAE", x, 1.0)
             + surfaces.mseed_records("XX.TILT.00.BAN", x[::-1], 1.0))
    with tempfile.TemporaryDirectory() as t:
        gw = surfaces.gwpy_file(Path(t) / "gw.h5", n=256).read_bytes()
        sp = h5_spectra(Path(t) / "sp.h5", n=20).read_bytes()
    asd = joined(["frequency_hz,asd"] + [f"{f!r},1e-9" for f in np.logspace(-5, 1, 20).tolist()])
    return {
        "csv_series": (joined(series).encode(), "in.csv", ["budget", "--tilt", "in.csv"]),
        "csv_spectrum": (joined(spectrum).encode(), "in.csv", ["budget", "--tilt", "in.csv"]),
        "h5_series": (h5, "in.h5", ["budget", "--tilt", "in.h5"]),
        "params_toml": (params, "in.toml", ["--params", "in.toml", "modes"]),
        "freq_file": (freq, "in.txt", ["tf", "--freq-file", "in.txt", "--input", "theta_t",
                                       "--output", "X"]),
        "measured_csv": (joined(measured_lines(40)).encode(), "m.csv",
                         ["budget", "--tilt", PETERSON, "--measured", "m.csv"]),
        "fit_csv": (fit, "in.csv", ["fit", "--measured", "in.csv", "--format", "json"]),
        "mseed": (mseed, "in.mseed", ["budget", "--tilt", "in.mseed", "--axes",
                                      "theta_t=-BAE,eta_t=-BAN", "--nperseg", "64"]),
        "gwpy": (gw, "in.h5", ["budget", "--tilt", "in.h5:/", "--axes",
                               "theta_t=theta,eta_t=eta", "--nperseg", "64"]),
        "h5_spectra": (sp, "in.h5", ["budget", "--tilt", "in.h5"]),
        "readout_asd": (asd.encode(), "r.csv", ["budget", "--tilt", PETERSON, "--readout",
                                                "X=r.csv"]),
    }


# Fuzz kinds whose seeds are binary files: mutated byte-wise, never number by number.
BINARY_KINDS = {"h5_series", "mseed", "gwpy", "h5_spectra"}


def mutate(data: bytes, rng: random.Random, binary_format: bool) -> tuple[bytes, list[str]]:
    buf = bytearray(data)
    ops = []
    for _ in range(rng.choice([1, 1, 1, 1, 2, 2, 3, 4, 8])):
        if binary_format:
            op = rng.choice(["flip", "flip", "byte", "word", "word", "word", "insert", "delete",
                             "dup", "truncate"])
        else:
            op = rng.choice(["flip", "byte", "insert", "delete", "dup", "truncate", "number",
                             "number", "number", "number", "number", "number", "dupline"])
        if not buf and op not in ("insert",):
            op = "insert"

        def pos(span=1):
            if binary_format and rng.random() < 0.7:
                return rng.randrange(0, max(1, min(len(buf) - span + 1, 2048)))
            return rng.randrange(0, max(1, len(buf) - span + 1))

        if op == "flip":
            i = pos()
            buf[i] ^= 1 << rng.randrange(8)
        elif op == "byte":
            buf[pos()] = rng.choice(INTERESTING_BYTES + [rng.randrange(256)])
        elif op == "word":
            size = rng.choice([1, 2, 4, 8])
            if len(buf) < size:
                continue
            i = pos(size)
            if rng.random() < 0.3 and size == 8:
                val = np.array([rng.choice([np.nan, np.inf, -np.inf, 1e308, 5e-324, -0.0])],
                               dtype="<f8").tobytes()
            else:
                w = rng.choice(INTERESTING_WORDS) & ((1 << (8 * size)) - 1)
                val = w.to_bytes(size, rng.choice(["little", "big"]))
            buf[i:i + size] = val
        elif op == "insert":
            i = rng.randrange(0, len(buf) + 1)
            buf[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 8)))
        elif op == "delete":
            i = pos()
            del buf[i:i + rng.randint(1, 16)]
        elif op == "dup":
            i = pos()
            chunk = bytes(buf[i:i + rng.randint(1, 256)])
            j = rng.randrange(0, len(buf) + 1)
            buf[j:j] = chunk * rng.choice([1, 1, 2, 16])
        elif op == "truncate":
            del buf[rng.randrange(0, len(buf) + 1):]
        elif op == "number":
            nums = list(NUMBER_RE.finditer(bytes(buf)))
            if not nums:
                continue
            m = rng.choice(nums)
            buf[m.start():m.end()] = rng.choice(INTERESTING_NUMBERS)
        elif op == "dupline":
            lines = bytes(buf).split(b"\n")
            k = rng.randrange(len(lines))
            lines[k:k] = [lines[k]] * rng.choice([1, 2, 100])
            buf = bytearray(b"\n".join(lines))
        ops.append(op)
    return bytes(buf), ops


def cases_fuzz(corpus, iterations: int, seed: int) -> list[Case]:
    kinds = sorted(corpus)
    cases = []
    for i in range(iterations):
        kind = kinds[i % len(kinds)]
        content, name, args = corpus[kind]
        rng = random.Random(f"{seed}:{i}")
        data, ops = mutate(content, rng, kind in BINARY_KINDS)

        def setup(ctx, data=data, name=name):
            write(ctx.dir / name, data)

        cases.append(C("fuzz", f"{kind} #{i} ({'+'.join(ops) or 'none'})", args, setup=setup,
                       timeout=SHORT_TIMEOUT, artifacts=[name]))
    return cases


# --------------------------------------------------------------------------------------------
# Running and classifying


def snapshot(root: Path) -> dict[str, tuple]:
    out = {}
    for dirpath, dirnames, filenames in os.walk(root, followlinks=False):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            try:
                st = p.lstat()
            except OSError:
                continue
            out[str(p.relative_to(root))] = (stat.S_IFMT(st.st_mode), st.st_size, st.st_mtime_ns,
                                             st.st_ino)
    return out


def neutralize_allowed(s: str) -> str:
    for pat in ALLOWED_STDOUT:
        s = pat.sub(lambda m: re.sub(r"(?i)nan|inf", "allowed", m.group(0)), s)
    return s


def is_temp_name(rel: str) -> bool:
    base = os.path.basename(rel)
    return any(r.match(base) for r in TEMP_NAME_RES)


class StreamScanner(threading.Thread):
    """Drains a pipe; keeps its head and scans it line by line for non-finite numbers."""

    def __init__(self, fileobj, huge: bool, close_after: int | None = None, cap: int | None = None):
        super().__init__(daemon=True)
        self.fd = fileobj
        self.huge = huge
        self.close_after = close_after
        self.cap = cap
        self.head = bytearray()
        self.total = 0
        self.evidence: list[str] = []
        self.data = bytearray()

    def scan(self, text: bytes):
        if len(self.evidence) >= 5:
            return
        s = text.decode("utf-8", "replace")
        s = neutralize_allowed(s)
        for m in NONFINITE_RE.finditer(s):
            line_start = s.rfind("\n", 0, m.start()) + 1
            line_end = s.find("\n", m.end())
            line = s[line_start: line_end if line_end >= 0 else len(s)]
            self.evidence.append("stdout: " + line[:160])
            if len(self.evidence) >= 5:
                return
        if self.huge:
            for m in HUGE_ZERO_RE.finditer(s):
                line_start = s.rfind("\n", 0, m.start()) + 1
                self.evidence.append("stdout (huge case): " + s[line_start:line_start + 160]
                                     .split("\n")[0])
                if len(self.evidence) >= 5:
                    return

    def run(self):
        fd = self.fd.fileno()
        if self.close_after is not None:
            try:
                self.head += os.read(fd, self.close_after)
            except OSError:
                pass
            self.fd.close()
            return
        pending = b""
        while True:
            try:
                chunk = os.read(fd, 1 << 16)
            except OSError:
                break
            if not chunk:
                break
            self.total += len(chunk)
            if self.cap is not None:
                if len(self.data) < self.cap:
                    self.data += chunk[: self.cap - len(self.data)]
                continue
            if len(self.head) < STDOUT_HEAD:
                self.head += chunk[: STDOUT_HEAD - len(self.head)]
            pending += chunk
            cut = pending.rfind(b"\n")
            if cut >= 0:
                self.scan(pending[: cut + 1])
                pending = pending[cut + 1:]
            if len(pending) > (1 << 20):
                self.scan(pending)
                pending = b""
        if pending and self.cap is None:
            self.scan(pending)
        self.fd.close()


def scan_text_file(path: Path, csv: bool) -> list[str]:
    with open(path, "rb") as fh:
        data = fh.read(TEXT_SCAN_CAP)
    s = data.decode("utf-8", "replace")
    ev = []
    if csv:
        header = None
        for line in s.splitlines():
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            if header is None:
                header = [h.strip() for h in line.split(",")]
                continue
            if not NONFINITE_RE.search(line):
                continue
            for i, field_ in enumerate(line.split(",")):
                if NONFINITE_FIELD_RE.match(field_):
                    col = header[i] if i < len(header) else f"#{i}"
                    if not ALLOWED_NONFINITE_NAMES.search(col):
                        ev.append(f"{path.name}: column {col} = {field_.strip()}")
                        if len(ev) >= 3:
                            return ev
        return ev
    s = neutralize_allowed(s)
    for m in NONFINITE_RE.finditer(s):
        ev.append(f"{path.name}: ...{s[max(0, m.start() - 40):m.end() + 20]}...")
        if len(ev) >= 3:
            break
    return ev


def scan_h5_file(path: Path) -> list[str]:
    ev: list[str] = []
    budget = [H5_SCAN_CAP]
    try:
        f = h5py.File(path, "r")
    except Exception as e:  # noqa: BLE001
        return [f"{path.name}: unreadable HDF5 output ({type(e).__name__})"]

    def check_array(a, where):
        a = np.asarray(a)
        if a.dtype.names:
            for n in a.dtype.names:
                check_array(a[n], f"{where}.{n}")
            return
        if a.dtype.kind in "fc" and a.size and not np.isfinite(a).all():
            bad = np.asarray(a)[~np.isfinite(a)].ravel()[0]
            ev.append(f"{path.name}: {where} has {bad}")

    def visit(name, obj):
        if len(ev) >= 5:
            return
        for k, v in obj.attrs.items():
            try:
                check_array(v, f"/{name}@{k}")
            except Exception:  # noqa: BLE001
                pass
        if not isinstance(obj, h5py.Dataset) or ALLOWED_NONFINITE_NAMES.search(name):
            return
        dt = obj.dtype
        if not (dt.kind in "fc" or (dt.names and any(dt[n].kind in "fc" for n in dt.names))):
            return
        if obj.shape == ():
            check_array(obj[()], "/" + name)
            return
        step = max(1, 1_000_000 // max(1, int(np.prod(obj.shape[1:]))))
        for s in range(0, obj.shape[0], step):
            if budget[0] <= 0:
                ev.append(f"{path.name}: scan stopped after {H5_SCAN_CAP} elements") \
                    if not any("scan stopped" in e for e in ev) else None
                return
            block = obj[s:s + step]
            budget[0] -= block.size
            check_array(block, f"/{name}[{s}:]")
            if len(ev) >= 5:
                return

    try:
        with f:
            visit("", f)
            f.visititems(visit)
    except Exception as e:  # noqa: BLE001
        ev.append(f"{path.name}: error while scanning ({type(e).__name__}: {e})")
    return [e for e in ev if "scan stopped" not in e]


def null_evidence(stdout_head: bytes, root: Path, rels: list[str], keys: str) -> list[str]:
    """`null` values of the JSON keys matching `keys` on stdout or in a written .json file."""
    pat = re.compile(r'"(' + keys + r')"\s*:\s*(null|\[[^\]]*\bnull\b[^\]]*\])')
    texts = [("stdout", stdout_head.decode("utf-8", "replace"))]
    for rel in rels:
        p = root / rel
        if p.suffix.lower() == ".json" and p.is_file():
            texts.append((p.name, p.read_text(errors="replace")[:TEXT_SCAN_CAP]))
    ev = []
    for where, text in texts:
        for m in pat.finditer(text):
            ev.append(f"{where}: {m.group(0)[:120]}")
    return ev[:5]


def scan_outputs(root: Path, rels: list[str]) -> list[str]:
    ev = []
    for rel in rels:
        p = root / rel
        if not p.is_file() or p.is_symlink() and not p.exists():
            continue
        ext = p.suffix.lower()
        if ext in (".h5", ".hdf5"):
            ev += scan_h5_file(p)
        elif ext == ".png":
            continue
        else:
            ev += scan_text_file(p, ext == ".csv")
    return ev


def make_preexec(close_fds: list[int]):
    def preexec():
        resource.setrlimit(resource.RLIMIT_AS, (MEM_LIMIT, MEM_LIMIT))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        for fd in close_fds:
            try:
                os.close(fd)
            except OSError:
                pass
    return preexec


def child_env() -> dict:
    env = dict(os.environ)
    env["RUST_BACKTRACE"] = "0"
    env.pop("RUST_LIB_BACKTRACE", None)
    env["LC_ALL"] = "C"
    return env


def remove_tree(path: Path):
    def onerror(func, p, exc):
        subprocess.run(["chattr", "-R", "-i", str(path)], capture_output=True)
        try:
            func(p)
        except OSError:
            pass
    if path.exists():
        shutil.rmtree(path, onerror=onerror)
        if path.exists():
            shutil.rmtree(path, ignore_errors=True)


def execute(case: Case, binary: str, workroot: Path, keep_scratch: bool,
            crash_dir: Path | None, label: str) -> dict:
    cdir = Path(tempfile.mkdtemp(prefix="case-", dir=workroot))
    ctx = Ctx(cdir, binary)
    timeout = case.timeout or DEFAULT_TIMEOUT
    rec = {"binary": binary, "category": case.cat, "case": case.name,
           "command": display_command(case, binary), "must_fail": case.must_fail,
           "must_succeed": case.must_succeed}
    try:
        if case.setup:
            case.setup(ctx)
        args = []
        for a in case.args:
            if isinstance(a, ArgFromFile):
                args.append((cdir / str(a)).read_text())
            else:
                args.append(a)
        # The displayed command names the value a setup computed.
        if args != case.args:
            rec["command"] = shlex.join([binary] + [shown(a) for a in args])
    except Exception as e:  # noqa: BLE001
        rec.update(classification="setup-error", flags=[], note=f"{type(e).__name__}: {e}")
        for fin in ctx.finalizers:
            fin()
        if not keep_scratch:
            remove_tree(cdir)
        return rec
    before = snapshot(cdir)
    close = []
    stdin = subprocess.DEVNULL
    if case.stdin == "closed":
        stdin, close = None, close + [0]
    devfull = []
    if case.stdout == "closed":
        stdout = None
        close.append(1)
    elif case.stdout == "devfull":
        devfull.append(open("/dev/full", "wb"))
        stdout = devfull[-1]
    elif case.stdout == "broken_pipe":
        r_end, w_end = os.pipe()
        os.close(r_end)
        devfull.append(os.fdopen(w_end, "wb"))
        stdout = devfull[-1]
    else:
        stdout = subprocess.PIPE
    if case.stderr == "closed":
        stderr = None
        close.append(2)
    elif case.stderr == "devfull":
        devfull.append(open("/dev/full", "wb"))
        stderr = devfull[-1]
    else:
        stderr = subprocess.PIPE
    initial_names = set(os.listdir(cdir))
    argv, env = [binary] + args, child_env()
    if case.python is not None:
        if binary not in PYTHONS:
            rec.update(classification="setup-error", flags=[],
                       note="no --python for this binary")
            if not keep_scratch:
                remove_tree(cdir)
            return rec
        exe, extra_env = PYTHONS[binary]
        argv = [exe, PY_CASE, case.python]
        env.update(extra_env)
    t0 = time.monotonic()
    try:
        proc = subprocess.Popen(argv, cwd=cdir, stdin=stdin, stdout=stdout,
                                stderr=stderr, preexec_fn=make_preexec(close),
                                start_new_session=True, env=env)
    except OSError as e:
        rec.update(classification="setup-error", flags=[], note=f"cannot start: {e}")
        for fin in ctx.finalizers:
            fin()
        if not keep_scratch:
            remove_tree(cdir)
        return rec
    finally:
        for fh in devfull:
            fh.close()
    out_scan = err_scan = None
    if stdout is subprocess.PIPE:
        out_scan = StreamScanner(proc.stdout, case.huge,
                                 close_after=1 if case.stdout == "close_after_1" else None)
        out_scan.start()
    if stderr is subprocess.PIPE:
        err_scan = StreamScanner(proc.stderr, False, cap=STDERR_CAP)
        err_scan.start()
    timed_out = False
    sent = None
    while True:
        try:
            rc = proc.wait(timeout=0.02 if case.sig and sent is None else
                           max(0.01, t0 + timeout - time.monotonic()))
            break
        except subprocess.TimeoutExpired:
            now = time.monotonic()
            if case.sig and sent is None:
                fire = False
                if case.sig_when == "tempfile":
                    if set(os.listdir(cdir)) - initial_names:
                        time.sleep(0.3)
                        fire = True
                    elif now - t0 > timeout - 5:  # never appeared: signal before the end
                        fire = True
                elif now - t0 >= float(case.sig_when):
                    fire = True
                if fire:
                    try:
                        os.kill(proc.pid, case.sig)
                        sent = time.monotonic() - t0
                    except ProcessLookupError:
                        pass
            if now >= t0 + timeout:
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
                timed_out = True
                rc = proc.wait()
                break
    duration = time.monotonic() - t0
    try:  # leftovers of a killed process group
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    for s in (out_scan, err_scan):
        if s:
            s.join(10)
    for fin in ctx.finalizers:
        fin()
    after = snapshot(cdir)
    new = sorted(k for k in after if k not in before)
    changed = sorted(k for k in after if k in before and after[k] != before[k])
    stderr_text = bytes(err_scan.data).decode("utf-8", "replace") if err_scan else None

    sig = -rc if rc < 0 else None
    flags = []
    panic = (rc == 101) or (stderr_text is not None and "panicked at" in stderr_text)
    oom_msg = stderr_text is not None and "memory allocation of" in stderr_text
    expected_sig = {case.sig} if case.sig else set()
    if case.stdout in ("close_after_1", "broken_pipe"):
        expected_sig.add(signal.SIGPIPE)
    if timed_out:
        flags.append("hang")
    elif panic:
        flags.append("panic")
    elif sig in expected_sig:
        pass
    elif oom_msg or sig == signal.SIGABRT or sig == signal.SIGKILL:
        flags.append("abort_oom")
    elif sig is not None:
        flags.append("crash")
    failed = timed_out or rc != 0
    controlled = failed and not timed_out and sig is None and not panic and not oom_msg
    if rc == 0:
        ev = out_scan.evidence if out_scan and case.stdout == "pipe" else []
        ev = ev + scan_outputs(cdir, new + changed)
        if case.nonfinite_only:
            ev = [e for e in ev if re.search(case.nonfinite_only, e)]
        if case.null_keys:
            ev = ev + null_evidence(bytes(out_scan.head) if out_scan else b"", cdir,
                                    new + changed, case.null_keys)
        if ev:
            flags.append("nonfinite")
            rec["nonfinite_evidence"] = ev[:5]
    # An input overwritten: a regular file that was there before the run and changed (content,
    # size, time or inode) or went away.
    overwritten = [k for k, v in before.items()
                   if v[0] == stat.S_IFREG and after.get(k) != v]
    if overwritten:
        flags.append("overwrote")
        rec["overwritten"] = overwritten[:10]
    temp_new = [k for k in new if is_temp_name(k)]
    if (failed and new) or temp_new:
        flags.append("leftover")
        rec["left_behind"] = new[:10]
    if case.must_fail and rc == 0:
        flags.append("ignored" if case.ignored_option else "accepted")
    if case.must_succeed and controlled:
        flags.append("refused")
    if controlled and stderr_text is not None:
        lines = stderr_text.rstrip("\n")
        nlines = lines.count("\n") + 1 if lines else 0
        if nlines > 1:
            flags.append("multiline")
        if nlines == 0:
            flags.append("silent")
    if controlled and rc != 2 and not case.sig:
        flags.append("exit_not_2")
    if (case.culprit and controlled and (case.must_fail or case.culprit_if_fails)
            and stderr_text is not None
            and not re.search(case.culprit, stderr_text, re.S)):
        flags.append("unclear")
    order = FLAGS
    primary = next((f for f in order if f in flags), None)
    rec.update(
        exit_code=rc if rc >= 0 else None,
        signal=signal.Signals(sig).name if sig else None,
        timed_out=timed_out,
        signal_sent_at_s=round(sent, 3) if sent is not None else None,
        duration_s=round(duration, 3),
        stderr_head=stderr_text[:300] if stderr_text is not None else None,
        stdout_bytes=out_scan.total if out_scan else None,
        new_files=new[:20],
        changed_files=changed[:20],
        flags=flags,
        classification=primary or ("ok" if rc == 0 else "error"),
    )
    if crash_dir and any(f in flags for f in ("crash", "abort_oom", "panic", "hang")):
        keep_crasher(rec, case, args, binary, cdir, crash_dir, label)
    if not keep_scratch:
        remove_tree(cdir)
    return rec


_CRASH_LOCK = threading.Lock()
_CRASH_COUNT: dict[str, int] = {}


def keep_crasher(rec, case, args, binary, cdir: Path, crash_dir: Path, label: str):
    with _CRASH_LOCK:
        n = _CRASH_COUNT.get(label, 0) + 1
        _CRASH_COUNT[label] = n
    slug = re.sub(r"[^A-Za-z0-9_.-]+", "_", f"{case.cat}-{case.name}")[:80]
    dst = crash_dir / label / f"{n:04d}-{slug}"
    dst.mkdir(parents=True, exist_ok=True)
    files = []
    prelude: list[str] = []
    local_args = list(args)
    for a in list(case.artifacts) + [a for a in args if a and len(a) < 4096]:
        p = Path(a) if os.path.isabs(a) else cdir / a
        try:
            if p.is_file() and not p.is_symlink() and p.stat().st_size <= ARTIFACT_CAP:
                shutil.copyfile(p, dst / p.name)
                files.append(p.name)
                # The generated inputs are deleted after the audit: name the kept copy.
                if os.path.isabs(a) and not a.startswith(str(REPO)):
                    local_args = [p.name if x == a else x for x in local_args]
        except OSError:
            pass
        if os.path.isabs(a) and os.path.islink(a) and os.readlink(a).startswith("/dev/"):
            prelude.append(shlex.join(["ln", "-sf", os.readlink(a), os.path.basename(a)]))
            local_args = [os.path.basename(a) if x == a else x for x in local_args]
    shown_cmd = (shlex.join([binary] + local_args) if all(len(a) < 4096 for a in local_args)
                 else rec["command"])
    (dst / "command.txt").write_text(
        f"# {rec['classification']}: {case.cat} / {case.name}\n"
        f"# run in this directory (it holds: {', '.join(files) or 'no input files'})\n"
        + "".join(line + "\n" for line in prelude)
        + f"{shown_cmd}\n"
        f"# exit {rec['exit_code']} signal {rec['signal']} timed_out {rec['timed_out']}\n")
    (dst / "stderr.txt").write_text(rec.get("stderr_head") or "")
    rec["crasher_dir"] = str(dst)


# --------------------------------------------------------------------------------------------
# Report


def category_table(counts, binaries, columns, titles):
    """A markdown table of `counts[(category, binary)][column]`, one row per category and a
    total, each cell `B1 / B2 / ...`; returns its lines."""
    head = ["category", *titles]
    lines = ["| " + " | ".join(head) + " |",
             "|" + "|".join(["---"] + ["---:"] * (len(head) - 1)) + "|"]
    totals = {b: dict.fromkeys(columns, 0) for b in binaries}
    for c in [c for c in CATEGORIES if any((c, b) in counts for b in binaries)]:
        cells = [c]
        for col in columns:
            vals = []
            for b in binaries:
                v = counts.get((c, b), {}).get(col, 0)
                totals[b][col] += v
                vals.append(str(v))
            cells.append(" / ".join(vals))
        lines.append("| " + " | ".join(cells) + " |")
    lines.append("| **total** | " + " | ".join(" / ".join(str(totals[b][col]) for b in binaries)
                                               for col in columns) + " |")
    return lines


def summarize(records, binaries, labels):
    """Every flag per category, and the time spent in each binary."""
    counts: dict = {}
    time_s = dict.fromkeys(binaries, 0.0)
    for r in records:
        row = counts.setdefault((r["category"], r["binary"]), {"cases": 0, **dict.fromkeys(FLAGS, 0)})
        row["cases"] += 1
        time_s[r["binary"]] += r.get("duration_s") or 0.0
        for f in r.get("flags", []):
            row[f] += 1
    lines = ["Cells are " + " / ".join(labels[b] for b in binaries) + "; "
             + "; ".join(f"{labels[b]} = `{b}`" for b in binaries) + ".", ""]
    lines += category_table(counts, binaries, ["cases", *TABLE_FLAGS],
                            ["cases", *(FLAG_TITLES[f] for f in TABLE_FLAGS)])
    lines += ["", "Time in the binary (sum over cases): " + ", ".join(
        f"{labels[b]} {time_s[b]:.1f} s" for b in binaries)]
    return "\n".join(lines)


def summarize_kinds(records, binaries, labels):
    """Cases per category and the defects by kind (KINDS; a case counts once per kind)."""
    counts: dict = {}
    for r in records:
        row = counts.setdefault((r["category"], r["binary"]), dict.fromkeys(["cases", *KINDS], 0))
        row["cases"] += 1
        flags = set(r.get("flags", []))
        for kind, members in KINDS.items():
            row[kind] += bool(flags & set(members))
    return "\n".join(category_table(counts, binaries, ["cases", *KINDS], ["cases", *KINDS]))


def defect_classes(records, binaries, labels):
    out = []
    for b in binaries:
        out.append(f"### Defect classes in {labels[b]} (`{b}`)")
        out.append("")
        groups: dict[tuple, list] = {}
        for r in records:
            if r["binary"] != b:
                continue
            for f in r.get("flags", []):
                groups.setdefault((f, r["category"]), []).append(r)
        if not groups:
            out.append("none")
        for (f, cat) in sorted(groups, key=lambda k: (FLAGS.index(k[0]), CATEGORIES.index(k[1]))):
            rs = groups[(f, cat)]
            ex = min(rs, key=lambda r: len(r["command"]))
            detail = ""
            if f == "nonfinite" and ex.get("nonfinite_evidence"):
                detail = f" -> {ex['nonfinite_evidence'][0][:120]}"
            elif f == "leftover":
                detail = f" -> left {ex.get('left_behind', [])[:3]}"
            elif ex.get("stderr_head"):
                detail = " -> " + ex["stderr_head"].strip().replace("\n", " | ")[:140]
            elif ex.get("signal"):
                detail = f" -> {ex['signal']}"
            out.append(f"- **{FLAG_TITLES[f]}** / {cat}: {len(rs)} case(s); e.g. "
                       f"{ex['case']}: `{ex['command']}`{detail}")
        out.append("")
    return "\n".join(out)


def main(argv=None) -> int:
    global DEFAULT_TIMEOUT
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bin", action="append", required=True, help="binary to audit (repeatable)")
    ap.add_argument("--fuzz-iterations", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None,
                    help="output directory (inputs, scratch, crashers); default: a new temp dir")
    ap.add_argument("--json", type=Path, default=None, help="write all per-case records here")
    ap.add_argument("--jobs", type=int, default=2, help="parallel cases (default 2)")
    ap.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT)
    ap.add_argument("--only", default=None,
                    help="comma-separated categories to run (default: all)")
    ap.add_argument("--keep-scratch", action="store_true")
    ap.add_argument("--keep-inputs", action="store_true")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--python", action="append", default=[],
                    help="the Python of the binary in the same position: an interpreter with "
                         "tiltnoise installed, or a directory holding the package (put on "
                         "PYTHONPATH of this interpreter); repeatable, one per --bin")
    ap.add_argument("--require-clean", action="store_true",
                    help="exit 1 if any case has a defect flag other than hang (timing "
                         "depends on the machine's load); for CI")
    ap.add_argument("--fast", action="store_true",
                    help="CI's pass: every category but the signal cases of long writes, "
                         "the 1 GB and 100 MB inputs and the 4 GiB Python cases")
    a = ap.parse_args(argv)

    DEFAULT_TIMEOUT = a.timeout
    binaries = [str(Path(b).resolve()) if os.sep in b else b for b in a.bin]
    for b in binaries:
        if not (os.path.isfile(b) and os.access(b, os.X_OK)):
            print(f"hostile_cli: not an executable file: {b}", file=sys.stderr)
            return 2
    for p in (LAB_H5, PETERSON, DAMPED):
        if not os.path.isfile(p):
            print(f"hostile_cli: missing repository file {p}", file=sys.stderr)
            return 2
    labels = {b: f"B{i + 1}" for i, b in enumerate(binaries)}
    if len(a.python) > len(binaries):
        print("hostile_cli: more --python than --bin", file=sys.stderr)
        return 2
    for b, py in zip(binaries, a.python):
        if os.path.isdir(py):
            path = os.pathsep.join([py, *filter(None, [os.environ.get("PYTHONPATH")])])
            PYTHONS[b] = (sys.executable, {"PYTHONPATH": path})
        elif os.path.isfile(py) and os.access(py, os.X_OK):
            PYTHONS[b] = (py, {})
        else:
            print(f"hostile_cli: --python {py}: neither an interpreter nor a directory",
                  file=sys.stderr)
            return 2
    out = a.out or Path(tempfile.mkdtemp(prefix="hostile-cli-"))
    out.mkdir(parents=True, exist_ok=True)
    inputs = out / "inputs"
    scratch = out / "scratch"
    crash_dir = out / "crashers"
    for p in (inputs, scratch):
        remove_tree(p)
        p.mkdir(parents=True)
    remove_tree(crash_dir)
    only = set(s.strip() for s in a.only.split(",")) if a.only else set(CATEGORIES)

    t_start = time.monotonic()
    have_chattr = chattr_available()
    cases: list[Case] = []
    if "parameters" in only:
        cases += cases_parameters(inputs, param_keys(binaries), params_text(binaries[0]))
    if "tilt inputs" in only:
        cases += cases_tilt(inputs)
    if "frequency options" in only:
        cases += cases_frequency(inputs)
    if "outputs" in only:
        cases += cases_outputs(inputs, have_chattr)
    if only & set(NEW_SURFACES) or "process" in only:
        surfaces.pair_inputs(inputs, binaries[0])
        for cat, build in [("miniseed", surfaces.cases_miniseed),
                           ("gwpy addressing", surfaces.cases_gwpy),
                           ("coherence/subtract pairs", surfaces.cases_pairs),
                           ("option edges", surfaces.cases_option_edges),
                           ("python", surfaces.cases_python)]:
            if cat in only:
                cases += build(inputs)
        if only & set(newest.CATEGORIES):
            newest.newest_inputs(inputs, binaries[0])
            for cat, build in newest.CATEGORIES.items():
                if cat in only:
                    cases += build(inputs)
        if "process" in only:
            cases += surfaces.cases_process_new()
    if "process" in only:
        cases += cases_process()
    if "fuzz" in only and a.fuzz_iterations > 0:
        cases += cases_fuzz(fuzz_corpus(binaries[0]), a.fuzz_iterations, a.seed)
    if a.fast:
        cases = [c for c in cases if not c.serial and not any(
            big in c.name for big in ("1 GB", "100 MB", "50 MB", "10 MB"))]
    if a.list:
        for c in cases:
            print(f"{c.cat}\t{c.name}\t{display_command(c, 'tiltnoise')}")
        return 0
    print(f"hostile_cli: {len(cases)} cases x {len(binaries)} binaries; output in {out}",
          file=sys.stderr)
    if not have_chattr:
        print("hostile_cli: chattr +i does not work here: read-only directory cases skipped",
              file=sys.stderr)

    tasks = [(c, b) for c in cases if not c.serial for b in binaries]
    serial = [(c, b) for c in cases if c.serial for b in binaries]
    records: list[dict] = []
    done = [0]
    lock = threading.Lock()
    total = len(tasks) + len(serial)

    def run(task):
        c, b = task
        r = execute(c, b, scratch, a.keep_scratch, crash_dir, labels[b])
        with lock:
            done[0] += 1
            if done[0] % 200 == 0 or done[0] == total:
                print(f"hostile_cli: {done[0]}/{total} runs, "
                      f"{time.monotonic() - t_start:.0f} s", file=sys.stderr)
        return r

    with ThreadPoolExecutor(max_workers=max(1, a.jobs)) as pool:
        records += list(pool.map(run, tasks))
    for t in serial:
        records.append(run(t))
    wall = time.monotonic() - t_start

    print("## Hostile-input audit of the tiltnoise command line")
    print()
    print(f"{len(cases)} cases per binary (fuzz: {a.fuzz_iterations} iterations, seed {a.seed}); "
          f"wall time {wall:.0f} s with {a.jobs} worker(s).")
    print()
    print("Defects by kind (a case counts once per kind):")
    print()
    print(summarize_kinds(records, binaries, labels))
    print()
    print("Every flag:")
    print()
    print(summarize(records, binaries, labels))
    print()
    print(defect_classes(records, binaries, labels))
    setup_errors = [r for r in records if r.get("classification") == "setup-error"]
    if setup_errors:
        print(f"{len(setup_errors)} case(s) could not be set up, e.g. {setup_errors[0]['case']}: "
              f"{setup_errors[0].get('note')}")
    if a.json:
        a.json.parent.mkdir(parents=True, exist_ok=True)
        a.json.write_text(json.dumps({
            "binaries": {labels[b]: b for b in binaries},
            "seed": a.seed, "fuzz_iterations": a.fuzz_iterations,
            "wall_time_s": round(wall, 1), "chattr": have_chattr,
            "records": records}, indent=1))
    if not a.keep_inputs:
        remove_tree(inputs)
    if not a.keep_scratch:
        remove_tree(scratch)
    if crash_dir.exists():
        print(f"Crashing, aborting, panicking and hanging inputs: {crash_dir}")
    defective = [r for r in records if set(r.get("flags", [])) - {"hang"}]
    if a.require_clean and (defective or setup_errors):
        for r in (defective + setup_errors)[:20]:
            print(f"hostile_cli: {r['category']} / {r['case']}: {r.get('flags') or r.get('note')}",
                  file=sys.stderr)
        print(f"hostile_cli: {len(defective)} case(s) with defects, {len(setup_errors)} could "
              "not be set up", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
