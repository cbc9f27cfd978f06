//! [`TermKind`]: what a noise term of a budget is, in the spirit of pygwinc's `Noise` /
//! `Budget`: the kind decides whether the term adds to the total, which group it belongs to and
//! the key under which the files store it; its unit is the observable's.

use crate::model::{Observable, TiltAxis, TranslationAxis};
use std::fmt;

/// The kind of a term of an observable's budget.
#[derive(Debug, Clone, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum TermKind {
    /// Floor tilt through the transfer functions, every tilt axis with its cross-spectra (the
    /// rotations alone).
    Tilt,
    /// One tilt axis alone, `|H_oi|^2 S_ii`: a diagnostic breakdown of [`TermKind::Tilt`] (it
    /// does not add up to it when the axes are correlated); not part of the total.
    TiltAxis(TiltAxis),
    /// Floor translation through the transfer functions, every translation axis with its
    /// cross-spectra (the translations alone).
    Translation,
    /// One translation axis alone: a diagnostic breakdown of [`TermKind::Translation`].
    TranslationAxis(TranslationAxis),
    /// The floor's whole motion, tilt and translation with every cross-spectrum between them
    /// (`H S H^H` over all the inputs): when a record has both, this term adds to the total and
    /// [`TermKind::Tilt`] and [`TermKind::Translation`] are its breakdown (never added in
    /// quadrature: tilt and floor acceleration are correlated, and act alike at low frequency).
    Ground,
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
    /// [`TermKind::Translation`] and its per-axis breakdown.
    Translation,
    /// [`TermKind::Ground`].
    Ground,
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
    /// The key of the term in the budget files (`tilt`, `tilt.eta_t`, `translation`,
    /// `translation.x_t`, `ground`, `witness_noise`, `readout`, `thermal`, `thermal.torsion_b`,
    /// `user`, `user.<name>`, `measured`, `residual`); see `docs/schemas.md`.
    pub fn name(&self) -> String {
        match self {
            TermKind::Tilt => "tilt".into(),
            TermKind::TiltAxis(a) => format!("tilt.{}", a.name()),
            TermKind::Translation => "translation".into(),
            TermKind::TranslationAxis(t) => format!("translation.{}", t.name()),
            TermKind::Ground => "ground".into(),
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
            "translation" => TermKind::Translation,
            "ground" => TermKind::Ground,
            "witness_noise" => TermKind::WitnessNoise,
            "readout" => TermKind::Readout,
            "thermal" => TermKind::Thermal,
            "user" => TermKind::User,
            "measured" => TermKind::Measured,
            "residual" => TermKind::Residual,
            _ => {
                if let Some(axis) = name.strip_prefix("tilt.") {
                    TermKind::TiltAxis(TiltAxis::ALL.into_iter().find(|a| a.name() == axis)?)
                } else if let Some(axis) = name.strip_prefix("translation.") {
                    TermKind::TranslationAxis(
                        TranslationAxis::ALL
                            .into_iter()
                            .find(|a| a.name() == axis)?,
                    )
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

    /// Whether the term is an independent noise of the model that adds in power to the total
    /// of a budget that has (`with_ground`) or has not a [`TermKind::Ground`] term: the
    /// readout, thermal and user terms, and the one term of the floor's motion that holds all
    /// its inputs with their cross-spectra, `ground` when the record has tilt and translation,
    /// else `tilt` or `translation`. Breakdowns (`tilt` and `translation` beside `ground`, one
    /// axis, one thermal element) and data (measured, residual) do not.
    pub fn adds_to_total(&self, with_ground: bool) -> bool {
        match self {
            TermKind::Ground | TermKind::Readout | TermKind::Thermal | TermKind::User => true,
            TermKind::Tilt | TermKind::Translation => !with_ground,
            _ => false,
        }
    }

    /// Whether the term is one of the floor's motion: tilt, translation or ground, or one axis
    /// of them (the terms estimated from the record, read at a frequency as band means; not
    /// the witness noise, a given spectrum).
    pub fn is_ground_motion(&self) -> bool {
        *self != TermKind::WitnessNoise
            && matches!(
                self.group(),
                TermGroup::Tilt | TermGroup::Translation | TermGroup::Ground
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
            TermKind::Translation | TermKind::TranslationAxis(_) => TermGroup::Translation,
            TermKind::Ground => TermGroup::Ground,
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
    /// `tilt`, `translation`, `ground`, `readout`, `thermal`, `user` or `measured`: the
    /// attribute `group` of a term in the budget files.
    pub fn name(self) -> &'static str {
        match self {
            TermGroup::Tilt => "tilt",
            TermGroup::Translation => "translation",
            TermGroup::Ground => "ground",
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
    /// The sum in power of the terms that add to the total ([`TermKind::adds_to_total`]).
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
            TermKind::Translation,
            TermKind::TranslationAxis(TranslationAxis::ZT),
            TermKind::Ground,
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
        assert_eq!(TermKind::from_name("translation.theta_t"), None);
        assert_eq!(TermKind::from_name("thermal."), None);
        assert_eq!(TermKind::from_name("user."), None);
        assert_eq!(TermKind::from_name("user.a.b"), None);
    }

    #[test]
    fn only_independent_noises_add_to_the_total() {
        for with_ground in [false, true] {
            let adds = |k: TermKind| k.adds_to_total(with_ground);
            assert!(adds(TermKind::Readout) && adds(TermKind::Thermal) && adds(TermKind::User));
            assert!(!adds(TermKind::UserNamed("actuation".into())));
            assert!(!adds(TermKind::TiltAxis(TiltAxis::ThetaT)));
            assert!(!adds(TermKind::WitnessNoise));
            assert!(!adds(TermKind::TranslationAxis(TranslationAxis::XT)));
            assert!(!adds(TermKind::ThermalElement("torsion_b".into())));
            assert!(!adds(TermKind::Measured) && !adds(TermKind::Residual));
        }
        // The floor's motion adds once: tilt or translation alone, or ground, never both.
        assert!(TermKind::Tilt.adds_to_total(false) && TermKind::Translation.adds_to_total(false));
        assert!(!TermKind::Tilt.adds_to_total(true) && !TermKind::Translation.adds_to_total(true));
        assert!(TermKind::Ground.adds_to_total(true));
    }
}
