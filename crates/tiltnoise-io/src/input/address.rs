//! Which format a path names, and the HDF5 address `FILE.h5:/group/dataset`.

use std::path::{Path, PathBuf};
use tiltnoise_core::input::{InputError, InputFormat};

/// The format named by the extension of `path` (case-insensitive); an HDF5 address
/// `FILE.h5:/group/dataset` is HDF5 ([`split_hdf5_address`]).
///
/// # Errors
///
/// [`InputError::Extension`] for anything but `.h5`, `.hdf5`, `.csv`, `.mseed`,
/// `.miniseed`, `.ms`.
pub fn input_format(path: &Path) -> Result<InputFormat, InputError> {
    let (file, _) = split_hdf5_address(path);
    let ext = file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "h5" | "hdf5" => Ok(InputFormat::Hdf5),
        "csv" => Ok(InputFormat::Csv),
        "mseed" | "miniseed" | "ms" => Ok(InputFormat::Miniseed),
        _ => Err(InputError::Extension {
            path: path.to_path_buf(),
            extension: ext,
        }),
    }
}

/// Splits an HDF5 address `FILE.h5:/group/dataset` (or `FILE.hdf5:/group`) into the file and
/// the object path inside it. A path that exists as given, or has no `.h5:/` or `.hdf5:/`,
/// is returned whole with no object.
///
/// ```
/// use std::path::{Path, PathBuf};
/// use tiltnoise_io::input::split_hdf5_address;
/// let (file, object) = split_hdf5_address(Path::new("run/tilt.h5:/gwpy/theta"));
/// assert_eq!((file, object.as_deref()), (PathBuf::from("run/tilt.h5"), Some("/gwpy/theta")));
/// assert_eq!(split_hdf5_address(Path::new("tilt.h5")).1, None);
/// ```
pub fn split_hdf5_address(path: &Path) -> (PathBuf, Option<String>) {
    let whole = (path.to_path_buf(), None);
    if path.exists() {
        return whole;
    }
    let text = path.to_string_lossy();
    let lower = text.to_ascii_lowercase();
    let found = [".h5:/", ".hdf5:/"]
        .iter()
        .filter_map(|m| lower.rfind(m).map(|i| (i + m.len() - 2, i + m.len() - 1)))
        .max();
    match found {
        Some((colon, object)) => (
            PathBuf::from(&text[..colon]),
            Some(text[object..].to_string()),
        ),
        None => whole,
    }
}
