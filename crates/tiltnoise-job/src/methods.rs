//! The methods job: every evaluation method's worst error against the double-double reference
//! and its time per point, for a matrix of the model on a grid, with the method `auto` picks.

use crate::error::JobError;
use std::path::Path;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::methods::{methods_table, MethodRow};
use tiltnoise_core::model::{Input, Model, Observable, Request};
use tiltnoise_core::tf::planner::{NoChoice, DEFAULT_REL_TOL};
use tiltnoise_core::tf::Method;
use tiltnoise_io::{OutputError, Staging};
use tiltnoise_plot::methods_figure::{methods_figure, MethodPoint};
use tiltnoise_plot::View;

/// A comparison of the methods to run.
pub struct MethodsRequest<'a> {
    /// The model.
    pub model: &'a Model,
    /// The grid (Hz), ascending, positive.
    pub grid_hz: Vec<f64>,
    /// Inputs of the matrix (default: the three tilt angles); its rows are every observable.
    pub inputs: Option<Vec<Input>>,
}

/// Every method measured, and `auto`'s pick at the default tolerance.
pub struct MethodsResult {
    /// The matrix measured.
    pub request: Request,
    /// The grid (Hz).
    pub grid_hz: Vec<f64>,
    /// One row per method of [`Method::ALL`], in that order.
    pub rows: Vec<MethodRow>,
    /// What `auto` picks on the grid's band at [`MethodsResult::target_rel_err`], or why none.
    pub auto: Result<Method, NoChoice>,
    /// The tolerance `auto` is asked for.
    pub target_rel_err: f64,
}

impl MethodsResult {
    /// `7x3 tilt matrix`, `7x6 ground matrix`, or the inputs named: what the table measures.
    pub fn matrix_label(&self) -> String {
        let request = &self.request;
        let size = format!("{}x{}", request.outputs.len(), request.inputs.len());
        let groups = [
            ("tilt", Input::all_tilts()),
            ("translation", Input::all_translations()),
            ("ground", Input::all_ground()),
        ];
        match groups.iter().find(|(_, inputs)| *inputs == request.inputs) {
            Some((name, _)) => format!("{size} {name} matrix"),
            None => {
                let names: Vec<&str> = request.inputs.iter().map(|i| i.name()).collect();
                format!("{size} matrix from {}", names.join(", "))
            }
        }
    }

    /// The grid as the chart's title names it: `400 points, 1e-5 to 1e2 Hz`.
    pub fn grid_label(&self) -> String {
        let (lo, hi) = match (self.grid_hz.first(), self.grid_hz.last()) {
            (Some(lo), Some(hi)) => (*lo, *hi),
            _ => (f64::NAN, f64::NAN),
        };
        format!("{} points, {lo:e} to {hi:e} Hz", self.grid_hz.len())
    }

    /// `auto`'s pick as the table and the JSON name it: the method, or `none (why)`.
    pub fn auto_text(&self) -> String {
        match &self.auto {
            Ok(m) => m.name().to_string(),
            Err(refusal) => format!("none ({refusal})"),
        }
    }
}

/// Runs the comparison: checks the grid, asks the planner for its pick and measures every
/// method on the grid.
///
/// # Errors
///
/// [`JobError::Option`] naming `freq_hz` for an empty grid or one with a frequency that is not
/// positive and finite; [`JobError::Cancelled`] when `cancel` was set before the measurement.
pub fn run(req: MethodsRequest<'_>, cancel: &Cancel) -> Result<MethodsResult, JobError> {
    let grid = req.grid_hz;
    if let Some(f) = grid.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
        return Err(JobError::option(
            "freq_hz",
            Some(&f.to_string()),
            "every frequency of the comparison must be finite and > 0 Hz".to_string(),
        ));
    }
    let (Some(&lo), Some(&hi)) = (grid.first(), grid.last()) else {
        return Err(JobError::option(
            "freq_hz",
            None,
            "the comparison needs at least one frequency".to_string(),
        ));
    };
    let request = Request {
        outputs: Observable::ALL.to_vec(),
        inputs: req.inputs.unwrap_or_else(Input::all_tilts),
    };
    let auto = crate::tf::choose(req.model, &request, (lo, hi), DEFAULT_REL_TOL)
        .map(|c| c.method)
        .map_err(|e| match e {
            JobError::NoMethod(refusal) => *refusal,
            other => NoChoice::Band(other.message()),
        });
    cancel.check().map_err(|_| JobError::Cancelled)?;
    let rows = methods_table(req.model, &request, &grid);
    Ok(MethodsResult {
        request,
        grid_hz: grid,
        rows,
        auto,
        target_rel_err: DEFAULT_REL_TOL,
    })
}

/// Saves the chart of a comparison (time per point against worst error, one point per usable
/// method, the target error marked) as `.png` or `.svg`, drawn with `view`, as one of the outputs of `stage`; the
/// same for every front end.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for another extension (nothing is written), or
/// [`OutputError::Write`] naming `path`.
pub fn save(
    stage: &Staging,
    path: &Path,
    result: &MethodsResult,
    view: &View,
) -> Result<(), OutputError> {
    let points: Vec<MethodPoint> = result
        .rows
        .iter()
        .filter_map(|r| {
            Some((
                r.method.name().to_string(),
                r.ns_per_point?,
                r.worst.as_ref()?.0,
            ))
        })
        .collect();
    let title = format!(
        "Speed against accuracy, {}, {}",
        result.matrix_label(),
        result.grid_label()
    );
    crate::save_image(stage, path, |format| {
        methods_figure(&points, result.target_rel_err, &title, view, format)
    })
}
