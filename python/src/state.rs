//! Pickling (`pickle`, `copy`, `multiprocessing`, joblib): an object pickles as
//! `(Class._from_state, (STATE_VERSION, state))`, `state` its Rust value serialized by serde as
//! CBOR bytes, which keep every `f64` bit for bit (NaN and infinities included). Two objects of
//! a class are equal (`==`) when their states are: every value equal bit for bit, the same
//! files behind them.
//!
//! The state is that of this build's types: a pickle is for another process of the same
//! version (what multiprocessing and joblib do), not an archive (the files of `save` are).
//! A state of another version is refused with a `ValueError` saying so, never misread.

use crate::errors::value_error;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyTuple};
use serde::de::DeserializeOwned;
use serde::Serialize;

/// The version of the states: raised whenever a pickled type changes, so that an old pickle is
/// refused instead of misread.
pub const STATE_VERSION: u32 = 5;

/// What `__reduce__` returns: the class's `_from_state` and its arguments.
pub type Reduced<'py> = (Bound<'py, PyAny>, Bound<'py, PyTuple>);

/// The state of `value`.
fn dump<T: Serialize>(value: &T) -> PyResult<Vec<u8>> {
    let mut out = Vec::new();
    ciborium::into_writer(value, &mut out)
        .map_err(|e| value_error(format!("cannot pickle: {e}")))?;
    Ok(out)
}

/// `(type(slf)._from_state, (STATE_VERSION, state of value))`.
pub fn reduce<'py, T: Serialize>(slf: &Bound<'py, PyAny>, value: &T) -> PyResult<Reduced<'py>> {
    let py = slf.py();
    let from_state = slf.get_type().getattr("_from_state")?;
    let state = PyBytes::new(py, &dump(value)?);
    let args = PyTuple::new(
        py,
        [
            STATE_VERSION.into_pyobject(py)?.into_any(),
            state.into_any(),
        ],
    )?;
    Ok((from_state, args))
}

/// The value of a `class` pickled as `(version, state)`.
pub fn load<T: DeserializeOwned>(class: &str, version: u32, state: &[u8]) -> PyResult<T> {
    if version != STATE_VERSION {
        return Err(value_error(format!(
            "a tiltnoise.{class} pickled with state version {version} cannot be read by this \
             tiltnoise ({}, state version {STATE_VERSION}): pickles are for processes of the \
             same version; save results with .save() to keep them",
            env!("CARGO_PKG_VERSION")
        )));
    }
    ciborium::from_reader(state)
        .map_err(|e| value_error(format!("not the state of a tiltnoise.{class}: {e}")))
}

/// `a == other`: `other` is of `a`'s class and has the same state.
pub fn equal<T>(a: &T, other: &Bound<'_, PyAny>) -> PyResult<bool>
where
    T: Serialize + pyo3::PyClass<Frozen = pyo3::pyclass::boolean_struct::True> + Sync,
{
    match other.cast::<T>() {
        Ok(b) => Ok(dump(a)? == dump(b.get())?),
        Err(_) => Ok(false),
    }
}
