//! `Model.fit`: the constrained least-squares fit of chosen parameters to measured mode
//! frequencies (the command line's `tiltnoise fit`).

use crate::errors::{value_error, InputFileError};
use crate::params::PyParams;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use tiltnoise_core::fit::{self, FitConfig, FitError, FitResult, Measured, SigmaSource};
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::refuse_repeats;

/// The measured modes: Table II's measured column, or a CSV file (`mode,frequency_hz[,sigma_hz]`).
fn measured(path: Option<PathBuf>) -> PyResult<Measured> {
    match path {
        None => Ok(Measured::table_ii()),
        Some(p) => tiltnoise_io::read_measured_modes(&p).map_err(|e| match e {
            FitError::Measured { .. } => InputFileError::new_err(e.to_string()),
            other => value_error(other.to_string()),
        }),
    }
}

/// Runs the fit of `params` (`Model.fit`).
pub fn run(
    py: Python<'_>,
    params: &Params,
    free: Option<Vec<String>>,
    measured_path: Option<PathBuf>,
    bound_sigmas: f64,
    prior: bool,
) -> PyResult<Fit> {
    let measured = measured(measured_path)?;
    if let Some(keys) = &free {
        refuse_repeats("free", "parameter key", keys, String::clone)
            .map_err(|e| value_error(e.to_string()))?;
    }
    let config = FitConfig {
        free: free.unwrap_or_else(|| FitConfig::default().free),
        bound_sigmas,
        prior,
        ..FitConfig::default()
    };
    let result = py
        .detach(|| fit::fit(params, &measured, &config))
        .map_err(|e| value_error(e.to_string()))?;
    Ok(Fit {
        result,
        origin: measured.origin,
    })
}

/// The result of :meth:`Model.fit` (the command line's ``fit --format json``, by the same
/// names): ``params`` (the fitted :class:`Params`), ``parameters`` and ``modes`` (lists of
/// dicts), ``chi2``, ``chi2_nominal``, ``prior_term``, ``dof``, ``singular_values``,
/// ``weak_directions``, ``iterations``, ``evaluations``, ``stop``, ``projected_gradient``,
/// ``measured_origin``.
#[pyclass(module = "tiltnoise", frozen)]
pub struct Fit {
    result: FitResult,
    origin: String,
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
    /// ``None``), ``data_sigma_rel``, ``poorly_constrained``.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        self.result
            .params
            .iter()
            .map(|p| {
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
