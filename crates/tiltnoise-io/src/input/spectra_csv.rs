//! Tilt spectra from CSV: header `freq_hz,theta_t,eta_t[,phi_t]`, one-sided ASD per axis in
//! rad/sqrt(Hz), axes uncorrelated.

use super::csv::{self, parse_field, CsvFile, Prelude};
use super::format_error::FormatError;
use super::meta::{asd_unit, ASD_UNITS};
use crate::input::spectra_checks::no_scale_for_spectra;
use num_complex::Complex64;
use tiltnoise_core::input::{assemble, check_csd_finite, TiltSpectra};
use tiltnoise_core::input::{frequency_refusal, require_two, InputError};
use tiltnoise_core::input::{InputFormat, InputKind, Provenance, ReadOptions};
use tiltnoise_core::limits::ASDS;

/// Reads the records of a CSV spectrum whose prelude has been read (`prelude.header[0]` is
/// `freq_hz`).
pub(crate) fn read(
    mut file: CsvFile,
    prelude: Prelude,
    opts: &ReadOptions,
) -> Result<TiltSpectra, InputError> {
    let path = file.path.clone();
    no_scale_for_spectra(&path, opts)?;
    let csv::Interpreted {
        resolved,
        quantity,
        start_time,
        mut notes,
    } = csv::interpret_spectra(&path, &prelude, opts, asd_unit, ASD_UNITS)?;
    notes.push("CSV spectra: axes taken as uncorrelated (off-diagonal CSD = 0)".to_string());
    let unit = quantity.asd_unit();

    let mut freqs: Vec<f64> = Vec::new();
    // asd[source column index][k]
    let mut asd: Vec<Vec<f64>> = vec![Vec::new(); prelude.header.len() - 1];
    file.for_each_record(prelude.header.len(), |line, fields| {
        let row = freqs.len();
        let location = || format!("line {line} (row {row}), column {}", prelude.header[0]);
        let f = match parse_field(fields[0]) {
            Ok(Some(f)) => f,
            _ => {
                return Err(FormatError::CsvNumber {
                    path: path.clone(),
                    line,
                    column: prelude.header[0].clone(),
                    text: fields[0].to_string(),
                    unit: "Hz",
                    empty_allowed: false,
                }
                .into())
            }
        };
        if let Some(allowed) = frequency_refusal(f, freqs.last().copied()) {
            return Err(InputError::Frequency {
                path: path.clone(),
                location: location(),
                value: f,
                allowed,
            });
        }
        freqs.push(f);
        for m in &resolved.channels {
            let text = fields[m.index + 1];
            let v = match parse_field(text) {
                Ok(Some(v)) => v,
                _ => {
                    return Err(FormatError::CsvNumber {
                        path: path.clone(),
                        line,
                        column: m.source.clone(),
                        text: text.to_string(),
                        unit,
                        empty_allowed: false,
                    }
                    .into())
                }
            };
            if !ASDS.admits(v) {
                return Err(InputError::Asd {
                    path: path.clone(),
                    location: format!("line {line} (row {row})"),
                    column: m.source.clone(),
                    value: v,
                    unit,
                    power: false,
                });
            }
            asd[m.index].push(v);
        }
        Ok(())
    })?;
    require_two(&path, "column frequency_hz", freqs.len(), "frequencies")?;
    let csd = assemble(&freqs, &resolved.channels, quantity, |k, a, b| {
        if a == b {
            Complex64::new(asd[a][k] * asd[a][k], 0.0)
        } else {
            Complex64::new(0.0, 0.0)
        }
    });
    let axes: Vec<_> = resolved
        .channels
        .iter()
        .filter_map(|c| c.tilt_axis())
        .collect();
    check_csd_finite(&path, &freqs, &axes, &csd)?;
    Ok(TiltSpectra {
        freqs_hz: freqs,
        axes,
        csd,
        provenance: Provenance {
            path,
            format: InputFormat::Csv,
            kind: InputKind::Spectra,
            quantity,
            axis_map: resolved.map.to_string(),
            start_time,
            notes,
        },
    })
}
