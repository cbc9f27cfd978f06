//! The files and figures of a simulated record, the same for the command line and Python:
//! HDF5 (series, ASDs, provenance), CSV (ASDs), or the ASD figure (Figure 3).

use crate::figure::save_image;
use std::path::Path;
use tiltnoise_core::model::Observable;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::simulate::{aliased_frequency_hz, Simulation};
use tiltnoise_io::{
    write_asd_csv, write_observable_series_hdf5, OutputError, OutputKind, RunMeta, SeriesAsd,
    SimulationMeta, Staging,
};
use tiltnoise_plot::simulate_figure::{
    asd_figure, time_series_figure, ModeMark, SimAsdData, TimeSeriesData,
};
use tiltnoise_plot::View;

/// The ASD figure of a record sampled at `fs_hz`: its ASDs, the readout levels, the modes
/// (those above Nyquist marked at their aliases) and a caption that starts with `description`.
pub fn asd_figure_data(
    asd: &SeriesAsd,
    readout: &[(Observable, f64)],
    modes: &NormalModes,
    fs_hz: f64,
    description: &str,
) -> SimAsdData {
    SimAsdData {
        freqs_hz: asd.freqs_hz.clone(),
        asd: asd.asd.clone(),
        readout_asd: readout.to_vec(),
        modes: modes
            .modes
            .iter()
            .enumerate()
            .map(|(k, m)| ModeMark {
                index: m.index,
                frequency_hz: m.frequency_hz,
                apparent_frequency_hz: aliased_frequency_hz(m.frequency_hz, fs_hz),
                seen_by: modes.observables_seeing(k),
            })
            .collect(),
        caption: vec![
            description.to_string(),
            format!(
                "One-sided Welch ASDs: periodic Hann, {} samples per segment, 50 % overlap, {} \
                 segments, mean. Modes above Nyquist ({} Hz) are marked at their aliases.",
                asd.segment_len,
                asd.n_segments,
                fs_hz / 2.0
            ),
        ],
    }
}

/// What a simulated record's files are made of.
pub struct RecordOutputs<'a> {
    /// The whole record with its provenance, or `None` when it streamed to its HDF5 files
    /// (`SimulateResult::finish_records`), which [`save`] then leaves alone.
    pub record: Option<(&'a Simulation, &'a SimulationMeta)>,
    /// The ASDs.
    pub asd: &'a SeriesAsd,
    /// The run's provenance (the CSV's).
    pub run: &'a RunMeta,
    /// The ASD figure.
    pub figure: &'a SimAsdData,
}

/// Saves a simulated record in the format named by the extension of `path`: `.h5`/`.hdf5`
/// (series, ASDs and provenance; schema `tiltnoise.observable_series`), `.csv` (the ASDs) or
/// `.png`/`.svg` (the ASD figure, drawn with `view`), as one of the outputs of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for another extension (nothing is written), or the writer's
/// [`OutputError::Write`] naming `path`.
pub fn save(
    stage: &Staging,
    path: &Path,
    out: &RecordOutputs<'_>,
    view: &View,
) -> Result<(), OutputError> {
    match crate::output_kind(path, super::OUTPUT_KINDS)? {
        OutputKind::Hdf5 => match out.record {
            Some((sim, meta)) => write_observable_series_hdf5(stage, path, sim, out.asd, meta),
            None => Ok(()),
        },
        OutputKind::Csv => write_asd_csv(stage, path, &out.asd.freqs_hz, &out.asd.asd, out.run),
        _ => save_image(stage, path, |format| asd_figure(out.figure, view, format)),
    }
}

/// Draws the time-series figure (Figures 4 and 5) of `data` with `view`'s limits, size and
/// resolution in the format `path`'s extension names (`.png`, `.svg`), as one of the outputs
/// of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for another extension, [`OutputError::Write`] naming `path`.
pub fn save_time_figure(
    stage: &Staging,
    path: &Path,
    data: &TimeSeriesData,
    view: &View,
) -> Result<(), OutputError> {
    save_image(stage, path, |format| time_series_figure(data, view, format))
}
