//! The parameters job: the effective parameter set (Table I, a parameter file, overrides) as
//! the `params` command prints it, TOML that reads back unchanged, and the reader of
//! parameter files both front ends call.

mod outcome;

pub use outcome::ParamsOutcome;

use crate::error::JobError;
use crate::outcome::Invocation;
use crate::progress::Progress;
use std::path::Path;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::ParamError;
use tiltnoise_core::params::Params;

/// The parameter set to show.
#[derive(Debug, Clone)]
pub struct ParamsRequest {
    /// The effective parameters (a file read with [`read`], overrides applied).
    pub params: Params,
    /// Who asked, for the provenance.
    pub invocation: Invocation,
}

/// Reads and validates a TOML parameter file (the format the `params` command prints).
///
/// # Errors
///
/// [`ParamError::Read`] when the file cannot be read, another [`ParamError`] naming the key
/// when it is not a valid parameter set.
pub fn read(path: &Path) -> Result<Params, ParamError> {
    tiltnoise_io::read_params(path)
}

/// Runs the job: the parameter set with its provenance (no modes: nothing is solved).
///
/// # Errors
///
/// [`JobError::Cancelled`] when `cancel` was set.
pub fn run(
    req: &ParamsRequest,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<ParamsOutcome, JobError> {
    cancel.check().map_err(|_| JobError::Cancelled)?;
    let provenance = req.invocation.provenance(&req.params, None);
    progress.finish();
    Ok(ParamsOutcome {
        params: req.params.clone(),
        provenance,
    })
}
