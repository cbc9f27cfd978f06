//! The output paths of a run, checked before anything is computed, so that a run that could
//! not write its results fails in a moment instead of after the computation, and never
//! replaces one of its own inputs.

use crate::atomic::probe_directory;
use crate::input::split_hdf5_address;
use crate::staging_dir::NAME_MAX;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::OutputError;

/// Checks every output path of a run against the rules below and against the files the run
/// reads (`inputs`: the option that names each, such as `--tilt`, and its path); the
/// extension, which depends on the command, is the caller's to check.
///
/// * The path names a file of at most 255 bytes (which most file systems accept, so that the
///   final rename cannot fail on it) and is not an existing directory.
/// * Its directory exists, is a directory, and the run can stage its outputs there (a staging
///   directory is created there and removed at once).
/// * No two outputs are the same file, and no output is an input of the run. Files are
///   compared by identity: device and inode for files that exist (following symbolic links),
///   else the canonical directory and the file name, so `./out.h5` and `out.h5`, a symbolic
///   link and its target, or two hard links, are the same file. An input given as an HDF5
///   address (`tilt.h5:/group/dataset`, [`split_hdf5_address`]) is the file it addresses.
///
/// # Errors
///
/// [`OutputError::Refused`] naming the first path that breaks a rule, and the rule.
pub fn check_outputs(outputs: &[&Path], inputs: &[(&str, &Path)]) -> Result<(), OutputError> {
    let refuse = |path: &Path, rule: String| OutputError::Refused {
        path: path.to_path_buf(),
        rule,
    };
    let inputs: Vec<(&str, &Path, Identity)> = inputs
        .iter()
        .map(|&(option, path)| (option, path, Identity::of(&split_hdf5_address(path).0)))
        .collect();
    let mut checked: Vec<(&Path, Identity)> = Vec::with_capacity(outputs.len());
    let mut probed: Vec<PathBuf> = Vec::new();
    for &path in outputs {
        let Some(name) = path.file_name() else {
            return Err(refuse(path, "the path does not name a file".to_string()));
        };
        if name.len() > NAME_MAX {
            return Err(refuse(
                path,
                format!(
                    "the file name is {} bytes long; at most {NAME_MAX} are allowed",
                    name.len()
                ),
            ));
        }
        if path.is_dir() {
            return Err(refuse(
                path,
                "it is a directory; give the path of a file".to_string(),
            ));
        }
        let dir = directory_of(path);
        match std::fs::metadata(&dir) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => {
                return Err(refuse(
                    path,
                    format!("{} is not a directory", dir.display()),
                ))
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(refuse(
                    path,
                    format!("the directory {} does not exist", dir.display()),
                ))
            }
            Err(e) => {
                return Err(refuse(
                    path,
                    format!("the directory {} cannot be used: {e}", dir.display()),
                ))
            }
        }
        let canonical_dir = std::fs::canonicalize(&dir).unwrap_or_else(|_| dir.clone());
        if !probed.contains(&canonical_dir) {
            probe_directory(&dir).map_err(|e| {
                refuse(
                    path,
                    format!("the directory {} is not writable: {e}", dir.display()),
                )
            })?;
            probed.push(canonical_dir);
        }
        let identity = Identity::of(path);
        if let Some((other, _)) = checked.iter().find(|(_, id)| id.same_file(&identity)) {
            let rule = match *other == path {
                true => "it is given twice; every output must be a different file".to_string(),
                false => format!(
                    "it is the same file as the output {}; every output must be a different \
                     file",
                    other.display()
                ),
            };
            return Err(refuse(path, rule));
        }
        if let Some((option, input, _)) = inputs.iter().find(|(_, _, id)| id.same_file(&identity)) {
            return Err(refuse(
                path,
                format!(
                    "it is the file {option} {} reads; an output must not replace an input of \
                     the run",
                    input.display()
                ),
            ));
        }
        checked.push((path, identity));
    }
    Ok(())
}

/// The directory a file is created in: the parent, `.` for a bare file name.
fn directory_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// What makes two paths the same file.
struct Identity {
    /// Device and inode of the file the path leads to, when it exists.
    inode: Option<(u64, u64)>,
    /// The canonical directory joined with the file name, when the directory exists.
    path: Option<PathBuf>,
}

impl Identity {
    fn of(path: &Path) -> Identity {
        #[cfg(unix)]
        let inode = {
            use std::os::unix::fs::MetadataExt;
            std::fs::metadata(path).ok().map(|m| (m.dev(), m.ino()))
        };
        #[cfg(not(unix))]
        let inode = None;
        let path = path.file_name().and_then(|name| {
            std::fs::canonicalize(directory_of(path))
                .ok()
                .map(|d| d.join(name))
        });
        Identity { inode, path }
    }

    fn same_file(&self, other: &Identity) -> bool {
        (self.inode.is_some() && self.inode == other.inode)
            || (self.path.is_some() && self.path == other.path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refusal(outputs: &[&Path], inputs: &[(&str, &Path)]) -> String {
        check_outputs(outputs, inputs).unwrap_err().to_string()
    }

    #[test]
    fn every_rule_names_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let (a, b) = (d.join("a.h5"), d.join("b.svg"));
        assert!(check_outputs(&[&a, &b], &[]).is_ok());
        // The probe leaves nothing behind.
        assert_eq!(std::fs::read_dir(d).unwrap().count(), 0);

        let missing = d.join("nodir/b.svg");
        let e = refusal(&[&a, &missing], &[]);
        assert!(
            e.contains("nodir/b.svg") && e.contains("does not exist"),
            "{e}"
        );
        std::fs::write(d.join("file"), "x").unwrap();
        let e = refusal(&[&d.join("file/c.h5")], &[]);
        assert!(e.contains("is not a directory"), "{e}");
        let e = refusal(&[d], &[]);
        assert!(e.contains("it is a directory"), "{e}");
        let e = refusal(&[Path::new("..")], &[]);
        assert!(e.contains("does not name a file"), "{e}");
        let e = refusal(&[&d.join(format!("{}.h5", "n".repeat(253)))], &[]);
        assert!(e.contains("256 bytes long; at most 255"), "{e}");

        let e = refusal(&[&a, &b, &a], &[]);
        assert!(e.contains("given twice"), "{e}");
        std::fs::create_dir(d.join("sub")).unwrap();
        let roundabout = d.join("sub/../a.h5");
        let e = refusal(&[&a, &roundabout], &[]);
        assert!(e.contains("same file as the output"), "{e}");
    }

    #[test]
    fn an_output_must_not_be_an_input() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let input = d.join("tilt.h5");
        std::fs::write(&input, "x").unwrap();
        let e = refusal(&[&input], &[("tilt", &input)]);
        assert!(e.contains("tilt") && e.contains("replace an input"), "{e}");
        #[cfg(unix)]
        {
            let link = d.join("link.h5");
            std::os::unix::fs::symlink(&input, &link).unwrap();
            let e = refusal(&[&link], &[("tilt", &input)]);
            assert!(e.contains("link.h5") && e.contains("tilt"), "{e}");
        }
        let other = d.join("other.h5");
        assert!(check_outputs(&[&other], &[("tilt", &input)]).is_ok());
    }

    #[test]
    fn an_hdf5_address_is_the_file_it_addresses() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let file = d.join("gw.h5");
        std::fs::write(&file, "x").unwrap();
        let address = d.join("gw.h5:/tilt/theta");
        let e = refusal(&[&file], &[("tilt", &address)]);
        assert!(e.contains("tilt") && e.contains("replace an input"), "{e}");
        let roundabout = d.join("sub/../gw.h5");
        std::fs::create_dir(d.join("sub")).unwrap();
        assert!(check_outputs(&[&roundabout], &[("tilt", &address)]).is_err());
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(&file, d.join("link.h5")).unwrap();
            let through_link = d.join("link.h5:/theta");
            assert!(check_outputs(&[&file], &[("tilt", &through_link)]).is_err());
            std::fs::hard_link(&file, d.join("hard.h5")).unwrap();
            assert!(check_outputs(&[&d.join("hard.h5")], &[("tilt", &address)]).is_err());
        }
        let other = d.join("other.h5");
        assert!(check_outputs(&[&other], &[("tilt", &address)]).is_ok());
    }
}
