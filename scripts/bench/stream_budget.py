#!/usr/bin/env python3
"""Streaming run of `tiltnoise budget` on 30 days of 3-axis tilt at 10 Hz: peak memory and throughput.

    cargo build --release
    python3 scripts/bench/stream_budget.py [--dir /tmp/tiltnoise-bench] [--runs 3] [--limit-mb 256]
    python3 scripts/bench/stream_budget.py --ground [--runs 3]

With --ground, the input is ground_30d.h5 (the same tilt plus three translation channels in
m/s^2, 1.24 GB) and the two commands compared are the hourly budget of its three tilt inputs
(`--axes theta_t=theta_t,eta_t=eta_t,phi_t=phi_t`) and of all six (tilt, translation and ground
terms from the 6x6 cross-spectra); the script reports the ratio of their median wall times and
exits 1 if the six-input run exceeds --limit-mb or --max-ratio (default 3) times the three-input
one's time.

Makes tilt_30d.h5 (25 920 000 samples x 3 axes, about 622 MB) with make_inputs.py if missing,
then runs, as whole processes under GNU time (/usr/bin/time; `apt-get install time`),

    hourly: tiltnoise budget --tilt tilt_30d.h5 --nperseg 16384 --segment-duration 3600 --save OUT.h5
    whole:  tiltnoise budget --tilt tilt_30d.h5 --nperseg 16384 --save OUT.h5      (for reference)

alternately --runs times each, and reports per command the median wall time, the peak resident
set size (GNU time's "Maximum resident set size", the largest over the runs), and the throughput:
samples per channel per second, values (samples x axes) per second and input MB (1e6 bytes) per
second. The input is read through the page cache, which holds it after the first (untimed)
warm-up run, so this is the processing rate, not the disk's. Exits 1 if the hourly run's peak
RSS exceeds --limit-mb (MB = 1e6 bytes), 2 if a run fails.

Memory model of the hourly run (see scripts/bench/README.md): the per-segment `tilt` PSDs are
kept as f32 until the end, n_segments x n_bins x 3 observables x 4 bytes, and building the
percentile bands converts one observable at a time to f64 (n_segments x n_bins x 8 bytes) on top;
the script prints that estimate next to the measurement.
"""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
sys.dont_write_bytecode = True  # no __pycache__ inside the repository
sys.path.insert(0, HERE)
import make_inputs  # noqa: E402
from compare_budget import snapshot  # noqa: E402


def run(gnu_time, cmd):
    """(wall s, peak RSS kB, user s, sys s) of one run of cmd under GNU time."""
    with tempfile.NamedTemporaryFile("r") as out:
        t0 = time.perf_counter()
        p = subprocess.run([gnu_time, "-f", "%M %U %S", "-o", out.name] + cmd,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            print(f"failed (exit {p.returncode}): {' '.join(cmd)}\n{p.stderr.decode()}", file=sys.stderr)
            sys.exit(2)
        rss_kb, user, sys_s = out.read().split()[-3:]
    return wall, int(rss_kb), float(user), float(sys_s)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", default="/tmp/tiltnoise-bench")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--nperseg", type=int, default=16384)
    ap.add_argument("--segment-duration", type=float, default=3600.0)
    ap.add_argument("--rust", default=os.path.join(REPO, "target", "release", "tiltnoise"))
    ap.add_argument("--limit-mb", type=float, default=256.0, help="peak RSS limit, MB = 1e6 bytes")
    ap.add_argument("--no-whole", action="store_true", help="skip the reference run without segments")
    ap.add_argument("--ground", action="store_true",
                    help="six inputs (tilt and translation) against three, on ground_30d.h5")
    ap.add_argument("--max-ratio", type=float, default=3.0,
                    help="with --ground: largest six-input / three-input wall-time ratio")
    args = ap.parse_args()
    gnu_time = shutil.which("time", path="/usr/bin:/bin")
    if gnu_time is None:
        sys.exit("GNU time not found at /usr/bin/time (apt-get install time)")
    if not os.path.exists(args.rust):
        sys.exit(f"{args.rust} not found: run `cargo build --release` first")
    args.rust = snapshot(args.rust, args.dir)

    key = "ground_30d" if args.ground else "30d"
    tilt = make_inputs.ensure(args.dir, (key,))[key]
    n = make_inputs.FILES[key][1]
    n_ch = len(make_inputs.channels(key))
    size = os.path.getsize(tilt)
    base = [args.rust, "budget", "--tilt", tilt, "--nperseg", str(args.nperseg)]
    hourly = ["--segment-duration", f"{args.segment_duration:g}"]
    save = lambda name: ["--save", os.path.join(args.dir, f"budget_30d_{name}.h5")]  # noqa: E731
    if args.ground:
        tilts = ",".join(f"{a}={a}" for a in make_inputs.AXES)
        cmds = {"three": base + ["--axes", tilts] + hourly + save("three"),
                "six": base + hourly + save("six")}
        limited = "six"
    else:
        cmds = {"hourly": base + hourly + save("hourly")}
        if not args.no_whole:
            cmds["whole"] = base + save("whole")
        limited = "hourly"
    print(f"input {tilt}: {n} samples x {n_ch} channels at 10 Hz ({n / 864000:.0f} days), {size / 1e6:.1f} MB")
    for name, c in cmds.items():
        run(gnu_time, c)  # warm-up: puts the input in the page cache
    res = {k: [] for k in cmds}
    for r in range(args.runs):
        for name in (list(cmds) if r % 2 == 0 else list(cmds)[::-1]):
            res[name].append(run(gnu_time, cmds[name]))

    n_bins = args.nperseg // 2
    n_seg = int(n // round(args.segment_duration * 10.0))
    # f32 tilt PSD per segment, bin and observable; the band reads them in place (no f64 copy).
    est = n_seg * n_bins * 3 * 4 / 1e6
    print(f"{args.runs} alternating runs each after one warm-up; {os.cpu_count()} CPUs; "
          f"{time.strftime('%Y-%m-%d')}")
    print()
    print(f"{'run':<7} {'median s':>9} {'user s':>7} {'sys s':>6} {'peak RSS MB':>12} {'MiB':>6} "
          f"{'Msamples/s':>11} {'Mvalues/s':>10} {'MB/s':>7}")
    channels_read = {"three": 3, "six": 6}
    for name, rs in res.items():
        wall = statistics.median(r[0] for r in rs)
        rss_kb = max(r[1] for r in rs)
        user = statistics.median(r[2] for r in rs)
        sys_s = statistics.median(r[3] for r in rs)
        read = channels_read.get(name, n_ch)
        print(f"{name:<7} {wall:9.2f} {user:7.2f} {sys_s:6.2f} {rss_kb * 1024 / 1e6:12.1f} {rss_kb / 1024:6.1f} "
              f"{n / wall / 1e6:11.2f} {read * n / wall / 1e6:10.2f} {size / wall / 1e6:7.1f}")
    print("  (samples = per channel; values = samples x channels read; MB = 1e6 bytes of the input file)")
    print(f"  hourly run: {n_seg} segments x {n_bins} bins; per-segment PSDs of the term that adds to "
          f"the total kept as f32 for 3 observables: estimate {est:.0f} MB of heap on top of the base")
    peak_mb = max(r[1] for r in res[limited]) * 1024 / 1e6
    ok = peak_mb <= args.limit_mb
    print(f"peak RSS of the {limited} run {peak_mb:.1f} MB, limit {args.limit_mb:g} MB: {'met' if ok else 'MISSED'}")
    if args.ground:
        ratio = statistics.median(r[0] for r in res["six"]) / statistics.median(r[0] for r in res["three"])
        ratio_ok = ratio <= args.max_ratio
        print(f"six-input / three-input median wall time {ratio:.2f}, limit {args.max_ratio:g}: "
              f"{'met' if ratio_ok else 'MISSED'}")
        ok = ok and ratio_ok
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
