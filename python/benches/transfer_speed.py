#!/usr/bin/env python3
"""Speed of tiltnoise.Model.transfer against numpy.linalg.solve, side by side in one process.

    python python/benches/transfer_speed.py [--points 100000] [--rounds 7] [--number 1]
                                            [--warmup 0] [--json] [--after]

The 7x3 tilt matrix H(f) = C (K - w^2 M)^-1 (G0 + w^2 G2) of Table I (outputs X, Y, Z, theta,
eta, phi, phi_a; inputs theta_t, eta_t, phi_t) on --points log-spaced frequencies from 1e-5 to
100 Hz:

* tiltnoise: ``Model.transfer(f)`` (method auto, which picks the pole-zero form), returning a new
  complex128 array [n, 7, 3]; with ``out=`` (a reused array); with ``threads=1``. The plan is
  built by a warm-up call (its cost, "first call", is reported separately on a new Model).
* NumPy, as a NumPy user writes it from the same model's matrices (``Model.matrices()``):
  ``H = C @ numpy.linalg.solve(D, G)`` on the stacked (n, 8, 8) and (n, 8, 3) complex arrays
  ``D = K - w^2 M``, ``G = G0 + w^2 G2``; the stacking is timed separately and not included
  in the ratio (in NumPy's favour).

Every timed function runs once untimed, then --rounds rounds in which each runs once (or
--number times in a row, the mean of which is the round's sample, as timeit does; --warmup
untimed calls first), the order rotating between rounds; the medians are reported, and the ratio's range over the rounds. The
machine may be shared: read the ratios, measured side by side, rather than the absolute times.
--after: instead, the reused-array call (2 threads) timed right after each of: nothing, a new
array from transfer, numpy.ones of the result's size, NumPy's solve, H.fill (what the work
before a call leaves in the caches and the memory system costs the call).
Per-call cost on small grids (1, 10, 100 points) is the mean of many calls, NumPy including
the stacking there (it is part of every call); the arithmetic alone is the same on 1000 points
into a reused array small enough to stay in the L2 cache.
"""

import argparse
import json
import platform
import statistics
import time

import numpy as np

import tiltnoise


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=100_000, help="grid size (default 1e5)")
    ap.add_argument("--rounds", type=int, default=7, help="timed rounds (default 7)")
    ap.add_argument("--warmup", type=int, default=0,
                    help="untimed calls of the same function right before each timed sample "
                         "(default 0: the sample follows the other functions' calls)")
    ap.add_argument("--number", type=int, default=1,
                    help="calls in a row per timed sample, as timeit's number (default 1: each "
                         "sample is one call right after the other functions' calls)")
    ap.add_argument("--json", action="store_true", help="print one JSON object instead of tables")
    ap.add_argument("--after", action="store_true",
                    help="time the reused-array call right after each kind of other work")
    return ap.parse_args()


def numpy_parts(mats, f):
    w2 = (2 * np.pi * f) ** 2
    k = mats["K"] + 1j * mats["K_imag"]

    def stack():
        d = k[None] - w2[:, None, None] * mats["M"][None]
        g = (mats["G0"][None] + w2[:, None, None] * mats["G2"][None]).astype(complex)
        return d, g

    def solve(d, g):
        return mats["C"] @ np.linalg.solve(d, g)

    return stack, solve


def timed(fn, number=1):
    t = time.perf_counter()
    for _ in range(number):
        fn()
    return (time.perf_counter() - t) / number


def per_call_us(fn, budget_s=0.3):
    fn()
    n, t = 0, time.perf_counter()
    while time.perf_counter() - t < budget_s:
        fn()
        n += 1
    return (time.perf_counter() - t) / n * 1e6


def after_other_work(args, model, f, out, numpy_solve):
    before = {
        "nothing": lambda: None,
        "a new array from transfer": lambda: model.transfer(f),
        "numpy.ones of the result's size": lambda: np.ones(out.shape, out.dtype),
        "NumPy's solve": numpy_solve,
        "H.fill (the same array)": lambda: out.fill(1.0),
    }
    times = {k: [] for k in before}
    for _ in range(args.rounds):
        for k, work in before.items():
            work()
            times[k].append(timed(lambda: model.transfer(f, out=out)))
    print(f"model.transfer(f, out=H) on {args.points} points, 2 threads, right after other work "
          f"(median of {args.rounds} rounds)")
    for k, v in times.items():
        print(f"  after {k:<34} {statistics.median(v) / args.points * 1e9:6.1f} ns/point")


def main():
    args = parse_args()
    f = np.logspace(-5, 2, args.points)
    model = tiltnoise.Model()

    t0 = time.perf_counter()
    fresh_model = tiltnoise.Model()
    fresh_model.transfer(f)
    first_call = time.perf_counter() - t0

    mats = model.matrices()
    stack, solve = numpy_parts(mats, f)
    d, g = stack()
    h_np = solve(d, g)
    h = model.transfer(f)
    out = np.empty_like(h)
    scale = np.abs(h).max(axis=0, keepdims=True)
    big = np.abs(h) > 1e-6 * scale
    agree = float(np.max(np.abs(h_np - h)[big] / np.abs(h)[big]))

    if args.after:
        after_other_work(args, model, f, out, lambda: solve(d, g))
        return

    runs = {
        "tiltnoise": lambda: model.transfer(f),
        "tiltnoise_out": lambda: model.transfer(f, out=out),
        "tiltnoise_1thread": lambda: model.transfer(f, threads=1),
        "tiltnoise_1thread_out": lambda: model.transfer(f, threads=1, out=out),
        "numpy_stack": stack,
        "numpy_solve": lambda: solve(d, g),
        # The memory floor of the result: writing its 336 bytes per point, into a new array
        # and into a reused one, with nothing computed.
        "floor_new_array": lambda: np.ones(h.shape, h.dtype),
        "floor_fill_out": lambda: out.fill(1.0),
    }
    names = list(runs)
    for fn in runs.values():
        fn()
    times = {k: [] for k in names}
    for r in range(args.rounds):
        order = names[r % len(names):] + names[: r % len(names)]
        for k in order:
            for _ in range(args.warmup):
                runs[k]()
            times[k].append(timed(runs[k], args.number))
    med = {k: statistics.median(v) for k, v in times.items()}
    ratios = {
        k: [n / t for n, t in zip(times["numpy_solve"], times[k])]
        for k in names if k.startswith("tiltnoise")
    }

    small = {}
    for n in (1, 10, 100):
        fn = f[:: max(1, len(f) // n)][:n].copy()
        st, so = numpy_parts(mats, fn)
        small[n] = {
            "tiltnoise_us": per_call_us(lambda: model.transfer(fn)),
            "numpy_us": per_call_us(lambda: so(*st())),
        }

    # The arithmetic alone: 1000 points into a reused array that stays in the L2 cache.
    f_cache = np.logspace(-5, 2, 1000)
    out_cache = np.empty((1000, 7, 3), complex)
    in_cache_ns = per_call_us(lambda: model.transfer(f_cache, out=out_cache, threads=1)) * 1e3 / 1000

    result = {
        "points": args.points,
        "rounds": args.rounds,
        "number": args.number,
        "warmup": args.warmup,
        "machine": f"{platform.machine()}, {platform.python_version()}",
        "tiltnoise_version": tiltnoise.__version__,
        "max_rel_difference_numpy_vs_tiltnoise": agree,
        "first_call_s": first_call,
        "median_s": med,
        "ns_per_point": {k: v / args.points * 1e9 for k, v in med.items()},
        "numpy_solve_over": {
            k: {"median": statistics.median(v), "min": min(v), "max": max(v)}
            for k, v in ratios.items()
        },
        "small_grids": small,
        "in_cache_1thread_ns_per_point": in_cache_ns,
        # NumPy's solve over one thread's write of the result's size (ordinary stores).
        "ceiling_new_array": med["numpy_solve"] / med["floor_new_array"],
        "ceiling_reused": med["numpy_solve"] / med["floor_fill_out"],
    }
    if args.json:
        print(json.dumps(result, indent=2))
        return
    print(f"7x3 tilt matrix, {args.points} log points 1e-5..100 Hz, {args.rounds} rounds "
          f"of {args.warmup} untimed + {args.number} timed call(s) in a row (median); NumPy and tiltnoise agree to {agree:.1e} relative where |H| > 1e-6 max")
    print(f"{'what':<34} {'ms':>9} {'ns/point':>9} {'numpy_solve / this':>24}")
    for k in names:
        ratio = ""
        if k in ratios:
            r = result["numpy_solve_over"][k]
            ratio = f"{r['median']:7.0f}x ({r['min']:.0f}-{r['max']:.0f})"
        print(f"{k:<34} {med[k] * 1e3:9.2f} {med[k] / args.points * 1e9:9.1f} {ratio:>24}")
    print(f"result: {h.nbytes / args.points:.0f} bytes per point; numpy_solve over one thread's "
          f"write of that size (floor_*): {result['ceiling_new_array']:.0f}x into a new array, "
          f"{result['ceiling_reused']:.0f}x into a reused one")
    print(f"the arithmetic alone (1000 points into a reused array in L2, one thread): "
          f"{in_cache_ns:.1f} ns/point")
    print(f"first call on a new Model (planner + pole-zero factors + grid): {first_call * 1e3:.1f} ms")
    print(f"{'per call, small grids':<22} {'tiltnoise us':>13} {'numpy us':>10}")
    for n, v in small.items():
        print(f"{n:>6} points{'':<9} {v['tiltnoise_us']:13.1f} {v['numpy_us']:10.1f}")


if __name__ == "__main__":
    main()
