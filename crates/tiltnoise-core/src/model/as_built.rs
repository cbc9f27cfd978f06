//! The model's geometry-dependent matrices: the closed forms of Appendix A for the symmetric
//! pendulum, or the linearization about the tilted rest configuration of an asymmetric one
//! ([`crate::geometry`]).

use super::damping::{self, SwingDirections};
use super::{
    matrices, tilt, translation, Derived, ForceMatrix, Mat8, ObservationMatrix, TiltMatrix,
    TranslationMatrix, Vec8,
};
use crate::dd::Dd;
use crate::error::ParamError;
use crate::geometry::{self, Linearization};
use crate::params::Params;

/// Everything in the model that depends on where the bodies rest.
pub(super) struct RestLinear {
    pub derived: Derived,
    /// The rest configuration `q0` (zero for the symmetric pendulum).
    pub rest: Vec8,
    pub mass: Mat8,
    pub stiffness_gravity: Mat8,
    pub force: ForceMatrix,
    pub tilt: tilt::TiltForcing,
    pub translation: translation::TranslationForcing,
    pub observation: ObservationMatrix,
    pub swing: SwingDirections,
}

impl RestLinear {
    /// The closed forms of Appendix A: every `[asymmetry]` key is 0.
    pub fn symmetric(p: &Params) -> RestLinear {
        let derived = matrices::derived(p);
        let mass = matrices::mass(p);
        let (stiffness_gravity, _) = matrices::stiffness(p);
        let force = matrices::force_matrix(p);
        let tilt = tilt::TiltForcing::new(p, &derived, &force, &stiffness_gravity);
        let translation = translation::TranslationForcing::new(p, &force);
        RestLinear {
            derived,
            rest: Vec8::zeros(),
            mass,
            stiffness_gravity,
            force,
            tilt,
            translation,
            observation: matrices::observation(p),
            swing: damping::symmetric_swing(),
        }
    }

    /// The linearization about the rest configuration of the pendulum as built: computed in
    /// double-double and rounded, so that every entry is its exact value to half an ulp, as
    /// the closed forms are to a few, and entries equal in exact arithmetic are equal here (the
    /// tilt columns of `G0` and the columns of `K` they repeat, say): the `f64` model keeps the
    /// structural cancellations of the physics (the `f^4` of phi/eta_t at low frequency) that
    /// an `f64` evaluation of the kinematics would blur with its own rounding.
    ///
    /// A readout rotation alone leaves the pendulum as drawn: the closed forms then hold for
    /// everything but the observation matrix.
    pub fn as_built(p: &Params) -> Result<RestLinear, ParamError> {
        let lin: Linearization<f64> = geometry::linearize::<Dd>(p)?.cleaned().map(|x| x.to_f64());
        let observation = ObservationMatrix::from_fn(|r, c| lin.observation[r][c]);
        if !p.asymmetry.moves_mass() {
            return Ok(RestLinear {
                observation,
                ..RestLinear::symmetric(p)
            });
        }
        let square = |a: &[[f64; 8]; 8]| Mat8::from_fn(|r, c| a[r][c]);
        let mut derived = matrices::derived(p);
        [derived.r_ga0_m, derived.r_gb0_m] = lin.r_g0;
        Ok(RestLinear {
            derived,
            rest: Vec8::from_fn(|r, _| lin.rest[r]),
            mass: square(&lin.mass),
            stiffness_gravity: square(&lin.stiffness_gravity),
            force: ForceMatrix::from_fn(|r, c| lin.force[r][c]),
            tilt: tilt::TiltForcing {
                g0: TiltMatrix::from_fn(|r, c| lin.ground_g0[r][c]),
                g2: TiltMatrix::from_fn(|r, c| lin.ground_g2[r][c]),
            },
            translation: translation::TranslationForcing {
                g2: TranslationMatrix::from_fn(|r, c| lin.ground_g2[r][3 + c]),
            },
            observation,
            swing: lin
                .swing
                .map(|fibre| fibre.map(|v| Vec8::from_fn(|r, _| v[r]))),
        })
    }
}
