//! Helpers shared by the integration tests of every crate: paths inside the repository, JSON
//! fixtures, a named-tolerance comparison and the damped test model. The command line's test
//! binary includes this file too (`tests/it/common.rs`), so it depends on `tiltnoise-core` and
//! the standard library only.
// Each test binary uses a different subset of these helpers.
#![allow(dead_code)]

use std::path::PathBuf;
use tiltnoise_core::params::Params;

/// A path inside the repository (`crate::REPO_ROOT` is the repository root of the test binary
/// that includes this file).
pub fn repo(rel: &str) -> PathBuf {
    PathBuf::from(crate::REPO_ROOT).join(rel)
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

/// `p` with loss angle `loss_rad` on both torsions and both bouncings (the damped test model
/// of the transfer-function tests).
pub fn with_torsion_and_bouncing_loss(p: Params, loss_rad: f64) -> Params {
    let mut p = p;
    for key in [
        "torsion_a_rad",
        "torsion_b_rad",
        "bouncing_a_rad",
        "bouncing_b_rad",
    ] {
        p = p.with_override(&format!("loss.{key}={loss_rad}")).unwrap();
    }
    p
}
