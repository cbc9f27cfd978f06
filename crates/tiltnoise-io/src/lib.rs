//! tiltnoise-io: every file `tiltnoise` reads or writes.
//!
//! * [`input`]: floor-tilt inputs and measured observables (HDF5, CSV), validated strictly;
//!   layouts in `docs/input_formats.md`.
//! * [`read_measured_modes`] (measured mode frequencies for the fit) and [`read_freq_file`]
//!   (frequency grids).
//! * Writers: transfer functions, noise budgets, coherence, Monte Carlo, fit and simulation
//!   results as HDF5 or CSV (schemas in `docs/schemas.md`); the cleaned record of `subtract` in
//!   the observable-series layout (`docs/subtract.md`).
//! * [`check_outputs`]: the output paths of a run, checked before it computes anything.
//! * [`Staging`]: every writer is atomic and takes the run's `Staging`: each output is written
//!   in a private staging directory beside its target and renamed onto it when the run commits,
//!   so a failed or interrupted run leaves nothing at the target paths, nor a temporary file,
//!   and never clobbers an existing file. Figures (`tiltnoise-plot`) are written through
//!   [`Staging::write`] by the caller. [`remove_staging_for_exit`] is the interrupt handler's.
//!
//! Depends on `tiltnoise-core` for the data it stores; the numerical core never depends on this
//! crate, and the figures never do either.

mod asd_csv;
mod atomic;
mod budget_csv;
mod budget_hdf5;
mod coherence_csv;
mod coherence_hdf5;
pub mod csv_layout;
mod fit_hdf5;
mod freq_file;
mod h5util;
pub mod input;
mod mc_hdf5;
mod measured_modes;
mod messages;
mod output_paths;
mod params_file;
mod run_meta;
mod series_hdf5;
mod series_hdf5_stream;
mod staging_dir;
mod subtract_hdf5;
mod text_file;
mod tf_csv;
mod tf_hdf5;
mod tf_notes;
mod tf_stream;

pub use asd_csv::{write_asd_csv, SCHEMA_OBSERVABLE_ASD_CSV, SCHEMA_VERSION_OBSERVABLE_ASD_CSV};
pub use atomic::{AtomicFile, Staging};
pub use budget_csv::{
    budget_csv_string, write_budget_csv, SCHEMA_BUDGET_CSV, SCHEMA_VERSION_BUDGET_CSV,
};
pub use budget_hdf5::{
    write_budget_hdf5, SCHEMA_BUDGET, SCHEMA_VERSION_BUDGET, SPECTRAL_CONVENTION,
};
pub use coherence_csv::{
    coherence_csv_string, write_coherence_csv, SCHEMA_COHERENCE_CSV, SCHEMA_VERSION_COHERENCE_CSV,
};
pub use coherence_hdf5::{
    write_coherence_hdf5, CoherenceInputs, SCHEMA_COHERENCE, SCHEMA_VERSION_COHERENCE,
};
pub use fit_hdf5::{write_fit_hdf5, SCHEMA_FIT, SCHEMA_VERSION_FIT};
pub use freq_file::read_freq_file;
pub use mc_hdf5::{write_mc_hdf5, REJECTED_DRAWS, SCHEMA_MC, SCHEMA_VERSION_MC};
pub use measured_modes::{read_measured_modes, read_visibilities};
pub use output_paths::check_outputs;
pub use params_file::read_params;
pub use run_meta::{RunMeta, TOOL_VERSION};
pub use series_hdf5::{
    write_observable_series_hdf5, SeriesAsd, SimulationMeta, SCHEMA_OBSERVABLE_SERIES,
    SCHEMA_VERSION_OBSERVABLE_SERIES,
};
pub use series_hdf5_stream::{ObservableSeriesWriter, COORDINATES_GROUP, SERIES_CHUNK_SAMPLES};
pub use staging_dir::{remove_staging_for_exit, ExitCleanup};
pub use subtract_hdf5::{write_subtract_hdf5, SubtractMeta};
pub use tf_csv::{
    format_f64, push_tf_csv_rows, tf_csv_header, tf_csv_string, write_tf_csv, SCHEMA_TF_CSV,
    SCHEMA_VERSION_TF_CSV,
};
pub use tf_hdf5::{write_tf_hdf5, SCHEMA_TF, SCHEMA_VERSION_TF, SIGN_CONVENTION, TIME_DEPENDENCE};
pub use tf_stream::{TfCsvWriter, TfHdf5Writer, TF_CHUNK_FREQS};

use std::path::Path;
pub use tiltnoise_core::error::OutputError;
pub use tiltnoise_core::input::InputMeta;

/// Version of the HDF5 library linked into this build (`major.minor.release`): the one
/// bundled with `hdf5-metno`, built from source and linked statically.
pub fn hdf5_version() -> String {
    let (major, minor, release) = hdf5::library_version();
    format!("{major}.{minor}.{release}")
}

/// Output format, chosen by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum OutputKind {
    /// HDF5 (`.h5`, `.hdf5`): the self-describing archive format.
    Hdf5,
    /// Comma-separated text (`.csv`).
    Csv,
    /// A command's report as JSON (`.json`).
    Json,
    /// PNG bitmap figure (`.png`).
    Png,
    /// SVG vector figure (`.svg`).
    Svg,
}

impl OutputKind {
    /// Every kind, in the order messages list them.
    pub const ALL: [OutputKind; 5] = [
        OutputKind::Hdf5,
        OutputKind::Csv,
        OutputKind::Json,
        OutputKind::Png,
        OutputKind::Svg,
    ];

    /// The extensions of this kind, without the dot, lower case.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            OutputKind::Hdf5 => &["h5", "hdf5"],
            OutputKind::Csv => &["csv"],
            OutputKind::Json => &["json"],
            OutputKind::Png => &["png"],
            OutputKind::Svg => &["svg"],
        }
    }

    /// The kind among `allowed` that the extension of `path` names, compared
    /// case-insensitively: the one output-kind rule of every command and writer.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] naming `path` and the extensions of `allowed` when the
    /// extension is missing or names no kind of `allowed`.
    pub fn of_path(path: &Path, allowed: &[OutputKind]) -> Result<OutputKind, OutputError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        allowed
            .iter()
            .copied()
            .find(|k| ext.as_deref().is_some_and(|e| k.extensions().contains(&e)))
            .ok_or_else(|| OutputError::UnknownFormat {
                path: path.to_path_buf(),
                allowed: extensions_of(allowed),
            })
    }

    /// [`OutputKind::of_path`] among every kind.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] as [`OutputKind::of_path`].
    pub fn from_path(path: &Path) -> Result<OutputKind, OutputError> {
        Self::of_path(path, &Self::ALL)
    }
}

/// The extensions of `kinds` as messages show them: `.h5, .hdf5, .png, .svg`.
pub fn extensions_of(kinds: &[OutputKind]) -> String {
    kinds
        .iter()
        .flat_map(|k| k.extensions())
        .map(|e| format!(".{e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod output_kind_tests {
    use super::*;

    #[test]
    fn a_path_names_one_of_the_kinds_allowed_in_any_case() {
        let figure = [OutputKind::Png, OutputKind::Svg];
        assert_eq!(
            OutputKind::of_path(Path::new("a.Svg"), &figure).unwrap(),
            OutputKind::Svg
        );
        assert_eq!(
            OutputKind::from_path(Path::new("r.JSON")).unwrap(),
            OutputKind::Json
        );
        assert_eq!(
            OutputKind::from_path(Path::new("b.hdf5")).unwrap(),
            OutputKind::Hdf5
        );
        for name in ["a.h5", "a.pdf", "a", "a.png.tmp"] {
            match OutputKind::of_path(Path::new(name), &figure).unwrap_err() {
                OutputError::UnknownFormat { path, allowed } => {
                    assert_eq!(path, Path::new(name));
                    assert_eq!(allowed, ".png, .svg");
                }
                other => panic!("{name}: {other}"),
            }
        }
        assert_eq!(
            extensions_of(&OutputKind::ALL),
            ".h5, .hdf5, .csv, .json, .png, .svg"
        );
    }
}
