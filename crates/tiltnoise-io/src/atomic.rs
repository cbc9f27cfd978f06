//! Atomic file replacement: write to a temporary file next to the target, then rename. Used by
//! every writer (HDF5, CSV, figures) so that a failed run never leaves a partial file.

use std::ffi::OsString;
use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::OutputError;

/// Writes `path` atomically: `write` receives the path of a fresh, empty temporary file in the
/// same directory as `path` (so the final rename never crosses a file system), fills it, and the
/// temporary file is then flushed to disk and renamed onto `path`.
///
/// The temporary file is named `.<file name>.<random>.<ext>`: it keeps the real extension as
/// its suffix, for libraries that look at it. `write` may replace the file at that path (HDF5
/// opens it with `hdf5::File::create`), but must have closed it when it returns.
///
/// On any error the temporary file is removed and `path` is left as it was: absent if it did not
/// exist, untouched if it did. A new file gets the usual permissions (`0o666` minus the umask);
/// a replaced file's permissions are not carried over.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path`, with the operating system's message (for example
/// `No such file or directory (os error 2)` when the directory does not exist) or the message
/// returned by `write`.
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), OutputError> {
    let fail = |message: String| OutputError::Write {
        path: path.to_path_buf(),
        message,
    };
    let file_name = path
        .file_name()
        .ok_or_else(|| fail("the path does not name a file".to_string()))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut prefix = OsString::from(".");
    prefix.push(file_name);
    prefix.push(".");
    let mut suffix = OsString::new();
    if let Some(ext) = path.extension() {
        suffix.push(".");
        suffix.push(ext);
    }

    // `make_in` (unlike `tempfile_in`) returns the operating system's error unchanged, and lets
    // the file be created with the ordinary umask-controlled mode instead of 0o600.
    let temp = tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(&suffix)
        .make_in(&dir, create_new)
        .map_err(|e| fail(e.to_string()))?;
    // Close our handle; keep the path, which deletes the file when dropped.
    let temp = temp.into_temp_path();

    write(&temp).map_err(fail)?;
    OpenOptions::new()
        .write(true)
        .open(&temp)
        .and_then(|f| f.sync_all())
        .map_err(|e| fail(format!("cannot flush temporary file: {e}")))?;
    temp.persist(path).map_err(|e| fail(e.error.to_string()))?;
    Ok(())
}

fn create_new(path: &Path) -> io::Result<File> {
    let mut options = OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.mode(0o666);
    }
    options.open(path)
}
