//! Noise budget as CSV: one ASD column per observable and term (schema `docs/schemas.md`,
//! section "Noise budgets, CSV").

use super::format_f64;
use crate::atomic::write_atomic;
use std::io::{BufWriter, Write as _};
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::noise::BudgetReport;

/// Writes the budget's ASDs as CSV, atomically (see [`super::write_atomic`]).
///
/// One header line, `freq_hz` followed by `OBS.TERM` for every observable `OBS` and term `TERM`
/// in the report's order (`X.tilt,X.tilt.eta_t,X.readout,X.total,phi.tilt,...`), then, if the
/// report has segment bands, `OBS.tilt.median,OBS.tilt.pLO,OBS.tilt.pHI` per band (`LO`, `HI`:
/// the percentiles, e.g. `X.tilt.p10`), then, for observables whose budget carries the response
/// to their equivalent input (damped models), `OBS.equivalent.TERM` for the terms referred to
/// that input (`X`: test-mass acceleration, m s^-2/sqrt(Hz); `phi`, `phi_a`: torque, N
/// m/sqrt(Hz); see [`tiltnoise_core::noise::equivalent`]). Then one line per frequency. Every value is
/// an ASD, `sqrt(PSD)`, in the observable's unit/sqrt(Hz) except the `equivalent` columns,
/// written so that it parses back to exactly the same `f64` ([`format_f64`]). No comment lines:
/// the file loads directly into pandas or NumPy.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` if the report is inconsistent (a spectrum whose length
/// differs from the frequency grid) or on any I/O failure; nothing is left at `path`.
pub fn write_budget_csv(path: &Path, report: &BudgetReport) -> Result<(), OutputError> {
    write_atomic(path, |temp| {
        let text = budget_csv_string(report)?;
        let file = std::fs::File::create(temp).map_err(|e| e.to_string())?;
        let mut out = BufWriter::new(file);
        out.write_all(text.as_bytes())
            .and_then(|()| out.flush())
            .map_err(|e| e.to_string())
    })
}

/// The CSV text of [`write_budget_csv`].
///
/// # Errors
///
/// A message naming the first spectrum whose length differs from the frequency grid.
pub fn budget_csv_string(report: &BudgetReport) -> Result<String, String> {
    report.check()?;
    let (names, columns) = asd_columns(report);
    let n_f = report.budget.freqs_hz.len();
    let mut s = String::with_capacity((n_f + 1) * (1 + columns.len()) * 24);
    s.push_str("freq_hz");
    for name in &names {
        s.push(',');
        s.push_str(name);
    }
    s.push('\n');
    for (k, &f) in report.budget.freqs_hz.iter().enumerate() {
        s.push_str(&format_f64(f));
        for column in &columns {
            s.push(',');
            s.push_str(&format_f64(column[k]));
        }
        s.push('\n');
    }
    Ok(s)
}

/// Column names and ASD values (without the frequency column), in file order.
fn asd_columns(report: &BudgetReport) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut names = Vec::new();
    let mut columns = Vec::new();
    for ob in &report.budget.observables {
        for (component, psd) in ob.components() {
            names.push(format!("{}.{}", ob.observable.name(), component.name()));
            columns.push(psd.iter().map(|p| p.sqrt()).collect());
        }
    }
    for (o, band) in &report.segment_bands {
        let o = o.name();
        let sqrt = |v: &[f64]| v.iter().map(|p| p.sqrt()).collect::<Vec<f64>>();
        names.push(format!("{o}.tilt.median"));
        columns.push(sqrt(&band.median));
        names.push(format!("{o}.tilt.p{}", format_f64(band.lower_pct)));
        columns.push(sqrt(&band.lower));
        names.push(format!("{o}.tilt.p{}", format_f64(band.upper_pct)));
        columns.push(sqrt(&band.upper));
    }
    // Last, so that the columns above keep their places: the noise referred to the test
    // mass's actuation input (damped models), in that input's unit.
    for ob in &report.budget.observables {
        let Some(referred) = tiltnoise_core::noise::equivalent::referred_terms(ob) else {
            continue;
        };
        for (component, psd) in &referred.terms {
            let name = component.name();
            names.push(format!("{}.equivalent.{name}", ob.observable.name()));
            columns.push(psd.iter().map(|p| p.sqrt()).collect());
        }
    }
    (names, columns)
}
