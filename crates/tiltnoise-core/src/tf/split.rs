//! The split method: tilt transfer functions with full relative accuracy.
//!
//! # Why the direct LU is not enough
//!
//! phi/eta_t and phi_a/eta_t fall as f^4 below the torsion modes: in `G0 + w^2 G2` the gravity
//! correction and the apparent forces cancel to leave a pure translation of the suspension point,
//! which does not turn the pendulum about z. A direct solve of `(K_c - w^2 M) q = G0 + w^2 G2`
//! computes that cancellation in floating point: the eta components of the solution are O(1),
//! its phi components O(w^4), and the rounding that leaks into phi is O(w^2) (the phi rows of
//! `w^2 G2` are O(w^2)), so the relative error grows as f^-2 below the torsion modes (2e-7 at
//! 1e-5 Hz for Table I). At high frequency eta/phi_t and phi/eta_t fall as f^-2 after a
//! cancellation of O(1) terms, and the error grows as f^2 (1e-6 at 100 Hz).
//!
//! # The split (tilt theta_t, eta_t)
//!
//! `G0 = K_gravity S`, where `S` puts theta_t on theta_a and eta_t on eta_a, and `K_c S =
//! K_gravity S` because the elastic entries sit on phi and delta only. Hence, exactly,
//!
//! ```text
//! H = C S + w^2 C D^-1 R,     D = K_c - w^2 M,   R = G2 + M S,
//! ```
//!
//! and `R` is the generalized force of a pure translation of the upper suspension point by
//! `h` per radian: `R[:, theta_t] = h (c1 e_theta_a + m_b Z_b e_theta_b)` and likewise for eta_t,
//! `c1 = m_b (Z + Z_b) + m_a (Z + Z_a)`, i.e. `R = (h / g) K_gravity S`. It is built here in
//! closed form, so its phi and delta rows are exactly zero, whereas `G2 + M S` evaluated from
//! the library matrices leaves rounding there in general (Table I's numbers happen to round to
//! an exact 0; with m_a = 1.3 kg the phi_a row is -3.5e-18; `tests/it/methods.rs` checks that the
//! two agree to rounding). With exact zeros in `R` and no coupling of phi to eta in `K_c`, the
//! f^4 of phi/eta_t comes out of the solve with relative accuracy: its phi components are
//! driven only through the O(w^2) mass coupling. Above the block's modes the mass-line split
//!
//! ```text
//! w^2 D^-1 R = -M^-1 R + D^-1 (K_c M^-1 R)            (exact: D^-1 (K_c - D) M^-1 R = w^2 D^-1 R)
//! ```
//!
//! is used instead, evaluated in **absolute test-mass angles** `u = T q`
//! (`psi_b = phi_a + phi_b`, `eta_b,abs = eta_a + eta_b`, `theta_b,abs = theta_a + theta_b`;
//! crossbar angles and both elongations unchanged). In these coordinates the test mass's
//! rotation about z has the mass-matrix row `I^b_33 e_psi` only and `R_psi = 0`, so
//! `(M^-1 R)_psi` is exactly 0 and the f^-2 of phi/eta_t is what remains,
//! `(D^-1 K_c M^-1 R)_psi`. `M_u = T^-T M T^-1`, `K_u = T^-T K_c T^-1`, `C_u = C T^-1` are formed
//! by additions of the library's entries (T is unit triangular), which makes the zeros of the
//! psi row of `M_u` exact; `R_u` is the closed form in absolute angles,
//! `h (m_a (Z + Z_a) + m_b Z)` on the crossbar angle and `h m_b Z_b` on the test mass's.
//!
//! # The floor's rotation about the vertical (phi_t)
//!
//! `G0 = 0` and `G2 = -M e_phi_a` (a rigid rotation about the upper fibre), so
//! `H = -w^2 C D^-1 M e_phi_a = C e_phi_a - C D^-1 K_c e_phi_a` with `K_c e_phi_a =
//! k_a (1 + i phi_ta) e_phi_a` exactly. The first form is used at low frequency (the second
//! cancels there: `D^-1 K_c -> 1`), the second at high frequency (the first cancels there for
//! eta/phi_t, which falls as f^-2: `w^2 D^-1 M -> -1`).
//!
//! # The floor's translation (x_t, y_t, z_t)
//!
//! `G0 = 0` and `G2` is the apparent force of the floor's acceleration on both centres of mass
//! ([`crate::model::translation`]), with exact zeros where the balanced crossbar cancels it, so
//! nothing needs splitting off: the low form is `H = w^2 C D^-1 G2` and the high form the
//! mass-line split above, `H = -C M^-1 G2 + C D^-1 K_c M^-1 G2` (with `K_c + i w C` under viscous
//! damping), both in absolute angles. The x_t column is the eta_t column's translation forcing
//! per `-h` (`R[:, eta_t] = -h G2[:, x_t]`), so phi/x_t falls as `f^4` at low frequency and as
//! `f^-2` at high frequency exactly as phi/eta_t does, and keeps its relative accuracy the same
//! way: `(T^-T G2)_psi = 0` exactly.
//!
//! # Where the forms switch
//!
//! Both forms are exact; they differ in rounding. The low form loses relative accuracy only on
//! the entries that fall as f^-2 above the block's modes (eta/phi_t), by `eps (w / w_lo)^2`
//! above the lowest mode `w_lo` of the block (measured: 2e-7 at 100 Hz if used there). The high
//! form loses it on the entries that are small below the modes because `D^-1 K_c -> 1`, by
//! `eps (w_hi / w)^2` below the highest mode `w_hi`, and by `eps (w_hi w_lo / w^2)^2` for the
//! f^4 entries below `w_lo` (measured: 1e-3 for phi/eta_t at 1e-5 Hz if used there). The
//! switch is where the first two are equal, `w^2 = w_lo w_hi`, the geometric mean of the
//! block's extreme undamped eigenvalues, where both are `eps w_hi / w_lo`: 1e-13 for Table I's
//! swing-x+torsion block (1.3 mHz .. 0.62 Hz, switch at 29 mHz), 6e-15 for its
//! swing-y+bounce block (0.41 Hz .. 10.8 Hz, switch at 2.1 Hz).
//!
//! # Forces
//!
//! Force inputs need no split (their forcing does not depend on frequency, so nothing cancels
//! in it), but they do need the absolute angles: in relative angles several force entries are
//! small differences of O(1) coordinates, e.g. phi/F_b.x above the swing modes (a force at the
//! test mass's centre does not turn it about z, so `(M^-1 Q)_psi = 0` and phi falls as f^-4
//! while phi_a and phi_b fall as f^-2) or theta/F_b.z and Z/M_b.x below them (in absolute
//! angles the gravity stiffness is diagonal, so the static response of the other angle is an
//! exact zero). The block-reduced LU loses up to 1e-4 relative on these (phi/F_b.x at 90 Hz);
//! here they are solved as `C_u D_u^-1 T^-T Q` with the same factorization as the tilt columns.
//! What remains is the cube's vertical position `Z = -(delta_a + delta_b + d theta_a)`, a
//! difference of relative coordinates for Z/F_b.y and Y/F_b.z above the bounce modes (below
//! 1e-11 relative at 100 Hz, growing as f^2; an absolute vertical coordinate of the test mass
//! would remove it).
//!
//! # Damping
//!
//! With swing loss (`Im(K_c)` on theta, eta) or viscous damping (`D = K_c + i w C - w^2 M`),
//! `K_c S = K_gravity S` no longer holds. Exactly,
//! `G0 + w^2 G2 = D S + w^2 R - i (Im(K_c) + w C) S`, so each tilt form above gains the term
//! `-C D^-1 i (Im(K_c) + w C) S`, and the high forms use `K_c + i w C` where they used `K_c`
//! (`D^-1 (K_c + i w C) M^-1 R = M^-1 R + w^2 D^-1 R`). The extra forcing has exact zeros on
//! the phi rows (it lives on theta, eta), so the phi entries keep their relative accuracy; with
//! swing loss phi/eta_t falls as `phi f^2` instead of `f^4` at low frequency (physics, not
//! rounding). Undamped or torsion/bounce-only structural damping takes the original path.
//!
//! Entries across blocks are never computed and are exactly 0.0. Per frequency: one 4x4 LU per
//! needed block and one solve per input, with no allocation.

use super::direct::{omega_sq, with_viscous, EquilibratedLu};
use super::{Input, Method, Request, TransferFunction};
use crate::error::TfError;
use crate::model::{Block, Coord, ForceInput, Model, TiltAxis, TranslationAxis};
use crate::modes::NormalModes;
use nalgebra::{Matrix4, RowVector4, Scalar, Vector4};
use num_complex::Complex64;
use std::ops::Sub;

/// Plan of the split method.
pub struct Split {
    request: Request,
    /// The blocks the request needs.
    blocks: Vec<AbsoluteBlock>,
}

/// Each crossbar angle with the test-mass angle measured relative to it.
const RELATIVE_PAIRS: [(Coord, Coord); 3] = [
    (Coord::ThetaA, Coord::ThetaB),
    (Coord::EtaA, Coord::EtaB),
    (Coord::PhiA, Coord::PhiB),
];

/// The change to absolute test-mass angles within one block, `u = T q`: `u_b = q_a + q_b` for
/// each pair (crossbar angle `a`, test-mass angle `b` relative to it), other coordinates as is.
struct Absolute {
    /// Block-local indices `(a, b)`.
    pairs: Vec<(usize, usize)>,
}

impl Absolute {
    fn new(block: Block) -> Absolute {
        let coords = block.coords();
        let pos = |c: Coord| coords.iter().position(|&x| x == c);
        let pairs = RELATIVE_PAIRS
            .into_iter()
            .filter_map(|(a, b)| Some((pos(a)?, pos(b)?)))
            .collect();
        Absolute { pairs }
    }

    /// `T^-T A T^-1` for a matrix of the equations of motion (M or K). `q = T^-1 u` has
    /// `q_b = u_b - u_a`, so this is a subtraction of columns, then of rows.
    fn congruence<T: Scalar + Copy + Sub<Output = T>>(&self, m: &Matrix4<T>) -> Matrix4<T> {
        let mut m = *m;
        for &(a, b) in &self.pairs {
            for r in 0..4 {
                m[(r, a)] = m[(r, a)] - m[(r, b)];
            }
        }
        for &(a, b) in &self.pairs {
            for c in 0..4 {
                m[(a, c)] = m[(a, c)] - m[(b, c)];
            }
        }
        m
    }

    /// `C T^-1` for an observation row.
    fn observation(&self, c: &RowVector4<f64>) -> RowVector4<f64> {
        let mut c = *c;
        for &(a, b) in &self.pairs {
            c[a] -= c[b];
        }
        c
    }

    /// `T^-T Q` for a generalized force.
    fn force<T: Scalar + Copy + Sub<Output = T>>(&self, q: &Vector4<T>) -> Vector4<T> {
        let mut q = *q;
        for &(a, b) in &self.pairs {
            q[a] = q[a] - q[b];
        }
        q
    }
}

/// One block's share of the request, in absolute test-mass angles.
struct AbsoluteBlock {
    /// `K_u = T^-T K_c T^-1`.
    stiffness: Matrix4<Complex64>,
    /// `M_u = T^-T M T^-1`.
    mass: Matrix4<f64>,
    /// `C_u = T^-T C T^-1`, when there is viscous damping.
    damping: Option<Matrix4<f64>>,
    /// Below this `w^2` the low-frequency forms are used (see the module docs).
    crossover_w2: f64,
    /// Outputs that read the block: row in the request, `C_u` row.
    outputs: Vec<(usize, RowVector4<f64>)>,
    columns: Vec<Column>,
}

/// One input in its two exact forms (the same form twice for a force).
struct Column {
    /// Column in the request.
    col: usize,
    low: Form,
    high: Form,
}

/// `H_o = offset_o + C_u,o D_u^-1 (sign w^(2 p) forcing + damped + i w damped_w)`, with `p`
/// 1 or 0; `damped` and `damped_w` are the damping terms of the module docs (zero without
/// swing loss or viscous damping, and then skipped).
#[derive(Clone)]
struct Form {
    /// Per block output.
    offset: Vec<f64>,
    forcing: Vector4<Complex64>,
    sign: f64,
    times_w2: bool,
    damped: Vector4<Complex64>,
    damped_w: Vector4<f64>,
    has_damped: bool,
}

impl Form {
    fn new(offset: Vec<f64>, forcing: Vector4<Complex64>, sign: f64, times_w2: bool) -> Form {
        Form {
            offset,
            forcing,
            sign,
            times_w2,
            damped: Vector4::zeros(),
            damped_w: Vector4::zeros(),
            has_damped: false,
        }
    }

    /// Adds the damping terms `damped + i w damped_w` to the forcing.
    fn with_damping(mut self, damped: Vector4<Complex64>, damped_w: Vector4<f64>) -> Form {
        self.has_damped =
            damped.iter().any(|z| z.norm() != 0.0) || damped_w.iter().any(|&v| v != 0.0);
        self.damped = damped;
        self.damped_w = damped_w;
        self
    }
}

/// The block-local index of coordinate `c`, if the block has it.
fn local(idx: &[usize; 4], c: Coord) -> Option<usize> {
    idx.iter().position(|&i| i == c.index())
}

/// The generalized force of force input `f` on the block.
fn force_q(model: &Model, idx: &[usize; 4], f: ForceInput) -> Vector4<f64> {
    Vector4::from_fn(|r, _| model.force_matrix()[(idx[r], f.index())])
}

/// The forcing `g2` of floor translation `a` on the block.
fn translation_q(model: &Model, idx: &[usize; 4], a: TranslationAxis) -> Vector4<f64> {
    Vector4::from_fn(|r, _| model.translation_forcing().g2[(idx[r], a.index())])
}

/// One block's matrices and observation rows, in the model's coordinates (`_q`) and in
/// absolute test-mass angles, from which each input's two forms are built.
struct BlockParts<'a> {
    model: &'a Model,
    idx: [usize; 4],
    t: Absolute,
    mass_q: Matrix4<f64>,
    stiffness_q: Matrix4<Complex64>,
    damping_q: Matrix4<f64>,
    /// `M_u = T^-T M T^-1`.
    mass: Matrix4<f64>,
    /// `K_u = T^-T K_c T^-1`.
    stiffness: Matrix4<Complex64>,
    /// `C_u = T^-T C T^-1`, when there is viscous damping.
    damping: Option<Matrix4<f64>>,
    /// Outputs that read the block: row in the request, `C` row.
    obs_q: Vec<(usize, RowVector4<f64>)>,
    /// The same with the `C_u` row.
    outputs: Vec<(usize, RowVector4<f64>)>,
}

impl<'a> BlockParts<'a> {
    fn new(
        model: &'a Model,
        block: Block,
        idx: [usize; 4],
        obs_q: Vec<(usize, RowVector4<f64>)>,
    ) -> Self {
        let t = Absolute::new(block);
        let mass_q = Model::block_of(model.mass(), block);
        let k = model.stiffness_complex();
        let stiffness_q = Matrix4::from_fn(|r, c| k[(idx[r], idx[c])]);
        let mass = t.congruence(&mass_q);
        let stiffness = t.congruence(&stiffness_q);
        let damping_q = Model::block_of(model.damping(), block);
        let damping = model.has_viscous().then(|| t.congruence(&damping_q));
        let outputs: Vec<(usize, RowVector4<f64>)> = obs_q
            .iter()
            .map(|(row, c)| (*row, t.observation(c)))
            .collect();
        BlockParts {
            model,
            idx,
            t,
            mass_q,
            stiffness_q,
            damping_q,
            mass,
            stiffness,
            damping,
            obs_q,
            outputs,
        }
    }

    /// Per tilt column `a`: T^-T i Im(K_c) e_a (the loss term).
    fn loss_column(&self, a: usize) -> Vector4<Complex64> {
        self.t.force(
            &self
                .stiffness_q
                .column(a)
                .map(|z| Complex64::new(0.0, z.im)),
        )
    }

    /// Per tilt column `a`: T^-T C e_a (the viscous term).
    fn viscous_column(&self, a: usize) -> Vector4<f64> {
        self.t.force(&self.damping_q.column(a).into_owned())
    }

    /// Column `j` of the block's observation rows.
    fn observed_column(&self, j: usize) -> Vec<f64> {
        self.obs_q.iter().map(|(_, c)| c[j]).collect()
    }

    /// `C_u y0` for a static displacement `y0`, or zero without viscous damping.
    fn damped(&self, y0: &Vector4<f64>) -> Vector4<f64> {
        match &self.damping {
            Some(c) => c * y0,
            None => Vector4::zeros(),
        }
    }

    /// The low- and high-frequency forms of `input`.
    fn forms(&self, input: Input) -> (Form, Form) {
        match input {
            Input::Force(f) => {
                let form = Form::new(
                    vec![0.0; self.outputs.len()],
                    self.t
                        .force(&force_q(self.model, &self.idx, f))
                        .map(Complex64::from),
                    1.0,
                    false,
                );
                (form.clone(), form)
            }
            Input::Translation(a) => self.translation_forms(a),
            Input::Tilt(axis @ (TiltAxis::ThetaT | TiltAxis::EtaT)) => {
                self.suspension_tilt_forms(axis)
            }
            Input::Tilt(axis) => self.rotation_tilt_forms(axis),
        }
    }

    fn translation_forms(&self, a: TranslationAxis) -> (Form, Form) {
        let g = self.t.force(&translation_q(self.model, &self.idx, a));
        let y0 = self
            .mass
            .lu()
            .solve(&g)
            .expect("M is positive definite (checked by Model::new)");
        let high_offset = self.outputs.iter().map(|(_, c)| -c.dot(&y0.transpose()));
        let c_y0 = self.damped(&y0);
        (
            Form::new(
                vec![0.0; self.outputs.len()],
                g.map(Complex64::from),
                1.0,
                true,
            ),
            Form::new(
                high_offset.collect(),
                self.stiffness * y0.map(Complex64::from),
                1.0,
                false,
            )
            .with_damping(Vector4::zeros(), c_y0),
        )
    }

    /// A tilt about a horizontal axis, which also moves the suspension point.
    fn suspension_tilt_forms(&self, axis: TiltAxis) -> (Form, Form) {
        let p = self.model.params();
        let (m_a, m_b) = (p.mass.m_a_kg, p.mass.m_b_kg);
        let l = &p.length;
        let a = local(&self.idx, tilt_coord(axis)).expect("filtered above");
        let b = local(&self.idx, partner(tilt_coord(axis)))
            .expect("theta_b, eta_b share the block of theta_a, eta_a");
        // Suspension-point translation h per radian, in absolute angles.
        let mut r_u = Vector4::zeros();
        r_u[a] = l.h_m * (m_a * (l.z_m + l.z_a_m) + m_b * l.z_m);
        r_u[b] = l.h_m * (m_b * l.z_b_m);
        let y0 = self
            .mass
            .lu()
            .solve(&r_u)
            .expect("M is positive definite (checked by Model::new)");
        let static_part = self.observed_column(a);
        let high_offset = static_part
            .iter()
            .zip(&self.outputs)
            .map(|(s, (_, c))| s - c.dot(&y0.transpose()))
            .collect();
        let (loss, visc) = (-self.loss_column(a), -self.viscous_column(a));
        let c_y0 = self.damped(&y0);
        (
            Form::new(static_part, r_u.map(Complex64::from), 1.0, true).with_damping(loss, visc),
            Form::new(
                high_offset,
                self.stiffness * y0.map(Complex64::from),
                1.0,
                false,
            )
            .with_damping(loss, visc + c_y0),
        )
    }

    /// A tilt about the vertical axis.
    fn rotation_tilt_forms(&self, axis: TiltAxis) -> (Form, Form) {
        let a = local(&self.idx, tilt_coord(axis)).expect("filtered above");
        (
            Form::new(
                vec![0.0; self.outputs.len()],
                self.t
                    .force(&self.mass_q.column(a).into_owned())
                    .map(Complex64::from),
                -1.0,
                true,
            ),
            Form::new(
                self.observed_column(a),
                self.t.force(&self.stiffness_q.column(a).into_owned()),
                -1.0,
                false,
            )
            .with_damping(Vector4::zeros(), -self.viscous_column(a)),
        )
    }
}

impl AbsoluteBlock {
    fn new(
        model: &Model,
        modes: &NormalModes,
        block: Block,
        request: &Request,
    ) -> Option<AbsoluteBlock> {
        let idx = block.coords().map(Coord::index);
        let inputs: Vec<(usize, Input)> = request
            .inputs
            .iter()
            .enumerate()
            .filter(|&(_, &input)| match input {
                Input::Tilt(axis) => local(&idx, tilt_coord(axis)).is_some(),
                Input::Translation(a) => translation_q(model, &idx, a).iter().any(|&v| v != 0.0),
                Input::Force(f) => force_q(model, &idx, f).iter().any(|&v| v != 0.0),
            })
            .map(|(col, &input)| (col, input))
            .collect();
        let observation = model.observation();
        let obs_q: Vec<(usize, RowVector4<f64>)> = request
            .outputs
            .iter()
            .enumerate()
            .map(|(row, o)| {
                (
                    row,
                    RowVector4::from_fn(|_, c| observation[(o.index(), idx[c])]),
                )
            })
            .filter(|(_, c)| c.iter().any(|&v| v != 0.0))
            .collect();
        if inputs.is_empty() || obs_q.is_empty() {
            return None;
        }
        let parts = BlockParts::new(model, block, idx, obs_q);
        let columns = inputs
            .into_iter()
            .map(|(col, input)| {
                let (low, high) = parts.forms(input);
                Column { col, low, high }
            })
            .collect();
        let eigenvalues: Vec<f64> = modes
            .modes
            .iter()
            .filter(|m| m.block == Some(block))
            .map(|m| m.omega_sq)
            .collect();
        let lo = eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = eigenvalues.iter().copied().fold(0.0, f64::max);
        Some(AbsoluteBlock {
            stiffness: parts.stiffness,
            mass: parts.mass,
            damping: parts.damping,
            crossover_w2: (lo * hi).sqrt(),
            outputs: parts.outputs,
            columns,
        })
    }

    fn eval(
        &self,
        w2: f64,
        freq_hz: f64,
        n_in: usize,
        out: &mut [Complex64],
    ) -> Result<(), TfError> {
        let lu = match &self.damping {
            Some(c) => {
                let k = with_viscous(&self.stiffness, c, w2.sqrt());
                EquilibratedLu::factor(&k, &self.mass, w2, freq_hz)?
            }
            None => EquilibratedLu::factor(&self.stiffness, &self.mass, w2, freq_hz)?,
        };
        for column in &self.columns {
            let form = if w2 <= self.crossover_w2 {
                &column.low
            } else {
                &column.high
            };
            let scale = if form.times_w2 {
                form.sign * w2
            } else {
                form.sign
            };
            let (mut x, factor) = if form.has_damped {
                let w = w2.sqrt();
                let y = form.forcing * Complex64::from(scale)
                    + form.damped
                    + form.damped_w.map(|v| Complex64::new(0.0, w * v));
                (y, 1.0)
            } else {
                (form.forcing, scale)
            };
            lu.solve_mut(&mut x)?;
            for ((row, c), offset) in self.outputs.iter().zip(&form.offset) {
                let cx: Complex64 = (0..4).map(|j| x[j] * c[j]).sum();
                out[row * n_in + column.col] = offset + cx * factor;
            }
        }
        Ok(())
    }
}

/// The crossbar coordinate a tilt angle acts on: `S` for theta_t, eta_t; the rigid rotation
/// about the upper fibre for phi_t.
fn tilt_coord(axis: TiltAxis) -> Coord {
    match axis {
        TiltAxis::ThetaT => Coord::ThetaA,
        TiltAxis::EtaT => Coord::EtaA,
        TiltAxis::PhiT => Coord::PhiA,
    }
}

/// The test-mass angle measured relative to a crossbar angle.
fn partner(c: Coord) -> Coord {
    RELATIVE_PAIRS
        .into_iter()
        .find(|&(a, _)| a == c)
        .expect("called with a crossbar angle")
        .1
}

impl Split {
    /// Prepares the absolute-angle systems of the blocks the request needs.
    pub fn new(model: &Model, request: Request) -> Split {
        let modes = NormalModes::new(model);
        let blocks = Block::ALL
            .into_iter()
            .filter_map(|block| AbsoluteBlock::new(model, &modes, block, &request))
            .collect();
        Split { request, blocks }
    }
}

impl TransferFunction for Split {
    fn method(&self) -> Method {
        Method::Split
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        let w2 = omega_sq(freq_hz)?;
        let n_in = self.request.inputs.len();
        out.fill(Complex64::new(0.0, 0.0));
        for block in &self.blocks {
            block.eval(w2, freq_hz, n_in, out)?;
        }
        Ok(())
    }
}
