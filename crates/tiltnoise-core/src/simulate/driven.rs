//! The undamped model driven by the floor's motion (tilt and translation), propagated exactly in
//! the normal-mode basis for a piecewise-linear drive at a fine step, sampled every `keep_every`
//! steps: a record of the observables made from a known tilt or translation series, for example
//! to test `subtract`.
//!
//! # Method
//!
//! A ground input enters as `M q'' + K q = G0 u - G2 u''` (the frequency-domain forcing
//! `(G0 + w^2 G2) u` of [`crate::model::tilt`]; for a translation `G0 = 0` and `G2` the apparent
//! forces of [`crate::model::translation`]). The substitution `q = p - M^-1 G2 u` removes
//! the second derivative: `M p'' + K p = B0 u` with `B0 = G0 + K M^-1 G2`, the split of the
//! state-space method ([`crate::tf::StateSpace`]). In the mass-normalized modes `V` of
//! [`NormalModes`], `p = V a` and `a_k'' + w_k^2 a_k = b_k(t)` with `b = V^T B0 u`.
//!
//! Over one step `h` with `u` linear in time, `b_k(t) = b_n + s_n (t - t_n)`, the deviation
//! `d = a_k - b_k / w_k^2` obeys `d'' + w_k^2 d = 0` exactly (a linear forcing has a linear
//! particular solution), so `(d, d' / w_k)` turns by the angle `w_k h` as in
//! [`super::ModalPropagator`]; only `d'` jumps where the slope of `u` changes. The step is exact
//! for a piecewise-linear `u` whatever `w_k h` is. The run starts at the quasi-static state of
//! the first step (`a = b / w^2`, `a' = s / w^2`), so nothing rings at the start.
//!
//! # What the piecewise-linear input costs
//!
//! A band-limited tilt sampled at the fine step `h` and joined by straight lines is seen
//! through `sinc^2(f h)`, a relative error of `(pi f h)^2 / 3` at frequency `f`, plus images of
//! the response at `f + m / h` of relative size about `(f h)^2`: `3e-5` at 30 mHz for
//! `h = 0.1 s`. [`drive_from_record`] therefore interpolates a coarse record to a finer step
//! first (band-limited, [`bandlimited_upsample`]).
//!
//! A translation's response vanishes as `w^2` at low frequency while `p` and `M^-1 G2 u` are
//! each of the order of `u`: the sum loses the factor `(f / f_1)^2` of relative accuracy below
//! the lowest mode `f_1` of the block (the ratio `eps (f_1 / f)^2`, 1e-10 at 0.1 mHz for Table
//! I's swing-x+torsion block). A drive's constant offset or linear trend excites nothing (no
//! acceleration) and comes out as zero to rounding.
//!
//! Only the undamped model is supported, like [`super::simulate`].

use super::{InitialState, SimError, Simulation};
use crate::cancel::Cancel;
use crate::limits::{check_memory, planned_bytes};
use crate::model::{Input, Model, Observable};
use crate::modes::NormalModes;
use crate::rng::Rng;
use num_complex::Complex64;
use realfft::RealFftPlanner;

/// Largest factor by which [`drive_from_record`] refines the step.
pub const MAX_OVERSAMPLE: usize = 1000;

/// The floor's motion at a fine step: the pendulum's drive, tilt in the crate's sign convention
/// (rad) and translation along the lab axes (m).
#[derive(Debug, Clone, PartialEq)]
pub struct GroundDrive {
    /// Step between samples (s).
    pub step_s: f64,
    /// The ground inputs driven ([`Input::Tilt`], [`Input::Translation`]), each once, at least
    /// one.
    pub inputs: Vec<Input>,
    /// One series per input, all of the same length (>= 2): tilt angle (rad) or displacement
    /// (m).
    pub samples: Vec<Vec<f64>>,
}

/// What to record from a driven run.
#[derive(Debug, Clone, PartialEq)]
pub struct DrivenConfig {
    /// Record every this many steps of the drive (>= 1); the record's step is
    /// `keep_every * step_s`, its first sample at `t = 0`.
    pub keep_every: usize,
    /// White readout noise per observable: one-sided ASD in unit/sqrt(Hz) at the record's rate.
    pub readout_asd: Vec<(Observable, f64)>,
    /// Seed of the readout noise (stream 0, as [`super::simulate`]).
    pub seed: u64,
    /// Polled every [`super::PROGRESS_STRIDE`] steps.
    pub cancel: Cancel,
}

/// Exact response of the undamped model to `drive` (see the module docs), recorded every
/// `cfg.keep_every` steps, with white readout noise.
///
/// # Errors
///
/// [`SimError::Damped`] for a damped model; [`SimError::InvalidDrive`] for an empty, ragged
/// or non-finite drive or a zero `keep_every`; [`SimError::InvalidStep`],
/// [`SimError::InvalidReadout`], [`SimError::NonOscillatoryMode`], [`SimError::TooLarge`].
pub fn simulate_driven(
    model: &Model,
    drive: &GroundDrive,
    cfg: &DrivenConfig,
) -> Result<Simulation, SimError> {
    if !model.is_undamped() {
        return Err(SimError::Damped);
    }
    let h = drive.step_s;
    if !(h.is_finite() && h > 0.0) {
        return Err(SimError::InvalidStep { dt_s: h });
    }
    check_drive(drive)?;
    if cfg.keep_every == 0 {
        return Err(SimError::InvalidDrive {
            message: "keep_every = 0: at least every step must be kept".into(),
        });
    }
    for &(o, asd) in &cfg.readout_asd {
        if !(asd.is_finite() && asd >= 0.0) {
            return Err(SimError::InvalidReadout {
                observable: o.name(),
                asd,
            });
        }
    }
    let n_fine = drive.samples[0].len();
    let n_out = (n_fine - 1) / cfg.keep_every + 1;
    super::check_samples(
        || {
            format!(
                "a driven record of {n_fine} steps kept every {}",
                cfg.keep_every
            )
        },
        n_out as f64,
    )?;

    let dyn_ = Dynamics::new(model)?;
    let (omega, modes) = (dyn_.omega, &dyn_.modes);
    let c = model.observation();
    let columns: Vec<usize> = drive.inputs.iter().map(|&i| ground_column(i)).collect();
    let modal_in: Vec<[f64; 8]> = columns.iter().map(|&a| dyn_.modal_in[a]).collect();
    let feed: Vec<[f64; 8]> = columns.iter().map(|&a| dyn_.feed[a]).collect();
    let shapes: [[f64; 8]; 8] =
        std::array::from_fn(|k| std::array::from_fn(|i| modes.modes[k].shape[i]));

    let forcing_at = |j: usize| -> [f64; 8] {
        let mut b = [0.0; 8];
        for (series, m) in drive.samples.iter().zip(&modal_in) {
            for k in 0..8 {
                b[k] += m[k] * series[j];
            }
        }
        b
    };
    let (cos, sin): ([f64; 8], [f64; 8]) = (
        std::array::from_fn(|k| (omega[k] * h).cos()),
        std::array::from_fn(|k| (omega[k] * h).sin()),
    );
    let w2: [f64; 8] = std::array::from_fn(|k| omega[k] * omega[k]);
    // State (a_k, a_k') at the current step, quasi-static at the start.
    let mut b_now = forcing_at(0);
    let mut b_next = forcing_at(1);
    let mut a: [f64; 8] = std::array::from_fn(|k| b_now[k] / w2[k]);
    let mut a_dot: [f64; 8] = std::array::from_fn(|k| (b_next[k] - b_now[k]) / h / w2[k]);

    let mut q_out = Vec::with_capacity(n_out);
    let mut obs: Vec<Vec<f64>> = (0..7).map(|_| Vec::with_capacity(n_out)).collect();
    let record = |j: usize, a: &[f64; 8], q_out: &mut Vec<[f64; 8]>, obs: &mut [Vec<f64>]| {
        let mut q = [0.0; 8];
        for (k, shape) in shapes.iter().enumerate() {
            for i in 0..8 {
                q[i] += shape[i] * a[k];
            }
        }
        for (series, f) in drive.samples.iter().zip(&feed) {
            for i in 0..8 {
                q[i] += f[i] * series[j];
            }
        }
        for (o, out) in obs.iter_mut().enumerate() {
            out.push((0..8).map(|i| c[(o, i)] * q[i]).sum());
        }
        q_out.push(q);
    };
    record(0, &a, &mut q_out, &mut obs);
    for j in 0..n_fine - 1 {
        if j % super::PROGRESS_STRIDE == 0 {
            cfg.cancel.check()?;
        }
        if j > 0 {
            b_now = b_next;
            b_next = forcing_at(j + 1);
        }
        for k in 0..8 {
            let slope = (b_next[k] - b_now[k]) / h;
            let d = a[k] - b_now[k] / w2[k];
            let v = (a_dot[k] - slope / w2[k]) / omega[k];
            let (d1, v1) = (cos[k] * d + sin[k] * v, cos[k] * v - sin[k] * d);
            a[k] = d1 + b_next[k] / w2[k];
            a_dot[k] = omega[k] * v1 + slope / w2[k];
        }
        if (j + 1) % cfg.keep_every == 0 {
            record(j + 1, &a, &mut q_out, &mut obs);
        }
    }

    let dt_out = h * cfg.keep_every as f64;
    let mut rng = Rng::stream(cfg.seed, 0);
    let sigma_per_asd = (0.5 / dt_out).sqrt();
    for &(o, asd) in &cfg.readout_asd {
        if asd == 0.0 {
            continue;
        }
        for x in obs[o.index()].iter_mut() {
            *x += asd * sigma_per_asd * rng.gaussian();
        }
    }
    Ok(Simulation {
        dt_s: dt_out,
        q: q_out,
        observables: Observable::ALL.into_iter().zip(obs).collect(),
    })
}

/// The column of a ground input in [`Dynamics`]: tilt axes 0..3, translations 3..6.
fn ground_column(input: Input) -> usize {
    match input {
        Input::Tilt(a) => a.index(),
        Input::Translation(a) => 3 + a.index(),
        Input::Force(_) => unreachable!("check_drive admits ground inputs only"),
    }
}

/// The modes and the ground forcing in the form the stepping uses.
struct Dynamics {
    modes: NormalModes,
    /// `w_k` (rad/s).
    omega: [f64; 8],
    /// Per ground column ([`ground_column`]): modal forcing `V^T B0 e_axis`.
    modal_in: [[f64; 8]; 6],
    /// Per ground column: the feed-through `-M^-1 G2 e_axis` of `q`.
    feed: [[f64; 8]; 6],
}

impl Dynamics {
    fn new(model: &Model) -> Result<Dynamics, SimError> {
        let modes = NormalModes::new(model);
        let mut omega = [0.0; 8];
        for (k, mode) in modes.modes.iter().enumerate() {
            if !(mode.omega_sq > 0.0 && mode.omega_sq.is_finite()) {
                return Err(SimError::NonOscillatoryMode {
                    index: mode.index,
                    omega_sq: mode.omega_sq,
                });
            }
            omega[k] = mode.omega_sq.sqrt();
        }
        let forcing = model.tilt_forcing();
        let lu = model.mass().lu();
        let m_inv = |g2| lu.solve(g2).expect("the mass matrix is positive definite");
        let (tilt, translation) = (m_inv(&forcing.g2), m_inv(&model.translation_forcing().g2));
        // B0 = G0 + K M^-1 G2; a translation has G0 = 0.
        let b0 = [
            forcing.g0 + model.stiffness() * tilt,
            model.stiffness() * translation,
        ];
        let m_inv_g2 = [tilt, translation];
        let modal_in = std::array::from_fn(|c| {
            std::array::from_fn(|k| modes.modes[k].shape.dot(&b0[c / 3].column(c % 3)))
        });
        let feed = std::array::from_fn(|c| std::array::from_fn(|i| -m_inv_g2[c / 3][(i, c % 3)]));
        Ok(Dynamics {
            modes,
            omega,
            modal_in,
            feed,
        })
    }
}

/// The state [`simulate_driven`] starts from: quasi-static for the drive's first step
/// (`a_k = b_k / w_k^2`, `a_k' = b_k' / w_k^2`, `q = V a - M^-1 G2 u`), so that nothing rings
/// at the start.
///
/// # Errors
///
/// As [`simulate_driven`].
pub fn quasi_static_start(model: &Model, drive: &GroundDrive) -> Result<InitialState, SimError> {
    check_drive(drive)?;
    let d = Dynamics::new(model)?;
    let h = drive.step_s;
    let (mut q, mut qdot) = ([0.0; 8], [0.0; 8]);
    for (&input, series) in drive.inputs.iter().zip(&drive.samples) {
        let (u, du) = (series[0], (series[1] - series[0]) / h);
        let a = ground_column(input);
        for k in 0..8 {
            let w2 = d.omega[k] * d.omega[k];
            for i in 0..8 {
                q[i] += d.modes.modes[k].shape[i] * d.modal_in[a][k] * u / w2;
                qdot[i] += d.modes.modes[k].shape[i] * d.modal_in[a][k] * du / w2;
            }
        }
        for i in 0..8 {
            q[i] += d.feed[a][i] * u;
            qdot[i] += d.feed[a][i] * du;
        }
    }
    Ok(InitialState { q, qdot })
}

fn check_drive(drive: &GroundDrive) -> Result<(), SimError> {
    let bad = |message: String| Err(SimError::InvalidDrive { message });
    if drive.inputs.is_empty() || drive.inputs.len() != drive.samples.len() {
        return bad(format!(
            "{} inputs and {} series: one series per input, at least one",
            drive.inputs.len(),
            drive.samples.len()
        ));
    }
    for (k, input) in drive.inputs.iter().enumerate() {
        if !input.is_ground() {
            return bad(format!(
                "{} is not a motion of the floor: a drive is tilt (theta_t, eta_t, phi_t) or \
                 translation (x_t, y_t, z_t)",
                input.name()
            ));
        }
        if drive.inputs[..k].contains(input) {
            return bad(format!("{} is driven twice", input.name()));
        }
    }
    let n = drive.samples[0].len();
    if n < 2 {
        return bad(format!("{n} sample(s): at least 2 are needed"));
    }
    for (input, series) in drive.inputs.iter().zip(&drive.samples) {
        if series.len() != n {
            return bad(format!(
                "{} has {} samples and {} has {n}",
                input.name(),
                series.len(),
                drive.inputs[0].name()
            ));
        }
        if let Some((i, v)) = series.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return bad(format!("{} sample {i} = {v} is not finite", input.name()));
        }
    }
    Ok(())
}

/// A record of sampling step `dt_s` (one series per ground input of `inputs`) turned into the
/// drive of [`simulate_driven`]: interpolated
/// to `dt_s / oversample` by [`bandlimited_upsample`], scaled by `gains[input]` and delayed by
/// `delay_steps` fine steps (`drive(t) = gain record(t - delay)`; before the record's first
/// sample or after its last the end value is held).
///
/// # Errors
///
/// [`SimError::InvalidDrive`] for an oversampling factor outside `1 ..= MAX_OVERSAMPLE`, a
/// non-finite gain, or a record [`simulate_driven`] would refuse; [`SimError::TooLarge`] when
/// the fine drive does not fit into memory.
pub fn drive_from_record(
    dt_s: f64,
    inputs: &[Input],
    record: &[Vec<f64>],
    oversample: usize,
    gains: &[f64],
    delay_steps: i64,
) -> Result<GroundDrive, SimError> {
    if !(1..=MAX_OVERSAMPLE).contains(&oversample) {
        return Err(SimError::InvalidDrive {
            message: format!("oversampling factor {oversample}: must be 1 ..= {MAX_OVERSAMPLE}"),
        });
    }
    if let Some(g) = gains.iter().find(|g| !g.is_finite()) {
        return Err(SimError::InvalidDrive {
            message: format!("gain {g} is not finite"),
        });
    }
    check_drive(&GroundDrive {
        step_s: dt_s,
        inputs: inputs.to_vec(),
        samples: record.to_vec(),
    })?;
    let n = record[0].len();
    let n_fine = (n - 1) * oversample + 1;
    check_memory(
        || format!("a drive of {n_fine} steps on {} inputs", inputs.len()),
        planned_bytes(n * oversample * (inputs.len() + 2), 16),
    )?;
    let samples = record
        .iter()
        .zip(gains)
        .map(|(x, &g)| {
            let fine = bandlimited_upsample(x, oversample);
            (0..n_fine as i64)
                .map(|j| g * fine[(j - delay_steps).clamp(0, n_fine as i64 - 1) as usize])
                .collect()
        })
        .collect();
    Ok(GroundDrive {
        step_s: dt_s / oversample as f64,
        inputs: inputs.to_vec(),
        samples,
    })
}

/// `x` (at least 2 samples) interpolated to `factor` times its rate, band-limited:
/// `(x.len() - 1) * factor + 1` samples, equal to `x` at every `factor`-th one. The line through
/// the two end samples is removed first and added back (interpolated exactly), so that the
/// periodic extension the FFT assumes has no jump at the ends; the rest is interpolated by zero
/// padding its discrete Fourier transform (an even length's Nyquist bin split between `+-n/2`).
/// Exact when the record minus that line is a trigonometric polynomial of period `n` samples
/// below the Nyquist frequency; otherwise the error comes from the kink of the periodic
/// extension at the ends and is largest near them.
pub fn bandlimited_upsample(x: &[f64], factor: usize) -> Vec<f64> {
    let n = x.len();
    let (x0, x1) = (x[0], x[n - 1]);
    let line = |t: f64| x0 + (x1 - x0) * t / (n - 1) as f64;
    if factor == 1 {
        return x.to_vec();
    }
    let mut planner = RealFftPlanner::<f64>::new();
    let mut buf: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, &v)| v - line(i as f64))
        .collect();
    let fwd = planner.plan_fft_forward(n);
    let mut spec = fwd.make_output_vec();
    fwd.process(&mut buf, &mut spec)
        .expect("buffers sized by the plan");
    let long = n * factor;
    let inv = planner.plan_fft_inverse(long);
    let mut wide = inv.make_input_vec();
    for (k, s) in spec.iter().enumerate() {
        wide[k] = if n % 2 == 0 && k == n / 2 {
            s * 0.5
        } else {
            *s
        };
    }
    // The inverse transform of a real signal ignores the imaginary part of DC; the zero-padded
    // Nyquist bin of the long transform is 0.
    wide[0] = Complex64::new(wide[0].re, 0.0);
    let mut out = inv.make_output_vec();
    inv.process(&mut wide, &mut out)
        .expect("buffers sized by the plan");
    let n_fine = (n - 1) * factor + 1;
    out.truncate(n_fine);
    for (j, v) in out.iter_mut().enumerate() {
        *v = *v / n as f64 + line(j as f64 / factor as f64);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line plus products `sin(2 pi k t / n) sin(2 pi k (t + 1) / n)` (trigonometric
    /// polynomials of period n that vanish at both end samples) is interpolated exactly: the
    /// line through the ends is the line itself and the rest is band-limited and periodic.
    /// Tolerance: the FFT's rounding, `eps log2(n f)` relative to the signal's size, times a
    /// small constant for the two transforms and the line.
    #[test]
    fn upsampling_is_exact_for_a_line_plus_a_periodic_band_limited_signal() {
        let n = 64;
        let tau = std::f64::consts::TAU;
        let p = |k: f64, t: f64| {
            (tau * k * t / n as f64).sin() * (tau * k * (t + 1.0) / n as f64).sin()
        };
        let f = |t: f64| 0.3 + 0.01 * t + p(1.0, t) + 0.2 * p(5.0, t);
        let x: Vec<f64> = (0..n).map(|i| f(i as f64)).collect();
        let factor = 5;
        let fine = bandlimited_upsample(&x, factor);
        assert_eq!(fine.len(), (n - 1) * factor + 1);
        let tol = 16.0 * f64::EPSILON * ((n * factor) as f64).log2() * 2.0;
        for (j, v) in fine.iter().enumerate() {
            let want = f(j as f64 / factor as f64);
            assert!((v - want).abs() <= tol, "j = {j}: {v} vs {want}");
        }
    }

    /// The rounding scale of the quasi-static response of observable `o` per unit of ground
    /// column `a`: the modal sum's terms `|C v_k| |v_k^T B0| / w_k^2`, each with the
    /// eigensolver's relative error `8 eps w_max^2 / w_k^2` (Weyl / Davis-Kahan with the gap
    /// bounded by `w_k^2`) plus `64 eps` of rounding, and `64 eps` on the feed-through; in
    /// units of eps.
    fn static_rounding_scale(model: &Model, d: &Dynamics, o: Observable, a: usize) -> f64 {
        let c = model.observation();
        let w2_max = d.omega.iter().fold(0.0f64, |m, w| m.max(w * w));
        let modal: f64 = (0..8)
            .map(|k| {
                let cv: f64 = (0..8)
                    .map(|i| c[(o.index(), i)] * d.modes.modes[k].shape[i])
                    .sum();
                let w2 = d.omega[k].powi(2);
                (cv * d.modal_in[a][k] / w2).abs() * (64.0 + 8.0 * w2_max / w2)
            })
            .sum();
        let feed: f64 = (0..8)
            .map(|i| (c[(o.index(), i)] * d.feed[a][i]).abs())
            .sum();
        modal + 64.0 * feed
    }

    fn record_all(keep_every: usize) -> DrivenConfig {
        DrivenConfig {
            keep_every,
            readout_asd: Vec::new(),
            seed: 0,
            cancel: Cancel::never(),
        }
    }

    /// A floor moving at constant velocity is not accelerated: from the quasi-static start the
    /// exact response is 0 at every step (the modal part and the feed-through `-M^-1 G2 u`
    /// cancel), for each translation. What the cancellation leaves is within the accuracy
    /// target of every transfer function times the size of the cancelling terms,
    /// `||c||_1 ||M^-1 G2||_inf |u|`.
    #[test]
    fn a_floor_at_constant_velocity_excites_nothing() {
        use crate::model::TranslationAxis;
        use crate::params::Params;
        let model = Model::new(&Params::table_i()).unwrap();
        let d = Dynamics::new(&model).unwrap();
        let n = 2000;
        for axis in TranslationAxis::ALL {
            let input = Input::Translation(axis);
            let drive = GroundDrive {
                step_s: 0.5,
                inputs: vec![input],
                samples: vec![(0..n).map(|j| 1e-6 + 3e-9 * j as f64).collect()],
            };
            let sim = simulate_driven(&model, &drive, &record_all(1)).unwrap();
            let feed = &d.feed[ground_column(input)];
            let feed_size = feed.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for o in Observable::ALL {
                let c_size: f64 = model.observation().row(o.index()).abs().sum();
                for (j, &u) in drive.samples[0].iter().enumerate() {
                    let got = sim.observable(o)[j];
                    let tol = crate::tf::DEFAULT_REL_TOL * c_size * feed_size * u.abs();
                    assert!(
                        got.abs() <= tol,
                        "{}/{} at step {j}: {got:e} (tol {tol:e})",
                        o.name(),
                        axis.name()
                    );
                }
            }
        }
    }

    /// A tilt about y is a rigid rotation of the pendulum with the floor plus a translation of
    /// the suspension point by `-h eta_t` along x (`G2[:, eta_t] + M e_eta_a = -h G2[:, x_t]`,
    /// `model::translation`), and the rigid rotation's forcing `(K_gravity e_eta_a, -M e_eta_a)`
    /// moves `q` by exactly `e_eta_a eta_t`. So for any drive `s(t)`, the response to
    /// `eta_t = s` is `C e_eta_a s - h` times the response to `x_t = s`, sample by sample,
    /// likewise `theta_t` and `+h y_t`. Here `s` is a few tones from 0.2 mHz to 3 Hz over
    /// 4000 s, across the torsion, swing and bounce modes; agreement within the accuracy target
    /// of every transfer function, relative to the largest response.
    #[test]
    fn tilt_is_a_rotation_plus_the_translation_of_the_suspension_point() {
        use crate::model::{Coord, TiltAxis, TranslationAxis};
        use crate::params::Params;
        let model = Model::new(&Params::table_i()).unwrap();
        let h = model.params().length.h_m;
        let step = 0.05;
        let n = 80_000;
        let s: Vec<f64> = (0..n)
            .map(|j| {
                let t = j as f64 * step;
                [(2e-4, 1.0), (1.1e-3, 0.3), (0.37, 0.02), (3.0, 0.003)]
                    .iter()
                    .map(|&(f, a)| a * 1e-6 * (std::f64::consts::TAU * f * t + f).sin())
                    .sum()
            })
            .collect();
        let run = |input: Input| {
            let drive = GroundDrive {
                step_s: step,
                inputs: vec![input],
                samples: vec![s.clone()],
            };
            simulate_driven(&model, &drive, &record_all(10)).unwrap()
        };
        let c = model.observation();
        for (tilt, axis, sign, coord) in [
            (TiltAxis::EtaT, TranslationAxis::XT, -1.0, Coord::EtaA),
            (TiltAxis::ThetaT, TranslationAxis::YT, 1.0, Coord::ThetaA),
        ] {
            let (by_tilt, by_translation) = (run(Input::Tilt(tilt)), run(Input::Translation(axis)));
            for o in Observable::ALL {
                let rigid = c[(o.index(), coord.index())];
                let (a, b) = (by_tilt.observable(o), by_translation.observable(o));
                let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let mut worst = 0.0f64;
                for (j, (&x, &y)) in a.iter().zip(b).enumerate() {
                    let want = rigid * s[10 * j] + sign * h * y;
                    worst = worst.max((x - want).abs());
                }
                assert!(
                    worst <= crate::tf::DEFAULT_REL_TOL * scale,
                    "{}/{} against the rigid rotation and {}: max |diff| {worst:e}, largest \
                     response {scale:e}",
                    o.name(),
                    tilt.name(),
                    axis.name()
                );
            }
        }
    }

    /// A tilt linear in time has `u'' = 0`: from the quasi-static start the exact response is
    /// the static one, `X = H_X,eta(0) u` and `Y = H_Y,theta(0) u`, at every step, however
    /// large `w_k h` (the 0.5 s step is beyond explicit integrators' limit for the bouncing
    /// modes). `H(0)` from the transfer functions (an LU solve of `K`, not the modes).
    /// Tolerance: the modal sum's terms `|C v_k| |v_k^T B0| |u| / w_k^2`, each with the
    /// eigensolver's relative error `8 eps w_max^2 / w_k^2` (Weyl / Davis-Kahan with the gap
    /// bounded by `w_k^2`), plus `64 eps` of rounding on every term and the feed-through.
    #[test]
    fn a_ramp_gives_the_static_response_exactly() {
        use crate::model::{Request, TiltAxis};
        use crate::params::Params;
        use crate::tf::{plan, Method};
        let model = Model::new(&Params::table_i()).unwrap();
        let n = 2000;
        let drive = GroundDrive {
            step_s: 0.5,
            inputs: vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)],
            samples: vec![
                (0..n).map(|j| 1e-6 + 3e-9 * j as f64).collect(),
                (0..n).map(|j| -2e-6 + 5e-9 * j as f64).collect(),
            ],
        };
        let sim = simulate_driven(
            &model,
            &drive,
            &DrivenConfig {
                keep_every: 7,
                readout_asd: Vec::new(),
                seed: 0,
                cancel: Cancel::never(),
            },
        )
        .unwrap();
        let request = Request {
            outputs: vec![Observable::X, Observable::Y],
            inputs: vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)],
        };
        let h0 = plan(&model, &request, Method::Split)
            .unwrap()
            .eval(0.0)
            .unwrap();
        let d = Dynamics::new(&model).unwrap();
        let magnitude = |o: Observable, a: usize| static_rounding_scale(&model, &d, o, a);
        for (j, i) in (0..n).step_by(7).enumerate() {
            let (ut, ue) = (drive.samples[0][i], drive.samples[1][i]);
            for (row, o) in [Observable::X, Observable::Y].into_iter().enumerate() {
                let want = h0[row * 2].re * ut + h0[row * 2 + 1].re * ue;
                let tol = f64::EPSILON * (magnitude(o, 0) * ut.abs() + magnitude(o, 1) * ue.abs());
                let got = sim.observable(o)[j];
                assert!(
                    (got - want).abs() <= tol,
                    "{} at step {i}: {got:e} vs {want:e} (tol {tol:e})",
                    o.name()
                );
            }
        }
    }
}
