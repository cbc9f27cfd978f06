//! A synthetic record for the subtraction tests, made independently of the code under test:
//! a known floor tilt, band-limited and periodic, built at a fine step from random Fourier
//! coefficients; the pendulum driven by `gain x tilt(t - delay)` propagated in the time domain
//! (the exact modal stepping of `simulate::driven`, not the frequency-domain filter that
//! `subtract` uses) with its own parameters; white readout noise; the tilt record (the witness)
//! is the tilt sampled every `oversample` fine steps, plus its own white noise.
//!
//! The command line's test binary includes this file too, to write the same record to files.
// Each test binary uses a different subset of these helpers.
#![allow(dead_code)]

use num_complex::Complex64;
use realfft::RealFftPlanner;
use tiltnoise_core::model::{Input, Model, Observable, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::rng::Rng;
use tiltnoise_core::simulate::driven::{simulate_driven, DrivenConfig, GroundDrive};

/// What to make.
#[derive(Debug, Clone)]
pub struct Spec {
    /// Record rate (Hz).
    pub fs_hz: f64,
    /// Record length (samples).
    pub n: usize,
    /// Fine steps per record sample.
    pub oversample: usize,
    /// One-sided tilt ASD per axis at 10 mHz (rad/sqrt(Hz)); it falls as f^-1/2 from 0.5 mHz,
    /// and is tapered to zero between `cut_hz.0` and `cut_hz.1`.
    pub tilt_asd_10mhz: [f64; 2],
    /// Taper of the tilt spectrum (Hz).
    pub cut_hz: (f64, f64),
    /// The pendulum's parameters.
    pub truth: Params,
    /// The pendulum sees `gain[a]` times the true tilt of axis a (theta_t, eta_t).
    pub gains: [f64; 2],
    /// The pendulum's response lags the tilt record by this many fine steps.
    pub delay_steps: usize,
    /// White readout per observable (unit/sqrt(Hz)).
    pub readout: Vec<(Observable, f64)>,
    /// White noise of the tilt record per axis (rad/sqrt(Hz)).
    pub witness_noise: [f64; 2],
    /// Co-located instruments beside the witness: the same tilt with their own white noise
    /// per axis (rad/sqrt(Hz)), independent of the witness's.
    pub colocated_noise: Vec<[f64; 2]>,
    /// Seed of every random stream.
    pub seed: u64,
}

impl Spec {
    /// The verification: h = 2.5 m against the nominal 2.0, gains 1.03 and 0.97, a
    /// delay of 2.3 s, 1 nm/sqrt(Hz) readout on X and Y, 1 nrad/sqrt(Hz) on phi, 2^16 s at
    /// 1 Hz with a 0.1 s fine step, tilt 1e-7 rad/sqrt(Hz) at 10 mHz.
    pub fn verification() -> Spec {
        Spec {
            fs_hz: 1.0,
            n: 1 << 16,
            oversample: 100,
            tilt_asd_10mhz: [1e-7, 1e-7],
            cut_hz: (0.25, 0.3),
            truth: Params::table_i().with_override("length.h_m=2.5").unwrap(),
            gains: [1.03, 0.97],
            delay_steps: 230,
            readout: vec![
                (Observable::X, 1e-9),
                (Observable::Y, 1e-9),
                (Observable::Phi, 1e-9),
            ],
            witness_noise: [0.0, 0.0],
            colocated_noise: Vec::new(),
            seed: 7,
        }
    }

    /// A tiltmeter that records mostly its own noise above 0.1 Hz: its white noise is 30 % of
    /// the tilt ASD at 10 mHz on both axes (3e-9 rad/sqrt(Hz) on theta_t's 1e-8, 6e-8 on
    /// eta_t's 2e-7), the pendulum with h = 1.7 m, otherwise as [`Spec::verification`]. Fitted
    /// from Table I (h = 2.0 m), the swing modes near 0.41 Hz, where the witness is all noise,
    /// amplify whatever the prediction passes there.
    pub fn noisy_witness() -> Spec {
        Spec {
            tilt_asd_10mhz: [1e-8, 2e-7],
            witness_noise: [3e-9, 6e-8],
            truth: Params::table_i().with_override("length.h_m=1.7").unwrap(),
            ..Spec::verification()
        }
    }

    /// The true delay (s).
    pub fn delay_s(&self) -> f64 {
        self.delay_steps as f64 / (self.fs_hz * self.oversample as f64)
    }
}

/// The record: the tilt record (theta_t, eta_t), the co-located records and the measured
/// observables.
pub struct Record {
    pub axes: Vec<TiltAxis>,
    pub tilt: Vec<Vec<f64>>,
    pub colocated: Vec<Vec<Vec<f64>>>,
    pub measured: Vec<(Observable, Vec<f64>)>,
}

/// One-sided ASD of the tilt (rad/sqrt(Hz)) at `f` for an ASD of `a10` at 10 mHz.
fn tilt_asd(spec: &Spec, a10: f64, f: f64) -> f64 {
    if f < 5e-4 || f >= spec.cut_hz.1 {
        return 0.0;
    }
    let taper = if f <= spec.cut_hz.0 {
        1.0
    } else {
        let x = (f - spec.cut_hz.0) / (spec.cut_hz.1 - spec.cut_hz.0);
        (0.5 * std::f64::consts::PI * x).cos().powi(2)
    };
    a10 * (f / 1e-2).powf(-0.5) * taper
}

/// Makes the record of `spec`.
pub fn make(spec: &Spec) -> Record {
    let m = spec.oversample;
    let n_fine = spec.n * m;
    let fs_fine = spec.fs_hz * m as f64;
    let df = spec.fs_hz / spec.n as f64;
    let mut planner = RealFftPlanner::<f64>::new();
    let inv = planner.plan_fft_inverse(n_fine);
    let axes = vec![TiltAxis::ThetaT, TiltAxis::EtaT];
    let mut fine = Vec::new();
    for (a, &a10) in spec.tilt_asd_10mhz.iter().enumerate() {
        let mut rng = Rng::stream(spec.seed, 10 + a as u64);
        let mut spec_c = inv.make_input_vec();
        for (k, c) in spec_c.iter_mut().enumerate() {
            // E|X_k|^2 = P F N / 2 for a one-sided PSD P of a series of N samples at F.
            let p = tilt_asd(spec, a10, k as f64 * df).powi(2);
            let s = (p * fs_fine * n_fine as f64 / 4.0).sqrt();
            *c = Complex64::new(s * rng.gaussian(), s * rng.gaussian());
        }
        spec_c[0] = Complex64::new(0.0, 0.0);
        let last = spec_c.len() - 1;
        spec_c[last] = Complex64::new(0.0, 0.0);
        let mut x = inv.make_output_vec();
        inv.process(&mut spec_c, &mut x).unwrap();
        fine.push(x.iter().map(|v| v / n_fine as f64).collect::<Vec<f64>>());
    }
    let drive = GroundDrive {
        step_s: 1.0 / fs_fine,
        inputs: axes.iter().map(|&a| Input::Tilt(a)).collect(),
        samples: fine
            .iter()
            .zip(spec.gains)
            .map(|(x, g)| {
                (0..n_fine)
                    .map(|j| g * x[(j + n_fine - spec.delay_steps) % n_fine])
                    .collect()
            })
            .collect(),
    };
    let model = Model::new(&spec.truth).unwrap();
    let sim = simulate_driven(
        &model,
        &drive,
        &DrivenConfig {
            keep_every: m,
            readout_asd: spec.readout.clone(),
            seed: spec.seed,
            cancel: tiltnoise_core::cancel::Cancel::never(),
        },
    )
    .unwrap();
    let measured = spec
        .readout
        .iter()
        .map(|(o, _)| (*o, sim.observable(*o)[..spec.n].to_vec()))
        .collect();
    // An instrument's record: the tilt sampled every `m` fine steps plus white noise of
    // one-sided ASD `noise[a]` from random stream `stream + a`.
    let record = |noise: [f64; 2], stream: u64| -> Vec<Vec<f64>> {
        fine.iter()
            .zip(noise)
            .enumerate()
            .map(|(a, (x, noise))| {
                let mut rng = Rng::stream(spec.seed, stream + a as u64);
                let sigma = noise * (spec.fs_hz / 2.0).sqrt();
                (0..spec.n)
                    .map(|i| x[i * m] + sigma * rng.gaussian())
                    .collect()
            })
            .collect()
    };
    let tilt = record(spec.witness_noise, 20);
    let colocated = spec
        .colocated_noise
        .iter()
        .enumerate()
        .map(|(c, &noise)| record(noise, 30 + 2 * c as u64))
        .collect();
    Record {
        axes,
        tilt,
        colocated,
        measured,
    }
}
