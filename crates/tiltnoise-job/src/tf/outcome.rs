//! A transfer matrix computed whole: its files (HDF5, CSV), its figure and its JSON.

use super::stream::{json_head, json_tail_units, point_json};
use crate::error::JobError;
use crate::figures::TfFigureOptions;
use crate::outcome::{output_kind, Outcome, Provenance};
use std::path::Path;
use tiltnoise_core::tf::planner::Choice;
use tiltnoise_core::tf::TransferMatrix;
use tiltnoise_io::{OutputKind, Staging};

/// The kinds of file a tf result is saved as: HDF5 (schema `tiltnoise.tf`), CSV and
/// the figure.
pub const OUTPUT_KINDS: &[OutputKind] = crate::outcome::SPECTRA_KINDS;

/// A transfer matrix computed whole, how its method was chosen, and what its outputs record.
pub struct TfOutcome {
    /// The matrix.
    pub tf: TransferMatrix,
    /// `auto`'s pick with its evidence (`None` for a method asked for).
    pub choice: Option<Choice>,
    pub(crate) provenance: Provenance,
    pub(crate) figure: TfFigureOptions,
}

impl Outcome for TfOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// `.h5` (schema `tiltnoise.tf`), `.csv`, `.png`, `.svg`.
    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// Saves the matrix: HDF5 (schema `tiltnoise.tf`, with the provenance), CSV, or the
    /// figure drawn with the request's figure options; the same files as a streamed run's.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        output_kind(path, self.output_kinds())?;
        Ok(super::save(
            stage,
            path,
            &self.tf,
            &self.provenance,
            &self.figure,
        )?)
    }

    /// The document `tf --format json` prints without `--save`: `inputs`, `method`,
    /// `observables`, `per`, `points` (one `{"H": [[[re, im] per input] per observable],
    /// "frequency_hz": f}` per frequency) and `units` (per observable, per input).
    fn json(&self) -> serde_json::Value {
        let mut doc = json_head(&self.tf, self.tf.method);
        let points = (0..self.tf.freqs_hz.len())
            .map(|k| point_json(&self.tf, k))
            .collect();
        doc.insert("points".into(), serde_json::Value::Array(points));
        doc.insert("units".into(), json_tail_units(&self.tf));
        serde_json::Value::Object(doc)
    }
}
