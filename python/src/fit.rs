//! `Model.fit`: the constrained least-squares fit of chosen parameters to measured mode
//! frequencies (the command line's `tiltnoise fit`).

use crate::args::kw;
use crate::errors::{value_error, PyResultExt};
use crate::inputs::Inputs;
use crate::interrupt;
use crate::job_args::job_error;
use crate::params::PyParams;
use crate::state;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::fit::{FitResult, SigmaSource};
use tiltnoise_core::params::Params;
use tiltnoise_job::files::Staging;
use tiltnoise_job::fit::{FitOutcome, FitRequest};
use tiltnoise_job::{Invocation, Outcome, Provenance, Silent};

/// What `Model.fit` measures against: the frequency file, or Table II's measured column; with
/// visibilities and no frequency file, no frequency at all (Table II belongs to the paper's
/// pendulum, not to the one whose record gave the visibilities), as on the command line.
pub struct FitInputs {
    /// `measured=`: the frequency file.
    pub measured: Option<PathBuf>,
    /// `visibility=`: the visibility file.
    pub visibility: Option<PathBuf>,
}

/// Runs the fit job on `params` (`Model.fit`).
pub fn run(
    py: Python<'_>,
    params: &Params,
    params_file: Option<&std::path::Path>,
    free: Option<Vec<String>>,
    inputs: FitInputs,
    bound_sigmas: f64,
    prior: bool,
) -> PyResult<Fit> {
    let files = Inputs::of_params(params_file)
        .with("measured", inputs.measured.as_deref())
        .with("visibility", inputs.visibility.as_deref());
    let req = FitRequest {
        params,
        measured: inputs.measured,
        visibility: inputs.visibility,
        free,
        bound_sigmas,
        prior,
        invocation: Invocation::of_this_process(),
    };
    let cancel = Cancel::new();
    let FitOutcome {
        result,
        origin,
        provenance,
    } = interrupt::watch(py, &cancel, || {
        tiltnoise_job::fit::run(&req, &cancel, &Silent).map_err(job_error)
    })?;
    Ok(Fit {
        result,
        origin,
        provenance,
        inputs: files,
    })
}

/// The result of :meth:`Model.fit` (the command line's ``fit --format json``, by the same
/// names): ``params`` (the fitted :class:`Params`), ``parameters`` and ``modes`` (lists of
/// dicts), ``chi2``, ``chi2_nominal``, ``prior_term``, ``dof``, ``singular_values``,
/// ``weak_directions``, ``iterations``, ``evaluations``, ``stop``, ``projected_gradient``,
/// ``measured_origin``.
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Fit {
    result: FitResult,
    origin: String,
    /// What the saved files record (the job's provenance).
    provenance: Provenance,
    /// The files read: no `save` may replace one.
    inputs: Inputs,
}

impl Fit {
    /// The fit as the job returned it.
    fn outcome(&self) -> FitOutcome {
        FitOutcome {
            result: self.result.clone(),
            origin: self.origin.clone(),
            provenance: self.provenance.clone(),
        }
    }
}

#[pymethods]
impl Fit {
    /// The fitted parameter set.
    #[getter]
    fn params(&self) -> PyParams {
        PyParams::unread(self.result.fitted_params.clone())
    }

    /// Per free parameter: ``key``, ``unit``, ``nominal``, ``fitted``, ``prior_sigma``,
    /// ``fitted_sigma`` (``None`` on a bound), ``at_bound`` (``"lower"``, ``"upper"`` or
    /// ``None``), ``data_sigma_rel``, ``poorly_constrained``, ``start`` (where the fit began:
    /// away from the symmetric point for an asymmetry offset).
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.result
            .params
            .iter()
            .zip(&self.result.start)
            .map(|(p, &start)| {
                let d = PyDict::new(py);
                d.set_item("key", &p.key)?;
                d.set_item("unit", &p.unit)?;
                d.set_item("nominal", p.nominal)?;
                d.set_item("fitted", p.fitted)?;
                d.set_item("prior_sigma", p.prior_sigma)?;
                d.set_item("fitted_sigma", p.fitted_sigma)?;
                d.set_item("at_bound", p.at_bound.map(|b| b.name()))?;
                d.set_item("data_sigma_rel", p.data_sigma_rel)?;
                d.set_item("poorly_constrained", p.poorly_constrained)?;
                d.set_item("start", start)?;
                Ok(d)
            })
            .collect()
    }

    /// Per measured mode: ``index``, ``measured_hz``, ``sigma_hz``, ``sigma_source``
    /// (``"file"`` or ``"digits"``), ``nominal_hz``, ``fitted_hz``, ``residual_hz``,
    /// ``residual_sigmas``.
    #[getter]
    fn modes<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.result
            .modes
            .iter()
            .map(|m| {
                let d = PyDict::new(py);
                d.set_item("index", m.measured.mode)?;
                d.set_item("measured_hz", m.measured.frequency_hz)?;
                d.set_item("sigma_hz", m.measured.sigma_hz)?;
                d.set_item(
                    "sigma_source",
                    match m.measured.sigma_source {
                        SigmaSource::File => "file",
                        SigmaSource::Digits => "digits",
                    },
                )?;
                d.set_item("nominal_hz", m.nominal_hz)?;
                d.set_item("fitted_hz", m.fitted_hz)?;
                d.set_item("residual_hz", m.residual_hz())?;
                d.set_item("residual_sigmas", m.residual_sigmas())?;
                Ok(d)
            })
            .collect()
    }

    /// Per measured visibility (the command line's ``visibilities``): ``mode``,
    /// ``observable``, ``reference``, ``measured`` (the signed ratio), ``sigma``,
    /// ``sigma_source``, ``nominal`` and ``fitted`` (the model's ratio; NaN where the reference
    /// does not see the mode), ``residual_sigmas``.
    #[getter]
    fn visibilities<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.result
            .visibilities
            .iter()
            .map(|v| {
                let d = PyDict::new(py);
                d.set_item("mode", v.measured.mode)?;
                d.set_item("observable", v.measured.observable.name())?;
                d.set_item("reference", v.measured.reference.name())?;
                d.set_item("measured", v.measured.ratio)?;
                d.set_item("sigma", v.measured.sigma)?;
                d.set_item(
                    "sigma_source",
                    match v.measured.sigma_source {
                        SigmaSource::File => "file",
                        SigmaSource::Digits => "digits",
                    },
                )?;
                d.set_item("nominal", v.nominal)?;
                d.set_item("fitted", v.fitted)?;
                d.set_item("residual_sigmas", v.residual_sigmas())?;
                Ok(d)
            })
            .collect()
    }

    /// Data chi^2 at the solution.
    #[getter]
    fn chi2(&self) -> f64 {
        self.result.chi2
    }

    /// Data chi^2 at the nominal parameters.
    #[getter]
    fn chi2_nominal(&self) -> f64 {
        self.result.chi2_nominal
    }

    /// The prior term at the solution (0 without the prior).
    #[getter]
    fn prior_term(&self) -> f64 {
        self.result.prior_term
    }

    /// Degrees of freedom.
    #[getter]
    fn dof(&self) -> usize {
        self.result.dof
    }

    /// Singular values of the data Jacobian in scaled variables, largest first.
    #[getter]
    fn singular_values(&self) -> Vec<f64> {
        self.result.singular_values.clone()
    }

    /// ``[(singular_value, {key: component})]`` of the combinations known to worse than one
    /// error bar.
    #[getter]
    fn weak_directions(&self) -> Vec<(f64, Vec<(String, f64)>)> {
        self.result
            .weak_directions
            .iter()
            .map(|w| (w.singular_value, w.direction.clone()))
            .collect()
    }

    /// Solver iterations.
    #[getter]
    fn iterations(&self) -> usize {
        self.result.iterations
    }

    /// Model evaluations.
    #[getter]
    fn evaluations(&self) -> usize {
        self.result.evaluations
    }

    /// Why the solver stopped.
    #[getter]
    fn stop(&self) -> &'static str {
        self.result.stop.describe()
    }

    /// Projected gradient of chi^2 / 2 at the solution (per error bar).
    #[getter]
    fn projected_gradient(&self) -> f64 {
        self.result.projected_gradient
    }

    /// Where the measured frequencies came from.
    #[getter]
    fn measured_origin(&self) -> &str {
        &self.origin
    }

    /// The report as the command line's ``fit --format json`` prints it (keys in alphabetical
    /// order, non-finite numbers as ``null``).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.outcome().json()).map_err(|e| value_error(e.to_string()))
    }

    /// Writes the fit as the command line's ``fit --save`` does: ``.json`` (the report of
    /// :meth:`to_json`) or ``.h5``/``.hdf5`` (schema ``tiltnoise.fit``); atomically. Raises
    /// ``OSError`` if it cannot be written or is one of the files read, ``ValueError`` for
    /// another extension.
    fn save(&self, py: Python<'_>, #[pyo3(from_py_with = kw::path)] path: PathBuf) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, tiltnoise_job::fit::OUTPUT_KINDS).py()?;
        self.inputs.check_save(&path)?;
        let fit = self.outcome();
        py.detach(|| Staging::committed(|stage| fit.save(stage, &path)))
            .map_err(job_error)
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        state::load("Fit", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        format!(
            "Fit({} parameters to {} modes of {}: chi2 {:.4} (nominal {:.4}), dof {}; {})",
            self.result.params.len(),
            self.result.modes.len(),
            self.origin,
            self.result.chi2,
            self.result.chi2_nominal,
            self.result.dof,
            self.result.stop.describe()
        )
    }
}
