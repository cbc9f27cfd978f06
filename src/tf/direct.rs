//! The direct method: a complex LU of the full 8x8 dynamic stiffness at every frequency.
//!
//! The matrix mixes units (kg m^2 next to kg, N m/rad next to N/m) and its entries span ten
//! decades, so it is symmetrically equilibrated first: with `s_i = (|K_ii| + w^2 M_ii)^-1/2`,
//! `D_s = S D S` has entries of order one and its condition number measures how close `w` is to a
//! resonance rather than the choice of units. After the solve the reciprocal 1-norm condition
//! number of `D_s` is computed from its explicit inverse (cheap for 8x8); below
//! [`SINGULAR_RCOND`] fewer than three digits are guaranteed and the result is reported as singular.
//!
//! Exact zeros are preserved: the model is block diagonal (see [`crate::model::Block`]), and
//! Gaussian elimination never fills in across blocks (multipliers are exactly 0), so entries such
//! as X/theta_t come out as exactly 0.0.

use super::{Input, Method, Request, TransferFunction};
use crate::error::{FreqError, TfError};
use crate::model::{CMat8, Mat8, Model};
use crate::units::angular;
use nalgebra::{DMatrix, SMatrix};
use num_complex::Complex64;

/// Below this reciprocal condition number of the equilibrated dynamic stiffness the LU's
/// forward error bound `n eps cond` (n = 8 unknowns) exceeds 1e-3, so fewer than three digits
/// of the result would be guaranteed: the frequency is on an undamped resonance to working
/// precision (relative detuning of order 1e-12 or less) and the result is reported as singular.
pub const SINGULAR_RCOND: f64 = 1e3 * 8.0 * f64::EPSILON;

/// Plan of the direct method.
pub struct Direct {
    request: Request,
    stiffness: CMat8,
    mass: Mat8,
    /// Forcing independent of frequency (8 x inputs).
    forcing0: DMatrix<f64>,
    /// Forcing per unit w^2 (8 x inputs).
    forcing2: DMatrix<f64>,
    /// Observation rows (outputs x 8).
    observe: DMatrix<f64>,
}

impl Direct {
    /// Prepares the matrices of `request` for `model`.
    pub fn new(model: &Model, request: Request) -> Direct {
        let n_in = request.inputs.len();
        let mut forcing0 = DMatrix::zeros(8, n_in);
        let mut forcing2 = DMatrix::zeros(8, n_in);
        let tilt = model.tilt_forcing();
        for (col, input) in request.inputs.iter().enumerate() {
            match input {
                Input::Tilt(axis) => {
                    forcing0.set_column(col, &tilt.g0.column(axis.index()));
                    forcing2.set_column(col, &tilt.g2.column(axis.index()));
                }
                Input::Force(f) => {
                    forcing0.set_column(col, &model.force_matrix().column(f.index()));
                }
            }
        }
        let observe = DMatrix::from_fn(request.outputs.len(), 8, |r, c| {
            model.observation()[(request.outputs[r].index(), c)]
        });
        Direct {
            stiffness: model.stiffness_complex(),
            mass: *model.mass(),
            forcing0,
            forcing2,
            observe,
            request,
        }
    }
}

fn one_norm(m: &CMat8) -> f64 {
    (0..8)
        .map(|c| m.column(c).iter().map(|z| z.norm()).sum::<f64>())
        .fold(0.0, f64::max)
}

impl TransferFunction for Direct {
    fn method(&self) -> Method {
        Method::Direct
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        if !(freq_hz.is_finite() && freq_hz >= 0.0) {
            return Err(FreqError::Invalid {
                value: freq_hz,
                origin: "transfer-function evaluation".into(),
            }
            .into());
        }
        let w2 = angular(freq_hz).powi(2);
        let scale: [f64; 8] = std::array::from_fn(|i| {
            1.0 / (self.stiffness[(i, i)].norm() + w2 * self.mass[(i, i)]).sqrt()
        });
        let d_s = CMat8::from_fn(|r, c| {
            (self.stiffness[(r, c)] - Complex64::from(w2 * self.mass[(r, c)]))
                * (scale[r] * scale[c])
        });
        let n_in = self.request.inputs.len();
        let singular = |rcond: f64| TfError::Singular { freq_hz, rcond };
        let lu = d_s.lu();
        let inverse = lu.try_inverse().ok_or_else(|| singular(0.0))?;
        let rcond = 1.0 / (one_norm(&d_s) * one_norm(&inverse));
        // A NaN rcond (non-finite entries) is singular too.
        if rcond.is_nan() || rcond < SINGULAR_RCOND {
            return Err(singular(rcond));
        }
        let forcing = DMatrix::from_fn(8, n_in, |r, c| {
            Complex64::from((self.forcing0[(r, c)] + w2 * self.forcing2[(r, c)]) * scale[r])
        });
        let mut y = forcing;
        for c in 0..n_in {
            let mut col = SMatrix::<Complex64, 8, 1>::from_fn(|r, _| y[(r, c)]);
            if !lu.solve_mut(&mut col) {
                return Err(singular(0.0));
            }
            for r in 0..8 {
                y[(r, c)] = col[r] * scale[r];
            }
        }
        let n_out = self.request.outputs.len();
        for o in 0..n_out {
            for i in 0..n_in {
                out[o * n_in + i] = (0..8).map(|k| y[(k, i)] * self.observe[(o, k)]).sum();
            }
        }
        Ok(())
    }
}
