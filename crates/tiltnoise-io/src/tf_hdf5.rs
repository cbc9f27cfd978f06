//! Transfer matrix as HDF5 (schema `tiltnoise.tf`, documented in `docs/schemas.md`).

use super::h5util::{dataset, provenance, str_attr, strings, strs_attr, unit_dataset};
use crate::atomic::Staging;
use crate::run_meta::RunMeta;
use crate::tf_notes::{ground_quantity_note, has_translation};
use ndarray::ArrayView3;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::tf::TransferMatrix;

/// Value of the root attribute `schema`.
pub const SCHEMA_TF: &str = "tiltnoise.tf";

/// Value of the root attribute `schema_version`. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_TF: i64 = 2;

/// Value of the root attribute `sign_convention` (see [`tiltnoise_core::model::tilt`]).
pub const SIGN_CONVENTION: &str = "tilt t = small right-handed rotation taking the floor frame \
     to the inertial frame; X -> -eta_t (Z+Z_b+h_c), Y -> +theta_t (Z+Z_b+h_c) as f -> 0";

/// Value of the root attribute `translation_convention`, written when the matrix has a floor
/// translation input (see [`tiltnoise_core::model::translation`]).
pub const TRANSLATION_CONVENTION: &str = "x_t, y_t, z_t = displacement of the floor, the \
     suspension point and the housing together along the lab axes (crossbar arm along y, z up), \
     m; per unit floor acceleration a = -w^2 u: X/x_t -> X/eta_t / g, Y/y_t -> -Y/theta_t / g \
     as f -> 0 (equivalence principle)";

/// Value of the root attribute `time_dependence`: values are complex amplitudes of
/// `exp(+i w t)`.
pub const TIME_DEPENDENCE: &str = "exp(+i w t)";

/// Writes `tf` and the run's provenance `meta` as an HDF5 file of schema [`SCHEMA_TF`],
/// as one of the outputs of `stage` (see [`Staging::write`]).
///
/// Layout: root attributes `schema`, `schema_version`, `tool_version`, `created_by`, `method`,
/// `parameters_toml`, `sign_convention`, `time_dependence` (and `translation_convention` with a
/// floor-translation input); datasets `/frequency_hz`,
/// `/transfer` (complex, `[n_freq, n_outputs, n_inputs]`), `/outputs`, `/inputs`,
/// `/output_units`, `/input_units`, and `/modes/{index,frequency_hz}` when `meta.modes` is not
/// empty. Every item is described in `docs/schemas.md`.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O or HDF5 failure; nothing is left at `path`.
pub fn write_tf_hdf5(
    stage: &Staging,
    path: &Path,
    tf: &TransferMatrix,
    meta: &RunMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        write_file(temp, tf, meta)
            .map_err(|e| format!("HDF5: {}", crate::messages::first_line(&e.to_string())))
    })
}

fn write_file(path: &Path, tf: &TransferMatrix, meta: &RunMeta) -> hdf5::Result<()> {
    let (nf, no, ni) = (tf.freqs_hz.len(), tf.outputs.len(), tf.inputs.len());
    if tf.n_stored_freqs() != nf {
        return Err(format!(
            "transfer matrix holds values at {} frequencies, expected {nf}",
            tf.n_stored_freqs()
        )
        .into());
    }
    // The file is dense whatever the matrix's layout: structural zeros as 0.
    let file = hdf5::File::create(path)?;
    write_root(&file, tf, meta)?;

    let freq = dataset(&file, "frequency_hz", &tf.freqs_hz)?;
    str_attr(&freq, "unit", "Hz")?;

    let dense = tf.dense_values();
    let values = ArrayView3::from_shape((nf, no, ni), &dense).map_err(|e| e.to_string())?;
    let transfer = file
        .new_dataset_builder()
        .with_data(values)
        .create("transfer")?;
    transfer_attrs(&transfer, tf)?;
    write_labels(&file, tf)?;
    write_modes(&file, meta)?;
    file.close()
}

/// The root attributes of a file of `tf`'s labels and method (`tf` may hold any part of the
/// grid).
pub(crate) fn write_root(
    file: &hdf5::File,
    tf: &TransferMatrix,
    meta: &RunMeta,
) -> hdf5::Result<()> {
    provenance(file, SCHEMA_TF, SCHEMA_VERSION_TF, meta)?;
    str_attr(file, "method", tf.method.name())?;
    str_attr(file, "parameters_toml", &meta.params_toml)?;
    str_attr(file, "sign_convention", SIGN_CONVENTION)?;
    str_attr(file, "time_dependence", TIME_DEPENDENCE)?;
    if has_translation(&tf.inputs) {
        str_attr(file, "translation_convention", TRANSLATION_CONVENTION)?;
    }
    if let Some(per) = ground_quantity_note(tf) {
        str_attr(file, "ground_quantity", &per)?;
    }
    Ok(())
}

/// The attributes of the `/transfer` dataset.
pub(crate) fn transfer_attrs(transfer: &hdf5::Dataset, tf: &TransferMatrix) -> hdf5::Result<()> {
    let (no, ni) = (tf.outputs.len(), tf.inputs.len());
    let output_names: Vec<&str> = tf.outputs.iter().map(|o| o.name()).collect();
    let input_names: Vec<&str> = tf.inputs.iter().map(|i| i.name()).collect();
    let units: Vec<String> = (0..no)
        .flat_map(|o| (0..ni).map(move |i| (o, i)))
        .map(|(o, i)| tf.unit(o, i))
        .collect();
    strs_attr(transfer, "outputs", output_names.iter().copied())?;
    strs_attr(transfer, "inputs", input_names.iter().copied())?;
    strs_attr(transfer, "unit", units.iter().map(String::as_str))?;
    Ok(())
}

/// The datasets `/outputs`, `/inputs`, `/output_units`, `/input_units`.
pub(crate) fn write_labels(file: &hdf5::File, tf: &TransferMatrix) -> hdf5::Result<()> {
    let output_names: Vec<&str> = tf.outputs.iter().map(|o| o.name()).collect();
    let input_names: Vec<&str> = tf.inputs.iter().map(|i| i.name()).collect();
    dataset(file, "outputs", &strings(output_names.iter().copied())?)?;
    dataset(file, "inputs", &strings(input_names.iter().copied())?)?;
    dataset(
        file,
        "output_units",
        &strings(tf.outputs.iter().map(|o| o.unit()))?,
    )?;
    dataset(
        file,
        "input_units",
        &strings((0..tf.inputs.len()).map(|i| tf.input_unit(i)))?,
    )?;
    Ok(())
}

/// The group `/modes`, when `meta.modes` is not empty.
pub(crate) fn write_modes(file: &hdf5::File, meta: &RunMeta) -> hdf5::Result<()> {
    if !meta.modes.is_empty() {
        let modes = file.create_group("modes")?;
        let index: Vec<i64> = meta
            .modes
            .iter()
            .map(|&(n, _)| i64::try_from(n).map_err(|e| e.to_string()))
            .collect::<Result<_, _>>()?;
        let freqs: Vec<f64> = meta.modes.iter().map(|&(_, f)| f).collect();
        unit_dataset(&modes, "index", &index, "1")?;
        let mf = dataset(&modes, "frequency_hz", &freqs)?;
        str_attr(&mf, "unit", "Hz")?;
    }
    Ok(())
}
