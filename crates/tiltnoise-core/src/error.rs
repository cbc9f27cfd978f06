//! Typed errors of the library. Every variant carries the fields a user needs to fix the input:
//! the key or file, the offending value, the unit and what is allowed. The binary adds context
//! with `anyhow` and maps every error to exit code 2.

use crate::limits::LimitError;
use std::fmt;
use std::path::PathBuf;

/// A number as messages show it: the shortest decimal that reads back to the same `f64`, in
/// exponent form when it would be long (`|x| >= 1e7` or `|x| < 1e-5`), so that a value such as
/// `1e300` never turns into 301 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x != 0.0 && x.is_finite() && !(1e-5..1e7).contains(&x.abs()) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}

/// A parameter set that cannot describe a physical pendulum, or a parameter file that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum ParamError {
    /// The file could not be read at all.
    #[error("cannot read parameter file {path}: {reason}")]
    Read {
        /// The file that was asked for.
        path: PathBuf,
        /// What the operating system said (in the message, so not also a `source()`).
        reason: std::io::Error,
    },
    /// The text is not valid TOML, or has unknown/missing keys or a value of the wrong type.
    #[error("invalid parameter file {origin}: {message}")]
    Syntax {
        /// The file name, or `--set` / `embedded Table I`.
        origin: String,
        /// The TOML parser's message (it names the key and line).
        message: String,
    },
    /// A numeric value outside the physically allowed range.
    #[error("parameter `{key}` = {} {unit} is not allowed: must be {allowed}", Num(*.value))]
    OutOfRange {
        /// Dotted key, e.g. `inertia.a11_kg_m2`.
        key: String,
        /// The value given.
        value: f64,
        /// Unit of the value.
        unit: &'static str,
        /// What is allowed, e.g. `finite and > 0`.
        allowed: &'static str,
    },
    /// A tensor or matrix assembled from several parameters is not positive definite.
    #[error("{what} is not positive definite (from parameters {keys}): {detail}")]
    NotPositiveDefinite {
        /// Which matrix: `inertia tensor of body a`, `mass matrix M`.
        what: &'static str,
        /// The parameters it is built from.
        keys: String,
        /// The failing pivot or eigenvalue.
        detail: String,
    },
    /// The equilibrium the model linearizes about is not stable: a mode has `omega^2 <= 0`.
    #[error(
        "the parameters give an unstable equilibrium: the mode dominated by {mode} has \
         omega^2 = {omega_sq:.3e} rad^2/s^2 (must be > 0; the stiffness K is not positive \
         definite). Check the lengths (a centre of mass above its suspension point, \
         length.z_a_m > length.z_m or length.z_b_m too short against length.h_c_m) and the \
         torsion and bouncing constants"
    )]
    Unstable {
        /// The smallest generalized eigenvalue of (K, M).
        omega_sq: f64,
        /// Dominant coordinates of the unstable mode with their energy shares in M.
        mode: String,
    },
    /// A matrix of the model overflows `f64` for the given parameter values.
    #[error("the parameters cannot be represented: {detail}")]
    NotFinite {
        /// What overflowed.
        detail: String,
    },
    /// `--set KEY=VALUE` with a malformed assignment or a key that does not exist.
    #[error("--set {assignment}: {message}")]
    Override {
        /// The assignment as given.
        assignment: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A parameter file, or one of its lines, over its size limit
    /// ([`crate::limits::MAX_SETTINGS_FILE_BYTES`], [`crate::limits::MAX_LINE_BYTES`]).
    #[error(transparent)]
    TooLarge(#[from] LimitError),
}

/// A frequency request that cannot be evaluated.
#[derive(Debug, thiserror::Error)]
pub enum FreqError {
    /// A frequency that is negative, NaN or infinite.
    #[error("frequency {} Hz ({origin}) is not allowed: must be finite and >= 0", Num(*.value))]
    Invalid {
        /// The value.
        value: f64,
        /// Where it came from, e.g. `line 3 of f.txt`.
        origin: String,
    },
    /// A malformed `FLO:N:FHI` specification or frequency file.
    #[error("{origin}: {message}")]
    Spec {
        /// The specification or file.
        origin: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// A grid or frequency file over its size limit ([`crate::limits::MAX_GRID_POINTS`],
    /// [`crate::limits::MAX_FREQ_FILE_BYTES`]).
    #[error(transparent)]
    TooLarge(#[from] LimitError),
}

/// An evaluation of a transfer function that has no meaningful result.
#[derive(Debug, thiserror::Error)]
pub enum TfError {
    /// The dynamic stiffness `K(1 + i phi) - w^2 M` is singular to working precision: the
    /// frequency sits on an undamped resonance.
    #[error(
        "dynamic stiffness is singular at {} Hz (reciprocal condition {rcond:.1e} after \
         equilibration): an undamped resonance; add loss angles or move the frequency",
        Num(*.freq_hz)
    )]
    Singular {
        /// The frequency asked for.
        freq_hz: f64,
        /// Reciprocal 1-norm condition number of the equilibrated matrix.
        rcond: f64,
    },
    /// A frequency that is negative or not finite.
    #[error(transparent)]
    Freq(#[from] FreqError),
    /// A value of the transfer function overflows `f64` (a frequency or parameter values far
    /// beyond a laboratory pendulum's): refused rather than returned as inf or NaN.
    #[error(
        "the transfer function is not finite at {} Hz: the frequency or the parameter \
         values are beyond the range of f64",
        Num(*.freq_hz)
    )]
    NotFinite {
        /// The first frequency (in grid order) with a non-finite value.
        freq_hz: f64,
    },
    /// A grid whose result does not fit into the memory available ([`crate::tf::evaluate`]).
    #[error(transparent)]
    TooLarge(#[from] LimitError),
    /// The planner found no method that meets the requested tolerance, or cannot plan the
    /// request ([`crate::tf::plan_auto`]).
    #[error("{message}")]
    NoMethod {
        /// Every candidate's verdict, or why the request cannot be planned.
        message: String,
    },
}

/// Failure to write an output file. Nothing is left at `path` when this is returned.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// The extension does not name a supported format.
    #[error("cannot save {path}: unknown extension, allowed are {allowed}")]
    UnknownFormat {
        /// The path asked for.
        path: PathBuf,
        /// The supported extensions.
        allowed: &'static str,
    },
    /// Any I/O failure (directory missing, permission denied, disk full).
    #[error("cannot write {path}: {message}")]
    Write {
        /// The path asked for.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}
