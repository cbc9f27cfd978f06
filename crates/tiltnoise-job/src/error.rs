//! The errors of a job, naming the option or key that failed by its snake-case name; each
//! front end renders them in its own spelling ([`JobError::message`]).

use crate::budget::ArrayError;
use crate::subtract::SubtractFailure;
use std::fmt;
use tiltnoise_core::budget::option_checks::{
    percentiles_error, require_segments_for_percentiles, InputKind,
};
use tiltnoise_core::budget::BudgetError;
use tiltnoise_core::cancel::Cancelled;
use tiltnoise_core::coherence::CoherenceError;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::error::{FreqError, ParamError, TfError};
use tiltnoise_core::error::{Num, Shown};
use tiltnoise_core::fit::FitError;
use tiltnoise_core::input::InputError;
use tiltnoise_core::mc::McError;
use tiltnoise_core::model::Observable;
use tiltnoise_core::option_key::{self, Message, OptionKey};
use tiltnoise_core::options::OptionError;
use tiltnoise_core::repeats::Repeated;
use tiltnoise_core::simulate::SimError;
use tiltnoise_core::spectral::SpectralError;
use tiltnoise_core::tf::planner::NoChoice;
use tiltnoise_core::tf::PlanError;

/// Why a job did not run to its end. Options are named in snake case (`segment_duration`);
/// [`JobError::message`] spells them as the front end does. `Display` uses the keyword
/// spelling.
#[derive(Debug)]
pub enum JobError {
    /// A file the job reads cannot be read or is not valid (the error names the file).
    Input(Box<InputError>),
    /// A file named in an item of an option (a coloured readout, a user term) cannot be read
    /// or is not valid.
    OptionFile {
        /// The option.
        option: OptionKey,
        /// The item, as `KEY=VALUE`.
        item: String,
        /// What is wrong with the file.
        source: Box<InputError>,
    },
    /// An option or an item of one whose value does not fit.
    Option {
        /// The option.
        option: OptionKey,
        /// The item or value, when the message shows it.
        value: Option<Message>,
        /// What is wrong and what is allowed.
        problem: Message,
    },
    /// An option that applies to the other kind of input than the one `path` holds.
    NotForInput {
        /// The option.
        option: OptionKey,
        /// What the input holds.
        holds: InputKind,
        /// The input, as given.
        path: String,
    },
    /// An item on an observable the budget does not compute.
    NotBudgeted {
        /// The option.
        option: OptionKey,
        /// The item, as `KEY=VALUE`.
        item: String,
        /// Its observable.
        observable: Observable,
        /// The observables budgeted.
        budgeted: Vec<Observable>,
    },
    /// Percentiles without segments.
    PercentilesNeedSegments,
    /// Percentiles out of order or range.
    Percentiles {
        /// The lower percentile given.
        lower: f64,
        /// The upper percentile given.
        upper: f64,
    },
    /// A key given twice.
    Repeated(Repeated),
    /// The computation on the input `path` failed.
    Budget {
        /// The input, as given.
        path: String,
        /// Why.
        source: Box<BudgetError>,
    },
    /// The records give no coherence estimate (or the run was cancelled).
    Coherence(Box<CoherenceError>),
    /// The subtraction's records do not fit it, or its result is not finite.
    Subtract(Box<SubtractFailure>),
    /// `auto` found no method for the request on the grid's band.
    NoMethod(Box<NoChoice>),
    /// The method asked for cannot evaluate the request on this model.
    Plan(Box<PlanError>),
    /// The transfer functions have no value at a frequency, do not fit into memory, or the run
    /// was cancelled.
    Tf(Box<TfError>),
    /// A file of frequencies cannot be read or is not valid.
    Freq(Box<FreqError>),
    /// The Monte Carlo cannot run (sizes, error model, every draw rejected, cancelled).
    MonteCarlo(Box<McError>),
    /// The run was cancelled.
    Cancelled,
    /// An option's value the library refused (its message names the option).
    Refused(Box<OptionError>),
    /// A simulation that cannot run as asked (or was cancelled).
    Simulate(Box<SimError>),
    /// A fit, or a measurement of visibilities, that failed (a file it reads names itself).
    Fit(Box<FitError>),
    /// A file of measured frequencies or visibilities that cannot be read or is not valid
    /// (the error names it).
    FitFile(Box<FitError>),
    /// The spectra of a simulated record.
    Spectral(Box<SpectralError>),
    /// An output the job writes while it runs (a record streamed to its file).
    Output(Box<OutputError>),
    /// Arrays that are not a record of the floor's motion (the message names the input).
    Arrays(Box<ArrayError>),
    /// Parameters that describe no pendulum.
    Params(Box<ParamError>),
}

impl JobError {
    /// The message, one line, with the options spelled as the front end in use does
    /// ([`tiltnoise_core::option_key`]).
    pub fn message(&self) -> String {
        match self {
            JobError::Input(e) => e.to_string(),
            JobError::OptionFile {
                option,
                item,
                source,
            } => format!("{option} {}: {source}", Shown(item)),
            JobError::Option {
                option,
                value: Some(value),
                problem,
            } => format!("{option} {}: {problem}", Shown(&value.to_string())),
            JobError::Option {
                option,
                value: None,
                problem,
            } => format!("{option}: {problem}"),
            JobError::NotForInput {
                option,
                holds: InputKind::Spectra,
                path,
            } => format!(
                "{} applies to time-series input, and {} holds spectra; leave it out (the model \
                 grid of spectra input is set with {})",
                option,
                Shown(path),
                OptionKey::FREQ
            ),
            JobError::NotForInput {
                option,
                holds: InputKind::Series,
                path,
            } => format!(
                "{} applies to spectra input, and {} holds a time series, whose budget is on the \
                 Welch grid (set its resolution with {})",
                option,
                Shown(path),
                OptionKey::NPERSEG
            ),
            JobError::NotBudgeted {
                option,
                item,
                observable,
                budgeted,
            } => format!(
                "{} {}: {} is not budgeted; allowed: {} (add it with {})",
                option,
                Shown(item),
                observable.name(),
                budgeted
                    .iter()
                    .map(|o| o.name())
                    .collect::<Vec<_>>()
                    .join(", "),
                OptionKey::OBSERVABLES
            ),
            JobError::PercentilesNeedSegments => require_segments_for_percentiles(false)
                .err()
                .map_or_else(String::new, |e| e.to_string()),
            JobError::Percentiles { lower, upper } => {
                let given = option_key::pair(Num(*lower), Num(*upper)).to_string();
                percentiles_error(&given).to_string()
            }
            JobError::Repeated(r) => r.to_string(),
            JobError::Budget { path, source } => format!("budget of {}: {source}", Shown(path)),
            JobError::Coherence(e) => e.to_string(),
            JobError::Subtract(e) => e.message(),
            JobError::NoMethod(refusal) => match refusal.as_ref() {
                NoChoice::Tolerance { .. } => {
                    format!(
                        "{refusal}; run with {} for every candidate",
                        OptionKey::EXPLAIN
                    )
                }
                NoChoice::NearMode { .. } => format!(
                    "{refusal} ({}, or another {})",
                    OptionKey::METHOD.given("polezero"),
                    OptionKey::FREQ_HZ
                ),
                NoChoice::Band(_) => refusal.to_string(),
            },
            JobError::Plan(e) => e.to_string(),
            JobError::Tf(e) => format!("evaluating the transfer functions: {e}"),
            JobError::Freq(e) => e.to_string(),
            JobError::MonteCarlo(e) => e.to_string(),
            JobError::Cancelled => Cancelled.to_string(),
            JobError::Refused(e) => e.to_string(),
            JobError::Simulate(e) => e.to_string(),
            JobError::Fit(e) | JobError::FitFile(e) => e.to_string(),
            JobError::Spectral(e) => e.to_string(),
            JobError::Output(e) => e.to_string(),
            JobError::Arrays(e) => e.to_string(),
            JobError::Params(e) => e.to_string(),
        }
    }

    /// A file named by an option item.
    pub(crate) fn option_file(option: OptionKey, item: &str, source: InputError) -> JobError {
        JobError::OptionFile {
            option,
            item: item.to_string(),
            source: Box::new(source),
        }
    }

    /// An option item that does not fit.
    pub(crate) fn option(
        option: OptionKey,
        value: Option<&str>,
        problem: impl Into<Message>,
    ) -> JobError {
        JobError::Option {
            option,
            value: value.map(Message::from),
            problem: problem.into(),
        }
    }

    /// An option's pair of values that does not fit (a band), the pair in the front end's
    /// form.
    pub(crate) fn option_pair(
        option: OptionKey,
        (first, second): (f64, f64),
        problem: impl Into<Message>,
    ) -> JobError {
        let pair = option_key::pair(Num(first), Num(second));
        JobError::Option {
            option,
            value: Some(tiltnoise_core::message!("{pair}")),
            problem: problem.into(),
        }
    }
}

impl fmt::Display for JobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message())
    }
}

impl std::error::Error for JobError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            JobError::Input(e) | JobError::OptionFile { source: e, .. } => Some(e.as_ref()),
            JobError::Budget { source, .. } => Some(source.as_ref()),
            JobError::Coherence(e) => Some(e.as_ref()),
            JobError::NoMethod(e) => Some(e.as_ref()),
            JobError::Plan(e) => Some(e.as_ref()),
            JobError::Tf(e) => Some(e.as_ref()),
            JobError::Freq(e) => Some(e.as_ref()),
            JobError::MonteCarlo(e) => Some(e.as_ref()),
            JobError::Refused(e) => Some(e.as_ref()),
            JobError::Simulate(e) => Some(e.as_ref()),
            JobError::Fit(e) | JobError::FitFile(e) => Some(e.as_ref()),
            JobError::Spectral(e) => Some(e.as_ref()),
            JobError::Output(e) => Some(e.as_ref()),
            JobError::Arrays(e) => Some(e.as_ref()),
            _ => None,
        }
    }
}

impl From<InputError> for JobError {
    fn from(e: InputError) -> JobError {
        JobError::Input(Box::new(e))
    }
}

macro_rules! from_boxed {
    ($($ty:ident => $variant:ident),*) => {$(
        impl From<$ty> for JobError {
            fn from(e: $ty) -> JobError {
                JobError::$variant(Box::new(e))
            }
        }
    )*};
}

from_boxed!(
    OptionError => Refused,
    SimError => Simulate,
    FitError => Fit,
    SpectralError => Spectral,
    OutputError => Output
);

impl From<tiltnoise_core::limits::LimitError> for JobError {
    fn from(e: tiltnoise_core::limits::LimitError) -> JobError {
        JobError::Simulate(Box::new(SimError::TooLarge(e)))
    }
}

/// The path of an input as messages and files show it.
pub(crate) fn shown_path(path: &std::path::Path) -> String {
    path.display().to_string()
}
