//! The parameters of the coupling fit: a gain per witness input (the instrument's
//! calibration), a delay, the parameter-file keys of `--fit`, and a scale of each witness noise
//! level whose uncertainty is stated; their boxes, scales and internal variables.

use super::SubtractError;
use crate::fit::jacobian::with_value;
use crate::params::uncertainty::is_absolute_key;
use crate::params::Params;

/// Half-width of the box of a gain, in its logarithm: the gain stays within `[1/2, 2]`.
pub const GAIN_LN_HALF_WIDTH: f64 = std::f64::consts::LN_2;
/// Scale of a gain: not constrained when its uncertainty is 10 % or more.
pub const GAIN_SCALE: f64 = 0.1;
/// Half-widths of the box of a model parameter tried in turn, relative to its nominal value:
/// the first whose edges are physical is used.
pub const KEY_HALF_WIDTHS: [f64; 4] = [0.75, 0.5, 0.2, 0.1];
/// Scale of a model parameter the error model calls exact, relative to its value.
pub const EXACT_KEY_SCALE: f64 = 0.1;
/// Relative step of the central differences of the transfer functions in a model parameter:
/// `eps^(1/3)`, which balances truncation against rounding.
pub const KEY_STEP_REL: f64 = 6.055_454_452_393_343e-6;
/// Half-width of the box of a noise scale's logarithm, in units of its stated relative
/// uncertainty (and at most [`NOISE_LN_MAX_HALF_WIDTH`]).
pub const NOISE_BOX_SIGMAS: f64 = 5.0;
/// Largest half-width of the box of a noise scale's logarithm: the scale stays within
/// `[1/4, 4]`.
pub const NOISE_LN_MAX_HALF_WIDTH: f64 = 1.386_294_361_119_890_6;

/// Parameter files' sections whose keys `subtract` may fit: everything that shapes the
/// undamped transfer functions from the floor.
pub const FREE_SECTIONS: [&str; 6] = [
    "mass",
    "inertia",
    "torsion",
    "bouncing",
    "length",
    "asymmetry",
];
/// Half-widths of the box of an assembly offset tried in turn, in units of its absolute error
/// bar from the parameter file: the first whose edges are physical is used.
pub const OFFSET_HALF_WIDTH_SIGMAS: [f64; 3] = [3.0, 2.0, 1.0];
/// The one environment key that may be fitted.
pub const FREE_ENVIRONMENT_KEY: &str = "environment.g_m_per_s2";

/// What a parameter is.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Kind {
    /// The gain of witness input `a`; internal variable `ln g`.
    Gain(usize),
    /// The delay (s).
    Delay,
    /// A parameter-file key, in its own unit.
    Key(String),
    /// The scale of witness input `a`'s noise ASD; internal variable its logarithm, with a
    /// Gaussian prior of standard deviation the stated relative uncertainty.
    NoiseScale(usize),
}

/// One candidate parameter.
#[derive(Debug, Clone)]
pub(crate) struct Param {
    pub kind: Kind,
    pub name: String,
    pub unit: String,
    /// Internal variable (ln g, tau, p, ln scale) at the nominal value.
    pub nominal: f64,
    /// Half-width of the box around `nominal`, internal units.
    pub half_width: f64,
    /// Scale in internal units.
    pub scale: f64,
    /// Standard deviation of a Gaussian prior at `nominal` (internal units), if any: a noise
    /// scale's stated uncertainty, a key's error bar from the parameter file, or the scale of
    /// a key the data do not constrain.
    pub prior: Option<f64>,
}

impl Param {
    /// The gain of witness input `a` named `input_name`.
    pub fn gain(a: usize, input_name: &str) -> Param {
        Param {
            kind: Kind::Gain(a),
            name: format!("gain.{input_name}"),
            unit: "1".into(),
            nominal: 0.0,
            half_width: GAIN_LN_HALF_WIDTH,
            scale: GAIN_SCALE,
            prior: None,
        }
    }

    /// The delay, within `+-max_delay_s`, on a scale of one sample `dt`.
    pub fn delay(max_delay_s: f64, dt: f64) -> Param {
        Param {
            kind: Kind::Delay,
            name: "delay_s".into(),
            unit: "s".into(),
            nominal: 0.0,
            half_width: max_delay_s,
            scale: dt,
            prior: None,
        }
    }

    /// The noise scale of witness input `a` named `input_name`, uncertain by `rel`.
    pub fn noise_scale(a: usize, input_name: &str, rel: f64) -> Param {
        Param {
            kind: Kind::NoiseScale(a),
            name: format!("noise_scale.{input_name}"),
            unit: "1".into(),
            nominal: 0.0,
            half_width: (NOISE_BOX_SIGMAS * rel).min(NOISE_LN_MAX_HALF_WIDTH),
            scale: rel,
            prior: Some(rel),
        }
    }

    /// Whether the parameter is a multiplicative factor fitted in its logarithm.
    pub fn is_logarithmic(&self) -> bool {
        matches!(self.kind, Kind::Gain(_) | Kind::NoiseScale(_))
    }
}

/// Checks the keys of `--fit` and builds their parameters.
pub(crate) fn key_params(base: &Params, keys: &[String]) -> Result<Vec<Param>, SubtractError> {
    let fields = base.fields();
    let allowed = allowed_keys(base).join(", ");
    let sigmas = base.effective_uncertainties();
    let mut out: Vec<Param> = Vec::new();
    for key in keys {
        let Some(field) = fields.iter().find(|f| f.key == key) else {
            return Err(SubtractError::UnknownKey {
                key: key.clone(),
                allowed,
            });
        };
        if !allowed_keys(base).contains(&field.key) {
            return Err(SubtractError::NotFreeKey {
                key: key.clone(),
                reason: not_free_reason(field.key, field.value),
                allowed,
            });
        }
        if out.iter().any(|p| &p.name == key) {
            return Err(SubtractError::DuplicateKey { key: key.clone() });
        }
        let p0 = field.value;
        if is_absolute_key(key) {
            out.push(offset_param(base, key, p0, field.unit, &sigmas, &allowed)?);
            continue;
        }
        let half_width = KEY_HALF_WIDTHS
            .iter()
            .map(|h| h * p0.abs())
            .find(|&hw| {
                [p0 - hw, p0 + hw].iter().all(|&edge| {
                    with_value(base, key, edge).is_ok() && edge.signum() == p0.signum()
                })
            })
            .ok_or_else(|| SubtractError::NotFreeKey {
                key: key.clone(),
                reason: format!(
                    "even +/-{} % of its value {} {} reaches non-physical values",
                    KEY_HALF_WIDTHS[KEY_HALF_WIDTHS.len() - 1] * 100.0,
                    p0,
                    field.unit
                ),
                allowed: allowed.clone(),
            })?;
        let rel = sigmas
            .iter()
            .find(|u| u.key == *key)
            .map_or(0.0, |u| u.rel_sigma);
        let scale = if rel > 0.0 { rel } else { EXACT_KEY_SCALE } * p0.abs();
        out.push(Param {
            kind: Kind::Key(key.clone()),
            name: key.clone(),
            unit: field.unit.to_string(),
            nominal: p0,
            half_width,
            scale,
            // An error bar of the parameter file is what is known of the key before the data:
            // its prior. A key the file calls exact has none (unless the data cannot
            // constrain it, see `estimate`).
            prior: (rel > 0.0).then_some(scale),
        });
    }
    Ok(out)
}

/// Keys `--fit` accepts for `params`: those of [`FREE_SECTIONS`] and [`FREE_ENVIRONMENT_KEY`]
/// with a non-zero value.
pub fn allowed_keys(params: &Params) -> Vec<&'static str> {
    params
        .fields()
        .iter()
        .filter(|f| {
            let section = f.key.split('.').next().unwrap_or("");
            (FREE_SECTIONS.contains(&section) || f.key == FREE_ENVIRONMENT_KEY)
                && (f.value != 0.0 || is_absolute_key(f.key))
        })
        .map(|f| f.key)
        .collect()
}

/// The parameter of an assembly offset (`asymmetry.*`, nominal usually 0): its scale and prior
/// are the absolute error bar of the parameter file, which it must have; its box the largest of
/// [`OFFSET_HALF_WIDTH_SIGMAS`] error bars whose edges stay within the body.
fn offset_param(
    base: &Params,
    key: &str,
    p0: f64,
    unit: &str,
    sigmas: &[crate::params::uncertainty::Uncertainty],
    allowed: &str,
) -> Result<Param, SubtractError> {
    let sigma = sigmas
        .iter()
        .find(|u| u.key == key)
        .map_or(0.0, |u| u.abs_sigma);
    let not_free = |reason: String| SubtractError::NotFreeKey {
        key: key.to_string(),
        reason,
        allowed: allowed.to_string(),
    };
    if sigma <= 0.0 || !sigma.is_finite() {
        return Err(not_free(format!(
            "an assembly offset is fitted within its error bar, and the parameter file gives it \
             none (give an absolute sigma in {unit} in [uncertainty], e.g. \
             \"{key}\" = {{ sigma = 1e-3 }})"
        )));
    }
    let half_width = OFFSET_HALF_WIDTH_SIGMAS
        .iter()
        .map(|k| k * sigma)
        .find(|&hw| {
            [p0 - hw, p0 + hw]
                .iter()
                .all(|&edge| with_value(base, key, edge).is_ok())
        })
        .ok_or_else(|| {
            not_free(format!(
                "even +/-1 error bar ({sigma} {unit}) around {p0} {unit} leaves the body"
            ))
        })?;
    Ok(Param {
        kind: Kind::Key(key.to_string()),
        name: key.to_string(),
        unit: unit.to_string(),
        nominal: p0,
        half_width,
        scale: sigma,
        prior: Some(sigma),
    })
}

fn not_free_reason(key: &str, value: f64) -> String {
    let section = key.split('.').next().unwrap_or("");
    match section {
        "loss" | "viscous" => "damping is not estimated by subtract (its transfer functions are \
                               fitted with the model's damping held fixed)"
            .to_string(),
        "environment" => "it does not enter the tilt transfer functions".to_string(),
        _ if value == 0.0 => "its nominal value is 0, so it has no scale to fit".to_string(),
        _ => "it is not a parameter of the tilt transfer functions".to_string(),
    }
}
