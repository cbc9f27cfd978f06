//! Metadata shared by the readers: unit strings and the quantity decision.

use super::InputError;
use super::Quantity;
use std::path::Path;
use tiltnoise_core::error::{shown_list, Shown};

/// Accepted unit strings of time-series channels, for messages.
pub(crate) const SERIES_UNITS: &str = "rad, mrad, urad, nrad (angle), rad/s, mrad/s, urad/s, \
     nrad/s (rate), or counts (with a scale factor for the channel)";
/// Accepted unit strings of ASD columns/datasets, for messages.
pub(crate) const ASD_UNITS: &str = "rad/sqrt(Hz) (angle) or rad/s/sqrt(Hz) (rate)";
/// Accepted unit strings of CSD datasets, for messages.
pub(crate) const CSD_UNITS: &str = "rad^2/Hz (angle) or rad^2/s^2/Hz (rate)";

fn normalize(unit: &str) -> String {
    unit.chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_lowercase()
        .replace(['\u{b5}', '\u{3bc}'], "u")
        .replace("**", "^")
        .replace('²', "^2")
        .replace("√hz", "sqrt(hz)")
        .replace("hz^0.5", "sqrt(hz)")
        .replace("hz^(1/2)", "sqrt(hz)")
        .replace("hz(1/2)", "sqrt(hz)")
}

/// What a unit string says of a channel: its quantity (none for digitizer counts) and the
/// factor that turns its values into rad or rad/s (or the spectra's SI units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Unit {
    pub quantity: Option<Quantity>,
    pub factor: f64,
}

impl Unit {
    fn si(quantity: Quantity) -> Unit {
        Unit {
            quantity: Some(quantity),
            factor: 1.0,
        }
    }
}

/// `rad`, `mrad`, `urad` (or `µrad`), `nrad` -> angle; the same over `s` -> rate; `counts` ->
/// no quantity (a scale factor is then required). Case and whitespace are ignored, so gwpy's
/// `nrad / s` is read.
pub(crate) fn series_unit(unit: &str) -> Option<Unit> {
    let n = normalize(unit);
    if matches!(n.as_str(), "counts" | "count" | "ct") {
        return Some(Unit {
            quantity: None,
            factor: 1.0,
        });
    }
    let (angle, quantity) = match n.strip_suffix("/s") {
        Some(a) => (a, Quantity::Rate),
        None => (n.as_str(), Quantity::Angle),
    };
    let factor = match angle {
        "rad" => 1.0,
        "mrad" => 1e-3,
        "urad" => 1e-6,
        "nrad" => 1e-9,
        _ => return None,
    };
    Some(Unit {
        quantity: Some(quantity),
        factor,
    })
}

/// `rad/sqrt(Hz)` -> angle, `rad/s/sqrt(Hz)` -> rate.
pub(crate) fn asd_unit(unit: &str) -> Option<Unit> {
    match normalize(unit).as_str() {
        "rad/sqrt(hz)" => Some(Unit::si(Quantity::Angle)),
        "rad/s/sqrt(hz)" | "rad/(sqrt(hz)s)" => Some(Unit::si(Quantity::Rate)),
        _ => None,
    }
}

/// `rad^2/Hz` -> angle, `rad^2/s^2/Hz` -> rate.
pub(crate) fn csd_unit(unit: &str) -> Option<Unit> {
    match normalize(unit).as_str() {
        "rad^2/hz" | "rad2/hz" => Some(Unit::si(Quantity::Angle)),
        "rad^2/s^2/hz" | "rad2/s2/hz" | "rad2/(hzs2)" => Some(Unit::si(Quantity::Rate)),
        _ => None,
    }
}

/// A declared unit of one channel.
#[derive(Debug, Clone)]
pub(crate) struct Declared {
    pub channel: String,
    pub unit: String,
    /// `None` for digitizer counts.
    pub quantity: Option<Quantity>,
    /// Multiplies the values into rad or rad/s.
    pub factor: f64,
}

/// The factor of each of the `mapped` channels of a series: its unit's prefix (`declared`)
/// times its scale from the options, which channels in counts must have. Appends a note for
/// each factor other than 1.
pub(crate) fn series_factors(
    path: &Path,
    mapped: &[String],
    declared: &[Declared],
    scales: &[super::ChannelScale],
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, InputError> {
    let mut out = Vec::new();
    for c in mapped {
        let d = declared.iter().find(|d| &d.channel == c);
        let mut factor = 1.0;
        if let Some(d) = d.filter(|d| d.factor != 1.0) {
            factor = d.factor;
            notes.push(super::scale_note(
                c,
                d.factor,
                &format!(
                    "units `{}` to {}",
                    d.unit,
                    d.quantity.map_or("", |q| q.unit())
                ),
            ));
        }
        match (
            super::scale_for(scales, c),
            d.is_some_and(|d| d.quantity.is_none()),
        ) {
            (Some(s), _) => {
                factor *= s;
                notes.push(super::scale_note(c, s, "given explicitly"));
            }
            (None, true) => {
                return Err(InputError::Scale {
                    path: path.to_path_buf(),
                    channel: c.clone(),
                    message: "is in counts; allowed: give a scale CHANNEL=FACTOR with the rad \
                              or rad/s per count of the instrument's response"
                        .to_string(),
                })
            }
            (None, false) => {}
        }
        out.push(factor);
    }
    Ok(out)
}

/// Decides the quantity from the override and the declared units of the mapped channels
/// (`undeclared`: mapped channels without a unit), appending provenance notes.
pub(crate) fn decide_quantity(
    path: &Path,
    override_q: Option<Quantity>,
    declared: &[Declared],
    undeclared: &[String],
    notes: &mut Vec<String>,
) -> Result<Quantity, InputError> {
    // Channels in counts declare no quantity: they take the others'.
    let mut undeclared = undeclared.to_vec();
    undeclared.extend(
        declared
            .iter()
            .filter(|d| d.quantity.is_none())
            .map(|d| d.channel.clone()),
    );
    let declared: Vec<(&Declared, Quantity)> = declared
        .iter()
        .filter_map(|d| d.quantity.map(|q| (d, q)))
        .collect();
    let from_file = declared.first().copied();
    if let (Some((first, q)), None) = (from_file, override_q) {
        if let Some((other, oq)) = declared.iter().find(|(_, oq)| *oq != q) {
            return Err(InputError::MixedQuantity {
                path: path.to_path_buf(),
                channel_a: first.channel.clone(),
                unit_a: q.unit(),
                channel_b: other.channel.clone(),
                unit_b: oq.unit(),
            });
        }
    }
    match (override_q, from_file) {
        (Some(q), _) => {
            notes.push(format!(
                "quantity: {} ({}) given explicitly",
                q.name(),
                q.unit()
            ));
            for (d, _) in declared.iter().filter(|(_, dq)| *dq != q) {
                notes.push(format!(
                    "the explicit quantity {} overrides the file's units `{}` of channel `{}`",
                    q.name(),
                    Shown(&d.unit),
                    Shown(&d.channel)
                ));
            }
            if q == Quantity::Rate {
                notes.push(RATE_NOTE.to_string());
            }
            Ok(q)
        }
        (None, Some((d, q))) => {
            notes.push(format!(
                "quantity: {} (from the file's units `{}`)",
                q.name(),
                d.unit
            ));
            if !undeclared.is_empty() {
                notes.push(format!(
                    "channels without units, assumed {}: {}",
                    q.name(),
                    shown_list(&undeclared)
                ));
            }
            if q == Quantity::Rate {
                notes.push(RATE_NOTE.to_string());
            }
            Ok(q)
        }
        (None, None) => {
            notes.push(
                "quantity: not given in the file or the options; assumed angle (rad)".to_string(),
            );
            Ok(Quantity::Angle)
        }
    }
}

/// How a rate is turned into angle (`tiltnoise_core::input::rate`), for the provenance.
const RATE_NOTE: &str = "rate to angle: spectra divided by (2 pi f)^2 at every f > 0, exact \
     up to Nyquist (a series' samples stay in rad/s, nothing is integrated in time); f = 0 \
     carries no angle information and is excluded";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units() {
        let q = |u: &str| series_unit(u).map(|u| (u.quantity, u.factor));
        assert_eq!(q(" RAD/s "), Some((Some(Quantity::Rate), 1.0)));
        assert_eq!(q("rad"), Some((Some(Quantity::Angle), 1.0)));
        assert_eq!(q("nrad / s"), Some((Some(Quantity::Rate), 1e-9)));
        assert_eq!(q("µrad"), Some((Some(Quantity::Angle), 1e-6)));
        assert_eq!(q("urad/s"), Some((Some(Quantity::Rate), 1e-6)));
        assert_eq!(q("mrad"), Some((Some(Quantity::Angle), 1e-3)));
        assert_eq!(q("counts"), Some((None, 1.0)));
        assert_eq!(q("deg"), None);
        assert_eq!(q("krad"), None);
        assert_eq!(q("rad/s/s"), None);
        let a = |u: &str| asd_unit(u).and_then(|u| u.quantity);
        let c = |u: &str| csd_unit(u).and_then(|u| u.quantity);
        assert_eq!(a("rad/√Hz"), Some(Quantity::Angle));
        assert_eq!(a("rad / Hz(1/2)"), Some(Quantity::Angle));
        assert_eq!(a("rad/s/sqrt(Hz)"), Some(Quantity::Rate));
        // astropy's text of the units gwpy writes
        assert_eq!(a("rad / (Hz(1/2) s)"), Some(Quantity::Rate));
        assert_eq!(c("rad2 / Hz"), Some(Quantity::Angle));
        assert_eq!(c("rad2 / (Hz s2)"), Some(Quantity::Rate));
        assert_eq!(c("rad²/Hz"), Some(Quantity::Angle));
        assert_eq!(c("rad**2/s**2/Hz"), Some(Quantity::Rate));
    }
}
