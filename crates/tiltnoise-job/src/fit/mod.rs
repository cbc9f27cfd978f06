//! The fit job: measured mode frequencies and visibilities (files read once, or Table II's
//! measured column) to the constrained least-squares fit of chosen parameters within their
//! error bars ([`tiltnoise_core::fit`]).

mod json;

pub use json::{save, OUTPUT_KINDS};

use crate::error::JobError;
use crate::outcome::{Invocation, Provenance};
use crate::progress::Progress;
use std::path::{Path, PathBuf};
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::fit::{self, FitConfig, FitError, FitResult, Measured, Visibilities};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::refuse_repeats;

/// A fit to run.
pub struct FitRequest<'a> {
    /// The nominal parameters, the fit's start and the centre of its box.
    pub params: &'a Params,
    /// Measured mode frequencies, CSV `mode,frequency_hz[,sigma_hz]` (default: Table II's
    /// measured column, or none when `visibility` is given).
    pub measured: Option<PathBuf>,
    /// Measured mode visibilities, CSV `mode,observable,reference,ratio[,sigma]`.
    pub visibility: Option<PathBuf>,
    /// Free parameters, dotted keys, each once (default: `FitConfig::default().free`).
    pub free: Option<Vec<String>>,
    /// Box half-width in error bars.
    pub bound_sigmas: f64,
    /// Add the Gaussian prior to chi^2.
    pub prior: bool,
    /// Who asked for the fit (the provenance of its files).
    pub invocation: Invocation,
}

impl FitRequest<'_> {
    /// The files the job reads besides the parameter file, each with the option (snake case)
    /// that names it.
    pub fn input_files(&self) -> Vec<(&'static str, &Path)> {
        let measured = self
            .measured
            .iter()
            .map(|p| ("measured_modes", p.as_path()));
        let visibility = self.visibility.iter().map(|p| ("visibility", p.as_path()));
        measured.chain(visibility).collect()
    }
}

/// A fit and what it was measured against.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct FitOutcome {
    /// The fit.
    pub result: FitResult,
    /// Where the measured frequencies came from.
    pub origin: String,
    /// What the files record: the nominal parameters and the invocation.
    pub provenance: Provenance,
}

fn file_error(e: FitError) -> JobError {
    JobError::FitFile(Box::new(e))
}

/// Runs the fit: reads the measured frequencies and visibilities, checks the free keys and
/// fits. A fit takes seconds: `progress` is only told that it is over.
///
/// # Errors
///
/// A [`JobError`]: `FitFile` for a file that cannot be read or is not valid (named); `Fit`
/// for a key or bound that is not allowed, a fit that fails or is cancelled; `Repeated` for a key given
/// twice.
pub fn run(
    req: &FitRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<FitOutcome, JobError> {
    let outcome = fit(req, cancel);
    progress.finish();
    outcome
}

fn fit(req: &FitRequest<'_>, cancel: &Cancel) -> Result<FitOutcome, JobError> {
    // Visibilities without a frequency file are fitted alone: Table II's frequencies belong to
    // the paper's pendulum, not to the one whose record gave the visibilities.
    let measured = match (&req.measured, &req.visibility) {
        (Some(path), _) => tiltnoise_io::read_measured_modes(path).map_err(file_error)?,
        (None, None) => Measured::table_ii(),
        (None, Some(_)) => Measured {
            modes: Vec::new(),
            origin: "no frequency file".into(),
        },
    };
    let visibilities = match &req.visibility {
        Some(path) => tiltnoise_io::read_visibilities(path).map_err(file_error)?,
        None => Visibilities::none(),
    };
    let free = match &req.free {
        Some(keys) => {
            let keys: Vec<String> = keys.iter().map(|k| k.trim().to_string()).collect();
            refuse_repeats(OptionKey::FREE, "parameter key", &keys, String::clone)
                .map_err(JobError::Repeated)?;
            keys
        }
        None => FitConfig::default().free,
    };
    let config = FitConfig {
        free,
        bound_sigmas: req.bound_sigmas,
        prior: req.prior,
        cancel: cancel.clone(),
    };
    let result = fit::fit_with_visibilities(req.params, &measured, &visibilities, &config)?;
    Ok(FitOutcome {
        result,
        origin: measured.origin,
        provenance: req.invocation.provenance(req.params, None),
    })
}
