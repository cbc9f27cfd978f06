//! Estimation of the coupling parameters (a gain per tilt axis, a delay, chosen model
//! parameters) from the cross spectra of the tilt record and the measured observables.
//!
//! # The estimator
//!
//! The measured observable is `y = sum_a G_a t_a + n` and the tilt record `w_a = t_a + m_a`:
//! the true tilt `t` seen through the model, `G_a = g_a H_a(f; p) exp(-i w tau)`, plus readout
//! noise `n`, and the tiltmeter's own noise `m`, uncorrelated with `t`, `n` and each other.
//! With `S_ab = <conj(w_a) w_b>` and `s_a = <conj(w_a) y>` (Welch, [`crate::spectral`]),
//! `E[s] = S_tt G` and `E[S] = S_tt + S_mm`. Ordinary least squares of `y` on `w` (the
//! `H1 = S^-1 s` estimate) is therefore biased towards zero by `S_tt (S_tt + S_mm)^-1`, the
//! attenuation of errors-in-variables regression. This estimator removes the bias with the
//! tiltmeter's own noise PSD `S_mm` (given by the user; zero if not): it fits the residual
//!
//! ```text
//! r_k(theta) = s_k - (S_k - S_mm,k) G_k(theta)
//! ```
//!
//! whose expectation is zero at the true parameters whatever the witness noise is (the
//! corrected, or "method of moments", estimator of W. A. Fuller, *Measurement Error Models*,
//! Wiley 1987, sec. 1.2 and 2.2, applied per frequency as in the errors-in-variables
//! frequency-domain identification of R. Pintelon and J. Schoukens, *System Identification:
//! A Frequency Domain Approach*, 2nd ed., Wiley 2012, ch. 7). Its covariance, for Gaussian
//! data averaged over `n` effective Welch segments, is `S_k S_ee,k / n` with
//! `S_ee = <|y - G^T w|^2>` (Isserlis' theorem; J. S. Bendat and A. G. Piersol, *Random Data*,
//! 4th ed., Wiley 2010, sec. 9.3): each residual is whitened with it, so that
//! `chi^2 = sum_k 2 r_k^H C_k^-1 r_k` counts two real degrees of freedom per axis and bin.
//!
//! * **Assumptions**: stationary Gaussian noise; `m` white or known per axis and uncorrelated
//!   between axes; readout noise uncorrelated with the tilt record; spectra smooth over a few
//!   bins; the model's transfer functions exact up to the fitted parameters. Without `S_mm` the
//!   gains are biased low by `S_mm / S` (reported per axis when `S_mm` is given).
//! * **Bins**: every other Welch bin of the band, so that the residuals of neighbouring bins
//!   (correlated by 4/9 for the Hann window) do not count twice; the remaining correlation of
//!   bins two apart (1/36) widens the uncertainties by `sqrt(1 + 2/36)`. Bins where a 1 %
//!   error of the model's frequencies changes the transfer function by more than 1 % (near the
//!   resonances) or where `S - S_mm` is not positive definite are left out.
//! * **Weights**: first from the coherence (`S_ee = S_yy (1 - gamma^2) K / (K - A)` for `K`
//!   segments and `A` axes, model-free), then once more from the residual of the first fit (iteratively reweighted).
//! * **Delay**: started from a scan of the allowed range in steps of `1 / (8 f_max)` with the
//!   gains solved linearly at each step, so that the fit cannot stop in a minimum one phase turn
//!   away; the Welch cross spectrum of a delay `tau` is attenuated by the window's
//!   self-overlap at `tau` ([`super::stats::hann_delay_factor`]), which the model includes.
//! * **What the data cannot constrain** is fixed at its nominal value and reported with the
//!   uncertainty it would have had: a parameter whose linearized (Fisher) uncertainty is at
//!   least its scale (10 % for a gain; one sample for the delay; its error bar from the
//!   parameter file, or 10 % for a parameter the error model calls exact, such as `length.h_m`).
//! * **Uncertainties**: `(J^T J)^-1` of the whitened residuals at the solution, times the
//!   bin-correlation factor, times `sqrt(chi^2 / dof)` when that exceeds 1 (model or noise
//!   misfit: the Birge ratio).

use super::stats::{hann_delay_factor, hann_delay_factor_slope};
use super::SubtractError;
use crate::fit::jacobian::with_value;
use crate::fit::lm::{self, LmOptions, Stop};
use crate::model::{Input, Model, Observable, Request, TiltAxis};
use crate::params::Params;
use crate::spectral::CrossSpectra;
use crate::tf::{plan, Method};
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;
use std::f64::consts::TAU;

/// A bin enters the fit when a 1 % error of the model's frequencies changes its transfer
/// functions by less than this fraction ([`super::predict::sensitivity`]).
pub const FIT_SENSITIVITY: f64 = 0.01;
/// The lowest bin of the default band (DC and the first bins carry the segments' detrending).
pub const FIRST_BIN: usize = 3;
/// The default band ends at this fraction of the Nyquist frequency (above it the record's
/// anti-alias filter, if any, is not in the model).
pub const TOP_FRACTION_OF_NYQUIST: f64 = 0.8;
/// Half-width of the box of a gain, in its logarithm: the gain stays within `[1/2, 2]`.
pub const GAIN_LN_HALF_WIDTH: f64 = std::f64::consts::LN_2;
/// Scale of a gain: not constrained when its uncertainty is 10 % or more.
pub const GAIN_SCALE: f64 = 0.1;
/// Half-widths of the box of a model parameter tried in turn, relative to its nominal value:
/// the first whose edges are physical is used.
pub const KEY_HALF_WIDTHS: [f64; 3] = [0.5, 0.2, 0.1];
/// Scale of a model parameter the error model calls exact, relative to its value.
pub const EXACT_KEY_SCALE: f64 = 0.1;
/// Relative step of the central differences of the transfer functions in a model parameter:
/// `eps^(1/3)`, which balances truncation against rounding.
pub const KEY_STEP_REL: f64 = 6.055_454_452_393_343e-6;
/// Smallest residual PSD used as a weight, relative to the measured PSD: the rounding floor of
/// the spectra, so that a noiseless channel cannot get an infinite weight.
pub const S_EE_FLOOR: f64 = 1e-12;

/// Projected-gradient tolerance of the solver (cost per unit of the box half-width): far
/// below `1 / sigma_u`, so the last step is a negligible fraction of the uncertainty.
pub const LM_GTOL: f64 = 1e-6;

/// Parameter files' sections whose keys `subtract` may fit: everything that shapes the
/// undamped tilt transfer functions.
pub const FREE_SECTIONS: [&str; 5] = ["mass", "inertia", "torsion", "bouncing", "length"];
/// The one environment key that may be fitted.
pub const FREE_ENVIRONMENT_KEY: &str = "environment.g_m_per_s2";

/// What was asked of the fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitRequest {
    /// Model parameters to fit besides the gains and the delay (dotted keys).
    pub keys: Vec<String>,
    /// Fit band (Hz); `None`: from bin [`FIRST_BIN`] to [`TOP_FRACTION_OF_NYQUIST`].
    pub band_hz: Option<(f64, f64)>,
    /// Largest delay magnitude allowed (s).
    pub max_delay_s: f64,
    /// White noise PSD of the tilt record per axis (rad^2/Hz, one-sided), the record's axis
    /// order; zero when unknown.
    pub witness_noise_psd: Vec<f64>,
}

/// How an estimate came out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// `gain.<axis>`, `delay_s` or a parameter-file key.
    pub name: String,
    /// Unit (`1` for a gain).
    pub unit: String,
    /// Value before the fit (1, 0, the parameter file's).
    pub nominal: f64,
    /// Estimate (the nominal value when not constrained).
    pub value: f64,
    /// Standard uncertainty; for a parameter not constrained, the one the data would have
    /// given it (possibly infinite).
    pub sigma: f64,
    /// The scale against which "not constrained" was decided (see the module docs).
    pub scale: f64,
    /// Fitted, on the box, or not constrained.
    pub status: Status,
    /// Box of the fit `(lower, upper)`.
    pub bounds: (f64, f64),
}

/// The outcome of the fit.
#[derive(Debug, Clone)]
pub struct FitReport {
    /// Every parameter asked for: the gains (record's axis order), the delay, the keys.
    pub estimates: Vec<Estimate>,
    /// The fitted parameter set (keys at their estimates).
    pub params: Params,
    /// `chi^2` of the whitened residuals at the solution.
    pub chi2: f64,
    /// Real residuals minus fitted parameters.
    pub dof: usize,
    /// Factor applied to the linearized uncertainties (bin correlation and Birge ratio).
    pub sigma_factor: f64,
    /// Correlation matrix of the fitted parameters, in the order of `fitted`.
    pub correlation: Vec<Vec<f64>>,
    /// Names of the fitted parameters (the rows of `correlation`).
    pub fitted: Vec<String>,
    /// Fit band actually used (Hz).
    pub band_hz: (f64, f64),
    /// Bins used per observable.
    pub bins: Vec<(Observable, usize)>,
    /// Solver iterations over both passes, and why the last pass stopped.
    pub iterations: usize,
    /// Why the last pass stopped.
    pub stop: Stop,
    /// Median over the fit bins of `S_mm / S_ww` per axis: the relative bias of the gains that
    /// the correction removed (0 without a witness noise model).
    pub witness_bias: Vec<f64>,
    /// Notes on bins and parameters.
    pub notes: Vec<String>,
}

/// The spectra of one bin of one observable, prepared for the residuals.
struct Bin {
    /// Index into the fit grid.
    grid: usize,
    /// `s_a = <conj(w_a) y>`.
    s: DVector<Complex64>,
    /// `S - S_mm`.
    sc: DMatrix<Complex64>,
    /// `S` itself, for the residual PSD.
    sww: DMatrix<Complex64>,
    /// `L^-1` with `S = L L^H`.
    l_inv: DMatrix<Complex64>,
    /// `S_yy`.
    syy: f64,
    /// Residual PSD used as the weight.
    see: f64,
}

/// One candidate parameter.
#[derive(Debug, Clone)]
enum Kind {
    Gain(usize),
    Delay,
    Key(String),
}

#[derive(Debug, Clone)]
struct Param {
    kind: Kind,
    name: String,
    unit: String,
    /// Internal variable (ln g, tau, p) at the nominal value.
    nominal: f64,
    /// Half-width of the box around `nominal`, internal units.
    half_width: f64,
    /// Scale in internal units.
    scale: f64,
}

/// Everything the residuals need.
struct Problem<'a> {
    base: &'a Params,
    request: Request,
    n_in: usize,
    freqs: Vec<f64>,
    bins: Vec<(usize, Vec<Bin>)>,
    params: Vec<Param>,
    n_eff: f64,
    segment_s: f64,
    fraction_s: f64,
}

/// Transfer functions `[freq][output][input]` of `params` on `freqs`.
fn transfer(
    params: &Params,
    request: &Request,
    freqs: &[f64],
) -> Result<Vec<Complex64>, SubtractError> {
    let model = Model::new(params).map_err(|e| SubtractError::Params(e.to_string()))?;
    let tf =
        plan(&model, request, Method::Split).map_err(|e| SubtractError::Plan(e.to_string()))?;
    let block = request.outputs.len() * request.inputs.len();
    let mut out = vec![Complex64::new(0.0, 0.0); freqs.len() * block];
    tf.eval_grid_into(freqs, &mut out)?;
    Ok(out)
}

impl Problem<'_> {
    /// The gains (record's axis order) and the delay behind the aligned samples,
    /// `tau - fraction_s` (s), at internal values `theta`.
    fn coupling_at(&self, theta: &[f64]) -> (Vec<f64>, f64) {
        let gains = self
            .params
            .iter()
            .zip(theta)
            .filter(|(p, _)| matches!(p.kind, Kind::Gain(_)))
            .map(|(_, &v)| v.exp())
            .collect();
        let tau = self
            .params
            .iter()
            .position(|p| matches!(p.kind, Kind::Delay))
            .map_or(0.0, |i| theta[i]);
        (gains, tau - self.fraction_s)
    }

    /// The parameter set at internal values `theta` (keys only).
    fn params_at(&self, theta: &[f64]) -> Result<Params, SubtractError> {
        let mut p = self.base.clone();
        for (par, &v) in self.params.iter().zip(theta) {
            if let Kind::Key(key) = &par.kind {
                p = with_value(&p, key, v).map_err(|e| SubtractError::Params(e.to_string()))?;
            }
        }
        Ok(p)
    }

    /// Whitened residuals and their Jacobian in `u` (columns: `free`) at internal values
    /// `theta`.
    fn residuals(
        &self,
        theta: &[f64],
        free: &[usize],
    ) -> Result<(DVector<f64>, DMatrix<f64>), SubtractError> {
        let params = self.params_at(theta)?;
        let h = transfer(&params, &self.request, &self.freqs)?;
        // dH/dp per free key, central differences.
        let mut dh: Vec<Option<Vec<Complex64>>> = vec![None; self.params.len()];
        for &j in free {
            if let Kind::Key(key) = &self.params[j].kind {
                let p = theta[j];
                let step = KEY_STEP_REL * p.abs();
                let at = |v: f64| -> Result<Vec<Complex64>, SubtractError> {
                    let q = with_value(&params, key, v)
                        .map_err(|e| SubtractError::Params(e.to_string()))?;
                    transfer(&q, &self.request, &self.freqs)
                };
                let (hp, hm) = (at(p + step)?, at(p - step)?);
                dh[j] = Some(
                    hp.iter()
                        .zip(&hm)
                        .map(|(a, b)| (a - b) / (2.0 * step))
                        .collect(),
                );
            }
        }
        let rows: usize = self.bins.iter().map(|(_, b)| b.len()).sum::<usize>() * 2 * self.n_in;
        let mut r = DVector::zeros(rows);
        let mut jac = DMatrix::zeros(rows, free.len());
        let (gains, tau_eff) = self.coupling_at(theta);
        let x = tau_eff / self.segment_s;
        let rho = hann_delay_factor(x);
        let drho_dtau = hann_delay_factor_slope(x) / self.segment_s;
        let n_out = self.request.outputs.len();
        let block = n_out * self.n_in;
        let mut row = 0;
        let mut dg = vec![DVector::<Complex64>::zeros(self.n_in); free.len()];
        for (o, bins) in &self.bins {
            for bin in bins {
                let f = self.freqs[bin.grid];
                let w = TAU * f;
                let phase = Complex64::from_polar(rho, -w * tau_eff);
                let hrow = &h[bin.grid * block + o * self.n_in..][..self.n_in];
                let g = DVector::from_fn(self.n_in, |a, _| hrow[a] * gains[a] * phase);
                let weight = (2.0 * self.n_eff / bin.see).sqrt();
                let res = &bin.l_inv * (&bin.s - &bin.sc * &g) * Complex64::new(weight, 0.0);
                for (jj, &j) in free.iter().enumerate() {
                    let par = &self.params[j];
                    let d = &mut dg[jj];
                    d.fill(Complex64::new(0.0, 0.0));
                    match &par.kind {
                        Kind::Gain(a) => d[*a] = g[*a],
                        Kind::Delay => {
                            let factor = Complex64::new(drho_dtau / rho, -w);
                            d.copy_from(&(&g * factor));
                        }
                        Kind::Key(_) => {
                            let dh = dh[j].as_ref().expect("computed for every free key");
                            let drow = &dh[bin.grid * block + o * self.n_in..][..self.n_in];
                            for a in 0..self.n_in {
                                d[a] = drow[a] * gains[a] * phase;
                            }
                        }
                    }
                    let dr = -(&bin.l_inv * (&bin.sc * &*d)) * Complex64::new(weight, 0.0);
                    for a in 0..self.n_in {
                        jac[(row + 2 * a, jj)] = dr[a].re * par.half_width;
                        jac[(row + 2 * a + 1, jj)] = dr[a].im * par.half_width;
                    }
                }
                for a in 0..self.n_in {
                    r[row + 2 * a] = res[a].re;
                    r[row + 2 * a + 1] = res[a].im;
                }
                row += 2 * self.n_in;
            }
        }
        Ok((r, jac))
    }

    /// The coupling `G` of every bin at `theta`, for the residual PSD.
    fn couplings(&self, theta: &[f64]) -> Result<Vec<Vec<DVector<Complex64>>>, SubtractError> {
        let params = self.params_at(theta)?;
        let h = transfer(&params, &self.request, &self.freqs)?;
        let block = self.request.outputs.len() * self.n_in;
        let (gains, tau_eff) = self.coupling_at(theta);
        let rho = hann_delay_factor(tau_eff / self.segment_s);
        Ok(self
            .bins
            .iter()
            .map(|(o, bins)| {
                bins.iter()
                    .map(|bin| {
                        let f = self.freqs[bin.grid];
                        let phase = Complex64::from_polar(rho, -TAU * f * tau_eff);
                        let hrow = &h[bin.grid * block + o * self.n_in..][..self.n_in];
                        DVector::from_fn(self.n_in, |a, _| hrow[a] * gains[a] * phase)
                    })
                    .collect()
            })
            .collect())
    }
}

/// `<|y - G^T w|^2>` from the spectra: `S_yy - 2 Re(sum_a G_a conj(s_a)) + G^H S G`.
pub(crate) fn residual_psd(
    syy: f64,
    s: &DVector<Complex64>,
    sww: &DMatrix<Complex64>,
    g: &DVector<Complex64>,
) -> f64 {
    let cross: Complex64 = g.iter().zip(s.iter()).map(|(g, s)| g * s.conj()).sum();
    let quad = (g.adjoint() * sww * g)[(0, 0)].re;
    syy - 2.0 * cross.re + quad
}

/// Coherence-limited residual PSD `S_yy - s^H S^-1 s` (the Wiener residual of the same data),
/// or `None` when `S` is singular.
pub(crate) fn coherence_residual(
    syy: f64,
    s: &DVector<Complex64>,
    sww: &DMatrix<Complex64>,
) -> Option<f64> {
    let w = sww.clone().lu().solve(s)?;
    Some(residual_psd(syy, s, sww, &w))
}

/// `sqrt(diag((J^T J)^-1))` and the correlation matrix through the SVD of `J`; a parameter in
/// the numerical null space gets an infinite sigma.
fn covariance(jac: &DMatrix<f64>) -> (Vec<f64>, Vec<Vec<f64>>) {
    let cols = jac.ncols();
    if cols == 0 {
        return (Vec::new(), Vec::new());
    }
    let svd = jac.clone().svd(false, true);
    let v_t = svd.v_t.expect("requested");
    let s_max = svd.singular_values.max();
    let mut cov = DMatrix::<f64>::zeros(cols, cols);
    let mut null = vec![false; cols];
    for (i, &s) in svd.singular_values.iter().enumerate() {
        if s <= s_max * crate::fit::RANK_TOL || s == 0.0 {
            for j in 0..cols {
                if v_t[(i, j)].abs() > crate::fit::RANK_TOL {
                    null[j] = true;
                }
            }
            continue;
        }
        for a in 0..cols {
            for b in 0..cols {
                cov[(a, b)] += v_t[(i, a)] * v_t[(i, b)] / (s * s);
            }
        }
    }
    let sigma: Vec<f64> = (0..cols)
        .map(|j| {
            if null[j] {
                f64::INFINITY
            } else {
                cov[(j, j)].sqrt()
            }
        })
        .collect();
    let corr = (0..cols)
        .map(|a| {
            (0..cols)
                .map(|b| {
                    if null[a] || null[b] {
                        f64::NAN
                    } else {
                        cov[(a, b)] / (sigma[a] * sigma[b])
                    }
                })
                .collect()
        })
        .collect();
    (sigma, corr)
}

/// Checks the keys of `--fit` and builds their parameters.
fn key_params(base: &Params, keys: &[String]) -> Result<Vec<Param>, SubtractError> {
    let fields = base.fields();
    let allowed = allowed_keys(base).join(", ");
    let sigmas = base.effective_uncertainties();
    let mut out: Vec<Param> = Vec::new();
    for key in keys {
        let Some(field) = fields.iter().find(|f| f.key == key) else {
            return Err(SubtractError::UnknownKey {
                key: key.clone(),
                allowed,
            });
        };
        if !allowed_keys(base).contains(&field.key) {
            return Err(SubtractError::NotFreeKey {
                key: key.clone(),
                reason: not_free_reason(field.key, field.value),
                allowed,
            });
        }
        if out.iter().any(|p| &p.name == key) {
            return Err(SubtractError::DuplicateKey { key: key.clone() });
        }
        let p0 = field.value;
        let half_width = KEY_HALF_WIDTHS
            .iter()
            .map(|h| h * p0.abs())
            .find(|&hw| {
                [p0 - hw, p0 + hw].iter().all(|&edge| {
                    with_value(base, key, edge).is_ok() && edge.signum() == p0.signum()
                })
            })
            .ok_or_else(|| SubtractError::NotFreeKey {
                key: key.clone(),
                reason: format!(
                    "even +/-{} % of its value {} {} reaches non-physical values",
                    KEY_HALF_WIDTHS[KEY_HALF_WIDTHS.len() - 1] * 100.0,
                    p0,
                    field.unit
                ),
                allowed: allowed.clone(),
            })?;
        let rel = sigmas
            .iter()
            .find(|u| u.key == *key)
            .map_or(0.0, |u| u.rel_sigma);
        let scale = if rel > 0.0 { rel } else { EXACT_KEY_SCALE } * p0.abs();
        out.push(Param {
            kind: Kind::Key(key.clone()),
            name: key.clone(),
            unit: field.unit.to_string(),
            nominal: p0,
            half_width,
            scale,
        });
    }
    Ok(out)
}

/// Keys `--fit` accepts for `params`: those of [`FREE_SECTIONS`] and [`FREE_ENVIRONMENT_KEY`]
/// with a non-zero value.
pub fn allowed_keys(params: &Params) -> Vec<&'static str> {
    params
        .fields()
        .iter()
        .filter(|f| {
            let section = f.key.split('.').next().unwrap_or("");
            (FREE_SECTIONS.contains(&section) || f.key == FREE_ENVIRONMENT_KEY) && f.value != 0.0
        })
        .map(|f| f.key)
        .collect()
}

fn not_free_reason(key: &str, value: f64) -> String {
    let section = key.split('.').next().unwrap_or("");
    match section {
        "loss" | "viscous" => "damping is not estimated by subtract (its transfer functions are \
                               fitted with the model's damping held fixed)"
            .to_string(),
        "environment" => "it does not enter the tilt transfer functions".to_string(),
        _ if value == 0.0 => "its nominal value is 0, so it has no scale to fit".to_string(),
        _ => "it is not a parameter of the tilt transfer functions".to_string(),
    }
}

/// The bins of the fit band (every other Welch bin from the first) and their frequencies.
fn band_bins(
    freqs_hz: &[f64],
    band_hz: Option<(f64, f64)>,
) -> Result<((f64, f64), Vec<usize>), SubtractError> {
    let n = freqs_hz.len();
    let nyquist_bin = n - 1;
    let (lo, hi) = match band_hz {
        None => (
            FIRST_BIN,
            ((TOP_FRACTION_OF_NYQUIST * nyquist_bin as f64).floor() as usize).max(FIRST_BIN),
        ),
        Some((flo, fhi)) => {
            let lo = freqs_hz.partition_point(|&f| f < flo).max(1);
            let hi = freqs_hz.partition_point(|&f| f <= fhi).saturating_sub(1);
            (lo, hi.min(nyquist_bin - 1))
        }
    };
    if hi < lo {
        return Err(SubtractError::Band {
            what: "fit".into(),
            band_hz: band_hz.unwrap_or((0.0, 0.0)),
            grid_hz: (freqs_hz[1], freqs_hz[nyquist_bin]),
        });
    }
    let bins: Vec<usize> = (lo..=hi).step_by(2).collect();
    Ok(((freqs_hz[lo], freqs_hz[bins[bins.len() - 1]]), bins))
}

/// Welch cross spectra of the training stretch: the tilt axes, then the observables.
#[derive(Debug, Clone, Copy)]
pub struct Training<'a> {
    /// The spectral matrices.
    pub spectra: &'a CrossSpectra,
    /// Sample rate (Hz).
    pub fs_hz: f64,
    /// Welch segment length (samples).
    pub segment_len: usize,
    /// Effective number of independent averages ([`super::stats::effective_averages`]).
    pub n_eff: f64,
    /// Segments averaged.
    pub n_segments: usize,
}

/// The whole fit: see the module docs. `fraction_s` is the known part of the delay from the
/// alignment ([`super::align::Alignment::fraction_s`]).
pub fn fit(
    base: &Params,
    axes: &[TiltAxis],
    outputs: &[Observable],
    training: &Training,
    fraction_s: f64,
    req: &FitRequest,
) -> Result<FitReport, SubtractError> {
    let spectra = training.spectra;
    let n_eff = training.n_eff;
    let n_in = axes.len();
    let segment_s = training.segment_len as f64 / training.fs_hz;
    let dt = 1.0 / training.fs_hz;
    let bin_variance_factor = super::stats::bin_variance_factor(training.segment_len, 2);
    let mut params: Vec<Param> = axes
        .iter()
        .enumerate()
        .map(|(a, axis)| Param {
            kind: Kind::Gain(a),
            name: format!("gain.{}", axis.name()),
            unit: "1".into(),
            nominal: 0.0,
            half_width: GAIN_LN_HALF_WIDTH,
            scale: GAIN_SCALE,
        })
        .collect();
    params.push(Param {
        kind: Kind::Delay,
        name: "delay_s".into(),
        unit: "s".into(),
        nominal: 0.0,
        half_width: req.max_delay_s,
        scale: dt,
    });
    params.extend(key_params(base, &req.keys)?);
    let mut notes = Vec::new();

    let (band, grid_bins) = band_bins(&spectra.freqs_hz, req.band_hz)?;
    let freqs: Vec<f64> = grid_bins.iter().map(|&k| spectra.freqs_hz[k]).collect();
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: axes.iter().map(|&a| Input::Tilt(a)).collect(),
    };
    let h0 = transfer(base, &request, &freqs)?;
    let shifted: Vec<f64> = freqs
        .iter()
        .map(|f| f * (1.0 + super::predict::FREQ_ERROR_REL))
        .collect();
    let h1 = transfer(base, &request, &shifted)?;
    let block = outputs.len() * n_in;
    let n_ch = spectra.n_channels;
    let mut bins: Vec<(usize, Vec<Bin>)> = Vec::new();
    let mut counts = Vec::new();
    for (o, &obs) in outputs.iter().enumerate() {
        let yc = n_in + o;
        let structural_zero = (0..freqs.len()).all(|g| {
            h0[g * block + o * n_in..][..n_in]
                .iter()
                .all(|z| z.norm() == 0.0)
        });
        if structural_zero {
            notes.push(format!(
                "{}: not driven by the record's tilt axes (its transfer functions from them are \
                 exactly 0); left out of the fit",
                obs.name()
            ));
            counts.push((obs, 0));
            continue;
        }
        let mut list = Vec::new();
        let (mut sensitive, mut singular) = (0, 0);
        for (g, &k) in grid_bins.iter().enumerate() {
            let row = &h0[g * block + o * n_in..][..n_in];
            let row1 = &h1[g * block + o * n_in..][..n_in];
            let sensitivity = super::predict::sensitivity(row, row1);
            if sensitivity.is_nan() || sensitivity >= FIT_SENSITIVITY {
                sensitive += 1;
                continue;
            }
            let m = spectra.matrix(k);
            let sww = DMatrix::from_fn(n_in, n_in, |a, b| m[a * n_ch + b]);
            let s = DVector::from_fn(n_in, |a, _| m[a * n_ch + yc]);
            let syy = m[yc * n_ch + yc].re;
            let mut sc = sww.clone();
            for a in 0..n_in {
                sc[(a, a)] -= req.witness_noise_psd[a];
            }
            let chol = sww.clone().cholesky();
            let positive = sc.clone().cholesky().is_some();
            let (Some(chol), true) = (chol, positive && syy > 0.0) else {
                singular += 1;
                continue;
            };
            let l_inv = chol
                .l()
                .solve_lower_triangular(&DMatrix::identity(n_in, n_in))
                .expect("a Cholesky factor is invertible");
            let coh = coherence_residual(syy, &s, &sww).unwrap_or(syy);
            let k_seg = training.n_segments as f64;
            let n_fac = if k_seg > n_in as f64 {
                k_seg / (k_seg - n_in as f64)
            } else {
                1.0
            };
            let see = (coh * n_fac).clamp(S_EE_FLOOR * syy, syy.max(S_EE_FLOOR * syy));
            list.push(Bin {
                grid: g,
                s,
                sc,
                sww,
                l_inv,
                syy,
                see,
            });
        }
        if sensitive > 0 {
            notes.push(format!(
                "{}: {sensitive} bin(s) of the band left out where a 1 % error of the model's \
                 frequencies changes the transfer function by 1 % or more (resonances)",
                obs.name()
            ));
        }
        if singular > 0 {
            notes.push(format!(
                "{}: {singular} bin(s) left out where the tilt record's spectral matrix minus its \
                 own noise is not positive definite (no tilt above the tiltmeter's noise)",
                obs.name()
            ));
        }
        counts.push((obs, list.len()));
        if !list.is_empty() {
            bins.push((o, list));
        }
    }
    if bins.is_empty() {
        return Err(SubtractError::NoFitBins { band_hz: band });
    }
    let witness_bias = (0..n_in)
        .map(|a| {
            let mut r: Vec<f64> = bins
                .iter()
                .flat_map(|(_, b)| b.iter())
                .map(|b| req.witness_noise_psd[a] / b.sww[(a, a)].re)
                .collect();
            median(&mut r)
        })
        .collect();
    let problem = Problem {
        base,
        request,
        n_in,
        freqs,
        bins,
        params,
        n_eff,
        segment_s,
        fraction_s,
    };
    let mut theta: Vec<f64> = problem.params.iter().map(|p| p.nominal).collect();
    scan_delay(&problem, &h0, &mut theta, &mut notes);

    let all: Vec<usize> = (0..problem.params.len()).collect();
    let opts = LmOptions {
        gtol: LM_GTOL,
        max_iterations: 200,
    };
    let mut iterations = 0;
    let mut stop = Stop::Gradient;
    let mut problem = problem;
    let mut free = constrained(&problem, &theta, &all)?;
    for pass in 0..2 {
        for &j in &all {
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
            let out = lm::minimize(u0, 1.0, &opts, |u| problem.residuals(&to_theta(u), &free))?;
            theta = to_theta(&out.u);
            iterations += out.iterations;
            stop = out.stop;
        }
        if pass == 0 {
            // Weights from the residual of the first fit.
            let g = problem.couplings(&theta)?;
            for ((_, bins), gs) in problem.bins.iter_mut().zip(&g) {
                for (bin, g) in bins.iter_mut().zip(gs) {
                    let see = residual_psd(bin.syy, &bin.s, &bin.sww, g);
                    bin.see = see.clamp(S_EE_FLOOR * bin.syy, f64::INFINITY);
                }
            }
            free = constrained(&problem, &theta, &free)?;
        }
    }
    let (r, jac) = problem.residuals(&theta, &free)?;
    let chi2 = r.norm_squared();
    let dof = r.len().saturating_sub(free.len()).max(1);
    let birge = (chi2 / dof as f64).max(1.0).sqrt();
    // chi^2 / dof has a standard deviation of sqrt(2 / dof); beyond 5 of them the misfit is not
    // noise, and the Birge scaling cannot stand for it.
    if chi2 / dof as f64 > 1.0 + 5.0 * (2.0 / dof as f64).sqrt() {
        notes.push(format!(
            "chi^2/dof = {:.3} for {dof} dof: the model does not describe the data within their \
             noise; the estimates may carry systematic errors that their uncertainties (scaled by \
             {birge:.3}) do not include (a channel with almost no noise, a wrong fit band, a \
             model parameter that should be fitted)",
            chi2 / dof as f64
        ));
    }
    let sigma_factor = bin_variance_factor.sqrt() * birge;
    let (sig_u, correlation) = covariance(&jac);
    let (_, jac_all) = problem.residuals(&theta, &all)?;
    let (sig_all, _) = covariance(&jac_all);
    let params_fit = problem.params_at(&theta)?;
    let estimates = problem
        .params
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let (lo, hi) = (p.nominal - p.half_width, p.nominal + p.half_width);
            let position = free.iter().position(|&f| f == j);
            let (status, sigma_int) = match position {
                Some(jj) => {
                    let u = (theta[j] - p.nominal) / p.half_width;
                    let s = sig_u[jj] * p.half_width * sigma_factor;
                    if u.abs() >= 1.0 - 1e-9 {
                        (Status::AtBound, s)
                    } else {
                        (Status::Fitted, s)
                    }
                }
                None => (
                    Status::NotConstrained,
                    sig_all[j] * p.half_width * sigma_factor,
                ),
            };
            match p.kind {
                Kind::Gain(_) => {
                    let g = theta[j].exp();
                    Estimate {
                        name: p.name.clone(),
                        unit: p.unit.clone(),
                        nominal: 1.0,
                        value: g,
                        sigma: g * sigma_int,
                        scale: p.scale,
                        status,
                        bounds: (lo.exp(), hi.exp()),
                    }
                }
                _ => Estimate {
                    name: p.name.clone(),
                    unit: p.unit.clone(),
                    nominal: p.nominal,
                    value: theta[j],
                    sigma: sigma_int,
                    scale: p.scale,
                    status,
                    bounds: (lo, hi),
                },
            }
        })
        .collect();
    Ok(FitReport {
        estimates,
        params: params_fit,
        chi2,
        dof,
        sigma_factor,
        correlation,
        fitted: free
            .iter()
            .map(|&j| problem.params[j].name.clone())
            .collect(),
        band_hz: band,
        bins: counts,
        iterations,
        stop,
        witness_bias,
        notes,
    })
}

/// The members of `candidates` whose Fisher uncertainty at `theta` (all candidates free
/// together) is below their scale.
fn constrained(
    problem: &Problem,
    theta: &[f64],
    candidates: &[usize],
) -> Result<Vec<usize>, SubtractError> {
    let mut free = candidates.to_vec();
    // Dropping one parameter can only shrink the others' uncertainties: drop the worst one at
    // a time until every remaining one is constrained.
    loop {
        if free.is_empty() {
            return Ok(free);
        }
        let (_, jac) = problem.residuals(theta, &free)?;
        let (sig, _) = covariance(&jac);
        let worst = free
            .iter()
            .enumerate()
            .map(|(jj, &j)| {
                (
                    jj,
                    sig[jj] * problem.params[j].half_width / problem.params[j].scale,
                )
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .expect("not empty");
        if worst.1 < 1.0 {
            return Ok(free);
        }
        free.remove(worst.0);
    }
}

/// Scans the delay over its box in steps of `1 / (8 f_max)`, the gains solved linearly at each
/// step (keys nominal, first-pass weights), and starts `theta` at the best step.
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
                let f = problem.freqs[bin.grid];
                let phase = Complex64::from_polar(rho, -TAU * f * tau_eff);
                let hrow = &h0[bin.grid * block + o * n_in..][..n_in];
                let weight = Complex64::new((2.0 * problem.n_eff / bin.see).sqrt(), 0.0);
                let z0 = &bin.l_inv * &bin.s * weight;
                let v: Vec<DVector<Complex64>> = (0..n_in)
                    .map(|a| &bin.l_inv * bin.sc.column(a) * (hrow[a] * phase * weight))
                    .collect();
                z0_sq += z0.norm_squared();
                for a in 0..n_in {
                    rhs[a] += v[a].dotc(&z0).re;
                    for b in 0..n_in {
                        normal[(a, b)] += v[a].dotc(&v[b]).re;
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
                         convention for this axis may be opposite to the model's (check the \
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
