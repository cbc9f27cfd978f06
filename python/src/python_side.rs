//! The pure-Python part of the package (`tiltnoise/_convert.py`, `tiltnoise/_plots.py`, ...):
//! conversions and figures that use optional packages (gwpy, pandas, matplotlib), called from
//! the methods of the extension's classes.

use pyo3::prelude::*;
use pyo3::types::PyTuple;

/// `tiltnoise.<module>.<function>(obj, *args)`.
pub fn call<'py>(
    obj: &Bound<'py, PyAny>,
    module: &str,
    function: &str,
    args: &[Bound<'py, PyAny>],
) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    let mut all = vec![obj.clone()];
    all.extend(args.iter().cloned());
    py.import(format!("tiltnoise.{module}"))?
        .getattr(function)?
        .call1(PyTuple::new(py, all)?)
}
