//! Atomic outputs: every file is written to a temporary file next to its target and renamed
//! onto it only when complete, so that a failed run never leaves a partial file.
//!
//! * [`write_atomic`]: one file.
//! * [`AtomicFile`]: one file written over time (a long record, chunk by chunk), renamed when
//!   finished, removed if dropped before.
//! * [`Staging`]: every output of a run. While a `Staging` is active on the calling thread,
//!   [`write_atomic`] leaves each finished temporary file in place, and [`Staging::commit`]
//!   renames them all at the end; if the run fails before, dropping the `Staging` removes them,
//!   so either every output of the run appears or none does.
//! * [`remove_temporaries_for_exit`]: removes the temporary files that exist at that moment,
//!   for an interrupt handler that then ends the process (signals are the command line's).

use std::cell::RefCell;
use std::ffi::OsString;
use std::fs::{File, OpenOptions};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use tempfile::TempPath;
use tiltnoise_core::error::OutputError;

/// The longest file name most file systems accept (bytes).
pub(crate) const NAME_MAX: usize = 255;

/// How long [`remove_temporaries_for_exit`] waits before removing the temporary files again.
const RECREATE_GRACE: std::time::Duration = std::time::Duration::from_millis(100);

/// Temporary files that exist right now, for [`remove_temporaries_for_exit`].
static LIVE_TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

thread_local! {
    /// The outputs staged by the active [`Staging`] of this thread, if any.
    static STAGED: RefCell<Option<Vec<Staged>>> = const { RefCell::new(None) };
}

/// A finished temporary file and the path it is to be renamed to.
struct Staged {
    temp: Registered,
    target: PathBuf,
}

/// A temporary file known to the interrupt handler for as long as it exists.
struct Registered(Option<TempPath>);

impl Registered {
    /// Creates the temporary file with `create` and registers it, holding the registry's lock
    /// throughout: an interrupt handled in between waits for the lock and then finds the file,
    /// so there is no moment when the file exists unregistered.
    fn create(create: impl FnOnce() -> io::Result<TempPath>) -> io::Result<Registered> {
        let mut live = LIVE_TEMPORARIES
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let temp = create()?;
        live.push(temp.to_path_buf());
        Ok(Registered(Some(temp)))
    }

    fn path(&self) -> &Path {
        self.0.as_deref().expect("present until persisted")
    }

    fn forget(path: &Path) {
        if let Ok(mut live) = LIVE_TEMPORARIES.lock() {
            live.retain(|p| p != path);
        }
    }

    /// Renames the file onto `target`; on failure the file is removed (on drop).
    fn persist(mut self, target: &Path) -> io::Result<()> {
        let temp = self.0.take().expect("present until persisted");
        let path = temp.to_path_buf();
        let result = temp.persist(target).map_err(|e| e.error);
        Registered::forget(&path);
        result
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        if let Some(temp) = self.0.take() {
            let path = temp.to_path_buf();
            drop(temp); // removes the file
            Registered::forget(&path);
        }
    }
}

/// Writes `path` atomically: `write` receives the path of a fresh, empty temporary file in the
/// same directory as `path` (so the final rename never crosses a file system), fills it, and the
/// temporary file is then flushed to disk and renamed onto `path` (at once, or by
/// [`Staging::commit`] when a [`Staging`] is active on this thread).
///
/// The temporary file is named `.<file name>.<random>.<ext>`, the file name shortened so that
/// the whole name fits in 255 bytes: it keeps the real extension as its suffix, for libraries
/// that look at it. `write` may replace the file at that path (HDF5 opens it with
/// `hdf5::File::create`), but must have closed it when it returns.
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
    let file = AtomicFile::create(path)?;
    write(file.temp_path()).map_err(|message| file.fail(message))?;
    file.finish()
}

/// An output written over time, atomically as by [`write_atomic`]: from
/// [`AtomicFile::create`] to [`AtomicFile::finish`] the data go to a temporary file next to
/// the target, which the interrupt handler knows; dropping an unfinished `AtomicFile` (the run
/// failed) removes it, and `path` is left as it was. For a long record written chunk by chunk
/// while it is computed.
#[must_use = "an AtomicFile that is not finished removes its output"]
pub struct AtomicFile {
    temp: Registered,
    target: PathBuf,
}

impl AtomicFile {
    /// Creates the empty temporary file for `path` (named as by [`write_atomic`]).
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming `path` when the temporary file cannot be created.
    pub fn create(path: &Path) -> Result<AtomicFile, OutputError> {
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
        let mut suffix = OsString::new();
        if let Some(ext) = path.extension() {
            suffix.push(".");
            suffix.push(ext);
        }
        // `.` + name + `.` + 6 random characters + suffix <= NAME_MAX.
        let room = NAME_MAX.saturating_sub(2 + RANDOM_LEN + suffix.len());
        let mut prefix = OsString::from(".");
        prefix.push(shortened(file_name, room));
        prefix.push(".");

        // `make_in` (unlike `tempfile_in`) returns the operating system's error unchanged, and
        // lets the file be created with the ordinary umask-controlled mode instead of 0o600.
        // Close our handle; keep the path, which deletes the file when dropped.
        let temp = Registered::create(|| {
            tempfile::Builder::new()
                .prefix(&prefix)
                .suffix(&suffix)
                .rand_bytes(RANDOM_LEN)
                .make_in(&dir, create_new)
                .map(|t| t.into_temp_path())
        })
        .map_err(|e| fail(e.to_string()))?;
        Ok(AtomicFile {
            temp,
            target: path.to_path_buf(),
        })
    }

    /// The temporary file to write (it may be replaced, as HDF5's `File::create` does, and
    /// must be closed before [`AtomicFile::finish`]).
    pub fn temp_path(&self) -> &Path {
        self.temp.path()
    }

    /// The path the output is renamed to.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// [`OutputError::Write`] naming the target with `message`.
    pub fn fail(&self, message: String) -> OutputError {
        OutputError::Write {
            path: self.target.clone(),
            message,
        }
    }

    /// Flushes the temporary file to disk and renames it onto the target: at once, or by
    /// [`Staging::commit`] when a [`Staging`] is active on this thread.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target; the temporary file is then removed.
    pub fn finish(self) -> Result<(), OutputError> {
        OpenOptions::new()
            .write(true)
            .open(self.temp.path())
            .and_then(|f| f.sync_all())
            .map_err(|e| self.fail(format!("cannot flush temporary file: {e}")))?;
        let AtomicFile { temp, target } = self;
        let staged = STAGED.with(|s| {
            let mut s = s.borrow_mut();
            match s.as_mut() {
                Some(list) => {
                    list.push(Staged {
                        temp,
                        target: target.clone(),
                    });
                    None
                }
                None => Some(temp),
            }
        });
        match staged {
            Some(temp) => temp.persist(&target).map_err(|e| OutputError::Write {
                path: target,
                message: e.to_string(),
            }),
            None => Ok(()),
        }
    }
}

/// Creates and removes a temporary file in `dir`: whether the run can create its outputs there.
pub(crate) fn probe_directory(dir: &Path) -> io::Result<()> {
    // Registered while it exists, so that an interrupt removes it too.
    drop(Registered::create(|| {
        tempfile::Builder::new()
            .prefix(".tiltnoise-probe.")
            .rand_bytes(RANDOM_LEN)
            .make_in(dir, create_new)
            .map(|t| t.into_temp_path())
    })?);
    Ok(())
}

/// Random characters in a temporary file's name.
const RANDOM_LEN: usize = 6;

/// At most `max` bytes of `name`, cut at a character boundary when the name is UTF-8.
fn shortened(name: &std::ffi::OsStr, max: usize) -> OsString {
    if name.len() <= max {
        return name.to_os_string();
    }
    match name.to_str() {
        Some(s) => {
            let mut end = max;
            while !s.is_char_boundary(end) {
                end -= 1;
            }
            OsString::from(&s[..end])
        }
        None => {
            #[cfg(unix)]
            {
                use std::os::unix::ffi::{OsStrExt, OsStringExt};
                OsString::from_vec(name.as_bytes()[..max].to_vec())
            }
            #[cfg(not(unix))]
            {
                OsString::from("output")
            }
        }
    }
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

/// The outputs of one run, written all or none: while it is active, [`write_atomic`] on this
/// thread writes each output to its temporary file and leaves it there; [`Staging::commit`]
/// renames them all. Dropping a `Staging` that was not committed (the run failed) removes every
/// temporary file it holds, so no output of a failed run appears.
#[must_use = "a Staging that is not committed removes its outputs"]
pub struct Staging {
    _not_send: std::marker::PhantomData<*const ()>,
}

impl Staging {
    /// Starts staging the outputs of this thread.
    ///
    /// # Panics
    ///
    /// If a `Staging` is already active on this thread.
    pub fn begin() -> Staging {
        STAGED.with(|s| {
            let mut s = s.borrow_mut();
            assert!(s.is_none(), "a Staging is already active on this thread");
            *s = Some(Vec::new());
        });
        Staging {
            _not_send: std::marker::PhantomData,
        }
    }

    /// Renames every staged output onto its target, in the order they were written, and ends
    /// the staging. Returns the targets.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the first target that cannot be renamed; the temporary
    /// files not yet renamed are removed. (Renames within a directory that took the temporary
    /// file do not fail in practice; the outputs renamed before stay.)
    pub fn commit(self) -> Result<Vec<PathBuf>, OutputError> {
        let staged = STAGED.with(|s| s.borrow_mut().take()).unwrap_or_default();
        let mut done = Vec::with_capacity(staged.len());
        let mut rest = staged.into_iter();
        for s in rest.by_ref() {
            if let Err(e) = s.temp.persist(&s.target) {
                return Err(OutputError::Write {
                    path: s.target,
                    message: e.to_string(),
                });
            }
            done.push(s.target);
        }
        Ok(done)
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        // Not committed: the staged temporary files are removed as they drop.
        STAGED.with(|s| drop(s.borrow_mut().take()));
    }
}

/// Removes every temporary file of [`write_atomic`], [`AtomicFile`] and [`Staging`] that exists
/// now and returns how many there were, for a process about to end at once (the command
/// line's interrupt handler). The registry stays locked afterwards, so that no temporary file
/// can appear any more: a writer that tries to create one waits for the process to end.
/// Safe to call from any thread: a writer holds the lock only for a moment.
///
/// A registered path can still be created again by a writer already past the registry: the
/// HDF5 library creates its file over the (registered) temporary one, so a `File::create`
/// running on another thread at the moment of the removal leaves a fresh file behind. The
/// files are therefore removed a second time after a pause (100 ms), long enough for such a
/// create to have finished.
pub fn remove_temporaries_for_exit() -> usize {
    let live = LIVE_TEMPORARIES
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    for p in live.iter() {
        let _ = std::fs::remove_file(p);
    }
    if !live.is_empty() {
        std::thread::sleep(RECREATE_GRACE);
        for p in live.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
    let removed = live.len();
    std::mem::forget(live);
    removed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    fn write_text(path: &Path, text: &str) -> Result<(), OutputError> {
        write_atomic(path, |t| std::fs::write(t, text).map_err(|e| e.to_string()))
    }

    #[test]
    fn a_failed_run_leaves_none_of_its_outputs() {
        let dir = tempfile::tempdir().unwrap();
        {
            let _stage = Staging::begin();
            write_text(&dir.path().join("a.csv"), "a").unwrap();
            // Staged, not renamed: only the temporary file exists.
            assert_eq!(listing(dir.path()).len(), 1);
            assert!(!dir.path().join("a.csv").exists());
            let err = write_atomic(&dir.path().join("b.csv"), |_| Err("drawing failed".into()));
            assert!(err.is_err());
        } // dropped without commit
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
    }

    #[test]
    fn a_committed_run_has_every_output_and_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let stage = Staging::begin();
        write_text(&dir.path().join("a.csv"), "a").unwrap();
        write_text(&dir.path().join("b.csv"), "b").unwrap();
        let done = stage.commit().unwrap();
        assert_eq!(done.len(), 2);
        assert_eq!(listing(dir.path()), vec!["a.csv", "b.csv"]);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("b.csv")).unwrap(),
            "b"
        );
        // Without a Staging, a write is renamed at once.
        write_text(&dir.path().join("c.csv"), "c").unwrap();
        assert!(dir.path().join("c.csv").exists());
    }

    #[test]
    fn an_unfinished_file_is_removed_and_a_finished_one_staged() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("long.h5");
        {
            let file = AtomicFile::create(&target).unwrap();
            std::fs::write(file.temp_path(), "part").unwrap();
            assert_eq!(listing(dir.path()).len(), 1);
        } // dropped unfinished
        assert!(listing(dir.path()).is_empty());
        let stage = Staging::begin();
        let file = AtomicFile::create(&target).unwrap();
        std::fs::write(file.temp_path(), "all").unwrap();
        file.finish().unwrap();
        assert!(!target.exists(), "staged until the commit");
        stage.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "all");
        assert_eq!(listing(dir.path()), vec!["long.h5"]);
    }

    #[test]
    fn temporary_names_fit_in_255_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let name = format!("{}.csv", "n".repeat(251));
        assert_eq!(name.len(), 255);
        write_text(&dir.path().join(&name), "x").unwrap();
        assert_eq!(listing(dir.path()), vec![name]);
    }
}
