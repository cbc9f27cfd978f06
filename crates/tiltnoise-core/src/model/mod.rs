//! The linearized 8-DoF model of the double torsion pendulum (paper, Appendix A): mass and
//! stiffness matrices, the zeroth-order generalized-force matrix, the forcing by the floor's tilt
//! and translation, and the observation matrix. For the symmetric pendulum these are the
//! Appendix's closed forms; with `[asymmetry]` offsets, the linearization about the tilted rest
//! configuration of the pendulum as built ([`crate::geometry`]). Pure numerics: depends on
//! `params`, `geometry` and `nalgebra`, never on I/O.

mod as_built;
mod coords;
pub mod damping;
mod matrices;
mod request;
pub mod tilt;
pub mod translation;

pub use coords::{Block, Coord, ForceInput, Observable, TiltAxis, TranslationAxis};
pub use damping::{DampingKind, DissipativeElement};
pub use request::{Input, Request};

use crate::error::ParamError;
use crate::params::Params;
use nalgebra::{SMatrix, SVector};
use num_complex::Complex64;

/// 8x8 real matrix in coordinate order [`Coord::ALL`].
pub type Mat8 = SMatrix<f64, 8, 8>;
/// 8x8 complex matrix.
pub type CMat8 = SMatrix<Complex64, 8, 8>;
/// Generalized forces per unit external force/torque (8 x 12).
pub type ForceMatrix = SMatrix<f64, 8, 12>;
/// Generalized forces per unit tilt angle (8 x 3).
pub type TiltMatrix = SMatrix<f64, 8, 3>;
/// Generalized forces per unit floor displacement and `w^2` (8 x 3).
pub type TranslationMatrix = SMatrix<f64, 8, 3>;
/// Observables per unit coordinate (7 x 8).
pub type ObservationMatrix = SMatrix<f64, 7, 8>;
/// A generalized-coordinate vector.
pub type Vec8 = SVector<f64, 8>;

/// Geometric quantities derived from the parameters (section II.A and Appendix A).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Derived {
    /// Horizontal offset of the crossbar centre of mass from the upper fibre, y_a = d m_b / m_a (m).
    pub y_a_m: f64,
    /// Crossbar centre of mass at equilibrium, relative to the upper suspension point (m).
    pub r_ga0_m: [f64; 3],
    /// Test-mass centre of mass at equilibrium, relative to the upper suspension point (m).
    pub r_gb0_m: [f64; 3],
    /// Lever arm of the cube centre below the upper suspension point, Z + Z_b + h_c (m):
    /// the static tilt gain of X and Y.
    pub lever_m: f64,
}

/// Refuses a parameter set whose equilibrium is not stable: the undamped stiffness `K` must be
/// positive definite on the model's coordinates, i.e. every generalized eigenvalue
/// `omega^2` of `(K, M)` positive. The error names the unstable mode by its dominant
/// coordinates (e.g. a crossbar centre of mass above the upper suspension point makes the
/// crossbar's swing unstable).
fn check_stable(mass: &Mat8, stiffness: &Mat8) -> Result<(), ParamError> {
    // M = L L^T; L^-1 K L^-T has the generalized eigenvalues of (K, M); M was checked
    // positive definite before.
    let Some(chol) = mass.cholesky() else {
        return Ok(());
    };
    let l = chol.l();
    let Some(l_inv) = l.try_inverse() else {
        return Ok(());
    };
    let a = l_inv * stiffness * l_inv.transpose();
    let a = (a + a.transpose()) * 0.5;
    let eig = a.symmetric_eigen();
    let scale = eig.eigenvalues.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // Eigenvalues within rounding of zero (n eps ||A||) count as zero, which is not stable
    // either: a zero-frequency mode has no restoring force.
    let tol = 8.0 * f64::EPSILON * scale;
    let (k, &omega_sq) = eig
        .eigenvalues
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .expect("8 eigenvalues");
    if omega_sq > tol && omega_sq.is_finite() {
        return Ok(());
    }
    // The mode shape in the model's coordinates: q = L^-T y.
    let q = l_inv.transpose() * eig.eigenvectors.column(k);
    let energy: Vec<f64> = (0..8).map(|i| q[i] * (mass * q)[i]).collect();
    let total: f64 = energy.iter().sum();
    let mut shares: Vec<(Coord, f64)> = Coord::ALL
        .iter()
        .map(|&c| (c, energy[c.index()] / total))
        .collect();
    shares.sort_by(|a, b| b.1.total_cmp(&a.1));
    let dominant: Vec<String> = shares
        .iter()
        .filter(|(_, s)| *s >= 0.1)
        .map(|(c, s)| format!("{} {s:.2}", c.name()))
        .collect();
    Err(ParamError::Unstable {
        omega_sq,
        mode: dominant.join(", "),
    })
}

/// True when no entry of `m` couples the two blocks of [`Block`].
fn block_diagonal(m: &Mat8) -> bool {
    let [a, b] = Block::ALL.map(|block| block.coords().map(Coord::index));
    a.iter()
        .all(|&i| b.iter().all(|&j| m[(i, j)] == 0.0 && m[(j, i)] == 0.0))
}

/// The linear model built from one validated parameter set. Immutable; cheap to clone.
#[derive(Debug, Clone)]
pub struct Model {
    params: Params,
    derived: Derived,
    /// The rest configuration about which the model is linear.
    rest: Vec8,
    /// `M`, `K_c` and the viscous damping are block diagonal in the [`Block`] split.
    decoupled: bool,
    mass: Mat8,
    stiffness_gravity: Mat8,
    stiffness_elastic: Mat8,
    /// `Im(K_c)`: the sum of the structural elements' matrices.
    stiffness_imag: Mat8,
    /// Viscous damping matrix `C`: the sum of the viscous elements' matrices.
    damping: Mat8,
    dissipation: Vec<DissipativeElement>,
    force: ForceMatrix,
    tilt: tilt::TiltForcing,
    translation: translation::TranslationForcing,
    observation: ObservationMatrix,
}

impl Model {
    /// Builds the model. Fails if the mass matrix is not positive definite (possible for
    /// parameter sets that pass the per-key checks, e.g. a huge negative I^a_23 coupling), if
    /// the equilibrium is not stable (the stiffness is not positive definite, see
    /// [`ParamError::Unstable`]), if the pendulum as built has no stable rest configuration
    /// near the drawing's ([`ParamError::NoEquilibrium`]), or if a matrix entry overflows.
    pub fn new(params: &Params) -> Result<Model, ParamError> {
        let linear = if params.asymmetry.is_zero() {
            as_built::RestLinear::symmetric(params)
        } else {
            as_built::RestLinear::as_built(params)?
        };
        let as_built::RestLinear {
            derived,
            rest,
            mass,
            stiffness_gravity,
            force,
            tilt,
            translation,
            observation,
            swing,
        } = linear;
        let (_, stiffness_elastic) = matrices::stiffness(params);
        let dissipation = damping::elements(params, &swing);
        let stiffness_imag = damping::total(&dissipation, DampingKind::Structural);
        let damping = damping::total(&dissipation, DampingKind::Viscous);
        if mass.cholesky().is_none() {
            let eig = mass.symmetric_eigenvalues().min();
            return Err(ParamError::NotPositiveDefinite {
                what: "mass matrix M",
                keys: "mass.*, inertia.*, length.*".into(),
                detail: format!("smallest eigenvalue {eig:e} (mixed units kg, kg m, kg m^2)"),
            });
        }
        check_stable(&mass, &(stiffness_gravity + stiffness_elastic))?;
        let finite = |m: &[f64]| m.iter().all(|x| x.is_finite());
        if !(finite(mass.as_slice())
            && finite(stiffness_gravity.as_slice())
            && finite(stiffness_elastic.as_slice())
            && finite(stiffness_imag.as_slice())
            && finite(damping.as_slice())
            && finite(force.as_slice())
            && finite(tilt.g0.as_slice())
            && finite(tilt.g2.as_slice())
            && finite(translation.g2.as_slice())
            && finite(observation.as_slice()))
        {
            return Err(ParamError::NotFinite {
                detail: "an entry of M, K, C, the force, tilt, translation or observation matrix \
                         overflows f64; the parameter values are far outside a laboratory \
                         pendulum's"
                    .into(),
            });
        }
        let decoupled = [mass, stiffness_gravity, stiffness_imag, damping]
            .iter()
            .all(block_diagonal);
        Ok(Model {
            params: params.clone(),
            derived,
            rest,
            decoupled,
            mass,
            stiffness_gravity,
            stiffness_elastic,
            stiffness_imag,
            damping,
            dissipation,
            force,
            tilt,
            translation,
            observation,
        })
    }

    /// The parameters the model was built from.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Derived geometry.
    pub fn derived(&self) -> &Derived {
        &self.derived
    }

    /// Mass matrix M (Appendix A, eq. EM), symmetric positive definite. Units: kg, kg m, kg m^2
    /// according to the pair of coordinates.
    pub fn mass(&self) -> &Mat8 {
        &self.mass
    }

    /// Undamped stiffness K = gravity part + elastic part.
    pub fn stiffness(&self) -> Mat8 {
        self.stiffness_gravity + self.stiffness_elastic
    }

    /// Gravity part of K (swinging); lossless.
    pub fn stiffness_gravity(&self) -> &Mat8 {
        &self.stiffness_gravity
    }

    /// Elastic part of K (fibre torsion and bouncing), diagonal.
    pub fn stiffness_elastic(&self) -> &Mat8 {
        &self.stiffness_elastic
    }

    /// Complex stiffness with structural damping, `K_c = K + i Im(K_c)`: every structural
    /// element `k (1 + i phi)` (torsion, bouncing, and the diluted swing of each fibre; see
    /// [`damping`]). Viscous damping is not in here: see [`Model::damping`].
    pub fn stiffness_complex(&self) -> CMat8 {
        CMat8::from_fn(|r, c| {
            Complex64::new(
                self.stiffness_gravity[(r, c)] + self.stiffness_elastic[(r, c)],
                self.stiffness_imag[(r, c)],
            )
        })
    }

    /// `Im(K_c)`, symmetric positive semi-definite (N m/rad, N/m, N m/m by entry).
    pub fn stiffness_imag(&self) -> &Mat8 {
        &self.stiffness_imag
    }

    /// Viscous damping matrix `C` (N m s/rad, N s/m, ...), symmetric positive semi-definite; the
    /// dynamic stiffness is `K_c + i w C - w^2 M`.
    pub fn damping(&self) -> &Mat8 {
        &self.damping
    }

    /// True when some viscous coefficient is nonzero.
    pub fn has_viscous(&self) -> bool {
        self.damping.iter().any(|&c| c != 0.0)
    }

    /// `K_c + i w C` at angular frequency `w` (rad/s): the dynamic stiffness without the
    /// inertia term.
    pub fn stiffness_dynamic(&self, omega_rad_s: f64) -> CMat8 {
        let mut k = self.stiffness_complex();
        if self.has_viscous() {
            for (z, &c) in k.iter_mut().zip(self.damping.iter()) {
                z.im += omega_rad_s * c;
            }
        }
        k
    }

    /// Every dissipative element with a nonzero coefficient (structural first). Empty when
    /// the model is undamped.
    pub fn dissipative_elements(&self) -> &[DissipativeElement] {
        &self.dissipation
    }

    /// True when there is no dissipation at all (every loss angle and viscous coefficient 0).
    pub fn is_undamped(&self) -> bool {
        self.dissipation.is_empty()
    }

    /// Zeroth-order generalized forces per unit force/torque component (Appendix A), columns in
    /// the order of [`ForceInput::ALL`]. Units: m (force -> torque-like Q), 1 or rad/rad.
    pub fn force_matrix(&self) -> &ForceMatrix {
        &self.force
    }

    /// Tilt forcing `G(w) = G0 + w^2 G2`; see [`tilt`] for the sign convention.
    pub fn tilt_forcing(&self) -> &tilt::TiltForcing {
        &self.tilt
    }

    /// Floor-translation forcing `G(w) = w^2 G2`; see [`translation`] for the convention.
    pub fn translation_forcing(&self) -> &translation::TranslationForcing {
        &self.translation
    }

    /// Observation matrix C: observables (X, Y, Z in m; theta, eta, phi, phi_a in rad) from q.
    pub fn observation(&self) -> &ObservationMatrix {
        &self.observation
    }

    /// The rest configuration `q0` the model is linearized about (rad, m; coordinate order
    /// [`Coord::ALL`]): 0 for the symmetric pendulum, the tilted equilibrium found from the
    /// exact potential when an `[asymmetry]` offset moves a centre of mass
    /// ([`crate::geometry`]). Angles of body b are relative to body a, as the coordinates.
    pub fn rest_configuration(&self) -> &Vec8 {
        &self.rest
    }

    /// True when `M`, `K_c` and the viscous damping are exactly block diagonal in the split
    /// of [`Block`], so that the two blocks are independent systems: always for the symmetric
    /// pendulum, and with any offsets that keep the mirror plane x = 0 (along y only, or a
    /// readout rotation; the observation matrix may then mix the blocks). An offset along x
    /// couples them: the coupled 8x8 system.
    pub fn decoupled(&self) -> bool {
        self.decoupled
    }

    /// True when every `[asymmetry]` key is 0: the symmetric pendulum of the paper, whose
    /// matrices are the closed forms of Appendix A.
    pub fn is_symmetric(&self) -> bool {
        self.params.asymmetry.is_zero()
    }

    /// Principal 4x4 sub-matrix of an 8x8 matrix on one block's coordinates.
    pub fn block_of(matrix: &Mat8, block: Block) -> SMatrix<f64, 4, 4> {
        let idx = block.coords().map(Coord::index);
        SMatrix::<f64, 4, 4>::from_fn(|r, c| matrix[(idx[r], idx[c])])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without the upper fibre's torsion constant the crossbar's torsion has only the negative
    /// gravity stiffness of its offset centre of mass: an unstable equilibrium, refused with
    /// the mode named.
    #[test]
    fn unstable_equilibrium_is_refused_naming_the_mode() {
        let params = Params::table_i()
            .with_override("torsion.k_a_n_m_per_rad=1e-30")
            .unwrap();
        let err = Model::new(&params).unwrap_err();
        match &err {
            ParamError::Unstable { omega_sq, mode } => {
                assert!(*omega_sq < 0.0, "{err}");
                assert!(mode.starts_with("phi_a"), "{err}");
            }
            other => panic!("expected Unstable, got {other}"),
        }
    }

    #[test]
    fn table_i_is_stable() {
        assert!(Model::new(&Params::table_i()).is_ok());
    }
}
