//! `tiltnoise.subtract` (the command line's `subtract --tilt FILE --measured FILE`) and the
//! `Subtraction` it returns: the subtract job's fit, report and cleaned record.

use crate::budget::model_of;
use crate::errors::{value_error, PyResultExt};
use crate::inputs::Inputs;
use crate::job_args;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::collections::BTreeMap;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::model::Input;
use tiltnoise_core::options;
use tiltnoise_core::repeats::refuse_repeats;
use tiltnoise_io::OutputError;
use tiltnoise_job::subtract::{SubtractOutcome, SubtractRequest};

/// The band of the residual summaries when none is given (Hz), as on the command line.
const REPORT_BAND_HZ: (f64, f64) = (3e-3, 3e-2);

/// `option=(lo, hi)`: finite with `0 < lo < hi` (Hz).
fn band(option: &str, band: Option<(f64, f64)>) -> PyResult<Option<(f64, f64)>> {
    match band {
        Some((lo, hi)) if !(lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi) => {
            Err(value_error(format!(
                "{option} ({lo}, {hi}): expected (FLO, FHI) in Hz with 0 < FLO < FHI, e.g. \
                 (3e-3, 3e-2)"
            )))
        }
        other => Ok(other),
    }
}

/// `colocated_ratio`: `{input: R}`, each a floor input with a finite R > 0.
fn parse_colocated_ratio(ratios: BTreeMap<String, f64>) -> PyResult<Vec<(Input, f64)>> {
    ratios
        .into_iter()
        .map(|(name, r)| {
            let input = Input::from_name(&name)
                .filter(|i| i.is_ground())
                .ok_or_else(|| {
                    value_error(format!(
                        "colocated_ratio {name}=...: `{name}` is not a floor input of the model; \
                         allowed: theta_t, eta_t, phi_t, x_t, y_t, z_t"
                    ))
                })?;
            if !(r.is_finite() && r > 0.0) {
                return Err(value_error(format!(
                    "colocated_ratio {name}={r}: the ratio is not allowed: must be finite and > 0"
                )));
            }
            Ok((input, r))
        })
        .collect()
}

/// Fits the coupling of the floor's motion into the measured observables and removes the
/// tilt part: the command line's ``tiltnoise subtract --tilt TILT --measured MEASURED``.
///
/// ``tilt``: the record of the floor's motion (the witness; HDF5, CSV or miniSEED time series
/// of tilt and translation), read with ``axes``, ``quantity``, ``units``, ``corrected``,
/// ``pendulum_tiltmeter``, ``gaps`` and ``scale`` as :func:`budget_from_file` reads it.
/// ``measured``: the time series of the observables (HDF5 as ``simulate`` writes it, or CSV
/// ``time_s,X,...`` in m, rad); ``observables`` selects some (default: all).
/// ``fit``: parameter-file keys fitted besides a gain per witness input and the delay;
/// ``band``: ``(FLO, FHI)`` Hz of the fit (default: chosen from the records);
/// ``report_band``: ``(FLO, FHI)`` Hz of the residual summaries (default (3e-3, 3e-2));
/// ``nperseg``: Welch segment; ``holdout``: fraction of the overlap held out at its end, in
/// (0, 0.5] (default 0.25); ``max_delay``: largest delay searched (s).
/// ``witness_noise``: ``{input: ASD | path | (ASD or path, rel)}``, the witness's own noise
/// (one-sided ASD in the input's unit/sqrt(Hz)); ``colocated``: paths of one or two records of
/// instruments beside the witness (huddle test, three-cornered hat); ``colocated_ratio``:
/// ``{input: R}``, the co-located noise ASD over the witness's (huddle test);
/// ``readout``: ``{observable: ASD}``, white readout the cleaned residual is compared with.
/// ``params``: a :class:`Params` or :class:`Model`.
///
/// Returns a :class:`Subtraction`. Raises ``FileNotFoundError``/``OSError`` if a file cannot
/// be read, :class:`InputFileError` if it is not a valid record, ``ValueError`` for options or
/// records the subtraction refuses.
#[pyfunction]
#[pyo3(signature = (tilt, measured, *, fit=None, band=None, report_band=None, nperseg=None, holdout=0.25, max_delay=None, witness_noise=None, colocated=None, colocated_ratio=None, readout=None, observables=None, axes=None, quantity=None, gaps=None, scale=None, units=None, corrected=None, pendulum_tiltmeter=None, params=None))]
#[allow(clippy::too_many_arguments)]
pub fn subtract(
    py: Python<'_>,
    tilt: PathBuf,
    measured: PathBuf,
    fit: Option<Vec<String>>,
    band: Option<(f64, f64)>,
    report_band: Option<(f64, f64)>,
    nperseg: Option<usize>,
    holdout: f64,
    max_delay: Option<f64>,
    witness_noise: Option<&Bound<'_, PyDict>>,
    colocated: Option<Vec<PathBuf>>,
    colocated_ratio: Option<BTreeMap<String, f64>>,
    readout: Option<BTreeMap<String, f64>>,
    observables: Option<&Bound<'_, PyAny>>,
    axes: Option<&str>,
    quantity: Option<&str>,
    gaps: Option<&str>,
    scale: Option<BTreeMap<String, f64>>,
    units: Option<BTreeMap<String, String>>,
    corrected: Option<Vec<String>>,
    pendulum_tiltmeter: Option<Vec<String>>,
    params: Option<&Bound<'_, PyAny>>,
) -> PyResult<Subtraction> {
    let (model, params) = model_of(params)?;
    let fit = fit.unwrap_or_default();
    refuse_repeats("fit", "parameter key", &fit, |k| k.clone())
        .map_err(|e| value_error(e.to_string()))?;
    let readout_asd = readout
        .unwrap_or_default()
        .into_iter()
        .map(|(name, asd)| options::readout_item("readout", &name, asd).py())
        .collect::<PyResult<Vec<_>>>()?;
    let req = SubtractRequest {
        model: &model,
        tilt,
        read: job_args::file_read_request(
            axes,
            quantity,
            units,
            corrected,
            pendulum_tiltmeter,
            gaps,
            scale,
        )?,
        measured,
        observables: job_args::observables(observables)?,
        colocated: colocated.unwrap_or_default(),
        colocated_ratio: parse_colocated_ratio(colocated_ratio.unwrap_or_default())?,
        witness_noise: job_args::witness_noise(witness_noise)?,
        readout_asd,
        fit,
        band_hz: self::band("band", band)?,
        report_band_hz: self::band("report_band", report_band)?.unwrap_or(REPORT_BAND_HZ),
        nperseg,
        holdout,
        max_delay_s: max_delay,
    };
    let inputs = Inputs::of_params(params.file.as_deref())
        .with_all(job_args::python_names(req.input_files()));
    let cancel = Cancel::new();
    let outcome = crate::interrupt::watch(py, &cancel, || {
        tiltnoise_job::subtract::run(req, &cancel).map_err(job_args::job_error)
    })?;
    Ok(Subtraction { outcome, inputs })
}

/// A subtraction: the fitted coupling (``estimates``), the report (``report``, the command
/// line's JSON report as a dict) and the cleaned record, written by ``save``.
#[pyclass(module = "tiltnoise", frozen)]
pub struct Subtraction {
    outcome: SubtractOutcome,
    /// The files read: no `save` may replace one.
    inputs: Inputs,
}

#[pymethods]
impl Subtraction {
    /// The fitted parameters, each a dict with ``name``, ``value``, ``sigma`` (``None`` when the
    /// data do not constrain it), ``unit`` and ``status`` (``fitted``, ``at_bound`` or
    /// ``not_constrained``, as in the report).
    #[getter]
    fn estimates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for e in &self.outcome.result.fit.estimates {
            let d = PyDict::new(py);
            d.set_item("name", &e.name)?;
            d.set_item("value", e.value)?;
            d.set_item("sigma", e.sigma.is_finite().then_some(e.sigma))?;
            d.set_item("unit", &e.unit)?;
            d.set_item("status", e.status.name())?;
            list.append(d)?;
        }
        Ok(list)
    }

    /// The report as ``subtract --format json`` prints it (``docs/subtract.md``), as a dict.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = self.outcome.report().to_json();
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The notes of reading the witness record.
    #[getter]
    fn input_notes(&self) -> Vec<String> {
        self.outcome.input_notes.clone()
    }

    /// Writes the cleaned record (``.h5``/``.hdf5``, what ``budget_from_file(measured=...)``
    /// reads) or the report (``.json``), as the command line's ``--save`` does. Refuses to
    /// replace an input.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        self.inputs.check_save(&path)?;
        py.detach(|| match ext.as_deref() {
            Some("h5" | "hdf5") => {
                tiltnoise_io::write_subtract_hdf5(&path, &self.outcome.result, &self.outcome.meta)
            }
            Some("json") => self.outcome.report().write(&path),
            _ => Err(OutputError::UnknownFormat {
                path: path.clone(),
                allowed: ".h5, .hdf5, .json",
            }),
        })
        .py()
    }

    fn __repr__(&self) -> String {
        let r = &self.outcome.result;
        format!(
            "Subtraction({} of {} vs {}; {} samples at {} Hz; {} estimates)",
            r.residuals
                .iter()
                .map(|s| s.observable.name())
                .collect::<Vec<_>>()
                .join(", "),
            self.outcome.meta.measured_path,
            self.outcome.tilt_path,
            r.alignment.len,
            r.alignment.fs_hz,
            r.fit.estimates.len()
        )
    }
}
