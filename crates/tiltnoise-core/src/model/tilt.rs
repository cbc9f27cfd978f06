//! Floor tilt as generalized forces (paper, section IV.B), with one sign convention for the
//! gravity correction and the apparent forces and torques together.
//!
//! # Sign convention
//!
//! `t = (theta_t, eta_t, phi_t)` is the small rotation that takes the **floor (enclosure) frame
//! to the local inertial frame**: equivalently, the floor itself is rotated by `-t` (right-handed)
//! about axes through its base, and `t` is the right-handed angle of the true vertical as seen
//! from the floor. With this definition the paper's stated quasi-static limits hold:
//!
//! ```text
//!   X -> -eta_t (Z + Z_b + h_c),   Y -> +theta_t (Z + Z_b + h_c)   as f -> 0
//! ```
//!
//! i.e. the test mass hangs plumb and the GRS, which tilts with the floor, sees it displaced. The
//! paper's literal recipe (a right-handed floor rotation, the potential at theta_a + theta_t,
//! eta_a + eta_t, and `r_t'' = h(eta_t'', -theta_t'', 0)`) is this convention with `t -> -t`:
//! it flips every transfer function's sign, including the two limits the paper states. The
//! convention is applied to **both** terms below; flipping only one of them breaks the exact
//! cancellation that makes phi and phi_a fall as f^4 at low frequency.
//!
//! # The forcing
//!
//! In the enclosure frame the equations of motion are `M q'' + K q = Q(t)` with
//!
//! * gravity correction: the potential is `U(theta_a - theta_t, eta_a - eta_t, ...)`, giving
//!   `Q_grav = K_gravity S t`, where `S` puts `theta_t` on theta_a and `eta_t` on eta_a;
//! * apparent forces and torques of the frame's angular acceleration `w_t' = -t''` (rotation
//!   about the floor pivot, a height `h` below the upper suspension point):
//!   `F_i = -m_i (r_s'' + w_t' x r_g,i)` with `r_s'' = w_t' x (0, 0, h)`, and `M_i = -I_i w_t'`,
//!   mapped to generalized forces by the zeroth-order matrix of Appendix A.
//!
//! For a harmonic tilt `t e^{iwt}` this is `Q = (G0 + w^2 G2) t` with `G0 = K_gravity S` and
//! `G2 = -(dQ_app / dt'')`. Centrifugal and Coriolis terms are second order and dropped (paper).

use super::{Coord, Derived, ForceMatrix, Mat8, TiltMatrix};
use crate::params::Params;

/// `G(w) = G0 + w^2 G2`: generalized forces per unit tilt angle (columns theta_t, eta_t, phi_t).
#[derive(Debug, Clone, PartialEq)]
pub struct TiltForcing {
    /// Gravity correction, units of K (N m/rad per rad for angle rows, N/rad for delta rows).
    pub g0: TiltMatrix,
    /// Apparent forces and torques per unit `w^2 t` (units of M per rad).
    pub g2: TiltMatrix,
}

/// Cross product `a x b`.
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl TiltForcing {
    pub(super) fn new(
        p: &Params,
        dv: &Derived,
        force: &ForceMatrix,
        stiffness_gravity: &Mat8,
    ) -> TiltForcing {
        let mut g0 = TiltMatrix::zeros();
        for (col, coord) in [(0, Coord::ThetaA), (1, Coord::EtaA)] {
            g0.set_column(col, &stiffness_gravity.column(coord.index()));
        }
        let i = &p.inertia;
        let inertia_a = [
            [i.a11_kg_m2, 0.0, 0.0],
            [0.0, i.a22_kg_m2, i.a23_kg_m2],
            [0.0, i.a23_kg_m2, i.a33_kg_m2],
        ];
        let inertia_b = [
            [i.b11_kg_m2, 0.0, 0.0],
            [0.0, i.b22_kg_m2, 0.0],
            [0.0, 0.0, i.b33_kg_m2],
        ];
        let h = p.length.h_m;
        let mut g2 = TiltMatrix::zeros();
        for axis in 0..3 {
            // Unit tilt acceleration t'' = e_axis, so the frame's angular acceleration is -e_axis.
            let mut w_dot = [0.0; 3];
            w_dot[axis] = -1.0;
            let r_s = cross(w_dot, [0.0, 0.0, h]);
            let apparent_force = |m: f64, r_g: [f64; 3]| {
                let rot = cross(w_dot, r_g);
                [0, 1, 2].map(|k| -m * (r_s[k] + rot[k]))
            };
            let apparent_torque = |inertia: [[f64; 3]; 3]| {
                [0, 1, 2].map(|k| -(0..3).map(|j| inertia[k][j] * w_dot[j]).sum::<f64>())
            };
            let f_a = apparent_force(p.mass.m_a_kg, dv.r_ga0_m);
            let f_b = apparent_force(p.mass.m_b_kg, dv.r_gb0_m);
            let m_a = apparent_torque(inertia_a);
            let m_b = apparent_torque(inertia_b);
            let inputs: Vec<f64> = [f_a, f_b, m_a, m_b].concat();
            // Q per unit t''; with t'' = -w^2 t, G2 = -Q.
            for row in 0..8 {
                let q: f64 = (0..12).map(|c| force[(row, c)] * inputs[c]).sum();
                g2[(row, axis)] = -q;
            }
        }
        TiltForcing { g0, g2 }
    }

    /// `G0 + w^2 G2` at angular frequency `omega` (rad/s).
    pub fn at(&self, omega: f64) -> TiltMatrix {
        self.g0 + self.g2 * (omega * omega)
    }
}
