//! Comma-separated text as every tiltnoise reader takes it, tokenized by the `csv` crate: the
//! measured mode frequencies of [`crate::fit`] (including the embedded Table II), and in
//! `tiltnoise-io` the tilt and measured inputs and the frequency files.
//!
//! The rules on top of the tokenizer, the same for every format:
//!
//! * A record is one line; line numbers are 1-based and count `\n`, as an editor shows them. A
//!   `\r` before the `\n` (CRLF) is trimmed with the last field.
//! * Blank lines and comment lines (`#`, possibly indented) are skipped. Formats with metadata
//!   in their comment lines read those lines before handing the rest to [`CsvRecords`]. An
//!   indented comment is tokenized before it is recognised, so `,"` in it opens a quote.
//! * Fields are trimmed and may be enclosed in double quotes (`""` inside quotes is one quote),
//!   so a quoted field may hold a comma; blanks around the quotes are allowed. A quote left
//!   open at the end of the line is an error, not a field running over several lines.
//!
//! No files are opened here: the caller hands in the text or a reader.

use std::io::{self, Read};

/// Why the next record could not be read. The message says what is wrong and what is
/// allowed; the formats' own errors add the file and the line.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The underlying reader failed.
    #[error("{0}")]
    Io(io::Error),
    /// A field is not UTF-8.
    #[error("not UTF-8 text; allowed: UTF-8 (or ASCII)")]
    NotUtf8 {
        /// 1-based line number.
        line: usize,
    },
    /// A double quote opened on this line is not closed on it.
    #[error(
        "a double quote opens a field that is not closed on this line; allowed: quoted fields \
         closed on their own line"
    )]
    OpenQuote {
        /// 1-based line number.
        line: usize,
    },
}

impl RecordError {
    /// The line the error is on (`None` for a failed reader).
    pub fn line(&self) -> Option<usize> {
        match self {
            RecordError::Io(_) => None,
            RecordError::NotUtf8 { line } | RecordError::OpenQuote { line } => Some(*line),
        }
    }
}

/// The records of comma-separated text, one at a time (see the module docs for the rules).
pub struct CsvRecords<R: Read> {
    reader: csv::Reader<io::Chain<R, &'static [u8]>>,
    record: csv::ByteRecord,
    /// Line number of the first line of the input, minus one.
    line_offset: usize,
}

impl<'a> CsvRecords<&'a [u8]> {
    /// The records of `text`, whose first line is line 1. A leading UTF-8 byte-order mark is
    /// ignored.
    pub fn from_text(text: &'a str) -> Self {
        CsvRecords::new(strip_bom(text).as_bytes(), 1)
    }
}

/// Line `line` (1-based) of `text` as written, trimmed: for messages that quote a record of
/// [`CsvRecords::from_text`].
pub fn line_text(text: &str, line: usize) -> &str {
    strip_bom(text)
        .lines()
        .nth(line.saturating_sub(1))
        .map_or("", str::trim)
}

fn strip_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

impl<R: Read> CsvRecords<R> {
    /// The records of `input`, whose first line has the (1-based) number `first_line` in the
    /// caller's file (the lines before it were read by the caller).
    pub fn new(input: R, first_line: usize) -> Self {
        let reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            // Lines end at `\n` only, as an editor counts them; see `next_record` for why
            // every record must end with one.
            .terminator(csv::Terminator::Any(b'\n'))
            .buffer_capacity(1 << 16)
            .from_reader(input.chain(&b"\n"[..]));
        CsvRecords {
            reader,
            record: csv::ByteRecord::new(),
            line_offset: first_line.saturating_sub(1),
        }
    }

    /// The next record: its 1-based line number and its fields, trimmed and unquoted. `None`
    /// at the end of the input.
    pub fn next_record(&mut self) -> Result<Option<(usize, Vec<&str>)>, RecordError> {
        loop {
            let more = self
                .reader
                .read_byte_record(&mut self.record)
                .map_err(|e| {
                    RecordError::Io(match e.into_kind() {
                        csv::ErrorKind::Io(e) => e,
                        // Not produced for flexible byte records; kept as text all the same.
                        other => io::Error::other(format!("{other:?}")),
                    })
                })?;
            if !more {
                return Ok(None);
            }
            // The tokenizer skips blank and comment lines silently, so the line a record starts
            // on is counted back from the line after it: every record ends with a `\n` (one is
            // appended to the input), and any other line break in it is inside a quoted field.
            let after = self.reader.position().line() as usize;
            let inside = self
                .record
                .as_slice()
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            if inside > 0 {
                // A quote left open runs to the end of the input and swallows the appended
                // `\n`: then its last field ends with it and the record has no `\n` of its own.
                let open = self.record.iter().next_back();
                let own = usize::from(!open.is_some_and(|f| f.ends_with(b"\n")));
                return Err(RecordError::OpenQuote {
                    line: self.line_offset + after - own - inside,
                });
            }
            let line = self.line_offset + after - 1;
            // A comment line starting with `#` never reaches here; an indented one does (its
            // first field starts with blanks: a field starting with `#` itself was quoted).
            let first = self.record.get(0).unwrap_or_default();
            if first.first().is_some_and(u8::is_ascii_whitespace)
                && first.trim_ascii_start().starts_with(b"#")
            {
                continue;
            }
            // A line of blanks (an empty line never reaches here; `""` is an empty field).
            if self.record.len() == 1
                && !first.is_empty()
                && std::str::from_utf8(first).is_ok_and(|f| f.trim().is_empty())
            {
                continue;
            }
            let fields = self
                .record
                .iter()
                .map(|f| std::str::from_utf8(f).map(unquote))
                .collect::<Result<Vec<&str>, _>>()
                .map_err(|_| RecordError::NotUtf8 { line })?;
            return Ok(Some((line, fields)));
        }
    }
}

/// Trims a field and removes double quotes enclosing it when blanks stood outside them (the
/// tokenizer unquotes only a field that starts with the quote).
fn unquote(s: &str) -> &str {
    let s = s.trim();
    s.strip_prefix('"')
        .and_then(|s| s.strip_suffix('"'))
        .unwrap_or(s)
        .trim()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all(text: &str) -> Result<Vec<(usize, Vec<String>)>, RecordError> {
        let mut records = CsvRecords::from_text(text);
        let mut out = Vec::new();
        while let Some((line, fields)) = records.next_record()? {
            out.push((line, fields.iter().map(|f| f.to_string()).collect()));
        }
        Ok(out)
    }

    fn rec(line: usize, fields: &[&str]) -> (usize, Vec<String>) {
        (line, fields.iter().map(|f| f.to_string()).collect())
    }

    #[test]
    fn lines_comments_blanks_and_quotes() {
        let text = "\u{feff}a,b\r\n\n# c,\"d\n  # e, \"f\n \t \r\n\"1,5\" ,\"2\"\"\"\n 3 , \"4\" \n\"\"\n5,6";
        assert_eq!(
            all(text).unwrap(),
            [
                rec(1, &["a", "b"]),
                rec(6, &["1,5", "2\""]),
                rec(7, &["3", "4"]),
                rec(8, &[""]),
                rec(9, &["5", "6"]),
            ]
        );
    }

    #[test]
    fn open_quotes_name_their_line() {
        for (text, line) in [
            ("a\n\n1,\"2\n3\n", 3),
            ("a\n1\n\"2\n", 3),
            ("a\n1\n\"2", 3),
            ("\"a\n", 1),
        ] {
            match all(text) {
                Err(RecordError::OpenQuote { line: l }) => assert_eq!(l, line, "{text:?}"),
                other => panic!("{text:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn first_line_offset_and_utf8() {
        let mut records = CsvRecords::new(&b"x,y\n\n1,\xe9\n"[..], 4);
        assert_eq!(records.next_record().unwrap().unwrap().0, 4);
        assert!(matches!(
            records.next_record(),
            Err(RecordError::NotUtf8 { line: 6 })
        ));
        // Comments are not decoded.
        let mut records = CsvRecords::new(&b"x\n# caf\xe9\n  # caf\xe9\n1\n"[..], 1);
        assert_eq!(records.next_record().unwrap().unwrap().0, 1);
        assert_eq!(records.next_record().unwrap().unwrap().0, 4);
    }
}
