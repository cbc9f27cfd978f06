//! Output files: transfer functions and noise budgets as HDF5 or CSV (schemas in
//! `docs/schemas.md`), figures via [`crate::plot`].
//!
//! Pure I/O: the numerical modules never import this one. Every writer is atomic (see
//! [`write_atomic`]): a failed write leaves nothing at the target path and never clobbers an
//! existing file.

mod budget_csv;
mod budget_hdf5;
mod h5util;
mod mc_hdf5;
mod series_hdf5;
mod tf_csv;
mod tf_hdf5;

pub use crate::atomic::write_atomic;
pub(crate) use budget_csv::check_report as check_budget_report;
pub use budget_csv::{budget_csv_string, write_budget_csv};
pub use budget_hdf5::{
    write_budget_hdf5, SCHEMA_BUDGET, SCHEMA_VERSION_BUDGET, SPECTRAL_CONVENTION,
};
pub use mc_hdf5::{write_mc_hdf5, REJECTED_DRAWS, SCHEMA_MC, SCHEMA_VERSION_MC};
pub use series_hdf5::{
    write_observable_series_hdf5, SeriesAsd, SimulationMeta, SCHEMA_OBSERVABLE_SERIES,
    SCHEMA_VERSION_OBSERVABLE_SERIES,
};
pub use tf_csv::{format_f64, tf_csv_string, write_tf_csv};
pub use tf_hdf5::{write_tf_hdf5, SCHEMA_TF, SCHEMA_VERSION_TF, SIGN_CONVENTION, TIME_DEPENDENCE};

use crate::error::OutputError;
use crate::noise::BudgetReport;
use crate::tf::TransferMatrix;
use std::path::Path;

/// Provenance of a run, stored alongside the results in self-describing formats (HDF5).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunMeta {
    /// Version of the tool that wrote the file: [`TOOL_VERSION`].
    pub tool_version: String,
    /// The full effective parameter set as TOML text ([`crate::params::Params::to_toml`]).
    pub params_toml: String,
    /// The command line that produced the file.
    pub command_line: String,
    /// Normal modes to record: `(index, frequency in Hz)`. The index is stored unchanged; by
    /// convention it is the mode's `index` from the `modes` module (1-based, in order of
    /// increasing frequency: the paper's nu_1 ... nu_8). Empty: no `/modes` group is written.
    pub modes: Vec<(usize, f64)>,
}

impl RunMeta {
    /// The provenance of the running process: this tool's version, `params` as TOML, the
    /// command line, and the frequencies of `modes` when given.
    pub fn of_this_run(
        params: &crate::params::Params,
        modes: Option<&crate::modes::NormalModes>,
    ) -> RunMeta {
        RunMeta {
            tool_version: TOOL_VERSION.to_string(),
            params_toml: params.to_toml(),
            command_line: std::env::args().collect::<Vec<_>>().join(" "),
            modes: modes
                .map(|m| m.modes.iter().map(|m| (m.index, m.frequency_hz)).collect())
                .unwrap_or_default(),
        }
    }
}

/// Provenance of the tilt input of a budget run, stored in the budget's HDF5 file and shown in
/// its figure. Plain strings, so that this module does not depend on [`crate::input`]; the
/// caller fills it from the reader's `crate::input::Provenance`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InputMeta {
    /// The input file, as given.
    pub path: String,
    /// File format: `hdf5` or `csv`.
    pub format: String,
    /// `series` (time series) or `spectra`.
    pub kind: String,
    /// Quantity of the file's channels before conversion to angle: `angle` or `rate`.
    pub quantity: String,
    /// The effective axis map, e.g. `theta_t=-LJE,eta_t=-LJN`.
    pub axis_map: String,
    /// Start time of the record (ISO 8601), if the file gives one.
    pub start_time: Option<String>,
    /// The reader's notes: where the map and quantity came from, assumptions, gaps.
    pub notes: Vec<String>,
}

/// This crate's version, `env!("CARGO_PKG_VERSION")`, for [`RunMeta::tool_version`].
pub const TOOL_VERSION: &str = env!("CARGO_PKG_VERSION");

/// Extensions accepted by [`OutputKind::from_path`], as shown in error messages.
pub const ALLOWED_EXTENSIONS: &str = ".h5, .hdf5, .csv, .png, .svg";

/// Output format, chosen by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OutputKind {
    /// HDF5 (`.h5`, `.hdf5`): the self-describing archive format.
    Hdf5,
    /// Comma-separated text (`.csv`).
    Csv,
    /// PNG bitmap figure (`.png`).
    Png,
    /// SVG vector figure (`.svg`).
    Svg,
}

impl OutputKind {
    /// The format named by the extension of `path`, compared case-insensitively.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] naming `path` and [`ALLOWED_EXTENSIONS`] when the
    /// extension is missing or not supported.
    pub fn from_path(path: &Path) -> Result<OutputKind, OutputError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("h5" | "hdf5") => Ok(OutputKind::Hdf5),
            Some("csv") => Ok(OutputKind::Csv),
            Some("png") => Ok(OutputKind::Png),
            Some("svg") => Ok(OutputKind::Svg),
            _ => Err(OutputError::UnknownFormat {
                path: path.to_path_buf(),
                allowed: ALLOWED_EXTENSIONS,
            }),
        }
    }
}

/// Saves a transfer matrix in the format named by the extension of `path`: HDF5
/// ([`write_tf_hdf5`], with `meta`), CSV ([`write_tf_csv`]; `meta` is not stored), or a
/// PNG/SVG figure ([`crate::plot::tf_figure()`]).
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for an unsupported extension (nothing is written), or the
/// writer's [`OutputError::Write`].
pub fn save_tf(path: &Path, tf: &TransferMatrix, meta: &RunMeta) -> Result<(), OutputError> {
    match OutputKind::from_path(path)? {
        OutputKind::Hdf5 => write_tf_hdf5(path, tf, meta),
        OutputKind::Csv => write_tf_csv(path, tf),
        OutputKind::Png | OutputKind::Svg => crate::plot::tf_figure(tf, path),
    }
}

/// Saves a noise budget in the format named by the extension of `path`: HDF5
/// ([`write_budget_hdf5`], with `meta` and `input`), CSV ([`write_budget_csv`]; ASDs only,
/// `meta` and `input` are not stored), or a PNG/SVG figure
/// ([`crate::plot::budget_figure_with`], with the input named in the caption).
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for an unsupported extension (nothing is written), or the
/// writer's [`OutputError::Write`].
pub fn save_budget(
    path: &Path,
    report: &BudgetReport,
    meta: &RunMeta,
    input: &InputMeta,
) -> Result<(), OutputError> {
    match OutputKind::from_path(path)? {
        OutputKind::Hdf5 => write_budget_hdf5(path, report, meta, input),
        OutputKind::Csv => write_budget_csv(path, report),
        OutputKind::Png | OutputKind::Svg => {
            let options = crate::plot::BudgetFigureOptions {
                input: Some(input.clone()),
                ..crate::plot::BudgetFigureOptions::default()
            };
            crate::plot::budget_figure_with(report, path, &options)
        }
    }
}
