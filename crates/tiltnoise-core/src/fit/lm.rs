//! Levenberg-Marquardt on a box `|u_i| <= bound`, with an active set: minimizes
//! `cost(u) = |r(u)|^2 / 2` for residuals `r` with Jacobian `J = dr/du`.
//!
//! Each iteration fixes the variables that sit on a bound with the gradient `g = J^T r` pushing
//! them outwards, solves the damped normal equations `(A + lambda diag(A)) d = -g` on the
//! others (`A = J^T J` restricted to them; Marquardt's scaling, so the step does not depend on
//! the units of `u`), projects `u + d` onto the box and accepts it if the cost decreases, or
//! stays equal to rounding while the projected gradient falls (`lambda / 3`), otherwise
//! retries with `4 lambda` (also when the step is not finite, or the residuals are not
//! finite there, which `eval` reports as an error). It stops when the projected gradient
//! `|u - clamp(u - g)|_inf` is at most `gtol` (first-order optimality on the box), or when
//! `lambda` exceeds [`LAMBDA_MAX`] (no decreasing step exists at working precision). There is
//! deliberately no small-step test: with a large `lambda` the accepted steps are small long
//! before the minimum, and such a test stops early.
//!
//! Pure numerics on `nalgebra` dynamic matrices; knows nothing of pendulums.

use nalgebra::{DMatrix, DVector};

/// Damping above which no step is attempted any more: the step is then `~ g / (lambda A_ii)`,
/// below the rounding of `u` for any `A_ii` and `g` met in practice.
pub const LAMBDA_MAX: f64 = 1e16;

/// The damping's starting value, relative to `diag(A)` (Marquardt's classic 1e-3: nearly a
/// Gauss-Newton step).
pub const INITIAL_LAMBDA: f64 = 1e-3;

/// Relative rounding error of the cost `|r|^2 / 2` of a few residuals (a few eps): cost
/// differences below it are not a reliable measure of progress.
pub const COST_ROUNDING: f64 = 8.0 * f64::EPSILON;

/// Stopping settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    /// Projected-gradient tolerance (units of the cost per unit of u).
    pub gtol: f64,
    /// Iteration limit (an iteration is one accepted or rejected step).
    pub max_iterations: usize,
}

/// Why the iteration stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Stop {
    /// Projected gradient below `gtol`.
    Gradient,
    /// `lambda` exceeded [`LAMBDA_MAX`]: no decrease possible at working precision.
    NoDecrease,
    /// `max_iterations` reached.
    MaxIterations,
}

impl Stop {
    /// Short description for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Stop::Gradient => "projected gradient below tolerance",
            Stop::NoDecrease => "no decreasing step at working precision",
            Stop::MaxIterations => "iteration limit reached (not converged)",
        }
    }
}

/// The state at the end of the iteration.
#[derive(Debug, Clone)]
pub struct LmOutcome {
    /// Solution in the scaled variables.
    pub u: DVector<f64>,
    /// Residuals at `u`.
    pub r: DVector<f64>,
    /// Jacobian at `u`.
    pub jac: DMatrix<f64>,
    /// Iterations done.
    pub iterations: usize,
    /// Residual evaluations (with Jacobian) done.
    pub evaluations: usize,
    /// Why it stopped.
    pub stop: Stop,
    /// `|u - clamp(u - J^T r)|_inf` at `u`.
    pub projected_gradient: f64,
}

/// Minimizes `|r(u)|^2 / 2` over `|u_i| <= bound` from `u0` (projected onto the box first).
/// `eval` returns residuals and Jacobian, or an error for a point where they do not exist
/// (a non-physical parameter set): such a trial step is rejected like one that raises the cost.
/// An error at the starting point is returned.
pub fn minimize<E>(
    u0: DVector<f64>,
    bound: f64,
    opts: &LmOptions,
    mut eval: impl FnMut(&DVector<f64>) -> Result<(DVector<f64>, DMatrix<f64>), E>,
) -> Result<LmOutcome, E> {
    let clamp = |u: &DVector<f64>| u.map(|x| x.clamp(-bound, bound));
    let mut u = clamp(&u0);
    let (mut r, mut jac) = eval(&u)?;
    let mut evaluations = 1;
    let mut cost = 0.5 * r.norm_squared();
    // The damping multiplies diag(A) (Marquardt's scaling), so it is dimensionless: a start
    // scaled by A's own size would damp a steep problem (large residuals per error bar) so
    // hard that no step could lower the cost measurably.
    let mut lambda = INITIAL_LAMBDA;
    let mut iterations = 0;
    let stop = loop {
        let g = jac.transpose() * &r;
        if projected_gradient(&u, &g, bound) <= opts.gtol {
            break Stop::Gradient;
        }
        if iterations >= opts.max_iterations {
            break Stop::MaxIterations;
        }
        if lambda > LAMBDA_MAX {
            break Stop::NoDecrease;
        }
        iterations += 1;
        let free: Vec<usize> = (0..u.len())
            .filter(|&i| !((u[i] >= bound && g[i] < 0.0) || (u[i] <= -bound && g[i] > 0.0)))
            .collect();
        let jf = jac.select_columns(&free);
        let a = jf.transpose() * &jf;
        let mut damped = a.clone();
        for i in 0..free.len() {
            damped[(i, i)] += lambda * a[(i, i)].max(f64::MIN_POSITIVE);
        }
        let gf = DVector::from_iterator(free.len(), free.iter().map(|&i| g[i]));
        let Some(step) = damped.cholesky().map(|c| c.solve(&(-gf))) else {
            lambda *= 4.0;
            continue;
        };
        // Near a minimum with a large residual the cost changes by less than its rounding
        // (|du| below sqrt(eps cost / A_ii)); there a step is accepted when the cost is equal
        // to rounding and the projected gradient falls, so the iteration still reaches a
        // first-order point instead of stopping sqrt(eps) short of it.
        let pg = projected_gradient(&u, &g, bound);
        let better = |t: &DVector<f64>, r_new: &DVector<f64>, j_new: &DMatrix<f64>| {
            let c = 0.5 * r_new.norm_squared();
            c < cost
                || (c <= cost * (1.0 + COST_ROUNDING)
                    && projected_gradient(t, &(j_new.transpose() * r_new), bound) < pg)
        };
        let mut trial = u.clone();
        for (s, &i) in step.iter().zip(&free) {
            trial[i] += s;
        }
        let trial = clamp(&trial);
        // A step that is not finite (the damped system of a Jacobian near overflow) is
        // rejected like one that raises the cost, never evaluated.
        if trial.iter().any(|x| !x.is_finite()) {
            lambda *= 4.0;
            continue;
        }
        evaluations += 1;
        match eval(&trial) {
            Ok((r_new, jac_new)) if better(&trial, &r_new, &jac_new) => {
                u = trial;
                r = r_new;
                jac = jac_new;
                cost = 0.5 * r.norm_squared();
                lambda /= 3.0;
            }
            _ => lambda *= 4.0,
        }
    };
    let g = jac.transpose() * &r;
    Ok(LmOutcome {
        projected_gradient: projected_gradient(&u, &g, bound),
        u,
        r,
        jac,
        iterations,
        evaluations,
        stop,
    })
}

/// `|u - clamp(u - g)|_inf`: zero exactly at a first-order point of the box problem.
fn projected_gradient(u: &DVector<f64>, g: &DVector<f64>, bound: f64) -> f64 {
    u.iter()
        .zip(g.iter())
        .map(|(&ui, &gi)| (ui - (ui - gi).clamp(-bound, bound)).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Linear least squares `r = A u - b` with a known unconstrained solution inside the box
    /// and one outside it: LM must land on the exact minimizer, then on the bound.
    #[test]
    fn linear_problem_inside_and_on_the_bound() {
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 0.5, 0.0, 2.0, 1.0, 1.0]);
        let opts = LmOptions {
            gtol: 1e-13,
            max_iterations: 200,
        };
        for (truth, bound) in [([0.3, -0.2], 1.0), ([3.0, -0.2], 1.0)] {
            let t = DVector::from_row_slice(&truth);
            let b = &a * &t;
            let out = minimize(DVector::zeros(2), bound, &opts, |u| {
                Ok::<_, ()>((&a * u - &b, a.clone()))
            })
            .unwrap();
            // Inside: the minimizer is the truth; a first-order point with |g| <= gtol is within
            // gtol / sigma_min(A)^2 of it (sigma_min^2 > 1 here), plus rounding.
            if truth[0] <= bound {
                assert!((&out.u - &t).amax() <= 1e-12, "{:?}", out.u);
            } else {
                // On the bound u_0 = 1: the minimizer of the rest with u_0 fixed.
                assert_eq!(out.u[0], bound);
                let rest = a.column(1);
                let want = rest.dot(&(&b - a.column(0) * bound)) / rest.norm_squared();
                assert!((out.u[1] - want).abs() <= 1e-12, "{} vs {want}", out.u[1]);
            }
        }
    }

    /// Normal equations that overflow (a Jacobian of 1e200) and trial points where the
    /// residuals do not exist: every such step is rejected, and the iteration ends within its
    /// bound, at the (finite) starting point.
    #[test]
    fn overflowing_steps_are_rejected_and_the_iteration_ends() {
        let opts = LmOptions {
            gtol: 1e-13,
            max_iterations: 50,
        };
        let out = minimize(DVector::from_element(1, 0.5), 1.0, &opts, |u| {
            if u[0] != 0.5 {
                return Err(());
            }
            Ok((
                DVector::from_element(1, 1e200),
                DMatrix::from_element(1, 1, 1e200),
            ))
        })
        .unwrap();
        assert!(out.iterations <= opts.max_iterations);
        assert_eq!(out.u[0], 0.5);
        assert!(matches!(out.stop, Stop::NoDecrease | Stop::MaxIterations));
    }
}
