//! What a budget is given besides the floor's motion: readout noise (white or coloured) and
//! user-named terms, each file read once here and checked against what is budgeted.

use crate::error::JobError;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::{Num, Shown};
use tiltnoise_core::model::{Input, Observable};
use tiltnoise_core::noise::{
    is_term_name, GivenAsd, NoiseLevel, Readout, UserSource, UserTerm, WitnessNoise,
};
use tiltnoise_core::option_key::{Message, OptionKey};
use tiltnoise_io::input::read_asd_column;

/// A one-sided ASD as the user gives it: white (a number, in the quantity's unit/sqrt(Hz),
/// checked by the front end's parser) or a file (CSV or HDF5, `read_asd_column`'s layouts).
#[derive(Debug, Clone, PartialEq)]
pub enum AsdSpec {
    /// White: the ASD at every frequency.
    White(f64),
    /// Coloured: the file that holds it.
    File(PathBuf),
}

impl AsdSpec {
    /// The value as a user writes it: the number, or the path.
    fn shown(&self) -> String {
        match self {
            AsdSpec::White(a) => Num(*a).to_string(),
            AsdSpec::File(p) => p.display().to_string(),
        }
    }
}

/// The readout noise of one observable; a white 0 removes it.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadoutItem {
    /// The observable read out.
    pub observable: Observable,
    /// Its readout ASD.
    pub asd: AsdSpec,
}

impl ReadoutItem {
    /// `OBS=VALUE`, for messages.
    fn item(&self) -> String {
        format!("{}={}", self.observable.name(), self.asd.shown())
    }
}

/// A user-named term: `name`, what its ASD is of, and the file that holds the ASD.
#[derive(Debug, Clone, PartialEq)]
pub struct TermItem {
    /// The term's name (`user.NAME` in the budget).
    pub name: String,
    /// An observable (the file holds its ASD) or an input of the model (the file holds the
    /// input's ASD, propagated through the transfer functions).
    pub source: UserSource,
    /// The ASD file.
    pub file: PathBuf,
}

impl TermItem {
    /// `NAME=SOURCE:FILE`, for messages.
    fn item(&self) -> String {
        format!(
            "{}={}:{}",
            self.name,
            self.source.name(),
            self.file.display()
        )
    }
}

/// The own noise of the instrument that records a floor input of the model (a tilt or a
/// translation): its ASD in the input's unit/sqrt(Hz), and the ASD's relative uncertainty
/// (1 sigma; 0 when exact).
#[derive(Debug, Clone, PartialEq)]
pub struct WitnessItem {
    /// The floor input recorded.
    pub input: Input,
    /// The instrument's noise.
    pub asd: AsdSpec,
    /// Relative uncertainty of the ASD.
    pub rel: f64,
}

impl WitnessItem {
    /// `INPUT=VALUE[:REL]`, for messages.
    fn item(&self) -> String {
        let rel = if self.rel == 0.0 {
            String::new()
        } else {
            format!(":{}", Num(self.rel))
        };
        format!("{}={}{rel}", self.input.name(), self.asd.shown())
    }
}

/// The witness noise of `items`, every file read and every level checked.
///
/// # Errors
///
/// A [`JobError`] naming the item: a file that cannot be read, a level or an uncertainty
/// that is not allowed.
pub fn witness_noise(items: &[WitnessItem]) -> Result<Vec<WitnessNoise>, JobError> {
    items
        .iter()
        .map(|it| {
            let input = it.input;
            let level = match &it.asd {
                AsdSpec::White(a) => NoiseLevel::White(*a),
                AsdSpec::File(path) => NoiseLevel::Curve(read_given(
                    OptionKey::WITNESS_NOISE,
                    &it.item(),
                    path,
                    input.name(),
                    input.unit(),
                )?),
            };
            let noise = WitnessNoise {
                input,
                level,
                rel: it.rel,
            };
            // The message names the input once, with the item.
            match noise.problem() {
                Some(problem) => Err(JobError::option(
                    OptionKey::WITNESS_NOISE,
                    Some(input.name()),
                    format!("{problem} (in {})", it.item()),
                )),
                None => Ok(noise),
            }
        })
        .collect()
}

/// The unit of an ASD of a quantity of SI unit `unit`.
fn asd_unit(unit: &str) -> &'static str {
    match unit {
        "m" => "m/sqrt(Hz)",
        "rad" => "rad/sqrt(Hz)",
        "N" => "N/sqrt(Hz)",
        _ => "N m/sqrt(Hz)",
    }
}

/// Reads the ASD of `quantity` (SI unit `unit`) from `path`, for the item `item` of `option`
/// (snake case, e.g. `witness_noise`). The ASD's origin, which the budget files keep, is the
/// file and its column.
///
/// # Errors
///
/// [`JobError::OptionFile`] when the file cannot be read or has no such column,
/// [`JobError::Option`] when its frequencies or values are not allowed.
pub fn read_given(
    option: OptionKey,
    item: &str,
    path: &Path,
    quantity: &str,
    unit: &str,
) -> Result<GivenAsd, JobError> {
    let column = read_asd_column(path, quantity, asd_unit(unit))
        .map_err(|e| JobError::option_file(option, item, e))?;
    let origin = format!("{} (column {})", path.display(), column.column);
    GivenAsd::new(column.freqs_hz, column.asd, &origin)
        .map_err(|e| JobError::option(option, Some(item), Message::shown(e)))
}

/// The readout: the paper's 9e-9 m/sqrt(Hz) on X, replaced per observable by `items` in
/// order (a white 0 removes one); every item on a budgeted observable.
pub(crate) fn readout(items: &[ReadoutItem], budgeted: &[Observable]) -> Result<Readout, JobError> {
    let mut readout = Readout::default();
    for it in items {
        let o = it.observable;
        if !budgeted.contains(&o) {
            return Err(JobError::NotBudgeted {
                option: OptionKey::READOUT,
                item: it.item(),
                observable: o,
                budgeted: budgeted.to_vec(),
            });
        }
        readout.asd.retain(|(x, _)| *x != o);
        readout.given.retain(|(x, _)| *x != o);
        match &it.asd {
            AsdSpec::White(asd) if *asd > 0.0 => readout.asd.push((o, *asd)),
            AsdSpec::White(_) => {}
            AsdSpec::File(path) => {
                let given = read_given(OptionKey::READOUT, &it.item(), path, o.name(), o.unit())?;
                readout.given.push((o, given));
            }
        }
    }
    // The default readout is on X; without X it has nothing to apply to.
    readout.asd.retain(|(o, _)| budgeted.contains(o));
    Ok(readout)
}

/// The user terms of `items`: a name allowed and each source budgeted, every file read.
pub(crate) fn terms(
    items: &[TermItem],
    budgeted: &[Observable],
) -> Result<Vec<UserTerm>, JobError> {
    items
        .iter()
        .map(|it| {
            let item = it.item();
            if !is_term_name(&it.name) {
                return Err(JobError::option(
                    OptionKey::TERM,
                    Some(&item),
                    format!(
                        "the name `{}` is not allowed: 1 to 64 letters, digits or _, starting \
                         with a letter",
                        Shown(&it.name)
                    ),
                ));
            }
            let unit = match it.source {
                UserSource::Observable(o) if !budgeted.contains(&o) => {
                    return Err(JobError::NotBudgeted {
                        option: OptionKey::TERM,
                        item,
                        observable: o,
                        budgeted: budgeted.to_vec(),
                    })
                }
                UserSource::Observable(o) => o.unit(),
                UserSource::Input(i) => i.unit(),
            };
            let asd = read_given(OptionKey::TERM, &item, &it.file, it.source.name(), unit)?;
            Ok(UserTerm {
                name: it.name.clone(),
                source: it.source,
                asd,
            })
        })
        .collect()
}
