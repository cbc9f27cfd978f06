//! The simulate job: free motion of the undamped model (exact modal propagation) with white
//! readout noise, streamed chunk by chunk through the HDF5 records being written, the Welch
//! accumulators and the pieces of the time-series figure, to the one-sided ASDs and the
//! resonance check against the observability table; [`driven`] drives the model with a record
//! of the floor's motion instead. The record is held whole only when the caller asks for it.

pub mod driven;
mod outcome;
mod outputs;

pub use outcome::HeldSimulation;
pub use outputs::asd_figure_data;

/// The kinds of file a simulation is saved as: the record with its spectra (HDF5), the spectra
/// (CSV) and the ASD figure.
pub const OUTPUT_KINDS: &[tiltnoise_io::OutputKind] = crate::outcome::SPECTRA_KINDS;

use crate::error::JobError;
use crate::outcome::{Invocation, Provenance};
use crate::progress::Progress;
use std::path::PathBuf;
use std::sync::Mutex;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::limits::{check_memory, planned_bytes, STREAMED_WELCH_BYTES_PER_SAMPLE};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::noise::Readout;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options::{self, OptionError};
use tiltnoise_core::simulate::resonance::{check_resonances, ResonanceCheck};
use tiltnoise_core::simulate::stream::{FreeMotion, MinMaxEnvelope, SimChunk};
use tiltnoise_core::simulate::{
    check_sampling, describe_run, initial_state, Excitation, InitialState, ModalPropagator,
    SimConfig, SimError, Simulation,
};
use tiltnoise_core::spectral::{Psd, WelchAccumulator, WelchConfig};
use tiltnoise_io::{ObservableSeriesWriter, SeriesAsd};
use tiltnoise_plot::simulate_figure::{TimePanel, TimeSeriesData};
use tiltnoise_plot::View;

/// A free-motion simulation to run.
pub struct SimulateRequest<'a> {
    /// The model (undamped).
    pub model: &'a Model,
    /// Length of the record (s).
    pub duration_s: f64,
    /// Sampling step (s).
    pub step_s: f64,
    /// The initial state asked for.
    pub excitation: Excitation,
    /// White readout ASDs `(observable, unit/sqrt(Hz))` over the default (9e-9 m/sqrt(Hz) on
    /// X), in order; 0 removes one.
    pub readout: Vec<(Observable, f64)>,
    /// Seed of the readout noise.
    pub seed: u64,
    /// Welch segment of the ASDs (default `default_sim_nperseg`).
    pub nperseg: Option<usize>,
    /// Samples computed per chunk (default `SERIES_CHUNK_SAMPLES`); the numbers do not
    /// depend on it.
    pub chunk_samples: Option<usize>,
    /// What of the record to keep besides its spectra.
    pub keep: Keep,
    /// The limits, size and resolution of the figures the run is saved to.
    pub view: View,
    /// Who asked for the run (the provenance of its files).
    pub invocation: Invocation,
}

/// What a simulation keeps of its record: its spectra always; the rest only when asked, so
/// that a long record streams through in bounded memory.
#[derive(Debug, Clone, Default)]
pub struct Keep {
    /// The whole record, coordinates included ([`SimulateResult::record`]).
    pub record: bool,
    /// HDF5 files the record streams to (each completed with the spectra when the result
    /// saves it: [`Outcome::save`](crate::Outcome::save)).
    pub hdf5: Vec<PathBuf>,
    /// Write the generalized coordinates to the HDF5 files too.
    pub hdf5_coordinates: bool,
    /// The data of the time-series figure (phi over the run, X over a quarter of nu_1).
    pub time_figure: bool,
}

/// A simulated free motion: its spectra, the resonance check and what was kept.
pub struct SimulateResult {
    /// Samples.
    pub n_samples: usize,
    /// Sampling step (s).
    pub dt_s: f64,
    /// The initial state.
    pub init: InitialState,
    /// Where it came from (kick, given values, equal energy).
    pub init_source: String,
    /// The readout, in observable order.
    pub readout: Vec<(Observable, f64)>,
    /// Seed of the readout noise.
    pub seed: u64,
    /// Length asked for (s).
    pub duration_s: f64,
    /// One sentence on the run (samples, step, initial state, readout, seed).
    pub description: String,
    /// One-sided Welch ASDs of the observables.
    pub asd: SeriesAsd,
    /// Which modes each channel shows, against the observability table.
    pub check: ResonanceCheck,
    /// The model's normal modes.
    pub modes: NormalModes,
    /// What the files record: the parameters, the modes and the invocation.
    pub provenance: Provenance,
    /// The whole record, when [`Keep::record`].
    pub record: Option<Simulation>,
    /// The time-series figure, when [`Keep::time_figure`].
    pub time_figure: Option<TimeSeriesData>,
    /// The view of the figures (the request's).
    view: View,
    /// The HDF5 files written as the record streamed, each to be completed with the spectra
    /// when it is saved.
    streamed: Mutex<Vec<(PathBuf, ObservableSeriesWriter)>>,
}

impl SimulateResult {
    /// Sample rate (Hz).
    pub fn fs_hz(&self) -> f64 {
        1.0 / self.dt_s
    }

    /// The writer of the HDF5 file `path` the record streamed to, once.
    fn take_streamed(&self, path: &std::path::Path) -> Option<ObservableSeriesWriter> {
        let mut streamed = self.streamed.lock().unwrap_or_else(|e| e.into_inner());
        let k = streamed.iter().position(|(p, _)| p == path)?;
        Some(streamed.swap_remove(k).1)
    }
}

/// The readout of `items` over the default (9e-9 m/sqrt(Hz) on X), each observable once, in
/// observable order.
fn readout(items: &[(Observable, f64)]) -> Result<Vec<(Observable, f64)>, OptionError> {
    let mut readout =
        options::apply_readout(OptionKey::READOUT, Readout::default(), items, None)?.asd;
    readout.sort_by_key(|(o, _)| o.index());
    Ok(readout)
}

/// Points of the whole-run panel of the time-series figure: the minimum and maximum of at most
/// this many blocks of samples (the figure shows 4000 columns).
const TIME_FIGURE_BLOCKS: usize = 1 << 15;

/// The coordinates per sample and the seven observables of a record held whole.
type HeldRecord = (Vec<[f64; 8]>, Vec<Vec<f64>>);

/// What streams out of the record besides the files: the Welch accumulators, the whole
/// record and the time-figure pieces when kept.
struct Sinks {
    welch: Vec<WelchAccumulator>,
    writers: Vec<(PathBuf, ObservableSeriesWriter)>,
    record: Option<HeldRecord>,
    phi: Option<MinMaxEnvelope>,
    x_start: Option<(Vec<f64>, usize)>,
}

impl Sinks {
    fn push(&mut self, chunk: &SimChunk) -> Result<(), JobError> {
        for (_, w) in &mut self.writers {
            w.append(chunk)?;
        }
        for (acc, x) in self.welch.iter_mut().zip(&chunk.observables) {
            acc.push(&[x])?;
        }
        if let Some((q, obs)) = &mut self.record {
            q.extend_from_slice(&chunk.q);
            for (all, part) in obs.iter_mut().zip(&chunk.observables) {
                all.extend_from_slice(part);
            }
        }
        if let Some(e) = &mut self.phi {
            e.push(chunk.observable(Observable::Phi));
        }
        if let Some((x_start, n_x)) = &mut self.x_start {
            let x = chunk.observable(Observable::X);
            let missing = *n_x - x_start.len().min(*n_x);
            x_start.extend_from_slice(&x[..x.len().min(missing)]);
        }
        Ok(())
    }
}

/// Checks the request: an undamped model, the sampling and the segment within the limits of
/// a record that streams (or is held whole), a chunk of at least one sample. Returns the
/// samples, the Welch segment and the chunk.
fn check(req: &SimulateRequest<'_>) -> Result<(usize, usize, usize), JobError> {
    if !req.model.is_undamped() {
        return Err(SimError::Damped.into());
    }
    let (n, nperseg) = check_sampling(req.duration_s, req.step_s, req.nperseg, !req.keep.record)?;
    check_memory(
        || {
            tiltnoise_core::message!(
                "{}: Welch segments of the 7 observables",
                OptionKey::NPERSEG.given(nperseg)
            )
        },
        planned_bytes(nperseg, 7 * STREAMED_WELCH_BYTES_PER_SAMPLE),
    )?;
    let chunk = match req.chunk_samples {
        Some(0) => {
            return Err(JobError::option(
                OptionKey::CHUNK_SAMPLES,
                Some("0"),
                "a chunk must hold at least 1 sample".to_string(),
            ))
        }
        Some(c) => c,
        None => tiltnoise_io::SERIES_CHUNK_SAMPLES,
    };
    Ok((n, nperseg, chunk))
}

/// Runs the simulation: checks the request, streams the record chunk by chunk through the
/// HDF5 files, the Welch accumulators and what is kept (`progress` told the samples done
/// after each chunk, and finished once), and checks the resonances.
///
/// # Errors
///
/// A [`JobError`] naming the option that is not allowed; `Simulate` wrapping the cancellation
/// when `cancel` was set; `Output` for an HDF5 file that cannot be written.
pub fn run(
    req: &SimulateRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<SimulateResult, JobError> {
    let result = simulate(req, cancel, progress);
    progress.finish();
    result
}

fn simulate(
    req: &SimulateRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<SimulateResult, JobError> {
    let (n, nperseg, chunk_samples) = check(req)?;
    let model = req.model;
    let readout = readout(&req.readout)?;
    let (init, init_source) = initial_state(model, &req.excitation)?;
    let cfg = SimConfig {
        dt_s: req.step_s,
        duration_s: req.duration_s,
        readout_asd: readout.clone(),
        seed: req.seed,
        cancel: cancel.clone(),
    };
    let coordinates = req.keep.record || req.keep.hdf5_coordinates;
    let mut motion = FreeMotion::new(model, &init, &cfg, coordinates)?;
    let dt_s = motion.dt_s();
    let mut result = SimulateResult {
        n_samples: n,
        dt_s,
        init,
        description: describe_run((n, dt_s), &init_source, &readout, req.seed),
        init_source,
        readout,
        seed: req.seed,
        duration_s: req.duration_s,
        asd: SeriesAsd {
            freqs_hz: Vec::new(),
            asd: Vec::new(),
            segment_len: nperseg,
            overlap: WelchConfig::new(nperseg).overlap,
            averaging: "mean".to_string(),
            n_segments: 0,
        },
        // Filled in with the spectra when the record has streamed through.
        check: ResonanceCheck {
            df_hz: f64::NAN,
            fs_hz: 1.0 / dt_s,
            channels: Vec::new(),
        },
        modes: NormalModes::new(model),
        provenance: Provenance::default(),
        record: None,
        time_figure: None,
        view: req.view.clone(),
        streamed: Mutex::new(Vec::new()),
    };
    result.provenance = req
        .invocation
        .provenance(model.params(), Some(&result.modes));
    let mut sinks = Sinks::new(&req.keep, &result)?;
    let mut chunk = SimChunk::default();
    while {
        cancel.check().map_err(SimError::from)?;
        motion.next_chunk(chunk_samples, &mut chunk)
    } {
        sinks.push(&chunk)?;
        progress.report(motion.samples_done() as u64, n as u64);
    }
    sinks.finish(&mut result, model)?;
    Ok(result)
}

impl Sinks {
    /// The sinks of `keep` for the run `result` describes (its HDF5 files created).
    fn new(keep: &Keep, result: &SimulateResult) -> Result<Sinks, JobError> {
        let (n, dt_s) = (result.n_samples, result.dt_s);
        let wcfg = WelchConfig::new(result.asd.segment_len);
        let meta = result.simulation_meta();
        let writers = keep
            .hdf5
            .iter()
            .map(|p| {
                let w = ObservableSeriesWriter::create(p, dt_s, &meta, keep.hdf5_coordinates)?;
                Ok((p.clone(), w))
            })
            .collect::<Result<Vec<_>, tiltnoise_io::OutputError>>()?;
        let welch = Observable::ALL
            .iter()
            .map(|_| WelchAccumulator::new(1, 1.0 / dt_s, &wcfg))
            .collect::<Result<Vec<_>, _>>()?;
        // The second panel of the time-series figure: X over the first quarter of the nu_1
        // period (a fraction of a torsion period, to show the swinging oscillations).
        let quarter_s = 0.25 / result.modes.modes[0].frequency_hz;
        let n_x = ((quarter_s / dt_s).ceil() as usize).clamp(2, n);
        Ok(Sinks {
            welch,
            writers,
            record: keep.record.then(|| {
                (
                    Vec::with_capacity(n),
                    (0..7).map(|_| Vec::with_capacity(n)).collect(),
                )
            }),
            phi: keep
                .time_figure
                .then(|| MinMaxEnvelope::new(n, TIME_FIGURE_BLOCKS)),
            x_start: keep.time_figure.then(|| (Vec::with_capacity(n_x), n_x)),
        })
    }

    /// The spectra, the resonance check and what was kept, into `result`.
    fn finish(self, result: &mut SimulateResult, model: &Model) -> Result<(), JobError> {
        let mut psds = Vec::with_capacity(7);
        for (o, acc) in Observable::ALL.into_iter().zip(self.welch) {
            let m = acc.finish()?;
            psds.push((
                o,
                Psd {
                    psd: m.psd(0),
                    freqs_hz: m.freqs_hz,
                    n_segments: m.n_segments,
                },
            ));
        }
        let prop = ModalPropagator::new(model, &result.init, result.dt_s)?;
        let (u0, v0) = prop.initial_modal_state();
        let amplitude: [f64; 8] = std::array::from_fn(|k| u0[k].hypot(v0[k]));
        let (fs, nperseg) = (result.fs_hz(), result.asd.segment_len);
        result.check = check_resonances(
            &result.modes,
            &amplitude,
            &psds,
            fs,
            nperseg,
            &result.readout,
        );
        result.asd.freqs_hz = psds[0].1.freqs_hz.clone();
        result.asd.asd = psds.iter().map(|(o, p)| (*o, p.asd())).collect();
        result.asd.n_segments = psds[0].1.n_segments;
        result.record = self.record.map(|(q, obs)| Simulation {
            dt_s: result.dt_s,
            q,
            observables: Observable::ALL.into_iter().zip(obs).collect(),
        });
        if let (Some(phi), Some((x, _))) = (self.phi, self.x_start) {
            let (values, spacing) = phi.finish();
            result.time_figure = Some(time_series_data(
                (values, spacing * result.dt_s),
                (x, result.dt_s),
                &result.init_source,
            ));
        }
        result.streamed = Mutex::new(self.writers);
        Ok(())
    }
}

/// Figures 4 and 5: phi over the whole run (`(values, spacing in s)`: the series, or its
/// min/max envelope for a long run), X over the first quarter of the nu_1 period.
fn time_series_data(
    (phi, phi_dt_s): (Vec<f64>, f64),
    (x, dt_s): (Vec<f64>, f64),
    init_source: &str,
) -> TimeSeriesData {
    TimeSeriesData {
        title: format!("Simulated free motion ({init_source})"),
        panels: vec![
            TimePanel {
                title: "φ: test-mass torsion, whole run (cf. Figure 4)".to_string(),
                observable: Observable::Phi,
                dt_s: phi_dt_s,
                t0_s: 0.0,
                values: phi,
            },
            TimePanel {
                title: format!(
                    "X: test-mass displacement, first {:.0} s = 1/4 of the ν1 period (cf. Figure 5)",
                    x.len() as f64 * dt_s
                ),
                observable: Observable::X,
                dt_s,
                t0_s: 0.0,
                values: x,
            },
        ],
    }
}
