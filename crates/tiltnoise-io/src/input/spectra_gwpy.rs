//! Tilt spectra from gwpy FrequencySeries datasets (HDF5): one 1-D dataset per axis, each with
//! gwpy's attributes `x0` (first frequency, Hz), `dx` (spacing, Hz), `xunit` (`Hz`) and `unit`
//! (an ASD such as `rad / Hz(1/2)` or a PSD such as `rad2 / Hz`), in a group addressed as
//! `FILE.h5:/group` (or one dataset, `FILE.h5:/group/dataset`) or at the root. The axes are
//! taken as uncorrelated (off-diagonal CSD 0); bins at `f <= 0` (gwpy's spectra start at DC)
//! are dropped.

use super::format_error::FormatError;
use super::h5::{self, h5err, AttrValue};
use super::meta::{asd_unit, csd_unit, decide_quantity, Declared, ASD_UNITS, CSD_UNITS};
use crate::input::spectra_checks::{no_scale_for_spectra, refuse_translation_spectra};
use num_complex::Complex64;
use std::path::Path;
use tiltnoise_core::input::{assemble, check_csd_finite, require_two, InputError, TiltSpectra};
use tiltnoise_core::input::{
    frequency_refusal, InputFormat, InputKind, Mapped, Provenance, ReadOptions,
};
use tiltnoise_core::limits::{ASDS, PSDS};

/// Whether the values of a dataset are amplitude or power spectral densities.
#[derive(Clone, Copy, PartialEq)]
enum Density {
    Amplitude,
    Power,
}

fn num_attr(
    path: &Path,
    ds: &hdf5::Dataset,
    object: &str,
    name: &'static str,
    allowed: &'static str,
) -> Result<f64, InputError> {
    match h5::attr(path, ds, object, name)? {
        Some(AttrValue::Num(v)) if v.is_finite() => Ok(v),
        None => Err(FormatError::MissingAttribute {
            path: path.to_path_buf(),
            object: object.to_string(),
            attribute: name,
            expected: allowed,
        }
        .into()),
        Some(other) => Err(InputError::BadAttribute {
            path: path.to_path_buf(),
            object: object.to_string(),
            attribute: name,
            value: other.describe(),
            allowed,
        }),
    }
}

/// Reads the FrequencySeries `available` (dataset names) of `group` (`prefix` its path).
pub(crate) fn read(
    path: &Path,
    file: &hdf5::File,
    group: &hdf5::Group,
    prefix: &str,
    available: &[String],
    opts: &ReadOptions,
) -> Result<TiltSpectra, InputError> {
    no_scale_for_spectra(path, opts)?;
    let mut notes = vec!["gwpy FrequencySeries layout (attributes x0, dx in Hz)".to_string()];
    let start_time = h5::start_and_description(path, file, &mut notes)?;
    let file_map = h5::axis_map(path, file)?;
    let resolved = h5::resolve_axes(
        path,
        available,
        &vec![None; available.len()],
        "dataset",
        opts,
        file_map.as_ref(),
        &mut notes,
    )?;
    refuse_translation_spectra(path, &resolved)?;
    let mut grid: Option<(String, f64, f64, usize)> = None;
    let mut values: Vec<Vec<f64>> = Vec::new();
    let mut declared = Vec::new();
    let mut undeclared = Vec::new();
    let mut density = None;
    for m in &resolved.channels {
        let name = format!("{prefix}/{}", m.source);
        let object = format!("dataset {name}");
        let ds = group
            .dataset(&m.source)
            .map_err(h5err(path, object.clone()))?;
        let (float, dtype) = h5::is_float(&ds).map_err(h5err(path, object.clone()))?;
        if ds.shape().len() != 1 || !float {
            return Err(FormatError::BadDataset {
                path: path.to_path_buf(),
                dataset: name,
                found: format!("type {dtype} and shape {:?}", ds.shape()),
                allowed: "a 1-D float dataset, one value per frequency".to_string(),
            }
            .into());
        }
        h5::check_storage(path, &ds, &name)?;
        let len = ds.shape()[0];
        h5::check_whole_read(path, &name, len, resolved.channels.len(), "frequencies")?;
        let (x0, dx) = first_and_spacing(path, &ds, &object)?;
        match &grid {
            None => grid = Some((name.clone(), x0, dx, len)),
            Some((a, x0_a, dx_a, len_a)) => {
                if (x0, dx, len) != (*x0_a, *dx_a, *len_a) {
                    return Err(InputError::BadAttribute {
                        path: path.to_path_buf(),
                        object,
                        attribute: "x0",
                        value: format!(
                            "x0 = {x0} Hz, dx = {dx} Hz, {len} values ({a}: x0 = {x0_a} Hz, dx = \
                             {dx_a} Hz, {len_a} values)"
                        ),
                        allowed: "the same frequencies for every mapped dataset",
                    });
                }
            }
        }
        let (unit, this) = unit_and_density(path, &ds, &object, m, &mut declared, &mut undeclared)?;
        if density.is_some_and(|d| d != this) {
            return Err(InputError::Units {
                path: path.to_path_buf(),
                location: format!("attribute `unit` of {object}"),
                value: unit.unwrap_or_default(),
                allowed: "ASDs for every axis or PSDs for every axis, not both",
            });
        }
        density = Some(this);
        let v = checked_values(path, &ds, &object, &name, m, this)?;
        values.push(v);
    }
    let quantity = decide_quantity(path, opts.quantity, &declared, &undeclared, &mut notes)?;
    let (first, x0, dx, len) = grid.expect("resolve maps at least one channel");
    let (keep, freqs) = positive_frequencies(path, &first, (x0, dx, len), &mut notes)?;
    notes.push("gwpy spectra: axes taken as uncorrelated (off-diagonal CSD = 0)".to_string());
    let power = density == Some(Density::Power);
    // values[i] belongs to resolved.channels[i]; `assemble` indexes by source index.
    let by_index = |a: usize| {
        resolved
            .channels
            .iter()
            .position(|m| m.index == a)
            .expect("a mapped source")
    };
    let csd = assemble(&freqs, &resolved.channels, quantity, |k, a, b| {
        if a == b {
            let v = values[by_index(a)][keep[k]];
            Complex64::new(if power { v } else { v * v }, 0.0)
        } else {
            Complex64::new(0.0, 0.0)
        }
    });
    let axes: Vec<_> = resolved
        .channels
        .iter()
        .filter_map(|c| c.tilt_axis())
        .collect();
    check_csd_finite(path, &freqs, &axes, &csd)?;
    Ok(TiltSpectra {
        freqs_hz: freqs,
        axes,
        csd,
        provenance: Provenance {
            path: path.to_path_buf(),
            format: InputFormat::Hdf5,
            kind: InputKind::Spectra,
            quantity,
            axis_map: resolved.map.to_string(),
            start_time,
            notes,
        },
    })
}

/// What `x0` and `dx` must be, for messages.
const X0: &str = "the first frequency in Hz (gwpy's x0): finite, the same for every axis";
const DX: &str = "the frequency spacing in Hz (gwpy's dx): finite and > 0, the same for every \
                  axis";

/// The first frequency and the spacing (Hz) of a FrequencySeries dataset.
fn first_and_spacing(
    path: &Path,
    ds: &hdf5::Dataset,
    object: &str,
) -> Result<(f64, f64), InputError> {
    let x0 = num_attr(path, ds, object, "x0", X0)?;
    let dx = num_attr(path, ds, object, "dx", DX)?;
    if dx <= 0.0 {
        return Err(InputError::BadAttribute {
            path: path.to_path_buf(),
            object: object.to_string(),
            attribute: "dx",
            value: format!("{dx}"),
            allowed: DX,
        });
    }
    Ok((x0, dx))
}

/// The `unit` attribute of the dataset of `m`, if any, and the density it says (an ASD when
/// there is none); the unit goes to `declared`, or the channel to `undeclared`.
fn unit_and_density(
    path: &Path,
    ds: &hdf5::Dataset,
    object: &str,
    m: &Mapped,
    declared: &mut Vec<Declared>,
    undeclared: &mut Vec<String>,
) -> Result<(Option<String>, Density), InputError> {
    let unit = match h5::attr(path, ds, object, "unit")? {
        None => None,
        Some(AttrValue::Str(u)) => Some(u),
        Some(other) => Some(other.describe()),
    };
    let density = match &unit {
        None => {
            undeclared.push(m.source.clone());
            Density::Amplitude
        }
        Some(u) => {
            let (d, unit) = match (asd_unit(u), csd_unit(u)) {
                (Some(unit), _) => (Density::Amplitude, unit),
                (None, Some(unit)) => (Density::Power, unit),
                (None, None) => {
                    return Err(InputError::Units {
                        path: path.to_path_buf(),
                        location: format!("attribute `unit` of {object}"),
                        value: u.clone(),
                        allowed: "an ASD in rad/sqrt(Hz) or rad/s/sqrt(Hz) (gwpy: \
                      `rad / Hz(1/2)`), or a PSD in rad^2/Hz or rad^2/s^2/Hz \
                      (gwpy: `rad2 / Hz`)",
                    })
                }
            };
            declared.push(Declared {
                channel: m.source.clone(),
                unit: u.clone(),
                quantity: unit.quantity,
            });
            d
        }
    };
    Ok((unit, density))
}

/// The values of the dataset of `m`, each within what an ASD or a PSD (`density`) allows.
fn checked_values(
    path: &Path,
    ds: &hdf5::Dataset,
    object: &str,
    name: &str,
    m: &Mapped,
    density: Density,
) -> Result<Vec<f64>, InputError> {
    let v = ds
        .read_raw::<f64>()
        .map_err(h5err(path, object.to_string()))?;
    let unit_text = if density == Density::Amplitude {
        ASD_UNITS
    } else {
        CSD_UNITS
    };
    let power = density == Density::Power;
    let allowed = if power { PSDS } else { ASDS };
    if let Some((k, bad)) = allowed.first_refused(&v) {
        return Err(InputError::Asd {
            path: path.to_path_buf(),
            location: format!("{name}[{k}]"),
            column: m.source.clone(),
            value: bad,
            unit: unit_text,
            power,
        });
    }
    Ok(v)
}

/// The bins above 0 Hz of the grid `x0 + k dx`, `k < len` (their indices and frequencies),
/// checked as frequencies; a note when bins at or below 0 Hz are dropped.
fn positive_frequencies(
    path: &Path,
    first: &str,
    (x0, dx, len): (f64, f64, usize),
    notes: &mut Vec<String>,
) -> Result<(Vec<usize>, Vec<f64>), InputError> {
    let keep: Vec<usize> = (0..len).filter(|&k| x0 + k as f64 * dx > 0.0).collect();
    if keep.len() < len {
        notes.push(format!(
            "{} bins at f <= 0 Hz dropped (a spectrum at DC has no tilt information here)",
            len - keep.len()
        ));
    }
    let freqs: Vec<f64> = keep.iter().map(|&k| x0 + k as f64 * dx).collect();
    for (i, &f) in freqs.iter().enumerate() {
        if let Some(allowed) = frequency_refusal(f, i.checked_sub(1).map(|p| freqs[p])) {
            return Err(InputError::Frequency {
                path: path.to_path_buf(),
                location: format!(
                    "bin {} of dataset {first} (x0 = {x0} Hz, dx = {dx} Hz)",
                    keep[i]
                ),
                value: f,
                allowed,
            });
        }
    }
    require_two(
        path,
        &format!("dataset {first}"),
        freqs.len(),
        "frequencies",
    )?;
    Ok((keep, freqs))
}
