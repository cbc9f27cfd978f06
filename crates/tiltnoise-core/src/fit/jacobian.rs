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

use super::FitError;
use crate::model::{Mat8, Model};
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
    let model = Model::new(params).map_err(FitError::Params)?;
    let modes = NormalModes::new_f64(&model);
    let freqs: [f64; 8] = std::array::from_fn(|k| modes.modes[k].frequency_hz);
    let mut jac = DMatrix::zeros(8, keys.len());
    for (j, key) in keys.iter().enumerate() {
        let (dm, dk) = matrix_derivatives(params, key)?;
        for (k, mode) in modes.modes.iter().enumerate() {
            let v = &mode.shape;
            let d_omega_sq = (v.transpose() * (dk - dm * mode.omega_sq) * v)[(0, 0)];
            jac[(k, j)] = d_omega_sq / (8.0 * std::f64::consts::PI.powi(2) * freqs[k]);
        }
    }
    Ok((freqs, jac))
}

/// Central differences `(dM/dp, dK/dp)` of the undamped matrices.
fn matrix_derivatives(params: &Params, key: &str) -> Result<(Mat8, Mat8), FitError> {
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
    ))
}
