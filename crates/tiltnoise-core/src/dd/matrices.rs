//! The model's matrices in double-double, written from the paper's formulas (Appendix A,
//! eqs. (def_I) and (EM), the zeroth-order generalized forces, section II.D and section IV.B),
//! the apparent forces of the floor's translation, and the parameter values. It shares with
//! `crate::model` (the `f64` model) only the formulas of M, K and the zeroth-order force matrix
//! ([`crate::appendix`], evaluated here in double-double) and the coordinate order, which is
//! fixed by the paper and restated here; everything else is written independently.

use super::complex::CDd;
use super::real::Dd;
use crate::appendix;
use crate::params::Params;

/// q = (theta_a, eta_a, phi_a, delta_a, theta_b, eta_b, phi_b, delta_b): the paper's order,
/// which is also [`crate::model::Coord::ALL`].
pub const TA: usize = 0;
pub const EA: usize = 1;
pub const PA: usize = 2;
pub const DA: usize = 3;
pub const TB: usize = 4;
pub const EB: usize = 5;
pub const PB: usize = 6;
pub const DB: usize = 7;

/// Rows of the observation matrix: X, Y, Z, theta, eta, phi, phi_a.
pub const OBS_X: usize = 0;
pub const OBS_Y: usize = 1;
pub const OBS_Z: usize = 2;
pub const OBS_THETA: usize = 3;
pub const OBS_ETA: usize = 4;
pub const OBS_PHI: usize = 5;
pub const OBS_PHI_A: usize = 6;

/// All matrices of the linear model in double-double.
#[derive(Debug, Clone)]
pub struct Matrices {
    /// Mass matrix M (kg, kg m, kg m^2 by coordinate pair).
    pub mass: [[Dd; 8]; 8],
    /// Gravity (swing) part of the stiffness, real.
    pub stiffness_gravity: [[Dd; 8]; 8],
    /// K_gravity + K_elastic (1 + i phi) + i phi_swing (each fibre's share of K_gravity).
    pub stiffness: [[CDd; 8]; 8],
    /// Viscous damping matrix C (the dynamic stiffness is K_c + i w C - w^2 M).
    pub damping: [[Dd; 8]; 8],
    /// Generalized forces of the 12 force and torque components (columns F_a.xyz, F_b.xyz,
    /// M_a.xyz, M_b.xyz).
    pub force: [[Dd; 12]; 8],
    /// Tilt forcing, frequency-independent part G0 (columns theta_t, eta_t, phi_t).
    pub g0: [[Dd; 3]; 8],
    /// Tilt forcing, part multiplying w^2 (G2).
    pub g2: [[Dd; 3]; 8],
    /// Floor-translation forcing per unit `w^2` displacement (columns x_t, y_t, z_t); its
    /// frequency-independent part is zero.
    pub translation_g2: [[Dd; 3]; 8],
    /// Observation matrix C (rows X, Y, Z, theta, eta, phi, phi_a).
    pub observation: [[Dd; 8]; 7],
}

fn dd(x: f64) -> Dd {
    Dd::from_f64(x)
}

fn cross(a: [Dd; 3], b: [Dd; 3]) -> [Dd; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The rounding scale of each datum of [`Matrices`]: the sum of the magnitudes of the terms
/// computed into it (its rounding is a few [`super::DD_EPS`] of this), where that differs from
/// the datum's own magnitude.
#[derive(Debug, Clone)]
pub struct Scales {
    /// Of [`Matrices::mass`].
    pub mass: [[f64; 8]; 8],
    /// Of [`Matrices::stiffness`] (real and imaginary parts together).
    pub stiffness: [[f64; 8]; 8],
    /// Of [`Matrices::force`].
    pub force: [[f64; 12]; 8],
    /// Of [`Matrices::g0`].
    pub g0: [[f64; 3]; 8],
    /// Of [`Matrices::g2`].
    pub g2: [[f64; 3]; 8],
    /// Of [`Matrices::translation_g2`].
    pub translation_g2: [[f64; 3]; 8],
    /// Of [`Matrices::observation`].
    pub observation: [[f64; 8]; 7],
}

impl Scales {
    /// Each datum's own magnitude as its scale (the closed forms).
    pub fn own(m: &Matrices) -> Scales {
        let abs = |x: &Dd| x.to_f64().abs();
        Scales {
            mass: m.mass.map(|r| r.map(|x| abs(&x))),
            stiffness: m
                .stiffness
                .map(|r| r.map(|z| z.re.to_f64().abs() + z.im.to_f64().abs())),
            force: m.force.map(|r| r.map(|x| abs(&x))),
            g0: m.g0.map(|r| r.map(|x| abs(&x))),
            g2: m.g2.map(|r| r.map(|x| abs(&x))),
            translation_g2: m.translation_g2.map(|r| r.map(|x| abs(&x))),
            observation: m.observation.map(|r| r.map(|x| abs(&x))),
        }
    }
}

/// `B loads`: the generalized forces of 12 force and torque components (zero terms skipped).
fn generalized_forces(force: &[[Dd; 12]; 8], loads: &[Dd]) -> [Dd; 8] {
    std::array::from_fn(|r| {
        let mut q = Dd::ZERO;
        for (c, &load) in loads.iter().enumerate() {
            if !force[r][c].is_zero() && !load.is_zero() {
                q += force[r][c] * load;
            }
        }
        q
    })
}

/// The closed forms of Appendix A: the symmetric pendulum (the `[asymmetry]` keys are not read;
/// [`crate::geometry::dd_matrices`] gives the matrices of any parameter set).
pub fn build(p: &Params) -> Matrices {
    // Appendix A: M, the gravity part of K (eqs. (def_I) and (EM)) and the zeroth-order
    // generalized forces (its last display), in double-double.
    let mass = appendix::mass::<Dd>(p);
    let kg = appendix::stiffness_gravity::<Dd>(p);
    let force = appendix::force::<Dd>(p);
    let (g0, g2) = tilt_forcing(p, &kg, &force);
    Matrices {
        mass,
        stiffness: stiffness(p, &kg),
        damping: damping(p),
        translation_g2: translation_forcing(p, &force),
        observation: observation(p),
        stiffness_gravity: kg,
        force,
        g0,
        g2,
    }
}

/// The complex stiffness: the gravity part `kg` plus the fibres' elastic stiffness with
/// structural damping k (1 + i phi), plus the swing's loss.
fn stiffness(p: &Params, kg: &[[Dd; 8]; 8]) -> [[CDd; 8]; 8] {
    let (m_a, m_b) = (dd(p.mass.m_a_kg), dd(p.mass.m_b_kg));
    let l = &p.length;
    let (z, z_a, z_b) = (dd(l.z_m), dd(l.z_a_m), dd(l.z_b_m));
    let g = dd(p.environment.g_m_per_s2);
    let zza = z + z_a;
    let mut stiffness = kg.map(|row| row.map(CDd::real));
    let lp = &p.loss;
    for (c, k, phi) in appendix::stiffness_elastic(p) {
        stiffness[c][c] += CDd::new(dd(k), Dd::mul_f64_exact(k, phi));
    }
    // Swing: the gravity potential is a sum over the fibres' pendulums,
    // 1/2 g [m_a (Z + Z_a) + m_b Z] theta_a^2 (upper fibre: both bodies, the test mass's weight
    // at the lower suspension point) + 1/2 m_b g Z_b (theta_a + theta_b)^2 (lower fibre: the
    // test mass about the lower suspension point), and likewise for eta; each fibre's share
    // gets its diluted loss angle, phi_swing = phi_bending / D.
    let k_ga = g * (m_a * zza + m_b * z);
    let k_gb = m_b * g * z_b;
    let phi_a = dd(lp.bending_a_rad) / dd(lp.dilution_a);
    let phi_b = dd(lp.bending_b_rad) / dd(lp.dilution_b);
    let (im_a, im_b) = (phi_a * k_ga, phi_b * k_gb);
    for (a, b) in [(TA, TB), (EA, EB)] {
        stiffness[a][a] += CDd::new(Dd::ZERO, im_a + im_b);
        stiffness[a][b] += CDd::new(Dd::ZERO, im_b);
        stiffness[b][a] += CDd::new(Dd::ZERO, im_b);
        stiffness[b][b] += CDd::new(Dd::ZERO, im_b);
    }
    stiffness
}

/// Viscous damping on the same coordinates as the stiffness (swing of fibre b on the absolute
/// angles).
fn damping(p: &Params) -> [[Dd; 8]; 8] {
    let v = &p.viscous;
    let mut damping = [[Dd::ZERO; 8]; 8];
    for (c, coef) in [
        (PA, v.torsion_a_n_m_s_per_rad),
        (PB, v.torsion_b_n_m_s_per_rad),
        (DA, v.bouncing_a_n_s_per_m),
        (DB, v.bouncing_b_n_s_per_m),
    ] {
        damping[c][c] = dd(coef);
    }
    let (c_a, c_b) = (dd(v.swing_a_n_m_s_per_rad), dd(v.swing_b_n_m_s_per_rad));
    for (a, b) in [(TA, TB), (EA, EB)] {
        damping[a][a] = c_a + c_b;
        damping[a][b] = c_b;
        damping[b][a] = c_b;
        damping[b][b] = c_b;
    }
    damping
}

/// Tilt forcing `(G0, G2)` (section IV.B, crate convention: t takes the floor frame to the
/// inertial frame), columns theta_t, eta_t, phi_t.
fn tilt_forcing(
    p: &Params,
    kg: &[[Dd; 8]; 8],
    force: &[[Dd; 12]; 8],
) -> ([[Dd; 3]; 8], [[Dd; 3]; 8]) {
    let (m_a, m_b) = (dd(p.mass.m_a_kg), dd(p.mass.m_b_kg));
    let i = &p.inertia;
    let (a11, a22, a33, a23) = (
        dd(i.a11_kg_m2),
        dd(i.a22_kg_m2),
        dd(i.a33_kg_m2),
        dd(i.a23_kg_m2),
    );
    let (b11, b22, b33) = (dd(i.b11_kg_m2), dd(i.b22_kg_m2), dd(i.b33_kg_m2));
    let l = &p.length;
    let (d, z, z_a, z_b, h) = (dd(l.d_m), dd(l.z_m), dd(l.z_a_m), dd(l.z_b_m), dd(l.h_m));
    // Section II.A: the crossbar's centre of mass balances the test mass on the upper fibre.
    let y_a = appendix::y_a::<Dd>(p);
    let zza = z + z_a;
    let zzb = z + z_b;
    let one = Dd::ONE;

    // G0: the potential is evaluated at theta_a - theta_t, eta_a - eta_t, so the tilt columns
    // are K_gravity's theta_a and eta_a columns; phi_t does not enter the potential.
    let mut g0 = [[Dd::ZERO; 3]; 8];
    for r in 0..8 {
        g0[r][0] = kg[r][TA];
        g0[r][1] = kg[r][EA];
    }
    // G2: apparent forces and torques per unit t'' (frame angular acceleration w' = -t'').
    let zero = Dd::ZERO;
    let inertia_a = [[a11, zero, zero], [zero, a22, a23], [zero, a23, a33]];
    let inertia_b = [[b11, zero, zero], [zero, b22, zero], [zero, zero, b33]];
    let r_ga0 = [zero, y_a, -zza];
    let r_gb0 = [zero, -d, -zzb];
    let mut g2 = [[Dd::ZERO; 3]; 8];
    for axis in 0..3 {
        let mut w_dot = [zero; 3];
        w_dot[axis] = -one;
        let r_s = cross(w_dot, [zero, zero, h]);
        let apparent_force = |m: Dd, r_g: [Dd; 3]| {
            let rot = cross(w_dot, r_g);
            [0, 1, 2].map(|k| -(m * (r_s[k] + rot[k])))
        };
        let apparent_torque = |inertia: [[Dd; 3]; 3]| {
            [0, 1, 2].map(|k| {
                -(inertia[k][0] * w_dot[0] + inertia[k][1] * w_dot[1] + inertia[k][2] * w_dot[2])
            })
        };
        let [fa, fb, ma, mb] = [
            apparent_force(m_a, r_ga0),
            apparent_force(m_b, r_gb0),
            apparent_torque(inertia_a),
            apparent_torque(inertia_b),
        ];
        let loads: Vec<Dd> = [fa, fb, ma, mb].concat();
        // Q per unit t''; a harmonic tilt has t'' = -w^2 t, so G2 = -Q.
        for (r, q) in generalized_forces(force, &loads).into_iter().enumerate() {
            g2[r][axis] = -q;
        }
    }
    (g0, g2)
}

/// Floor-translation forcing per unit `w^2` displacement (columns x_t, y_t, z_t).
fn translation_forcing(p: &Params, force: &[[Dd; 12]; 8]) -> [[Dd; 3]; 8] {
    let (m_a, m_b) = (dd(p.mass.m_a_kg), dd(p.mass.m_b_kg));
    // Floor translation: the frame accelerates by u'' without turning, so each body feels
    // -m u'' at its centre of mass and no torque. Q per unit u''; u'' = -w^2 u, so G2 = -Q.
    let mut translation_g2 = [[Dd::ZERO; 3]; 8];
    for axis in 0..3 {
        let mut loads = [Dd::ZERO; 12];
        loads[axis] = -m_a;
        loads[3 + axis] = -m_b;
        for (r, q) in generalized_forces(force, &loads).into_iter().enumerate() {
            translation_g2[r][axis] = -q;
        }
    }
    // Section II.A places the crossbar's centre of mass so that the pendulum balances on the
    // upper fibre, m_a y_a = m_b d: a uniform field along x exerts no torque about the fibre
    // (phi_a), one along z none about x (theta_a). y_a = d m_b / m_a in double-double leaves a
    // few DD_EPS of m_b d there; the balance is exact by definition.
    translation_g2[PA][0] = Dd::ZERO;
    translation_g2[TA][2] = Dd::ZERO;
    translation_g2
}

/// Observation matrix C (section II.D), rows X, Y, Z, theta, eta, phi, phi_a.
fn observation(p: &Params) -> [[Dd; 8]; 7] {
    let l = &p.length;
    let (d, h_c, z, z_b) = (dd(l.d_m), dd(l.h_c_m), dd(l.z_m), dd(l.z_b_m));
    let one = Dd::ONE;
    let lever = z + z_b + h_c;
    let lower = h_c + z_b;
    let mut observation = [[Dd::ZERO; 8]; 7];
    observation[OBS_X][EA] = -lever;
    observation[OBS_X][EB] = -lower;
    observation[OBS_X][PA] = d;
    observation[OBS_Y][TA] = lever;
    observation[OBS_Y][TB] = lower;
    observation[OBS_Z][DA] = -one;
    observation[OBS_Z][DB] = -one;
    observation[OBS_Z][TA] = -d;
    observation[OBS_THETA][TA] = one;
    observation[OBS_THETA][TB] = one;
    observation[OBS_ETA][EA] = one;
    observation[OBS_ETA][EB] = one;
    observation[OBS_PHI][PA] = one;
    observation[OBS_PHI][PB] = one;
    observation[OBS_PHI_A][PA] = one;
    observation
}
