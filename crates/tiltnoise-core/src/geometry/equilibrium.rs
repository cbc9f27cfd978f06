//! The rest configuration: Newton's method on the gradient of the exact potential, with the
//! exact Hessian from hyper-dual numbers.

use super::kinematics::{gravity, Consts};
use super::scalar::{HyperDual, Real};
use nalgebra::SMatrix;

/// Iterations allowed before the solve is declared divergent (Newton from the drawing's
/// configuration converges in a handful for any offset the parameters admit).
const MAX_ITERATIONS: usize = 40;

/// Largest rest angle (rad) an iterate may reach: far beyond any offset the parameters admit,
/// so an iterate out there has left the basin of the drawing's equilibrium.
const MAX_REST_ANGLE: f64 = 0.5;

/// `q` with the hyper-dual seeds `e1` on coordinate `i` and `e2` on `j`.
pub(super) fn seeded<S: Real>(q: &[S; 8], i: Option<usize>, j: Option<usize>) -> [HyperDual<S>; 8] {
    std::array::from_fn(|k| HyperDual::variable(q[k], i == Some(k), j == Some(k)))
}

/// Gradient and Hessian of the gravity potential (with the fibres' pre-tension) at `q`, the
/// floor level: one hyper-dual evaluation per pair `i <= j`.
pub(super) fn gravity_derivatives<S: Real>(c: &Consts<S>, q: &[S; 8]) -> ([S; 8], [[S; 8]; 8]) {
    let ch = c.map(HyperDual::constant);
    let level = [HyperDual::constant(S::from_f64(0.0)); 3];
    let zero = S::from_f64(0.0);
    let mut grad = [zero; 8];
    let mut upper = [[zero; 8]; 8];
    for (i, row) in upper.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate().skip(i) {
            let u = gravity(&ch, &seeded(q, Some(i), Some(j)), &level);
            *entry = u.e12;
            if i == j {
                grad[i] = u.e1;
            }
        }
    }
    let hess = std::array::from_fn(|i| std::array::from_fn(|j| upper[i.min(j)][i.max(j)]));
    (grad, hess)
}

/// Gradient and Hessian of the whole potential: gravity plus the elastic `1/2 k q^2`.
fn derivatives<S: Real>(c: &Consts<S>, q: &[S; 8]) -> ([S; 8], [[S; 8]; 8]) {
    let (mut grad, mut hess) = gravity_derivatives(c, q);
    for &(k, stiffness) in &c.elastic {
        grad[k] = grad[k] + stiffness * q[k];
        hess[k][k] = hess[k][k] + stiffness;
    }
    (grad, hess)
}

/// Solves `a x = b` by Gaussian elimination with partial pivoting (`a` is symmetric positive
/// definite here, checked by the caller).
fn solve_linear<S: Real>(mut a: [[S; 8]; 8], mut b: [S; 8]) -> [S; 8] {
    for k in 0..8 {
        let p = (k..8)
            .max_by(|&x, &y| a[x][k].to_f64().abs().total_cmp(&a[y][k].to_f64().abs()))
            .unwrap_or(k);
        a.swap(k, p);
        b.swap(k, p);
        let (pivot_row, pivot_b) = (a[k], b[k]);
        for (row, b_i) in a.iter_mut().zip(b.iter_mut()).skip(k + 1) {
            let l = row[k] / pivot_row[k];
            for (x, &y) in row.iter_mut().zip(&pivot_row).skip(k) {
                *x = *x - l * y;
            }
            *b_i = *b_i - l * pivot_b;
        }
    }
    let mut x = b;
    for k in (0..8).rev() {
        let mut s = b[k];
        for j in k + 1..8 {
            s = s - a[k][j] * x[j];
        }
        x[k] = s / a[k][k];
    }
    x
}

/// The potential itself: gravity and pre-tension plus the elastic `1/2 k q^2`.
fn potential<S: Real>(c: &Consts<S>, q: &[S; 8]) -> S {
    let level = [S::from_f64(0.0); 3];
    c.elastic
        .iter()
        .fold(gravity(c, q, &level), |u, &(k, stiffness)| {
            u + S::from_f64(0.5) * stiffness * q[k] * q[k]
        })
}

/// The rest configuration nearest to `start` (the drawing's `q = 0`, or an `f64` solution to
/// polish): Newton steps `dq = -H^-1 grad U` until the energy of a step, `dq^T H dq`, is below
/// `eps^2 E`, with `E` the pendulum's gravity stiffness scale `g (m_a (Z + Z_a) + m_b (Z +
/// Z_b))`; then two more, which quadratic convergence takes to the rounding floor of the
/// gradient. Where the potential is not convex (at `q = 0` an offset of the crossbar couples
/// its swing to the barely stiff torsion) the step is Levenberg's, on `H + tau diag|H|` with
/// the smallest `tau` of a ladder that makes it positive definite, and the step is halved
/// while the potential rises (beyond its rounding). Fails, with the reason, when an angle
/// leaves the small-tilt region, the iteration does not converge, or it ends on a saddle.
pub(super) fn rest<S: Real>(c: &Consts<S>, start: [S; 8]) -> Result<[S; 8], String> {
    // The swing and bounce first, with both torsion angles held: that problem is convex (the
    // pendulums' gravity stiffness dominates), and at its solution the offsets no longer
    // couple the swing to the torsion at first order, so the full problem is convex there.
    let swing = newton(c, start, [true, true, false, true, true, true, false, true])?;
    newton(c, swing, [true; 8])
}

/// [`rest`] in the coordinates marked `free`, the others held at their values in `start`.
fn newton<S: Real>(c: &Consts<S>, start: [S; 8], free: [bool; 8]) -> Result<[S; 8], String> {
    let scale = (c.g * (c.m_a * (c.z + c.z_a) + c.m_b * (c.z + c.z_b))).to_f64();
    let floor = S::EPSILON * S::EPSILON * scale;
    let describe = |q: &[S; 8]| {
        format!(
            "theta_a {:.3e}, eta_a {:.3e}, theta_b {:.3e}, eta_b {:.3e} rad",
            q[0].to_f64(),
            q[1].to_f64(),
            q[4].to_f64(),
            q[5].to_f64()
        )
    };
    let mut q = start;
    let mut extra = None;
    for _ in 0..MAX_ITERATIONS {
        let (mut grad, mut hess) = derivatives(c, &q);
        for k in (0..8).filter(|&k| !free[k]) {
            grad[k] = S::from_f64(0.0);
            for row in hess.iter_mut() {
                row[k] = S::from_f64(0.0);
            }
            hess[k] = [S::from_f64(0.0); 8];
            hess[k][k] = S::from_f64(1.0);
        }
        let to_f64 = |h: &[[S; 8]; 8]| SMatrix::<f64, 8, 8>::from_fn(|r, k| h[r][k].to_f64());
        let convex = to_f64(&hess).cholesky().is_some();
        if extra == Some(0) {
            if !convex {
                return Err(format!(
                    "the rest configuration found ({}) is a saddle of the potential, not a \
                     minimum",
                    describe(&q)
                ));
            }
            return Ok(q);
        }
        let step_matrix = if convex {
            hess
        } else {
            (-6..=12)
                .map(|e| {
                    let tau = S::from_f64(10f64.powi(e));
                    let mut h = hess;
                    for (k, row) in h.iter_mut().enumerate() {
                        let d = S::from_f64(hess[k][k].to_f64().abs());
                        row[k] = row[k] + tau * d;
                    }
                    h
                })
                .find(|h| to_f64(h).cholesky().is_some())
                .ok_or_else(|| {
                    format!("the potential has no descent direction at {}", describe(&q))
                })?
        };
        let dq = solve_linear(step_matrix, grad.map(|g| -g));
        let h64 = to_f64(&step_matrix);
        let energy: f64 = (0..8)
            .map(|r| {
                (0..8)
                    .map(|k| dq[r].to_f64() * h64[(r, k)] * dq[k].to_f64())
                    .sum::<f64>()
            })
            .sum();
        let u0 = potential(c, &q);
        let slack = 16.0 * S::EPSILON * (u0.to_f64().abs() + scale);
        let mut alpha = 1.0;
        let moved = loop {
            let trial: [S; 8] = std::array::from_fn(|k| q[k] + S::from_f64(alpha) * dq[k]);
            if (potential(c, &trial) - u0).to_f64() <= slack || alpha < 1e-12 {
                break trial;
            }
            alpha *= 0.5;
        };
        q = moved;
        let angles = [0, 1, 2, 4, 5, 6].map(|k| q[k].to_f64().abs());
        if let Some(angle) = angles
            .into_iter()
            .find(|a| a.is_nan() || *a > MAX_REST_ANGLE)
        {
            return Err(format!(
                "Newton's method left the small-tilt region (an angle of {angle:.3e} rad, \
                 more than {MAX_REST_ANGLE} rad)"
            ));
        }
        match extra {
            Some(n) => extra = Some(n - 1),
            None if convex && alpha == 1.0 && energy <= floor => extra = Some(2),
            None => {}
        }
    }
    Err(format!(
        "Newton's method did not converge in {MAX_ITERATIONS} iterations (last at {})",
        describe(&q)
    ))
}
