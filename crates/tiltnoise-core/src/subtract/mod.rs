//! Tilt subtraction: how much of a measured record of the observables is floor tilt, how well
//! the model's coupling matches the data, and what is left once it is removed.
//!
//! Inputs: a tilt record (the witness: angle series in the crate's sign convention, one per
//! axis) and a measured record of some observables (m, rad), each with its sample rate and,
//! optionally, the ISO 8601 time of its first sample. The pipeline ([`subtract`]):
//!
//! 1. **Alignment** ([`align()`]): by start times to the nearest sample (the fraction of a sample
//!    left is a known part of the delay); without a start time in either file both records are
//!    taken to start together (the provenance says so). Rates must agree; nothing is
//!    resampled.
//! 2. **Split**: the first part of the overlap trains (fit, Wiener filter), the last
//!    `holdout_fraction` of it validates.
//! 3. **Fit** ([`estimate`]): a gain per tilt axis (the tiltmeter's calibration), a delay (the
//!    clocks' offset) and any chosen model parameters, by errors-in-variables-corrected
//!    weighted least squares on the Welch cross spectra, with uncertainties; parameters the data
//!    cannot constrain are held at their nominal values and reported as such.
//! 4. **Prediction** ([`predict`]): the tilt part of each observable in the time domain
//!    through the fitted model (exact frequency-domain filtering of the whole overlap), and the
//!    cleaned record `measured - predicted`.
//! 5. **Residuals** ([`residuals`]): on the held-out stretch, the cleaned residual against
//!    the readout, against the residual the coherence allows, and against a data-driven
//!    multiple-input Wiener filter trained on the training stretch.
//!
//! Welch settings throughout: periodic Hann, 50 % overlap, mean, constant detrend
//! ([`crate::spectral`]); one-sided PSDs (unit^2/Hz) and ASDs (unit/sqrt(Hz)); `e^{+iwt}`.
//!
//! Pure numerics: depends on `params`, `model`, `tf`, `spectral`, `fit` (the solver) and
//! `simulate` (nothing else; no I/O).

pub mod align;
pub mod estimate;
mod input_checks;
pub mod predict;
pub mod residuals;
pub mod stats;

pub use align::{align, Alignment, StartTime};
pub use estimate::{Estimate, FitReport, FitRequest, Status};
pub use predict::{Coupling, Prediction};
pub use residuals::{BandSummary, ResidualSpectra};

use crate::error::{Num, TfError};
use crate::model::{Model, Observable, TiltAxis};
use crate::params::Params;
use crate::spectral::{csd_matrix, welch, SpectralError, WelchConfig};

/// Default held-out fraction of the overlap.
pub const DEFAULT_HOLDOUT_FRACTION: f64 = 0.25;
/// Largest held-out fraction: the fit needs the larger part.
pub const MAX_HOLDOUT_FRACTION: f64 = 0.5;
/// Default report band (Hz): where the pendulum is quiet between its torsion and
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

/// The tilt record: angle series (rad), crate sign convention.
#[derive(Debug, Clone, Copy)]
pub struct TiltRecord<'a> {
    /// Sample rate (Hz).
    pub fs_hz: f64,
    /// Axes, canonical order.
    pub axes: &'a [TiltAxis],
    /// One series per axis, equal lengths.
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
    /// White noise of the tilt record per axis: one-sided ASD (rad/sqrt(Hz)).
    pub witness_noise_asd: Vec<(TiltAxis, f64)>,
    /// White readout of the measured observables: one-sided ASD (unit/sqrt(Hz)).
    pub readout_asd: Vec<(Observable, f64)>,
    /// Band of the residual summaries (Hz).
    pub report_band_hz: (f64, f64),
}

impl Default for SubtractConfig {
    fn default() -> Self {
        SubtractConfig {
            segment_len: None,
            holdout_fraction: DEFAULT_HOLDOUT_FRACTION,
            keys: Vec::new(),
            fit_band_hz: None,
            max_delay_s: None,
            witness_noise_asd: Vec::new(),
            readout_asd: Vec::new(),
            report_band_hz: DEFAULT_REPORT_BAND_HZ,
        }
    }
}

/// The outcome of [`subtract`].
#[derive(Debug, Clone)]
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
    /// Predicted tilt part per observable over the overlap.
    pub prediction: Prediction,
    /// Measured minus predicted, per observable, over the overlap.
    pub cleaned: Vec<(Observable, Vec<f64>)>,
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
    TooShort(String),
    /// An option outside its allowed range.
    #[error("{0}")]
    Config(String),
    /// A record the estimation cannot use: a non-finite sample or spectrum, a dead channel.
    #[error("{0}")]
    Record(String),
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
         model, or the tilt record has no power above its own noise there); choose another \
         band with --band",
        Num(.band_hz.0), Num(.band_hz.1)
    )]
    NoFitBins {
        /// The band (Hz).
        band_hz: (f64, f64),
    },
    /// A key that is not a parameter.
    #[error("--fit: unknown parameter key `{}`; allowed: {allowed}", crate::error::Shown(.key))]
    UnknownKey {
        /// The key given.
        key: String,
        /// Keys that may be fitted.
        allowed: String,
    },
    /// A key that cannot be fitted.
    #[error("--fit: parameter `{key}` is not a free parameter here: {reason}; allowed: {allowed}")]
    NotFreeKey {
        /// The key.
        key: String,
        /// Why.
        reason: String,
        /// Keys that may be fitted.
        allowed: String,
    },
    /// The same key twice.
    #[error("--fit: parameter `{key}` is listed twice; give each key once")]
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
/// an overlap too short for the Welch segment, options out of range, bad fit keys.
pub fn subtract(
    params: &Params,
    tilt: &TiltRecord,
    measured: &MeasuredRecord,
    cfg: &SubtractConfig,
) -> Result<SubtractResult, SubtractError> {
    let n_w = tilt.data.first().map_or(0, Vec::len);
    let n_m = measured.channels.first().map_or(0, |c| c.1.len());
    let alignment = align(
        (tilt.fs_hz, n_w, tilt.start),
        (measured.fs_hz, n_m, measured.start),
    )?;
    let fs = alignment.fs_hz;
    check_config(tilt, measured, cfg)?;
    let n = alignment.len;
    let n_hold = (n as f64 * cfg.holdout_fraction).round() as usize;
    let n_train = n - n_hold;
    let segment_len = match cfg.segment_len {
        Some(l) => l,
        None => {
            pow2_floor((n_train / DEFAULT_SEGMENTS_IN_TRAINING).min(n_hold / MIN_HOLDOUT_SEGMENTS))
                .min(MAX_DEFAULT_SEGMENT)
        }
    };
    let span = |m: usize| format!("{m} samples ({} s)", Num(m as f64 / fs));
    if segment_len < MIN_SEGMENT
        || n_train < MIN_TRAINING_SEGMENTS * segment_len
        || n_hold < MIN_HOLDOUT_SEGMENTS * segment_len
    {
        let needed_seg = segment_len.max(MIN_SEGMENT);
        let needed = (MIN_TRAINING_SEGMENTS * needed_seg) as f64 / (1.0 - cfg.holdout_fraction);
        let needed = needed.max((MIN_HOLDOUT_SEGMENTS * needed_seg) as f64 / cfg.holdout_fraction);
        return Err(SubtractError::TooShort(format!(
            "the records overlap for {}: with a held-out fraction of {} and a Welch segment of {} \
             the overlap must be at least {} (training >= {MIN_TRAINING_SEGMENTS} segments, \
             held-out >= {MIN_HOLDOUT_SEGMENTS}); use longer records or a shorter --nperseg",
            span(n),
            cfg.holdout_fraction,
            span(needed_seg),
            span(needed.ceil() as usize),
        )));
    }
    let segment_s = segment_len as f64 / fs;
    let max_delay_s = match cfg.max_delay_s {
        Some(d) if d.is_finite() && d > 0.0 && d <= MAX_DELAY_FRACTION * segment_s => d,
        Some(d) => {
            return Err(SubtractError::Config(format!(
                "--max-delay {} s is not allowed: must be > 0 and at most {} of the Welch \
                 segment, {} s (longer delays need a longer --nperseg)",
                Num(d),
                MAX_DELAY_FRACTION,
                Num(MAX_DELAY_FRACTION * segment_s)
            )))
        }
        None => DEFAULT_MAX_DELAY_FRACTION * segment_s,
    };
    let w: Vec<&[f64]> = tilt
        .data
        .iter()
        .map(|x| &x[alignment.witness_first..alignment.witness_first + n])
        .collect();
    let y: Vec<&[f64]> = measured
        .channels
        .iter()
        .map(|(_, x)| &x[alignment.measured_first..alignment.measured_first + n])
        .collect();
    let outputs: Vec<Observable> = measured.channels.iter().map(|c| c.0).collect();
    let channel_names = input_checks::channel_names(tilt.axes, &outputs);
    input_checks::check_channels(&channel_names, &w, &y)?;
    let welch_cfg = WelchConfig::new(segment_len);
    let step = segment_len - welch_cfg.overlap;
    let train: Vec<&[f64]> = w.iter().chain(&y).map(|x| &x[..n_train]).collect();
    let training_spectra = csd_matrix(&train, fs, &welch_cfg)?;
    input_checks::check_spectra(&training_spectra, &channel_names, "training")?;
    let n_eff_train = stats::effective_averages(segment_len, step, training_spectra.n_segments);
    let witness_noise_psd: Vec<f64> = tilt
        .axes
        .iter()
        .map(|a| {
            cfg.witness_noise_asd
                .iter()
                .find(|(x, _)| x == a)
                .map_or(0.0, |(_, asd)| asd * asd)
        })
        .collect();
    let fit = estimate::fit(
        params,
        tilt.axes,
        &outputs,
        &estimate::Training {
            spectra: &training_spectra,
            fs_hz: fs,
            segment_len,
            n_eff: n_eff_train,
            n_segments: training_spectra.n_segments,
        },
        alignment.fraction_s,
        &FitRequest {
            keys: cfg.keys.clone(),
            band_hz: cfg.fit_band_hz,
            max_delay_s,
            witness_noise_psd,
        },
    )?;
    let gains: Vec<f64> = tilt
        .axes
        .iter()
        .map(|a| {
            fit.estimates
                .iter()
                .find(|e| e.name == format!("gain.{}", a.name()))
                .map_or(1.0, |e| e.value)
        })
        .collect();
    let delay_s = fit
        .estimates
        .iter()
        .find(|e| e.name == "delay_s")
        .map_or(0.0, |e| e.value);
    let fitted_model = Model::new(&fit.params).map_err(|e| SubtractError::Params(e.to_string()))?;
    let prediction = predict::predict(
        &fitted_model,
        fs,
        tilt.axes,
        &w,
        &outputs,
        &Coupling {
            gains,
            delay_s: delay_s - alignment.fraction_s,
        },
    )?;
    let cleaned: Vec<(Observable, Vec<f64>)> = prediction
        .series
        .iter()
        .zip(&y)
        .map(|((o, p), m)| (*o, m.iter().zip(p).map(|(a, b)| a - b).collect()))
        .collect();

    let held: Vec<&[f64]> = w.iter().chain(&y).map(|x| &x[n_train..]).collect();
    let held_spectra = csd_matrix(&held, fs, &welch_cfg)?;
    input_checks::check_spectra(&held_spectra, &channel_names, "held-out")?;
    let n_eff_held = stats::effective_averages(segment_len, step, held_spectra.n_segments);
    let psds = |series: &[(Observable, Vec<f64>)]| -> Result<Vec<Vec<f64>>, SubtractError> {
        series
            .iter()
            .map(|(_, x)| Ok(welch(&x[n_train..], fs, &welch_cfg)?.psd))
            .collect()
    };
    let predicted_psd = psds(&prediction.series)?;
    let cleaned_psd = psds(&cleaned)?;
    let wiener = residuals::Wiener::train(&training_spectra, tilt.axes.len(), outputs.len());
    let report_band = cfg.report_band_hz;
    let grid = &held_spectra.freqs_hz;
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
    let residuals = residuals::evaluate(
        &wiener,
        &residuals::HeldOut {
            spectra: &held_spectra,
            predicted_psd: &predicted_psd,
            cleaned_psd: &cleaned_psd,
            n_eff: n_eff_held,
            n_segments: held_spectra.n_segments,
            bin_variance_factor: stats::bin_variance_factor(segment_len, 1),
        },
        &outputs,
        &cfg.readout_asd,
        report_band,
    );
    let mut notes = vec![alignment.note.clone()];
    notes.extend(fit.notes.iter().cloned());
    for (o, bands) in &prediction.guarded {
        if !bands.is_empty() {
            let list: Vec<String> = bands
                .iter()
                .map(|(a, b)| format!("{} .. {} Hz", Num(*a), Num(*b)))
                .collect();
            notes.push(format!(
                "{}: not predicted near the model's undamped resonances ({})",
                o.name(),
                list.join(", ")
            ));
        }
    }
    for r in &residuals {
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
    Ok(SubtractResult {
        alignment,
        segment_len,
        n_train,
        n_holdout: n_hold,
        n_eff: (n_eff_train, n_eff_held),
        fit,
        max_delay_s,
        prediction,
        cleaned,
        residuals,
        notes,
    })
}

fn check_config(
    tilt: &TiltRecord,
    measured: &MeasuredRecord,
    cfg: &SubtractConfig,
) -> Result<(), SubtractError> {
    let f = cfg.holdout_fraction;
    if !(f > 0.0 && f <= MAX_HOLDOUT_FRACTION) {
        return Err(SubtractError::Config(format!(
            "--holdout {} is not allowed: must be > 0 and <= {MAX_HOLDOUT_FRACTION} (the fit \
             needs the larger part of the overlap)",
            Num(f)
        )));
    }
    for (axis, asd) in &cfg.witness_noise_asd {
        if !tilt.axes.contains(axis) {
            return Err(SubtractError::Config(format!(
                "--tilt-noise {}: the tilt record has no axis {}; it has {}",
                axis.name(),
                axis.name(),
                names(tilt.axes.iter().map(|a| a.name()))
            )));
        }
        if !(asd.is_finite() && *asd >= 0.0) {
            return Err(SubtractError::Config(format!(
                "--tilt-noise {}={}: the ASD (rad/sqrt(Hz)) must be finite and >= 0",
                axis.name(),
                Num(*asd)
            )));
        }
    }
    for (o, asd) in &cfg.readout_asd {
        if !measured.channels.iter().any(|c| c.0 == *o) {
            return Err(SubtractError::Config(format!(
                "--readout {}: the measured record has no channel {}; it has {}",
                o.name(),
                o.name(),
                names(measured.channels.iter().map(|c| c.0.name()))
            )));
        }
        if !(asd.is_finite() && *asd >= 0.0) {
            return Err(SubtractError::Config(format!(
                "--readout {}={}: the ASD ({}/sqrt(Hz)) must be finite and >= 0",
                o.name(),
                Num(*asd),
                o.unit()
            )));
        }
    }
    if let Some((a, b)) = cfg.fit_band_hz {
        if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b) {
            return Err(SubtractError::Config(format!(
                "--band {}:{}: must be FLO:FHI with 0 < FLO < FHI (Hz)",
                Num(a),
                Num(b)
            )));
        }
    }
    let (a, b) = cfg.report_band_hz;
    if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b) {
        return Err(SubtractError::Config(format!(
            "--report-band {}:{}: must be FLO:FHI with 0 < FLO < FHI (Hz)",
            Num(a),
            Num(b)
        )));
    }
    Ok(())
}

fn names<'a>(it: impl Iterator<Item = &'a str>) -> String {
    it.collect::<Vec<_>>().join(", ")
}
