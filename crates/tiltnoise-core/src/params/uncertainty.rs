//! The error model of the parameters: the optional `[uncertainty]` table of a parameter file, its
//! defaults, and its validation.
//!
//! ```toml
//! [uncertainty]
//! "mass.m_a_kg" = { rel_sigma = 0.03, distribution = "uniform" }
//! "length.h_m" = { rel_sigma = 0.0 }          # exact
//! "asymmetry.tm_com_x_m" = { sigma = 2e-4 }    # absolute: 0.2 mm
//! ```
//!
//! * Keys are the dotted keys of [`Params::fields`]; quoted (`"mass.m_a_kg"`) or bare dotted
//!   (`mass.m_a_kg`) TOML keys both work.
//! * `rel_sigma` is the relative standard deviation (0.03 = 3 %) of the parameter, relative to
//!   its own value; 0 makes it exact. `distribution` is `gaussian` (the default) or `uniform`
//!   (flat on `+/- sqrt(3) rel_sigma`: the same standard deviation).
//! * The `[asymmetry]` keys, whose nominal value is an offset from the drawing (0 by default),
//!   take an absolute `sigma` in the key's unit instead ([`is_absolute_key`]); a relative error
//!   of a nominal 0 would mean nothing. Their default is 0 (exact), so a Monte Carlo draws
//!   nothing new unless a file sets one; a draw that leaves the key's bound
//!   ([`crate::params::Asymmetry::limits`]) is rejected as non-physical, as any other.
//! * Entries override [`default_uncertainties`]: Gaussian, 2.5 % on masses, inertias and lengths
//!   (except `length.h_m`), 10 % on the torsion and bouncing constants, everything else exact.
//! * An error bar may not make the parameter non-physical within its range: the relative factor
//!   `1 + rel_sigma z` must stay positive. For a Gaussian, 4 sigma must stay below 100 %
//!   (`rel_sigma <` [`MAX_REL_SIGMA`]); for a uniform draw the whole range `+/- sqrt(3) sigma`
//!   must (`rel_sigma <` [`MAX_REL_SIGMA_UNIFORM`] = 1/sqrt(3)).
//!
//! This module depends only on its parent [`crate::params`]; the Monte Carlo (`crate::mc`) and the
//! fit use it, never the other way round.

use super::Params;
use crate::error::Shown;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::sync::OnceLock;

/// Largest relative standard deviation of a Gaussian error (exclusive): 4 sigma must stay below
/// 100 %, so that a draw is non-physical with probability below 3e-5.
pub const MAX_REL_SIGMA: f64 = 0.25;

/// Largest relative standard deviation of a uniform error (exclusive), 1/sqrt(3): the range
/// `+/- sqrt(3) rel_sigma` must stay below 100 %.
pub const MAX_REL_SIGMA_UNIFORM: f64 = 0.577_350_269_189_625_8;

/// Default relative standard deviation on masses, lengths and inertias (the paper: 2-3 %).
pub const DEFAULT_REL_SIGMA_GEOMETRY: f64 = 0.025;

/// Default relative standard deviation on the torsion and bouncing constants (the paper: 10 %).
pub const DEFAULT_REL_SIGMA_SPRINGS: f64 = 0.10;

/// Names accepted for `distribution`, as shown in error messages.
pub const ALLOWED_DISTRIBUTIONS: &str = "gaussian, uniform";

/// Shape of the distribution of a parameter's relative error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Distribution {
    /// Gaussian with standard deviation `rel_sigma`.
    #[default]
    Gaussian,
    /// Uniform on `+/- sqrt(3) rel_sigma` (the same standard deviation).
    Uniform,
}

impl Distribution {
    /// The name used in parameter files and outputs: `gaussian` or `uniform`.
    pub fn name(self) -> &'static str {
        match self {
            Distribution::Gaussian => "gaussian",
            Distribution::Uniform => "uniform",
        }
    }

    /// The distribution called `name` in a parameter file.
    pub fn from_name(name: &str) -> Option<Distribution> {
        match name {
            "gaussian" => Some(Distribution::Gaussian),
            "uniform" => Some(Distribution::Uniform),
            _ => None,
        }
    }

    /// Largest relative standard deviation accepted (exclusive): [`MAX_REL_SIGMA`] or
    /// [`MAX_REL_SIGMA_UNIFORM`].
    pub fn max_rel_sigma(self) -> f64 {
        match self {
            Distribution::Gaussian => MAX_REL_SIGMA,
            Distribution::Uniform => MAX_REL_SIGMA_UNIFORM,
        }
    }

    /// Why larger values are refused, for error messages.
    fn limit_reason(self) -> &'static str {
        match self {
            Distribution::Gaussian => "4 sigma would reach zero",
            Distribution::Uniform => "the range +/- sqrt(3) sigma would reach zero",
        }
    }
}

/// True for the keys whose error is absolute (`sigma` in the key's unit): the `[asymmetry]`
/// offsets, whose nominal value 0 gives a relative error no meaning.
pub fn is_absolute_key(key: &str) -> bool {
    key.starts_with("asymmetry.")
}

/// The error of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// Dotted parameter key, as in the parameter file (e.g. `mass.m_a_kg`).
    pub key: String,
    /// Relative standard deviation (0.025 = 2.5 %), relative to the parameter's own value; 0
    /// for the keys with an absolute error ([`is_absolute_key`]).
    pub rel_sigma: f64,
    /// Absolute standard deviation in the key's unit, for the keys of [`is_absolute_key`]; 0
    /// for every other key.
    pub abs_sigma: f64,
    /// Distribution shape.
    pub distribution: Distribution,
}

impl Uncertainty {
    /// The standard deviation of a parameter of value `value`, in its unit:
    /// `rel_sigma |value| + abs_sigma` (one of the two is 0).
    pub fn sigma_at(&self, value: f64) -> f64 {
        self.rel_sigma * value.abs() + self.abs_sigma
    }

    /// No error: the parameter is exact.
    pub fn is_exact(&self) -> bool {
        self.rel_sigma == 0.0 && self.abs_sigma == 0.0
    }
}

/// An error model that cannot be used. Every message names the key, the value and what is
/// allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum UncertaintyError {
    /// A key that is not a parameter.
    #[error(
        "[uncertainty]: unknown parameter key `{}`; allowed keys: {allowed}",
        Shown(.key)
    )]
    UnknownKey {
        /// The key given.
        key: String,
        /// Every valid key.
        allowed: String,
    },
    /// The same key listed twice.
    #[error(
        "[uncertainty]: parameter `{}` has more than one uncertainty; give each key once",
        Shown(.key)
    )]
    DuplicateKey {
        /// The repeated key.
        key: String,
    },
    /// A relative sigma that is negative or not finite.
    #[error(
        "[uncertainty]: rel_sigma of `{key}` = {rel_sigma} is not allowed: must be finite and >= 0"
    )]
    InvalidSigma {
        /// The parameter.
        key: String,
        /// The value given.
        rel_sigma: f64,
    },
    /// An absolute sigma that is negative or not finite.
    #[error(
        "[uncertainty]: sigma of `{key}` = {sigma:e} is not allowed: must be {} (absolute, in \
         the key's unit; see docs/limits.md)",
        crate::limits::OFFSET_SIGMAS.allowed("")
    )]
    InvalidAbsSigma {
        /// The parameter.
        key: String,
        /// The value given.
        sigma: f64,
    },
    /// A relative sigma so large that draws would be non-physical.
    #[error(
        "[uncertainty]: rel_sigma of `{key}` = {rel_sigma} ({percent} %, {dist}) can make the \
         parameter non-physical ({reason}): must be < {max:.4} ({max_percent:.1} %)",
        percent = rel_sigma * 100.0,
        dist = distribution.name(),
        reason = distribution.limit_reason(),
        max = distribution.max_rel_sigma(),
        max_percent = distribution.max_rel_sigma() * 100.0
    )]
    NonPhysical {
        /// The parameter.
        key: String,
        /// The value given.
        rel_sigma: f64,
        /// Its distribution.
        distribution: Distribution,
    },
    /// A distribution name that is not known.
    #[error(
        "[uncertainty]: distribution of `{key}` = \"{}\" is not known; allowed: {allowed}",
        Shown(.name),
        allowed = ALLOWED_DISTRIBUTIONS
    )]
    UnknownDistribution {
        /// The parameter.
        key: String,
        /// The name given.
        name: String,
    },
    /// An entry that is not `{ rel_sigma = ..., distribution = ... }`.
    #[error(
        "[uncertainty]: entry `{key}`: {message}; expected e.g. {example}",
        key = Shown(.key),
        example = EntryExample(.key)
    )]
    Malformed {
        /// The key of the entry.
        key: String,
        /// What is wrong.
        message: String,
    },
}

/// An example entry for `key` in a message: `sigma` (absolute) for an [asymmetry] key,
/// `rel_sigma` for every other.
struct EntryExample<'a>(&'a str);

impl std::fmt::Display for EntryExample<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let key = Shown(self.0);
        if is_absolute_key(self.0) {
            write!(
                f,
                "`\"{key}\" = {{ sigma = 1e-4, distribution = \"gaussian\" }}` (an [asymmetry] \
                 key's sigma is absolute, in the key's unit)"
            )
        } else {
            write!(
                f,
                "`\"{key}\" = {{ rel_sigma = 0.03, distribution = \"gaussian\" }}` (relative; an \
                 [asymmetry] key takes an absolute `sigma`)"
            )
        }
    }
}

/// The `[uncertainty]` table of a parameter file: the entries that override
/// [`default_uncertainties`]. Validated when read (see [`check`]); empty when the file has none.
///
/// In TOML it is written as one sub-table per key, sorted by key; it reads back unchanged.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct UncertaintyTable {
    /// The entries, at most one per key.
    pub entries: Vec<Uncertainty>,
}

impl UncertaintyTable {
    /// No entry: every parameter has its default error.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// [`check`] against `keys`, the keys of [`Params::fields`].
    pub fn validate(&self, keys: &[&str]) -> Result<(), UncertaintyError> {
        check(&self.entries, keys)
    }
}

/// The keys of [`Params::fields`] (they do not depend on the values), for the deserializer,
/// which has no `Params` at hand. Built from the embedded Table I, which has no `[uncertainty]`
/// table, so building it never comes back here.
fn parameter_keys() -> &'static [&'static str] {
    static KEYS: OnceLock<Vec<&'static str>> = OnceLock::new();
    KEYS.get_or_init(|| Params::table_i().fields().iter().map(|f| f.key).collect())
}

/// Checks an error model: every key is one of `keys` and appears once, every `rel_sigma` is
/// finite, >= 0 and below its distribution's [`Distribution::max_rel_sigma`], every
/// `abs_sigma` finite and >= 0.
pub fn check(list: &[Uncertainty], keys: &[&str]) -> Result<(), UncertaintyError> {
    for (i, u) in list.iter().enumerate() {
        if !keys.contains(&u.key.as_str()) {
            return Err(UncertaintyError::UnknownKey {
                key: u.key.clone(),
                allowed: keys.join(", "),
            });
        }
        if list[..i].iter().any(|v| v.key == u.key) {
            return Err(UncertaintyError::DuplicateKey { key: u.key.clone() });
        }
        if !crate::limits::OFFSET_SIGMAS.admits(u.abs_sigma) {
            return Err(UncertaintyError::InvalidAbsSigma {
                key: u.key.clone(),
                sigma: u.abs_sigma,
            });
        }
        if !(u.rel_sigma.is_finite() && u.rel_sigma >= 0.0) {
            return Err(UncertaintyError::InvalidSigma {
                key: u.key.clone(),
                rel_sigma: u.rel_sigma,
            });
        }
        if u.rel_sigma >= u.distribution.max_rel_sigma() {
            return Err(UncertaintyError::NonPhysical {
                key: u.key.clone(),
                rel_sigma: u.rel_sigma,
                distribution: u.distribution,
            });
        }
    }
    Ok(())
}

/// The default error model, one entry per parameter in [`Params::fields`] order: Gaussian, 2.5 %
/// on every `mass.*`, `inertia.*` (I^a_23 too, relative to its own value) and `length.*` except
/// `length.h_m`; 10 % on `torsion.*` and `bouncing.*`; `rel_sigma = 0` (exact) for
/// `length.h_m`, `environment.g_m_per_s2` and `loss.*` (only g of these enters the modes);
/// `abs_sigma = 0` (exact) for the `[asymmetry]` keys.
pub fn default_uncertainties(params: &Params) -> Vec<Uncertainty> {
    params
        .fields()
        .iter()
        .map(|f| {
            let section = f.key.split('.').next().unwrap_or("");
            let rel_sigma = match section {
                "mass" | "inertia" => DEFAULT_REL_SIGMA_GEOMETRY,
                "length" if f.key != "length.h_m" => DEFAULT_REL_SIGMA_GEOMETRY,
                "torsion" | "bouncing" => DEFAULT_REL_SIGMA_SPRINGS,
                _ => 0.0,
            };
            Uncertainty {
                key: f.key.to_string(),
                rel_sigma,
                abs_sigma: 0.0,
                distribution: Distribution::Gaussian,
            }
        })
        .collect()
}

impl Params {
    /// The effective error model: [`default_uncertainties`] with the entries of the
    /// `[uncertainty]` table replacing the defaults of their keys. One entry per parameter, in
    /// [`Params::fields`] order; exact parameters have `rel_sigma = abs_sigma = 0`.
    pub fn effective_uncertainties(&self) -> Vec<Uncertainty> {
        let mut list = default_uncertainties(self);
        for u in &mut list {
            if let Some(e) = self.uncertainty.entries.iter().find(|e| e.key == u.key) {
                *u = e.clone();
            }
        }
        list
    }

    /// The effective error model as TOML comments (one `# "key" = { ... }` line per parameter
    /// that is not exact, then the exact ones), for `tiltnoise params`.
    pub fn uncertainty_comment(&self) -> String {
        let list = self.effective_uncertainties();
        let mut text = String::from(
            "\n# Effective error model (defaults of tiltnoise, overridden by [uncertainty] above);\n\
             # rel_sigma is the relative standard deviation, uniform is flat on +/- sqrt(3) sigma:\n",
        );
        if list.iter().any(|u| u.abs_sigma > 0.0) {
            text.push_str("# (sigma: the absolute standard deviation of an [asymmetry] offset)\n");
        }
        for u in list.iter().filter(|u| !u.is_exact()) {
            let (name, value) = if is_absolute_key(&u.key) {
                ("sigma", u.abs_sigma)
            } else {
                ("rel_sigma", u.rel_sigma)
            };
            text.push_str(&format!(
                "#   \"{}\" = {{ {name} = {value:?}, distribution = \"{}\" }}\n",
                u.key,
                u.distribution.name()
            ));
        }
        let exact: Vec<&str> = list
            .iter()
            .filter(|u| u.is_exact())
            .map(|u| u.key.as_str())
            .collect();
        if exact.is_empty() {
            return text;
        }
        let mut line = String::from("#   exact:");
        for key in exact {
            if line.len() + key.len() > 96 {
                text.push_str(&line);
                text.push('\n');
                line = String::from("#         ");
            }
            line.push(' ');
            line.push_str(key);
        }
        text.push_str(&line);
        text.push('\n');
        text
    }
}

/// One entry as written in TOML: `sigma` for an absolute key, else `rel_sigma`.
#[derive(Serialize)]
struct EntryOut {
    #[serde(skip_serializing_if = "Option::is_none")]
    rel_sigma: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    sigma: Option<f64>,
    distribution: &'static str,
}

impl Serialize for UncertaintyTable {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut sorted: Vec<&Uncertainty> = self.entries.iter().collect();
        sorted.sort_by(|a, b| a.key.cmp(&b.key));
        let mut map = serializer.serialize_map(Some(sorted.len()))?;
        for u in sorted {
            map.serialize_entry(
                &u.key,
                &EntryOut {
                    rel_sigma: (!is_absolute_key(&u.key)).then_some(u.rel_sigma),
                    sigma: is_absolute_key(&u.key).then_some(u.abs_sigma),
                    distribution: u.distribution.name(),
                },
            )?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for UncertaintyTable {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let table = toml::Table::deserialize(deserializer)?;
        let mut entries = Vec::new();
        flatten("", &table, &mut entries).map_err(|e| D::Error::custom(e.to_string()))?;
        check(&entries, parameter_keys()).map_err(|e| D::Error::custom(e.to_string()))?;
        Ok(UncertaintyTable { entries })
    }
}

/// Collects the entries of `table`, whose keys follow `prefix`: a sub-table with `rel_sigma`,
/// `sigma` or `distribution` is an entry, any other sub-table continues the dotted key (so that the bare
/// dotted key `mass.m_a_kg = {...}` reads like the quoted `"mass.m_a_kg" = {...}`).
fn flatten(
    prefix: &str,
    table: &toml::Table,
    out: &mut Vec<Uncertainty>,
) -> Result<(), UncertaintyError> {
    for (name, value) in table {
        let key = match prefix {
            "" => name.clone(),
            _ => format!("{prefix}.{name}"),
        };
        let malformed = |message: String| UncertaintyError::Malformed {
            key: key.clone(),
            message,
        };
        let toml::Value::Table(t) = value else {
            return Err(malformed(format!("value {value} is not a table")));
        };
        if !["rel_sigma", "sigma", "distribution"]
            .iter()
            .any(|f| t.contains_key(*f))
        {
            flatten(&key, t, out)?;
            continue;
        }
        // An [asymmetry] key's nominal value is 0: its error is absolute.
        let (spread, unit) = if is_absolute_key(&key) {
            ("sigma", " (absolute, in the key's unit)")
        } else {
            ("rel_sigma", "")
        };
        if let Some(field) = t
            .keys()
            .find(|k| k.as_str() != spread && k.as_str() != "distribution")
        {
            return Err(malformed(format!(
                "unknown field `{field}`; allowed fields: {spread}{unit}, distribution"
            )));
        }
        let value = match t.get(spread) {
            Some(toml::Value::Float(x)) => *x,
            Some(toml::Value::Integer(n)) => *n as f64,
            Some(other) => {
                return Err(malformed(format!("{spread} = {other} is not a number")));
            }
            None => return Err(malformed(format!("{spread} is missing"))),
        };
        let (rel_sigma, abs_sigma) = if is_absolute_key(&key) {
            (0.0, value)
        } else {
            (value, 0.0)
        };
        let distribution = match t.get("distribution") {
            None => Distribution::Gaussian,
            Some(toml::Value::String(name)) => Distribution::from_name(name).ok_or_else(|| {
                UncertaintyError::UnknownDistribution {
                    key: key.clone(),
                    name: name.clone(),
                }
            })?,
            Some(other) => {
                return Err(UncertaintyError::UnknownDistribution {
                    key: key.clone(),
                    name: other.to_string(),
                });
            }
        };
        out.push(Uncertainty {
            key,
            rel_sigma,
            abs_sigma,
            distribution,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TABLE: &str = "\n[uncertainty]\n\
        \"mass.m_a_kg\" = { rel_sigma = 0.03, distribution = \"uniform\" }\n\
        \"length.h_m\" = { rel_sigma = 0 }\n\
        torsion.k_b_n_m_per_rad = { rel_sigma = 0.2 }\n";

    fn with_table(table: &str) -> Result<Params, String> {
        Params::from_toml_str(&format!("{}{table}", super::super::TABLE_I_TOML), "t.toml")
            .map_err(|e| e.to_string())
    }

    #[test]
    fn uniform_limit_is_one_over_sqrt_3() {
        assert!((MAX_REL_SIGMA_UNIFORM * 3f64.sqrt() - 1.0).abs() <= f64::EPSILON);
    }

    #[test]
    fn table_overrides_defaults_and_round_trips() {
        let p = with_table(TABLE).unwrap();
        let eff = p.effective_uncertainties();
        assert_eq!(eff.len(), p.fields().len());
        let get = |k: &str| eff.iter().find(|u| u.key == k).unwrap().clone();
        assert_eq!(
            (
                get("mass.m_a_kg").rel_sigma,
                get("mass.m_a_kg").distribution
            ),
            (0.03, Distribution::Uniform)
        );
        assert_eq!(get("length.h_m").rel_sigma, 0.0);
        assert_eq!(get("torsion.k_b_n_m_per_rad").rel_sigma, 0.2);
        // Untouched keys keep their defaults.
        assert_eq!(get("mass.m_b_kg").rel_sigma, DEFAULT_REL_SIGMA_GEOMETRY);
        assert_eq!(get("environment.g_m_per_s2").rel_sigma, 0.0);
        let back = Params::from_toml_str(&p.to_toml(), "round trip").unwrap();
        assert_eq!(back, p);
        // And through --set, which goes through a TOML table.
        assert_eq!(p.with_override("length.d_m=0.15").unwrap(), p);
    }

    #[test]
    fn bad_entries_name_key_value_and_what_is_allowed() {
        let cases = [
            (
                "\"mass.m_c_kg\" = { rel_sigma = 0.01 }",
                &["mass.m_c_kg", "mass.m_a_kg"][..],
            ),
            (
                "\"mass.m_a_kg\" = { rel_sigma = -0.01 }",
                &["mass.m_a_kg", "-0.01", ">= 0"],
            ),
            (
                "\"mass.m_a_kg\" = { rel_sigma = nan }",
                &["mass.m_a_kg", "NaN", ">= 0"],
            ),
            (
                "\"mass.m_a_kg\" = { rel_sigma = 0.25 }",
                &["mass.m_a_kg", "0.25", "< 0.2500", "gaussian"],
            ),
            (
                "\"mass.m_a_kg\" = { rel_sigma = 0.6, distribution = \"uniform\" }",
                &["mass.m_a_kg", "0.6", "< 0.5774", "sqrt(3)"],
            ),
            (
                "\"mass.m_a_kg\" = { rel_sigma = 0.1, distribution = \"lognormal\" }",
                &["mass.m_a_kg", "lognormal", "gaussian, uniform"],
            ),
            (
                "\"mass.m_a_kg\" = { rel_sigma = 0.1, sigma = 2 }",
                &["mass.m_a_kg", "sigma", "rel_sigma, distribution"],
            ),
            (
                "\"mass.m_a_kg\" = { distribution = \"uniform\" }",
                &["mass.m_a_kg", "rel_sigma is missing"],
            ),
            (
                "\"mass.m_a_kg\" = 0.1",
                &["mass.m_a_kg", "0.1", "not a table"],
            ),
        ];
        for (entry, needles) in cases {
            let e = with_table(&format!("\n[uncertainty]\n{entry}\n")).unwrap_err();
            assert!(e.contains("t.toml"), "{e}");
            for n in needles {
                assert!(e.contains(n), "`{n}` missing in: {e}");
            }
        }
        // Just below the limits is accepted.
        assert!(with_table("\n[uncertainty]\n\"mass.m_a_kg\" = { rel_sigma = 0.249 }\n").is_ok());
        assert!(with_table(
            "\n[uncertainty]\n\"mass.m_a_kg\" = { rel_sigma = 0.577, distribution = \"uniform\" }\n"
        )
        .is_ok());
    }

    /// The [asymmetry] keys take an absolute `sigma` (their nominal value is 0), every other
    /// key a `rel_sigma`; each refuses the other's field, names the key and reads back.
    #[test]
    fn asymmetry_keys_take_an_absolute_sigma() {
        let p = with_table(
            "\n[uncertainty]\n\"asymmetry.tm_com_x_m\" = { sigma = 2e-4, distribution = \"uniform\" }\n",
        )
        .unwrap();
        let eff = p.effective_uncertainties();
        let u = eff
            .iter()
            .find(|u| u.key == "asymmetry.tm_com_x_m")
            .unwrap();
        assert_eq!((u.rel_sigma, u.abs_sigma), (0.0, 2e-4));
        assert_eq!(u.sigma_at(0.0), 2e-4);
        assert!(eff
            .iter()
            .filter(|u| is_absolute_key(&u.key) && u.key != "asymmetry.tm_com_x_m")
            .all(|u| u.is_exact()));
        assert!(p.to_toml().contains("sigma = 0.0002"), "{}", p.to_toml());
        assert_eq!(
            Params::from_toml_str(&p.to_toml(), "round trip").unwrap(),
            p
        );
        for (entry, needles) in [
            (
                "\"asymmetry.tm_com_x_m\" = { rel_sigma = 0.1 }",
                &[
                    "asymmetry.tm_com_x_m",
                    "rel_sigma",
                    "allowed fields: sigma",
                    "expected e.g. `\"asymmetry.tm_com_x_m\" = { sigma = 1e-4",
                ][..],
            ),
            (
                "\"mass.m_a_kg\" = { sigma = 0.1 }",
                &[
                    "mass.m_a_kg",
                    "sigma",
                    "allowed fields: rel_sigma",
                    "expected e.g. `\"mass.m_a_kg\" = { rel_sigma = 0.03",
                ],
            ),
            (
                "\"asymmetry.sensor_rot_z_rad\" = { sigma = -1e-3 }",
                &[
                    "asymmetry.sensor_rot_z_rad",
                    "-1e-3",
                    "0 or a value from 1e-20 to 1e0",
                ],
            ),
            (
                "\"asymmetry.tm_com_x_m\" = { sigma = 1e-310 }",
                &[
                    "asymmetry.tm_com_x_m",
                    "1e-310",
                    "0 or a value from 1e-20 to 1e0",
                ],
            ),
            (
                "\"asymmetry.tm_com_x_m\" = { sigma = 2 }",
                &[
                    "asymmetry.tm_com_x_m",
                    "= 2e0",
                    "0 or a value from 1e-20 to 1e0",
                ],
            ),
        ] {
            let e = with_table(&format!("\n[uncertainty]\n{entry}\n")).unwrap_err();
            for n in needles {
                assert!(e.contains(n), "`{n}` missing in: {e}");
            }
            // The example is of the key's own kind: never the field the entry was refused for.
            let refused_example = if entry.contains("asymmetry.") {
                "{ rel_sigma = "
            } else {
                "{ sigma = "
            };
            let example = e.split("expected e.g.").nth(1).unwrap_or("");
            assert!(!example.contains(refused_example), "{e}");
        }
    }

    #[test]
    fn check_refuses_duplicates() {
        let u = Uncertainty {
            key: "mass.m_a_kg".into(),
            rel_sigma: 0.01,
            abs_sigma: 0.0,
            distribution: Distribution::Gaussian,
        };
        let e = check(&[u.clone(), u], parameter_keys()).unwrap_err();
        assert!(matches!(e, UncertaintyError::DuplicateKey { .. }), "{e}");
    }
}
