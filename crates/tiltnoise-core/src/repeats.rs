//! The one rule for options that name things, in every command and in Python: each key of a
//! repeatable `KEY=VALUE` option (`--set`, `--scale`, `--readout`, `--tilt-noise`,
//! `--drive-gain`, `--init`, `--term` names) and each name of a list option (`--observables`,
//! `--input`, `--output`, `--fit`, `--free`, `--at`) is given once, whether it comes twice in
//! one occurrence (`X,X`) or in two (`--readout X=1e-9 --readout X=2e-9`). A repeat is refused
//! rather than resolved (first or last wins), because a user who repeats a key has made a
//! mistake the program cannot correct.
//!
//! Depends on nothing else in the crate but [`crate::option_key`], which names the option.

use crate::option_key::OptionKey;

/// A key or name given twice in one option.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{option}: {name} is given twice; name each {what} once")]
pub struct Repeated {
    /// The option, shown as the front end in use spells it (`--readout`, `readout`).
    pub option: OptionKey,
    /// The key or name, as the user gave it (the first spelling, for names with aliases).
    pub name: String,
    /// What a key is, singular: `observable`, `channel`, `parameter key`, `frequency`.
    pub what: &'static str,
}

/// Refuses the first key of `keys` (in order) that equals an earlier one: [`Repeated`] naming
/// `option`, the key as `name` shows it, and `what` keys are. Keys are compared after the
/// caller's parsing (trimmed text, or the typed value: `X` and ` X ` are one observable).
///
/// ```
/// use tiltnoise_core::option_key::OptionKey;
/// use tiltnoise_core::repeats::refuse_repeats;
/// let (observables, readout) = (OptionKey::OBSERVABLES, OptionKey::READOUT);
/// assert!(refuse_repeats(observables, "observable", &["X", "phi"], |k| k.to_string()).is_ok());
/// let e = refuse_repeats(readout, "observable", &["X", "phi", "X"], |k| k.to_string());
/// // Without a front end's style installed, the key is shown as itself.
/// assert_eq!(
///     e.unwrap_err().to_string(),
///     "readout: X is given twice; name each observable once"
/// );
/// ```
pub fn refuse_repeats<K: PartialEq>(
    option: OptionKey,
    what: &'static str,
    keys: &[K],
    name: impl Fn(&K) -> String,
) -> Result<(), Repeated> {
    match keys
        .iter()
        .enumerate()
        .find(|(i, k)| keys[..*i].contains(k))
    {
        Some((_, k)) => Err(Repeated {
            option,
            name: name(k),
            what,
        }),
        None => Ok(()),
    }
}

/// Refuses a key given twice among `KEY=VALUE` items ([`keys_of`]), before they are parsed
/// one by one: `--readout X=1e-9 --readout X=2e-9`, `--init theta_a=1,theta_a=2` (after
/// [`list_entries`]).
pub fn refuse_repeated_keys<S: AsRef<str>>(
    option: OptionKey,
    what: &'static str,
    items: &[S],
) -> Result<(), Repeated> {
    refuse_repeats(option, what, &keys_of(items), |k| k.to_string())
}

/// The keys of `KEY=VALUE` items, trimmed (an item without `=` is all key).
pub fn keys_of<S: AsRef<str>>(items: &[S]) -> Vec<&str> {
    items
        .iter()
        .map(|item| {
            let item = item.as_ref();
            item.split_once('=').map_or(item, |(k, _)| k).trim()
        })
        .collect()
}

/// The entries of an option whose occurrences are comma-separated lists (`--init
/// theta_a=1e-5,phi_b=0.01 --init delta_b=1e-6`), trimmed, empty ones left out.
pub fn list_entries<S: AsRef<str>>(specs: &[S]) -> Vec<&str> {
    specs
        .iter()
        .flat_map(|s| s.as_ref().split(','))
        .map(str::trim)
        .filter(|e| !e.is_empty())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_repeat_is_named_with_its_option() {
        let keys = keys_of(&["length.h_m=1", " mass.m_a_kg = 2", "length.h_m =3"]);
        assert_eq!(keys, ["length.h_m", "mass.m_a_kg", "length.h_m"]);
        let e =
            refuse_repeats(OptionKey::SET, "parameter key", &keys, |k| k.to_string()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "set: length.h_m is given twice; name each parameter key once"
        );
        // Typed keys: equal values are one key however they were written.
        let e = refuse_repeats(OptionKey::AT, "frequency", &[1e-3, 2e-3, 0.001], |f| {
            f.to_string()
        })
        .unwrap_err();
        assert_eq!(e.name, "0.001");
        assert!(refuse_repeats::<f64>(OptionKey::AT, "frequency", &[], |f| f.to_string()).is_ok());
        assert_eq!(keys_of(&["no-equals"]), ["no-equals"]);
        let entries = list_entries(&["theta_a=1, phi_b=2,", "theta_a=3"]);
        assert_eq!(entries, ["theta_a=1", "phi_b=2", "theta_a=3"]);
        let e = refuse_repeated_keys(OptionKey::INIT, "coordinate", &entries).unwrap_err();
        assert_eq!(
            e.to_string(),
            "init: theta_a is given twice; name each coordinate once"
        );
    }
}
