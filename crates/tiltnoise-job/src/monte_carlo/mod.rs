//! The Monte Carlo job: the normal modes over the parameter errors (the error model of the
//! parameter file, see [`tiltnoise_core::params::uncertainty`]), with the nominal modes beside
//! them; its report and files ([`summary_json`], [`save`]), the same for every front end.

mod outputs;

pub use outputs::{caption, save, summary_json, OUTPUT_KINDS};

use crate::error::JobError;
use crate::outcome::{Invocation, Provenance};
use crate::progress::Progress;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::mc::{self, McConfig, McResult};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_plot::View;

/// A Monte Carlo of the modes to run.
#[derive(Debug, Clone)]
pub struct McRequest<'a> {
    /// The nominal parameters and their error model.
    pub params: &'a Params,
    /// Number of draws.
    pub samples: usize,
    /// Seed of the random streams (the result depends on it alone).
    pub seed: u64,
    /// Worker threads (0: every core); the result does not depend on it.
    pub threads: usize,
    /// Who asked for the run (the provenance of its files).
    pub invocation: Invocation,
    /// The histograms' limits, size and resolution (`.png`/`.svg` outputs).
    pub figure: View,
}

/// The draws, the configuration they were made with and the nominal modes.
pub struct McRun {
    /// The draws and their statistics.
    pub result: McResult,
    /// The configuration (the error model drawn from).
    pub config: McConfig,
    /// The nominal mode frequencies (Hz), ascending.
    pub nominal_hz: [f64; 8],
    /// What the files record: the parameters and the invocation.
    pub provenance: Provenance,
    /// The histograms' limits, size and resolution.
    pub figure: View,
}

/// Refuses more draws or threads than allowed or than fit into memory, before anything is
/// allocated (a front end checks this before its outputs).
///
/// # Errors
///
/// [`JobError::MonteCarlo`] naming `samples` or `threads`.
pub fn check(req: &McRequest<'_>) -> Result<(), JobError> {
    let names = (OptionKey::SAMPLES, OptionKey::THREADS);
    mc::check_size(req.samples, req.threads, names)
        .map_err(|e| JobError::MonteCarlo(Box::new(e.into())))
}

/// The configuration `req` runs with: the error model of its parameters, polling `cancel`.
/// A front end that keeps a result without its configuration rebuilds it with this.
pub fn config(req: &McRequest<'_>, cancel: &Cancel) -> McConfig {
    McConfig {
        samples: req.samples,
        seed: req.seed,
        threads: req.threads,
        cancel: cancel.clone(),
        ..McConfig::default_for(req.params)
    }
}

/// Runs the Monte Carlo; `progress` is told, from the workers, the draws done of
/// `req.samples` (and finished once, also on a failure).
///
/// # Errors
///
/// [`JobError::MonteCarlo`]: sizes over their limits, an error model that cannot be used,
/// every draw rejected, or `cancel` set.
pub fn run(
    req: &McRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<McRun, JobError> {
    check(req)?;
    let config = config(req, cancel);
    let mc_error = |e: mc::McError| JobError::MonteCarlo(Box::new(e));
    let total = req.samples as u64;
    let drawn = mc::run(req.params, &config, &|done| {
        progress.report(done as u64, total)
    });
    progress.finish();
    let result = drawn.map_err(mc_error)?;
    let model = Model::new(req.params).map_err(|e| mc_error(e.into()))?;
    let nominal: Vec<f64> = NormalModes::new(&model).frequencies_hz();
    let nominal_hz = <[f64; 8]>::try_from(nominal.as_slice())
        .expect("the model has eight coordinates, so eight modes");
    Ok(McRun {
        result,
        config,
        nominal_hz,
        provenance: req.invocation.provenance(req.params, None),
        figure: req.figure.clone(),
    })
}
