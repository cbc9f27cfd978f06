//! Mass, stiffness, generalized-force and observation matrices from Appendix A of the paper, in
//! `f64`: M and K are [`crate::appendix`]'s formulas (shared with the double-double reference),
//! the others written here. `tests/it/energy_crosscheck.rs` rebuilds every matrix from the
//! energies of section II and checks this entry by entry.

use super::{Coord, Derived, ForceMatrix, Mat8, ObservationMatrix};
use crate::appendix;
use crate::params::Params;

use Coord::*;

fn at(c: Coord) -> usize {
    c.index()
}

pub(super) fn derived(p: &Params) -> Derived {
    let l = &p.length;
    let y_a = appendix::y_a::<f64>(p);
    Derived {
        y_a_m: y_a,
        r_ga0_m: [0.0, y_a, -(l.z_m + l.z_a_m)],
        r_gb0_m: [0.0, -l.d_m, -(l.z_m + l.z_b_m)],
        lever_m: l.z_m + l.z_b_m + l.h_c_m,
    }
}

/// Mass matrix M ([`appendix::mass`]).
pub(super) fn mass(p: &Params) -> Mat8 {
    let m = appendix::mass::<f64>(p);
    Mat8::from_fn(|r, c| m[r][c])
}

/// Stiffness split into the gravity part ([`appendix::stiffness_gravity`]) and the elastic part
/// (diagonal: torsion and bouncing of each fibre). Loss angles live in [`super::damping`].
pub(super) fn stiffness(p: &Params) -> (Mat8, Mat8) {
    let g = appendix::stiffness_gravity::<f64>(p);
    let kg = Mat8::from_fn(|r, c| g[r][c]);
    let mut ke = Mat8::zeros();
    for (c, k, _) in appendix::stiffness_elastic(p) {
        ke[(c, c)] = k;
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
