//! Dissipation: the structural (loss-angle) and viscous elements of the fibres.
//!
//! Every element acts on a few generalized-force directions `v_j` of q with a weight `w_j`;
//! its matrix is `sum_j w_j v_j v_j^T`, symmetric positive semi-definite by construction (the
//! weights are >= 0), so every element dissipates. For a structural element the matrix is its
//! imaginary stiffness `Im(K_e)` (N m/rad, N/m), for a viscous one its damping matrix `C_e`
//! (N m s/rad, N s/m). The rank-one form is what the thermal noise needs:
//! `c^T H Im(K_e) H^H c = sum_j w_j |c^T H v_j|^2` keeps full relative accuracy.
//!
//! # Which coordinates each element acts on
//!
//! * torsion of fibre a (b): `phi_a` (`phi_b`, the twist of the lower fibre relative to the
//!   crossbar), weight `phi k_a` (`phi k_b`);
//! * bouncing of fibre a (b): `delta_a` (`delta_b`), weight `phi kappa_a` (`phi kappa_b`);
//! * swing of fibre a (b): the fibre's share of the gravity stiffness. The gravity potential of
//!   section II, to second order, is
//!
//!   ```text
//!   V = 1/2 g [m_a (Z + Z_a) + m_b Z] (theta_a^2 + eta_a^2)
//!     + 1/2 m_b g Z_b [(theta_a + theta_b)^2 + (eta_a + eta_b)^2]
//!   ```
//!
//!   (expand it: `theta_a^2` gets `g c1`, `c1 = m_a (Z + Z_a) + m_b (Z + Z_b)`, the cross term
//!   `m_b g Z_b`, `theta_b^2` gets `m_b g Z_b`: exactly `K_gravity`). The first term is the
//!   upper fibre's pendulum (both bodies hanging from it, the test mass's weight acting at the
//!   lower suspension point), the second the lower fibre's pendulum (the test mass about the
//!   lower suspension point, on its absolute angle). So `K_gravity = k_ga (e_ta e_ta^T + e_ea
//!   e_ea^T) + k_gb (u_t u_t^T + u_e u_e^T)` with `k_ga = g [m_a (Z + Z_a) + m_b Z]`,
//!   `k_gb = m_b g Z_b`, `u_t = e_theta_a + e_theta_b`, `u_e = e_eta_a + e_eta_b`, and the swing
//!   loss of fibre a (b) is `phi_swing k_ga` (`phi_swing k_gb`) on those directions. The swing
//!   loss angle is the fibre's material loss angle diluted, `phi_swing = phi_fibre / D`.
//!
//! Viscous elements act on the same directions with the coefficients of
//! [`crate::params::Viscous`].
//!
//! # At a tilted equilibrium
//!
//! With the `[asymmetry]` offsets the bodies rest tilted ([`crate::geometry`]) and the gravity
//! stiffness is no longer exactly the sum above: it gains couplings of the order of the rest
//! angles. The loss of a fibre's swing is the fibre's bending loss near its clamp, which is set
//! by the angle through which the fibre's direction turns away from its rest direction, whatever
//! that rest direction is. So each swing element keeps its weight `phi_swing k_g` (`k_ga`, `k_gb`
//! from the nominal lengths and tensions: the pendulum's gravity stiffness changes only at second
//! order in the rest angles, well inside the uncertainty of a dilution factor) and acts on the
//! two components of that turn: the angular displacement of the body the fibre carries about the
//! body's own x and y axes (the fibre is its z axis), per unit `q`, from the exact kinematics
//! ([`crate::geometry::Linearization::swing`]). At the symmetric equilibrium these are exactly
//! `e_theta_a, e_eta_a` and `u_t, u_e` above. Torsion and bouncing act on the fibres' own
//! coordinates phi and delta and stay there; viscous swing elements use the same directions.

use super::{Coord, Mat8, Vec8};
use crate::params::Params;

/// How an element dissipates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DampingKind {
    /// Structural (hysteretic) damping `k (1 + i phi)`: a frequency-independent imaginary
    /// stiffness; its thermal force noise is `4 k_B T Im(k) / w`, a 1/f PSD.
    Structural,
    /// Viscous damping `i w c`: its thermal force noise is `4 k_B T c`, white.
    Viscous,
}

impl DampingKind {
    /// `structural` or `viscous`.
    pub fn name(self) -> &'static str {
        match self {
            DampingKind::Structural => "structural",
            DampingKind::Viscous => "viscous",
        }
    }
}

/// One dissipative element of the model.
#[derive(Debug, Clone, PartialEq)]
pub struct DissipativeElement {
    /// `torsion_a`, `bouncing_b`, `swing_b`, ...; viscous elements end in `_viscous`.
    pub name: String,
    /// Structural or viscous.
    pub kind: DampingKind,
    /// `(w_j, v_j)`: the element's matrix is `sum_j w_j v_j v_j^T`, `w_j > 0`. Units of `w_j`:
    /// N m/rad or N/m (structural, imaginary stiffness), N m s/rad or N s/m (viscous).
    pub terms: Vec<(f64, Vec8)>,
}

impl DissipativeElement {
    /// The element's matrix `sum_j w_j v_j v_j^T`: `Im(K_e)` (structural) or `C_e` (viscous).
    pub fn matrix(&self) -> Mat8 {
        self.terms
            .iter()
            .fold(Mat8::zeros(), |acc, (w, v)| acc + v * v.transpose() * *w)
    }
}

fn unit(coords: &[Coord]) -> Vec8 {
    let mut v = Vec8::zeros();
    for c in coords {
        v[c.index()] = 1.0;
    }
    v
}

/// Gravity stiffness of each fibre's pendulum, `(k_ga, k_gb)` (N m/rad), see the module docs.
pub fn swing_stiffness(p: &Params) -> (f64, f64) {
    let (m_a, m_b, g) = (p.mass.m_a_kg, p.mass.m_b_kg, p.environment.g_m_per_s2);
    let l = &p.length;
    (
        g * (m_a * (l.z_m + l.z_a_m) + m_b * l.z_m),
        m_b * g * l.z_b_m,
    )
}

/// The two swing directions of each fibre (upper, lower): the components, per unit `q`, of
/// the turn of the fibre's direction away from its rest direction. At the symmetric equilibrium
/// these are `e_theta_a, e_eta_a` and `e_theta_a + e_theta_b, e_eta_a + e_eta_b`; at a tilted
/// one they come from the exact kinematics ([`crate::geometry::Linearization::swing`]).
pub type SwingDirections = [[Vec8; 2]; 2];

/// The swing directions at the symmetric equilibrium.
pub(super) fn symmetric_swing() -> SwingDirections {
    use Coord::*;
    [
        [unit(&[ThetaA]), unit(&[EtaA])],
        [unit(&[ThetaA, ThetaB]), unit(&[EtaA, EtaB])],
    ]
}

/// Every dissipative element with a nonzero coefficient, structural first, in the order
/// torsion a, torsion b, bouncing a, bouncing b, swing a, swing b; the swing elements act on
/// `swing`.
pub(super) fn elements(p: &Params, swing: &SwingDirections) -> Vec<DissipativeElement> {
    use Coord::*;
    let (k_ga, k_gb) = swing_stiffness(p);
    let (loss, visc) = (&p.loss, &p.viscous);
    let [swing_a, swing_b] = swing;
    let one = |c: Coord| vec![unit(&[c])];
    let specs: [(&str, f64, f64, Vec<Vec8>); 6] = [
        (
            "torsion_a",
            loss.torsion_a_rad * p.torsion.k_a_n_m_per_rad,
            visc.torsion_a_n_m_s_per_rad,
            one(PhiA),
        ),
        (
            "torsion_b",
            loss.torsion_b_rad * p.torsion.k_b_n_m_per_rad,
            visc.torsion_b_n_m_s_per_rad,
            one(PhiB),
        ),
        (
            "bouncing_a",
            loss.bouncing_a_rad * p.bouncing.kappa_a_n_per_m,
            visc.bouncing_a_n_s_per_m,
            one(DeltaA),
        ),
        (
            "bouncing_b",
            loss.bouncing_b_rad * p.bouncing.kappa_b_n_per_m,
            visc.bouncing_b_n_s_per_m,
            one(DeltaB),
        ),
        (
            "swing_a",
            loss.swing_a_rad() * k_ga,
            visc.swing_a_n_m_s_per_rad,
            swing_a.to_vec(),
        ),
        (
            "swing_b",
            loss.swing_b_rad() * k_gb,
            visc.swing_b_n_m_s_per_rad,
            swing_b.to_vec(),
        ),
    ];
    let mut out = Vec::new();
    for kind in [DampingKind::Structural, DampingKind::Viscous] {
        for (name, structural, viscous, dirs) in &specs {
            let w = match kind {
                DampingKind::Structural => *structural,
                DampingKind::Viscous => *viscous,
            };
            if w > 0.0 {
                out.push(DissipativeElement {
                    name: match kind {
                        DampingKind::Structural => name.to_string(),
                        DampingKind::Viscous => format!("{name}_viscous"),
                    },
                    kind,
                    terms: dirs.iter().map(|v| (w, *v)).collect(),
                });
            }
        }
    }
    out
}

/// Sum of the matrices of the elements of one kind.
pub(super) fn total(elements: &[DissipativeElement], kind: DampingKind) -> Mat8 {
    elements
        .iter()
        .filter(|e| e.kind == kind)
        .fold(Mat8::zeros(), |acc, e| acc + e.matrix())
}
