//! Transfer matrix as CSV (schema `docs/schemas.md`, section "Transfer functions, CSV").

use crate::atomic::Staging;
use crate::csv_layout::{csv_head, CsvPreamble};
use crate::run_meta::RunMeta;
use crate::tf_hdf5::{SIGN_CONVENTION, TIME_DEPENDENCE, TRANSLATION_CONVENTION};
use crate::tf_notes::{ground_quantity_note, has_translation};
use std::io::{BufWriter, Write as _};
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::tf::TransferMatrix;

/// Writes `tf` as CSV, as one of the outputs of `stage` (see [`Staging::write`]).
///
/// The layout of every tiltnoise CSV ([`crate::csv_layout`]): `#` lines (schema, provenance,
/// conventions, `# units:`), one header line, `frequency_hz` followed by `OUT.IN.re,OUT.IN.im`
/// for every output `OUT` (in the matrix's row order) and input `IN` (column order,
/// innermost), in the output's unit per the input's (`m/rad`, `rad/(N m)`), then one line per
/// frequency. Every number is written so that it parses back to exactly the same `f64`; see
/// [`format_f64`].
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O failure; nothing is left at `path`.
pub fn write_tf_csv(
    stage: &Staging,
    path: &Path,
    tf: &TransferMatrix,
    meta: &RunMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        let file = std::fs::File::create(temp).map_err(|e| e.to_string())?;
        let mut out = BufWriter::new(file);
        let text = tf_csv_string(tf, meta);
        out.write_all(text.as_bytes())
            .and_then(|()| out.flush())
            .map_err(|e| e.to_string())
    })
}

/// The CSV text of [`write_tf_csv`] (also what `tiltnoise tf` prints without `--save`).
pub fn tf_csv_string(tf: &TransferMatrix, meta: &RunMeta) -> String {
    let (nf, no, ni) = (tf.freqs_hz.len(), tf.outputs.len(), tf.inputs.len());
    let mut s = String::with_capacity((nf + 1) * (1 + 2 * no * ni) * 24);
    s.push_str(&tf_csv_header(tf, meta));
    push_tf_csv_rows(&mut s, tf);
    s
}

/// Value of the `# schema:` line of a transfer-function CSV.
pub const SCHEMA_TF_CSV: &str = "tiltnoise.transfer_functions_csv";

/// Value of the `# schema_version:` line. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_TF_CSV: u32 = 2;

/// The `#` lines and the header line of [`tf_csv_string`] (each with its newline) for the
/// outputs, inputs and units of `tf` (a whole matrix or its first block).
pub fn tf_csv_header(tf: &TransferMatrix, meta: &RunMeta) -> String {
    let mut columns = Vec::new();
    for (oi, o) in tf.outputs.iter().enumerate() {
        for (ii, i) in tf.inputs.iter().enumerate() {
            let unit = tf.unit(oi, ii);
            let (o, i) = (o.name(), i.name());
            columns.push((format!("{o}.{i}.re"), unit.clone()));
            columns.push((format!("{o}.{i}.im"), unit));
        }
    }
    let mut notes = vec![
        format!("H(f) per unit input, time dependence {TIME_DEPENDENCE}"),
        format!("tilt sign convention: {SIGN_CONVENTION}"),
    ];
    if has_translation(&tf.inputs) {
        notes.push(format!("floor translation: {TRANSLATION_CONVENTION}"));
    }
    if let Some(per) = ground_quantity_note(tf) {
        notes.push(per);
    }
    let preamble = CsvPreamble {
        schema: SCHEMA_TF_CSV,
        schema_version: SCHEMA_VERSION_TF_CSV,
        meta,
        notes,
    };
    csv_head(&preamble, &columns)
}

/// Appends the data lines of [`tf_csv_string`] for every frequency of `tf` to `s`: a grid
/// written in parts gives the same text as at once.
pub fn push_tf_csv_rows(s: &mut String, tf: &TransferMatrix) {
    let (no, ni) = (tf.outputs.len(), tf.inputs.len());
    for (k, &f) in tf.freqs_hz.iter().enumerate() {
        push_f64(s, f);
        for o in 0..no {
            for i in 0..ni {
                let h = tf.get(k, o, i);
                s.push(',');
                push_f64(s, h.re);
                s.push(',');
                push_f64(s, h.im);
            }
        }
        s.push('\n');
    }
}

fn push_f64(s: &mut String, x: f64) {
    s.push_str(&format_f64(x));
}

/// Formats `x` for text files so that it parses back (Rust `str::parse::<f64>`, Python
/// `float`, NumPy, C `strtod`) to exactly the same value, bit for bit.
///
/// * `0` for `+0.0` and `-0` for `-0.0` (the sign of zero survives the round trip);
/// * plain decimal for `1e-4 <= |x| < 1e16` (`0.5`, `123.25`, `1234567`), scientific notation
///   otherwise (`1.2345e-7`, `6.02e23`); both with the fewest digits that round-trip;
/// * `NaN`, `inf`, `-inf` for non-finite values.
pub fn format_f64(x: f64) -> String {
    if x == 0.0 {
        return if x.is_sign_negative() { "-0" } else { "0" }.to_string();
    }
    let a = x.abs();
    if !x.is_finite() || (1e-4..1e16).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::format_f64;

    #[test]
    fn format_round_trips_and_is_short() {
        for (x, s) in [
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (0.1, "0.1"),
            (-2.5e-7, "-2.5e-7"),
            (1e16, "1e16"),
            (123456.75, "123456.75"),
            (f64::MIN_POSITIVE, "2.2250738585072014e-308"),
            (f64::INFINITY, "inf"),
        ] {
            assert_eq!(format_f64(x), s);
        }
        let mut v = 0x3ff0_0000_0000_0001_u64;
        for _ in 0..10_000 {
            v = v
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = f64::from_bits(v);
            if x.is_nan() {
                continue;
            }
            let back: f64 = format_f64(x).parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x:e}");
        }
        assert!(format_f64(f64::NAN).parse::<f64>().unwrap().is_nan());
    }
}
