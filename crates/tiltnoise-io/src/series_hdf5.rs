//! Simulated observable time series as HDF5 (schema `tiltnoise.observable_series`, documented in
//! `docs/schemas.md` and `docs/simulate.md`).
//!
//! The layout is the budget's time-series input layout (`tiltnoise.tilt_series`: root attribute
//! `sample_rate_hz`, one 1-D float64 dataset per channel with a `units` attribute) under its own
//! schema name, because the channels are the pendulum's observables (m, rad), not floor tilt:
//! `tiltnoise budget --measured` reads it (the budget's comparison with a measured record), and
//! `--tilt` refuses it by its schema. Everything else (ASDs, initial state, parameters) lives in
//! groups, which series readers ignore.

use super::h5util::{dataset, scalar_attr, str_attr, strs_attr, unit_dataset, units_dataset};
use crate::atomic::Staging;
use crate::budget_hdf5::SPECTRAL_CONVENTION;
use crate::run_meta::RunMeta;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::{Coord, Observable};
use tiltnoise_core::simulate::{InitialState, Simulation};

/// Value of the root attribute `schema` of a simulated (or measured) observable time series.
pub const SCHEMA_OBSERVABLE_SERIES: &str = "tiltnoise.observable_series";

/// Value of the root attribute `schema_version`.
pub const SCHEMA_VERSION_OBSERVABLE_SERIES: i64 = 2;

/// One-sided Welch ASDs of the observables, stored in the group `/asd`.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SeriesAsd {
    /// Frequencies (Hz), `k fs / segment_len`, `k = 0 ..= segment_len / 2`.
    pub freqs_hz: Vec<f64>,
    /// `(observable, one-sided ASD in unit/sqrt(Hz))`.
    pub asd: Vec<(Observable, Vec<f64>)>,
    /// Welch segment length (samples).
    pub segment_len: usize,
    /// Welch overlap (samples).
    pub overlap: usize,
    /// `mean` or `median`.
    pub averaging: String,
    /// Segments averaged.
    pub n_segments: usize,
}

/// Provenance of a simulation run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimulationMeta {
    /// Tool version, parameters, command line, mode frequencies.
    pub run: RunMeta,
    /// Free text stored as the root attribute `description`.
    pub description: String,
    /// ISO 8601 start time of the record, if any.
    pub start_time: Option<String>,
    /// Seed of the readout-noise generator.
    pub seed: u64,
    /// The initial state (SI units, crate coordinate order).
    pub init: InitialState,
    /// How the initial state was chosen (e.g. `equal energy 1e-12 J per mode`).
    pub init_source: String,
    /// White readout noise per observable: one-sided ASD (unit/sqrt(Hz)); others noiseless.
    pub readout_asd: Vec<(Observable, f64)>,
    /// Requested duration (s).
    pub duration_s: f64,
}

/// Writes the seven observable series of `sim` (with their readout noise), the ASDs and the
/// run's provenance to `path`, atomically (nothing is left at `path` on error).
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O or HDF5 failure, or if an ASD's length
/// differs from its frequency grid.
pub fn write_observable_series_hdf5(
    stage: &Staging,
    path: &Path,
    sim: &Simulation,
    asd: &SeriesAsd,
    meta: &SimulationMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        check_asd(asd)?;
        write_file(temp, sim, asd, meta)
            .map_err(|e| format!("HDF5: {}", crate::messages::first_line(&e.to_string())))
    })
}

/// Refuses ASDs whose lengths differ from their frequency grid's.
pub(crate) fn check_asd(asd: &SeriesAsd) -> Result<(), String> {
    match asd.asd.iter().find(|(_, a)| a.len() != asd.freqs_hz.len()) {
        Some((o, a)) => Err(format!(
            "ASD of {} has {} values but the frequency grid {}",
            o.name(),
            a.len(),
            asd.freqs_hz.len()
        )),
        None => Ok(()),
    }
}

fn write_file(
    path: &Path,
    sim: &Simulation,
    asd: &SeriesAsd,
    meta: &SimulationMeta,
) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    write_root(&file, sim.dt_s, meta)?;
    for (o, series) in &sim.observables {
        let ds = dataset(&file, o.name(), series)?;
        series_attrs(&ds, *o, meta)?;
    }
    write_groups(&file, asd, meta)
}

/// The root attributes of a series of step `dt_s` (s).
pub(crate) fn write_root(file: &hdf5::File, dt_s: f64, meta: &SimulationMeta) -> hdf5::Result<()> {
    str_attr(file, "schema", SCHEMA_OBSERVABLE_SERIES)?;
    scalar_attr(file, "schema_version", SCHEMA_VERSION_OBSERVABLE_SERIES)?;
    scalar_attr(file, "sample_rate_hz", 1.0 / dt_s)?;
    scalar_attr(file, "dt_s", dt_s)?;
    scalar_attr(file, "duration_s", meta.duration_s)?;
    str_attr(file, "description", &meta.description)?;
    if let Some(t) = &meta.start_time {
        str_attr(file, "start_time", t)?;
    }
    str_attr(file, "tool_version", &meta.run.tool_version)?;
    str_attr(file, "created_by", &meta.run.command_line)?;
    str_attr(file, "parameters_toml", &meta.run.params_toml)?;
    scalar_attr(file, "seed", meta.seed)?;
    str_attr(file, "spectral_convention", SPECTRAL_CONVENTION)?;
    Ok(())
}

/// The attributes of the series dataset of observable `o`.
pub(crate) fn series_attrs(
    ds: &hdf5::Dataset,
    o: Observable,
    meta: &SimulationMeta,
) -> hdf5::Result<()> {
    str_attr(ds, "unit", o.unit())?;
    let r = meta
        .readout_asd
        .iter()
        .find(|(x, _)| *x == o)
        .map_or(0.0, |r| r.1);
    scalar_attr(ds, "readout_asd", r)?;
    str_attr(ds, "readout_asd_unit", &format!("{}/sqrt(Hz)", o.unit()))?;
    Ok(())
}

/// The groups `/asd`, `/initial_state` and `/modes`.
pub(crate) fn write_groups(
    file: &hdf5::File,
    asd: &SeriesAsd,
    meta: &SimulationMeta,
) -> hdf5::Result<()> {
    let g = file.create_group("asd")?;
    str_attr(&g, "spectral_convention", SPECTRAL_CONVENTION)?;
    str_attr(&g, "window", "hann (periodic)")?;
    scalar_attr(&g, "segment_len", asd.segment_len as u64)?;
    scalar_attr(&g, "overlap", asd.overlap as u64)?;
    str_attr(&g, "averaging", &asd.averaging)?;
    scalar_attr(&g, "n_segments", asd.n_segments as u64)?;
    unit_dataset(&g, "frequency_hz", &asd.freqs_hz, "Hz")?;
    for (o, a) in &asd.asd {
        let ds = dataset(&g, o.name(), a)?;
        str_attr(&ds, "unit", &format!("{}/sqrt(Hz)", o.unit()))?;
    }

    let g = file.create_group("initial_state")?;
    str_attr(&g, "source", &meta.init_source)?;
    strs_attr(&g, "coordinates", Coord::ALL.iter().map(|c| c.name()))?;
    strs_attr(&g, "unit", Coord::ALL.iter().map(|c| c.unit()))?;
    units_dataset(&g, "q", &meta.init.q, Coord::ALL.iter().map(|c| c.unit()))?;
    let rates: Vec<String> = Coord::ALL
        .iter()
        .map(|c| format!("{}/s", c.unit()))
        .collect();
    units_dataset(&g, "qdot", &meta.init.qdot, &rates)?;

    if !meta.run.modes.is_empty() {
        let g = file.create_group("modes")?;
        let index: Vec<u64> = meta.run.modes.iter().map(|m| m.0 as u64).collect();
        let f: Vec<f64> = meta.run.modes.iter().map(|m| m.1).collect();
        unit_dataset(&g, "index", &index, "1")?;
        unit_dataset(&g, "frequency_hz", &f, "Hz")?;
    }
    Ok(())
}
