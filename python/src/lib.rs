//! The Python extension module `tiltnoise._tiltnoise` (PyO3): tiltnoise-core's parameters,
//! model, modes, transfer functions, Welch spectra, noise budgets, Monte Carlo, fit and
//! simulation, and tiltnoise-io's
//! tilt readers and budget writers, for the package `tiltnoise` (python/tiltnoise/).
//!
//! A thin layer: every number comes from the library crates. It converts arguments (names as
//! on the command line, NumPy arrays), the library's typed errors into Python exceptions with
//! the command line's messages (module `errors`), and releases the GIL around every computation.

mod args;
mod arrays;
mod budget;
mod coherence;
mod errors;
mod fit;
mod grid;
mod inputs;
mod interrupt;
mod job_args;
mod model;
mod monte_carlo;
mod params;
mod python_side;
mod simulate;
mod spectral;
mod state;
mod subtract;
mod visibility;

use pyo3::prelude::*;

/// Panics on purpose, for the tests that a Rust panic becomes a Python exception
/// (`pyo3_runtime.PanicException`) and never ends the interpreter: `where_` is `here` (holding
/// the GIL), `detached` (with the GIL released, as every computation runs) or `thread` (in a
/// worker thread of a computation with the GIL released, as a multi-threaded evaluation).
#[pyfunction]
fn _panic_for_tests(py: Python<'_>, where_: &str) -> PyResult<()> {
    let boom = || panic_on_purpose(where_);
    match where_ {
        "here" => boom(),
        "detached" => py.detach(boom),
        "thread" => py.detach(|| {
            std::thread::scope(|s| s.spawn(boom).join().expect("the worker thread panicked"))
        }),
        _ => return Err(errors::value_error("where_: here, detached or thread")),
    }
    Ok(())
}

fn panic_on_purpose(where_: &str) {
    panic!("a panic on purpose ({where_})")
}

#[pymodule]
#[pyo3(name = "_tiltnoise")]
fn tiltnoise_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // NumPy's C API is looked up on first use by importing a NumPy module, which runs Python
    // code: at a later first use, a pending Ctrl-C would fail the import and the lookup would
    // panic. Looked up here, while the import of tiltnoise runs, it is never looked up again.
    numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("hdf5_version", tiltnoise_job::files::hdf5_version())?;
    m.add(
        "InputFileError",
        m.py().get_type::<errors::InputFileError>(),
    )?;
    m.add_class::<params::PyParams>()?;
    m.add_class::<model::PyModel>()?;
    m.add_class::<model::Mode>()?;
    m.add_class::<monte_carlo::MonteCarlo>()?;
    m.add_class::<fit::Fit>()?;
    m.add_class::<simulate::Simulation>()?;
    m.add_class::<budget::Budget>()?;
    m.add_class::<coherence::Coherence>()?;
    m.add_class::<subtract::Subtraction>()?;
    m.add_class::<visibility::Visibilities>()?;
    m.add_function(wrap_pyfunction!(spectral::welch, m)?)?;
    m.add_function(wrap_pyfunction!(spectral::csd, m)?)?;
    m.add_function(wrap_pyfunction!(budget::budget, m)?)?;
    m.add_function(wrap_pyfunction!(budget::budget_from_file, m)?)?;
    m.add_function(wrap_pyfunction!(coherence::coherence, m)?)?;
    m.add_function(wrap_pyfunction!(subtract::subtract, m)?)?;
    m.add_function(wrap_pyfunction!(visibility::visibility, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_tests, m)?)?;
    Ok(())
}
