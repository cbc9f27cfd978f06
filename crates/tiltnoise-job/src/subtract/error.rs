//! Why a subtraction did not run, beyond the readers' and the options' errors: records that do
//! not fit it, a result that is not finite; each message names its options by
//! key, spelled by the front end in use.

use tiltnoise_core::error::Shown;
use tiltnoise_core::model::Observable;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::subtract::SubtractError;

/// Why a subtraction did not run, beyond the readers' and the options' errors.
#[derive(Debug)]
pub enum SubtractFailure {
    /// More than two co-located records.
    TooManyColocated(usize),
    /// A noise ratio without exactly one co-located record.
    RatioNeedsOneColocated,
    /// A noise ratio for an input that the witness or the co-located record does not record.
    RatioUnrecorded {
        /// The ratio's input and value, as given (`x_t=1`).
        item: String,
        /// The input.
        input: String,
        /// The option of the record that lacks it (`tilt` or `colocated`).
        option: OptionKey,
        /// The record.
        path: String,
        /// The inputs the record has.
        present: Vec<String>,
    },
    /// A record of the floor's motion (`option`) holds spectra.
    WitnessSpectra {
        /// The option.
        option: OptionKey,
        /// The file.
        path: String,
    },
    /// The measured record holds spectra.
    MeasuredSpectra(String),
    /// A record of the floor's motion whose channels do not map to the model's inputs.
    Channels {
        /// The option.
        option: OptionKey,
        /// The file.
        path: String,
        /// Why.
        problem: String,
    },
    /// A start time that is not ISO 8601.
    StartTime {
        /// The option.
        option: OptionKey,
        /// The file.
        path: String,
        /// The start time as the file gives it.
        value: String,
    },
    /// An observable twice in the measured record.
    RepeatedChannel {
        /// The file.
        path: String,
        /// The observable.
        observable: Observable,
    },
    /// An observable asked for that the measured record lacks.
    MissingChannel {
        /// The file.
        path: String,
        /// The observable.
        observable: Observable,
        /// The observables it has.
        present: Vec<Observable>,
    },
    /// The subtraction was refused, or its result has a number that is not finite.
    Run {
        /// The witness record.
        tilt: String,
        /// The measured record.
        measured: String,
        /// Why.
        reason: RunFailure,
    },
}

/// Why the subtraction of two readable records failed.
#[derive(Debug)]
pub enum RunFailure {
    /// The subtraction refused the records or the options.
    Refused(SubtractError),
    /// A fitted value or its uncertainty is not finite.
    Estimate {
        /// The parameter.
        name: String,
        /// Its value.
        value: f64,
        /// Its uncertainty.
        sigma: f64,
    },
    /// The fit's chi^2 is not finite.
    Chi2(f64),
    /// A band summary of the residuals is not finite.
    Band {
        /// Which summary.
        what: &'static str,
        /// The observable.
        observable: Observable,
        /// Its value.
        value: f64,
    },
    /// Another number of the result (a relative gain, a noise or residual spectrum, a band
    /// check) is not finite.
    Value {
        /// What it is, with the observable or input and the bin.
        what: String,
        /// Its value.
        value: f64,
    },
    /// A sample of the prediction or the cleaned record is not finite.
    Sample {
        /// The observable.
        observable: Observable,
        /// The sample.
        index: usize,
        /// Its value.
        value: f64,
    },
}

impl SubtractFailure {
    /// The message, one line, with the options spelled as the front end in use does.
    pub(crate) fn message(&self) -> String {
        match self {
            SubtractFailure::TooManyColocated(n) => format!(
                "{} is given {n} times: give one record (a huddle test with the witness) or two \
                 (a three-cornered hat)",
                OptionKey::COLOCATED
            ),
            SubtractFailure::RatioNeedsOneColocated => format!(
                "{} applies to a huddle test: give exactly one {} record (a three-cornered hat \
                 needs no noise ratio)",
                OptionKey::COLOCATED_RATIO,
                OptionKey::COLOCATED
            ),
            SubtractFailure::RatioUnrecorded {
                item,
                input,
                option,
                path,
                present,
            } => format!(
                "{} {item}: {} {path} has no input {input}; it has {} (the ratio applies to an \
                 input that the witness and the co-located record both record)",
                OptionKey::COLOCATED_RATIO,
                option,
                present.join(", ")
            ),
            SubtractFailure::WitnessSpectra { option, path } => format!(
                "{} {path}: holds spectra; subtract needs a time series of the floor's motion \
                 (tilt angle or rate, and translation)",
                option
            ),
            SubtractFailure::MeasuredSpectra(path) => format!(
                "{} {path}: holds spectra; subtract needs a time series of the observables \
                 (HDF5 as `tiltnoise simulate` writes, or CSV time_s,X,...)",
                OptionKey::MEASURED
            ),
            SubtractFailure::Channels {
                option,
                path,
                problem,
            } => format!("{} {path}: {problem}", option),
            SubtractFailure::StartTime {
                option,
                path,
                value,
            } => format!(
                "{} {path}: start time `{}` is not an ISO 8601 date-time",
                option,
                Shown(value)
            ),
            SubtractFailure::RepeatedChannel { path, observable } => format!(
                "{} {path}: channel {} appears twice; give each observable once",
                OptionKey::MEASURED,
                observable.name()
            ),
            SubtractFailure::MissingChannel {
                path,
                observable,
                present,
            } => format!(
                "{} {name}: {} {path} has no channel {name}; it has {}",
                OptionKey::OBSERVABLES,
                OptionKey::MEASURED,
                present
                    .iter()
                    .map(|o| o.name())
                    .collect::<Vec<_>>()
                    .join(", "),
                name = observable.name()
            ),
            SubtractFailure::Run {
                tilt,
                measured,
                reason,
            } => format!(
                "subtract {} {tilt} {} {measured}: {}",
                OptionKey::TILT,
                OptionKey::MEASURED,
                reason.message()
            ),
        }
    }
}

impl RunFailure {
    fn message(&self) -> String {
        match self {
            RunFailure::Refused(e) => e.to_string(),
            RunFailure::Estimate { name, value, sigma } => format!(
                "the fit of {name} gave {value} +/- {sigma}: not finite (the data may be \
                 degenerate; fit fewer parameters)"
            ),
            RunFailure::Chi2(chi2) => format!("the fit's chi^2 is {chi2}: not finite"),
            RunFailure::Band {
                what,
                observable,
                value,
            } => format!(
                "the {what} ASD of {} in the report band is {value}: not finite (is the channel \
                 constant or noiseless there? leave it out with {})",
                observable.name(),
                OptionKey::OBSERVABLES
            ),
            RunFailure::Value { what, value } => {
                format!("the {what} is {value}: not finite; nothing was written")
            }
            RunFailure::Sample {
                observable,
                index,
                value,
            } => format!(
                "the prediction of {} at sample {index} is {value}: not finite",
                observable.name()
            ),
        }
    }
}
