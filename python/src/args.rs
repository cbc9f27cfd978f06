//! Keyword arguments of list, path-list, number-list and pair types from Python, converted in
//! one place by one rule (every call of the module uses these):
//!
//! - a list of names (`corrected`, `fit`, `free`, `inputs`, ...) is a `str` or a sequence of
//!   `str`; a single `str` is a one-item list (as NumPy and pathlib users expect);
//! - a list of paths (`colocated`) is a `str`/`os.PathLike` or a sequence of them, one path
//!   a one-item list;
//! - a list of numbers (`at`) is a number (a Python, NumPy scalar or 0-d array: one item) or a
//!   sequence / 1-D array of numbers;
//! - a pair (`band`, `report_band`, `fit_band`, `percentiles`) is a sequence or array of
//!   exactly two numbers, NumPy scalars included.
//!
//! Any other type is refused with a `TypeError` naming the keyword, the value and the type
//! expected; a pair with another number of values with a `ValueError` saying what is expected.
//! The checks of the values themselves (known names, `lo < hi`, ranges) are the job's, with the
//! command line's messages.

use crate::errors::value_error;
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyBytes, PyDict, PyString};
use std::path::PathBuf;

/// The value as the message shows it: its `repr`, shortened past 60 characters.
fn shown(value: &Bound<'_, PyAny>) -> String {
    let repr = value
        .repr()
        .map(|r| r.to_string_lossy().into_owned())
        .unwrap_or_else(|_| "...".to_string());
    if repr.chars().count() > 60 {
        format!("{}...", repr.chars().take(57).collect::<String>())
    } else {
        repr
    }
}

/// The name of the value's type, for messages.
fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".to_string())
}

/// `TypeError`: `kw=VALUE: expected EXPECTED, got TYPE`.
pub fn type_error(kw: &str, value: &Bound<'_, PyAny>, expected: &str) -> PyErr {
    PyTypeError::new_err(format!(
        "{kw}={}: expected {expected}, got {}",
        shown(value),
        type_name(value)
    ))
}

/// The items of a sequence argument: anything iterable but a string, bytes or a mapping (whose
/// iteration would give characters, bytes or keys), and but a 0-d array; `None` for anything
/// else (the caller refuses it or takes it as a single item).
fn items<'py>(arg: &Bound<'py, PyAny>) -> PyResult<Option<Vec<Bound<'py, PyAny>>>> {
    if arg.is_instance_of::<PyString>()
        || arg.is_instance_of::<PyBytes>()
        || arg.is_instance_of::<PyByteArray>()
        || arg.is_instance_of::<PyDict>()
    {
        return Ok(None);
    }
    if let Ok(a) = arg.cast::<PyUntypedArray>() {
        if a.ndim() == 0 {
            return Ok(None);
        }
    }
    let Ok(iter) = arg.try_iter() else {
        return Ok(None);
    };
    iter.collect::<PyResult<Vec<_>>>().map(Some)
}

/// A list of `str`: a `str` (one item) or a sequence of `str`; `None` stays `None`.
pub fn strings(kw: &str, arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<String>>> {
    const EXPECTED: &str = "a str or a sequence of str";
    let Some(arg) = arg else {
        return Ok(None);
    };
    if let Ok(s) = arg.cast::<PyString>() {
        return Ok(Some(vec![s.to_cow()?.into_owned()]));
    }
    let Some(items) = items(arg)? else {
        return Err(type_error(kw, arg, EXPECTED));
    };
    items
        .iter()
        .map(|item| match item.cast::<PyString>() {
            Ok(s) => Ok(s.to_cow()?.into_owned()),
            Err(_) => Err(PyTypeError::new_err(format!(
                "{kw}={}: expected {EXPECTED}; an item is {} ({})",
                shown(arg),
                type_name(item),
                shown(item)
            ))),
        })
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// Names as `--input`, `--output`, `--observables` take them: [`strings`], and not none (an
/// empty sequence names nothing: `ValueError`). `None` stays `None` (the default).
pub fn names(kw: &str, arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<String>>> {
    let names = strings(kw, arg)?;
    if names.as_ref().is_some_and(Vec::is_empty) {
        return Err(value_error(format!(
            "{kw}: an empty sequence names nothing; give one or more names, or None for the \
             default"
        )));
    }
    Ok(names)
}

/// A path: a `str` or an `os.PathLike` (of `str`), else `None`.
fn path_of(value: &Bound<'_, PyAny>) -> Option<PathBuf> {
    let is_path = value.is_instance_of::<PyString>()
        || (!value.is_instance_of::<PyBytes>() && value.hasattr("__fspath__").unwrap_or(false));
    if !is_path {
        return None;
    }
    value.extract::<PathBuf>().ok()
}

/// A list of paths: a `str` or `os.PathLike` (one item) or a sequence of them; `None` stays
/// `None`.
pub fn paths(kw: &str, arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<PathBuf>>> {
    const EXPECTED: &str = "a path (str or os.PathLike) or a sequence of paths";
    let Some(arg) = arg else {
        return Ok(None);
    };
    if let Some(path) = path_of(arg) {
        return Ok(Some(vec![path]));
    }
    let Some(items) = items(arg)? else {
        return Err(type_error(kw, arg, EXPECTED));
    };
    items
        .iter()
        .map(|item| {
            path_of(item).ok_or_else(|| {
                PyTypeError::new_err(format!(
                    "{kw}={}: expected {EXPECTED}; an item is {} ({})",
                    shown(arg),
                    type_name(item),
                    shown(item)
                ))
            })
        })
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// A number: a Python `int` or `float`, a NumPy scalar or a 0-d array (not a `bool`, a `str`
/// or anything else), or `None`.
fn number_of(value: &Bound<'_, PyAny>) -> Option<f64> {
    if value.is_instance_of::<PyBool>()
        || value.is_instance_of::<PyString>()
        || value.is_instance_of::<PyBytes>()
    {
        return None;
    }
    if let Ok(a) = value.cast::<PyUntypedArray>() {
        if a.ndim() != 0 {
            return None;
        }
    }
    value.extract::<f64>().ok()
}

/// A list of numbers: a number (one item) or a sequence or 1-D array of numbers; `None` stays
/// `None`.
pub fn numbers(kw: &str, arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<f64>>> {
    const EXPECTED: &str = "a number or a sequence of numbers";
    let Some(arg) = arg else {
        return Ok(None);
    };
    if let Some(x) = number_of(arg) {
        return Ok(Some(vec![x]));
    }
    let Some(items) = items(arg)? else {
        return Err(type_error(kw, arg, EXPECTED));
    };
    items
        .iter()
        .map(|item| {
            number_of(item).ok_or_else(|| {
                PyTypeError::new_err(format!(
                    "{kw}={}: expected {EXPECTED}; an item is {} ({})",
                    shown(arg),
                    type_name(item),
                    shown(item)
                ))
            })
        })
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// A pair of numbers `(lo, hi)`, `what` saying what they are (e.g. `(FLO, FHI) in Hz, FLO <
/// FHI`): a sequence or array of exactly two numbers; `None` stays `None`.
pub fn pair(kw: &str, arg: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Option<(f64, f64)>> {
    let Some(arg) = arg else {
        return Ok(None);
    };
    let expected = format!("two numbers {what}");
    let Some(items) = items(arg)? else {
        return Err(type_error(kw, arg, &expected));
    };
    if items.len() != 2 {
        return Err(value_error(format!(
            "{kw}={}: expected {expected}, got {} value{}",
            shown(arg),
            items.len(),
            if items.len() == 1 { "" } else { "s" }
        )));
    }
    let number = |item: &Bound<'_, PyAny>| {
        number_of(item).ok_or_else(|| {
            PyTypeError::new_err(format!(
                "{kw}={}: expected {expected}; an item is {} ({})",
                shown(arg),
                type_name(item),
                shown(item)
            ))
        })
    };
    Ok(Some((number(&items[0])?, number(&items[1])?)))
}
