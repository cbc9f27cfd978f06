#!/usr/bin/env python3
"""Deterministic synthetic floor-tilt inputs for the budget benchmarks (schema tiltnoise.tilt_series).

    python3 scripts/bench/make_inputs.py [OUTDIR] [--only 12h|30d|ground_12h|ground_30d] [--force]

OUTDIR defaults to /tmp/tiltnoise-bench (never the repository). Writes

    tilt_12h.h5   432 000 samples per axis at 10 Hz (12 h), about 10 MB
    tilt_30d.h5   25 920 000 samples per axis at 10 Hz (30 days), about 622 MB
    ground_12h.h5, ground_30d.h5   the same tilt plus the floor's translation (six channels),
                  about 21 MB and 1.24 GB

Each file holds root datasets theta_t, eta_t, phi_t (1-D float64, attribute units = "rad") and the
root attributes schema, schema_version, sample_rate_hz = 10.0, start_time, description.

The signal: three independent white Gaussian sequences (numpy PCG64, fixed seed) are coloured by a
first-order low-pass (pole 0.9995 at 10 Hz: corner about 0.8 mHz, PSD ~ 1/f^2 above it, i.e. a
"red" tilt spectrum), a white floor is added, and the three are mixed by a fixed matrix so that the
axes are correlated (theta_t/eta_t coherence 0.2 to 0.4; phi_t about 3 times smaller and weakly
coupled). Levels of theta_t and eta_t: about 7e-9 rad/sqrt(Hz) at 1 mHz, 2e-9 at 5 mHz, 1e-10 at
0.1 Hz, 1.5e-11 at 1 Hz, plus a constant offset per axis (removed by the constant detrend). Generated and written in blocks of 2^20 samples, with the filter state carried
across blocks, so the 30-day file needs only a few tens of MB of memory to make. The same seed and
block size always give bit-identical files (a fingerprint of the first samples is printed).

The `ground_*` files hold the same three tilt datasets, bit for bit, and three more, x_t, y_t, z_t
(attribute units = "m/s^2"): the floor's acceleration as an inertial sensor reports it, made by
the same recipe from a second generator stream (seed + 1) scaled by ACCEL_PER_RAD, with a part of
eta_t and theta_t mixed in (a seismometer senses tilt), so all six channels are correlated.
"""

import argparse
import hashlib
import os
import sys
import time

import h5py
import numpy as np

FS_HZ = 10.0
SEED = 20240301
BLOCK = 1 << 20
POLE = 0.9995
# Rows: theta_t, eta_t, phi_t; columns: the three independent red sequences.
MIX = np.array([[1.0, 0.0, 0.0], [0.55, 0.85, 0.0], [0.05, 0.10, 0.30]])
RED_SCALE = 1.5e-11  # rad per unit white sample before the low-pass
WHITE_FLOOR = 2e-11  # rad rms white floor per sample
OFFSET = np.array([3.0e-6, -1.2e-6, 4.0e-7])  # rad, constant tilt per axis
AXES = ("theta_t", "eta_t", "phi_t")
TRANSLATIONS = ("x_t", "y_t", "z_t")
ACCEL_PER_RAD = 5.0  # m/s^2 per rad of the tilt recipe: accelerations of about 5e-8 m/s^2/sqrt(Hz)
# Rows: x_t, y_t, z_t; columns: theta_t, eta_t, phi_t (the tilt an inertial sensor senses, g t).
TILT_SENSED = np.array([[0.0, 9.81, 0.0], [-9.81, 0.0, 0.0], [0.0, 0.0, 0.0]])

FILES = {
    "12h": ("tilt_12h.h5", 12 * 3600 * 10),
    "30d": ("tilt_30d.h5", 30 * 24 * 3600 * 10),
    "ground_12h": ("ground_12h.h5", 12 * 3600 * 10),
    "ground_30d": ("ground_30d.h5", 30 * 24 * 3600 * 10),
}


def channels(key):
    """The datasets of a file: the tilt axes, and the translations for the ground_* files."""
    return AXES + TRANSLATIONS if key.startswith("ground") else AXES


def write_series(path, n_samples, seed=SEED, translations=False):
    """Writes the synthetic series of n_samples per axis to path (atomically via a .tmp file),
    with the floor's translations too when `translations`."""
    from scipy import signal  # here, so that importing this module (compare scripts) stays light

    rng = np.random.Generator(np.random.PCG64(seed))
    rng_t = np.random.Generator(np.random.PCG64(seed + 1))
    b, a = [1.0 - POLE], [1.0, -POLE]
    zi = np.zeros((3, 1))
    zi_t = np.zeros((3, 1))
    tmp = path + ".tmp"
    fp = hashlib.sha256()
    with h5py.File(tmp, "w") as f:
        f.attrs["schema"] = "tiltnoise.tilt_series"
        f.attrs["schema_version"] = 1
        f.attrs["sample_rate_hz"] = FS_HZ
        f.attrs["start_time"] = "2024-03-01T00:00:00Z"
        f.attrs["description"] = (
            f"synthetic red correlated floor tilt for benchmarks (scripts/bench/make_inputs.py, seed {seed})"
        )
        dsets = []
        for name in AXES:
            d = f.create_dataset(name, shape=(n_samples,), dtype="f8")
            d.attrs["units"] = "rad"
            dsets.append(d)
        tdsets = []
        for name in TRANSLATIONS if translations else ():
            d = f.create_dataset(name, shape=(n_samples,), dtype="f8")
            d.attrs["units"] = "m/s^2"
            tdsets.append(d)
        pos = 0
        while pos < n_samples:
            n = min(BLOCK, n_samples - pos)
            white = rng.standard_normal((3, n))
            # Low-pass gain at DC is 1; scale so the red part dominates below ~0.1 Hz.
            red, zi = signal.lfilter(b, a, white * (RED_SCALE / (1.0 - POLE)), axis=1, zi=zi)
            floor = rng.standard_normal((3, n)) * WHITE_FLOOR
            x = MIX @ (red + floor) + OFFSET[:, None]
            for c, d in enumerate(dsets):
                d[pos : pos + n] = x[c]
            if tdsets:
                white = rng_t.standard_normal((3, n))
                red_t, zi_t = signal.lfilter(b, a, white * (RED_SCALE / (1.0 - POLE)), axis=1, zi=zi_t)
                floor = rng_t.standard_normal((3, n)) * WHITE_FLOOR
                u = ACCEL_PER_RAD * (MIX @ (red_t + floor)) + TILT_SENSED @ (x - OFFSET[:, None])
                for c, d in enumerate(tdsets):
                    d[pos : pos + n] = u[c]
            if pos == 0:
                fp.update(np.ascontiguousarray(x[:, :4096]).tobytes())
            pos += n
    os.replace(tmp, path)
    return fp.hexdigest()[:16]


def ensure(outdir, which=("12h", "30d"), force=False, quiet=False):
    """Creates the requested files in outdir unless present; returns {key: path}."""
    os.makedirs(outdir, exist_ok=True)
    paths = {}
    for key in which:
        name, n = FILES[key]
        path = os.path.join(outdir, name)
        paths[key] = path
        if os.path.exists(path) and not force:
            with h5py.File(path, "r") as f:
                ok = all(a in f and f[a].shape == (n,) for a in channels(key))
                ok = ok and float(f.attrs["sample_rate_hz"]) == FS_HZ
            if ok:
                continue
        t0 = time.perf_counter()
        digest = write_series(path, n, translations=key.startswith("ground"))
        if not quiet:
            mb = os.path.getsize(path) / 1e6
            print(
                f"wrote {path}: {n} samples x {len(channels(key))} channels, {mb:.1f} MB, "
                f"{time.perf_counter() - t0:.1f} s, fingerprint {digest}",
                file=sys.stderr,
            )
    return paths


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("outdir", nargs="?", default="/tmp/tiltnoise-bench")
    ap.add_argument("--only", choices=sorted(FILES), action="append", help="make only this file (repeatable)")
    ap.add_argument("--force", action="store_true", help="rewrite files that already exist")
    args = ap.parse_args()
    ensure(args.outdir, tuple(args.only or ("12h", "30d")), force=args.force)


if __name__ == "__main__":
    main()
