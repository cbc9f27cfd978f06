//! Typed errors of the library. Every variant carries the fields a user needs to fix the input:
//! the key or file, the offending value, the unit and what is allowed. The binary adds context
//! with `anyhow` and maps every error to exit code 2.

use crate::limits::LimitError;
pub use crate::num_text::Num;
use crate::option_key::OptionKey;
use std::fmt::{self, Write as _};
use std::path::PathBuf;

/// Characters of a value from the user or a file that a message shows ([`Shown`]).
pub const SHOWN_MAX_CHARS: usize = 200;

/// A value from the command line or from a file as a one-line message shows it: control
/// characters and invisible line and direction marks escaped (`\n`, `\t`, `\x1b`, `\u{2028}`),
/// so that the message stays on one line and cannot drive the terminal, and at most
/// [`SHOWN_MAX_CHARS`] characters, the rest replaced by `... (N bytes)` with the length of the
/// whole value.
///
/// ```
/// use tiltnoise_core::error::Shown;
/// assert_eq!(Shown("a\tb\n").to_string(), "a\\tb\\n");
/// let long = "x".repeat(100_000);
/// assert_eq!(Shown(&long).to_string(), format!("{}... (100000 bytes)", "x".repeat(200)));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shown<'a>(pub &'a str);

impl fmt::Display for Shown<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&shown_within(self.0, SHOWN_MAX_CHARS))
    }
}

/// `text` with control characters and invisible line and direction marks escaped, at most
/// `max_chars` characters of it (counted after escaping), followed by `... (N bytes)` when it
/// was cut. [`Shown`] is this with [`SHOWN_MAX_CHARS`].
pub fn shown_within(text: &str, max_chars: usize) -> String {
    let mut out = String::with_capacity(text.len().min(max_chars) + 24);
    let mut chars = 0;
    let mut escaped = String::new();
    for c in text.chars() {
        escaped.clear();
        escape_char(c, &mut escaped);
        let n = escaped.chars().count();
        if chars + n > max_chars {
            let _ = write!(out, "... ({} bytes)", text.len());
            return out;
        }
        chars += n;
        out.push_str(&escaped);
    }
    out
}

/// Names from the command line or a file joined with `, ` as messages show them: each one
/// [`Shown`], the list cut once it is longer than [`SHOWN_MAX_CHARS`] characters, with
/// `... (N more)` for the names left out.
pub fn shown_list<S: AsRef<str>>(names: &[S]) -> String {
    let mut out = String::new();
    for (i, name) in names.iter().enumerate() {
        if i > 0 && out.chars().count() > SHOWN_MAX_CHARS {
            let _ = write!(out, ", ... ({} more)", names.len() - i);
            break;
        }
        if i > 0 {
            out.push_str(", ");
        }
        let _ = write!(out, "{}", Shown(name.as_ref()));
    }
    out
}

fn escape_char(c: char, out: &mut String) {
    match c {
        '\n' => out.push_str("\\n"),
        '\r' => out.push_str("\\r"),
        '\t' => out.push_str("\\t"),
        c if c.is_ascii_control() => {
            let _ = write!(out, "\\x{:02x}", u32::from(c));
        }
        // C1 controls; line and paragraph separators, direction marks and overrides, which
        // break a line or reorder it on a terminal; the byte-order mark.
        '\u{80}'..='\u{9f}'
        | '\u{200e}'
        | '\u{200f}'
        | '\u{2028}'..='\u{202e}'
        | '\u{2066}'..='\u{2069}'
        | '\u{feff}' => {
            let _ = write!(out, "\\u{{{:x}}}", u32::from(c));
        }
        c => out.push(c),
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
    /// An offset of the `[asymmetry]` section too large for the body it moves in.
    #[error(
        "parameter `{key}` = {} {unit} is not allowed: |value| must be < {limit:.4e} {unit} \
         ({reason})",
        Num(*.value)
    )]
    OffsetTooLarge {
        /// Dotted key, e.g. `asymmetry.tm_com_x_m`.
        key: &'static str,
        /// The value given.
        value: f64,
        /// Its unit, `m` or `rad`.
        unit: &'static str,
        /// The bound of `|value|`, in the key's unit.
        limit: f64,
        /// What the bound is a fraction of.
        reason: &'static str,
    },
    /// The exact potential of an asymmetric pendulum has no stable rest configuration near
    /// the drawing's (Newton on its gradient diverges or ends on a saddle).
    #[error("no stable equilibrium with the [asymmetry] offsets {keys}: {detail}")]
    NoEquilibrium {
        /// The nonzero asymmetry keys with their values.
        keys: String,
        /// What failed.
        detail: String,
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
    #[error("{}: {message}", OptionKey::SET.given(Shown(.assignment)))]
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
    /// A frequency above [`MAX_FREQUENCY_HZ`](crate::limits::MAX_FREQUENCY_HZ) in a grid the
    /// user gives.
    #[error(
        "frequency {} Hz ({origin}) is not allowed: must be <= {:e} Hz (see docs/limits.md)",
        Num(*.value),
        crate::limits::MAX_FREQUENCY_HZ
    )]
    TooHigh {
        /// The value.
        value: f64,
        /// Where it came from, e.g. `line 3 of f.txt`.
        origin: String,
    },
    /// A malformed `FLO:N:FHI` specification or frequency file.
    #[error("{origin}: {message}")]
    Spec {
        /// The specification (the option and its value) or the file.
        origin: crate::option_key::Message,
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
    /// Cancelled through the caller's token ([`crate::cancel`]).
    #[error(transparent)]
    Cancelled(#[from] crate::cancel::Cancelled),
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
    /// An entry of a transfer function whose value is beyond the range of `f64` at a frequency
    /// (e.g. a tilt's response per unit floor acceleration, `H / w^2`, below 1e-150 Hz): decided
    /// from the exact exponent ([`crate::tf::LowFrequency`]), refused rather than returned as
    /// inf or NaN.
    #[error(
        "the transfer function {entry} per unit floor {per} overflows f64 at {} Hz{}: use \
         frequencies where it is below 1.8e308, or the transfer function per unit displacement",
        Num(*.freq_hz),
        .log10_magnitude.map_or(String::new(), |l| format!(" (its magnitude is about 1e{:.0})", l.floor()))
    )]
    Overflow {
        /// The frequency (Hz).
        freq_hz: f64,
        /// `OUTPUT/INPUT`, e.g. `X/eta_t`.
        entry: String,
        /// The floor quantity with its unit, e.g. `acceleration (rad/s^2)`.
        per: String,
        /// `log10 |H|` from the exact exponent, when known.
        log10_magnitude: Option<f64>,
    },
    /// A grid whose result does not fit into the memory available ([`crate::tf::evaluate`]).
    #[error(transparent)]
    TooLarge(#[from] LimitError),
    /// A transfer function per unit velocity or acceleration of the floor asked for where it has
    /// no value from the one per unit displacement (0 Hz, see [`crate::ground`]).
    #[error(
        "a transfer function per unit floor {quantity} has no value at {} Hz (a floor {quantity} \
         carries no displacement there): use frequencies above 0 Hz",
        Num(*.freq_hz)
    )]
    NoGroundFactor {
        /// `velocity` or `acceleration`.
        quantity: &'static str,
        /// The frequency.
        freq_hz: f64,
    },
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
        /// The supported extensions, as the message lists them (`.h5, .hdf5, .png, .svg`).
        allowed: String,
    },
    /// An output path that breaks a rule of the run, found before anything is computed: no
    /// such directory, not writable, a directory, given twice, or an input of the run.
    #[error("cannot save {path}: {rule}")]
    Refused {
        /// The path asked for.
        path: PathBuf,
        /// The rule it breaks.
        rule: String,
    },
    /// Any I/O failure (directory missing, permission denied, disk full).
    #[error("cannot write {path}: {message}")]
    Write {
        /// The path asked for.
        path: PathBuf,
        /// What went wrong.
        message: crate::option_key::Message,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shown_values_are_one_line_and_short() {
        assert_eq!(Shown("length.h_m").to_string(), "length.h_m");
        assert_eq!(
            Shown("a\nb\r\t\u{1b}[31m\u{7f}\u{85}\u{2028}\u{202e}").to_string(),
            "a\\nb\\r\\t\\x1b[31m\\x7f\\u{85}\\u{2028}\\u{202e}"
        );
        // Non-ASCII text that is not a control stays as it is.
        assert_eq!(Shown("φ_a µrad").to_string(), "φ_a µrad");
        let long = "é".repeat(300);
        let shown = Shown(&long).to_string();
        assert_eq!(shown, format!("{}... (600 bytes)", "é".repeat(200)));
        // The limit counts the escaped text.
        let controls = "\u{1b}".repeat(100);
        let shown = Shown(&controls).to_string();
        assert!(shown.chars().count() <= SHOWN_MAX_CHARS + 20, "{shown}");
        assert!(shown.ends_with("... (100 bytes)"), "{shown}");
        assert_eq!(shown_within("abcdef", 3), "abc... (6 bytes)");
        assert_eq!(shown_within("abc", 3), "abc");
    }

    #[test]
    fn shown_lists_are_cut_with_a_count() {
        assert_eq!(shown_list(&["E", "N\n"]), "E, N\\n");
        assert_eq!(shown_list::<&str>(&[]), "");
        let names: Vec<String> = (0..100_000).map(|i| format!("c{i}")).collect();
        let shown = shown_list(&names);
        assert!(shown.len() < 2 * SHOWN_MAX_CHARS, "{shown}");
        assert!(shown.starts_with("c0, c1, c2"), "{shown}");
        assert!(shown.ends_with("more)"), "{shown}");
        let huge = vec!["x".repeat(10_000); 3];
        let shown = shown_list(&huge);
        assert!(shown.len() < 3 * SHOWN_MAX_CHARS, "{shown}");
        assert!(shown.ends_with("(2 more)"), "{shown}");
    }
}
