//! Mass, stiffness, generalized-force and observation matrices from Appendix A of the paper, in
//! `f64`: M, K and the force matrix are [`crate::appendix`]'s formulas (shared with the
//! double-double reference), the others written here. `tests/it/energy_crosscheck.rs` rebuilds every matrix from the
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

/// Zeroth-order generalized forces B ([`appendix::force`]), columns F_a.xyz, F_b.xyz, M_a.xyz,
/// M_b.xyz.
pub(super) fn force_matrix(p: &Params) -> ForceMatrix {
    let b = appendix::force::<f64>(p);
    ForceMatrix::from_fn(|r, c| b[r][c])
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
