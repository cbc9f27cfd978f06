//! Mode frequencies and their derivatives with respect to chosen parameters.
//!
//! The derivative of an eigenvalue of the symmetric-definite pencil `(K, M)` with
//! mass-normalized shape `v_k` (`v_k^T M v_k = 1`) is the first-order perturbation result
//! `d(w_k^2)/dp = v_k^T (dK/dp - w_k^2 dM/dp) v_k`, exact for a simple eigenvalue. Each block's
//! eigenvalues are simple for every physical parameter set seen here; the near-degenerate pair
//! nu_3/nu_4 lives in two different blocks, so the formula applies to each separately. Then
//! `df_k/dp = d(w_k^2)/dp / (8 pi^2 f_k)`.
//!
//! `dK/dp` and `dM/dp` are central differences of the assembled matrices with the relative step
//! [`MATRIX_STEP_REL`]. The matrices are polynomial or rational in the parameters; for a central
//! difference the truncation error is `O(h^2 |M'''|)` and the rounding error `O(eps |M| / h)`, so
//! with `h = s |p|` (derivatives scale with `1/|p|`) the total relative error is minimized at
//! `s ~ eps^(1/3) = 6e-6`, where it is `~ eps^(2/3) = 4e-11`. Entries linear in `p` (stiffness
//! in k, kappa; mass in m, I) have no truncation error at all.
//!
//! An `[asymmetry]` offset is 0 at the symmetric pendulum, so its step is absolute:
//! [`MATRIX_STEP_REL`] times the larger of `|p|` and the offset's bound (a tenth of the body it
//! moves in, [`crate::params::Asymmetry::limits`]), the length on which the matrices vary with
//! it. (At exactly 0 the first derivative of a frequency with an offset along x vanishes by the
//! mirror symmetry; the central difference returns that 0 to rounding.)
//!
//! Modes are identified by their label `nu_k` ([`crate::modes`]): the rank (sorted frequency)
//! for the symmetric pendulum, as in Table II; the symmetric mode a mode continues for the
//! pendulum as built.
//! Pure numerics: depends on `params`, `model`, `modes`.

use super::visibility::{model_ratio, MeasuredVisibility};
use super::FitError;
use crate::model::{Mat8, Model, ObservationMatrix};
use crate::modes::NormalModes;
use crate::params::Params;
use nalgebra::DMatrix;

/// Relative step of the central differences of M and K: `eps^(1/3)` (see the module docs).
pub const MATRIX_STEP_REL: f64 = 6.0554544523933395e-6;

/// `params` with `key` set to `value`, validated.
pub fn with_value(params: &Params, key: &str, value: f64) -> Result<Params, FitError> {
    // `{:e}` prints the shortest decimal that reads back as the same f64: the override is exact.
    params
        .with_override(&format!("{key}={value:e}"))
        .map_err(FitError::Params)
}

/// The value of parameter `key` in `params`.
pub fn value_of(params: &Params, key: &str) -> Option<f64> {
    params
        .fields()
        .iter()
        .find(|f| f.key == key)
        .map(|f| f.value)
}

/// Mode frequencies (Hz, by label nu_1 .. nu_8) and `jac[(k, j)] = d f_k / d p_j` (Hz per unit of parameter
/// `keys[j]`) at `params`.
pub fn frequencies_and_jacobian(
    params: &Params,
    keys: &[String],
) -> Result<([f64; 8], DMatrix<f64>), FitError> {
    let e = evaluate(params, keys, &[])?;
    Ok((e.frequencies_hz, e.frequency_jacobian))
}

/// The model's side of a fit at one parameter set.
#[derive(Debug, Clone)]
pub struct ModelEvaluation {
    /// Mode frequencies (Hz), by label nu_1 .. nu_8.
    pub frequencies_hz: [f64; 8],
    /// `d f_k / d p_j` (Hz per unit of parameter `keys[j]`), row `k` for nu_(k+1).
    pub frequency_jacobian: DMatrix<f64>,
    /// The model's value of each visibility, in the order given.
    pub ratios: Vec<f64>,
    /// `d ratio_i / d p_j`.
    pub ratio_jacobian: DMatrix<f64>,
}

/// Mode frequencies, the model's visibilities `visibilities` and their derivatives with
/// respect to the parameters `keys` at `params` (see the module docs: the eigenvalue and shape
/// perturbations with central differences of M, K and the observation matrix C).
///
/// # Errors
///
/// [`FitError::Params`] when a parameter set is not physical; [`FitError::Visibility`] when
/// the model's mode has no component at all in a visibility's reference observable (choose a
/// reference the mode is seen in).
pub fn evaluate(
    params: &Params,
    keys: &[String],
    visibilities: &[MeasuredVisibility],
) -> Result<ModelEvaluation, FitError> {
    let model = Model::new(params).map_err(FitError::Params)?;
    let modes = NormalModes::new_f64(&model);
    let by_label = |label: usize| {
        modes
            .modes
            .iter()
            .find(|m| m.index == label)
            .expect("the labels are a permutation of 1..8")
    };
    let frequencies_hz: [f64; 8] = std::array::from_fn(|k| by_label(k + 1).frequency_hz);
    let derivatives = keys
        .iter()
        .map(|key| matrix_derivatives(params, key))
        .collect::<Result<Vec<_>, _>>()?;
    let mut frequency_jacobian = DMatrix::zeros(8, keys.len());
    for (j, (dm, dk, _)) in derivatives.iter().enumerate() {
        for (k, &f) in frequencies_hz.iter().enumerate() {
            let mode = by_label(k + 1);
            let v = &mode.shape;
            let d_omega_sq = (v.transpose() * (dk - dm * mode.omega_sq) * v)[(0, 0)];
            frequency_jacobian[(k, j)] = d_omega_sq / (8.0 * std::f64::consts::PI.powi(2) * f);
        }
    }
    let mut ratios = Vec::with_capacity(visibilities.len());
    let mut ratio_jacobian = DMatrix::zeros(visibilities.len(), keys.len());
    for (i, v) in visibilities.iter().enumerate() {
        let (ratio, slopes) = model_ratio(&modes, model.observation(), v, &derivatives)
            .ok_or_else(|| FitError::Visibility {
                origin: format!("nu_{} {}/{}", v.mode, v.observable.name(), v.reference.name()),
                message: format!(
                    "the model's nu_{} has no component in the reference {} at {}; measure the                      ratio against an observable that sees the mode",
                    v.mode,
                    v.reference.name(),
                    keys.iter()
                        .map(|k| format!("{k} = {:e}", value_of(params, k).unwrap_or(f64::NAN)))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })?;
        ratios.push(ratio);
        for (j, s) in slopes.into_iter().enumerate() {
            ratio_jacobian[(i, j)] = s;
        }
    }
    Ok(ModelEvaluation {
        frequencies_hz,
        frequency_jacobian,
        ratios,
        ratio_jacobian,
    })
}

/// Central differences `(dM/dp, dK/dp, dC/dp)` of the undamped matrices and the observation
/// matrix.
fn matrix_derivatives(
    params: &Params,
    key: &str,
) -> Result<(Mat8, Mat8, ObservationMatrix), FitError> {
    let p = value_of(params, key).ok_or_else(|| FitError::UnknownKey {
        key: key.to_string(),
        allowed: String::new(),
    })?;
    let scale = if crate::params::uncertainty::is_absolute_key(key) {
        let l = &params.length;
        let limits = params.asymmetry.limits(l.d_m, l.z_a_m, l.z_b_m);
        let limit = limits
            .iter()
            .find(|x| x.key == key)
            .map_or(0.0, |x| x.limit);
        p.abs().max(limit)
    } else {
        p.abs()
    };
    let h = MATRIX_STEP_REL * scale;
    // The step actually taken is the difference of the two representable values.
    let (lo, hi) = (p - h, p + h);
    let minus = Model::new(&with_value(params, key, lo)?).map_err(FitError::Params)?;
    let plus = Model::new(&with_value(params, key, hi)?).map_err(FitError::Params)?;
    let step = hi - lo;
    Ok((
        (plus.mass() - minus.mass()) / step,
        (plus.stiffness() - minus.stiffness()) / step,
        (plus.observation() - minus.observation()) / step,
    ))
}
