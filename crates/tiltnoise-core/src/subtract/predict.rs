//! The tilt part of each observable in the time domain: the witness series through the
//! model's transfer functions, with a gain per input, a delay and the optimal weighting given
//! the witness noise ([`super::weighting`]), by exact filtering in the frequency domain.
//!
//! # Method
//!
//! `y_o(t) = sum_a g_a (h_oa * w_a)(t - tau)` is computed on the DFT of the whole record:
//!
//! 1. the line through each channel's first and last sample is removed, so that the periodic
//!    extension the DFT assumes has no jump; its response is added back exactly: a tilt linear
//!    in time has `u'' = 0`, so the response is the static one, `H(0) (a + b (t - tau))`
//!    (for a damped model the real part of `H(0)`, exact to first order in the loss angles),
//!    weighted as the lowest DFT bin is (the line holds the record's longest periods) and left
//!    out with the lowest band;
//! 2. the rest is transformed, multiplied bin by bin by `F_o(f_k) = A(f_k) G_o(f_k)`, with
//!    `G_oa = g_a H_oa(f_k) exp(-i 2 pi f_k tau)` (`e^{+iwt}` convention: a delay is
//!    `exp(-i w tau)`; [`crate::tf::Method::Split`], full relative accuracy on every entry)
//!    and `A = S_ww^-1 S_tt` the weighting, interpolated linearly between the Welch bins where
//!    it is estimated (it is smooth there, so the filter's impulse response is short), and
//!    transformed back.
//!
//! This is the periodic steady state of the band-limited interpolant of the record: inside
//! the record it solves the equations of motion driven by that interpolant exactly (up to the
//! FFT's rounding, `eps log2 N` relative to the record's norm, and the transfer functions'
//! `1e-13`), fractional delays included. What it cannot know is the tilt before the record: the
//! model's memory of it (the impulse response) makes the first and last samples less certain,
//! and for an undamped mode it never fades, which is why a free oscillation of unknown amplitude
//! at every mode stays in any prediction of an undamped model (the measured record has its own,
//! from its initial state). Near an undamped resonance the response depends on damping the
//! model does not have: where a 1 % error of the frequency, up or down (the model's accuracy on
//! the mode frequencies, Table II), changes the transfer function by more than its own size the
//! prediction is not made (both sides of a pole: an undamped pole's high side is as uncertain
//! as its low side), and between half that and that it is tapered to zero (a raised cosine in
//! the sensitivity), so that the prediction's spectrum has no step; the bands left out are
//! reported.
//!
//! The alternative, time stepping an exact discretization of the modes
//! ([`crate::simulate::driven`]), is exact only for a piecewise-linear tilt: for a record
//! sampled at `dt` it sees the band-limited tilt through `sinc^2(f dt)`, a relative error of
//! `(pi f dt)^2 / 3`, 3e-3 at 30 mHz for a 1 Hz record, and fractional delays cost it an
//! interpolation. Here both are exact.

use super::SubtractError;
use crate::cancel::Cancel;
use crate::model::{Input, Model, Observable, Request};
use crate::tf::plan;
use nalgebra::DMatrix;
use num_complex::Complex64;
use realfft::RealFftPlanner;

/// Relative frequency error of the model's modes (1 %: Table II's calculated against measured
/// frequencies) with which [`sensitivity`] probes the transfer functions.
pub const FREQ_ERROR_REL: f64 = 0.01;

/// Relative change of a transfer-function row under [`FREQ_ERROR_REL`] above which a bin is not
/// predicted: the model does not determine the response there. From half of it the prediction
/// is tapered.
pub const GUARD_SENSITIVITY: f64 = 1.0;

/// The coupling parameters of a prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupling {
    /// Gain per witness input: the pendulum sees `g_a` times the record.
    pub gains: Vec<f64>,
    /// Delay of the pendulum's response behind the record (s).
    pub delay_s: f64,
}

/// The weighting `A(f)` of the witness inputs ([`super::weighting`]) on a frequency grid,
/// read between its points linearly (constant beyond them).
#[derive(Debug, Clone, PartialEq)]
pub struct Weights {
    /// Increasing frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// `A` at each frequency (inputs x inputs).
    pub at: Vec<DMatrix<Complex64>>,
}

impl Weights {
    /// No weighting: the witness is taken as the floor motion itself.
    pub fn identity(n_in: usize) -> Weights {
        Weights {
            freqs_hz: vec![0.0],
            at: vec![DMatrix::identity(n_in, n_in)],
        }
    }

    /// `A` at `f`.
    pub fn at(&self, f: f64) -> DMatrix<Complex64> {
        let k = self.freqs_hz.partition_point(|&x| x <= f);
        if k == 0 {
            return self.at[0].clone();
        }
        if k == self.freqs_hz.len() {
            return self.at[k - 1].clone();
        }
        let (f0, f1) = (self.freqs_hz[k - 1], self.freqs_hz[k]);
        let t = (f - f0) / (f1 - f0);
        &self.at[k - 1] * Complex64::new(1.0 - t, 0.0) + &self.at[k] * Complex64::new(t, 0.0)
    }
}

/// The predicted tilt parts, as spectra of the whole record, from which series are made with
/// any band left out ([`Predictor::series`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Predictor {
    fs_hz: f64,
    n: usize,
    outputs: Vec<Observable>,
    /// Per output, the DFT of the prediction without its line part.
    spectra: Vec<Vec<Complex64>>,
    /// Per output, the response to the line through the end samples (time domain).
    line: Vec<Vec<f64>>,
    /// Frequency bands (Hz) left out of the prediction of each observable (see the module
    /// docs), merged from neighbouring bins.
    pub guarded: Vec<(Observable, Vec<(f64, f64)>)>,
}

/// Predicted tilt parts of the observables.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Prediction {
    /// One series per requested observable, the record's length, in m or rad.
    pub series: Vec<(Observable, Vec<f64>)>,
    /// Frequency bands (Hz) left out of the prediction of each observable near the model's
    /// resonances.
    pub guarded: Vec<(Observable, Vec<(f64, f64)>)>,
}

/// `max(|H_row(f (1 + e)) - H_row(f)|, |H_row(f (1 - e)) - H_row(f)|) / |H_row(f)|`
/// (Euclidean norms over the row's inputs, `e` = [`FREQ_ERROR_REL`]): how much a 1 % error of
/// frequency either way changes the response; NaN for a row of zeros.
pub fn sensitivity(h: &[Complex64], h_up: &[Complex64], h_down: &[Complex64]) -> f64 {
    let norm = |v: &mut dyn Iterator<Item = Complex64>| v.map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    let base = norm(&mut h.iter().copied());
    let up = norm(&mut h.iter().zip(h_up).map(|(a, b)| b - a));
    let down = norm(&mut h.iter().zip(h_down).map(|(a, b)| b - a));
    up.max(down) / base
}

/// The factor on the prediction at a sensitivity `s`: 1 up to half of [`GUARD_SENSITIVITY`],
/// 0 from it on, a raised cosine between.
pub fn guard_factor(s: f64) -> f64 {
    let x = (s / GUARD_SENSITIVITY - 0.5) * 2.0;
    if x.is_nan() || x >= 1.0 {
        0.0
    } else if x <= 0.0 {
        1.0
    } else {
        (0.5 * std::f64::consts::PI * x).cos().powi(2)
    }
}

impl Predictor {
    /// The prediction of every observable, each bin's spectrum multiplied by `mask(output
    /// index, frequency)` (1: predicted; 0: left out), the line part by the mask at 0 Hz.
    pub fn series(&self, mask: &dyn Fn(usize, f64) -> f64) -> Prediction {
        let mut planner = RealFftPlanner::<f64>::new();
        let inv = planner.plan_fft_inverse(self.n);
        let df = self.fs_hz / self.n as f64;
        let series = self
            .spectra
            .iter()
            .enumerate()
            .map(|(o, spec)| {
                let mut spec: Vec<Complex64> = spec
                    .iter()
                    .enumerate()
                    .map(|(k, z)| z * mask(o, k as f64 * df))
                    .collect();
                let mut y = inv.make_output_vec();
                inv.process(&mut spec, &mut y)
                    .expect("buffers sized by the plan");
                let n = self.n as f64;
                let line_mask = mask(o, 0.0);
                for (v, l) in y.iter_mut().zip(&self.line[o]) {
                    *v = *v / n + line_mask * l;
                }
                (self.outputs[o], y)
            })
            .collect();
        Prediction {
            series,
            guarded: self.guarded.clone(),
        }
    }

    /// The spectrum (DFT, unnormalized) of output `o`'s prediction without its line part.
    pub fn spectrum(&self, o: usize) -> &[Complex64] {
        &self.spectra[o]
    }
}

/// Bins of the whole record's DFT between two polls of the cancellation token: three transfer
/// function evaluations each, a few milliseconds for all of them.
pub const CANCEL_BINS: usize = 4096;

/// The tilt parts of `outputs` predicted from the witness record `data` (one series per input
/// of `inputs`, equal lengths >= 2, sampled at `fs_hz`) through `model` with `coupling` and the
/// weighting `weights`, polling `cancel` every [`CANCEL_BINS`] bins.
///
/// # Errors
///
/// [`SubtractError::Tf`] when the transfer functions cannot be evaluated at a bin (an exact
/// undamped resonance); [`SubtractError::Cancelled`] once `cancel` is set.
#[allow(clippy::too_many_arguments)]
pub fn predictor(
    model: &Model,
    fs_hz: f64,
    inputs: &[Input],
    data: &[&[f64]],
    outputs: &[Observable],
    coupling: &Coupling,
    weights: &Weights,
    cancel: &Cancel,
) -> Result<Predictor, SubtractError> {
    let n = data[0].len();
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: inputs.to_vec(),
    };
    let tf = plan(model, &request, super::method_for(model))
        .map_err(|e| SubtractError::Plan(e.to_string()))?;
    let (n_out, n_in) = (outputs.len(), inputs.len());
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(n);
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
    let mut h_up = h.clone();
    let mut h_down = h.clone();
    let mut h0 = h.clone();
    tf.eval_into(0.0, &mut h0)?;
    let df = fs_hz / n as f64;
    for k in 1..n_bins {
        if k % CANCEL_BINS == 0 {
            cancel.check()?;
        }
        let f = k as f64 * df;
        tf.eval_into(f, &mut h)?;
        tf.eval_into(f * (1.0 + FREQ_ERROR_REL), &mut h_up)?;
        tf.eval_into(f * (1.0 - FREQ_ERROR_REL), &mut h_down)?;
        let at = weights.at(f);
        let phase = Complex64::from_polar(1.0, -std::f64::consts::TAU * f * coupling.delay_s);
        for o in 0..n_out {
            let rows = o * n_in..(o + 1) * n_in;
            let guard = guard_factor(sensitivity(
                &h[rows.clone()],
                &h_up[rows.clone()],
                &h_down[rows.clone()],
            ));
            if guard == 0.0 {
                match guarded[o].last_mut() {
                    Some(band) if (band.1 - (f - df)).abs() <= 0.5 * df => band.1 = f,
                    _ => guarded[o].push((f, f)),
                }
                continue;
            }
            // y = F^T w with F = A G.
            let mut y = Complex64::new(0.0, 0.0);
            for b in 0..n_in {
                let f_b: Complex64 = (0..n_in)
                    .map(|a| at[(b, a)] * h[o * n_in + a] * coupling.gains[a])
                    .sum();
                y += f_b * spectra[b][k];
            }
            out_spec[o][k] = y * phase * guard;
        }
    }
    for spec in out_spec.iter_mut() {
        // A real series' DFT has real DC and (even length) Nyquist bins.
        spec[0].im = 0.0;
        if n % 2 == 0 {
            spec[n_bins - 1].im = 0.0;
        }
    }
    // The line holds the record's longest periods: it is weighted as the lowest bin is,
    // `F_b = sum_a A_ba G_a(0)`, so that a witness that records only its own noise there (a
    // noise rising at low frequency) adds none of it.
    let at_lowest = weights.at(df);
    let shift = coupling.delay_s * fs_hz;
    let line = (0..n_out)
        .map(|o| {
            let f_line: Vec<f64> = (0..n_in)
                .map(|b| {
                    (0..n_in)
                        .map(|a| at_lowest[(b, a)] * h0[o * n_in + a].re * coupling.gains[a])
                        .sum::<Complex64>()
                        .re
                })
                .collect();
            (0..n)
                .map(|i| {
                    let t = i as f64 - shift;
                    lines
                        .iter()
                        .zip(&f_line)
                        .map(|(&(c0, c1), f)| f * (c0 + c1 * t))
                        .sum()
                })
                .collect()
        })
        .collect();
    Ok(Predictor {
        fs_hz,
        n,
        outputs: outputs.to_vec(),
        spectra: out_spec,
        line,
        guarded: outputs.iter().copied().zip(guarded).collect(),
    })
}

/// [`predictor`] without weighting, every band predicted.
///
/// # Errors
///
/// As [`predictor`].
pub fn predict(
    model: &Model,
    fs_hz: f64,
    inputs: &[Input],
    data: &[&[f64]],
    outputs: &[Observable],
    coupling: &Coupling,
) -> Result<Prediction, SubtractError> {
    let p = predictor(
        model,
        fs_hz,
        inputs,
        data,
        outputs,
        coupling,
        &Weights::identity(inputs.len()),
        &Cancel::never(),
    )?;
    Ok(p.series(&|_, _| 1.0))
}
