//! The one shape of every command: a `Request` (plain values, paths, parsed options), one
//! `run(&Request, &Cancel, &dyn Progress) -> Result<Outcome, JobError>` in the command's own
//! module, and an outcome that carries its [`Provenance`], saves itself by output kind and
//! renders its JSON. The front ends parse their syntax into the request, run it and render
//! tables from the outcome; they never write a file or build provenance themselves.

use crate::error::JobError;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_io::{OutputKind, RunMeta, Staging};

/// The provenance every output of a run records: this tool's version, the effective
/// parameters, the command that asked for the run and the model's normal modes. Built by the
/// job from the request, never by a front end.
pub type Provenance = RunMeta;

/// What the caller tells the job about itself for the provenance: the command as the user
/// typed it (the command line's arguments, or the Python call).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Invocation {
    /// The command line, or the Python call, that asked for the run.
    pub command_line: String,
}

impl Invocation {
    /// The arguments of this process, joined by spaces (the command line's invocation).
    pub fn of_this_process() -> Self {
        Self {
            command_line: std::env::args().collect::<Vec<_>>().join(" "),
        }
    }

    /// The provenance of a run of `params` that this invocation asked for, with the normal
    /// `modes` when the run computed them (the one place a job builds its [`Provenance`]).
    pub fn provenance(&self, params: &Params, modes: Option<&NormalModes>) -> Provenance {
        Provenance {
            command_line: self.command_line.clone(),
            ..RunMeta::of_this_run(params, modes)
        }
    }
}

/// A command's result: saved by output kind, rendered as JSON.
pub trait Outcome {
    /// The provenance the outputs record.
    fn provenance(&self) -> &Provenance;

    /// The output kinds [`Outcome::save`] writes; a path of another kind is refused before
    /// anything is written.
    fn output_kinds(&self) -> &'static [OutputKind];

    /// Saves the outcome to `path` in the kind its extension names, as one of the outputs of
    /// `stage` (the file appears only when `stage` commits).
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] for a kind not in [`Outcome::output_kinds`] (nothing is
    /// written), or the writer's error.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError>;

    /// The outcome as JSON (the command line's `--format json`, Python's `to_json`).
    fn json(&self) -> serde_json::Value;
}

/// The kinds of file of a result on a frequency grid (a budget, a coherence, transfer functions,
/// a simulation's spectra): HDF5, CSV and the figure.
pub const SPECTRA_KINDS: &[OutputKind] = &[
    OutputKind::Hdf5,
    OutputKind::Csv,
    OutputKind::Png,
    OutputKind::Svg,
];

/// The output kind of `path` when it is one of `allowed`: the one output-kind rule of every
/// command.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] naming `path` and the extensions of `allowed`.
pub fn output_kind(path: &Path, allowed: &[OutputKind]) -> Result<OutputKind, OutputError> {
    OutputKind::of_path(path, allowed)
}
