//! The tilt part of each observable in the time domain: the tilt series through the model's
//! transfer functions, with a gain per axis and a delay, by exact filtering in the frequency
//! domain.
//!
//! # Method
//!
//! `y_o(t) = sum_a g_a (h_oa * w_a)(t - tau)` is computed on the DFT of the whole record:
//!
//! 1. the line through each channel's first and last sample is removed, so that the periodic
//!    extension the DFT assumes has no jump; its response is added back exactly: a tilt linear
//!    in time has `u'' = 0`, so the response is the static one, `H(0) (a + b (t - tau))`
//!    (for a damped model the real part of `H(0)`, exact to first order in the loss angles);
//! 2. the rest is transformed, multiplied bin by bin by `g_a H_oa(f_k) exp(-i 2 pi f_k tau)`
//!    (`e^{+iwt}` convention: a delay is `exp(-i w tau)`; [`crate::tf::Method::Split`], full
//!    relative accuracy on every tilt entry) and transformed back.
//!
//! This is the periodic steady state of the band-limited interpolant of the record: inside
//! the record it solves the equations of motion driven by that interpolant exactly (up to the
//! FFT's rounding, `eps log2 N` relative to the record's norm, and the transfer functions'
//! `1e-13`), fractional delays included. What it cannot know is the tilt before the record: the
//! model's memory of it (the impulse response) makes the first and last samples less certain,
//! and for an undamped mode it never fades, which is why a free oscillation of unknown amplitude
//! at every mode stays in any prediction of an undamped model (the measured record has its own,
//! from its initial state). Near an undamped resonance the response depends on damping the
//! model does not have: bins where a 1 % error of the frequency (the model's accuracy on the
//! mode frequencies, Table II) changes the transfer function by more than its own size are not
//! predicted (set to zero) and reported as guarded bands.
//!
//! The alternative, time stepping an exact discretization of the modes
//! ([`crate::simulate::driven`]), is exact only for a piecewise-linear tilt: for a record
//! sampled at `dt` it sees the band-limited tilt through `sinc^2(f dt)`, a relative error of
//! `(pi f dt)^2 / 3`, 3e-3 at 30 mHz for a 1 Hz record, and fractional delays cost it an
//! interpolation. Here both are exact.

use super::SubtractError;
use crate::model::{Input, Model, Observable, Request, TiltAxis};
use crate::tf::{plan, Method};
use num_complex::Complex64;
use realfft::RealFftPlanner;

/// Relative frequency error of the model's modes (1 %: Table II's calculated against measured
/// frequencies) with which [`sensitivity`] probes the transfer functions.
pub const FREQ_ERROR_REL: f64 = 0.01;

/// Relative change of a transfer-function row under [`FREQ_ERROR_REL`] above which a bin is not
/// predicted: the model does not determine the response there.
pub const GUARD_SENSITIVITY: f64 = 1.0;

/// The coupling parameters of a prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupling {
    /// Gain per tilt axis of the record: the pendulum sees `g_a` times the record.
    pub gains: Vec<f64>,
    /// Delay of the pendulum's response behind the record (s).
    pub delay_s: f64,
}

/// Predicted tilt parts of the observables.
#[derive(Debug, Clone, PartialEq)]
pub struct Prediction {
    /// One series per requested observable, the record's length, in m or rad.
    pub series: Vec<(Observable, Vec<f64>)>,
    /// Frequency bands (Hz) left out of the prediction of each observable (see the module
    /// docs), merged from neighbouring bins.
    pub guarded: Vec<(Observable, Vec<(f64, f64)>)>,
}

/// `|H_row(f (1 + FREQ_ERROR_REL)) - H_row(f)| / |H_row(f)|` (Euclidean norms over the row's
/// inputs): how much a 1 % error of frequency changes the response; NaN for a row of zeros.
pub fn sensitivity(h: &[Complex64], h_shifted: &[Complex64]) -> f64 {
    let norm = |v: &mut dyn Iterator<Item = Complex64>| v.map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    let base = norm(&mut h.iter().copied());
    let diff = norm(&mut h.iter().zip(h_shifted).map(|(a, b)| b - a));
    diff / base
}

/// The tilt parts of `outputs` predicted from the tilt record `data` (one series per axis of
/// `axes`, equal lengths >= 2, sampled at `fs_hz`) through `model` with `coupling`.
///
/// # Errors
///
/// [`SubtractError::Tf`] when the transfer functions cannot be evaluated at a bin (an exact
/// undamped resonance).
pub fn predict(
    model: &Model,
    fs_hz: f64,
    axes: &[TiltAxis],
    data: &[&[f64]],
    outputs: &[Observable],
    coupling: &Coupling,
) -> Result<Prediction, SubtractError> {
    let n = data[0].len();
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: axes.iter().map(|&a| Input::Tilt(a)).collect(),
    };
    let tf =
        plan(model, &request, Method::Split).map_err(|e| SubtractError::Plan(e.to_string()))?;
    let (n_out, n_in) = (outputs.len(), axes.len());
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(n);
    let inv = planner.plan_fft_inverse(n);
    let lines: Vec<(f64, f64)> = data
        .iter()
        .map(|x| (x[0], (x[n - 1] - x[0]) / (n - 1) as f64))
        .collect();
    let spectra: Vec<Vec<Complex64>> = data
        .iter()
        .zip(&lines)
        .map(|(x, &(a, b))| {
            let mut buf: Vec<f64> = x
                .iter()
                .enumerate()
                .map(|(i, v)| v - a - b * i as f64)
                .collect();
            let mut spec = fwd.make_output_vec();
            fwd.process(&mut buf, &mut spec)
                .expect("buffers sized by the plan");
            spec
        })
        .collect();
    let n_bins = n / 2 + 1;
    let mut out_spec: Vec<Vec<Complex64>> = vec![vec![Complex64::new(0.0, 0.0); n_bins]; n_out];
    let mut guarded: Vec<Vec<(f64, f64)>> = vec![Vec::new(); n_out];
    let mut h = vec![Complex64::new(0.0, 0.0); n_out * n_in];
    let mut h_shifted = h.clone();
    let mut h0 = h.clone();
    tf.eval_into(0.0, &mut h0)?;
    let df = fs_hz / n as f64;
    for k in 0..n_bins {
        let f = k as f64 * df;
        if k == 0 {
            h.copy_from_slice(&h0);
        } else {
            tf.eval_into(f, &mut h)?;
            tf.eval_into(f * (1.0 + FREQ_ERROR_REL), &mut h_shifted)?;
        }
        let phase = Complex64::from_polar(1.0, -std::f64::consts::TAU * f * coupling.delay_s);
        for o in 0..n_out {
            let row = &h[o * n_in..(o + 1) * n_in];
            if k > 0 && sensitivity(row, &h_shifted[o * n_in..(o + 1) * n_in]) > GUARD_SENSITIVITY {
                match guarded[o].last_mut() {
                    Some(band) if (band.1 - (f - df)).abs() <= 0.5 * df => band.1 = f,
                    _ => guarded[o].push((f, f)),
                }
                continue;
            }
            let mut y = Complex64::new(0.0, 0.0);
            for a in 0..n_in {
                y += row[a] * coupling.gains[a] * spectra[a][k];
            }
            out_spec[o][k] = y * phase;
        }
    }
    let mut series = Vec::with_capacity(n_out);
    for (o, spec) in out_spec.iter_mut().enumerate() {
        // A real series' DFT has real DC and (even length) Nyquist bins.
        spec[0].im = 0.0;
        if n % 2 == 0 {
            spec[n_bins - 1].im = 0.0;
        }
        let mut y = inv.make_output_vec();
        inv.process(spec, &mut y)
            .expect("buffers sized by the plan");
        let shift = coupling.delay_s * fs_hz;
        for (i, v) in y.iter_mut().enumerate() {
            *v /= n as f64;
            let t = i as f64 - shift;
            for (a, &(c0, c1)) in lines.iter().enumerate() {
                *v += h0[o * n_in + a].re * coupling.gains[a] * (c0 + c1 * t);
            }
        }
        series.push((outputs[o], y));
    }
    Ok(Prediction {
        series,
        guarded: outputs.iter().copied().zip(guarded).collect(),
    })
}
