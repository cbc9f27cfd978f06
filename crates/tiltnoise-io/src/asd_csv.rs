//! ASDs of observables as CSV (`tiltnoise simulate --save asd.csv`), in the layout the budget
//! reads as a measured spectrum (`docs/input_formats.md`).

use crate::{format_f64, write_atomic};
use std::fmt::Write;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::model::Observable;

/// ASDs as CSV `freq_hz,X,Y,Z,theta,eta,phi,phi_a` (the budget's measured-spectrum format;
/// DC left out), atomically. `freqs_hz[0]` is the DC bin and is skipped; every ASD has one
/// value per frequency.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path`; nothing is left there.
pub fn write_asd_csv(
    path: &Path,
    freqs_hz: &[f64],
    asd: &[(Observable, Vec<f64>)],
) -> Result<(), OutputError> {
    let mut text = String::from(
        "# one-sided ASD of simulated observables (m/sqrt(Hz), rad/sqrt(Hz))\nfreq_hz",
    );
    for (o, _) in asd {
        let _ = write!(text, ",{}", o.name());
    }
    text.push('\n');
    for (k, f) in freqs_hz.iter().enumerate().skip(1) {
        text.push_str(&format_f64(*f));
        for (_, a) in asd {
            text.push(',');
            text.push_str(&format_f64(a[k]));
        }
        text.push('\n');
    }
    write_atomic(path, |temp| {
        std::fs::write(temp, &text).map_err(|e| e.to_string())
    })
}
