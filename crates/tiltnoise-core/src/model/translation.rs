//! Floor translation as generalized forces: the floor's displacement along the lab axes, the
//! apparent forces it makes, and its low-frequency equivalence with tilt.
//!
//! # Convention
//!
//! `u = (x_t, y_t, z_t)` (m) is the displacement of the floor as a rigid body along the lab axes:
//! the crossbar arm lies along y (the test mass hangs at `(0, -d, .)` from the upper fibre), x is
//! perpendicular to it (the direction of the test mass's X), z is up. The floor carries the pivot
//! about which tilt is defined, the upper suspension point (a height `h` above the pivot) and the
//! sensor housing, which all move together: with a tilt as well, the suspension point moves by
//! `u + r x (0, 0, h)`, `r = -t` the floor's own rotation in this crate's tilt convention (see
//! [`super::tilt`]). The equations of motion are written in the floor's frame, so each body feels
//! the apparent force `-m_i u''` at its centre of mass (no torque: the frame does not rotate), and
//! every observable stays relative to the housing. For `u e^{+i w t}` the generalized forces are
//!
//! ```text
//! Q = w^2 G2 u,   G2[:, k] = m_a B[:, F_a.k] + m_b B[:, F_b.k],   G0 = 0,
//! ```
//!
//! with `B` the zeroth-order force matrix of Appendix A ([`super::Model::force_matrix`]).
//! Transfer functions are per unit displacement: m/m, rad/m. The potential does not change (the
//! floor does not turn), hence `G0 = 0` and every response vanishes as `w^2` at low frequency.
//!
//! # The balanced crossbar: exact zeros
//!
//! The crossbar's centre of mass sits at `y_a = d m_b / m_a` (section II.A): the pendulum's first
//! moment about the upper fibre has no y component, `m_a y_a - m_b d = 0`. A uniform field
//! therefore exerts no torque about the upper fibre when it points along x (the phi_a row of the
//! x_t column), nor about x when it points along z (the theta_a row of the z_t column). Both
//! entries are set to exactly 0: in `f64` the two products round to about `eps m_b d` apart,
//! which would turn the `f^4` of phi/x_t and theta/z_t at low frequency into a spurious `f^2`.
//!
//! # Equivalence with tilt
//!
//! In exact arithmetic `G2[:, x_t] = -K_gravity e_eta_a / g` and `G2[:, y_t] = +K_gravity
//! e_theta_a / g`, the tilt's gravity forcing `G0` per `g` (the upper fibre holds both bodies, the
//! lower one the test mass). With the dynamic stiffness `D` (damped or not), per unit floor
//! acceleration `a = -w^2 u`,
//!
//! ```text
//! H_x_t / (-w^2) - H_eta_t / g = -(w^2 / g) C D^-1 G2[:, eta_t]
//! H_y_t / (-w^2) + H_theta_t / g = +(w^2 / g) C D^-1 G2[:, theta_t]
//! ```
//!
//! so as `f -> 0` a horizontal floor acceleration acts exactly as a tilt, `eta_t = a_x / g`,
//! `theta_t = -a_y / g` (the equivalence principle), with a difference that vanishes as `f^2`.
//! A vertical acceleration acts as a change of `g` by `a_z`: the static response per unit `a_z`
//! is the fibres' extra stretch under the bodies' weight, `delta_a = (m_a + m_b) / kappa_a`,
//! `delta_b = m_b / kappa_b`, so `Z = -(delta_a + delta_b)` per unit acceleration, and no swing
//! (the crossbar is balanced). Conversely a tilt about x or y contains the translation of the
//! suspension point: `G2[:, eta_t] + M e_eta_a = -h G2[:, x_t]` and `G2[:, theta_t] + M e_theta_a
//! = +h G2[:, y_t]` (what the split method calls the translation forcing `R`).

use super::{Coord, ForceMatrix, TranslationMatrix};
use crate::params::Params;

/// `G(w) = w^2 G2`: generalized forces per unit floor displacement (columns x_t, y_t, z_t).
#[derive(Debug, Clone, PartialEq)]
pub struct TranslationForcing {
    /// Apparent forces per unit `w^2 u` (units of M per m: kg, kg m).
    pub g2: TranslationMatrix,
}

/// The entries of `G2` that vanish because the crossbar is balanced on the upper fibre
/// (`m_a y_a = m_b d`): `(coordinate, translation column)`.
pub const BALANCED: [(Coord, usize); 2] = [(Coord::PhiA, 0), (Coord::ThetaA, 2)];

impl TranslationForcing {
    pub(super) fn new(p: &Params, force: &ForceMatrix) -> TranslationForcing {
        let (m_a, m_b) = (p.mass.m_a_kg, p.mass.m_b_kg);
        let mut g2 = TranslationMatrix::zeros();
        for axis in 0..3 {
            // -m u'' = +w^2 m u on each body, at its centre of mass: columns F_a.k and F_b.k.
            let column = force.column(axis) * m_a + force.column(3 + axis) * m_b;
            g2.set_column(axis, &column);
        }
        for (coord, axis) in BALANCED {
            g2[(coord.index(), axis)] = 0.0;
        }
        TranslationForcing { g2 }
    }

    /// `w^2 G2` at angular frequency `omega` (rad/s).
    pub fn at(&self, omega: f64) -> TranslationMatrix {
        self.g2 * (omega * omega)
    }
}

/// The response of every observable per unit floor acceleration as `f -> 0`, `-C K_c^-1 G2`
/// (rows in the order of [`super::Observable::ALL`], columns x_t, y_t, z_t; units m/(m s^-2),
/// rad/(m s^-2)): the equivalence principle's values, `X/eta_t / g` for x_t, `-Y/theta_t / g`
/// for y_t, the fibres' stretch per unit `g` for z_t (see the module docs). Complex with
/// structural loss (`K_c = K + i Im(K_c)`).
pub fn acceleration_limit(model: &super::Model) -> nalgebra::SMatrix<num_complex::Complex64, 7, 3> {
    use num_complex::Complex64;
    let lu = model.stiffness_complex().lu();
    let g2 = model
        .translation_forcing()
        .g2
        .map(|v| Complex64::new(-v, 0.0));
    let q = lu
        .solve(&g2)
        .expect("K_c is regular: Model::new checks that K is positive definite");
    model.observation().map(Complex64::from) * q
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;

    /// The balanced entries are rounding before they are zeroed: the two products `m_a y_a`
    /// and `m_b d` differ by a few ulps of `m_b d`, for Table I and for a crossbar whose
    /// `y_a` is not a round number.
    #[test]
    fn balanced_entries_are_only_rounding() {
        for over in ["mass.m_a_kg=0.8", "mass.m_a_kg=1.3"] {
            let p = Params::table_i().with_override(over).unwrap();
            let model = Model::new(&p).unwrap();
            let b = model.force_matrix();
            let (m_a, m_b) = (p.mass.m_a_kg, p.mass.m_b_kg);
            let moment = m_b * p.length.d_m;
            for (coord, axis) in BALANCED {
                let raw = b[(coord.index(), axis)] * m_a + b[(coord.index(), 3 + axis)] * m_b;
                assert!(
                    raw.abs() <= 4.0 * f64::EPSILON * moment,
                    "{over}: {} row of column {axis}: {raw:e}",
                    coord.name()
                );
                assert_eq!(model.translation_forcing().g2[(coord.index(), axis)], 0.0);
            }
        }
    }

    /// 1-norm condition number of `S K S`, `S = diag(K_ii^-1/2)`.
    fn equilibrated_cond(model: &Model) -> f64 {
        let k = model.stiffness();
        let s: Vec<f64> = (0..8).map(|i| 1.0 / k[(i, i)].sqrt()).collect();
        let ks = crate::model::Mat8::from_fn(|r, c| k[(r, c)] * s[r] * s[c]);
        let inv = ks.try_inverse().unwrap();
        let norm1 =
            |m: &crate::model::Mat8| (0..8).map(|c| m.column(c).abs().sum()).fold(0.0, f64::max);
        norm1(&ks) * norm1(&inv)
    }

    /// The limits per unit acceleration are the equivalence principle's: the tilt's static
    /// response per g for x_t and y_t (the pendulum hangs along the apparent vertical), Hooke's
    /// law under the extra weight for z_t; within the LU's rounding.
    #[test]
    fn acceleration_limits_are_the_equivalence_principle() {
        use crate::model::Observable;
        let p = Params::table_i();
        let model = Model::new(&p).unwrap();
        let limit = acceleration_limit(&model);
        let g = p.environment.g_m_per_s2;
        let lever = model.derived().lever_m;
        let (m_a, m_b) = (p.mass.m_a_kg, p.mass.m_b_kg);
        let hooke = -((m_a + m_b) / p.bouncing.kappa_a_n_per_m + m_b / p.bouncing.kappa_b_n_per_m);
        for (o, axis, want) in [
            (Observable::X, 0, -lever / g),
            (Observable::Eta, 0, 1.0 / g),
            (Observable::Y, 1, -lever / g),
            (Observable::Theta, 1, -1.0 / g),
            (Observable::Z, 2, hooke),
            (Observable::Y, 2, 0.0),
            (Observable::Phi, 0, 0.0),
        ] {
            let got = limit[(o.index(), axis)];
            // LU of the 8x8 stiffness: forward error n eps cond on a solution of scale
            // lever / g, cond that of the symmetrically equilibrated K.
            let tol = 8.0 * f64::EPSILON * equilibrated_cond(&model) * lever / g;
            assert!(
                (got - want).norm() <= tol,
                "{} per unit acceleration along axis {axis}: {got} vs {want:e}",
                o.name()
            );
        }
    }
}
