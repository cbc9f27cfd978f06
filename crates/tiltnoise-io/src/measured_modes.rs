//! Measured mode-frequency files (`tiltnoise fit --measured`), in the format that
//! [`tiltnoise_core::fit::Measured::parse`] validates.

use std::path::Path;
use tiltnoise_core::fit::{FitError, Measured};

/// Reads and validates a measured-frequency file; its path names it in messages.
///
/// # Errors
///
/// [`FitError::Measured`] naming the file (and line) when it cannot be read or is malformed.
pub fn read_measured_modes(path: &Path) -> Result<Measured, FitError> {
    let origin = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| FitError::Measured {
        origin: origin.clone(),
        message: e.to_string(),
    })?;
    Measured::parse(&text, &origin)
}
