//! Free motion of the undamped model from given initial conditions, propagated exactly in the
//! normal-mode basis, sampled at a fixed step, with optional white readout noise.
//!
//! # Method
//!
//! With the mass-normalized shapes `V` of [`NormalModes`] (`V^T M V = I`, `V^T K V = diag(w^2)`),
//! the modal coordinates `a = V^T M q` obey `a_k'' = -w_k^2 a_k`, whose exact solution is
//! `a_k(t) = a_k0 cos(w_k t) + (adot_k0 / w_k) sin(w_k t)`. The pair `(u, v) = (a_k, adot_k / w_k)`
//! rotates by the angle `w_k dt` each step; [`ModalPropagator`] applies that 2x2 rotation with
//! `cos(w_k dt)`, `sin(w_k dt)` computed once. The step is exact whatever `w_k dt` is
//! (unconditionally stable, norm-preserving up to rounding): an explicit integrator at the
//! paper's 0.1 s sampling is unstable for the 7.7 and 10.8 Hz bouncing modes (`w dt = 4.9` and
//! `6.8`, above leapfrog's limit of 2). Rounding makes the amplitude and phase drift by at most a
//! few `eps` per step (the test suite bounds it over 432 000 steps against direct evaluation).
//!
//! Only the undamped model is supported ([`Model::is_undamped`]); a damped model is refused with
//! [`SimError::Damped`].
//!
//! # Sampling and aliasing
//!
//! Samples are taken at `t_i = i dt`, `i = 0 .. n` with `n = floor(duration / dt)` (to within a
//! relative 1e-9, so 43 200 s at 0.1 s gives exactly 432 000 samples). Modes above the Nyquist
//! frequency `1 / (2 dt)` are sampled exactly but appear aliased in spectra: at 0.1 s the 7.74 Hz
//! mode shows up at 2.26 Hz and the 10.81 Hz mode at 0.81 Hz ([`aliased_frequency_hz`]).
//!
//! # Readout noise
//!
//! White Gaussian noise of one-sided ASD `a` (unit/sqrt(Hz)) sampled at `fs = 1 / dt` has the
//! per-sample standard deviation `a sqrt(fs / 2)`. The normals come from [`crate::rng`]
//! (stream 0 of the seed, one block of `n` normals per noisy observable in the order of
//! [`SimConfig::readout_asd`]): the same seed gives the same series on every platform, held
//! whole or produced in chunks ([`stream`]).
//!
//! # Resonance check
//!
//! [`resonance`] compares the peaks found in the ASD of each simulated channel with the modes
//! the observability table ([`NormalModes::visible`]) says the channel sees.
//!
//! [`driven`] propagates the same modes driven by floor tilt.
//!
//! Pure numerics: depends on `model`, `modes` and (for [`resonance`]) `spectral` only.

use crate::cancel::{Cancel, Cancelled};
use crate::error::Num;
use crate::limits::{
    check_count, check_memory, planned_bytes, LimitError, MAX_SIM_SAMPLES, SIM_BYTES_PER_SAMPLE,
};
use crate::model::{Coord, Model, Observable, Vec8};
use crate::modes::NormalModes;
use stream::{FreeMotion, SimChunk};

pub mod driven;
mod init;
pub mod resonance;
pub mod stream;

pub use init::{
    check_sampling, default_sim_nperseg, describe_run, initial_state, parse_coordinates,
    readout_text, record_description, set_coordinate, Excitation, MAX_DEFAULT_SIM_NPERSEG,
    MIN_SIM_NPERSEG,
};

/// Refuses a simulation of `n_samples` (a float: `floor(duration / dt)` may be beyond any
/// integer) over [`MAX_SIM_SAMPLES`] or over the memory available ([`SIM_BYTES_PER_SAMPLE`]
/// each, outputs included), before anything is allocated. `what` names the request in the
/// message, e.g. `--duration 9e7 s at --step 0.1 s`.
pub fn check_samples<W: Into<crate::option_key::Message>>(
    what: impl Fn() -> W,
    n_samples: f64,
) -> Result<(), LimitError> {
    check_count(&what, n_samples, "samples", MAX_SIM_SAMPLES)?;
    // Within the limit, so a whole number of samples that fits a usize.
    let n = n_samples as usize;
    check_memory(&what, planned_bytes(n, SIM_BYTES_PER_SAMPLE))
}

/// Initial conditions in crate coordinate order ([`crate::model::Coord::ALL`]), SI units
/// (rad, m; rad/s, m/s).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct InitialState {
    /// Generalized coordinates at t = 0.
    pub q: [f64; 8],
    /// Generalized velocities at t = 0.
    pub qdot: [f64; 8],
}

/// Sampling, duration and readout noise of a simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimConfig {
    /// Sampling step (s). The paper's value is 0.1 s.
    pub dt_s: f64,
    /// Length of the record (s). The paper's value is 12 h = 43 200 s.
    pub duration_s: f64,
    /// White readout noise per observable: one-sided ASD in observable unit / sqrt(Hz).
    /// Observables not listed are noiseless.
    pub readout_asd: Vec<(Observable, f64)>,
    /// Seed of the noise generator.
    pub seed: u64,
    /// Polled between chunks of [`PROGRESS_STRIDE`] samples by [`simulate_with_progress`]; a
    /// caller of [`stream::FreeMotion`] polls it between the chunks it asks for.
    pub cancel: Cancel,
}

impl Default for SimConfig {
    /// The paper's setting: 0.1 s for 12 h, X read out with 9 nm/sqrt(Hz), seed 0.
    fn default() -> Self {
        SimConfig {
            dt_s: 0.1,
            duration_s: 43_200.0,
            readout_asd: vec![(Observable::X, 9e-9)],
            seed: 0,
            cancel: Cancel::never(),
        }
    }
}

impl SimConfig {
    /// Same as the default but without readout noise.
    pub fn noiseless() -> Self {
        SimConfig {
            readout_asd: Vec::new(),
            ..SimConfig::default()
        }
    }

    /// Number of samples `floor(duration / dt)` (to within a relative 1e-9), unvalidated.
    fn n_samples_f64(&self) -> f64 {
        (self.duration_s / self.dt_s * (1.0 + 1e-9)).floor()
    }
}

/// A simulated record.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Simulation {
    /// Sampling step (s); sample `i` is at `t = i dt_s`.
    pub dt_s: f64,
    /// Generalized coordinates per sample, crate coordinate order (noiseless).
    pub q: Vec<[f64; 8]>,
    /// All seven observables in [`Observable::ALL`] order, with readout noise where configured.
    pub observables: Vec<(Observable, Vec<f64>)>,
}

impl Simulation {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// True when there are no samples (never the case for a result of [`simulate`]).
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }

    /// Sampling frequency 1 / dt (Hz).
    pub fn fs_hz(&self) -> f64 {
        1.0 / self.dt_s
    }

    /// The series of one observable.
    pub fn observable(&self, o: Observable) -> &[f64] {
        &self.observables[o.index()].1
    }

    /// The series of one generalized coordinate (copied out of the per-sample layout).
    pub fn coordinate(&self, index: usize) -> Vec<f64> {
        self.q.iter().map(|q| q[index]).collect()
    }
}

/// Why a simulation was refused. Every variant names the value and what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// Cancelled through the configuration's token ([`crate::cancel`]).
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
    /// An initial coordinate or rate outside the linear model's range, or not finite.
    #[error(
        "initial {what} of {coordinate} = {} {unit} is not allowed: must be finite and at most \
         {} {unit} in magnitude (the model is linearized about the equilibrium)",
        crate::error::Num(*.value),
        crate::error::Num(*.max)
    )]
    InitialOutOfRange {
        /// The coordinate.
        coordinate: &'static str,
        /// `value` or `rate`.
        what: &'static str,
        /// The value given.
        value: f64,
        /// Its unit.
        unit: &'static str,
        /// The largest magnitude allowed.
        max: f64,
    },
    /// The model has non-zero loss angles.
    #[error(
        "the model is damped (non-zero loss angles in [loss]): exact free-motion propagation \
         supports only the undamped model; set every loss.*_rad to 0"
    )]
    Damped,
    /// Non-positive or non-finite step.
    #[error("sampling step dt = {dt_s} s is not allowed: must be finite and > 0")]
    InvalidStep {
        /// The step given (s).
        dt_s: f64,
    },
    /// Non-positive or non-finite duration.
    #[error("duration = {duration_s} s is not allowed: must be finite and > 0")]
    InvalidDuration {
        /// The duration given (s).
        duration_s: f64,
    },
    /// duration / dt gives fewer than 2 samples.
    #[error(
        "duration {duration_s} s at dt = {dt_s} s gives {n_samples} sample(s): at least 2 are \
         needed (duration >= 2 dt)"
    )]
    TooFewSamples {
        /// The duration given (s).
        duration_s: f64,
        /// The step given (s).
        dt_s: f64,
        /// floor(duration / dt).
        n_samples: f64,
    },
    /// duration / dt is above [`MAX_SIM_SAMPLES`] or the memory available
    /// ([`check_samples`]).
    #[error(transparent)]
    TooLarge(#[from] LimitError),
    /// A non-finite initial coordinate or velocity.
    #[error("initial {what}[{index}] = {value} is not allowed: must be finite")]
    InvalidInitial {
        /// "q" or "qdot".
        what: &'static str,
        /// Coordinate index (crate order).
        index: usize,
        /// The value given.
        value: f64,
    },
    /// A negative or non-finite readout ASD.
    #[error("readout ASD of {observable} = {asd} is not allowed: must be finite and >= 0")]
    InvalidReadout {
        /// Observable name.
        observable: &'static str,
        /// The ASD given.
        asd: f64,
    },
    /// A tilt drive that cannot be propagated ([`driven`]): empty, ragged or non-finite.
    #[error("tilt drive: {message}")]
    InvalidDrive {
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A mode with w^2 <= 0 (statically unstable or neutral pendulum): no oscillatory solution.
    #[error(
        "mode nu_{index} has w^2 = {omega_sq:e} rad^2/s^2: free motion needs every w^2 > 0 \
         (the pendulum is statically unstable or neutral for these parameters)"
    )]
    NonOscillatoryMode {
        /// 1-based mode index.
        index: usize,
        /// Its eigenvalue.
        omega_sq: f64,
    },
}

/// Exact step-by-step propagation of the free motion in the normal-mode basis.
#[derive(Debug, Clone)]
pub struct ModalPropagator {
    /// Mass-normalized shapes, column k = mode k (nu_{k+1}).
    shapes: [[f64; 8]; 8],
    /// Angular frequencies w_k (rad/s).
    omega: [f64; 8],
    /// cos(w_k dt), sin(w_k dt).
    cos: [f64; 8],
    sin: [f64; 8],
    /// Initial (a_k, adot_k / w_k).
    u0: [f64; 8],
    v0: [f64; 8],
    /// Current (a_k, adot_k / w_k).
    u: [f64; 8],
    v: [f64; 8],
    dt_s: f64,
    steps: u64,
}

impl ModalPropagator {
    /// Modal decomposition of `init` for steps of `dt_s`. Checks that the model is undamped,
    /// every mode oscillatory, the step and the initial state finite.
    pub fn new(model: &Model, init: &InitialState, dt_s: f64) -> Result<ModalPropagator, SimError> {
        if !model.is_undamped() {
            return Err(SimError::Damped);
        }
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(SimError::InvalidStep { dt_s });
        }
        for (what, x) in [("q", &init.q), ("qdot", &init.qdot)] {
            if let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                return Err(SimError::InvalidInitial { what, index, value });
            }
        }
        let modes = NormalModes::new(model);
        let m = model.mass();
        let mq = m * Vec8::from(init.q);
        let mqdot = m * Vec8::from(init.qdot);
        let mut p = ModalPropagator {
            shapes: [[0.0; 8]; 8],
            omega: [0.0; 8],
            cos: [0.0; 8],
            sin: [0.0; 8],
            u0: [0.0; 8],
            v0: [0.0; 8],
            u: [0.0; 8],
            v: [0.0; 8],
            dt_s,
            steps: 0,
        };
        for (k, mode) in modes.modes.iter().enumerate() {
            if !(mode.omega_sq > 0.0 && mode.omega_sq.is_finite()) {
                return Err(SimError::NonOscillatoryMode {
                    index: mode.index,
                    omega_sq: mode.omega_sq,
                });
            }
            let w = mode.omega_sq.sqrt();
            p.omega[k] = w;
            p.shapes[k] = std::array::from_fn(|i| mode.shape[i]);
            let (s, c) = (w * dt_s).sin_cos();
            p.cos[k] = c;
            p.sin[k] = s;
            p.u0[k] = mode.shape.dot(&mq);
            p.v0[k] = mode.shape.dot(&mqdot) / w;
        }
        p.u = p.u0;
        p.v = p.v0;
        Ok(p)
    }

    /// Angular frequencies w_k (rad/s), nu_1 first.
    pub fn omega(&self) -> &[f64; 8] {
        &self.omega
    }

    /// Mass-normalized shape of mode k (0-based), crate coordinate order.
    pub fn shape(&self, k: usize) -> &[f64; 8] {
        &self.shapes[k]
    }

    /// The step (s).
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// Current modal state `(a_k, adot_k / w_k)`.
    pub fn modal_state(&self) -> ([f64; 8], [f64; 8]) {
        (self.u, self.v)
    }

    /// Initial modal state `(a_k0, adot_k0 / w_k)`.
    pub fn initial_modal_state(&self) -> ([f64; 8], [f64; 8]) {
        (self.u0, self.v0)
    }

    /// Modal energies `(adot_k^2 + w_k^2 a_k^2) / 2` (J), conserved by the exact motion.
    pub fn modal_energy(&self) -> [f64; 8] {
        std::array::from_fn(|k| {
            0.5 * self.omega[k].powi(2) * (self.u[k].powi(2) + self.v[k].powi(2))
        })
    }

    /// Advances by one step `dt`: an exact 2x2 rotation per mode.
    #[inline]
    pub fn step(&mut self) {
        for k in 0..8 {
            let (u, v) = (self.u[k], self.v[k]);
            self.u[k] = self.cos[k] * u + self.sin[k] * v;
            self.v[k] = self.cos[k] * v - self.sin[k] * u;
        }
        self.steps += 1;
    }

    /// Current generalized coordinates `q = V a`.
    pub fn q(&self) -> [f64; 8] {
        self.combine(&self.u, 1.0)
    }

    /// Current generalized velocities `qdot = V (w v)`.
    pub fn qdot(&self) -> [f64; 8] {
        let wv: [f64; 8] = std::array::from_fn(|k| self.omega[k] * self.v[k]);
        self.combine(&wv, 1.0)
    }

    fn combine(&self, a: &[f64; 8], scale: f64) -> [f64; 8] {
        let mut q = [0.0; 8];
        for (k, shape) in self.shapes.iter().enumerate() {
            let ak = a[k] * scale;
            for i in 0..8 {
                q[i] += shape[i] * ak;
            }
        }
        q
    }
}

/// Frequency (Hz) at which a sinusoid of `f_hz` appears when sampled at `fs_hz`: folded into
/// `0 ..= fs_hz / 2`.
pub fn aliased_frequency_hz(f_hz: f64, fs_hz: f64) -> f64 {
    let r = f_hz.rem_euclid(fs_hz);
    r.min(fs_hz - r)
}

/// Free motion from `init`, sampled every `cfg.dt_s` for `cfg.duration_s`, with white readout
/// noise on the observables listed in `cfg.readout_asd`.
pub fn simulate(
    model: &Model,
    init: &InitialState,
    cfg: &SimConfig,
) -> Result<Simulation, SimError> {
    simulate_with_progress(model, init, cfg, &mut |_, _| {})
}

/// Samples between two calls of the progress callback of [`simulate_with_progress`].
pub const PROGRESS_STRIDE: usize = 1 << 16;

/// [`simulate`], calling `progress(samples_done, n_samples)` every [`PROGRESS_STRIDE`] samples
/// and once at the end (the library never draws to the terminal). The whole record is held in
/// memory (at most [`MAX_SIM_SAMPLES`] samples, and what the memory available allows); a long
/// record is better produced chunk by chunk with [`stream::FreeMotion`], which gives the same
/// numbers.
pub fn simulate_with_progress(
    model: &Model,
    init: &InitialState,
    cfg: &SimConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Simulation, SimError> {
    let n = stream::sample_count(cfg, MAX_SIM_SAMPLES)?;
    check_samples(
        || {
            format!(
                "duration {} s at dt = {} s",
                Num(cfg.duration_s),
                Num(cfg.dt_s)
            )
        },
        n as f64,
    )?;
    let mut motion = FreeMotion::with_limit(model, init, cfg, true, MAX_SIM_SAMPLES)?;
    let mut q = Vec::with_capacity(n);
    let mut obs: Vec<Vec<f64>> = (0..7).map(|_| Vec::with_capacity(n)).collect();
    let mut chunk = SimChunk::default();
    while {
        cfg.cancel.check()?;
        motion.next_chunk(PROGRESS_STRIDE, &mut chunk)
    } {
        q.extend_from_slice(&chunk.q);
        for (all, part) in obs.iter_mut().zip(&chunk.observables) {
            all.extend_from_slice(part);
        }
        if motion.samples_done() < n {
            progress(motion.samples_done(), n);
        }
    }
    progress(n, n);
    Ok(Simulation {
        dt_s: cfg.dt_s,
        q,
        observables: Observable::ALL.into_iter().zip(obs).collect(),
    })
}

/// The largest initial coordinate: 1 rad for an angle, 1 m for an elongation. The model is
/// linearized about the equilibrium (small angles); far larger amplitudes are outside it and,
/// squared in the spectra, would overflow `f64`.
pub const MAX_INITIAL_COORDINATE: f64 = 1.0;

/// The largest initial rate: an amplitude of [`MAX_INITIAL_COORDINATE`] at 100 Hz, far above
/// every mode (rad/s or m/s).
pub const MAX_INITIAL_RATE: f64 = MAX_INITIAL_COORDINATE * std::f64::consts::TAU * 100.0;

/// Refuses an initial state outside the linear model's range (see
/// [`MAX_INITIAL_COORDINATE`], [`MAX_INITIAL_RATE`]) or not finite, naming the coordinate.
pub fn check_initial_state(init: &InitialState) -> Result<(), SimError> {
    for c in Coord::ALL {
        let (q, v) = (init.q[c.index()], init.qdot[c.index()]);
        if !(q.is_finite() && q.abs() <= MAX_INITIAL_COORDINATE) {
            return Err(SimError::InitialOutOfRange {
                coordinate: c.name(),
                what: "value",
                value: q,
                unit: c.unit(),
                max: MAX_INITIAL_COORDINATE,
            });
        }
        if !(v.is_finite() && v.abs() <= MAX_INITIAL_RATE) {
            return Err(SimError::InitialOutOfRange {
                coordinate: c.name(),
                what: "rate",
                value: v,
                unit: if c.unit() == "m" { "m/s" } else { "rad/s" },
                max: MAX_INITIAL_RATE,
            });
        }
    }
    Ok(())
}

/// A static displacement along X released from rest: the static deflection `K q = B[:, F_b.x] F`
/// under a force along x on the test mass, scaled so that the observable X equals `x_m`;
/// `qdot = 0`. If the model's X does not respond to F_b.x statically the result is non-finite
/// and [`simulate`] refuses it ([`SimError::InvalidInitial`]).
pub fn kick_x(model: &Model, x_m: f64) -> InitialState {
    let f_bx = crate::model::ForceInput::from_name("F_b.x").expect("F_b.x is a force component");
    let b: Vec8 = model.force_matrix().column(f_bx.index()).into();
    let q = model
        .stiffness()
        .lu()
        .solve(&b)
        .unwrap_or_else(|| Vec8::from_element(f64::NAN));
    let x = (model.observation().row(Observable::X.index()) * q)[(0, 0)];
    let q = q * (x_m / x);
    InitialState {
        q: std::array::from_fn(|i| q[i]),
        qdot: [0.0; 8],
    }
}

/// Energy per mode (J) of [`equal_energy_init`] in the default run of `tiltnoise simulate`:
/// 1e-12 J gives torsion amplitudes of about 1e-3 rad, swinging amplitudes of a few
/// micrometres and bouncing amplitudes of tens of nanometres, all well above the 9 nm/sqrt(Hz)
/// readout noise of X in 12 h of data and well inside the small-oscillation regime.
pub const DEFAULT_MODE_ENERGY_J: f64 = 1e-12;

/// Phase (rad) given to mode `k` (0-based) by [`equal_energy_init`]: arbitrary, distinct,
/// fixed so that runs are reproducible.
pub fn equal_energy_phase_rad(k: usize) -> f64 {
    0.7 + 1.3 * k as f64
}

/// Initial state putting the same energy `energy_j` (J) into each of the eight normal modes,
/// with the phases [`equal_energy_phase_rad`]: modal amplitude `a_k = sqrt(2 E) / w_k`,
/// `q = sum_k v_k a_k cos(p_k)`, `qdot = sum_k v_k a_k w_k sin(p_k)`. Equal energy per mode is
/// what thermal equilibrium gives (equipartition), so every mode is excited and each channel's
/// peaks follow the observability table. The paper's Figure 3 used "many arbitrary but
/// reasonable initial conditions" that it does not list; this is the documented substitute.
pub fn equal_energy_init(model: &Model, energy_j: f64) -> InitialState {
    let modes = NormalModes::new(model);
    let mut q = Vec8::zeros();
    let mut qdot = Vec8::zeros();
    for (k, mode) in modes.modes.iter().enumerate() {
        let w = mode.omega_sq.max(0.0).sqrt();
        let a = (2.0 * energy_j).sqrt() / w;
        let p = equal_energy_phase_rad(k);
        q += mode.shape * (a * p.cos());
        qdot += mode.shape * (a * w * p.sin());
    }
    InitialState {
        q: std::array::from_fn(|i| q[i]),
        qdot: std::array::from_fn(|i| qdot[i]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aliasing_folds_into_nyquist_band() {
        assert!((aliased_frequency_hz(7.7443, 10.0) - 2.2557).abs() < 1e-12);
        assert!((aliased_frequency_hz(10.8143, 10.0) - 0.8143).abs() < 1e-12);
        assert_eq!(aliased_frequency_hz(0.4, 10.0), 0.4);
    }
}
