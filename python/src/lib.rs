//! The Python extension module `tiltnoise._tiltnoise` (PyO3): tiltnoise-core's parameters,
//! model, modes, transfer functions, Welch spectra and noise budgets, and tiltnoise-io's
//! tilt readers and budget writers, for the package `tiltnoise` (python/tiltnoise/).
//!
//! A thin layer: every number comes from the library crates. It converts arguments (names as
//! on the command line, NumPy arrays), the library's typed errors into Python exceptions with
//! the command line's messages (module `errors`), and releases the GIL around every computation.

mod budget;
mod errors;
mod fit;
mod model;
mod params;
mod spectral;

use pyo3::prelude::*;

#[pymodule]
#[pyo3(name = "_tiltnoise")]
fn tiltnoise_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("hdf5_version", tiltnoise_io::hdf5_version())?;
    m.add(
        "InputFileError",
        m.py().get_type::<errors::InputFileError>(),
    )?;
    m.add_class::<params::PyParams>()?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<model::Mode>()?;
    m.add_class::<model::MonteCarlo>()?;
    m.add_class::<fit::Fit>()?;
    m.add_class::<budget::Budget>()?;
    m.add_function(wrap_pyfunction!(spectral::welch, m)?)?;
    m.add_function(wrap_pyfunction!(spectral::csd, m)?)?;
    m.add_function(wrap_pyfunction!(budget::budget, m)?)?;
    m.add_function(wrap_pyfunction!(budget::budget_from_file, m)?)?;
    Ok(())
}
