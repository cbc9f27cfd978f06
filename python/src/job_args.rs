//! The budget job's options from Python arguments: `observables`, `readout` (white or
//! coloured), `term`, `at`; and the job's errors as Python exceptions, in keyword spelling.
//! The job (`tiltnoise_job`) reads the files and checks everything against the budget, as it
//! does for the command line.

use crate::args;
use crate::errors::{read_error, value_error, InputFileError, IntoPyErr, PyResultExt};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use tiltnoise_core::budget::BudgetError;
use tiltnoise_core::fit::FitError;
use tiltnoise_core::input::AxisMap;
use tiltnoise_core::model::Observable;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options::{self, observable_names};
use tiltnoise_core::repeats::refuse_repeats;
use tiltnoise_core::simulate::SimError;
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::{AsdSpec, JobError, ReadoutItem, TermItem, WitnessItem};

/// A job's error as the exception of its kind (`errors`' rules), with the message in keyword
/// spelling.
pub fn job_error(e: JobError) -> PyErr {
    let message = crate::errors::shown(&e);
    let kind = match e {
        JobError::Input(e) | JobError::OptionFile { source: e, .. } => (*e).into_py_err(),
        JobError::Budget { source, .. } => match *source {
            BudgetError::Input(e) => e.into_py_err(),
            other => other.into_py_err(),
        },
        JobError::Tf(e) => (*e).into_py_err(),
        JobError::Freq(e) => (*e).into_py_err(),
        JobError::MonteCarlo(e) => (*e).into_py_err(),
        JobError::FitFile(e) => match *e {
            FitError::Read { reason, .. } => return read_error(&reason, message),
            FitError::Measured { .. } | FitError::Visibility { .. } => {
                return InputFileError::new_err(message)
            }
            FitError::TooLarge(e) => e.into_py_err(),
            _ => return value_error(message),
        },
        JobError::Fit(e) => match *e {
            FitError::TooLarge(e) => e.into_py_err(),
            _ => return value_error(message),
        },
        JobError::Simulate(e) => match *e {
            SimError::TooLarge(e) => e.into_py_err(),
            _ => return value_error(message),
        },
        JobError::Refused(e) => (*e).into_py_err(),
        JobError::Spectral(e) => (*e).into_py_err(),
        JobError::Output(e) => (*e).into_py_err(),
        _ => return value_error(message),
    };
    Python::attach(|py| PyErr::from_type(kind.get_type(py), message))
}

/// How to read a record of the floor's motion from `axes` (the axis map), `quantity`,
/// `gaps` and `scale` (`{channel: factor}`), as the command line's options of the same names.
pub fn read_request(
    axes: Option<String>,
    quantity: Option<String>,
    gaps: Option<String>,
    scale: Option<std::collections::BTreeMap<String, f64>>,
) -> PyResult<ReadRequest> {
    let scale: Vec<String> = scale
        .unwrap_or_default()
        .iter()
        .map(|(c, f)| format!("{c}={f:?}"))
        .collect();
    Ok(ReadRequest {
        axis_map: axes
            .as_deref()
            .map(AxisMap::parse)
            .transpose()
            .map_err(|e| value_error(crate::errors::shown(&e)))?,
        quantity: quantity
            .as_deref()
            .map(str::parse)
            .transpose()
            .map_err(value_error)?,
        gaps: gaps
            .as_deref()
            .map(str::parse)
            .transpose()
            .map_err(value_error)?,
        scale: options::parse_keyed_items(OptionKey::SCALE, "channel", &scale).py()?,
        ..ReadRequest::default()
    })
}

/// The channel lists of a record of the floor's motion: the translation channels `corrected`
/// already and the tilt channels read by a `pendulum_tiltmeter` (each a `str` or a sequence of
/// them, [`crate::args::strings`]; none by default).
pub struct ChannelLists {
    /// `corrected=`.
    pub corrected: Vec<String>,
    /// `pendulum_tiltmeter=`.
    pub pendulum_tiltmeter: Vec<String>,
}

impl ChannelLists {
    /// The lists of the keywords `corrected` and `pendulum_tiltmeter`.
    pub fn of(
        corrected: Option<&Bound<'_, PyAny>>,
        pendulum_tiltmeter: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<ChannelLists> {
        Ok(ChannelLists {
            corrected: args::strings("corrected", corrected)?.unwrap_or_default(),
            pendulum_tiltmeter: args::strings("pendulum_tiltmeter", pendulum_tiltmeter)?
                .unwrap_or_default(),
        })
    }
}

/// How to read a record of the floor's motion from a file: [`read_request`]'s options and
/// `units` (`{channel: unit}`), and the [`ChannelLists`], each channel once.
pub fn file_read_request(
    axes: Option<String>,
    quantity: Option<String>,
    units: Option<std::collections::BTreeMap<String, String>>,
    channels_of: ChannelLists,
    gaps: Option<String>,
    scale: Option<std::collections::BTreeMap<String, f64>>,
) -> PyResult<ReadRequest> {
    let names_once = |option: OptionKey, names: Vec<String>| -> PyResult<Vec<String>> {
        refuse_repeats(option, "channel", &names, |n| n.clone())
            .map_err(|e| value_error(crate::errors::shown(&e)))?;
        Ok(names)
    };
    Ok(ReadRequest {
        units: options::parse_keyed_items(
            OptionKey::UNITS,
            "channel",
            &units
                .unwrap_or_default()
                .iter()
                .map(|(c, u)| format!("{c}={u}"))
                .collect::<Vec<_>>(),
        )
        .py()?,
        corrected: names_once(OptionKey::CORRECTED, channels_of.corrected)?,
        pendulum_tiltmeter: names_once(
            OptionKey::PENDULUM_TILTMETER,
            channels_of.pendulum_tiltmeter,
        )?,
        ..read_request(axes, quantity, gaps, scale)?
    })
}

/// `observables`: a list of names or a comma-separated string, each once.
pub fn observables(arg: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<Observable>>> {
    let Some(arg) = arg else {
        return Ok(None);
    };
    let names = args::names("observables", Some(arg))?.unwrap_or_default();
    options::parse_outputs(OptionKey::OBSERVABLES, &names)
        .py()
        .map(Some)
}

/// `readout`: `{observable: ASD}` (white, unit/sqrt(Hz); 0 removes it) or `{observable:
/// path}` (coloured, a CSV or HDF5 ASD file), over the default 9e-9 m/sqrt(Hz) on X.
pub fn readout(arg: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<ReadoutItem>> {
    let Some(d) = arg else {
        return Ok(Vec::new());
    };
    const EXPECTED: &str = "a dict {observable: ASD (a number) or ASD file (a path)}";
    let mut items = Vec::new();
    for (name, value) in args::entries("readout", d, EXPECTED)? {
        if let Some(path) = args::path_of(&value) {
            let observable = Observable::from_name(&name).ok_or_else(|| {
                value_error(format!(
                    "readout {name}=...: unknown observable `{name}`; allowed: {}",
                    observable_names()
                ))
            })?;
            items.push(ReadoutItem {
                observable,
                asd: AsdSpec::File(path),
            });
            continue;
        }
        let asd = args::number_of(&value)
            .ok_or_else(|| args::entry_error("readout", d, EXPECTED, &name, &value))?;
        let (observable, asd) = options::readout_item(OptionKey::READOUT, &name, asd).py()?;
        items.push(ReadoutItem {
            observable,
            asd: AsdSpec::White(asd),
        });
    }
    Ok(items)
}

/// `term`: `{name: (source, path)}`, `source` an observable or an input of the model.
pub fn terms(arg: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<TermItem>> {
    let Some(d) = arg else {
        return Ok(Vec::new());
    };
    const EXPECTED: &str =
        "a dict {name: (source, path)}, e.g. {\"mag\": (\"phi\", \"phi_mag.csv\")}";
    let mut items = Vec::new();
    for (name, value) in args::entries("term", d, EXPECTED)? {
        let pair = value
            .extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>()
            .ok()
            .and_then(|(s, f)| Some((s.extract::<String>().ok()?, args::path_of(&f)?)));
        let Some((source, file)) = pair else {
            return Err(args::entry_error("term", d, EXPECTED, &name, &value));
        };
        let source = options::term_source(OptionKey::TERM, &format!("{name}=..."), &source).py()?;
        items.push(TermItem { name, source, file });
    }
    Ok(items)
}

/// The keyword that names each of the job's input files in the Python call (`files` from the
/// request's `input_files`, by the command line's option names), for the rule that no `save`
/// replaces one: `renamed` lists the options whose keyword differs in this call (the tilt
/// file is `path=` in `budget_from_file`, `tilt=` in `subtract` and `coherence`).
pub fn python_names<'a>(
    files: Vec<(&'static str, &'a std::path::Path)>,
    renamed: &'static [(&'static str, &'static str)],
) -> impl Iterator<Item = (&'static str, &'a std::path::Path)> {
    files.into_iter().map(move |(option, path)| {
        let keyword = renamed
            .iter()
            .find(|(o, _)| *o == option)
            .map_or(option, |(_, k)| *k);
        (keyword, path)
    })
}

/// `witness_noise`: `{input: ASD}` (white, in the input's unit/sqrt(Hz)), `{input: path}` (an
/// ASD file), or either as `(value, rel)` with the ASD's relative uncertainty; `input` a floor
/// input of the model, `theta_t` .. `z_t`.
pub fn witness_noise(arg: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<WitnessItem>> {
    let Some(d) = arg else {
        return Ok(Vec::new());
    };
    const EXPECTED: &str = "a dict {input: ASD (a number) or ASD file (a path), or either \
                            with its relative uncertainty as (value, rel)}";
    let mut items = Vec::new();
    for (name, value) in args::entries("witness_noise", d, EXPECTED)? {
        let input =
            options::floor_input(OptionKey::WITNESS_NOISE, &format!("{name}=..."), &name).py()?;
        let (level, rel) = match value.extract::<(Bound<'_, PyAny>, Bound<'_, PyAny>)>() {
            Ok((level, rel)) => match args::number_of(&rel) {
                Some(rel) => (level, rel),
                None => {
                    return Err(args::entry_error(
                        "witness_noise",
                        d,
                        EXPECTED,
                        &name,
                        &value,
                    ))
                }
            },
            Err(_) => (value.clone(), 0.0),
        };
        let asd = match (args::path_of(&level), args::number_of(&level)) {
            (Some(path), _) => AsdSpec::File(path),
            (None, Some(asd)) => AsdSpec::White(asd),
            (None, None) => {
                return Err(args::entry_error(
                    "witness_noise",
                    d,
                    EXPECTED,
                    &name,
                    &value,
                ))
            }
        };
        items.push(WitnessItem { input, asd, rel });
    }
    Ok(items)
}
