//! The modal method: superposition of the undamped normal modes,
//!
//! ```text
//! H(w) = sum_k (C v_k) (v_k^T G(w)) / (lambda_k (1 + i phi_k) - w^2)
//! ```
//!
//! with the mass-normalized shapes `v_k` and eigenvalues `lambda_k` of [`NormalModes`] (computed
//! per block, so a mode's shape is exactly zero on the other block and entries across blocks are
//! exactly 0.0, as in the direct method), `G(w) = G0 + w^2 G2` for tilt and the force-matrix
//! column for forces. The eigenvalues are the eigensolver's, not refined
//! ([`crate::modes::refined_omega_sq`]): a refined `lambda_k` paired with the unrefined shape
//! breaks the consistency `V Lambda^-1 V^T = K^-1` the sum relies on, and measured errors get
//! worse, not better (near nu_1 and at low frequency). A comparison method, kept honest:
//!
//! * **Damping is approximate.** The loss enters as modal loss angles
//!   `phi_k = v_k^T Im(K_c) v_k / lambda_k`, neglecting the off-diagonal terms
//!   `v_j^T Im(K_c) v_k` by which structural damping couples the modes
//!   ([`super::Method::exact_for_damping`] is false). Exact when the model is undamped.
//! * **No relative accuracy where the modal terms cancel.** Each term carries the eigensolver's
//!   error (of order `eps ||L^-1 K L^-T|| / gap` in the shapes, 3e-11 for the torsion modes of
//!   Table I; `eps ||L^-1 K L^-T||` absolute in the eigenvalues, 5e-11 relative for those
//!   modes, 7e-10 of the response 1 % from nu_1). Where the sum is much smaller than its terms,
//!   or a term's projection `v_k^T (G0 + w^2 G2)` is itself a cancellation (eta_t on the
//!   torsion modes), the error is that of the parts. phi/eta_t and phi_a/eta_t fall as f^4 at
//!   low frequency because the gravity and inertia terms cancel exactly; the modal sum levels
//!   off at a floor of eigensolver error instead (about 2e-12 at f = 0, where the exact value is
//!   0: the torsion modes' tiny swing components times the large gravity forcing), so
//!   their relative error grows as f^-4 (about 1e2 at 1e-5 Hz for Table I). With loss angles
//!   the neglected damping coupling is worse still: phi_a/eta_t comes out as 5e-4 at f = 0 with
//!   loss angles of 1e-3. Measured in `tests/it/methods.rs`.
//!
//! Per frequency: a singularity check on the modal dynamic stiffness (equilibrated like the
//! direct method's, `d_k = (lambda_k (1 + i phi_k) - w^2) / (|lambda_k (1 + i phi_k)| + w^2)`)
//! and one pass over the modes, with no allocation.

use super::direct::{forcing_columns, omega_sq};
use super::{Method, Request, TransferFunction, SINGULAR_RCOND};
use crate::error::TfError;
use crate::model::Model;
use crate::modes::NormalModes;
use num_complex::Complex64;

/// Plan of the modal method.
pub struct Modal {
    request: Request,
    terms: Vec<ModalTerm>,
}

/// One mode's share of the request.
struct ModalTerm {
    /// `lambda_k (1 + i phi_k)` (rad^2/s^2).
    eigenvalue: Complex64,
    /// `C v_k` per output.
    observe: Vec<f64>,
    /// `v_k^T G0` per input.
    force0: Vec<f64>,
    /// `v_k^T G2` per input.
    force2: Vec<f64>,
}

impl Modal {
    /// Solves the eigenproblem once and projects the request on the modes; modes the request
    /// neither drives nor observes are dropped.
    pub fn new(model: &Model, request: Request) -> Modal {
        let (forcing0, forcing2) = forcing_columns(model, &request.inputs);
        let loss = model.stiffness_complex().map(|z| z.im);
        let terms = NormalModes::new(model)
            .modes
            .iter()
            .map(|mode| {
                let v = &mode.shape;
                let project = |g: &nalgebra::DMatrix<f64>| -> Vec<f64> {
                    (0..request.inputs.len())
                        .map(|i| (0..8).map(|r| v[r] * g[(r, i)]).sum())
                        .collect()
                };
                ModalTerm {
                    eigenvalue: Complex64::new(mode.omega_sq, (v.transpose() * loss * v)[(0, 0)]),
                    observe: request
                        .outputs
                        .iter()
                        .map(|o| mode.observable_amplitude[o.index()])
                        .collect(),
                    force0: project(&forcing0),
                    force2: project(&forcing2),
                }
            })
            .filter(|t| {
                t.observe.iter().any(|&c| c != 0.0)
                    && t.force0.iter().chain(&t.force2).any(|&g| g != 0.0)
            })
            .collect();
        Modal { request, terms }
    }
}

impl TransferFunction for Modal {
    fn method(&self) -> Method {
        Method::Modal
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        let w2 = omega_sq(freq_hz)?;
        let (lo, hi) = self
            .terms
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), t| {
                let d = (t.eigenvalue - w2).norm() / (t.eigenvalue.norm() + w2);
                (lo.min(d), hi.max(d))
            });
        let rcond = lo / hi;
        if !self.terms.is_empty() && (rcond.is_nan() || rcond < SINGULAR_RCOND) {
            return Err(TfError::Singular { freq_hz, rcond });
        }
        let n_in = self.request.inputs.len();
        out.fill(Complex64::new(0.0, 0.0));
        for t in &self.terms {
            let response = 1.0 / (t.eigenvalue - w2);
            for (o, &c) in t.observe.iter().enumerate() {
                for i in 0..n_in {
                    out[o * n_in + i] += c * (t.force0[i] + w2 * t.force2[i]) * response;
                }
            }
        }
        Ok(())
    }
}
