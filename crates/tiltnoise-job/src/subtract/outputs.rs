//! The files of a subtraction, by extension, for every front end: `.h5`/`.hdf5` the cleaned
//! record (the observable-series layout `budget --measured` reads) with the predicted tilt
//! parts, estimates and residual spectra; `.json` the report; `.png`/`.svg` the figure.

use crate::error::JobError;
use crate::outcome::{Outcome, Provenance};
use crate::subtract::SubtractOutcome;
use std::path::Path;
use tiltnoise_io::{write_subtract_hdf5, OutputError, OutputKind, Staging};
use tiltnoise_plot::View;

/// The extensions a subtraction is saved to, for messages.
pub const ALLOWED: &str = ".h5, .hdf5, .json, .png, .svg";

/// What a subtraction's output file holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SaveKind {
    /// The cleaned record and the fit (HDF5).
    Hdf5,
    /// The report (JSON).
    Json,
    /// The figure (PNG or SVG).
    Image,
}

impl SaveKind {
    /// The kind `path`'s extension names.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] for another extension.
    pub fn of(path: &Path) -> Result<SaveKind, OutputError> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("h5" | "hdf5") => Ok(SaveKind::Hdf5),
            Some("json") => Ok(SaveKind::Json),
            Some("png" | "svg") => Ok(SaveKind::Image),
            _ => Err(OutputError::UnknownFormat {
                path: path.to_path_buf(),
                allowed: ALLOWED,
            }),
        }
    }
}

/// The kinds of file of [`OutputKind`] a subtraction is saved as: the cleaned record (HDF5)
/// and the figure; besides them, `.json` holds the report ([`Outcome::json`]).
pub const OUTPUT_KINDS: &[OutputKind] = &[OutputKind::Hdf5, OutputKind::Png, OutputKind::Svg];

impl SubtractOutcome {
    /// Writes the output `path` names by its extension ([`SaveKind`]) as one of the outputs of
    /// `stage`; a figure with `view`'s limits, size and resolution.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] for another extension, [`OutputError::Write`] naming
    /// `path` when it cannot be written (nothing is left there).
    pub fn save_with(&self, stage: &Staging, path: &Path, view: &View) -> Result<(), OutputError> {
        match SaveKind::of(path)? {
            SaveKind::Hdf5 => write_subtract_hdf5(stage, path, &self.result, &self.meta),
            SaveKind::Json => self.report().write(stage, path),
            SaveKind::Image => self.save_figure(stage, path, view),
        }
    }
}

impl Outcome for SubtractOutcome {
    fn provenance(&self) -> &Provenance {
        &self.meta.run
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// Saves `.h5`/`.hdf5` (the cleaned record), `.json` (the report) or the figure (with the
    /// request's figure options).
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        Ok(self.save_with(stage, path, &self.figure)?)
    }

    /// The report (the schema in `docs/subtract.md`).
    fn json(&self) -> serde_json::Value {
        serde_json::to_value(self.report()).expect("a report of numbers and strings serializes")
    }
}
