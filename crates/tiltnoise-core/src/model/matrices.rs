//! Mass, stiffness, generalized-force and observation matrices from Appendix A of the paper.
//!
//! One generalization of the Appendix: it assumes I^b_22 = I^b_11, while Table I gives
//! 2.77e-4 and 2.76e-4 kg m^2. Here I^b_22 is used wherever the test mass rotates about its
//! y axis (the eta rows), which is what the Lagrangian of section II gives; with
//! I^b_22 = I^b_11 the matrices are exactly the Appendix's. `tests/it/energy_crosscheck.rs`
//! rebuilds every matrix from the energies of section II and checks this entry by entry.

use super::{Coord, Derived, ForceMatrix, Mat8, ObservationMatrix};
use crate::params::Params;

use Coord::*;

fn at(c: Coord) -> usize {
    c.index()
}

pub(super) fn derived(p: &Params) -> Derived {
    let l = &p.length;
    let y_a = l.d_m * p.mass.m_b_kg / p.mass.m_a_kg;
    Derived {
        y_a_m: y_a,
        r_ga0_m: [0.0, y_a, -(l.z_m + l.z_a_m)],
        r_gb0_m: [0.0, -l.d_m, -(l.z_m + l.z_b_m)],
        lever_m: l.z_m + l.z_b_m + l.h_c_m,
    }
}

/// Mass matrix: the coefficients of the second derivatives in the equations of motion (EM).
pub(super) fn mass(p: &Params, dv: &Derived) -> Mat8 {
    let (m_a, m_b) = (p.mass.m_a_kg, p.mass.m_b_kg);
    let i = &p.inertia;
    let l = &p.length;
    let (d, z, z_a, z_b, y_a) = (l.d_m, l.z_m, l.z_a_m, l.z_b_m, dv.y_a_m);
    // Modified moments of inertia, eq. (def_I).
    let ia1 = i.a11_kg_m2 + m_a * ((z + z_a).powi(2) + y_a * y_a);
    let ib1 = i.b11_kg_m2 + m_b * ((z + z_b).powi(2) + d * d);
    let ia2 = i.a22_kg_m2 + m_a * (z + z_a).powi(2);
    let ib2 = i.b22_kg_m2 + m_b * (z + z_b).powi(2);
    let ia3 = i.a33_kg_m2 + m_a * y_a * y_a;
    let ib3 = i.b33_kg_m2 + m_b * d * d;
    let ia4 = i.a23_kg_m2 + m_b * d * (z_a - z_b);
    // I_b4 and I_b5 with I^b_11 for theta (about x) and I^b_22 for eta (about y).
    let ib4_theta = i.b11_kg_m2 + m_b * z_b * z_b;
    let ib4_eta = i.b22_kg_m2 + m_b * z_b * z_b;
    let ib5_theta = i.b11_kg_m2 + m_b * z_b * (z + z_b);
    let ib5_eta = i.b22_kg_m2 + m_b * z_b * (z + z_b);

    let mut m = Mat8::zeros();
    let mut sym = |r: Coord, c: Coord, v: f64| {
        m[(at(r), at(c))] = v;
        m[(at(c), at(r))] = v;
    };
    sym(ThetaA, ThetaA, ia1 + ib1);
    sym(ThetaA, ThetaB, ib5_theta);
    sym(ThetaA, DeltaB, m_b * d);
    sym(EtaA, EtaA, ia2 + ib2);
    sym(EtaA, PhiA, ia4);
    sym(EtaA, EtaB, ib5_eta);
    sym(PhiA, PhiA, ia3 + ib3);
    sym(PhiA, PhiB, i.b33_kg_m2);
    sym(PhiA, EtaB, -m_b * d * z_b);
    sym(DeltaA, DeltaA, m_a + m_b);
    sym(DeltaA, DeltaB, m_b);
    sym(ThetaB, ThetaB, ib4_theta);
    sym(EtaB, EtaB, ib4_eta);
    sym(PhiB, PhiB, i.b33_kg_m2);
    sym(DeltaB, DeltaB, m_b);
    m
}

/// Stiffness split into the gravity part and the elastic part (diagonal: torsion and bouncing
/// of each fibre). Loss angles live in [`super::damping`].
pub(super) fn stiffness(p: &Params) -> (Mat8, Mat8) {
    let (m_a, m_b, g) = (p.mass.m_a_kg, p.mass.m_b_kg, p.environment.g_m_per_s2);
    let l = &p.length;
    let c1 = m_b * (l.z_m + l.z_b_m) + m_a * (l.z_m + l.z_a_m);
    let mut kg = Mat8::zeros();
    for (a, b) in [(ThetaA, ThetaB), (EtaA, EtaB)] {
        kg[(at(a), at(a))] = g * c1;
        kg[(at(a), at(b))] = m_b * g * l.z_b_m;
        kg[(at(b), at(a))] = m_b * g * l.z_b_m;
        kg[(at(b), at(b))] = m_b * g * l.z_b_m;
    }
    let mut ke = Mat8::zeros();
    for (c, k) in [
        (PhiA, p.torsion.k_a_n_m_per_rad),
        (PhiB, p.torsion.k_b_n_m_per_rad),
        (DeltaA, p.bouncing.kappa_a_n_per_m),
        (DeltaB, p.bouncing.kappa_b_n_per_m),
    ] {
        ke[(at(c), at(c))] = k;
    }
    (kg, ke)
}

/// Zeroth-order generalized forces (Appendix A, last display), columns F_a.xyz, F_b.xyz,
/// M_a.xyz, M_b.xyz. Row h is the gradient of the body positions and rotation angles with
/// respect to q_h at equilibrium, so this matrix is also J^T for the kinematics behind M.
pub(super) fn force_matrix(p: &Params, dv: &Derived) -> ForceMatrix {
    let l = &p.length;
    let (d, z, z_a, z_b, y_a) = (l.d_m, l.z_m, l.z_a_m, l.z_b_m, dv.y_a_m);
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
    let mut b = ForceMatrix::zeros();
    let rows: [(Coord, &[(usize, f64)]); 8] = [
        (
            ThetaA,
            &[
                (FBY, z + z_b),
                (FAY, z + z_a),
                (MAX, 1.0),
                (MBX, 1.0),
                (FAZ, y_a),
                (FBZ, -d),
            ],
        ),
        (
            EtaA,
            &[(FBX, -(z + z_b)), (FAX, -(z + z_a)), (MAY, 1.0), (MBY, 1.0)],
        ),
        (PhiA, &[(FAX, -y_a), (FBX, d), (MAZ, 1.0), (MBZ, 1.0)]),
        (DeltaA, &[(FAZ, -1.0), (FBZ, -1.0)]),
        (ThetaB, &[(FBY, z_b), (MBX, 1.0)]),
        (EtaB, &[(FBX, -z_b), (MBY, 1.0)]),
        (PhiB, &[(MBZ, 1.0)]),
        (DeltaB, &[(FBZ, -1.0)]),
    ];
    for (coord, entries) in rows {
        for &(col, v) in entries {
            b[(at(coord), col)] = v;
        }
    }
    b
}

/// Observation matrix (section II.D): X, Y, Z of the cube centre, theta, eta, phi of the test
/// mass, and phi_a of the crossbar.
pub(super) fn observation(p: &Params) -> ObservationMatrix {
    let l = &p.length;
    let lever = l.z_m + l.z_b_m + l.h_c_m;
    let lower = l.h_c_m + l.z_b_m;
    let mut c = ObservationMatrix::zeros();
    let rows: [&[(Coord, f64)]; 7] = [
        &[(EtaA, -lever), (EtaB, -lower), (PhiA, l.d_m)],
        &[(ThetaA, lever), (ThetaB, lower)],
        &[(DeltaA, -1.0), (DeltaB, -1.0), (ThetaA, -l.d_m)],
        &[(ThetaA, 1.0), (ThetaB, 1.0)],
        &[(EtaA, 1.0), (EtaB, 1.0)],
        &[(PhiA, 1.0), (PhiB, 1.0)],
        &[(PhiA, 1.0)],
    ];
    for (r, entries) in rows.iter().enumerate() {
        for &(coord, v) in entries.iter() {
            c[(r, at(coord))] = v;
        }
    }
    c
}
