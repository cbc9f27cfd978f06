#!/usr/bin/env python3
"""A SYNTHETIC pendulum record for `tiltnoise coherence`: a tilt time series filtered through
the model's transfer functions (from `tiltnoise tf`), with a tiltmeter gain error, a delay and
white readout noise. Not a measurement.

    python3 scripts/coherence/synthetic_pendulum.py TILT.h5 OUT.h5 [--tiltnoise BIN]
        [--params FILE] [--gain 1.1] [--delay-s 0] [--seed 1]

* TILT.h5: a tilt series in the layout `tiltnoise budget --tilt` reads (HDF5, root attribute
  sample_rate_hz, datasets theta_t / eta_t in rad, tiltnoise's sign convention), e.g.
  tilt_data/lab_tilt_24h.h5.
* The transfer functions come from `tiltnoise tf --freq-file` on the record's FFT grid, so the
  filtering is exact for the (circularly extended) record: Y = gain H exp(-i w delay) X,
  time dependence exp(+i w t). The pendulum therefore responds to `gain` times the recorded
  tilt, i.e. the tiltmeter under-reads the tilt by 1/gain.
* White readout noise, one-sided ASD: X 9e-9 m/sqrt(Hz) (the paper's), phi and phi_a
  1e-9 rad/sqrt(Hz) (assumed), drawn with numpy's default_rng(seed).
* Output: the layout `tiltnoise simulate` writes (schema tiltnoise.observable_series), with
  the tilt file's start_time, so that `tiltnoise coherence` aligns the two.

Needs numpy and h5py.
"""

import argparse
import os
import subprocess
import tempfile

import h5py
import numpy as np

READOUT = {"X": 9e-9, "phi": 1e-9, "phi_a": 1e-9}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("tilt")
    ap.add_argument("out")
    ap.add_argument("--tiltnoise", default="target/release/tiltnoise")
    ap.add_argument("--params", default=None)
    ap.add_argument("--gain", type=float, default=1.0)
    ap.add_argument("--delay-s", type=float, default=0.0)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()

    with h5py.File(a.tilt, "r") as f:
        fs = float(f.attrs["sample_rate_hz"])
        start = f.attrs.get("start_time")
        axes = [k for k in ("theta_t", "eta_t", "phi_t") if k in f]
        tilt = {k: f[k][()].astype(float) for k in axes}
    n = len(tilt[axes[0]])
    freqs = np.fft.rfftfreq(n, 1 / fs)
    with tempfile.TemporaryDirectory() as d:
        grid = os.path.join(d, "grid.txt")
        np.savetxt(grid, freqs[1:], fmt="%.17g")
        cmd = [a.tiltnoise]
        if a.params:
            cmd += ["--params", a.params]
        cmd += ["tf", "--freq-file", grid, "--input", ",".join(axes),
                "--output", ",".join(READOUT)]
        text = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    lines = [l for l in text.strip().split("\n") if not l.startswith("#")]
    header = lines[0].split(",")
    table = np.array([[float(v) for v in line.split(",")] for line in lines[1:]])
    rng = np.random.default_rng(a.seed)
    spectra = {k: np.fft.rfft(tilt[k]) for k in axes}
    shift = np.exp(-2j * np.pi * freqs * a.delay_s)
    out = {}
    for obs, asd in READOUT.items():
        y = np.zeros(len(freqs), dtype=complex)
        for ax in axes:
            h = (table[:, header.index(f"{obs}.{ax}.re")]
                 + 1j * table[:, header.index(f"{obs}.{ax}.im")])
            y[1:] += a.gain * h * shift[1:] * spectra[ax][1:]
        out[obs] = np.fft.irfft(y, n) + asd * np.sqrt(fs / 2) * rng.standard_normal(n)
    with h5py.File(a.out, "w") as f:
        f.attrs["schema"] = "tiltnoise.observable_series"
        f.attrs["schema_version"] = 1
        f.attrs["sample_rate_hz"] = fs
        if start is not None:
            f.attrs["start_time"] = start
        f.attrs["description"] = (
            f"SYNTHETIC pendulum record, not a measurement: {a.tilt} through the model's "
            f"transfer functions (tiltnoise tf{' --params ' + a.params if a.params else ''}), "
            f"gain {a.gain}, delay {a.delay_s} s, white readout "
            + ", ".join(f"{k} {v:g}" for k, v in READOUT.items())
            + f" (one-sided ASD), seed {a.seed}; scripts/coherence/synthetic_pendulum.py")
        for obs, y in out.items():
            ds = f.create_dataset(obs, data=y)
            ds.attrs["units"] = "m" if obs == "X" else "rad"
    print(f"wrote {a.out}: {n} samples at {fs} Hz, {', '.join(out)}")


if __name__ == "__main__":
    main()
