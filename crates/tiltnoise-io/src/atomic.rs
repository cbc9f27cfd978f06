//! Atomic outputs: every file is written inside a private staging directory next to its
//! target and renamed onto it only when the whole run has succeeded, so that a failed or
//! interrupted run never leaves a partial file, nor a temporary one.
//!
//! * [`Staging`]: the outputs of one run, written all or none. The caller makes one, passes it
//!   to every writer, and commits it at the end; dropped without a commit, it removes them all.
//!   [`Staging::write`] writes one file.
//! * [`AtomicFile`]: one file written over time (a long record, chunk by chunk), handed to the
//!   run's [`Staging`] when finished, removed if dropped before.
//! * [`remove_staging_for_exit`](crate::remove_staging_for_exit): removes every staging
//!   directory, for an interrupt handler that then ends the process (signals are the command
//!   line's); `staging_dir.rs` says why nothing can be left.

use crate::staging_dir::StagingDir;
use std::collections::VecDeque;
use std::fs::OpenOptions;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};
use tiltnoise_core::error::OutputError;

/// An output being written: its own staging directory `.<name>.XXXXXX.tmp` beside the target
/// (the name shortened so that it fits in 255 bytes), registered for the interrupt handler
/// from the moment it exists, and the path of the file to write inside it, which has the
/// target's own name (for libraries that look at the extension). Finished, it goes to the
/// run's [`Staging`] ([`AtomicFile::finish`]); dropped before (the run failed), the directory
/// is removed with what it holds, and the target is left as it was.
#[must_use = "an AtomicFile that is not finished removes its output"]
pub struct AtomicFile {
    dir: StagingDir,
    file: PathBuf,
    target: PathBuf,
}

impl AtomicFile {
    /// Creates and registers the staging directory of `path`. The file itself is not created:
    /// the writer creates it at [`AtomicFile::temp_path`].
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming `path`, with the operating system's message (for example
    /// `No such file or directory (os error 2)` when the directory does not exist).
    pub fn create(path: &Path) -> Result<AtomicFile, OutputError> {
        let fail = |message: String| OutputError::Write {
            path: path.to_path_buf(),
            message: message.into(),
        };
        let file_name = path
            .file_name()
            .ok_or_else(|| fail("the path does not name a file".to_string()))?;
        let parent = path.parent().unwrap_or(Path::new(""));
        let dir = StagingDir::create(parent, file_name).map_err(|e| fail(e.to_string()))?;
        let file = dir.path().join(file_name);
        Ok(AtomicFile {
            dir,
            file,
            target: path.to_path_buf(),
        })
    }

    /// The file to write, inside the staging directory. The writer creates it (the usual
    /// permissions, `0o666` minus the umask, are those the target gets) and must have closed it
    /// before [`AtomicFile::finish`]; it may replace it (HDF5's `File::create` truncates).
    pub fn temp_path(&self) -> &Path {
        &self.file
    }

    /// The path the output is renamed to.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// [`OutputError::Write`] naming the target with `message`.
    pub fn fail(&self, message: String) -> OutputError {
        OutputError::Write {
            path: self.target.clone(),
            message: message.into(),
        }
    }

    /// Flushes the file to disk and hands it to `stage`, which renames it onto the target when
    /// it commits.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the target (also when the writer created no file); the
    /// staging directory is then removed.
    pub fn finish(self, stage: &Staging) -> Result<(), OutputError> {
        OpenOptions::new()
            .write(true)
            .open(&self.file)
            .and_then(|f| f.sync_all())
            .map_err(|e| self.fail(format!("cannot flush temporary file: {e}")))?;
        stage
            .finished
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(self);
        Ok(())
    }
}

/// The outputs of one run, written all or none. Every writer takes the run's `Staging` and
/// leaves its finished file in its staging directory; [`Staging::commit`] renames them all
/// onto their targets. Dropping a `Staging` that was not committed (the run failed) removes
/// every staging directory it holds, so no output of a failed run appears.
///
/// Used from several threads at once if need be (`&Staging` is all a writer needs).
#[must_use = "a Staging that is not committed removes its outputs"]
#[derive(Default)]
pub struct Staging {
    finished: Mutex<Vec<AtomicFile>>,
}

impl std::fmt::Debug for Staging {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let finished = self.finished.lock().unwrap_or_else(PoisonError::into_inner);
        f.debug_struct("Staging")
            .field(
                "targets",
                &finished.iter().map(|a| &a.target).collect::<Vec<_>>(),
            )
            .finish()
    }
}

impl Staging {
    /// A run with no output yet.
    pub fn new() -> Staging {
        Staging::default()
    }

    /// Runs `write` with a `Staging` of its own and commits it when `write` succeeds: for a
    /// front end that saves one result at a time (Python's `save` methods). On an error
    /// nothing `write` wrote appears.
    ///
    /// # Errors
    ///
    /// The error of `write`, or of [`Staging::commit`].
    pub fn committed<T, E: From<OutputError>>(
        write: impl FnOnce(&Staging) -> Result<T, E>,
    ) -> Result<T, E> {
        let stage = Staging::new();
        let value = write(&stage)?;
        stage.commit()?;
        Ok(value)
    }

    /// Writes `path` as one of the run's outputs: `write` receives the path of the file to
    /// create inside a fresh staging directory beside `path` (so the final rename never
    /// crosses a file system) and fills it; the file is then flushed to disk and kept until
    /// [`Staging::commit`].
    ///
    /// On any error the staging directory is removed and `path` is left as it was: absent if
    /// it did not exist, untouched if it did. A new file gets the usual permissions (`0o666`
    /// minus the umask); a replaced file's permissions are not carried over.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming `path`, with the operating system's message (for example
    /// `No such file or directory (os error 2)` when the directory does not exist) or the
    /// message returned by `write`.
    pub fn write(
        &self,
        path: &Path,
        write: impl FnOnce(&Path) -> Result<(), String>,
    ) -> Result<(), OutputError> {
        let file = AtomicFile::create(path)?;
        write(file.temp_path()).map_err(|message| file.fail(message))?;
        file.finish(self)
    }

    /// Renames every finished output onto its target, in the order they were finished, and
    /// removes their staging directories. Returns the targets.
    ///
    /// The renames are done under the lock of the interrupt handler's registry: an interrupt
    /// finds either every output still staged (and removes them all) or every output in place.
    ///
    /// # Errors
    ///
    /// [`OutputError::Write`] naming the first target that cannot be renamed; the outputs not
    /// yet renamed are removed. (Renames within a directory that took the staging directory
    /// do not fail in practice; the outputs renamed before stay.)
    pub fn commit(self) -> Result<Vec<PathBuf>, OutputError> {
        let mut pending: VecDeque<AtomicFile> = self
            .finished
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner)
            .into();
        let mut done = Vec::with_capacity(pending.len());
        let mut registry = crate::staging_dir::registry();
        while let Some(output) = pending.pop_front() {
            if let Err(e) = std::fs::rename(&output.file, &output.target) {
                // Released before the rest is dropped: dropping removes and unregisters.
                drop(registry);
                return Err(output.fail(e.to_string()));
            }
            let AtomicFile { dir, target, .. } = output;
            dir.close_committed(&mut registry);
            done.push(target);
        }
        Ok(done)
    }
}

/// Creates and removes a staging directory in `dir`: whether the run can create its outputs
/// there.
pub(crate) fn probe_directory(dir: &Path) -> std::io::Result<()> {
    drop(StagingDir::create(
        dir,
        std::ffi::OsStr::new("tiltnoise-probe"),
    )?);
    Ok(())
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

    fn write_text(stage: &Staging, path: &Path, text: &str) -> Result<(), OutputError> {
        stage.write(path, |t| std::fs::write(t, text).map_err(|e| e.to_string()))
    }

    #[test]
    fn a_failed_run_leaves_none_of_its_outputs() {
        let dir = tempfile::tempdir().unwrap();
        {
            let stage = Staging::new();
            write_text(&stage, &dir.path().join("a.csv"), "a").unwrap();
            // Staged, not renamed: only the staging directory exists.
            let names = listing(dir.path());
            assert_eq!(names.len(), 1);
            assert!(names[0].starts_with(".a.csv.") && names[0].ends_with(".tmp"));
            assert!(!dir.path().join("a.csv").exists());
            let err = stage.write(&dir.path().join("b.csv"), |_| Err("drawing failed".into()));
            assert!(err.is_err());
        } // dropped without commit
        assert!(listing(dir.path()).is_empty(), "{:?}", listing(dir.path()));
    }

    #[test]
    fn a_committed_run_has_every_output_and_no_temporary_file() {
        let dir = tempfile::tempdir().unwrap();
        let stage = Staging::new();
        write_text(&stage, &dir.path().join("a.csv"), "a").unwrap();
        write_text(&stage, &dir.path().join("b.csv"), "b").unwrap();
        let done = stage.commit().unwrap();
        assert_eq!(
            done,
            vec![dir.path().join("a.csv"), dir.path().join("b.csv")]
        );
        assert_eq!(listing(dir.path()), vec!["a.csv", "b.csv"]);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("b.csv")).unwrap(),
            "b"
        );
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
        let stage = Staging::new();
        let file = AtomicFile::create(&target).unwrap();
        assert_eq!(file.temp_path().file_name(), target.file_name());
        std::fs::write(file.temp_path(), "all").unwrap();
        file.finish(&stage).unwrap();
        assert!(!target.exists(), "staged until the commit");
        stage.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "all");
        assert_eq!(listing(dir.path()), vec!["long.h5"]);
    }

    #[test]
    fn a_writer_that_creates_no_file_fails() {
        let dir = tempfile::tempdir().unwrap();
        let stage = Staging::new();
        let err = stage
            .write(&dir.path().join("none.csv"), |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("none.csv") && err.contains("cannot flush"),
            "{err}"
        );
        assert!(listing(dir.path()).is_empty());
        assert_eq!(stage.commit().unwrap(), Vec::<PathBuf>::new());
    }

    #[test]
    fn an_existing_target_is_replaced_only_by_the_commit() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("old.csv");
        std::fs::write(&target, "old").unwrap();
        let stage = Staging::new();
        write_text(&stage, &target, "new").unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        drop(stage);
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old");
        assert_eq!(listing(dir.path()), vec!["old.csv"]);
        let stage = Staging::new();
        write_text(&stage, &target, "new").unwrap();
        stage.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
        assert_eq!(listing(dir.path()), vec!["old.csv"]);
    }

    #[test]
    fn temporary_names_fit_in_255_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let name = format!("{}.csv", "n".repeat(251));
        assert_eq!(name.len(), 255);
        let stage = Staging::new();
        write_text(&stage, &dir.path().join(&name), "x").unwrap();
        stage.commit().unwrap();
        assert_eq!(listing(dir.path()), vec![name]);
    }

    #[test]
    fn the_file_to_write_is_inside_a_staging_directory_beside_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let file = AtomicFile::create(&dir.path().join("x.h5")).unwrap();
        assert!(file.temp_path().is_absolute());
        assert_eq!(
            file.temp_path().parent().unwrap().parent(),
            Some(dir.path())
        );
    }
}
