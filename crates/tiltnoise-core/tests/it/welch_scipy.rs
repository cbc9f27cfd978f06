//! Welch PSD / CSD against scipy.signal fixtures, plus identities that need no reference:
//! Parseval, the white-noise level, Hermitian symmetry, and the error cases.
//!
//! The fixtures in `tests/fixtures/welch/` are written by `gen_welch_fixtures.py` (see the
//! README there); this test only reads them.

use std::f64::consts::PI;
use std::path::PathBuf;

use crate::tolerances::{WELCH_FLOOR_FRAC, WELCH_REL};
use num_complex::Complex64;
use serde_json::Value;
use tiltnoise_core::spectral::{
    csd, csd_matrix, hann_periodic, welch, Averaging, Detrend, SpectralError, WelchConfig,
};

fn fixture_dir() -> PathBuf {
    crate::common::repo("tests/fixtures/welch")
}

fn read_json(name: &str) -> Value {
    let path = fixture_dir().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read fixture {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("bad JSON in {}: {e}", path.display()))
}

fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn usize_of(v: &Value) -> usize {
    v.as_u64().expect("unsigned integer") as usize
}

/// Largest normalised error `|got - want| / max(|want|, WELCH_FLOOR_FRAC * max|want|)` of a
/// spectrum.
fn max_normalised_error(got: &[Complex64], want: &[Complex64]) -> f64 {
    assert_eq!(got.len(), want.len());
    let peak = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let floor = WELCH_FLOOR_FRAC * peak;
    got.iter()
        .zip(want)
        .map(|(g, w)| {
            let denom = w.norm().max(floor);
            if denom == 0.0 {
                (g - w).norm()
            } else {
                (g - w).norm() / denom
            }
        })
        .fold(0.0, f64::max)
}

fn real(v: &[f64]) -> Vec<Complex64> {
    v.iter().map(|&x| Complex64::new(x, 0.0)).collect()
}

#[test]
fn hann_window_matches_scipy_get_window() {
    let fx = read_json("window_hann.json");
    let windows = fx["hann"].as_object().expect("hann object");
    assert!(windows.len() >= 5);
    for (n, want) in windows {
        let n: usize = n.parse().expect("window length");
        let want = f64s(want);
        let got = hann_periodic(n);
        assert_eq!(got.len(), want.len());
        for (k, (g, w)) in got.iter().zip(&want).enumerate() {
            // Same formula as scipy; only libm's cos may differ by an ulp.
            assert!(
                (g - w).abs() <= 4.0 * f64::EPSILON,
                "n = {n}, k = {k}: {g} vs {w}"
            );
        }
    }
}

#[test]
fn scipy_fixtures_match() {
    let inputs = read_json("inputs.json");
    let series = &inputs["series"];
    let mut names: Vec<String> = std::fs::read_dir(fixture_dir())
        .expect("fixture dir")
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.starts_with("case_") && n.ends_with(".json"))
        .collect();
    names.sort();
    // Guard against silently testing nothing (13 cases at the time of writing).
    assert!(
        names.len() >= 13,
        "only {} fixture cases found",
        names.len()
    );

    let mut worst = (0.0f64, String::new());
    let (mut n_welch, mut n_csd, mut n_median, mut n_odd) = (0, 0, 0, 0);
    for name in &names {
        let case = read_json(name);
        let kind = case["kind"].as_str().expect("kind");
        let fs = case["fs_hz"].as_f64().expect("fs_hz");
        let nperseg = usize_of(&case["nperseg"]);
        let averaging = match case["average"].as_str().expect("average") {
            "mean" => Averaging::Mean,
            "median" => Averaging::Median,
            other => panic!("{name}: unknown average {other}"),
        };
        let detrend = match case["detrend"].as_str().expect("detrend") {
            "constant" => Detrend::Constant,
            "none" => Detrend::None,
            other => panic!("{name}: unknown detrend {other}"),
        };
        let cfg = WelchConfig::new(nperseg)
            .with_overlap(usize_of(&case["noverlap"]))
            .with_averaging(averaging)
            .with_detrend(detrend);
        n_median += usize::from(averaging == Averaging::Median);
        n_odd += nperseg % 2;
        let input = &series[case["input"].as_str().expect("input")];
        let channels: Vec<Vec<f64>> = case["channels"]
            .as_array()
            .expect("channels")
            .iter()
            .map(|c| f64s(&input[usize_of(c)]))
            .collect();
        let refs: Vec<&[f64]> = channels.iter().map(|c| c.as_slice()).collect();
        let want_f = f64s(&case["freqs_hz"]);
        let want_nseg = usize_of(&case["n_segments"]);

        let (got_f, err) = match kind {
            "welch" => {
                n_welch += 1;
                let p = welch(refs[0], fs, &cfg).expect("welch");
                assert_eq!(p.n_segments, want_nseg, "{name}");
                let e = max_normalised_error(&real(&p.psd), &real(&f64s(&case["psd"])));
                (p.freqs_hz, e)
            }
            "csd_matrix" => {
                n_csd += 1;
                let nc = refs.len();
                let m = csd_matrix(&refs, fs, &cfg).expect("csd_matrix");
                assert_eq!(m.n_segments, want_nseg, "{name}");
                let re = f64s(&case["csd_re"]);
                let im = f64s(&case["csd_im"]);
                let want: Vec<Complex64> = re
                    .iter()
                    .zip(&im)
                    .map(|(&r, &i)| Complex64::new(r, i))
                    .collect();
                assert_eq!(want.len(), m.data.len(), "{name}");
                // Compare each entry (i, j) as its own spectrum, so that the floor is relative
                // to that entry's peak.
                let mut e = 0.0f64;
                for i in 0..nc {
                    for j in 0..nc {
                        let w: Vec<Complex64> = (0..m.n_freqs())
                            .map(|k| want[(k * nc + i) * nc + j])
                            .collect();
                        e = e.max(max_normalised_error(&m.csd(i, j), &w));
                        if i != j {
                            // The pairwise function gives the same numbers.
                            let c = csd(refs[i], refs[j], fs, &cfg).expect("csd");
                            e = e.max(max_normalised_error(&c.csd, &w));
                        } else {
                            let p = welch(refs[i], fs, &cfg).expect("welch");
                            e = e.max(max_normalised_error(&real(&p.psd), &w));
                        }
                    }
                }
                (m.freqs_hz, e)
            }
            other => panic!("{name}: unknown kind {other}"),
        };
        assert_eq!(got_f.len(), want_f.len(), "{name}: number of bins");
        for (g, w) in got_f.iter().zip(&want_f) {
            // k*fs/n here vs k*(1/(n*(1/fs))) in numpy: a few ulps apart.
            assert!(
                (g - w).abs() <= 1e-14 * w.abs().max(1.0),
                "{name}: f {g} vs {w}"
            );
        }
        println!("{name}: max normalised error {err:.3e}");
        assert!(
            err <= WELCH_REL,
            "{name}: error {err:e} exceeds {WELCH_REL:e}"
        );
        if err > worst.0 {
            worst = (err, name.clone());
        }
    }
    println!(
        "max normalised error over all {} cases: {:.3e} ({})",
        names.len(),
        worst.0,
        worst.1
    );
    assert!(n_welch >= 4 && n_csd >= 3 && n_median >= 3 && n_odd >= 3);
}

/// Deterministic standard normal numbers: SplitMix64 + Box–Muller.
struct Gauss {
    state: u64,
    spare: Option<f64>,
}

impl Gauss {
    fn new(seed: u64) -> Self {
        Self {
            state: seed,
            spare: None,
        }
    }

    fn uniform(&mut self) -> f64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        // (0, 1]: never 0, so ln is finite.
        ((z >> 11) as f64 + 1.0) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let r = (-2.0 * self.uniform().ln()).sqrt();
        let t = 2.0 * PI * self.uniform();
        self.spare = Some(r * t.sin());
        r * t.cos()
    }

    fn vec(&mut self, n: usize, sigma: f64, offset: f64) -> Vec<f64> {
        (0..n).map(|_| offset + sigma * self.next()).collect()
    }
}

/// Three correlated channels with offsets and a delay (non-zero imaginary cross spectra).
fn correlated_channels(n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut g = Gauss::new(seed);
    let common = g.vec(n + 5, 1.0, 0.0);
    let a: Vec<f64> = (0..n).map(|t| common[t + 5] + 0.3 * g.next()).collect();
    let b: Vec<f64> = (0..n)
        .map(|t| 4.0 - 0.8 * common[t] + 0.5 * g.next())
        .collect();
    let c: Vec<f64> = (0..n)
        .map(|t| 2.0 * g.next() + 0.1 * common[t + 2] + (0.2 * t as f64).sin())
        .collect();
    vec![a, b, c]
}

/// Parseval for this estimator. For segment `s` of channel `i` let
/// `y_i[n] = w[n] (x_i[s*step + n] - mean_s)` and `Y_i = DFT_N(y_i)`. For real sequences
/// `sum_{k=0}^{N-1} conj(Y_i[k]) Y_j[k] = N sum_n y_i[n] y_j[n]`, and since
/// `Y[N-k] = conj(Y[k])` the real parts of bins `k` and `N-k` are equal, so the one-sided sum with
/// the doubling `c_k` covers the full sum exactly. With `scale = 1/(fs sum w²)` and
/// `df = fs/N`, for mean averaging:
///
/// `sum_k Re S_ij[k] * df = mean_s( sum_n y_i[n] y_j[n] ) / sum_n w[n]²`.
///
/// (The imaginary parts do not cancel in a one-sided sum, so only the real part is tested.)
/// Tolerance: the FFT's normwise relative error `~ eps log2 N`, the one-sided sum of `N/2+1`
/// terms and the segment mean each contribute at most `(N/2 + 1) eps` and `n_seg eps`
/// respectively (naive summation bounds); with a safety factor 10 on the sum of those. The error
/// of a cross term is measured relative to `sqrt(E_ii E_jj)` (Cauchy–Schwarz), since the cross
/// sum itself may be small by cancellation.
#[test]
fn parseval_identity() {
    let fs = 7.5;
    let chans = correlated_channels(3000, 11);
    let refs: Vec<&[f64]> = chans.iter().map(|c| c.as_slice()).collect();
    for (len, overlap, detrend) in [
        (256usize, 128usize, Detrend::Constant),
        (255, 191, Detrend::Constant),
        (100, 0, Detrend::None),
    ] {
        let cfg = WelchConfig::new(len)
            .with_overlap(overlap)
            .with_detrend(detrend);
        let m = csd_matrix(&refs, fs, &cfg).unwrap();
        let nseg = m.n_segments;
        let step = len - overlap;
        let df = fs / len as f64;
        // Independent window: the closed form, not the crate's function.
        let w: Vec<f64> = (0..len)
            .map(|n| 0.5 - 0.5 * (2.0 * PI * n as f64 / len as f64).cos())
            .collect();
        let sw2: f64 = w.iter().map(|v| v * v).sum();
        let nc = refs.len();
        let mut energy = vec![0.0; nc * nc];
        for s in 0..nseg {
            let y: Vec<Vec<f64>> = refs
                .iter()
                .map(|x| {
                    let seg = &x[s * step..s * step + len];
                    let mean = match detrend {
                        Detrend::Constant => seg.iter().sum::<f64>() / len as f64,
                        Detrend::None => 0.0,
                    };
                    seg.iter().zip(&w).map(|(v, wn)| (v - mean) * wn).collect()
                })
                .collect();
            for i in 0..nc {
                for j in 0..nc {
                    energy[i * nc + j] +=
                        y[i].iter().zip(&y[j]).map(|(a, b)| a * b).sum::<f64>() / sw2;
                }
            }
        }
        for e in &mut energy {
            *e /= nseg as f64;
        }
        let eps = f64::EPSILON;
        let tol = 10.0 * eps * ((len as f64).log2() + (len / 2 + 1) as f64 + nseg as f64);
        for i in 0..nc {
            for j in 0..nc {
                let total: f64 = (0..m.n_freqs()).map(|k| m.get(k, i, j).re).sum::<f64>() * df;
                let want = energy[i * nc + j];
                let norm = (energy[i * nc + i] * energy[j * nc + j]).sqrt();
                let err = (total - want).abs() / norm;
                assert!(
                    err <= tol,
                    "len {len}, ({i},{j}): {total} vs {want}, error {err:e} > {tol:e}"
                );
            }
        }
    }
}

/// Gaussian white noise of variance σ² at `fs` has one-sided PSD `2σ²/fs`.
///
/// Bins `2 ..= N/2 - 2` are averaged: there the constant detrend has no effect (the Hann
/// window's DFT vanishes beyond bin 1) and the pseudo-covariance `E[Y_a Y_b] ∝ G(a+b)` vanishes,
/// `G(m) = sum_n w[n]² e^{-2πimn/N}` being non-zero only for `m ≡ 0, ±1, ±2 (mod N)`. The
/// segments do not overlap, so they are independent. For Gaussian data
/// `Cov(|Y_a|², |Y_b|²) = σ⁴ |G(a-b)|²`, hence the relative variance of the average over `K`
/// bins and `S` segments is `sum_{a,b} |G(a-b)|² / (K² S G(0)²)` (≈ 1.94 / (K S) for Hann,
/// adjacent-bin power correlation 4/9). The test allows 6 standard deviations.
#[test]
fn white_noise_level() {
    let fs = 20.0;
    let sigma = 0.7;
    let len = 256usize;
    let nseg = 256usize;
    let mut g = Gauss::new(2024);
    let x = g.vec(len * nseg, sigma, 1.5);
    let cfg = WelchConfig::new(len).with_overlap(0);
    let p = welch(&x, fs, &cfg).unwrap();
    assert_eq!(p.n_segments, nseg);
    let bins = 2..=(len / 2 - 2);
    let k_count = bins.clone().count();
    let level = bins.clone().map(|k| p.psd[k]).sum::<f64>() / k_count as f64;
    let expected = 2.0 * sigma * sigma / fs;

    let w = hann_periodic(len);
    let big_g = |m: usize| -> f64 {
        (0..len)
            .map(|n| w[n] * w[n] * (2.0 * PI * (m * n) as f64 / len as f64).cos())
            .sum::<f64>()
    };
    let g_tab: Vec<f64> = (0..k_count).map(big_g).collect();
    let mut sum_cov = 0.0;
    for a in 0..k_count {
        for b in 0..k_count {
            sum_cov += g_tab[a.abs_diff(b)].powi(2);
        }
    }
    let rel_sd = (sum_cov / (g_tab[0].powi(2) * (k_count * k_count * nseg) as f64)).sqrt();
    let rel_err = (level - expected) / expected;
    println!(
        "white noise: level {level:.6e}, expected {expected:.6e}, rel. error {rel_err:+.4} \
         ({:.2} sigma, sigma = {rel_sd:.4})",
        rel_err / rel_sd
    );
    assert!(
        rel_err.abs() <= 6.0 * rel_sd,
        "white-noise PSD {level} vs 2σ²/fs = {expected}: {rel_err:+.4} > 6 × {rel_sd:.4}"
    );
    // ASD is the square root.
    assert!((p.asd()[10] - p.psd[10].sqrt()).abs() == 0.0);
}

#[test]
fn csd_matrix_is_hermitian_with_psd_diagonal() {
    let chans = correlated_channels(2000, 5);
    let refs: Vec<&[f64]> = chans.iter().map(|c| c.as_slice()).collect();
    for averaging in [Averaging::Mean, Averaging::Median] {
        for len in [128usize, 99] {
            let cfg = WelchConfig::new(len).with_averaging(averaging);
            let m = csd_matrix(&refs, 3.0, &cfg).unwrap();
            assert_eq!(m.n_channels, 3);
            assert_eq!(m.data.len(), m.n_freqs() * 9);
            assert_eq!(m.n_freqs(), len / 2 + 1);
            // k fs / len, rounded as scipy rounds it: three roundings of at most eps/2 each,
            // against a reference rounded twice, so within 5 eps/2 (bit for bit against scipy
            // in the Python tests).
            for (k, f) in m.freqs_hz.iter().enumerate() {
                let exact = k as f64 * 3.0 / len as f64;
                assert!(
                    (f - exact).abs() <= 2.5 * f64::EPSILON * exact,
                    "{f} vs {exact}"
                );
            }
            let psds: Vec<Vec<f64>> = refs
                .iter()
                .map(|x| welch(x, 3.0, &cfg).unwrap().psd)
                .collect();
            for (i, psd) in psds.iter().enumerate() {
                assert_eq!(&m.psd(i), psd, "diagonal = welch PSD");
            }
            let mut any_imag = false;
            for k in 0..m.n_freqs() {
                for i in 0..3 {
                    let d = m.get(k, i, i);
                    assert_eq!(d.im, 0.0);
                    assert!(d.re >= 0.0);
                    for j in 0..3 {
                        assert_eq!(m.get(k, i, j), m.get(k, j, i).conj());
                        any_imag |= i != j && m.get(k, i, j).im.abs() > 0.0;
                        if averaging == Averaging::Mean {
                            // A mean of outer products is positive semi-definite:
                            // |S_ij|² <= S_ii S_jj.
                            let lhs = m.get(k, i, j).norm_sqr();
                            let rhs = m.get(k, i, i).re * m.get(k, j, j).re;
                            assert!(lhs <= rhs * (1.0 + 1e-12), "k {k} ({i},{j})");
                        }
                    }
                }
                assert_eq!(m.matrix(k)[4], m.get(k, 1, 1));
            }
            assert!(
                any_imag,
                "the delayed channels must give imaginary cross spectra"
            );
        }
    }
}

#[test]
fn errors_name_the_lengths() {
    let cfg = WelchConfig::new(64);
    let e = welch(&[0.0; 10], 1.0, &cfg).unwrap_err();
    assert_eq!(
        e,
        SpectralError::SeriesTooShort {
            n_samples: 10,
            segment_len: 64
        }
    );
    let msg = e.to_string();
    assert!(msg.contains("10") && msg.contains("64"), "{msg}");

    for overlap in [64usize, 100] {
        let bad = WelchConfig::new(64).with_overlap(overlap);
        let e = welch(&[0.0; 1000], 1.0, &bad).unwrap_err();
        assert_eq!(
            e,
            SpectralError::OverlapTooLarge {
                overlap,
                segment_len: 64
            }
        );
        let msg = e.to_string();
        assert!(
            msg.contains(&overlap.to_string()) && msg.contains("64"),
            "{msg}"
        );
    }

    let e = welch(&[0.0; 1000], 1.0, &WelchConfig::new(1)).unwrap_err();
    assert_eq!(e, SpectralError::SegmentTooShort { segment_len: 1 });

    let a = vec![0.0; 300];
    let b = vec![0.0; 299];
    let e = csd_matrix(&[&a, &a, &b], 1.0, &cfg).unwrap_err();
    assert_eq!(
        e,
        SpectralError::ChannelLengthMismatch {
            channel: 2,
            len: 299,
            expected: 300
        }
    );
    let msg = e.to_string();
    assert!(msg.contains("299") && msg.contains("300"), "{msg}");
    assert!(matches!(
        csd(&a, &b, 1.0, &cfg).unwrap_err(),
        SpectralError::ChannelLengthMismatch { len: 299, .. }
    ));
    assert_eq!(
        csd_matrix(&[], 1.0, &cfg).unwrap_err(),
        SpectralError::NoChannels
    );
    assert!(matches!(
        welch(&a, -1.0, &cfg).unwrap_err(),
        SpectralError::InvalidSampleRate { .. }
    ));
    // Exactly one segment is enough.
    assert_eq!(welch(&a[..64], 1.0, &cfg).unwrap().n_segments, 1);
}
