//! A computed budget: its files (HDF5, CSV), its figure and its summary's JSON, the same for
//! every front end.

use crate::error::JobError;
use crate::figures::BudgetFigureOptions;
use crate::outcome::{output_kind, Outcome, Provenance};
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::noise::BudgetReport;
use tiltnoise_io::{budget_csv_string, write_budget_csv, write_budget_hdf5, OutputKind, Staging};

/// The kinds of file a budget result is saved as: HDF5 (schema `tiltnoise.budget`), CSV and
/// the figure.
pub const OUTPUT_KINDS: &[OutputKind] = crate::outcome::SPECTRA_KINDS;

/// A noise budget, where its floor's motion came from, and the provenance its files record.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct BudgetOutcome {
    /// The budget.
    pub report: BudgetReport,
    /// The input's provenance; its notes are the reader's.
    pub input: InputMeta,
    provenance: Provenance,
}

/// How [`BudgetOutcome::save_with`] writes what the outcome alone does not say: the CSV's
/// zero columns and the figure's options.
#[derive(Debug, Clone, Default)]
pub struct SaveOptions {
    /// Keep the CSV columns that are zero at every frequency (left out by default and named
    /// in a `# note:` line; the HDF5 file always has every term).
    pub keep_zero_columns: bool,
    /// Size, view and note of the figure; its `input` is the outcome's, whatever is given.
    pub figure: BudgetFigureOptions,
}

impl BudgetOutcome {
    /// The outcome of `report`, computed from the floor's motion `input`, whose files record
    /// `provenance`. The job builds its own from the request; this one is for a report
    /// computed or changed elsewhere (a test's hand-made report).
    pub fn new(report: BudgetReport, input: InputMeta, provenance: Provenance) -> Self {
        Self {
            report,
            input,
            provenance,
        }
    }

    /// The budget as the CSV [`Outcome::save`] writes (`docs/schemas.md`): columns that are
    /// zero at every frequency left out and named in a `# note:` line unless
    /// `keep_zero_columns`.
    ///
    /// # Errors
    ///
    /// Why the report cannot be written (a term of another length than the grid).
    pub fn csv(&self, keep_zero_columns: bool) -> Result<String, String> {
        budget_csv_string(&self.report, &self.provenance, keep_zero_columns)
    }

    /// Saves the budget to `path` as [`Outcome::save`] does, with `options`: HDF5 (schema
    /// `tiltnoise.budget`, with the provenance and the input's), CSV (ASDs only, zero columns
    /// as `options` says), or the figure drawn with `options.figure` and the input named in
    /// its caption; as one of the outputs of `stage`.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] for an extension of no output kind (nothing is
    /// written), or the writer's [`OutputError::Write`].
    pub fn save_with(
        &self,
        stage: &Staging,
        path: &Path,
        options: &SaveOptions,
    ) -> Result<(), JobError> {
        let (report, meta) = (&self.report, &self.provenance);
        let written: Result<(), OutputError> = match output_kind(path, self.output_kinds())? {
            OutputKind::Hdf5 => write_budget_hdf5(stage, path, report, meta, &self.input),
            OutputKind::Csv => {
                write_budget_csv(stage, path, report, meta, options.keep_zero_columns)
            }
            _ => {
                let figure = BudgetFigureOptions {
                    input: Some(self.input.clone()),
                    ..options.figure.clone()
                };
                crate::save_image(stage, path, |format| {
                    tiltnoise_plot::budget_figure_with(report, format, &figure)
                })
            }
        };
        Ok(written?)
    }
}

impl Outcome for BudgetOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// `.h5` (schema `tiltnoise.budget`), `.csv`, `.png`, `.svg`.
    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// [`BudgetOutcome::save_with`] the default options: zero CSV columns left out, the
    /// figure in its default size and view.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        self.save_with(stage, path, &SaveOptions::default())
    }

    /// `budget --format json`: the budget read at its summary frequencies, with the input's
    /// and the budget's notes (`{"notes": [...], "summary": [...]}`).
    fn json(&self) -> serde_json::Value {
        super::summary::summary_json(&self.report, &self.input.notes)
    }
}
