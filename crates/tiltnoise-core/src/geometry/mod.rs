//! The pendulum as built: the exact kinematics and potential with the `[asymmetry]` offsets
//! ([`crate::params::asymmetry`]), the rest configuration they make, and the linear model
//! about it.
//!
//! # What is computed
//!
//! With a horizontal offset the bodies hang tilted, so the equilibrium is found, not assumed:
//! Newton's method on the gradient of the exact potential `U(q)` (gravity on both centres of
//! mass, the fibres' torsion and bouncing energies and their static pre-tension) in the paper's
//! eight generalized coordinates, from the drawing's configuration `q = 0`. About the rest
//! configuration `q0`:
//!
//! * `K = d^2 U / dq^2`: the gravity part (a Hessian) plus the elastic diagonal
//!   `k_a, k_b, kappa_a, kappa_b` (exactly);
//! * `M`: the kinetic-energy metric, `m_a J_a^T J_a + m_b J_b^T J_b + W_a^T I_a W_a +
//!   W_b^T I_b W_b` with `J = dr_g/dq` and `W` the body-frame angular velocity per unit `q'`;
//! * the zeroth-order force matrix `B` (forces at the centres of mass and torques about them,
//!   lab axes): `Q = J^T F + Omega^T T`, `Omega` the lab-frame angular velocity per unit `q'`;
//! * the ground forcing `G0 + w^2 G2` of the six floor motions (theta_t, eta_t, phi_t, then
//!   x_t, y_t, z_t): for the rotations, `G0 = -d^2 U / dq dt` with the vertical tilted in the
//!   crate's convention ([`crate::model::tilt`]) and `G2` from the apparent forces
//!   `-m (r_s'' + w' x r_g0)` and torques `-I_lab w'` at the rest configuration; for the
//!   translations `G0 = 0`, `G2 = m_a B_Fa + m_b B_Fb` (the apparent force `-m u''` at each centre
//!   of mass);
//! * the observation matrix: the cube centre's displacement and the test mass's rotation
//!   vector (lab axes), the crossbar's rotation about z, turned into the readout's axes by the
//!   sensor rotation;
//! * each fibre's swing directions, for its loss angle (see [`crate::model::damping`]).
//!
//! Every derivative is exact: the kinematics is written once for any [`Real`] scalar and
//! evaluated on hyper-dual numbers ([`HyperDual`]) over `f64` (the model) or over double-double
//! (the reference and the pole-zero method). With every offset 0 this reproduces the paper's
//! matrices to rounding; the crate keeps the closed forms of Appendix A for that case.
//!
//! Depends on `params` and `dd` (the double-double scalar) only.

mod double;
mod equilibrium;
mod kinematics;
pub mod scalar;

pub use double::dd_matrices;
pub use scalar::{HyperDual, Real, Tracked};

use crate::error::ParamError;
use crate::params::Params;
use equilibrium::{gravity_derivatives, seeded};
use kinematics::{cross, gravity, mat_mul, mat_vec, pose, rot, transpose, vee, Consts, V3};

/// The ground inputs, in column order of [`Linearization::ground_g0`]: the floor rotations
/// theta_t, eta_t, phi_t (rad), then the floor translations x_t, y_t, z_t (m).
pub const GROUND_INPUTS: [&str; 6] = ["theta_t", "eta_t", "phi_t", "x_t", "y_t", "z_t"];

/// The linear model about the rest configuration, in the scalar `S`. Coordinate order
/// [`crate::model::Coord::ALL`]; units as the model's matrices.
#[derive(Debug, Clone)]
pub struct Linearization<S> {
    /// The rest configuration `q0` (rad, m).
    pub rest: [S; 8],
    /// Mass matrix.
    pub mass: [[S; 8]; 8],
    /// Gravity part of the stiffness; the elastic part is the diagonal `k_a, k_b, kappa_a,
    /// kappa_b` on phi_a, phi_b, delta_a, delta_b.
    pub stiffness_gravity: [[S; 8]; 8],
    /// Generalized forces per unit force/torque (columns F_a.xyz, F_b.xyz, M_a.xyz, M_b.xyz).
    pub force: [[S; 12]; 8],
    /// Ground forcing independent of frequency (columns [`GROUND_INPUTS`]).
    pub ground_g0: [[S; 6]; 8],
    /// Ground forcing per unit `w^2` (columns [`GROUND_INPUTS`]).
    pub ground_g2: [[S; 6]; 8],
    /// Observation matrix (rows X, Y, Z, theta, eta, phi, phi_a).
    pub observation: [[S; 8]; 7],
    /// Per fibre (upper, lower), the two components of its swing per unit `q`: the body-frame
    /// angular displacement of the body it carries about the body's x and y axes, i.e. the
    /// turn of the fibre's direction away from its rest direction.
    pub swing: [[[S; 8]; 2]; 2],
    /// Crossbar and test-mass centres of mass at rest, from the upper suspension point (m).
    pub r_g0: [V3<S>; 2],
}

/// How deep a linearization's computation is, in roundings along one path (a rotation entry
/// 5, the composed attitude 5, a position 6, the energy and its dot products about 10, the
/// Jacobian contractions about 10, rounded up): an entry within `CLEAN_DEPTH EPSILON mag` of
/// zero is a structural zero of the exact computation ([`Tracked::cleaned`]).
pub const CLEAN_DEPTH: f64 = 64.0;

impl<T: Copy> Linearization<T> {
    /// Every entry mapped by `f`.
    pub fn map<U>(&self, f: impl Fn(T) -> U) -> Linearization<U> {
        let m8 = |a: &[[T; 8]; 8]| a.map(|r| r.map(&f));
        Linearization {
            rest: self.rest.map(&f),
            mass: m8(&self.mass),
            stiffness_gravity: m8(&self.stiffness_gravity),
            force: self.force.map(|r| r.map(&f)),
            ground_g0: self.ground_g0.map(|r| r.map(&f)),
            ground_g2: self.ground_g2.map(|r| r.map(&f)),
            observation: self.observation.map(|r| r.map(&f)),
            swing: self.swing.map(|fibre| fibre.map(|v| v.map(&f))),
            r_g0: self.r_g0.map(|v| v.map(&f)),
        }
    }
}

impl<S: Real> Linearization<Tracked<S>> {
    /// The values, each within rounding of zero set to exactly 0 ([`CLEAN_DEPTH`]): the
    /// structural zeros of the exact linearization (those of the mirror plane, and those of
    /// balances such as `m_a y_a = m_b d`) come out exact.
    pub fn cleaned(&self) -> Linearization<S> {
        self.map(|t| t.cleaned(CLEAN_DEPTH))
    }

    /// Each entry's magnitude: the sum of the magnitudes of the terms computed into it, the
    /// scale of its rounding.
    pub fn magnitudes(&self) -> Linearization<f64> {
        self.map(|t| t.mag)
    }
}

/// The rest configuration and the linear model of `p` in the scalar `S`, each entry with the
/// magnitude of its rounding ([`Tracked`]). The rest configuration is solved in `f64` first
/// and, for a more precise `S`, polished by Newton steps in `S`; the linearization about it
/// treats it as exact.
///
/// # Errors
///
/// [`ParamError::NoEquilibrium`] when Newton's method finds no stable rest configuration near
/// the drawing's (offsets far beyond those [`Params::validate`] admits).
pub fn linearize<S: Real>(p: &Params) -> Result<Linearization<Tracked<S>>, ParamError> {
    let fail = |detail: String| {
        let keys: Vec<String> = p
            .fields()
            .iter()
            .filter(|f| f.key.starts_with("asymmetry.") && f.value != 0.0)
            .map(|f| format!("{} = {} {}", f.key, f.value, f.unit))
            .collect();
        ParamError::NoEquilibrium {
            keys: keys.join(", "),
            detail,
        }
    };
    let rest = equilibrium::rest(&Consts::<f64>::new(p), [0.0; 8]).map_err(fail)?;
    let c = Consts::<S>::new(p);
    let floor = floors(&Consts::<f64>::new(p), &rest, S::EPSILON);
    let rest = rest.map(S::from_f64);
    let rest = if S::EPSILON < f64::EPSILON {
        equilibrium::rest(&c, rest).map_err(fail)?
    } else {
        rest
    };
    // A coordinate below the solve's own floor is 0 to its precision, and 0 it is: the noise
    // of the last Newton step would otherwise seed the linearization with tiny terms of no
    // cancellation (sin of a 1e-34 rad noise angle) that no rounding scale can tell from
    // genuine ones.
    let rest: [S; 8] = std::array::from_fn(|k| {
        if rest[k].to_f64().abs() <= floor[k] {
            S::from_f64(0.0)
        } else {
            rest[k]
        }
    });
    Ok(at_rest(&Consts::new(p), rest.map(Tracked::exact)))
}

/// The accuracy, per coordinate, of the rest configuration of `p` solved with unit roundoff
/// `eps` ([`linearize`] sets the coordinates below it to 0): Newton's method stops at a step
/// energy of about `(CLEAN_DEPTH eps)^2 E`, `E` the gravity stiffness scale, so a coordinate
/// errs by at most `CLEAN_DEPTH eps sqrt(E (K^-1)_kk)` (rad or m).
///
/// # Errors
///
/// As [`linearize`].
pub fn rest_floors(p: &Params, eps: f64) -> Result<[f64; 8], ParamError> {
    let c = Consts::<f64>::new(p);
    let rest = equilibrium::rest(&c, [0.0; 8]).map_err(|detail| ParamError::NoEquilibrium {
        keys: String::new(),
        detail,
    })?;
    Ok(floors(&c, &rest, eps))
}

/// Newton's method stops at a step energy of about `(CLEAN_DEPTH eps)^2 E` (`E` the gravity
/// stiffness scale `g (m_a (Z + Z_a) + m_b (Z + Z_b))`), so a coordinate's error is at most
/// `CLEAN_DEPTH eps sqrt(E (K^-1)_kk)` (Cauchy-Schwarz in the energy norm), `K` the stiffness at
/// the rest configuration `rest` (rad or m).
fn floors(c: &Consts<f64>, rest: &[f64; 8], eps: f64) -> [f64; 8] {
    let (_, mut k) = gravity_derivatives(c, rest);
    for &(i, stiffness) in &c.elastic {
        k[i][i] += stiffness;
    }
    let k = nalgebra::SMatrix::<f64, 8, 8>::from_fn(|r, j| k[r][j]);
    let scale = c.g * (c.m_a * (c.z + c.z_a) + c.m_b * (c.z + c.z_b));
    match k.try_inverse() {
        Some(inv) => {
            std::array::from_fn(|i| CLEAN_DEPTH * eps * (scale * inv[(i, i)].abs()).sqrt())
        }
        None => [0.0; 8],
    }
}

/// The first-order motion per unit `q'_h`, for every `h`.
struct Velocities<S> {
    /// `dr_ga/dq_h`, `dr_gb/dq_h`, `dr_cube/dq_h`.
    r_ga: [V3<S>; 8],
    r_gb: [V3<S>; 8],
    r_cube: [V3<S>; 8],
    /// Angular velocities in the lab frame (`[w]x = A' A^T`) and the body frame
    /// (`[w]x = A^T A'`), crossbar then test mass.
    lab: [[V3<S>; 8]; 2],
    body: [[V3<S>; 8]; 2],
}

fn velocities<S: Real>(c: &Consts<S>, q: &[S; 8]) -> Velocities<S> {
    let ch = c.map(HyperDual::constant);
    let zero = S::from_f64(0.0);
    let none = [[zero; 3]; 8];
    let mut v = Velocities {
        r_ga: none,
        r_gb: none,
        r_cube: none,
        lab: [none; 2],
        body: [none; 2],
    };
    let at = pose(c, q);
    for h in 0..8 {
        let p = pose(&ch, &seeded(q, Some(h), None));
        let d = |x: V3<HyperDual<S>>| x.map(|e| e.e1);
        v.r_ga[h] = d(p.r_ga);
        v.r_gb[h] = d(p.r_gb);
        v.r_cube[h] = d(p.r_cube);
        for (body, (a, a0)) in [(p.a_a, at.a_a), (p.a_b, at.a_b)].into_iter().enumerate() {
            let da = a.map(|r| r.map(|e| e.e1));
            v.lab[body][h] = vee(&mat_mul(&da, &transpose(&a0)));
            v.body[body][h] = vee(&mat_mul(&transpose(&a0), &da));
        }
    }
    v
}

fn at_rest<S: Real>(c: &Consts<S>, rest: [S; 8]) -> Linearization<S> {
    let zero = S::from_f64(0.0);
    let (_, stiffness_gravity) = gravity_derivatives(c, &rest);
    let v = velocities(c, &rest);
    let at = pose(c, &rest);
    let inertia = [c.i_a, c.i_b];
    let mass = std::array::from_fn(|i| {
        std::array::from_fn(|j| {
            let rotation = (0..2).fold(zero, |acc, b| {
                acc + kinematics::dot(v.body[b][i], mat_vec(&inertia[b], v.body[b][j]))
            });
            c.m_a * kinematics::dot(v.r_ga[i], v.r_ga[j])
                + c.m_b * kinematics::dot(v.r_gb[i], v.r_gb[j])
                + rotation
        })
    });
    let force: [[S; 12]; 8] = std::array::from_fn(|h| {
        let cols = [v.r_ga[h], v.r_gb[h], v.lab[0][h], v.lab[1][h]];
        std::array::from_fn(|k| cols[k / 3][k % 3])
    });

    let mut ground_g0 = [[zero; 6]; 8];
    let ch = c.map(HyperDual::constant);
    for (h, row) in ground_g0.iter_mut().enumerate() {
        for (axis, g0) in row.iter_mut().take(3).enumerate() {
            let t: [HyperDual<S>; 3] =
                std::array::from_fn(|k| HyperDual::variable(zero, false, k == axis));
            // Q = -dU/dq, linear part in t.
            *g0 = -gravity(&ch, &seeded(&rest, Some(h), None), &t).e12;
        }
    }
    let mut ground_g2 = [[zero; 6]; 8];
    // Tilt: the frame's angular acceleration w' = -t'' about the floor pivot, a height h below
    // the upper suspension point; loads per unit t'', and t'' = -w^2 t.
    let inertia_lab = [0, 1].map(|b| {
        let a = [at.a_a, at.a_b][b];
        mat_mul(&mat_mul(&a, &inertia[b]), &transpose(&a))
    });
    for axis in 0..3 {
        let w_dot: V3<S> = std::array::from_fn(|k| S::from_f64(if k == axis { -1.0 } else { 0.0 }));
        let r_s = cross(w_dot, [zero, zero, c.h]);
        let apparent = |m: S, r: V3<S>| {
            let rot = cross(w_dot, r);
            std::array::from_fn::<S, 3, _>(|k| -(m * (r_s[k] + rot[k])))
        };
        let torque = |i: usize| mat_vec(&inertia_lab[i], w_dot).map(|x| -x);
        let loads = [
            apparent(c.m_a, at.r_ga),
            apparent(c.m_b, at.r_gb),
            torque(0),
            torque(1),
        ];
        for (h, row) in ground_g2.iter_mut().enumerate() {
            let q = (0..12).fold(zero, |acc, k| acc + force[h][k] * loads[k / 3][k % 3]);
            row[axis] = -q;
        }
    }
    for (h, row) in ground_g2.iter_mut().enumerate() {
        for axis in 0..3 {
            row[3 + axis] = c.m_a * force[h][axis] + c.m_b * force[h][3 + axis];
        }
    }

    // The readout's components of a lab vector: R_s v (R of eq. (matriceR)).
    let sensor = rot(c.sensor[0], c.sensor[1], c.sensor[2]);
    let position = v.r_cube.map(|r| mat_vec(&sensor, r));
    let tm = v.lab[1].map(|w| mat_vec(&sensor, w));
    let crossbar = v.lab[0].map(|w| mat_vec(&sensor, w));
    let observation = std::array::from_fn(|row| {
        std::array::from_fn(|h| match row {
            0..=2 => position[h][row],
            3..=5 => tm[h][row - 3],
            _ => crossbar[h][2],
        })
    });
    let swing = [0, 1].map(|b| [0, 1].map(|k| std::array::from_fn(|h| v.body[b][h][k])));
    Linearization {
        rest,
        mass,
        stiffness_gravity,
        force,
        ground_g0,
        ground_g2,
        observation,
        swing,
        r_g0: [at.r_ga, at.r_gb],
    }
}

#[cfg(test)]
mod tests;
