//! Coherence and measured transfer functions as CSV, units in the header (schema
//! `docs/schemas.md`, section "Coherence, CSV").

use crate::atomic::Staging;
use crate::csv_layout::{csv_head, CsvPreamble};
use crate::run_meta::RunMeta;
use crate::tf_csv::format_f64;
use std::io::{BufWriter, Write as _};
use std::path::Path;
use tiltnoise_core::coherence::CoherenceReport;
use tiltnoise_core::error::OutputError;

/// Value of the `# schema:` line of a coherence CSV.
pub const SCHEMA_COHERENCE_CSV: &str = "tiltnoise.coherence_csv";

/// Value of the `# schema_version:` line. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_COHERENCE_CSV: u32 = 2;

/// Writes the report as CSV, as one of the outputs of `stage` (see [`Staging::write`]).
///
/// The layout of every tiltnoise CSV ([`crate::csv_layout`]: `#` lines ending with `# units:`,
/// then one header line), then one line per Welch bin. Columns: `frequency_hz`, `estimable` (1
/// or 0), `AXIS.psd` (rad^2/Hz) per tilt axis, then per observable `OBS`: `OBS.psd` (U^2/Hz),
/// `OBS.residual_psd` (U^2/Hz), `OBS.multiple_coherence` (1) with `_lower` and `_upper`, and
/// per tilt axis `AXIS`: `OBS.AXIS.coherence` (1) with `_lower` and `_upper`, `OBS.AXIS.tf_re`,
/// `OBS.AXIS.tf_im`, `OBS.AXIS.tf_radius`, `OBS.AXIS.tf_sigma`, `OBS.AXIS.model_re`,
/// `OBS.AXIS.model_im` (U/rad), `OBS.AXIS.model_resolved` (1 or 0: whether the bin entered the
/// measured/model fit; `U` the observable's unit, m or rad). Values parse back to the same
/// `f64` ([`format_f64`]); `NaN` where a bin is not estimable.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O failure; nothing is left at `path`.
pub fn write_coherence_csv(
    stage: &Staging,
    path: &Path,
    report: &CoherenceReport,
    meta: &RunMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        let text = coherence_csv_string(report, meta);
        let file = std::fs::File::create(temp).map_err(|e| e.to_string())?;
        let mut out = BufWriter::new(file);
        out.write_all(text.as_bytes())
            .and_then(|()| out.flush())
            .map_err(|e| e.to_string())
    })
}

/// The CSV text of [`write_coherence_csv`].
pub fn coherence_csv_string(report: &CoherenceReport, meta: &RunMeta) -> String {
    let mut names: Vec<(String, String)> = vec![("estimable".into(), "1".into())];
    let mut columns: Vec<Vec<f64>> = vec![report
        .estimable
        .iter()
        .map(|&e| f64::from(u8::from(e)))
        .collect()];
    let mut push = |name: String, column: Vec<f64>| {
        // `NAME[UNIT]` -> (NAME, UNIT); a name without brackets is dimensionless.
        let (n, u) = match name.split_once('[') {
            Some((n, u)) => (n.to_string(), u.trim_end_matches(']').to_string()),
            None => (name, "1".to_string()),
        };
        names.push((n, u));
        columns.push(column);
    };
    for (axis, psd) in report.axes.iter().zip(&report.tilt_psd) {
        push(format!("{}.psd[rad^2/Hz]", axis.name()), psd.clone());
    }
    for ob in &report.observables {
        let (o, u) = (ob.observable.name(), ob.observable.unit());
        push(format!("{o}.psd[{u}^2/Hz]"), ob.psd.clone());
        push(
            format!("{o}.residual_psd[{u}^2/Hz]"),
            ob.residual_psd.clone(),
        );
        push(
            format!("{o}.multiple_coherence[1]"),
            ob.multiple_coherence.clone(),
        );
        push(
            format!("{o}.multiple_coherence_lower[1]"),
            ob.multiple_coherence_lower.clone(),
        );
        push(
            format!("{o}.multiple_coherence_upper[1]"),
            ob.multiple_coherence_upper.clone(),
        );
        for a in &ob.axes {
            let p = format!("{o}.{}", a.axis.name());
            push(format!("{p}.coherence[1]"), a.coherence.clone());
            push(format!("{p}.coherence_lower[1]"), a.coherence_lower.clone());
            push(format!("{p}.coherence_upper[1]"), a.coherence_upper.clone());
            push(
                format!("{p}.tf_re[{u}/rad]"),
                a.tf.iter().map(|z| z.re).collect(),
            );
            push(
                format!("{p}.tf_im[{u}/rad]"),
                a.tf.iter().map(|z| z.im).collect(),
            );
            push(format!("{p}.tf_radius[{u}/rad]"), a.tf_radius.clone());
            push(format!("{p}.tf_sigma[{u}/rad]"), a.tf_sigma.clone());
            push(
                format!("{p}.model_re[{u}/rad]"),
                a.model.iter().map(|z| z.re).collect(),
            );
            push(
                format!("{p}.model_im[{u}/rad]"),
                a.model.iter().map(|z| z.im).collect(),
            );
            push(
                format!("{p}.model_resolved"),
                a.model_resolved
                    .iter()
                    .map(|&r| f64::from(u8::from(r)))
                    .collect(),
            );
        }
    }
    let preamble = CsvPreamble {
        schema: SCHEMA_COHERENCE_CSV,
        schema_version: SCHEMA_VERSION_COHERENCE_CSV,
        meta,
        notes: vec![
            "one-sided PSDs; coherence is the magnitude-squared coherence; transfer functions \
             measured/model in the observable's unit per rad of tilt, time dependence exp(+i w t)"
                .to_string(),
        ],
    };
    let n_f = report.freqs_hz.len();
    let mut s = csv_head(&preamble, &names);
    s.reserve((n_f + 1) * (columns.len() + 1) * 24);
    for k in 0..n_f {
        s.push_str(&format_f64(report.freqs_hz[k]));
        for column in &columns {
            s.push(',');
            s.push_str(&format_f64(column[k]));
        }
        s.push('\n');
    }
    s
}
