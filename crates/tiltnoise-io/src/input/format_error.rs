//! [`FormatError`]: what is wrong with an input file in terms of its format (the HDF5
//! library's failure, a CSV line or field, a miniSEED record).
//!
//! These concepts belong to the readers, so the error lives here; it travels inside
//! [`InputError::Format`], so that every reader returns the one [`InputError`] and every front
//! end renders it as one line. [`FormatError::of`] finds it again. CSV line numbers are 1-based
//! (as shown by an editor), sample indices 0-based.

use std::path::PathBuf;
use tiltnoise_core::error::Shown;
use tiltnoise_core::input::InputError;

/// Formats an optional miniSEED record as `, record N (byte offset M)`.
fn at_record(record: &Option<(usize, u64)>) -> String {
    match record {
        Some((index, offset)) => format!(", record {index} (byte offset {offset})"),
        None => String::new(),
    }
}

/// An input file that is not valid in its format's own terms.
#[derive(Debug, thiserror::Error)]
pub enum FormatError {
    /// The HDF5 library failed (not an HDF5 file, corrupt file, unreadable object).
    #[error("input file {path}: HDF5 error reading {}: {message}", Shown(.object))]
    Hdf5 {
        /// The file.
        path: PathBuf,
        /// The object being read, e.g. `file`, `dataset /E`, `attribute sample_rate_hz of /`.
        object: String,
        /// The library's message.
        message: String,
    },

    /// A string stored in the file (an attribute's text) is not valid UTF-8.
    #[error("input file {path}: {} is not valid text: {detail}", Shown(.object))]
    InvalidText {
        /// The file.
        path: PathBuf,
        /// The object, e.g. `attribute `units` of dataset /E`.
        object: String,
        /// The first invalid byte and its offset.
        detail: String,
    },

    /// A structural CSV problem: missing header, wrong number of fields, duplicate column,
    /// unexpected column, malformed metadata line.
    #[error("input file {path}, line {line}: {message}")]
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong and what is allowed.
        message: String,
    },

    /// A CSV field that is not a number.
    #[error(
        "input file {path}, line {line}: column `{}` = `{}` is not a number ({unit}); \
         allowed: a decimal floating-point number{}",
        Shown(.column),
        Shown(.text),
        if *.empty_allowed { " (an empty field is a gap)" } else { "" }
    )]
    CsvNumber {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Column name.
        column: String,
        /// The text found.
        text: String,
        /// Unit of the column.
        unit: &'static str,
        /// Whether an empty field would have been accepted.
        empty_allowed: bool,
    },

    /// The time column is not strictly increasing.
    #[error(
        "input file {path}, line {line} (sample index {index}): time_s = {value:?} s is not \
         greater than the previous {previous:?} s; allowed: strictly increasing, uniformly \
         sampled times"
    )]
    TimeNotIncreasing {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// 0-based sample index.
        index: usize,
        /// The time found (s).
        value: f64,
        /// The time of the previous row (s).
        previous: f64,
    },

    /// The time column is not uniformly sampled.
    #[error(
        "input file {path}, line {line} (sample index {index}): time_s = {value:?} s deviates \
         from the uniform grid t0 + index * dt = {expected:?} s by {deviation:.3e} s; allowed: \
         at most {tolerance:.3e} s (relative {relative:.1e} of dt = {dt:?} s, from the printed \
         precision of the times)"
    )]
    TimeNotUniform {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// 0-based sample index.
        index: usize,
        /// The time found (s).
        value: f64,
        /// The uniform-grid time (s).
        expected: f64,
        /// `|value - expected|` (s).
        deviation: f64,
        /// The tolerance (s).
        tolerance: f64,
        /// `tolerance / dt`.
        relative: f64,
        /// The mean sampling interval `(t_last - t_0) / (n - 1)` (s).
        dt: f64,
    },

    /// A miniSEED record that cannot be decoded, or records that do not form one uniformly
    /// sampled series per channel.
    #[error("input file {path}{}: {message}", at_record(.record))]
    Miniseed {
        /// The file.
        path: PathBuf,
        /// The record (0-based index in the file) and its byte offset, when one is at fault.
        record: Option<(usize, u64)>,
        /// What is wrong and what is allowed.
        message: String,
    },

    /// A required HDF5 attribute is absent.
    #[error("input file {path}: required attribute `{attribute}` of {object} is missing; expected {expected}")]
    MissingAttribute {
        /// The file.
        path: PathBuf,
        /// The object that should carry it, e.g. `/` (root) or `dataset /E`.
        object: String,
        /// The attribute name.
        attribute: &'static str,
        /// What it should hold, with unit.
        expected: &'static str,
    },

    /// A required HDF5 dataset is absent.
    #[error("input file {path}: required dataset `{dataset}` is missing; expected {expected}")]
    MissingDataset {
        /// The file.
        path: PathBuf,
        /// The dataset path, e.g. `/frequency_hz`.
        dataset: String,
        /// What it should hold.
        expected: String,
    },

    /// An HDF5 dataset of the wrong type or shape.
    #[error(
        "input file {path}: dataset `{}` has {}; allowed: {allowed}",
        Shown(.dataset),
        Shown(.found)
    )]
    BadDataset {
        /// The file.
        path: PathBuf,
        /// The dataset path.
        dataset: String,
        /// Its type or shape.
        found: String,
        /// What is allowed.
        allowed: String,
    },

    /// A cross-spectral density matrix that is not Hermitian positive semidefinite within
    /// tolerance, or has non-finite entries.
    #[error("input file {path}: /csd[{index}, {i}, {j}] at {freq_hz:?} Hz ({pair}): {problem}")]
    Csd {
        /// The file.
        path: PathBuf,
        /// Frequency index.
        index: usize,
        /// Frequency (Hz).
        freq_hz: f64,
        /// Row.
        i: usize,
        /// Column.
        j: usize,
        /// The axis names of the row and column, e.g. `theta_t, eta_t`.
        pair: String,
        /// What is wrong, with the values and their unit, and what is allowed, with the
        /// tolerance.
        problem: String,
    },
}

impl FormatError {
    /// The format error `e` carries, if it is one.
    pub fn of(e: &InputError) -> Option<&FormatError> {
        match e {
            InputError::Format(inner) => inner.downcast_ref(),
            _ => None,
        }
    }
}

impl From<FormatError> for InputError {
    fn from(e: FormatError) -> InputError {
        InputError::Format(Box::new(e))
    }
}
