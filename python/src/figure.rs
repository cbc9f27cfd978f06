//! The command line's figures, written by the results' `save("x.png")` / `save("x.svg")`.

use std::path::Path;
use tiltnoise_io::OutputError;
use tiltnoise_plot::{DrawError, ImageFormat};

/// Writes the figure `draw` makes in the format of `path`'s extension, atomically, as the
/// command line's `--save x.png` does.
pub fn save(
    path: &Path,
    draw: impl FnOnce(ImageFormat) -> Result<Vec<u8>, DrawError>,
) -> Result<(), OutputError> {
    let format = ImageFormat::from_path(path)?;
    let bytes = draw(format).map_err(|e| OutputError::Write {
        path: path.to_path_buf(),
        message: e.0,
    })?;
    tiltnoise_io::write_atomic(path, |temp| {
        std::fs::write(temp, &bytes).map_err(|e| e.to_string())
    })
}
