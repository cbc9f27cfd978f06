//! ASDs of observables as CSV (`tiltnoise simulate --save asd.csv`), in the layout the budget
//! reads as a measured spectrum (`docs/input_formats.md`).

use crate::atomic::Staging;
use crate::csv_layout::{csv_head, CsvPreamble};
use crate::run_meta::RunMeta;
use crate::tf_csv::format_f64;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::Observable;

/// Value of the `# schema:` line of a CSV of observable ASDs.
pub const SCHEMA_OBSERVABLE_ASD_CSV: &str = "tiltnoise.observable_asd_csv";

/// Value of the `# schema_version:` line. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_OBSERVABLE_ASD_CSV: u32 = 2;

/// ASDs as CSV, `frequency_hz,X,Y,Z,theta,eta,phi,phi_a` in the layout of every tiltnoise CSV
/// ([`crate::csv_layout`]; the budget reads it back as a measured spectrum; DC left out),
/// atomically. `freqs_hz[0]` is the DC bin and is skipped; every ASD has one value per
/// frequency.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path`; nothing is left there.
pub fn write_asd_csv(
    stage: &Staging,
    path: &Path,
    freqs_hz: &[f64],
    asd: &[(Observable, Vec<f64>)],
    meta: &RunMeta,
) -> Result<(), OutputError> {
    let columns: Vec<(String, String)> = asd
        .iter()
        .map(|(o, _)| (o.name().to_string(), format!("{}/sqrt(Hz)", o.unit())))
        .collect();
    let preamble = CsvPreamble {
        schema: SCHEMA_OBSERVABLE_ASD_CSV,
        schema_version: SCHEMA_VERSION_OBSERVABLE_ASD_CSV,
        meta,
        notes: vec!["one-sided ASD = sqrt(PSD) of each simulated observable".to_string()],
    };
    let mut text = csv_head(&preamble, &columns);
    for (k, f) in freqs_hz.iter().enumerate().skip(1) {
        text.push_str(&format_f64(*f));
        for (_, a) in asd {
            text.push(',');
            text.push_str(&format_f64(a[k]));
        }
        text.push('\n');
    }
    stage.write(path, |temp| {
        std::fs::write(temp, &text).map_err(|e| e.to_string())
    })
}
