//! `scripts/build/cmake`, the cmake the bundled HDF5 build runs: which cmake and generator it
//! picks, and the one line it prints when the machine lacks what it needs. Stand-ins for cmake,
//! make and ninja on a `PATH` that holds nothing else but the few tools the script uses.

use crate::common::repo;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A `PATH` of its own: the script's tools, and the stand-ins a test adds.
struct Machine {
    dir: tempfile::TempDir,
}

impl Machine {
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("bin")).unwrap();
        std::fs::create_dir(dir.path().join("cache")).unwrap();
        let m = Machine { dir };
        for tool in ["sed", "head", "dirname"] {
            let real = ["/usr/bin", "/bin"]
                .iter()
                .map(|d| Path::new(d).join(tool))
                .find(|p| p.exists())
                .unwrap_or_else(|| panic!("{tool} on this machine"));
            std::os::unix::fs::symlink(real, m.bin().join(tool)).unwrap();
        }
        m
    }

    fn bin(&self) -> PathBuf {
        self.dir.path().join("bin")
    }

    /// A stand-in `name` that prints `version` for `--version` and its arguments otherwise.
    fn tool(&self, name: &str, version: &str) {
        let path = self.bin().join(name);
        std::fs::write(
            &path,
            format!(
                "#!/bin/sh\nif [ \"$1\" = --version ]; then echo '{version}'; exit 0; fi\n\
                 echo \"{name} ran: $*\"\n"
            ),
        )
        .unwrap();
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }

    /// Runs the script with `args`: exit code, standard output, standard error.
    fn run(&self, args: &[&str]) -> (Option<i32>, String, String) {
        let out = Command::new("/bin/sh")
            .arg(repo("scripts/build/cmake"))
            .args(args)
            .env_clear()
            .env("PATH", self.bin())
            .env("HOME", self.dir.path())
            .env("TILTNOISE_CMAKE_CACHE", self.dir.path().join("cache"))
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }
}

#[test]
fn a_new_enough_cmake_on_path_runs_with_make_as_is_and_without_make_with_ninja() {
    let m = Machine::new();
    m.tool("cmake", "cmake version 3.31.6");
    m.tool("make", "GNU Make 4.3");
    let (code, out, err) = m.run(&["src", "-DX=1"]);
    assert_eq!(
        (code, out.trim(), err.as_str()),
        (Some(0), "cmake ran: src -DX=1", "")
    );

    std::fs::remove_file(m.bin().join("make")).unwrap();
    m.tool("ninja", "1.11.1");
    let (code, out, _) = m.run(&["src", "-DX=1"]);
    let ninja = m.bin().join("ninja");
    assert_eq!(
        (code, out.trim()),
        (
            Some(0),
            format!(
                "cmake ran: -G Ninja -DCMAKE_MAKE_PROGRAM={} src -DX=1",
                ninja.display()
            )
            .as_str()
        )
    );
    // Building, and a generator the caller named, are left as they are.
    let (_, out, _) = m.run(&["--build", "dir"]);
    assert_eq!(out.trim(), "cmake ran: --build dir");
    let (_, out, _) = m.run(&["src", "-GUnix Makefiles"]);
    assert_eq!(out.trim(), "cmake ran: src -GUnix Makefiles");
}

#[test]
fn without_what_it_needs_it_says_in_one_line_what_is_missing_and_how_to_install_it() {
    // Debian 12's cmake is too old for HDF5 2.x, and there is no python3 to fetch a newer one.
    let m = Machine::new();
    m.tool("cmake", "cmake version 3.25.1");
    m.tool("make", "GNU Make 4.3");
    let (code, out, err) = m.run(&["src"]);
    assert_eq!((code, out.as_str()), (Some(2), ""), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for part in [
        "3.25.1",
        "older than the 3.26",
        "python3 with pip",
        "apt-get install python3-pip",
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }

    // A new enough cmake, no make, no ninja, no python3.
    let m = Machine::new();
    m.tool("cmake", "cmake version 4.0.2");
    let (code, out, err) = m.run(&["src"]);
    assert_eq!((code, out.as_str()), (Some(2), ""), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    for part in [
        "no make and no ninja on PATH",
        "apt-get install make",
        "python3-pip",
    ] {
        assert!(err.contains(part), "{part:?} not in {err}");
    }

    // A python3 without pip is no better than none.
    m.tool("python3", "Python 3.11.2");
    let pipless = m.bin().join("python3");
    std::fs::write(
        &pipless,
        "#!/bin/sh\necho 'No module named pip' >&2\nexit 1\n",
    )
    .unwrap();
    let (code, _, err) = m.run(&["src"]);
    assert_eq!(code, Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("no python3 with pip"), "{err}");
}
