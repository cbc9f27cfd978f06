//! The state-space method, for comparison: the first-order form in which python-control and
//! scipy.signal evaluate a mechanical model, evaluated the way they do.
//!
//! The second-order model `(K_c - w^2 M) q = (G0 + w^2 G2) u` has a forcing that grows with
//! `w^2` (the suspension point's acceleration), which a proper state-space model cannot carry in
//! `B`; it is split off with `w^2 G2 = -(K_c - w^2 M) M^-1 G2 + K_c M^-1 G2`:
//!
//! ```text
//! q = (K_c - w^2 M)^-1 B0 u - M^-1 G2 u,   B0 = G0 + K_c M^-1 G2,
//! x = (q, q'),   A = [[0, I], [-M^-1 K_c, 0]],   B = [[0], [M^-1 B0]],
//! H(w) = [C, 0] (i w I - A)^-1 B + D,   D = -C M^-1 G2,
//! ```
//!
//! (force inputs: `G2 = 0`, `B0` the force columns, `D = 0`). As a NumPy user would build it:
//! `M^-1` applied by an LU of `M` in `f64`, and at every frequency an LU with partial pivoting
//! of the 16x16 complex `i w I - A`, no equilibration. One addition of ours, which the Python
//! tools do not make: the singularity check of every other method (the equilibrated 8x8
//! `K_c - w^2 M`, whose determinant vanishes exactly where that of `i w I - A` does; see
//! [`super::direct`]), so that an exact resonance gives an error rather than a large wrong
//! number. The state-space solve itself is not checked: near a resonance it returns what the
//! Python tools return. Structural loss angles enter through the complex
//! `K_c` (exact, as in the direct method); viscous damping is refused (its tilt forcing has a
//! `w C M^-1 G2` term that this form does not carry).
//!
//! What the form costs (measured against the double-double reference in `tests/it/methods.rs`
//! and by `tiltnoise methods`):
//!
//! * `B0 = G0 + K_c M^-1 G2` and `H = [C, 0] X + D` are sums of large terms of opposite signs.
//!   phi/eta_t and phi_a/eta_t fall as f^4 at low frequency because the gravity and inertia
//!   parts of the tilt forcing cancel exactly; here they cancel in rounded `f64` arithmetic, so
//!   those entries keep an absolute floor of rounding error and their relative error grows as
//!   f^-4 below the torsion modes.
//! * `i w I - A` mixes `w` with `M^-1 K` (eigenvalues from 1e-4 to 4e3 rad^2/s^2 for Table I) in
//!   unequilibrated form: its condition number, not just the distance to a resonance, sets
//!   the LU's error.

use super::direct::{forcing_columns, omega_sq, EquilibratedLu};
use super::{Method, Request, TransferFunction};
use crate::error::TfError;
use crate::model::{CMat8, Mat8, Model};
use nalgebra::{DMatrix, SMatrix};
use num_complex::Complex64;

/// States: the 8 coordinates and their velocities.
const N: usize = 16;

/// Plan of the state-space method.
pub struct StateSpace {
    request: Request,
    /// `A` (16 x 16).
    a: SMatrix<Complex64, N, N>,
    /// `B` (16 x inputs).
    b: DMatrix<Complex64>,
    /// `C` on the coordinates (outputs x 8); zero on the velocities.
    c: DMatrix<f64>,
    /// `D = -C M^-1 G2` (outputs x inputs).
    d: DMatrix<f64>,
    /// `K_c` and `M`, for the singularity check.
    stiffness: CMat8,
    mass: Mat8,
}

impl StateSpace {
    /// Forms `A`, `B`, `C`, `D` of `request` for `model` in `f64`. The caller refuses viscous
    /// damping ([`super::plan`]).
    pub fn new(model: &Model, request: Request) -> StateSpace {
        let (g0, g2) = forcing_columns(model, &request.inputs);
        let mass_lu = model.mass().lu();
        let k_c = model.stiffness_complex();
        // M^-1 X for a real X, as `numpy.linalg.solve(M, X)`.
        let m_inv = |x: &DMatrix<f64>| -> DMatrix<f64> {
            let mut y = x.clone();
            for mut col in y.column_iter_mut() {
                let mut v = nalgebra::SVector::<f64, 8>::from_column_slice(col.as_slice());
                assert!(mass_lu.solve_mut(&mut v), "M is positive definite");
                col.copy_from_slice(v.as_slice());
            }
            y
        };
        let m_inv_g2 = m_inv(&g2);
        let k_re = DMatrix::from_fn(8, 8, |r, c| k_c[(r, c)].re);
        let k_im = DMatrix::from_fn(8, 8, |r, c| k_c[(r, c)].im);
        // B0 = G0 + K_c M^-1 G2, then M^-1 B0 (real and imaginary parts separately).
        let b0_re = &g0 + &k_re * &m_inv_g2;
        let b0_im = &k_im * &m_inv_g2;
        let (mb_re, mb_im) = (m_inv(&b0_re), m_inv(&b0_im));
        let mk_re = m_inv(&k_re);
        let mk_im = m_inv(&k_im);
        let n_in = request.inputs.len();
        let mut a = SMatrix::<Complex64, N, N>::zeros();
        let mut b = DMatrix::<Complex64>::zeros(N, n_in);
        for r in 0..8 {
            a[(r, 8 + r)] = Complex64::new(1.0, 0.0);
            for c in 0..8 {
                a[(8 + r, c)] = -Complex64::new(mk_re[(r, c)], mk_im[(r, c)]);
            }
            for i in 0..n_in {
                b[(8 + r, i)] = Complex64::new(mb_re[(r, i)], mb_im[(r, i)]);
            }
        }
        let c = DMatrix::from_fn(request.outputs.len(), 8, |r, c| {
            model.observation()[(request.outputs[r].index(), c)]
        });
        let d = -(&c * &m_inv_g2);
        StateSpace {
            request,
            a,
            b,
            c,
            d,
            stiffness: k_c,
            mass: *model.mass(),
        }
    }
}

impl TransferFunction for StateSpace {
    fn method(&self) -> Method {
        Method::StateSpace
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        let w2 = omega_sq(freq_hz)?;
        EquilibratedLu::factor(&self.stiffness, &self.mass, w2, freq_hz)?;
        let singular = TfError::Singular {
            freq_hz,
            rcond: 0.0,
        };
        let mut s_minus_a = -self.a;
        for k in 0..N {
            s_minus_a[(k, k)] += Complex64::new(0.0, w2.sqrt());
        }
        let lu = s_minus_a.lu();
        let n_in = self.request.inputs.len();
        for i in 0..n_in {
            let mut x = nalgebra::SVector::<Complex64, N>::from_fn(|r, _| self.b[(r, i)]);
            if !lu.solve_mut(&mut x) {
                return Err(singular);
            }
            for o in 0..self.request.outputs.len() {
                let h: Complex64 =
                    (0..8).map(|k| x[k] * self.c[(o, k)]).sum::<Complex64>() + self.d[(o, i)];
                if !(h.re.is_finite() && h.im.is_finite()) {
                    return Err(singular);
                }
                out[o * n_in + i] = h;
            }
        }
        Ok(())
    }
}
