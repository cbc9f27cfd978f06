//! `Model.monte_carlo` (the command line's `tiltnoise mc`) and the `MonteCarlo` it returns:
//! the Monte Carlo job's draws with the nominal modes, its JSON report and its files.

use crate::args::kw;
use crate::arrays;
use crate::errors::PyResultExt;
use crate::inputs::Inputs;
use crate::interrupt;
use crate::job_args::job_error;
use crate::params::PyParams;
use crate::python_side;
use crate::state;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::mc::McResult;
use tiltnoise_job::figures::View;
use tiltnoise_job::files::Staging;
use tiltnoise_job::monte_carlo::{self, McRequest, McRun};
use tiltnoise_job::{Invocation, Outcome, Provenance, Silent};

/// Runs the Monte Carlo job for `params` with Ctrl-C honoured.
pub fn run(
    py: Python<'_>,
    params: PyParams,
    samples: usize,
    seed: u64,
    threads: usize,
) -> PyResult<MonteCarlo> {
    let req = McRequest {
        params: &params.inner,
        samples,
        seed,
        threads,
        invocation: Invocation::of_this_process(),
        figure: View::default(),
    };
    let cancel = Cancel::new();
    let run = interrupt::watch(py, &cancel, || {
        monte_carlo::run(&req, &cancel, &Silent).map_err(job_error)
    })?;
    let provenance = run.provenance;
    let r = run.result;
    Ok(MonteCarlo {
        samples: r.samples,
        rejected: r.rejected,
        freqs_hz: r.freqs_hz,
        sample_index: r.sample_index,
        mean_hz: r.mean_hz.to_vec(),
        std_hz: r.std_hz.to_vec(),
        nominal_hz: run.nominal_hz.to_vec(),
        seed,
        threads,
        params,
        provenance,
    })
}

/// The result of :meth:`Model.monte_carlo`: the mode frequencies of every accepted draw, their
/// mean and standard deviation beside the nominal modes; ``summary`` is the command line's
/// ``mc --format json`` report, ``save`` writes its files and figure.
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct MonteCarlo {
    /// Draws made (accepted + rejected).
    #[pyo3(get)]
    samples: usize,
    /// Draws rejected as non-physical.
    #[pyo3(get)]
    rejected: usize,
    freqs_hz: Vec<[f64; 8]>,
    sample_index: Vec<usize>,
    /// Mean frequency per mode (Hz).
    #[pyo3(get)]
    mean_hz: Vec<f64>,
    /// Standard deviation (n - 1) per mode (Hz).
    #[pyo3(get)]
    std_hz: Vec<f64>,
    /// Frequency per mode of the nominal parameters (Hz), ascending.
    #[pyo3(get)]
    nominal_hz: Vec<f64>,
    /// Seed of the random streams (the draws depend on it alone).
    #[pyo3(get)]
    seed: u64,
    /// Worker threads asked for (0: every core); the draws do not depend on it.
    threads: usize,
    /// The nominal parameters and their error model.
    params: PyParams,
    /// What the saved files record (the job's).
    provenance: Provenance,
}

impl MonteCarlo {
    /// The job's result again: the draws, the configuration they were made with (rebuilt from
    /// the parameters, samples, seed and threads, as the job builds it) and the nominal modes.
    fn job_run(&self) -> McRun {
        let req = McRequest {
            params: &self.params.inner,
            samples: self.samples,
            seed: self.seed,
            threads: self.threads,
            invocation: Invocation::default(),
            figure: View::default(),
        };
        let array = |v: &[f64]| <[f64; 8]>::try_from(v).expect("eight modes, as made");
        McRun {
            result: McResult {
                samples: self.samples,
                rejected: self.rejected,
                freqs_hz: self.freqs_hz.clone(),
                sample_index: self.sample_index.clone(),
                mean_hz: array(&self.mean_hz),
                std_hz: array(&self.std_hz),
            },
            config: monte_carlo::config(&req, &Cancel::never()),
            nominal_hz: array(&self.nominal_hz),
            provenance: self.provenance.clone(),
            figure: View::default(),
        }
    }
}

#[pymethods]
impl MonteCarlo {
    /// Mode frequencies (Hz) of every accepted draw, ``[n_accepted, 8]``, each row ascending
    /// (read-only).
    #[getter]
    fn freqs_hz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat: Vec<f64> = self.freqs_hz.iter().flatten().copied().collect();
        let a = PyArray1::from_vec(py, flat).reshape([self.freqs_hz.len(), 8])?;
        arrays::read_only(a)
    }

    /// 0-based draw number of each row of ``freqs_hz`` (read-only).
    #[getter]
    fn sample_index<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<usize>>> {
        arrays::read_only(PyArray1::from_slice(py, &self.sample_index))
    }

    /// The parameters drawn around, with their error model.
    #[getter]
    fn params(&self) -> PyParams {
        self.params.clone()
    }

    /// The report as the command line's ``mc --format json`` prints it: ``{"modes": [{"index",
    /// "nominal_hz", "mean_hz", "std_hz"}], "rejected", "samples", "seed"}`` (a non-finite
    /// value is ``None``).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.to_json()?,))
    }

    /// The text of :attr:`summary`, the command line's ``mc --format json`` without its final
    /// newline.
    fn to_json(&self) -> PyResult<String> {
        monte_carlo::summary_json(&self.job_run())
            .map_err(|e| crate::errors::value_error(e.to_string()))
    }

    /// Writes the Monte Carlo as the command line's ``mc --save`` does, atomically:
    /// ``.h5``/``.hdf5`` (schema ``tiltnoise.mc``: every draw, the error model and the
    /// parameters) or the command line's histograms of the eight modes as ``.png`` or
    /// ``.svg`` (the same image as ``tiltnoise mc --save x.png`` for the same draws). Raises
    /// ``OSError`` if it cannot be written or is the parameter file, ``ValueError`` for
    /// another extension.
    fn save(&self, py: Python<'_>, #[pyo3(from_py_with = kw::path)] path: PathBuf) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, monte_carlo::OUTPUT_KINDS).py()?;
        Inputs::of_params(self.params.file.as_deref()).check_save(&path)?;
        let run = self.job_run();
        py.detach(|| Staging::committed(|stage| run.save(stage, &path)))
            .map_err(job_error)
    }

    /// The draws drawn with matplotlib: one histogram per mode, the nominal frequency and the
    /// mean marked. Returns a new ``matplotlib.figure.Figure`` (of ``matplotlib.pyplot``).
    /// Needs matplotlib; raises ``ImportError`` saying so without it. The command line's own
    /// figure is :meth:`save` to a ``.png`` or ``.svg`` path.
    fn plot<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_plots", "monte_carlo_plot", &[])
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        state::load("MonteCarlo", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        format!(
            "MonteCarlo({} draws, {} rejected, seed {}; mean_hz={:?}, std_hz={:?})",
            self.samples, self.rejected, self.seed, self.mean_hz, self.std_hz
        )
    }
}
