//! The coherence job: a tilt time series and a measured time series of the observables, each
//! file read once, aligned by their start times, to the coherence, the measured transfer
//! functions with their confidence intervals and the model's beside them.

mod json;
mod outcome;

pub use json::{peak_bin, significant_bins};
pub use outcome::{CoherenceOutcome, OUTPUT_KINDS};
pub use tiltnoise_io::CoherenceInputs;

use crate::budget::ReadRequest;
use crate::error::{shown_path, JobError};
use crate::figures::View;
use crate::outcome::Invocation;
use crate::progress::Progress;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::coherence::{coherence_from_series, CoherenceOptions, Record};
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_io::input::{
    parse_start_time, read_measured_input, read_start_time, read_tilt_series, MeasuredInput,
};

/// A coherence analysis to run.
pub struct CoherenceRequest<'a> {
    /// The model.
    pub model: &'a Model,
    /// The tilt time series (HDF5, CSV or miniSEED).
    pub tilt: PathBuf,
    /// How to read it (tilt channels only: the axis map, quantity, gaps and scales).
    pub read: ReadRequest,
    /// The measured time series of the observables (HDF5 as `simulate` writes it, or CSV).
    pub measured: PathBuf,
    /// The observables to analyse, each in the measured file (default: all of its channels).
    pub observables: Option<Vec<Observable>>,
    /// Welch segment length (default: 2^14, or the largest power of two <= N/4).
    pub nperseg: Option<usize>,
    /// Welch overlap as a fraction of the segment (default 0.5).
    pub overlap: Option<f64>,
    /// Confidence level of every interval and threshold (default 0.95).
    pub confidence: Option<f64>,
    /// Band (Hz) of the measured/model fit, `0 <= lo < hi` (default: every bin).
    pub fit_band_hz: Option<(f64, f64)>,
    /// Size, resolution and axis limits of the figure [`Outcome::save`](crate::Outcome::save)
    /// draws.
    pub view: View,
    /// Who asked, for the provenance.
    pub invocation: Invocation,
}

/// A coherence report and where its records came from: the numbers of a
/// [`CoherenceOutcome`], without the run's provenance.
#[derive(Debug, Clone)]
pub struct CoherenceResult {
    /// The report.
    pub report: tiltnoise_core::coherence::CoherenceReport,
    /// The records' provenance, as the files keep it.
    pub inputs: CoherenceInputs,
}

impl CoherenceRequest<'_> {
    /// The files the job reads, each with the option (snake case) that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &std::path::Path)> {
        vec![("tilt", &self.tilt), ("measured", &self.measured)]
    }
}

/// Runs the analysis: checks the options, reads the tilt and the measured record once each,
/// selects the observables and computes the report.
///
/// # Errors
///
/// A [`JobError`] naming the option or file that failed; `Coherence` for records that give
/// no estimate (and when `cancel` was set).
pub fn run(
    req: &CoherenceRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<CoherenceOutcome, JobError> {
    if let Some((lo, hi)) = req.fit_band_hz {
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && lo < hi) {
            return Err(JobError::option(
                OptionKey::FIT_BAND,
                Some(&format!("{lo}:{hi}")),
                "must be finite with 0 <= FLO < FHI (Hz)".to_string(),
            ));
        }
    }
    let tilt = read_tilt_series(&req.tilt, &req.read.options())?;
    let measured_path = shown_path(&req.measured);
    let measured =
        match read_measured_input(&req.measured)? {
            MeasuredInput::Series(s) => s,
            MeasuredInput::Spectra(_) => return Err(JobError::option(
                OptionKey::MEASURED,
                Some(&measured_path),
                "the file holds spectra (header frequency_hz); coherence needs a time series of \
                 the observables (header time_s, or HDF5)"
                    .to_string(),
            )),
        };
    let measured_start = read_start_time(&req.measured)?;
    let channels: Vec<(Observable, &[f64])> = match &req.observables {
        None => measured
            .channels
            .iter()
            .map(|(o, x)| (*o, x.as_slice()))
            .collect(),
        Some(observables) => observables
            .iter()
            .map(|&o| {
                let found = measured.channels.iter().find(|(c, _)| *c == o);
                found.map(|(c, x)| (*c, x.as_slice())).ok_or_else(|| {
                    let present: Vec<&str> =
                        measured.channels.iter().map(|(o, _)| o.name()).collect();
                    JobError::option(
                        OptionKey::OBSERVABLES,
                        Some(o.name()),
                        format!(
                            "the measured file {measured_path} has no channel {}; it has {}",
                            o.name(),
                            present.join(", ")
                        ),
                    )
                })
            })
            .collect::<Result<_, _>>()?,
    };
    let defaults = CoherenceOptions::default();
    let opts = CoherenceOptions {
        welch_segment_len: req.nperseg,
        welch_overlap_fraction: req.overlap.unwrap_or(defaults.welch_overlap_fraction),
        confidence: req.confidence.unwrap_or(defaults.confidence),
        fit_band_hz: req.fit_band_hz,
        tilt_quantity: tilt.quantity(),
        cancel: cancel.clone(),
    };
    let tilt_name = shown_path(&req.tilt);
    let tilt_record = Record {
        name: &tilt_name,
        sample_rate_hz: tilt.sample_rate_hz,
        start_time: tilt
            .provenance
            .start_time
            .as_deref()
            .and_then(parse_start_time),
        channels: tilt
            .axes
            .iter()
            .zip(&tilt.data)
            .map(|(a, x)| (*a, x.as_slice()))
            .collect::<Vec<(TiltAxis, &[f64])>>(),
    };
    let measured_record = Record {
        name: &measured_path,
        sample_rate_hz: measured.sample_rate_hz,
        start_time: measured_start.as_deref().and_then(parse_start_time),
        channels,
    };
    let report = coherence_from_series(req.model, &tilt_record, &measured_record, &opts)
        .map_err(|e| JobError::Coherence(Box::new(e)))?;
    progress.finish();
    Ok(CoherenceOutcome {
        report,
        provenance: crate::modes::provenance(req.model, &req.invocation),
        view: req.view.clone(),
        inputs: CoherenceInputs {
            tilt: InputMeta::from(&tilt.provenance),
            measured_path,
            measured_start_time: measured_start,
        },
    })
}

/// Saves a coherence report with the provenance `meta` in the format named by the extension
/// of `path` (as [`CoherenceOutcome`]'s `save`, which writes through the same code), drawn with
/// `view`, as one of the outputs of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`](tiltnoise_core::error::OutputError::UnknownFormat) for
/// another extension (nothing is written), or the writer's error naming `path`.
pub fn save(
    stage: &tiltnoise_io::Staging,
    path: &std::path::Path,
    result: &CoherenceResult,
    meta: &crate::Provenance,
    view: &View,
) -> Result<(), tiltnoise_core::error::OutputError> {
    outcome::write(stage, path, &result.report, &result.inputs, meta, view)
}
