//! Monte Carlo of the normal modes: the parameters are drawn within their stated errors and the
//! eight mode frequencies of every draw are collected, giving the mean and standard deviation per
//! mode (the "calculated" column of Table II, whose error bars are the paper's Monte Carlo spread).
//!
//! * Each listed parameter is drawn as `p (1 + rel_sigma z)`, with `z` a standard Gaussian or a
//!   uniform variate on `[-sqrt(3), sqrt(3)]` (same standard deviation); the others are exact.
//! * Every draw is validated with [`Params::validate`] and [`Model::new`] (mass matrix positive
//!   definite) and must give eight non-negative eigenvalues; a draw that fails is *rejected* and
//!   counted, not redrawn.
//! * A configuration whose error bar can make a parameter non-physical with non-negligible
//!   probability is refused up front: `rel_sigma` must be below [`MAX_REL_SIGMA`] = 0.25 (4 sigma
//!   must not reach zero; for a uniform draw the range `+/- sqrt(3) sigma` then stays below 44 %).
//! * Reproducible: sample `i` has its own random stream derived from `(seed, i)`, so the result
//!   is bit-identical for a given seed whatever the number of threads.
//! * Per draw only the eigenvalues are computed, per decoupled 4x4 block (Cholesky reduction and
//!   symmetric eigenvalues, exactly as [`crate::modes::NormalModes`] does), and the eight
//!   frequencies are sorted (mode identity by rank, as in Table II).
//!
//! Pure numerics: depends on `params` and `model` only; no I/O.

use crate::error::ParamError;
use crate::model::{Block, Model};
use crate::params::Params;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Largest relative standard deviation accepted (exclusive): 4 sigma must stay below 100 %.
pub const MAX_REL_SIGMA: f64 = 0.25;

/// Default relative standard deviation on masses, lengths and inertias (the paper: 2-3 %).
pub const DEFAULT_REL_SIGMA_GEOMETRY: f64 = 0.025;

/// Default relative standard deviation on the torsion and bouncing constants (the paper: 10 %).
pub const DEFAULT_REL_SIGMA_SPRINGS: f64 = 0.10;

/// Shape of the distribution of a parameter's relative error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distribution {
    /// Gaussian with standard deviation `rel_sigma`.
    Gaussian,
    /// Uniform on `+/- sqrt(3) rel_sigma` (the same standard deviation).
    Uniform,
}

/// The error of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// Dotted parameter key, as in the parameter file (e.g. `mass.m_a_kg`).
    pub key: String,
    /// Relative standard deviation (0.025 = 2.5 %), relative to the parameter's own value.
    pub rel_sigma: f64,
    /// Distribution shape.
    pub distribution: Distribution,
}

/// The default error model: Gaussian, 2.5 % on every `mass.*`, `inertia.*` (I^a_23 too, relative
/// to its own value) and `length.*` except `length.h_m`; 10 % on `torsion.*` and `bouncing.*`.
/// `length.h_m`, `environment.g_m_per_s2` and `loss.*` are exact (they do not enter the modes
/// anyway, except g).
pub fn default_uncertainties(params: &Params) -> Vec<Uncertainty> {
    params
        .fields()
        .iter()
        .filter_map(|f| {
            let section = f.key.split('.').next().unwrap_or("");
            let rel_sigma = match section {
                "mass" | "inertia" => DEFAULT_REL_SIGMA_GEOMETRY,
                "length" if f.key != "length.h_m" => DEFAULT_REL_SIGMA_GEOMETRY,
                "torsion" | "bouncing" => DEFAULT_REL_SIGMA_SPRINGS,
                _ => return None,
            };
            Some(Uncertainty {
                key: f.key.to_string(),
                rel_sigma,
                distribution: Distribution::Gaussian,
            })
        })
        .collect()
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
}

impl McConfig {
    /// 10 000 samples, seed 1, all cores, [`default_uncertainties`].
    pub fn default_for(params: &Params) -> McConfig {
        McConfig {
            samples: 10_000,
            seed: 1,
            threads: 0,
            uncertainties: default_uncertainties(params),
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
    /// A key that is not a parameter.
    #[error("Monte Carlo: unknown parameter key `{key}`; allowed keys: {allowed}")]
    UnknownKey {
        /// The key given.
        key: String,
        /// Every valid key.
        allowed: String,
    },
    /// The same key listed twice.
    #[error("Monte Carlo: parameter `{key}` has more than one uncertainty; give each key once")]
    DuplicateKey {
        /// The repeated key.
        key: String,
    },
    /// A relative sigma that is negative or not finite.
    #[error(
        "Monte Carlo: relative sigma of `{key}` = {rel_sigma} is not allowed: must be finite and >= 0"
    )]
    InvalidSigma {
        /// The parameter.
        key: String,
        /// The value given.
        rel_sigma: f64,
    },
    /// A relative sigma so large that draws would be non-physical with non-negligible
    /// probability.
    #[error(
        "Monte Carlo: relative sigma of `{key}` = {rel_sigma} ({percent} %) can make the parameter \
         non-physical (4 sigma reaches zero): must be < {max} ({max_percent} %)",
        percent = rel_sigma * 100.0,
        max = MAX_REL_SIGMA,
        max_percent = MAX_REL_SIGMA * 100.0
    )]
    SigmaTooLarge {
        /// The parameter.
        key: String,
        /// The value given.
        rel_sigma: f64,
    },
    /// The nominal parameter set does not build a model.
    #[error("Monte Carlo: nominal parameters: {0}")]
    Nominal(#[from] ParamError),
    /// Every draw was rejected.
    #[error(
        "Monte Carlo: all {samples} draws were rejected as non-physical; reduce the error bars"
    )]
    AllRejected {
        /// Number of draws.
        samples: usize,
    },
}

/// The eight undamped mode frequencies (Hz) of a model, sorted ascending, or `None` if a block's
/// mass matrix is not positive definite or an eigenvalue is negative or not finite. Same
/// arithmetic as [`crate::modes::NormalModes::new`] (eigenvalues only).
pub fn mode_frequencies_hz(model: &Model) -> Option<[f64; 8]> {
    let mass = model.mass();
    let stiffness = model.stiffness();
    let mut out = [0.0; 8];
    for (b, block) in Block::ALL.into_iter().enumerate() {
        let mb = Model::block_of(mass, block);
        let kb = Model::block_of(&stiffness, block);
        let l = mb.cholesky()?.l();
        let l_inv = l.try_inverse()?;
        let a = l_inv * kb * l_inv.transpose();
        let a = (a + a.transpose()) * 0.5;
        let eig = a.symmetric_eigenvalues();
        for k in 0..4 {
            let w2 = eig[k];
            if !(w2.is_finite() && w2 >= 0.0) {
                return None;
            }
            out[4 * b + k] = w2.sqrt() / std::f64::consts::TAU;
        }
    }
    out.sort_by(f64::total_cmp);
    Some(out)
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
            scope.spawn(move || {
                const REPORT_EVERY: usize = 256;
                let first = t * chunk;
                for (j, out) in slot.iter_mut().enumerate() {
                    *out = plan.draw(first + j);
                    if (j + 1) % REPORT_EVERY == 0 {
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
    let freqs_hz: Vec<[f64; 8]> = draws.into_iter().flatten().collect();
    if freqs_hz.is_empty() {
        return Err(McError::AllRejected { samples: n });
    }
    let (mean_hz, std_hz) = mean_and_std(&freqs_hz);
    Ok(McResult {
        samples: n,
        rejected: n - freqs_hz.len(),
        freqs_hz,
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

/// Which parameter, with what error: indices into a flat array of the parameter values.
struct Plan {
    nominal: Params,
    draws: Vec<(usize, f64, Distribution)>,
    seed: u64,
}

impl Plan {
    fn new(params: &Params, cfg: &McConfig) -> Result<Plan, McError> {
        if cfg.samples == 0 {
            return Err(McError::NoSamples);
        }
        Model::new(params)?;
        let fields = params.fields();
        let keys: Vec<&str> = fields.iter().map(|f| f.key).collect();
        let mut draws = Vec::with_capacity(cfg.uncertainties.len());
        for u in &cfg.uncertainties {
            let i = keys
                .iter()
                .position(|&k| k == u.key)
                .ok_or_else(|| McError::UnknownKey {
                    key: u.key.clone(),
                    allowed: keys.join(", "),
                })?;
            if draws.iter().any(|&(j, _, _)| j == i) {
                return Err(McError::DuplicateKey { key: u.key.clone() });
            }
            if !(u.rel_sigma.is_finite() && u.rel_sigma >= 0.0) {
                return Err(McError::InvalidSigma {
                    key: u.key.clone(),
                    rel_sigma: u.rel_sigma,
                });
            }
            if u.rel_sigma >= MAX_REL_SIGMA {
                return Err(McError::SigmaTooLarge {
                    key: u.key.clone(),
                    rel_sigma: u.rel_sigma,
                });
            }
            if u.rel_sigma > 0.0 {
                draws.push((i, u.rel_sigma, u.distribution));
            }
        }
        Ok(Plan {
            nominal: params.clone(),
            draws,
            seed: cfg.seed,
        })
    }

    /// Draw number `index`: its frequencies, or `None` if rejected.
    fn draw(&self, index: usize) -> Option<[f64; 8]> {
        let mut rng = Rng::for_sample(self.seed, index as u64);
        let mut p = self.nominal.clone();
        for &(i, rel_sigma, dist) in &self.draws {
            let z = match dist {
                Distribution::Gaussian => rng.gaussian(),
                Distribution::Uniform => 3f64.sqrt() * (2.0 * rng.uniform() - 1.0),
            };
            let v = field_mut(&mut p, i);
            *v *= 1.0 + rel_sigma * z;
        }
        p.validate().ok()?;
        let model = Model::new(&p).ok()?;
        mode_frequencies_hz(&model)
    }
}

/// The parameter at position `i` of [`Params::fields`].
fn field_mut(p: &mut Params, i: usize) -> &mut f64 {
    let (m, n, t, b, l) = (
        &mut p.mass,
        &mut p.inertia,
        &mut p.torsion,
        &mut p.bouncing,
        &mut p.length,
    );
    match i {
        0 => &mut m.m_a_kg,
        1 => &mut m.m_b_kg,
        2 => &mut n.a11_kg_m2,
        3 => &mut n.a22_kg_m2,
        4 => &mut n.a33_kg_m2,
        5 => &mut n.a23_kg_m2,
        6 => &mut n.b11_kg_m2,
        7 => &mut n.b22_kg_m2,
        8 => &mut n.b33_kg_m2,
        9 => &mut t.k_a_n_m_per_rad,
        10 => &mut t.k_b_n_m_per_rad,
        11 => &mut b.kappa_a_n_per_m,
        12 => &mut b.kappa_b_n_per_m,
        13 => &mut l.d_m,
        14 => &mut l.h_c_m,
        15 => &mut l.z_m,
        16 => &mut l.z_a_m,
        17 => &mut l.z_b_m,
        18 => &mut l.h_m,
        19 => &mut p.environment.g_m_per_s2,
        20 => &mut p.loss.torsion_a_rad,
        21 => &mut p.loss.torsion_b_rad,
        22 => &mut p.loss.bouncing_a_rad,
        23 => &mut p.loss.bouncing_b_rad,
        _ => unreachable!("Params has 24 fields"),
    }
}

/// SplitMix64 finalizer: a bijective 64-bit mix.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// xoshiro256** with a cached second Box-Muller variate. One per sample.
struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl Rng {
    /// Independent stream for sample `index` of run `seed`: SplitMix64 seeded by a mix of both.
    fn for_sample(seed: u64, index: u64) -> Rng {
        let mut x = mix64(seed ^ mix64(index ^ 0x6A09_E667_F3BC_C909));
        let mut next = || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            mix64(x)
        };
        let s = [next(), next(), next(), next()];
        Rng { s, spare: None }
    }

    fn next_u64(&mut self) -> u64 {
        let s = &mut self.s;
        let result = s[1].wrapping_mul(5).rotate_left(7).wrapping_mul(9);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// Uniform on [0, 1) with 53 random bits.
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard Gaussian (Box-Muller).
    fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1 = 1.0 - self.uniform(); // (0, 1]: ln is finite
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_mut_matches_fields_order() {
        let p = Params::table_i();
        for (i, f) in p.fields().iter().enumerate() {
            let mut q = p.clone();
            *field_mut(&mut q, i) = 1234.5;
            assert_eq!(q.fields()[i].value, 1234.5, "{}", f.key);
            assert_eq!(
                q.fields().iter().filter(|g| g.value == 1234.5).count(),
                1,
                "{}",
                f.key
            );
        }
        assert_eq!(p.fields().len(), 24);
    }

    #[test]
    fn gaussian_moments() {
        let n = 200_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for i in 0..n / 2 {
            let mut r = Rng::for_sample(7, i as u64);
            for _ in 0..2 {
                let z = r.gaussian();
                s1 += z;
                s2 += z * z;
            }
        }
        let mean = s1 / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 5.0 / (n as f64).sqrt(), "mean {mean}");
        assert!(
            (var - 1.0).abs() < 5.0 * (2.0 / n as f64).sqrt(),
            "var {var}"
        );
    }
}
