//! [`TermKind`]: what a noise term of a budget is, in the spirit of pygwinc's `Noise` /
//! `Budget`: the kind decides whether the term adds to the total, which group it belongs to and
//! the key under which the files store it; its unit is the observable's.

use crate::model::{Observable, TiltAxis};
use std::fmt;

/// The kind of a term of an observable's budget.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum TermKind {
    /// Floor tilt through the transfer functions, every axis with its cross-spectra.
    Tilt,
    /// One tilt axis alone, `|H_oi|^2 S_ii`: a diagnostic breakdown of [`TermKind::Tilt`] (it
    /// does not add up to it when the axes are correlated); not part of the total.
    TiltAxis(TiltAxis),
    /// The witness instruments' own noise through the model, `sum_i |H_oi|^2 S_nn,i`: the
    /// part of [`TermKind::Tilt`] that is the tiltmeter's noise, not the floor's motion (the
    /// tilt term, computed from the witness record, already contains it); not part of the
    /// total.
    WitnessNoise,
    /// Readout (sensing) noise of the observable.
    Readout,
    /// Thermal noise of every dissipative element together (fluctuation-dissipation theorem).
    Thermal,
    /// Thermal noise of one dissipative element (`torsion_b`, `swing_a_viscous`, ...): a
    /// breakdown of [`TermKind::Thermal`], not part of the total.
    ThermalElement(String),
    /// The user-named terms together (independent: their sum in power).
    User,
    /// One user-named term (an ASD of the observable, or an input noise through the model): a
    /// breakdown of [`TermKind::User`], not part of the total.
    UserNamed(String),
    /// A measured spectrum of the observable, for comparison: not part of the model's total.
    Measured,
    /// `measured - total` in power, clipped at 0: what the model does not explain.
    Residual,
}

/// The groups a budget's terms are drawn and stored in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TermGroup {
    /// [`TermKind::Tilt`], its per-axis breakdown and the witness noise in it.
    Tilt,
    /// [`TermKind::Readout`].
    Readout,
    /// [`TermKind::Thermal`] and its per-element breakdown.
    Thermal,
    /// [`TermKind::User`] and the user-named terms.
    User,
    /// [`TermKind::Measured`] and [`TermKind::Residual`]: data, not model.
    Measured,
}

impl TermKind {
    /// The key of the term in the budget files (`tilt`, `tilt.eta_t`, `witness_noise`,
    /// `readout`, `thermal`, `thermal.torsion_b`, `user`, `user.<name>`, `measured`,
    /// `residual`); see
    /// `docs/schemas.md`.
    pub fn name(&self) -> String {
        match self {
            TermKind::Tilt => "tilt".into(),
            TermKind::TiltAxis(a) => format!("tilt.{}", a.name()),
            TermKind::WitnessNoise => "witness_noise".into(),
            TermKind::Readout => "readout".into(),
            TermKind::Thermal => "thermal".into(),
            TermKind::ThermalElement(e) => format!("thermal.{e}"),
            TermKind::User => "user".into(),
            TermKind::UserNamed(n) => format!("user.{n}"),
            TermKind::Measured => "measured".into(),
            TermKind::Residual => "residual".into(),
        }
    }

    /// The kind stored under `name` in a budget file ([`TermKind::name`]), if any.
    pub fn from_name(name: &str) -> Option<TermKind> {
        Some(match name {
            "tilt" => TermKind::Tilt,
            "witness_noise" => TermKind::WitnessNoise,
            "readout" => TermKind::Readout,
            "thermal" => TermKind::Thermal,
            "user" => TermKind::User,
            "measured" => TermKind::Measured,
            "residual" => TermKind::Residual,
            _ => {
                if let Some(axis) = name.strip_prefix("tilt.") {
                    TermKind::TiltAxis(TiltAxis::ALL.into_iter().find(|a| a.name() == axis)?)
                } else if let Some(user) = name.strip_prefix("user.") {
                    if !is_term_name(user) {
                        return None;
                    }
                    TermKind::UserNamed(user.to_string())
                } else {
                    let element = name.strip_prefix("thermal.")?;
                    if element.is_empty() {
                        return None;
                    }
                    TermKind::ThermalElement(element.to_string())
                }
            }
        })
    }

    /// Whether the term is an independent noise of the model that adds in power to the total.
    /// Breakdowns (one tilt axis, one thermal element) and data (measured, residual) do not.
    pub fn in_total(&self) -> bool {
        matches!(
            self,
            TermKind::Tilt | TermKind::Readout | TermKind::Thermal | TermKind::User
        )
    }

    /// Whether the term is a noise the model predicts (everything but measured and residual):
    /// the terms referred to the equivalent input by a [`super::Calibration`].
    pub fn is_model(&self) -> bool {
        !matches!(self, TermKind::Measured | TermKind::Residual)
    }

    /// The group of the term.
    pub fn group(&self) -> TermGroup {
        match self {
            TermKind::Tilt | TermKind::TiltAxis(_) | TermKind::WitnessNoise => TermGroup::Tilt,
            TermKind::Readout => TermGroup::Readout,
            TermKind::Thermal | TermKind::ThermalElement(_) => TermGroup::Thermal,
            TermKind::User | TermKind::UserNamed(_) => TermGroup::User,
            TermKind::Measured | TermKind::Residual => TermGroup::Measured,
        }
    }

    /// The unit of the term's ASD for observable `o`: the observable's unit per sqrt(Hz) (its
    /// PSD is in the square of that).
    pub fn asd_unit(&self, o: Observable) -> String {
        format!("{}/sqrt(Hz)", o.unit())
    }
}

impl TermGroup {
    /// `tilt`, `readout`, `thermal`, `user` or `measured`: the attribute `group` of a term in
    /// the budget files.
    pub fn name(self) -> &'static str {
        match self {
            TermGroup::Tilt => "tilt",
            TermGroup::Readout => "readout",
            TermGroup::Thermal => "thermal",
            TermGroup::User => "user",
            TermGroup::Measured => "measured",
        }
    }
}

/// Whether `name` can name a user term: 1 to 64 ASCII letters, digits or `_`, starting with a
/// letter (a file key: no `.`, `/`, `,` or spaces).
pub fn is_term_name(name: &str) -> bool {
    (1..=64).contains(&name.len())
        && name.starts_with(|c: char| c.is_ascii_alphabetic())
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// One curve of an observable's budget: a term, or the computed total.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Component {
    /// A term of the budget.
    Term(TermKind),
    /// The sum in power of the terms that add to the total ([`TermKind::in_total`]).
    Total,
}

impl Component {
    /// The key in the budget files: the term's [`TermKind::name`], or `total`.
    pub fn name(&self) -> String {
        match self {
            Component::Term(k) => k.name(),
            Component::Total => super::TOTAL_NAME.to_string(),
        }
    }
}

impl fmt::Display for TermKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        let kinds = [
            TermKind::Tilt,
            TermKind::TiltAxis(TiltAxis::EtaT),
            TermKind::WitnessNoise,
            TermKind::Readout,
            TermKind::Thermal,
            TermKind::ThermalElement("swing_a_viscous".into()),
            TermKind::User,
            TermKind::UserNamed("magnetic_2".into()),
            TermKind::Measured,
            TermKind::Residual,
        ];
        for k in kinds {
            assert_eq!(TermKind::from_name(&k.name()), Some(k.clone()), "{k}");
        }
        assert_eq!(TermKind::from_name("total"), None);
        assert_eq!(TermKind::from_name("tilt.x"), None);
        assert_eq!(TermKind::from_name("thermal."), None);
        assert_eq!(TermKind::from_name("user."), None);
        assert_eq!(TermKind::from_name("user.a.b"), None);
    }

    #[test]
    fn only_independent_noises_add_to_the_total() {
        assert!(TermKind::Tilt.in_total() && TermKind::Readout.in_total());
        assert!(TermKind::Thermal.in_total() && TermKind::User.in_total());
        assert!(!TermKind::UserNamed("actuation".into()).in_total());
        assert!(!TermKind::TiltAxis(TiltAxis::ThetaT).in_total());
        assert!(!TermKind::WitnessNoise.in_total());
        assert!(!TermKind::ThermalElement("torsion_b".into()).in_total());
        assert!(!TermKind::Measured.in_total() && !TermKind::Residual.in_total());
    }
}
