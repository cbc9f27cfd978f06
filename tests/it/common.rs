//! Helpers of the command-line, file and figure tests: running the `tiltnoise` binary, directory
//! listings, HDF5 string attributes and the reference data kept beside the repository; the
//! helpers every crate's tests share come from `crates/tiltnoise-core/tests/it/common.rs`.

#[path = "../../crates/tiltnoise-core/tests/it/common.rs"]
mod shared;
pub use shared::*;

use hdf5::types::VarLenUnicode;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `../shared/tilt_data/<rel>` beside the repository, or `None` when it is absent. That data is
/// GPL/LGPL and kept out of this repository (CI clones shared/ beside it), so a plain clone
/// skips the tests that read it: `test` is the test's name, and the one line saying it was
/// skipped and why goes straight to standard error, past the test harness's output capture.
pub fn shared_tilt_data(test: &str, rel: &str) -> Option<PathBuf> {
    let p = repo("../shared/tilt_data").join(rel);
    if p.exists() {
        return Some(p);
    }
    let line = format!(
        "skipped {test}: ../shared/tilt_data/{rel} not found (GPL/LGPL data kept out of this \
         repository; CI has it)\n"
    );
    std::io::stderr()
        .write_all(line.as_bytes())
        .expect("standard error is writable");
    None
}

/// The numbers of a CSV that `tiltnoise tf` writes: the header, the frequencies, and per
/// frequency the complex entries `(re, im)` in header order.
pub fn parse_tf_csv(text: &str) -> (Vec<String>, Vec<f64>, Vec<Vec<num_complex::Complex64>>) {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let (mut freqs, mut rows) = (Vec::new(), Vec::new());
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|s| s.parse().unwrap()).collect();
        freqs.push(v[0]);
        rows.push(
            v[1..]
                .chunks_exact(2)
                .map(|c| num_complex::Complex64::new(c[0], c[1]))
                .collect(),
        );
    }
    (header, freqs, rows)
}

/// Runs the `tiltnoise` binary with `args`.
///
/// Tests run in parallel threads of one process: a child spawned while another thread holds an
/// HDF5 file open inherits that descriptor and its lock, and a later open of the same file fails
/// with "unable to lock file, errno = 11". HDF5's advisory locking protects nothing here (every
/// file belongs to one test), so it is switched off for the children and for this process.
pub fn tiltnoise(args: &[&str]) -> Output {
    disable_hdf5_file_locking();
    Command::new(env!("CARGO_BIN_EXE_tiltnoise"))
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .args(args)
        .output()
        .expect("the binary runs")
}

/// The standard error of a run, as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Runs a failing command: exit code 2, a single error line that contains every `needle`.
pub fn assert_fails(args: &[&str], needles: &[&str]) {
    let out = tiltnoise(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: not one line: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` missing from: {err}");
    }
}

/// [`assert_fails`], and the command leaves `out_dir` as it was.
pub fn assert_fails_without_output(args: &[&str], out_dir: &Path, needles: &[&str]) {
    let before = listing(out_dir);
    assert_fails(args, needles);
    assert_eq!(before, listing(out_dir), "{args:?} left files behind");
}

/// Every entry of the directory, sorted.
pub fn listing(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

/// A scalar string attribute.
pub fn str_attr(loc: &hdf5::Location, name: &str) -> String {
    loc.attr(name)
        .unwrap_or_else(|e| panic!("attribute {name}: {e}"))
        .read_scalar::<VarLenUnicode>()
        .unwrap()
        .as_str()
        .to_string()
}

/// A 1-D string attribute.
pub fn strs_attr(loc: &hdf5::Location, name: &str) -> Vec<String> {
    strings(
        &loc.attr(name)
            .unwrap_or_else(|e| panic!("attribute {name}: {e}")),
    )
}

/// A 1-D string dataset.
pub fn strs_dataset(group: &hdf5::Group, name: &str) -> Vec<String> {
    strings(
        &group
            .dataset(name)
            .unwrap_or_else(|e| panic!("dataset {name}: {e}")),
    )
}

/// The strings of a 1-D string dataset or attribute.
pub fn strings(c: &hdf5::Container) -> Vec<String> {
    c.read_1d::<VarLenUnicode>()
        .unwrap()
        .iter()
        .map(|s| s.as_str().to_string())
        .collect()
}

/// Sets `HDF5_USE_FILE_LOCKING=FALSE` for this test process (read by HDF5 at every file open).
pub fn disable_hdf5_file_locking() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| std::env::set_var("HDF5_USE_FILE_LOCKING", "FALSE"));
}
