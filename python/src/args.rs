//! Keyword arguments from Python, converted in one place by one rule per type (every call of
//! the module uses these), so that a value of the wrong type is refused with a `TypeError`
//! `KW=VALUE: expected WHAT, got TYPE` naming the keyword, whatever the call:
//!
//! - a number (`holdout`, `fs`, `rel_tol`, ...) is a Python `int` or `float`, a NumPy scalar
//!   or a 0-d array, not a `bool` or a `str`;
//! - an integer (`nperseg`, `seed`, `samples`, ...) is a Python `int`, a NumPy integer or a
//!   0-d integer array (anything with `__index__`), not a `bool` or a `float`; a negative one
//!   (or one over 2**64 - 1) is a `ValueError` naming the keyword;
//! - a flag (`prior`, `keep_zero_columns`) is a `bool` (or `numpy.bool_`);
//! - a name (`method`, `quantity`, `gaps`, `axes` of a file, ...) is a `str`; a path
//!   (`path`, `tilt`, `measured`, `visibility`) a `str` or an `os.PathLike` of `str`;
//! - a mapping (`units`, `scale`, `readout`, `term`, ...) is a `dict` with `str` keys (the
//!   values as the keyword's own rule says: a number for `scale`, ...);
//! - an optional keyword (default `None`) takes `None` too, for its default;
//! - a list of names (`corrected`, `fit`, `free`, `inputs`, ...) is a `str` or a sequence of
//!   `str`; a single `str` is a one-item list (as NumPy and pathlib users expect);
//! - a list of paths (`colocated`) is a `str`/`os.PathLike` or a sequence of them, one path
//!   a one-item list;
//! - a list of numbers (`at`) is a number (one item) or a sequence / 1-D array of numbers;
//! - a pair (`band`, `report_band`, `fit_band`, `percentiles`) is a sequence or array of
//!   exactly two numbers, NumPy scalars included.
//!
//! Scalars and mappings are converted as PyO3 extracts the arguments, by the converter of the
//! keyword's name in [`kw`] (`#[pyo3(from_py_with = kw::holdout)]`, its type saying the rule:
//! [`Keyword`]); lists and pairs in the call's body ([`strings`], [`names`], [`paths`],
//! [`numbers`], [`pair`], [`band`]). A `str` keyword with a default other than `None` is a
//! `String`, whose default (`String::from("auto")`) PyO3 cannot show: its call spells out the
//! signature Python shows (`text_signature`), which `test_stubs.py` checks against the stubs. A pair with
//! another number of values is a `ValueError` saying what is expected. The checks of the
//! values themselves (known names, `lo < hi`, ranges) are the job's, with the command line's
//! messages.

use crate::errors::value_error;
use crate::params::PyParams;
use numpy::{PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyByteArray, PyBytes, PyDict, PyFloat, PyString};
use std::collections::BTreeMap;
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

/// `TypeError` for an item of a list, pair or mapping argument `arg`: `kw=VALUE: expected
/// EXPECTED; ITEM is TYPE (VALUE)`, `which` saying which item (`an item`, `the value of 'x'`).
fn item_error(
    kw: &str,
    arg: &Bound<'_, PyAny>,
    expected: &str,
    which: &str,
    item: &Bound<'_, PyAny>,
) -> PyErr {
    PyTypeError::new_err(format!(
        "{kw}={}: expected {expected}; {which} is {} ({})",
        shown(arg),
        type_name(item),
        shown(item)
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

/// A list argument: one item (`item` gives it) as a one-item list, or a sequence of items;
/// `None` stays `None`; anything else a `TypeError` saying `expected`.
fn one_or_many<T>(
    kw: &str,
    arg: Option<&Bound<'_, PyAny>>,
    expected: &str,
    item: impl Fn(&Bound<'_, PyAny>) -> Option<T>,
) -> PyResult<Option<Vec<T>>> {
    let Some(arg) = arg else {
        return Ok(None);
    };
    if let Some(one) = item(arg) {
        return Ok(Some(vec![one]));
    }
    let Some(items) = items(arg)? else {
        return Err(type_error(kw, arg, expected));
    };
    items
        .iter()
        .map(|i| item(i).ok_or_else(|| item_error(kw, arg, expected, "an item", i)))
        .collect::<PyResult<Vec<_>>>()
        .map(Some)
}

/// A `str`, else `None`.
fn string_of(value: &Bound<'_, PyAny>) -> Option<String> {
    let s = value.cast::<PyString>().ok()?;
    s.to_cow().ok().map(|s| s.into_owned())
}

/// A list of `str`: a `str` (one item) or a sequence of `str`; `None` stays `None`.
pub fn strings(kw: &str, arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<String>>> {
    one_or_many(kw, arg, "a str or a sequence of str", string_of)
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
pub fn path_of(value: &Bound<'_, PyAny>) -> Option<PathBuf> {
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
    one_or_many(
        kw,
        arg,
        "a path (str or os.PathLike) or a sequence of paths",
        path_of,
    )
}

/// A number: a Python `int` or `float`, a NumPy scalar or a 0-d array (not a `bool`, a `str`
/// or anything else), or `None`.
pub fn number_of(value: &Bound<'_, PyAny>) -> Option<f64> {
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
    one_or_many(kw, arg, "a number or a sequence of numbers", number_of)
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
        number_of(item).ok_or_else(|| item_error(kw, arg, &expected, "an item", item))
    };
    Ok(Some((number(&items[0])?, number(&items[1])?)))
}

/// A frequency band `(FLO, FHI)` in Hz (`band`, `report_band`, `fit_band`): a [`pair`].
pub fn band(kw: &str, arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<(f64, f64)>> {
    pair(kw, arg, "(FLO, FHI) in Hz, 0 < FLO < FHI")
}

/// A value of one type of keyword: what it is (for messages) and how it is read.
pub trait Scalar: Sized {
    /// What the keyword takes, as the message says it (`a number (int or float)`).
    const EXPECTED: &'static str;

    /// The type's short name, for a mapping's values (`{str: number}`).
    const NAME: &'static str;

    /// The value; `Ok(None)` for a value of another type (the caller's `TypeError`), a
    /// `ValueError` naming `kw` for one of the type but out of its range.
    fn scalar(kw: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>>;
}

impl Scalar for f64 {
    const EXPECTED: &'static str = "a number (int or float)";
    const NAME: &'static str = "number";

    fn scalar(_: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
        Ok(number_of(value))
    }
}

impl Scalar for bool {
    const EXPECTED: &'static str = "a bool (True or False)";
    const NAME: &'static str = "bool";

    fn scalar(_: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
        // A Python `bool` or `numpy.bool_`, never an `int` (PyO3's rule).
        Ok(value.extract::<bool>().ok())
    }
}

impl Scalar for String {
    const EXPECTED: &'static str = "a str";
    const NAME: &'static str = "str";

    fn scalar(_: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
        Ok(string_of(value))
    }
}

impl Scalar for PathBuf {
    const EXPECTED: &'static str = "a path (str or os.PathLike)";
    const NAME: &'static str = "path";

    fn scalar(_: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
        Ok(path_of(value))
    }
}

impl Scalar for PyParams {
    const EXPECTED: &'static str = "a tiltnoise.Params";
    const NAME: &'static str = "Params";

    fn scalar(_: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
        Ok(value.cast::<PyParams>().ok().map(|p| p.get().clone()))
    }
}

/// An unsigned integer: an object with `__index__` (not a `bool` or a `float`), within
/// `0..=max`.
fn unsigned_of(kw: &str, value: &Bound<'_, PyAny>, max: u64) -> PyResult<Option<u64>> {
    if value.is_instance_of::<PyBool>()
        || value.is_instance_of::<PyFloat>()
        || value.is_instance_of::<PyString>()
        || !value.hasattr("__index__").unwrap_or(false)
    {
        return Ok(None);
    }
    let Ok(index) = value.call_method0("__index__") else {
        return Ok(None);
    };
    match index.extract::<u64>() {
        Ok(n) if n <= max => Ok(Some(n)),
        _ => Err(value_error(format!(
            "{kw}={}: expected an integer from 0 to {max}",
            shown(value)
        ))),
    }
}

/// [`Scalar`] for unsigned integer types.
macro_rules! unsigned_scalar {
    ($($ty:ty),*) => {$(
        impl Scalar for $ty {
            const EXPECTED: &'static str = "an integer";
            const NAME: &'static str = "int";

            fn scalar(kw: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<Self>> {
                // `MAX` fits u64 for every type listed.
                Ok(unsigned_of(kw, value, <$ty>::MAX as u64)?.map(|n| n as $ty))
            }
        }
    )*};
}

unsigned_scalar!(u32, u64, usize);

/// How a keyword of one type is converted, its value given (`None` included): a [`Scalar`],
/// an `Option` of one (`None` for the default), a mapping.
pub trait Keyword<'py>: Sized {
    /// The value of keyword `kw`, or the error naming it.
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self>;
}

impl<'py, T: Scalar> Keyword<'py> for T {
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self> {
        T::scalar(kw, value)?.ok_or_else(|| type_error(kw, value, T::EXPECTED))
    }
}

impl<'py, T: Scalar> Keyword<'py> for Option<T> {
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self> {
        if value.is_none() {
            return Ok(None);
        }
        match T::scalar(kw, value)? {
            Some(v) => Ok(Some(v)),
            None => Err(type_error(kw, value, &format!("{} or None", T::EXPECTED))),
        }
    }
}

/// A mapping keyword whose values the call reads itself (`readout`, `term`, ...): a `dict`,
/// or `None`.
impl<'py> Keyword<'py> for Option<Bound<'py, PyDict>> {
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self> {
        if value.is_none() {
            return Ok(None);
        }
        match value.cast::<PyDict>() {
            Ok(d) => Ok(Some(d.clone())),
            Err(_) => Err(type_error(kw, value, "a dict or None")),
        }
    }
}

/// The entries of the dict of mapping keyword `kw`, in its order, whose values the caller
/// reads (a key that is not a `str`: a `TypeError` naming the keyword, `expected` saying what
/// the dict holds, e.g. `a dict {observable: ASD}`).
pub fn entries<'py>(
    kw: &str,
    d: &Bound<'py, PyDict>,
    expected: &str,
) -> PyResult<Vec<(String, Bound<'py, PyAny>)>> {
    d.iter()
        .map(|(k, v)| match string_of(&k) {
            Some(key) => Ok((key, v)),
            None => Err(item_error(kw, d.as_any(), expected, "a key", &k)),
        })
        .collect()
}

/// `TypeError` for the value of entry `key` of the dict `d` of mapping keyword `kw`.
pub fn entry_error(
    kw: &str,
    d: &Bound<'_, PyDict>,
    expected: &str,
    key: &str,
    value: &Bound<'_, PyAny>,
) -> PyErr {
    item_error(
        kw,
        d.as_any(),
        expected,
        &format!("the value of {key:?}"),
        value,
    )
}

/// The entries of a mapping keyword `kw` holding `{str: V}`, in the dict's order; `also` says
/// what else the keyword takes (` or None`).
pub fn dict_of<V: Scalar>(
    kw: &str,
    value: &Bound<'_, PyAny>,
    also: &str,
) -> PyResult<Vec<(String, V)>> {
    let expected = format!("a dict {{str: {}}}{also}", V::NAME);
    let Ok(d) = value.cast::<PyDict>() else {
        return Err(type_error(kw, value, &expected));
    };
    entries(kw, d, &expected)?
        .into_iter()
        .map(|(key, v)| match V::scalar(kw, &v)? {
            Some(item) => Ok((key, item)),
            None => Err(entry_error(kw, d, &expected, &key, &v)),
        })
        .collect()
}

/// A mapping `{str: value}` in the dict's order (`Params.update`'s `values`).
impl<'py, V: Scalar> Keyword<'py> for Vec<(String, V)> {
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self> {
        dict_of(kw, value, "")
    }
}

/// A mapping `{str: value}` in the dict's order, or `None` (`Model.simulate`'s `readout`).
impl<'py, V: Scalar> Keyword<'py> for Option<Vec<(String, V)>> {
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self> {
        if value.is_none() {
            return Ok(None);
        }
        dict_of(kw, value, " or None").map(Some)
    }
}

/// A mapping `{str: value}` (`units`, `scale`, `colocated_ratio`, ...), or `None`.
impl<'py, V: Scalar> Keyword<'py> for Option<BTreeMap<String, V>> {
    fn keyword(kw: &str, value: &Bound<'py, PyAny>) -> PyResult<Self> {
        if value.is_none() {
            return Ok(None);
        }
        Ok(Some(dict_of(kw, value, " or None")?.into_iter().collect()))
    }
}

/// One converter per keyword name, for `#[pyo3(from_py_with = args::kw::NAME)]`: the keyword's
/// value as its parameter's type ([`Keyword`]), a wrong type a `TypeError` naming it.
macro_rules! keywords {
    ($($name:ident),* $(,)?) => {
        /// The converters of the keywords by name (see the module docs).
        pub mod kw {
            use super::Keyword;
            use pyo3::prelude::*;
            $(
                #[doc = concat!("`", stringify!($name), "=`, converted by its type's rule.")]
                pub fn $name<'py, T: Keyword<'py>>(value: &Bound<'py, PyAny>) -> PyResult<T> {
                    T::keyword(stringify!($name), value)
                }
            )*
        }
    };
}

keywords!(
    at_band,
    average,
    axes,
    bound_sigmas,
    colocated_ratio,
    confidence,
    duration,
    fs,
    gaps,
    holdout,
    keep_zero_columns,
    key,
    kick_x,
    max_delay,
    measured,
    method,
    mode_energy,
    noverlap,
    nperseg,
    observable,
    overlap,
    params,
    path,
    phase,
    prior,
    quantity,
    readout,
    rel_tol,
    samples,
    scale,
    seed,
    segment_duration,
    step,
    term,
    threads,
    tilt,
    units,
    value,
    values,
    visibility,
    window,
    witness_noise,
);
