"""Cases of the hostile-input audit for the newest surfaces: units and instruments of
six-component records, witness noise and co-located records of `subtract`, the asymmetry keys,
visibility files and records, translation and ground transfer functions at extreme frequencies,
their Python calls, and the outputs of `subtract`, `visibility` and `fit`.

Imported by hostile_cli.py, which runs the cases; the pair of records comes from surfaces.py
(`pair_inputs` must have run), the case type and input helpers from case_kit.py. See README.md.
"""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import h5py
import numpy as np

import surfaces
from case_kit import SHORT_TIMEOUT, C, chain, copy_setup, write

SIX = "six.h5"
FREE = "free.h5"
VIS = "vis.csv"
PARAMS = "p.toml"
_IN: dict = {}

# The asymmetry key of the cases, and what an error about it must name.
ASYM = "asymmetry.tm_com_x_m"
ASYM_RE = r"tm_com_x_m"
# Every channel of the six-component record: (name, unit, scale).
SIX_CHANNELS = [("E", "rad", 1e-9), ("N", "rad", 1e-9), ("Z", "rad", 1e-9),
                ("HE", "m/s^2", 1e-8), ("HN", "m/s^2", 1e-8), ("HZ", "m/s^2", 1e-8)]
SIX_AXES = ["--axes", "theta_t=-E,eta_t=-N,phi_t=-Z,x_t=HE,y_t=HN,z_t=HZ"]


def newest_inputs(inputs: Path, first_bin: str) -> None:
    """The six-component record, two co-located records (the pair's tilt plus 10 % of its
    own noise), one with theta_t only, a 12 h free-motion record at 0.5 s, its visibility file
    and the parameter file, all made once (the record and file by the first binary)."""
    d = inputs / "newest"
    d.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(9)
    with h5py.File(d / SIX, "w") as f:
        f.attrs["sample_rate_hz"] = 1.0
        for name, unit, scale in SIX_CHANNELS:
            f.create_dataset(name, data=scale * rng.standard_normal(8192)).attrs["units"] = unit
    tilt = surfaces._PAIR["tilt"]
    for name, seed, drop in (("co1.h5", 3, None), ("co2.h5", 4, None),
                             ("co_theta.h5", 5, "eta_t")):
        shutil.copyfile(tilt, d / name)
        r = np.random.default_rng(seed)
        with h5py.File(d / name, "r+") as f:
            for ch in ("theta_t", "eta_t"):
                x = f[ch][...]
                f[ch][...] = x + 0.1 * np.std(x) * r.standard_normal(x.size)
            if drop:
                del f[drop]
    subprocess.run([first_bin, "simulate", "--step", "0.5", "--save", str(d / FREE)],
                   capture_output=True, timeout=300)
    subprocess.run([first_bin, "visibility", "--measured", str(d / FREE), "--save",
                    str(d / VIS)], capture_output=True, timeout=300)
    if not (d / VIS).exists():  # a stand-in: the cases still run
        write(d / VIS, "mode,observable,reference,ratio,sigma\n1,phi_a,phi,0.6,1e-8\n")
    r = subprocess.run([first_bin, "params"], capture_output=True, timeout=60)
    write(d / PARAMS, r.stdout)
    _IN["dir"] = d


def _in(name: str) -> str:
    return str(_IN["dir"] / name)


def pair_with(*names):
    """The pair of records plus the named inputs of newest_inputs, in the scratch directory."""
    return chain(surfaces.pair_setup(), copy_setup(*[(_in(n), n) for n in names]))


def vis_lines() -> list[str]:
    return (_IN["dir"] / VIS).read_text().splitlines()


def vis_variant(name: str, row: str) -> Path:
    """The visibility file with the row of the same mode and channels as `row` (else its first
    data row) replaced by `row`."""
    lines = vis_lines()
    data = [i for i, line in enumerate(lines)
            if line and not line.startswith("#") and not line.startswith("mode")]
    key = ",".join(row.split(",")[:3]) + ","
    same = [i for i in data if lines[i].startswith(key)]
    lines[(same or data)[0]] = row
    return write(_IN["dir"] / f"vis_{name}.csv", "\n".join(lines) + "\n")


def params_with(name: str, uncertainty: str) -> Path:
    text = (_IN["dir"] / PARAMS).read_text()
    return write(_IN["dir"] / f"params_{name}.toml", f"{text}\n[uncertainty]\n{uncertainty}\n")


# --------------------------------------------------------------------------------------------
# units and instruments


def cases_units(inputs: Path) -> list:
    cat = "units and instruments"
    cases = []
    six = _in(SIX)

    def budget(label, extra=(), **kw):
        cases.append(C(cat, f"budget: {label}", ["budget", "--tilt", six, *SIX_AXES, *extra],
                       **kw))

    budget("six-component record", must_succeed=True)
    budget("--corrected HE,HN,HZ", ["--corrected", "HE,HN,HZ"], must_succeed=True)
    budget("--pendulum-tiltmeter N --corrected HE",
           ["--pendulum-tiltmeter", "N", "--corrected", "HE"], must_succeed=True)
    budget("--corrected HE twice", ["--corrected", "HE", "--corrected", "HE"], must_fail=True,
           culprit=r"HE.*(twice|once)")
    budget("--corrected a missing channel", ["--corrected", "nope"], must_fail=True,
           culprit=r"nope")
    budget("--corrected a tilt channel", ["--corrected", "E"], must_fail=True, culprit=r"\bE\b")
    budget("--pendulum-tiltmeter N without a corrected HE", ["--pendulum-tiltmeter", "N"],
           must_fail=True, culprit=r"\bN\b")
    budget("--pendulum-tiltmeter on a translation channel", ["--pendulum-tiltmeter", "HE"],
           must_fail=True, culprit=r"HE")
    budget("--pendulum-tiltmeter on a missing channel", ["--pendulum-tiltmeter", "nope"],
           must_fail=True, culprit=r"nope")
    for unit in ("nrad", "m", "furlong", ""):
        budget(f"--units E={unit or '(empty)'} against the file's rad", ["--units", f"E={unit}"],
               must_fail=True, culprit=r"\bE\b")
    budget("--units HE=rad/s against the file's m/s^2", ["--units", "HE=rad/s"],
           must_fail=True, culprit=r"HE")
    budget("--units nope=rad", ["--units", "nope=rad"], must_fail=True, culprit=r"nope")
    for value in ("1e300", "1e-310", "0", "nan", "-1e200"):
        budget(f"--scale HE={value}", ["--scale", f"HE={value}"], must_fail=True,
               culprit=r"HE", huge=value == "1e300")
    budget("--scale E=1e-3 and HE=1e3 (in range)", ["--scale", "E=1e-3", "--scale", "HE=1e3"],
           must_succeed=True)
    # Two miniSEED channels off each other's time grid: the error must name both.
    e, n = surfaces.tilt_samples(4096, 3), surfaces.tilt_samples(4096, 4)
    for shift in (0.5, 0.25):
        path = write(_IN["dir"] / f"offgrid_{shift}.mseed",
                     surfaces.mseed_records("XX.TILT.00.BAE", e, 1.0)
                     + surfaces.mseed_records("XX.TILT.00.BAN", n, 1.0, t0=shift))
        cases.append(C(cat, f"budget: miniSEED channels {shift} s off each other's grid",
                       ["budget", "--tilt", str(path), "--axes", "theta_t=-BAE,eta_t=-BAN"],
                       must_fail=True, culprit=r"(?s)BAE.*BAN|BAN.*BAE"))
    # The same options on `subtract`, whose witness has only tilt.
    pair = ["subtract", "--tilt", surfaces.PAIR_TILT, "--measured", surfaces.PAIR_MEASURED]
    for label, extra, culprit in [("--corrected x_t", ["--corrected", "x_t"], r"x_t"),
                                  ("--units eta_t=m/s^2", ["--units", "eta_t=m/s^2"], r"eta_t")]:
        cases.append(C(cat, f"subtract: {label} on a tilt-only witness", pair + extra,
                       setup=surfaces.pair_setup(), must_fail=True, culprit=culprit))
    return cases


# --------------------------------------------------------------------------------------------
# witness noise and co-located records


def cases_witness(inputs: Path) -> list:
    cat = "witness and co-located"
    cases = []
    pair = ["subtract", "--tilt", surfaces.PAIR_TILT, "--measured", surfaces.PAIR_MEASURED,
            "--format", "json"]
    gains = "relative_gains"

    def sub(label, extra, names=("co1.h5", "co2.h5", "co_theta.h5"), **kw):
        kw.setdefault("null_keys", gains)
        cases.append(C(cat, f"subtract: {label}", pair + list(extra), setup=pair_with(*names),
                       **kw))

    sub("--colocated once (huddle)", ["--colocated", "co1.h5"], must_succeed=True)
    sub("--colocated twice (three-cornered hat)", ["--colocated", "co1.h5", "--colocated",
                                                   "co2.h5"], must_succeed=True)
    sub("--colocated three times", ["--colocated", "co1.h5", "--colocated", "co2.h5",
                                    "--colocated", "co2.h5"], must_fail=True,
        culprit=r"colocated")
    sub("--colocated a missing file", ["--colocated", "nope.h5"], must_fail=True,
        culprit=r"nope\.h5")
    sub("--colocated the measured record", ["--colocated", surfaces.PAIR_MEASURED],
        must_fail=True, culprit=r"meas\.h5")
    for ratio in ("1", "1e-300", "1e150", "1e300", "0", "-1", "nan", "inf"):
        bad = ratio in ("-1", "nan", "inf")  # 0: a noiseless co-located instrument
        sub(f"--colocated-ratio eta_t={ratio}", ["--colocated", "co1.h5", "--colocated-ratio",
                                                 f"eta_t={ratio}"],
            must_fail=bad, culprit=r"eta_t" if bad else None, culprit_if_fails=True,
            huge=ratio in ("1e150", "1e300"))  # 1e150, 1e300: finite results or a refusal
    sub("--colocated-ratio eta_t=1e150 --save s.h5",
        ["--colocated", "co1.h5", "--colocated-ratio", "eta_t=1e150", "--save", "s.h5"],
        nonfinite_only=gains, culprit=r"eta_t", culprit_if_fails=True)
    sub("--colocated-ratio x_t=1, no record has x_t",
        ["--colocated", "co1.h5", "--colocated-ratio", "x_t=1"], must_fail=True,
        ignored_option=True, culprit=r"x_t")
    sub("--colocated-ratio eta_t=2, the co-located record has only theta_t",
        ["--colocated", "co_theta.h5", "--colocated-ratio", "eta_t=2"], must_fail=True,
        ignored_option=True, culprit=r"eta_t")
    sub("--colocated-ratio eta_t twice", ["--colocated", "co1.h5", "--colocated-ratio",
                                          "eta_t=2", "--colocated-ratio", "eta_t=3"],
        must_fail=True, culprit=r"eta_t.*(twice|once|repeat)")
    sub("--colocated-ratio without --colocated", ["--colocated-ratio", "eta_t=2"],
        must_fail=True, culprit=r"colocated")
    sub("--colocated-ratio with two records", ["--colocated", "co1.h5", "--colocated",
                                               "co2.h5", "--colocated-ratio", "eta_t=2"],
        must_fail=True, culprit=r"colocated")
    sub("--witness-noise eta_t=1e-9", ["--witness-noise", "eta_t=1e-9"], must_succeed=True)
    sub("--witness-noise eta_t=1e-9:0.1", ["--witness-noise", "eta_t=1e-9:0.1"],
        must_succeed=True)
    for value in ("1e-310", "1e300", "nan", "-1e-9", "1e-9:nan", "1e-9:2", "1e-9:-0.1",
                  "nope.csv"):
        sub(f"--witness-noise eta_t={value}", ["--witness-noise", f"eta_t={value}"],
            must_fail=True, culprit=r"eta_t")
    sub("--witness-noise x_t (not in the witness)", ["--witness-noise", "x_t=1e-9"],
        must_fail=True, culprit=r"x_t")
    sub("--witness-noise eta_t twice", ["--witness-noise", "eta_t=1e-9", "--witness-noise",
                                        "eta_t=2e-9"], must_fail=True,
        culprit=r"eta_t.*(twice|once|repeat)")
    sub("--witness-noise eta_t with --colocated", ["--witness-noise", "eta_t=1e-9",
                                                   "--colocated", "co1.h5"], must_fail=True,
        culprit=r"eta_t")
    return cases


# --------------------------------------------------------------------------------------------
# asymmetry keys


def cases_asymmetry(inputs: Path) -> list:
    cat = "asymmetry"
    cases = []
    tf = ["tf", "--freq", "1e-3:10:1"]
    budget = ["budget", "--tilt", surfaces._PAIR["tilt"], "--nperseg", "4096"]
    for value in ("0", "1e-310", "1e-300", "1e-30", "1e-3", "1e300", "nan"):
        # A subnormal may be refused, but the error must then name the key.
        valid = value in ("0", "1e-300", "1e-30", "1e-3")
        bad = value in ("1e300", "nan")
        for cmd, args in (("modes", ["modes"]), ("tf", tf), ("budget", budget)):
            cases.append(C(cat, f"--set {ASYM}={value} {cmd}", ["--set", f"{ASYM}={value}",
                                                                 *args],
                           must_succeed=valid, must_fail=bad, culprit=ASYM_RE,
                           culprit_if_fails=not valid, huge=value == "1e300"))
    cases.append(C(cat, "--set asymmetry.sensor_rot_z_rad=1e-300 tf",
                   ["--set", "asymmetry.sensor_rot_z_rad=1e-300", *tf], must_succeed=True))
    free = ["fit", "--visibility", _in(VIS), "--free", ASYM]
    for sigma in ("1e-310", "1e-300", "1e-3"):
        p = params_with(f"sigma_{sigma}", f'"{ASYM}" = {{ sigma = {sigma} }}')
        cases.append(C(cat, f"[uncertainty] {ASYM} sigma {sigma}: fit --visibility --free",
                       ["--params", str(p), *free], culprit=ASYM_RE, culprit_if_fails=True))
        cases.append(C(cat, f"[uncertainty] {ASYM} sigma {sigma}: mc",
                       ["--params", str(p), "mc", "--samples", "200"], culprit=ASYM_RE,
                       culprit_if_fails=True))
    for sigma in ("0", "-1e-3", "nan", "1e300"):
        p = params_with(f"sigma_{sigma}", f'"{ASYM}" = {{ sigma = {sigma} }}')
        cases.append(C(cat, f"[uncertainty] {ASYM} sigma {sigma}", ["--params", str(p), "modes"],
                       must_fail=sigma in ("-1e-3", "nan"), culprit=ASYM_RE,
                       culprit_if_fails=True))
    p = params_with("rel_sigma", f'"{ASYM}" = {{ rel_sigma = 0.03 }}')
    # The error must not suggest the very field it refuses.
    cases.append(C(cat, f"[uncertainty] {ASYM} rel_sigma", ["--params", str(p), "modes"],
                   must_fail=True, culprit=r"(?s)^(?!.*\{ ?rel_sigma).*tm_com_x_m.*\bsigma\b"))
    cases.append(C(cat, f"fit --free {ASYM} without an error bar", ["fit", "--free", ASYM],
                   must_fail=True, culprit=ASYM_RE))
    return cases


# --------------------------------------------------------------------------------------------
# visibility files and records


def cases_visibility(inputs: Path) -> list:
    cat = "visibility"
    cases = []
    cases.append(C(cat, "fit --visibility (the measured file)", ["fit", "--visibility", _in(VIS)],
                   must_succeed=True))
    eta = next((line for line in vis_lines() if line.startswith("1,eta,phi,")),
               "1,eta,phi,-6.7e-7,1e-14").split(",")
    rows = [("sigma 1e-310 (nu_1 eta/phi, its ratio kept)", ",".join(eta[:4] + ["1e-310"]),
             False, r"1e-310|sigma"),
            ("sigma 1e-310 (nu_1 phi_a/phi, ratio 1e-4 off)", "1,phi_a,phi,0.6458,1e-310",
             False, r"1e-310|sigma"),
            ("sigma 0", "1,phi_a,phi,0.6458,0", True, r"sigma"),
            ("sigma NaN", "1,phi_a,phi,0.6458,nan", True, r"sigma"),
            ("sigma -1", "1,phi_a,phi,0.6458,-1", True, r"sigma"),
            ("sigma empty", "1,phi_a,phi,0.6458,", False, None),
            ("ratio NaN", "1,phi_a,phi,nan,1e-3", True, r"ratio"),
            ("ratio 1e308", "1,phi_a,phi,1e308,1e-3", True, r"ratio|1e308"),
            ("mode 9", "9,phi_a,phi,0.6,1e-3", True, r"mode"),
            ("mode 0", "0,phi_a,phi,0.6,1e-3", True, r"mode"),
            ("mode 1.5", "1.5,phi_a,phi,0.6,1e-3", True, r"mode"),
            ("unknown observable", "1,foo,phi,0.6,1e-3", True, r"foo"),
            ("unknown reference", "1,phi_a,bar,0.6,1e-3", True, r"bar"),
            ("observable is its reference", "1,phi,phi,1,1e-3", True, r"phi"),
            ("a missing field", "1,phi_a,phi", True, r"line"),
            ("an extra field", "1,phi_a,phi,0.6,1e-3,7", True, r"line")]
    for label, row, bad, culprit in rows:
        path = vis_variant(re.sub(r"[^A-Za-z0-9]+", "_", label), row)
        cases.append(C(cat, f"fit --visibility with a row of {label}",
                       ["fit", "--visibility", str(path)], must_fail=bad, culprit=culprit,
                       culprit_if_fails=culprit is not None, timeout=SHORT_TIMEOUT))
    cases.append(C(cat, "fit --visibility an empty file",
                   ["fit", "--visibility", str(write(_IN["dir"] / "vis_empty.csv", ""))],
                   must_fail=True, culprit=r"vis_empty"))
    cases.append(C(cat, "fit --visibility a missing file", ["fit", "--visibility", "nope.csv"],
                   must_fail=True, culprit=r"nope\.csv"))
    cases.append(C(cat, "visibility --measured (the free-motion record)",
                   ["visibility", "--measured", _in(FREE)], must_succeed=True))

    def damaged(label, edit, culprit, must_fail=True, **kw):
        def setup(ctx):
            shutil.copyfile(_in(FREE), ctx.dir / FREE)
            with h5py.File(ctx.dir / FREE, "r+") as f:
                edit(f)
        cases.append(C(cat, f"visibility --measured: {label}", ["visibility", "--measured",
                                                                 FREE],
                       setup=setup, must_fail=must_fail, culprit=culprit, **kw))

    for value, tag in ((np.nan, "NaN"), (1e308, "1e308"), (1e-310, "1e-310")):
        damaged(f"X one sample {tag} at index 5000", surfaces.set_sample("X", 5000, value),
                r"X.*5000", huge=tag == "1e308")
    damaged("X all zero", surfaces.set_all("X", 0.0), r"\bX\b|signal-to-noise|SNR",
            must_fail=False,
            culprit_if_fails=True)
    damaged("every channel all zero",
            lambda f: [surfaces.set_all(n, 0.0)(f) for n in ("X", "Y", "Z", "theta", "eta",
                                                              "phi", "phi_a")],
            r"zero|signal|peak|SNR")

    def rate(v):
        def edit(f):
            f.attrs["sample_rate_hz"] = v
            if "dt_s" in f.attrs:
                f.attrs["dt_s"] = 1 / v if v else 0.0
        return edit

    for v in (0.0, np.nan, 1e300, 1e-300):
        damaged(f"sample_rate_hz {v}", rate(v), r"sample_rate_hz|rate|dt_s")

    def shorten(f):
        x = f["phi"][...]
        del f["phi"]
        f.create_dataset("phi", data=x[:1000]).attrs["unit"] = "rad"

    damaged("phi shorter than X", shorten, r"phi")
    damaged("no observables", lambda f: [f.__delitem__(n) for n in ("X", "Y", "Z", "theta",
                                                                     "eta", "phi", "phi_a")],
            r"free\.h5|observable")

    def truncate(ctx):
        data = Path(_in(FREE)).read_bytes()
        (ctx.dir / FREE).write_bytes(data[: len(data) // 2])

    cases.append(C(cat, "visibility --measured: truncated file", ["visibility", "--measured",
                                                                   FREE],
                   setup=truncate, must_fail=True, culprit=r"free\.h5"))
    return cases


# --------------------------------------------------------------------------------------------
# translation and ground transfer functions at extreme frequencies

TF_FREQS = ("5e-324", "1e-310", "1e-200", "1e-100", "1e3")


def cases_ground_tf(inputs: Path) -> list:
    cat = "ground tf"
    cases = []
    for inp in ("translation", "ground"):
        for per in ("displacement", "velocity", "acceleration"):
            for f in TF_FREQS:
                base = ["tf", "--input", inp, "--per", per, "--freq", f]
                # Either finite numbers or a one-line refusal that names the frequency.
                kw = dict(culprit=r"(?i)freq|Hz|" + f.replace("-", r"-?"),
                          culprit_if_fails=True, must_succeed=f == "1e3")
                cases.append(C(cat, f"{inp} per {per} at {f} Hz", base, **kw))
                if f in ("1e-310", "1e-200"):
                    for ext in ("h5", "csv"):
                        cases.append(C(cat, f"{inp} per {per} at {f} Hz --save t.{ext}",
                                       base + ["--save", f"t.{ext}"], **kw))
    return cases


# --------------------------------------------------------------------------------------------
# Python


def cases_python_newest(inputs: Path) -> list:
    cat = "python (newest)"
    cases = []
    # `public(obj)`: the object's public attributes, so that py_case.py checks their numbers.
    pre = "import numpy as np, tiltnoise as tn\n"
    helper = ("def public(o):\n"
              "    return {k: getattr(o, k) for k in dir(o)\n"
              "            if not k.startswith('_') and not callable(getattr(o, k))}\n")

    def py(label, code, setup=None, **kw):
        code = pre + (helper if "public(" in code else "") + code
        cases.append(C(cat, label, [], python=code, setup=setup, **kw))

    for inp in ("translation", "ground"):
        for f in TF_FREQS:
            py(f"Model().transfer({f}, inputs={inp!r})",
               f"result = tn.Model().transfer(np.array([{f}]), inputs={inp!r})",
               culprit=r"ValueError: .*(freq|Hz)", culprit_if_fails=True,
               must_succeed=f == "1e3")
    py(f"Model.fit(free={ASYM!r}) with a single string",
       f"result = public(tn.Model().fit(free={ASYM!r}))", must_fail=True,
       culprit=r"\bfree\b")
    py("Model.fit(free='length.d_m') with a single string",
       "result = public(tn.Model().fit(free='length.d_m'))", culprit=r"\bfree\b",
       culprit_if_fails=True)
    pair = f"'{surfaces.PAIR_TILT}', '{surfaces.PAIR_MEASURED}'"
    py("subtract(colocated='co1.h5') with a single string",
       f"result = tn.subtract({pair}, colocated='co1.h5')", setup=pair_with("co1.h5"),
       culprit=r"\bcolocated\b", culprit_if_fails=True, timeout=60)
    py("budget(corrected='x_t') with a single string",
       "r = np.random.default_rng(1)\n"
       "x = {'eta_t': 1e-9 * r.standard_normal(8192), 'x_t': 1e-8 * r.standard_normal(8192)}\n"
       "result = tn.budget(x, fs=1.0, units={'x_t': 'm/s^2'}, corrected='x_t')",
       culprit=r"\bcorrected\b", culprit_if_fails=True)
    py("subtract(band=np.array(0.01))", f"result = tn.subtract({pair}, band=np.array(0.01))",
       setup=pair_with(), must_fail=True, culprit=r"\bband\b", timeout=60)
    py("Model.fit(visibility='nope.csv')", "result = tn.Model().fit(visibility='nope.csv')",
       must_fail=True, culprit=r"^FileNotFoundError: .*nope\.csv")
    py("Model.fit(visibility=<the measured file>)",
       f"result = public(tn.Model().fit(visibility={_in(VIS)!r}))", must_succeed=True)
    py("visibility(<the free-motion record>)",
       f"result = public(tn.visibility({_in(FREE)!r}))",
       must_succeed=True)
    py("visibility('nope.h5')", "result = tn.visibility('nope.h5')", must_fail=True,
       culprit=r"^FileNotFoundError: .*nope\.h5")
    return cases


# --------------------------------------------------------------------------------------------
# outputs of subtract, visibility, fit


def cases_outputs_newest(inputs: Path) -> list:
    cat = "newest outputs"
    cases = []
    same = r"same file|replace an input|input of the run"
    missing = r"nodir"
    sub = ["subtract", "--tilt", surfaces.PAIR_TILT, "--measured", surfaces.PAIR_MEASURED,
           "--colocated", "co1.h5"]
    for target in ("co1.h5", surfaces.PAIR_TILT, surfaces.PAIR_MEASURED, f"./{surfaces.PAIR_TILT}"):
        cases.append(C(cat, f"subtract --save {target} (an input)", sub + ["--save", target],
                       setup=pair_with("co1.h5"), must_fail=True, culprit=same))
    cases.append(C(cat, "subtract --save into a missing directory",
                   sub + ["--save", "nodir/s.h5"], setup=pair_with("co1.h5"), must_fail=True,
                   culprit=missing))
    cases.append(C(cat, "subtract: several --save, the last fails",
                   sub + ["--save", "s.json", "--save", "s.h5", "--save", "nodir/s.png"],
                   setup=pair_with("co1.h5"), must_fail=True, culprit=missing))
    vis = ["visibility", "--measured", FREE]
    free_here = copy_setup((_in(FREE), FREE))
    cases.append(C(cat, "visibility --save onto its record", vis + ["--save", FREE],
                   setup=free_here, must_fail=True, culprit=same + r"|\.csv"))
    cases.append(C(cat, "visibility --save into a missing directory",
                   vis + ["--save", "nodir/v.csv"], setup=free_here, must_fail=True,
                   culprit=missing))
    cases.append(C(cat, "visibility --save v.csv", vis + ["--save", "v.csv"], setup=free_here,
                   must_succeed=True))
    fit = ["fit", "--visibility", VIS]
    vis_here = copy_setup((_in(VIS), VIS), (_in(PARAMS), PARAMS))
    cases.append(C(cat, "fit --save onto its visibility file", fit + ["--save", VIS],
                   setup=vis_here, must_fail=True, culprit=same + r"|extension"))
    cases.append(C(cat, "fit --save into a missing directory", fit + ["--save", "nodir/f.json"],
                   setup=vis_here, must_fail=True, culprit=missing))
    cases.append(C(cat, "fit: several --save, the last fails",
                   fit + ["--save", "f.json", "--save", "f.h5", "--save", "nodir/f.h5"],
                   setup=vis_here, must_fail=True, culprit=missing))
    cases.append(C(cat, "fit --save f.json --save f.h5", fit + ["--save", "f.json", "--save",
                                                                "f.h5"],
                   setup=vis_here, must_succeed=True))
    return cases


CATEGORIES = {"units and instruments": cases_units, "witness and co-located": cases_witness,
              "asymmetry": cases_asymmetry, "visibility": cases_visibility,
              "ground tf": cases_ground_tf, "python (newest)": cases_python_newest,
              "newest outputs": cases_outputs_newest}
