//! Helpers shared by integration tests: paths to reference data and a named-tolerance comparison.
#![allow(dead_code)]

use std::path::PathBuf;

/// `../shared/tilt_data/<rel>` beside the repository (CI clones with shared/ beside it).
pub fn shared_tilt_data(rel: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/tilt_data")
        .join(rel);
    assert!(
        p.exists(),
        "reference data {} not found: the tests expect ../shared/ beside the repository",
        p.display()
    );
    p
}

/// A path inside the repository.
pub fn repo(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// Reads a JSON fixture.
pub fn json(rel: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(repo(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    serde_json::from_str(&text).unwrap()
}

/// A JSON array of numbers.
pub fn floats(v: &serde_json::Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

/// `|got - want| <= rel * |want| + abs`, with a message naming what and where.
pub fn assert_close(what: &str, at: &str, got: f64, want: f64, rel: f64, abs: f64) {
    let tol = rel * want.abs() + abs;
    assert!(
        (got - want).abs() <= tol,
        "{what} at {at}: got {got:e}, want {want:e} (|diff| {:e} > tol {tol:e})",
        (got - want).abs()
    );
}
