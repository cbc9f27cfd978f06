"""Cases of the hostile-input audit for the surfaces added after the first audit: miniSEED, gwpy
addressing, `coherence` and `subtract` on pairs of records, the options of every command at their
edges (repeated keys, values whose derived quantities overflow or underflow), the Python package,
and the process conditions of the new commands.

Imported by hostile_cli.py, which runs the cases; the case type and the input helpers come from
case_kit.py, shared with hostile_cli.py. See README.md for the categories.
"""
from __future__ import annotations

import math
import os
import shutil
import signal
import struct
import subprocess
from pathlib import Path

import h5py
import numpy as np

from case_kit import (LAB_H5, PETERSON, REPO, C, chain, copy_setup, h5_measured, joined,
                      measured_lines, write)

# A valid pair of records: the lab tilt (86400 s at 1 Hz) and the observables the pendulum
# model answers it with (made by the first binary's `simulate --tilt` when the inputs are
# generated; see pair_inputs).
PAIR_TILT = "tilt.h5"
PAIR_MEASURED = "meas.h5"

# The stem of an error about a value out of its documented magnitudes, or non-finite: the
# message must name the value.
E308 = r"1e308|1\.0+e\+?308|1e\+308"


# --------------------------------------------------------------------------------------------
# miniSEED 2 records written by hand (no ObsPy): fixed header, blockette 1000, data.

ENCODINGS = {"int16": (1, "h", 2), "int32": (3, "i", 4), "float32": (4, "f", 4),
             "float64": (5, "d", 8)}


def _btime(t: float) -> tuple[int, int, int, int, int, int]:
    """(year, day of year, hour, minute, second, 1e-4 s) of `t` s after 2024-03-20T00:00:00."""
    day0 = 80
    ticks = round(t * 10_000)
    secs, frac = divmod(ticks, 10_000)
    days, secs = divmod(secs, 86_400)
    hour, secs = divmod(secs, 3600)
    minute, sec = divmod(secs, 60)
    return 2024, day0 + days, hour, minute, sec, frac


def _rate_fields(fs: float) -> tuple[int, int]:
    if fs >= 1 and float(fs).is_integer() and fs < 32768:
        return int(fs), 1
    if fs < 1 and float(1 / fs).is_integer() and 1 / fs < 32768:
        return -int(1 / fs), 1
    return int(round(fs * 1000)), -1000


def mseed_records(code: str, samples, fs: float, encoding="float64", byteorder=">",
                  reclen=512, t0=0.0, edit=None) -> bytes:
    """The records of one channel `NET.STA.LOC.CHA`; `edit(i, header: bytearray)` may change
    record i's fixed header and blockette (the first 64 bytes) before it is written."""
    net, sta, loc, cha = code.split(".")
    enc, fmt, size = ENCODINGS[encoding]
    per = (reclen - 64) // size
    factor, mult = _rate_fields(fs)
    out = bytearray()
    samples = list(samples)
    for i, start in enumerate(range(0, len(samples), per)):
        chunk = samples[start:start + per]
        y, d, hh, mm, ss, frac = _btime(t0 + start / fs)
        head = bytearray(64)
        head[0:8] = f"{i + 1:06d}D ".encode()
        head[8:13] = sta.ljust(5).encode()
        head[13:15] = loc.ljust(2).encode()
        head[15:18] = cha.ljust(3).encode()
        head[18:20] = net.ljust(2).encode()
        struct.pack_into(byteorder + "HHBBBBH", head, 20, y, d, hh, mm, ss, 0, frac)
        struct.pack_into(byteorder + "Hhh", head, 30, len(chunk), factor, mult)
        struct.pack_into(byteorder + "BBBBiHH", head, 36, 0, 0, 0, 1, 0, 64, 48)
        struct.pack_into(byteorder + "HHBBBB", head, 48, 1000, 0, enc,
                         1 if byteorder == ">" else 0, reclen.bit_length() - 1, 0)
        if edit:
            edit(i, head)
        data = struct.pack(byteorder + fmt * len(chunk), *chunk)
        out += head + data + bytes(reclen - 64 - len(data))
    return bytes(out)


def mseed_file(path: Path, channels, **kw) -> Path:
    """`channels`: (code, samples, fs, encoding) each."""
    blob = b"".join(mseed_records(code, s, fs, enc, **kw) for code, s, fs, enc in channels)
    return write(path, blob)


def tilt_samples(n=4096, seed=3, scale=1e-9):
    rng = np.random.default_rng(seed)
    return (scale * rng.standard_normal(n)).tolist()


# --------------------------------------------------------------------------------------------
# miniSEED


def cases_miniseed(inputs: Path) -> list:
    cat = "miniseed"
    d = inputs / "miniseed"
    cases = []
    e = tilt_samples(4096, 3)
    n = tilt_samples(4096, 4)
    counts_e = [int(x * 1e9 * 1000) for x in e]
    counts_n = [int(x * 1e9 * 1000) for x in n]

    def f64(name, e_=e, n_=n, fs=1.0, **kw):
        return mseed_file(d / f"{name}.mseed", [("XX.TILT.00.BAE", e_, fs, "float64"),
                                               ("XX.TILT.00.BAN", n_, fs, "float64")], **kw)

    axes = ["--axes", "theta_t=-BAE,eta_t=-BAN"]

    def budget(label, path, extra=(), **kw):
        cases.append(C(cat, f"budget: {label}", ["budget", "--tilt", path, *axes, *extra], **kw))

    valid = f64("valid")
    budget("valid FLOAT64 angle", valid, must_succeed=True)
    budget("valid little-endian", f64("little_endian", byteorder="<"), must_succeed=True)
    ints = mseed_file(d / "counts.mseed", [("XX.TILT.00.BAE", counts_e, 1.0, "int32"),
                                           ("XX.TILT.00.BAN", counts_n, 1.0, "int32")])
    budget("INT32 counts with --scale", ints, ["--scale", "BAE=1e-12", "--scale", "BAN=1e-12"],
           must_succeed=True)
    budget("INT32 counts without --scale", ints, must_fail=True, culprit=r"BAE|BAN")
    for label, value, culprit in [("1e308", 1e308, E308), ("1e150", 1e150, r"1e150|1e\+150"),
                                  ("-1e200", -1e200, r"1e200|1e\+200"),
                                  ("subnormal 1e-310", 1e-310, r"1e-310"),
                                  ("NaN", math.nan, r"NaN|nan"), ("inf", math.inf, r"inf")]:
        x = list(e)
        x[2000] = value
        budget(f"one FLOAT64 sample {label} at index 2000", f64(f"sample_{label}", e_=x),
               must_fail=True, huge=True, culprit=rf"BAE.*2000.*({culprit})|({culprit}).*BAE.*2000")
    x = list(e)
    x[2000] = math.nan
    budget("NaN sample with --gaps interpolate", f64("sample_nan_gap", e_=x),
           ["--gaps", "interpolate"], must_succeed=True)
    budget("--scale BAE=1e-300 (samples underflow)", ints,
           ["--scale", "BAE=1e-300", "--scale", "BAN=1e-12"], must_fail=True, huge=True,
           culprit=r"BAE")
    budget("--scale BAE=1e300 (samples overflow)", ints,
           ["--scale", "BAE=1e300", "--scale", "BAN=1e-12"], must_fail=True, huge=True,
           culprit=r"BAE")
    for value in ("0", "nan", "-inf"):
        budget(f"--scale BAE={value}", ints, ["--scale", f"BAE={value}", "--scale", "BAN=1e-12"],
               must_fail=True, culprit=r"BAE")
    budget("--scale BAE twice", ints, ["--scale", "BAE=1e-12", "--scale", "BAE=2e-12",
                                       "--scale", "BAN=1e-12"], must_fail=True,
           culprit=r"BAE.*(twice|repeat|more than once)")

    def rate_edit(factor, mult):
        def edit(i, head):
            struct.pack_into(">hh", head, 32, factor, mult)
        return edit

    for label, (factor, mult) in [("sample rate 0", (0, 1)), ("sample rate 1e9 Hz", (32767, 32767)),
                                  ("sample rate 1/32767^2 Hz", (-32767, -32767))]:
        budget(f"header {label}", f64(f"rate_{label.replace(' ', '_').replace('/', '_')}",
                                       edit=rate_edit(factor, mult)),
               must_fail=True, culprit=r"rate|Hz")

    def b1000(offset, fmt, value, only=None):
        def edit(i, head):
            if only is None or i == only:
                struct.pack_into(">" + fmt, head, offset, value)
        return edit

    budget("record length exponent 30 in blockette 1000", f64("reclen_30", edit=b1000(54, "B", 30)),
           must_fail=True, culprit=r"record|length")
    budget("record length exponent 6 (64 bytes)", f64("reclen_6", edit=b1000(54, "B", 6)),
           must_fail=True, culprit=r"record|length")
    budget("unknown encoding 99", f64("encoding_99", edit=b1000(52, "B", 99)), must_fail=True,
           culprit=r"encoding")
    budget("blockette chain loops (next = itself)", f64("blockette_loop", edit=b1000(50, "H", 48)),
           must_fail=True, culprit=r"blockette|loop")
    budget("data offset past the record", f64("data_offset", edit=b1000(44, "H", 4000)),
           must_fail=True, culprit=r"offset|record")
    budget("more samples declared than the record holds",
           f64("nsamples", edit=b1000(30, "H", 60000)), must_fail=True, culprit=r"sample|record")
    blob = valid.read_bytes()
    budget("truncated in the middle of a record", write(d / "truncated.mseed", blob[:-300]),
           must_fail=True, culprit=r"truncat|record|byte")
    budget("empty file", write(d / "empty.mseed", b""), must_fail=True)
    budget("random bytes", write(d / "random.mseed", np.random.default_rng(9).bytes(4096)),
           must_fail=True)
    # A gap of one record in BAE: refused by default, bridged on request.
    rec = 512
    per = (rec - 64) // 8
    gap_blob = (mseed_records("XX.TILT.00.BAE", e[:per * 10], 1.0)
                + mseed_records("XX.TILT.00.BAE", e[per * 11:], 1.0, t0=per * 11)
                + mseed_records("XX.TILT.00.BAN", n, 1.0))
    gap = write(d / "gap.mseed", gap_blob)
    budget("a gap of one record", gap, must_fail=True, culprit=r"BAE.*gap|gap.*BAE|no records")
    budget("a gap of one record with --gaps interpolate", gap, ["--gaps", "interpolate"],
           must_succeed=True)
    rates = mseed_file(d / "two_rates.mseed", [("XX.TILT.00.BAE", e, 1.0, "float64"),
                                               ("XX.TILT.00.BAN", n, 2.0, "float64")])
    budget("channels at different rates", rates, must_fail=True, culprit=r"rate")
    for rel in ("gap_overlap.mseed", "overlap_differs.mseed"):
        src = REPO / "tests/fixtures/input/miniseed" / rel
        cases.append(C(cat, f"budget: fixture {rel} (Steim-2 counts without --scale)",
                       ["budget", "--tilt", str(src)], must_fail=True))
    # The same reader under the other commands.
    big = list(e) * 22  # 90112 s, longer than the pair's tilt record
    x = list(big)
    x[8000] = 1e308
    bad = mseed_file(d / "long_1e308.mseed", [("XX.TILT.00.BAE", x, 1.0, "float64"),
                                              ("XX.TILT.00.BAN", big, 1.0, "float64")])
    culprit = rf"long_1e308.*BAE.*8000|BAE.*8000.*({E308})"
    cases.append(C(cat, "simulate --tilt: one sample 1e308 at index 8000",
                   ["simulate", "--tilt", bad, *axes, "--oversample", "2"], must_fail=True,
                   huge=True, culprit=culprit))
    cases.append(C(cat, "coherence --tilt: one sample 1e308 at index 8000",
                   ["coherence", "--tilt", bad, *axes, "--measured", PAIR_MEASURED],
                   setup=pair_setup(), must_fail=True, huge=True, culprit=culprit))
    cases.append(C(cat, "subtract --tilt: one sample 1e308 at index 8000",
                   ["subtract", "--tilt", bad, *axes, "--measured", PAIR_MEASURED],
                   setup=pair_setup(), must_fail=True, huge=True, culprit=culprit))
    # Rotation and translation channels told by their units (miniSEED states none).
    g = 9.81
    six = mseed_file(d / "six.mseed", [("XX.TILT.00.BJN", n, 1.0, "float64"),
                                       ("XX.TILT.00.BHE", [-g * v for v in n], 1.0, "float64")])

    def units(label, given, **kw):
        args = ["budget", "--tilt", six]
        for u in given:
            args += ["--units", u]
        cases.append(C(cat, f"budget six.mseed: {label}", args, **kw))

    units("--units BJN=rad, BHE=m/s^2", ["BJN=rad", "BHE=m/s^2"], must_succeed=True)
    units("--units BHE=furlong/s (no unit of the floor's motion)", ["BJN=rad", "BHE=furlong/s"],
          must_fail=True, culprit=r"BHE.*furlong|furlong.*BHE")
    units("--units BHE twice", ["BJN=rad", "BHE=m/s^2", "BHE=m/s"], must_fail=True,
          culprit=r"BHE.*(twice|repeat|more than once)")
    units("translation channel BHE without a unit", ["BJN=rad"], must_fail=True,
          culprit=r"BHE.*unit")
    units("--units BHE=rad/s (the instrument code says translation)", ["BJN=rad", "BHE=rad/s"],
          must_fail=True, culprit=r"BHE.*(instrument|translation)")
    units("--units of a channel the file lacks", ["BJN=rad", "BHE=m/s^2", "LHZ=m/s^2"],
          must_fail=True, culprit=r"LHZ")
    nano = mseed_file(d / "nano.mseed", [("XX.TILT.00.BAE", [1e9 * v for v in e], 1.0, "float64"),
                                         ("XX.TILT.00.BAN", [1e9 * v for v in n], 1.0, "float64")])
    budget("tilt in nrad without a unit (RMS about 1, read as rad)", nano, must_fail=True,
           culprit=r"(BAE|BAN).*(urad|nrad)")
    budget("tilt in nrad with --units", nano, ["--units", "BAE=nrad", "--units", "BAN=nrad"],
           must_succeed=True)
    cases.append(C(cat, "budget --tilt in.mseed --save in.mseed (same file)",
                   ["budget", "--tilt", "in.mseed", *axes, "--save", "in.mseed"],
                   setup=copy_setup((valid, "in.mseed")), must_fail=True))
    cases.append(C(cat, "budget --measured in.mseed (miniSEED is no measured record)",
                   ["budget", "--tilt", valid, *axes, "--measured", valid], must_fail=True,
                   culprit=r"miniSEED|mseed"))
    return cases


# --------------------------------------------------------------------------------------------
# gwpy addressing


def gwpy_file(path: Path, n=86400, dx=1.0, unit="urad", edit=None, group=None, seed=21) -> Path:
    """gwpy TimeSeries datasets `theta` and `eta` (at the root or in `group`)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    with h5py.File(path, "w") as f:
        g = f.require_group(group) if group else f
        for name in ("theta", "eta"):
            ds = g.create_dataset(name, data=1e-3 * rng.standard_normal(n))
            ds.attrs.update({"x0": 1.2e9, "dx": dx, "xunit": "s", "unit": unit, "name": name})
        if edit:
            edit(g)
    return path


def gwpy_fseries(path: Path, edit=None) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    f_hz = np.arange(0, 200) * 0.005
    asd = np.where(f_hz > 0, 1e-9 * (np.maximum(f_hz, 1e-3) / 1e-3) ** -1.0, 0.0)
    with h5py.File(path, "w") as f:
        for name in ("theta", "eta"):
            ds = f.create_dataset(name, data=asd)
            ds.attrs.update({"x0": 0.0, "dx": 0.005, "xunit": "Hz", "unit": "rad / Hz(1/2)",
                             "name": name})
        if edit:
            edit(f)
    return path


def cases_gwpy(inputs: Path) -> list:
    cat = "gwpy addressing"
    d = inputs / "gwpy"
    cases = []
    gw = gwpy_file(d / "gw.h5")
    gwg = gwpy_file(d / "gw_group.h5", group="tilt")
    theta = ["--axes", "theta_t=theta"]
    both = ["--axes", "theta_t=theta,eta_t=eta"]

    def add(label, args, **kw):
        cases.append(C(cat, label, args, **kw))

    add("budget --tilt gw.h5:/theta (valid)", ["budget", "--tilt", f"{gw}:/theta", *theta],
        must_succeed=True)
    add("budget --tilt gw.h5:/tilt (group, valid)", ["budget", "--tilt", f"{gwg}:/tilt", *both],
        must_succeed=True)
    same = r"same file|replace an input|input of the run"
    for cmd, extra in [("budget", []), ("simulate", ["--oversample", "2"]),
                       ("coherence", ["--measured", PAIR_MEASURED]),
                       ("subtract", ["--measured", PAIR_MEASURED])]:
        for label, tilt, save, setup_extra in [
                ("gw.h5:/theta --save gw.h5", "gw.h5:/theta", "gw.h5", []),
                ("./gw.h5:/theta --save ./gw.h5", "./gw.h5:/theta", "./gw.h5", []),
                ("gw.h5:/theta --save ./sub/../gw.h5", "gw.h5:/theta", "sub/../gw.h5",
                 [(None, "sub")]),
                ("link.h5:/theta --save gw.h5 (symlink)", "link.h5:/theta", "gw.h5", ["link"]),
                ("gw.h5:/theta --save hard.h5 (hard link)", "gw.h5:/theta", "hard.h5", ["hard"]),
        ]:
            if cmd != "budget" and save != "gw.h5":
                continue
            files = [(gw, "gw.h5"), *[p for p in setup_extra if isinstance(p, tuple)]]
            setup = copy_setup(*files)
            if "link" in setup_extra:
                setup = chain(setup, lambda c: os.symlink("gw.h5", c.dir / "link.h5"))
            if "hard" in setup_extra:
                setup = chain(setup, lambda c: os.link(c.dir / "gw.h5", c.dir / "hard.h5"))
            if cmd in ("coherence", "subtract"):
                setup = chain(setup, pair_setup())
            add(f"{cmd} --tilt {label}", [cmd, "--tilt", tilt, *theta, *extra, "--save", save],
                setup=setup, must_fail=True, culprit=same)
    add("budget --tilt gw.h5:/theta --measured m.csv --save m.csv",
        ["budget", "--tilt", f"{gw}:/theta", *theta, "--measured", "m.csv", "--save", "m.csv"],
        setup=lambda c: write(c.dir / "m.csv", joined(measured_lines())), must_fail=True,
        culprit=same)
    add("budget --tilt gw.h5:/nope (missing object)", ["budget", "--tilt", f"{gw}:/nope"],
        must_fail=True, culprit=r"nope")
    add("budget --tilt gw.h5: (empty object)", ["budget", "--tilt", f"{gw}:"], must_fail=True)
    add("budget --tilt gw.h5:/ (the root)", ["budget", "--tilt", f"{gw}:/", *both],
        must_succeed=True)
    add("budget --tilt gw.h5://theta", ["budget", "--tilt", f"{gw}://theta", *theta],
        must_fail=False)
    add("budget --tilt gw.h5:/theta/ (trailing slash)", ["budget", "--tilt", f"{gw}:/theta/",
                                                         *theta], must_fail=False)
    add("budget --tilt gw.h5:/theta:/x", ["budget", "--tilt", f"{gw}:/theta:/x"], must_fail=True)
    add("budget --tilt missing.h5:/theta", ["budget", "--tilt", str(d / "missing.h5") + ":/theta"],
        must_fail=True, culprit=r"missing\.h5")

    def attr(name, value):
        def edit(g):
            for ds in ("theta", "eta"):
                g[ds].attrs[name] = value
        return edit

    for label, edit, culprit in [
            ("dx = 0", attr("dx", 0.0), r"dx"), ("dx = NaN", attr("dx", np.nan), r"dx"),
            ("dx = -1", attr("dx", -1.0), r"dx"),
            ("dx = 1e-300 (rate 1e300 Hz)", attr("dx", 1e-300), r"dx|rate|Hz"),
            ("dx = 1e300", attr("dx", 1e300), r"dx|rate|Hz"),
            ("xunit Hz (a FrequencySeries as a tilt series)", attr("xunit", "Hz"), r"xunit|Hz|spectr"),
            ("unit furlong", attr("unit", "furlong"), r"furlong")]:
        p = gwpy_file(d / f"gw_{label.split(' (')[0].replace(' ', '_')}.h5", n=8192, edit=edit)
        add(f"budget --tilt gw.h5:/theta with {label}", ["budget", "--tilt", f"{p}:/theta", *theta],
            must_fail=True, culprit=culprit)

    def sample(value, index=3000):
        def edit(g):
            g["eta"][index] = value
        return edit

    # In eta, and both axes read: theta alone drives neither X nor phi (structural zeros).
    for label, value in [("1e308 urad", 1e308), ("1e-300 urad", 1e-300), ("1e150 urad", 1e150)]:
        p = gwpy_file(d / f"gw_sample_{label.split()[0]}.h5", n=8192, edit=sample(value))
        add(f"budget --tilt gw.h5:/ with one sample {label} in eta",
            ["budget", "--tilt", f"{p}:/", *both], must_fail=True, huge=True,
            culprit=r"eta.*3000|3000.*eta")
    fs = gwpy_fseries(d / "fs.h5")
    add("budget --tilt fs.h5:/theta (FrequencySeries, valid)",
        ["budget", "--tilt", f"{fs}:/theta", *theta], must_succeed=True)

    def fsv(index, value):
        def edit(f):
            f["theta"][index] = value
        return edit

    for label, edit, culprit in [("ASD -1e-9", fsv(20, -1e-9), r"theta"),
                                 ("ASD 1e300", fsv(20, 1e300), r"1e300|1e\+300"),
                                 ("ASD 1e100", fsv(20, 1e100), r"1e100|1e\+100"),
                                 ("ASD 1e-200 (PSD underflows)", fsv(20, 1e-200), r"1e-200"),
                                 ("dx 0", attr("dx", 0.0), r"dx")]:
        p = gwpy_fseries(d / f"fs_{label.split(' (')[0].replace(' ', '_')}.h5", edit=edit)
        add(f"budget --tilt fs.h5:/theta with {label}", ["budget", "--tilt", f"{p}:/theta", *theta],
            must_fail=True, huge=True, culprit=culprit)
    return cases


# --------------------------------------------------------------------------------------------
# coherence and subtract on pairs of records

_PAIR = {}


def pair_inputs(inputs: Path, first_bin: str) -> None:
    """The valid pair: the lab tilt, and the observables `simulate --tilt` answers it with."""
    d = inputs / "pairs"
    d.mkdir(parents=True, exist_ok=True)
    tilt = d / PAIR_TILT
    shutil.copyfile(LAB_H5, tilt)
    meas = d / PAIR_MEASURED
    r = subprocess.run([first_bin, "simulate", "--tilt", str(tilt), "--oversample", "2",
                        "--save", str(meas)], capture_output=True, timeout=300)
    if r.returncode != 0 or not meas.exists():
        h5_measured(meas, n=86400)
    _PAIR["tilt"], _PAIR["measured"] = tilt, meas


def pair_setup(tilt_edit=None, measured_edit=None):
    """Copies the pair into the scratch directory as tilt.h5 and meas.h5, edited."""

    def setup(ctx):
        for src, name, edit in [(_PAIR["tilt"], PAIR_TILT, tilt_edit),
                                (_PAIR["measured"], PAIR_MEASURED, measured_edit)]:
            dst = ctx.dir / name
            if not dst.exists():
                shutil.copyfile(src, dst)
            if edit:
                with h5py.File(dst, "r+") as f:
                    edit(f)
    return setup


def set_sample(name, index, value):
    def edit(f):
        f[name][index] = value
    return edit


def set_all(name, value):
    def edit(f):
        f[name][...] = value
    return edit


def cases_pairs(inputs: Path) -> list:
    cat = "coherence/subtract pairs"
    cases = []
    pair = ["--tilt", PAIR_TILT, "--measured", PAIR_MEASURED]

    def both(label, extra=(), tilt_edit=None, measured_edit=None, **kw):
        for cmd in ("coherence", "subtract"):
            cases.append(C(cat, f"{cmd}: {label}", [cmd, *pair, *extra],
                           setup=pair_setup(tilt_edit, measured_edit), **kw))

    def one(cmd, label, extra=(), tilt_edit=None, measured_edit=None, **kw):
        cases.append(C(cat, f"{cmd}: {label}", [cmd, *pair, *extra],
                       setup=pair_setup(tilt_edit, measured_edit), **kw))

    both("valid pair", must_succeed=True)
    both("measured X one sample 1e308", measured_edit=set_sample("X", 5000, 1e308),
         must_fail=True, huge=True, culprit=r"meas\.h5.*X.*5000|X.*5000.*meas\.h5")
    both("measured X one sample 1e150", measured_edit=set_sample("X", 5000, 1e150),
         must_fail=True, huge=True, culprit=r"meas\.h5.*X.*5000|X.*5000.*meas\.h5")
    both("measured X one sample 1e-310", measured_edit=set_sample("X", 5000, 1e-310),
         must_fail=True, culprit=r"X.*5000")
    both("measured X one sample NaN", measured_edit=set_sample("X", 5000, np.nan),
         must_fail=True, culprit=r"X.*5000")
    both("tilt eta_t one sample 1e150", tilt_edit=set_sample("eta_t", 7000, 1e150),
         must_fail=True, huge=True, culprit=r"tilt\.h5.*eta_t.*7000|eta_t.*7000")
    both("tilt eta_t one sample 1e308", tilt_edit=set_sample("eta_t", 7000, 1e308),
         must_fail=True, huge=True, culprit=r"eta_t.*7000")
    both("tilt eta_t one sample 1e-310", tilt_edit=set_sample("eta_t", 7000, 1e-310),
         must_fail=True, culprit=r"eta_t.*7000")
    both("measured X all zero", measured_edit=set_all("X", 0.0), must_fail=True,
         culprit=r"\bX\b.*(zero|dead|constant|no signal)|(zero|dead|constant).*\bX\b")
    both("tilt eta_t all zero", tilt_edit=set_all("eta_t", 0.0), must_fail=True,
         culprit=r"eta_t.*(zero|dead|constant|no signal)|(zero|dead|constant).*eta_t")
    both("tilt theta_t and eta_t all zero",
         tilt_edit=lambda f: (set_all("eta_t", 0.0)(f), set_all("theta_t", 0.0)(f)),
         must_fail=True, culprit=r"(theta_t|eta_t).*(zero|dead|constant|no signal)")
    both("measured X constant 1e-6", measured_edit=set_all("X", 1e-6), must_fail=True,
         culprit=r"\bX\b.*(zero|dead|constant|no signal)|(zero|dead|constant).*\bX\b")

    def rate(value):
        def edit(f):
            f.attrs["sample_rate_hz"] = value
        return edit

    both("measured at 2 Hz, tilt at 1 Hz", measured_edit=rate(2.0), must_fail=True,
         culprit=r"rate|Hz")
    both("measured sample rate 1e300 Hz", measured_edit=rate(1e300), must_fail=True,
         culprit=r"sample_rate_hz|rate")
    both("measured sample rate 1e-300 Hz", measured_edit=rate(1e-300), must_fail=True,
         culprit=r"sample_rate_hz|rate")

    def start(value):
        def edit(f):
            f.attrs["start_time"] = value
        return edit

    both("records a year apart (no overlap)", measured_edit=start("2025-03-20T00:00:00+01:00"),
         must_fail=True, culprit=r"overlap|start")
    one("subtract", "--observables X,X", ["--observables", "X,X"], must_fail=True,
        culprit=r"X.*(twice|repeat|more than once)")
    one("coherence", "--output X,X", ["--output", "X,X"], must_fail=True,
        culprit=r"X.*(twice|repeat|more than once)")
    one("subtract", "--tilt-noise eta_t twice",
        ["--tilt-noise", "eta_t=1e-9", "--tilt-noise", "eta_t=2e-9"], must_fail=True,
        culprit=r"eta_t.*(twice|repeat|more than once)")
    one("subtract", "--readout X twice", ["--readout", "X=1e-9", "--readout", "X=2e-9"],
        must_fail=True, culprit=r"X.*(twice|repeat|more than once)")
    one("subtract", "--fit length.h_m,length.h_m", ["--fit", "length.h_m,length.h_m"],
        must_fail=True, culprit=r"h_m.*(twice|repeat|more than once)")
    for value in ("1e-300", "1e300", "nan", "-1"):
        one("subtract", f"--tilt-noise eta_t={value}", ["--tilt-noise", f"eta_t={value}"],
            must_fail=True, culprit=r"eta_t")
        one("subtract", f"--readout X={value}", ["--readout", f"X={value}"], must_fail=True,
            culprit=r"X")
    for opt, values in [("--holdout", ["0", "0.6", "nan"]), ("--max-delay", ["-1", "1e300", "nan"]),
                        ("--band", ["0:0", "nan:1", "0.1:0.01", "1e-300:1e-299"]),
                        ("--report-band", ["1:0.1", "inf:inf"]),
                        ("--nperseg", ["1", "1099511627776"])]:
        for v in values:
            one("subtract", f"{opt} {v}", [opt, v], must_fail=True)
    for opt, values in [("--confidence", ["0", "1", "nan"]), ("--fit-band", ["1:0.1", "nan:1"]),
                        ("--nperseg", ["1", "1099511627776"]), ("--overlap", ["1", "-0.5"])]:
        for v in values:
            one("coherence", f"{opt} {v}", [opt, v], must_fail=True)
    same = r"same file|replace an input|input of the run"
    for cmd in ("coherence", "subtract"):
        for target in (PAIR_TILT, PAIR_MEASURED):
            one(cmd, f"--save {target} (an input)", ["--save", target], must_fail=True,
                culprit=same)
    return cases


# --------------------------------------------------------------------------------------------
# Option edges: repeated keys and names, and values whose derived quantities leave f64


def cases_option_edges(inputs: Path) -> list:
    cat = "option edges"
    d = inputs / "options"
    cases = []
    lab = ["budget", "--tilt", LAB_H5, "--nperseg", "4096"]
    rep = r"(twice|repeat|more than once)"

    def add(label, args, **kw):
        cases.append(C(cat, label, args, **kw))

    # Repeated keys of KEY=VALUE options and repeated names of list options, every command.
    add("--set length.h_m twice", ["--set", "length.h_m=1", "--set", "length.h_m=2", "modes"],
        must_fail=True, culprit=rf"h_m.*{rep}")
    add("budget --readout X twice", [*lab, "--readout", "X=1e-9", "--readout", "X=2e-9"],
        must_fail=True, culprit=rf"X.*{rep}")
    add("budget --scale theta_t twice", [*lab, "--scale", "theta_t=1", "--scale", "theta_t=2"],
        must_fail=True, culprit=rf"theta_t.*{rep}")
    asd = write(d / "asd.csv", joined(["frequency_hz,asd"] + [
        f"{f!r},1e-9" for f in np.logspace(-5, 1, 40).tolist()]))
    add("budget --term a twice", [*lab, "--term", f"a=X:{asd}", "--term", f"a=phi:{asd}"],
        must_fail=True, culprit=rf"a.*{rep}")
    add("budget --units eta_t=urad (the file states rad)", [*lab, "--units", "eta_t=urad"],
        must_fail=True, culprit=r"eta_t.*rad")
    add("budget --observables X,X", [*lab, "--observables", "X,X"], must_fail=True,
        culprit=rf"X.*{rep}")
    add("budget --at 1e-3,1e-3", [*lab, "--at", "1e-3,1e-3"], must_fail=True,
        culprit=rf"1e-3|0\.001.*{rep}")
    add("tf --input eta_t,eta_t", ["tf", "--freq", "1e-3:5:1", "--input", "eta_t,eta_t"],
        must_fail=True, culprit=rf"eta_t.*{rep}")
    add("tf --output X --output X", ["tf", "--freq", "1e-3:5:1", "--output", "X", "--output", "X"],
        must_fail=True, culprit=rf"X.*{rep}")
    add("tf --observables X,X", ["tf", "--freq", "1e-3:5:1", "--observables", "X,X",
                                 "--save", "t.png"], must_fail=True, culprit=rf"X.*{rep}")
    add("simulate --init theta_a twice in one list",
        ["simulate", "--duration", "1000", "--init", "theta_a=1e-5,theta_a=2e-5"],
        must_fail=True, culprit=rf"theta_a.*{rep}")
    add("simulate --init theta_a in two options",
        ["simulate", "--duration", "1000", "--init", "theta_a=1e-5", "--init", "theta_a=2e-5"],
        must_fail=True, culprit=rf"theta_a.*{rep}")
    add("simulate --init-rate phi_b twice",
        ["simulate", "--duration", "1000", "--init-rate", "phi_b=1e-5,phi_b=1e-5"],
        must_fail=True, culprit=rf"phi_b.*{rep}")
    add("simulate --readout X twice",
        ["simulate", "--duration", "1000", "--readout", "X=1e-9", "--readout", "X=2e-9"],
        must_fail=True, culprit=rf"X.*{rep}")
    add("simulate --drive-gain eta_t twice",
        ["simulate", "--tilt", LAB_H5, "--oversample", "2", "--drive-gain", "eta_t=1,eta_t=2"],
        must_fail=True, culprit=rf"eta_t.*{rep}")
    add("simulate --tilt --scale theta_t twice",
        ["simulate", "--tilt", LAB_H5, "--oversample", "2", "--scale", "theta_t=1",
         "--scale", "theta_t=1"], must_fail=True, culprit=rf"theta_t.*{rep}")
    add("coherence --scale theta_t twice",
        ["coherence", "--tilt", PAIR_TILT, "--measured", PAIR_MEASURED, "--scale", "theta_t=1",
         "--scale", "theta_t=1"], setup=pair_setup(), must_fail=True,
        culprit=rf"theta_t.*{rep}")
    add("fit --free k twice", ["fit", "--free",
                               "torsion.k_a_n_m_per_rad,torsion.k_a_n_m_per_rad"],
        must_fail=True, culprit=rf"k_a.*{rep}")
    add("budget --axes theta_t twice", [*lab, "--axes", "theta_t=theta_t,theta_t=eta_t"],
        must_fail=True, culprit=r"theta_t")
    # Values whose derived quantities leave the normal range of f64.
    add("budget --scale eta_t=1e-300 (the tilt PSD underflows)",
        [*lab, "--scale", "eta_t=1e-300"], must_fail=True, huge=True, culprit=r"eta_t")
    add("budget --scale eta_t=1e300 (the tilt PSD overflows)",
        [*lab, "--scale", "eta_t=1e300"], must_fail=True, huge=True, culprit=r"eta_t")
    add("budget --readout X=1e-300 (the PSD underflows)", [*lab, "--readout", "X=1e-300"],
        must_fail=True, huge=True, culprit=r"X")
    add("budget --readout X=1e200 (the PSD overflows)", [*lab, "--readout", "X=1e200"],
        must_fail=True, huge=True, culprit=r"X")
    for label, value in [("1e150", 1e150), ("1e-310", 1e-310)]:
        p = h5_tilt_with(d / f"tilt_{label}.h5", "eta_t", 5000, value)
        add(f"budget: tilt eta_t one sample {label}", ["budget", "--tilt", p], must_fail=True,
            huge=True, culprit=r"eta_t.*5000")
    mp = h5_measured(d / "measured_1e308.h5", n=86400,
                     edit=lambda f: f["X"].__setitem__(4000, 1e308))
    add("budget --measured with one sample 1e308", [*lab, "--measured", mp], must_fail=True,
        huge=True, culprit=r"X.*4000")
    sp = write(d / "spectrum_1e100.csv", joined(["frequency_hz,theta_t,eta_t"] + [
        f"{f!r},1e100,1e-9" for f in np.logspace(-5, 1, 40).tolist()]))
    add("budget --tilt spectrum with ASD 1e100", ["budget", "--tilt", sp], must_fail=True,
        huge=True, culprit=r"1e100|1e\+100")
    sp = write(d / "spectrum_1e-200.csv", joined(["frequency_hz,theta_t,eta_t"] + [
        f"{f!r},1e-200,1e-9" for f in np.logspace(-5, 1, 40).tolist()]))
    add("budget --tilt spectrum with ASD 1e-200 (its PSD underflows)", ["budget", "--tilt", sp],
        must_fail=True, culprit=r"1e-200")
    tiny = write(d / "asd_tiny.csv", joined(["frequency_hz,asd"] + [
        f"{f!r},1e-200" for f in np.logspace(-5, 1, 40).tolist()]))
    add("budget --readout X=FILE of ASD 1e-200", [*lab, "--readout", f"X={tiny}"],
        must_fail=True, culprit=r"asd_tiny|1e-200")
    add("budget --term a=X:FILE of ASD 1e-200", [*lab, "--term", f"a=X:{tiny}"],
        must_fail=True, culprit=r"asd_tiny|1e-200")
    add("simulate --tilt with one sample 1e308 at index 8000",
        ["simulate", "--tilt", h5_tilt_with(d / "tilt_sim_1e308.h5", "eta_t", 8000, 1e308),
         "--oversample", "2"], must_fail=True, huge=True, culprit=r"eta_t.*8000")
    add("simulate --drive-gain eta_t=1e300", ["simulate", "--tilt", LAB_H5, "--oversample", "2",
                                             "--drive-gain", "eta_t=1e300"], must_fail=True,
        huge=True, culprit=r"eta_t")
    add("simulate --drive-gain eta_t=1e-300", ["simulate", "--tilt", LAB_H5, "--oversample", "2",
                                              "--drive-gain", "eta_t=1e-300"], must_fail=True,
        huge=True, culprit=r"eta_t")
    add("simulate --readout X=1e-300", ["simulate", "--duration", "1000", "--readout",
                                        "X=1e-300"], must_fail=True, culprit=r"X")
    add("simulate --mode-energy 1e-300", ["simulate", "--duration", "1000", "--mode-energy",
                                          "1e-300"], must_fail=True, huge=True,
        culprit=r"mode-energy")
    add("simulate --kick-x 1e-300", ["simulate", "--duration", "1000", "--kick-x", "1e-300"],
        must_fail=True, huge=True, culprit=r"kick-x")
    return cases


def h5_tilt_with(path: Path, channel: str, index: int, value: float) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(LAB_H5, path)
    with h5py.File(path, "r+") as f:
        f[channel][index] = value
    return path


# --------------------------------------------------------------------------------------------
# The Python package: each case is a snippet run by py_case.py under the interpreter and
# package of the binary's slot (--python); `result` is scanned for non-finite numbers.

GIB = 1 << 30


def cases_python(inputs: Path) -> list:
    cat = "python"
    cases = []

    def py(label, code, **kw):
        cases.append(C(cat, label, [], python=code, **kw))

    pre = "import numpy as np, tiltnoise as tn\n"
    noise = "x = np.random.default_rng(1).standard_normal(4096) * 1e-9\n"
    size = r"(MemoryError|ValueError): .*(limit|memory|samples|points|allowed)"
    py("transfer on a 1e9-point broadcast view",
       pre + "f = np.broadcast_to(np.float64(1e-3), (10**9,))\nresult = tn.Model().transfer(f)",
       must_fail=True, culprit=size)
    for fn in ("welch", "csd"):
        args = "x" if fn == "welch" else "x, x"
        py(f"{fn} on a 2^31-sample broadcast view",
           pre + f"x = np.broadcast_to(np.float64(1.0), (2**31,))\nresult = tn.{fn}({args}, 1.0)",
           must_fail=True, culprit=size)
    py("budget on 2^31-sample broadcast views",
       pre + "x = np.broadcast_to(np.float64(1e-9), (2**31,))\n"
             "result = tn.budget({'theta_t': x, 'eta_t': x}, fs=1.0)",
       must_fail=True, culprit=size)
    py("welch on a real 3e8-sample float32 array",
       pre + "x = np.ones(300_000_000, dtype=np.float32)\nresult = tn.welch(x, 1.0)",
       must_fail=True, culprit=size, timeout=60)
    py("welch on float32", pre + noise + "result = tn.welch(x.astype(np.float32), 1.0)",
       must_succeed=True)
    py("welch on int64", pre + "x = np.arange(4096) % 7\nresult = tn.welch(x, 1.0)",
       must_succeed=True)
    py("welch on int16", pre + "x = (np.arange(4096) % 7).astype(np.int16)\n"
                               "result = tn.welch(x, 1.0)", must_succeed=True)
    py("welch on a non-contiguous view", pre + noise + "result = tn.welch(x[::2], 1.0)",
       must_succeed=True)
    py("welch on a small zero-stride view",
       pre + "x = np.broadcast_to(np.float64(1.0), (4096,))\nresult = tn.welch(x, 1.0)",
       must_succeed=True)
    py("welch on a reversed view", pre + noise + "result = tn.welch(x[::-1], 1.0)",
       must_succeed=True)
    for dtype in ("complex128", "object", "datetime64[s]", "U3"):
        make = {"object": "np.array([1.0] * 4096, dtype=object)",
                "U3": "np.array(['1'] * 4096)"}.get(
            dtype, f"np.zeros(4096, dtype='{dtype}')")
        py(f"welch on {dtype}", pre + f"x = {make}\nresult = tn.welch(x, 1.0)", must_fail=True,
           culprit=r"(ValueError|TypeError): .*(dtype|float64)")
    py("welch with one sample 1e308", pre + noise + "x[100] = 1e308\nresult = tn.welch(x, 1.0)",
       must_fail=True, huge=True, culprit=r"ValueError: .*x.*100")
    py("welch with one NaN sample", pre + noise + "x[100] = np.nan\nresult = tn.welch(x, 1.0)",
       must_fail=True, culprit=r"ValueError: .*x.*100")
    py("csd with one sample 1e-310 in y",
       pre + noise + "y = x.copy(); y[7] = 1e-310\nresult = tn.csd(x, y, 1.0)",
       must_fail=True, culprit=r"ValueError: .*y.*7")
    for fs in ("1e308", "0.0", "float('nan')", "-1.0", "1e-300"):
        py(f"budget(fs={fs})", pre + noise + f"result = tn.budget({{'eta_t': x}}, fs={fs})",
           must_fail=True, culprit=r"ValueError: .*\bfs\b")
        py(f"welch(fs={fs})", pre + noise + f"result = tn.welch(x, {fs})", must_fail=True,
           culprit=r"ValueError: .*\bfs\b")
    py("budget with one tilt sample 1e150",
       pre + noise + "x[50] = 1e150\nresult = tn.budget({'eta_t': x}, fs=1.0)", must_fail=True,
       huge=True, culprit=r"ValueError: .*eta_t.*50")
    py("budget with one tilt sample 1e-310",
       pre + noise + "x[50] = 1e-310\nresult = tn.budget({'eta_t': x}, fs=1.0)",
       must_fail=True, culprit=r"ValueError: .*eta_t.*50")
    py("budget on int32 and float32 rows",
       pre + "x = (np.arange(8192) % 5).astype(np.int32)\n"
             "result = tn.budget({'eta_t': x * 1e-9, 'theta_t': (x * 1e-9).astype(np.float32)},"
             " fs=1.0)", must_succeed=True)
    py("budget readout X=1e-300", pre + noise + "result = tn.budget({'eta_t': x}, fs=1.0, "
                                               "readout={'X': 1e-300})",
       must_fail=True, culprit=r"ValueError: .*X")
    py("transfer(out=float64 array)",
       pre + "result = tn.Model().transfer(np.array([1e-3]), out=np.zeros((1, 7, 3)))",
       must_fail=True, culprit=r"(ValueError|TypeError): .*out.*complex128")
    py("transfer(out=non-contiguous complex128)",
       pre + "o = np.zeros((1, 7, 6), complex)[:, :, ::2]\n"
             "result = tn.Model().transfer(np.array([1e-3]), out=o)",
       must_fail=True, culprit=r"(ValueError|TypeError): .*out.*contiguous")
    py("transfer on a 2-D grid", pre + "result = tn.Model().transfer(np.ones((3, 3)))",
       must_fail=True, culprit=r"ValueError: .*freq")
    py("transfer on strings", pre + "result = tn.Model().transfer(['a', 'b'])",
       must_fail=True, culprit=r"(ValueError|TypeError): .*freq")
    py("transfer on a float32 view", pre + "f = np.logspace(-3, 0, 64).astype(np.float32)[::2]\n"
                                           "result = tn.Model().transfer(f)", must_succeed=True)
    py("transfer inputs eta_t twice",
       pre + "result = tn.Model().transfer(1e-3, inputs=['eta_t', 'eta_t'])", must_fail=True,
       culprit=r"ValueError: .*eta_t.*(twice|repeat)")
    py("simulate init theta_a twice",
       pre + "result = tn.Model().simulate(1000.0, init='theta_a=1e-5,theta_a=2e-5')",
       must_fail=True, culprit=r"ValueError: .*theta_a.*(twice|repeat)")
    py("simulate(duration=1e300)", pre + "result = tn.Model().simulate(1e300)", must_fail=True,
       culprit=r"ValueError")
    py("monte_carlo(samples=10**12)", pre + "result = tn.Model().monte_carlo(samples=10**12)",
       must_fail=True, culprit=r"(ValueError|MemoryError)")
    py("budget nperseg=2**40", pre + noise + "result = tn.budget({'eta_t': x}, fs=1.0, "
                                            "nperseg=2**40)", must_fail=True,
       culprit=r"ValueError")
    same = r"(OSError|ValueError|InputFileError): .*(same file|replace an input|input)"
    gw = gwpy_file(inputs / "python" / "gw.h5", n=8192)
    py("Budget.save onto its gwpy input (gw.h5:/theta)",
       pre + "b = tn.budget_from_file('gw.h5:/theta', axes='theta_t=theta')\nb.save('gw.h5')",
       setup=copy_setup((gw, "gw.h5")), must_fail=True, culprit=same)
    py("Budget.save onto its input (plain path)",
       pre + "b = tn.budget_from_file('in.csv')\nb.save('in.csv')",
       setup=copy_setup((PETERSON, "in.csv")), must_fail=True, culprit=same)
    py("Budget.save onto its input via a symlink",
       pre + "b = tn.budget_from_file('in.csv')\nb.save('link.csv')",
       setup=chain(copy_setup((PETERSON, "in.csv")),
                   lambda c: os.symlink("in.csv", c.dir / "link.csv")),
       must_fail=True, culprit=same)
    py("Budget.save onto its measured file",
       pre + "b = tn.budget_from_file('in.csv', measured='m.csv')\nb.save('m.csv')",
       setup=chain(copy_setup((PETERSON, "in.csv")),
                   lambda c: write(c.dir / "m.csv", joined(measured_lines()))),
       must_fail=True, culprit=same)
    py("Simulation.save onto its parameter file",
       pre + "p = tn.Params.from_toml('p.csv')\nsim = tn.Model(p).simulate(1000.0)\n"
             "sim.save('p.csv')",
       setup=lambda c: write(c.dir / "p.csv", subprocess.run(
           [c.bin, "params"], capture_output=True).stdout), must_fail=True, culprit=same)
    py("Budget.save a budget of arrays", pre + noise + "b = tn.budget({'eta_t': x}, fs=1.0)\n"
                                                       "b.save('out.h5')", must_succeed=True)
    py("SIGINT during a long transfer",
       pre + "result = tn.Model().transfer(np.logspace(-4, 1, 1_000_000), method='direct')",
       sig=signal.SIGINT, sig_when=1.0, timeout=60, serial=True)
    return cases


# --------------------------------------------------------------------------------------------
# Process conditions of the new commands


def cases_process_new() -> list:
    cat = "process"
    cases = []
    pair = ["--tilt", PAIR_TILT, "--measured", PAIR_MEASURED]
    for cmd in ("coherence", "subtract"):
        for sig in (signal.SIGINT, signal.SIGTERM):
            cases.append(C(cat, f"{sig.name} at 0.3 s: {cmd} with saved outputs",
                           [cmd, *pair, "--save", "o.h5", "--save", "o.png"], setup=pair_setup(),
                           sig=sig, sig_when=0.3, timeout=60, serial=True))
        cases.append(C(cat, f"stdout closed: {cmd}", [cmd, *pair], setup=pair_setup(),
                       stdout="closed"))
        cases.append(C(cat, f"stdout to /dev/full: {cmd}", [cmd, *pair], setup=pair_setup(),
                       stdout="devfull", must_fail=True))
        cases.append(C(cat, f"stdout | head -c 1: {cmd}", [cmd, *pair], setup=pair_setup(),
                       stdout="close_after_1"))
    cases.append(C(cat, "SIGTERM at 0.3 s: simulate --tilt to HDF5",
                   ["simulate", "--tilt", LAB_H5, "--save", "s.h5"], sig=signal.SIGTERM,
                   sig_when=0.3, timeout=60, serial=True))
    cases.append(C(cat, "stdout to /dev/full: simulate --tilt",
                   ["simulate", "--tilt", LAB_H5, "--oversample", "2"], stdout="devfull",
                   must_fail=True))
    return cases


__all__ = ["cases_miniseed", "cases_gwpy", "cases_pairs", "cases_option_edges", "cases_python",
           "cases_process_new", "pair_inputs", "mseed_records"]
