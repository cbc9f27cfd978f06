#!/usr/bin/env python3
"""Generate the project's own tilt inputs in tilt_data/ from the Peterson (1993) noise models.

Run from anywhere:  python3 tilt_data/make_tilt_data.py

Reads only `peterson1993_coefficients.csv` (next to this script: the public-domain NLNM/NHNM
coefficients of USGS Open-File Report 93-322, re-encoded by hand) and writes, next to it:

  peterson_tilt_asd.csv        NHNM/g as tilt ASD (rad/sqrt(Hz)), 201-point log grid 1e-5..10 Hz
  peterson_nlnm_tilt_asd.csv   NLNM/g, same grid
  lab_tilt_target_asd.csv      the lab-floor spectrum that lab_tilt_24h.h5 is drawn from
  lab_tilt_24h.h5              24 h of synthetic two-axis tilt angle at 1 Hz (fixed seed)

Everything is deterministic (numpy.random.default_rng(SEED), floats written with repr, HDF5
without timestamps). After writing, the script checks the synthetic series against its target
with scipy.signal.welch / coherence and prints the numbers quoted in README.md.
"""

import csv
import os
import sys

import h5py
import numpy as np
import scipy
from scipy import signal

HERE = os.path.dirname(os.path.abspath(__file__))
G = 9.80665  # standard gravity (m/s^2), the same value as the crate's default parameter set
SEED = 19930322  # the report number, OFR 93-322
FS = 1.0  # Hz
N = 86400  # 24 h at 1 Hz
START_TIME = "2024-03-20T00:00:00+01:00"  # synthetic: local midnight, Central European Time
THETA_PSD_FACTOR = 0.5  # theta_t PSD = 0.5 x eta_t PSD (ASD ratio 1/sqrt(2))
COHERENCE = 0.3  # magnitude-squared coherence between the axes (frequency independent, phase 0)
MOD_DEPTH = 0.5  # day-night amplitude modulation depth
MOD_PEAK_H = 14.0  # local hour of the modulation maximum (the minimum is at 02:00)
# Hz, 1e-5..10 Hz, 201 log-spaced points (33.3 per decade) rounded to 6 significant digits so that
# the grid's decimal text is exact and the ends are exactly 1e-5 and 10
GRID = np.array([float(f"{10.0 ** (-5.0 + 6.0 * k / 200.0):.6g}") for k in range(201)])


def load_coefficients(path):
    """{model: list of (period_min_s, period_max_s, a_db, b_db)} from the coefficients CSV."""
    rows = {}
    with open(path, newline="") as fh:
        lines = [ln for ln in fh if not ln.startswith("#")]
    for r in csv.DictReader(lines):
        rows.setdefault(r["model"], []).append(
            (float(r["period_min_s"]), float(r["period_max_s"]), float(r["a_db"]), float(r["b_db"]))
        )
    return rows


def psd_db(bands, freq_hz):
    """Peterson acceleration PSD in dB rel. 1 (m/s^2)^2/Hz at the given frequencies."""
    period = 1.0 / np.asarray(freq_hz, dtype=float)
    # 1/1e-5 is 100000.00000000001 in floating point: snap the two grid ends onto the model range
    lo, hi = bands[0][0], bands[-1][1]
    period = np.where(abs(period / hi - 1.0) < 1e-12, hi, period)
    period = np.where(abs(period / lo - 1.0) < 1e-12, lo, period)
    out = np.empty_like(period)
    for i, p in enumerate(period):
        for k, (p_lo, p_hi, a, b) in enumerate(bands):
            last = k == len(bands) - 1
            if p_lo <= p < p_hi or (last and p == p_hi):
                out[i] = a + b * np.log10(p)
                break
        else:
            raise ValueError(f"period {p} s is outside the model's 0.1..1e5 s")
    return out


def tilt_asd(bands, freq_hz):
    """Tilt-equivalent ASD sqrt(S_a)/g (rad/sqrt(Hz)) of an acceleration noise model."""
    return np.sqrt(10.0 ** (psd_db(bands, freq_hz) / 10.0)) / G


def lab_psd(coef, freq_hz):
    """Lab-floor tilt PSD (rad^2/Hz) for (theta_t, eta_t): geometric mean of NLNM/g and NHNM/g."""
    eta = tilt_asd(coef["NLNM"], freq_hz) * tilt_asd(coef["NHNM"], freq_hz)
    return THETA_PSD_FACTOR * eta, eta


def write_asd_csv(name, freq_hz, theta, eta):
    with open(os.path.join(HERE, name), "w", newline="\n") as fh:
        fh.write("freq_hz,theta_t,eta_t\n")
        for f, a, b in zip(freq_hz, theta, eta):
            fh.write(f"{float(f)!r},{float(a)!r},{float(b)!r}\n")


def modulation(n, fs):
    """Day-night amplitude envelope m(t) with mean(m^2) = 1 over a whole day."""
    hours = np.arange(n) / fs / 3600.0  # local time, the record starts at local midnight
    m = 1.0 + MOD_DEPTH * np.cos(2.0 * np.pi * (hours - MOD_PEAK_H) / 24.0)
    return m / np.sqrt(1.0 + MOD_DEPTH**2 / 2.0)


def synthesize(coef):
    """Stationary two-axis tilt by frequency-domain filtering of white noise, then modulated."""
    rng = np.random.default_rng(SEED)
    white = rng.standard_normal((2, N))  # unit variance: one-sided PSD 2/fs
    w0, w1 = np.fft.rfft(white[0]), np.fft.rfft(white[1])
    rho = np.sqrt(COHERENCE)
    f = np.fft.rfftfreq(N, 1.0 / FS)
    s_theta, s_eta = np.zeros_like(f), np.zeros_like(f)
    s_theta[1:], s_eta[1:] = lab_psd(coef, f[1:])  # no DC: zero-mean series
    eta = np.fft.irfft(w0 * np.sqrt(s_eta * FS / 2.0), n=N)
    theta = np.fft.irfft((rho * w0 + np.sqrt(1.0 - rho**2) * w1) * np.sqrt(s_theta * FS / 2.0), n=N)
    m = modulation(N, FS)
    return theta * m, eta * m, theta, eta


def write_h5(theta, eta):
    path = os.path.join(HERE, "lab_tilt_24h.h5")
    desc = (
        "SYNTHETIC two-axis floor tilt angle, not a measurement. Gaussian noise filtered in the "
        "frequency domain to the one-sided PSD of lab_tilt_target_asd.csv (eta_t: geometric mean "
        "of the Peterson 1993 NLNM/g and NHNM/g tilt-equivalent; theta_t: 0.5 x that PSD), "
        f"magnitude-squared coherence {COHERENCE} between the axes (phase 0), multiplied by a "
        f"day-night envelope (1 + {MOD_DEPTH} cos(2 pi (local_hour - {MOD_PEAK_H:g}) / 24)) / "
        f"sqrt(1 + {MOD_DEPTH}^2/2). Tilt sign convention of tiltnoise (t takes the floor frame to "
        "the inertial frame). start_time is made up. Generated by tilt_data/make_tilt_data.py."
    )
    with h5py.File(path, "w", track_order=False) as h:
        for name, data in (("theta_t", theta), ("eta_t", eta)):
            ds = h.create_dataset(name, data=np.asarray(data, dtype="<f8"), track_times=False)
            ds.attrs["units"] = "rad"
        h.attrs["schema"] = "tiltnoise.tilt_series"
        h.attrs["schema_version"] = np.int64(1)
        h.attrs["sample_rate_hz"] = np.float64(FS)
        h.attrs["start_time"] = START_TIME
        h.attrs["description"] = desc
        h.attrs["seed"] = np.int64(SEED)
    return path


BANDS = ((3e-4, 1e-3), (1e-3, 2e-3), (2e-3, 5e-3), (5e-3, 1e-2), (1e-2, 1e-1), (1e-1, 0.5))


def band_ratios(f, psd, target):
    """'lo-hi: mean(psd/target) +- standard error of that mean' per band, as one line."""
    out = []
    for lo, hi in BANDS:
        sel = (f >= lo) & (f < hi)
        if sel.any():
            r = psd[sel] / target[sel]
            out.append(f"{lo * 1e3:g}-{hi * 1e3:g} mHz {r.mean():.2f}+-{r.std() / np.sqrt(sel.sum()):.2f}")
    return "; ".join(out)


def verify(coef, theta, eta, theta_stat, eta_stat):
    """Checks of the synthetic series against the target (the numbers quoted in README.md)."""
    f = np.fft.rfftfreq(N, 1.0 / FS)[1:]
    t_th, t_et = lab_psd(coef, f)
    print("Whole-record periodogram of the stationary series / target (no window; +- = std. error):")
    for axis, x, t in (("theta_t", theta_stat, t_th), ("eta_t", eta_stat, t_et)):
        pgram = 2.0 * np.abs(np.fft.rfft(x)[1:]) ** 2 / (N * FS)
        print(f"  {axis:7s} {band_ratios(f, pgram, t)}")
    nper = 3600
    print(f"scipy.signal.welch / target, nperseg={nper} (1 h), noverlap={nper // 2}, hann, detrend constant:")
    for label, (th, et) in (("stationary", (theta_stat, eta_stat)), ("file", (theta, eta))):
        for axis, x, i in (("theta_t", th, 0), ("eta_t", et, 1)):
            fw, p = signal.welch(x, FS, nperseg=nper, noverlap=nper // 2)
            print(f"  {label:10s} {axis:7s} {band_ratios(fw[1:], p[1:], lab_psd(coef, fw[1:])[i])}")
        fw, coh = signal.coherence(th, et, FS, nperseg=nper, noverlap=nper // 2)
        sel = (fw >= 1e-3) & (fw < 0.4)
        print(f"  {label:10s} coherence, mean over 1 mHz-0.4 Hz: {coh[sel].mean():.3f}")
    # The lowest Welch bins see Hann leakage from the steep (~f^-2.9 in PSD) spectrum below them.
    for nper in (3600, 21600):
        fw, p = signal.welch(eta_stat, FS, nperseg=nper, noverlap=nper // 2)
        r = p[1:4] / lab_psd(coef, fw[1:4])[1]
        print(f"  stationary eta_t, nperseg={nper}: bins k=1,2,3 at PSD/target " + ", ".join(f"{v:.2f}" for v in r))
    # hourly spread of the ASD (nperseg=1200 inside each hour)
    print("Hourly eta_t ASD (welch inside each hour, nperseg=1200, noverlap=600):")
    for fq in (5e-3, 1e-2):
        asd = []
        for hr in range(24):
            fw, p = signal.welch(eta[hr * 3600 : (hr + 1) * 3600], FS, nperseg=1200, noverlap=600)
            asd.append(np.sqrt(p[np.argmin(abs(fw - fq))]))
        asd = np.array(asd)
        print(
            f"  {fq * 1e3:g} mHz: min {asd.min():.3g} (hour {asd.argmin():02d}), "
            f"max {asd.max():.3g} (hour {asd.argmax():02d}), max/min {asd.max() / asd.min():.1f}, "
            f"target {np.sqrt(lab_psd(coef, np.array([fq]))[1][0]):.3g}"
        )
    for fq in (1e-3, 2e-3, 5e-3, 1e-2):
        t_th, t_et = lab_psd(coef, np.array([fq]))
        print(f"target ASD at {fq * 1e3:g} mHz: theta_t {np.sqrt(t_th[0]):.3g}, eta_t {np.sqrt(t_et[0]):.3g} rad/sqrt(Hz)")
    print(f"rms over the day: theta_t {theta.std():.3g} rad, eta_t {eta.std():.3g} rad")


def main():
    coef = load_coefficients(os.path.join(HERE, "peterson1993_coefficients.csv"))
    nhnm = tilt_asd(coef["NHNM"], GRID)
    nlnm = tilt_asd(coef["NLNM"], GRID)
    write_asd_csv("peterson_tilt_asd.csv", GRID, nhnm, nhnm)
    write_asd_csv("peterson_nlnm_tilt_asd.csv", GRID, nlnm, nlnm)
    s_th, s_et = lab_psd(coef, GRID)
    write_asd_csv("lab_tilt_target_asd.csv", GRID, np.sqrt(s_th), np.sqrt(s_et))
    theta, eta, theta_stat, eta_stat = synthesize(coef)
    path = write_h5(theta, eta)
    print(f"wrote {path} (numpy {np.__version__}, scipy {scipy.__version__}, h5py {h5py.__version__})")
    for fq in (1e-3, 5e-3, 1e-2):
        print(f"  tilt ASD at {fq * 1e3:g} mHz: NHNM/g {tilt_asd(coef['NHNM'], [fq])[0]:.3g}, "
              f"NLNM/g {tilt_asd(coef['NLNM'], [fq])[0]:.3g} rad/sqrt(Hz)")
    verify(coef, theta, eta, theta_stat, eta_stat)
    return 0


if __name__ == "__main__":
    sys.exit(main())
