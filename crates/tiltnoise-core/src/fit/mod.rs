//! Constrained least-squares fit of chosen parameters to measured normal-mode frequencies (the
//! paper's validation: "a least square fit, constrained within the experimental error bars,
//! then adjusts the mechanical parameters in order to best match the observed normal mode
//! frequencies", Table II), and to measured mode visibilities ([`visibility`]: the signed ratio
//! of a mode's components in two observables), which is what determines the `[asymmetry]`
//! offsets of the pendulum as built.
//!
//! * **Variables.** Each free parameter `p` is fitted in the scaled variable
//!   `u = (p - p0) / sigma_p`, with `p0` the nominal value and `sigma_p = rel_sigma |p0|` its
//!   error bar from [`crate::mc::uncertainties`] (the Monte Carlo's error model, overridable in
//!   the parameter file), or the absolute `sigma` of an `[asymmetry]` offset, whose nominal value
//!   is 0 (its box is then absolute too: `|p - p0| <= n sigma`). Parameters without an error
//!   bar (g, h, loss angles, and the offsets unless the file gives them one) cannot be free.
//! * **Objective.** `chi^2 = sum_k ((f_k(p) - f_k,meas) / sigma_k)^2` over the measured modes,
//!   mode identity by label (the rank, sorted frequencies, as in Table II, for the symmetric
//!   pendulum; see [`crate::modes`] for the pendulum as built), plus `sum_i ((rho_i(p) -
//!   rho_i,meas) / sigma_i)^2` over the measured visibilities `rho_i`. "Constrained within the error
//!   bars" is read literally: a hard box `|u| <= n` (`n` = [`FitConfig::bound_sigmas`], 1 by
//!   default). Optionally ([`FitConfig::prior`]) the Gaussian prior `sum u^2` is added, which
//!   turns the fit into a maximum a-posteriori estimate that also works for parameters the data
//!   cannot pin down; the box still applies.
//! * **Solver.** Levenberg-Marquardt with an active set on the box ([`lm`]), analytic Jacobian
//!   from eigenvalue and eigenvector perturbation theory ([`jacobian`]).
//! * **Start.** The nominal parameters, except for the free `[asymmetry]` offsets: at the
//!   symmetric point a frequency's derivative with an offset along x vanishes (the mirror
//!   symmetry makes every frequency even in it), so the data cannot tell its sign there and a
//!   fit to frequencies alone would stay put. Each free offset starts a quarter of its box away
//!   from 0, on each side ([`START_FRACTION`]); every combination of sides is a start (up to
//!   [`MAX_SIGN_STARTS`] of them, beyond that all offsets on one side, then on the other), and
//!   the solution with the least objective is kept.
//! * **Uncertainties.** Linearized covariance `(J^T J)^-1` of the scaled variables at the
//!   solution (`J` = weighted Jacobian, with the prior rows when the prior is on), over the free
//!   parameters *not* on a bound; a parameter on a bound is flagged and has no sigma (the
//!   linearization does not describe a truncated distribution). Not rescaled by `chi^2 / dof`.
//!   The correlations are those of that covariance ([`FitResult::correlation`]).
//! * **Poorly constrained** ("prior-dominated"): a free parameter whose data-only sigma,
//!   `sqrt((J_d^T J_d)^-1_ii)` in units of its error bar, is >= 1: the measured frequencies
//!   determine it no better than its error bar did. The singular values `s < 1` of the data
//!   Jacobian `J_d` and their right singular vectors are reported as the weak directions (a
//!   combination `v . u` is determined to `1 / s` error bars).
//!
//! Pure numerics: depends on `params`, `model`, `modes`, `mc` (the error model); no I/O.

pub mod jacobian;
pub mod lm;
pub mod measured;
pub mod peaks;
pub mod visibility;

pub use measured::{Measured, MeasuredMode, SigmaSource};
pub use visibility::{MeasuredVisibility, Visibilities};

use crate::cancel::{Cancel, Cancelled};
use crate::error::{ParamError, Shown};
use crate::option_key::OptionKey;
use crate::params::Params;
use crate::repeats::{refuse_repeats, Repeated};
use nalgebra::{DMatrix, DVector};

/// Default free parameters: for each mode, or pair of nearly degenerate modes, the parameter
/// its frequency is most sensitive to per error bar (`docs/fit.md` has the table):
/// k_a (nu_1), k_b (nu_2), kappa_a and kappa_b (nu_7, nu_8), Z (the crossbar swing pair
/// nu_3, nu_4), I^a_22 (nu_4 alone: the nu_3/nu_4 splitting), Z_b (the test-mass swing pair
/// nu_5, nu_6) and d (nu_6 alone, through the crossbar's centre-of-mass offset: the nu_5/nu_6
/// splitting). Eight parameters for eight modes with linearly independent sensitivity
/// patterns, so the weighted Jacobian of the Table II example has full rank.
pub const DEFAULT_FREE: [&str; 8] = [
    "torsion.k_a_n_m_per_rad",
    "torsion.k_b_n_m_per_rad",
    "bouncing.kappa_a_n_per_m",
    "bouncing.kappa_b_n_per_m",
    "length.z_m",
    "inertia.a22_kg_m2",
    "length.z_b_m",
    "length.d_m",
];

/// Projected-gradient tolerance of the solver, in units of `chi^2 / 2` per error bar.
pub const GTOL: f64 = 1e-10;
/// Iteration limit of the solver.
pub const MAX_ITERATIONS: usize = 200;

/// Where a free `[asymmetry]` offset starts, as a fraction of its box half-width, on either
/// side of 0 (module docs): far enough from the symmetric point for the frequencies' derivative
/// to tell the sides apart, well inside the box.
pub const START_FRACTION: f64 = 0.25;

/// The most starts made of the combinations of sides of the free offsets (4 offsets); with
/// more offsets, two starts (every offset on the positive side, every one on the negative).
pub const MAX_SIGN_STARTS: usize = 16;

/// Singular values of the weighted Jacobian below `s_max * RANK_TOL` count as zero when
/// inverting `J^T J` (sigma reported infinite): `RANK_TOL` is `eps` times a generous bound on
/// the matrix dimension, the usual numerical-rank threshold.
pub const RANK_TOL: f64 = 16.0 * f64::EPSILON;

/// Most sweeps of the SVD of a Jacobian (of at most a few dozen rows by eight columns, whose
/// bidiagonal QR converges in about two sweeps per singular value): a bound, so that an SVD
/// that does not converge is an error, never a loop without end.
pub const SVD_MAX_ITERATIONS: usize = 1000;

/// What to fit and how.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FitConfig {
    /// Dotted keys of the free parameters (each once, each with an error bar).
    pub free: Vec<String>,
    /// Half-width of the box in error bars, `|p - p0| <= bound_sigmas sigma_p` (finite, > 0).
    pub bound_sigmas: f64,
    /// Add the Gaussian prior `sum ((p - p0) / sigma_p)^2` to the objective.
    pub prior: bool,
    /// Polled before each evaluation of the model's frequencies and Jacobian (not part of a
    /// stored configuration: a restored one is never cancelled).
    #[serde(skip)]
    pub cancel: Cancel,
}

impl Default for FitConfig {
    fn default() -> FitConfig {
        FitConfig {
            free: DEFAULT_FREE.iter().map(|k| k.to_string()).collect(),
            bound_sigmas: 1.0,
            prior: false,
            cancel: Cancel::never(),
        }
    }
}

/// Which bound a parameter ended on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Bound {
    /// `p = p0 - n sigma_p`.
    Lower,
    /// `p = p0 + n sigma_p`.
    Upper,
}

impl Bound {
    /// `lower` or `upper`, as in the fit's files.
    pub fn name(self) -> &'static str {
        match self {
            Bound::Lower => "lower",
            Bound::Upper => "upper",
        }
    }
}

/// One fitted parameter.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FittedParam {
    /// Dotted key.
    pub key: String,
    /// SI unit.
    pub unit: String,
    /// Nominal value p0.
    pub nominal: f64,
    /// Fitted value.
    pub fitted: f64,
    /// Error bar sigma_p = rel_sigma |p0|, or the absolute sigma of an offset (the prior sigma).
    pub prior_sigma: f64,
    /// Linearized posterior sigma at the solution; `None` on a bound, infinite if the
    /// parameter lies in the null space of the Jacobian.
    pub fitted_sigma: Option<f64>,
    /// The bound the parameter ended on, if any.
    pub at_bound: Option<Bound>,
    /// Data-only sigma in units of the error bar, `sqrt((J_d^T J_d)^-1_ii)`.
    pub data_sigma_rel: f64,
    /// `data_sigma_rel >= 1`: the data determine it no better than its error bar.
    pub poorly_constrained: bool,
}

/// One measured mode at the nominal and the fitted parameters.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ModeFit {
    /// The measurement.
    pub measured: MeasuredMode,
    /// Model frequency at the nominal parameters (Hz).
    pub nominal_hz: f64,
    /// Model frequency at the fitted parameters (Hz).
    pub fitted_hz: f64,
}

impl ModeFit {
    /// Fitted minus measured (Hz).
    pub fn residual_hz(&self) -> f64 {
        self.fitted_hz - self.measured.frequency_hz
    }

    /// Fitted minus measured, in measurement sigmas.
    pub fn residual_sigmas(&self) -> f64 {
        self.residual_hz() / self.measured.sigma_hz
    }
}

/// One measured visibility at the nominal and the fitted parameters.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VisibilityFit {
    /// The measurement.
    pub measured: MeasuredVisibility,
    /// Model ratio at the nominal parameters (NaN where the model's mode has no component in
    /// the reference there, e.g. the symmetric pendulum's nu_6 in Y).
    pub nominal: f64,
    /// Model ratio at the fitted parameters.
    pub fitted: f64,
}

impl VisibilityFit {
    /// Fitted minus measured.
    pub fn residual(&self) -> f64 {
        self.fitted - self.measured.ratio
    }

    /// Fitted minus measured, in measurement sigmas.
    pub fn residual_sigmas(&self) -> f64 {
        self.residual() / self.measured.sigma
    }
}

/// A combination of free parameters the data determine poorly.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WeakDirection {
    /// Singular value of the data Jacobian (< 1): the combination is known to `1 / s` error bars.
    pub singular_value: f64,
    /// Unit vector in scaled variables, one component per free parameter (key, component).
    pub direction: Vec<(String, f64)>,
}

/// The outcome of a fit.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct FitResult {
    /// The free parameters, in the order given.
    pub params: Vec<FittedParam>,
    /// The measured modes, by rank.
    pub modes: Vec<ModeFit>,
    /// The measured visibilities, in the order of [`Visibilities::items`] (empty when none).
    pub visibilities: Vec<VisibilityFit>,
    /// Correlation matrix of the fitted parameters (order of `params`), from the linearized
    /// covariance; rows and columns of a parameter on a bound are NaN (no covariance there).
    pub correlation: Vec<Vec<f64>>,
    /// The starting point the solution was reached from (parameter values, order of `params`).
    pub start: Vec<f64>,
    /// The full fitted parameter set.
    pub fitted_params: Params,
    /// Data chi^2 at the nominal parameters; NaN when a visibility's reference observable does
    /// not see its mode there (the symmetric pendulum's nu_2 in Y, say).
    pub chi2_nominal: f64,
    /// Data chi^2 at the solution.
    pub chi2: f64,
    /// Prior term `sum u^2` at the solution (0 when the prior is off).
    pub prior_term: f64,
    /// Degrees of freedom: measurements (modes and visibilities) minus free parameters (box
    /// only), or measurements (with the prior, which adds one pseudo-measurement per
    /// parameter).
    pub dof: usize,
    /// Singular values of the data Jacobian in scaled variables, largest first.
    pub singular_values: Vec<f64>,
    /// Singular directions with `s < 1`.
    pub weak_directions: Vec<WeakDirection>,
    /// Solver summary.
    pub iterations: usize,
    /// Model evaluations (frequencies plus Jacobian).
    pub evaluations: usize,
    /// Why the solver stopped.
    pub stop: lm::Stop,
    /// Projected gradient of `chi^2 / 2` at the solution (per error bar).
    pub projected_gradient: f64,
    /// The configuration used.
    pub config: FitConfig,
}

/// A fit that cannot be run.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// Cancelled through [`FitConfig::cancel`].
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    /// A measured-frequency or visibility file that cannot be opened or read (its reason
    /// kept whole, so that a missing file stays a missing file to the caller).
    #[error("{what} {origin}: {reason}")]
    Read {
        /// What the file holds: `measured frequencies` or `visibilities`.
        what: &'static str,
        /// The file, as given.
        origin: String,
        /// What the operating system said.
        reason: std::io::Error,
    },
    /// A malformed visibility file, or a visibility the model cannot form.
    #[error("visibilities {origin}: {message}")]
    Visibility {
        /// File (and line), or the ratio.
        origin: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A malformed measured-frequency file.
    #[error("measured frequencies {origin}: {message}")]
    Measured {
        /// File (and line).
        origin: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A measured-frequency file, or one of its lines, over its size limit
    /// ([`crate::limits::MAX_SETTINGS_FILE_BYTES`], [`crate::limits::MAX_LINE_BYTES`]).
    #[error(transparent)]
    TooLarge(#[from] crate::limits::LimitError),
    /// No free parameter.
    #[error("fit: no free parameter; give at least one with {}", OptionKey::FREE.given("KEY,..."))]
    NoFree,
    /// More free parameters than measurements.
    #[error(
        "fit: {free} free parameters but only {modes} measured modes and {visibilities} \
         visibilities; at most as many free parameters as measurements are allowed (drop some \
         from {} or measure more)",
        OptionKey::FREE
    )]
    TooManyFree {
        /// Number of free parameters.
        free: usize,
        /// Number of measured mode frequencies.
        modes: usize,
        /// Number of measured visibilities.
        visibilities: usize,
    },
    /// A free key that is not a parameter.
    #[error(
        "fit: unknown parameter key `{}` in {}; allowed keys: {allowed}",
        Shown(.key),
        OptionKey::FREE
    )]
    UnknownKey {
        /// The key given.
        key: String,
        /// The keys that can be free.
        allowed: String,
    },
    /// A free key whose parameter has no error bar.
    #[error(
        "fit: parameter `{key}` in {} is exact (error bar 0), so it cannot move; allowed \
         keys (with an error bar): {allowed}",
        OptionKey::FREE
    )]
    ExactKey {
        /// The key given.
        key: String,
        /// The keys that can be free.
        allowed: String,
    },
    /// The same key twice in the free parameters.
    #[error(transparent)]
    Repeated(#[from] Repeated),
    /// A box width that is not a positive finite number.
    #[error("fit: {} is not allowed: must be finite and > 0", OptionKey::BOUND_SIGMAS.given(.value))]
    BoundSigmas {
        /// The value given.
        value: f64,
    },
    /// The box reaches non-physical values of a parameter.
    #[error(
        "fit: the box {lower:e}..{upper:e} {unit} of `{key}` (nominal +/- {n} error bars) reaches \
         non-physical values ({reason}); reduce {} or the parameter's error bar",
        OptionKey::BOUND_SIGMAS
    )]
    BoxNotPhysical {
        /// The parameter.
        key: String,
        /// Box edges.
        lower: f64,
        /// Box edges.
        upper: f64,
        /// Unit.
        unit: String,
        /// Box half-width in error bars.
        n: f64,
        /// The validation error at the edge.
        reason: String,
    },
    /// The nominal or a derived parameter set is not physical.
    #[error(transparent)]
    Params(ParamError),
    /// A number the fit derived (a fitted value, a sigma, a correlation, chi^2, ...) is not
    /// finite; nothing is printed or written ([`check_finite`]).
    #[error(
        "fit: the {quantity} is {}: not finite, so nothing is printed or written (the data \
         may not determine it, or the error bars span too many orders of magnitude; fit fewer \
         parameters with {})",
        crate::num_text::Num(*.value),
        OptionKey::FREE
    )]
    NotFinite {
        /// What it is (with the parameter, mode or row).
        quantity: String,
        /// Its value.
        value: f64,
    },
}

/// Weighted residuals, their Jacobian in `u`, the eight model frequencies (Hz) and the model's
/// visibilities.
type Evaluation = (DVector<f64>, DMatrix<f64>, [f64; 8], Vec<f64>);

/// One free parameter's setup.
struct Free {
    key: String,
    unit: String,
    nominal: f64,
    sigma: f64,
}

/// Fits `config.free` of `params` to the measured frequencies `measured` (see the module docs).
pub fn fit(
    params: &Params,
    measured: &Measured,
    config: &FitConfig,
) -> Result<FitResult, FitError> {
    fit_with_visibilities(params, measured, &Visibilities::none(), config)
}

/// The starting points in scaled variables (module docs): 0 for every parameter but the free
/// offsets, which start at `+/- START_FRACTION n` in every combination of sides.
fn starts(free: &[Free], n: f64) -> Vec<DVector<f64>> {
    let offsets: Vec<usize> = (0..free.len())
        .filter(|&j| crate::params::uncertainty::is_absolute_key(&free[j].key))
        .collect();
    let delta = START_FRACTION * n;
    let at = |signs: &dyn Fn(usize) -> f64| {
        let mut u = DVector::zeros(free.len());
        for (i, &j) in offsets.iter().enumerate() {
            u[j] = delta * signs(i);
        }
        u
    };
    if offsets.is_empty() {
        return vec![DVector::zeros(free.len())];
    }
    if 1usize << offsets.len().min(usize::BITS as usize - 1) > MAX_SIGN_STARTS {
        return vec![at(&|_| 1.0), at(&|_| -1.0)];
    }
    (0..1usize << offsets.len())
        .map(|bits| at(&|i| if bits >> i & 1 == 1 { -1.0 } else { 1.0 }))
        .collect()
}

/// Fits `config.free` of `params` to the measured frequencies `measured` and visibilities
/// `visibilities` together (see the module docs).
pub fn fit_with_visibilities(
    params: &Params,
    measured: &Measured,
    visibilities: &Visibilities,
    config: &FitConfig,
) -> Result<FitResult, FitError> {
    let vis = &visibilities.items;
    let free = check_config(params, (measured.modes.len(), vis.len()), config)?;
    let n = config.bound_sigmas;
    let problem = Problem {
        params,
        measured,
        vis,
        keys: free.iter().map(|f| f.key.clone()).collect(),
        free: &free,
        ranks: measured.modes.iter().map(|x| x.mode - 1).collect(),
        data_rows: measured.modes.len() + vis.len(),
        config,
    };
    let data_rows = problem.data_rows;
    let ranks = &problem.ranks;
    let nominal = problem.at(&DVector::zeros(free.len()))?;
    let nominal_model = crate::model::Model::new(&nominal).map_err(FitError::Params)?;
    let nominal_freqs = jacobian::evaluate(&nominal, &[], &[])?.frequencies_hz;
    let nominal_ratios = nominal_ratios(&nominal_model, vis);
    let chi2_nominal = problem.chi2(&nominal_freqs, &nominal_ratios);
    let (out, u_start, evaluations) = problem.best_of_starts(n)?;
    let fitted_params = problem.at(&out.u)?;
    let (_, _, fitted_freqs, fitted_ratios) = problem.residuals(&out.u)?;

    let data_jac = out.jac.rows(0, data_rows).into_owned();
    let (params_out, correlation) = uncertainties(&free, &out, &data_jac, n)?;
    let (singular_values, weak_directions) = weak_directions(&data_jac, &problem.keys)?;
    let chi2 = out.r.rows(0, data_rows).norm_squared();
    let result = FitResult {
        params: params_out,
        modes: measured
            .modes
            .iter()
            .zip(ranks)
            .map(|(x, &k)| ModeFit {
                measured: x.clone(),
                nominal_hz: nominal_freqs[k],
                fitted_hz: fitted_freqs[k],
            })
            .collect(),
        visibilities: vis
            .iter()
            .zip(nominal_ratios.iter().zip(&fitted_ratios))
            .map(|(v, (&nominal, &fitted))| VisibilityFit {
                measured: v.clone(),
                nominal,
                fitted,
            })
            .collect(),
        correlation,
        start: free
            .iter()
            .zip(u_start.iter())
            .map(|(f, &u)| f.nominal + u * f.sigma)
            .collect(),
        fitted_params,
        chi2_nominal,
        chi2,
        prior_term: match config.prior {
            true => out.u.norm_squared(),
            false => 0.0,
        },
        dof: if config.prior {
            data_rows
        } else {
            data_rows - free.len()
        },
        singular_values,
        weak_directions,
        iterations: out.iterations,
        evaluations: evaluations + 2,
        stop: out.stop,
        projected_gradient: out.projected_gradient,
        config: config.clone(),
    };
    check_finite(&result)?;
    Ok(result)
}

/// The first value of `values` that is not finite, as [`FitError::NotFinite`] naming
/// `quantity(index)`.
fn first_nonfinite<'a>(
    quantity: impl Fn(usize) -> String,
    values: impl IntoIterator<Item = &'a f64>,
) -> Result<(), FitError> {
    match values.into_iter().enumerate().find(|(_, v)| !v.is_finite()) {
        Some((k, &value)) => Err(FitError::NotFinite {
            quantity: quantity(k),
            value,
        }),
        None => Ok(()),
    }
}

/// Every number of a fit that is printed or written is finite, or the fit is refused naming
/// it ([`FitError::NotFinite`]). The only exceptions are the documented markers of "not
/// available": the sigma (`None`) and the correlations (NaN) of a parameter on a bound, and
/// the nominal model visibility (NaN) where the model's mode has no component in the reference,
/// which makes `chi2_nominal` NaN (never infinite). Every way out of a fit that returns a
/// result passes here.
pub fn check_finite(r: &FitResult) -> Result<(), FitError> {
    for p in &r.params {
        let key = &p.key;
        first_nonfinite(
            |k| {
                let what = [
                    "nominal value",
                    "fitted value",
                    "prior sigma",
                    "data-only sigma",
                ];
                format!("{} of {key}", what[k])
            },
            &[p.nominal, p.fitted, p.prior_sigma, p.data_sigma_rel],
        )?;
        first_nonfinite(|_| format!("fitted sigma of {key}"), p.fitted_sigma.iter())?;
    }
    for (i, row) in r.correlation.iter().enumerate() {
        if r.params[i].at_bound.is_some() {
            continue;
        }
        for (j, &c) in row.iter().enumerate() {
            if r.params[j].at_bound.is_none() && !c.is_finite() {
                return Err(FitError::NotFinite {
                    quantity: format!("correlation of {} and {}", r.params[i].key, r.params[j].key),
                    value: c,
                });
            }
        }
    }
    for m in &r.modes {
        first_nonfinite(
            |k| {
                let what = ["nominal", "fitted"][k];
                format!("{what} frequency of nu_{}", m.measured.mode)
            },
            &[m.nominal_hz, m.fitted_hz],
        )?;
    }
    for v in &r.visibilities {
        let m = &v.measured;
        let name = format!(
            "visibility nu_{} {}/{}",
            m.mode,
            m.observable.name(),
            m.reference.name()
        );
        first_nonfinite(|_| format!("fitted {name}"), [&v.fitted])?;
        if v.nominal.is_infinite() {
            return Err(FitError::NotFinite {
                quantity: format!("nominal {name}"),
                value: v.nominal,
            });
        }
    }
    if r.chi2_nominal.is_infinite() {
        return Err(FitError::NotFinite {
            quantity: "chi^2 at the nominal parameters".into(),
            value: r.chi2_nominal,
        });
    }
    first_nonfinite(
        |k| ["chi^2", "prior term", "projected gradient"][k].to_string(),
        &[r.chi2, r.prior_term, r.projected_gradient],
    )?;
    first_nonfinite(
        |k| format!("starting value of {}", r.params[k].key),
        &r.start,
    )?;
    first_nonfinite(
        |k| format!("singular value {} of the data Jacobian", k + 1),
        &r.singular_values,
    )?;
    for w in &r.weak_directions {
        first_nonfinite(
            |k| format!("weak direction's component along {}", w.direction[k].0),
            w.direction.iter().map(|(_, c)| c),
        )?;
    }
    Ok(())
}

/// The least-squares problem in the scaled variables `u` (module docs).
struct Problem<'a> {
    params: &'a Params,
    measured: &'a Measured,
    vis: &'a [MeasuredVisibility],
    free: &'a [Free],
    keys: Vec<String>,
    /// Per measured mode, its index among the model's eight.
    ranks: Vec<usize>,
    /// Frequency rows, then visibility rows.
    data_rows: usize,
    config: &'a FitConfig,
}

impl Problem<'_> {
    /// The parameter set at `u`.
    fn at(&self, u: &DVector<f64>) -> Result<Params, FitError> {
        self.free
            .iter()
            .zip(u.iter())
            .try_fold(self.params.clone(), |p, (f, &ui)| {
                jacobian::with_value(&p, &f.key, f.nominal + ui * f.sigma)
            })
    }

    /// Frequency rows, visibility rows, then (with the prior) one row u_j per parameter.
    /// Once cancelled every evaluation fails, which the minimizer takes as rejected steps
    /// until its damping runs out (a few dozen cheap rounds); the check after it returns.
    fn residuals(&self, u: &DVector<f64>) -> Result<Evaluation, FitError> {
        let (free, vis, data_rows, config) = (self.free, self.vis, self.data_rows, self.config);
        let m = self.measured.modes.len();
        config.cancel.check()?;
        let e = jacobian::evaluate(&self.at(u)?, &self.keys, vis)?;
        let rows = data_rows + if config.prior { free.len() } else { 0 };
        let mut r = DVector::zeros(rows);
        let mut jac = DMatrix::zeros(rows, free.len());
        for (i, (x, &k)) in self.measured.modes.iter().zip(&self.ranks).enumerate() {
            r[i] = (e.frequencies_hz[k] - x.frequency_hz) / x.sigma_hz;
            for (j, f) in free.iter().enumerate() {
                jac[(i, j)] = e.frequency_jacobian[(k, j)] * f.sigma / x.sigma_hz;
            }
        }
        for (i, v) in vis.iter().enumerate() {
            r[m + i] = (e.ratios[i] - v.ratio) / v.sigma;
            for (j, f) in free.iter().enumerate() {
                jac[(m + i, j)] = e.ratio_jacobian[(i, j)] * f.sigma / v.sigma;
            }
        }
        if config.prior {
            for j in 0..free.len() {
                r[data_rows + j] = u[j];
                jac[(data_rows + j, j)] = 1.0;
            }
        }
        // A residual or a derivative that is not finite is refused here: at the start it is
        // the fit's error, at a trial step the minimizer rejects the step.
        if let Some(i) =
            (0..rows).find(|&i| !r[i].is_finite() || jac.row(i).iter().any(|x| !x.is_finite()))
        {
            let (what, value) = match r[i].is_finite() {
                true => (
                    "derivative",
                    jac.row(i).iter().copied().find(|x| !x.is_finite()),
                ),
                false => ("residual", Some(r[i])),
            };
            return Err(FitError::NotFinite {
                quantity: format!("{what} of {}", self.row_name(i)),
                value: value.unwrap_or(f64::NAN),
            });
        }
        Ok((r, jac, e.frequencies_hz, e.ratios))
    }

    /// What row `i` of the residuals is, for messages.
    fn row_name(&self, i: usize) -> String {
        let m = self.measured.modes.len();
        if i < m {
            format!("the frequency of nu_{}", self.measured.modes[i].mode)
        } else if i < self.data_rows {
            let v = &self.vis[i - m];
            format!(
                "the visibility nu_{} {}/{}",
                v.mode,
                v.observable.name(),
                v.reference.name()
            )
        } else {
            format!("the prior of {}", self.free[i - self.data_rows].key)
        }
    }

    /// `chi^2` of the data at the model frequencies `freqs` and visibilities `ratios`.
    fn chi2(&self, freqs: &[f64; 8], ratios: &[f64]) -> f64 {
        self.measured
            .modes
            .iter()
            .zip(&self.ranks)
            .map(|(x, &k)| ((freqs[k] - x.frequency_hz) / x.sigma_hz).powi(2))
            .chain(
                self.vis
                    .iter()
                    .zip(ratios)
                    .map(|(v, r)| ((r - v.ratio) / v.sigma).powi(2)),
            )
            .sum::<f64>()
    }

    /// The best solution over every start within `n` prior sigmas, its start, and the
    /// evaluations spent over all starts.
    fn best_of_starts(&self, n: f64) -> Result<(lm::LmOutcome, DVector<f64>, usize), FitError> {
        let opts = lm::LmOptions {
            gtol: GTOL,
            max_iterations: MAX_ITERATIONS,
        };
        let mut best: Option<(lm::LmOutcome, DVector<f64>)> = None;
        let mut evaluations = 0;
        for u0 in starts(self.free, n) {
            let out = lm::minimize(u0.clone(), n, &opts, |u| {
                self.residuals(u).map(|(r, j, _, _)| (r, j))
            })?;
            self.config.cancel.check()?;
            evaluations += out.evaluations;
            if best
                .as_ref()
                .is_none_or(|(b, _)| out.r.norm_squared() < b.r.norm_squared())
            {
                best = Some((out, u0));
            }
        }
        let (out, u_start) = best.expect("at least one start");
        Ok((out, u_start, evaluations))
    }
}

/// The fitted parameters with their uncertainties (those on the box have none), and the
/// correlation matrix (NaN in the rows and columns of those on the box).
fn uncertainties(
    free: &[Free],
    out: &lm::LmOutcome,
    data_jac: &DMatrix<f64>,
    n: f64,
) -> Result<(Vec<FittedParam>, Vec<Vec<f64>>), FitError> {
    let data_sigma_rel = diag_of_inverse(data_jac)?;
    let at_bound: Vec<Option<Bound>> = out
        .u
        .iter()
        .map(|&ui| match ui {
            x if x >= n => Some(Bound::Upper),
            x if x <= -n => Some(Bound::Lower),
            _ => None,
        })
        .collect();
    let inside: Vec<usize> = (0..free.len()).filter(|&j| at_bound[j].is_none()).collect();
    let covariance = covariance(&out.jac.select_columns(&inside))?;
    let mut correlation = vec![vec![f64::NAN; free.len()]; free.len()];
    for (a, &i) in inside.iter().enumerate() {
        for (b, &j) in inside.iter().enumerate() {
            correlation[i][j] =
                covariance[(a, b)] / (covariance[(a, a)] * covariance[(b, b)]).sqrt();
        }
    }
    let params_out = free
        .iter()
        .enumerate()
        .map(|(j, f)| FittedParam {
            key: f.key.clone(),
            unit: f.unit.clone(),
            nominal: f.nominal,
            fitted: f.nominal + out.u[j] * f.sigma,
            prior_sigma: f.sigma,
            fitted_sigma: inside
                .iter()
                .position(|&i| i == j)
                .map(|pos| covariance[(pos, pos)].sqrt() * f.sigma),
            at_bound: at_bound[j],
            data_sigma_rel: data_sigma_rel[j],
            poorly_constrained: data_sigma_rel[j] >= 1.0,
        })
        .collect();
    Ok((params_out, correlation))
}

/// The SVD of `jac` (its right singular vectors only), or [`FitError::NotFinite`] when it does
/// not converge within [`SVD_MAX_ITERATIONS`] sweeps (a Jacobian that is not finite).
fn svd_of(
    jac: &DMatrix<f64>,
) -> Result<nalgebra::linalg::SVD<f64, nalgebra::Dyn, nalgebra::Dyn>, FitError> {
    if let Some(&value) = jac.iter().find(|x| !x.is_finite()) {
        return Err(FitError::NotFinite {
            quantity: "weighted Jacobian".into(),
            value,
        });
    }
    jac.clone()
        .try_svd(false, true, f64::EPSILON, SVD_MAX_ITERATIONS)
        .ok_or_else(|| FitError::NotFinite {
            quantity: format!(
                "SVD of the weighted Jacobian (not converged in {SVD_MAX_ITERATIONS} sweeps)"
            ),
            value: f64::NAN,
        })
}

/// The data Jacobian's singular values, largest first, and the directions along those below 1
/// (combinations of the parameters the data know less well than the prior).
fn weak_directions(
    data_jac: &DMatrix<f64>,
    keys: &[String],
) -> Result<(Vec<f64>, Vec<WeakDirection>), FitError> {
    let svd = svd_of(data_jac)?;
    let v_t = svd.v_t.expect("requested");
    let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let singular_values: Vec<f64> = order.iter().map(|&i| svd.singular_values[i]).collect();
    let weak_directions = order
        .iter()
        .filter(|&&i| svd.singular_values[i] < 1.0)
        .map(|&i| WeakDirection {
            singular_value: svd.singular_values[i],
            direction: keys
                .iter()
                .enumerate()
                .map(|(j, k)| (k.clone(), v_t[(i, j)]))
                .collect(),
        })
        .collect();
    Ok((singular_values, weak_directions))
}

/// The model's visibilities at the nominal parameters, NaN where the reference does not see
/// the mode (the symmetric pendulum's forbidden channels).
fn nominal_ratios(model: &crate::model::Model, vis: &[MeasuredVisibility]) -> Vec<f64> {
    let modes = crate::modes::NormalModes::new_f64(model);
    vis.iter()
        .map(|v| {
            visibility::model_ratio(&modes, model.observation(), v, &[])
                .map_or(f64::NAN, |(r, _)| r)
        })
        .collect()
}

/// `(J^T J)^-1` through the SVD of `J` (the pseudo-inverse: directions along a numerically zero
/// singular value, see [`RANK_TOL`], get an infinite variance).
fn covariance(jac: &DMatrix<f64>) -> Result<DMatrix<f64>, FitError> {
    let cols = jac.ncols();
    if cols == 0 {
        return Ok(DMatrix::zeros(0, 0));
    }
    let svd = svd_of(jac)?;
    let v_t = svd.v_t.expect("requested");
    let s_max = svd.singular_values.max();
    Ok(DMatrix::from_fn(cols, cols, |a, b| {
        let mut c = 0.0;
        for (i, &s) in svd.singular_values.iter().enumerate() {
            let (va, vb) = (v_t[(i, a)], v_t[(i, b)]);
            if s <= s_max * RANK_TOL {
                if va != 0.0 && vb != 0.0 {
                    return if a == b { f64::INFINITY } else { f64::NAN };
                }
                continue;
            }
            c += va * vb / (s * s);
        }
        c
    }))
}

/// `sqrt(diag((J^T J)^-1))` through the SVD of `J`; a parameter with a component along a
/// numerically zero singular value gets an infinite value.
fn diag_of_inverse(jac: &DMatrix<f64>) -> Result<Vec<f64>, FitError> {
    let cols = jac.ncols();
    if cols == 0 {
        return Ok(Vec::new());
    }
    let svd = svd_of(jac)?;
    let v_t = svd.v_t.expect("requested");
    let s_max = svd.singular_values.max();
    Ok((0..cols)
        .map(|j| {
            let mut var = 0.0;
            for (i, &s) in svd.singular_values.iter().enumerate() {
                let c = v_t[(i, j)];
                if s <= s_max * RANK_TOL {
                    if c != 0.0 {
                        return f64::INFINITY;
                    }
                    continue;
                }
                var += (c / s).powi(2);
            }
            var.sqrt()
        })
        .collect())
}

/// Checks the configuration against the parameters and the measurements.
fn check_config(
    params: &Params,
    (modes, visibilities): (usize, usize),
    config: &FitConfig,
) -> Result<Vec<Free>, FitError> {
    let n = config.bound_sigmas;
    if !(n.is_finite() && n > 0.0) {
        return Err(FitError::BoundSigmas { value: n });
    }
    if config.free.is_empty() {
        return Err(FitError::NoFree);
    }
    refuse_repeats(
        OptionKey::FREE,
        "parameter key",
        &config.free,
        String::clone,
    )?;
    let fields = params.fields();
    let sigma_of = |key: &str, value: f64| {
        crate::mc::uncertainties(params)
            .into_iter()
            .find(|u| u.key == key)
            .map_or(0.0, |u| u.sigma_at(value))
    };
    let allowed: Vec<&str> = fields
        .iter()
        .filter(|f| sigma_of(f.key, f.value) > 0.0)
        .map(|f| f.key)
        .collect();
    let allowed = allowed.join(", ");
    let mut out: Vec<Free> = Vec::with_capacity(config.free.len());
    for key in &config.free {
        let field = fields
            .iter()
            .find(|f| f.key == key)
            .ok_or_else(|| FitError::UnknownKey {
                key: key.clone(),
                allowed: allowed.clone(),
            })?;
        let sigma = sigma_of(key, field.value);
        let absolute = crate::params::uncertainty::is_absolute_key(key);
        if sigma <= 0.0 {
            return Err(FitError::ExactKey {
                key: key.clone(),
                allowed: allowed.clone(),
            });
        }
        let (lower, upper) = (field.value - n * sigma, field.value + n * sigma);
        // A box edge that changes the sign of the parameter would also make the matrix
        // derivative step (relative to |p|) vanish; the physical ranges exclude it anyway. An
        // offset may take either sign (its step is absolute).
        let edge_error = [lower, upper].into_iter().find_map(|edge| {
            let reason = match jacobian::with_value(params, key, edge) {
                Err(e) => Some(e.to_string()),
                Ok(_) if !absolute && (edge.signum() != field.value.signum() || edge == 0.0) => {
                    Some("the parameter changes sign".to_string())
                }
                Ok(_) => None,
            };
            reason.map(|r| (edge, r))
        });
        if let Some((_, reason)) = edge_error {
            return Err(FitError::BoxNotPhysical {
                key: key.clone(),
                lower,
                upper,
                unit: field.unit.to_string(),
                n,
                reason,
            });
        }
        out.push(Free {
            key: key.clone(),
            unit: field.unit.to_string(),
            nominal: field.value,
            sigma,
        });
    }
    if out.len() > modes + visibilities {
        return Err(FitError::TooManyFree {
            free: out.len(),
            modes,
            visibilities,
        });
    }
    Ok(out)
}
