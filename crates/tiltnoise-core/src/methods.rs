//! The methods table: every evaluation method's accuracy against the double-double reference
//! and its cost per frequency point, for the user's parameters and grid (`tiltnoise methods`).
//!
//! Accuracy: the worst relative error over every structurally nonzero entry and every grid
//! point farther than 1 % from a normal mode (a structural zero must be exactly zero, else the
//! error is infinite). Cost: wall time of evaluating the whole grid with
//! [`crate::tf::evaluate_into`] into a reused matrix (the plan's own layout, as
//! [`crate::tf::evaluate`] stores it), repeated until at least [`MIN_TIMING_S`] has passed,
//! divided by the points evaluated; single thread.

use crate::error::Num;
use crate::model::Model;
use crate::modes::NormalModes;
use crate::reference::{relative_errors, ReferenceModel};
use crate::tf::POLE_EXCLUSION;
use crate::tf::{evaluate_into, plan, Method, Request, TransferMatrix};
use num_complex::Complex64;
use std::time::Instant;

/// Minimum wall time of a timing run (s): long enough to average out scheduler noise.
pub const MIN_TIMING_S: f64 = 0.05;

/// One row of the methods table.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodRow {
    /// The method.
    pub method: Method,
    /// Worst relative error and where: (error, entry "OUT/IN", frequency in Hz); `None` when
    /// the method cannot serve the request.
    pub worst: Option<(f64, String, f64)>,
    /// Why the method is not usable (unsupported input, singular point).
    pub unusable: Option<String>,
    /// Nanoseconds per frequency point (whole request matrix), when usable.
    pub ns_per_point: Option<f64>,
    /// Whether every structurally zero entry came out exactly 0.
    pub exact_zeros: Option<bool>,
}

/// Evaluates every method of [`Method::ALL`] on `grid`.
pub fn methods_table(model: &Model, request: &Request, grid: &[f64]) -> Vec<MethodRow> {
    let reference = ReferenceModel::new(model.params());
    let modes = NormalModes::new(model).frequencies_hz();
    let checked: Vec<f64> = grid
        .iter()
        .copied()
        .filter(|f| modes.iter().all(|m| ((f - m) / m).abs() > POLE_EXCLUSION))
        .collect();
    let wants: Vec<_> = checked
        .iter()
        .map(|&f| reference.eval_dd(request, f))
        .collect();
    let ni = request.inputs.len();
    let entry = |idx: usize| {
        format!(
            "{}/{}",
            request.outputs[idx / ni].name(),
            request.inputs[idx % ni].name()
        )
    };
    Method::ALL
        .iter()
        .map(|&method| {
            let unusable = |why: String| MethodRow {
                method,
                worst: None,
                unusable: Some(why),
                ns_per_point: None,
                exact_zeros: None,
            };
            let tf = match plan(model, request, method) {
                Ok(tf) => tf,
                Err(e) => return unusable(e.to_string()),
            };
            let mut worst = (0.0f64, String::new(), 0.0);
            let mut exact_zeros = true;
            for (&f, want) in checked.iter().zip(&wants) {
                let (got, want) = match (tf.eval(f), want) {
                    (Ok(g), Ok(w)) => (g, w),
                    (Err(e), _) => return unusable(format!("at {} Hz: {e}", Num(f))),
                    (_, Err(e)) => return unusable(format!("reference at {} Hz: {e}", Num(f))),
                };
                for (idx, err) in relative_errors(&got, want).into_iter().enumerate() {
                    if want[idx].to_c64() == Complex64::new(0.0, 0.0)
                        && got[idx] != want[idx].to_c64()
                    {
                        exact_zeros = false;
                    }
                    if err > worst.0 || err.is_nan() {
                        worst = (err, entry(idx), f);
                    }
                }
            }
            // The whole grid into a reused matrix in the plan's layout, as `tf::evaluate` does
            // minus the allocation of its result. A point on a pole is an error for LU methods;
            // timing does not need the values.
            let mut out = TransferMatrix::from_dense(Vec::new(), vec![], vec![], method, &[]);
            let start = Instant::now();
            let mut points = 0usize;
            while start.elapsed().as_secs_f64() < MIN_TIMING_S || points == 0 {
                let _ = evaluate_into(tf.as_ref(), grid, 1, &mut out);
                points += grid.len();
            }
            MethodRow {
                method,
                worst: Some(worst),
                unusable: None,
                ns_per_point: Some(start.elapsed().as_secs_f64() * 1e9 / points as f64),
                exact_zeros: Some(exact_zeros),
            }
        })
        .collect()
}
