//! The files a result was computed from, kept with it so that no `save` of the result replaces
//! one of them: the command line's rule for `--save` (`tiltnoise_io::check_outputs`: compared
//! by file identity, whatever the spelling, HDF5 addresses included).

use crate::errors::PyResultExt;
use pyo3::PyResult;
use std::path::{Path, PathBuf};

/// The input files of a result, each with the argument that named it (`path`, `measured`,
/// `Params.from_toml`), for the message.
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
    /// (its directory is missing or not writable): `OSError` naming the path and the rule.
    pub fn check_save(&self, path: &Path) -> PyResult<()> {
        let inputs: Vec<(&str, &Path)> = self
            .0
            .iter()
            .map(|(a, p)| (a.as_str(), p.as_path()))
            .collect();
        tiltnoise_io::check_outputs(&[path], &inputs).py()
    }
}
