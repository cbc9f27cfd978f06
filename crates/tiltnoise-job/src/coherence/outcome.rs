//! The coherence found: a summary on the terminal, the JSON report, the files (HDF5, CSV) and
//! the figure.

use super::CoherenceInputs;
use crate::error::JobError;
use crate::figures::{CoherenceFigureOptions, View};
use crate::outcome::{output_kind, Outcome, Provenance};
use std::path::Path;
use tiltnoise_core::coherence::CoherenceReport;
use tiltnoise_core::error::OutputError;

/// The kinds of file a coherence result is saved as: HDF5 (schema `tiltnoise.coherence`), CSV and
/// the figure.
pub const OUTPUT_KINDS: &[OutputKind] = crate::outcome::SPECTRA_KINDS;
use tiltnoise_io::{
    coherence_csv_string, write_coherence_csv, write_coherence_hdf5, OutputKind, Staging,
};

/// A coherence report, where its records came from, and the provenance its files record.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct CoherenceOutcome {
    /// The report.
    pub report: CoherenceReport,
    /// The records' provenance, as the files keep it.
    pub inputs: CoherenceInputs,
    pub(crate) provenance: Provenance,
    /// The figure's view (not kept by a serialized outcome: the default view then).
    #[serde(skip)]
    pub(crate) view: View,
}

impl CoherenceOutcome {
    /// The report as the CSV [`Outcome::save`] writes (`docs/schemas.md`).
    pub fn csv(&self) -> String {
        coherence_csv_string(&self.report, &self.provenance)
    }
}

impl Outcome for CoherenceOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// `.h5` (schema `tiltnoise.coherence`), `.csv`, `.png`, `.svg`.
    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// Saves the report: HDF5 (schema `tiltnoise.coherence`, with the provenance and the
    /// records'), CSV, or the figure titled with the records' names, drawn in the request's
    /// view; the same for every front end.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        output_kind(path, self.output_kinds())?;
        let (report, inputs) = (&self.report, &self.inputs);
        Ok(write(
            stage,
            path,
            report,
            inputs,
            &self.provenance,
            &self.view,
        )?)
    }

    /// `coherence --format json`: the numbers of the summary, unrounded (NaN is `null`), the
    /// tilt reader's notes (`input_notes`) and the analysis's (`notes`).
    fn json(&self) -> serde_json::Value {
        super::json::summary_json(&self.report, &self.inputs.tilt.notes)
    }
}

/// Writes a coherence report in the format named by the extension of `path`: HDF5 (schema
/// `tiltnoise.coherence`, with `meta` and the records' provenance), CSV, or the PNG/SVG figure
/// titled with the records' names and drawn with `view`, as one of the outputs of `stage`.
pub(super) fn write(
    stage: &Staging,
    path: &Path,
    report: &CoherenceReport,
    inputs: &CoherenceInputs,
    meta: &Provenance,
    view: &View,
) -> Result<(), OutputError> {
    match crate::output_kind(path, OUTPUT_KINDS)? {
        OutputKind::Hdf5 => write_coherence_hdf5(stage, path, report, meta, inputs),
        OutputKind::Csv => write_coherence_csv(stage, path, report, meta),
        _ => {
            let options = CoherenceFigureOptions {
                tilt_name: inputs.tilt.path.clone(),
                measured_name: inputs.measured_path.clone(),
                view: view.clone(),
                ..CoherenceFigureOptions::default()
            };
            crate::save_image(stage, path, |format| {
                tiltnoise_plot::coherence_figure(report, format, &options)
            })
        }
    }
}
