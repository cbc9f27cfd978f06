#!/usr/bin/env python3
"""NumPy baseline of the transfer-function speed benchmark.

    python3 scripts/bench/methods_numpy.py [--threads 1] [--points 100000] [--runs 5]

The 7x3 tilt matrix H(f) = C (K - w^2 M)^-1 (G0 + w^2 G2) of Table I (outputs X, Y, Z, theta,
eta, phi, phi_a; inputs theta_t, eta_t, phi_t) at `--points` log-spaced frequencies from 1e-5 to
100 Hz, the way a NumPy user would write it:

    D = K - w^2 M        stacked, (n, 8, 8) complex
    G = G0 + w^2 G2      stacked, (n, 8, 3) complex
    H = C @ numpy.linalg.solve(D, G)

M, K, G0, G2 come from `budget_numpy.build_model` (the float64 port of
scripts/reference/tilt_budget_reference.py, with the crate's tilt convention); the observation
matrix is extended here from its 3 rows (X, phi, phi_a) to all 7 (section II.D), and the 3 rows
it shares with `build_model` are checked to be identical.

Timed (time.perf_counter, after one untimed warm-up; the median of `--runs` runs is reported):

* `solve`: `numpy.linalg.solve(D, G)` followed by `C @ X`, each allocating its result (what
  a NumPy user writes);
* `solve_out`: the same arithmetic into preallocated arrays: the gufunc behind
  `numpy.linalg.solve` (`numpy.linalg._umath_linalg.solve`, which takes `out=`; private, so
  checked here against `solve` bit for bit) and `numpy.matmul(C, X, out=H)`. NumPy without
  the page faults of fresh results: the baseline against which a Rust evaluation into a
  reused buffer is compared;
* `stack`: building D and G from w^2 (reported for information; not in `solve`);
* `solve_real`: the same solve on real float64 D and G, only when every loss angle is 0 (an
  undamped model is real; for information: what a NumPy user could do for Table I).

Interpreter start-up, imports and the model build are excluded. The BLAS thread count is set
from `--threads` in OPENBLAS_NUM_THREADS, OMP_NUM_THREADS and MKL_NUM_THREADS before NumPy is
imported, so run one process per thread count (scripts/bench/compare_methods.py does).
`numpy.linalg.solve` on a stack of 8x8 matrices calls LAPACK's ?gesv once per matrix in NumPy's
own gufunc loop, so BLAS threads are not expected to help.

Prints one JSON object on stdout: ns per point (median, and every run) of each timed part.
"""

import argparse
import json
import os
import sys
import time


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1, help="BLAS/OpenMP threads (default 1)")
    ap.add_argument("--points", type=int, default=100_000, help="grid size (default 1e5)")
    ap.add_argument("--runs", type=int, default=5, help="timed runs; the median is reported (default 5)")
    ap.add_argument("--params", default=None, help="parameter TOML (default src/params/table1.toml)")
    return ap.parse_args()


ARGS = parse_args()
# Before NumPy is imported (also through budget_numpy below).
for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[var] = str(ARGS.threads)

import tomllib  # noqa: E402

import numpy as np  # noqa: E402

sys.dont_write_bytecode = True  # no __pycache__ inside the repository
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from budget_numpy import DEFAULT_PARAMS, build_model  # noqa: E402

TA, EA, PA, DA, TB, EB, PB, DB = range(8)
OUTPUTS7 = ("X", "Y", "Z", "theta", "eta", "phi", "phi_a")
F_LO_HZ, F_HI_HZ = 1e-5, 100.0


def observation7(tp):
    """All 7 observation rows (X, Y, Z, theta, eta, phi, phi_a), as src/model/matrices.rs."""
    L = tp["length"]
    d, h_c, Z, Z_b = L["d_m"], L["h_c_m"], L["z_m"], L["z_b_m"]
    lever, lower = Z + Z_b + h_c, h_c + Z_b
    C = np.zeros((7, 8))
    C[0, EA], C[0, EB], C[0, PA] = -lever, -lower, d
    C[1, TA], C[1, TB] = lever, lower
    C[2, DA], C[2, DB], C[2, TA] = -1.0, -1.0, -d
    C[3, TA], C[3, TB] = 1.0, 1.0
    C[4, EA], C[4, EB] = 1.0, 1.0
    C[5, PA], C[5, PB] = 1.0, 1.0
    C[6, PA] = 1.0
    return C


def median_ns_per_point(fn, runs, n):
    fn()  # warm-up (page faults of the outputs, LAPACK workspace)
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    per = sorted(t * 1e9 / n for t in times)
    return per[len(per) // 2], [t * 1e9 / n for t in times]


def main():
    with open(ARGS.params or DEFAULT_PARAMS, "rb") as fh:
        tp = tomllib.load(fh)
    M, K, G0, G2, C3 = build_model(tp)
    C = observation7(tp)
    if not np.array_equal(C[[0, 5, 6]], C3):
        sys.exit("observation rows X, phi, phi_a differ from budget_numpy.build_model")
    n = ARGS.points
    f = np.logspace(np.log10(F_LO_HZ), np.log10(F_HI_HZ), n)
    f[0], f[-1] = F_LO_HZ, F_HI_HZ  # endpoints as the Rust grid has them
    w2 = (2 * np.pi * f) ** 2

    def stack():
        D = K[None, :, :] - w2[:, None, None] * M[None, :, :]
        G = (G0[None, :, :] + w2[:, None, None] * G2[None, :, :]).astype(complex)
        return D, G

    D, G = stack()
    H = None

    def solve():
        nonlocal H
        H = C @ np.linalg.solve(D, G)

    from numpy.linalg import _umath_linalg

    X_out = np.empty((n, 8, G.shape[2]), complex)
    H_out = np.empty((n, C.shape[0], G.shape[2]), complex)

    def solve_out():
        _umath_linalg.solve(D, G, out=X_out, signature="DD->D")
        np.matmul(C, X_out, out=H_out)

    result = {
        "points": n,
        "threads": ARGS.threads,
        "runs": ARGS.runs,
        "numpy": np.__version__,
        "python": sys.version.split()[0],
        "shape_H": None,
    }
    med, all_runs = median_ns_per_point(solve, ARGS.runs, n)
    result["shape_H"] = list(H.shape)
    result["solve_ns_per_point"], result["solve_runs"] = med, all_runs
    med, all_runs = median_ns_per_point(solve_out, ARGS.runs, n)
    if not np.array_equal(H_out, H):
        sys.exit("solve_out (preallocated) differs from C @ numpy.linalg.solve(D, G)")
    result["solve_out_ns_per_point"], result["solve_out_runs"] = med, all_runs
    med, all_runs = median_ns_per_point(stack, ARGS.runs, n)
    result["stack_ns_per_point"], result["stack_runs"] = med, all_runs
    if not np.any(K.imag):
        Dr, Gr = D.real.copy(), G.real.copy()

        def solve_real():
            C @ np.linalg.solve(Dr, Gr)

        med, all_runs = median_ns_per_point(solve_real, ARGS.runs, n)
        result["solve_real_ns_per_point"], result["solve_real_runs"] = med, all_runs
    print(json.dumps(result))


if __name__ == "__main__":
    main()
