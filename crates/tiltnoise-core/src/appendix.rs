//! The mass, stiffness and zeroth-order generalized-force matrices of Appendix A (eqs. (def_I)
//! and (EM), and its last display), written once over the scalar they are evaluated in: `f64` for the model ([`crate::model`]) and double-double for
//! the reference ([`crate::dd::matrices`]). The reference stays an independent check of the
//! arithmetic (every sum and product rounded 2^-53 times more finely); the formulas, fixed by
//! the paper, are stated here once, and `tests/it/energy_crosscheck.rs` rebuilds them from the
//! energies of section II.
//!
//! One generalization of the Appendix: it assumes I^b_22 = I^b_11, while Table I gives
//! 2.77e-4 and 2.76e-4 kg m^2. Here I^b_22 is used wherever the test mass rotates about its
//! y axis (the eta rows), which is what the Lagrangian of section II gives; with
//! I^b_22 = I^b_11 the matrices are exactly the Appendix's.

use crate::dd::Dd;
use crate::params::Params;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// The arithmetic the formulas need.
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Zero.
    const ZERO: Self;
    /// A parameter value.
    fn of(x: f64) -> Self;
    /// `self * self`.
    fn sqr(self) -> Self {
        self * self
    }
}

impl Scalar for f64 {
    const ZERO: f64 = 0.0;
    fn of(x: f64) -> f64 {
        x
    }
}

impl Scalar for Dd {
    const ZERO: Dd = Dd::ZERO;
    fn of(x: f64) -> Dd {
        Dd::from_f64(x)
    }
    fn sqr(self) -> Dd {
        Dd::sqr(self)
    }
}

/// q = (theta_a, eta_a, phi_a, delta_a, theta_b, eta_b, phi_b, delta_b): the paper's order,
/// which is also [`crate::model::Coord::ALL`].
const TA: usize = 0;
const EA: usize = 1;
const PA: usize = 2;
const DA: usize = 3;
const TB: usize = 4;
const EB: usize = 5;
const PB: usize = 6;
const DB: usize = 7;

/// The horizontal offset y_a of the crossbar's centre of mass (m): section II.A places it so
/// that the pendulum balances on the upper fibre, m_a y_a = m_b d.
pub fn y_a<S: Scalar>(p: &Params) -> S {
    S::of(p.length.d_m) * S::of(p.mass.m_b_kg) / S::of(p.mass.m_a_kg)
}

/// Mass matrix M: the coefficients of the second derivatives in the equations of motion (EM),
/// with the modified moments of inertia of eq. (def_I).
pub fn mass<S: Scalar>(p: &Params) -> [[S; 8]; 8] {
    let (m_a, m_b) = (S::of(p.mass.m_a_kg), S::of(p.mass.m_b_kg));
    let i = &p.inertia;
    let (a11, a22, a33, a23) = (
        S::of(i.a11_kg_m2),
        S::of(i.a22_kg_m2),
        S::of(i.a33_kg_m2),
        S::of(i.a23_kg_m2),
    );
    let (b11, b22, b33) = (S::of(i.b11_kg_m2), S::of(i.b22_kg_m2), S::of(i.b33_kg_m2));
    let l = &p.length;
    let (d, z, z_a, z_b) = (S::of(l.d_m), S::of(l.z_m), S::of(l.z_a_m), S::of(l.z_b_m));
    let y_a = y_a::<S>(p);
    let (zza, zzb) = (z + z_a, z + z_b);
    let ia1 = a11 + m_a * (zza.sqr() + y_a.sqr());
    let ib1 = b11 + m_b * (zzb.sqr() + d.sqr());
    let ia2 = a22 + m_a * zza.sqr();
    let ib2 = b22 + m_b * zzb.sqr();
    let ia3 = a33 + m_a * y_a * y_a;
    let ib3 = b33 + m_b * d * d;
    let ia4 = a23 + m_b * d * (z_a - z_b);
    // I_b4 and I_b5 with I^b_11 for theta (about x) and I^b_22 for eta (about y).
    let ib4_theta = b11 + m_b * z_b * z_b;
    let ib4_eta = b22 + m_b * z_b * z_b;
    let ib5_theta = b11 + m_b * z_b * zzb;
    let ib5_eta = b22 + m_b * z_b * zzb;

    let mut m = [[S::ZERO; 8]; 8];
    let mut sym = |r: usize, c: usize, v: S| {
        m[r][c] = v;
        m[c][r] = v;
    };
    sym(TA, TA, ia1 + ib1);
    sym(TA, TB, ib5_theta);
    sym(TA, DB, m_b * d);
    sym(EA, EA, ia2 + ib2);
    sym(EA, PA, ia4);
    sym(EA, EB, ib5_eta);
    sym(PA, PA, ia3 + ib3);
    sym(PA, PB, b33);
    sym(PA, EB, -(m_b * d * z_b));
    sym(DA, DA, m_a + m_b);
    sym(DA, DB, m_b);
    sym(TB, TB, ib4_theta);
    sym(EB, EB, ib4_eta);
    sym(PB, PB, b33);
    sym(DB, DB, m_b);
    m
}

/// The gravity (swing) part of the stiffness K, real: eq. (EM) for theta and eta of each body.
pub fn stiffness_gravity<S: Scalar>(p: &Params) -> [[S; 8]; 8] {
    let (m_a, m_b, g) = (
        S::of(p.mass.m_a_kg),
        S::of(p.mass.m_b_kg),
        S::of(p.environment.g_m_per_s2),
    );
    let l = &p.length;
    let (z, z_a, z_b) = (S::of(l.z_m), S::of(l.z_a_m), S::of(l.z_b_m));
    let c1 = m_b * (z + z_b) + m_a * (z + z_a);
    let mut k = [[S::ZERO; 8]; 8];
    for (a, b) in [(TA, TB), (EA, EB)] {
        k[a][a] = g * c1;
        k[a][b] = m_b * g * z_b;
        k[b][a] = m_b * g * z_b;
        k[b][b] = m_b * g * z_b;
    }
    k
}

/// The fibres' elastic stiffness, diagonal: `(coordinate index, stiffness, loss angle)` of the
/// torsion (N m/rad) and bouncing (N/m) of each fibre.
pub fn stiffness_elastic(p: &Params) -> [(usize, f64, f64); 4] {
    let lp = &p.loss;
    [
        (PA, p.torsion.k_a_n_m_per_rad, lp.torsion_a_rad),
        (PB, p.torsion.k_b_n_m_per_rad, lp.torsion_b_rad),
        (DA, p.bouncing.kappa_a_n_per_m, lp.bouncing_a_rad),
        (DB, p.bouncing.kappa_b_n_per_m, lp.bouncing_b_rad),
    ]
}

/// Columns of the force matrix: F_a.xyz, F_b.xyz (forces at the centres of mass), M_a.xyz,
/// M_b.xyz (torques about them).
const FAX: usize = 0;
const FAY: usize = 1;
const FAZ: usize = 2;
const FBX: usize = 3;
const FBY: usize = 4;
const FBZ: usize = 5;
const MAX: usize = 6;
const MAY: usize = 7;
const MAZ: usize = 8;
const MBX: usize = 9;
const MBY: usize = 10;
const MBZ: usize = 11;

/// Zeroth-order generalized forces B (Appendix A, last display): the generalized force on each
/// coordinate of the 12 force and torque components, columns F_a.xyz, F_b.xyz, M_a.xyz,
/// M_b.xyz. Row h is the gradient of the body positions and rotation angles with respect to q_h
/// at equilibrium, so B is also J^T for the kinematics behind M.
pub fn force<S: Scalar>(p: &Params) -> [[S; 12]; 8] {
    let l = &p.length;
    let (d, z, z_a, z_b) = (S::of(l.d_m), S::of(l.z_m), S::of(l.z_a_m), S::of(l.z_b_m));
    let y_a = y_a::<S>(p);
    let (zza, zzb, one) = (z + z_a, z + z_b, S::of(1.0));
    let rows: [(usize, &[(usize, S)]); 8] = [
        (
            TA,
            &[
                (FBY, zzb),
                (FAY, zza),
                (MAX, one),
                (MBX, one),
                (FAZ, y_a),
                (FBZ, -d),
            ],
        ),
        (EA, &[(FBX, -zzb), (FAX, -zza), (MAY, one), (MBY, one)]),
        (PA, &[(FAX, -y_a), (FBX, d), (MAZ, one), (MBZ, one)]),
        (DA, &[(FAZ, -one), (FBZ, -one)]),
        (TB, &[(FBY, z_b), (MBX, one)]),
        (EB, &[(FBX, -z_b), (MBY, one)]),
        (PB, &[(MBZ, one)]),
        (DB, &[(FBZ, -one)]),
    ];
    let mut b = [[S::ZERO; 12]; 8];
    for (row, entries) in rows {
        for &(col, v) in entries {
            b[row][col] = v;
        }
    }
    b
}
