//! Measured normal-mode frequencies: the CSV format of `--measured`, the embedded Table II
//! example, and the default measurement sigma taken from the printed digits.
//!
//! Format (documented for users in `docs/fit.md`), CSV as [`crate::csv_text`] reads it: `#`
//! starts a comment line; the first other line is the header `mode,frequency_hz` or
//! `mode,frequency_hz,sigma_hz`; then one row per measured mode, in any order, any subset of the
//! eight modes. `mode` is the rank 1..8 (the paper's nu_k, modes sorted by frequency);
//! `frequency_hz` is finite and > 0; `sigma_hz`, when present and not empty, is the
//! one-standard-deviation error in Hz (finite and > 0). When it is absent the sigma is half a
//! unit of the last printed digit of `frequency_hz` (`0.4065` -> `0.00005`; `1.331e-3` ->
//! `0.0005e-3`): the rounding error of a value reported to that many digits, the only error
//! information Table II carries.

use super::FitError;
use crate::csv_text::{line_text, CsvRecords};
use crate::error::Shown;

/// The measured column of Table II of the paper, in the format above.
pub const TABLE_II_MEASURED_CSV: &str = include_str!("table2_measured.csv");

/// The highest measured mode frequency accepted (Hz): far above every mode of a torsion
/// pendulum (PETER's highest is 11 Hz); larger values are not measurements of one.
pub const MAX_MEASURED_HZ: f64 = 1e6;

/// The lowest measured mode frequency accepted (Hz): a period of 30 years, far below every mode
/// of a torsion pendulum; smaller values (down to subnormal numbers, whose error bars underflow
/// to 0) are not measurements of one.
pub const MIN_MEASURED_HZ: f64 = 1e-9;

/// The smallest error bar accepted, relative to its frequency: a few units of f64's resolution
/// (2^-50); a smaller one cannot be resolved by any fitted frequency and turns chi^2 infinite.
pub const MIN_SIGMA_REL: f64 = 8.881784197001252e-16;

/// Where a default sigma came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SigmaSource {
    /// Given in the `sigma_hz` column.
    File,
    /// Half a unit of the last printed digit of the frequency.
    Digits,
}

/// One measured mode frequency.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MeasuredMode {
    /// Rank of the mode, 1..=8 (nu_1 is the lowest frequency).
    pub mode: usize,
    /// Measured frequency (Hz).
    pub frequency_hz: f64,
    /// One-standard-deviation error (Hz), > 0.
    pub sigma_hz: f64,
    /// Where `sigma_hz` came from.
    pub sigma_source: SigmaSource,
}

/// A set of measured modes, sorted by mode rank, each rank at most once.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The modes, sorted by `mode`.
    pub modes: Vec<MeasuredMode>,
    /// Where they came from (file name or `embedded Table II`).
    pub origin: String,
}

impl Measured {
    /// The embedded example: Table II's measured column, sigmas from the printed digits.
    pub fn table_ii() -> Measured {
        Measured::parse(TABLE_II_MEASURED_CSV, "embedded Table II")
            .expect("the embedded Table II file is valid")
    }

    /// Parses and validates the CSV text; `origin` names it in error messages. (Files are
    /// read by `tiltnoise_io::read_measured_modes`.)
    pub fn parse(text: &str, origin: &str) -> Result<Measured, FitError> {
        let fail = |line: usize, message: String| FitError::Measured {
            origin: format!("{origin}, line {line}"),
            message,
        };
        let mut records = CsvRecords::from_text(text);
        let Some((hline, columns)) = next_record(&mut records, origin)? else {
            return Err(FitError::Measured {
                origin: origin.to_string(),
                message: "no header line; expected `mode,frequency_hz[,sigma_hz]`".into(),
            });
        };
        let n_columns = columns.len();
        let with_sigma = match columns[..] {
            ["mode", "frequency_hz"] => false,
            ["mode", "frequency_hz", "sigma_hz"] => true,
            _ => {
                return Err(fail(
                    hline,
                    format!(
                        "header `{}`; allowed: `mode,frequency_hz` or `mode,frequency_hz,sigma_hz`",
                        Shown(line_text(text, hline))
                    ),
                ))
            }
        };
        let mut modes: Vec<MeasuredMode> = Vec::new();
        while let Some((n, cells)) = next_record(&mut records, origin)? {
            if cells.len() != n_columns {
                return Err(fail(
                    n,
                    format!(
                        "`{}` has {} fields, the header has {n_columns}",
                        Shown(line_text(text, n)),
                        cells.len(),
                    ),
                ));
            }
            let mode: usize = cells[0]
                .parse()
                .ok()
                .filter(|m| (1..=8).contains(m))
                .ok_or_else(|| {
                    fail(
                        n,
                        format!(
                            "mode `{}` is not allowed: must be an integer 1..8",
                            Shown(cells[0])
                        ),
                    )
                })?;
            if modes.iter().any(|m| m.mode == mode) {
                return Err(fail(
                    n,
                    format!("mode {mode} is listed twice; give each mode once"),
                ));
            }
            let frequency_hz = parse_positive(cells[1])
                .filter(|f| (MIN_MEASURED_HZ..=MAX_MEASURED_HZ).contains(f))
                .ok_or_else(|| {
                    fail(
                        n,
                        format!(
                            "frequency_hz `{}` of mode {mode} is not allowed: must be finite, \
                             >= {MIN_MEASURED_HZ:e} Hz and <= {MAX_MEASURED_HZ:e} Hz",
                            Shown(cells[1])
                        ),
                    )
                })?;
            let (sigma_hz, sigma_source) = match with_sigma && !cells[2].is_empty() {
                true => (
                    parse_positive(cells[2]).ok_or_else(|| {
                        fail(n, format!("sigma_hz `{}` of mode {mode} is not allowed: must be finite and > 0 (or empty: half the last digit)", Shown(cells[2])))
                    })?,
                    SigmaSource::File,
                ),
                false => (half_last_digit(cells[1]), SigmaSource::Digits),
            };
            if !(sigma_hz >= MIN_SIGMA_REL * frequency_hz && sigma_hz > 0.0) {
                return Err(fail(
                    n,
                    format!(
                        "sigma_hz {sigma_hz:e} of mode {mode} is not allowed: must be at least \
                         {MIN_SIGMA_REL:e} times the frequency ({:e} Hz), the resolution of f64",
                        MIN_SIGMA_REL * frequency_hz
                    ),
                ));
            }
            modes.push(MeasuredMode {
                mode,
                frequency_hz,
                sigma_hz,
                sigma_source,
            });
        }
        if modes.is_empty() {
            return Err(FitError::Measured {
                origin: origin.to_string(),
                message: "no measured mode; need at least one row `mode,frequency_hz`".into(),
            });
        }
        modes.sort_by_key(|m| m.mode);
        Ok(Measured {
            modes,
            origin: origin.to_string(),
        })
    }
}

/// The next record, its error as a [`FitError`].
fn next_record<'a>(
    records: &'a mut CsvRecords<&[u8]>,
    origin: &str,
) -> Result<Option<(usize, Vec<&'a str>)>, FitError> {
    records.next_record().map_err(|e| FitError::Measured {
        origin: match e.line() {
            Some(line) => format!("{origin}, line {line}"),
            None => origin.to_string(),
        },
        message: e.to_string(),
    })
}

fn parse_positive(cell: &str) -> Option<f64> {
    cell.parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
}

/// Half a unit of the last printed digit of a decimal number that already parsed as a finite
/// f64: `0.4065` -> 5e-5, `7.926` -> 5e-4, `12` -> 0.5, `1.331e-3` -> 5e-7.
pub fn half_last_digit(text: &str) -> f64 {
    let lower = text.to_ascii_lowercase();
    let (mantissa, exponent) = match lower.split_once('e') {
        Some((m, e)) => (m, e.parse::<i32>().unwrap_or(0)),
        None => (lower.as_str(), 0),
    };
    let decimals = mantissa
        .split_once('.')
        .map_or(0, |(_, frac)| frac.len() as i32);
    0.5 * 10f64.powi(exponent - decimals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_last_digit_of_printed_values() {
        // Compared in units of the expected value: powi and the decimal literals round
        // differently, so equality holds to a few ulps, not exactly.
        const ULPS: f64 = 4.0 * f64::EPSILON;
        for (text, want) in [
            ("0.001331", 5e-7),
            ("1.331e-3", 5e-7),
            ("0.4065", 5e-5),
            ("0.6170", 5e-5),
            ("0.58815", 5e-6),
            ("10.393", 5e-4),
            ("12", 0.5),
            ("1E2", 50.0),
        ] {
            let got = half_last_digit(text);
            assert!(
                (got - want).abs() <= ULPS * want,
                "{text}: {got:e} vs {want:e}"
            );
        }
    }

    #[test]
    fn embedded_table_ii() {
        let m = Measured::table_ii();
        assert_eq!(m.modes.len(), 8);
        assert_eq!(m.modes[0].frequency_hz, 1.331e-3);
        assert_eq!(m.modes[7].frequency_hz, 10.393);
        assert!(m
            .modes
            .iter()
            .all(|x| x.sigma_source == SigmaSource::Digits));
    }

    #[test]
    fn subset_with_sigma_and_errors() {
        let ok = Measured::parse(
            "mode,frequency_hz,sigma_hz\n7,7.9,0.1\n1,0.00133,\n",
            "t.csv",
        )
        .unwrap();
        assert_eq!(ok.modes.iter().map(|m| m.mode).collect::<Vec<_>>(), [1, 7]);
        assert_eq!(ok.modes[1].sigma_hz, 0.1);
        assert_eq!(ok.modes[0].sigma_source, SigmaSource::Digits);
        // CSV as written by spreadsheets: byte-order mark, quotes, CRLF.
        let quoted = Measured::parse(
            "\u{feff}\"mode\",\"frequency_hz\"\r\n\"2\",\"0.002117\"\r\n",
            "t.csv",
        )
        .unwrap();
        assert_eq!(quoted.modes[0].frequency_hz, 0.002117);
        for (text, needle) in [
            ("mode,frequency_hz\n9,1.0\n", "mode `9`"),
            ("mode,frequency_hz\n1,1.0\n1,2.0\n", "listed twice"),
            ("mode,frequency_hz\n1,-1.0\n", "frequency_hz `-1.0`"),
            ("mode,frequency_hz\n1,nan\n", "frequency_hz `nan`"),
            (
                "mode,frequency_hz\n1,inf\n",
                "must be finite, >= 1e-9 Hz and <= 1e6 Hz",
            ),
            (
                "mode,frequency_hz\n5,4.9e-324\n",
                "must be finite, >= 1e-9 Hz and <= 1e6 Hz",
            ),
            (
                "mode,frequency_hz\n1,1e300\n",
                "must be finite, >= 1e-9 Hz and <= 1e6 Hz",
            ),
            (
                "mode,frequency_hz,sigma_hz\n1,1.0,1e-300\n",
                "at least 8.881784197001252e-16 times the frequency",
            ),
            ("mode,frequency_hz,sigma_hz\n1,1.0,0\n", "sigma_hz `0`"),
            ("mode,freq\n1,1.0\n", "header"),
            ("mode,frequency_hz\n1\n", "has 1 fields"),
            ("mode,frequency_hz\n", "no measured mode"),
            (
                "mode,frequency_hz\n1,\"1.0\n",
                "t.csv, line 2: a double quote",
            ),
            (
                "mode,frequency_hz\n 1 , 1.0 , \n",
                "`1 , 1.0 ,` has 3 fields",
            ),
        ] {
            let e = Measured::parse(text, "t.csv").unwrap_err().to_string();
            assert!(e.contains(needle) && e.contains("t.csv"), "{text:?}: {e}");
        }
    }
}
