//! The strict CSV reader of the tilt inputs: `#` comment lines (metadata keys `# units:`,
//! `# axes:`, `# start_time:`, `# description:` before the header), one header line, then
//! records with exactly as many fields as the header. The lines before the header are read here
//! (they carry the metadata); the header and the records are tokenized by
//! [`tiltnoise_core::csv_text`], whose rules (blank and comment lines skipped, fields trimmed,
//! double quotes) hold for every CSV file tiltnoise reads.
//!
//! A file is read through [`BoundedReader`]: at most [`MAX_DATA_FILE_BYTES`] (a larger regular
//! file is refused before reading), lines of at most [`MAX_LINE_BYTES`], and at most
//! [`MAX_SERIES_SAMPLES`] records.

use super::format_error::FormatError;
use super::meta::decide_quantity;
use super::series_units::{self, Plan, Stated};
use crate::input::spectra_checks::refuse_translation_spectra;
use std::fs::File;
use std::io::{BufRead, BufReader, Chain, Cursor, Read};
use std::path::{Path, PathBuf};
use tiltnoise_core::csv_text::{CsvRecords, RecordError};
use tiltnoise_core::error::{shown_list, Shown};
use tiltnoise_core::input::InputError;
use tiltnoise_core::input::{check_scales, AxisMap, Quantity, ReadOptions, UNITS_ALLOWED};
use tiltnoise_core::input::{resolve, MapOrigin, Motion, Resolved};
use tiltnoise_core::limits::{
    check_count, check_file_len, BoundedReader, Overrun, MAX_DATA_FILE_BYTES, MAX_LINE_BYTES,
    MAX_SERIES_SAMPLES,
};

/// What [`MAX_DATA_FILE_BYTES`] limits, for messages.
const DATA_FILE: &str = "a CSV input";

/// The file as read: bounded in bytes and line length.
type Source = BufReader<BoundedReader<File>>;

/// Whether a header's first column names the frequency: `frequency_hz`, the name in every
/// file tiltnoise writes, or `freq_hz`, the name in files written before.
pub(crate) fn is_frequency_column(name: Option<&String>) -> bool {
    matches!(name.map(String::as_str), Some("frequency_hz" | "freq_hz"))
}

/// Metadata keys recognised in `# key: value` lines before the header.
pub(crate) const META_KEYS: [&str; 4] = ["units", "axes", "start_time", "description"];

/// What is allowed instead of bytes that are not UTF-8.
const NOT_UTF8: &str = "not UTF-8 text; allowed: a UTF-8 (or ASCII) CSV file (an HDF5 file \
                        needs the extension .h5 or .hdf5)";

/// One `# key: value` line.
#[derive(Debug, Clone)]
pub(crate) struct MetaLine {
    pub key: String,
    pub value: String,
    pub line: usize,
}

/// Everything before the first record.
#[derive(Debug, Clone)]
pub(crate) struct Prelude {
    pub header: Vec<String>,
    pub header_line: usize,
    pub meta: Vec<MetaLine>,
}

impl Prelude {
    /// The metadata line of key `key` (keys are unique, see [`CsvFile::open`]).
    pub fn meta(&self, key: &str) -> Option<&MetaLine> {
        self.meta.iter().find(|m| m.key == key)
    }
}

/// An open CSV file positioned after its header.
pub(crate) struct CsvFile {
    pub path: PathBuf,
    /// The header line, then the rest of the file.
    records: CsvRecords<Chain<Cursor<String>, Source>>,
}

/// The lines before the header, one at a time.
struct Lines<'a> {
    path: &'a Path,
    reader: Source,
    line_no: usize,
    /// The last line read, with its line ending.
    buf: String,
}

impl Lines<'_> {
    fn err(&self, line: usize, message: String) -> InputError {
        InputError::from(FormatError::Csv {
            path: self.path.to_path_buf(),
            line,
            message,
        })
    }

    /// Reads the next line into `self.buf`; `false` at end of file.
    fn next_line(&mut self) -> Result<bool, InputError> {
        self.buf.clear();
        let n = self.reader.read_line(&mut self.buf).map_err(|e| {
            if e.kind() == std::io::ErrorKind::InvalidData {
                self.err(self.line_no + 1, NOT_UTF8.to_string())
            } else {
                io_error(self.path, e)
            }
        })?;
        if n == 0 {
            return Ok(false);
        }
        self.line_no += 1;
        if self.line_no == 1 && self.buf.starts_with('\u{feff}') {
            self.buf.drain(..3);
            // A second mark is text, not encoding (the CSV parser would drop it silently):
            // the file was concatenated or converted twice.
            if self.buf.starts_with('\u{feff}') {
                return Err(self.err(
                    1,
                    "starts with two byte-order marks (U+FEFF); allowed: at most one, at the \
                     start of the file"
                        .to_string(),
                ));
            }
        }
        Ok(true)
    }
}

/// The error of a failed read: a limit of the [`BoundedReader`] or the operating system's.
fn io_error(path: &Path, reason: std::io::Error) -> InputError {
    match Overrun::of(&reason) {
        Some(o) => o
            .to_limit_error(&format!("input file {}", path.display()), DATA_FILE)
            .into(),
        None => InputError::Io {
            path: path.to_path_buf(),
            reason,
        },
    }
}

/// The error of a record that could not be read.
fn record_error(path: &Path, e: RecordError) -> InputError {
    match e {
        RecordError::Io(reason) => io_error(path, reason),
        RecordError::NotUtf8 { line } => InputError::from(FormatError::Csv {
            path: path.to_path_buf(),
            line,
            message: NOT_UTF8.to_string(),
        }),
        e @ RecordError::OpenQuote { line } => InputError::from(FormatError::Csv {
            path: path.to_path_buf(),
            line,
            message: e.to_string(),
        }),
    }
}

impl CsvFile {
    /// Opens `path` and reads its comment and metadata lines and its header.
    pub fn open(path: &Path) -> Result<(CsvFile, Prelude), InputError> {
        let io = |reason| InputError::Io {
            path: path.to_path_buf(),
            reason,
        };
        let file = File::open(path).map_err(io)?;
        let meta = file.metadata().map_err(io)?;
        if meta.is_file() {
            let what = || format!("input file {}", path.display());
            check_file_len(what, meta.len(), MAX_DATA_FILE_BYTES, DATA_FILE)?;
        }
        let bounded = BoundedReader::new(file, MAX_DATA_FILE_BYTES, MAX_LINE_BYTES);
        let mut lines = Lines {
            path,
            reader: BufReader::with_capacity(1 << 16, bounded),
            line_no: 0,
            buf: String::new(),
        };
        let no_header = |line: usize| {
            InputError::from(FormatError::Csv {
                path: path.to_path_buf(),
                line,
                message:
                    "no header line; allowed: optional `#` comment lines, then a header such as \
                 time_s,theta_t,eta_t or frequency_hz,theta_t,eta_t, then data rows"
                        .to_string(),
            })
        };
        let mut meta: Vec<MetaLine> = Vec::new();
        loop {
            if !lines.next_line()? {
                return Err(no_header(lines.line_no));
            }
            let line = lines.buf.trim();
            if line.is_empty() {
                continue;
            }
            let Some(comment) = line.strip_prefix('#') else {
                break;
            };
            if let Some((key, value)) = comment.trim_start().split_once(':') {
                let key = key.trim();
                if META_KEYS.contains(&key) {
                    if let Some(prev) = meta.iter().find(|m| m.key == key) {
                        return Err(lines.err(
                            lines.line_no,
                            format!(
                                "metadata key `# {key}:` repeated (first on line {}); allowed: \
                                 once",
                                prev.line
                            ),
                        ));
                    }
                    meta.push(MetaLine {
                        key: key.to_string(),
                        value: value.trim().to_string(),
                        line: lines.line_no,
                    });
                }
            }
        }
        let header_line = lines.line_no;
        let rest = Cursor::new(std::mem::take(&mut lines.buf)).chain(lines.reader);
        let mut file = CsvFile {
            path: path.to_path_buf(),
            records: CsvRecords::new(rest, header_line),
        };
        let header: Vec<String> = match file.records.next_record() {
            Ok(Some((_, names))) => names.iter().map(|n| n.to_string()).collect(),
            Ok(None) => return Err(no_header(header_line)),
            Err(e) => return Err(record_error(path, e)),
        };
        let header_err = |message: String| {
            InputError::from(FormatError::Csv {
                path: path.to_path_buf(),
                line: header_line,
                message,
            })
        };
        for (i, name) in header.iter().enumerate() {
            if name.is_empty() {
                return Err(header_err(format!(
                    "header column {} has an empty name; allowed: non-empty names",
                    i + 1
                )));
            }
            if let Some(j) = header[..i].iter().position(|n| n == name) {
                return Err(header_err(format!(
                    "header column `{}` appears twice (columns {} and {}); allowed: unique names",
                    Shown(name),
                    j + 1,
                    i + 1
                )));
            }
        }
        Ok((
            file,
            Prelude {
                header,
                header_line,
                meta,
            },
        ))
    }

    /// Calls `f(line_number, fields)` for every record after the header, at most
    /// [`MAX_SERIES_SAMPLES`]. Every record must have `n_fields` fields.
    pub fn for_each_record(
        &mut self,
        n_fields: usize,
        f: impl FnMut(usize, &[&str]) -> Result<(), InputError>,
    ) -> Result<(), InputError> {
        self.for_each_record_up_to(MAX_SERIES_SAMPLES, n_fields, f)
    }

    /// [`CsvFile::for_each_record`] with at most `max_records` records.
    fn for_each_record_up_to(
        &mut self,
        max_records: usize,
        n_fields: usize,
        mut f: impl FnMut(usize, &[&str]) -> Result<(), InputError>,
    ) -> Result<(), InputError> {
        let mut count = 0usize;
        while let Some((line, fields)) = self
            .records
            .next_record()
            .map_err(|e| record_error(&self.path, e))?
        {
            count += 1;
            check_count(
                || format!("input file {}, line {line}", self.path.display()),
                count as f64,
                "data rows",
                max_records,
            )?;
            if fields.len() != n_fields {
                return Err(FormatError::Csv {
                    path: self.path.clone(),
                    line,
                    message: format!(
                        "{} fields but the header has {n_fields}; allowed: exactly one field \
                         per header column",
                        fields.len()
                    ),
                }
                .into());
            }
            f(line, &fields)?;
        }
        Ok(())
    }
}

/// Parses a number field. `Ok(None)` for an empty field.
pub(crate) fn parse_field(text: &str) -> Result<Option<f64>, ()> {
    if text.is_empty() {
        return Ok(None);
    }
    text.parse::<f64>().map(Some).map_err(|_| ())
}

/// Resolution of a printed decimal number: the place value of its last digit, e.g. `8191.0` ->
/// 0.1, `1.25e-3` -> 1e-5, `100` -> 1.
pub(crate) fn decimal_resolution(text: &str) -> f64 {
    let (mantissa, exp) = match text.find(['e', 'E']) {
        Some(i) => (&text[..i], text[i + 1..].parse::<i32>().unwrap_or(0)),
        None => (text, 0),
    };
    let decimals = mantissa
        .split_once('.')
        .map_or(0, |(_, frac)| frac.len() as i32);
    10f64.powi(exp - decimals)
}

/// The units declared by the `# units:` line of a spectrum for the mapped columns `mapped`
/// (names), either one unit for every column or per column. Returns the declared units and the
/// mapped columns without one.
fn declared_units(
    path: &Path,
    prelude: &Prelude,
    mapped: &[String],
    classify: fn(&str) -> Option<super::meta::SpectrumUnit>,
    allowed: &'static str,
) -> Result<(Vec<super::meta::Declared>, Vec<String>), InputError> {
    use super::meta::Declared;
    let Some(m) = prelude.meta("units") else {
        return Ok((Vec::new(), mapped.to_vec()));
    };
    let bad_unit = |column: Option<&str>, value: &str| InputError::Units {
        path: path.to_path_buf(),
        location: match column {
            Some(c) => format!("line {} (# units:), column `{}`", m.line, Shown(c)),
            None => format!("line {} (# units:)", m.line),
        },
        value: value.to_string(),
        allowed,
    };
    let mut declared = Vec::new();
    if m.value.contains('=') {
        for (name, unit) in unit_entries(path, prelude, m)? {
            let u = classify(unit).ok_or_else(|| bad_unit(Some(name), unit))?;
            if mapped.iter().any(|c| c == name) {
                declared.push(Declared {
                    channel: name.to_string(),
                    unit: unit.to_string(),
                    quantity: u.quantity,
                });
            }
        }
    } else {
        let u = classify(&m.value).ok_or_else(|| bad_unit(None, &m.value))?;
        declared.extend(mapped.iter().map(|c| Declared {
            channel: c.clone(),
            unit: m.value.clone(),
            quantity: u.quantity,
        }));
    }
    let undeclared = mapped
        .iter()
        .filter(|c| !declared.iter().any(|d| &d.channel == *c))
        .cloned()
        .collect();
    Ok((declared, undeclared))
}

/// The `# axes:` map, if any.
fn axis_map(path: &Path, prelude: &Prelude) -> Result<Option<(AxisMap, String)>, InputError> {
    let Some(m) = prelude.meta("axes") else {
        return Ok(None);
    };
    let origin = format!("{}, line {} (# axes:)", path.display(), m.line);
    let map = AxisMap::parse_from(&m.value, &origin)?;
    Ok(Some((
        map,
        format!("line {} `# axes:` of the file", m.line),
    )))
}

/// Resolves the axis map (explicit, else `# axes:`, else the default) against the data columns
/// of `prelude`, of which `motions` says what each measures; the map's notes first.
fn map_columns(
    path: &Path,
    prelude: &Prelude,
    opts: &ReadOptions,
    motions: &[Option<Motion>],
) -> Result<(Resolved, Vec<String>), InputError> {
    let file_map = axis_map(path, prelude)?;
    let origin = match (&opts.axis_map, &file_map) {
        (Some(m), _) => MapOrigin::Options(m),
        (None, Some((m, from))) => MapOrigin::File(m, from),
        (None, None) => MapOrigin::Default,
    };
    let resolved = resolve(path, &prelude.header[1..], motions, origin, "column")?;
    let mut notes = resolved.notes.clone();
    if let (Some(_), Some((m, from))) = (&opts.axis_map, &file_map) {
        notes.push(format!(
            "the explicit axis map overrides the file's map {m} ({from})"
        ));
    }
    Ok((resolved, notes))
}

/// What a CSV spectrum's prelude decides: the channel mapping (tilt axes only), the quantity,
/// the start time and the provenance notes so far.
pub(crate) struct Interpreted {
    /// The axis map resolved against the data columns (`prelude.header[1..]`).
    pub resolved: Resolved,
    /// From the explicit quantity, else the `# units:` line, else angle.
    pub quantity: Quantity,
    /// The validated `# start_time:` value.
    pub start_time: Option<String>,
    /// Axis-map, quantity and description notes, in that order.
    pub notes: Vec<String>,
}

/// Interprets the prelude of a CSV spectrum: resolves the axis map against the data columns
/// (tilt axes only: spectra of translations are not read), decides the quantity from the
/// `# units:` line, whose units `classify` recognises (`allowed` lists them for the error), and
/// reads `# start_time:` and `# description:`.
pub(crate) fn interpret_spectra(
    path: &Path,
    prelude: &Prelude,
    opts: &ReadOptions,
    classify: fn(&str) -> Option<super::meta::SpectrumUnit>,
    allowed: &'static str,
) -> Result<Interpreted, InputError> {
    let unknown = vec![None; prelude.header.len() - 1];
    let (resolved, mut notes) = map_columns(path, prelude, opts, &unknown)?;
    refuse_translation_spectra(path, &resolved)?;
    let mapped: Vec<String> = resolved.channels.iter().map(|m| m.source.clone()).collect();
    let (declared, undeclared) = declared_units(path, prelude, &mapped, classify, allowed)?;
    let quantity = decide_quantity(path, opts.quantity, &declared, &undeclared, &mut notes)?;
    let start_time = start_time(path, prelude, &mut notes)?;
    if let Some(d) = prelude.meta("description") {
        notes.push(format!("description: {}", Shown(&d.value)));
    }
    Ok(Interpreted {
        resolved,
        quantity,
        start_time,
        notes,
    })
}

/// What a CSV time series' prelude decides: the channel mapping, the plan of every mapped
/// channel (quantity, factor, sensor), the start time and the provenance notes so far.
pub(crate) struct InterpretedSeries {
    /// The axis map resolved against the data columns (`prelude.header[1..]`).
    pub resolved: Resolved,
    /// One entry per `resolved.channels`.
    pub plan: Plan,
    /// The validated `# start_time:` value.
    pub start_time: Option<String>,
    /// Axis-map, unit, factor and description notes, in that order.
    pub notes: Vec<String>,
}

/// The units the `# units:` line states for the data columns: one for every column
/// (`# units: rad/s`) or per column (`# units: LJN=rad/s, LHE=m/s^2`).
fn stated_units(path: &Path, prelude: &Prelude) -> Result<Vec<Option<Stated>>, InputError> {
    let columns = &prelude.header[1..];
    let Some(m) = prelude.meta("units") else {
        return Ok(vec![None; columns.len()]);
    };
    let location = |column: Option<&str>| match column {
        Some(c) => format!("line {} (# units:), column `{}`", m.line, Shown(c)),
        None => format!("line {} (# units:)", m.line),
    };
    let checked = |column: Option<&str>, unit: &str| {
        let s = Stated::in_file(unit, location(column));
        match s.parsed {
            Some(_) => Ok(s),
            None => Err(InputError::Units {
                path: path.to_path_buf(),
                location: location(column),
                value: unit.to_string(),
                allowed: UNITS_ALLOWED,
            }),
        }
    };
    if !m.value.contains('=') {
        let s = checked(None, &m.value)?;
        return Ok(vec![Some(s); columns.len()]);
    }
    let mut out = vec![None; columns.len()];
    for (name, unit) in unit_entries(path, prelude, m)? {
        let i = columns
            .iter()
            .position(|c| c == name)
            .expect("unit_entries names data columns");
        out[i] = Some(checked(Some(name), unit)?);
    }
    Ok(out)
}

/// The `COLUMN=UNIT` entries of a per-column `# units:` line, each naming a data column once.
fn unit_entries<'a>(
    path: &Path,
    prelude: &Prelude,
    m: &'a MetaLine,
) -> Result<Vec<(&'a str, &'a str)>, InputError> {
    let mut entries: Vec<(&str, &str)> = Vec::new();
    for item in m.value.split(',') {
        let Some((name, unit)) = item.split_once('=') else {
            return Err(FormatError::Csv {
                path: path.to_path_buf(),
                line: m.line,
                message: format!(
                    "`# units:` entry `{}` has no `=`; allowed: one unit for all columns \
                     (e.g. `# units: rad/s`) or COLUMN=UNIT entries separated by commas",
                    Shown(item.trim())
                ),
            }
            .into());
        };
        let (name, unit) = (name.trim(), unit.trim());
        let repeated = entries.iter().any(|(n, _)| *n == name);
        if !prelude.header[1..].iter().any(|h| h == name) || repeated {
            return Err(FormatError::Csv {
                path: path.to_path_buf(),
                line: m.line,
                message: format!(
                    "`# units:` names column `{}`, which is {}; allowed: each data column \
                     of the header ({}) at most once",
                    Shown(name),
                    if repeated {
                        "repeated"
                    } else {
                        "not a data column"
                    },
                    shown_list(&prelude.header[1..])
                ),
            }
            .into());
        }
        entries.push((name, unit));
    }
    Ok(entries)
}

/// Interprets the prelude of a CSV time series: the units of the data columns (the `# units:`
/// line, then the options'), the axis map resolved with what they say each column measures,
/// the plan of the mapped columns ([`series_units::plan`]), `# start_time:` and
/// `# description:`.
pub(crate) fn interpret_series(
    path: &Path,
    prelude: &Prelude,
    opts: &ReadOptions,
) -> Result<InterpretedSeries, InputError> {
    let columns = &prelude.header[1..];
    let mut unit_notes = Vec::new();
    let stated = series_units::merge_given(
        path,
        columns,
        stated_units(path, prelude)?,
        &opts.units,
        "column",
        &mut unit_notes,
    )?;
    let motions = series_units::motions(path, columns, &stated)?;
    let (resolved, mut notes) = map_columns(path, prelude, opts, &motions)?;
    notes.extend(unit_notes);
    check_scales(path, &opts.scale, columns, "column")?;
    let plan = series_units::plan(path, &resolved, &stated, opts, &mut notes)?;
    let start_time = start_time(path, prelude, &mut notes)?;
    if let Some(d) = prelude.meta("description") {
        notes.push(format!("description: {}", Shown(&d.value)));
    }
    Ok(InterpretedSeries {
        resolved,
        plan,
        start_time,
        notes,
    })
}

/// The `# start_time:` value, validated; a note when it has no zone designator.
pub(crate) fn start_time(
    path: &Path,
    prelude: &Prelude,
    notes: &mut Vec<String>,
) -> Result<Option<String>, InputError> {
    prelude
        .meta("start_time")
        .map(|m| {
            super::start_time::checked(
                path,
                format!("line {}", m.line),
                "# start_time:",
                m.value.clone(),
                notes,
            )
        })
        .transpose()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_byte_order_mark_is_read_two_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        std::fs::write(&path, "\u{feff}time_s,E\n0,1\n1,2\n").unwrap();
        assert!(CsvFile::open(&path).is_ok());
        std::fs::write(&path, "\u{feff}\u{feff}time_s,E\n0,1\n1,2\n").unwrap();
        let e = CsvFile::open(&path).err().unwrap().to_string();
        assert!(
            e.contains("line 1") && e.contains("two byte-order marks"),
            "{e}"
        );
    }

    #[test]
    fn records_beyond_the_limit_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.csv");
        std::fs::write(&path, "# units: rad\ntime_s,E\n0,1\n1,2\n\n2,3\n3,4\n").unwrap();
        let (mut file, _) = CsvFile::open(&path).unwrap();
        let mut rows = 0;
        let e = file
            .for_each_record_up_to(3, 2, |_, _| {
                rows += 1;
                Ok(())
            })
            .unwrap_err()
            .to_string();
        assert_eq!(rows, 3);
        assert_eq!(
            e,
            format!(
                "input file {}, line 7: 4 data rows, more than the 3 allowed (see \
                 docs/limits.md)",
                path.display()
            )
        );
    }

    #[test]
    fn resolution() {
        assert_eq!(decimal_resolution("8191.0"), 0.1);
        assert_eq!(decimal_resolution("100"), 1.0);
        assert!((decimal_resolution("1.25e-3") - 1e-5).abs() < 1e-20);
        assert_eq!(decimal_resolution("1e3"), 1000.0);
    }
}
