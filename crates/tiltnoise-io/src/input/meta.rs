//! Metadata shared by the readers: unit strings and the quantity decision.

use std::path::Path;
use tiltnoise_core::error::{shown_list, Shown};
use tiltnoise_core::input::normalize_unit as normalize;
use tiltnoise_core::input::InputError;
use tiltnoise_core::input::Quantity;

/// Accepted unit strings of ASD columns/datasets, for messages.
pub(crate) const ASD_UNITS: &str = "rad/sqrt(Hz) (angle) or rad/s/sqrt(Hz) (rate)";
/// Accepted unit strings of CSD datasets, for messages.
pub(crate) const CSD_UNITS: &str = "rad^2/Hz (angle) or rad^2/s^2/Hz (rate)";

/// What the unit string of a spectrum says: its quantity (the spectra are read in SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SpectrumUnit {
    pub quantity: Option<Quantity>,
}

impl SpectrumUnit {
    fn si(quantity: Quantity) -> SpectrumUnit {
        SpectrumUnit {
            quantity: Some(quantity),
        }
    }
}

/// `rad/sqrt(Hz)` -> angle, `rad/s/sqrt(Hz)` -> rate.
pub(crate) fn asd_unit(unit: &str) -> Option<SpectrumUnit> {
    match normalize(unit).as_str() {
        "rad/sqrt(hz)" => Some(SpectrumUnit::si(Quantity::Angle)),
        "rad/s/sqrt(hz)" | "rad/(sqrt(hz)s)" => Some(SpectrumUnit::si(Quantity::Rate)),
        _ => None,
    }
}

/// `rad^2/Hz` -> angle, `rad^2/s^2/Hz` -> rate.
pub(crate) fn csd_unit(unit: &str) -> Option<SpectrumUnit> {
    match normalize(unit).as_str() {
        "rad^2/hz" | "rad2/hz" => Some(SpectrumUnit::si(Quantity::Angle)),
        "rad^2/s^2/hz" | "rad2/s2/hz" | "rad2/(hzs2)" => Some(SpectrumUnit::si(Quantity::Rate)),
        _ => None,
    }
}

/// A declared unit of one tilt channel.
#[derive(Debug, Clone)]
pub(crate) struct Declared {
    pub channel: String,
    pub unit: String,
    /// `None` for digitizer counts.
    pub quantity: Option<Quantity>,
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
