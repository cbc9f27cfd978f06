//! `tiltnoise.subtract` (the command line's `subtract --tilt FILE --measured FILE`) and the
//! `Subtraction` it returns: the subtract job's fit, report, cleaned record and figure, with
//! names and units.

use crate::args::{self, kw};
use crate::budget::model_of;
use crate::errors::PyResultExt;
use crate::inputs::Inputs;
use crate::job_args;
use crate::params::PyParams;
use crate::python_side;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::collections::BTreeMap;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::model::{Input, Observable};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::subtract::{ResidualSpectra, DEFAULT_REPORT_BAND_HZ};
use tiltnoise_job::files::Staging;
use tiltnoise_job::subtract::{SubtractOutcome, SubtractRequest};
use tiltnoise_job::Outcome;

/// `colocated_ratio`: `{input: R}` as inputs and numbers (the job checks them).
fn parse_colocated_ratio(ratios: BTreeMap<String, f64>) -> PyResult<Vec<(Input, f64)>> {
    ratios
        .into_iter()
        .map(|(name, r)| {
            let input = options::floor_input(
                OptionKey::COLOCATED_RATIO,
                &format!("{name}={}", tiltnoise_core::error::Num(r)),
                &name,
            )
            .py()?;
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
/// Ctrl-C stops it with ``KeyboardInterrupt``. Returns a :class:`Subtraction`. Raises ``FileNotFoundError``/``OSError`` if a file cannot
/// be read, :class:`InputFileError` if it is not a valid record, ``ValueError`` for options or
/// records the subtraction refuses.
#[pyfunction]
#[pyo3(signature = (tilt, measured, *, fit=None, band=None, report_band=None, nperseg=None, holdout=0.25, max_delay=None, witness_noise=None, colocated=None, colocated_ratio=None, readout=None, observables=None, axes=None, quantity=None, gaps=None, scale=None, units=None, corrected=None, pendulum_tiltmeter=None, params=None))]
#[allow(clippy::too_many_arguments)]
pub fn subtract(
    py: Python<'_>,
    #[pyo3(from_py_with = kw::tilt)] tilt: PathBuf,
    #[pyo3(from_py_with = kw::measured)] measured: PathBuf,
    fit: Option<&Bound<'_, PyAny>>,
    band: Option<&Bound<'_, PyAny>>,
    report_band: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::nperseg)] nperseg: Option<usize>,
    #[pyo3(from_py_with = kw::holdout)] holdout: f64,
    #[pyo3(from_py_with = kw::max_delay)] max_delay: Option<f64>,
    #[pyo3(from_py_with = kw::witness_noise)] witness_noise: Option<Bound<'_, PyDict>>,
    colocated: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::colocated_ratio)] colocated_ratio: Option<BTreeMap<String, f64>>,
    #[pyo3(from_py_with = kw::readout)] readout: Option<BTreeMap<String, f64>>,
    observables: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = kw::axes)] axes: Option<String>,
    #[pyo3(from_py_with = kw::quantity)] quantity: Option<String>,
    #[pyo3(from_py_with = kw::gaps)] gaps: Option<String>,
    #[pyo3(from_py_with = kw::scale)] scale: Option<BTreeMap<String, f64>>,
    #[pyo3(from_py_with = kw::units)] units: Option<BTreeMap<String, String>>,
    corrected: Option<&Bound<'_, PyAny>>,
    pendulum_tiltmeter: Option<&Bound<'_, PyAny>>,
    params: Option<&Bound<'_, PyAny>>,
) -> PyResult<Subtraction> {
    let fit = args::strings("fit", fit)?;
    let band = args::band("band", band)?;
    let report_band = args::band("report_band", report_band)?;
    let colocated = args::paths("colocated", colocated)?;
    let channels_of = job_args::ChannelLists::of(corrected, pendulum_tiltmeter)?;
    let (model, params) = model_of(params)?;
    let readout_asd = readout
        .unwrap_or_default()
        .into_iter()
        .map(|(name, asd)| options::readout_item(OptionKey::READOUT, &name, asd).py())
        .collect::<PyResult<Vec<_>>>()?;
    let req = SubtractRequest {
        model: &model,
        tilt,
        read: job_args::file_read_request(axes, quantity, units, channels_of, gaps, scale)?,
        measured,
        observables: job_args::observables(observables)?,
        colocated: colocated.unwrap_or_default(),
        colocated_ratio: parse_colocated_ratio(colocated_ratio.unwrap_or_default())?,
        witness_noise: job_args::witness_noise(witness_noise.as_ref())?,
        readout_asd,
        fit: fit.unwrap_or_default(),
        band_hz: band,
        report_band_hz: report_band.unwrap_or(DEFAULT_REPORT_BAND_HZ),
        nperseg,
        holdout,
        max_delay_s: max_delay,
        invocation: tiltnoise_job::Invocation::of_this_process(),
        figure: tiltnoise_job::figures::View::default(),
    };
    let inputs = Inputs::of_params(params.file.as_deref())
        .with_all(job_args::python_names(req.input_files(), &[]));
    let cancel = Cancel::new();
    let outcome = crate::interrupt::watch(py, &cancel, || {
        tiltnoise_job::subtract::run(&req, &cancel, &tiltnoise_job::Silent)
            .map_err(job_args::job_error)
    })?;
    Ok(Subtraction { outcome, inputs })
}

/// A subtraction: the fitted coupling (``estimates``, ``fitted_params``), the tilt part
/// predicted and removed from the measured record over the overlap (``predicted``,
/// ``cleaned``, in ``units``), the held-out spectra (``frequency_hz``, ``asd``), the report
/// (the command line's JSON report as a dict); ``save`` writes the command line's files and
/// figure, ``plot`` draws the spectra with matplotlib.
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Subtraction {
    outcome: SubtractOutcome,
    /// The files read: no `save` may replace one.
    inputs: Inputs,
}

/// The curves of the held-out spectra, by name, as in the figure's legend.
const CURVES: [&str; 6] = [
    "measured",
    "predicted",
    "cleaned",
    "wiener",
    "coherence_limit",
    "witness_limited",
];

/// The PSD of `curve` in `s` (one of [`CURVES`]).
fn curve_psd<'a>(s: &'a ResidualSpectra, curve: &str) -> &'a [f64] {
    match curve {
        "measured" => &s.measured_psd,
        "predicted" => &s.predicted_psd,
        "cleaned" => &s.cleaned_psd,
        "wiener" => &s.wiener_psd,
        "coherence_limit" => &s.expected_psd,
        _ => &s.witness_limited_psd,
    }
}

impl Subtraction {
    /// `{observable: array}` of `series`.
    fn per_observable<'py>(
        py: Python<'py>,
        series: &[(Observable, Vec<f64>)],
    ) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (o, x) in series {
            d.set_item(o.name(), PyArray1::from_slice(py, x))?;
        }
        Ok(d)
    }
}

#[pymethods]
impl Subtraction {
    /// The observables subtracted, in the measured record's order.
    #[getter]
    fn observables(&self) -> Vec<&'static str> {
        self.outcome
            .result
            .cleaned
            .iter()
            .map(|(o, _)| o.name())
            .collect()
    }

    /// ``{observable: unit}`` of the series (``m``, ``rad``); the ASDs are in unit/sqrt(Hz).
    #[getter]
    fn units(&self) -> BTreeMap<&'static str, &'static str> {
        self.outcome
            .result
            .cleaned
            .iter()
            .map(|(o, _)| (o.name(), o.unit()))
            .collect()
    }

    /// Sample rate of the overlap (Hz).
    #[getter]
    fn sample_rate_hz(&self) -> f64 {
        self.outcome.result.alignment.fs_hz
    }

    /// ISO 8601 time of the first sample of the overlap, when the records state start times.
    #[getter]
    fn start_time(&self) -> Option<String> {
        self.outcome.meta.start_time.clone()
    }

    /// ``{observable: measured minus predicted}`` over the overlap, in ``units``: the cleaned
    /// record ``save("x.h5")`` writes.
    #[getter]
    fn cleaned<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        Self::per_observable(py, &self.outcome.result.cleaned)
    }

    /// ``{observable: predicted tilt part}`` over the overlap, in ``units``, as subtracted.
    #[getter]
    fn predicted<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        Self::per_observable(py, &self.outcome.result.prediction.series)
    }

    /// Frequencies (Hz) of the held-out Welch spectra, DC first.
    #[getter]
    fn frequency_hz<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let f = self
            .outcome
            .result
            .residuals
            .first()
            .map_or(&[][..], |s| &s.freqs_hz);
        PyArray1::from_slice(py, f)
    }

    /// ``{observable: {curve: one-sided ASD}}`` on the held-out stretch, in unit/sqrt(Hz), on
    /// ``frequency_hz``: ``measured``, ``predicted`` (the tilt part), ``cleaned``, ``wiener``
    /// (the residual of a multiple-input Wiener filter trained on the training stretch),
    /// ``coherence_limit`` (the least any linear filter of the witness can leave) and
    /// ``witness_limited`` (what the witness's own noise keeps from being removed): the
    /// curves of the figure.
    #[getter]
    fn asd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for s in &self.outcome.result.residuals {
            let curves = PyDict::new(py);
            for curve in CURVES {
                let asd: Vec<f64> = curve_psd(s, curve)
                    .iter()
                    .map(|v| v.max(0.0).sqrt())
                    .collect();
                curves.set_item(curve, PyArray1::from_vec(py, asd))?;
            }
            d.set_item(s.observable.name(), curves)?;
        }
        Ok(d)
    }

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

    /// The parameter set at the fit's solution (the fitted keys at their estimates, the others
    /// as given).
    #[getter]
    fn fitted_params(&self) -> PyParams {
        PyParams::unread(self.outcome.result.fit.params.clone())
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

    /// The subtraction's notes (alignment, fit, bands left raw).
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.outcome.result.notes.clone()
    }

    /// Writes what the command line's ``--save`` writes: the cleaned record (``.h5``/``.hdf5``,
    /// what ``budget_from_file(measured=...)`` reads), the report (``.json``) or the command
    /// line's figure (``.png``/``.svg``, the same image as ``tiltnoise subtract --save x.png``);
    /// atomically. Raises ``OSError`` if it cannot be written or is one of the files read,
    /// ``ValueError`` for another extension.
    fn save(&self, py: Python<'_>, #[pyo3(from_py_with = kw::path)] path: PathBuf) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, tiltnoise_job::subtract::outputs::OUTPUT_KINDS).py()?;
        self.inputs.check_save(&path)?;
        py.detach(|| Staging::committed(|stage| self.outcome.save(stage, &path)))
            .map_err(job_args::job_error)
    }

    /// The held-out spectra drawn with matplotlib: one log-log panel per observable, the
    /// curves of ``asd`` and the report band. Returns a new ``matplotlib.figure.Figure`` (of
    /// ``matplotlib.pyplot``, so a notebook shows it). Needs matplotlib; raises ``ImportError``
    /// saying so without it. The command line's own figure is :meth:`save` to a ``.png`` or
    /// ``.svg`` path.
    fn plot<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_plots", "subtraction_plot", &[])
    }

    /// ``{"cleaned": gwpy.timeseries.TimeSeriesDict, "predicted": TimeSeriesDict, "asd":
    /// {observable: {curve: gwpy.frequencyseries.FrequencySeries}}}``: the series over the
    /// overlap (``t0`` its start as GPS time when the records state one, else 0; ``dt`` one
    /// over ``sample_rate_hz``) and the held-out ASDs, each named ``"OBS.cleaned"``,
    /// ``"OBS.predicted"``, ``"OBS.CURVE"`` with its unit. Needs gwpy (``pip install gwpy``);
    /// raises ``ImportError`` saying so without it.
    fn to_gwpy<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_convert", "subtraction_to_gwpy", &[])
    }

    /// ``{"cleaned": DataFrame, "predicted": DataFrame}`` indexed by ``time_s`` (from the
    /// overlap's start), one column per observable, and ``"asd"``: a DataFrame indexed by
    /// ``frequency_hz``, one column per ``"OBS.CURVE"``; units in each frame's
    /// ``attrs["units"]``. Needs pandas (``pip install pandas``); raises ``ImportError``
    /// saying so without it.
    fn to_pandas<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_convert", "subtraction_to_pandas", &[])
    }

    /// The report band (Hz) of the residual summaries: ``(FLO, FHI)``, the first and last bin.
    #[getter]
    fn report_band_hz(&self) -> Option<(f64, f64)> {
        self.outcome
            .result
            .residuals
            .first()
            .map(|s| s.band.band_hz)
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<crate::state::Reduced<'py>> {
        crate::state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        crate::state::load("Subtraction", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        crate::state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        let r = &self.outcome.result;
        format!(
            "Subtraction({} of {} vs {}; {} samples at {} Hz; {} estimates)",
            self.observables().join(", "),
            self.outcome.meta.measured_path,
            self.outcome.tilt_path,
            r.alignment.len,
            r.alignment.fs_hz,
            r.fit.estimates.len()
        )
    }
}
