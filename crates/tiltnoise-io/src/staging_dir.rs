//! Staging directories: every output is written inside a private directory of its own,
//! `.<name>.XXXXXX.tmp` beside its target (so that the final rename stays on one file
//! system), and every such directory that exists is registered here, for an interrupt handler
//! that removes them all.
//!
//! Nothing can be left behind, by construction:
//!
//! * a directory is created and registered in one step, under the registry's lock;
//! * it leaves the registry only once it is gone (removed, or emptied by the commit's rename
//!   and removed, under the same lock);
//! * the file of an output is created inside its directory, never anywhere else;
//! * [`remove_staging_for_exit`] takes the lock, removes every registered directory with what
//!   it holds (again while a file being created in it at that moment makes it non-empty) and
//!   keeps the lock until the process ends.
//!
//! So once the handler has run no staging directory exists and none can be created (a writer
//! that asks waits for the end of the process), and a writer that creates its file afterwards,
//! however long it stalled, gets `ENOENT`.

use std::collections::hash_map::RandomState;
use std::ffi::{OsStr, OsString};
use std::hash::{BuildHasher, Hasher};
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// The longest file name most file systems accept (bytes).
pub(crate) const NAME_MAX: usize = 255;

/// Random characters in a staging directory's name.
const RANDOM_LEN: usize = 6;

/// The end of a staging directory's name.
const SUFFIX: &str = ".tmp";

/// Names tried before giving up when every one is taken.
const NAME_ATTEMPTS: usize = 1 << 10;

/// Removals of a directory tried while files keep appearing in it (each attempt empties it;
/// a writer creates a file or two, so the second attempt finds it empty in practice).
const REMOVE_ATTEMPTS: usize = 1 << 10;

/// The staging directories that exist now, and how many outputs were committed (renamed onto
/// their targets) by this process.
pub(crate) struct Registry {
    dirs: Vec<PathBuf>,
    committed: usize,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    dirs: Vec::new(),
    committed: 0,
});

/// The registry, locked. A panic while it was held cannot leave it inconsistent (every change
/// is one push or one removal), so a poisoned lock is taken as it is.
pub(crate) fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Registry {
    fn forget(&mut self, dir: &Path) {
        if let Some(i) = self.dirs.iter().position(|d| d == dir) {
            self.dirs.swap_remove(i);
        }
    }
}

/// A staging directory, registered for as long as it exists; removed with what it holds when
/// dropped.
pub(crate) struct StagingDir {
    /// Absolute, so that a change of the working directory does not lose it.
    path: Option<PathBuf>,
}

impl StagingDir {
    /// Creates the directory `.<name>.XXXXXX.tmp` (mode 0o700) in `parent` and registers it,
    /// both under the registry's lock: there is no moment when it exists unregistered. `name`
    /// is shortened so that the whole name fits in [`NAME_MAX`] bytes.
    ///
    /// # Errors
    ///
    /// The operating system's error, unchanged (the parent is missing or not writable, ...).
    pub(crate) fn create(parent: &Path, name: &OsStr) -> io::Result<StagingDir> {
        let parent = match parent.as_os_str().is_empty() {
            true => Path::new("."),
            false => parent,
        };
        let parent = std::path::absolute(parent)?;
        let room = NAME_MAX.saturating_sub(2 + RANDOM_LEN + SUFFIX.len());
        let mut prefix = OsString::from(".");
        prefix.push(shortened(name, room));
        prefix.push(".");
        let random = RandomState::new();
        let mut registry = registry();
        for attempt in 0..NAME_ATTEMPTS {
            let mut dir_name = prefix.clone();
            dir_name.push(random_chars(&random, attempt));
            dir_name.push(SUFFIX);
            let path = parent.join(dir_name);
            match create_private_dir(&path) {
                Ok(()) => {
                    registry.dirs.push(path.clone());
                    return Ok(StagingDir { path: Some(path) });
                }
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
        Err(io::Error::new(
            io::ErrorKind::AlreadyExists,
            format!(
                "{NAME_ATTEMPTS} names of staging directories tried in {}, all taken",
                parent.display()
            ),
        ))
    }

    /// The directory.
    pub(crate) fn path(&self) -> &Path {
        self.path.as_deref().expect("present until removed")
    }

    /// For the commit, which holds the registry's lock (`registry`) and has renamed the
    /// directory's output onto its target: removes the directory, counts the output as
    /// committed, and unregisters the directory once it is gone.
    pub(crate) fn close_committed(mut self, registry: &mut Registry) {
        let path = self.path.take().expect("present until removed");
        registry.committed += 1;
        if remove_until_gone(&path).is_ok() {
            registry.forget(&path);
        }
    }
}

impl Drop for StagingDir {
    fn drop(&mut self) {
        if let Some(path) = self.path.take() {
            // Removed first, unregistered after: a directory that exists is always registered.
            // (Removed without the lock: an interrupt handled meanwhile removes it too.)
            if remove_until_gone(&path).is_ok() {
                registry().forget(&path);
            }
        }
    }
}

/// Removes `dir` and everything in it, again as long as files created meanwhile keep it from
/// being removed. `Ok` when it is gone (also when it was gone before).
fn remove_until_gone(dir: &Path) -> io::Result<()> {
    let mut last = None;
    for _ in 0..REMOVE_ATTEMPTS {
        match std::fs::remove_dir_all(dir) {
            Ok(()) => return Ok(()),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
            Err(e) => last = Some(e),
        }
        std::thread::yield_now();
    }
    Err(last.expect("at least one attempt"))
}

/// What [`remove_staging_for_exit`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExitCleanup {
    /// Staging directories removed (one per output being written or written and not yet
    /// committed).
    pub removed: usize,
    /// Staging directories that could not be removed, with the reason.
    pub left: Vec<(PathBuf, String)>,
    /// Outputs this process had already committed (renamed onto their targets) before.
    pub committed: usize,
}

/// Removes every staging directory that exists, with what it holds, for a process about to end
/// at once (the command line's interrupt handler; signals are the front end's). The registry
/// stays locked afterwards, so that no staging directory can appear any more: a writer that
/// asks for one waits for the process to end, and a writer that creates a file in a directory
/// removed here gets `ENOENT`. Safe to call from any thread; a commit in progress (a few
/// renames) is waited for, so the outputs of a run appear all or none.
pub fn remove_staging_for_exit() -> ExitCleanup {
    let registry = registry();
    let mut cleanup = ExitCleanup {
        removed: 0,
        left: Vec::new(),
        committed: registry.committed,
    };
    for dir in &registry.dirs {
        match remove_until_gone(dir) {
            Ok(()) => cleanup.removed += 1,
            Err(e) => cleanup.left.push((dir.clone(), e.to_string())),
        }
    }
    // Never released: the process ends holding it.
    std::mem::forget(registry);
    cleanup
}

/// Creates `path` as a directory only its owner may enter (the output inside it gets the
/// usual permissions when it is created).
fn create_private_dir(path: &Path) -> io::Result<()> {
    let mut builder = std::fs::DirBuilder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::DirBuilderExt;
        builder.mode(0o700);
    }
    builder.create(path)
}

/// [`RANDOM_LEN`] letters and digits, different for each `attempt`.
fn random_chars(random: &RandomState, attempt: usize) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    let mut hasher = random.build_hasher();
    hasher.write_usize(attempt);
    hasher.write_u32(std::process::id());
    let mut bits = hasher.finish();
    (0..RANDOM_LEN)
        .map(|_| {
            let c = ALPHABET[(bits % ALPHABET.len() as u64) as usize];
            bits /= ALPHABET.len() as u64;
            char::from(c)
        })
        .collect()
}

/// At most `max` bytes of `name`, cut at a character boundary when the name is UTF-8.
pub(crate) fn shortened(name: &OsStr, max: usize) -> OsString {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn registered(dir: &Path) -> bool {
        registry().dirs.iter().any(|d| d == dir)
    }

    #[test]
    fn a_staging_directory_is_registered_exactly_while_it_exists() {
        let parent = tempfile::tempdir().unwrap();
        let staging = StagingDir::create(parent.path(), OsStr::new("a.h5")).unwrap();
        let path = staging.path().to_path_buf();
        assert!(path.is_dir() && registered(&path));
        let name = path.file_name().unwrap().to_str().unwrap();
        assert!(
            name.starts_with(".a.h5.") && name.ends_with(".tmp") && name.len() == 16,
            "{name}"
        );
        std::fs::write(path.join("a.h5"), "part").unwrap();
        drop(staging);
        assert!(!path.exists() && !registered(&path));
        assert_eq!(std::fs::read_dir(parent.path()).unwrap().count(), 0);
    }

    #[test]
    fn a_file_created_after_its_directory_was_removed_fails_and_leaves_nothing() {
        // What the interrupt handler does to a writer stalled between creating its directory
        // and creating its file.
        let parent = tempfile::tempdir().unwrap();
        let staging = StagingDir::create(parent.path(), OsStr::new("late.csv")).unwrap();
        let dir = staging.path().to_path_buf();
        remove_until_gone(&dir).unwrap();
        let err = std::fs::write(dir.join("late.csv"), "late").unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::NotFound);
        assert_eq!(std::fs::read_dir(parent.path()).unwrap().count(), 0);
        drop(staging);
        assert!(!registered(&dir));
    }

    #[test]
    fn a_directory_is_removed_while_files_keep_appearing_in_it() {
        let parent = tempfile::tempdir().unwrap();
        let staging = StagingDir::create(parent.path(), OsStr::new("busy.h5")).unwrap();
        let dir = staging.path().to_path_buf();
        let writer = {
            let dir = dir.clone();
            std::thread::spawn(move || {
                // Files until the directory is gone (the first failure is ENOENT), a few
                // microseconds apart, so that files appear during a removal's pass. Back to
                // back, on two free cores, the writer can refill the directory as fast as a
                // pass empties it and the removal never ends; a real writer creates one file
                // in its staging directory, so that is no case for the handler.
                let mut i = 0u64;
                loop {
                    match std::fs::write(dir.join(format!("f{i}")), "x") {
                        Ok(()) => i += 1,
                        Err(e) => return (i, e.kind()),
                    }
                    std::thread::sleep(std::time::Duration::from_micros(20));
                }
            })
        };
        // Let it create some.
        while std::fs::read_dir(&dir).map(|d| d.count()).unwrap_or(0) < 10 {
            std::thread::yield_now();
        }
        remove_until_gone(&dir).unwrap();
        let (created, kind) = writer.join().unwrap();
        assert!(created >= 10);
        assert_eq!(kind, io::ErrorKind::NotFound);
        assert_eq!(std::fs::read_dir(parent.path()).unwrap().count(), 0);
    }

    #[test]
    fn long_names_are_shortened_to_fit() {
        let parent = tempfile::tempdir().unwrap();
        let name = format!("{}.csv", "é".repeat(130));
        let staging = StagingDir::create(parent.path(), OsStr::new(&name)).unwrap();
        let dir_name = staging.path().file_name().unwrap().to_str().unwrap();
        assert!(dir_name.len() <= NAME_MAX, "{}", dir_name.len());
        assert!(dir_name.ends_with(".tmp"));
    }
}
