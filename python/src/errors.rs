//! The library's typed errors as Python exceptions, with the command line's messages.
//!
//! * A file that cannot be opened or read: `FileNotFoundError`, `PermissionError`,
//!   `IsADirectoryError` or `OSError`, by what the operating system said, whichever call and
//!   keyword named it (the libraries' errors keep the reason whole for this).
//! * A file that was read but is not valid (layout, attributes, values, a parameter file's
//!   TOML, a text file that is not UTF-8): [`InputFileError`], a subclass of `OSError`.
//! * A request whose memory the machine does not have (`tiltnoise_core::limits`: more than
//!   half of what is available, under the process's address-space limit too): `MemoryError`.
//! * Everything else the caller can fix (a parameter out of range, an unknown name, an option
//!   that does not fit the data, a count over its documented limit, a file extension that
//!   names no format, a frequency on an undamped resonance): `ValueError`.

use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyMemoryError, PyOSError, PyPermissionError,
    PyValueError,
};
use pyo3::PyErr;
use std::io::ErrorKind;
use tiltnoise_core::budget::BudgetError;
use tiltnoise_core::error::{FreqError, OutputError, ParamError, TfError};
use tiltnoise_core::input::InputError;
use tiltnoise_core::limits::LimitError;
use tiltnoise_core::mc::McError;
use tiltnoise_core::option_key::{OptionKey, OptionStyle};
use tiltnoise_core::options::OptionError;
use tiltnoise_core::spectral::SpectralError;

pyo3::create_exception!(
    tiltnoise,
    InputFileError,
    PyOSError,
    "A file that was read but is not valid: its layout, an attribute or a value is not what \
     tiltnoise accepts (the message names the file, the object and what is allowed)."
);

/// Python's spelling of the options the libraries name in their messages: the keyword
/// argument (`nperseg`, `nperseg=8`), a mapping entry as a dict (`units={"eta_t": "urad"}`), a
/// pair as a tuple; a parameter override is `Params.set`.
pub struct Keywords;

impl OptionStyle for Keywords {
    fn option(&self, key: OptionKey) -> String {
        match key {
            OptionKey::SET => "Params.set".to_string(),
            OptionKey::DRAWN_OBSERVABLES => "observables".to_string(),
            // The planner's reasoning is a method of its own in Python.
            OptionKey::EXPLAIN => "Model.explain()".to_string(),
            _ => key.key().to_string(),
        }
    }

    fn given(&self, key: OptionKey, value: &str) -> String {
        match key {
            OptionKey::SET => format!("{} {value}", self.option(key)),
            _ => format!("{}={value}", self.option(key)),
        }
    }

    fn entry(&self, key: OptionKey, name: &str, value: &str) -> String {
        format!("{}={{\"{name}\": \"{value}\"}}", self.option(key))
    }

    fn pair(&self, first: &str, second: &str) -> String {
        format!("({first}, {second})")
    }
}

/// The `OSError` subclass for an operating-system failure to open or read a file.
pub fn os_error(kind: ErrorKind, message: String) -> PyErr {
    match kind {
        ErrorKind::NotFound => PyFileNotFoundError::new_err(message),
        ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
        ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// The exception for a file that could not be read, `reason` what reading it said: the
/// `OSError` subclass of an operating-system failure ([`os_error`]), [`InputFileError`] for a
/// text file that is not UTF-8 (read, but not valid).
pub fn read_error(reason: &std::io::Error, message: String) -> PyErr {
    match reason.kind() {
        ErrorKind::InvalidData => InputFileError::new_err(message),
        kind => os_error(kind, message),
    }
}

/// Conversion of a library error into the Python exception of its kind (see the module docs).
pub trait IntoPyErr {
    /// The exception, carrying the error's message.
    fn into_py_err(self) -> PyErr;
}

impl IntoPyErr for LimitError {
    fn into_py_err(self) -> PyErr {
        match self {
            LimitError::Memory { .. } => PyMemoryError::new_err(shown(&self)),
            _ => PyValueError::new_err(shown(&self)),
        }
    }
}

impl IntoPyErr for ParamError {
    fn into_py_err(self) -> PyErr {
        let message = shown(&self);
        match self {
            ParamError::Read { reason, .. } => read_error(&reason, message),
            ParamError::TooLarge(e) => e.into_py_err(),
            _ => PyValueError::new_err(message),
        }
    }
}

impl IntoPyErr for InputError {
    fn into_py_err(self) -> PyErr {
        let message = shown(&self);
        match self {
            InputError::Io { reason, .. } => read_error(&reason, message),
            // A path whose extension names no supported format: the argument is wrong, not
            // the file (which is not opened).
            InputError::Extension { .. } => PyValueError::new_err(message),
            InputError::TooLarge(e) => e.into_py_err(),
            _ => InputFileError::new_err(message),
        }
    }
}

/// `ValueError` for an error that is not about memory, the error of its [`LimitError`] for one
/// over a limit.
macro_rules! value_or_limit {
    ($($ty:ident),*) => {$(
        impl IntoPyErr for $ty {
            fn into_py_err(self) -> PyErr {
                match self {
                    $ty::TooLarge(e) => e.into_py_err(),
                    other => PyValueError::new_err(shown(&other)),
                }
            }
        }
    )*};
}

value_or_limit!(SpectralError, TfError, FreqError, OptionError, McError);

impl IntoPyErr for BudgetError {
    fn into_py_err(self) -> PyErr {
        match self {
            BudgetError::Input(e) => e.into_py_err(),
            BudgetError::TooLarge(e) => e.into_py_err(),
            other => PyValueError::new_err(shown(&other)),
        }
    }
}

impl IntoPyErr for OutputError {
    fn into_py_err(self) -> PyErr {
        let message = shown(&self);
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

/// `message` (an error of the libraries) as Python shows it: every option it names spelled as
/// the keyword argument ([`Keywords`]).
pub fn shown(message: &dyn std::fmt::Display) -> String {
    tiltnoise_core::option_key::render(&Keywords, message)
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
