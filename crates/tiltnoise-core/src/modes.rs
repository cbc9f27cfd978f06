//! Normal modes: the generalized symmetric eigenproblem `K v = w^2 M v` of the undamped model,
//! and which observables see each mode.
//!
//! The problem is solved per decoupled block ([`Block`]), so a mode's shape is exactly zero on
//! the other block's coordinates and "observable X does not see mode 5" is an exact statement,
//! not a rounding threshold. Within a block: Cholesky `M = L L^T`, symmetric eigenproblem of
//! `L^-1 K L^-T`, shapes `v = L^-T y`, normalized so that `V^T M V = I` (mass-normalized).
//! Pure numerics: depends on `model` only.

use crate::model::{Block, Coord, Mat8, Model, Observable, Vec8};
use nalgebra::{Matrix4, Vector4};

/// An observable "sees" a mode when its amplitude in the mass-normalized shape is at least this
/// fraction of the largest amplitude of that observable over all modes. Modes outside the
/// observable's block have amplitude exactly 0; this threshold only matters within a block.
pub const VISIBILITY_THRESHOLD: f64 = 1e-3;

/// One normal mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// 1-based, in order of increasing frequency (the paper's nu_1 ... nu_8).
    pub index: usize,
    /// Eigenvalue w^2 (rad^2/s^2).
    pub omega_sq: f64,
    /// Frequency w / 2 pi (Hz).
    pub frequency_hz: f64,
    /// The decoupled block the mode lives in.
    pub block: Block,
    /// Mass-normalized shape (v^T M v = 1), coordinate order [`Coord::ALL`].
    pub shape: Vec8,
    /// Share of the modal kinetic energy in each coordinate, `v_i (M v)_i`; sums to 1.
    pub energy_share: [f64; 8],
    /// Observable amplitudes `C v` of the mass-normalized shape (units: observable / sqrt(kg m^2)).
    pub observable_amplitude: [f64; 7],
    /// Modal loss angle `1/Q` (rad): `v^T Im(K_c) v / w^2` (structural) plus
    /// `v^T C v / w` (viscous, at the mode's own frequency), from the undamped shape. 0 when
    /// the model is undamped. See [`modal_loss_angle`].
    pub loss_angle: f64,
    /// Quality factor `Q = 1 / loss_angle`; `f64::INFINITY` when undamped.
    pub quality_factor: f64,
}

impl Mode {
    /// Coordinates holding at least `min_share` of the modal kinetic energy, largest first.
    pub fn dominant_coords(&self, min_share: f64) -> Vec<(Coord, f64)> {
        let mut v: Vec<(Coord, f64)> = Coord::ALL
            .into_iter()
            .map(|c| (c, self.energy_share[c.index()]))
            .filter(|&(_, s)| s >= min_share)
            .collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1));
        v
    }
}

/// All normal modes of a model, sorted by frequency, with the observability table.
#[derive(Debug, Clone, PartialEq)]
pub struct NormalModes {
    /// The modes, nu_1 first.
    pub modes: Vec<Mode>,
    /// `visible[k][o]`: observable `o` sees mode `k` (see [`VISIBILITY_THRESHOLD`]).
    pub visible: Vec<[bool; 7]>,
}

fn block_matrix(m: &Mat8, block: Block) -> Matrix4<f64> {
    Model::block_of(m, block)
}

impl NormalModes {
    /// Solves the undamped eigenproblem of `model` (loss angles are ignored here), with every
    /// eigenvalue refined to full `f64` accuracy: the `f64` eigensolver leaves the small
    /// eigenvalues of a block with a relative error up to `eps ||A|| / lambda_k` (about 1e-11
    /// for nu_1 of Table I, whose block also holds the 0.6 Hz swing), so a frequency printed
    /// with 17 digits would not be the pole. The Rayleigh quotient `v^T K v / v^T M v` of the
    /// `f64` shape, evaluated in double-double from the paper's matrices ([`crate::dd`]), has
    /// an error of order `||dv||^2` (about 1e-22 relative): the frequency is the pole to the
    /// last bit, and every evaluation method reports it as singular.
    pub fn new(model: &Model) -> NormalModes {
        let mut modes = NormalModes::new_f64(model);
        let m = crate::dd::matrices::build(model.params());
        for mode in modes.modes.iter_mut() {
            let v: [crate::dd::Dd; 8] =
                std::array::from_fn(|i| crate::dd::Dd::from_f64(mode.shape[i]));
            let quad = |a: &dyn Fn(usize, usize) -> crate::dd::Dd| {
                let mut acc = crate::dd::Dd::ZERO;
                for i in 0..8 {
                    for j in 0..8 {
                        acc += v[i] * a(i, j) * v[j];
                    }
                }
                acc
            };
            let k = quad(&|i, j| m.stiffness[i][j].re);
            let mm = quad(&|i, j| m.mass[i][j]);
            let omega_sq = k / mm;
            if omega_sq.to_f64() > 0.0 {
                mode.omega_sq = omega_sq.to_f64();
                mode.loss_angle = modal_loss_angle(model, &mode.shape, mode.omega_sq);
                mode.quality_factor = 1.0 / mode.loss_angle;
                let pi = crate::dd::Dd::from_f64(crate::dd::PI_HI)
                    + crate::dd::Dd::from_f64(crate::dd::PI_LO);
                let two_pi = pi + pi;
                mode.frequency_hz = (omega_sq.sqrt() / two_pi).to_f64();
            }
        }
        modes
    }

    /// [`NormalModes::new`] without the double-double refinement of the eigenvalues: relative
    /// errors up to `eps ||A|| / lambda_k` (1e-11 for nu_1 of Table I), for the Monte Carlo and
    /// the fit, which evaluate the modes thousands of times and need far less.
    pub fn new_f64(model: &Model) -> NormalModes {
        let mass = model.mass();
        let stiffness = model.stiffness();
        let mut modes = Vec::with_capacity(8);
        for block in Block::ALL {
            let mb = block_matrix(mass, block);
            let kb = block_matrix(&stiffness, block);
            let l = mb
                .cholesky()
                .expect("Model::new checked that M is positive definite")
                .l();
            let l_inv = l
                .try_inverse()
                .expect("a Cholesky factor with positive diagonal is invertible");
            let a = l_inv * kb * l_inv.transpose();
            let a = (a + a.transpose()) * 0.5;
            let eig = a.symmetric_eigen();
            for k in 0..4 {
                let y: Vector4<f64> = eig.eigenvectors.column(k).into();
                let v4 = l_inv.transpose() * y;
                let v4 = v4 / (v4.transpose() * mb * v4)[(0, 0)].sqrt();
                let mut shape = Vec8::zeros();
                for (i, c) in block.coords().into_iter().enumerate() {
                    shape[c.index()] = v4[i];
                }
                let omega_sq = eig.eigenvalues[k];
                let loss_angle = modal_loss_angle(model, &shape, omega_sq);
                modes.push(Mode {
                    index: 0,
                    omega_sq,
                    frequency_hz: omega_sq.max(0.0).sqrt() / std::f64::consts::TAU,
                    block,
                    shape,
                    energy_share: std::array::from_fn(|i| shape[i] * (mass * shape)[i]),
                    observable_amplitude: std::array::from_fn(|o| {
                        (model.observation().row(o) * shape)[(0, 0)]
                    }),
                    loss_angle,
                    quality_factor: 1.0 / loss_angle,
                });
            }
        }
        modes.sort_by(|a, b| a.omega_sq.total_cmp(&b.omega_sq));
        for (k, m) in modes.iter_mut().enumerate() {
            m.index = k + 1;
        }
        let largest: [f64; 7] = std::array::from_fn(|o| {
            modes
                .iter()
                .map(|m| m.observable_amplitude[o].abs())
                .fold(0.0, f64::max)
        });
        let visible = modes
            .iter()
            .map(|m| {
                std::array::from_fn(|o| {
                    largest[o] > 0.0
                        && m.observable_amplitude[o].abs() >= VISIBILITY_THRESHOLD * largest[o]
                })
            })
            .collect();
        NormalModes { modes, visible }
    }

    /// Observables that see mode `k` (0-based position in `modes`).
    pub fn observables_seeing(&self, k: usize) -> Vec<Observable> {
        Observable::ALL
            .into_iter()
            .filter(|o| self.visible[k][o.index()])
            .collect()
    }

    /// Mode frequencies (Hz), nu_1 first.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.modes.iter().map(|m| m.frequency_hz).collect()
    }
}

/// Modal loss angle of a mass-normalized undamped shape `v` with eigenvalue `w^2`:
/// `phi = v^T Im(K_c) v / w^2 + v^T C v / w` (rad), the first-order (weak-damping) value of
/// `Im(lambda) / Re(lambda)` for the damped eigenvalue `lambda` of `K_c + i w C - lambda M`
/// (the neglected terms are of second order in the loss: the coupling of modes by damping).
/// 0 for an undamped model or a non-positive eigenvalue.
pub fn modal_loss_angle(model: &Model, shape: &Vec8, omega_sq: f64) -> f64 {
    if model.is_undamped() || omega_sq <= 0.0 {
        return 0.0;
    }
    let structural = (shape.transpose() * model.stiffness_imag() * shape)[(0, 0)] / omega_sq;
    let viscous = (shape.transpose() * model.damping() * shape)[(0, 0)] / omega_sq.sqrt();
    structural + viscous
}

/// Rayleigh-quotient iteration on the undamped pencil `(K, M)` started from `mode`: returns
/// w^2 accurate to working precision in the mode's own scale (the block eigensolver's error is
/// of order eps |K| / |M|, which for the 1e-4 rad^2/s^2 torsion modes is a relative 1e-11).
pub fn refined_omega_sq(model: &Model, mode: &Mode) -> f64 {
    let (m, k) = (model.mass(), model.stiffness());
    let (mut v, mut lambda) = (mode.shape, mode.omega_sq);
    for _ in 0..6 {
        match (k - m * lambda).lu().solve(&(m * v)) {
            Some(w) if w.iter().all(|x| x.is_finite()) => v = w / w.norm(),
            // The shifted matrix is exactly singular: lambda is an eigenvalue already.
            _ => break,
        }
        lambda = (v.transpose() * k * v)[(0, 0)] / (v.transpose() * m * v)[(0, 0)];
    }
    lambda
}

/// Section III's decoupled physical-pendulum estimates of the swinging frequencies (Hz):
/// `(crossbar nu_{3,4}, test mass nu_{5,6})`.
pub fn decoupled_swing_estimates_hz(model: &Model) -> (f64, f64) {
    let p = model.params();
    let (m_a, m_b, g) = (p.mass.m_a_kg, p.mass.m_b_kg, p.environment.g_m_per_s2);
    let l = &p.length;
    let la = l.z_m + l.z_a_m;
    let crossbar = (m_a * g * la / (p.inertia.a11_kg_m2 + m_a * la * la)).sqrt();
    let test_mass = (m_b * g * l.z_b_m / (p.inertia.b11_kg_m2 + m_b * l.z_b_m * l.z_b_m)).sqrt();
    (
        crossbar / std::f64::consts::TAU,
        test_mass / std::f64::consts::TAU,
    )
}
