//! Names and options as a user gives them, parsed and checked once for every front end: the
//! command line (`--input F_b.x,M_b.z`, `--readout X=9e-9`) and the Python package
//! (`inputs=["F_b.x", "M_b.z"]`, `readout={"X": 9e-9}`) call these functions and so say the
//! same thing about the same mistake. A message starts with the option, an [`OptionKey`] the
//! front end in use spells (`--readout`, `readout`), then the value given and what is allowed.

use crate::error::{Num, Shown};
use crate::limits::{LimitError, ASDS};
use crate::model::{ForceInput, Input, Observable};
use crate::noise::Readout;
use crate::option_key::{Message, OptionKey};
use crate::repeats::{refuse_repeats, Repeated};

/// A name or option value that is not allowed; the message names the option, the value and
/// what is allowed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptionError {
    /// An empty name in a comma-separated list.
    #[error("{option} \"{}\": empty name in the list (names are separated by single commas)", Shown(.spec))]
    EmptyName {
        /// The option.
        option: OptionKey,
        /// The list given.
        spec: String,
    },
    /// A name that is no input.
    #[error("{option}: unknown input \"{}\"; allowed: {}", Shown(.name), input_names())]
    UnknownInput {
        /// The option.
        option: OptionKey,
        /// The name given.
        name: String,
    },
    /// A name that is no observable.
    #[error("{option}: unknown observable \"{}\"; allowed: {}", Shown(.name), observable_names())]
    UnknownObservable {
        /// The option.
        option: OptionKey,
        /// The name given.
        name: String,
    },
    /// A key or name given twice (also through a group).
    #[error(transparent)]
    Repeated(#[from] Repeated),
    /// A readout item that is not `OBS=ASD`.
    #[error("{option} {}: expected OBS=ASD, e.g. X=9e-9", Shown(.item))]
    ReadoutSyntax {
        /// The option.
        option: OptionKey,
        /// The item given.
        item: String,
    },
    /// A readout item whose observable is unknown.
    #[error("{option} {}: unknown observable `{}`; allowed: {}", Shown(.item), Shown(.name), observable_names())]
    ReadoutObservable {
        /// The option.
        option: OptionKey,
        /// The item given.
        item: String,
        /// The observable's name given.
        name: String,
    },
    /// A value that does not parse as a number.
    #[error("{option} {}: `{}` is not a number", Shown(.item), Shown(.value))]
    NotANumber {
        /// The option.
        option: OptionKey,
        /// The item given.
        item: String,
        /// The value's text.
        value: String,
    },
    /// A readout ASD that is negative, not finite, or outside [`ASDS`] (its PSD would overflow
    /// or underflow).
    #[error(
        "{option} {}: ASD {} {unit}/sqrt(Hz) is not allowed: must be {} (see docs/limits.md)",
        Shown(.item),
        Num(*.asd),
        ASDS.allowed(&format!("{unit}/sqrt(Hz)"))
    )]
    ReadoutAsd {
        /// The option.
        option: OptionKey,
        /// The item given.
        item: String,
        /// The ASD given.
        asd: f64,
        /// The observable's unit.
        unit: &'static str,
    },
    /// A readout on an observable the budget does not compute.
    #[error("{option} {name}=...: {name} is not budgeted; allowed: {allowed}")]
    NotBudgeted {
        /// The option.
        option: OptionKey,
        /// The observable.
        name: &'static str,
        /// The budgeted observables, comma-separated.
        allowed: String,
    },
    /// An item of a `KEY=VALUE` option that does not parse (the message says what is
    /// expected).
    #[error("{option}: {message}")]
    Item {
        /// The option.
        option: OptionKey,
        /// What is wrong with the item and what is allowed.
        message: String,
    },
    /// An item naming an input that is not a motion of the floor (what a witness records).
    #[error(
        "{option} {}: `{}` is not a floor input of the model; allowed: {}",
        Shown(.item),
        Shown(.name),
        floor_input_names()
    )]
    NotAFloorInput {
        /// The option.
        option: OptionKey,
        /// The item given.
        item: String,
        /// The name given.
        name: String,
    },
    /// The source of a user noise term that is neither an observable nor an input.
    #[error(
        "{option} {}: unknown source `{}`; allowed: an observable ({}) or an input of the model \
         ({})",
        Shown(.item),
        Shown(.name),
        observable_names(),
        model_input_names()
    )]
    UnknownSource {
        /// The option.
        option: OptionKey,
        /// The item given.
        item: String,
        /// The name given.
        name: String,
    },
    /// A range that is not two numbers `LO:HI` (or `LO,HI`).
    #[error("{option} {}: {}{expected}", Shown(.text), RangePart(.part.as_deref()))]
    Range {
        /// The option.
        option: OptionKey,
        /// The range given.
        text: String,
        /// The part that is not a finite number, when the range has two parts.
        part: Option<String>,
        /// What the option takes, e.g. `expected FLO:FHI in Hz, e.g. 1e-3:0.1`.
        expected: String,
    },
    /// An option that does not fit the others or the input, or a value out of its range (the
    /// message says why and what to do instead).
    #[error("{0}")]
    Conflict(Message),
    /// A size beyond a documented limit or the memory available.
    #[error(transparent)]
    TooLarge(#[from] LimitError),
}

/// The part of a range that is not a number, for [`OptionError::Range`].
struct RangePart<'a>(Option<&'a str>);

impl std::fmt::Display for RangePart<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            Some(part) => write!(f, "`{}` is not a finite number; ", Shown(part)),
            None => Ok(()),
        }
    }
}

/// The floor inputs of the model (what a witness records) with their SI units, for messages:
/// `theta_t, eta_t, phi_t (rad), x_t, y_t, z_t (m)`.
pub fn floor_input_names() -> String {
    let mut groups: Vec<(&str, Vec<&str>)> = Vec::new();
    for input in Input::all_ground() {
        match groups.last_mut() {
            Some((unit, names)) if *unit == input.unit() => names.push(input.name()),
            _ => groups.push((input.unit(), vec![input.name()])),
        }
    }
    groups
        .iter()
        .map(|(unit, names)| format!("{} ({unit})", names.join(", ")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Every input of the model with its SI unit, for messages: the floor inputs
/// ([`floor_input_names`]), then the forces and torques, `F_a.x .. F_b.z (N), M_a.x .. M_b.z
/// (N m)`.
pub fn model_input_names() -> String {
    let (forces, torques): (Vec<ForceInput>, Vec<ForceInput>) =
        ForceInput::ALL.into_iter().partition(|f| f.unit() == "N");
    let span = |group: &[ForceInput]| match (group.first(), group.last()) {
        (Some(a), Some(b)) => format!("{} .. {} ({})", a.name(), b.name(), a.unit()),
        _ => String::new(),
    };
    format!(
        "{}, {}, {}",
        floor_input_names(),
        span(&forces),
        span(&torques)
    )
}

/// The source `name` of a user noise term of `option`: an observable (the term is that
/// observable's ASD) or an input of the model (its ASD, propagated), for the item `item`.
///
/// # Errors
///
/// [`OptionError::UnknownSource`] for a name that is neither.
pub fn term_source(
    option: OptionKey,
    item: &str,
    name: &str,
) -> Result<crate::noise::UserSource, OptionError> {
    let name = name.trim();
    match (Observable::from_name(name), Input::from_name(name)) {
        (Some(o), _) => Ok(crate::noise::UserSource::Observable(o)),
        (None, Some(i)) => Ok(crate::noise::UserSource::Input(i)),
        (None, None) => Err(OptionError::UnknownSource {
            option,
            item: item.to_string(),
            name: name.to_string(),
        }),
    }
}

/// The floor input (a tilt angle or a translation of the floor) `name`, of the item `item` of
/// `option` (the one rule for witness items, co-located noise ratios and drives).
///
/// # Errors
///
/// [`OptionError::NotAFloorInput`] for a name that is no input, or a force or torque.
pub fn floor_input(option: OptionKey, item: &str, name: &str) -> Result<Input, OptionError> {
    Input::from_name(name.trim())
        .filter(|i| i.is_ground())
        .ok_or_else(|| OptionError::NotAFloorInput {
            option,
            item: item.to_string(),
            name: name.trim().to_string(),
        })
}

/// The two finite numbers of a range `LO:HI` of `option` (or `LO,HI`, as ranges were written
/// before they took the band syntax), the one reading of every range the command line takes
/// (bands, percentiles, axis limits); `expected` says what the option takes. Whether the ends
/// are in order and range is for the option's own check, which Python's `(LO, HI)` tuples
/// meet too.
///
/// # Errors
///
/// [`OptionError::Range`] for a range of other than two parts, or a part that is not a finite
/// number.
pub fn parse_range(
    option: OptionKey,
    text: &str,
    expected: &str,
) -> Result<(f64, f64), OptionError> {
    let error = |part: Option<&str>| OptionError::Range {
        option,
        text: text.to_string(),
        part: part.map(str::to_string),
        expected: expected.to_string(),
    };
    let separator = if text.contains(':') { ':' } else { ',' };
    let parts: Vec<&str> = text.split(separator).map(str::trim).collect();
    let [lo, hi] = parts[..] else {
        return Err(error(None));
    };
    let number = |part: &str| match part.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        _ => Err(error(Some(part))),
    };
    Ok((number(lo)?, number(hi)?))
}

/// The `KEY=VALUE` items of `option`, each key once (`what` names a key in the message:
/// `channel`), each parsed by `T`'s `FromStr` (whose error says what is expected): the one
/// reading of the unit and scale maps of both front ends (Python's dicts are handed over as
/// such items).
///
/// # Errors
///
/// [`OptionError::Repeated`] for a key given twice, [`OptionError::Item`] for the first item
/// that does not parse.
pub fn parse_keyed_items<T, S>(
    option: OptionKey,
    what: &'static str,
    items: &[S],
) -> Result<Vec<T>, OptionError>
where
    T: std::str::FromStr<Err = String>,
    S: AsRef<str>,
{
    crate::repeats::refuse_repeated_keys(option, what, items)?;
    items
        .iter()
        .map(|s| {
            s.as_ref()
                .parse()
                .map_err(|message| OptionError::Item { option, message })
        })
        .collect()
}

/// Every input name, for messages.
pub fn input_names() -> String {
    let mut names: Vec<&str> = Input::all_ground().into_iter().map(Input::name).collect();
    names.extend(ForceInput::ALL.iter().map(|f| f.name()));
    format!(
        "{}, or the groups `tilt`, `translation`, `ground` and `forces`",
        names.join(", ")
    )
}

/// Every observable name, for messages.
pub fn observable_names() -> String {
    let names: Vec<&str> = Observable::ALL.iter().map(|o| o.name()).collect();
    names.join(", ")
}

/// The names of `specs` (each a comma-separated list, as a repeated option gives them),
/// trimmed; an empty name is refused.
pub fn split_names<S: AsRef<str>>(
    option: OptionKey,
    specs: &[S],
) -> Result<Vec<&str>, OptionError> {
    let mut names = Vec::new();
    for spec in specs {
        let spec = spec.as_ref();
        for name in spec.split(',').map(str::trim) {
            if name.is_empty() {
                return Err(OptionError::EmptyName {
                    option,
                    spec: spec.to_string(),
                });
            }
            names.push(name);
        }
    }
    Ok(names)
}

/// The inputs named by `specs` ([`split_names`]): tilt angles (`theta_t`, `eta_t`, `phi_t`),
/// floor translations (`x_t`, `y_t`, `z_t`), force and torque components (`F_a.x` .. `M_b.z`)
/// and the groups `tilt`, `translation`, `ground` (tilt and translation) and `forces`, in the
/// order given, each once; no name means the three tilt angles.
pub fn parse_inputs<S: AsRef<str>>(
    option: OptionKey,
    specs: &[S],
) -> Result<Vec<Input>, OptionError> {
    if specs.is_empty() {
        return Ok(Input::all_tilts());
    }
    let mut inputs: Vec<Input> = Vec::new();
    for name in split_names(option, specs)? {
        match name {
            "tilt" => inputs.extend(Input::all_tilts()),
            "translation" => inputs.extend(Input::all_translations()),
            "ground" => inputs.extend(Input::all_ground()),
            "forces" => inputs.extend(ForceInput::ALL.into_iter().map(Input::Force)),
            _ => inputs.push(
                Input::from_name(name).ok_or_else(|| OptionError::UnknownInput {
                    option,
                    name: name.to_string(),
                })?,
            ),
        }
    }
    refuse_repeats(option, "input", &inputs, |i| i.name().to_string())?;
    Ok(inputs)
}

/// The observables named by `specs` ([`split_names`]), in the order given, each once; no name
/// means all seven.
pub fn parse_outputs<S: AsRef<str>>(
    option: OptionKey,
    specs: &[S],
) -> Result<Vec<Observable>, OptionError> {
    if specs.is_empty() {
        return Ok(Observable::ALL.to_vec());
    }
    let outputs = split_names(option, specs)?
        .into_iter()
        .map(|name| {
            Observable::from_name(name).ok_or_else(|| OptionError::UnknownObservable {
                option,
                name: name.to_string(),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    refuse_repeats(option, "observable", &outputs, |o| o.name().to_string())?;
    Ok(outputs)
}

/// One readout item `OBS=ASD` as the command line gives it: the observable and its white
/// readout noise, one-sided ASD in the observable's unit/sqrt(Hz), finite and >= 0.
pub fn parse_readout_item(option: OptionKey, item: &str) -> Result<(Observable, f64), OptionError> {
    let (name, value) = item
        .split_once('=')
        .ok_or_else(|| OptionError::ReadoutSyntax {
            option,
            item: item.to_string(),
        })?;
    let asd: Result<f64, OptionError> = value.trim().parse().map_err(|_| OptionError::NotANumber {
        option,
        item: item.to_string(),
        value: value.to_string(),
    });
    // The observable is checked first, as it comes first in the item.
    let o = readout_observable(option, item, name.trim())?;
    check_readout_asd(option, item, o, asd?)
}

/// One readout item given as a name and a number (a keyword argument's dict entry), checked
/// as [`parse_readout_item`] checks `NAME=ASD`.
pub fn readout_item(
    option: OptionKey,
    name: &str,
    asd: f64,
) -> Result<(Observable, f64), OptionError> {
    let item = format!("{name}={}", Num(asd));
    let o = readout_observable(option, &item, name)?;
    check_readout_asd(option, &item, o, asd)
}

fn readout_observable(
    option: OptionKey,
    item: &str,
    name: &str,
) -> Result<Observable, OptionError> {
    Observable::from_name(name).ok_or_else(|| OptionError::ReadoutObservable {
        option,
        item: item.to_string(),
        name: name.to_string(),
    })
}

fn check_readout_asd(
    option: OptionKey,
    item: &str,
    o: Observable,
    asd: f64,
) -> Result<(Observable, f64), OptionError> {
    if !ASDS.admits(asd) {
        return Err(OptionError::ReadoutAsd {
            option,
            item: item.to_string(),
            asd,
            unit: o.unit(),
        });
    }
    Ok((o, asd))
}

/// `readout` with the items applied: a value replaces the observable's readout (the default is
/// the paper's 9e-9 m/sqrt(Hz) on X), 0 removes it. An observable given twice is refused; with
/// `budgeted`, so is an observable outside it.
pub fn apply_readout(
    option: OptionKey,
    mut readout: Readout,
    items: &[(Observable, f64)],
    budgeted: Option<&[Observable]>,
) -> Result<Readout, OptionError> {
    let observables: Vec<Observable> = items.iter().map(|(o, _)| *o).collect();
    refuse_repeats(option, "observable", &observables, |o| o.name().to_string())?;
    for &(o, asd) in items {
        if let Some(budgeted) = budgeted {
            if !budgeted.contains(&o) {
                let allowed: Vec<&str> = budgeted.iter().map(|o| o.name()).collect();
                return Err(OptionError::NotBudgeted {
                    option,
                    name: o.name(),
                    allowed: allowed.join(", "),
                });
            }
        }
        readout.asd.retain(|(x, _)| *x != o);
        if asd > 0.0 {
            readout.asd.push((o, asd));
        }
    }
    Ok(readout)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lists_of_inputs_follow_the_model() {
        assert_eq!(
            floor_input_names(),
            "theta_t, eta_t, phi_t (rad), x_t, y_t, z_t (m)"
        );
        assert_eq!(
            model_input_names(),
            "theta_t, eta_t, phi_t (rad), x_t, y_t, z_t (m), F_a.x .. F_b.z (N), \
             M_a.x .. M_b.z (N m)"
        );
        let key = OptionKey::WITNESS_NOISE;
        assert_eq!(floor_input(key, "x", " y_t ").unwrap().name(), "y_t");
        for name in ["F_b.x", "M_a.z", "theta", "zz"] {
            let e = floor_input(key, "ITEM", name).unwrap_err().to_string();
            assert!(
                e.starts_with("witness_noise ITEM: `") && e.contains("floor input"),
                "{e}"
            );
        }
        let term = OptionKey::TERM;
        assert!(matches!(
            term_source(term, "m=phi:f.csv", "phi"),
            Ok(crate::noise::UserSource::Observable(Observable::Phi))
        ));
        assert!(matches!(
            term_source(term, "m=F_b.x:f.csv", "F_b.x"),
            Ok(crate::noise::UserSource::Input(_))
        ));
        let e = term_source(term, "m=F_c.x:f.csv", "F_c.x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown source `F_c.x`") && e.contains("M_a.x .. M_b.z (N m)"));
    }

    #[test]
    fn ranges_are_two_finite_numbers_in_either_syntax() {
        let key = OptionKey::BAND;
        for text in ["1e-3:0.1", "1e-3,0.1", " 1e-3 : 0.1 "] {
            assert_eq!(parse_range(key, text, "E").unwrap(), (1e-3, 0.1));
        }
        // Order and sign are the option's own check: the reading keeps them.
        assert_eq!(parse_range(key, "2:-1", "E").unwrap(), (2.0, -1.0));
        for (text, part) in [
            ("1", None),
            ("1:2:3", None),
            ("1:2,3", Some("2,3")),
            ("a:1", Some("a")),
        ] {
            match parse_range(key, text, "expected LO:HI").unwrap_err() {
                OptionError::Range {
                    part: p, expected, ..
                } => {
                    assert_eq!(p.as_deref(), part, "{text}");
                    assert_eq!(expected, "expected LO:HI");
                }
                other => panic!("{text}: {other}"),
            }
        }
        for text in ["1:inf", "nan:1"] {
            assert!(parse_range(key, text, "E").is_err(), "{text}");
        }
    }

    #[test]
    fn keyed_items_parse_each_key_once() {
        let units: Vec<crate::input::ChannelUnit> =
            parse_keyed_items(OptionKey::UNITS, "channel", &["LHE=m/s^2", "LJE=rad/s"]).unwrap();
        assert_eq!(units.len(), 2);
        let e = parse_keyed_items::<crate::input::ChannelScale, _>(
            OptionKey::SCALE,
            "channel",
            &["BJE=2", "BJE=3"],
        )
        .unwrap_err();
        assert!(matches!(e, OptionError::Repeated(_)), "{e}");
        let e = parse_keyed_items::<crate::input::ChannelScale, _>(
            OptionKey::SCALE,
            "channel",
            &["BJE"],
        )
        .unwrap_err();
        assert!(matches!(e, OptionError::Item { .. }), "{e}");
    }

    #[test]
    fn inputs_parse_lists_groups_and_repeats() {
        let got = parse_inputs(OptionKey::INPUTS, &["F_b.x, M_b.z", "theta_t"]).unwrap();
        let names: Vec<&str> = got.iter().map(|i| i.name()).collect();
        assert_eq!(names, ["F_b.x", "M_b.z", "theta_t"]);
        assert_eq!(
            parse_inputs::<&str>(OptionKey::INPUTS, &[]).unwrap(),
            Input::all_tilts()
        );
        assert_eq!(
            parse_inputs(OptionKey::INPUTS, &["forces"]).unwrap().len(),
            12
        );
        assert_eq!(
            parse_inputs(OptionKey::INPUTS, &["tilt,forces"])
                .unwrap()
                .len(),
            15
        );
        assert_eq!(
            parse_inputs(OptionKey::INPUTS, &["translation"]).unwrap(),
            Input::all_translations()
        );
        let ground = parse_inputs(OptionKey::INPUTS, &["ground"]).unwrap();
        let names: Vec<&str> = ground.iter().map(|i| i.name()).collect();
        assert_eq!(names, ["theta_t", "eta_t", "phi_t", "x_t", "y_t", "z_t"]);
        let e = parse_inputs(OptionKey::INPUTS, &["ground,y_t"]).unwrap_err();
        assert!(e.to_string().contains("y_t is given twice"), "{e}");
    }

    #[test]
    fn bad_input_names_are_refused_with_the_allowed_list() {
        let e = parse_inputs(OptionKey::INPUTS, &["F_c.x"])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("inputs: unknown input \"F_c.x\"")
                && e.contains("M_b.z")
                && e.contains("theta_t"),
            "{e}"
        );
        let e = parse_inputs(OptionKey::INPUTS, &["F_b.x,F_b.x"]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "inputs: F_b.x is given twice; name each input once"
        );
        let e = parse_inputs(OptionKey::INPUTS, &["tilt,eta_t"]).unwrap_err();
        assert!(e.to_string().contains("eta_t is given twice"), "{e}");
        let e = parse_inputs(OptionKey::INPUTS, &["F_b.x,,M_b.z"]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "inputs \"F_b.x,,M_b.z\": empty name in the list (names are separated by single \
             commas)"
        );
    }

    #[test]
    fn outputs_parse_and_refuse_unknown_names() {
        let got = parse_outputs(OptionKey::OUTPUTS, &["phi,X"]).unwrap();
        assert_eq!(got, [Observable::Phi, Observable::X]);
        assert_eq!(
            parse_outputs::<&str>(OptionKey::OUTPUTS, &[]).unwrap(),
            Observable::ALL.to_vec()
        );
        let e = parse_outputs(OptionKey::OUTPUTS, &["x"])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "outputs: unknown observable \"x\"; allowed: X, Y, Z, theta, eta, phi, phi_a"
        );
        let e = parse_outputs(OptionKey::OUTPUTS, &["X", "X"])
            .unwrap_err()
            .to_string();
        assert_eq!(e, "outputs: X is given twice; name each observable once");
    }

    #[test]
    fn readout_items_as_text_and_as_keywords() {
        assert_eq!(
            parse_readout_item(OptionKey::READOUT, "phi = 1e-9").unwrap(),
            (Observable::Phi, 1e-9)
        );
        assert_eq!(
            readout_item(OptionKey::READOUT, "phi", 1e-9).unwrap(),
            (Observable::Phi, 1e-9)
        );
        let cases = [
            ("X", "readout X: expected OBS=ASD, e.g. X=9e-9"),
            (
                "q=1",
                "readout q=1: unknown observable `q`; allowed: X, Y, Z, theta, eta, phi, phi_a",
            ),
            ("X=abc", "readout X=abc: `abc` is not a number"),
            (
                "X=-1",
                "readout X=-1: ASD -1 m/sqrt(Hz) is not allowed: must be 0 or a value from \
                 1e-40 to 1e40 m/sqrt(Hz) (see docs/limits.md)",
            ),
        ];
        for (item, want) in cases {
            assert_eq!(
                parse_readout_item(OptionKey::READOUT, item)
                    .unwrap_err()
                    .to_string(),
                want
            );
        }
        assert_eq!(
            readout_item(OptionKey::READOUT, "phi", f64::NAN)
                .unwrap_err()
                .to_string(),
            "readout phi=NaN: ASD NaN rad/sqrt(Hz) is not allowed: must be 0 or a value from \
             1e-40 to 1e40 rad/sqrt(Hz) (see docs/limits.md)"
        );
    }

    #[test]
    fn readout_items_replace_remove_and_are_checked_against_the_budget() {
        let budgeted = [Observable::X, Observable::Phi];
        let r = apply_readout(
            OptionKey::READOUT,
            Readout::default(),
            &[(Observable::Phi, 1e-9), (Observable::X, 0.0)],
            Some(&budgeted),
        )
        .unwrap();
        assert_eq!(r.asd, [(Observable::Phi, 1e-9)]);
        let e = apply_readout(
            OptionKey::READOUT,
            Readout::default(),
            &[(Observable::Theta, 1e-9)],
            Some(&budgeted),
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "readout theta=...: theta is not budgeted; allowed: X, phi"
        );
        let r = apply_readout(
            OptionKey::READOUT,
            Readout::default(),
            &[(Observable::Theta, 1e-9)],
            None,
        );
        assert_eq!(r.unwrap().asd.len(), 2);
        let e = apply_readout(
            OptionKey::READOUT,
            Readout::default(),
            &[(Observable::X, 1e-9), (Observable::X, 2e-9)],
            None,
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "readout: X is given twice; name each observable once"
        );
    }
}
