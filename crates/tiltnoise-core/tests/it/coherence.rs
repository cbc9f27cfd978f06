//! Coherence, multiple-input transfer functions and their confidence intervals:
//!
//! * against `scipy.signal.coherence`, and against `numpy.linalg.solve` on scipy's CSD matrix
//!   (committed fixtures in `tests/fixtures/coherence/`, written by
//!   `gen_coherence_fixtures.py`; this test only reads them), and the statistics against
//!   `scipy.stats`;
//! * by recovering known transfer functions (a delay, a first-order lag) from records filtered
//!   through them, within the stated confidence circles, with the sign and phase of the
//!   `exp(+i w t)` convention;
//! * by Monte Carlo coverage of the coherence intervals and thresholds;
//! * through the whole job: a record made from tilt through the model's own transfer functions
//!   gives back the model (factor 1), a gain error, and a sub-sample offset of the grids.

use crate::common::{coloured, json, repo, through_model};
use crate::tolerances::{
    BIN_FREQ_REL, COHERENCE_ABS, MIMO_REL_PER_COND, NORMAL_QUANTILE_REL, QUANTILE_REL,
    WINDOW_SUM_REL,
};
use num_complex::Complex64;
use serde_json::Value;
use std::f64::consts::PI;
use tiltnoise_core::coherence::{coherence_from_series, CoherenceOptions, Record};
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::rng::Rng;
use tiltnoise_core::spectral::confidence::{
    beta_upper_quantile, coherence_interval, coherence_threshold, equivalent_averages,
    f2_upper_quantile, normal_quantile, tf_radius,
};
use tiltnoise_core::spectral::{coherence, csd_matrix, multiple_input, WelchConfig};

const FIXTURES: &str = "tests/fixtures/coherence";

fn floats(v: &Value) -> Vec<f64> {
    crate::common::floats(v)
}

fn fixture_inputs() -> (f64, Vec<Vec<f64>>) {
    let inputs = json(&format!("{FIXTURES}/inputs.json"));
    let mut channels: Vec<Vec<f64>> = inputs["tilt"]
        .as_array()
        .unwrap()
        .iter()
        .map(floats)
        .collect();
    channels.extend(inputs["observables"].as_array().unwrap().iter().map(floats));
    (inputs["fs_hz"].as_f64().unwrap(), channels)
}

fn cases() -> Vec<Value> {
    let mut names: Vec<_> = std::fs::read_dir(repo(FIXTURES))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.starts_with("case_") && n.ends_with(".json"))
        .collect();
    names.sort();
    assert_eq!(names.len(), 3, "{names:?}");
    names
        .iter()
        .map(|n| json(&format!("{FIXTURES}/{n}")))
        .collect()
}

fn config(case: &Value) -> WelchConfig {
    let len = case["nperseg"].as_u64().unwrap() as usize;
    WelchConfig::new(len).with_overlap(case["noverlap"].as_u64().unwrap() as usize)
}

#[test]
fn coherence_equals_scipy_signal_coherence() {
    let (fs, channels) = fixture_inputs();
    let views: Vec<&[f64]> = channels.iter().map(Vec::as_slice).collect();
    let mut worst: f64 = 0.0;
    for case in cases() {
        let name = case["name"].as_str().unwrap();
        let m = csd_matrix(&views, fs, &config(&case)).unwrap();
        for (got, want) in m.freqs_hz.iter().zip(floats(&case["freqs_hz"])) {
            assert!(
                (got - want).abs() <= BIN_FREQ_REL * want,
                "{name}: {got} vs {want}"
            );
        }
        assert_eq!(m.n_segments as u64, case["n_segments"].as_u64().unwrap());
        for o in 0..2 {
            for i in 0..3 {
                let want = floats(&case["coherence"][format!("{o},{i}")]);
                let got = coherence(&m, i, 3 + o);
                // DC: both compute 0/0-like rounding residues of the detrended mean.
                for k in 1..want.len() {
                    let err = (got[k] - want[k]).abs();
                    worst = worst.max(err);
                    assert!(
                        err <= COHERENCE_ABS,
                        "{name}: coherence of observable {o} with tilt {i} at {} Hz: {} vs \
                         scipy {}",
                        m.freqs_hz[k],
                        got[k],
                        want[k]
                    );
                }
            }
        }
    }
    println!("coherence vs scipy: largest absolute difference {worst:.1e}");
}

#[test]
fn multiple_input_estimate_equals_numpy_solve_on_scipy_csd() {
    let (fs, channels) = fixture_inputs();
    let views: Vec<&[f64]> = channels.iter().map(Vec::as_slice).collect();
    let mut worst: f64 = 0.0;
    for case in cases() {
        let name = case["name"].as_str().unwrap();
        let m = csd_matrix(&views, fs, &config(&case)).unwrap();
        for label in ["q3", "q2"] {
            let fx = &case[label];
            let inputs: Vec<usize> = fx["inputs"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_u64().unwrap() as usize)
                .collect();
            let q = inputs.len();
            let est = multiple_input(&m, &inputs, &[3, 4]).unwrap();
            let (re, im) = (floats(&fx["tf_re"]), floats(&fx["tf_im"]));
            let (mc, nn) = (
                floats(&fx["multiple_coherence"]),
                floats(&fx["residual_psd"]),
            );
            let (inv, cond) = (floats(&fx["inverse_diagonal"]), floats(&fx["cond"]));
            for (b, &c) in cond.iter().enumerate() {
                let k = b + 1; // the fixture leaves DC out
                assert!(est.estimable[k], "{name} {label} bin {k}");
                let tol = MIMO_REL_PER_COND * c;
                for o in 0..2 {
                    let want: Vec<Complex64> = (0..q)
                        .map(|i| Complex64::new(re[(b * 2 + o) * q + i], im[(b * 2 + o) * q + i]))
                        .collect();
                    let diff: f64 = (0..q)
                        .map(|i| (est.tf_at(k, o, i) - want[i]).norm_sqr())
                        .sum::<f64>()
                        .sqrt();
                    let norm: f64 = want.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
                    worst = worst.max(diff / norm / c);
                    assert!(
                        diff <= tol * norm,
                        "{name} {label}: H of output {o} at {} Hz off by {:e} relative (tol {tol:e})",
                        m.freqs_hz[k],
                        diff / norm
                    );
                    let syy = m.get(k, 3 + o, 3 + o).re;
                    let got_mc = est.multiple_coherence_at(k, o);
                    assert!(
                        (got_mc - mc[b * 2 + o]).abs() <= tol,
                        "{name} {label} mc {k} {o}"
                    );
                    let got_nn = est.residual_psd_at(k, o);
                    assert!(
                        (got_nn - nn[b * 2 + o]).abs() <= tol * syy,
                        "{name} {label} S_nn {k} {o}"
                    );
                }
                for i in 0..q {
                    let want = inv[b * q + i];
                    assert!(
                        (est.inverse_diagonal_at(k, i) - want).abs() <= tol * want,
                        "{name} {label}: inverse diagonal {i} at bin {k}"
                    );
                }
            }
        }
    }
    println!("multiple-input estimate vs numpy: largest relative difference per unit condition {worst:.1e}");
}

#[test]
fn equivalent_averages_and_quantiles_equal_the_independent_computation() {
    for case in cases() {
        let want = case["n_equivalent"].as_f64().unwrap();
        let k = case["n_segments"].as_u64().unwrap() as usize;
        let got = equivalent_averages(&config(&case), k);
        assert!(
            (got - want).abs() <= WINDOW_SUM_REL * want,
            "{}: {got} vs {want}",
            case["name"]
        );
    }
    let stats = json(&format!("{FIXTURES}/stats.json"));
    for row in stats["norm_ppf"].as_array().unwrap() {
        let (p, want) = (row[0].as_f64().unwrap(), row[1].as_f64().unwrap());
        let got = normal_quantile(p);
        assert!(
            (got - want).abs() <= NORMAL_QUANTILE_REL * want.abs(),
            "ppf({p}): {got} vs {want}"
        );
    }
    for row in stats["beta_isf"].as_array().unwrap() {
        let r = floats(row);
        let (q, n, alpha, want) = (r[0] as usize, r[1], r[2], r[3]);
        let got = beta_upper_quantile(q, n, alpha);
        assert!(
            (got - want).abs() <= QUANTILE_REL * want,
            "Beta({q}, {n} - {q}) upper {alpha}: {got} vs {want}"
        );
        assert_eq!(coherence_threshold(n, q, alpha), got);
    }
    for row in stats["f2_isf"].as_array().unwrap() {
        let r = floats(row);
        let got = f2_upper_quantile(r[0], r[1]);
        assert!(
            (got - r[2]).abs() <= QUANTILE_REL * r[2],
            "F(2, {}) upper {}: {got}",
            r[0],
            r[1]
        );
    }
}

/// Share of `hits` out of `n` checks of `level`-confidence statements, asserted to lie within
/// 5 standard deviations of `level` for `n / inflation` independent checks (neighbouring Welch
/// bins are correlated; `inflation` counts that). A fixed seed makes the outcome deterministic;
/// the bound is what a correct interval passes but for a 1-in-a-million draw.
fn assert_coverage(what: &str, hits: usize, n: usize, level: f64, inflation: f64) {
    let share = hits as f64 / n as f64;
    let sd = (level * (1.0 - level) * inflation / n as f64).sqrt();
    assert!(
        (share - level).abs() <= 5.0 * sd,
        "{what}: {hits} of {n} ({share:.4}) within their {level} intervals; expected {level} \
         +/- {:.4} (5 sd)",
        5.0 * sd
    );
    println!("{what}: {hits} of {n} ({share:.4}) at level {level}");
}

/// Variance inflation of a count over all bins of a spectrum for the periodic Hann window:
/// `1 + 2 (4/9 + 1/36)` (adjacent-bin correlation of the estimates).
const HANN_BIN_INFLATION: f64 = 1.0 + 2.0 * (4.0 / 9.0 + 1.0 / 36.0);

#[test]
fn known_transfer_functions_are_recovered_with_their_sign_and_phase() {
    // Two correlated coloured inputs; the output is a lagged copy of the first (a delay of
    // three samples, gain -1.7) plus the second through a first-order lag, plus white noise.
    let n = 1 << 16;
    let fs = 4.0;
    let dt = 1.0 / fs;
    let mut rng = Rng::stream(7, 0);
    let w1 = coloured(&mut rng, n, 0.9);
    let w2 = coloured(&mut rng, n, 0.5);
    let x1 = w1.clone();
    let x2: Vec<f64> = w1.iter().zip(&w2).map(|(a, b)| 0.5 * a + b).collect();
    let (g, d) = (-1.7, 3usize);
    let (a, b) = (0.8, 0.6);
    let mut lag = 0.0;
    let y: Vec<f64> = (0..n)
        .map(|k| {
            lag = a * lag + b * x2[k];
            let delayed = if k >= d { x1[k - d] } else { 0.0 };
            g * delayed + lag + 0.7 * rng.gaussian()
        })
        .collect();
    // exp(+i w t): a delay tau is exp(-i w tau); y[n] = a y[n-1] + b x[n] is b / (1 - a z^-1)
    // with z^-1 = exp(-i w dt).
    let h1 = |f: f64| g * Complex64::from_polar(1.0, -2.0 * PI * f * d as f64 * dt);
    let h2 = |f: f64| b / (1.0 - a * Complex64::from_polar(1.0, -2.0 * PI * f * dt));
    let cfg = WelchConfig::new(512);
    let m = csd_matrix(&[&x1, &x2, &y], fs, &cfg).unwrap();
    let n_d = equivalent_averages(&cfg, m.n_segments);
    let est = multiple_input(&m, &[0, 1], &[2]).unwrap();
    let level = 0.95;
    let (mut hits, mut checks, mut conj_hits) = (0, 0, 0);
    for k in 1..m.n_freqs() {
        let f = m.freqs_hz[k];
        let nn = est.residual_psd_at(k, 0);
        for (i, h) in [h1(f), h2(f)].into_iter().enumerate() {
            let r = tf_radius(nn, est.inverse_diagonal_at(k, i), n_d, 2, level);
            let got = est.tf_at(k, 0, i);
            checks += 1;
            hits += usize::from((got - h).norm() <= r);
            conj_hits += usize::from((got - h.conj()).norm() <= r);
        }
    }
    assert_coverage(
        "recovered H within the 95 % circles",
        hits,
        checks,
        level,
        HANN_BIN_INFLATION,
    );
    // The opposite time convention (a lag as a positive phase) is far outside the circles.
    assert!(
        conj_hits < checks / 4,
        "the conjugate fits {conj_hits} of {checks}"
    );
    // The phase of the delay, read off directly at 0.5 Hz: -2 pi f tau + pi (the gain is
    // negative), i.e. the output lags.
    let k = m.freqs_hz.iter().position(|&f| f == 0.5).unwrap();
    let phase = est.tf_at(k, 0, 0).arg();
    let want = PI - 2.0 * PI * 0.5 * 3.0 * dt;
    assert!(
        (phase - want).abs() < 0.05,
        "phase {phase} rad, want {want} rad"
    );
}

#[test]
fn coherence_intervals_and_thresholds_have_their_coverage() {
    // y = h1 x1 + h2 x2 + n with white, independent x1, x2, n: every bin has the same true
    // ordinary coherence with x1 and multiple coherence with (x1, x2).
    let cfg = WelchConfig::new(64);
    let n = 64 * 12; // 23 half-overlapping segments
    let level = 0.95;
    let (h1, h2, sn) = (0.8, 0.6, 1.0);
    let true_ordinary = h1 * h1 / (h1 * h1 + h2 * h2 + sn * sn);
    let true_multiple = (h1 * h1 + h2 * h2) / (h1 * h1 + h2 * h2 + sn * sn);
    let mut counts = [0usize; 4]; // ordinary, multiple, null ordinary, null multiple exceed
    let mut checks = 0;
    let mut n_d = 0.0;
    for r in 0..150 {
        let mut rng = Rng::stream(11, r);
        let x1: Vec<f64> = (0..n).map(|_| rng.gaussian()).collect();
        let x2: Vec<f64> = (0..n).map(|_| rng.gaussian()).collect();
        let y: Vec<f64> = (0..n)
            .map(|k| h1 * x1[k] + h2 * x2[k] + sn * rng.gaussian())
            .collect();
        let z: Vec<f64> = (0..n).map(|_| rng.gaussian()).collect(); // unrelated to x
        let m = csd_matrix(&[&x1, &x2, &y, &z], 1.0, &cfg).unwrap();
        n_d = equivalent_averages(&cfg, m.n_segments);
        let est = multiple_input(&m, &[0, 1], &[2, 3]).unwrap();
        let ordinary = coherence(&m, 0, 2);
        let null = coherence(&m, 0, 3);
        // Bins 1 .. Nyquist - 1: DC is detrended away, Nyquist has half the degrees of freedom.
        for k in 1..m.n_freqs() - 1 {
            checks += 1;
            let (lo, hi) = coherence_interval(ordinary[k], n_d, 1, level);
            counts[0] += usize::from(lo <= true_ordinary && true_ordinary <= hi);
            let (lo, hi) = coherence_interval(est.multiple_coherence_at(k, 0), n_d, 2, level);
            counts[1] += usize::from(lo <= true_multiple && true_multiple <= hi);
            counts[2] += usize::from(null[k] > coherence_threshold(n_d, 1, 1.0 - level));
            counts[3] += usize::from(
                est.multiple_coherence_at(k, 1) > coherence_threshold(n_d, 2, 1.0 - level),
            );
        }
    }
    println!("n_d = {n_d:.2}");
    assert_coverage(
        "ordinary coherence interval",
        counts[0],
        checks,
        level,
        HANN_BIN_INFLATION,
    );
    assert_coverage(
        "multiple coherence interval",
        counts[1],
        checks,
        level,
        HANN_BIN_INFLATION,
    );
    assert_coverage(
        "ordinary null below threshold",
        checks - counts[2],
        checks,
        level,
        HANN_BIN_INFLATION,
    );
    assert_coverage(
        "multiple null below threshold",
        checks - counts[3],
        checks,
        level,
        HANN_BIN_INFLATION,
    );
}

/// Synthetic tilt and the model's X and phi from it: [`through_model`] with readouts 1e-9
/// m/sqrt(Hz) and 1e-13 rad/sqrt(Hz) (phi/eta_t is small: a quiet phi readout makes it
/// measurable).
struct Synthetic {
    tilt: Vec<Vec<f64>>,
    measured: Vec<Vec<f64>>,
}

fn synthetic(model: &Model, n: usize, gain: f64, advance_s: f64) -> Synthetic {
    let outputs = [Observable::X, Observable::Phi];
    let (tilt, measured) = through_model(model, n, &outputs, &[1e-9, 1e-13], gain, advance_s, 3);
    Synthetic { tilt, measured }
}

fn records<'a>(
    s: &'a Synthetic,
    skip: usize,
    starts: (Option<&'a str>, Option<&'a str>),
) -> (Record<'a, TiltAxis>, Record<'a, Observable>) {
    (
        Record {
            name: "--tilt synthetic",
            sample_rate_hz: 1.0,
            start_time: starts.0.map(|t| t.parse().unwrap()),
            channels: vec![
                (TiltAxis::ThetaT, &s.tilt[0][..]),
                (TiltAxis::EtaT, &s.tilt[1][..]),
            ],
        },
        Record {
            name: "--measured synthetic",
            sample_rate_hz: 1.0,
            start_time: starts.1.map(|t| t.parse().unwrap()),
            channels: vec![
                (Observable::X, &s.measured[0][skip..]),
                (Observable::Phi, &s.measured[1][skip..]),
            ],
        },
    )
}

#[test]
fn a_record_made_through_the_model_gives_back_the_model() {
    let model = Model::new(&Params::table_i()).unwrap();
    let n = 1 << 15;
    // Every bin, the undamped resonances at 1.3 mHz, 2.2 mHz and 0.41 Hz included: the bins
    // where the Welch resolution does not resolve the model are left out of the fit.
    let opts = CoherenceOptions {
        welch_segment_len: Some(1024),
        ..CoherenceOptions::default()
    };
    for gain in [1.0, 1.1] {
        let s = synthetic(&model, n, gain, 0.0);
        let (tilt, measured) = records(&s, 0, (None, None));
        let report = coherence_from_series(&model, &tilt, &measured, &opts).unwrap();
        assert_eq!(report.welch.n_samples, n);
        // X and phi respond to eta_t; X does not respond to theta_t in the model (the blocks
        // decouple), so that entry has no agreement to report.
        for (o, name) in [(0, "X"), (1, "phi")] {
            let eta = &report.observables[o].axes[1];
            let a = eta
                .agreement
                .as_ref()
                .unwrap_or_else(|| panic!("{name}/eta_t"));
            println!(
                "{name}/eta_t, true gain {gain}: measured/model = {:.4} +/- {:.4} at {:.2} +/- {:.2} \
                 deg over {} bins, chi2/nu {:.2}",
                a.gain(),
                a.sigma,
                a.phase_deg(),
                a.phase_sigma_deg(),
                a.n_bins,
                a.chi2_per_dof
            );
            assert!(
                (a.factor - Complex64::new(gain, 0.0)).norm() < 5.0 * a.sigma,
                "{name}/eta_t: factor {} for true gain {gain}",
                a.factor
            );
            assert!(a.sigma < 0.02 * gain, "{name}/eta_t: sigma {}", a.sigma);
            assert!(
                (0.7..1.4).contains(&a.chi2_per_dof),
                "{name}: chi2/nu {}",
                a.chi2_per_dof
            );
        }
        assert!(
            report.observables[0].axes[0].agreement.is_none(),
            "X/theta_t is 0 in the model"
        );
    }
}

#[test]
fn a_sub_sample_offset_of_the_grids_is_taken_out_of_the_phase() {
    let model = Model::new(&Params::table_i()).unwrap();
    let n = 1 << 15;
    // The measured record starts 5.3 s after the tilt: skip 5 samples of a record whose
    // samples are taken 0.3 s late.
    let s = synthetic(&model, n, 1.0, 0.3);
    let starts = (Some("2024-01-01T00:00:00Z"), Some("2024-01-01T00:00:05.3Z"));
    let (tilt, measured) = records(&s, 5, starts);
    let opts = CoherenceOptions {
        welch_segment_len: Some(1024),
        fit_band_hz: Some((5e-3, 0.2)),
        ..CoherenceOptions::default()
    };
    let report = coherence_from_series(&model, &tilt, &measured, &opts).unwrap();
    let al = &report.alignment;
    assert_eq!((al.start_a, al.start_b, al.len), (5, 0, n - 5));
    assert!(
        (al.residual_offset_s - 0.3).abs() < 1e-9,
        "{}",
        al.residual_offset_s
    );
    let a = report.observables[0].axes[1].agreement.clone().unwrap();
    assert!(
        (a.factor - Complex64::new(1.0, 0.0)).norm() < 5.0 * a.sigma,
        "X/eta_t: factor {} (uncorrected, 0.3 s would be 10.8 deg at 0.1 Hz)",
        a.factor
    );
    assert!(
        (0.7..1.4).contains(&a.chi2_per_dof),
        "chi2/nu {}",
        a.chi2_per_dof
    );
}

#[test]
fn records_that_cannot_be_analysed_are_refused_with_their_names() {
    let model = Model::new(&Params::table_i()).unwrap();
    let s = synthetic(&model, 4096, 1.0, 0.0);
    let opts = CoherenceOptions::default();
    let run = |tilt: &Record<'_, TiltAxis>, measured: &Record<'_, Observable>| {
        coherence_from_series(&model, tilt, measured, &opts)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    let (tilt, mut measured) = records(
        &s,
        0,
        (Some("2024-01-01T00:00:00Z"), Some("2024-01-02T00:00:00Z")),
    );
    let e = run(&tilt, &measured);
    assert!(
        e.contains("do not overlap") && e.contains("--measured synthetic"),
        "{e}"
    );
    measured.start_time = None;
    measured.sample_rate_hz = 2.0;
    let e = run(&tilt, &measured);
    assert!(e.contains("2 Hz") && e.contains("same sample rate"), "{e}");
    measured.sample_rate_hz = 1.0;
    let short = CoherenceOptions {
        welch_segment_len: Some(8192),
        ..CoherenceOptions::default()
    };
    let e = coherence_from_series(&model, &tilt, &measured, &short)
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("shorter than one Welch segment of 8192"), "{e}");
    let flat = vec![2.5; 4096];
    let mut dead = tilt.clone();
    dead.channels[1].1 = &flat;
    let e = run(&dead, &measured);
    assert!(
        e.contains("eta_t of --tilt synthetic is constant (2.5) over the common stretch")
            && e.contains("no power above DC"),
        "{e}"
    );
    let mut nan = s.measured[0].clone();
    nan[99] = f64::NAN;
    let mut bad = measured.clone();
    bad.channels[0].1 = &nan;
    let e = run(&tilt, &bad);
    assert!(
        e.contains("--measured synthetic: channel X has the non-finite sample NaN at index 99"),
        "{e}"
    );
    let mut ragged = measured.clone();
    ragged.channels[1].1 = &s.measured[1][..100];
    let e = run(&tilt, &ragged);
    assert!(
        e.contains("channel phi has 100 samples but channel X has 4096"),
        "{e}"
    );
    let doubled: Vec<f64> = s.tilt[0].iter().map(|v| 2.0 * v).collect();
    let mut dependent = tilt.clone();
    dependent.channels[1].1 = &doubled;
    let e = run(&dependent, &measured);
    assert!(e.contains("linearly dependent at every frequency"), "{e}");
}
