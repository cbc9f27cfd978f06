//! Monte Carlo of the normal modes: the parameters are drawn within their stated errors and the
//! eight mode frequencies of every draw are collected, giving the mean and standard deviation per
//! mode (the "calculated" column of Table II, whose error bars are the paper's Monte Carlo spread).
//!
//! * Each listed parameter is drawn as `p (1 + rel_sigma z)` (an `[asymmetry]` offset as
//!   `p + sigma z`, its error being absolute), with `z` a standard Gaussian or a uniform variate
//!   on `[-sqrt(3), sqrt(3)]` (same standard deviation); the others are exact.
//! * Every draw is validated with [`Params::validate`] and [`Model::new`] (mass matrix positive
//!   definite) and must give eight non-negative eigenvalues; a draw that fails is *rejected* and
//!   counted, not redrawn.
//! * The error model is the parameter file's (see [`crate::params::uncertainty`]):
//!   [`uncertainties`] merges its `[uncertainty]` table with [`default_uncertainties`].
//! * A configuration whose error bar can make a parameter non-physical is refused up front:
//!   `rel_sigma` must be below [`MAX_REL_SIGMA`] = 0.25 for a Gaussian (4 sigma must not reach
//!   zero) and below 1/sqrt(3) for a uniform draw (its range `+/- sqrt(3) sigma` must not).
//! * Only parameters that enter the undamped modes are drawn (masses, inertias, torsion and
//!   bouncing constants, lengths, g, the `[asymmetry]` offsets); an error on any other (loss
//!   angles, damping, temperature, the readout rotation) is accepted and has no effect.
//! * At most [`MAX_MC_DRAWS`] draws on at most [`MAX_THREADS`] threads, and no more draws than
//!   fit into the memory available ([`check_size`]).
//! * Reproducible: sample `i` has its own random stream derived from `(seed, i)`, so the result
//!   is bit-identical for a given seed whatever the number of threads.
//! * Per draw only the eigenvalues are computed, per decoupled 4x4 block or of the coupled 8x8
//!   problem (Cholesky reduction and symmetric eigenvalues, exactly as
//!   [`crate::modes::NormalModes`] does), and the eight frequencies are sorted (mode identity by
//!   rank, as in Table II).
//!
//! Pure numerics: depends on `params`, `model` and `modes` (the reduction of the pencil); no I/O.

use crate::cancel::{Cancel, Cancelled};
use crate::error::ParamError;
use crate::limits::{
    check_count, check_memory, planned_bytes, LimitError, MAX_MC_DRAWS, MAX_THREADS,
    MC_BYTES_PER_DRAW,
};
use crate::model::{Block, Model};
use crate::modes::reduced_pencil;
use crate::option_key::OptionKey;
use crate::params::uncertainty::{check, UncertaintyError};
use crate::params::Params;
use crate::rng::Rng;
use std::sync::atomic::{AtomicUsize, Ordering};

pub use crate::params::uncertainty::{
    default_uncertainties, Distribution, Uncertainty, DEFAULT_REL_SIGMA_GEOMETRY,
    DEFAULT_REL_SIGMA_SPRINGS, MAX_REL_SIGMA, MAX_REL_SIGMA_UNIFORM,
};

/// The effective error model of `params`: [`default_uncertainties`] with the entries of the
/// parameter file's `[uncertainty]` table overriding them (one entry per parameter key, in
/// [`Params::fields`] order; exact parameters have `rel_sigma = 0`). See
/// [`Params::effective_uncertainties`].
pub fn uncertainties(params: &Params) -> Vec<Uncertainty> {
    params.effective_uncertainties()
}

/// Monte Carlo settings.
#[derive(Debug, Clone, PartialEq)]
pub struct McConfig {
    /// Number of draws (> 0). Default 10 000.
    pub samples: usize,
    /// Seed of the random streams. The result depends on it and on nothing else.
    pub seed: u64,
    /// Worker threads; 0 means all available cores. Does not change the result.
    pub threads: usize,
    /// Parameters to draw; the others are exact.
    pub uncertainties: Vec<Uncertainty>,
    /// Polled by every worker between blocks of draws.
    pub cancel: Cancel,
}

impl McConfig {
    /// 10 000 samples, seed 1, all cores, the error model of `params` ([`uncertainties`]).
    pub fn default_for(params: &Params) -> McConfig {
        McConfig {
            samples: 10_000,
            seed: 1,
            threads: 0,
            uncertainties: uncertainties(params),
            cancel: Cancel::never(),
        }
    }
}

/// Result of a Monte Carlo run.
#[derive(Debug, Clone, PartialEq)]
pub struct McResult {
    /// Number of draws made (accepted + rejected).
    pub samples: usize,
    /// Draws rejected as non-physical (see the module documentation).
    pub rejected: usize,
    /// Mode frequencies (Hz) of every accepted draw, sorted ascending, in sample order.
    pub freqs_hz: Vec<[f64; 8]>,
    /// Sample number (0-based, `< samples`) of each row of `freqs_hz`; the missing numbers
    /// are the rejected draws.
    pub sample_index: Vec<usize>,
    /// Mean frequency per mode (Hz).
    pub mean_hz: [f64; 8],
    /// Sample standard deviation (n - 1) per mode (Hz); 0 with a single accepted draw.
    pub std_hz: [f64; 8],
}

/// A Monte Carlo configuration that cannot be run.
#[derive(Debug, thiserror::Error)]
pub enum McError {
    /// `samples` is 0.
    #[error("Monte Carlo: samples = 0; need at least 1 sample")]
    NoSamples,
    /// An error model that cannot be used (unknown or repeated key, invalid or too large sigma).
    #[error("Monte Carlo: {0}")]
    Uncertainty(#[from] UncertaintyError),
    /// The nominal parameter set does not build a model.
    #[error("Monte Carlo: nominal parameters: {0}")]
    Nominal(#[from] ParamError),
    /// More draws or threads than allowed, or than fit into memory.
    #[error("Monte Carlo: {0}")]
    TooLarge(#[from] LimitError),
    /// Cancelled through [`McConfig::cancel`].
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    /// Every draw was rejected.
    #[error(
        "Monte Carlo: all {samples} draws were rejected as non-physical; reduce the error bars"
    )]
    AllRejected {
        /// Number of draws.
        samples: usize,
    },
}

/// The eight undamped mode frequencies (Hz) of a model, sorted ascending, or `None` if a mass
/// matrix is not positive definite or an eigenvalue is negative or not finite. Same arithmetic
/// as [`crate::modes::NormalModes::new`] (eigenvalues only): per block when the model is
/// decoupled, of the full 8x8 pencil otherwise.
pub fn mode_frequencies_hz(model: &Model) -> Option<[f64; 8]> {
    let mass = model.mass();
    let stiffness = model.stiffness();
    let mut w2: Vec<f64> = Vec::with_capacity(8);
    if model.decoupled() {
        for block in Block::ALL {
            let mb = Model::block_of(mass, block);
            let kb = Model::block_of(&stiffness, block);
            let (_, a) = reduced_pencil(&mb, &kb)?;
            w2.extend(a.symmetric_eigenvalues().iter());
        }
    } else {
        let (_, a) = reduced_pencil(mass, &stiffness)?;
        w2.extend(a.symmetric_eigenvalues().iter());
    }
    let mut out = [0.0; 8];
    for (f, &w2) in out.iter_mut().zip(&w2) {
        if !(w2.is_finite() && w2 >= 0.0) {
            return None;
        }
        *f = w2.sqrt() / std::f64::consts::TAU;
    }
    out.sort_by(f64::total_cmp);
    Some(out)
}

/// Refuses more than [`MAX_MC_DRAWS`] draws, more than fit into the memory available
/// ([`MC_BYTES_PER_DRAW`] each), or more than [`MAX_THREADS`] threads, before anything is
/// allocated. `names` are what the messages call the two counts, e.g. the options
/// `("--samples", "--threads")`.
pub fn check_size(
    samples: usize,
    threads: usize,
    names: (OptionKey, OptionKey),
) -> Result<(), LimitError> {
    let what = || crate::message!("{} {samples}", names.0);
    check_count(what, samples as f64, "Monte Carlo draws", MAX_MC_DRAWS)?;
    check_memory(what, planned_bytes(samples, MC_BYTES_PER_DRAW))?;
    let what = || crate::message!("{} {threads}", names.1);
    check_count(what, threads as f64, "threads", MAX_THREADS)
}

/// Runs the Monte Carlo. `progress` is called from the worker threads with the number of draws
/// completed so far (all threads together), every few hundred draws and once at the end with
/// `cfg.samples`.
pub fn run(
    params: &Params,
    cfg: &McConfig,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<McResult, McError> {
    let plan = Plan::new(params, cfg)?;
    let n = cfg.samples;
    let threads = match cfg.threads {
        0 => std::thread::available_parallelism().map_or(1, |t| t.get()),
        t => t,
    }
    .clamp(1, n);
    let done = AtomicUsize::new(0);
    let chunk = n.div_ceil(threads);
    let mut draws: Vec<Option<[f64; 8]>> = vec![None; n];
    std::thread::scope(|scope| {
        for (t, slot) in draws.chunks_mut(chunk).enumerate() {
            let (plan, done) = (&plan, &done);
            let cancel = &cfg.cancel;
            scope.spawn(move || {
                // Draws between progress reports and cancellation checks (well under a
                // millisecond of work).
                const REPORT_EVERY: usize = 256;
                let first = t * chunk;
                for (j, out) in slot.iter_mut().enumerate() {
                    *out = plan.draw(first + j);
                    if (j + 1) % REPORT_EVERY == 0 {
                        if cancel.is_cancelled() {
                            return;
                        }
                        progress(done.fetch_add(REPORT_EVERY, Ordering::Relaxed) + REPORT_EVERY);
                    }
                }
                let rest = slot.len() % REPORT_EVERY;
                if rest > 0 {
                    progress(done.fetch_add(rest, Ordering::Relaxed) + rest);
                }
            });
        }
    });
    cfg.cancel.check()?;
    let (sample_index, freqs_hz): (Vec<usize>, Vec<[f64; 8]>) = draws
        .into_iter()
        .enumerate()
        .filter_map(|(i, d)| Some((i, d?)))
        .unzip();
    if freqs_hz.is_empty() {
        return Err(McError::AllRejected { samples: n });
    }
    let (mean_hz, std_hz) = mean_and_std(&freqs_hz);
    Ok(McResult {
        samples: n,
        rejected: n - freqs_hz.len(),
        freqs_hz,
        sample_index,
        mean_hz,
        std_hz,
    })
}

/// Shifted two-pass mean and sample standard deviation per mode, in sample order (so the result
/// does not depend on how the work was split). With identical samples the mean is exactly that
/// value and the standard deviation exactly 0.
fn mean_and_std(x: &[[f64; 8]]) -> ([f64; 8], [f64; 8]) {
    let n = x.len() as f64;
    let shift = x[0];
    let mut mean = [0.0; 8];
    for k in 0..8 {
        let s: f64 = x.iter().map(|r| r[k] - shift[k]).sum();
        mean[k] = shift[k] + s / n;
    }
    let mut std = [0.0; 8];
    if x.len() > 1 {
        for k in 0..8 {
            let d: Vec<f64> = x.iter().map(|r| r[k] - mean[k]).collect();
            let s: f64 = d.iter().sum();
            let ss: f64 = d.iter().map(|v| v * v).sum();
            // Corrected two-pass (Chan, Golub, LeVeque): removes the rounding error of the mean.
            std[k] = ((ss - s * s / n).max(0.0) / (n - 1.0)).sqrt();
        }
    }
    (mean, std)
}

/// Which parameter, with what error: accessors of the drawn parameters.
struct Plan {
    nominal: Params,
    /// Each drawn parameter with its relative and absolute standard deviations (one is 0).
    draws: Vec<(FieldMut, f64, f64, Distribution)>,
    seed: u64,
}

impl Plan {
    fn new(params: &Params, cfg: &McConfig) -> Result<Plan, McError> {
        if cfg.samples == 0 {
            return Err(McError::NoSamples);
        }
        check_size(
            cfg.samples,
            cfg.threads,
            (OptionKey::SAMPLES, OptionKey::THREADS),
        )?;
        Model::new(params)?;
        let keys: Vec<&str> = params.fields().iter().map(|f| f.key).collect();
        check(&cfg.uncertainties, &keys)?;
        let draws = cfg
            .uncertainties
            .iter()
            .filter(|u| !u.is_exact())
            .filter_map(|u| {
                Some((
                    modal_field(&u.key)?,
                    u.rel_sigma,
                    u.abs_sigma,
                    u.distribution,
                ))
            })
            .collect();
        // The error model is not needed per draw: clone and validate the values only.
        let nominal = Params {
            uncertainty: Default::default(),
            ..params.clone()
        };
        Ok(Plan {
            nominal,
            draws,
            seed: cfg.seed,
        })
    }

    /// Draw number `index`: its frequencies, or `None` if rejected.
    fn draw(&self, index: usize) -> Option<[f64; 8]> {
        let mut rng = Rng::stream(self.seed, index as u64);
        let mut p = self.nominal.clone();
        for &(field, rel_sigma, abs_sigma, dist) in &self.draws {
            let z = match dist {
                Distribution::Gaussian => rng.gaussian(),
                Distribution::Uniform => 3f64.sqrt() * (2.0 * rng.uniform() - 1.0),
            };
            let value = field(&mut p);
            if abs_sigma > 0.0 {
                *value += abs_sigma * z;
            } else {
                *value *= 1.0 + rel_sigma * z;
            }
        }
        p.validate().ok()?;
        let model = Model::new(&p).ok()?;
        mode_frequencies_hz(&model)
    }
}

/// Access to one parameter value.
type FieldMut = fn(&mut Params) -> &mut f64;

/// The parameter `key` if it enters the undamped mode frequencies (mass and stiffness
/// matrices), else `None`.
fn modal_field(key: &str) -> Option<FieldMut> {
    let f: FieldMut = match key {
        "mass.m_a_kg" => |p| &mut p.mass.m_a_kg,
        "mass.m_b_kg" => |p| &mut p.mass.m_b_kg,
        "inertia.a11_kg_m2" => |p| &mut p.inertia.a11_kg_m2,
        "inertia.a22_kg_m2" => |p| &mut p.inertia.a22_kg_m2,
        "inertia.a33_kg_m2" => |p| &mut p.inertia.a33_kg_m2,
        "inertia.a23_kg_m2" => |p| &mut p.inertia.a23_kg_m2,
        "inertia.b11_kg_m2" => |p| &mut p.inertia.b11_kg_m2,
        "inertia.b22_kg_m2" => |p| &mut p.inertia.b22_kg_m2,
        "inertia.b33_kg_m2" => |p| &mut p.inertia.b33_kg_m2,
        "torsion.k_a_n_m_per_rad" => |p| &mut p.torsion.k_a_n_m_per_rad,
        "torsion.k_b_n_m_per_rad" => |p| &mut p.torsion.k_b_n_m_per_rad,
        "bouncing.kappa_a_n_per_m" => |p| &mut p.bouncing.kappa_a_n_per_m,
        "bouncing.kappa_b_n_per_m" => |p| &mut p.bouncing.kappa_b_n_per_m,
        "length.d_m" => |p| &mut p.length.d_m,
        "length.h_c_m" => |p| &mut p.length.h_c_m,
        "length.z_m" => |p| &mut p.length.z_m,
        "length.z_a_m" => |p| &mut p.length.z_a_m,
        "length.z_b_m" => |p| &mut p.length.z_b_m,
        "length.h_m" => |p| &mut p.length.h_m,
        "environment.g_m_per_s2" => |p| &mut p.environment.g_m_per_s2,
        "asymmetry.crossbar_com_x_m" => |p| &mut p.asymmetry.crossbar_com_x_m,
        "asymmetry.crossbar_com_y_m" => |p| &mut p.asymmetry.crossbar_com_y_m,
        "asymmetry.tm_com_x_m" => |p| &mut p.asymmetry.tm_com_x_m,
        "asymmetry.tm_com_y_m" => |p| &mut p.asymmetry.tm_com_y_m,
        "asymmetry.lower_attachment_x_m" => |p| &mut p.asymmetry.lower_attachment_x_m,
        "asymmetry.lower_attachment_y_m" => |p| &mut p.asymmetry.lower_attachment_y_m,
        _ => return None,
    };
    Some(f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modal_field_sets_its_own_key_only() {
        let p = Params::table_i();
        let mut drawn = 0;
        for f in p.fields() {
            let Some(field) = modal_field(f.key) else {
                continue;
            };
            drawn += 1;
            let mut q = p.clone();
            *field(&mut q) = 1234.5;
            let changed: Vec<&str> = q
                .fields()
                .iter()
                .zip(p.fields())
                .filter(|(a, b)| a.value != b.value)
                .map(|(a, _)| a.key)
                .collect();
            assert_eq!(changed, [f.key]);
        }
        // Every parameter with a non-zero default error enters the modes.
        for u in default_uncertainties(&p).iter().filter(|u| !u.is_exact()) {
            assert!(modal_field(&u.key).is_some(), "{}", u.key);
        }
        assert_eq!(drawn, 26);
    }

    #[test]
    fn sizes_over_the_limits_are_refused_before_drawing() {
        let p = Params::table_i();
        for (samples, threads, needle) in [
            (usize::MAX, 1, "samples 18446744073709551615: "),
            (MAX_MC_DRAWS + 1, 1, "10000001 Monte Carlo draws"),
            (10, MAX_THREADS + 1, "threads 1025: 1025 threads"),
        ] {
            let cfg = McConfig {
                samples,
                threads,
                ..McConfig::default_for(&p)
            };
            let e = run(&p, &cfg, &|_| {}).unwrap_err();
            assert!(matches!(e, McError::TooLarge(_)), "{e}");
            assert!(e.to_string().contains(needle), "{e}");
        }
        assert!(check_size(
            MAX_MC_DRAWS,
            MAX_THREADS,
            (OptionKey::SAMPLES, OptionKey::THREADS)
        )
        .is_ok());
    }

    #[test]
    fn parameters_outside_the_modes_do_not_enter_them() {
        // The claim behind `modal_field`: the undamped modes depend only on the drawn keys.
        let p = Params::table_i();
        let base = mode_frequencies_hz(&Model::new(&p).unwrap()).unwrap();
        for f in p.fields().iter().filter(|f| modal_field(f.key).is_none()) {
            // (A readout rotation changes what the observables read, never the modes.)
            let v = if f.value == 0.0 { 1e-3 } else { f.value * 1.5 };
            let q = p.with_override(&format!("{}={v:?}", f.key)).unwrap();
            let other = mode_frequencies_hz(&Model::new(&q).unwrap()).unwrap();
            assert_eq!(other, base, "{}", f.key);
        }
    }
}
