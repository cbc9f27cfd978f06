//! `tiltnoise.Model`: normal modes, transfer functions (the command line's `modes` and `tf`),
//! the model's matrices and the Monte Carlo of the modes (`mc`).

use crate::args::kw;
use crate::arrays;
use crate::errors::{value_error, PyResultExt};
use crate::grid::{self, GridBuffer};
use crate::interrupt;
use crate::job_args::job_error;
use crate::params::PyParams;
use crate::state;
use numpy::{Complex64, PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::model::{Coord, ForceInput, Input, Model, Observable, Request};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::simulate::DEFAULT_MODE_ENERGY_J;
use tiltnoise_core::tf::{
    self, eval_grid_threads_cancellable, Destination, Method, Scene, TransferFunction,
};
use tiltnoise_job::figures::View;
use tiltnoise_job::files::Staging;
use tiltnoise_job::modes::{ModesOutcome, ModesRequest, DOMINANT_SHARE};
use tiltnoise_job::{Invocation, JobError, Outcome, Silent};

// The defaults of `transfer`, `explain` and `simulate` are written as literals in their
// signatures, so that Python's `inspect.signature` (and the type stubs) show the numbers; they
// are the library's defaults, as the command line's.
const _: () = assert!(tf::DEFAULT_REL_TOL == 1e-9);
const _: () = assert!(DEFAULT_MODE_ENERGY_J == 1e-12);

/// Grids of at most this many points are evaluated without releasing the GIL: releasing and
/// taking it back costs more than evaluating so few points, and even the slowest method
/// (`statespace`) holds it for a short time only.
const HOLD_GIL_MAX_POINTS: usize = 16;

/// Grids at least this long are evaluated on every core: below it, starting a thread costs
/// more than the points it takes over (about 10 ns each). They are also the grids evaluated
/// under [`interrupt::watch`] (one more thread), so that Ctrl-C stops them.
const THREADED_GRID: usize = 8192;

/// The cores this process may use, asked once: `available_parallelism` reads the cgroup's
/// CPU quota from files on every call, tens of microseconds.
fn cores() -> usize {
    static CORES: OnceLock<usize> = OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// Plans built so far, per request and method: a plan does its per-model work (pole-zero
/// factors in double-double, factorized forcing) once, so later calls cost only their points.
type PlanCache = HashMap<(Vec<Input>, Vec<Observable>, Method), Arc<dyn TransferFunction>>;

/// The planner's choices so far, per request, band and tolerance (the `f64` bits).
type ChoiceCache = HashMap<(Vec<Input>, Vec<Observable>, [u64; 3]), Method>;

/// The linear 8-DoF model of the double torsion pendulum built from one parameter set.
///
/// ``Model(params=None)`` builds it from ``params`` (a :class:`Params`; default Table I) and
/// raises ``ValueError`` if the parameters do not describe a stable pendulum (the message
/// names the unstable mode or the offending keys).
///
/// Conventions (as the command line's): SI units; complex amplitudes for ``exp(+i w t)`` time
/// dependence; the tilt ``(theta_t, eta_t, phi_t)`` is the rotation taking the floor frame to
/// the inertial frame, so that ``X -> -eta_t (Z + Z_b + h_c)`` as ``f -> 0``.
#[pyclass(name = "Model", module = "tiltnoise", frozen)]
pub struct PyModel {
    pub model: Arc<Model>,
    /// The parameter file the model's parameters were read from, if any.
    pub params_file: Option<std::path::PathBuf>,
    modes: OnceLock<ModesOutcome>,
    plans: Mutex<PlanCache>,
    choices: Mutex<ChoiceCache>,
    last: Mutex<Option<LastPlan>>,
}

/// The plan of the last call of `transfer`: a repeated call (the same names, method, band
/// and tolerance) finds it by comparing these, without hashing into the caches.
struct LastPlan {
    request: Request,
    /// The method asked for (`None`: `auto`).
    asked: Option<Method>,
    /// For `auto`: the band's and the tolerance's bits (the planner's choice depends on them).
    scene: [u64; 3],
    plan: Arc<dyn TransferFunction>,
}

impl PyModel {
    /// The model of `params` (Table I when `None`).
    pub fn build(params: Option<&PyParams>) -> PyResult<PyModel> {
        let model = Model::new(&PyParams::or_table_i(params)).py()?;
        Ok(PyModel {
            model: Arc::new(model),
            params_file: params.and_then(|p| p.file.clone()),
            modes: OnceLock::new(),
            plans: Mutex::new(HashMap::new()),
            choices: Mutex::new(HashMap::new()),
            last: Mutex::new(None),
        })
    }

    /// The normal modes, as the modes job finds them (once per model).
    pub fn normal_modes(&self) -> &NormalModes {
        let outcome = self.modes.get_or_init(|| {
            let req = ModesRequest {
                model: &self.model,
                invocation: Invocation::of_this_process(),
            };
            tiltnoise_job::modes::run(&req, &Cancel::never(), &Silent)
                .expect("a run that cannot be cancelled has no error")
        });
        &outcome.modes
    }

    /// The method `auto` takes for `request` on `band` (see [`grid::auto_band`]) and `rel_tol`,
    /// remembered per request, band and tolerance.
    fn auto_method(
        &self,
        py: Python<'_>,
        request: &Request,
        band: (f64, f64),
        rel_tol: f64,
    ) -> PyResult<Method> {
        let key = (
            request.inputs.clone(),
            request.outputs.clone(),
            scene_bits(band, rel_tol),
        );
        if let Some(&m) = lock(&self.choices).get(&key) {
            return Ok(m);
        }
        let model = &self.model;
        let choice = py
            .detach(|| tiltnoise_job::tf::choose(model, request, band, rel_tol))
            .map_err(job_error)?;
        lock(&self.choices).insert(key, choice.method);
        Ok(choice.method)
    }

    /// The plan `transfer` evaluates: `asked` (`None`: what `auto` picks on `band`, the
    /// grid's [`grid::auto_band`]), looked up in the last call's first.
    fn plan_for(
        &self,
        py: Python<'_>,
        request: Request,
        asked: Option<Method>,
        band: (f64, f64),
        rel_tol: f64,
    ) -> PyResult<Arc<dyn TransferFunction>> {
        let scene = match asked {
            None => scene_bits(band, rel_tol),
            Some(_) => [0; 3],
        };
        if let Some(last) = lock(&self.last).as_ref() {
            if last.asked == asked && last.scene == scene && last.request == request {
                return Ok(Arc::clone(&last.plan));
            }
        }
        let method = match asked {
            Some(m) => m,
            None => self.auto_method(py, &request, band, rel_tol)?,
        };
        let plan = self.plan(py, &request, method)?;
        *lock(&self.last) = Some(LastPlan {
            request,
            asked,
            scene,
            plan: Arc::clone(&plan),
        });
        Ok(plan)
    }

    /// The plan of `request` with `method`, built once per model.
    fn plan(
        &self,
        py: Python<'_>,
        request: &Request,
        method: Method,
    ) -> PyResult<Arc<dyn TransferFunction>> {
        let key = (request.inputs.clone(), request.outputs.clone(), method);
        if let Some(p) = lock(&self.plans).get(&key) {
            return Ok(Arc::clone(p));
        }
        let model = &self.model;
        let plan: Arc<dyn TransferFunction> = py
            .detach(|| tiltnoise_job::tf::plan(model, request, method))
            .map_err(job_error)?
            .into();
        lock(&self.plans).insert(key, Arc::clone(&plan));
        Ok(plan)
    }
}

/// A mutex's data; a panic while it was held cannot leave a cache inconsistent (entries are
/// inserted whole), so a poisoned lock is used as it is.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Work between two polls of the cancellation token in [`eval_in_parts`]: a tenth of the
/// half second an interrupt may take.
const PART_TIME: Duration = Duration::from_millis(50);

/// [`eval_grid_threads_cancellable`] in consecutive parts of the grid whose size follows the
/// time each part takes (doubled while under half of [`PART_TIME`], halved above it), polling
/// `cancel` between parts: the library polls it per block of points, which the slowest
/// methods take a second or more to evaluate. The values are the same: every point is
/// evaluated alone.
fn eval_in_parts(
    plan: &dyn TransferFunction,
    freqs: &[f64],
    buffer: &mut [Complex64],
    threads: usize,
    destination: Destination,
    cancel: &Cancel,
) -> Result<(), tiltnoise_core::error::TfError> {
    // The whole output decides how it is written, as in one call.
    let destination = match destination.streams(std::mem::size_of_val(buffer)) {
        true => Destination::Streamed,
        false => destination,
    };
    let block = buffer.len() / freqs.len().max(1);
    let (mut start, mut points) = (0, THREADED_GRID);
    while start < freqs.len() {
        cancel.check()?;
        let end = (start + points).min(freqs.len());
        let began = Instant::now();
        eval_grid_threads_cancellable(
            plan,
            &freqs[start..end],
            &mut buffer[start * block..end * block],
            threads,
            destination,
            cancel,
        )?;
        let took = began.elapsed();
        if took < PART_TIME / 2 {
            points = points.saturating_mul(2);
        } else if took > PART_TIME {
            points = (points / 2).max(1);
        }
        start = end;
    }
    Ok(())
}

/// The names of `observables`.
fn names_of(observables: &[Observable]) -> Vec<String> {
    observables.iter().map(|o| o.name().to_string()).collect()
}

/// A band and a tolerance as a cache key.
fn scene_bits(band: (f64, f64), rel_tol: f64) -> [u64; 3] {
    [band.0.to_bits(), band.1.to_bits(), rel_tol.to_bits()]
}

/// `inputs` of [`PyModel::transfer`]: names as on the command line's `--input`; `None`: the
/// three tilt angles.
fn parse_inputs(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Input>> {
    match arg {
        None => Ok(Input::all_tilts()),
        Some(arg) => options::parse_inputs(
            OptionKey::INPUTS,
            &crate::args::names("inputs", Some(arg))?.unwrap_or_default(),
        )
        .py(),
    }
}

/// `outputs` of [`PyModel::transfer`]: names as on the command line's `--output`; `None`:
/// all seven observables.
fn parse_outputs(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Observable>> {
    match arg {
        None => Ok(Observable::ALL.to_vec()),
        Some(arg) => options::parse_outputs(
            OptionKey::OUTPUTS,
            &crate::args::names("outputs", Some(arg))?.unwrap_or_default(),
        )
        .py(),
    }
}

/// `method` of [`PyModel::transfer`]: `auto` (`None`) or a method's command-line name.
fn parse_method(name: &str) -> PyResult<Option<Method>> {
    if name == "auto" {
        return Ok(None);
    }
    Method::ALL
        .into_iter()
        .find(|m| m.name() == name)
        .map(Some)
        .ok_or_else(|| {
            let allowed: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
            value_error(format!(
                "method: unknown method {name:?}; allowed: auto, {}",
                allowed.join(", ")
            ))
        })
}

/// `rel_tol` of [`PyModel::transfer`], checked by the transfer-function job as the command
/// line's `--rel-tol`.
fn check_rel_tol(rel_tol: f64) -> PyResult<()> {
    tiltnoise_job::tf::rel_tol(Some(rel_tol))
        .map(drop)
        .map_err(job_error)
}

/// The methods job's request of [`PyModel::methods`] and [`PyModel::save_methods`]: the chart
/// in the default view; the grid is an array, so it has no spelling for the JSON's `grid`.
fn methods_request<'a>(
    model: &'a Model,
    freq_hz: &Bound<'_, PyAny>,
    inputs: Option<&Bound<'_, PyAny>>,
) -> PyResult<tiltnoise_job::methods::MethodsRequest<'a>> {
    Ok(tiltnoise_job::methods::MethodsRequest {
        model,
        grid_hz: grid::frequencies(freq_hz, grid::GRID)?,
        inputs: Some(parse_inputs(inputs)?),
        grid_spec: String::new(),
        view: View::default(),
        invocation: Invocation::of_this_process(),
    })
}

/// An 8x8 (or other) nalgebra matrix as a row-major NumPy array.
fn matrix<'py, R: nalgebra::Dim, C: nalgebra::Dim, S: nalgebra::RawStorage<f64, R, C>>(
    py: Python<'py>,
    m: &nalgebra::Matrix<f64, R, C, S>,
) -> Bound<'py, PyArray2<f64>> {
    let rows: Vec<Vec<f64>> = (0..m.nrows())
        .map(|r| (0..m.ncols()).map(|c| m[(r, c)]).collect())
        .collect();
    PyArray2::from_vec2(py, &rows).expect("rows of equal length")
}

#[pymethods]
impl PyModel {
    #[new]
    #[pyo3(signature = (params=None))]
    fn new(#[pyo3(from_py_with = kw::params)] params: Option<PyParams>) -> PyResult<Self> {
        PyModel::build(params.as_ref())
    }

    /// The parameters the model was built from.
    #[getter]
    fn params(&self) -> PyParams {
        PyParams {
            inner: self.model.params().clone(),
            file: self.params_file.clone(),
        }
    }

    /// The normal modes (the command line's ``tiltnoise modes``), nu_1 first.
    ///
    /// Each :class:`Mode` has ``index`` (1-based), ``frequency_hz``, ``quality_factor`` (also
    /// ``q``; ``inf`` for an undamped model), ``loss_angle_rad``, ``block``,
    /// ``dominant_coordinates`` (``(coordinate, energy share)`` for every coordinate holding at
    /// least 5 % of the modal kinetic energy, largest first), ``energy_share``, ``seen_by``
    /// (the observables that see the mode), ``observable_amplitude`` and ``shape``.
    fn modes(&self, py: Python<'_>) -> Vec<Mode> {
        let modes = py.detach(|| self.normal_modes());
        modes
            .modes
            .iter()
            .enumerate()
            .map(|(k, m)| Mode {
                index: m.index,
                frequency_hz: m.frequency_hz,
                omega_sq_rad2_per_s2: m.omega_sq,
                quality_factor: m.quality_factor,
                loss_angle_rad: m.loss_angle,
                block: m.block_name().to_string(),
                overlap: m.overlap,
                ratio: Observable::ALL
                    .iter()
                    .map(|o| (o.name().to_string(), modes.ratio[k][o.index()]))
                    .collect(),
                seen_above_ratio: names_of(&modes.observables_above_ratio(k)),
                dominant_coordinates: m
                    .dominant_coords(DOMINANT_SHARE)
                    .into_iter()
                    .map(|(c, s)| (c.name().to_string(), s))
                    .collect(),
                energy_share: Coord::ALL
                    .iter()
                    .map(|c| (c.name().to_string(), m.energy_share[c.index()]))
                    .collect(),
                seen_by: names_of(&modes.observables_seeing(k)),
                observable_amplitude: Observable::ALL
                    .iter()
                    .map(|o| (o.name().to_string(), m.observable_amplitude[o.index()]))
                    .collect(),
                shape: m.shape.iter().copied().collect(),
            })
            .collect()
    }

    /// Transfer functions from inputs to observables (the command line's ``tiltnoise tf``).
    ///
    /// ``freq_hz``: a number or a 1-D array of frequencies in Hz, finite and >= 0.
    /// ``inputs``: names as ``--input``, a comma-separated ``str`` or a sequence: the tilt
    /// angles ``theta_t``, ``eta_t``, ``phi_t`` (rad), the floor translations ``x_t``, ``y_t``,
    /// ``z_t`` (m, along the lab axes: the crossbar arm along y, z up; the floor, the suspension
    /// point and the housing move together), the force components ``F_a.x`` .. ``F_b.z`` (N)
    /// and torque components ``M_a.x`` .. ``M_b.z`` (N m) on the crossbar (a) and the test mass
    /// (b), and the groups ``tilt``, ``translation``, ``ground`` (tilt and translation) and
    /// ``forces``; default the three tilt angles. ``outputs``: ``X``, ``Y``, ``Z`` (m), ``theta``, ``eta``, ``phi``, ``phi_a``
    /// (rad); default all seven. ``method``: ``auto`` (the cheapest method whose error against
    /// the double-double reference on the grid's band is at most ``rel_tol``), ``direct``,
    /// ``block``, ``split``, ``polezero``, ``modal``, ``statespace`` or ``torsion2``.
    /// ``threads``: evaluation threads (default: every core for grids of 8192 points or more).
    /// ``out``: a C-contiguous complex128 array of the result's shape to write into (as
    /// NumPy's ``out=``; saves allocating and first touching a new array on repeated calls).
    ///
    /// Returns a complex128 array ``H[n_freq, n_outputs, n_inputs]`` in the order asked: the
    /// complex amplitude of each observable per unit input for ``exp(+i w t)`` time
    /// dependence, in the observable's unit per the input's unit (m/rad, rad/rad, m/m, rad/m,
    /// m/N, rad/(N m), ...); per unit floor acceleration divide a translation's column by
    /// ``-(2 pi f)**2``. ``auto`` measures the candidates against the double-double reference
    /// on the grid's band (about 0.1 s) once per request, band and tolerance, and remembers the
    /// pick: the result never depends on earlier calls. For many grids on different bands,
    /// name the method (``method="polezero"`` is what it picks for the tilt matrix of Table I).
    /// Raises ``ValueError`` for an unknown name, a frequency that is
    /// negative or not finite, or one on an undamped resonance.
    #[pyo3(signature = (freq_hz, inputs=None, outputs=None, method=String::from("auto"), rel_tol=1e-9, threads=None, out=None), text_signature = "($self, freq_hz, inputs=None, outputs=None, method='auto', rel_tol=1e-9, threads=None, out=None)")]
    #[allow(clippy::too_many_arguments)]
    #[allow(unsafe_code, reason = "a new NumPy array filled in place")]
    fn transfer<'py>(
        &self,
        py: Python<'py>,
        freq_hz: &Bound<'py, PyAny>,
        inputs: Option<&Bound<'py, PyAny>>,
        outputs: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = kw::method)] method: String,
        #[pyo3(from_py_with = kw::rel_tol)] rel_tol: f64,
        #[pyo3(from_py_with = kw::threads)] threads: Option<usize>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray3<Complex64>>> {
        let request = Request {
            inputs: parse_inputs(inputs)?,
            outputs: parse_outputs(outputs)?,
        };
        let asked = parse_method(&method)?;
        check_rel_tol(rel_tol)?;
        // The grid's copy, and the result unless it goes into `out`: 16 bytes an entry.
        let entries = (request.outputs.len() * request.inputs.len()) as u64;
        let per_point = 8 + if out.is_none() { 16 * entries } else { 0 };
        let mut grid = GridBuffer::take();
        let band = grid.fill(freq_hz, grid::grid_size(per_point))?;
        let freqs = grid.freqs();
        let dims = [freqs.len(), request.outputs.len(), request.inputs.len()];
        let out = out
            .map(|o| arrays::output::<Complex64>("out", o, dims, "complex128"))
            .transpose()?;
        let plan = self.plan_for(py, request, asked, band, rel_tol)?;
        let threads = threads.unwrap_or(match freqs.len() >= THREADED_GRID {
            true => cores(),
            false => 1,
        });
        let plan = plan.as_ref();
        let eval = |buffer: &mut [Complex64], destination| -> PyResult<()> {
            let never = Cancel::never();
            let mut run = || {
                eval_grid_threads_cancellable(plan, freqs, buffer, threads, destination, &never)
                    .py()
            };
            match freqs.len() {
                n if n <= HOLD_GIL_MAX_POINTS => run(),
                n if n < THREADED_GRID => py.detach(run),
                _ => {
                    let cancel = Cancel::new();
                    interrupt::watch(py, &cancel, || {
                        eval_in_parts(plan, freqs, buffer, threads, destination, &cancel).py()
                    })
                }
            }
        };
        match out {
            Some(h) => {
                let mut rw = h
                    .try_readwrite()
                    .map_err(|e| value_error(format!("out: not writeable ({e})")))?;
                eval(
                    rw.as_slice_mut()
                        .map_err(|_| value_error("out: must be C-contiguous"))?,
                    Destination::Reused,
                )?;
                drop(rw);
                Ok(h)
            }
            None => {
                // SAFETY: every element is written by `eval_grid_threads` before the array is
                // returned (on error it is dropped unread).
                let h = unsafe { PyArray3::<Complex64>::new(py, dims, false) };
                // SAFETY: the array was just created (C-contiguous, aligned) and nothing else
                // refers to it until it is returned, so the slice is its only reference; the
                // borrow tracking of `try_readwrite` has nothing to guard.
                let buffer = unsafe { h.as_slice_mut() }
                    .map_err(|_| value_error("a new array that is not contiguous"))?;
                eval(buffer, Destination::Fresh)?;
                Ok(h)
            }
        }
    }

    /// :meth:`transfer` as a :class:`TransferFunction`: the complex values with the
    /// frequencies, the names and the units of every input and output, convertible to gwpy
    /// (``to_gwpy()``) and pandas (``to_pandas()``), drawn by ``plot()``. The arguments are
    /// :meth:`transfer`'s.
    #[pyo3(signature = (freq_hz, inputs=None, outputs=None, method=String::from("auto"), rel_tol=1e-9), text_signature = "($self, freq_hz, inputs=None, outputs=None, method='auto', rel_tol=1e-9)")]
    fn transfer_function<'py>(
        slf: &Bound<'py, Self>,
        py: Python<'py>,
        freq_hz: &Bound<'py, PyAny>,
        inputs: Option<&Bound<'py, PyAny>>,
        outputs: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = kw::method)] method: String,
        #[pyo3(from_py_with = kw::rel_tol)] rel_tol: f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let h = slf.get().transfer(
            py,
            freq_hz,
            inputs,
            outputs,
            method.clone(),
            rel_tol,
            None,
            None,
        )?;
        let freqs = PyArray1::from_vec(py, grid::frequencies(freq_hz, grid::GRID)?);
        let (ins, outs) = (parse_inputs(inputs)?, parse_outputs(outputs)?);
        let names_units = |n: Vec<(&'static str, &'static str)>| n.into_iter().unzip();
        let (in_names, in_units): (Vec<_>, Vec<_>) =
            names_units(ins.iter().map(|i| (i.name(), i.unit())).collect());
        let (out_names, out_units): (Vec<_>, Vec<_>) =
            names_units(outs.iter().map(|o| (o.name(), o.unit())).collect());
        py.import("tiltnoise._transfer")?
            .getattr("TransferFunction")?
            .call1((freqs, h, in_names, out_names, in_units, out_units, method))?
            .call_method1("_of", (slf, rel_tol, outputs.is_some()))
    }

    /// Writes the transfer functions of :meth:`transfer` with these arguments as the command
    /// line's ``tf --save`` does (:meth:`TransferFunction.save` calls it): ``drawn``, the
    /// observables of the figure (each one computed); ``phase``, a phase panel beside each
    /// magnitude panel.
    #[pyo3(signature = (path, freq_hz, inputs, outputs, method, rel_tol, drawn, phase))]
    #[allow(clippy::too_many_arguments)]
    fn _save_transfer(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = kw::path)] path: std::path::PathBuf,
        freq_hz: &Bound<'_, PyAny>,
        inputs: Option<&Bound<'_, PyAny>>,
        outputs: Option<&Bound<'_, PyAny>>,
        method: &str,
        rel_tol: f64,
        drawn: Vec<String>,
        #[pyo3(from_py_with = kw::phase)] phase: bool,
    ) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, tiltnoise_job::tf::OUTPUT_KINDS).py()?;
        crate::inputs::Inputs::of_params(self.params_file.as_deref()).check_save(&path)?;
        let request = Request {
            inputs: parse_inputs(inputs)?,
            outputs: parse_outputs(outputs)?,
        };
        let drawn = options::parse_outputs(OptionKey::DRAWN_OBSERVABLES, &drawn).py()?;
        if let Some(o) = drawn.iter().find(|o| !request.outputs.contains(o)) {
            return Err(value_error(format!(
                "observables: {} is not among the computed observables ({})",
                o.name(),
                request
                    .outputs
                    .iter()
                    .map(|o| o.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            )));
        }
        let model = &self.model;
        let req = tiltnoise_job::tf::TfRequest {
            model,
            request,
            grid: tiltnoise_job::tf::FreqGrid::Points(grid::frequencies(freq_hz, grid::GRID)?),
            per: tiltnoise_core::ground::GroundQuantity::Displacement,
            method: parse_method(method)?,
            rel_tol: Some(rel_tol),
            block_freqs: None,
            figure: None,
            figure_options: tiltnoise_job::tf::figure_options(
                model,
                drawn,
                phase,
                crate::errors::shown(&OptionKey::DRAWN_OBSERVABLES),
            ),
            invocation: Invocation::of_this_process(),
        };
        let outcome = py
            .detach(|| tiltnoise_job::tf::run(&req, &Cancel::never(), &Silent))
            .map_err(job_error)?;
        py.detach(|| Staging::committed(|stage| outcome.save(stage, &path)))
            .map_err(job_error)
    }

    /// Which method ``method="auto"`` picks for this request and grid, and why: every
    /// candidate's measured error against the double-double reference (the command line's
    /// ``tf --explain``).
    #[pyo3(signature = (freq_hz, inputs=None, outputs=None, rel_tol=1e-9))]
    fn explain(
        &self,
        py: Python<'_>,
        freq_hz: &Bound<'_, PyAny>,
        inputs: Option<&Bound<'_, PyAny>>,
        outputs: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = kw::rel_tol)] rel_tol: f64,
    ) -> PyResult<String> {
        let request = Request {
            inputs: parse_inputs(inputs)?,
            outputs: parse_outputs(outputs)?,
        };
        check_rel_tol(rel_tol)?;
        let band =
            Scene::over_grid(request.clone(), &grid::frequencies(freq_hz, grid::GRID)?).band_hz;
        let model = &self.model;
        let choice = py
            .detach(|| tiltnoise_job::tf::choose(model, &request, band, rel_tol))
            .map_err(|e| match e {
                // Asked for the reasoning: the refusal is the answer, without a pointer here.
                JobError::NoMethod(refusal) => value_error(refusal.to_string()),
                other => job_error(other),
            })?;
        Ok(choice.explain())
    }

    /// The model's matrices as NumPy arrays, for work outside tiltnoise:
    /// ``H(w) = C (K + i K_imag + i w D - w^2 M)^-1 G(w)`` with ``G = G0 + w^2 G2`` (tilt),
    /// ``w^2 G2_translation`` (floor translation) or ``F`` (forces and torques).
    ///
    /// Keys: ``M`` (8x8 mass matrix), ``K`` (8x8 undamped stiffness), ``K_imag`` (8x8
    /// structural damping, ``Im K_c``), ``D`` (8x8 viscous damping), ``G0``, ``G2`` (8x3 tilt
    /// forcing), ``G2_translation`` (8x3 floor-translation forcing per unit ``w^2``),
    /// ``F`` (8x12 force/torque forcing), ``C`` (7x8 observation matrix), ``q0`` (the rest
    /// configuration the model is linear about: 0 for the symmetric pendulum, the tilted
    /// equilibrium of the pendulum as built), and the labels ``coordinates``, ``observables``,
    /// ``tilt_inputs``, ``translation_inputs``, ``force_inputs``.
    fn matrices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let m = &self.model;
        let d = PyDict::new(py);
        d.set_item("M", matrix(py, m.mass()))?;
        d.set_item("K", matrix(py, &m.stiffness()))?;
        d.set_item("K_imag", matrix(py, m.stiffness_imag()))?;
        d.set_item("D", matrix(py, m.damping()))?;
        d.set_item("G0", matrix(py, &m.tilt_forcing().g0))?;
        d.set_item("G2", matrix(py, &m.tilt_forcing().g2))?;
        d.set_item("G2_translation", matrix(py, &m.translation_forcing().g2))?;
        d.set_item("F", matrix(py, m.force_matrix()))?;
        d.set_item("C", matrix(py, m.observation()))?;
        d.set_item("q0", m.rest_configuration().as_slice().to_vec())?;
        let names = |v: Vec<&'static str>| PyList::new(py, v);
        d.set_item(
            "coordinates",
            names(Coord::ALL.iter().map(|c| c.name()).collect())?,
        )?;
        d.set_item(
            "observables",
            names(Observable::ALL.iter().map(|o| o.name()).collect())?,
        )?;
        d.set_item(
            "tilt_inputs",
            names(Input::all_tilts().into_iter().map(Input::name).collect())?,
        )?;
        d.set_item(
            "translation_inputs",
            names(
                Input::all_translations()
                    .into_iter()
                    .map(Input::name)
                    .collect(),
            )?,
        )?;
        d.set_item(
            "force_inputs",
            names(ForceInput::ALL.iter().map(|f| f.name()).collect())?,
        )?;
        Ok(d)
    }

    /// Monte Carlo of the normal modes over the parameter errors (the command line's
    /// ``tiltnoise mc``): Gaussian draws with the default error model (2.5 % on masses,
    /// lengths and inertias, 10 % on torsion and bouncing constants, g and h exact) or the
    /// parameter file's ``[uncertainty]`` table. The result depends on ``seed`` only, not on
    /// ``threads`` (0: every core).
    #[pyo3(signature = (samples=10_000, seed=1, threads=0))]
    fn monte_carlo(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = kw::samples)] samples: usize,
        #[pyo3(from_py_with = kw::seed)] seed: u64,
        #[pyo3(from_py_with = kw::threads)] threads: usize,
    ) -> PyResult<crate::monte_carlo::MonteCarlo> {
        crate::monte_carlo::run(py, self.params(), samples, seed, threads)
    }

    /// Every evaluation method's worst error against the double-double reference and its time
    /// per point (the command line's ``tiltnoise methods``), on ``freq_hz`` (frequencies in Hz,
    /// positive, ascending) for the matrix of every observable from ``inputs`` (names as in
    /// :meth:`transfer`; default the three tilt angles). Returns a dict with the keys of the
    /// command line's JSON report: ``matrix`` (what was measured, e.g. ``7x3 tilt matrix``),
    /// ``auto`` (the method ``method="auto"`` picks at ``target_rel_err``, or ``none (why)``),
    /// ``target_rel_err`` and ``methods``, one dict per method with ``name``, ``max_rel_err``,
    /// ``worst_entry``, ``worst_freq_hz``, ``ns_per_point``, ``exact_zeros`` and ``unusable``
    /// (``None`` where a value does not apply).
    #[pyo3(signature = (freq_hz, inputs=None))]
    fn methods<'py>(
        &self,
        py: Python<'py>,
        freq_hz: &Bound<'py, PyAny>,
        inputs: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let req = methods_request(&self.model, freq_hz, inputs)?;
        let result = py
            .detach(|| tiltnoise_job::methods::run(&req, &Cancel::never(), &Silent))
            .map_err(job_error)?;
        let methods = PyList::empty(py);
        for r in &result.rows {
            let row = PyDict::new(py);
            row.set_item("name", r.method.name())?;
            row.set_item("max_rel_err", r.worst.as_ref().map(|w| w.0))?;
            row.set_item("worst_entry", r.worst.as_ref().map(|w| w.1.clone()))?;
            row.set_item("worst_freq_hz", r.worst.as_ref().map(|w| w.2))?;
            row.set_item("ns_per_point", r.ns_per_point)?;
            row.set_item("exact_zeros", r.exact_zeros)?;
            row.set_item("unusable", r.unusable.clone())?;
            methods.append(row)?;
        }
        let d = PyDict::new(py);
        d.set_item("matrix", result.matrix_label())?;
        d.set_item("auto", result.auto_text())?;
        d.set_item("target_rel_err", result.target_rel_err)?;
        d.set_item("methods", methods)?;
        Ok(d)
    }

    /// Runs :meth:`methods` and writes its chart, time per point against worst error, as the
    /// command line's ``methods --save`` does: ``.png`` or ``.svg`` (the command line's chart
    /// for the same grid and inputs, drawn by the same code; the measured times, and so the
    /// points' places, differ from run to run), atomically. Raises
    /// ``ValueError`` for another extension, ``OSError`` if it cannot be written or is the
    /// parameter file.
    #[pyo3(signature = (path, freq_hz, inputs=None))]
    fn save_methods(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = kw::path)] path: std::path::PathBuf,
        freq_hz: &Bound<'_, PyAny>,
        inputs: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        tiltnoise_job::figures::image_format(&path).py()?;
        crate::inputs::Inputs::of_params(self.params_file.as_deref()).check_save(&path)?;
        let req = methods_request(&self.model, freq_hz, inputs)?;
        py.detach(|| {
            let result =
                tiltnoise_job::methods::run(&req, &Cancel::never(), &Silent).map_err(job_error)?;
            Staging::committed(|stage| result.save(stage, &path)).map_err(job_error)
        })
    }

    /// Constrained least-squares fit of the parameters ``free`` (dotted keys; default the
    /// command line's eight) to measured mode frequencies, each within ``bound_sigmas`` of its
    /// error bar, optionally with the Gaussian prior (the command line's ``tiltnoise fit``;
    /// ``docs/fit.md``). ``measured``: a CSV file ``mode,frequency_hz[,sigma_hz]`` (any subset
    /// of the modes); default Table II's measured column, or none when ``visibility`` is given.
    /// ``visibility``: a CSV file ``mode,observable,reference,ratio[,sigma]`` of measured mode
    /// visibilities (the command line's ``fit --visibility``), fitted together with the
    /// frequencies. Returns a :class:`Fit`.
    #[pyo3(signature = (free=None, measured=None, bound_sigmas=1.0, prior=false, visibility=None))]
    fn fit(
        &self,
        py: Python<'_>,
        free: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = kw::measured)] measured: Option<std::path::PathBuf>,
        #[pyo3(from_py_with = kw::bound_sigmas)] bound_sigmas: f64,
        #[pyo3(from_py_with = kw::prior)] prior: bool,
        #[pyo3(from_py_with = kw::visibility)] visibility: Option<std::path::PathBuf>,
    ) -> PyResult<crate::fit::Fit> {
        let free = crate::args::strings("free", free)?;
        let inputs = crate::fit::FitInputs {
            measured,
            visibility,
        };
        crate::fit::run(
            py,
            self.model.params(),
            self.params_file.as_deref(),
            free,
            inputs,
            bound_sigmas,
            prior,
        )
    }

    /// Free motion of the undamped model (the command line's ``tiltnoise simulate``): exact
    /// modal propagation sampled every ``step`` seconds for ``duration`` seconds, white
    /// readout noise, one-sided Welch ASDs and the resonance check. Returns a
    /// :class:`Simulation`.
    ///
    /// The initial state: ``kick_x`` (m), the paper's kick test (the test mass displaced
    /// statically along X and released from rest); or ``init`` / ``init_rate``, coordinates
    /// and rates as a dict ``{"theta_a": 1e-5, "phi_b": 0.01}`` or the command line's
    /// ``"theta_a=1e-5,phi_b=0.01"`` (rad, m; rad/s, m/s; unlisted ones 0); default: the
    /// energy ``mode_energy`` (J) in each of the eight modes. ``readout``: ``{observable:
    /// ASD}`` over the default ``{"X": 9e-9}`` (unit/sqrt(Hz); 0 removes one); ``seed`` of
    /// the noise; ``nperseg``: Welch segment (default the largest power of two <= n/3, at most
    /// 2**18).
    /// Raises ``ValueError`` for a damped model or options that do not fit, with the command
    /// line's messages.
    #[pyo3(signature = (duration=43_200.0, step=0.1, *, init=None, init_rate=None, kick_x=None, mode_energy=1e-12, readout=None, seed=0, nperseg=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        #[pyo3(from_py_with = kw::duration)] duration: f64,
        #[pyo3(from_py_with = kw::step)] step: f64,
        init: Option<&Bound<'_, PyAny>>,
        init_rate: Option<&Bound<'_, PyAny>>,
        #[pyo3(from_py_with = kw::kick_x)] kick_x: Option<f64>,
        #[pyo3(from_py_with = kw::mode_energy)] mode_energy: f64,
        #[pyo3(from_py_with = kw::readout)] readout: Option<Vec<(String, f64)>>,
        #[pyo3(from_py_with = kw::seed)] seed: u64,
        #[pyo3(from_py_with = kw::nperseg)] nperseg: Option<usize>,
    ) -> PyResult<crate::simulate::Simulation> {
        let args = crate::simulate::SimulateArgs {
            duration,
            step,
            init,
            init_rate,
            kick_x,
            mode_energy,
            readout,
            seed,
            nperseg,
        };
        crate::simulate::run(py, &self.model, self.params_file.as_deref(), args)
    }

    /// Pickles as its parameters (and the file they were read from).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), &slf.get().params())
    }

    /// The model of pickled parameters.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        PyModel::build(Some(&state::load("Model", version, state)?))
    }

    /// Equal when built from equal parameters (read from the same file, if any).
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        Ok(match other.cast::<PyModel>() {
            Ok(o) => {
                let o = o.get();
                self.model.params() == o.model.params() && self.params_file == o.params_file
            }
            Err(_) => false,
        })
    }

    fn __repr__(&self) -> String {
        format!("Model({})", self.params().describe())
    }
}

/// One normal mode (see :meth:`Model.modes`).
#[pyclass(module = "tiltnoise", frozen, get_all)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Mode {
    /// The label k of nu_k: the rank in frequency (the paper's nu_1 ... nu_8) for the
    /// symmetric pendulum, the symmetric mode it overlaps most for the pendulum as built.
    index: usize,
    /// Frequency (Hz), refined to the last bit in double-double.
    frequency_hz: f64,
    /// Eigenvalue w^2 (rad^2/s^2).
    omega_sq_rad2_per_s2: f64,
    /// Quality factor; ``inf`` when the model is undamped.
    quality_factor: f64,
    /// Modal loss angle 1/Q (rad).
    loss_angle_rad: f64,
    /// The decoupled block of the model the mode lives in, or ``coupled``.
    block: String,
    /// Mass-metric overlap with the symmetric pendulum's mode nu_index (1 when symmetric).
    overlap: f64,
    /// Amplitude in each observable over the largest of its unit group in this mode.
    ratio: BTreeMap<String, f64>,
    /// Observables whose ``ratio`` reaches 1e-4.
    seen_above_ratio: Vec<String>,
    /// ``(coordinate, share)`` of the coordinates with at least 5 % of the kinetic energy.
    dominant_coordinates: Vec<(String, f64)>,
    /// Share of the modal kinetic energy per coordinate (sums to 1).
    energy_share: BTreeMap<String, f64>,
    /// Observables that see the mode.
    seen_by: Vec<String>,
    /// Observable amplitudes of the mass-normalized shape.
    observable_amplitude: BTreeMap<String, f64>,
    /// Mass-normalized shape, coordinates in ``Model.matrices()["coordinates"]`` order.
    shape: Vec<f64>,
}

#[pymethods]
impl Mode {
    /// The quality factor (``inf`` when undamped).
    #[getter]
    fn q(&self) -> f64 {
        self.quality_factor
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        state::load("Mode", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        let dominant: Vec<String> = self
            .dominant_coordinates
            .iter()
            .map(|(c, s)| format!("{c} {s:.2}"))
            .collect();
        format!(
            "Mode(nu_{}: {:.6e} Hz, Q {}, {}; seen by {})",
            self.index,
            self.frequency_hz,
            self.quality_factor,
            dominant.join(", "),
            self.seen_by.join(" ")
        )
    }
}
