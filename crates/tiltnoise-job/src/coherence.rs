//! The coherence job: a tilt time series and a measured time series of the observables, each
//! file read once, aligned by their start times, to the coherence, the measured transfer
//! functions with their confidence intervals and the model's beside them.

use crate::budget::ReadRequest;
use crate::error::{shown_path, JobError};
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::coherence::{coherence_from_series, CoherenceOptions, CoherenceReport, Record};
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_io::input::{
    parse_start_time, read_measured_input, read_start_time, read_tilt_series, MeasuredInput,
};
use tiltnoise_io::{
    write_coherence_csv, write_coherence_hdf5, CoherenceInputs, OutputError, OutputKind, RunMeta,
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
}

/// A coherence report and where its records came from.
#[derive(Debug, Clone)]
pub struct CoherenceResult {
    /// The report.
    pub report: CoherenceReport,
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
pub fn run(req: CoherenceRequest<'_>, cancel: &Cancel) -> Result<CoherenceResult, JobError> {
    if let Some((lo, hi)) = req.fit_band_hz {
        if !(lo.is_finite() && hi.is_finite() && lo >= 0.0 && lo < hi) {
            return Err(JobError::option(
                "fit_band",
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
                "measured",
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
                        "observables",
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
    Ok(CoherenceResult {
        report,
        inputs: CoherenceInputs {
            tilt: InputMeta::from(&tilt.provenance),
            measured_path,
            measured_start_time: measured_start,
        },
    })
}

/// Saves a coherence report in the format named by the extension of `path`: HDF5 (schema
/// `tiltnoise.coherence`, with `meta` and the records' provenance), CSV, or the PNG/SVG figure
/// titled with the records' names and drawn with `view`, as one of the outputs of `stage`; the same for every front
/// end.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for another extension (nothing is written), or the writer's
/// [`OutputError::Write`] naming `path`.
pub fn save(
    stage: &tiltnoise_io::Staging,
    path: &std::path::Path,
    result: &CoherenceResult,
    meta: &RunMeta,
    view: &tiltnoise_plot::View,
) -> Result<(), OutputError> {
    let (report, inputs) = (&result.report, &result.inputs);
    match OutputKind::from_path(path)? {
        OutputKind::Hdf5 => write_coherence_hdf5(stage, path, report, meta, inputs),
        OutputKind::Csv => write_coherence_csv(stage, path, report, meta),
        OutputKind::Png | OutputKind::Svg => {
            let options = tiltnoise_plot::CoherenceFigureOptions {
                tilt_name: inputs.tilt.path.clone(),
                measured_name: inputs.measured_path.clone(),
                view: view.clone(),
                ..tiltnoise_plot::CoherenceFigureOptions::default()
            };
            crate::save_image(stage, path, |format| {
                tiltnoise_plot::coherence_figure(report, format, &options)
            })
        }
    }
}
