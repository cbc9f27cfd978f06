//! The direct method: a complex LU of the full 8x8 dynamic stiffness at every frequency.
//!
//! The matrix mixes units (kg m^2 next to kg, N m/rad next to N/m) and its entries span ten
//! decades, so it is symmetrically equilibrated first: with `s_i = (|K_ii| + w^2 M_ii)^-1/2`,
//! `D_s = S D S` has entries of order one and its condition number measures how close `w` is to a
//! resonance rather than the choice of units. After the solve the reciprocal 1-norm condition
//! number of `D_s` is computed from its explicit inverse (cheap for 8x8); below
//! [`SINGULAR_RCOND`] fewer than three digits are guaranteed and the result is reported as singular.
//! [`EquilibratedLu`] is that factorization for any small dimension; the block-reduced, split and
//! 2-DoF methods use it on their 4x4 and 2x2 systems.
//!
//! Exact zeros are preserved: the model is block diagonal (see [`crate::model::Block`]), and
//! Gaussian elimination never fills in across blocks (multipliers are exactly 0), so entries such
//! as X/theta_t come out as exactly 0.0.

use super::{Input, Method, Request, TransferFunction};
use crate::error::{FreqError, TfError};
use crate::model::{CMat8, Mat8, Model};
use crate::units::angular;
use nalgebra::{Const, DMatrix, DimMin, SMatrix, SVector};
use num_complex::Complex64;

/// Below this reciprocal condition number of the equilibrated dynamic stiffness the LU's
/// forward error bound `n eps cond` (n = 8 unknowns) exceeds 1e-3, so fewer than three digits
/// of the result would be guaranteed: the frequency is on an undamped resonance to working
/// precision (relative detuning of order 1e-12 or less) and the result is reported as singular.
/// The same threshold is used for the smaller systems of the other methods, where it is
/// slightly conservative (their bound `n eps cond` has n = 4 or 2).
pub const SINGULAR_RCOND: f64 = 1e3 * 8.0 * f64::EPSILON;

/// Checks that `freq_hz` can be evaluated and returns `w^2` (rad^2/s^2).
pub(crate) fn omega_sq(freq_hz: f64) -> Result<f64, TfError> {
    if !(freq_hz.is_finite() && freq_hz >= 0.0) {
        return Err(FreqError::Invalid {
            value: freq_hz,
            origin: "transfer-function evaluation".into(),
        }
        .into());
    }
    Ok(angular(freq_hz).powi(2))
}

/// LU factorization of the symmetrically equilibrated dynamic stiffness `K_c - w^2 M` (N x N),
/// with the singularity check of the module docs. Solves take and return unscaled vectors.
/// With viscous damping pass `K_c + i w C` as the stiffness.
pub(crate) struct EquilibratedLu<const N: usize>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    lu: nalgebra::LU<Complex64, Const<N>, Const<N>>,
    scale: [f64; N],
    freq_hz: f64,
}

impl<const N: usize> EquilibratedLu<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    /// Factors `stiffness - w2 mass`; fails with [`TfError::Singular`] when the equilibrated
    /// matrix has a reciprocal condition number below [`SINGULAR_RCOND`] (or NaN).
    pub(crate) fn factor(
        stiffness: &SMatrix<Complex64, N, N>,
        mass: &SMatrix<f64, N, N>,
        w2: f64,
        freq_hz: f64,
    ) -> Result<Self, TfError> {
        let scale: [f64; N] =
            std::array::from_fn(|i| 1.0 / (stiffness[(i, i)].norm() + w2 * mass[(i, i)]).sqrt());
        let d_s = SMatrix::<Complex64, N, N>::from_fn(|r, c| {
            (stiffness[(r, c)] - Complex64::from(w2 * mass[(r, c)])) * (scale[r] * scale[c])
        });
        let singular = |rcond: f64| TfError::Singular { freq_hz, rcond };
        let lu = d_s.lu();
        let inverse = lu.try_inverse().ok_or_else(|| singular(0.0))?;
        let rcond = 1.0 / (one_norm(&d_s) * one_norm(&inverse));
        // A NaN rcond (non-finite entries) is singular too.
        if rcond.is_nan() || rcond < SINGULAR_RCOND {
            return Err(singular(rcond));
        }
        Ok(EquilibratedLu { lu, scale, freq_hz })
    }

    /// Overwrites `x` (a generalized force) with `(K_c - w^2 M)^-1 x`.
    pub(crate) fn solve_mut(&self, x: &mut SVector<Complex64, N>) -> Result<(), TfError> {
        for (v, s) in x.iter_mut().zip(self.scale) {
            *v *= s;
        }
        if !self.lu.solve_mut(x) {
            return Err(TfError::Singular {
                freq_hz: self.freq_hz,
                rcond: 0.0,
            });
        }
        for (v, s) in x.iter_mut().zip(self.scale) {
            *v *= s;
        }
        Ok(())
    }
}

/// `K_c + i w C` for a viscous damping matrix `C` and angular frequency `w` (rad/s).
pub(crate) fn with_viscous<const N: usize>(
    stiffness: &SMatrix<Complex64, N, N>,
    damping: &SMatrix<f64, N, N>,
    omega: f64,
) -> SMatrix<Complex64, N, N> {
    SMatrix::<Complex64, N, N>::from_fn(|r, c| {
        stiffness[(r, c)] + Complex64::new(0.0, omega * damping[(r, c)])
    })
}

fn one_norm<const N: usize>(m: &SMatrix<Complex64, N, N>) -> f64 {
    (0..N)
        .map(|c| m.column(c).iter().map(|z| z.norm()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Plan of the direct method.
pub struct Direct {
    request: Request,
    stiffness: CMat8,
    /// Viscous damping matrix C (zero when there is none).
    damping: Mat8,
    viscous: bool,
    mass: Mat8,
    /// Forcing independent of frequency (8 x inputs).
    forcing0: DMatrix<f64>,
    /// Forcing per unit w^2 (8 x inputs).
    forcing2: DMatrix<f64>,
    /// Observation rows (outputs x 8).
    observe: DMatrix<f64>,
}

/// The `8 x inputs` forcing matrices `(G0, G2)` of a request: tilt columns from
/// [`Model::tilt_forcing`], translation columns (`G0 = 0`) from [`Model::translation_forcing`],
/// force columns (frequency independent) from [`Model::force_matrix`].
pub(super) fn forcing_columns(model: &Model, inputs: &[Input]) -> (DMatrix<f64>, DMatrix<f64>) {
    let mut forcing0 = DMatrix::zeros(8, inputs.len());
    let mut forcing2 = DMatrix::zeros(8, inputs.len());
    let tilt = model.tilt_forcing();
    for (col, input) in inputs.iter().enumerate() {
        match input {
            Input::Tilt(axis) => {
                forcing0.set_column(col, &tilt.g0.column(axis.index()));
                forcing2.set_column(col, &tilt.g2.column(axis.index()));
            }
            Input::Translation(axis) => {
                forcing2.set_column(col, &model.translation_forcing().g2.column(axis.index()));
            }
            Input::Force(f) => {
                forcing0.set_column(col, &model.force_matrix().column(f.index()));
            }
        }
    }
    (forcing0, forcing2)
}

impl Direct {
    /// Prepares the matrices of `request` for `model`.
    pub fn new(model: &Model, request: Request) -> Direct {
        let (forcing0, forcing2) = forcing_columns(model, &request.inputs);
        let observe = DMatrix::from_fn(request.outputs.len(), 8, |r, c| {
            model.observation()[(request.outputs[r].index(), c)]
        });
        Direct {
            stiffness: model.stiffness_complex(),
            damping: *model.damping(),
            viscous: model.has_viscous(),
            mass: *model.mass(),
            forcing0,
            forcing2,
            observe,
            request,
        }
    }
}

impl Direct {
    /// The equilibrated LU of `D = K_c + i w C - w^2 M` at `freq_hz`, and `w^2`.
    fn factor(&self, freq_hz: f64) -> Result<(EquilibratedLu<8>, f64), TfError> {
        let w2 = omega_sq(freq_hz)?;
        let lu = if self.viscous {
            let k = with_viscous(&self.stiffness, &self.damping, w2.sqrt());
            EquilibratedLu::factor(&k, &self.mass, w2, freq_hz)?
        } else {
            EquilibratedLu::factor(&self.stiffness, &self.mass, w2, freq_hz)?
        };
        Ok((lu, w2))
    }

    /// Responses `x = D^-1 v` of the coordinates to generalized forces `v` (one per entry of
    /// `forces`, overwritten by its response), `D = K_c + i w C - w^2 M`, with the
    /// equilibration and singularity check of [`Direct`]. Units: coordinate per unit
    /// generalized force. The thermal-noise module solves `D y = c` with observation rows.
    pub fn solve_generalized(
        &self,
        freq_hz: f64,
        forces: &mut [SVector<Complex64, 8>],
    ) -> Result<(), TfError> {
        let (lu, _) = self.factor(freq_hz)?;
        for x in forces.iter_mut() {
            lu.solve_mut(x)?;
        }
        Ok(())
    }
}

impl TransferFunction for Direct {
    fn method(&self) -> Method {
        Method::Direct
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        let (lu, w2) = self.factor(freq_hz)?;
        let n_in = self.request.inputs.len();
        for i in 0..n_in {
            let mut y = SVector::<Complex64, 8>::from_fn(|r, _| {
                Complex64::from(self.forcing0[(r, i)] + w2 * self.forcing2[(r, i)])
            });
            lu.solve_mut(&mut y)?;
            for o in 0..self.request.outputs.len() {
                out[o * n_in + i] = (0..8).map(|k| y[k] * self.observe[(o, k)]).sum();
            }
        }
        Ok(())
    }
}
