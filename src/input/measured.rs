//! A measured spectrum of the observables, for comparison with a budget: CSV with header
//! `freq_hz` then any of `X`, `Y`, `Z`, `theta`, `eta`, `phi`, `phi_a`; values are one-sided
//! ASDs (m/sqrt(Hz) for X, Y, Z; rad/sqrt(Hz) for the angles). Frequencies strictly increasing
//! and > 0; ASDs finite and >= 0.

use super::csv::{parse_field, CsvFile};
use super::error::InputError;
use crate::model::Observable;
use std::path::Path;

/// Measured ASDs per observable on the file's own frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpectra {
    /// Frequencies (Hz), strictly increasing, > 0.
    pub freqs_hz: Vec<f64>,
    /// `(observable, ASD per frequency)`.
    pub asd: Vec<(Observable, Vec<f64>)>,
}

/// Reads a measured-spectrum CSV (see the module docs).
pub fn read_measured(path: &Path) -> Result<MeasuredSpectra, InputError> {
    let mut file = CsvFile::open(path)?;
    let prelude = file.prelude()?;
    let csv_err = |line: usize, message: String| InputError::Csv {
        path: path.to_path_buf(),
        line,
        message,
    };
    if prelude.header.first().map(String::as_str) != Some("freq_hz") {
        return Err(csv_err(
            prelude.header_line,
            "measured spectrum: the header must start with freq_hz, then observables \
             (X, Y, Z, theta, eta, phi, phi_a)"
                .into(),
        ));
    }
    let mut observables = Vec::new();
    for name in &prelude.header[1..] {
        let o = Observable::ALL
            .into_iter()
            .find(|o| o.name() == name)
            .ok_or_else(|| {
                csv_err(
                    prelude.header_line,
                    format!(
                        "measured spectrum: unknown column `{name}`; allowed: X, Y, Z, theta, \
                         eta, phi, phi_a"
                    ),
                )
            })?;
        observables.push(o);
    }
    let mut freqs: Vec<f64> = Vec::new();
    let mut asd: Vec<Vec<f64>> = vec![Vec::new(); observables.len()];
    file.for_each_record(prelude.header.len(), |line, fields| {
        let number = |i: usize| match parse_field(fields[i]) {
            Ok(Some(v)) => Ok(v),
            _ => Err(csv_err(
                line,
                format!(
                    "column `{}` = `{}` is not a number",
                    prelude.header[i], fields[i]
                ),
            )),
        };
        let f = number(0)?;
        let previous = freqs.last().copied().unwrap_or(0.0);
        if !(f.is_finite() && f > previous) {
            return Err(InputError::Frequency {
                path: path.to_path_buf(),
                location: format!("line {line}, column freq_hz"),
                value: f,
                allowed: format!("finite, > 0 and greater than the previous {previous} Hz"),
            });
        }
        freqs.push(f);
        for (c, (o, column)) in observables.iter().zip(asd.iter_mut()).enumerate() {
            let v = number(c + 1)?;
            if !(v.is_finite() && v >= 0.0) {
                return Err(InputError::Asd {
                    path: path.to_path_buf(),
                    location: format!("line {line}"),
                    column: o.name().to_string(),
                    value: v,
                    unit: if o.unit() == "m" {
                        "m/sqrt(Hz)"
                    } else {
                        "rad/sqrt(Hz)"
                    },
                });
            }
            column.push(v);
        }
        Ok(())
    })?;
    if freqs.len() < 2 {
        return Err(csv_err(
            prelude.header_line,
            "measured spectrum: need at least 2 rows".into(),
        ));
    }
    Ok(MeasuredSpectra {
        freqs_hz: freqs,
        asd: observables.into_iter().zip(asd).collect(),
    })
}
