//! Round trip `tiltnoise simulate` -> sim.h5 -> `tiltnoise budget --measured sim.h5`: the
//! budget's `measured` term of X is the Welch PSD of the simulated X (checked against an
//! independent Welch written here with realfft), at the readout level 9e-9 m/sqrt(Hz) in a band
//! free of resonances, within the statistical error of a K-segment Welch average; the simulated
//! record is refused as floor tilt.

use crate::common;
use crate::tolerances::EPS;

use common::{assert_fails_without_output, tiltnoise};
use realfft::RealFftPlanner;
use std::f64::consts::PI;
use std::path::Path;

/// The paper's X readout, the simulate default (m/sqrt(Hz)).
const READOUT_X: f64 = 9e-9;

fn read(path: &Path, name: &str) -> Vec<f64> {
    let f = hdf5::File::open(path).unwrap();
    f.dataset(name).unwrap().read_raw::<f64>().unwrap()
}

fn hann(n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| 0.5 - 0.5 * (2.0 * PI * i as f64 / n as f64).cos())
        .collect()
}

/// Independent Welch: periodic Hann, constant detrend, one-sided density, mean of the
/// segments. Returns `(psd, per-bin rounding bound)`: the FFT's error is at most
/// `c eps log2(N) ||X||_2` in 2-norm (Higham, Accuracy and Stability, sec. 24.1; c = 5 covers
/// the twiddle factors and the detrend), so a bin's `|X_k|^2` is off by at most
/// `2 |X_k| d + d^2` with `d` that bound; scaled like the PSD and averaged.
fn welch_independent(x: &[f64], fs: f64, n: usize, step: usize) -> (Vec<f64>, Vec<f64>) {
    let w = hann(n);
    let s2: f64 = w.iter().map(|v| v * v).sum();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut psd = vec![0.0; n / 2 + 1];
    let mut bound = vec![0.0; n / 2 + 1];
    let mut k = 0;
    let mut start = 0;
    while start + n <= x.len() {
        let seg = &x[start..start + n];
        let mean = seg.iter().sum::<f64>() / n as f64;
        let mut buf: Vec<f64> = seg.iter().zip(&w).map(|(v, w)| (v - mean) * w).collect();
        let norm_x = buf.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut spec = fft.make_output_vec();
        fft.process(&mut buf, &mut spec).unwrap();
        let d = 5.0 * EPS * (n as f64).log2() * (n as f64).sqrt() * norm_x;
        for (j, c) in spec.iter().enumerate() {
            let scale = if j == 0 || j == n / 2 { 1.0 } else { 2.0 } / (fs * s2);
            psd[j] += c.norm_sqr() * scale;
            bound[j] += (2.0 * c.norm() * d + d * d) * scale;
        }
        k += 1;
        start += step;
    }
    for (p, b) in psd.iter_mut().zip(bound.iter_mut()) {
        *p /= k as f64;
        *b /= k as f64;
    }
    (psd, bound)
}

#[test]
fn simulate_budget_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let sim = dir.path().join("sim.h5");
    let b = dir.path().join("b.h5");
    let tilt = common::repo("tilt_data/lab_tilt_24h.h5");
    let out = tiltnoise(&["simulate", "--save", sim.to_str().unwrap()]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        tilt.to_str().unwrap(),
        "--measured",
        sim.to_str().unwrap(),
        "--save",
        b.to_str().unwrap(),
    ]);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{text}{}", common::stderr(&out));
    println!("{text}");
    assert!(text.contains("on the budget's own grid"), "{text}");

    // The budget: 1 Hz tilt, default segment 2^14 samples = 16384 s; the measured series at
    // 10 Hz gets the same segment duration, 163840 samples, overlap 81920.
    let freqs = read(&b, "frequency_hz");
    let measured = read(&b, "X/measured/psd");
    assert_eq!(measured.len(), freqs.len());
    let x = read(&sim, "X");
    let fs = 10.0;
    let (n, step) = (163_840, 81_920);
    let (psd, bound) = welch_independent(&x, fs, n, step);
    let df = fs / n as f64;
    let mut worst: f64 = 0.0;
    for (i, (&f, &m)) in freqs.iter().zip(&measured).enumerate() {
        // The budget drops DC: its bin i is Welch bin i + 1.
        assert!((f - (i + 1) as f64 * df).abs() <= 4.0 * EPS * f);
        let (want, tol) = (psd[i + 1], 2.0 * bound[i + 1]);
        assert!(
            (m - want).abs() <= tol,
            "f = {f} Hz: {m:e} vs {want:e} (tol {tol:e})"
        );
        worst = worst.max((m - want).abs() / want);
    }
    println!(
        "measured X vs independent Welch: worst relative difference {worst:.2e} over {} bins",
        freqs.len()
    );

    // Resonance-free band of X on the budget grid (0 .. 0.5 Hz): above the nu_1, nu_2 tails and
    // below nu_4 = 0.416 Hz (nu_6 = 0.622 Hz is beyond; X does not see nu_3, nu_5, nu_7, nu_8).
    let (f_lo, f_hi) = (0.05, 0.3);
    let band: Vec<f64> = freqs
        .iter()
        .zip(&measured)
        .filter(|(f, _)| **f >= f_lo && **f <= f_hi)
        .map(|(_, m)| *m)
        .collect();
    let nb = band.len() as f64;
    let mean = band.iter().sum::<f64>() / nb;
    // Statistical error of the band mean for white Gaussian noise: per bin, the Welch mean of K
    // segments has Var/P^2 = (1/K) (1 + 2 sum_j (1 - j/K) rho_j), rho_j = (sum w[i] w[i + jS])^2
    // / (sum w^2)^2 (Welch 1967); neighbouring bins of a Hann periodogram are correlated,
    // r_m = |sum w^2 e^{-2 pi i m t / N}|^2 / (sum w^2)^2 (4/9 and 1/36 for m = 1, 2), so the
    // mean over B bins has Var = Var_bin / B * (1 + 2 sum_m r_m).
    let k = (x.len() - (n - step)) / step;
    let w = hann(n);
    let s2: f64 = w.iter().map(|v| v * v).sum();
    let mut seg_factor = 1.0;
    for j in 1..k {
        let shift = j * step;
        if shift >= n {
            break;
        }
        let c: f64 = (0..n - shift).map(|i| w[i] * w[i + shift]).sum();
        seg_factor += 2.0 * (1.0 - j as f64 / k as f64) * (c / s2).powi(2);
    }
    let mut bin_factor = 1.0;
    for m in 1..=3 {
        let (re, im) = w.iter().enumerate().fold((0.0, 0.0), |(re, im), (i, wi)| {
            let a = 2.0 * PI * (m * i) as f64 / n as f64;
            (re + wi * wi * a.cos(), im - wi * wi * a.sin())
        });
        bin_factor += 2.0 * (re * re + im * im) / (s2 * s2);
    }
    let sigma = (seg_factor / k as f64 * bin_factor / nb).sqrt();
    let expected = READOUT_X * READOUT_X;
    let rel = mean / expected - 1.0;
    println!(
        "band {f_lo}..{f_hi} Hz: {} bins, K = {k} segments: mean ASD {:.4e} m/sqrt(Hz) vs \
         {READOUT_X:e}; PSD off by {rel:+.2e}, sigma {sigma:.2e} (bin factor {bin_factor:.3}, \
         segment factor {seg_factor:.3})",
        band.len(),
        mean.sqrt()
    );
    // 5 sigma: a Gaussian deviation this large has probability 6e-7.
    assert!(rel.abs() <= 5.0 * sigma);

    // The simulated record is not floor tilt: refused by its schema, nothing written.
    let b2 = dir.path().join("b2.h5");
    assert_fails_without_output(
        &[
            "budget",
            "--tilt",
            sim.to_str().unwrap(),
            "--save",
            b2.to_str().unwrap(),
        ],
        dir.path(),
        &[
            "schema",
            "tiltnoise.observable_series",
            "tiltnoise.tilt_series",
        ],
    );
}

#[test]
fn measured_csv_series_and_too_short_records() {
    let dir = tempfile::tempdir().unwrap();
    let tilt = common::repo("tilt_data/lab_tilt_24h.h5");
    // 2048 s of X at 1 Hz as CSV (a made-up sinusoid plus offset): the budget with 1024-sample
    // segments at 1 Hz takes it on its own grid.
    let csv = dir.path().join("x.csv");
    let mut text = String::from("time_s,X\n");
    let xs: Vec<f64> = (0..2048)
        .map(|i| 1e-6 * (2.0 * PI * 0.1 * i as f64).sin() + 3e-7)
        .collect();
    for (i, v) in xs.iter().enumerate() {
        text.push_str(&format!("{i},{v:e}\n"));
    }
    std::fs::write(&csv, text).unwrap();
    let b = dir.path().join("b.h5");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        tilt.to_str().unwrap(),
        "--nperseg",
        "1024",
        "--measured",
        csv.to_str().unwrap(),
        "--save",
        b.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let measured = read(&b, "X/measured/psd");
    // Printed with {:e}: the shortest representation that round-trips, so the CSV values are
    // the f64 values used here.
    let (psd, bound) = welch_independent(&xs, 1.0, 1024, 512);
    assert_eq!(measured.len(), 512);
    for i in 0..measured.len() {
        assert!((measured[i] - psd[i + 1]).abs() <= 2.0 * bound[i + 1]);
    }

    // A record shorter than one of the budget's segments (16384 s by default).
    let b2 = dir.path().join("b2.h5");
    assert_fails_without_output(
        &[
            "budget",
            "--tilt",
            tilt.to_str().unwrap(),
            "--measured",
            csv.to_str().unwrap(),
            "--save",
            b2.to_str().unwrap(),
        ],
        dir.path(),
        &["--measured", "x.csv", "2048 samples", "16384"],
    );
}

#[test]
fn measured_csv_series_needs_finite_times() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("t.csv");
    for first in ["nan", "-inf"] {
        std::fs::write(&csv, format!("time_s,X\n{first},1e-9\n1,2e-9\n2,3e-9\n")).unwrap();
        let e = tiltnoise_io::input::read_measured_input(&csv)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("time_s = `{first}`")) && e.contains("must be finite"),
            "{e}"
        );
    }
}
