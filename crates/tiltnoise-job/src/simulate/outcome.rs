//! What a free-motion simulation leaves, for every front end: [`SimulateResult`], the run as
//! it streamed (its HDF5 files completed as they are saved), and [`HeldSimulation`], a record
//! held whole that a caller keeps and saves later (Python's `Simulation`, which pickles it).
//! Both save by output kind ([`super::OUTPUT_KINDS`]) and render the same JSON summary.

use super::outputs::{asd_figure_data, save, save_time_figure, RecordOutputs};
use super::{SimulateResult, OUTPUT_KINDS};
use crate::error::{shown_path, JobError};
use crate::outcome::{output_kind, Outcome, Provenance};
use std::path::Path;
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{aliased_frequency_hz, record_description, Simulation};
use tiltnoise_io::{OutputKind, SeriesAsd, SimulationMeta, Staging};
use tiltnoise_plot::View;

impl SimulateResult {
    /// The provenance a saved record carries.
    pub fn simulation_meta(&self) -> SimulationMeta {
        SimulationMeta {
            run: self.provenance.clone(),
            description: record_description(&self.description),
            start_time: None,
            seed: self.seed,
            init: self.init,
            init_source: self.init_source.clone(),
            readout_asd: self.readout.clone(),
            duration_s: self.duration_s,
        }
    }

    /// Draws the time-series figure (Figures 4 and 5) to `path` (`.png`, `.svg`) with the
    /// request's view, as one of the outputs of `stage`.
    ///
    /// # Errors
    ///
    /// [`JobError::Option`] naming `save_time` when the run kept no time-series figure
    /// ([`super::Keep::time_figure`]); the writer's error.
    pub fn save_time_figure(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        let Some(data) = &self.time_figure else {
            return Err(JobError::option(
                OptionKey::SAVE_TIME,
                Some(&shown_path(path)),
                "the run kept no time-series figure (ask for it before the run)",
            ));
        };
        Ok(save_time_figure(stage, path, data, &self.view)?)
    }

    /// The record held whole ([`super::Keep::record`]) with all that its files need, for a
    /// caller that keeps it; `None` when the record streamed through.
    pub fn into_held(self, params: &Params) -> Option<HeldSimulation> {
        let check_table = self.check.table();
        let check_agrees = self.check.all_agree();
        let modes_hz = self
            .modes
            .modes
            .iter()
            .map(|m| (m.index, m.frequency_hz))
            .collect();
        let json = self.json();
        let meta = self.simulation_meta();
        Some(HeldSimulation {
            sim: self.record?,
            asd: self.asd,
            meta,
            description: self.description,
            check_table,
            check_agrees,
            modes_hz,
            params: params.clone(),
            json,
        })
    }
}

impl Outcome for SimulateResult {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// `.h5`: a file the record streamed to ([`super::Keep::hdf5`]), completed with the
    /// spectra, or the record held whole; `.csv`: the ASDs; `.png`/`.svg`: the ASD figure with
    /// the request's view.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        let kind = output_kind(path, OUTPUT_KINDS)?;
        let meta = self.simulation_meta();
        if kind == OutputKind::Hdf5 {
            if let Some(writer) = self.take_streamed(path) {
                return Ok(writer.finish(stage, &self.asd)?);
            }
            if self.record.is_none() {
                return Err(JobError::option(
                    OptionKey::SAVE,
                    Some(&shown_path(path)),
                    "the record streamed through without this file: name the HDF5 files a \
                     run writes before it runs",
                ));
            }
        }
        let figure = asd_figure_data(
            &self.asd,
            &self.readout,
            &self.modes,
            self.fs_hz(),
            &self.description,
        );
        let outputs = RecordOutputs {
            record: self.record.as_ref().map(|sim| (sim, &meta)),
            asd: &self.asd,
            run: &self.provenance,
            figure: &figure,
        };
        Ok(save(stage, path, &outputs, &self.view)?)
    }

    /// The numbers of the summary, unrounded, and the resonance check per channel and mode.
    fn json(&self) -> serde_json::Value {
        summary_json(self)
    }
}

/// A simulated free motion held whole: the record, its spectra and provenance, the resonance
/// check as the command line prints it, and the parameters its figure's modes are computed
/// from; serializable, so a caller may keep it (Python pickles it) and save it later.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct HeldSimulation {
    /// The record: the observables with their readout noise and the coordinates.
    pub sim: Simulation,
    /// One-sided Welch ASDs of the observables.
    pub asd: SeriesAsd,
    /// What a saved record says of the run: the provenance, the initial state and where it
    /// came from, the readout, the seed, the length asked for.
    pub meta: SimulationMeta,
    /// One sentence on the run.
    pub description: String,
    /// The resonance check as the command line prints it.
    pub check_table: String,
    /// Whether every channel shows the modes the observability table says it sees.
    pub check_agrees: bool,
    /// The model's normal modes, `(index, frequency in Hz)`.
    pub modes_hz: Vec<(usize, f64)>,
    /// The parameters of the model.
    pub params: Params,
    /// The run's JSON summary ([`Outcome::json`] of the run).
    json: serde_json::Value,
}

impl Outcome for HeldSimulation {
    fn provenance(&self) -> &Provenance {
        &self.meta.run
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// `.h5` (the series, the ASDs and the provenance), `.csv` (the ASDs) or the ASD figure,
    /// as the command line's `simulate --save` writes them.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        output_kind(path, OUTPUT_KINDS)?;
        let model = Model::new(&self.params).map_err(|e| JobError::Params(Box::new(e)))?;
        let modes = NormalModes::new(&model);
        let readout = &self.meta.readout_asd;
        let fs = self.sim.fs_hz();
        let figure = asd_figure_data(&self.asd, readout, &modes, fs, &self.description);
        let outputs = RecordOutputs {
            record: Some((&self.sim, &self.meta)),
            asd: &self.asd,
            run: &self.meta.run,
            figure: &figure,
        };
        Ok(save(stage, path, &outputs, &View::default())?)
    }

    fn json(&self) -> serde_json::Value {
        self.json.clone()
    }
}

/// The summary of a run as JSON (the command line's `--format json`): the numbers of its
/// table, unrounded, and the resonance check per channel and mode.
fn summary_json(r: &SimulateResult) -> serde_json::Value {
    use serde_json::json;
    let fs = r.fs_hz();
    let modes: Vec<serde_json::Value> = r
        .modes
        .modes
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let seen = r.modes.names_seeing(k);
            json!({
                "index": m.index,
                "frequency_hz": m.frequency_hz,
                "apparent_frequency_hz": aliased_frequency_hz(m.frequency_hz, fs),
                "seen_by": seen,
            })
        })
        .collect();
    let channels: Vec<serde_json::Value> = r
        .check
        .channels
        .iter()
        .map(|c| {
            let modes: Vec<serde_json::Value> = c
                .modes
                .iter()
                .map(|m| {
                    json!({
                        "mode": m.mode_index,
                        "spectrum": m.spectrum.name(),
                        "table_seen": m.table_seen,
                        "agrees": m.agrees(),
                    })
                })
                .collect();
            json!({ "observable": c.observable.name(), "readout_asd": c.readout_asd, "modes": modes })
        })
        .collect();
    let readout: serde_json::Map<String, serde_json::Value> = r
        .readout
        .iter()
        .map(|(o, a)| (o.name().to_string(), json!(a)))
        .collect();
    json!({
        "samples": r.n_samples,
        "dt_s": r.dt_s,
        "duration_s": r.n_samples as f64 * r.dt_s,
        "nyquist_hz": fs / 2.0,
        "initial_state": r.init_source,
        "readout_asd": readout,
        "seed": r.seed,
        "welch": {
            "segment_len": r.asd.segment_len,
            "overlap": r.asd.overlap,
            "n_segments": r.asd.n_segments,
        },
        "modes": modes,
        "resonance_check": {
            "all_agree": r.check.all_agree(),
            "tested": r.check.n_tested(),
            "channels": channels,
        },
    })
}
