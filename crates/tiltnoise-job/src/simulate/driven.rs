//! The driven simulation: the undamped model driven by a record of the floor's motion, tilt
//! and translation channels ([`tiltnoise_core::simulate::driven`]), optionally through
//! miscalibrated, late sensors (gains, a delay): a controlled record of the observables, for
//! example to test a subtraction, which should find those gains and that delay.

use super::outputs::{asd_figure_data, RecordOutputs};
use crate::budget::ReadRequest;
use crate::error::{shown_path, JobError};
use crate::outcome::{Outcome, Provenance};
use crate::progress::Progress;
use std::path::Path;
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::Num;
use tiltnoise_core::input::GroundMap;
use tiltnoise_core::limits::GAINS;
use tiltnoise_core::model::{Input, Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::simulate::default_sim_nperseg;
use tiltnoise_core::simulate::driven::{
    drive_from_record, quasi_static_start, simulate_driven, DrivenConfig,
};
use tiltnoise_core::simulate::{InitialState, SimError, Simulation};
use tiltnoise_core::spectral::{welch, WelchConfig};
use tiltnoise_io::input::{read_tilt, TiltInput};
use tiltnoise_io::{OutputKind, SeriesAsd, SimulationMeta, Staging};
use tiltnoise_plot::View;

/// A driven simulation to run.
pub struct DrivenRequest<'a> {
    /// The model (undamped).
    pub model: &'a Model,
    /// The record of the floor's motion (HDF5, CSV or miniSEED time series).
    pub tilt: PathBuf,
    /// How to read it.
    pub read: ReadRequest,
    /// Fine steps per record sample of the propagation.
    pub oversample: usize,
    /// The pendulum sees GAIN times the record's channel of an input, `(input name, gain)`
    /// (others 1), each input once.
    pub drive_gain: Vec<(String, f64)>,
    /// The pendulum sees the record this many seconds late (a whole number of fine steps).
    pub drive_delay_s: Option<f64>,
    /// White readout ASDs over the default, as for free motion.
    pub readout: Vec<(Observable, f64)>,
    /// Seed of the readout noise.
    pub seed: u64,
    /// Welch segment of the ASDs (default `default_sim_nperseg`).
    pub nperseg: Option<usize>,
    /// The limits, size and resolution of the figures the run is saved to.
    pub view: View,
    /// Who asked for the run (the provenance of its files).
    pub invocation: crate::Invocation,
}

impl DrivenRequest<'_> {
    /// The files the job reads, each with the option (snake case) that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &std::path::Path)> {
        vec![("tilt", &self.tilt)]
    }
}

/// A driven record of the observables and its spectra.
pub struct DrivenResult {
    /// The record, at the rate of the floor's record.
    pub record: Simulation,
    /// One-sided Welch ASDs of the observables.
    pub asd: SeriesAsd,
    /// The quasi-static start.
    pub init: InitialState,
    /// The readout, in observable order.
    pub readout: Vec<(Observable, f64)>,
    /// Seed of the readout noise.
    pub seed: u64,
    /// Sample rate (Hz).
    pub fs_hz: f64,
    /// What was simulated, in one paragraph (the files' description).
    pub description: String,
    /// The reader's and the ground map's notes on the floor's record.
    pub notes: Vec<String>,
    /// The floor record's start time, when it states one.
    pub start_time: Option<String>,
    /// The model's normal modes.
    pub modes: NormalModes,
    /// What the files record: the parameters, the modes and the invocation.
    pub provenance: crate::Provenance,
    /// The view of the figures (the request's).
    view: View,
}

impl DrivenResult {
    /// The provenance a saved record carries.
    pub fn simulation_meta(&self) -> SimulationMeta {
        SimulationMeta {
            run: self.provenance.clone(),
            description: self.description.clone(),
            start_time: self.start_time.clone(),
            seed: self.seed,
            init: self.init,
            init_source: "quasi-static state of the drive's first sample".into(),
            readout_asd: self.readout.clone(),
            duration_s: self.record.len() as f64 / self.fs_hz,
        }
    }
}

/// The gain of each input of the record (1 unless given).
fn gains(given: &[(String, f64)], inputs: &[Input]) -> Result<Vec<f64>, JobError> {
    let mut gains = vec![1.0; inputs.len()];
    for (name, g) in given {
        let item = format!("{name}={}", Num(*g));
        let i = inputs
            .iter()
            .position(|a| a.name() == name)
            .ok_or_else(|| {
                let names: Vec<&str> = inputs.iter().map(|a| a.name()).collect();
                JobError::option(
                    OptionKey::DRIVE_GAIN,
                    Some(&item),
                    format!(
                        "the record has no input `{name}`; it has {}",
                        names.join(", ")
                    ),
                )
            })?;
        if !GAINS.admits(*g) {
            return Err(JobError::option(
                OptionKey::DRIVE_GAIN,
                Some(&item),
                format!(
                    "the gain {} is not allowed: must be {} (see docs/limits.md)",
                    Num(*g),
                    GAINS.allowed("")
                ),
            ));
        }
        gains[i] = *g;
    }
    Ok(gains)
}

/// The delay in fine steps of `1 / (fs oversample)` s.
fn delay_steps(delay_s: f64, fs_hz: f64, oversample: usize) -> Result<i64, JobError> {
    let fine_step = 1.0 / (fs_hz * oversample as f64);
    let steps = delay_s / fine_step;
    if !(steps.is_finite() && (steps - steps.round()).abs() <= 1e-9 * steps.abs().max(1.0)) {
        return Err(JobError::option(
            OptionKey::DRIVE_DELAY,
            Some(&format!("{} s", Num(delay_s))),
            tiltnoise_core::message!(
                "must be a whole number of fine steps of {} s (the record's step / {})",
                Num(fine_step),
                OptionKey::OVERSAMPLE.given(oversample)
            ),
        ));
    }
    Ok(steps.round() as i64)
}

/// One-sided Welch ASDs of every observable of `sim`.
fn spectra(sim: &Simulation, fs: f64, nperseg: Option<usize>) -> Result<SeriesAsd, JobError> {
    let n = sim.len();
    let nperseg = nperseg.unwrap_or_else(|| default_sim_nperseg(n));
    if !(16..=n).contains(&nperseg) {
        return Err(JobError::option(
            OptionKey::NPERSEG,
            Some(&nperseg.to_string()),
            format!("the Welch segment must have 16 to {n} samples (the record's length)"),
        ));
    }
    let wcfg = WelchConfig::new(nperseg);
    let mut psds = Vec::new();
    for (o, x) in &sim.observables {
        psds.push((*o, welch(x, fs, &wcfg)?));
    }
    Ok(SeriesAsd {
        freqs_hz: psds[0].1.freqs_hz.clone(),
        asd: psds.iter().map(|(o, p)| (*o, p.asd())).collect(),
        segment_len: nperseg,
        overlap: wcfg.overlap,
        averaging: "mean".to_string(),
        n_segments: psds[0].1.n_segments,
    })
}

/// Runs the driven simulation: reads the record once, maps its channels to the model's
/// inputs (inertial sensors corrected), interpolates the drive band-limited to the fine step,
/// propagates it exactly from the quasi-static state and computes the ASDs.
///
/// # Errors
///
/// A [`JobError`] naming the option or file that failed; `Simulate` wrapping the cancellation
/// when `cancel` was set.
pub fn run(
    req: &DrivenRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<DrivenResult, JobError> {
    let result = driven(req, cancel);
    progress.finish();
    result
}

fn driven(req: &DrivenRequest<'_>, cancel: &Cancel) -> Result<DrivenResult, JobError> {
    let model = req.model;
    if !model.is_undamped() {
        return Err(SimError::Damped.into());
    }
    let shown = shown_path(&req.tilt);
    let series = match read_tilt(&req.tilt, &req.read.options())? {
        TiltInput::Series(s) => s,
        TiltInput::Spectra(_) => {
            return Err(JobError::option(
                OptionKey::TILT,
                Some(&shown),
                "holds spectra; a driven simulation needs a time series".to_string(),
            ))
        }
    };
    let g = model.params().environment.g_m_per_s2;
    let map = GroundMap::new(&series.channels(), g)
        .map_err(|e| JobError::option(OptionKey::TILT, Some(&shown), e.to_string()))?;
    let inputs: Vec<Input> = map.inputs();
    let channel_data: Vec<Vec<f64>> = series.channel_data().iter().map(|c| c.to_vec()).collect();
    let displacements = map.displacements(&channel_data, series.sample_rate_hz);
    let gains = gains(&req.drive_gain, &inputs)?;
    let fs = series.sample_rate_hz;
    let m = req.oversample;
    let delay_s = req.drive_delay_s.unwrap_or(0.0);
    let steps = delay_steps(delay_s, fs, m)?;
    let readout = super::readout(&req.readout)?;
    let drive = drive_from_record(1.0 / fs, &inputs, &displacements, m, &gains, steps)?;
    let init = quasi_static_start(model, &drive)?;
    let config = DrivenConfig {
        keep_every: m,
        readout_asd: readout.clone(),
        seed: req.seed,
        cancel: cancel.clone(),
    };
    let record = simulate_driven(model, &drive, &config)?;
    let asd = spectra(&record, fs, req.nperseg)?;
    let drive_text: Vec<String> = inputs
        .iter()
        .zip(&gains)
        .map(|(a, g)| format!("{} x {g}", a.name()))
        .collect();
    let description = format!(
        "SIMULATED response of the undamped pendulum model (not a measurement) to the record \
         {shown} of the floor's motion ({}, delayed by {} s), interpolated band-limited to {} s \
         steps and propagated exactly for the interpolated motion; quasi-static start; \
         readout: {}; seed {}.",
        drive_text.join(", "),
        Num(delay_s),
        Num(1.0 / (fs * m as f64)),
        tiltnoise_core::simulate::readout_text(&readout),
        req.seed
    );
    let notes = (series.provenance.notes.iter())
        .chain(map.notes())
        .chain(&map.series_note())
        .cloned()
        .collect();
    Ok(DrivenResult {
        record,
        asd,
        init,
        readout,
        seed: req.seed,
        fs_hz: fs,
        description,
        notes,
        start_time: series.provenance.start_time.clone(),
        provenance: req
            .invocation
            .provenance(model.params(), Some(&NormalModes::new(model))),
        modes: NormalModes::new(model),
        view: req.view.clone(),
    })
}

impl Outcome for DrivenResult {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        super::OUTPUT_KINDS
    }

    /// `.h5` (the record, its spectra and provenance), `.csv` (the ASDs) or the ASD figure
    /// with the request's view.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        let meta = self.simulation_meta();
        let figure = asd_figure_data(
            &self.asd,
            &self.readout,
            &self.modes,
            self.fs_hz,
            &self.description,
        );
        let outputs = RecordOutputs {
            record: Some((&self.record, &meta)),
            asd: &self.asd,
            run: &self.provenance,
            figure: &figure,
        };
        Ok(super::outputs::save(stage, path, &outputs, &self.view)?)
    }

    /// The record's notes, its length and rate, and what was simulated.
    fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "input_notes": self.notes,
            "samples": self.record.len(),
            "sample_rate_hz": self.fs_hz,
            "duration_s": self.record.len() as f64 / self.fs_hz,
            "description": self.description,
            "seed": self.seed,
        })
    }
}
