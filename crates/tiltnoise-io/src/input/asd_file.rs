//! A one-sided ASD of one quantity, for a coloured readout (`budget --readout phi=FILE`) or a
//! user-named term (`budget --term NAME=SOURCE:FILE`), in one of two layouts:
//!
//! * **CSV**: header `freq_hz`, then columns; the column named after the quantity (`phi`,
//!   `F_b.x`, ...) is read, or else a column named `asd`; other columns are ignored (so a
//!   measured-spectrum CSV with several observables serves any of them).
//! * **HDF5** (`.h5`, `.hdf5`): 1-D float datasets `/frequency_hz` and `/<quantity>` or `/asd`.
//!
//! Frequencies in Hz, finite, > 0 and strictly increasing, at least 2; ASDs finite and >= 0 in
//! the quantity's unit per sqrt(Hz). Errors name the file, the line or index, the column and the
//! value.

use super::address::input_format;
use super::csv::{parse_field, CsvFile};
use super::format_error::FormatError;
use super::h5::{self, h5err};
use std::path::Path;
use tiltnoise_core::error::Shown;
use tiltnoise_core::input::require_two;
use tiltnoise_core::input::{frequency_refusal, InputError, InputFormat};
use tiltnoise_core::limits::ASDS;

/// Frequencies (Hz) and one-sided ASD of the column read, and the column's name.
#[derive(Debug, Clone, PartialEq)]
pub struct AsdColumn {
    /// Frequencies (Hz), strictly increasing, > 0.
    pub freqs_hz: Vec<f64>,
    /// One-sided ASD at each frequency, finite and >= 0.
    pub asd: Vec<f64>,
    /// The column (or dataset) read: the quantity's name or `asd`.
    pub column: String,
}

/// The generic name of the ASD column (or dataset) when it is not named after the quantity.
pub const GENERIC_ASD_COLUMN: &str = "asd";

/// Reads the ASD of `quantity` (its column, else `asd`) from `path` (see the module docs);
/// `asd_unit` (e.g. `N/sqrt(Hz)`) is named in messages.
pub fn read_asd_column(
    path: &Path,
    quantity: &str,
    asd_unit: &'static str,
) -> Result<AsdColumn, InputError> {
    match input_format(path)? {
        InputFormat::Csv => read_csv(path, quantity, asd_unit),
        InputFormat::Hdf5 => read_hdf5(path, quantity, asd_unit),
        InputFormat::Miniseed => Err(InputError::UnknownLayout {
            path: path.to_path_buf(),
            format: "miniseed",
            found: "a miniSEED file, which holds time series, not an ASD".to_string(),
            accepted:
                "an ASD file as CSV (frequency_hz, then the quantity's column or `asd`) or HDF5",
        }),
    }
}

fn read_csv(path: &Path, quantity: &str, asd_unit: &'static str) -> Result<AsdColumn, InputError> {
    let (mut file, prelude) = CsvFile::open(path)?;
    let csv_err = |line: usize, message: String| {
        InputError::from(FormatError::Csv {
            path: path.to_path_buf(),
            line,
            message,
        })
    };
    let header = &prelude.header;
    if !super::csv::is_frequency_column(header.first()) {
        return Err(csv_err(
            prelude.header_line,
            format!(
                "ASD file: the header must start with frequency_hz (or freq_hz), then a column `{}` (or `{}`)",
                Shown(quantity),
                GENERIC_ASD_COLUMN
            ),
        ));
    }
    let pick = |name: &str| header.iter().skip(1).position(|h| h == name).map(|c| c + 1);
    let Some(c) = pick(quantity).or_else(|| pick(GENERIC_ASD_COLUMN)) else {
        return Err(csv_err(
            prelude.header_line,
            format!(
                "ASD file: no column `{}` or `{}`; columns: {}",
                Shown(quantity),
                GENERIC_ASD_COLUMN,
                header[1..]
                    .iter()
                    .map(|h| format!("`{}`", Shown(h)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    };
    let column = header[c].clone();
    let mut freqs: Vec<f64> = Vec::new();
    let mut asd: Vec<f64> = Vec::new();
    file.for_each_record(header.len(), |line, fields| {
        let number = |i: usize| match parse_field(fields[i]) {
            Ok(Some(v)) => Ok(v),
            _ => Err(csv_err(
                line,
                format!(
                    "column `{}` = `{}` is not a number",
                    Shown(&header[i]),
                    Shown(fields[i])
                ),
            )),
        };
        let f = number(0)?;
        check_frequency(path, &freqs, f, || {
            format!("line {line}, column {}", header[0])
        })?;
        let a = number(c)?;
        check_asd(path, a, &column, asd_unit, || format!("line {line}"))?;
        freqs.push(f);
        asd.push(a);
        Ok(())
    })?;
    require_two(path, "column frequency_hz", freqs.len(), "frequencies")?;
    Ok(AsdColumn {
        freqs_hz: freqs,
        asd,
        column,
    })
}

fn read_hdf5(path: &Path, quantity: &str, asd_unit: &'static str) -> Result<AsdColumn, InputError> {
    let file = h5::open(path)?;
    let names = h5::root_datasets(path, &file)?;
    let column = [quantity, GENERIC_ASD_COLUMN]
        .into_iter()
        .find(|n| names.iter().any(|x| x == n))
        .ok_or_else(|| FormatError::MissingDataset {
            path: path.to_path_buf(),
            dataset: format!("/{} (or /{GENERIC_ASD_COLUMN})", Shown(quantity)),
            expected: format!("the one-sided ASD of {} in {asd_unit}", Shown(quantity)),
        })?
        .to_string();
    if !names.iter().any(|n| n == "frequency_hz") {
        return Err(FormatError::MissingDataset {
            path: path.to_path_buf(),
            dataset: "/frequency_hz".to_string(),
            expected: "the frequencies (Hz) of the ASD".to_string(),
        }
        .into());
    }
    let read = |name: &str| -> Result<Vec<f64>, InputError> {
        let object = format!("dataset /{name}");
        let ds = file.dataset(name).map_err(h5err(path, object.clone()))?;
        let (float, dtype) = h5::is_float(&ds).map_err(h5err(path, object.clone()))?;
        let shape = ds.shape();
        if shape.len() != 1 || !float {
            return Err(FormatError::BadDataset {
                path: path.to_path_buf(),
                dataset: format!("/{name}"),
                found: format!("type {dtype} and shape {shape:?}"),
                allowed: "a 1-D float64 (or float32) dataset, one value per frequency".into(),
            }
            .into());
        }
        h5::check_whole_read(path, &format!("/{name}"), shape[0], 2, "frequencies")?;
        ds.read_raw::<f64>().map_err(h5err(path, object))
    };
    let freqs_hz = read("frequency_hz")?;
    let asd = read(&column)?;
    if freqs_hz.len() != asd.len() {
        return Err(InputError::LengthMismatch {
            path: path.to_path_buf(),
            channel_a: "frequency_hz".to_string(),
            len_a: freqs_hz.len(),
            channel_b: column,
            len_b: asd.len(),
        });
    }
    for k in 0..freqs_hz.len() {
        check_frequency(path, &freqs_hz[..k], freqs_hz[k], || {
            format!("/frequency_hz[{k}]")
        })?;
        check_asd(path, asd[k], &column, asd_unit, || {
            format!("/{column}[{k}]")
        })?;
    }
    require_two(path, "dataset /frequency_hz", freqs_hz.len(), "frequencies")?;
    Ok(AsdColumn {
        freqs_hz,
        asd,
        column,
    })
}

fn check_frequency(
    path: &Path,
    before: &[f64],
    f: f64,
    location: impl FnOnce() -> String,
) -> Result<(), InputError> {
    if let Some(allowed) = frequency_refusal(f, before.last().copied()) {
        return Err(InputError::Frequency {
            path: path.to_path_buf(),
            location: location(),
            value: f,
            allowed,
        });
    }
    Ok(())
}

fn check_asd(
    path: &Path,
    value: f64,
    column: &str,
    unit: &'static str,
    location: impl FnOnce() -> String,
) -> Result<(), InputError> {
    if !ASDS.admits(value) {
        return Err(InputError::Asd {
            path: path.to_path_buf(),
            location: location(),
            column: column.to_string(),
            value,
            unit,
            power: false,
        });
    }
    Ok(())
}
