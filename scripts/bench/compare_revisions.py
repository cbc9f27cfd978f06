#!/usr/bin/env python3
"""Speed of two revisions of tiltnoise side by side, with a control arm for the machine's noise.

    python3 scripts/bench/compare_revisions.py [--before REV] [--after REV] [--rounds 7]
                                               [--dir /tmp/tiltnoise-revisions] [--no-python]

Each revision is checked out (`git worktree add --detach`) under DIR/src-<sha>, built with
`cargo build --release` into its own DIR/target-<sha> (the first build of a revision takes
minutes; later runs reuse it), and its binary copied to DIR/tiltnoise-<sha>.snapshot, so a
concurrent build cannot swap it mid-run. Unless --no-python, the revision's Python package is
installed from that checkout into DIR/venv-<sha> (`pip install ./python`, the same target).

Cases (whole processes, wall clock around `subprocess.run`; the inputs are seeded and made once):

| case | command |
|---|---|
| `tf` | `tiltnoise tf --input ground --freq 1e-4:200000:30 --save OUT.h5` (200 000 points, 7 x 6) |
| `budget` | `tiltnoise budget --tilt tilt_12h.h5 --nperseg 16384 --save OUT.h5` (12 h, 3 axes, 10 Hz) |
| `simulate` | `tiltnoise simulate --duration 43200 --step 0.1 --save OUT.h5` (the paper's 12 h run) |
| `transfer_out` | Python: `Model.transfer(f, inputs=tilt, out=buf)` on 200 000 points into a reused array, median of 5 calls inside one process (the process's own figure, not its start-up) |

Arms: `before`, `after`, and `control`, a second arm running the `after` build again. Every
round runs each arm once per case in an order that rotates from round to round, so slow phases
of the shared machine hit every arm alike. Reported per case: each arm's median, the ratio of
medians after/before and control/after, and the per-round ratios' median and range.

Verdict: a case regresses when its per-round after/before ratio exceeds 1 in every round AND
its median exceeds 1 + the noise, the noise being the largest |control/after - 1| over the
rounds. Exit code 0 when no case regresses, 1 when one does, 2 when a build or a run failed.
Raw figures go to DIR/compare_revisions.json.
"""

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
BEFORE = "30186c8"
TRANSFER_POINTS = 200_000
TRANSFER_CALLS = 5

TRANSFER_SNIPPET = f"""
import time, numpy as np, tiltnoise
m = tiltnoise.Model()
f = np.logspace(-4, np.log10(30), {TRANSFER_POINTS})
inputs = ["theta_t", "eta_t", "phi_t"]
out = np.empty((f.size, 7, 3), dtype=np.complex128)
m.transfer(f, inputs=inputs, out=out)
times = []
for _ in range({TRANSFER_CALLS}):
    t = time.perf_counter(); m.transfer(f, inputs=inputs, out=out); times.append(time.perf_counter() - t)
assert np.all(np.isfinite(out))
times.sort()
print(times[len(times) // 2])
"""


def run(cmd, **kw):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)
    if p.returncode != 0:
        sys.stderr.write(p.stderr[-2000:])
        sys.exit(f"compare_revisions: `{' '.join(map(str, cmd))}` failed (exit {p.returncode})")
    return p.stdout


def resolve(rev):
    return run(["git", "-C", REPO, "rev-parse", "--verify", f"{rev}^{{commit}}"]).strip()


def prepare(sha, work, python):
    """Checks out, builds and snapshots revision `sha`; returns (binary, python or None)."""
    src = os.path.join(work, f"src-{sha[:12]}")
    target = os.path.join(work, f"target-{sha[:12]}")
    snapshot = os.path.join(work, f"tiltnoise-{sha[:12]}.snapshot")
    if not os.path.isdir(src):
        run(["git", "-C", REPO, "worktree", "add", "--detach", src, sha])
    env = dict(os.environ, CARGO_TARGET_DIR=target)
    print(f"building {sha[:12]} (cargo build --release) ...", file=sys.stderr, flush=True)
    run(["cargo", "build", "--release", "--locked", "-p", "tiltnoise"], cwd=src, env=env)
    shutil.copy2(os.path.join(target, "release", "tiltnoise"), snapshot)
    py = None
    if python:
        venv = os.path.join(work, f"venv-{sha[:12]}")
        py = os.path.join(venv, "bin", "python")
        if not os.path.exists(py):
            print(f"installing the Python package of {sha[:12]} ...", file=sys.stderr, flush=True)
            run([sys.executable, "-m", "venv", venv])
            run([py, "-m", "pip", "install", "--quiet", "numpy", os.path.join(src, "python")], env=env)
    return snapshot, py


def make_inputs(work):
    tilt = os.path.join(work, "tilt_12h.h5")
    if not os.path.exists(tilt):
        run([sys.executable, os.path.join(HERE, "make_inputs.py"), work, "--only", "12h"])
    return tilt


def case_commands(binary, py, tilt, out_dir, arm):
    out = lambda name: os.path.join(out_dir, f"{arm}-{name}.h5")  # noqa: E731
    cases = {
        "tf": [binary, "tf", "--input", "ground", "--freq", f"1e-4:{TRANSFER_POINTS}:30",
               "--save", out("tf")],
        "budget": [binary, "budget", "--tilt", tilt, "--nperseg", "16384", "--save", out("budget")],
        "simulate": [binary, "simulate", "--duration", "43200", "--step", "0.1",
                     "--save", out("simulate")],
    }
    if py:
        cases["transfer_out"] = [py, "-c", TRANSFER_SNIPPET]
    return cases


def timed(cmd, case):
    t = time.perf_counter()
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - t
    if p.returncode != 0:
        sys.stderr.write(p.stderr[-2000:])
        sys.exit(2)
    return float(p.stdout.strip()) if case == "transfer_out" else wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--before", default=BEFORE)
    ap.add_argument("--after", default="HEAD")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--dir", default="/tmp/tiltnoise-revisions")
    ap.add_argument("--no-python", action="store_true")
    args = ap.parse_args()
    if args.rounds < 2:
        sys.exit("compare_revisions: --rounds must be at least 2")
    os.makedirs(args.dir, exist_ok=True)
    before, after = resolve(args.before), resolve(args.after)
    tilt = make_inputs(args.dir)
    bins = {}
    for name, sha in (("before", before), ("after", after)):
        bins[name] = prepare(sha, args.dir, not args.no_python)
    bins["control"] = bins["after"]
    out_dir = os.path.join(args.dir, "out")
    os.makedirs(out_dir, exist_ok=True)
    arms = ["before", "after", "control"]
    commands = {arm: case_commands(*bins[arm], tilt, out_dir, arm) for arm in arms}
    cases = list(commands["after"])
    for arm in arms:  # warm-up: page cache, first-run effects
        for case in cases:
            timed(commands[arm][case], case)
    times = {case: {arm: [] for arm in arms} for case in cases}
    for r in range(args.rounds):
        order = arms[r % 3:] + arms[:r % 3]
        for case in cases:
            for arm in order:
                times[case][arm].append(timed(commands[arm][case], case))
        print(f"round {r + 1}/{args.rounds} done", file=sys.stderr, flush=True)
    report = {"before": before, "after": after, "rounds": args.rounds,
              "machine": platform.platform(), "cpus": os.cpu_count(), "cases": {}}
    regressed = []
    print(f"before {before[:12]}  after {after[:12]}  rounds {args.rounds}\n")
    print("| case | before (s) | after (s) | after/before (range) | control/after (range) | verdict |")
    print("|---|---|---|---|---|---|")
    for case in cases:
        t = times[case]
        ratio = [a / b for a, b in zip(t["after"], t["before"])]
        control = [c / a for c, a in zip(t["control"], t["after"])]
        noise = max(abs(c - 1) for c in control)
        med = statistics.median(ratio)
        worse = all(x > 1 for x in ratio) and med > 1 + noise
        if worse:
            regressed.append(case)
        verdict = "slower beyond noise" if worse else "within noise or faster"
        print(f"| `{case}` | {statistics.median(t['before']):.3f} | {statistics.median(t['after']):.3f} "
              f"| {med:.3f} ({min(ratio):.3f}..{max(ratio):.3f}) "
              f"| {statistics.median(control):.3f} ({min(control):.3f}..{max(control):.3f}) | {verdict} |")
        report["cases"][case] = {"times_s": t, "after_over_before": ratio,
                                 "control_over_after": control, "noise": noise, "regressed": worse}
    with open(os.path.join(args.dir, "compare_revisions.json"), "w") as fh:
        json.dump(report, fh, indent=1)
    return 1 if regressed else 0


if __name__ == "__main__":
    sys.exit(main())
