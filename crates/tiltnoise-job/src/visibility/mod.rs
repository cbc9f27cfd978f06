//! The visibility job: a recorded free motion of the observables, read once, to the
//! visibilities of the modes it shows (the signed ratio of each mode's peaks in two channels,
//! with its error) and the CSV that the fit reads back.

mod outcome;

pub use outcome::{VisibilityResult, OUTPUT_KINDS};

use crate::error::{shown_path, JobError};
use crate::outcome::Invocation;
use crate::progress::Progress;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::fit::peaks;
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_io::input::{read_measured_input, MeasuredInput};

/// A measurement of mode visibilities to run.
pub struct VisibilityRequest<'a> {
    /// The model whose mode frequencies the peaks are looked for at.
    pub model: &'a Model,
    /// The free-motion or ring-down record of the observables (HDF5 or CSV time series, the
    /// layout `simulate` writes).
    pub measured: PathBuf,
    /// Who asked for the measurement (its provenance).
    pub invocation: Invocation,
}

impl VisibilityRequest<'_> {
    /// The files the job reads, each with the option (snake case) that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &std::path::Path)> {
        vec![("measured", &self.measured)]
    }
}

/// Runs the measurement: reads the record once and measures each mode's peak near the
/// model's frequency in every channel. The peaks take a moment: `progress` is only told that
/// the measurement is over.
///
/// # Errors
///
/// A [`JobError`] naming the file: one that cannot be read, holds spectra, or shows no mode;
/// `Fit` wrapping the cancellation when `cancel` was set.
pub fn run(
    req: &VisibilityRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<VisibilityResult, JobError> {
    let result = measure(req, cancel);
    progress.finish();
    result
}

fn measure(req: &VisibilityRequest<'_>, cancel: &Cancel) -> Result<VisibilityResult, JobError> {
    let origin = shown_path(&req.measured);
    let series = match read_measured_input(&req.measured)? {
        MeasuredInput::Series(s) => s,
        MeasuredInput::Spectra(_) => {
            return Err(JobError::option(
                OptionKey::MEASURED,
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
        provenance: req.invocation.provenance(req.model.params(), Some(&modes)),
    })
}
