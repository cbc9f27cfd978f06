//! Tilt subtraction: how much of a measured record of the observables is floor motion, how
//! well the model's coupling matches the data, and what is left once it is removed.
//!
//! Inputs: a witness record (series of the model's floor inputs, such as the tilt angles in
//! the crate's sign convention, one per input), optionally the witness's own noise per input,
//! and a measured record of some observables (m, rad), each with its sample rate and,
//! optionally, the ISO 8601 time of its first sample. The pipeline ([`subtract`]):
//!
//! 1. **Alignment** ([`align()`]): by start times to the nearest sample (the fraction of a sample
//!    left is a known part of the delay); without a start time in either file both records are
//!    taken to start together (the provenance says so). Rates must agree; nothing is
//!    resampled.
//! 2. **Split**: the first part of the overlap trains (fit, Wiener filter), the last
//!    `holdout_fraction` of it validates.
//! 3. **Fit** ([`estimate`]): a gain per witness input (the instrument's calibration), a delay
//!    (the clocks' offset), any chosen model parameters and the scales of uncertain witness
//!    noise levels, by weighted least squares on the Welch cross spectra given the witness
//!    noise, with uncertainties; parameters the data cannot constrain are held at their
//!    nominal values and reported as such.
//! 4. **Prediction** ([`predict`]): the floor part of each observable in the time domain
//!    through the fitted model, weighted per bin by what the witness knows of the floor motion
//!    given its noise ([`weighting`]), and the cleaned record `measured - predicted`.
//! 5. **Check** ([`bands`]): per 1/3-decade band, the cleaned record against the raw one and
//!    against the residual the model expects; a band where it is worse is left raw.
//! 6. **Residuals** ([`residuals`]): on the held-out stretch, the cleaned residual against
//!    the readout, against the residual the coherence allows, and against a data-driven
//!    multiple-input Wiener filter trained on the training stretch.
//!
//! Welch settings throughout: periodic Hann, 50 % overlap, mean, constant detrend
//! ([`crate::spectral`]); one-sided PSDs (unit^2/Hz) and ASDs (unit/sqrt(Hz)); `e^{+iwt}`.
//!
//! Pure numerics: depends on `params`, `model`, `tf`, `spectral`, `fit` (the solver) and
//! `simulate` (nothing else; no I/O).

pub mod align;
pub mod bands;
pub mod colocated;
pub mod estimate;
mod input_checks;
mod parameters;
pub mod predict;
mod problem;
pub mod residuals;
pub mod stats;
pub mod weighting;

pub use crate::noise::{NoiseLevel, WitnessNoise};
pub use align::{align, Alignment, StartTime};
pub use bands::{Band, BandCheck};
pub use colocated::{ColocatedEstimate, Method};
pub use estimate::{Estimate, FitReport, FitRequest, Status};
pub use parameters::{FREE_ENVIRONMENT_KEY, FREE_SECTIONS};
pub use predict::{Coupling, Prediction};
pub use residuals::{BandSummary, ResidualSpectra};

use crate::cancel::{Cancel, Cancelled};
use crate::error::{Num, TfError};
use crate::model::{Input, Model, Observable};
use crate::option_key::OptionKey;
use crate::params::Params;
use crate::spectral::confidence::equivalent_averages;
use crate::spectral::{csd_matrix_cancellable, welch, SpectralError, WelchConfig};
use nalgebra::DVector;
use num_complex::Complex64;
use weighting::{prediction_margin, weighting as weigh, WitnessSpectra};

/// Default held-out fraction of the overlap.
pub const DEFAULT_HOLDOUT_FRACTION: f64 = 0.25;
/// Largest held-out fraction: the fit needs the larger part.
pub const MAX_HOLDOUT_FRACTION: f64 = 0.5;
/// Default report band (Hz): where the paper's pendulum is quiet between its torsion and
/// swing modes.
pub const DEFAULT_REPORT_BAND_HZ: (f64, f64) = (3e-3, 3e-2);
/// The default segment is the largest power of two that fits this many times into the
/// training stretch (15 half-overlapping segments) and [`MIN_HOLDOUT_SEGMENTS`] times into the
/// held-out stretch.
pub const DEFAULT_SEGMENTS_IN_TRAINING: usize = 8;
/// Largest default segment (samples).
pub const MAX_DEFAULT_SEGMENT: usize = 1 << 16;
/// Fewest samples per segment.
pub const MIN_SEGMENT: usize = 16;
/// The training stretch must hold this many segment lengths (7 half-overlapping segments).
pub const MIN_TRAINING_SEGMENTS: usize = 4;
/// The held-out stretch must hold this many segment lengths (3 half-overlapping segments).
pub const MIN_HOLDOUT_SEGMENTS: usize = 2;
/// Default largest delay, as a fraction of the segment: the window's attenuation of the cross
/// spectrum is then below 1.7 % and modelled ([`stats::hann_delay_factor`]).
pub const DEFAULT_MAX_DELAY_FRACTION: f64 = 0.05;
/// Largest delay allowed, as a fraction of the segment.
pub const MAX_DELAY_FRACTION: f64 = 0.1;

/// The witness record: one series per model input of the floor (tilt angles in rad, in the
/// crate's sign convention), each in the input's unit.
#[derive(Debug, Clone, Copy)]
pub struct WitnessRecord<'a> {
    /// Sample rate (Hz).
    pub fs_hz: f64,
    /// The inputs, each once.
    pub inputs: &'a [Input],
    /// One series per input, equal lengths.
    pub data: &'a [Vec<f64>],
    /// Time of the first sample, if known.
    pub start: Option<StartTime>,
}

/// The measured record of the observables (m, rad).
#[derive(Debug, Clone, Copy)]
pub struct MeasuredRecord<'a> {
    /// Sample rate (Hz).
    pub fs_hz: f64,
    /// One series per observable, equal lengths.
    pub channels: &'a [(Observable, Vec<f64>)],
    /// Time of the first sample, if known.
    pub start: Option<StartTime>,
}

/// What to do.
#[derive(Debug, Clone, PartialEq)]
pub struct SubtractConfig {
    /// Welch segment (samples); `None`: see [`DEFAULT_SEGMENTS_IN_TRAINING`].
    pub segment_len: Option<usize>,
    /// Fraction of the overlap held out for validation, in `(0, MAX_HOLDOUT_FRACTION]`.
    pub holdout_fraction: f64,
    /// Model parameters to fit besides the gains and the delay.
    pub keys: Vec<String>,
    /// Fit band (Hz); `None`: the default of [`estimate`].
    pub fit_band_hz: Option<(f64, f64)>,
    /// Largest delay magnitude (s); `None`: [`DEFAULT_MAX_DELAY_FRACTION`] of a segment.
    pub max_delay_s: Option<f64>,
    /// The witnesses' own noise per input (none: taken as noiseless, unless co-located records
    /// estimate it).
    pub witness_noise: Vec<WitnessNoise>,
    /// The ratio `r` of a co-located instrument's noise ASD to the witness's, per input, for
    /// a huddle (two instruments); 1 (equal noise) when not stated.
    pub colocated_noise_ratio: Vec<(Input, f64)>,
    /// White readout of the measured observables: one-sided ASD (unit/sqrt(Hz)).
    pub readout_asd: Vec<(Observable, f64)>,
    /// Band of the residual summaries (Hz).
    pub report_band_hz: (f64, f64),
    /// Polled between the stages and within the spectral estimates ([`crate::cancel`]).
    pub cancel: Cancel,
}

impl Default for SubtractConfig {
    fn default() -> Self {
        SubtractConfig {
            segment_len: None,
            holdout_fraction: DEFAULT_HOLDOUT_FRACTION,
            keys: Vec::new(),
            fit_band_hz: None,
            max_delay_s: None,
            witness_noise: Vec::new(),
            colocated_noise_ratio: Vec::new(),
            readout_asd: Vec::new(),
            report_band_hz: DEFAULT_REPORT_BAND_HZ,
            cancel: Cancel::never(),
        }
    }
}

/// The outcome of [`subtract`].
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct SubtractResult {
    /// How the records were aligned.
    pub alignment: Alignment,
    /// Welch segment (samples) and overlap of every spectral estimate.
    pub segment_len: usize,
    /// Samples of the training and of the held-out stretch.
    pub n_train: usize,
    /// Samples of the held-out stretch (the end of the overlap).
    pub n_holdout: usize,
    /// Effective averages of the training and held-out Welch estimates.
    pub n_eff: (f64, f64),
    /// The fit.
    pub fit: FitReport,
    /// Largest delay allowed (s).
    pub max_delay_s: f64,
    /// The witnesses' noise as used (after any fitted scale), per input: the PSD on the Welch
    /// grid (unit^2/Hz).
    pub witness_noise_psd: Vec<(Input, Vec<f64>)>,
    /// The noise levels estimated from co-located records.
    pub colocated: Vec<ColocatedEstimate>,
    /// Predicted floor part per observable over the overlap, as subtracted.
    pub prediction: Prediction,
    /// Measured minus predicted, per observable, over the overlap.
    pub cleaned: Vec<(Observable, Vec<f64>)>,
    /// The check of the cleaned record against the raw one, per observable.
    pub bands: Vec<(Observable, BandCheck)>,
    /// Residual spectra and band summaries on the held-out stretch.
    pub residuals: Vec<ResidualSpectra>,
    /// Notes for the provenance.
    pub notes: Vec<String>,
}

/// Why a subtraction was refused. Every message names the value and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum SubtractError {
    /// The sample rates differ.
    #[error(
        "the tilt record is sampled at {} Hz and the measured record at {} Hz ({} samples of \
         drift over the longer record; at most {} allowed): subtract does not resample; \
         resample one of them to the other's rate first",
        Num(*.witness_hz), Num(*.measured_hz), Num(*.drift_samples), align::MAX_RATE_DRIFT_SAMPLES
    )]
    RateMismatch {
        /// Tilt record's rate (Hz).
        witness_hz: f64,
        /// Measured record's rate (Hz).
        measured_hz: f64,
        /// Accumulated timing difference (samples).
        drift_samples: f64,
    },
    /// Only one record states its start time.
    #[error(
        "the {stated_by} record states its start time and the {missing_in} record does not: \
         give both a start time (time of sample 0, ISO 8601), or neither to take them as \
         starting together"
    )]
    OneStartTime {
        /// The record with a start time.
        stated_by: &'static str,
        /// The record without.
        missing_in: &'static str,
    },
    /// No common sample.
    #[error(
        "the records do not overlap in time: the tilt record covers {} .. {} s and the measured \
         record {} .. {} s (seconds from the tilt record's start)",
        Num(.witness_s.0), Num(.witness_s.1), Num(.measured_s.0), Num(.measured_s.1)
    )]
    NoOverlap {
        /// Span of the tilt record (s).
        witness_s: (f64, f64),
        /// Span of the measured record (s).
        measured_s: (f64, f64),
    },
    /// The overlap is too short for the spectral estimates.
    #[error("{0}")]
    TooShort(crate::option_key::Message),
    /// An option outside its allowed range.
    #[error("{0}")]
    Config(crate::option_key::Message),
    /// A record the estimation cannot use: a non-finite sample or spectrum, a dead channel.
    #[error("{0}")]
    Record(crate::option_key::Message),
    /// A band with no bin.
    #[error(
        "the {what} band {} .. {} Hz holds no bin of the Welch grid {} .. {} Hz; allowed: a band \
         inside the grid, wider than one bin",
        Num(.band_hz.0), Num(.band_hz.1), Num(.grid_hz.0), Num(.grid_hz.1)
    )]
    Band {
        /// `fit` or `report`.
        what: String,
        /// The band given (Hz).
        band_hz: (f64, f64),
        /// Bins 1 .. Nyquist (Hz).
        grid_hz: (f64, f64),
    },
    /// No usable bin in the fit band.
    #[error(
        "no bin of the fit band {} .. {} Hz is usable (every one is near a resonance of the \
         model, or the witness records no floor motion above its own noise there); choose \
         another band with {}",
        Num(.band_hz.0), Num(.band_hz.1), OptionKey::BAND
    )]
    NoFitBins {
        /// The band (Hz).
        band_hz: (f64, f64),
    },
    /// The witness is coherent with no observable.
    #[error(
        "the witness record is not coherent with any measured observable at any frequency (its \
         multiple coherence is what noise alone gives): it cannot be subtracted; check that the \
         records overlap in time, their axis maps and sign conventions, or give a fit band with \
         {}",
        OptionKey::BAND
    )]
    NotCoherent,
    /// A key that is not a parameter.
    #[error("{}: unknown parameter key `{}`; allowed: {allowed}", OptionKey::FIT, crate::error::Shown(.key))]
    UnknownKey {
        /// The key given.
        key: String,
        /// Keys that may be fitted.
        allowed: String,
    },
    /// A key that cannot be fitted.
    #[error(
        "{}: parameter `{key}` is not a free parameter here: {reason}; allowed: {allowed}",
        OptionKey::FIT
    )]
    NotFreeKey {
        /// The key.
        key: String,
        /// Why.
        reason: String,
        /// Keys that may be fitted.
        allowed: String,
    },
    /// The same key twice.
    #[error(
        "{}: parameter `{key}` is listed twice; give each key once",
        OptionKey::FIT
    )]
    DuplicateKey {
        /// The key.
        key: String,
    },
    /// A parameter set the fit reached is not physical, or the model cannot be built.
    #[error("{0}")]
    Params(String),
    /// The transfer functions cannot be planned.
    #[error("{0}")]
    Plan(String),
    /// The transfer functions cannot be evaluated.
    #[error(transparent)]
    Tf(#[from] TfError),
    /// A spectral estimate failed.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// The computation was cancelled ([`crate::cancel`]).
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
}

/// The largest power of two `<= n`.
fn pow2_floor(n: usize) -> usize {
    if n == 0 {
        0
    } else {
        1 << n.ilog2()
    }
}

/// Runs the whole pipeline of the module docs.
///
/// # Errors
///
/// Every refusal of [`SubtractError`]: records that do not overlap or do not share a rate,
/// an overlap too short for the Welch segment, options out of range, bad fit keys, witness
/// noise spectra that do not cover the Welch band.
pub fn subtract(
    params: &Params,
    witness: &WitnessRecord,
    colocated: &[WitnessRecord],
    measured: &MeasuredRecord,
    cfg: &SubtractConfig,
) -> Result<SubtractResult, SubtractError> {
    let n_w = witness.data.first().map_or(0, Vec::len);
    let n_m = measured.channels.first().map_or(0, |c| c.1.len());
    let alignment = align(
        (witness.fs_hz, n_w, witness.start),
        (measured.fs_hz, n_m, measured.start),
    )?;
    let fs = alignment.fs_hz;
    check_config(witness, measured, cfg)?;
    let n = alignment.len;
    let SegmentPlan {
        segment_len,
        n_train,
        n_hold,
        max_delay_s,
    } = SegmentPlan::new(n, fs, cfg)?;
    let inputs = witness.inputs;
    let n_in = inputs.len();
    let (w, y) = overlap(witness, measured, &alignment);
    let outputs: Vec<Observable> = measured.channels.iter().map(|c| c.0).collect();
    let channel_names = input_checks::channel_names(inputs, &outputs);
    input_checks::check_channels(&channel_names, &w, &y)?;
    let welch_cfg = WelchConfig::new(segment_len);
    let train: Vec<&[f64]> = w.iter().chain(&y).map(|x| &x[..n_train]).collect();
    let training_spectra = csd_matrix_cancellable(&train, fs, &welch_cfg, &cfg.cancel)?;
    input_checks::check_spectra(&training_spectra, &channel_names, "training")?;
    let n_eff_train = equivalent_averages(&welch_cfg, training_spectra.n_segments);
    let adjacent = stats::bin_variance_factor(segment_len, 1);
    let witness_spectra = WitnessSpectra::new(&training_spectra, n_in, n_eff_train, adjacent);
    let freqs = &training_spectra.freqs_hz;
    cfg.cancel.check()?;
    let colocated =
        colocated::estimate_all(witness, colocated, &cfg.colocated_noise_ratio, segment_len)?;
    let (noise_psd, noise_rel) = witness_noise(inputs, &cfg.witness_noise, &colocated, freqs)?;
    let fit = estimate::fit(
        params,
        inputs,
        &outputs,
        &estimate::Training {
            spectra: &training_spectra,
            witness: &witness_spectra,
            fs_hz: fs,
            segment_len,
            n_eff: n_eff_train,
        },
        alignment.fraction_s,
        &FitRequest {
            keys: cfg.keys.clone(),
            band_hz: cfg.fit_band_hz,
            max_delay_s,
            noise_psd: noise_psd.clone(),
            noise_rel,
        },
    )?;
    cfg.cancel.check()?;
    let noise_psd: Vec<Vec<f64>> = noise_psd
        .iter()
        .zip(&fit.noise_factors)
        .map(|(m, k)| m.iter().map(|v| v * k).collect())
        .collect();
    let noise_at = |k: usize| -> Vec<f64> { noise_psd.iter().map(|m| m[k]).collect() };
    let coupling = coupling_of(&fit, inputs, alignment.fraction_s);
    let fitted_model = Model::new(&fit.params).map_err(|e| SubtractError::Params(e.to_string()))?;
    let weights = prediction_weights(&witness_spectra, freqs, &noise_at);
    let predictor = predict::predictor(
        &fitted_model,
        fs,
        inputs,
        &w,
        &outputs,
        &coupling,
        &weights,
        &cfg.cancel,
    )?;
    let model_spectra = model_spectra(
        &fit.params,
        inputs,
        &outputs,
        &coupling,
        &witness_spectra,
        &noise_at,
    )?;
    cfg.cancel.check()?;
    let (prediction, cleaned, bands) = clean_never_worse(&Cleaning {
        predictor: &predictor,
        w: &w,
        y: &y,
        outputs: &outputs,
        fs,
        welch_cfg: &welch_cfg,
        model_spectra: &model_spectra,
        cancel: &cfg.cancel,
    })?;

    let held: Vec<&[f64]> = w.iter().chain(&y).map(|x| &x[n_train..]).collect();
    cfg.cancel.check()?;
    let held_spectra = csd_matrix_cancellable(&held, fs, &welch_cfg, &cfg.cancel)?;
    input_checks::check_spectra(&held_spectra, &channel_names, "held-out")?;
    let n_eff_held = equivalent_averages(&welch_cfg, held_spectra.n_segments);
    let predicted_psd = held_out_psds(&prediction.series, n_train, fs, &welch_cfg)?;
    let cleaned_psd = held_out_psds(&cleaned, n_train, fs, &welch_cfg)?;
    let wiener = residuals::Wiener::train(&training_spectra, n_in, outputs.len(), n_eff_train);
    let report_band = cfg.report_band_hz;
    check_report_band(&held_spectra.freqs_hz, report_band)?;
    let residuals = residuals::evaluate(
        &wiener,
        &residuals::HeldOut {
            spectra: &held_spectra,
            predicted_psd: &predicted_psd,
            cleaned_psd: &cleaned_psd,
            n_eff: n_eff_held,
            bin_variance_factor: adjacent,
            witness_limited: &model_spectra,
        },
        &outputs,
        &cfg.readout_asd,
        report_band,
    );
    let notes = run_notes(
        &alignment.note,
        &fit.notes,
        &prediction,
        &bands,
        &residuals,
        fs,
    );
    Ok(SubtractResult {
        alignment,
        segment_len,
        n_train,
        n_holdout: n_hold,
        n_eff: (n_eff_train, n_eff_held),
        fit,
        max_delay_s,
        witness_noise_psd: inputs.iter().copied().zip(noise_psd.clone()).collect(),
        colocated,
        prediction,
        cleaned,
        bands,
        residuals,
        notes,
    })
}

/// The witness and measured series over their overlap.
fn overlap<'a>(
    witness: &WitnessRecord<'a>,
    measured: &MeasuredRecord<'a>,
    alignment: &Alignment,
) -> (Vec<&'a [f64]>, Vec<&'a [f64]>) {
    let n = alignment.len;
    let w: Vec<&[f64]> = witness
        .data
        .iter()
        .map(|x| &x[alignment.witness_first..alignment.witness_first + n])
        .collect();
    let y: Vec<&[f64]> = measured
        .channels
        .iter()
        .map(|(_, x)| &x[alignment.measured_first..alignment.measured_first + n])
        .collect();
    (w, y)
}

/// Per input, its noise PSD on the Welch grid `freqs` (given, or from the colocated
/// witnesses) and the stated relative uncertainty of its level (0 when none was stated).
fn witness_noise(
    inputs: &[Input],
    given: &[WitnessNoise],
    colocated: &[ColocatedEstimate],
    freqs: &[f64],
) -> Result<(Vec<Vec<f64>>, Vec<f64>), SubtractError> {
    let noise = all_witness_noise(given, colocated)?;
    let noise_psd = noise_on_grid(inputs, &noise, freqs)?;
    let noise_rel: Vec<f64> = inputs
        .iter()
        .map(|i| noise.iter().find(|x| x.input == *i).map_or(0.0, |x| x.rel))
        .collect();
    Ok((noise_psd, noise_rel))
}

/// The prediction's weighting of the witnesses at every Welch bin but DC.
fn prediction_weights(
    witness_spectra: &WitnessSpectra,
    freqs: &[f64],
    noise_at: &dyn Fn(usize) -> Vec<f64>,
) -> predict::Weights {
    predict::Weights {
        freqs_hz: freqs[1..].to_vec(),
        at: (1..freqs.len())
            .map(|k| {
                let margin = prediction_margin(witness_spectra.dof[k]);
                weigh(&witness_spectra.smoothed[k], &noise_at(k), margin).at
            })
            .collect(),
    }
}

/// The Welch PSD of every series over the held-out stretch (from sample `n_train`).
fn held_out_psds(
    series: &[(Observable, Vec<f64>)],
    n_train: usize,
    fs: f64,
    welch_cfg: &WelchConfig,
) -> Result<Vec<Vec<f64>>, SubtractError> {
    series
        .iter()
        .map(|(_, x)| Ok(welch(&x[n_train..], fs, welch_cfg)?.psd))
        .collect()
}

/// Some bin of the held-out grid (DC left out) lies in the report band.
fn check_report_band(grid: &[f64], report_band: (f64, f64)) -> Result<(), SubtractError> {
    if grid
        .iter()
        .skip(1)
        .all(|&f| f < report_band.0 || f > report_band.1)
    {
        return Err(SubtractError::Band {
            what: "report".into(),
            band_hz: report_band,
            grid_hz: (grid[1], grid[grid.len() - 1]),
        });
    }
    Ok(())
}

/// How the overlap is cut: the Welch segment, the training and held-out stretches, the largest
/// delay searched.
struct SegmentPlan {
    segment_len: usize,
    n_train: usize,
    n_hold: usize,
    max_delay_s: f64,
}

impl SegmentPlan {
    /// The plan for an overlap of `n` samples at `fs` Hz, or why the options do not fit it.
    fn new(n: usize, fs: f64, cfg: &SubtractConfig) -> Result<SegmentPlan, SubtractError> {
        let n_hold = (n as f64 * cfg.holdout_fraction).round() as usize;
        let n_train = n - n_hold;
        let segment_len = match cfg.segment_len {
            Some(l) => l,
            None => pow2_floor(
                (n_train / DEFAULT_SEGMENTS_IN_TRAINING).min(n_hold / MIN_HOLDOUT_SEGMENTS),
            )
            .min(MAX_DEFAULT_SEGMENT),
        };
        let span = |m: usize| format!("{m} samples ({} s)", Num(m as f64 / fs));
        if segment_len < MIN_SEGMENT
            || n_train < MIN_TRAINING_SEGMENTS * segment_len
            || n_hold < MIN_HOLDOUT_SEGMENTS * segment_len
        {
            let needed_seg = segment_len.max(MIN_SEGMENT);
            let needed = (MIN_TRAINING_SEGMENTS * needed_seg) as f64 / (1.0 - cfg.holdout_fraction);
            let needed =
                needed.max((MIN_HOLDOUT_SEGMENTS * needed_seg) as f64 / cfg.holdout_fraction);
            return Err(SubtractError::TooShort(crate::message!(
                "the records overlap for {}: with a held-out fraction of {} and a Welch segment of {} \
                 the overlap must be at least {} (training >= {MIN_TRAINING_SEGMENTS} segments, \
                 held-out >= {MIN_HOLDOUT_SEGMENTS}); use longer records or a shorter {}",
                span(n),
                cfg.holdout_fraction,
                span(needed_seg),
                span(needed.ceil() as usize),
                OptionKey::NPERSEG,
            )));
        }
        let segment_s = segment_len as f64 / fs;
        let max_delay_s = match cfg.max_delay_s {
            Some(d) if d.is_finite() && d > 0.0 && d <= MAX_DELAY_FRACTION * segment_s => d,
            Some(d) => {
                return Err(SubtractError::Config(crate::message!(
                    "{} is not allowed: must be > 0 and at most {} of the Welch segment, {} s \
                     (longer delays need a longer {})",
                    OptionKey::MAX_DELAY.given(format!("{} s", Num(d))),
                    MAX_DELAY_FRACTION,
                    Num(MAX_DELAY_FRACTION * segment_s),
                    OptionKey::NPERSEG
                )))
            }
            None => DEFAULT_MAX_DELAY_FRACTION * segment_s,
        };
        Ok(SegmentPlan {
            segment_len,
            n_train,
            n_hold,
            max_delay_s,
        })
    }
}

/// The witness noise of every input: as given, and as the co-located records estimate it (an
/// input given both ways is refused).
fn all_witness_noise(
    given: &[WitnessNoise],
    colocated: &[ColocatedEstimate],
) -> Result<Vec<WitnessNoise>, SubtractError> {
    let mut noise = given.to_vec();
    for e in colocated {
        if noise.iter().any(|x| x.input == e.noise.input) {
            return Err(SubtractError::Config(crate::message!(
                "{}: the noise of {} is also estimated from the co-located records; give one \
                 or the other",
                OptionKey::WITNESS_NOISE.given(e.noise.input.name()),
                e.noise.input.name()
            )));
        }
        noise.push(e.noise.clone());
    }
    Ok(noise)
}

/// The fitted gain of every input (1 where not estimated) and the delay, less the records'
/// sub-sample offset `fraction_s`.
fn coupling_of(fit: &FitReport, inputs: &[Input], fraction_s: f64) -> Coupling {
    let value = |name: &str, default: f64| {
        fit.estimates
            .iter()
            .find(|e| e.name == name)
            .map_or(default, |e| e.value)
    };
    Coupling {
        gains: inputs
            .iter()
            .map(|i| value(&format!("gain.{}", i.name()), 1.0))
            .collect(),
        delay_s: value("delay_s", 0.0) - fraction_s,
    }
}

/// What [`clean_never_worse`] works on: the predictor, the aligned witness and measured
/// series, the Welch configuration and the model's spectra.
struct Cleaning<'a> {
    predictor: &'a predict::Predictor,
    w: &'a [&'a [f64]],
    y: &'a [&'a [f64]],
    outputs: &'a [Observable],
    fs: f64,
    welch_cfg: &'a WelchConfig,
    model_spectra: &'a [ModelSpectra],
    cancel: &'a Cancel,
}

/// The prediction and the cleaned record, checked band by band against the raw one before it is
/// written: a band where the cleaned record came out worse is left unpredicted, a record whose
/// variance would grow is left raw, until nothing changes. The residual expected of each band
/// is the coherence limit of the whole overlap.
#[allow(clippy::type_complexity)]
fn clean_never_worse(
    c: &Cleaning,
) -> Result<
    (
        predict::Prediction,
        Vec<(Observable, Vec<f64>)>,
        Vec<(Observable, BandCheck)>,
    ),
    SubtractError,
> {
    let Cleaning {
        predictor,
        w,
        y,
        outputs,
        fs,
        welch_cfg,
        model_spectra,
        cancel,
    } = *c;
    let n_in = w.len();
    let whole: Vec<&[f64]> = w.iter().chain(y.iter()).copied().collect();
    let whole_spectra = csd_matrix_cancellable(&whole, fs, welch_cfg, cancel)?;
    // The Welch grid of the segment length, the same as the training spectra's.
    let freqs = &whole_spectra.freqs_hz;
    let n_segments_whole = whole_spectra.n_segments;
    let n_eff_whole = equivalent_averages(welch_cfg, n_segments_whole);
    let raw_psd: Vec<Vec<f64>> = (0..outputs.len())
        .map(|o| whole_spectra.psd(n_in + o))
        .collect();
    let coherence_limit: Vec<Vec<f64>> = (0..outputs.len())
        .map(|o| residuals::coherence_limit(&whole_spectra, n_in, n_in + o, n_eff_whole))
        .collect();
    let mut left: Vec<Vec<(f64, f64)>> = vec![Vec::new(); outputs.len()];
    let mut whole_left = vec![false; outputs.len()];
    loop {
        cancel.check()?;
        let mask = |o: usize, f: f64| {
            if whole_left[o] {
                0.0
            } else {
                bands::mask(&left[o], f)
            }
        };
        let mut prediction = predictor.series(&mask);
        for (o, (_, p)) in prediction.series.iter_mut().enumerate() {
            if whole_left[o] {
                p.iter_mut().for_each(|v| *v = 0.0);
            }
        }
        let cleaned: Vec<(Observable, Vec<f64>)> = prediction
            .series
            .iter()
            .zip(y.iter())
            .map(|((o, p), m)| (*o, m.iter().zip(p).map(|(a, b)| a - b).collect()))
            .collect();
        let mut new_left: Vec<(usize, (f64, f64))> = Vec::new();
        let mut new_whole: Vec<usize> = Vec::new();
        let mut checks = Vec::with_capacity(outputs.len());
        for (o, (obs, c)) in cleaned.iter().enumerate() {
            let cleaned_psd = welch(c, fs, welch_cfg)?.psd;
            let ms = &model_spectra[o];
            let expected: Vec<f64> = (0..freqs.len())
                .map(|k| {
                    let c = ms.guard[k] * mask(o, freqs[k]);
                    raw_psd[o][k] - c * (2.0 - c) * (raw_psd[o][k] - coherence_limit[o][k])
                })
                .collect();
            let judged = bands::judge(
                freqs,
                &bands::BinSpectra {
                    raw: &raw_psd[o],
                    cleaned: &cleaned_psd,
                    expected: &expected,
                    witness_limited: &ms.witness_limited,
                },
                welch_cfg,
                n_segments_whole,
                &left[o],
            );
            let variance_ratio = variance(c) / variance(y[o]);
            if !whole_left[o] {
                let worse: Vec<(usize, (f64, f64))> = judged
                    .iter()
                    .filter(|b| b.ratio > 1.0 && !b.left_raw)
                    .map(|b| (o, (b.lo_hz, b.hi_hz)))
                    .collect();
                if worse.is_empty() && variance_ratio > 1.0 {
                    new_whole.push(o);
                }
                new_left.extend(worse);
            }
            checks.push((
                *obs,
                BandCheck {
                    bands: judged,
                    variance_ratio,
                    left_raw: whole_left[o],
                },
            ));
        }
        let changed = !(new_left.is_empty() && new_whole.is_empty());
        for (o, band) in new_left {
            left[o].push(band);
        }
        for o in new_whole {
            whole_left[o] = true;
        }
        if !changed {
            return Ok((prediction, cleaned, checks));
        }
    }
}

/// The run's notes: the alignment's, the fit's, and where the record was not predicted, left raw,
/// or came out below what the coherence allows.
fn run_notes(
    alignment_note: &str,
    fit_notes: &[String],
    prediction: &predict::Prediction,
    bands: &[(Observable, BandCheck)],
    residuals: &[residuals::ResidualSpectra],
    fs: f64,
) -> Vec<String> {
    let mut notes = vec![alignment_note.to_string()];
    notes.extend(fit_notes.iter().cloned());
    for (o, bands) in &prediction.guarded {
        if !bands.is_empty() {
            notes.push(format!(
                "{}: not predicted near the model's undamped resonances ({})",
                o.name(),
                band_list(bands)
            ));
        }
    }
    for (o, check) in bands {
        if check.left_raw {
            notes.push(format!(
                "{}: left raw entirely: the prediction would have raised the record's variance \
                 (by a factor {:.3}); check the witness, its noise level and the model",
                o.name(),
                check.variance_ratio
            ));
            continue;
        }
        let worse: Vec<&Band> = check.bands.iter().filter(|b| b.left_raw).collect();
        if !worse.is_empty() {
            let edges: Vec<(f64, f64)> = worse
                .iter()
                .map(|b| (b.lo_hz, b.hi_hz.min(fs / 2.0)))
                .collect();
            notes.push(format!(
                "{}: left raw in {} (the prediction did not lower the record there)",
                o.name(),
                band_list(&edges)
            ));
        }
    }
    for r in residuals {
        if r.band.below_coherence_bound {
            notes.push(format!(
                "{}: the cleaned residual in the report band is more than 3 sigma below the \
                 residual the measured coherence allows: the coherence estimate is limited there \
                 (Welch resolution bias where the coupling or the delay varies within a bin, \
                 with little noise), or the two stretches differ",
                r.observable.name()
            ));
        }
    }
    notes
}

/// `a .. b Hz, ...`.
fn band_list(bands: &[(f64, f64)]) -> String {
    bands
        .iter()
        .map(|(a, b)| format!("{} .. {} Hz", Num(*a), Num(*b)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Variance about the mean.
fn variance(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n
}

/// The witnesses' noise PSDs `[input][Welch bin]` (DC: that of bin 1); zeros for an input
/// without a stated noise.
fn noise_on_grid(
    inputs: &[Input],
    noise: &[WitnessNoise],
    freqs: &[f64],
) -> Result<Vec<Vec<f64>>, SubtractError> {
    inputs
        .iter()
        .map(|i| match noise.iter().find(|x| x.input == *i) {
            None => Ok(vec![0.0; freqs.len()]),
            Some(x) => {
                let mut psd = x
                    .psd_on(&freqs[1..])
                    .map_err(|e| SubtractError::Config(e.into()))?;
                psd.insert(0, psd[0]);
                Ok(psd)
            }
        })
        .collect()
}

/// What the model says of one observable on the Welch grid.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSpectra {
    /// The prediction's guard factor near the resonances ([`predict`]), per bin.
    pub guard: Vec<f64>,
    /// PSD of the witness-limited residual `G^H R G` (unit^2/Hz), the tilt PSD taken as zero
    /// where it is not significantly above the witness noise.
    pub witness_limited: Vec<f64>,
    /// Per input, the scalar witness-limited residual `|G_a|^2 S_tt S_mm / S_ww` of that
    /// input alone.
    pub witness_limited_by_input: Vec<Vec<f64>>,
}

/// [`ModelSpectra`] of every output with the fitted coupling.
fn model_spectra(
    fitted: &Params,
    inputs: &[Input],
    outputs: &[Observable],
    coupling: &Coupling,
    witness: &WitnessSpectra,
    noise_at: &dyn Fn(usize) -> Vec<f64>,
) -> Result<Vec<ModelSpectra>, SubtractError> {
    let n_in = inputs.len();
    let freqs = &witness.freqs_hz;
    let grid = &freqs[1..];
    let request = crate::model::Request {
        outputs: outputs.to_vec(),
        inputs: inputs.to_vec(),
    };
    let at = |scale: f64| -> Result<Vec<Complex64>, SubtractError> {
        let f: Vec<f64> = grid.iter().map(|f| f * scale).collect();
        problem::transfer(fitted, &request, &f)
    };
    let h = at(1.0)?;
    let h_up = at(1.0 + predict::FREQ_ERROR_REL)?;
    let h_down = at(1.0 - predict::FREQ_ERROR_REL)?;
    let block = outputs.len() * n_in;
    Ok((0..outputs.len())
        .map(|o| {
            let mut ms = ModelSpectra {
                guard: vec![0.0; freqs.len()],
                witness_limited: vec![0.0; freqs.len()],
                witness_limited_by_input: vec![vec![0.0; freqs.len()]; n_in],
            };
            for (g, &f) in grid.iter().enumerate() {
                let k = g + 1;
                let rows = g * block + o * n_in..g * block + (o + 1) * n_in;
                ms.guard[k] = predict::guard_factor(predict::sensitivity(
                    &h[rows.clone()],
                    &h_up[rows.clone()],
                    &h_down[rows.clone()],
                ));
                let phase =
                    Complex64::from_polar(1.0, -std::f64::consts::TAU * f * coupling.delay_s);
                let gv =
                    DVector::from_fn(n_in, |a, _| h[rows.start + a] * coupling.gains[a] * phase);
                let sbar = &witness.smoothed[k];
                let noise = noise_at(k);
                let margin = prediction_margin(witness.dof[k]);
                let wgt = weigh(sbar, &noise, margin);
                ms.witness_limited[k] = (gv.adjoint() * &wgt.limit * &gv)[(0, 0)].re.max(0.0);
                for a in 0..n_in {
                    let s = sbar[(a, a)].re;
                    let tt = (s - margin * noise[a]).max(0.0);
                    ms.witness_limited_by_input[a][k] = if s > 0.0 {
                        gv[a].norm_sqr() * tt * noise[a] / s
                    } else {
                        0.0
                    };
                }
            }
            ms
        })
        .collect())
}

fn check_config(
    witness: &WitnessRecord,
    measured: &MeasuredRecord,
    cfg: &SubtractConfig,
) -> Result<(), SubtractError> {
    let f = cfg.holdout_fraction;
    if !(f > 0.0 && f <= MAX_HOLDOUT_FRACTION) {
        return Err(SubtractError::Config(crate::message!(
            "{} is not allowed: must be > 0 and <= {MAX_HOLDOUT_FRACTION} (the fit needs the \
             larger part of the overlap)",
            OptionKey::HOLDOUT.given(Num(f))
        )));
    }
    for (i, input) in witness.inputs.iter().enumerate() {
        if !input.is_ground() {
            return Err(SubtractError::Config(
                format!(
                "the witness record's channel {} is not a motion of the floor; a witness records \
                 floor inputs of the model (theta_t, eta_t, phi_t, x_t, y_t, z_t)",
                input.name()
            )
                .into(),
            ));
        }
        if witness.inputs[..i].contains(input) {
            return Err(SubtractError::Config(
                format!(
                    "the witness record has input {} twice; give each input once",
                    input.name()
                )
                .into(),
            ));
        }
    }
    for (input, r) in &cfg.colocated_noise_ratio {
        if !crate::limits::admits_noise_ratio(*r) {
            return Err(SubtractError::Config(crate::message!(
                "{}: the ratio of noise ASDs is not allowed: must be {}",
                OptionKey::COLOCATED_RATIO.given(format!("{}={}", input.name(), Num(*r))),
                crate::limits::allowed_noise_ratios()
            )));
        }
    }
    for x in &cfg.witness_noise {
        if !witness.inputs.contains(&x.input) {
            return Err(SubtractError::Config(crate::message!(
                "{}: the witness record has no input {}; it has {}",
                OptionKey::WITNESS_NOISE.given(x.input.name()),
                x.input.name(),
                names(witness.inputs.iter().map(|a| a.name()))
            )));
        }
        x.check(OptionKey::WITNESS_NOISE)
            .map_err(SubtractError::Config)?;
    }
    for (o, asd) in &cfg.readout_asd {
        if !measured.channels.iter().any(|c| c.0 == *o) {
            return Err(SubtractError::Config(crate::message!(
                "{}: the measured record has no channel {}; it has {}",
                OptionKey::READOUT.given(o.name()),
                o.name(),
                names(measured.channels.iter().map(|c| c.0.name()))
            )));
        }
        if !(asd.is_finite() && *asd >= 0.0) {
            return Err(SubtractError::Config(crate::message!(
                "{}: the ASD ({}/sqrt(Hz)) must be finite and >= 0",
                OptionKey::READOUT.given(format!("{}={}", o.name(), Num(*asd))),
                o.unit()
            )));
        }
    }
    if let Some((a, b)) = cfg.fit_band_hz {
        if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b) {
            return Err(SubtractError::Config(crate::message!(
                "{}: must be FLO:FHI with 0 < FLO < FHI (Hz)",
                OptionKey::BAND.given(format!("{}:{}", Num(a), Num(b)))
            )));
        }
    }
    let (a, b) = cfg.report_band_hz;
    if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b) {
        return Err(SubtractError::Config(crate::message!(
            "{}: must be FLO:FHI with 0 < FLO < FHI (Hz)",
            OptionKey::REPORT_BAND.given(format!("{}:{}", Num(a), Num(b)))
        )));
    }
    Ok(())
}

fn names<'a>(it: impl Iterator<Item = &'a str>) -> String {
    it.collect::<Vec<_>>().join(", ")
}

/// The method of the subtraction's transfer functions: `split` (full relative accuracy on
/// every entry) for the symmetric pendulum, `polezero` for the pendulum as built (split serves
/// only the symmetric model's blocks).
pub(crate) fn method_for(model: &Model) -> crate::tf::Method {
    if model.is_symmetric() {
        crate::tf::Method::Split
    } else {
        crate::tf::Method::PoleZero
    }
}
