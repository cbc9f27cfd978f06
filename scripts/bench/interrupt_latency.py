#!/usr/bin/env python3
"""How fast an interrupt ends a long run of the command line.

    python3 scripts/bench/interrupt_latency.py [--bin target/release/tiltnoise]
        [--tilt /tmp/tiltnoise-bench/tilt_30d.h5] [--after 2] [--repeat 3]

Starts each long run in an empty temporary directory, sends SIGINT `--after` seconds later,
and reports the time from the signal to the end of the process, its exit code, its one line
on standard error and the files left in the directory (none expected). The 30-day budget
needs the input of `scripts/bench/make_inputs.py --only 30d`; it is skipped, with a line,
when the file is absent.
"""

import argparse
import os
import signal
import statistics
import subprocess
import tempfile
import time


def one_run(binary, args, after_s):
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, HDF5_USE_FILE_LOCKING="FALSE")
        p = subprocess.Popen([binary, *args], cwd=d, env=env, stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
        time.sleep(after_s)
        if p.poll() is not None:
            raise SystemExit(f"{args}: ended before the signal (exit {p.returncode})")
        t0 = time.perf_counter()
        p.send_signal(signal.SIGINT)
        p.wait()
        latency = time.perf_counter() - t0
        err = p.stderr.read().strip()
        return latency, p.returncode, err, sorted(os.listdir(d))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bin", default="target/release/tiltnoise")
    ap.add_argument("--tilt", default="/tmp/tiltnoise-bench/tilt_30d.h5")
    ap.add_argument("--after", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    runs = [
        ["mc", "--samples", "10000000", "--save", "mc.h5"],
        ["simulate", "--duration", "3e6", "--save", "sim.h5"],
        ["budget", "--tilt", a.tilt, "--save", "budget.h5"],
    ]
    print(f"| command | SIGINT after | time to exit (median of {a.repeat}, max) | exit | files left |")
    print("|---|---|---|---|---|")
    for args in runs:
        if "--tilt" in args and not os.path.exists(a.tilt):
            print(f"skipped `{' '.join(args)}`: {a.tilt} is absent (make_inputs.py --only 30d)")
            continue
        results = [one_run(os.path.abspath(a.bin), args, a.after) for _ in range(a.repeat)]
        lat = [r[0] for r in results]
        codes = sorted({r[1] for r in results})
        left = sorted({f for r in results for f in r[3]})
        print(f"| `{' '.join(args)}` | {a.after:g} s | {statistics.median(lat) * 1e3:.1f} ms, "
              f"{max(lat) * 1e3:.1f} ms | {codes} | {left or 'none'} |")
        print(f"<!-- {results[0][2]} -->")


if __name__ == "__main__":
    main()
