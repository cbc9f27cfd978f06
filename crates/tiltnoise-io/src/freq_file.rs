//! Frequency files (`tiltnoise tf --freq-file`): one frequency in Hz per line; blank lines and
//! `#` comment lines are ignored; CSV text as [`tiltnoise_core::csv_text`] reads it, with a
//! single column. At most [`MAX_FREQ_FILE_BYTES`] and [`MAX_GRID_POINTS`] frequencies.

use crate::text_file::{read_text_file, TextFileError};
use std::path::Path;
use tiltnoise_core::csv_text::{line_text, CsvRecords};
use tiltnoise_core::error::{FreqError, Shown};
use tiltnoise_core::limits::{check_count, MAX_FREQUENCY_HZ, MAX_FREQ_FILE_BYTES, MAX_GRID_POINTS};

/// Reads a frequency file. Every value must be finite, >= 0 and at most
/// [`MAX_FREQUENCY_HZ`]; at least one is required.
///
/// # Errors
///
/// [`FreqError::Spec`] naming the file (and line) when it cannot be read, a line is not one
/// number or there is none; [`FreqError::Invalid`] for a negative or non-finite frequency,
/// [`FreqError::TooHigh`] for one above [`MAX_FREQUENCY_HZ`];
/// [`FreqError::TooLarge`] for a file over [`MAX_FREQ_FILE_BYTES`] (a device or pipe is read
/// no further), a line over [`tiltnoise_core::limits::MAX_LINE_BYTES`] or more than
/// [`MAX_GRID_POINTS`] frequencies.
pub fn read_freq_file(path: &Path) -> Result<Vec<f64>, FreqError> {
    let origin = path.display().to_string();
    let name = format!("frequency file {origin}");
    let text = read_text_file(path, MAX_FREQ_FILE_BYTES, &name, "a frequency file").map_err(
        |e| match e {
            TextFileError::Io(e) => FreqError::Spec {
                origin: origin.clone().into(),
                message: format!("cannot read: {e}"),
            },
            TextFileError::TooLarge(e) => FreqError::TooLarge(e),
        },
    )?;
    parse_freq_text(&text, &origin)
}

/// The frequencies of the text of a frequency file; `origin` names it in messages.
fn parse_freq_text(text: &str, origin: &str) -> Result<Vec<f64>, FreqError> {
    let at = |line: usize| format!("{origin}, line {line}");
    let mut records = CsvRecords::from_text(text);
    let mut freqs = Vec::new();
    loop {
        let (line, fields) = match records.next_record() {
            Ok(Some(record)) => record,
            Ok(None) => break,
            Err(e) => {
                return Err(FreqError::Spec {
                    origin: e.line().map_or_else(|| origin.to_string(), at).into(),
                    message: e.to_string(),
                })
            }
        };
        let value = match fields[..] {
            [field] => field.parse::<f64>().ok(),
            _ => None,
        };
        let Some(value) = value else {
            return Err(FreqError::Spec {
                origin: at(line).into(),
                message: format!(
                    "`{}` is not a number (one frequency in Hz per line)",
                    Shown(line_text(text, line))
                ),
            });
        };
        if !(value.is_finite() && value >= 0.0) {
            return Err(FreqError::Invalid {
                value,
                origin: at(line),
            });
        }
        if value > MAX_FREQUENCY_HZ {
            return Err(FreqError::TooHigh {
                value,
                origin: at(line),
            });
        }
        if freqs.len() == MAX_GRID_POINTS {
            // Count the rest only for the message (the text is in memory, within its limit).
            let mut count = MAX_GRID_POINTS + 1;
            while let Ok(Some(_)) = records.next_record() {
                count += 1;
            }
            check_count(
                || format!("frequency file {origin}"),
                count as f64,
                "frequency points",
                MAX_GRID_POINTS,
            )?;
        }
        freqs.push(value);
    }
    if freqs.is_empty() {
        return Err(FreqError::Spec {
            origin: origin.into(),
            message: "no frequencies (one frequency in Hz per line expected)".into(),
        });
    }
    Ok(freqs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn freq_text_rules() {
        assert_eq!(
            parse_freq_text("# f\n0.1\n\n 2 \r\n  # g\n\"3\"\n", "f.txt").unwrap(),
            vec![0.1, 2.0, 3.0]
        );
        for (text, needles) in [
            (
                "0.1\nabc\n",
                &["f.txt, line 2", "`abc` is not a number"][..],
            ),
            (
                "0.1\n0.2,0.3\n",
                &["f.txt, line 2", "`0.2,0.3` is not a number"],
            ),
            ("0.1\n-3\n", &["frequency -3 Hz (f.txt, line 2)"]),
            ("NaN\n", &["frequency NaN Hz (f.txt, line 1)"]),
            ("0.1\n\"0.2\n", &["f.txt, line 2", "double quote"]),
            ("# only a comment\n", &["f.txt: no frequencies"]),
        ] {
            let e = parse_freq_text(text, "f.txt").unwrap_err().to_string();
            assert!(needles.iter().all(|n| e.contains(n)), "{text:?}: {e}");
        }
    }

    #[test]
    fn at_most_the_grid_limit_of_frequencies() {
        let full = "1\n".repeat(MAX_GRID_POINTS);
        assert_eq!(
            parse_freq_text(&full, "f.txt").unwrap().len(),
            MAX_GRID_POINTS
        );
        let over = full + "# comment\n2\n3\n";
        let e = parse_freq_text(&over, "f.txt").unwrap_err();
        assert_eq!(
            e.to_string(),
            "frequency file f.txt: 1000002 frequency points, more than the 1000000 allowed (see \
             docs/limits.md)"
        );
    }
}
