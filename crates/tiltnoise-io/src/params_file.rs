//! Parameter files: TOML text read within its limits, then parsed and validated by
//! [`Params::from_toml_str`].

use crate::text_file::{read_text_file, TextFileError};
use std::path::Path;
use tiltnoise_core::error::ParamError;
use tiltnoise_core::limits::MAX_SETTINGS_FILE_BYTES;
use tiltnoise_core::params::Params;

/// Reads, parses and validates a TOML parameter file of at most
/// [`MAX_SETTINGS_FILE_BYTES`] (a device or pipe is read no further) and lines of at most
/// [`MAX_LINE_BYTES`](tiltnoise_core::limits::MAX_LINE_BYTES).
///
/// # Errors
///
/// [`ParamError::Read`] when the file cannot be read, [`ParamError::TooLarge`] over a limit,
/// and the errors of [`Params::from_toml_str`].
pub fn read_params(path: &Path) -> Result<Params, ParamError> {
    let name = format!("parameter file {}", path.display());
    let text =
        read_text_file(path, MAX_SETTINGS_FILE_BYTES, &name, "a parameter file").map_err(|e| {
            match e {
                TextFileError::Io(reason) => ParamError::Read {
                    path: path.to_path_buf(),
                    reason,
                },
                TextFileError::TooLarge(e) => ParamError::TooLarge(e),
            }
        })?;
    Params::from_toml_str(&text, &path.display().to_string())
}
