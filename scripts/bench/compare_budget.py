#!/usr/bin/env python3
"""Side-by-side whole-process comparison: `tiltnoise budget` (Rust) vs the NumPy/SciPy baseline.

    cargo build --release
    python3 scripts/bench/compare_budget.py [--dir /tmp/tiltnoise-bench] [--runs 5]
                                            [--variants pairs,broadcast,numpy] [--hyperfine]

1. Makes the 12-hour input with make_inputs.py if it is missing (never inside the repository).
2. Runs, as whole processes, one untimed warm-up of each command, then `--runs` rounds in which
   every command runs once, interleaved (the order rotates from round to round, so slow phases
   of the shared machine hit every command alike). Wall clock is time.perf_counter() around
   subprocess.run. The figure reported is
   the ratio of medians; absolute times on a shared 2-core machine are noisy, the ratio is the
   measured quantity. Peak RSS comes from one more, untimed run of each command under GNU time
   (see peak_rss_mb for why not from the rusage of the timed child).
     rust:      target/release/tiltnoise budget --tilt IN.h5 --nperseg 16384 --save OUT.h5
     <variant>: python3 scripts/bench/budget_numpy.py --tilt IN.h5 --nperseg 16384 --save OUT.h5 --csd <variant>
   The speed target (Rust at least --target-ratio times faster) is checked against
   --target-variant (default `pairs`: scipy.signal.csd, how the pipeline is usually written);
   every other variant is reported too.
3. Compares every PSD of X, phi, phi_a in the Rust file with the target variant's file (terms
   tilt, tilt.theta_t, tilt.eta_t, tilt.phi_t, readout, total), per bin:
       |rust - numpy| <= 1e-8 |numpy|            where |numpy| >= 1e-12 peak,
       |rust - numpy| <= 1e-20 peak              elsewhere (peak = max |numpy| of that term).
   Why the floor is rounding and not a loosened test: each PSD is a sum of products
   conj(H_oi) S_ij H_oj. Both sides compute H and S in double precision with errors of order
   eps * cond relative to the *largest* contributions (cond of the equilibrated dynamic
   stiffness, up to ~1e4 near the modes); where a term falls 12 or more decades below its peak
   (notches of a transfer function, the f^4 cancellation of phi and phi_a at low frequency, the
   FFT leakage floor) those absolute errors, ~1e-16 * 1e4 * peak, are no longer small relative
   to the bin, so a relative test there would test rounding, not the pipeline. 1e-20 * peak is
   still 4 orders below the 1e-12 * peak threshold, so a real difference cannot hide in it.
   Terms that are exactly zero (e.g. X per theta_t, exactly decoupled) must be exactly zero on
   both sides. The frequency grids must be equal to 1e-15 relative.
4. Prints a table and exits 1 if the ratio target or any tolerance is missed, 2 on a failed run.

Optionally (--hyperfine, if hyperfine is installed) times the same commands with hyperfine too.
"""

import argparse
import hashlib
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.dont_write_bytecode = True  # no __pycache__ inside the repository
sys.path.insert(0, HERE)
import make_inputs  # noqa: E402

OUTPUTS = ("X", "phi", "phi_a")
TERMS = ("tilt", "tilt.theta_t", "tilt.eta_t", "tilt.phi_t", "readout", "total")
RTOL = 1e-8
FLOOR_BELOW = 1e-12  # bins below this fraction of the term's peak use the absolute floor
ABS_FLOOR = 1e-20  # absolute tolerance there, as a fraction of the peak


def run_once(cmd):
    """Runs cmd; returns (wall seconds, return code, stderr text)."""
    with tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=err)
        wall = time.perf_counter() - t0
        err.seek(0)
        return wall, p.returncode, err.read().decode(errors="replace")


def peak_rss_mb(cmd):
    """Peak RSS (MiB) of one run of cmd.

    With GNU time (/usr/bin/time -f %M) when it is installed. The fallback, the rusage of the
    child itself (os.wait4, or RUSAGE_CHILDREN), over-reports: Linux carries the RSS high-water
    mark of the forked (or vforked) address space across exec, so a child reports at least the
    RSS of this Python process at the time of the fork (checked: /bin/true started from a Python
    process holding 400 MB reports 400 MB).
    """
    gnu_time = shutil.which("time", path="/usr/bin:/bin")
    if gnu_time:
        with tempfile.NamedTemporaryFile("r") as out:
            subprocess.run([gnu_time, "-f", "%M", "-o", out.name] + cmd, check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            return int(out.read().split()[-1]) / 1024.0, "GNU time"
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    _, _, ru = os.wait4(p.pid, 0)
    return ru.ru_maxrss / 1024.0, "wait4 (upper bound)"


def commands(args, tilt, outdir):
    cmds = {
        "rust": [args.rust, "budget", "--tilt", tilt, "--nperseg", str(args.nperseg),
                 "--save", os.path.join(outdir, "budget_rust.h5")],
    }
    for v in args.variants:
        cmds[v] = [sys.executable, os.path.join(HERE, "budget_numpy.py"), "--tilt", tilt,
                   "--nperseg", str(args.nperseg), "--csd", v, "--timing",
                   "--save", os.path.join(outdir, f"budget_numpy_{v}.h5")]
    return cmds


def time_interleaved(cmds, runs):
    """Wall times per command, and the stage times the Python baseline prints (--timing)."""
    names = list(cmds)
    walls = {n: [] for n in names}
    stages = {n: {} for n in names}
    for n in names:  # warm-up: page cache, Python bytecode cache, dynamic loader
        _, rc, err = run_once(cmds[n])
        if rc != 0:
            print(f"{n} failed (exit {rc}):\n{' '.join(cmds[n])}\n{err}", file=sys.stderr)
            sys.exit(2)
    for r in range(runs):
        order = names[r % len(names):] + names[: r % len(names)]
        for n in order:
            wall, rc, err = run_once(cmds[n])
            if rc != 0:
                print(f"{n} failed (exit {rc}):\n{err}", file=sys.stderr)
                sys.exit(2)
            walls[n].append(wall)
            # budget_numpy.py --timing: "model+read 0.019s  csd 0.343s  tf 0.014s ..."
            words = err.split()
            for name, val in zip(words, words[1:]):
                if val.endswith("s") and val[:-1].replace(".", "", 1).isdigit():
                    stages[n].setdefault(name, []).append(float(val[:-1]))
    return walls, stages


def hyperfine(cmds, runs, outdir):
    exe = shutil.which("hyperfine")
    if exe is None:
        print("hyperfine not installed (apt-get install hyperfine); skipped")
        return None
    out = os.path.join(outdir, "hyperfine.json")
    argv = [exe, "--warmup", "1", "--runs", str(runs), "--export-json", out, "-N"]
    for n, c in cmds.items():
        argv += ["--command-name", n, " ".join(c)]
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
    with open(out) as fh:
        res = json.load(fh)["results"]
    return {r["command"]: r["median"] for r in res}


def compare(rust_path, numpy_path):
    """Per-term comparison rows and the overall verdict."""
    rows, ok = [], True
    with h5py.File(rust_path, "r") as a, h5py.File(numpy_path, "r") as b:
        fa, fb = a["frequency_hz"][()], b["frequency_hz"][()]
        grid_ok = fa.shape == fb.shape and np.all(np.abs(fa - fb) <= 1e-15 * np.abs(fb))
        if not grid_ok:
            print(f"frequency grids differ: {fa.shape} vs {fb.shape}")
            return [], False, len(fa)
        for o in OUTPUTS:
            for t in TERMS:
                in_a, in_b = t in a.get(o, {}), t in b.get(o, {})
                if not (in_a or in_b):
                    continue
                if in_a != in_b:
                    rows.append((o, t, "missing in " + ("numpy" if in_a else "rust"), None, None, 0, False))
                    ok = False
                    continue
                r, p = a[o][t]["psd"][()], b[o][t]["psd"][()]
                peak = np.max(np.abs(p))
                if peak == 0.0:
                    good = bool(np.all(r == 0.0))
                    rows.append((o, t, "exact zero", 0.0, 0.0, 0, good))
                    ok &= good
                    continue
                diff = np.abs(r - p)
                big = np.abs(p) >= FLOOR_BELOW * peak
                rel = diff[big] / np.abs(p[big])
                max_rel = float(rel.max()) if rel.size else 0.0
                floor_frac = float((diff[~big] / peak).max()) if (~big).any() else 0.0
                good = bool(np.all(rel <= RTOL) and floor_frac <= ABS_FLOOR)
                rows.append((o, t, "", max_rel, floor_frac, int((~big).sum()), good))
                ok &= good
    return rows, ok, len(fa)


def snapshot(binary, outdir):
    """Copies the binary into outdir and returns the copy: a concurrent `cargo build` cannot
    swap it in the middle of the measurement, and profiles stay symbolizable."""
    os.makedirs(outdir, exist_ok=True)
    copy = os.path.join(outdir, "tiltnoise.snapshot")
    shutil.copy2(binary, copy)
    with open(copy, "rb") as fh:
        digest = hashlib.sha256(fh.read()).hexdigest()[:12]
    built = time.strftime("%Y-%m-%d %H:%M", time.localtime(os.path.getmtime(binary)))
    print(f"binary {binary} (built {built}, sha256 {digest}), measured as {copy}")
    return copy


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", default="/tmp/tiltnoise-bench", help="inputs and outputs (outside the repo)")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--nperseg", type=int, default=16384)
    ap.add_argument("--rust", default=os.path.join(REPO, "target", "release", "tiltnoise"))
    ap.add_argument("--variants", default="pairs,broadcast,numpy",
                    help="budget_numpy.py --csd variants to time (comma-separated)")
    ap.add_argument("--target-variant", default="pairs")
    ap.add_argument("--target-ratio", type=float, default=10.0)
    ap.add_argument("--hyperfine", action="store_true", help="also time with hyperfine if installed")
    ap.add_argument("--json", help="write the measured figures to this JSON file")
    args = ap.parse_args()
    args.variants = [v for v in args.variants.split(",") if v]
    if args.target_variant not in args.variants:
        args.variants.insert(0, args.target_variant)
    if not os.path.exists(args.rust):
        sys.exit(f"{args.rust} not found: run `cargo build --release` first")
    args.rust = snapshot(args.rust, args.dir)

    tilt = make_inputs.ensure(args.dir, ("12h",))["12h"]
    n_samples = make_inputs.FILES["12h"][1]
    cmds = commands(args, tilt, args.dir)
    print(f"input {tilt}: {n_samples} samples x 3 axes at 10 Hz, {os.path.getsize(tilt) / 1e6:.1f} MB")
    print(f"{args.runs} interleaved rounds of {', '.join(cmds)} (after one warm-up each), {os.cpu_count()} CPUs")
    walls, stages = time_interleaved(cmds, args.runs)
    rss = {}
    for n in cmds:  # a separate, untimed pass
        rss[n], rss_how = peak_rss_mb(cmds[n])

    med = {n: statistics.median(w) for n, w in walls.items()}
    print()
    print(f"{'command':<12} {'median s':>9} {'min s':>8} {'max s':>8} {'peak RSS MiB':>12} {'time / rust':>12}")
    for n in cmds:
        print(f"{n:<12} {med[n]:9.3f} {min(walls[n]):8.3f} {max(walls[n]):8.3f} "
              f"{rss[n]:12.1f} {med[n] / med['rust']:12.1f}")
    print(f"  (peak RSS from one separate run each, measured with {rss_how})")
    for v in args.variants:
        st = stages[v]
        inside = sum(statistics.median(x) for x in st.values())
        print(f"  {v} inside the script: " + ", ".join(f"{k} {statistics.median(x):.3f}" for k, x in st.items())
              + f" s; the other {med[v] - inside:.3f} s is interpreter start and imports")
    # Per-round ratios (each round's commands ran back to back): their median and spread.
    per_round = {v: [p / r for p, r in zip(walls[v], walls["rust"])] for v in args.variants}
    for v in args.variants:
        pr = per_round[v]
        print(f"  per-round ratio {v}/rust: median {statistics.median(pr):.1f}, range {min(pr):.1f} .. {max(pr):.1f}")
    ratio = med[args.target_variant] / med["rust"]

    hf = hyperfine(cmds, args.runs, args.dir) if args.hyperfine else None
    if hf:
        print("hyperfine medians: " + ", ".join(f"{n} {t:.3f} s" for n, t in hf.items()) +
              "; ratios " + ", ".join(f"{v}/rust {hf[v] / hf['rust']:.1f}" for v in args.variants))

    rows, same, n_bins = compare(os.path.join(args.dir, "budget_rust.h5"),
                                 os.path.join(args.dir, f"budget_numpy_{args.target_variant}.h5"))
    print()
    print(f"results, rust vs numpy[{args.target_variant}], {n_bins} bins: "
          f"rtol {RTOL:g} where >= {FLOOR_BELOW:g} x peak, else |diff| <= {ABS_FLOOR:g} x peak")
    print(f"{'obs':<6} {'term':<13} {'max rel diff':>13} {'floor bins':>10} {'max diff/peak':>14}  ok")
    max_rel_all = 0.0
    for o, t, note, mr, ff, nf, good in rows:
        if note:
            print(f"{o:<6} {t:<13} {note:>13} {'':>10} {'':>14}  {'yes' if good else 'NO'}")
            continue
        max_rel_all = max(max_rel_all, mr)
        print(f"{o:<6} {t:<13} {mr:13.2e} {nf:10d} {ff:14.2e}  {'yes' if good else 'NO'}")

    print()
    fast = ratio >= args.target_ratio
    print(f"speed: rust is {ratio:.1f}x faster than numpy[{args.target_variant}] as whole processes "
          f"(median of {args.runs}); target {args.target_ratio:g}x: {'met' if fast else 'MISSED'}")
    for v in args.variants:
        if v != args.target_variant:
            print(f"       ({med[v] / med['rust']:.1f}x vs numpy[{v}], not a target)")
    print(f"results: max relative difference {max_rel_all:.2e} (tolerance {RTOL:g}): {'met' if same else 'MISSED'}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"walls_s": walls, "peak_rss_mib": rss, "median_s": med, "ratio": ratio,
                       "max_rel_diff": max_rel_all, "results_ok": same, "hyperfine_median_s": hf,
                       "date": time.strftime("%Y-%m-%d"), "cpus": os.cpu_count()}, fh, indent=1)
    sys.exit(0 if (fast and same) else 1)


if __name__ == "__main__":
    main()
