//! The JSON of the normal modes (`modes --format json`): the keys of every object in
//! alphabetical order, as every JSON report lists them (the fields of these structs are
//! declared in that order, maps are BTreeMaps).

use serde::Serialize;
use std::collections::BTreeMap;
use tiltnoise_core::model::{Coord, Observable};
use tiltnoise_core::modes::{NormalModes, RATIO_THRESHOLD};

/// Share of modal kinetic energy above which a coordinate is listed as dominant.
pub const DOMINANT_SHARE: f64 = 0.05;

/// `{"modes": [{"index": 1, "frequency_hz": ..., ...}, ...], "ratio_threshold": ...,
/// "rest_configuration": {...}}` of `modes` and the rest configuration `rest` (per
/// [`Coord::ALL`]).
pub(crate) fn modes_json(modes: &NormalModes, rest: &[f64]) -> serde_json::Value {
    let list = modes
        .modes
        .iter()
        .enumerate()
        .map(|(k, m)| ModeJson {
            block: m.block_name(),
            dominant_coordinates: m
                .dominant_coords(DOMINANT_SHARE)
                .into_iter()
                .map(|(c, energy_share)| CoordinateShare {
                    coordinate: c.name(),
                    energy_share,
                })
                .collect(),
            frequency_hz: m.frequency_hz,
            index: m.index,
            loss_angle_rad: m.loss_angle,
            observable_amplitude: Observable::ALL
                .iter()
                .map(|o| (o.name(), m.observable_amplitude[o.index()]))
                .collect(),
            omega_sq_rad2_per_s2: m.omega_sq,
            overlap: m.overlap,
            quality_factor: m.quality_factor.is_finite().then_some(m.quality_factor),
            ratio: Observable::ALL
                .iter()
                .map(|o| (o.name(), modes.ratio[k][o.index()]))
                .collect(),
            seen_above_ratio: modes
                .observables_above_ratio(k)
                .iter()
                .map(|o| o.name())
                .collect(),
            seen_by: modes
                .observables_seeing(k)
                .iter()
                .map(|o| o.name())
                .collect(),
            undamped: !m.quality_factor.is_finite(),
        })
        .collect();
    serde_json::to_value(ModesJson {
        modes: list,
        ratio_threshold: RATIO_THRESHOLD,
        rest_configuration: Coord::ALL
            .iter()
            .map(|c| (c.name(), rest[c.index()]))
            .collect(),
    })
    .expect("JSON of plain data")
}

#[derive(Serialize)]
struct ModesJson {
    modes: Vec<ModeJson>,
    /// [`RATIO_THRESHOLD`]: `seen_above_ratio` lists the observables whose ratio reaches it.
    ratio_threshold: f64,
    /// The rest configuration `q0` (rad, m): all 0 for the symmetric pendulum.
    rest_configuration: BTreeMap<&'static str, f64>,
}

#[derive(Serialize)]
struct ModeJson {
    block: &'static str,
    dominant_coordinates: Vec<CoordinateShare>,
    frequency_hz: f64,
    index: usize,
    loss_angle_rad: f64,
    observable_amplitude: BTreeMap<&'static str, f64>,
    omega_sq_rad2_per_s2: f64,
    /// Overlap with the symmetric pendulum's mode of the same label (1 when symmetric).
    overlap: f64,
    /// `null` when undamped (JSON has no infinity; numbers are never strings).
    quality_factor: Option<f64>,
    /// Amplitude over the largest of the observable's unit group, in this mode.
    ratio: BTreeMap<&'static str, f64>,
    seen_above_ratio: Vec<&'static str>,
    seen_by: Vec<&'static str>,
    /// No loss reaches the mode: Q is infinite, `quality_factor` is null.
    undamped: bool,
}

#[derive(Serialize)]
struct CoordinateShare {
    coordinate: &'static str,
    energy_share: f64,
}
