//! Transfer functions from inputs (tilt angles, floor translations, forces, torques) to
//! observables.
//!
//! `H(w) = C (K_c + i w D - w^2 M)^-1 G(w)`, with `K_c` the complex stiffness (structural loss
//! angles, [`crate::model::Model::stiffness_complex`]), `D` the viscous damping matrix (zero
//! unless the parameter file has `[viscous]` coefficients; methods that cannot represent it refuse
//! it at plan time), `G` the tilt forcing `G0 + w^2 G2` (columns per tilt angle, see
//! [`crate::model::tilt`]), the floor-translation forcing `w^2 G2` (columns per axis, see
//! [`crate::model::translation`]) or the zeroth-order force matrix (columns per force/torque
//! component). Units of an entry: the observable's unit per the input's unit (m/rad, rad/rad,
//! m/m, rad/m, m/N, rad/(N m), ...). The response is the complex amplitude for `e^{+i w t}`
//! time dependence.
//!
//! Methods are plain data ([`Method`]); [`plan`] builds a [`TransferFunction`] that does the
//! per-model work once and then evaluates cheaply at many frequencies
//! (RustFFT's recipe/plan pattern). The direct LU method is the `f64` oracle (slow, obviously
//! correct); the double-double [`crate::reference`] evaluator is the oracle of the accuracy
//! tests of every method, the direct one included.
//!
//! | method | what it computes | relative error, 7x3 tilt, 1e-5..100 Hz (Table I, measured) |
//! |---|---|---|
//! | [`Method::Direct`] | 8x8 LU per frequency | 1e-6: phi/eta_t, phi_a/eta_t grow as f^-2 below the torsion modes, eta/phi_t as f^2 above the swing modes |
//! | [`Method::Block`] | 4x4 LU per needed block | as direct (the same operations) |
//! | [`Method::Split`] | static part + translation forcing, absolute test-mass angles | 4e-13 outside 1 % of each entry's poles and zeros |
//! | [`Method::PoleZero`] | per entry `g s^p prod(z_j - s) / prod(lambda_k - s)`, built once in double-double | 3e-14 outside 1 % of each entry's poles and zeros (`tests/it/polezero.rs`) |
//! | [`Method::Modal`] | modal superposition | 1e-9 where modal terms do not cancel (the eigenvalues' error, 1 % from nu_1); none on phi/eta_t, phi_a/eta_t at low frequency (1e2 at 1e-5 Hz); damping approximate |
//! | [`Method::StateSpace`] | `[C, 0] (i w I - A)^-1 B + D`, 16x16 LU per frequency, as python-control and scipy.signal | 2.4e-5 on forces (phi/F_b.x at 100 Hz); none on phi/eta_t, phi_a/eta_t at low frequency (6e2 at 1e-5 Hz) |
//! | [`Method::Torsion2`] | the 2-DoF torsional model of section IV.C | a reduced model: 1e-5..1e-3 from the 8-DoF one at 0.5..5 mHz |
//!
//! `tests/it/methods.rs` checks every method against the reference with a tolerance derived from
//! its rounding model, on the tilt, force and floor-translation matrices, and prints these
//! numbers. On the translation matrix the methods behave as on tilt: direct and block lose
//! accuracy where phi/x_t falls as f^-2 above the swing modes, split and polezero keep it, modal
//! and statespace lose it where the entries are small remainders (theta/z_t falls as f^6 at low
//! frequency). The 2-DoF model refuses translations: they exert no torque on the balanced
//! crossbar.
//!
//! For the pendulum as built ([`crate::params::asymmetry`]) an offset along x couples the two
//! blocks into one 8x8 system: [`Method::Block`] refuses it at plan time, [`Method::Split`] and
//! [`Method::Torsion2`] refuse any offset (their closed forms are the symmetric pendulum's), and
//! [`Method::PoleZero`] factors the coupled system as a whole (8 poles, up to 8 factors per
//! entry), with a relative error of 1.1e-12 at most outside 1 % of each entry's poles and zeros
//! on the test models of `tests/it/methods.rs` (the reference's own error, `DD_EPS` times an
//! entry's condition from the data's rounding scales, is part of the bound there). Keys below
//! [`crate::params::asymmetry::LINEAR_BELOW`] are evaluated as their linear response, on two
//! plans of the method ([`Linearized`]): their effects are subnormal or below the structural
//! decisions of double-double otherwise.
//!
//! Per unit floor velocity or acceleration ([`TransferMatrix::per_ground_quantity`]), and below
//! [`EXACT_BELOW_HZ`] per unit displacement too, the floor's columns come from each entry's exact
//! product form scaled by powers of two ([`LowFrequency`]), so that a value within `f64`'s range
//! is computed and one beyond it refused ([`TfError::Overflow`]).

mod block;
mod buffer;
mod direct;
mod grid;
mod linear;
mod low_frequency;
mod matrix;
mod modal;
pub mod planner;
#[allow(unsafe_code, reason = "the AVX kernel")]
#[allow(
    clippy::undocumented_unsafe_blocks,
    reason = "the intrinsics of polezero/lanes.rs share one SAFETY argument, on its AVX type; \
              each block gets its own with the type that proves the CPU feature"
)]
mod polezero;
mod split;
mod statespace;
mod torsion2;

use crate::error::TfError;
use crate::model::Model;
pub use crate::model::{Input, Request};
use num_complex::Complex64;

pub use block::BlockReduced;
pub use buffer::{zeroed_complex, zeroed_f64};
pub use direct::{Direct, SINGULAR_RCOND};
pub(crate) use grid::check_grid_len;
pub use grid::{
    eval_grid_threads, eval_grid_threads_cancellable, evaluate, evaluate_into,
    evaluate_into_cancellable, Destination, STREAM_MIN_BYTES,
};
pub use linear::Linearized;
pub use low_frequency::{LowFrequency, EXACT_BELOW_HZ};
pub use matrix::{Layout, TransferMatrix};
pub use modal::Modal;
pub use planner::{
    choose, plan_auto, Choice, NoChoice, Scene, Verdict, DEFAULT_REL_TOL, POLE_EXCLUSION,
};
pub use polezero::{EntryFactors, PoleZero};
pub use split::Split;
pub use statespace::StateSpace;
pub use torsion2::Torsion2;

/// Evaluation methods. Plain data: the planner turns one into a [`TransferFunction`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Per-frequency LU of the full 8x8 dynamic stiffness, with equilibration and a condition
    /// check. Slow and obviously correct: the oracle for the other methods.
    Direct,
    /// Per-frequency 4x4 LU of each decoupled block the request needs ([`crate::model::Block`]),
    /// with the direct method's equilibration and condition check. Same results as direct.
    Block,
    /// Modal superposition over the undamped normal modes. Damping enters as modal loss angles,
    /// an approximation (see [`Method::exact_for_damping`]); loses all relative accuracy where
    /// the modal terms cancel (phi/eta_t and phi_a/eta_t at low frequency). A comparison method.
    Modal,
    /// Block LU in absolute test-mass angles, with the tilt response split into its exact static
    /// part and a translation forcing: full relative accuracy on every tilt entry, including the
    /// f^4 fall of phi/eta_t at low frequency, and on the force entries up to 100 Hz.
    Split,
    /// The 2-DoF torsional model of section IV.C (phi_a, phi_b only): a reduced model, valid
    /// near and below the torsion modes; refuses inputs and outputs it cannot represent.
    Torsion2,
    /// Each entry as `g s^p prod(z_j - s) / prod(lambda_k - s)` (`s = w^2`), with its poles,
    /// zeros and gain found once per plan in double-double from the reference's matrices:
    /// no solve per frequency. See [`PoleZero`].
    PoleZero,
    /// The first-order state-space form `[C, 0] (i w I - A)^-1 B + D` as python-control and
    /// scipy.signal evaluate it (16x16 LU per frequency, no equilibration): a comparison
    /// method that loses relative accuracy where the tilt forcing cancels. See [`StateSpace`].
    StateSpace,
}

impl Method {
    /// Every method, the oracle first.
    pub const ALL: [Method; 7] = [
        Method::Direct,
        Method::Block,
        Method::Split,
        Method::PoleZero,
        Method::Modal,
        Method::StateSpace,
        Method::Torsion2,
    ];

    /// Name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Method::Direct => "direct",
            Method::Block => "block",
            Method::Modal => "modal",
            Method::Split => "split",
            Method::Torsion2 => "torsion2",
            Method::PoleZero => "polezero",
            Method::StateSpace => "statespace",
        }
    }

    /// False when the method treats loss angles approximately (modal loss angles neglect the
    /// coupling of modes by damping); every other method solves `K_c - w^2 M` with the complex
    /// stiffness itself.
    pub fn exact_for_damping(self) -> bool {
        !matches!(self, Method::Modal)
    }

    /// False for the reduced 2-DoF model, whose transfer functions differ from the 8-DoF
    /// model's by the neglected coupling to the swing modes.
    pub fn full_model(self) -> bool {
        !matches!(self, Method::Torsion2)
    }
}

/// A request that a method cannot evaluate, found at plan time.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlanError {
    /// The method's model has no way to represent an input or an output of the request.
    #[error("method `{}` cannot evaluate {item}: {reason}", method.name())]
    Unsupported {
        /// The method asked for.
        method: Method,
        /// The input or output it cannot represent, e.g. `input eta_t`.
        item: String,
        /// Why, and what the method supports instead.
        reason: String,
    },
}

/// A planned transfer function: evaluates the `outputs x inputs` matrix at one frequency.
pub trait TransferFunction: Send + Sync {
    /// The method behind this plan.
    fn method(&self) -> Method;

    /// What the plan computes.
    fn request(&self) -> &Request;

    /// Writes `H(f)` row-major (`out[o * n_inputs + i]`) into `out`, whose length must be
    /// `outputs.len() * inputs.len()`. `freq_hz` must be finite and >= 0.
    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError>;

    /// Writes `H` at every frequency of `freqs_hz` into `out`, `[freq][output][input]`
    /// row-major (the dense [`Layout`]), whose length must be
    /// `freqs_hz.len() * outputs.len() * inputs.len()`, every value finite. Returns the error
    /// of the first frequency (in grid order) at which [`TransferFunction::eval_into`] fails
    /// or gives a value that is not finite ([`TfError::NotFinite`]: an overflow); `out` is
    /// then unspecified. The default calls `eval_into` point by point and checks each point's
    /// values while they are in cache; a method with a faster batch evaluation
    /// ([`Method::PoleZero`]) overrides it with the same values and errors.
    ///
    /// # Panics
    ///
    /// If `out` has the wrong length.
    fn eval_grid_into(&self, freqs_hz: &[f64], out: &mut [Complex64]) -> Result<(), TfError> {
        let block = check_grid_len(self.request(), freqs_hz, out);
        if block == 0 {
            // Nothing to write; each frequency is still checked.
            let mut none: [Complex64; 0] = [];
            return freqs_hz
                .iter()
                .try_for_each(|&f| self.eval_into(f, &mut none));
        }
        for (&f, h) in freqs_hz.iter().zip(out.chunks_exact_mut(block)) {
            self.eval_into(f, h)?;
            if h.iter().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
                return Err(TfError::NotFinite { freq_hz: f });
            }
        }
        Ok(())
    }

    /// [`TransferFunction::eval_grid_into`] into memory obtained as `destination` says: the
    /// same values and errors; only how a large output is written may differ (see
    /// [`Destination`]). The default ignores `destination`.
    ///
    /// # Panics
    ///
    /// If `out` has the wrong length.
    fn eval_grid_into_dest(
        &self,
        freqs_hz: &[f64],
        out: &mut [Complex64],
        destination: Destination,
    ) -> Result<(), TfError> {
        let _ = destination;
        self.eval_grid_into(freqs_hz, out)
    }

    /// The layout [`evaluate`] stores this plan's values in: [`Layout::dense`] unless the plan
    /// knows its structural zeros (or that its values are real) and overrides this together
    /// with [`TransferFunction::eval_grid_layout_into`].
    fn layout(&self) -> Layout {
        let r = self.request();
        Layout::dense(r.outputs.len() * r.inputs.len())
    }

    /// Writes `H` at every frequency of `freqs_hz` into `planes`, one per plane of
    /// [`TransferFunction::layout`], each as long as the grid: the values of
    /// [`TransferFunction::eval_grid_into`], stored differently, and the same errors. The
    /// default (dense layout) evaluates point by point with `eval_into`.
    ///
    /// # Panics
    ///
    /// If the number or the lengths of `planes` are wrong.
    fn eval_grid_layout_into(
        &self,
        freqs_hz: &[f64],
        planes: &mut [&mut [f64]],
    ) -> Result<(), TfError> {
        let n = self.layout().n_entries();
        assert_eq!(planes.len(), 2 * n, "two planes per entry (dense layout)");
        let mut h = vec![Complex64::new(0.0, 0.0); n];
        for (k, &f) in freqs_hz.iter().enumerate() {
            self.eval_into(f, &mut h)?;
            for (e, z) in h.iter().enumerate() {
                planes[2 * e][k] = z.re;
                planes[2 * e + 1][k] = z.im;
            }
        }
        Ok(())
    }

    /// Allocating convenience wrapper around [`TransferFunction::eval_into`].
    fn eval(&self, freq_hz: f64) -> Result<Vec<Complex64>, TfError> {
        let r = self.request();
        let mut out = vec![Complex64::new(0.0, 0.0); r.outputs.len() * r.inputs.len()];
        self.eval_into(freq_hz, &mut out)?;
        Ok(out)
    }
}

/// Builds the plan for `method` (factorizations and forcing matrices prepared once). Fails
/// for a method that cannot represent part of the request ([`Method::Torsion2`]), viscous
/// damping (the methods that solve only `K_c`), or the pendulum as built: `block` refuses the
/// coupled model (an offset along x), `split` and `torsion2` any `[asymmetry]` key. Keys below
/// [`crate::params::asymmetry::LINEAR_BELOW`] are evaluated as a linear response
/// ([`Linearized`]), on two plans of `method`.
pub fn plan(
    model: &Model,
    request: &Request,
    method: Method,
) -> Result<Box<dyn TransferFunction>, PlanError> {
    if model.has_viscous()
        && matches!(
            method,
            Method::Modal | Method::Torsion2 | Method::PoleZero | Method::StateSpace
        )
    {
        return Err(PlanError::Unsupported {
            method,
            item: "viscous damping".into(),
            reason: "this method solves only structural damping (the complex stiffness K_c); \
                     `direct`, `block` and `split` solve K_c + i w C - w^2 M with viscous terms"
                .into(),
        });
    }
    if let Some((item, reason)) = refused_for_geometry(model, method) {
        return Err(PlanError::Unsupported {
            method,
            item: item.into(),
            reason: reason.into(),
        });
    }
    if let Some((base, scaled, k)) = model.params().asymmetry.linear_split() {
        let build = |asymmetry| {
            let mut params = model.params().clone();
            params.asymmetry = asymmetry;
            Model::new(&params).map_err(|e| PlanError::Unsupported {
                method,
                item: "the pendulum as built".into(),
                reason: format!(
                    "its keys below 2^-80 are evaluated as a linear response, and the model \
                     with them scaled up by 2^{k} cannot be built: {e}"
                ),
            })
        };
        return Ok(Box::new(Linearized {
            base: plan_exact(&build(base)?, request, method)?,
            scaled: plan_exact(&build(scaled)?, request, method)?,
            k,
        }));
    }
    plan_exact(model, request, method)
}

/// [`plan`] on `model` as it is (no linear response in tiny keys).
fn plan_exact(
    model: &Model,
    request: &Request,
    method: Method,
) -> Result<Box<dyn TransferFunction>, PlanError> {
    Ok(match method {
        Method::Direct => Box::new(Direct::new(model, request.clone())),
        Method::Block => Box::new(BlockReduced::new(model, request.clone())),
        Method::Modal => Box::new(Modal::new(model, request.clone())),
        Method::Split => Box::new(Split::new(model, request.clone())),
        Method::Torsion2 => Box::new(Torsion2::new(model, request.clone())?),
        Method::PoleZero => Box::new(PoleZero::new(model, request.clone())),
        Method::StateSpace => Box::new(StateSpace::new(model, request.clone())),
    })
}

/// Why `method` cannot serve the pendulum as built ([`crate::params::asymmetry`]), if it
/// cannot: `(item, reason)`. Direct, pole-zero, modal and state-space work on whatever `M`,
/// `K_c`, forcing and observation the model has, coupled or not.
fn refused_for_geometry(model: &Model, method: Method) -> Option<(&'static str, &'static str)> {
    match method {
        Method::Block if !model.decoupled() => Some((
            "the coupled model",
            "an offset along x (asymmetry.crossbar_com_x_m, tm_com_x_m or \
             lower_attachment_x_m) couples the swing-y+bounce and swing-x+torsion blocks; \
             `polezero`, `direct`, `modal` and `statespace` solve the coupled 8x8 system",
        )),
        Method::Split if !model.is_symmetric() => Some((
            "the pendulum as built",
            "its exact static part and closed-form translation forcing hold for the symmetric \
             pendulum, whose observables each read one block; with [asymmetry] keys set, \
             `polezero` (or `direct`) has full accuracy",
        )),
        Method::Torsion2 if !model.is_symmetric() => Some((
            "the pendulum as built",
            "the 2-DoF torsional model of section IV.C is derived for the symmetric pendulum \
             read along the lab axes",
        )),
        _ => None,
    }
}

#[cfg(test)]
mod resonance_tests {
    use super::*;
    use crate::modes::NormalModes;
    use crate::params::Params;

    /// Every mode frequency as `NormalModes` gives it (refined to the last bit) is an exact
    /// undamped resonance, which every method of the full model reports as singular; a
    /// frequency one part in 1e9 away is evaluated.
    #[test]
    fn exact_undamped_resonances_are_singular_for_every_method() {
        let model = Model::new(&Params::table_i()).unwrap();
        let modes = NormalModes::new(&model);
        let methods = [
            Method::Direct,
            Method::Block,
            Method::Split,
            Method::PoleZero,
            Method::Modal,
            Method::StateSpace,
        ];
        for mode in &modes.modes {
            let f = mode.frequency_hz;
            for method in methods {
                let tf = plan(&model, &Request::all_tilt(), method).unwrap();
                match tf.eval(f) {
                    Err(TfError::Singular { .. }) => {}
                    other => panic!(
                        "nu_{} = {f:?} Hz, {}: expected singular, got {other:?}",
                        mode.index,
                        method.name()
                    ),
                }
                assert!(
                    tf.eval(f * (1.0 + 1e-9)).is_ok(),
                    "nu_{} + 1e-9, {}",
                    mode.index,
                    method.name()
                );
            }
        }
    }
}
