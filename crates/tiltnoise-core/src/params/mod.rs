//! Parameters of the double torsion pendulum: the TOML file format, the embedded Table I default,
//! `--set KEY=VALUE` overrides and validation.
//!
//! Every quantity is SI and carries its unit in its key (`m_a_kg`, `z_b_m`, ...). The embedded
//! default is `src/params/table1.toml`: the values of Table I of De Marchi et al. (2013) plus the
//! assumptions the paper does not state (`length.h_m`, `environment.g_m_per_s2`) and loss angles of 0.
//! This module depends on nothing else in the crate but the error types.

use crate::error::{shown_within, ParamError, Shown, SHOWN_MAX_CHARS};
use serde::{Deserialize, Serialize};

pub mod asymmetry;
mod fields;
pub mod uncertainty;
pub use asymmetry::Asymmetry;
pub use uncertainty::UncertaintyTable;

/// The embedded default parameter file (Table I of the paper), with a unit comment on every line.
pub const TABLE_I_TOML: &str = include_str!("table1.toml");

/// Masses of the two suspended bodies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Masses {
    /// Crossbar system (crossbar + counterweights), m_a (kg).
    pub m_a_kg: f64,
    /// Test mass with its shaft, m_b (kg).
    pub m_b_kg: f64,
}

/// Inertia tensors about each body's centre of mass in the body frame (kg m^2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Inertia {
    /// I^a_11.
    pub a11_kg_m2: f64,
    /// I^a_22.
    pub a22_kg_m2: f64,
    /// I^a_33.
    pub a33_kg_m2: f64,
    /// I^a_23, the only off-diagonal term of the crossbar (any sign).
    pub a23_kg_m2: f64,
    /// I^b_11.
    pub b11_kg_m2: f64,
    /// I^b_22.
    pub b22_kg_m2: f64,
    /// I^b_33.
    pub b33_kg_m2: f64,
}

/// Torsional spring constants of the fibres (N m / rad).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Torsion {
    /// Upper fibre, k_a.
    pub k_a_n_m_per_rad: f64,
    /// Lower fibre, k_b.
    pub k_b_n_m_per_rad: f64,
}

/// Longitudinal (bouncing) spring constants of the fibres (N/m).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bouncing {
    /// Upper fibre, kappa_{e,a}.
    pub kappa_a_n_per_m: f64,
    /// Lower fibre, kappa_{e,b}.
    pub kappa_b_n_per_m: f64,
}

/// Lengths (m). See section II.A of the paper for the geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Lengths {
    /// Crossbar arm, d: horizontal distance of the lower fibre from the upper fibre.
    pub d_m: f64,
    /// Cube geometric centre below the test-mass centre of mass, h_c.
    pub h_c_m: f64,
    /// Distance between the two fibre suspension points along the upper fibre, Z.
    pub z_m: f64,
    /// Lower suspension point to the crossbar centre of mass, Z_a.
    pub z_a_m: f64,
    /// Lower suspension point to the test-mass centre of mass, Z_b.
    pub z_b_m: f64,
    /// Height of the upper suspension point above the floor pivot of the tilt, h.
    /// Not given in the paper: an assumption (default 2.0 m).
    pub h_m: f64,
}

/// Environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Environment {
    /// Local gravitational acceleration (m s^-2). Not given in the paper: standard gravity assumed.
    pub g_m_per_s2: f64,
    /// Temperature of the dissipative elements (K), the T of the fluctuation-dissipation
    /// theorem in the thermal-noise terms. Optional in files; default 293.15 K (20 degC room
    /// temperature, an assumption).
    #[serde(default = "default_temperature_k")]
    pub temperature_k: f64,
}

/// Default of `environment.temperature_k`: 20 degC.
pub const DEFAULT_TEMPERATURE_K: f64 = 293.15;

fn default_temperature_k() -> f64 {
    DEFAULT_TEMPERATURE_K
}

fn default_dilution() -> f64 {
    1.0
}

/// Structural loss angles (rad): k -> k (1 + i phi) on each fibre's torsion, bouncing and
/// swing stiffness. See `docs/damping.md`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LossAngles {
    /// Torsion of the upper fibre.
    pub torsion_a_rad: f64,
    /// Torsion of the lower fibre.
    pub torsion_b_rad: f64,
    /// Bouncing of the upper fibre.
    pub bouncing_a_rad: f64,
    /// Bouncing of the lower fibre.
    pub bouncing_b_rad: f64,
    /// Material (bending) loss angle of the upper fibre. Its swing (pendulum) loss angle is
    /// `bending_a_rad / dilution_a` (optional in files, default 0).
    #[serde(default)]
    pub bending_a_rad: f64,
    /// Material (bending) loss angle of the lower fibre (optional, default 0).
    #[serde(default)]
    pub bending_b_rad: f64,
    /// Dilution factor D >= 1 of the upper fibre's swing: gravity stiffness over bending
    /// stiffness, `phi_pendulum = phi_fibre / D` (optional, default 1: no dilution).
    #[serde(default = "default_dilution")]
    pub dilution_a: f64,
    /// Dilution factor D >= 1 of the lower fibre's swing (optional, default 1).
    #[serde(default = "default_dilution")]
    pub dilution_b: f64,
}

impl LossAngles {
    /// Swing (pendulum) loss angle of the upper fibre, `bending_a_rad / dilution_a` (rad).
    pub fn swing_a_rad(&self) -> f64 {
        self.bending_a_rad / self.dilution_a
    }

    /// Swing (pendulum) loss angle of the lower fibre, `bending_b_rad / dilution_b` (rad).
    pub fn swing_b_rad(&self) -> f64 {
        self.bending_b_rad / self.dilution_b
    }
}

/// Viscous damping coefficients per fibre and motion: a generalized damping force `-c q'` on
/// the element's coordinate (see `docs/damping.md`). The whole section is optional; every
/// coefficient defaults to 0.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Viscous {
    /// Torsion of the upper fibre, on phi_a (N m s/rad).
    #[serde(default)]
    pub torsion_a_n_m_s_per_rad: f64,
    /// Torsion of the lower fibre, on phi_b (N m s/rad).
    #[serde(default)]
    pub torsion_b_n_m_s_per_rad: f64,
    /// Bouncing of the upper fibre, on delta_a (N s/m).
    #[serde(default)]
    pub bouncing_a_n_s_per_m: f64,
    /// Bouncing of the lower fibre, on delta_b (N s/m).
    #[serde(default)]
    pub bouncing_b_n_s_per_m: f64,
    /// Swing of the upper fibre, on theta_a and eta_a each (N m s/rad).
    #[serde(default)]
    pub swing_a_n_m_s_per_rad: f64,
    /// Swing of the lower fibre, on the test mass's absolute angles theta_a + theta_b and
    /// eta_a + eta_b each (N m s/rad).
    #[serde(default)]
    pub swing_b_n_m_s_per_rad: f64,
}

/// A complete parameter set. Build it with [`Params::table_i`] or [`Params::from_toml_str`]
/// (a file is read by `tiltnoise_io::read_params`); all of them validate, so a `Params` in hand
/// is physical.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Masses.
    pub mass: Masses,
    /// Inertia tensors.
    pub inertia: Inertia,
    /// Torsional constants.
    pub torsion: Torsion,
    /// Bouncing constants.
    pub bouncing: Bouncing,
    /// Lengths.
    pub length: Lengths,
    /// Gravity.
    pub environment: Environment,
    /// Loss angles.
    pub loss: LossAngles,
    /// Viscous damping coefficients (optional section, default 0).
    #[serde(default)]
    pub viscous: Viscous,
    /// Assembly asymmetries and readout misalignment (optional section, default 0: the
    /// symmetric pendulum of the paper).
    #[serde(default)]
    pub asymmetry: Asymmetry,
    /// Error bars overriding the defaults (optional section; see [`uncertainty`]).
    #[serde(default, skip_serializing_if = "UncertaintyTable::is_empty")]
    pub uncertainty: UncertaintyTable,
}

/// What values a parameter may take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Allowed {
    /// Finite and strictly positive.
    Positive,
    /// Finite and >= 0.
    NonNegative,
    /// Any finite value.
    Finite,
    /// A loss angle: finite, >= 0 and < 1 rad.
    LossAngle,
    /// A dilution factor: finite and >= 1.
    AtLeastOne,
    /// A length of the pendulum: > 0 and at most [`MAX_LENGTH_M`].
    Length,
    /// A length that may be 0: >= 0 and at most [`MAX_LENGTH_M`].
    LengthOrZero,
    /// An offset of the `[asymmetry]` section: finite, and below a fraction of the body it
    /// moves in ([`Asymmetry::limits`], checked with the lengths).
    Offset,
}

/// The largest length a parameter may have (m). The model describes a laboratory pendulum;
/// lengths far beyond one (`length.h_m = 1e300`, say) make the apparent forces `w^2 h` and the
/// spectra overflow `f64`, so they are refused at the key instead of giving inf or NaN later.
pub const MAX_LENGTH_M: f64 = 1e3;

impl Allowed {
    fn admits(self, v: f64) -> bool {
        v.is_finite()
            && match self {
                Allowed::Positive => v > 0.0,
                Allowed::NonNegative => v >= 0.0,
                Allowed::Finite => true,
                Allowed::LossAngle => (0.0..1.0).contains(&v),
                Allowed::AtLeastOne => v >= 1.0,
                Allowed::Length => v > 0.0 && v <= MAX_LENGTH_M,
                Allowed::LengthOrZero => (0.0..=MAX_LENGTH_M).contains(&v),
                Allowed::Offset => true,
            }
    }

    /// Human-readable rule, used in error messages and the README table.
    pub fn describe(self) -> &'static str {
        match self {
            Allowed::Positive => "finite and > 0",
            Allowed::NonNegative => "finite and >= 0",
            Allowed::Finite => "finite",
            Allowed::LossAngle => "finite, >= 0 and < 1",
            Allowed::AtLeastOne => "finite and >= 1",
            Allowed::Length => "> 0 and <= 1000 (a laboratory pendulum)",
            Allowed::LengthOrZero => ">= 0 and <= 1000 (a laboratory pendulum)",
            Allowed::Offset => {
                "finite, |value| < 10 % of the body's length (0.1 rad for a rotation)"
            }
        }
    }
}

/// One parameter as seen by validation, documentation and `--set`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Field {
    /// Dotted key, `section.name`.
    pub key: &'static str,
    /// Current value.
    pub value: f64,
    /// SI unit.
    pub unit: &'static str,
    /// Paper symbol or short description.
    pub symbol: &'static str,
    /// Allowed range.
    pub allowed: Allowed,
}

impl Params {
    /// The embedded Table I parameter set.
    pub fn table_i() -> Params {
        Params::from_toml_str(TABLE_I_TOML, "embedded Table I")
            .expect("the embedded Table I parameter file is valid")
    }

    /// Parses and validates a TOML parameter set. `origin` names the source in error messages.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Params, ParamError> {
        let depth = max_nesting(text);
        if depth > MAX_NESTING {
            return Err(ParamError::Syntax {
                origin: origin.to_string(),
                message: format!(
                    "brackets `[ ]` and `{{ }}` nested {depth} levels deep; allowed: at most \
                     {MAX_NESTING} (a parameter file needs 1)"
                ),
            });
        }
        let params: Params = toml::from_str(text).map_err(|e| ParamError::Syntax {
            origin: origin.to_string(),
            message: toml_error_line(&e, text),
        })?;
        params.validate()?;
        Ok(params)
    }

    /// The effective parameter set as TOML, with units in the keys; it reads back unchanged.
    pub fn to_toml(&self) -> String {
        let mut text = String::from(
            "# tiltnoise parameter set (SI units; unit in every key).\n\
             # Defaults: Table I of De Marchi et al., Phys. Rev. D 87, 122006 (2013);\n\
             # length.h_m and environment.g_m_per_s2 are assumptions, not from the paper.\n\n",
        );
        text.push_str(&toml::to_string(self).expect("parameters serialize to TOML"));
        text.push_str(&self.uncertainty_comment());
        text
    }

    /// Applies one `KEY=VALUE` override (e.g. `length.h_m=1.5`) and re-validates.
    pub fn with_override(&self, assignment: &str) -> Result<Params, ParamError> {
        let err = |message: String| ParamError::Override {
            assignment: assignment.to_string(),
            message,
        };
        let (key, value) = assignment
            .split_once('=')
            .ok_or_else(|| err("expected KEY=VALUE, e.g. length.h_m=1.5".into()))?;
        let (key, value) = (key.trim(), value.trim());
        let keys: Vec<&str> = self.fields().iter().map(|f| f.key).collect();
        if !keys.contains(&key) {
            return Err(err(format!(
                "unknown key `{}`; allowed keys: {}",
                Shown(key),
                keys.join(", ")
            )));
        }
        let number: f64 = value.parse().map_err(|_| {
            err(format!(
                "value `{}` of `{key}` is not a number",
                Shown(value)
            ))
        })?;
        let mut table = toml::Table::try_from(self).expect("parameters convert to a TOML table");
        let (section, name) = key.split_once('.').expect("keys are section.name");
        table
            .get_mut(section)
            .and_then(|s| s.as_table_mut())
            .expect("every key's section exists")
            .insert(name.to_string(), toml::Value::Float(number));
        let params: Params = table.try_into().map_err(|e: toml::de::Error| {
            err(shown_within(e.message().trim(), 2 * SHOWN_MAX_CHARS))
        })?;
        params.validate()?;
        Ok(params)
    }

    /// Every parameter with its key, unit, symbol and allowed range, in file order.
    pub fn fields(&self) -> Vec<Field> {
        let mut fields = self.mass.fields();
        fields.extend(self.inertia.fields());
        fields.extend(self.torsion.fields());
        fields.extend(self.bouncing.fields());
        fields.extend(self.length.fields());
        fields.extend(self.environment.fields());
        fields.extend(self.loss.fields());
        fields.extend(self.viscous.fields());
        fields.extend(self.asymmetry_fields());
        fields
    }

    /// The limits of the asymmetry offsets, which scale with the lengths.
    fn asymmetry_fields(&self) -> Vec<Field> {
        let symbols = [
            "crossbar centre of mass, x offset",
            "crossbar centre of mass, y offset",
            "test-mass centre of mass, x offset",
            "test-mass centre of mass, y offset",
            "lower fibre clamp, x offset",
            "lower fibre clamp, y offset",
            "readout axes, rotation about x",
            "readout axes, rotation about y",
            "readout axes, rotation about z",
        ];
        let l = &self.length;
        let mut fields = Vec::new();
        for (limit, symbol) in self
            .asymmetry
            .limits(l.d_m, l.z_a_m, l.z_b_m)
            .into_iter()
            .zip(symbols)
        {
            fields.push(Field {
                key: limit.key,
                value: limit.value,
                unit: limit.unit,
                symbol,
                allowed: Allowed::Offset,
            });
        }
        fields
    }

    /// Checks every value against its allowed range and both inertia tensors for positive
    /// definiteness. (The assembled mass matrix is checked when the model is built.)
    pub fn validate(&self) -> Result<(), ParamError> {
        for field in self.fields() {
            if !field.allowed.admits(field.value) {
                return Err(ParamError::OutOfRange {
                    key: field.key.to_string(),
                    value: field.value,
                    unit: field.unit,
                    allowed: field.allowed.describe(),
                });
            }
        }
        // The crossbar tensor is diag(I11) (+) [[I22, I23], [I23, I33]]: positive definite iff
        // the 2x2 block's determinant is positive (its diagonal is already checked).
        let i = &self.inertia;
        let det = i.a22_kg_m2 * i.a33_kg_m2 - i.a23_kg_m2 * i.a23_kg_m2;
        if det <= 0.0 {
            return Err(ParamError::NotPositiveDefinite {
                what: "inertia tensor of body a",
                keys: "inertia.a22_kg_m2, inertia.a33_kg_m2, inertia.a23_kg_m2".into(),
                detail: format!(
                    "I22 I33 - I23^2 = {det:e} kg^2 m^4; need |I23| < sqrt(I22 I33) = {:e} kg m^2",
                    (i.a22_kg_m2 * i.a33_kg_m2).sqrt()
                ),
            });
        }
        let l = &self.length;
        for limit in self.asymmetry.limits(l.d_m, l.z_a_m, l.z_b_m) {
            if limit.value.abs() >= limit.limit {
                return Err(ParamError::OffsetTooLarge {
                    key: limit.key,
                    value: limit.value,
                    unit: limit.unit,
                    limit: limit.limit,
                    reason: limit.reason,
                });
            }
        }
        // Already checked when read from TOML; this catches a table built in code. (Skipped
        // when empty: the Monte Carlo validates every draw.)
        if self.uncertainty.is_empty() {
            return Ok(());
        }
        let keys: Vec<&str> = self.fields().iter().map(|f| f.key).collect();
        self.uncertainty
            .validate(&keys)
            .map_err(|e| ParamError::Syntax {
                origin: "(uncertainty table built in code)".to_string(),
                message: e.to_string(),
            })
    }
}

/// A TOML error as one line: the line and column in `text` where the parser stopped, and its
/// message (which may quote the file, so it is [`shown_within`] a bound).
fn toml_error_line(e: &toml::de::Error, text: &str) -> String {
    let message = shown_within(e.message().trim(), 2 * SHOWN_MAX_CHARS);
    let Some(before) = e.span().and_then(|span| text.get(..span.start)) else {
        return message;
    };
    let line = before.matches('\n').count() + 1;
    let column = before.chars().rev().take_while(|&c| c != '\n').count() + 1;
    format!("line {line}, column {column}: {message}")
}

/// Deepest nesting of brackets a parameter file may have. The TOML parser's own limit does
/// not hold for every malformed input (an array opened and closed inside an unclosed inline
/// table, `a={[b]` repeated, recurses once per repetition until the stack overflows), so the
/// depth is checked before parsing.
const MAX_NESTING: usize = 16;

/// The deepest nesting of `[` and `{` in a TOML text, outside strings and comments (unclosed
/// brackets count to the end; a table header `[a]` is one level).
fn max_nesting(text: &str) -> usize {
    let b = text.as_bytes();
    // The open brackets, innermost last. A closer pops only the bracket it matches: the
    // parser's error recovery keeps `{` open across a stray `]` (`a = { b]` repeated recurses
    // once per line), so a mismatched closer must not lower the count.
    let mut open: Vec<u8> = Vec::new();
    let (mut deepest, mut i) = (0usize, 0usize);
    while i < b.len() {
        match b[i] {
            b'#' => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            q @ (b'"' | b'\'') => {
                let multiline = b[i..].starts_with(&[q, q, q]);
                i += if multiline { 3 } else { 1 };
                while i < b.len() {
                    if q == b'"' && b[i] == b'\\' {
                        i += 2;
                        continue;
                    }
                    if multiline && b[i..].starts_with(&[q, q, q]) {
                        i += 2;
                        break;
                    }
                    if !multiline && (b[i] == q || b[i] == b'\n') {
                        break;
                    }
                    i += 1;
                }
            }
            c @ (b'[' | b'{') => {
                open.push(c);
                deepest = deepest.max(open.len());
            }
            b']' if open.last() == Some(&b'[') => {
                open.pop();
            }
            b'}' if open.last() == Some(&b'{') => {
                open.pop();
            }
            _ => {}
        }
        i += 1;
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_i_round_trips_through_toml() {
        let p = Params::table_i();
        let back = Params::from_toml_str(&p.to_toml(), "round trip").unwrap();
        assert_eq!(p, back);
    }

    #[test]
    fn nesting_is_bounded_before_parsing() {
        assert_eq!(
            max_nesting("a = \"{[\\\"{\" # [[\n[b]\nc = { d = ['['] }\ne = \"\"\"\n[[\"\"\"\n"),
            2
        );
        // Without the check, the parser recurses once per repetition: a stack overflow.
        let e = Params::from_toml_str(&"a={[b]\n".repeat(20_000), "deep.toml").unwrap_err();
        let e = e.to_string();
        assert!(e.contains("deep.toml") && e.contains("at most 16"), "{e}");
        // A stray closer does not close a bracket of the other kind.
        assert_eq!(max_nesting("a = { b]\nc = [ d}\n"), 2);
        let stray = "[uncertainty]\n\"length.h_m\" = { rel_sigma]\n".repeat(20_000);
        let e = Params::from_toml_str(&stray, "stray.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("stray.toml") && e.contains("at most 16"), "{e}");
    }

    #[test]
    fn override_changes_one_value_only() {
        let p = Params::table_i();
        let q = p.with_override("length.h_m = 1.25").unwrap();
        assert_eq!(q.length.h_m, 1.25);
        assert_eq!(
            Params {
                length: Lengths {
                    h_m: p.length.h_m,
                    ..q.length.clone()
                },
                ..q.clone()
            },
            p
        );
    }

    #[test]
    fn override_rejects_unknown_key_and_non_number() {
        let p = Params::table_i();
        let e = p.with_override("length.hh=1").unwrap_err().to_string();
        assert!(
            e.contains("unknown key `length.hh`") && e.contains("length.h_m"),
            "{e}"
        );
        let e = p.with_override("length.h_m=abc").unwrap_err().to_string();
        assert!(e.contains("not a number"), "{e}");
        let e = p.with_override("length.h_m").unwrap_err().to_string();
        assert!(e.contains("KEY=VALUE"), "{e}");
    }

    #[test]
    fn override_and_file_errors_are_one_short_line() {
        let p = Params::table_i();
        let long = format!("length.h_m={}", "x".repeat(100_000));
        let e = p.with_override(&long).unwrap_err().to_string();
        assert!(e.len() < 1000 && e.contains("(100011 bytes)"), "{e}");
        let e = p
            .with_override("length.h\n_m\u{1b}=1")
            .unwrap_err()
            .to_string();
        assert!(!e.contains(['\n', '\u{1b}']), "{e}");
        assert!(e.contains("`length.h\\n_m\\x1b`"), "{e}");
        let text = TABLE_I_TOML.replace("m_b_kg = 0.11", "m_b_kg = \"0.11\"");
        let e = Params::from_toml_str(&text, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(!e.contains('\n'), "{e}");
        let line = TABLE_I_TOML
            .lines()
            .position(|l| l.starts_with("m_b_kg"))
            .unwrap()
            + 1;
        assert!(
            e.contains(&format!("t.toml: line {line}, column 10: invalid type")),
            "{e}"
        );
        let text = format!("{}\n{} = 1\n", TABLE_I_TOML, "q".repeat(100_000));
        let e = Params::from_toml_str(&text, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.len() < 1000 && !e.contains('\n'), "{e}");
    }

    #[test]
    fn negative_inertia_names_key_value_unit_and_rule() {
        let e = Params::table_i()
            .with_override("inertia.b33_kg_m2=-1e-5")
            .unwrap_err()
            .to_string();
        assert!(e.contains("inertia.b33_kg_m2"), "{e}");
        assert!(e.contains("-0.00001") || e.contains("-1e-5"), "{e}");
        assert!(e.contains("kg m^2") && e.contains("> 0"), "{e}");
    }

    #[test]
    fn non_finite_and_unknown_and_missing_keys_are_rejected() {
        let nan = TABLE_I_TOML.replace("m_b_kg = 0.11", "m_b_kg = nan");
        let e = Params::from_toml_str(&nan, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("mass.m_b_kg") && e.contains("NaN"), "{e}");
        let unknown = TABLE_I_TOML.replace("m_b_kg = 0.11", "m_b_kg = 0.11\nm_c_kg = 1.0");
        let e = Params::from_toml_str(&unknown, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.toml") && e.contains("m_c_kg"), "{e}");
        let missing = TABLE_I_TOML.replace("m_b_kg = 0.11", "");
        let e = Params::from_toml_str(&missing, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("m_b_kg"), "{e}");
    }

    #[test]
    fn crossbar_tensor_must_be_positive_definite() {
        let e = Params::table_i()
            .with_override("inertia.a23_kg_m2=0.1")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("not positive definite") && e.contains("a23"),
            "{e}"
        );
    }

    #[test]
    fn loss_angle_range() {
        let p = Params::table_i();
        assert!(p.with_override("loss.torsion_b_rad=1e-3").is_ok());
        assert!(p.with_override("loss.torsion_b_rad=-1e-3").is_err());
        assert!(p.with_override("loss.torsion_b_rad=1.5").is_err());
    }

    #[test]
    fn damping_keys_are_validated_and_optional() {
        let p = Params::table_i();
        assert_eq!(p.environment.temperature_k, DEFAULT_TEMPERATURE_K);
        assert_eq!(p.viscous, Viscous::default());
        for (set, rule) in [
            ("loss.bending_b_rad=-1e-4", ">= 0 and < 1"),
            ("loss.dilution_a=0.5", ">= 1"),
            ("viscous.swing_b_n_m_s_per_rad=-1", ">= 0"),
            ("environment.temperature_k=-4", "> 0"),
            ("viscous.torsion_b_n_m_s_per_rad=inf", ">= 0"),
        ] {
            let key = set.split('=').next().unwrap();
            let e = p.with_override(set).unwrap_err().to_string();
            assert!(e.contains(key) && e.contains(rule), "{set}: {e}");
        }
        let q = p
            .with_override("loss.bending_b_rad=1e-3")
            .and_then(|q| q.with_override("loss.dilution_b=50"))
            .unwrap();
        assert_eq!(q.loss.swing_b_rad(), 1e-3 / 50.0);
        // A file without the optional keys (an older parameter file) still reads.
        assert!(Params::from_toml_str(
            &TABLE_I_TOML.replace("temperature_k = 293.15", ""),
            "old.toml"
        )
        .is_ok());
    }
}
