//! `tiltnoise.budget` (arrays) and `tiltnoise.budget_from_file` (the command line's `budget
//! --tilt FILE`), and the `Budget` they return.

use crate::args::{self, kw};
use crate::arrays::{self, check_size, series};
use crate::errors::{value_error, PyResultExt};
use crate::inputs::Inputs;
use crate::interrupt;
use crate::job_args;
use crate::model::PyModel;
use crate::params::PyParams;
use crate::python_side;
use crate::spectral::{averaging, SERIES};
use crate::state;
use numpy::{PyArray1, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;
use std::sync::Arc;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::freq;
use tiltnoise_core::input::GapPolicy;
use tiltnoise_core::model::{Input, Model, Observable};
use tiltnoise_core::noise::equivalent::referred_terms;
use tiltnoise_core::noise::SpectralSource;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options::parse_keyed_items;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::refuse_repeats;
use tiltnoise_job::budget::{
    array_input, ArrayOptions, ArrayRecord, BudgetOutcome, BudgetRequest, SaveOptions, TiltSource,
    WelchRequest,
};
use tiltnoise_job::files::Staging;
use tiltnoise_job::{Invocation, Outcome, Silent};

/// The model of `params`: a `Model` (reused as it is), a `Params`, or Table I for `None`; and
/// its parameters (with the file they were read from).
pub(crate) fn model_of(params: Option<&Bound<'_, PyAny>>) -> PyResult<(Arc<Model>, PyParams)> {
    let Some(p) = params else {
        let params = Params::table_i();
        return Ok((
            Arc::new(Model::new(&params).py()?),
            PyParams::unread(params),
        ));
    };
    if let Ok(m) = p.cast::<PyModel>() {
        let m = m.get();
        let params = PyParams {
            inner: m.model.params().clone(),
            file: m.params_file.clone(),
        };
        return Ok((Arc::clone(&m.model), params));
    }
    let params = p
        .cast::<PyParams>()
        .map_err(|_| {
            args::type_error("params", p, "a tiltnoise.Params, a tiltnoise.Model or None")
        })?
        .get()
        .clone();
    Ok((Arc::new(Model::new(&params.inner).py()?), params))
}

/// The Welch and segment options of both entry points, as on the command line.
fn welch(
    nperseg: Option<usize>,
    overlap: Option<f64>,
    average: Option<&str>,
    segment_duration: Option<f64>,
    percentiles: Option<&Bound<'_, PyAny>>,
) -> PyResult<WelchRequest> {
    Ok(WelchRequest {
        nperseg,
        overlap,
        averaging: average.map(averaging).transpose()?,
        segment_duration_s: segment_duration,
        percentiles: args::pair(
            "percentiles",
            percentiles,
            "(LOWER, UPPER) with 0 <= LOWER < UPPER <= 100",
        )?,
    })
}

/// The input of the floor of a name, or a `ValueError` naming what is allowed.
fn ground_input(name: &str) -> PyResult<Input> {
    array_input(name).map_err(job_args::job_error)
}

/// `(input, samples)` from a dict `{input: array}` or a 2-D array with `axes`, each input
/// once, the size of all of them checked before any is copied (views are read in place).
fn tilt_channels(
    tilt: &Bound<'_, PyAny>,
    axes: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<(Input, Vec<f64>)>> {
    if let Ok(d) = tilt.cast::<PyDict>() {
        if axes.is_some() {
            return Err(value_error(
                "axes: give the axes either as the keys of the tilt dict or with a 2-D array, \
                 not both",
            ));
        }
        let mut given = Vec::new();
        for (name, v) in args::entries("tilt", d, "a dict {input: array}, input theta_t .. z_t")? {
            let axis = ground_input(&name)?;
            let array = v.cast::<PyUntypedArray>().ok().map(|a| a.len());
            given.push((axis, name, v, array));
        }
        let total = given.iter().map(|g| g.3.unwrap_or(0)).sum();
        check_size("tilt", total, SERIES)?;
        return given
            .into_iter()
            .map(|(axis, name, v, _)| Ok((axis, series(&format!("tilt[{name:?}]"), &v, SERIES)?)))
            .collect();
    }
    let Some(axes) = axes else {
        return Err(value_error(
            "tilt: a 2-D array needs axes, e.g. axes=(\"theta_t\", \"eta_t\") for its rows; or \
             give a dict {\"theta_t\": ..., \"eta_t\": ...}",
        ));
    };
    let names: Vec<String> = match axes.cast::<PyString>() {
        Ok(s) => s
            .to_cow()?
            .split(',')
            .map(|n| n.trim().to_string())
            .collect(),
        Err(_) => crate::args::strings("axes", Some(axes))?.unwrap_or_default(),
    };
    let axes = names
        .iter()
        .map(|n| ground_input(n))
        .collect::<PyResult<Vec<_>>>()?;
    refuse_repeats(OptionKey::AXES, "input", &axes, |a| a.name().to_string())
        .map_err(|e| value_error(crate::errors::shown(&e)))?;
    let rows = arrays::rows("tilt", tilt, SERIES)?;
    if rows.len() != axes.len() {
        return Err(value_error(format!(
            "tilt: expected a 2-D array of shape (len(axes), n_samples) = ({}, n), got {} rows",
            axes.len(),
            rows.len()
        )));
    }
    Ok(axes.into_iter().zip(rows).collect())
}

/// Noise budget of X, phi and phi_a (or any observables) from a time series of the floor's
/// motion given as arrays.
///
/// ``tilt``: a dict ``{"theta_t": x, "eta_t": y, "x_t": a}`` of 1-D arrays, or a 2-D array
/// whose rows are the inputs named by ``axes``. The inputs are the crate's tilt angles
/// ``theta_t``, ``eta_t``, ``phi_t`` (the rotation taking the floor frame to the inertial
/// frame, so a floor rotation ``E`` about East gives ``theta_t = -E``) and the floor's
/// translations ``x_t``, ``y_t``, ``z_t`` along the lab axes. ``units``: a dict ``{input:
/// unit}``: ``rad``, ``urad``, ``rad/s``, ... for tilt, ``m``, ``m/s``, ``m/s^2`` or a
/// prefixed form for translations, which need one; tilt inputs without one are in
/// ``quantity`` (``"angle"``, rad, or ``"rate"``, rad/s), all tilt inputs in one quantity. A
/// rate's, a velocity's or an acceleration's cross-spectra become the displacement's bin by bin
/// (exact up to Nyquist, DC excluded), as for the files. With tilt and translation the budget
/// has ``ground`` (both with their cross-spectra, what adds to the total), ``tilt`` and
/// ``translation``. Translations are inertial sensors (a seismometer reads ``a_x + g eta_t``),
/// corrected with the tilt of their axis unless listed in ``corrected``; tilt inputs listed in
/// ``pendulum_tiltmeter`` read ``eta_t + a_x / g`` and are corrected with the translation.
/// A tilt input whose unit is not given is refused when its detrended RMS exceeds 1e-2 rad (an
/// angle; ``pi fs`` times that for a rate), which no laboratory floor reaches: its values are
/// then likely in urad or nrad. ``fs``: sample rate (Hz). ``gaps``: ``"reject"``
/// (default) or ``"interpolate"`` non-finite samples.
///
/// The other options are the command line's ``budget`` options: ``nperseg`` (Welch segment,
/// default 2**14 or the largest power of two <= n/4), ``overlap`` (fraction, default 0.5),
/// ``average`` (``"mean"``/``"median"``), ``segment_duration`` (s) and ``percentiles``
/// (default (10, 90)) for the per-segment band; ``observables`` (names, default ``["X",
/// "phi", "phi_a"]``; any of X, Y, Z, theta, eta, phi, phi_a); ``readout`` (``{observable:
/// ASD}`` white, in the observable's unit/sqrt(Hz), or ``{observable: path}`` coloured, a CSV
/// ``frequency_hz,OBS`` or HDF5 ASD file covering the budget's band; over the default
/// ``{"X": 9e-9}`` m/sqrt(Hz); 0 removes one); ``term`` (``{name: (source, path)}``: a
/// user-named term ``user.NAME`` added in quadrature to the total, ``source`` an observable,
/// whose ASD the file holds, or an input of the model, ``theta_t`` .. ``z_t``, ``F_a.x`` ..
/// ``M_b.z``, whose ASD the file holds and which is propagated through the transfer
/// functions); ``witness_noise`` (``{input: ASD or path}`` or ``{input: (ASD or path,
/// rel)}``: the own noise of the tiltmeter or seismometer that recorded an input, in its
/// unit/sqrt(Hz), shown through the model as ``witness_noise`` beside the tilt term, which
/// already contains it; not added to the total); ``measured`` (a file of measured ASDs or
/// series of the observables: adds the
/// terms ``measured`` and ``residual``); ``at`` (frequencies, Hz, to read the budget at, each
/// in its band; default 1e-3, 2e-3, 5e-3 where they are) and ``at_band`` (half-width of the
/// Welch band means, relative, default 0.1): :attr:`Budget.summary`.
/// ``params``: a :class:`Params` or a :class:`Model` (default Table I).
///
/// Returns a :class:`Budget`. Raises ``ValueError`` for options or data that do not fit.
#[pyfunction]
#[pyo3(signature = (tilt, fs, *, axes=None, quantity=String::from("angle"), units=None, corrected=None, pendulum_tiltmeter=None, gaps=String::from("reject"), params=None, nperseg=None, overlap=None, average=None, segment_duration=None, percentiles=None, observables=None, readout=None, term=None, witness_noise=None, measured=None, at=None, at_band=None), text_signature = "(tilt, fs, *, axes=None, quantity='angle', units=None, corrected=None, pendulum_tiltmeter=None, gaps='reject', params=None, nperseg=None, overlap=None, average=None, segment_duration=None, percentiles=None, observables=None, readout=None, term=None, witness_noise=None, measured=None, at=None, at_band=None)")]
#[allow(clippy::too_many_arguments)]
pub fn budget(
    py: Python<'_>,
    tilt: &Bound<'_, PyAny>,
    #[pyo3(from_py_with = kw::fs)] fs: f64,
    axes: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::quantity)] quantity: String,
    #[pyo3(from_py_with = kw::units)] units: Option<std::collections::BTreeMap<String, String>>,
    corrected: Option<&Bound<'_, PyAny>>,
    pendulum_tiltmeter: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::gaps)] gaps: String,
    params: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::nperseg)] nperseg: Option<usize>,
    #[pyo3(from_py_with = kw::overlap)] overlap: Option<f64>,
    #[pyo3(from_py_with = kw::average)] average: Option<String>,
    #[pyo3(from_py_with = kw::segment_duration)] segment_duration: Option<f64>,
    percentiles: Option<&Bound<'_, PyAny>>,
    observables: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::readout)] readout: Option<Bound<'_, PyDict>>,
    #[pyo3(from_py_with = kw::term)] term: Option<Bound<'_, PyDict>>,
    #[pyo3(from_py_with = kw::witness_noise)] witness_noise: Option<Bound<'_, PyDict>>,
    #[pyo3(from_py_with = kw::measured)] measured: Option<PathBuf>,
    at: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::at_band)] at_band: Option<f64>,
) -> PyResult<Budget> {
    let channels_of = job_args::ChannelLists::of(corrected, pendulum_tiltmeter)?;
    let at = args::numbers("at", at)?;
    let (model, params) = model_of(params)?;
    let gaps: GapPolicy = gaps.parse().map_err(value_error)?;
    let channels = tilt_channels(tilt, axes)?;
    let items: Vec<String> = units
        .unwrap_or_default()
        .iter()
        .map(|(k, u)| format!("{k}={u}"))
        .collect();
    let options = ArrayOptions {
        quantity: quantity.parse().map_err(value_error)?,
        units: parse_keyed_items(OptionKey::UNITS, "channel", &items).py()?,
        corrected: channels_of.corrected,
        pendulum_tiltmeter: channels_of.pendulum_tiltmeter,
        gaps,
    };
    let record = ArrayRecord::new(fs, channels, options).map_err(job_args::job_error)?;
    let welch = welch(
        nperseg,
        overlap,
        average.as_deref(),
        segment_duration,
        percentiles,
    )?;
    let observables = job_args::observables(observables)?;
    let readout = job_args::readout(readout.as_ref())?;
    let terms = job_args::terms(term.as_ref())?;
    let witness_noise = job_args::witness_noise(witness_noise.as_ref())?;
    let cancel = Cancel::new();
    let result = interrupt::watch(py, &cancel, || -> PyResult<(BudgetOutcome, Inputs)> {
        let req = BudgetRequest {
            model: &model,
            tilt: TiltSource::Arrays(record),
            welch,
            freq_hz: None,
            observables,
            readout,
            terms,
            witness_noise,
            measured,
            at_hz: at,
            at_band,
            invocation: Invocation::of_this_process(),
        };
        let inputs = Inputs::of_params(params.file.as_deref())
            .with_all(job_args::python_names(req.input_files(), &[]));
        let result = tiltnoise_job::budget::run(req, &cancel, &Silent);
        Ok((result.map_err(job_args::job_error)?, inputs))
    })?;
    let (outcome, inputs) = result;
    Ok(Budget {
        outcome,
        params,
        inputs,
    })
}

/// Noise budget of X, phi and phi_a (or any observables) from a tilt file (the command line's
/// ``tiltnoise budget --tilt FILE``): HDF5 (``FILE.h5:/group`` addresses gwpy layouts), CSV or
/// miniSEED time series (angle or rate) or spectra, as described in
/// ``docs/input_formats.md``; an HDF5 series is streamed from disk in bounded memory.
///
/// ``axes`` is the axis map (``"theta_t=-E,eta_t=-N"`` or ``"theta_t=-LJE,x_t=LHE"``; default
/// from the file, else that for rotation channels and ``x_t=E``, ``y_t=N``, ``z_t=Z`` for
/// translation channels), ``quantity`` ``"angle"``/``"rate"`` of the tilt channels (default
/// from the file, else angle), ``units`` a dict ``{channel: unit}`` for files that do not state
/// them (``"rad/s"``, ``"m/s^2"``, ...; translation channels need one, and a unit the file
/// states must agree), ``corrected`` the translation channels whose tilt is removed already,
/// ``pendulum_tiltmeter`` the tilt channels read by a pendulum tiltmeter (see :func:`budget`),
/// ``gaps`` ``"reject"``/``"interpolate"``, ``scale`` a dict ``{channel: factor}`` (SI units
/// per count, required for channels in counts, applied before the axis map); ``freq`` is the
/// model grid of spectra input (``"FLO:N:FHI"`` or an array of Hz; default 1e-4..30 Hz plus
/// points around every resonance). The Welch, segment, observables, readout, term,
/// witness_noise, measured and ``at`` options are those of :func:`budget`; options of a series are refused for spectra
/// and ``freq`` for a series, as on the command line.
///
/// Raises ``FileNotFoundError``/``OSError`` if a file cannot be read, :class:`InputFileError`
/// (an ``OSError``) if it is not a valid input (the message names the file, the dataset
/// or column and what is allowed), ``ValueError`` for options that do not fit.
#[pyfunction]
#[pyo3(signature = (path, *, axes=None, quantity=None, units=None, corrected=None, pendulum_tiltmeter=None, gaps=None, params=None, nperseg=None, overlap=None, average=None, segment_duration=None, percentiles=None, observables=None, readout=None, term=None, witness_noise=None, freq=None, measured=None, scale=None, at=None, at_band=None))]
#[allow(clippy::too_many_arguments)]
pub fn budget_from_file(
    py: Python<'_>,
    #[pyo3(from_py_with = kw::path)] path: PathBuf,
    #[pyo3(from_py_with = kw::axes)] axes: Option<String>,
    #[pyo3(from_py_with = kw::quantity)] quantity: Option<String>,
    #[pyo3(from_py_with = kw::units)] units: Option<std::collections::BTreeMap<String, String>>,
    corrected: Option<&Bound<'_, PyAny>>,
    pendulum_tiltmeter: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::gaps)] gaps: Option<String>,
    params: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::nperseg)] nperseg: Option<usize>,
    #[pyo3(from_py_with = kw::overlap)] overlap: Option<f64>,
    #[pyo3(from_py_with = kw::average)] average: Option<String>,
    #[pyo3(from_py_with = kw::segment_duration)] segment_duration: Option<f64>,
    percentiles: Option<&Bound<'_, PyAny>>,
    observables: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::readout)] readout: Option<Bound<'_, PyDict>>,
    #[pyo3(from_py_with = kw::term)] term: Option<Bound<'_, PyDict>>,
    #[pyo3(from_py_with = kw::witness_noise)] witness_noise: Option<Bound<'_, PyDict>>,
    freq: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::measured)] measured: Option<PathBuf>,
    #[pyo3(from_py_with = kw::scale)] scale: Option<std::collections::BTreeMap<String, f64>>,
    at: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::at_band)] at_band: Option<f64>,
) -> PyResult<Budget> {
    let channels_of = job_args::ChannelLists::of(corrected, pendulum_tiltmeter)?;
    let at = args::numbers("at", at)?;
    let (model, params) = model_of(params)?;
    let read = job_args::file_read_request(axes, quantity, units, channels_of, gaps, scale)?;
    let freq_hz = match freq {
        None => None,
        Some(f) => Some(match f.cast::<PyString>() {
            Ok(spec) => freq::parse_spec(&spec.to_cow()?).py()?,
            Err(_) => crate::grid::frequencies(f, crate::grid::GRID)?,
        }),
    };
    let req = BudgetRequest {
        model: &model,
        tilt: TiltSource::File { path, read },
        welch: welch(
            nperseg,
            overlap,
            average.as_deref(),
            segment_duration,
            percentiles,
        )?,
        freq_hz,
        observables: job_args::observables(observables)?,
        readout: job_args::readout(readout.as_ref())?,
        terms: job_args::terms(term.as_ref())?,
        witness_noise: job_args::witness_noise(witness_noise.as_ref())?,
        measured,
        at_hz: at,
        at_band,
        invocation: Invocation::of_this_process(),
    };
    let inputs = Inputs::of_params(params.file.as_deref()).with_all(job_args::python_names(
        req.input_files(),
        &[("tilt", "path")],
    ));
    let cancel = Cancel::new();
    let outcome = interrupt::watch(py, &cancel, || {
        tiltnoise_job::budget::run(req, &cancel, &Silent).map_err(job_args::job_error)
    })?;
    Ok(Budget {
        outcome,
        params,
        inputs,
    })
}

/// A noise budget: one-sided spectra of each observable's terms on one frequency grid.
///
/// ``freq_hz`` (Hz); ``terms[observable][term]`` and ``total[observable]`` are ASDs in
/// ``units[observable]`` (``m/sqrt(Hz)`` for X, ``rad/sqrt(Hz)`` for phi and phi_a); the
/// names are those of the budget files (``tilt``, ``tilt.eta_t``, ``translation``,
/// ``translation.x_t``, ``ground``, ``readout``, ``thermal``, ``thermal.torsion_b``,
/// ``measured``, ``residual``; ``total`` is the sum in power of ``ground`` (or ``tilt`` or
/// ``translation`` when the record has one kind only), ``thermal`` and ``readout``). :meth:`psd` gives the PSDs; ``equivalent`` the
/// terms referred to the test mass's acceleration (X) or torque (phi, phi_a) for a damped
/// model; ``segment_bands`` the per-segment percentile band of the ``tilt`` term.
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Budget {
    /// The job's outcome: the report, the input's provenance and the run's.
    outcome: BudgetOutcome,
    params: PyParams,
    /// The files read: no `save` may replace one.
    inputs: Inputs,
}

impl Budget {
    fn observable(&self, name: &str) -> PyResult<&tiltnoise_core::noise::ObservableBudget> {
        let observables: Vec<&str> = self
            .outcome
            .report
            .budget
            .observables
            .iter()
            .map(|o| o.observable.name())
            .collect();
        Observable::from_name(name)
            .and_then(|o| self.outcome.report.budget.observable(o))
            .ok_or_else(|| {
                pyo3::exceptions::PyKeyError::new_err(format!(
                    "observable {name:?} is not in the budget; it has {}",
                    observables.join(", ")
                ))
            })
    }

    fn psd_of(&self, observable: &str, term: &str) -> PyResult<Vec<f64>> {
        let ob = self.observable(observable)?;
        if term == tiltnoise_core::noise::TOTAL_NAME {
            return Ok(ob.total());
        }
        ob.term_named(term).map(|t| t.psd.clone()).ok_or_else(|| {
            let names: Vec<String> = ob.components().iter().map(|(c, _)| c.name()).collect();
            pyo3::exceptions::PyKeyError::new_err(format!(
                "term {term:?} is not in the budget of {observable}; it has {}",
                names.join(", ")
            ))
        })
    }
}

fn asd<'py>(py: Python<'py>, psd: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_iter(py, psd.iter().map(|p| p.sqrt()))
}

/// The ASD of `psd` as a read-only array (the budget's values, not a place to change them).
fn fixed_asd<'py>(py: Python<'py>, psd: &[f64]) -> PyResult<Bound<'py, PyArray1<f64>>> {
    arrays::read_only(asd(py, psd))
}

/// `d` as a read-only mapping (`types.MappingProxyType`): assigning to a key raises
/// `TypeError` instead of changing a copy that the budget never sees.
fn read_only_dict<'py>(d: Bound<'py, PyDict>) -> PyResult<Bound<'py, PyAny>> {
    let py = d.py();
    py.import("types")?.getattr("MappingProxyType")?.call1((d,))
}

#[pymethods]
impl Budget {
    /// Frequencies (Hz), increasing, all > 0: the files' ``frequency_hz`` (read-only).
    #[getter]
    fn frequency_hz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        arrays::read_only(PyArray1::from_slice(
            py,
            &self.outcome.report.budget.freqs_hz,
        ))
    }

    /// The same as ``frequency_hz`` (the name of ``transfer``'s argument).
    #[getter]
    fn freq_hz<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.frequency_hz(py)
    }

    /// The observables, in report order (``X``, ``phi``, ``phi_a``).
    #[getter]
    fn observables(&self) -> Vec<&'static str> {
        self.outcome
            .report
            .budget
            .observables
            .iter()
            .map(|o| o.observable.name())
            .collect()
    }

    /// ``{observable: {term: ASD}}``, every term in report order (not the total). Read-only,
    /// mappings and arrays: a budget is a result, and an edit would change a copy it never
    /// sees (a different budget is computed anew; ``np.array(...)`` copies an ASD to work on).
    #[getter]
    fn terms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = PyDict::new(py);
        for ob in &self.outcome.report.budget.observables {
            let t = PyDict::new(py);
            for term in &ob.terms {
                t.set_item(term.name(), fixed_asd(py, &term.psd)?)?;
            }
            d.set_item(ob.observable.name(), read_only_dict(t)?)?;
        }
        read_only_dict(d)
    }

    /// ``{observable: ASD}`` of the total: the sum in power of tilt, thermal and readout
    /// (read-only, as ``terms``).
    #[getter]
    fn total<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let d = PyDict::new(py);
        for ob in &self.outcome.report.budget.observables {
            d.set_item(ob.observable.name(), fixed_asd(py, &ob.total())?)?;
        }
        read_only_dict(d)
    }

    /// ``{observable: unit of its ASDs}``: ``m/sqrt(Hz)`` or ``rad/sqrt(Hz)``.
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for ob in &self.outcome.report.budget.observables {
            d.set_item(
                ob.observable.name(),
                format!("{}/sqrt(Hz)", ob.observable.unit()),
            )?;
        }
        Ok(d)
    }

    /// One-sided PSD of a term (or ``"total"``) of an observable, (unit)**2/Hz.
    #[pyo3(signature = (observable, term=String::from("total")), text_signature = "($self, observable, term='total')")]
    fn psd<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = kw::observable)] observable: String,
        #[pyo3(from_py_with = kw::term)] term: String,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(PyArray1::from_vec(py, self.psd_of(&observable, &term)?))
    }

    /// ASD of a term (or ``"total"``) of an observable, unit/sqrt(Hz).
    #[pyo3(signature = (observable, term=String::from("total")), text_signature = "($self, observable, term='total')")]
    fn asd<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = kw::observable)] observable: String,
        #[pyo3(from_py_with = kw::term)] term: String,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(asd(py, &self.psd_of(&observable, &term)?))
    }

    /// For a damped model, ``{observable: {"input", "unit", "quantity", "response_abs",
    /// "terms": {term: ASD}}}``: every model term (and ``total``) referred to the test mass's
    /// acceleration along x (X; ``m s^-2/sqrt(Hz)``) or torque about z (phi, phi_a;
    /// ``N m/sqrt(Hz)``). Empty for an undamped model.
    #[getter]
    fn equivalent<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for ob in &self.outcome.report.budget.observables {
            let Some(r) = referred_terms(ob) else {
                continue;
            };
            let e = PyDict::new(py);
            e.set_item("input", r.input)?;
            e.set_item("unit", format!("{}/sqrt(Hz)", r.unit))?;
            e.set_item("quantity", r.quantity)?;
            e.set_item("response_abs", asd(py, r.response_psd))?;
            let t = PyDict::new(py);
            for (c, psd) in &r.terms {
                t.set_item(c.name(), asd(py, psd))?;
            }
            e.set_item("terms", t)?;
            d.set_item(ob.observable.name(), e)?;
        }
        Ok(d)
    }

    /// With ``segment_duration``: ``{observable: {"term" (``tilt``, ``translation`` or
    /// ``ground``: the floor's term of the total), "median", "lower", "upper" (its ASDs across
    /// segments), "lower_pct", "upper_pct", "n_segments"}}``; else empty.
    #[getter]
    fn segment_bands<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (o, band) in &self.outcome.report.segment_bands {
            let b = PyDict::new(py);
            b.set_item("term", band.term.name())?;
            b.set_item("median", asd(py, &band.median))?;
            b.set_item("lower", asd(py, &band.lower))?;
            b.set_item("upper", asd(py, &band.upper))?;
            b.set_item("lower_pct", band.lower_pct)?;
            b.set_item("upper_pct", band.upper_pct)?;
            b.set_item("n_segments", band.n_segments)?;
            d.set_item(o.name(), b)?;
        }
        Ok(d)
    }

    /// Segment length (s) of ``segment_bands``, or ``None``.
    #[getter]
    fn segment_duration_s(&self) -> Option<f64> {
        self.outcome.report.segment_duration_s
    }

    /// How the tilt spectra were obtained: ``{"source": "welch", "sample_rate_hz",
    /// "segment_len", "overlap", "averaging", "n_welch_segments", "n_samples"}`` or
    /// ``{"source": "spectra", "data_band_hz"}`` (the attributes of the budget's HDF5 file).
    #[getter]
    fn source<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        match &self.outcome.report.source {
            SpectralSource::Welch {
                sample_rate_hz,
                segment_len,
                overlap,
                averaging,
                n_welch_segments,
                n_samples,
            } => {
                d.set_item("source", "welch")?;
                d.set_item("sample_rate_hz", sample_rate_hz)?;
                d.set_item("segment_len", segment_len)?;
                d.set_item("overlap", overlap)?;
                d.set_item("averaging", averaging)?;
                d.set_item("n_welch_segments", n_welch_segments)?;
                d.set_item("n_samples", n_samples)?;
            }
            SpectralSource::Spectra { data_band_hz } => {
                d.set_item("source", "spectra")?;
                d.set_item("data_band_hz", data_band_hz)?;
            }
        }
        Ok(d)
    }

    /// The tilt axes that entered the budget.
    #[getter]
    fn axes(&self) -> Vec<&'static str> {
        self.outcome
            .report
            .inputs
            .iter()
            .filter(|i| matches!(i, Input::Tilt(_)))
            .map(|a| a.name())
            .collect()
    }

    /// The inputs of the floor's motion that entered the budget: tilt axes, then translations.
    #[getter]
    fn inputs(&self) -> Vec<&'static str> {
        self.outcome
            .report
            .inputs
            .iter()
            .map(|a| a.name())
            .collect()
    }

    /// ``{observable: white readout ASD}`` used (unit/sqrt(Hz)).
    #[getter]
    fn readout<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (o, a) in &self.outcome.report.readout.asd {
            d.set_item(o.name(), a)?;
        }
        Ok(d)
    }

    /// The input reader's notes, then the budget's (band restrictions, samples left out of the
    /// segments, gaps bridged).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.outcome
            .input
            .notes
            .iter()
            .chain(&self.outcome.report.notes)
            .cloned()
            .collect()
    }

    /// Where the tilt came from: ``path``, ``format``, ``kind``, ``quantity``, ``axis_map``,
    /// ``start_time`` (the ``input_*`` attributes of the budget's HDF5 file).
    #[getter]
    fn input<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let i = &self.outcome.input;
        let d = PyDict::new(py);
        d.set_item("path", &i.path)?;
        d.set_item("format", &i.format)?;
        d.set_item("kind", &i.kind)?;
        d.set_item("quantity", &i.quantity)?;
        d.set_item("axis_map", &i.axis_map)?;
        d.set_item("start_time", &i.start_time)?;
        Ok(d)
    }

    /// The budget read at the ``at`` frequencies (default 1e-3, 2e-3, 5e-3 Hz where they lie in
    /// its band), as the command line's ``budget --format json`` prints it: ``{"notes": [...],
    /// "summary": [{"frequency_hz", "band_hz", "observables": [{"observable", "asd_unit",
    /// "terms": [{"term", "group", "psd", "asd", "asd_rel_std", "evaluation", "band"}],
    /// "total": {"psd", "asd", "asd_rel_std"}}]}]}``: model terms exact at the frequency, Welch
    /// estimates the mean PSD of their bins in ``band_hz`` with their 1-sigma relative error
    /// (``None`` where unknown).
    #[getter]
    fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text =
            serde_json::to_string(&self.outcome.json()).map_err(|e| value_error(e.to_string()))?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// The parameters of the model the budget was computed with.
    #[getter]
    fn params(&self) -> PyParams {
        self.params.clone()
    }

    /// The budget as the command line's CSV (``#`` lines ending with ``# units:``, then ASD
    /// columns ``OBS.TERM``; ``docs/schemas.md``): columns that are zero at every frequency
    /// are left out and named in a ``# note:`` line unless ``keep_zero_columns``.
    #[pyo3(signature = (*, keep_zero_columns=false))]
    fn to_csv(
        &self,
        #[pyo3(from_py_with = kw::keep_zero_columns)] keep_zero_columns: bool,
    ) -> PyResult<String> {
        self.outcome.csv(keep_zero_columns).map_err(value_error)
    }

    /// Writes the budget as the command line's ``--save`` does: ``.h5``/``.hdf5`` (schema
    /// ``tiltnoise.budget``, with the parameters and the input's provenance), ``.csv``, or the
    /// command line's figure as ``.png`` or ``.svg`` (one panel per observable, the same
    /// image as ``tiltnoise budget --save x.png`` for the same budget); atomically (nothing
    /// is left at ``path`` on failure). Raises ``OSError`` if it cannot be written or is one
    /// of the files the budget was computed from (the tilt file, the measured record, the
    /// parameter file; compared as files, whatever the spelling), ``ValueError`` for another
    /// extension. ``keep_zero_columns``: as ``to_csv``.
    #[pyo3(signature = (path, *, keep_zero_columns=false))]
    fn save(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = kw::path)] path: PathBuf,
        #[pyo3(from_py_with = kw::keep_zero_columns)] keep_zero_columns: bool,
    ) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, tiltnoise_job::budget::OUTPUT_KINDS).py()?;
        self.inputs.check_save(&path)?;
        let options = SaveOptions {
            keep_zero_columns,
            ..SaveOptions::default()
        };
        py.detach(|| Staging::committed(|stage| self.outcome.save_with(stage, &path, &options)))
            .map_err(job_args::job_error)
    }

    /// ``{observable: {term: gwpy.frequencyseries.FrequencySeries}}`` of the ASDs, ``total``
    /// included, each named ``"OBS.TERM"`` with its unit (``m / Hz(1/2)``). Needs gwpy
    /// (``pip install gwpy``); raises ``ImportError`` saying so without it.
    fn to_gwpy<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_convert", "budget_to_gwpy", &[])
    }

    /// The ASDs as a ``pandas.DataFrame`` indexed by ``frequency_hz``, one column per
    /// ``"OBS.TERM"`` (the CSV's columns, ``OBS.total`` included), the unit of each column in
    /// ``df.attrs["units"]``. Needs pandas (``pip install pandas``); raises ``ImportError``
    /// saying so without it.
    fn to_pandas<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_convert", "budget_to_pandas", &[])
    }

    /// The budget drawn with matplotlib: one panel per observable, every term and the total
    /// (thick black) against frequency, log-log. Returns a new ``matplotlib.figure.Figure``
    /// (of ``matplotlib.pyplot``, so a notebook shows it). ``observables``: the panels (default
    /// every observable). Needs matplotlib; raises ``ImportError`` saying so without it. The
    /// command line's own figure is :meth:`save` to a ``.png`` or ``.svg`` path.
    #[pyo3(signature = (observables=None))]
    fn plot<'py>(
        slf: &Bound<'py, Self>,
        observables: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let observables = crate::args::names("observables", observables)?;
        let observables = observables.into_pyobject(slf.py())?.into_any();
        python_side::call(slf.as_any(), "_plots", "budget_plot", &[observables])
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        state::load("Budget", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        let b = &self.outcome.report.budget;
        let (lo, hi) = (
            b.freqs_hz.first().copied().unwrap_or(f64::NAN),
            b.freqs_hz.last().copied().unwrap_or(f64::NAN),
        );
        let obs: Vec<String> = b
            .observables
            .iter()
            .map(|o| {
                format!(
                    "{} [{}]",
                    o.observable.name(),
                    o.terms
                        .iter()
                        .map(|t| t.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })
            .collect();
        format!(
            "Budget({} frequencies {lo:.4e}..{hi:.4e} Hz from {}; {})",
            b.freqs_hz.len(),
            self.outcome.input.path,
            obs.join("; ")
        )
    }
}
