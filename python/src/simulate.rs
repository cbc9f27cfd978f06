//! `Model.simulate`: free motion of the undamped model, its one-sided Welch ASDs and the
//! resonance check (the command line's `tiltnoise simulate`), and the `Simulation` it returns.

use crate::args::kw;
use crate::errors::{value_error, PyResultExt};
use crate::inputs::Inputs;
use crate::interrupt;
use crate::job_args::job_error;
use crate::python_side;
use crate::state;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::model::{Coord, Model};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::simulate::{parse_coordinates, set_coordinate, Excitation};
use tiltnoise_job::figures::View;
use tiltnoise_job::files::Staging;
use tiltnoise_job::simulate::{HeldSimulation, Keep, SimulateRequest};
use tiltnoise_job::{Invocation, Outcome, Silent};

/// The options of `Model.simulate`, as given.
pub struct SimulateArgs<'a, 'py> {
    pub duration: f64,
    pub step: f64,
    pub init: Option<&'a Bound<'py, PyAny>>,
    pub init_rate: Option<&'a Bound<'py, PyAny>>,
    pub kick_x: Option<f64>,
    pub mode_energy: f64,
    pub readout: Option<Vec<(String, f64)>>,
    pub seed: u64,
    pub nperseg: Option<usize>,
}

/// Coordinates from a dict `{coordinate: value}` or a `str` `"theta_a=1e-5,phi_b=0.01"` (the
/// command line's syntax) into `out`.
fn coordinates(
    option: OptionKey,
    arg: Option<&Bound<'_, PyAny>>,
    rate: bool,
    out: &mut [f64; 8],
) -> PyResult<()> {
    let Some(arg) = arg else {
        return Ok(());
    };
    if let Ok(text) = arg.cast::<PyString>() {
        return parse_coordinates(option, &[text.to_cow()?], rate, out).py();
    }
    let kw = option.to_string();
    let values: Vec<(String, f64)> =
        crate::args::dict_of(&kw, arg, " or a str \"theta_a=1e-5,phi_b=0.01\"")?;
    for (name, value) in values {
        let item = format!("{name}={value}");
        set_coordinate(option, &item, &name, value, rate, out).py()?;
    }
    Ok(())
}

/// The excitation the options ask for: the kick, given coordinates and rates, or equal energy.
fn excitation(args: &SimulateArgs<'_, '_>) -> PyResult<Excitation> {
    let given = args.init.is_some() || args.init_rate.is_some();
    match args.kick_x {
        Some(_) if given => Err(value_error(
            "kick_x: the kick starts from a static deflection at rest; give either kick_x or \
             init/init_rate, not both",
        )),
        Some(x_m) => Ok(Excitation::KickX { x_m }),
        None if given => {
            let (mut q, mut qdot) = ([0.0; 8], [0.0; 8]);
            coordinates(OptionKey::INIT, args.init, false, &mut q)?;
            coordinates(OptionKey::INIT_RATE, args.init_rate, true, &mut qdot)?;
            Ok(Excitation::Given { q, qdot })
        }
        None => Ok(Excitation::EqualEnergy {
            energy_j: args.mode_energy,
        }),
    }
}

/// Runs the simulate job on `model`, the whole record kept (`Model.simulate`).
pub fn run(
    py: Python<'_>,
    model: &Model,
    params_file: Option<&std::path::Path>,
    args: SimulateArgs<'_, '_>,
) -> PyResult<Simulation> {
    let readout = args
        .readout
        .iter()
        .flatten()
        .map(|(name, asd)| options::readout_item(OptionKey::READOUT, name, *asd).py())
        .collect::<PyResult<Vec<_>>>()?;
    let req = SimulateRequest {
        model,
        duration_s: args.duration,
        step_s: args.step,
        excitation: excitation(&args)?,
        readout,
        seed: args.seed,
        nperseg: args.nperseg,
        chunk_samples: None,
        keep: Keep {
            record: true,
            ..Keep::default()
        },
        view: View::default(),
        invocation: Invocation::of_this_process(),
    };
    let cancel = Cancel::new();
    let r = interrupt::watch(py, &cancel, || {
        tiltnoise_job::simulate::run(&req, &cancel, &Silent).map_err(job_error)
    })?;
    let held = r
        .into_held(model.params())
        .ok_or_else(|| value_error("the simulation kept no record"))?;
    Ok(Simulation {
        held,
        inputs: Inputs::of_params(params_file),
    })
}

/// A simulated record of free motion (see :meth:`Model.simulate`): the seven observables with
/// their readout noise, the coordinates, the one-sided Welch ASDs and the resonance check.
///
/// ``time_s``, ``observables`` (``{observable: samples}``, m or rad), ``coordinates``
/// (``{coordinate: samples}``, noiseless, rad or m), ``frequency_hz`` (also ``freq_hz``, the
/// same) and ``asd`` (``{observable: ASD}`` in unit/sqrt(Hz), periodic Hann, ``nperseg``
/// samples, 50 % overlap, mean), ``resonance_check`` (the command line's table: which modes each channel shows,
/// against the observability table) and ``resonances_agree``. :meth:`save` writes the
/// command line's files; an ``.h5`` file is a measured record for ``budget(measured=...)``.
#[pyclass(module = "tiltnoise", frozen)]
#[derive(serde::Serialize, serde::Deserialize)]
pub struct Simulation {
    /// The record and all its files need (the job's).
    held: HeldSimulation,
    /// The parameter file, which no `save` may replace.
    inputs: Inputs,
}

#[pymethods]
impl Simulation {
    /// Sampling step (s).
    #[getter]
    fn dt_s(&self) -> f64 {
        self.held.sim.dt_s
    }

    /// Sample rate (Hz).
    #[getter]
    fn fs_hz(&self) -> f64 {
        self.held.sim.fs_hz()
    }

    /// Number of samples.
    #[getter]
    fn n_samples(&self) -> usize {
        self.held.sim.len()
    }

    /// Sample times ``i * dt_s`` (s).
    #[getter]
    fn time_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let dt = self.held.sim.dt_s;
        PyArray1::from_iter(py, (0..self.held.sim.len()).map(|i| i as f64 * dt))
    }

    /// ``{observable: samples}`` of all seven observables (m for X, Y, Z; rad for the angles),
    /// with readout noise where there is one.
    #[getter]
    fn observables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (o, x) in &self.held.sim.observables {
            d.set_item(o.name(), PyArray1::from_slice(py, x))?;
        }
        Ok(d)
    }

    /// ``{coordinate: samples}`` of the eight generalized coordinates (rad; m for the
    /// elongations ``delta_a``, ``delta_b``), noiseless.
    #[getter]
    fn coordinates<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for c in Coord::ALL {
            d.set_item(
                c.name(),
                PyArray1::from_vec(py, self.held.sim.coordinate(c.index())),
            )?;
        }
        Ok(d)
    }

    /// ``{"q": {coordinate: value}, "qdot": {coordinate: rate}}`` at t = 0 (SI units).
    #[getter]
    fn initial_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (key, values) in [
            ("q", &self.held.meta.init.q),
            ("qdot", &self.held.meta.init.qdot),
        ] {
            let v = PyDict::new(py);
            for c in Coord::ALL {
                v.set_item(c.name(), values[c.index()])?;
            }
            d.set_item(key, v)?;
        }
        Ok(d)
    }

    /// Where the initial state came from (kick, given values, or equal energy per mode).
    #[getter]
    fn init_source(&self) -> &str {
        &self.held.meta.init_source
    }

    /// ``{observable: white readout ASD}`` (unit/sqrt(Hz)); the others are noiseless.
    #[getter]
    fn readout<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (o, a) in &self.held.meta.readout_asd {
            d.set_item(o.name(), a)?;
        }
        Ok(d)
    }

    /// Seed of the readout noise.
    #[getter]
    fn seed(&self) -> u64 {
        self.held.meta.seed
    }

    /// Frequencies of the ASDs (Hz): ``k fs / nperseg``, DC included (the files'
    /// ``frequency_hz``).
    #[getter]
    fn frequency_hz<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.held.asd.freqs_hz)
    }

    /// The same as ``frequency_hz``.
    #[getter]
    fn freq_hz<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.frequency_hz(py)
    }

    /// ``{observable: one-sided ASD}`` (unit/sqrt(Hz)) of each observable's samples.
    #[getter]
    fn asd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (o, a) in &self.held.asd.asd {
            d.set_item(o.name(), PyArray1::from_slice(py, a))?;
        }
        Ok(d)
    }

    /// ``[(k, frequency_hz)]`` of the model's modes nu_k (Hz).
    #[getter]
    fn modes_hz(&self) -> Vec<(usize, f64)> {
        self.held.modes_hz.clone()
    }

    /// Welch segment of the ASDs (samples).
    #[getter]
    fn nperseg(&self) -> usize {
        self.held.asd.segment_len
    }

    /// Welch segments averaged.
    #[getter]
    fn n_welch_segments(&self) -> usize {
        self.held.asd.n_segments
    }

    /// The resonance check as the command line prints it: for each channel, the modes its
    /// ASD shows and whether that agrees with the observability table.
    #[getter]
    fn resonance_check(&self) -> &str {
        &self.held.check_table
    }

    /// Whether every tested mode is seen exactly where the observability table says.
    #[getter]
    fn resonances_agree(&self) -> bool {
        self.held.check_agrees
    }

    /// One sentence on the run (samples, step, initial state, readout, seed).
    #[getter]
    fn description(&self) -> &str {
        &self.held.description
    }

    /// Writes the run as the command line's ``simulate --save`` does, atomically: ``.h5`` /
    /// ``.hdf5`` (the series, the ASDs and the run's provenance; schema
    /// ``tiltnoise.observable_series``, readable by ``budget(measured=...)``), ``.csv``
    /// (the ASDs, ``freq_hz,X,...``), or the command line's figure of the ASDs as ``.png`` or
    /// ``.svg`` (the same image as ``tiltnoise simulate --save x.png`` for the same run).
    /// Raises ``OSError`` if it cannot be written or is the parameter file of the model,
    /// ``ValueError`` for another extension.
    fn save(&self, py: Python<'_>, #[pyo3(from_py_with = kw::path)] path: PathBuf) -> PyResult<()> {
        tiltnoise_job::output_kind(&path, tiltnoise_job::simulate::OUTPUT_KINDS).py()?;
        self.inputs.check_save(&path)?;
        py.detach(|| Staging::committed(|stage| self.held.save(stage, &path)))
            .map_err(job_error)
    }

    /// ``{"observables": {observable: gwpy.timeseries.TimeSeries}, "asd": {observable:
    /// gwpy.frequencyseries.FrequencySeries}}``: the samples (``t0 = 0``, ``dt = dt_s``) and
    /// the ASDs, each named by its observable, with its unit. Needs gwpy (``pip install
    /// gwpy``); raises ``ImportError`` saying so without it.
    fn to_gwpy<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_convert", "simulation_to_gwpy", &[])
    }

    /// ``{"observables": DataFrame indexed by time_s, "asd": DataFrame indexed by
    /// frequency_hz}``, one column per observable, units in each frame's ``attrs["units"]``.
    /// Needs pandas (``pip install pandas``); raises ``ImportError`` saying so without it.
    fn to_pandas<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_convert", "simulation_to_pandas", &[])
    }

    /// The ASDs drawn with matplotlib, log-log, displacements and angles in two panels, the
    /// modes marked. Returns a new ``matplotlib.figure.Figure`` (of ``matplotlib.pyplot``).
    /// Needs matplotlib; raises ``ImportError`` saying so without it.
    fn plot<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        python_side::call(slf.as_any(), "_plots", "simulation_plot", &[])
    }

    /// Pickles as its state (see the module's pickling notes).
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<state::Reduced<'py>> {
        state::reduce(slf.as_any(), slf.get())
    }

    /// The object of a pickled state.
    #[staticmethod]
    fn _from_state(version: u32, state: &[u8]) -> PyResult<Self> {
        state::load("Simulation", version, state)
    }

    /// Equal when every value is equal bit for bit and the same files are behind them.
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> PyResult<bool> {
        state::equal(self, other)
    }

    fn __repr__(&self) -> String {
        format!("Simulation({})", self.held.description)
    }
}
