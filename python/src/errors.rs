//! The library's typed errors as Python exceptions, with the command line's messages.
//!
//! * A file that cannot be opened or read: `FileNotFoundError`, `PermissionError`,
//!   `IsADirectoryError` or `OSError`, by what the operating system said.
//! * A file that was read but is not valid (layout, attributes, values, a parameter file's
//!   TOML): [`InputFileError`], a subclass of `OSError`.
//! * Everything else the caller can fix (a parameter out of range, an unknown name, an option
//!   that does not fit the data, a file extension that names no format, a frequency on an
//!   undamped resonance): `ValueError`.

use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyOSError, PyPermissionError, PyValueError,
};
use pyo3::PyErr;
use std::io::ErrorKind;
use tiltnoise_core::budget::BudgetError;
use tiltnoise_core::error::{FreqError, OutputError, ParamError, TfError};
use tiltnoise_core::input::InputError;
use tiltnoise_core::mc::McError;
use tiltnoise_core::options::OptionError;
use tiltnoise_core::spectral::SpectralError;

pyo3::create_exception!(
    tiltnoise,
    InputFileError,
    PyOSError,
    "A file that was read but is not valid: its layout, an attribute or a value is not what \
     tiltnoise accepts (the message names the file, the object and what is allowed)."
);

/// The `OSError` subclass for an operating-system failure to open or read a file.
fn os_error(kind: ErrorKind, message: String) -> PyErr {
    match kind {
        ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
        ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
        ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// Conversion of a library error into the Python exception of its kind (see the module docs).
pub trait IntoPyErr {
    /// The exception, carrying the error's message.
    fn into_py_err(self) -> PyErr;
}

impl IntoPyErr for ParamError {
    fn into_py_err(self) -> PyErr {
        let message = self.to_string();
        match self {
            ParamError::Read { reason, .. } => os_error(reason.kind(), message),
            _ => PyValueError::new_err(message),
        }
    }
}

impl IntoPyErr for InputError {
    fn into_py_err(self) -> PyErr {
        let message = self.to_string();
        match self {
            InputError::Io { reason, .. } => os_error(reason.kind(), message),
            // A path whose extension names no supported format: the argument is wrong, not
            // the file (which is not opened).
            InputError::Extension { .. } => PyValueError::new_err(message),
            _ => InputFileError::new_err(message),
        }
    }
}

impl IntoPyErr for SpectralError {
    fn into_py_err(self) -> PyErr {
        PyValueError::new_err(self.to_string())
    }
}

impl IntoPyErr for TfError {
    fn into_py_err(self) -> PyErr {
        PyValueError::new_err(self.to_string())
    }
}

impl IntoPyErr for FreqError {
    fn into_py_err(self) -> PyErr {
        PyValueError::new_err(self.to_string())
    }
}

impl IntoPyErr for OptionError {
    fn into_py_err(self) -> PyErr {
        PyValueError::new_err(self.to_string())
    }
}

impl IntoPyErr for McError {
    fn into_py_err(self) -> PyErr {
        PyValueError::new_err(self.to_string())
    }
}

impl IntoPyErr for BudgetError {
    fn into_py_err(self) -> PyErr {
        match self {
            BudgetError::Input(e) => e.into_py_err(),
            other => PyValueError::new_err(other.to_string()),
        }
    }
}

impl IntoPyErr for OutputError {
    fn into_py_err(self) -> PyErr {
        let message = self.to_string();
        match self {
            OutputError::UnknownFormat { .. } => PyValueError::new_err(message),
            _ => PyOSError::new_err(message),
        }
    }
}

/// `result.map_err(IntoPyErr::into_py_err)`, as a method.
pub trait PyResultExt<T> {
    /// The value, or the error as its Python exception.
    fn py(self) -> pyo3::PyResult<T>;
}

impl<T, E: IntoPyErr> PyResultExt<T> for Result<T, E> {
    fn py(self) -> pyo3::PyResult<T> {
        self.map_err(IntoPyErr::into_py_err)
    }
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
