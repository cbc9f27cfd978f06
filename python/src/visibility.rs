//! `tiltnoise.visibility` (the command line's `visibility --measured FILE`) and the
//! `Visibilities` it returns: the visibility job's peaks and ratios with names and units.

use crate::args::kw;
use crate::arrays;
use crate::budget::model_of;
use crate::inputs::Inputs;
use crate::job_args;
use crate::state;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_job::files::Staging;
use tiltnoise_job::visibility::{VisibilityRequest, VisibilityResult};
use tiltnoise_job::{Invocation, Outcome, Silent};

/// Mode visibilities measured from a recorded free motion (the command line's ``tiltnoise
/// visibility --measured MEASURED``): for each mode of the model whose peak the record shows,
/// the signed ratio of its peaks in a channel and in the reference channel of the same unit
/// (the strongest with an SNR of at least 10), with its first-order error from the local
/// noise; the file that :meth:`Model.fit` reads with ``visibility=``.
///
/// ``measured``: a free-motion or ring-down record of the observables (HDF5 or CSV time
/// series, the layout :meth:`Simulation.save` writes). ``params``: a :class:`Params` or
/// :class:`Model` whose mode frequencies the peaks are looked for near (default Table I).
///
/// Returns :class:`Visibilities`. Raises ``FileNotFoundError``/``OSError`` if the file cannot
/// be read, :class:`InputFileError` if it is not a valid record, ``ValueError`` for a record
/// of spectra or one that shows no mode.
#[pyfunction]
#[pyo3(signature = (measured, *, params=None))]
pub fn visibility(
    py: Python<'_>,
    #[pyo3(from_py_with = kw::measured)] measured: PathBuf,
    params: Option<&Bound<'_, PyAny>>,
) -> PyResult<Visibilities> {
    let (model, params) = model_of(params)?;
    let req = VisibilityRequest {
        model: &model,
        measured,
        invocation: Invocation::of_this_process(),
    };
    let inputs = Inputs::of_params(params.file.as_deref()).with_all(req.input_files());
    let cancel = Cancel::new();
    let result = crate::interrupt::watch(py, &cancel, || {
        tiltnoise_job::visibility::run(&req, &cancel, &Silent).map_err(job_args::job_error)
    })?;
    Ok(Visibilities { result, inputs })
}

/// The visibilities of a record (see :func:`visibility`): ``items`` (the ratios, as the CSV
/// lists them), ``peaks`` (each mode found: its expected and measured frequency in Hz, and
/// the amplitude SNR of its peak per channel), ``skipped`` (each mode not found, with the
/// reason), ``channels`` (the record's observables, the order of each peak's SNRs) and
/// ``origin`` (the record). A ratio is of like quantities in like units (m/m, rad/rad), so
/// dimensionless.
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Visibilities {
    result: VisibilityResult,
    /// The files read: no `save` may replace one.
    inputs: Inputs,
}

#[pymethods]
impl Visibilities {
    /// Per ratio: ``mode`` (k of nu_k), ``observable``, ``reference``, ``ratio`` (signed,
    /// dimensionless) and ``sigma`` (its 1-sigma error).
    #[getter]
    fn items<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        (self.result.measured.visibilities.items.iter())
            .map(|v| {
                let d = PyDict::new(py);
                d.set_item("mode", v.mode)?;
                d.set_item("observable", v.observable.name())?;
                d.set_item("reference", v.reference.name())?;
                d.set_item("ratio", v.ratio)?;
                d.set_item("sigma", v.sigma)?;
                Ok(d)
            })
            .collect()
    }

    /// Per mode found: ``mode``, ``expected_hz`` (the model's frequency), ``frequency_hz``
    /// (the peak's) and ``snr`` (``{observable: amplitude SNR at the peak}``).
    #[getter]
    fn peaks<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        (self.result.measured.peaks.iter())
            .map(|p| {
                let d = PyDict::new(py);
                d.set_item("mode", p.mode)?;
                d.set_item("expected_hz", p.expected_hz)?;
                d.set_item("frequency_hz", p.frequency_hz)?;
                let snr = PyDict::new(py);
                for (o, x) in self.result.channels.iter().zip(&p.snr) {
                    snr.set_item(o.name(), x)?;
                }
                d.set_item("snr", snr)?;
                Ok(d)
            })
            .collect()
    }

    /// ``[(mode, reason)]`` of the modes not measured.
    #[getter]
    fn skipped(&self) -> Vec<(usize, String)> {
        self.result.measured.skipped.clone()
    }

    /// The record's observables, in its order.
    #[getter]
    fn channels(&self) -> Vec<&'static str> {
        self.result.channels.iter().map(|o| o.name()).collect()
    }

    /// ``mode`` of each ratio of :attr:`items` (k of nu_k), as an array (read-only).
    #[getter]
    fn mode<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<usize>>> {
        let items = &self.result.measured.visibilities.items;
        let mode: Vec<usize> = items.iter().map(|v| v.mode).collect();
        arrays::read_only(PyArray1::from_vec(py, mode))
    }

    /// ``ratio`` of each entry of :attr:`items` (signed, dimensionless), as an array
    /// (read-only).
    #[getter]
    fn ratio<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let items = &self.result.measured.visibilities.items;
        arrays::read_only(PyArray1::from_vec(
            py,
            items.iter().map(|v| v.ratio).collect(),
        ))
    }

    /// ``sigma`` of each entry of :attr:`items` (1-sigma error of the ratio), as an array
    /// (read-only).
    #[getter]
    fn sigma<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let items = &self.result.measured.visibilities.items;
        arrays::read_only(PyArray1::from_vec(
            py,
            items.iter().map(|v| v.sigma).collect(),
        ))
    }

    /// The record the visibilities were measured from.
    #[getter]
    fn origin(&self) -> &str {
        &self.result.origin
    }

    /// The CSV ``mode,observable,reference,ratio,sigma`` that :meth:`Model.fit` reads with
    /// ``visibility=`` (the command line's ``visibility --format csv``).
    fn to_csv(&self) -> String {
        self.result.csv()
    }

    /// The measurement as JSON: ``{"channels", "origin", "peaks": [{"expected_hz",
    /// "frequency_hz", "mode", "snr": {observable: SNR}}], "skipped": [{"mode", "reason"}],
    /// "visibilities": [{"mode", "observable", "ratio", "reference", "sigma"}]}`` (keys in
    /// alphabetical order, frequencies in Hz, a non-finite number as ``null``).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.result.json())
            .map_err(|e| crate::errors::value_error(e.to_string()))
    }

    /// Writes :meth:`to_csv` to ``path`` (``.csv``), atomically. Raises ``OSError`` if it
    /// cannot be written or is one of the files read, ``ValueError`` for another extension.
    fn save(&self, py: Python<'_>, #[pyo3(from_py_with = kw::path)] path: PathBuf) -> PyResult<()> {
        self.inputs.check_save(&path)?;
        let result = self.result.clone();
        py.detach(|| Staging::committed(|stage| result.save(stage, &path)))
            .map_err(job_args::job_error)
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        state::load("Visibilities", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        format!(
            "Visibilities({} ratios of {} modes from {})",
            self.result.measured.visibilities.items.len(),
            self.result.measured.peaks.len(),
            self.result.origin
        )
    }
}
