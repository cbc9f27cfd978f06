//! The normal-modes job: the model's normal modes (Table II: frequencies, quality factors,
//! dominant coordinates, the observables that see each mode, amplitude ratios) and its rest
//! configuration, as the `modes` command prints them.

mod json;
mod outcome;

pub use json::DOMINANT_SHARE;
pub use outcome::ModesOutcome;

use crate::error::JobError;
use crate::outcome::{Invocation, Provenance};
use crate::progress::Progress;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;

/// The normal modes to compute.
pub struct ModesRequest<'a> {
    /// The model.
    pub model: &'a Model,
    /// Who asked, for the provenance.
    pub invocation: Invocation,
}

/// The provenance of a run on `model`: its parameters, its normal modes and `invocation`'s
/// command; every job that records the modes builds it here.
pub(crate) fn provenance(model: &Model, invocation: &Invocation) -> Provenance {
    invocation.provenance(model.params(), Some(&NormalModes::new(model)))
}

/// Runs the job: the normal modes of the model, with its rest configuration.
///
/// # Errors
///
/// [`JobError::Cancelled`] when `cancel` was set.
pub fn run(
    req: &ModesRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<ModesOutcome, JobError> {
    cancel.check().map_err(|_| JobError::Cancelled)?;
    let modes = NormalModes::new(req.model);
    let provenance = req.invocation.provenance(req.model.params(), Some(&modes));
    progress.finish();
    Ok(ModesOutcome {
        modes,
        rest_configuration: req.model.rest_configuration().as_slice().to_vec(),
        symmetric: req.model.is_symmetric(),
        provenance,
    })
}
