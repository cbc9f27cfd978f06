//! A synthetic record for the subtraction tests, made independently of the code under test:
//! a known floor tilt, band-limited and periodic, built at a fine step from random Fourier
//! coefficients; the pendulum driven by `gain x tilt(t - delay)` propagated in the time domain
//! (the exact modal stepping of `simulate::driven`, not the frequency-domain filter that
//! `subtract` uses) with its own parameters; white readout noise; the tilt record (the witness)
//! is the tilt sampled every `oversample` fine steps, plus its own noise (white, or rising below
//! a knee). Floor translations may drive the pendulum too, each recorded by its own witness (a
//! seismometer read as displacement) with its own noise.
//!
//! The command line's test binary includes this file too, to write the same record to files.
// Each test binary uses a different subset of these helpers.
#![allow(dead_code)]

use num_complex::Complex64;
use realfft::RealFftPlanner;
use tiltnoise_core::model::{Input, Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::noise::{GivenAsd, NoiseLevel};
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
    /// How the tilt record's noise rises at low frequency (white when `None`).
    pub witness_noise_rise: Option<Rise>,
    /// Floor translations driving the pendulum beside the tilt, each with its witness.
    pub translations: Vec<TranslationSpec>,
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
            witness_noise_rise: None,
            translations: Vec::new(),
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

    /// Six-component ground: [`Spec::noisy_witness`]'s tilt and tiltmeter, its noise rising as
    /// 1/f in ASD below 2 mHz, and floor translations along x and y, each partly the motion
    /// that a pivot 0.6 m lower would give the suspension point with the tilt
    /// ([`TranslationSpec::pivot_offset_m`]) and partly independent (1e-6 m/sqrt(Hz) at 10 mHz,
    /// shaped as the tilt), seen by the pendulum with gains 1.05 and 0.95 and recorded by
    /// seismometers with 3e-9 m/sqrt(Hz) of white displacement noise rising as 1/f^2 (white
    /// acceleration noise) below 20 mHz; the pendulum with h = 1.4 m.
    pub fn ground() -> Spec {
        let translation = |axis, gain| TranslationSpec {
            axis,
            asd_10mhz: 1e-6,
            pivot_offset_m: 0.6,
            gain,
            witness_noise: 3e-9,
            witness_noise_rise: Some(Rise {
                knee_hz: 2e-2,
                power: 2.0,
            }),
        };
        Spec {
            witness_noise_rise: Some(Rise {
                knee_hz: 2e-3,
                power: 1.0,
            }),
            translations: vec![
                translation(TranslationAxis::XT, 1.05),
                translation(TranslationAxis::YT, 0.95),
            ],
            truth: Params::table_i().with_override("length.h_m=1.4").unwrap(),
            ..Spec::noisy_witness()
        }
    }

    /// The true delay (s).
    pub fn delay_s(&self) -> f64 {
        self.delay_steps as f64 / (self.fs_hz * self.oversample as f64)
    }

    /// The witness record's inputs in the order of [`Record::witness`]: the tilt axes, then the
    /// translations.
    pub fn witness_inputs(&self) -> Vec<Input> {
        let mut inputs = vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)];
        inputs.extend(self.translations.iter().map(|t| Input::Translation(t.axis)));
        inputs
    }

    /// The true gains, in the order of [`Spec::witness_inputs`].
    pub fn witness_gains(&self) -> Vec<f64> {
        let mut gains = self.gains.to_vec();
        gains.extend(self.translations.iter().map(|t| t.gain));
        gains
    }

    /// The witness noise of each input of [`Spec::witness_inputs`] as the subtraction is told
    /// it: white, or as a spectrum sampled densely enough (100 points per decade from 1e-7 Hz
    /// to the Nyquist frequency) that log-log interpolation between its points is exact to
    /// 1e-4 for these shapes.
    pub fn witness_noise_levels(&self) -> Vec<(Input, NoiseLevel)> {
        let mut levels: Vec<(f64, Option<Rise>)> = self
            .witness_noise
            .iter()
            .map(|&w| (w, self.witness_noise_rise))
            .collect();
        levels.extend(
            self.translations
                .iter()
                .map(|t| (t.witness_noise, t.witness_noise_rise)),
        );
        self.witness_inputs()
            .into_iter()
            .zip(levels)
            .map(|(input, (white, rise))| {
                let level = match rise {
                    None => NoiseLevel::White(white),
                    Some(rise) => {
                        let top = (self.fs_hz / 2.0).log10();
                        let points = ((top + 7.0) * 100.0).ceil() as usize;
                        let mut freqs: Vec<f64> = (0..=points)
                            .map(|i| 10f64.powf(-7.0 + (top + 7.0) * i as f64 / points as f64))
                            .collect();
                        freqs[points] = self.fs_hz / 2.0;
                        let asd = freqs.iter().map(|&f| rise.asd(white, f)).collect();
                        NoiseLevel::Curve(GivenAsd::new(freqs, asd, "synthetic").unwrap())
                    }
                };
                (input, level)
            })
            .collect()
    }
}

/// A witness noise that rises below a knee: ASD `white * sqrt(1 + (knee / f)^(2 power))`.
#[derive(Debug, Clone, Copy)]
pub struct Rise {
    /// Where the rising part equals the white part (Hz).
    pub knee_hz: f64,
    /// The ASD's power of `1 / f` below the knee.
    pub power: f64,
}

impl Rise {
    /// The ASD at `f` for a white level `white`.
    pub fn asd(&self, white: f64, f: f64) -> f64 {
        white * (1.0 + (self.knee_hz / f).powf(2.0 * self.power)).sqrt()
    }
}

/// A floor translation (m) that drives the pendulum, and its witness.
#[derive(Debug, Clone)]
pub struct TranslationSpec {
    /// The axis.
    pub axis: TranslationAxis,
    /// One-sided ASD of its independent part at 10 mHz (m/sqrt(Hz)), shaped as the tilt.
    pub asd_10mhz: f64,
    /// The part that moves with the tilt: the translation of the floor's reference point if
    /// the floor turned about a pivot this much lower (m), `x_t = -L eta_t`, `y_t = +L theta_t`
    /// (the suspension point moves by `(x_t - h eta_t, y_t + h theta_t)` in the crate's tilt
    /// convention, `model::translation`): a model without this translation sees the
    /// suspension point at `h + L`.
    pub pivot_offset_m: f64,
    /// The pendulum sees `gain` times the true translation.
    pub gain: f64,
    /// White noise of its witness (m/sqrt(Hz)).
    pub witness_noise: f64,
    /// How that noise rises at low frequency (white when `None`).
    pub witness_noise_rise: Option<Rise>,
}

/// The record: the tilt record (theta_t, eta_t), the translation records (in the order of
/// [`Spec::translations`]), the co-located records and the measured observables.
pub struct Record {
    pub axes: Vec<TiltAxis>,
    pub tilt: Vec<Vec<f64>>,
    pub translation: Vec<Vec<f64>>,
    pub colocated: Vec<Vec<Vec<f64>>>,
    pub measured: Vec<(Observable, Vec<f64>)>,
}

impl Record {
    /// Every witness series, in the order of [`Spec::witness_inputs`].
    pub fn witness(&self) -> Vec<Vec<f64>> {
        self.tilt.iter().chain(&self.translation).cloned().collect()
    }
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

/// A periodic Gaussian series of `n` samples at `fs` Hz with one-sided PSD `psd(f)`, from
/// random Fourier coefficients of stream `stream` (no DC, no Nyquist).
fn fourier_series(n: usize, fs: f64, seed: u64, stream: u64, psd: impl Fn(f64) -> f64) -> Vec<f64> {
    let mut planner = RealFftPlanner::<f64>::new();
    let inv = planner.plan_fft_inverse(n);
    let df = fs / n as f64;
    let mut rng = Rng::stream(seed, stream);
    let mut spec_c = inv.make_input_vec();
    for (k, c) in spec_c.iter_mut().enumerate() {
        // E|X_k|^2 = P F N / 2 for a one-sided PSD P of a series of N samples at F.
        let s = (psd(k as f64 * df) * fs * n as f64 / 4.0).sqrt();
        *c = Complex64::new(s * rng.gaussian(), s * rng.gaussian());
    }
    spec_c[0] = Complex64::new(0.0, 0.0);
    let last = spec_c.len() - 1;
    spec_c[last] = Complex64::new(0.0, 0.0);
    let mut x = inv.make_output_vec();
    inv.process(&mut spec_c, &mut x).unwrap();
    x.iter().map(|v| v / n as f64).collect()
}

/// Makes the record of `spec`.
pub fn make(spec: &Spec) -> Record {
    let m = spec.oversample;
    let n_fine = spec.n * m;
    let fs_fine = spec.fs_hz * m as f64;
    let axes = vec![TiltAxis::ThetaT, TiltAxis::EtaT];
    let fine: Vec<Vec<f64>> = spec
        .tilt_asd_10mhz
        .iter()
        .enumerate()
        .map(|(a, &a10)| {
            fourier_series(n_fine, fs_fine, spec.seed, 10 + a as u64, |f| {
                tilt_asd(spec, a10, f).powi(2)
            })
        })
        .collect();
    let fine_translation: Vec<Vec<f64>> = spec
        .translations
        .iter()
        .enumerate()
        .map(|(j, t)| {
            let mut x = fourier_series(n_fine, fs_fine, spec.seed, 40 + j as u64, |f| {
                tilt_asd(spec, t.asd_10mhz, f).powi(2)
            });
            // In the crate's tilt convention a tilt moves a point a height L above the pivot
            // by (-L eta_t, +L theta_t) (`model::translation`).
            let with_tilt = match t.axis {
                TranslationAxis::XT => Some((1, -t.pivot_offset_m)),
                TranslationAxis::YT => Some((0, t.pivot_offset_m)),
                TranslationAxis::ZT => None,
            };
            if let Some((a, l)) = with_tilt {
                x.iter_mut().zip(&fine[a]).for_each(|(x, t)| *x += l * t);
            }
            x
        })
        .collect();
    let mut inputs: Vec<Input> = axes.iter().map(|&a| Input::Tilt(a)).collect();
    inputs.extend(spec.translations.iter().map(|t| Input::Translation(t.axis)));
    let drive = GroundDrive {
        step_s: 1.0 / fs_fine,
        inputs,
        samples: fine
            .iter()
            .chain(&fine_translation)
            .zip(spec.witness_gains())
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
    // An instrument's record of the fine series `x`: sampled every `m` fine steps plus white
    // noise of one-sided ASD `white` from random stream `stream`, and the noise's rise below
    // its knee from stream `stream + 100`.
    let record = |x: &[f64], white: f64, rise: Option<Rise>, stream: u64| -> Vec<f64> {
        let mut rng = Rng::stream(spec.seed, stream);
        let sigma = white * (spec.fs_hz / 2.0).sqrt();
        let mut r: Vec<f64> = (0..spec.n)
            .map(|i| x[i * m] + sigma * rng.gaussian())
            .collect();
        if let Some(rise) = rise {
            let red = fourier_series(spec.n, spec.fs_hz, spec.seed, stream + 100, |f| {
                (rise.asd(white, f).powi(2) - white * white).max(0.0)
            });
            r.iter_mut().zip(red).for_each(|(r, e)| *r += e);
        }
        r
    };
    let tilt_record = |noise: [f64; 2], rise: Option<Rise>, stream: u64| -> Vec<Vec<f64>> {
        fine.iter()
            .zip(noise)
            .enumerate()
            .map(|(a, (x, noise))| record(x, noise, rise, stream + a as u64))
            .collect()
    };
    let tilt = tilt_record(spec.witness_noise, spec.witness_noise_rise, 20);
    let translation = fine_translation
        .iter()
        .zip(&spec.translations)
        .enumerate()
        .map(|(j, (x, t))| record(x, t.witness_noise, t.witness_noise_rise, 60 + j as u64))
        .collect();
    let colocated = spec
        .colocated_noise
        .iter()
        .enumerate()
        .map(|(c, &noise)| tilt_record(noise, None, 30 + 2 * c as u64))
        .collect();
    Record {
        axes,
        tilt,
        translation,
        colocated,
        measured,
    }
}
