//! The files a result was computed from, kept with it so that no `save` of the result replaces
//! one of them: the command line's rule for `--save` (`tiltnoise_job::files::check_outputs`: compared
//! by file identity, whatever the spelling, HDF5 addresses included).

use crate::errors::PyResultExt;
use pyo3::PyResult;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::OutputError;

/// The input files of a result, each with the keyword that named it in its call (`path`,
/// `tilt`, `measured`, `Params.from_toml`), for the message.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub struct Inputs(Vec<(String, PathBuf)>);

impl Inputs {
    /// The parameter file of the model, if its parameters were read from one.
    pub fn of_params(file: Option<&Path>) -> Inputs {
        Inputs::default().with("Params.from_toml", file)
    }

    /// These inputs and `path` (if any), named by the argument `arg`.
    pub fn with(mut self, arg: &'static str, path: Option<&Path>) -> Inputs {
        self.0
            .extend(path.map(|p| (arg.to_string(), p.to_path_buf())));
        self
    }

    /// These inputs and every `(argument, path)` of `files`.
    pub fn with_all<'a>(
        mut self,
        files: impl IntoIterator<Item = (&'static str, &'a Path)>,
    ) -> Inputs {
        self.0.extend(
            files
                .into_iter()
                .map(|(a, p)| (a.to_string(), p.to_path_buf())),
        );
        self
    }

    /// Refuses to save to `path` when it is one of the inputs, or when it cannot be written
    /// (its directory is missing or not writable): `OSError` naming the path and the rule,
    /// the input as what it is to the reader and its keyword (`the tilt input (tilt=) tilt.h5`).
    pub fn check_save(&self, path: &Path) -> PyResult<()> {
        let inputs: Vec<(String, &Path)> = self
            .0
            .iter()
            .map(|(a, p)| (described(a), p.as_path()))
            .collect();
        let labelled: Vec<(&str, &Path)> = inputs.iter().map(|(a, p)| (a.as_str(), *p)).collect();
        match tiltnoise_job::files::check_outputs(&[path], &labelled) {
            Err(OutputError::Refused { path, rule }) => {
                // The library's rule reads `the file OPTION PATH reads` (the command line's
                // spelling, `the file --tilt tilt.h5 reads`): said here without the option.
                let rule = inputs
                    .iter()
                    .map(|(what, input)| {
                        (
                            format!("the file {what} {} reads", input.display()),
                            format!("the {what} {}", input.display()),
                        )
                    })
                    .find(|(said, _)| rule.contains(said.as_str()))
                    .map(|(said, meant)| rule.replacen(&said, &meant, 1))
                    .unwrap_or(rule);
                Err(OutputError::Refused { path, rule }).py()
            }
            other => other.py(),
        }
    }
}

/// The input named by the argument `arg`, as a reader says it: what it is and the keyword
/// that named it (`tilt input (path=)`, `tilt input (tilt=)`, `measured input (measured=)`,
/// `parameter file (Params.from_toml)`).
fn described(arg: &str) -> String {
    match arg {
        "Params.from_toml" => "parameter file (Params.from_toml)".to_string(),
        "path" => "tilt input (path=)".to_string(),
        other => format!("{} input ({other}=)", other.replace('_', " ")),
    }
}
