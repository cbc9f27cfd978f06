//! `tiltnoise.coherence` (the command line's `coherence --tilt FILE --measured FILE`) and the
//! `Coherence` it returns: the coherence job's report with names and units.

use crate::args::{self, kw};
use crate::budget::model_of;
use crate::errors::PyResultExt;
use crate::inputs::Inputs;
use crate::job_args;
use numpy::{Complex64, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::coherence::CoherenceReport;
use tiltnoise_job::coherence::{CoherenceOutcome, CoherenceRequest};
use tiltnoise_job::figures::View;
use tiltnoise_job::files::Staging;
use tiltnoise_job::{Invocation, Outcome};

/// Coherence of measured observables with the tilt axes, and their measured transfer
/// functions (multiple-input estimate with confidence intervals) against the model's: the
/// command line's ``tiltnoise coherence --tilt TILT --measured MEASURED``.
///
/// ``tilt``: a tilt time series file (HDF5, CSV or miniSEED; angle or rate), read with
/// ``axes`` (axis map), ``quantity``, ``gaps`` and ``scale`` as :func:`budget_from_file`
/// reads it. ``measured``: a time series of the observables (HDF5 as ``simulate`` writes
/// it, or CSV ``time_s,X,...`` in m, rad); the records are aligned by their start times.
/// ``observables``: the observables to analyse (default: every channel of ``measured``);
/// ``nperseg``, ``overlap``: Welch segment and overlap; ``confidence``: level of every
/// interval and threshold (default 0.95); ``fit_band``: ``(FLO, FHI)`` Hz of the
/// measured/model fit (default every bin). ``params``: a :class:`Params` or :class:`Model`.
///
/// Returns a :class:`Coherence`. Raises ``FileNotFoundError``/``OSError`` if a file cannot be
/// read, :class:`InputFileError` if it is not a valid record, ``ValueError`` for options or
/// records that give no estimate.
#[pyfunction]
#[pyo3(signature = (tilt, measured, *, axes=None, quantity=None, gaps=None, scale=None, observables=None, nperseg=None, overlap=None, confidence=None, fit_band=None, params=None))]
#[allow(clippy::too_many_arguments)]
pub fn coherence(
    py: Python<'_>,
    #[pyo3(from_py_with = kw::tilt)] tilt: PathBuf,
    #[pyo3(from_py_with = kw::measured)] measured: PathBuf,
    #[pyo3(from_py_with = kw::axes)] axes: Option<String>,
    #[pyo3(from_py_with = kw::quantity)] quantity: Option<String>,
    #[pyo3(from_py_with = kw::gaps)] gaps: Option<String>,
    #[pyo3(from_py_with = kw::scale)] scale: Option<std::collections::BTreeMap<String, f64>>,
    observables: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::nperseg)] nperseg: Option<usize>,
    #[pyo3(from_py_with = kw::overlap)] overlap: Option<f64>,
    #[pyo3(from_py_with = kw::confidence)] confidence: Option<f64>,
    fit_band: Option<&Bound<'_, PyAny>>,
    params: Option<&Bound<'_, PyAny>>,
) -> PyResult<Coherence> {
    let fit_band = args::band("fit_band", fit_band)?;
    let (model, params) = model_of(params)?;
    let observables = job_args::observables(observables)?;
    let req = CoherenceRequest {
        model: &model,
        tilt,
        read: job_args::read_request(axes, quantity, gaps, scale)?,
        measured,
        observables,
        nperseg,
        overlap,
        confidence,
        fit_band_hz: fit_band,
        view: View::default(),
        invocation: Invocation::of_this_process(),
    };
    let inputs = Inputs::of_params(params.file.as_deref())
        .with_all(job_args::python_names(req.input_files(), &[]));
    let cancel = Cancel::new();
    let outcome = crate::interrupt::watch(py, &cancel, || {
        tiltnoise_job::coherence::run(&req, &cancel, &tiltnoise_job::Silent)
            .map_err(job_args::job_error)
    })?;
    Ok(Coherence { outcome, inputs })
}

/// A coherence analysis: on the Welch grid ``frequency_hz``, for each observable the multiple
/// coherence with all tilt axes and, per axis, the ordinary coherence, the measured transfer
/// function (multiple-input estimate, ``units[observable]``, per rad of tilt) with its
/// confidence radius, and the model's. The names are the files' (``docs/schemas.md``,
/// ``tiltnoise.coherence``).
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Coherence {
    /// The job's outcome: the report, the records' provenance and the run's.
    outcome: CoherenceOutcome,
    /// The files read: no `save` may replace one.
    inputs: Inputs,
}

impl Coherence {
    fn report(&self) -> &CoherenceReport {
        &self.outcome.report
    }

    /// `{observable: {axis: f(axis estimate)}}`.
    fn per_axis<'py, T: numpy::Element>(
        &self,
        py: Python<'py>,
        f: impl Fn(&tiltnoise_core::coherence::AxisEstimate) -> &[T],
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for ob in &self.report().observables {
            let a = PyDict::new(py);
            for axis in &ob.axes {
                a.set_item(axis.axis.name(), PyArray1::from_slice(py, f(axis)))?;
            }
            d.set_item(ob.observable.name(), a)?;
        }
        Ok(d)
    }

    /// `{observable: f(observable estimate)}`.
    fn per_observable<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&tiltnoise_core::coherence::ObservableEstimate) -> &[f64],
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for ob in &self.report().observables {
            d.set_item(ob.observable.name(), PyArray1::from_slice(py, f(ob)))?;
        }
        Ok(d)
    }
}

#[pymethods]
impl Coherence {
    /// Frequencies of the Welch bins (Hz), DC excluded.
    #[getter]
    fn frequency_hz<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.report().freqs_hz)
    }

    /// The tilt axes of the record.
    #[getter]
    fn axes(&self) -> Vec<&'static str> {
        self.report().axes.iter().map(|a| a.name()).collect()
    }

    /// The observables analysed.
    #[getter]
    fn observables(&self) -> Vec<&'static str> {
        self.report()
            .observables
            .iter()
            .map(|o| o.observable.name())
            .collect()
    }

    /// ``{observable: unit of its transfer functions}``, e.g. ``m/rad``.
    #[getter]
    fn units(&self) -> std::collections::BTreeMap<&'static str, String> {
        self.report()
            .observables
            .iter()
            .map(|o| (o.observable.name(), format!("{}/rad", o.observable.unit())))
            .collect()
    }

    /// ``{observable: {axis: ordinary coherence}}`` (0..1).
    #[getter]
    fn coherence<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.per_axis(py, |a| &a.coherence)
    }

    /// ``{observable: multiple coherence with every tilt axis}`` (0..1).
    #[getter]
    fn multiple_coherence<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.per_observable(py, |o| &o.multiple_coherence)
    }

    /// ``{observable: {axis: measured transfer function}}`` (complex, ``units[observable]``).
    #[getter]
    fn transfer<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.per_axis::<Complex64>(py, |a| &a.tf)
    }

    /// ``{observable: {axis: radius of the transfer function's confidence disc}}``.
    #[getter]
    fn transfer_radius<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.per_axis(py, |a| &a.tf_radius)
    }

    /// ``{observable: {axis: the model's transfer function}}`` (complex).
    #[getter]
    fn model<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.per_axis::<Complex64>(py, |a| &a.model)
    }

    /// ``{observable: one-sided PSD}`` of the measured record, (unit)**2/Hz.
    #[getter]
    fn psd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.per_observable(py, |o| &o.psd)
    }

    /// ``{observable: {axis: {"gain", "gain_sigma", "phase_deg", "phase_sigma_deg", "n_bins",
    /// "band_hz", "chi2_per_dof"}}}``: the measured transfer function over the model's in the
    /// fit band, for each axis whose model is not identically 0.
    #[getter]
    fn agreement<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for ob in &self.report().observables {
            let a = PyDict::new(py);
            for axis in &ob.axes {
                if let Some(g) = &axis.agreement {
                    let e = PyDict::new(py);
                    e.set_item("gain", g.gain())?;
                    e.set_item("gain_sigma", g.sigma)?;
                    e.set_item("phase_deg", g.phase_deg())?;
                    e.set_item("phase_sigma_deg", g.phase_sigma_deg())?;
                    e.set_item("n_bins", g.n_bins)?;
                    e.set_item("band_hz", g.band_hz)?;
                    e.set_item("chi2_per_dof", g.chi2_per_dof)?;
                    a.set_item(axis.axis.name(), e)?;
                }
            }
            d.set_item(ob.observable.name(), a)?;
        }
        Ok(d)
    }

    /// Confidence level of the intervals and thresholds.
    #[getter]
    fn confidence(&self) -> f64 {
        self.report().confidence
    }

    /// Ordinary coherence that noise alone exceeds with probability ``1 - confidence``.
    #[getter]
    fn coherence_threshold(&self) -> f64 {
        self.report().coherence_threshold
    }

    /// The same for the multiple coherence with every axis.
    #[getter]
    fn multiple_coherence_threshold(&self) -> f64 {
        self.report().multiple_coherence_threshold
    }

    /// The tilt reader's notes, then the analysis's.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.outcome
            .inputs
            .tilt
            .notes
            .iter()
            .chain(&self.report().notes)
            .cloned()
            .collect()
    }

    /// The report as the command line's CSV (``docs/schemas.md``).
    fn to_csv(&self) -> String {
        self.outcome.csv()
    }

    /// Writes the report as the command line's ``--save`` does: ``.h5``/``.hdf5`` (schema
    /// ``tiltnoise.coherence``, with the parameters and the records' provenance), ``.csv``,
    /// or the command line's figure as ``.png`` or ``.svg`` (per observable, the coherence
    /// with each axis against the noise threshold and the measured transfer functions with
    /// their confidence band beside the model's: the same image as ``tiltnoise coherence
    /// --save x.png`` for the same records); atomically. Raises ``OSError`` if it cannot be
    /// written or is one of the files read, ``ValueError`` for another extension.
    fn save(&self, py: Python<'_>, #[pyo3(from_py_with = kw::path)] path: PathBuf) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, tiltnoise_job::coherence::OUTPUT_KINDS).py()?;
        self.inputs.check_save(&path)?;
        py.detach(|| Staging::committed(|stage| self.outcome.save(stage, &path)))
            .map_err(job_args::job_error)
    }

    /// ``{"coherence": {observable: {axis: FrequencySeries}}, "multiple_coherence":
    /// {observable: FrequencySeries}, "transfer": {observable: {axis: FrequencySeries}},
    /// "transfer_radius": ..., "model": ..., "psd": {observable: FrequencySeries}}``: the
    /// attributes of the same names as ``gwpy.frequencyseries.FrequencySeries`` on
    /// ``frequency_hz``, named ``"OBS.AXIS.coherence"``, ``"OBS.psd"``, ..., with their
    /// units (coherences dimensionless, transfer functions complex in ``units``, PSDs in
    /// unit**2/Hz). Needs gwpy (``pip install gwpy``); raises ``ImportError`` saying so
    /// without it.
    fn to_gwpy<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        crate::python_side::call(slf.as_any(), "_convert", "coherence_to_gwpy", &[])
    }

    /// The report as a ``pandas.DataFrame`` indexed by ``frequency_hz``, one column per
    /// ``"OBS.psd"``, ``"OBS.multiple_coherence"`` and ``"OBS.AXIS.coherence"``,
    /// ``"OBS.AXIS.transfer"`` (complex), ``"OBS.AXIS.transfer_radius"``,
    /// ``"OBS.AXIS.model"`` (complex), the unit of each column in ``df.attrs["units"]``.
    /// Needs pandas (``pip install pandas``); raises ``ImportError`` saying so without it.
    fn to_pandas<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        crate::python_side::call(slf.as_any(), "_convert", "coherence_to_pandas", &[])
    }

    /// The report drawn with matplotlib: per observable, the ordinary coherence with each
    /// axis and the multiple coherence against their noise thresholds, and the magnitude of
    /// each measured transfer function with its confidence band beside the model's, log-log.
    /// Returns a new ``matplotlib.figure.Figure`` (of ``matplotlib.pyplot``). Needs
    /// matplotlib; raises ``ImportError`` saying so without it. The command line's own figure
    /// is :meth:`save` to a ``.png`` or ``.svg`` path.
    fn plot<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        crate::python_side::call(slf.as_any(), "_plots", "coherence_plot", &[])
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<crate::state::Reduced<'py>> {
        crate::state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        crate::state::load("Coherence", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        crate::state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        format!(
            "Coherence({} bins of {} vs {}; axes {}; observables {})",
            self.report().freqs_hz.len(),
            self.outcome.inputs.measured_path,
            self.outcome.inputs.tilt.path,
            self.axes().join(", "),
            self.observables().join(", ")
        )
    }
}
