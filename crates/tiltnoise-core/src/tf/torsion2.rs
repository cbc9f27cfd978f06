//! The 2-DoF torsional model of section IV.C: the crossbar and test-mass torsion angles
//! `(phi_a, phi_b)` alone, with every swing and bounce coordinate dropped.
//!
//! ```text
//! M = [[I_c + I_t, I_t], [I_t, I_t]],   K = diag(k_a (1 + i phi_ta), k_b (1 + i phi_tb)),
//! I_c = I^a_33 + d y_a (m_a + m_b),     I_t = I^b_33
//! ```
//!
//! (`M` is exactly the phi-phi block of the 8-DoF mass matrix: `m_a y_a^2 + m_b d^2 =
//! d y_a (m_a + m_b)` since `y_a = d m_b / m_a`). Generalized forces are the phi rows of the
//! Appendix A force matrix, `Q_phi_a = -y_a F_a.x + d F_b.x + M_a.z + M_b.z`,
//! `Q_phi_b = M_b.z`: section IV.C writes `Q_phi_a` without the `-y_a F_a.x` term (it only
//! lists `F_b`), which is kept here for consistency with Appendix A. Observables are
//! `X = d phi_a` (the paper's X_GRS), `phi = phi_a + phi_b` and `phi_a`.
//!
//! The floor's rotation about the vertical, `phi_t`, is a rigid rotation of the enclosure about
//! the upper fibre and is represented exactly: `G(w) = -w^2 M e_phi_a` with this model's own `M`
//! (the phi rows of the full model's `G2`). Tilt about a horizontal axis (theta_t, eta_t) acts
//! through the swing coordinates, which this model does not have, and is refused at plan time,
//! as are the floor's translations (their apparent forces exert no torque on the balanced
//! crossbar), forces without a torsion component and the outputs Y, Z, theta, eta.
//!
//! Its transfer functions differ from the 8-DoF model's by the neglected mass coupling of the
//! torsion angles to the swing (`I_a4` on eta_a, `-m_b d Z_b` on eta_b): every neglected term
//! carries `w^2 M_pe (K_ee - w^2 M_ee)^-1`, a relative error of order `(f / f_swing)^2` times a
//! geometric factor, with f_swing = 0.416 Hz the lowest swing mode of the block. For Table I
//! (away from 1 % of the torsion modes and of the entries' zeros) it is at most
//! 1.8 (f / f_swing)^2 for the torques M_a.z, M_b.z (that is 2e-5 at nu_1 and 5e-5 at nu_2;
//! measured 7e-5 at 5 mHz), 3.9 (f / f_swing)^2 for phi_t, and 38 (f / f_swing)^2 for the
//! forces F_a.x, F_b.x, whose swing response X also reads directly (measured 9e-4 at 5 mHz). `tests/it/methods.rs` derives
//! the first-order coupling error and checks the difference against it.

use super::direct::{omega_sq, EquilibratedLu};
use super::{Input, Method, PlanError, Request, TransferFunction};
use crate::error::TfError;
use crate::model::{Coord, Model, TiltAxis};
use nalgebra::{Matrix2, RowVector2, Vector2};
use num_complex::Complex64;

/// The two coordinates of the model.
const COORDS: [Coord; 2] = [Coord::PhiA, Coord::PhiB];

/// Plan of the 2-DoF torsional model.
pub struct Torsion2 {
    request: Request,
    stiffness: Matrix2<Complex64>,
    mass: Matrix2<f64>,
    /// Per input: generalized forces independent of frequency and per unit w^2.
    forcing: Vec<(Vector2<f64>, Vector2<f64>)>,
    /// Per output: the observation row on (phi_a, phi_b).
    observe: Vec<RowVector2<f64>>,
}

impl Torsion2 {
    /// Builds the 2-DoF model; fails for an input or output it cannot represent.
    pub fn new(model: &Model, request: Request) -> Result<Torsion2, PlanError> {
        let p = model.params();
        let (d, y_a) = (p.length.d_m, model.derived().y_a_m);
        let i_c = p.inertia.a33_kg_m2 + d * y_a * (p.mass.m_a_kg + p.mass.m_b_kg);
        let i_t = p.inertia.b33_kg_m2;
        let mass = Matrix2::new(i_c + i_t, i_t, i_t, i_t);
        let k = model.stiffness_complex();
        let stiffness = Matrix2::from_fn(|r, c| {
            if r == c {
                k[(COORDS[r].index(), COORDS[r].index())]
            } else {
                Complex64::new(0.0, 0.0)
            }
        });
        let unsupported = |item: String, reason: String| PlanError::Unsupported {
            method: Method::Torsion2,
            item,
            reason,
        };
        let forcing = request
            .inputs
            .iter()
            .map(|&input| match input {
                Input::Tilt(TiltAxis::PhiT) => Ok((Vector2::zeros(), -mass.column(0))),
                Input::Tilt(axis) => Err(unsupported(
                    format!("input {}", axis.name()),
                    "the 2-DoF torsional model (section IV.C) has no eta or theta coordinates, \
                     only phi_a and phi_b, and tilt about a horizontal axis acts through the \
                     swing angles (eta_a, eta_b for eta_t; theta_a, theta_b for theta_t) by the \
                     gravity correction and the suspension point's acceleration; use `split` or \
                     `direct`"
                        .into(),
                )),
                Input::Translation(axis) => Err(unsupported(
                    format!("input {}", axis.name()),
                    "a floor translation turns neither fibre: its apparent forces act at the \
                     centres of mass, and the crossbar is balanced on the upper fibre \
                     (m_a y_a = m_b d), so it drives the 8-DoF model only through the swing and \
                     bounce coordinates (and their mass coupling to torsion), which the 2-DoF \
                     torsional model does not have; use `split` or `polezero`"
                        .into(),
                )),
                Input::Force(f) => {
                    let q = Vector2::from_fn(|r, _| {
                        model.force_matrix()[(COORDS[r].index(), f.index())]
                    });
                    if q.iter().all(|&v| v == 0.0) {
                        Err(unsupported(
                            format!("input {}", f.name()),
                            "it has no torsion component (Appendix A: Q_phi_a = -y_a F_a.x + \
                             d F_b.x + M_a.z + M_b.z, Q_phi_b = M_b.z); the 2-DoF torsional model \
                             accepts F_a.x, F_b.x, M_a.z, M_b.z and phi_t"
                                .into(),
                        ))
                    } else {
                        Ok((q, Vector2::zeros()))
                    }
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        let observe = request
            .outputs
            .iter()
            .map(|&o| {
                let c =
                    RowVector2::from_fn(|_, k| model.observation()[(o.index(), COORDS[k].index())]);
                if c.iter().all(|&v| v == 0.0) {
                    Err(unsupported(
                        format!("output {}", o.name()),
                        "it does not depend on the torsion angles phi_a, phi_b, the only \
                         coordinates of the 2-DoF torsional model; it accepts X (= d phi_a), \
                         phi and phi_a"
                            .into(),
                    ))
                } else {
                    Ok(c)
                }
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Torsion2 {
            request,
            stiffness,
            mass,
            forcing,
            observe,
        })
    }
}

impl TransferFunction for Torsion2 {
    fn method(&self) -> Method {
        Method::Torsion2
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        let w2 = omega_sq(freq_hz)?;
        let lu = EquilibratedLu::factor(&self.stiffness, &self.mass, w2, freq_hz)?;
        let n_in = self.forcing.len();
        for (i, (g0, g2)) in self.forcing.iter().enumerate() {
            let mut y = Vector2::from_fn(|r, _| Complex64::from(g0[r] + w2 * g2[r]));
            lu.solve_mut(&mut y)?;
            for (o, c) in self.observe.iter().enumerate() {
                out[o * n_in + i] = y[0] * c[0] + y[1] * c[1];
            }
        }
        Ok(())
    }
}
