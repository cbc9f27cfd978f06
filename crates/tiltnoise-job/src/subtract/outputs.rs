//! The files of a subtraction, by extension, for every front end: `.h5`/`.hdf5` the cleaned
//! record (the observable-series layout `budget --measured` reads) with the predicted tilt
//! parts, estimates and residual spectra; `.json` the report; `.png`/`.svg` the figure.

use crate::error::JobError;
use crate::outcome::{Outcome, Provenance};
use crate::subtract::SubtractOutcome;
use std::path::Path;
use tiltnoise_io::{write_subtract_hdf5, OutputError, OutputKind, Staging};
use tiltnoise_plot::View;

/// The kinds of file a subtraction is saved as: the cleaned record (HDF5), the report
/// ([`Outcome::json`]) and the figure.
pub const OUTPUT_KINDS: &[OutputKind] = &[
    OutputKind::Hdf5,
    OutputKind::Json,
    OutputKind::Png,
    OutputKind::Svg,
];

impl SubtractOutcome {
    /// Writes the output `path` names by its extension ([`OUTPUT_KINDS`]) as one of the outputs of
    /// `stage`; a figure with `view`'s limits, size and resolution.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] for another extension, [`OutputError::Write`] naming
    /// `path` when it cannot be written (nothing is left there).
    pub fn save_with(&self, stage: &Staging, path: &Path, view: &View) -> Result<(), OutputError> {
        match crate::output_kind(path, OUTPUT_KINDS)? {
            OutputKind::Hdf5 => write_subtract_hdf5(stage, path, &self.result, &self.meta),
            OutputKind::Json => self.report().write(stage, path),
            _ => self.save_figure(stage, path, view),
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
