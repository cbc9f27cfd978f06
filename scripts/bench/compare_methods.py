#!/usr/bin/env python3
"""Speed of each transfer-function method against numpy.linalg.solve, side by side.

    python3 scripts/bench/compare_methods.py [--points 100000] [--rounds 3] [--runs 5]
                                             [--dir /tmp/tiltnoise-bench] [--bench-exe PATH]

What is compared: the 7x3 tilt matrix of Table I at --points log-spaced frequencies from 1e-5 to
100 Hz, in ns per frequency point.

* Rust: the criterion benchmark `benches/methods.rs` (group `methods_7x3_tilt`: direct, block,
  split, polezero, modal, statespace point by point on one thread; block, split and polezero
  also on two threads, the grid cut in halves; the pole-zero grid evaluations on one and two threads:
  polezero_matrix, `tf::evaluate_into` into a reused `TransferMatrix` in the plan's own
  layout, what `auto` hands the user (the 11 entries of the 7x3 tilt matrix that are not
  structural zeros, real for the undamped Table I: 88 bytes per point); polezero_batch,
  `eval_grid_into` the dense complex 7x3 matrix into a reused buffer (336 bytes per point,
  NumPy's H); polezero_evaluate, `tf::evaluate` allocating its result, one thread). The
  script builds it once with `cargo bench --bench methods --no-run --message-format=json`,
  copies the executable to DIR/methods.snapshot (so a concurrent build cannot swap it mid-run;
  its sha256 is printed) and runs the copy as
      TILTNOISE_BENCH_METHODS_POINTS=N CRITERION_HOME=DIR/criterion \\
          DIR/methods.snapshot --bench --output-format bencher methods_7x3_tilt
  parsing `test methods_7x3_tilt/<method>/<1t|2t> ... bench: T ns/iter` (T = criterion's median
  time per grid); ns per point = T / N. `--bench-exe PATH` skips the build and measures PATH.
* NumPy: scripts/bench/methods_numpy.py --threads 1 and --threads 2, as separate processes
  (the BLAS thread variables are set before NumPy is imported); each reports the median of
  --runs timed runs of `C @ numpy.linalg.solve(D, G)` on the stacked (N, 8, 8) complex D, both
  allocating their results (`solve`) and into preallocated arrays (`solve_out`). Stacking D
  and G is excluded there (it is included on the Rust side: every method builds its matrices
  per point), so the ratio is, if anything, in NumPy's favour.

Like is compared with like: Rust into a reused buffer against NumPy into preallocated arrays
(NumPy's faster figure), and `tf::evaluate` (allocating) against NumPy allocating.

Interleaving: --rounds rounds; in each, the three processes (numpy 1 thread, numpy 2 threads,
Rust) run once each, and their order rotates from round to round, so slow phases of the shared
machine hit every side alike. Reported: the median over rounds of each figure, the ratio of
medians (NumPy ns/point over Rust ns/point at the same thread count), and the per-round ratio's
median and range.

Target: what `auto` does for the user (polezero_matrix: the pole-zero method, which
meets the 1e-9 relative accuracy target of crates/tiltnoise-core/tests/it/polezero.rs and
crates/tiltnoise-core/tests/it/methods.rs, evaluating the whole grid into its result) at least --target-ratio (100) times faster per point than
NumPy into preallocated arrays, single thread. Exit code 0 if met, 1 if missed, 2 if a run
failed. Raw figures go to DIR/compare_methods.json.
"""

import argparse
import datetime
import hashlib
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
METHODS = ("direct", "block", "split", "polezero", "polezero_batch", "polezero_matrix",
           "polezero_evaluate", "modal", "statespace")
TWO_THREAD = ("block", "split", "polezero", "polezero_batch", "polezero_matrix")
ACCURATE = "polezero_matrix"
ALLOCATING = "polezero_evaluate"
GROUP = "methods_7x3_tilt"
LINE = re.compile(r"test\s+" + GROUP + r"/(\w+)/(\dt)\s+\.\.\.\s+bench:\s+([\d,]+)\s+ns/iter")


def build_bench():
    """Builds benches/methods.rs; returns the path of its executable."""
    cmd = ["cargo", "bench", "--bench", "methods", "--no-run", "--message-format=json-render-diagnostics"]
    p = subprocess.run(cmd, cwd=REPO, stdout=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit(f"`{' '.join(cmd)}` failed (exit {p.returncode}); pass --bench-exe to measure a built copy")
    exe = None
    for line in p.stdout.splitlines():
        try:
            msg = json.loads(line)
        except json.JSONDecodeError:
            continue
        t = msg.get("target", {})
        if msg.get("reason") == "compiler-artifact" and t.get("name") == "methods" and "bench" in t.get("kind", []):
            exe = msg.get("executable") or exe
    if not exe:
        sys.exit("cargo did not report the executable of the `methods` bench")
    return exe


def snapshot(exe, outdir):
    copy = os.path.join(outdir, "methods.snapshot")
    shutil.copy2(exe, copy)
    with open(copy, "rb") as fh:
        digest = hashlib.sha256(fh.read()).hexdigest()[:12]
    built = datetime.datetime.fromtimestamp(os.path.getmtime(exe)).isoformat(timespec="seconds")
    print(f"bench executable {exe} (built {built}, sha256 {digest}), measured as {copy}")
    return copy, digest


def run(cmd, env_extra, what):
    env = dict(os.environ, **env_extra)
    p = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.stderr.write(p.stderr)
        print(f"{what} failed (exit {p.returncode}): {' '.join(cmd)}", file=sys.stderr)
        sys.exit(2)
    return p.stdout


def run_rust(exe, points, outdir):
    """{(method, '1t'|'2t'): ns per point} from one run of the criterion benchmark."""
    env = {"TILTNOISE_BENCH_METHODS_POINTS": str(points), "CRITERION_HOME": os.path.join(outdir, "criterion")}
    out = run([exe, "--bench", "--output-format", "bencher", GROUP], env, "Rust bench")
    res = {}
    for m in LINE.finditer(out):
        res[(m.group(1), m.group(2))] = int(m.group(3).replace(",", "")) / points
    want = [(m, "1t") for m in METHODS] + [(m, "2t") for m in TWO_THREAD]
    missing = [k for k in want if k not in res]
    if missing:
        sys.stderr.write(out)
        print(f"Rust bench output lacks {missing}", file=sys.stderr)
        sys.exit(2)
    return res


def run_numpy(threads, points, runs):
    cmd = [sys.executable, os.path.join(HERE, "methods_numpy.py"), "--threads", str(threads),
           "--points", str(points), "--runs", str(runs)]
    return json.loads(run(cmd, {"PYTHONDONTWRITEBYTECODE": "1"}, f"NumPy ({threads} thread)").strip().splitlines()[-1])


def machine():
    cpu = "?"
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    rustc = subprocess.run(["rustc", "--version"], stdout=subprocess.PIPE, text=True).stdout.strip()
    return {"cpu": cpu, "cpus": os.cpu_count(), "kernel": platform.release(), "rustc": rustc,
            "python": platform.python_version()}


def med(xs):
    return statistics.median(xs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100_000, help="grid size (default 1e5, the issue's)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds (default 3)")
    ap.add_argument("--runs", type=int, default=5, help="timed runs per NumPy process (median; default 5)")
    ap.add_argument("--dir", default="/tmp/tiltnoise-bench", help="scratch directory (snapshot, criterion data, JSON)")
    ap.add_argument("--bench-exe", help="measure this built bench executable instead of building one")
    ap.add_argument("--target-ratio", type=float, default=100.0)
    args = ap.parse_args()
    os.makedirs(args.dir, exist_ok=True)

    exe, digest = snapshot(args.bench_exe or build_bench(), args.dir)
    info = machine()
    info.update(date=datetime.date.today().isoformat(), points=args.points, rounds=args.rounds,
                numpy_runs=args.runs, sha256=digest, load_before=os.getloadavg())
    print(f"{info['date']}  {info['cpus']} CPUs ({info['cpu']}), Linux {info['kernel']}, {info['rustc']}, "
          f"Python {info['python']}; load average {info['load_before'][0]:.2f}")
    print(f"7x3 tilt matrix, {args.points} log-spaced points 1e-5..100 Hz; {args.rounds} interleaved rounds")

    sides = [("numpy", 1), ("numpy", 2), ("rust", None)]
    rounds = []
    for r in range(args.rounds):
        k = r % len(sides)
        rec = {}
        for side, threads in sides[k:] + sides[:k]:
            if side == "rust":
                rec["rust"] = run_rust(exe, args.points, args.dir)
            else:
                rec[f"numpy{threads}"] = run_numpy(threads, args.points, args.runs)
        rounds.append(rec)
        s = rec["rust"][(ACCURATE, "1t")]
        n1 = rec["numpy1"]["solve_out_ns_per_point"]
        n2, s2 = rec["numpy2"]["solve_out_ns_per_point"], rec["rust"][(ACCURATE, "2t")]
        na, sa = rec["numpy1"]["solve_ns_per_point"], rec["rust"][(ALLOCATING, "1t")]
        print(f"  round {r + 1}: reused outputs: numpy(1t) {n1:.0f} ns/pt, {ACCURATE}(1t) {s:.1f} ns/pt, "
              f"ratio {n1 / s:.1f}; 2 threads: numpy {n2:.0f}, {ACCURATE} {s2:.1f}, ratio {n2 / s2:.1f}; "
              f"fresh outputs: numpy {na:.0f}, {ALLOCATING} {sa:.1f}, ratio {na / sa:.1f}", flush=True)
    info["load_after"] = os.getloadavg()
    info["numpy"] = rounds[0]["numpy1"]["numpy"]

    # The NumPy figure each Rust figure is compared with: into preallocated arrays for the
    # benchmarks that write into a reused buffer, allocating for `polezero_evaluate` (which
    # allocates its result too).
    def baseline(m):
        return "solve_ns_per_point" if m == ALLOCATING else "solve_out_ns_per_point"

    np_ns = {(t, k): med([rec[f"numpy{t}"][k] for rec in rounds])
             for t in (1, 2) for k in ("solve_ns_per_point", "solve_out_ns_per_point")}
    rows = []
    for m in METHODS:
        row = {"method": m}
        for t in (1, 2):
            key = (m, f"{t}t")
            if key not in rounds[0]["rust"]:
                continue
            per = [rec["rust"][key] for rec in rounds]
            ratios = [rec[f"numpy{t}"][baseline(m)] / rec["rust"][key] for rec in rounds]
            row[f"ns{t}"] = med(per)
            row[f"ratio{t}"] = np_ns[(t, baseline(m))] / med(per)
            row[f"round_ratio{t}"] = (med(ratios), min(ratios), max(ratios))
        rows.append(row)

    def cell(x, fmt):
        return fmt.format(x) if x is not None else "—"

    print()
    print("NumPy / Rust: against NumPy into preallocated arrays, except polezero_evaluate (allocates "
          "its result) against NumPy allocating")
    print("| method | Rust ns/point, 1 thread | Rust ns/point, 2 threads | NumPy / Rust, 1 thread "
          "| NumPy / Rust, 2 threads | per-round ratio, 1 thread: median (range) |")
    print("|---|---|---|---|---|---|")
    for row in rows:
        rr = row["round_ratio1"]
        print(f"| {row['method']} | {cell(row.get('ns1'), '{:.1f}')} | {cell(row.get('ns2'), '{:.1f}')} "
              f"| {cell(row.get('ratio1'), '{:.1f}')} | {cell(row.get('ratio2'), '{:.1f}')} "
              f"| {rr[0]:.1f} ({rr[1]:.1f} .. {rr[2]:.1f}) |")
    extra = {t: {k: med([rec[f"numpy{t}"][k] for rec in rounds])
                 for k in ("solve_ns_per_point", "solve_out_ns_per_point", "stack_ns_per_point",
                           "solve_real_ns_per_point")
                 if k in rounds[0][f"numpy{t}"]} for t in (1, 2)}
    print(f"| NumPy: solve + matmul into preallocated arrays (complex) | {np_ns[(1, 'solve_out_ns_per_point')]:.0f} "
          f"| {np_ns[(2, 'solve_out_ns_per_point')]:.0f} | | | |")
    print(f"| NumPy: C @ numpy.linalg.solve(D, G), allocating (complex) | {np_ns[(1, 'solve_ns_per_point')]:.0f} "
          f"| {np_ns[(2, 'solve_ns_per_point')]:.0f} | | | |")
    print(f"| (NumPy: stacking D and G, not in the baseline) | {extra[1]['stack_ns_per_point']:.0f} "
          f"| {extra[2]['stack_ns_per_point']:.0f} | | | |")
    if "solve_real_ns_per_point" in extra[1]:
        print(f"| (NumPy: the same solve in real float64, undamped model) | {extra[1]['solve_real_ns_per_point']:.0f} "
              f"| {extra[2]['solve_real_ns_per_point']:.0f} | | | |")
    print(f"\nload average before {info['load_before'][0]:.2f}, after {info['load_after'][0]:.2f}")

    acc = next(r for r in rows if r["method"] == ACCURATE)
    met = acc["ratio1"] >= args.target_ratio
    need = np_ns[(1, "solve_out_ns_per_point")] / args.target_ratio
    print(f"target: {ACCURATE} >= {args.target_ratio:g}x NumPy into preallocated arrays per point (1 thread), "
          f"i.e. <= {need:.1f} ns/point: {'met' if met else 'MISSED'} ({acc['ratio1']:.1f}x, {acc['ns1']:.1f} ns/point; "
          f"2 threads {acc['ratio2']:.1f}x, {acc['ns2']:.1f} ns/point)")
    alloc = next(r for r in rows if r["method"] == ALLOCATING)
    print(f"allocating on both sides: {ALLOCATING} {alloc['ns1']:.1f} ns/point, {alloc['ratio1']:.1f}x NumPy's "
          f"{np_ns[(1, 'solve_ns_per_point')]:.0f}")
    with open(os.path.join(args.dir, "compare_methods.json"), "w") as fh:
        json.dump({"info": info, "rows": rows, "numpy": extra,
                   "rounds": [{k: (v if k != "rust" else {f"{a}/{b}": x for (a, b), x in v.items()})
                               for k, v in rec.items()} for rec in rounds]}, fh, indent=1)
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
