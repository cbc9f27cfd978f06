//! A tilt-rate series gives the angle spectrum of the angle series it came from, up to Nyquist.
//!
//! The angle is a sum of sinusoids on exact Welch bins, from the lowest bin to two bins below
//! Nyquist, on two axes with different phases (so that the cross-spectra are complex); its rate
//! is the analytic derivative. At a line the Hann window's main lobe sees only that line, so the
//! Welch estimate of the rate divided by `(2 pi f)^2` must equal the angle's estimate to
//! rounding, diagonal and cross-spectra alike; next to a line, the window's leakage is in the
//! rate's units and arrives scaled by `(f_line / f)^2` (`tiltnoise_core::input::rate`). The
//! trapezoid rule the readers used to apply is `x cot x` = 0.5 % of the truth at the top line
//! (4.99 Hz at 10 Hz): any time-domain integration fails this test by orders of magnitude.

use crate::tolerances::{FFT_STAGE_REL, OMEGA_SQ_REL, TONE_SAMPLE_ABS, U};
use num_complex::Complex64;
use std::f64::consts::TAU;
use std::path::PathBuf;
use tiltnoise_core::budget::{budget_from_series, BudgetOptions, RATE_BUDGET_NOTE};
use tiltnoise_core::input::{InputFormat, InputKind, Provenance, Quantity, TiltSeries};
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::noise::TermKind;
use tiltnoise_core::params::Params;
use tiltnoise_core::spectral::{csd_matrix, WelchConfig};

/// Samples per Welch segment, sample rate (Hz) and segments in the record (50 % overlap).
const SEG: usize = 2048;
const FS_HZ: f64 = 10.0;
const RECORD_SEGMENTS: usize = 8;
/// The lines: Welch bins at least 3 apart (no line's leakage reaches another line or its
/// neighbours), from bin 1 to bin SEG/2 - 2 (4.990 Hz).
const LINES: [usize; 9] = [1, 4, 9, 30, 101, 333, 700, 1003, 1022];

/// Angle amplitude (rad) of line `m` on axis `axis`: falling as `1/sqrt(m)`, so that the
/// angle and the rate carry comparable energy at both ends.
fn amplitude(axis: usize, m: usize) -> f64 {
    [1e-8, 0.7e-8][axis] / (m as f64).sqrt()
}

fn phase(axis: usize, m: usize) -> f64 {
    0.37 * m as f64 + 1.9 * axis as f64
}

fn omega(m: usize) -> f64 {
    TAU * m as f64 * FS_HZ / SEG as f64
}

/// `(angle, rate)` of one axis: `sum A cos(w t + p)` and its exact derivative, phases from the
/// exact integer `m n mod SEG`.
fn axis_series(axis: usize) -> (Vec<f64>, Vec<f64>) {
    let n = SEG * RECORD_SEGMENTS;
    let mut angle = vec![0.0; n];
    let mut rate = vec![0.0; n];
    for (i, (a, r)) in angle.iter_mut().zip(rate.iter_mut()).enumerate() {
        for m in LINES {
            let arg = TAU * ((m * i) % SEG) as f64 / SEG as f64 + phase(axis, m);
            *a += amplitude(axis, m) * arg.cos();
            *r -= amplitude(axis, m) * omega(m) * arg.sin();
        }
    }
    (angle, rate)
}

/// Bound on the relative error of the Welch periodogram value of a channel at bin `k` of a line
/// `m` (`k = m` or a neighbour), relative to that value's magnitude: the sampling error
/// ([`TONE_SAMPLE_ABS`] per line and the sum over the lines), the window's rounding and the
/// FFT's normwise error ([`FFT_STAGE_REL`] per stage), scaled by `||X|| / |X_k|`, where
/// `||X|| <= SEG rms` (Parseval, `|w| <= 1`) and `|X_k| = a_m SEG / 4` on the line, half of
/// that next to it (periodic Hann).
fn bin_rel(amps: &[f64], m_index: usize, on_line: bool) -> f64 {
    let sum_abs: f64 = amps.iter().map(|a| a.abs()).sum();
    let rms = (amps.iter().map(|a| a * a).sum::<f64>() / 2.0).sqrt();
    let eta = (TONE_SAMPLE_ABS + LINES.len() as f64 * U) * sum_abs / rms
        + U
        + (SEG as f64).log2() * FFT_STAGE_REL;
    let lobe = if on_line { 4.0 } else { 8.0 };
    eta * rms * lobe / amps[m_index]
}

fn spectra(series: &[&[f64]], quantity: Quantity) -> (Vec<f64>, Vec<Complex64>, usize) {
    let cfg = WelchConfig::new(SEG);
    let m = csd_matrix(series, FS_HZ, &cfg).unwrap();
    let (f, csd) = two_tilt_axes(quantity).apply(&m);
    (f, csd, m.n_segments)
}

#[test]
fn rate_cross_spectra_are_the_angle_cross_spectra_up_to_nyquist() {
    let (a0, r0) = axis_series(0);
    let (a1, r1) = axis_series(1);
    let (freqs, angle, k_seg) = spectra(&[&a0, &a1], Quantity::Angle);
    let (freqs_r, rate, _) = spectra(&[&r0, &r1], Quantity::Rate);
    assert_eq!(freqs, freqs_r);
    assert_eq!(
        freqs[0],
        FS_HZ / SEG as f64,
        "DC is excluded, the grid starts at bin 1"
    );
    assert!(rate.iter().all(|z| z.re.is_finite() && z.im.is_finite()));
    let at = |s: &[Complex64], k: usize, i: usize, j: usize| s[((k - 1) * 2 + i) * 2 + j];
    // Per estimate: the sum over the segments and the density scaling (`(K + 2) u`); for the
    // rate also the division by w^2 ([`OMEGA_SQ_REL`]) and the rounding of `f_k = k fs / N`
    // and of the rate's amplitudes `A w` (4 u).
    let welch_rel = (k_seg as f64 + 2.0) * U;
    let rate_rel = OMEGA_SQ_REL + 4.0 * U;
    let angle_amps = [0, 1].map(|axis| LINES.map(|j| amplitude(axis, j)));
    let rate_amps = [0, 1].map(|axis| LINES.map(|j| amplitude(axis, j) * omega(j)));
    for (li, &m) in LINES.iter().enumerate() {
        for (k, on_line) in [(m, true), (m - 1, false), (m + 1, false)] {
            if k == 0 {
                continue; // DC, excluded
            }
            // Away from the line the rate's leakage is scaled by (f_line / f_k)^2 (3 u).
            let scale = if on_line {
                1.0
            } else {
                (m as f64 / k as f64).powi(2)
            };
            for (i, j) in [(0, 0), (1, 1), (0, 1), (1, 0)] {
                let pair = |amps: &[[f64; 9]; 2]| {
                    let (ri, rj) = (
                        bin_rel(&amps[i], li, on_line),
                        bin_rel(&amps[j], li, on_line),
                    );
                    ri + rj + ri * rj + welch_rel
                };
                let bound = pair(&angle_amps) + pair(&rate_amps) + rate_rel + 3.0 * U;
                let want = at(&angle, k, i, j) * scale;
                let norm = (at(&angle, k, i, i).re * at(&angle, k, j, j).re).sqrt() * scale;
                let err = (at(&rate, k, i, j) - want).norm() / norm;
                assert!(
                    err <= bound,
                    "S_{i}{j} at bin {k} ({} Hz, line {m}): rate {:e} vs angle {:e} x {scale}: \
                     relative error {err:e} > bound {bound:e}",
                    freqs[k - 1],
                    at(&rate, k, i, j),
                    at(&angle, k, i, j)
                );
            }
        }
    }
}

fn series(data: Vec<Vec<f64>>, quantity: Quantity) -> TiltSeries {
    TiltSeries {
        sample_rate_hz: FS_HZ,
        axes: vec![TiltAxis::ThetaT, TiltAxis::EtaT],
        data,
        translations: Vec::new(),
        sensors: Default::default(),
        provenance: Provenance {
            path: PathBuf::from("(synthetic)"),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity,
            axis_map: "theta_t=theta_t,eta_t=eta_t".into(),
            start_time: None,
            notes: Vec::new(),
        },
    }
}

#[test]
fn budget_of_a_rate_is_the_budget_of_its_angle_at_every_line() {
    let (a0, r0) = axis_series(0);
    let (a1, r1) = axis_series(1);
    let model = Model::new(&Params::table_i()).unwrap();
    let opts = BudgetOptions {
        welch_segment_len: Some(SEG),
        ..BudgetOptions::default()
    };
    let run = |s: &mut TiltSeries| budget_from_series(&model, s, &opts, &mut |_, _| {}).unwrap();
    let angle = run(&mut series(vec![a0, a1], Quantity::Angle));
    let rate = run(&mut series(vec![r0, r1], Quantity::Rate));
    assert_eq!(angle.budget.freqs_hz, rate.budget.freqs_hz);
    assert!(rate.notes.iter().any(|n| n == RATE_BUDGET_NOTE));
    assert!(!angle.notes.iter().any(|n| n == RATE_BUDGET_NOTE));
    let x = |r: &tiltnoise_core::noise::BudgetReport| {
        let ob = r.budget.observable(Observable::X).unwrap();
        let theta = &ob.term(&TermKind::TiltAxis(TiltAxis::ThetaT)).unwrap().psd;
        assert!(theta.iter().all(|&p| p == 0.0), "X sees eta_t only");
        ob.term(&TermKind::Tilt).unwrap().psd.clone()
    };
    let (xa, xr) = (x(&angle), x(&rate));
    let k_seg = match angle.source {
        tiltnoise_core::noise::SpectralSource::Welch {
            n_welch_segments, ..
        } => n_welch_segments,
        _ => unreachable!("a series budget is a Welch budget"),
    };
    for (li, &m) in LINES.iter().enumerate() {
        // X = H eta_t: the eta_t PSD's bound (as above) and |H|^2 S (3 u).
        let amps = |w: bool| LINES.map(|j| amplitude(1, j) * if w { omega(j) } else { 1.0 });
        let bound = 2.0 * bin_rel(&amps(false), li, true)
            + 2.0 * bin_rel(&amps(true), li, true)
            + 2.0 * (k_seg as f64 + 2.0) * U
            + OMEGA_SQ_REL
            + 10.0 * U;
        let err = (xr[m - 1] - xa[m - 1]).abs() / xa[m - 1];
        assert!(
            err <= bound,
            "X tilt at {} Hz: rate {:e} vs angle {:e} ({err:e} > {bound:e})",
            rate.budget.freqs_hz[m - 1],
            xr[m - 1],
            xa[m - 1]
        );
    }
}

/// The map of a record of theta_t and eta_t in `quantity`: the budget's conversion of their
/// Welch cross-spectra to the angles'.
fn two_tilt_axes(quantity: Quantity) -> tiltnoise_core::input::GroundMap {
    use tiltnoise_core::input::{GroundChannel, GroundMap};
    let channels = [
        GroundChannel::tilt(TiltAxis::ThetaT, quantity),
        GroundChannel::tilt(TiltAxis::EtaT, quantity),
    ];
    GroundMap::new(&channels, 9.81).expect("rotation sensors alone")
}
