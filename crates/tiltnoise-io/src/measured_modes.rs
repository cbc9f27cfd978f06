//! Measured mode-frequency and visibility files (`tiltnoise fit --measured`, `--visibility`), in
//! the formats that [`tiltnoise_core::fit::Measured::parse`] and
//! [`tiltnoise_core::fit::Visibilities::parse`] validate.

use crate::text_file::{read_text_file, TextFileError};
use std::path::Path;
use tiltnoise_core::fit::{FitError, Measured, Visibilities};
use tiltnoise_core::limits::MAX_SETTINGS_FILE_BYTES;

/// Reads and validates a measured-frequency file; its path names it in messages.
///
/// # Errors
///
/// [`FitError::Read`] naming the file when it cannot be read, [`FitError::Measured`] naming
/// it (and the line) when it is malformed;
/// [`FitError::TooLarge`] for a file over [`MAX_SETTINGS_FILE_BYTES`] (a device or pipe is
/// read no further) or a line over [`tiltnoise_core::limits::MAX_LINE_BYTES`].
pub fn read_measured_modes(path: &Path) -> Result<Measured, FitError> {
    let origin = path.display().to_string();
    let name = format!("measured frequencies {origin}");
    let text = read_text_file(
        path,
        MAX_SETTINGS_FILE_BYTES,
        &name,
        "a measured-frequency file",
    )
    .map_err(|e| match e {
        TextFileError::Io(reason) => FitError::Read {
            what: "measured frequencies",
            origin: origin.clone(),
            reason,
        },
        TextFileError::TooLarge(e) => FitError::TooLarge(e),
    })?;
    Measured::parse(&text, &origin)
}

/// Reads and validates a visibility file (`tiltnoise fit --visibility`), in the format that
/// [`Visibilities::parse`] validates; its path names it in messages.
///
/// # Errors
///
/// [`FitError::Read`] naming the file when it cannot be read, [`FitError::Visibility`] naming
/// it (and the line) when it is malformed;
/// [`FitError::TooLarge`] as [`read_measured_modes`].
pub fn read_visibilities(path: &Path) -> Result<Visibilities, FitError> {
    let origin = path.display().to_string();
    let name = format!("visibilities {origin}");
    let text =
        read_text_file(path, MAX_SETTINGS_FILE_BYTES, &name, "a visibility file").map_err(|e| {
            match e {
                TextFileError::Io(reason) => FitError::Read {
                    what: "visibilities",
                    origin: origin.clone(),
                    reason,
                },
                TextFileError::TooLarge(e) => FitError::TooLarge(e),
            }
        })?;
    Visibilities::parse(&text, &origin)
}
