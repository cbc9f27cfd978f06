//! Monte Carlo of the normal modes as HDF5 (schema `tiltnoise.mc`, documented in
//! `docs/schemas.md`).

use super::h5util::{dataset, provenance, scalar_attr, str_attr, strings, unit_dataset};
use crate::atomic::Staging;
use crate::run_meta::RunMeta;
use ndarray::Array2;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::mc::{McConfig, McResult};

/// Value of the root attribute `schema`.
pub const SCHEMA_MC: &str = "tiltnoise.mc";

/// Value of the root attribute `schema_version`. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_MC: i64 = 2;

/// Value of the root attribute `rejected_draws`: what happens to rejected draws in `draws_hz`.
pub const REJECTED_DRAWS: &str = "excluded: draws_hz holds the accepted draws only, in sample \
                                  order; their sample numbers are in sample_index";

/// Writes a Monte Carlo result as an HDF5 file of schema [`SCHEMA_MC`], atomically (see
/// [`Staging::write`]): every accepted draw's eight mode frequencies (`/draws_hz`, N x 8,
/// Hz), the mean, standard deviation and nominal frequency per mode, the seed, sample counts and
/// error model of `cfg`, and the provenance of `meta` (its `modes` are not used: the nominal
/// frequencies are `nominal_hz`).
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O or HDF5 failure; nothing is left at `path`.
pub fn write_mc_hdf5(
    stage: &Staging,
    path: &Path,
    result: &McResult,
    cfg: &McConfig,
    nominal_hz: &[f64; 8],
    meta: &RunMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        write_file(temp, result, cfg, nominal_hz, meta)
            .map_err(|e| format!("HDF5: {}", crate::messages::first_line(&e.to_string())))
    })
}

fn write_file(
    path: &Path,
    result: &McResult,
    cfg: &McConfig,
    nominal_hz: &[f64; 8],
    meta: &RunMeta,
) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    provenance(&file, SCHEMA_MC, SCHEMA_VERSION_MC, meta)?;
    str_attr(&file, "parameters_toml", &meta.params_toml)?;
    scalar_attr(&file, "seed", cfg.seed)?;
    scalar_attr(&file, "samples", int(result.samples)?)?;
    scalar_attr(&file, "rejected", int(result.rejected)?)?;
    scalar_attr(&file, "accepted", int(result.freqs_hz.len())?)?;
    str_attr(&file, "rejected_draws", REJECTED_DRAWS)?;
    str_attr(
        &file,
        "mode_order",
        "per draw, the eight undamped mode frequencies sorted ascending (mode identity by rank)",
    )?;

    let flat: Vec<f64> = result.freqs_hz.iter().flatten().copied().collect();
    let draws = Array2::from_shape_vec((result.freqs_hz.len(), 8), flat)
        .map_err(|e| hdf5::Error::from(e.to_string()))?;
    let d = file
        .new_dataset_builder()
        .with_data(&draws)
        .create("draws_hz")?;
    str_attr(&d, "unit", "Hz")?;
    let index: Vec<i64> = result
        .sample_index
        .iter()
        .map(|&i| int(i))
        .collect::<hdf5::Result<_>>()?;
    unit_dataset(&file, "sample_index", &index, "1")?;
    let modes: Vec<i64> = (1..=8).collect();
    unit_dataset(&file, "mode_index", &modes, "1")?;
    for (name, values) in [
        ("mean_hz", &result.mean_hz),
        ("std_hz", &result.std_hz),
        ("nominal_hz", nominal_hz),
    ] {
        let d = dataset(&file, name, values)?;
        str_attr(&d, "unit", "Hz")?;
    }

    let group = file.create_group("uncertainty")?;
    let keys = strings(cfg.uncertainties.iter().map(|u| u.key.as_str()))?;
    dataset(&group, "key", &keys)?;
    let sigma: Vec<f64> = cfg.uncertainties.iter().map(|u| u.rel_sigma).collect();
    let d = dataset(&group, "rel_sigma", &sigma)?;
    str_attr(&d, "unit", "1 (relative standard deviation)")?;
    let sigma: Vec<f64> = cfg.uncertainties.iter().map(|u| u.abs_sigma).collect();
    let d = dataset(&group, "abs_sigma", &sigma)?;
    str_attr(
        &d,
        "unit",
        "the key's unit (absolute standard deviation of an [asymmetry] offset)",
    )?;
    let dists = strings(cfg.uncertainties.iter().map(|u| u.distribution.name()))?;
    dataset(&group, "distribution", &dists)?;
    file.close()
}

fn int(n: usize) -> hdf5::Result<i64> {
    i64::try_from(n).map_err(|e| e.to_string().into())
}
