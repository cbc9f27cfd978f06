#!/usr/bin/env python3
"""Judges a cleaned record against the raw one, independently of tiltnoise's own checks: per
1/3-decade band, the ratio of the band-mean Welch PSDs cleaned/raw with its statistical error,
and the ratio of the variances.

    python3 scripts/subtract/band_ratios.py RAW.h5 CLEANED.h5 [--nperseg 4096] [--fmin 1e-3]

* RAW.h5: the measured record (`tiltnoise.observable_series`, as `simulate` writes it);
  CLEANED.h5: the cleaned record `tiltnoise subtract --save cleaned.h5` writes (same layout,
  over the records' overlap, whose start it states). The raw record is cut to the cleaned one's
  span by the start times (or taken from its first sample when neither states one).
* Welch with scipy (periodic Hann, 50 % overlap, mean, constant detrend), one-sided PSD.
* The statistical error of a band ratio: sigma = sqrt(2 / nu), nu the equivalent degrees of
  freedom of the band mean of the raw PSD (Percival and Walden 1993, eq. 292c generalised to M
  adjacent bins: the correlation of windowed Fourier coefficients of overlapping segments and
  neighbouring bins, computed here from the window). Bands are 1/3 decade wide from --fmin to
  the Nyquist frequency; the limit is 1 + z sigma with z the two-sided 99.73 % point corrected
  for the number of bands (Bonferroni: 1 - 0.0027 / bands, one-sided).

Needs numpy, scipy and h5py.
"""

import argparse
from datetime import datetime

import h5py
import numpy as np
from scipy import signal, stats


def read(path):
    with h5py.File(path, "r") as f:
        fs = float(f.attrs["sample_rate_hz"])
        start = f.attrs.get("start_time")
        if isinstance(start, bytes):
            start = start.decode()
        chans = {k: f[k][()].astype(float) for k in f if isinstance(f[k], h5py.Dataset)}
    return fs, start, chans


def band_dof(nperseg, nseg, bins):
    """Equivalent chi-square dof of the mean of `bins` adjacent bins of a Welch PSD over
    `nseg` half-overlapping periodic-Hann segments."""
    w = signal.get_window("hann", nperseg)
    norm = np.sum(w * w)
    step = nperseg // 2
    denom = 0.0
    for d in range(min(nseg, -(-nperseg // step))):
        prod = np.zeros(nperseg)
        prod[: nperseg - d * step] = w[: nperseg - d * step] * w[d * step:]
        z = np.abs(np.fft.rfft(prod)) / norm
        segw = nseg if d == 0 else 2 * (nseg - d)
        for b in range(min(bins, len(z))):
            binw = bins if b == 0 else 2 * (bins - b)
            denom += segw * binw * z[b] ** 2
    return 2 * (bins * nseg) ** 2 / denom


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("raw")
    ap.add_argument("cleaned")
    ap.add_argument("--nperseg", type=int, default=4096)
    ap.add_argument("--fmin", type=float, default=1e-3)
    a = ap.parse_args()
    fs, raw_start, raw = read(a.raw)
    fs_c, cl_start, cleaned = read(a.cleaned)
    assert fs == fs_c, "sample rates differ"
    first = 0
    if raw_start and cl_start:
        t = lambda s: datetime.fromisoformat(s.replace("Z", "+00:00")).timestamp()
        first = int(round((t(cl_start) - t(raw_start)) * fs))
    for name, c in cleaned.items():
        if name not in raw:
            continue
        r = raw[name][first:first + len(c)]
        f, pr = signal.welch(r, fs, nperseg=a.nperseg)
        _, pc = signal.welch(c, fs, nperseg=a.nperseg)
        nseg = (len(c) - a.nperseg) // (a.nperseg // 2) + 1
        edges = a.fmin * 10 ** (np.arange(0, 12, 1 / 3))
        edges = np.append(edges[edges < fs / 2], fs / 2 + 1e-12)
        rows = []
        for lo, hi in zip(edges[:-1], edges[1:]):
            sel = (f >= lo) & (f < hi)
            m = int(sel.sum())
            if m == 0:
                continue
            ratio = pc[sel].mean() / pr[sel].mean()
            rows.append((lo, hi, m, ratio, np.sqrt(2 / band_dof(a.nperseg, nseg, m))))
        z = stats.norm.ppf(1 - 0.00135 / len(rows))
        worst = max(rows, key=lambda x: (x[3] - 1) / x[4])
        print(f"{name}: variance cleaned/raw = {np.var(c) / np.var(r):.4g}; "
              f"{len(rows)} bands, limit 1 + {z:.2f} sigma")
        for lo, hi, m, ratio, sig in rows:
            flag = "  WORSE" if ratio > 1 + z * sig else ""
            print(f"  {lo:9.3e} .. {hi:9.3e} Hz  {m:5d} bins  cleaned/raw {ratio:10.4g}"
                  f"  (1 + {(ratio - 1) / sig:+8.2f} sigma){flag}")
        top = max(rows, key=lambda x: x[3])
        print(f"  worst band ratio {top[3]:.4g} at {top[0]:.3e} .. {top[1]:.3e} Hz "
              f"({(worst[3] - 1) / worst[4]:+.1f} sigma at worst)")


if __name__ == "__main__":
    main()
