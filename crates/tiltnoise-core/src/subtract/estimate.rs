//! Estimation of the coupling parameters (a gain per witness input, a delay, chosen model
//! parameters, the scales of uncertain witness noise levels) from the cross spectra of the
//! witness record and the measured observables.
//!
//! # The estimator
//!
//! The measured observable is `y = G^T t + n` and the witness record `w = t + m`: the true
//! floor motion `t` seen through the model, `G_a = g_a H_a(f; p) exp(-i w tau)`, plus readout
//! noise `n`, and the witnesses' own noise `m`, uncorrelated with `t`, `n` and each other.
//! Given the witness record, `y` is Gaussian with mean `F^T w` and variance `S_ee`:
//!
//! ```text
//! F = S_ww^-1 S_tt G   (S_tt = S_ww - S_mm),      S_ee = S_nn + G^H (S_tt - S_tt S_ww^-1 S_tt) G,
//! ```
//!
//! the best linear prediction of the tilt part from the noisy witness
//! ([`super::weighting`]). With the Welch spectra `S_ab = <conj(w_a) w_b>` and
//! `s_a = <conj(w_a) y>` this is a linear regression with a fixed design: given `w`,
//!
//! ```text
//! r_k(theta) = s_k - S_k F_k(theta),      E[r_k | w] = 0,  Cov[r_k | w] = S_k S_ee,k / n_eff,
//! ```
//!
//! in every bin `k`, which the fit whitens (real and imaginary parts of every input as separate
//! residuals, `chi^2` counting two degrees of freedom per input and bin) and minimizes with the
//! fit module's Levenberg-Marquardt on the parameters' boxes.
//!
//! `S_ww` in `F` is the witness spectrum smoothed over the neighbouring bins, not the bin's
//! own: with the bin's own `S_k` the residual becomes `s_k - (S_k - S_mm) G` (the corrected, or
//! method-of-moments, estimator of errors-in-variables regression: W. A. Fuller, *Measurement
//! Error Models*, Wiley 1987, sec. 1.2), whose weights and Jacobian are correlated with its
//! residuals through the witness noise, biasing the estimates by `O(S_mm S_ww / (n_eff S_tt^2))`
//! and making the stated uncertainties too small. With the smoothed spectrum the residual is a
//! function of the readout and witness noise that has zero mean whatever the witness record, so
//! weights and Jacobian computed from the witness record cannot bias it (R. Pintelon and
//! J. Schoukens, *System Identification: A Frequency Domain Approach*, 2nd ed., Wiley 2012,
//! ch. 7; J. S. Bendat and A. G. Piersol, *Random Data*, 4th ed., Wiley 2010, sec. 9.3).
//!
//! * **Assumptions**: stationary Gaussian noise; `m` known per input (white or a spectrum) up
//!   to a stated relative uncertainty, uncorrelated between inputs and with the readout;
//!   spectra smooth over a few bins; the model's transfer functions exact up to the fitted
//!   parameters. Without `S_mm` (the default) `F = G`: the gains are then biased low by the
//!   unknown `S_mm / S_ww`.
//! * **Noise levels with an uncertainty** (`rel`, 1 sigma of the ASD): the noise PSD of that
//!   input is multiplied by `s^2`, `ln s` fitted with a Gaussian prior of standard deviation
//!   `rel` (a residual row `ln s / rel`). The data constrain `s` where the witness's signal and
//!   noise have different spectra; the prior carries the stated uncertainty into every
//!   estimate's sigma.
//! * **Bins**: every other Welch bin of the band, so that the residuals of neighbouring bins
//!   (correlated by 4/9 for the Hann window) do not count twice; the remaining correlation of
//!   bins two apart (1/36) widens the uncertainties by `sqrt(1 + 2/36)`. Left out: bins where
//!   a 1 % error of the model's frequencies, up or down, changes the transfer function by 1 %
//!   or more (the resonances, which the undamped model cannot fit), and bins where the witness
//!   spectral matrix is numerically singular (dependent or dead witnesses). No bin is selected
//!   by its data otherwise. The default band ends where the witness stops being coherent with
//!   every observable (the smoothed multiple coherence within 3 standard deviations of what
//!   noise alone gives): above it the witness records nothing of what the observables see,
//!   whatever its stated noise.
//! * **Weights**: first from the coherence (`S_ee = S_yy (1 - gamma^2) n / (n - A)`, model
//!   free), then from the first fit: the witness-limited part from the model, the rest
//!   smoothed from the residuals of the neighbouring bins.
//! * **Delay**: started from a scan of the allowed range in steps of `1 / (8 f_max)` with the
//!   gains solved linearly at each step, so that the fit cannot stop in a minimum one phase turn
//!   away; the Welch cross spectrum of a delay `tau` is attenuated by the window's
//!   self-overlap at `tau` ([`super::stats::hann_delay_factor`]), which the model includes.
//! * **What the data cannot constrain** is fixed at its nominal value and reported with the
//!   uncertainty it would have had: a parameter whose linearized (Fisher) uncertainty is at
//!   least its scale (10 % for a gain; one sample for the delay; its error bar from the
//!   parameter file, or 10 % for a parameter the error model calls exact, such as `length.h_m`).
//!   Noise scales always stay free: their prior constrains them.
//! * **Uncertainties**: `(J^T J)^-1` of the whitened residuals at the solution, the data rows'
//!   variance widened by the bin correlation and by `chi^2 / dof` when that exceeds 1 (model or
//!   noise misfit: the Birge ratio).

use super::parameters::{key_params, Kind, Param};
use super::problem::{
    coherence_residual, covariance, real_parts, regular, transfer, whitener, Bin, GridBin, Problem,
    S_EE_FLOOR,
};
use super::stats::hann_delay_factor;
use super::weighting::{smoothing_window, WitnessSpectra};
use super::SubtractError;
use crate::fit::lm::{self, LmOptions, Stop};
use crate::model::{Input, Observable, Request};
use crate::params::Params;
use crate::spectral::CrossSpectra;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

pub use super::parameters::allowed_keys;

/// A bin enters the fit when a 1 % error of the model's frequencies changes its transfer
/// functions by less than this fraction ([`super::predict::sensitivity`]).
pub const FIT_SENSITIVITY: f64 = 0.01;
/// The lowest bin of the default band (DC and the first bins carry the segments' detrending).
pub const FIRST_BIN: usize = 3;
/// The default band ends at this fraction of the Nyquist frequency (above it the record's
/// anti-alias filter, if any, is not in the model).
pub const TOP_FRACTION_OF_NYQUIST: f64 = 0.8;
/// Projected-gradient tolerance of the solver (cost per unit of the box half-width): far
/// below `1 / sigma_u`, so the last step is a negligible fraction of the uncertainty.
pub const LM_GTOL: f64 = 1e-6;
/// Iteration limit of each pass of the solver.
pub const LM_MAX_ITERATIONS: usize = 200;

/// What was asked of the fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitRequest {
    /// Model parameters to fit besides the gains and the delay (dotted keys).
    pub keys: Vec<String>,
    /// Fit band (Hz); `None`: from bin [`FIRST_BIN`] to [`TOP_FRACTION_OF_NYQUIST`], and no
    /// higher than the witness is coherent with some observable.
    pub band_hz: Option<(f64, f64)>,
    /// Largest delay magnitude allowed (s).
    pub max_delay_s: f64,
    /// The witnesses' noise PSDs `[input][Welch bin]` (unit^2/Hz, one-sided), the record's
    /// input order; zeros when unknown.
    pub noise_psd: Vec<Vec<f64>>,
    /// Relative uncertainty (1 sigma) of each input's noise ASD; 0 when exact.
    pub noise_rel: Vec<f64>,
}

/// How an estimate came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Status {
    /// Fitted inside its box.
    Fitted,
    /// Fitted, but on the edge of its box (the uncertainty does not describe it).
    AtBound,
    /// The data do not constrain it: held at its nominal value.
    NotConstrained,
}

impl Status {
    /// `fitted`, `at_bound`, `not_constrained`.
    pub fn name(self) -> &'static str {
        match self {
            Status::Fitted => "fitted",
            Status::AtBound => "at_bound",
            Status::NotConstrained => "not_constrained",
        }
    }
}

/// One estimated parameter.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimate {
    /// `gain.<input>`, `delay_s`, a parameter-file key or `noise_scale.<input>`.
    pub name: String,
    /// Unit (`1` for a gain or a noise scale).
    pub unit: String,
    /// Value before the fit (1, 0, the parameter file's).
    pub nominal: f64,
    /// Estimate (the nominal value when not constrained).
    pub value: f64,
    /// Standard uncertainty; for a parameter not constrained, the one the data would have
    /// given it (possibly infinite).
    pub sigma: f64,
    /// The scale against which "not constrained" was decided (see the module docs); for a
    /// noise scale its stated relative uncertainty.
    pub scale: f64,
    /// Fitted, on the box, or not constrained.
    pub status: Status,
    /// Box of the fit `(lower, upper)`.
    pub bounds: (f64, f64),
    /// Standard deviation of the Gaussian prior at the nominal value the fit used, in the
    /// estimate's unit, if any: a noise scale's stated uncertainty, or the scale of a key the
    /// data alone do not constrain.
    pub prior_sigma: Option<f64>,
}

/// The outcome of the fit.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct FitReport {
    /// Every parameter asked for: the gains (record's input order), the delay, the keys, the
    /// noise scales.
    pub estimates: Vec<Estimate>,
    /// The fitted parameter set (keys at their estimates).
    pub params: Params,
    /// The factors on the witnesses' noise PSDs at the solution (1 where not fitted).
    pub noise_factors: Vec<f64>,
    /// `chi^2` of the whitened residuals at the solution (priors included).
    pub chi2: f64,
    /// Real residuals minus fitted parameters.
    pub dof: usize,
    /// Factor applied to the data's linearized uncertainties (bin correlation and Birge ratio).
    pub sigma_factor: f64,
    /// Correlation matrix of the fitted parameters, in the order of `fitted`.
    pub correlation: Vec<Vec<f64>>,
    /// Names of the fitted parameters (the rows of `correlation`).
    pub fitted: Vec<String>,
    /// Fit band actually used (Hz).
    pub band_hz: (f64, f64),
    /// Highest frequency (Hz) where the witness is coherent with some observable (`None`:
    /// nowhere).
    pub coherent_top_hz: Option<f64>,
    /// Bins used per observable.
    pub bins: Vec<(Observable, usize)>,
    /// Solver iterations over both passes.
    pub iterations: usize,
    /// Why the last pass stopped.
    pub stop: Stop,
    /// Median over the fit bins of `S_mm / S_ww` per input: the relative bias of the gains
    /// that plain least squares would have (0 without a witness noise model).
    pub witness_bias: Vec<f64>,
    /// Notes on bins and parameters.
    pub notes: Vec<String>,
}

/// Welch cross spectra of the training stretch: the witness inputs, then the observables.
#[derive(Debug, Clone, Copy)]
pub struct Training<'a> {
    /// The spectral matrices.
    pub spectra: &'a CrossSpectra,
    /// The witness spectra smoothed across bins.
    pub witness: &'a WitnessSpectra,
    /// Sample rate (Hz).
    pub fs_hz: f64,
    /// Welch segment length (samples).
    pub segment_len: usize,
    /// Effective number of independent averages
    /// ([`crate::spectral::confidence::equivalent_averages`]).
    pub n_eff: f64,
}

/// The whole fit: see the module docs. `fraction_s` is the known part of the delay from the
/// alignment ([`super::align::Alignment::fraction_s`]).
pub fn fit(
    base: &Params,
    inputs: &[Input],
    outputs: &[Observable],
    training: &Training,
    fraction_s: f64,
    req: &FitRequest,
) -> Result<FitReport, SubtractError> {
    let spectra = training.spectra;
    let n_eff = training.n_eff;
    let n_in = inputs.len();
    let segment_s = training.segment_len as f64 / training.fs_hz;
    let dt = 1.0 / training.fs_hz;
    let bin_variance_factor = super::stats::bin_variance_factor(training.segment_len, 2);
    let params = candidates(base, inputs, req, dt)?;
    let mut notes = Vec::new();

    let FitBand {
        band,
        grid_bins,
        coherent_top,
    } = fit_band(training, n_in, outputs.len(), req, &mut notes)?;
    let freqs: Vec<f64> = grid_bins.iter().map(|&k| spectra.freqs_hz[k]).collect();
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: inputs.to_vec(),
    };
    let model = ModelRows::new(base, &request, &freqs)?;
    let grid = witness_grid(training, &grid_bins, n_in, req, &mut notes);
    let ObservableBins { bins, counts } = observable_bins(
        training, outputs, &grid_bins, &grid, &model, n_in, &mut notes,
    );
    if bins.is_empty() {
        return Err(SubtractError::NoFitBins { band_hz: band });
    }
    let witness_bias = witness_bias(&grid, &bins, n_in);
    let mut problem = Problem {
        base,
        request,
        n_in,
        freqs,
        grid,
        bins,
        params,
        n_eff,
        segment_s,
        fraction_s,
    };
    let mut theta: Vec<f64> = problem.params.iter().map(|p| p.nominal).collect();
    scan_delay(&problem, &model.h0, &mut theta, &mut notes);
    problem.reweight(&theta)?;

    let all: Vec<usize> = (0..problem.params.len()).collect();
    let solution = solve_two_passes(&mut problem, theta, &all)?;
    if solution.stop == Stop::MaxIterations {
        notes.push(format!(
            "the fit stopped at its iteration limit ({LM_MAX_ITERATIONS}) without converging: \
             the estimates are not at a minimum (fit fewer parameters, or a narrower band)"
        ));
    }
    let Solution {
        theta,
        free,
        iterations,
        stop,
    } = solution;
    let at_solution = problem.evaluate(&theta, &free)?;
    let chi2 = at_solution.r.norm_squared();
    let dof = at_solution.r.len().saturating_sub(free.len()).max(1);
    let birge = (chi2 / dof as f64).max(1.0).sqrt();
    // chi^2 / dof has a standard deviation of sqrt(2 / dof); beyond 5 of them the misfit is not
    // noise, and the Birge scaling cannot stand for it.
    if chi2 / dof as f64 > 1.0 + 5.0 * (2.0 / dof as f64).sqrt() {
        notes.push(format!(
            "chi^2/dof = {:.3} for {dof} dof: the model does not describe the data within their \
             noise; the estimates may carry systematic errors that their uncertainties (scaled by \
             {birge:.3}) do not include (a channel with almost no noise, a wrong fit band, a \
             wrong witness noise level, a model parameter that should be fitted)",
            chi2 / dof as f64
        ));
    }
    let sigma_factor = bin_variance_factor.sqrt() * birge;
    let data_rows = problem.data_rows();
    let (sig_u, correlation) = covariance(&at_solution, data_rows, sigma_factor);
    let (sig_all, _) = covariance(&problem.evaluate(&theta, &all)?, data_rows, sigma_factor);
    // What the data alone say of a key with a prior: whether it is constrained.
    let (sig_data, _) = covariance(&at_solution.data_only(data_rows), data_rows, sigma_factor);
    let params_fit = problem.params_at(&theta)?;
    let estimates = estimates_of(
        &problem.params,
        &theta,
        &free,
        &Sigmas {
            fitted: &sig_u,
            all: &sig_all,
            data_only: &sig_data,
        },
    );
    Ok(FitReport {
        estimates,
        params: params_fit,
        noise_factors: problem.noise_factors(&theta),
        chi2,
        dof,
        sigma_factor,
        correlation,
        fitted: free
            .iter()
            .map(|&j| problem.params[j].name.clone())
            .collect(),
        band_hz: band,
        coherent_top_hz: coherent_top,
        bins: counts,
        iterations,
        stop,
        witness_bias,
        notes,
    })
}

/// The band of the fit and its bins on the Welch grid.
struct FitBand {
    band: (f64, f64),
    grid_bins: Vec<usize>,
    coherent_top: Option<f64>,
}

/// The band asked for, or the one where the witness is coherent with some observable; a note
/// when the band asked for reaches above the coherent one.
fn fit_band(
    training: &Training,
    n_in: usize,
    n_out: usize,
    req: &FitRequest,
    notes: &mut Vec<String>,
) -> Result<FitBand, SubtractError> {
    let spectra = training.spectra;
    let adjacent = super::stats::bin_variance_factor(training.segment_len, 1);
    let coherent_top = coherent_top(spectra, n_in, n_out, training.n_eff, adjacent);
    if coherent_top.is_none() && req.band_hz.is_none() {
        return Err(SubtractError::NotCoherent);
    }
    let (band, grid_bins) = band_bins(&spectra.freqs_hz, req.band_hz, coherent_top)?;
    if let (Some(top), Some((_, hi))) = (coherent_top, req.band_hz) {
        if hi > top {
            notes.push(format!(
                "the fit band reaches {hi:e} Hz, above {top:e} Hz, where the witness stops being \
                 coherent with the observables: bins there carry no information on the coupling \
                 and depend on the stated witness noise"
            ));
        }
    }
    Ok(FitBand {
        band,
        grid_bins,
        coherent_top,
    })
}

/// The nominal model's transfer functions on the fit grid, and with its frequencies shifted
/// by `±FREQ_ERROR_REL` (to find the bins too close to a resonance).
struct ModelRows {
    h0: Vec<Complex64>,
    h_up: Vec<Complex64>,
    h_down: Vec<Complex64>,
    /// Transfer functions per grid frequency (`outputs × inputs`).
    block: usize,
    n_in: usize,
}

impl ModelRows {
    fn new(base: &Params, request: &Request, freqs: &[f64]) -> Result<Self, SubtractError> {
        let h0 = transfer(base, request, freqs)?;
        let shifted = |sign: f64| -> Vec<f64> {
            freqs
                .iter()
                .map(|f| f * (1.0 + sign * super::predict::FREQ_ERROR_REL))
                .collect()
        };
        let h_up = transfer(base, request, &shifted(1.0))?;
        let h_down = transfer(base, request, &shifted(-1.0))?;
        let n_in = request.inputs.len();
        Ok(Self {
            h0,
            h_up,
            h_down,
            block: request.outputs.len() * n_in,
            n_in,
        })
    }

    /// The transfer functions from every input to observable `o` at grid frequency `g`.
    fn row(&self, h: &[Complex64], o: usize, g: usize) -> Vec<Complex64> {
        h[g * self.block + o * self.n_in..][..self.n_in].to_vec()
    }
}

/// The witnesses' spectral matrices per fit bin (`None` where singular, with a note).
fn witness_grid(
    training: &Training,
    grid_bins: &[usize],
    n_in: usize,
    req: &FitRequest,
    notes: &mut Vec<String>,
) -> Vec<Option<GridBin>> {
    let spectra = training.spectra;
    let n_ch = spectra.n_channels;
    let noise_at = |k: usize| -> Vec<f64> { req.noise_psd.iter().map(|m| m[k]).collect() };
    let mut singular = 0;
    let grid: Vec<Option<GridBin>> = grid_bins
        .iter()
        .map(|&k| {
            let m = spectra.matrix(k);
            let sww = DMatrix::from_fn(n_in, n_in, |a, b| m[a * n_ch + b]);
            let sbar = training.witness.smoothed[k].clone();
            let usable = regular(&sbar) && regular(&sww);
            if !usable {
                singular += 1;
            }
            usable.then(|| GridBin {
                sww,
                sbar,
                noise: noise_at(k),
            })
        })
        .collect();
    if singular > 0 {
        notes.push(format!(
            "{singular} bin(s) of the band left out where the witnesses' spectral matrix is \
             numerically singular (dependent or dead witness channels)"
        ));
    }
    grid
}

/// The bins of the fit.
struct ObservableBins {
    /// Per observable driven by the witnesses (its index in the outputs), its usable bins with
    /// model-free first weights.
    bins: Vec<(usize, Vec<Bin>)>,
    /// Bins per observable (0 for one left out).
    counts: Vec<(Observable, usize)>,
}

/// Each observable's usable bins, with notes on those left out.
fn observable_bins(
    training: &Training,
    outputs: &[Observable],
    grid_bins: &[usize],
    grid: &[Option<GridBin>],
    model: &ModelRows,
    n_in: usize,
    notes: &mut Vec<String>,
) -> ObservableBins {
    let mut bins: Vec<(usize, Vec<Bin>)> = Vec::new();
    let mut counts = Vec::new();
    for (o, &obs) in outputs.iter().enumerate() {
        if (0..grid_bins.len()).all(|g| model.row(&model.h0, o, g).iter().all(|z| z.norm() == 0.0))
        {
            notes.push(format!(
                "{}: not driven by the witness inputs (its transfer functions from them are \
                 exactly 0); left out of the fit",
                obs.name()
            ));
            counts.push((obs, 0));
            continue;
        }
        let (list, sensitive) = bins_of_observable(training, o, grid_bins, grid, model, n_in);
        if sensitive > 0 {
            notes.push(format!(
                "{}: {sensitive} bin(s) of the band left out where a 1 % error of the model's \
                 frequencies changes the transfer function by 1 % or more (resonances)",
                obs.name()
            ));
        }
        counts.push((obs, list.len()));
        if !list.is_empty() {
            bins.push((o, list));
        }
    }
    ObservableBins { bins, counts }
}

/// The usable bins of observable `o`, and how many were left out near a resonance.
fn bins_of_observable(
    training: &Training,
    o: usize,
    grid_bins: &[usize],
    grid: &[Option<GridBin>],
    model: &ModelRows,
    n_in: usize,
) -> (Vec<Bin>, usize) {
    let spectra = training.spectra;
    let n_eff = training.n_eff;
    let n_ch = spectra.n_channels;
    let yc = n_in + o;
    let mut list = Vec::new();
    let mut sensitive = 0;
    for (g, &k) in grid_bins.iter().enumerate() {
        let Some(gb) = &grid[g] else { continue };
        let sens = super::predict::sensitivity(
            &model.row(&model.h0, o, g),
            &model.row(&model.h_up, o, g),
            &model.row(&model.h_down, o, g),
        );
        if sens.is_nan() || sens >= FIT_SENSITIVITY {
            sensitive += 1;
            continue;
        }
        let m = spectra.matrix(k);
        let s = DVector::from_fn(n_in, |a, _| m[a * n_ch + yc]);
        let syy = m[yc * n_ch + yc].re;
        if syy <= 0.0 {
            continue;
        }
        // Model-free first weights: the coherence residual, unbiased for n_eff averages.
        let coh = coherence_residual(syy, &s, &gb.sww).unwrap_or(syy);
        let n_fac = if n_eff > n_in as f64 {
            n_eff / (n_eff - n_in as f64)
        } else {
            1.0
        };
        let see = (coh * n_fac).clamp(S_EE_FLOOR * syy, syy.max(S_EE_FLOOR * syy));
        list.push(Bin {
            grid: g,
            s,
            syy,
            see,
            whitener: whitener(&gb.sbar, see, n_eff, None),
        });
    }
    (list, sensitive)
}

/// Median over the fit bins of `S_mm / S_ww` per input.
fn witness_bias(grid: &[Option<GridBin>], bins: &[(usize, Vec<Bin>)], n_in: usize) -> Vec<f64> {
    (0..n_in)
        .map(|a| {
            let mut r: Vec<f64> = bins
                .iter()
                .flat_map(|(_, b)| b.iter())
                .filter_map(|b| grid[b.grid].as_ref())
                .map(|g| g.noise[a] / g.sbar[(a, a)].re)
                .collect();
            median(&mut r)
        })
        .collect()
}

/// Where the solver ended.
struct Solution {
    theta: Vec<f64>,
    /// The parameters left free (the others at their nominal values).
    free: Vec<usize>,
    iterations: usize,
    stop: Stop,
}

/// Two passes of the solver: the second after reweighting at the first's solution and fixing
/// what the data then leave unconstrained.
fn solve_two_passes(
    problem: &mut Problem,
    mut theta: Vec<f64>,
    all: &[usize],
) -> Result<Solution, SubtractError> {
    let opts = LmOptions {
        gtol: LM_GTOL,
        max_iterations: LM_MAX_ITERATIONS,
    };
    let mut iterations = 0;
    let mut stop = Stop::Gradient;
    let mut free = constrained(problem, &theta, all)?;
    for pass in 0..2 {
        for &j in all {
            if !free.contains(&j) {
                theta[j] = problem.params[j].nominal;
            }
        }
        if !free.is_empty() {
            let u0 = DVector::from_iterator(
                free.len(),
                free.iter().map(|&j| {
                    (theta[j] - problem.params[j].nominal) / problem.params[j].half_width
                }),
            );
            let base_theta = theta.clone();
            let to_theta = |u: &DVector<f64>| -> Vec<f64> {
                let mut t = base_theta.clone();
                for (jj, &j) in free.iter().enumerate() {
                    t[j] = problem.params[j].nominal + u[jj] * problem.params[j].half_width;
                }
                t
            };
            // The instruments, fixed for the pass at its starting point; the estimate solves
            // Z^T r = 0, i.e. minimizes |(Z^T Z)^-1/2 Z^T r|^2 (exactly identified).
            let z = problem.evaluate(&theta, &free)?.inst;
            let project = projector(&z);
            let out = lm::minimize(u0, 1.0, &opts, |u| {
                let e = problem.evaluate(&to_theta(u), &free)?;
                Ok::<_, SubtractError>((&project * e.r, &project * e.jac))
            })?;
            theta = to_theta(&out.u);
            iterations += out.iterations;
            stop = out.stop;
        }
        if pass == 0 {
            problem.reweight(&theta)?;
            free = constrained(problem, &theta, &free)?;
        }
    }
    Ok(Solution {
        theta,
        free,
        iterations,
        stop,
    })
}

/// The candidate parameters: a gain per input, the delay, the requested keys, and the scale of
/// every witness noise given with an uncertainty.
fn candidates(
    base: &Params,
    inputs: &[Input],
    req: &FitRequest,
    dt: f64,
) -> Result<Vec<Param>, SubtractError> {
    let mut params: Vec<Param> = inputs
        .iter()
        .enumerate()
        .map(|(a, input)| Param::gain(a, input.name()))
        .collect();
    params.push(Param::delay(req.max_delay_s, dt));
    params.extend(key_params(base, &req.keys)?);
    for (a, input) in inputs.iter().enumerate() {
        let rel = req.noise_rel[a];
        if rel > 0.0 && req.noise_psd[a].iter().any(|&m| m > 0.0) {
            params.push(Param::noise_scale(a, input.name(), rel));
        }
    }
    Ok(params)
}

/// The uncertainties (in units of each parameter's half-width) [`estimates_of`] reports: of the
/// fitted parameters together, of every candidate free together (for the held ones), and of the
/// data alone (whether a key with a prior is constrained).
struct Sigmas<'a> {
    fitted: &'a [f64],
    all: &'a [f64],
    data_only: &'a [f64],
}

/// Every candidate's estimate at `theta`: fitted, on its bound, or not constrained (held, or a
/// key the data leave to its prior).
fn estimates_of(params: &[Param], theta: &[f64], free: &[usize], sig: &Sigmas) -> Vec<Estimate> {
    let (sig_u, sig_all, sig_data) = (sig.fitted, sig.all, sig.data_only);
    params
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let (lo, hi) = (p.nominal - p.half_width, p.nominal + p.half_width);
            let (status, sigma_int) = match free.iter().position(|&f| f == j) {
                Some(jj)
                    if matches!(p.kind, Kind::Key(_))
                        && p.prior.is_some()
                        && sig_data[jj] * p.half_width >= p.scale =>
                {
                    (Status::NotConstrained, sig_u[jj] * p.half_width)
                }
                Some(jj) => {
                    let u = (theta[j] - p.nominal) / p.half_width;
                    let s = sig_u[jj] * p.half_width;
                    if u.abs() >= 1.0 - 1e-9 {
                        (Status::AtBound, s)
                    } else {
                        (Status::Fitted, s)
                    }
                }
                None => (Status::NotConstrained, sig_all[j] * p.half_width),
            };
            if p.is_logarithmic() {
                let v = theta[j].exp();
                Estimate {
                    name: p.name.clone(),
                    unit: p.unit.clone(),
                    nominal: 1.0,
                    value: v,
                    sigma: v * sigma_int,
                    scale: p.scale,
                    status,
                    bounds: (lo.exp(), hi.exp()),
                    prior_sigma: p.prior,
                }
            } else {
                Estimate {
                    name: p.name.clone(),
                    unit: p.unit.clone(),
                    nominal: p.nominal,
                    value: theta[j],
                    sigma: sigma_int,
                    scale: p.scale,
                    status,
                    bounds: (lo, hi),
                    prior_sigma: p.prior,
                }
            }
        })
        .collect()
}

/// `(Z^T Z)^-1/2 Z^T` for instruments `Z` (through the eigenvalues of `Z^T Z`; directions it
/// does not span are left out).
fn projector(z: &DMatrix<f64>) -> DMatrix<f64> {
    let eig = (z.transpose() * z).symmetric_eigen();
    let top = eig.eigenvalues.max();
    let p = z.ncols();
    let mut inv_sqrt = DMatrix::<f64>::zeros(p, p);
    for l in 0..p {
        let e = eig.eigenvalues[l];
        if e > top * crate::fit::RANK_TOL && e > 0.0 {
            let v = eig.eigenvectors.column(l);
            inv_sqrt += v * v.transpose() / e.sqrt();
        }
    }
    inv_sqrt * z.transpose()
}

/// The highest Welch frequency where the witness is coherent with some observable: the
/// multiple coherence `gamma^2 = s^H S^-1 s / S_yy`, averaged over [`smoothing_window`], above
/// what the witness's own noise alone would give (`E = A / n` for `A` inputs and `n` averages,
/// plus 3 standard deviations of that average of `Beta(A, n - A)` values, neighbouring bins
/// counted with their correlation). Independent of the stated witness noise, which may be
/// wrong. `None` when no bin is coherent.
fn coherent_top(
    spectra: &CrossSpectra,
    n_in: usize,
    n_out: usize,
    n_eff: f64,
    adjacent: f64,
) -> Option<f64> {
    let freqs = &spectra.freqs_hz[1..];
    let (a, n) = (n_in as f64, n_eff.max(n_in as f64 + 1.0));
    let noise_mean = a / n;
    let noise_var = a * (n - a) / (n * n * (n + 1.0));
    let nc = spectra.n_channels;
    let mut top: Option<usize> = None;
    for y in n_in..n_in + n_out {
        let coh: Vec<f64> = (1..spectra.n_freqs())
            .map(|k| {
                let m = spectra.matrix(k);
                let sww = DMatrix::from_fn(n_in, n_in, |i, j| m[i * nc + j]);
                let s = DVector::from_fn(n_in, |i, _| m[i * nc + y]);
                let syy = m[y * nc + y].re;
                match coherence_residual(syy, &s, &sww) {
                    Some(left) if syy > 0.0 => (1.0 - left / syy).clamp(0.0, 1.0),
                    _ => 0.0,
                }
            })
            .collect();
        let coherent = (0..freqs.len()).rev().find(|&i| {
            let window = smoothing_window(freqs, i, 0);
            let mean = window.iter().map(|&j| coh[j]).sum::<f64>() / window.len() as f64;
            mean > noise_mean + 3.0 * (noise_var * adjacent / window.len() as f64).sqrt()
        });
        top = top.max(coherent);
    }
    top.map(|i| freqs[i])
}

/// The members of `candidates` the fit estimates: those whose Fisher uncertainty at `theta`
/// (all candidates free together) is below their scale, and the keys that are not, which get a
/// Gaussian prior of their scale at their nominal value (if they had none); gains and the
/// delay that are not are left out (held). Parameters with a prior always stay.
fn constrained(
    problem: &mut Problem,
    theta: &[f64],
    candidates: &[usize],
) -> Result<Vec<usize>, SubtractError> {
    let mut free = candidates.to_vec();
    // Dropping one parameter, or giving it a prior, can only shrink the others' uncertainties:
    // treat the worst one at a time until every remaining one is constrained.
    loop {
        let open: Vec<usize> = (0..free.len())
            .filter(|&jj| problem.params[free[jj]].prior.is_none())
            .collect();
        if open.is_empty() {
            return Ok(free);
        }
        let (sig, _) = covariance(&problem.evaluate(theta, &free)?, problem.data_rows(), 1.0);
        let worst = open
            .iter()
            .map(|&jj| {
                let p = &problem.params[free[jj]];
                (jj, sig[jj] * p.half_width / p.scale)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .expect("not empty");
        if worst.1 < 1.0 {
            return Ok(free);
        }
        let j = free[worst.0];
        if matches!(problem.params[j].kind, Kind::Key(_)) {
            problem.params[j].prior = Some(problem.params[j].scale);
        } else {
            free.remove(worst.0);
        }
    }
}

/// Scans the delay over its box in steps of `1 / (8 f_max)`, the gains solved linearly at each
/// step (keys and noise levels nominal, first-pass weights), and starts `theta` at the best
/// step.
fn scan_delay(problem: &Problem, h0: &[Complex64], theta: &mut [f64], notes: &mut Vec<String>) {
    let Some(tau_index) = problem
        .params
        .iter()
        .position(|p| matches!(p.kind, Kind::Delay))
    else {
        return;
    };
    let n_in = problem.n_in;
    let block = problem.request.outputs.len() * n_in;
    let f_max = problem.freqs.last().copied().unwrap_or(1.0);
    let max = problem.params[tau_index].half_width;
    let step = 1.0 / (8.0 * f_max);
    let n_steps = (max / step).ceil() as i64;
    // S - S_mm of every fit frequency, at the nominal noise levels.
    let wsc: Vec<Option<DMatrix<Complex64>>> = problem
        .grid
        .iter()
        .map(|g| {
            g.as_ref().map(|g| {
                let mut sc = g.sww.clone();
                for a in 0..n_in {
                    sc[(a, a)] -= g.noise[a];
                }
                sc
            })
        })
        .collect();
    let mut best: Option<(f64, f64, Vec<f64>)> = None;
    for i in -n_steps..=n_steps {
        let tau = (i as f64 * step).clamp(-max, max);
        let tau_eff = tau - problem.fraction_s;
        let rho = hann_delay_factor(tau_eff / problem.segment_s);
        let mut normal = DMatrix::<f64>::zeros(n_in, n_in);
        let mut rhs = DVector::<f64>::zeros(n_in);
        let mut z0_sq = 0.0;
        for (o, bins) in &problem.bins {
            for bin in bins {
                let wsc = wsc[bin.grid].as_ref().expect("usable");
                let f = problem.freqs[bin.grid];
                let phase = Complex64::from_polar(rho, -TAU * f * tau_eff);
                let hrow = &h0[bin.grid * block + o * n_in..][..n_in];
                let z0 = &bin.whitener * real_parts(&bin.s);
                let v: Vec<DVector<f64>> = (0..n_in)
                    .map(|a| &bin.whitener * real_parts(&(wsc.column(a) * (hrow[a] * phase))))
                    .collect();
                z0_sq += z0.norm_squared();
                for a in 0..n_in {
                    rhs[a] += v[a].dot(&z0);
                    for b in 0..n_in {
                        normal[(a, b)] += v[a].dot(&v[b]);
                    }
                }
            }
        }
        let svd = normal.clone().svd(true, true);
        let g = svd
            .solve(&rhs, normal.amax() * crate::fit::RANK_TOL)
            .unwrap_or_else(|_| DVector::zeros(n_in));
        let chi2 = z0_sq - rhs.dot(&g);
        if best.as_ref().is_none_or(|b| chi2 < b.0) {
            best = Some((chi2, tau, g.iter().copied().collect()));
        }
    }
    if let Some((_, tau, gains)) = best {
        theta[tau_index] = tau;
        for (j, p) in problem.params.iter().enumerate() {
            if let Kind::Gain(a) = p.kind {
                let g = gains[a];
                if g < 0.0 {
                    notes.push(format!(
                        "{}: the data favour a negative gain ({g:.3}): the record's sign \
                         convention for this input may be opposite to the model's (check the \
                         axis map)",
                        p.name
                    ));
                }
                if g > 0.0 {
                    theta[j] = g.ln().clamp(-p.half_width, p.half_width);
                }
            }
        }
    }
}

/// The bins of the fit band (every other Welch bin from the first) and their frequencies; the
/// default band ends at `coherent_top` (Hz) when given.
fn band_bins(
    freqs_hz: &[f64],
    band_hz: Option<(f64, f64)>,
    coherent_top: Option<f64>,
) -> Result<((f64, f64), Vec<usize>), SubtractError> {
    let n = freqs_hz.len();
    let nyquist_bin = n - 1;
    let (lo, hi) = match band_hz {
        None => {
            let top =
                ((TOP_FRACTION_OF_NYQUIST * nyquist_bin as f64).floor() as usize).max(FIRST_BIN);
            let coherent = coherent_top.map_or(top, |f| freqs_hz.partition_point(|&x| x <= f) - 1);
            (FIRST_BIN, top.min(coherent))
        }
        Some((flo, fhi)) => {
            let lo = freqs_hz.partition_point(|&f| f < flo).max(1);
            let hi = freqs_hz.partition_point(|&f| f <= fhi).saturating_sub(1);
            (lo, hi.min(nyquist_bin - 1))
        }
    };
    if hi < lo {
        return match (band_hz, coherent_top) {
            (None, Some(top)) => Err(SubtractError::NoFitBins {
                band_hz: (freqs_hz[FIRST_BIN], top),
            }),
            _ => Err(SubtractError::Band {
                what: "fit".into(),
                band_hz: band_hz.unwrap_or((0.0, 0.0)),
                grid_hz: (freqs_hz[1], freqs_hz[nyquist_bin]),
            }),
        };
    }
    let bins: Vec<usize> = (lo..=hi).step_by(2).collect();
    Ok(((freqs_hz[lo], freqs_hz[bins[bins.len() - 1]]), bins))
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
