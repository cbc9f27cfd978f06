//! Noise budget as CSV: one ASD column per observable and term (schema `docs/schemas.md`,
//! section "Noise budgets, CSV").

use crate::atomic::Staging;
use crate::budget_hdf5::SPECTRAL_CONVENTION;
use crate::csv_layout::{csv_head, drop_zero_columns, zero_columns_note, CsvPreamble};
use crate::run_meta::RunMeta;
use crate::tf_csv::format_f64;
use std::io::{BufWriter, Write as _};
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::noise::BudgetReport;

/// Value of the `# schema:` line of a budget CSV.
pub const SCHEMA_BUDGET_CSV: &str = "tiltnoise.budget_csv";

/// Value of the `# schema_version:` line. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_BUDGET_CSV: u32 = 2;

/// Writes the budget's ASDs as CSV, as one of the outputs of `stage` (see [`Staging::write`]).
///
/// The layout of every tiltnoise CSV ([`crate::csv_layout`]): `#` lines (schema, provenance,
/// notes, `# units:`), then one header line, `frequency_hz` followed by `OBS.TERM` for every
/// observable `OBS` and term `TERM` in the report's order
/// (`X.tilt,X.tilt.eta_t,X.readout,X.total,phi.tilt,...`), then, if the report has segment
/// bands, `OBS.TERM.median,OBS.TERM.pLO,OBS.TERM.pHI` per band (`TERM` the term of the floor's
/// motion that adds to the total, `tilt`, `translation` or `ground`; `LO`, `HI`: the
/// percentiles, e.g. `X.tilt.p10`), then, for observables whose budget carries the response to their
/// equivalent input (damped models), `OBS.equivalent.TERM` for the terms referred to that
/// input (`X`: test-mass acceleration, m s^-2/sqrt(Hz); `phi`, `phi_a`: torque, N
/// m/sqrt(Hz); see [`tiltnoise_core::noise::equivalent`]). Then one line per frequency. Every
/// value is a one-sided ASD, `sqrt(PSD)`, in the unit the `# units:` line gives, written so
/// that it parses back to exactly the same `f64` ([`format_f64`]). Columns that are zero at
/// every frequency (a term the model has but this run does not excite) are left out and named
/// in a `# note:` line, unless `keep_zero_columns`.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` if the report is inconsistent (a spectrum whose length
/// differs from the frequency grid) or on any I/O failure; nothing is left at `path`.
pub fn write_budget_csv(
    stage: &Staging,
    path: &Path,
    report: &BudgetReport,
    meta: &RunMeta,
    keep_zero_columns: bool,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        let text = budget_csv_string(report, meta, keep_zero_columns)?;
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
pub fn budget_csv_string(
    report: &BudgetReport,
    meta: &RunMeta,
    keep_zero_columns: bool,
) -> Result<String, String> {
    report.check()?;
    let mut columns = asd_columns(report);
    let dropped = drop_zero_columns(&mut columns, keep_zero_columns);
    let mut notes = vec![format!("every column an ASD; {SPECTRAL_CONVENTION}")];
    notes.extend(zero_columns_note(&dropped));
    let preamble = CsvPreamble {
        schema: SCHEMA_BUDGET_CSV,
        schema_version: SCHEMA_VERSION_BUDGET_CSV,
        meta,
        notes,
    };
    let heads: Vec<(String, String)> = columns
        .iter()
        .map(|(n, u, _)| (n.clone(), u.clone()))
        .collect();
    let n_f = report.budget.freqs_hz.len();
    let mut s = csv_head(&preamble, &heads);
    s.reserve((n_f + 1) * (1 + columns.len()) * 24);
    for (k, &f) in report.budget.freqs_hz.iter().enumerate() {
        s.push_str(&format_f64(f));
        for (_, _, column) in &columns {
            s.push(',');
            s.push_str(&format_f64(column[k]));
        }
        s.push('\n');
    }
    Ok(s)
}

/// `(name, unit, ASD values)` of every column after the frequency, in file order.
fn asd_columns(report: &BudgetReport) -> Vec<(String, String, Vec<f64>)> {
    let sqrt = |v: &[f64]| v.iter().map(|p| p.sqrt()).collect::<Vec<f64>>();
    let asd_unit = |u: &str| format!("{u}/sqrt(Hz)");
    let mut columns = Vec::new();
    for ob in &report.budget.observables {
        let unit = asd_unit(ob.observable.unit());
        for (component, psd) in ob.components() {
            let name = format!("{}.{}", ob.observable.name(), component.name());
            columns.push((name, unit.clone(), sqrt(&psd)));
        }
    }
    for (o, band) in &report.segment_bands {
        let unit = asd_unit(o.unit());
        let o = o.name();
        let term = band.term.name();
        columns.push((
            format!("{o}.{term}.median"),
            unit.clone(),
            sqrt(&band.median),
        ));
        let lower = format!("{o}.{term}.p{}", format_f64(band.lower_pct));
        columns.push((lower, unit.clone(), sqrt(&band.lower)));
        let upper = format!("{o}.{term}.p{}", format_f64(band.upper_pct));
        columns.push((upper, unit, sqrt(&band.upper)));
    }
    // Last, so that the columns above keep their places: the noise referred to the test
    // mass's actuation input (damped models), in that input's unit.
    for ob in &report.budget.observables {
        let Some(referred) = tiltnoise_core::noise::equivalent::referred_terms(ob) else {
            continue;
        };
        let unit = asd_unit(referred.unit);
        for (component, psd) in &referred.terms {
            let name = format!("{}.equivalent.{}", ob.observable.name(), component.name());
            columns.push((name, unit.clone(), sqrt(psd)));
        }
    }
    columns
}
