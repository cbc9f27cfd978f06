//! Small text files read whole (parameter, frequency, measured-mode and visibility files), within
//! their byte and line limits.

use std::io::{self, Read};
use std::path::Path;
use tiltnoise_core::limits::{check_file_len, BoundedReader, LimitError, Overrun, MAX_LINE_BYTES};

/// Why [`read_text_file`] failed.
#[derive(Debug)]
pub(crate) enum TextFileError {
    /// The file could not be opened or read, or is not UTF-8.
    Io(io::Error),
    /// The file or one of its lines is over its limit.
    TooLarge(LimitError),
}

/// Reads the text file `path` whole, refusing a file longer than `max_bytes` (from its
/// metadata when it is a regular file, else after `max_bytes + 1` bytes) or a line longer
/// than [`MAX_LINE_BYTES`]. `name` names the file in messages (e.g. `parameter file p.toml`),
/// `of` says what the limit is for (e.g. `a parameter file`).
pub(crate) fn read_text_file(
    path: &Path,
    max_bytes: u64,
    name: &str,
    of: &'static str,
) -> Result<String, TextFileError> {
    let file = std::fs::File::open(path).map_err(TextFileError::Io)?;
    let meta = file.metadata().map_err(TextFileError::Io)?;
    if meta.is_file() {
        check_file_len(|| name.to_string(), meta.len(), max_bytes, of)
            .map_err(TextFileError::TooLarge)?;
    }
    let mut text = String::new();
    BoundedReader::new(file, max_bytes, MAX_LINE_BYTES)
        .read_to_string(&mut text)
        .map_err(|e| match Overrun::of(&e) {
            Some(o) => TextFileError::TooLarge(o.to_limit_error(name, of)),
            None => TextFileError::Io(e),
        })?;
    Ok(text)
}
