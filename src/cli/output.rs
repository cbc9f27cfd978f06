//! Output files by extension: HDF5 and CSV through `tiltnoise-io`, figures drawn by
//! `tiltnoise-plot` and written by the job layer's [`save_image`], which Python uses too.

use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::noise::BudgetReport;
use tiltnoise_io::{write_budget_csv, write_budget_hdf5};
use tiltnoise_io::{OutputKind, RunMeta, Staging};

pub use tiltnoise_job::save_image;

/// Saves a noise budget in the format named by the extension of `path`: HDF5 (with `meta` and
/// `input`), CSV (ASDs only; identically-zero columns left out unless `keep_zero_columns`), or a PNG/SVG figure drawn with `figure` and the input named in
/// the caption; as one of the outputs of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for an unsupported extension (nothing is written), or the
/// writer's [`OutputError::Write`].
pub fn save_budget(
    stage: &Staging,
    path: &Path,
    report: &BudgetReport,
    meta: &RunMeta,
    input: &InputMeta,
    figure: &tiltnoise_plot::BudgetFigureOptions,
    keep_zero_columns: bool,
) -> Result<(), OutputError> {
    match OutputKind::from_path(path)? {
        OutputKind::Hdf5 => write_budget_hdf5(stage, path, report, meta, input),
        OutputKind::Csv => write_budget_csv(stage, path, report, meta, keep_zero_columns),
        OutputKind::Png | OutputKind::Svg => {
            let options = tiltnoise_plot::BudgetFigureOptions {
                input: Some(input.clone()),
                ..figure.clone()
            };
            save_image(stage, path, |format| {
                tiltnoise_plot::budget_figure_with(report, format, &options)
            })
        }
    }
}
