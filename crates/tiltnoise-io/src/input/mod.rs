//! Readers for floor-tilt inputs and measured observables: tilt **time series** and tilt
//! **spectra**, from HDF5 or CSV, with strict validation. The data they return, its
//! conventions (tilt sign, axis map, quantity, gaps) and its errors are
//! [`tiltnoise_core::input`]'s; the exact file layouts are documented in
//! `docs/input_formats.md`.
//!
//! # Entry points
//!
//! * [`open_tilt`]: opens a tilt input once, leaving an HDF5 series in the file to stream.
//! * [`read_tilt`]: decides by extension (`.h5`/`.hdf5`, `.csv`, `.mseed`/`.miniseed`/`.ms`)
//!   and content whether the file holds a series or spectra, and returns a [`TiltInput`]
//!   (miniSEED always holds a series).
//! * [`read_tilt_series`] / [`read_tilt_spectra`]: the same, insisting on one kind.
//! * [`TiltSeriesSource`]: streaming access to an HDF5 series in chunks (bounded memory), with
//!   results bit-identical to [`read_tilt_series`]; it is a
//!   [`tiltnoise_core::input::SeriesSource`] for the budget job.
//! * [`read_measured`], [`read_measured_input`]: measured ASDs or series of the observables.
//! * [`read_start_time`]: the start time a series file of either kind states;
//!   [`parse_start_time`] the instant it names, [`utc_text`] the text of an instant.
//! * [`read_asd_column`]: the ASD of one quantity (a coloured readout, a user-named term).

mod address;
mod asd_file;
mod csv;
mod format_error;
mod h5;
mod measured;
mod meta;
mod mseed;
mod series_csv;
mod series_units;
mod source;
mod spectra_checks;
mod spectra_csv;
mod spectra_gwpy;
mod spectra_hdf5;
mod start_time;

pub use address::{input_format, split_hdf5_address};
pub use asd_file::{read_asd_column, AsdColumn, GENERIC_ASD_COLUMN};
pub use format_error::FormatError;
pub use measured::{
    add_measured_file, read_measured, read_measured_input, MeasuredInput, MeasuredSeries,
    MeasuredSpectra, SCHEMA_OBSERVABLE_SERIES,
};
pub use source::TiltSeriesSource;
pub use start_time::{parse_start_time, utc_text};
pub use tiltnoise_core::input::*;

use std::path::Path;
use tiltnoise_core::error::Shown;

/// A tilt input opened once, by what it holds: an HDF5 time series to stream from the file in
/// bounded memory, a time series of another format read whole, or spectra.
pub enum OpenedTilt {
    /// An HDF5 time series, not yet read: stream it ([`TiltSeriesSource`]).
    Streamed(TiltSeriesSource),
    /// A CSV or miniSEED time series, read whole.
    Series(TiltSeries),
    /// Tilt spectra.
    Spectra(TiltSpectra),
}

/// Opens a tilt input of either kind once: the format from the extension (`.h5`/`.hdf5`,
/// `.csv`, `.mseed`/`.miniseed`/`.ms`), the kind from the content (HDF5: `schema` attribute if
/// present, else root attribute `sample_rate_hz` -> series, dataset `/frequency_hz` ->
/// spectra; CSV: first header column `time_s` -> series, `freq_hz` -> spectra). An HDF5 series
/// is left in the file to be streamed; anything else is read.
///
/// # Errors
///
/// [`InputError::Extension`], [`InputError::UnknownLayout`] (naming the accepted layouts), or
/// any validation error of the specific reader.
pub fn open_tilt(path: &Path, opts: &ReadOptions) -> Result<OpenedTilt, InputError> {
    match input_format(path)? {
        InputFormat::Csv => {
            let (file, prelude) = csv::CsvFile::open(path)?;
            match csv_kind(path, &prelude)? {
                InputKind::Series => series_csv::read(file, prelude, opts).map(OpenedTilt::Series),
                InputKind::Spectra => {
                    spectra_csv::read(file, prelude, opts).map(OpenedTilt::Spectra)
                }
            }
        }
        InputFormat::Hdf5 => {
            let (file_path, object) = split_hdf5_address(path);
            let file = h5::open(&file_path)?;
            if let Some(s) = gwpy_spectra(&file_path, &file, object.as_deref(), opts)? {
                return Ok(OpenedTilt::Spectra(s));
            }
            if object.is_some() {
                return TiltSeriesSource::from_file(&file_path, file, opts, object.as_deref())
                    .map(OpenedTilt::Streamed);
            }
            match h5::detect_kind(path, &file, None)? {
                InputKind::Series => {
                    TiltSeriesSource::from_file(path, file, opts, None).map(OpenedTilt::Streamed)
                }
                InputKind::Spectra => {
                    spectra_hdf5::read(path, &file, opts).map(OpenedTilt::Spectra)
                }
            }
        }
        InputFormat::Miniseed => mseed::read(path, opts).map(OpenedTilt::Series),
    }
}

/// Reads a tilt input of either kind whole: [`open_tilt`], then an HDF5 series is read into
/// memory.
///
/// # Errors
///
/// As [`open_tilt`], and the errors of reading an HDF5 series.
pub fn read_tilt(path: &Path, opts: &ReadOptions) -> Result<TiltInput, InputError> {
    Ok(match open_tilt(path, opts)? {
        OpenedTilt::Streamed(mut src) => TiltInput::Series(src.read_all()?),
        OpenedTilt::Series(s) => TiltInput::Series(s),
        OpenedTilt::Spectra(s) => TiltInput::Spectra(s),
    })
}

/// Reads a tilt time series (angle, rad), all in memory. For long HDF5 series use
/// [`TiltSeriesSource`]; the values are bit-identical.
///
/// # Errors
///
/// [`InputError::WrongKind`] if the file holds spectra; otherwise as [`read_tilt`].
pub fn read_tilt_series(path: &Path, opts: &ReadOptions) -> Result<TiltSeries, InputError> {
    match input_format(path)? {
        InputFormat::Hdf5 => {
            let mut src = TiltSeriesSource::open(path, opts)?;
            src.read_all()
        }
        InputFormat::Miniseed => mseed::read(path, opts),
        InputFormat::Csv => match read_tilt(path, opts)? {
            TiltInput::Series(s) => Ok(s),
            TiltInput::Spectra(_) => Err(wrong_kind(path, InputKind::Series, InputKind::Spectra)),
        },
    }
}

/// Reads tilt spectra (one-sided CSD, rad²/Hz).
///
/// # Errors
///
/// [`InputError::WrongKind`] if the file holds a time series; otherwise as [`read_tilt`].
pub fn read_tilt_spectra(path: &Path, opts: &ReadOptions) -> Result<TiltSpectra, InputError> {
    match input_format(path)? {
        InputFormat::Hdf5 => {
            let (file_path, object) = split_hdf5_address(path);
            let file = h5::open(&file_path)?;
            if let Some(s) = gwpy_spectra(&file_path, &file, object.as_deref(), opts)? {
                return Ok(s);
            }
            if object.is_some() {
                return Err(wrong_kind(path, InputKind::Spectra, InputKind::Series));
            }
            match h5::detect_kind(path, &file, Some(InputKind::Spectra))? {
                InputKind::Spectra => spectra_hdf5::read(path, &file, opts),
                InputKind::Series => Err(wrong_kind(path, InputKind::Spectra, InputKind::Series)),
            }
        }
        InputFormat::Csv => {
            let (file, prelude) = csv::CsvFile::open(path)?;
            match csv_kind(path, &prelude)? {
                InputKind::Spectra => spectra_csv::read(file, prelude, opts),
                InputKind::Series => Err(wrong_kind(path, InputKind::Spectra, InputKind::Series)),
            }
        }
        InputFormat::Miniseed => Err(wrong_kind(path, InputKind::Spectra, InputKind::Series)),
    }
}

/// The ISO 8601 time of sample 0 that the file states, if any.
///
/// # Errors
///
/// The reader's errors: an extension other than `.h5`, `.hdf5`, `.csv`, a file that cannot be
/// opened, a `start_time` that is not a string or not ISO 8601.
pub fn read_start_time(path: &Path) -> Result<Option<String>, InputError> {
    match input_format(path)? {
        InputFormat::Hdf5 => {
            let file = h5::open(path)?;
            h5::start_and_description(path, &file, &mut Vec::new())
        }
        InputFormat::Csv => {
            let (_, prelude) = csv::CsvFile::open(path)?;
            csv::start_time(path, &prelude, &mut Vec::new())
        }
        InputFormat::Miniseed => Err(InputError::UnknownLayout {
            path: path.to_path_buf(),
            format: "miniseed",
            found: "a miniSEED file, whose channels are named by SEED code, not by observable"
                .to_string(),
            accepted: "a record of the observables as HDF5 or CSV (X, Y, Z, theta, eta, phi, \
                       phi_a)",
        }),
    }
}

fn wrong_kind(path: &Path, expected: InputKind, found: InputKind) -> InputError {
    InputError::WrongKind {
        path: path.to_path_buf(),
        expected: expected.name(),
        found: found.name(),
    }
}

fn csv_kind(path: &Path, prelude: &csv::Prelude) -> Result<InputKind, InputError> {
    match prelude.header.first().map(String::as_str) {
        Some("time_s") => Ok(InputKind::Series),
        Some("frequency_hz" | "freq_hz") => Ok(InputKind::Spectra),
        other => Err(InputError::UnknownLayout {
            path: path.to_path_buf(),
            format: "csv",
            found: format!(
                "the header (line {}) starts with column `{}`, not time_s or frequency_hz (or freq_hz)",
                prelude.header_line,
                Shown(other.unwrap_or(""))
            ),
            accepted: ACCEPTED_LAYOUTS,
        }),
    }
}

/// gwpy FrequencySeries: the datasets `object` names (or the root's, when the root has neither
/// the `sample_rate_hz` attribute nor a `/frequency_hz` dataset) whose `xunit` is `Hz`, when
/// none is a TimeSeries (`xunit` `s`). `None` when they are not spectra of that layout.
fn gwpy_spectra(
    path: &Path,
    file: &hdf5::File,
    object: Option<&str>,
    opts: &ReadOptions,
) -> Result<Option<TiltSpectra>, InputError> {
    if object.is_none() {
        let native = h5::attr(path, file, "/", "sample_rate_hz")?.is_some()
            || h5::attr(path, file, "/", "schema")?.is_some()
            || h5::root_datasets(path, file)?
                .iter()
                .any(|n| n == "frequency_hz");
        if native {
            return Ok(None);
        }
    }
    let loc = h5::locate(path, file, object)?;
    let names = match &loc.only {
        Some(n) => vec![n.clone()],
        None => h5::root_datasets(path, &loc.group)?,
    };
    let units: Vec<Option<String>> = names
        .iter()
        .map(|n| h5::xunit(path, &loc.group, n))
        .collect();
    let freq: Vec<String> = names
        .iter()
        .zip(&units)
        .filter(|(_, u)| u.as_deref() == Some("Hz"))
        .map(|(n, _)| n.clone())
        .collect();
    if freq.is_empty() || units.iter().any(|u| u.as_deref() == Some("s")) {
        return Ok(None);
    }
    spectra_gwpy::read(path, file, &loc.group, &loc.prefix, &freq, opts).map(Some)
}
