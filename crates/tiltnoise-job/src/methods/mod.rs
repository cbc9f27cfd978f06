//! The methods job: every evaluation method's worst error against the double-double reference
//! and its time per point, for a matrix of the model on a grid, with the method `auto` picks.

mod outcome;

pub use outcome::MethodsOutcome;

use crate::error::JobError;
use crate::figures::View;
use crate::outcome::Invocation;
use crate::progress::Progress;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::methods::methods_table;
use tiltnoise_core::model::{Input, Model, Observable, Request};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::tf::planner::{NoChoice, DEFAULT_REL_TOL};

/// A comparison of the methods to run.
pub struct MethodsRequest<'a> {
    /// The model.
    pub model: &'a Model,
    /// The grid (Hz), ascending, positive.
    pub grid_hz: Vec<f64>,
    /// Inputs of the matrix (default: the three tilt angles); its rows are every observable.
    pub inputs: Option<Vec<Input>>,
    /// The grid as the user gave it (`1e-5:400:100`), for the JSON's `grid`.
    pub grid_spec: String,
    /// Size and resolution of the chart [`Outcome::save`](crate::Outcome::save) draws.
    pub view: View,
    /// Who asked, for the provenance.
    pub invocation: Invocation,
}

/// Runs the comparison: checks the grid, asks the planner for its pick and measures every
/// method on the grid.
///
/// # Errors
///
/// [`JobError::Option`] naming `freq_hz` for an empty grid or one with a frequency that is not
/// positive and finite; [`JobError::Cancelled`] when `cancel` was set before the measurement.
pub fn run(
    req: &MethodsRequest<'_>,
    cancel: &Cancel,
    progress: &dyn Progress,
) -> Result<MethodsOutcome, JobError> {
    let grid = req.grid_hz.clone();
    if let Some(f) = grid.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        return Err(JobError::option(
            OptionKey::FREQ_HZ,
            Some(&f.to_string()),
            "every frequency of the comparison must be finite and > 0 Hz".to_string(),
        ));
    }
    let (Some(&lo), Some(&hi)) = (grid.first(), grid.last()) else {
        return Err(JobError::option(
            OptionKey::FREQ_HZ,
            None,
            "the comparison needs at least one frequency".to_string(),
        ));
    };
    let request = Request {
        outputs: Observable::ALL.to_vec(),
        inputs: req.inputs.clone().unwrap_or_else(Input::all_tilts),
    };
    let auto = crate::tf::choose(req.model, &request, (lo, hi), DEFAULT_REL_TOL)
        .map(|c| c.method)
        .map_err(|e| match e {
            JobError::NoMethod(refusal) => *refusal,
            other => NoChoice::Band(other.message()),
        });
    cancel.check().map_err(|_| JobError::Cancelled)?;
    let rows = methods_table(req.model, &request, &grid);
    progress.finish();
    Ok(MethodsOutcome {
        request,
        grid_hz: grid,
        rows,
        auto,
        target_rel_err: DEFAULT_REL_TOL,
        grid_spec: req.grid_spec.clone(),
        view: req.view.clone(),
        provenance: crate::modes::provenance(req.model, &req.invocation),
    })
}
