//! The model's matrices in double-double for the reference and the pole-zero method, for any
//! parameter set: the closed forms of [`crate::dd::matrices`] for the symmetric pendulum, the
//! linearization about the tilted rest configuration ([`super::linearize`] in double-double)
//! for the pendulum as built, with the rounding scales of its data.

use crate::dd::matrices::{self, Matrices, Scales, DA, DB, PA, PB};
use crate::dd::{CDd, Dd};
use crate::error::ParamError;
use crate::params::Params;

fn dd(x: f64) -> Dd {
    Dd::from_f64(x)
}

/// The matrices of `p` in double-double, and their rounding scales when they differ from the
/// data's own magnitudes (the pendulum as built; `None` for the closed forms).
///
/// # Panics
///
/// If `p` has `[asymmetry]` offsets with no stable rest configuration, i.e. parameters for
/// which [`crate::model::Model::new`] fails: every caller in the crate builds from a model's
/// parameters.
pub fn dd_matrices(p: &Params) -> (Matrices, Option<Scales>) {
    if p.asymmetry.is_zero() {
        (matrices::build(p), None)
    } else {
        let (m, scales) = as_built(p)
            .unwrap_or_else(|e| panic!("double-double matrices of a model that fails: {e}"));
        (m, Some(scales))
    }
}

/// The linearization of the pendulum as built, in double-double, with the same dissipation as
/// the symmetric closed form: the fibres' torsion and bouncing on their own coordinates, each
/// fibre's swing loss on its swing directions at the rest configuration
/// (see [`crate::model::damping`]).
fn as_built(p: &Params) -> Result<(Matrices, Scales), ParamError> {
    let tracked = super::linearize::<Dd>(p)?;
    let (lin, mag) = (tracked.cleaned(), tracked.magnitudes());
    if !p.asymmetry.moves_mass() {
        // A readout rotation alone: the pendulum as drawn, read along turned axes.
        let mut scales = Scales::own(&matrices::build(p));
        scales.observation = mag.observation;
        let matrices = Matrices {
            observation: lin.observation,
            ..matrices::build(p)
        };
        return Ok((matrices, scales));
    }
    let g = dd(p.environment.g_m_per_s2);
    let (m_a, m_b) = (dd(p.mass.m_a_kg), dd(p.mass.m_b_kg));
    let l = &p.length;
    let k_g = [
        g * (m_a * (dd(l.z_m) + dd(l.z_a_m)) + m_b * dd(l.z_m)),
        m_b * g * dd(l.z_b_m),
    ];
    let lp = &p.loss;
    let phi_swing = [
        dd(lp.bending_a_rad) / dd(lp.dilution_a),
        dd(lp.bending_b_rad) / dd(lp.dilution_b),
    ];
    let v = &p.viscous;
    let c_swing = [dd(v.swing_a_n_m_s_per_rad), dd(v.swing_b_n_m_s_per_rad)];
    let mut stiffness = lin.stiffness_gravity.map(|row| row.map(CDd::real));
    let mut damping = [[Dd::ZERO; 8]; 8];
    for (c, k, phi, coef) in [
        (
            PA,
            p.torsion.k_a_n_m_per_rad,
            lp.torsion_a_rad,
            v.torsion_a_n_m_s_per_rad,
        ),
        (
            PB,
            p.torsion.k_b_n_m_per_rad,
            lp.torsion_b_rad,
            v.torsion_b_n_m_s_per_rad,
        ),
        (
            DA,
            p.bouncing.kappa_a_n_per_m,
            lp.bouncing_a_rad,
            v.bouncing_a_n_s_per_m,
        ),
        (
            DB,
            p.bouncing.kappa_b_n_per_m,
            lp.bouncing_b_rad,
            v.bouncing_b_n_s_per_m,
        ),
    ] {
        stiffness[c][c] += CDd::new(dd(k), Dd::mul_f64_exact(k, phi));
        damping[c][c] = dd(coef);
    }
    for fibre in 0..2 {
        let loss = phi_swing[fibre] * k_g[fibre];
        for s in &lin.swing[fibre] {
            for r in 0..8 {
                for c in 0..8 {
                    let ss = s[r] * s[c];
                    if ss.is_zero() {
                        continue;
                    }
                    if !loss.is_zero() {
                        stiffness[r][c] += CDd::new(Dd::ZERO, loss * ss);
                    }
                    if !c_swing[fibre].is_zero() {
                        damping[r][c] += c_swing[fibre] * ss;
                    }
                }
            }
        }
    }
    let tilts = |g: &[[f64; 6]; 8]| g.map(|row| [row[0], row[1], row[2]]);
    let translations = |g: &[[f64; 6]; 8]| g.map(|row| [row[3], row[4], row[5]]);
    let scales = Scales {
        mass: mag.mass,
        stiffness: std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                mag.stiffness_gravity[r][c]
                    + (stiffness[r][c] - CDd::real(lin.stiffness_gravity[r][c])).abs_f64()
            })
        }),
        force: mag.force,
        g0: tilts(&mag.ground_g0),
        g2: tilts(&mag.ground_g2),
        translation_g2: translations(&mag.ground_g2),
        observation: mag.observation,
    };
    let tilts = |g: &[[Dd; 6]; 8]| g.map(|row| [row[0], row[1], row[2]]);
    let translations = |g: &[[Dd; 6]; 8]| g.map(|row| [row[3], row[4], row[5]]);
    let matrices = Matrices {
        mass: lin.mass,
        stiffness_gravity: lin.stiffness_gravity,
        stiffness,
        damping,
        force: lin.force,
        g0: tilts(&lin.ground_g0),
        g2: tilts(&lin.ground_g2),
        translation_g2: translations(&lin.ground_g2),
        observation: lin.observation,
    };
    Ok((matrices, scales))
}
