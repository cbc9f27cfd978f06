//! Arrays from Python, copied into `Vec<f64>` (every computation runs with the GIL released,
//! while other Python threads could change an array) only after their size has been checked:
//! the count against its documented limit (`ValueError`) and the bytes the copy and the work
//! on it take against the memory available (`MemoryError`, see `tiltnoise_core::limits`). A
//! view (non-contiguous, reversed, or broadcast with a zero stride) is read element by element
//! in place: the only copy is the one checked. float64 and float32 arrays are read directly;
//! other float and integer arrays (float16, big-endian, int8 .. uint64) are converted to float64
//! by NumPy within the same check. Any other dtype (complex, bool, object, strings, dates) is
//! refused, naming the dtype needed.

use crate::errors::value_error;
use numpy::{
    PyArray3, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use tiltnoise_core::error::Num;
use tiltnoise_core::limits::{check_count, check_memory, planned_bytes, LimitError, Magnitudes};

/// How many elements an argument may have and what a run on it costs per element.
#[derive(Debug, Clone, Copy)]
pub struct Size {
    /// The documented limit on the count (`tiltnoise_core::limits`).
    pub limit: usize,
    /// What is counted, plural, for messages: `samples`, `frequencies`.
    pub unit: &'static str,
    /// Bytes planned per element: the copy and what the computation keeps per element.
    pub bytes_each: u64,
}

/// A size over a limit as its Python exception: `MemoryError` when the machine's memory is
/// the bound, else `ValueError`; the message names the argument, the count and the limit.
pub fn limit_error(e: LimitError) -> PyErr {
    crate::errors::IntoPyErr::into_py_err(e)
}

/// Refuses `n` elements of `what` over `size` (count, then memory), before anything is copied.
pub fn check_size(what: &str, n: usize, size: Size) -> PyResult<()> {
    check_count(|| what.to_string(), n as f64, size.unit, size.limit).map_err(limit_error)?;
    check_memory(
        || format!("{what}: {n} {}", size.unit),
        planned_bytes(n, size.bytes_each),
    )
    .map_err(limit_error)
}

/// Room for `n` more values in `out`, or a `MemoryError` naming `what` when the system refuses
/// the memory (the sizes are checked first, but the memory available can change meanwhile).
pub fn reserve(what: &str, out: &mut Vec<f64>, n: usize) -> PyResult<()> {
    out.try_reserve_exact(n).map_err(|e| {
        PyMemoryError::new_err(format!(
            "{what}: cannot allocate {n} values ({} MiB): {e}",
            n.saturating_mul(8) >> 20
        ))
    })
}

/// `arg` as a NumPy array without copying one (`numpy.asarray` of a list or a number makes
/// an array the size of what Python already holds).
fn as_ndarray<'py>(what: &str, arg: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = arg.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let np = arg.py().import("numpy")?;
    np.call_method1("asarray", (arg,))
        .map_err(|e| value_error(format!("{what}: not an array of numbers ({e})")))?
        .cast_into::<PyUntypedArray>()
        .map_err(|e| value_error(format!("{what}: not an array ({e})")))
}

/// The array's elements (any shape, read in C order) as `f64`, appended to `out`: float64 and
/// float32 read in place, other float and integer dtypes converted by NumPy; any other dtype
/// refused with a `TypeError` naming it.
fn append_f64(what: &str, a: &Bound<'_, PyUntypedArray>, out: &mut Vec<f64>) -> PyResult<()> {
    let dtype = a.dtype();
    if let Ok(a) = a.cast::<PyArrayDyn<f64>>() {
        let view = a
            .try_readonly()
            .map_err(|e| value_error(format!("{what}: {e}")))?;
        out.extend(view.as_array().iter().copied());
        return Ok(());
    }
    if let Ok(a) = a.cast::<PyArrayDyn<f32>>() {
        let view = a
            .try_readonly()
            .map_err(|e| value_error(format!("{what}: {e}")))?;
        out.extend(view.as_array().iter().map(|&x| f64::from(x)));
        return Ok(());
    }
    if matches!(dtype.kind(), b'f' | b'i' | b'u') {
        let converted = a.call_method1("astype", ("float64",))?;
        let converted = converted.cast::<PyArrayDyn<f64>>()?;
        let view = converted.readonly();
        out.extend(view.as_array().iter().copied());
        return Ok(());
    }
    Err(PyTypeError::new_err(format!(
        "{what}: dtype {dtype} is not allowed: give numbers as float64 (float32, float16 and \
         integer arrays are converted)"
    )))
}

/// A 1-D series of `f64` from an array-like named `what` (a view is read in place), its size
/// checked against `size` before the one copy is made.
pub fn series(what: &str, arg: &Bound<'_, PyAny>, size: Size) -> PyResult<Vec<f64>> {
    let a = as_ndarray(what, arg)?;
    if a.ndim() != 1 {
        return Err(value_error(format!(
            "{what}: expected a 1-D series, got an array of shape {:?}",
            a.shape()
        )));
    }
    let mut out = Vec::new();
    check_size(what, a.len(), size)?;
    reserve(what, &mut out, a.len())?;
    append_f64(what, &a, &mut out)?;
    Ok(out)
}

/// The frequencies of a number or a 0-d or 1-D array-like named `what`, into `out` (cleared
/// first, its allocation kept), their count checked against `size` first.
pub fn grid_into(
    what: &str,
    arg: &Bound<'_, PyAny>,
    size: Size,
    out: &mut Vec<f64>,
) -> PyResult<()> {
    out.clear();
    let a = as_ndarray(what, arg)?;
    if a.ndim() > 1 {
        return Err(value_error(format!(
            "{what}: expected a number or a 1-D array of frequencies in Hz, got {} dimensions",
            a.ndim()
        )));
    }
    check_size(what, a.len(), size)?;
    reserve(what, out, a.len())?;
    append_f64(what, &a, out)
}

/// The rows of a 2-D array-like named `what` as series (each a view read in place), the whole
/// array's size checked against `size` first.
pub fn rows(what: &str, arg: &Bound<'_, PyAny>, size: Size) -> PyResult<Vec<Vec<f64>>> {
    let a = as_ndarray(what, arg)?;
    let shape = a.shape().to_vec();
    if shape.len() != 2 {
        return Err(value_error(format!(
            "{what}: expected a 2-D array of shape (n_axes, n_samples), got shape {shape:?}"
        )));
    }
    check_size(what, a.len(), size)?;
    (0..shape[0])
        .map(|i| {
            let row = a.get_item(i)?.cast_into::<PyUntypedArray>()?;
            let mut out = Vec::new();
            reserve(what, &mut out, shape[1])?;
            append_f64(&format!("{what}[{i}]"), &row, &mut out)?;
            Ok(out)
        })
        .collect()
}

/// `a`, made read-only: an array a result hands out is a view of the result's values, not a
/// place to change them (a write raises `ValueError: assignment destination is read-only`).
pub fn read_only<T: numpy::Element, D: numpy::ndarray::Dimension>(
    a: Bound<'_, numpy::PyArray<T, D>>,
) -> PyResult<Bound<'_, numpy::PyArray<T, D>>> {
    let kwargs = pyo3::types::PyDict::new(a.py());
    kwargs.set_item("write", false)?;
    a.call_method("setflags", (), Some(&kwargs))?;
    Ok(a)
}

/// Refuses the first value of `values` (the argument `what`) outside `allowed`, naming its index
/// and value: `ValueError: x[100] = 1e308 is not allowed: ...`.
pub fn check_values(what: &str, values: &[f64], allowed: &Magnitudes, unit: &str) -> PyResult<()> {
    match allowed.first_refused(values) {
        None => Ok(()),
        Some((i, v)) => Err(value_error(format!(
            "{what}[{i}] = {} is not allowed: must be {} (beyond that the spectra overflow or \
             underflow f64; see docs/limits.md)",
            Num(v),
            allowed.allowed(unit)
        ))),
    }
}

/// The output array `out` for a result of shape `dims` and dtype `dtype_name` (`T`):
/// C-contiguous and of that shape, or a `TypeError`/`ValueError` saying what it is not (it is
/// never copied, so a view cannot be filled in place).
pub fn output<'py, T: numpy::Element>(
    what: &str,
    out: &Bound<'py, PyAny>,
    dims: [usize; 3],
    dtype_name: &str,
) -> PyResult<Bound<'py, PyArray3<T>>> {
    let a = out.cast::<PyUntypedArray>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what}: expected a NumPy array of dtype {dtype_name} and shape {dims:?}, got {}",
            out.get_type()
        ))
    })?;
    if a.dtype().is_equiv_to(&numpy::dtype::<T>(out.py())) && a.shape() != dims {
        return Err(value_error(format!(
            "{what}: shape {:?} does not fit the result's (n_freq, n_outputs, n_inputs) = \
             {dims:?}",
            a.shape()
        )));
    }
    let typed = a.cast::<PyArray3<T>>().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what}: a {}-D array of dtype {} is not allowed: must be {dtype_name} of shape \
             {dims:?}",
            a.ndim(),
            a.dtype()
        ))
    })?;
    if !a.is_c_contiguous() {
        return Err(value_error(format!(
            "{what}: must be C-contiguous (its strides are {:?} bytes; filling a view would need \
             a copy); give np.empty({dims:?}, dtype=np.{dtype_name})",
            a.strides()
        )));
    }
    Ok(typed.clone())
}
