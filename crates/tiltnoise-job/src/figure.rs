//! Figures written to files: drawn by `tiltnoise-plot` in the format the extension names and
//! written through `tiltnoise-io`'s atomic writer, the same way for every front end.

use std::path::Path;
use tiltnoise_io::{OutputError, Staging};
use tiltnoise_plot::{DrawError, ImageFormat};

/// Draws a figure in the format named by the extension of `path` and writes it as one of the
/// outputs of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for an extension other than `.png`/`.svg` (nothing is drawn),
/// [`OutputError::Write`] naming `path` for a drawing or write failure (nothing is left there).
pub fn save_image(
    stage: &Staging,
    path: &Path,
    draw: impl FnOnce(ImageFormat) -> Result<Vec<u8>, DrawError>,
) -> Result<(), OutputError> {
    let format = crate::figures::image_format(path)?;
    let bytes = draw(format).map_err(|e| OutputError::Write {
        path: path.to_path_buf(),
        message: e.0,
    })?;
    stage.write(path, |temp| {
        std::fs::write(temp, &bytes).map_err(|e| e.to_string())
    })
}
