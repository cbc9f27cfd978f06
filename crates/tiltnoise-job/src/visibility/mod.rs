//! The visibility job: a recorded free motion of the observables, read once, to the
//! visibilities of the modes it shows (the signed ratio of each mode's peaks in two channels,
//! with its error) and the CSV that the fit reads back.

use crate::error::{shown_path, JobError};
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::fit::peaks::{self, RecordVisibilities, MIN_SNR};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_io::input::{read_measured_input, MeasuredInput};

/// A measurement of mode visibilities to run.
pub struct VisibilityRequest<'a> {
    /// The model whose mode frequencies the peaks are looked for at.
    pub model: &'a Model,
    /// The free-motion or ring-down record of the observables (HDF5 or CSV time series, the
    /// layout `simulate` writes).
    pub measured: PathBuf,
}

impl VisibilityRequest<'_> {
    /// The files the job reads, each with the option (snake case) that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &std::path::Path)> {
        vec![("measured", &self.measured)]
    }
}

/// The visibilities of a record, the peaks they were read from, and the record's channels.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VisibilityResult {
    /// The measurement.
    pub measured: RecordVisibilities,
    /// The record's channels, in its order (the order of each peak's SNRs).
    pub channels: Vec<Observable>,
    /// The record, as given.
    pub origin: String,
}

impl VisibilityResult {
    /// The visibilities as the CSV `mode,observable,reference,ratio,sigma` that the fit reads
    /// (`docs/fit.md`), with comment lines that say where and how they were measured.
    pub fn csv(&self) -> String {
        let comment = [
            format!(
                "mode visibilities measured from {} by tiltnoise visibility",
                self.origin
            ),
            format!(
                "Hann-windowed peaks of each mode near the model's frequency; reference: the \
                 strongest channel of each unit with SNR >= {MIN_SNR}; sigma: first-order \
                 error from the local noise"
            ),
        ];
        self.measured.visibilities.to_csv(&comment)
    }
}

/// Runs the measurement: reads the record once and measures each mode's peak near the
/// model's frequency in every channel.
///
/// # Errors
///
/// A [`JobError`] naming the file: one that cannot be read, holds spectra, or shows no mode;
/// `Fit` wrapping the cancellation when `cancel` was set.
pub fn run(req: VisibilityRequest<'_>, cancel: &Cancel) -> Result<VisibilityResult, JobError> {
    let origin = shown_path(&req.measured);
    let series = match read_measured_input(&req.measured)? {
        MeasuredInput::Series(s) => s,
        MeasuredInput::Spectra(_) => {
            return Err(JobError::option(
                "measured",
                Some(&origin),
                "holds spectra; the visibilities need the time series (header time_s, or HDF5)"
                    .to_string(),
            ))
        }
    };
    let modes = NormalModes::new(req.model);
    let expected: [f64; 8] = std::array::from_fn(|k| {
        modes
            .modes
            .iter()
            .find(|m| m.index == k + 1)
            .map_or(f64::NAN, |m| m.frequency_hz)
    });
    let measured = peaks::measure(
        &series.channels,
        series.sample_rate_hz,
        &expected,
        &origin,
        cancel,
    )?;
    Ok(VisibilityResult {
        measured,
        channels: series.channels.iter().map(|(o, _)| *o).collect(),
        origin,
    })
}
