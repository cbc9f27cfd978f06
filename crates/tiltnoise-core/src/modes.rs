//! Normal modes: the generalized symmetric eigenproblem `K v = w^2 M v` of the undamped model,
//! which observables see each mode, and in what proportions.
//!
//! When the model is decoupled ([`Model::decoupled`]: the symmetric pendulum, or offsets that
//! keep its mirror plane) the problem is solved per block ([`Block`]), so a mode's shape is
//! exactly zero on the other block's coordinates and "observable X does not see mode 5" is an
//! exact statement, not a rounding threshold. An offset along x couples the blocks: the full
//! 8x8 problem is solved. Either way: Cholesky `M = L L^T`, symmetric eigenproblem of
//! `L^-1 K L^-T`, shapes `v = L^-T y`, normalized so that `V^T M V = I` (mass-normalized).
//!
//! # Labels
//!
//! A mode is labelled `nu_k` after the mode of the symmetric pendulum (the same parameters with
//! every `[asymmetry]` key 0, numbered by frequency as in Table II) whose shape it overlaps most
//! in the mass metric, `|u^T M v| / sqrt(u^T M u v^T M v)`: an offset moves frequencies by
//! parts in 1e4, and nu_3 and nu_4 are 0.9 mHz apart, so a rank could swap where the shape
//! does not. The sign of an asymmetric shape is chosen to make that overlap positive. For the
//! symmetric pendulum the label is the rank.
//!
//! # Visibility
//!
//! For each mode, each observable's amplitude relative to the mode's reference observable of
//! the same unit (the one of X, Y, Z, or of theta, eta, phi, phi_a, with the largest amplitude
//! in that mode): a signed real ratio, the mode shape of an undamped mode being real, its sign
//! the relative phase (0 or pi) of the mode's peaks in the two channels. An observable sees the
//! mode when the magnitude of its ratio is at least [`RATIO_THRESHOLD`].
//! [`Mode::ratio`] gives the ratio to any reference; [`NormalModes::shape_derivative`] the
//! first-order change of a shape with the matrices, for the derivatives of ratios.
//!
//! Pure numerics: depends on `model` (and `dd` for the refinement) only.

use crate::model::{Block, Coord, Mat8, Model, Observable, Vec8};
use nalgebra::allocator::Allocator;
use nalgebra::{Const, DefaultAllocator, DimDiff, DimMin, DimSub, Matrix4, SMatrix, SVector, U1};

/// An observable "sees" a mode when its amplitude in the mass-normalized shape is at least this
/// fraction of the largest amplitude of that observable over all modes. Modes outside the
/// observable's block have amplitude exactly 0; this threshold only matters within a block.
pub const VISIBILITY_THRESHOLD: f64 = 1e-3;

/// An observable sees a mode in the ratio table ([`NormalModes::ratio`]) when its amplitude is
/// at least this fraction of the mode's reference observable of the same unit: a peak 80 dB
/// below the mode's strongest peak in channels of that unit, about what a long free-motion
/// record resolves above its readout noise.
pub const RATIO_THRESHOLD: f64 = 1e-4;

/// One normal mode.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    /// The label `k` of `nu_k`, 1-based: the rank in frequency for the symmetric pendulum (the
    /// paper's nu_1 ... nu_8), the symmetric mode it continues otherwise (see the module docs).
    pub index: usize,
    /// Eigenvalue w^2 (rad^2/s^2).
    pub omega_sq: f64,
    /// Frequency w / 2 pi (Hz).
    pub frequency_hz: f64,
    /// The decoupled block the mode lives in; `None` when the model is coupled
    /// ([`Model::decoupled`]).
    pub block: Option<Block>,
    /// The mass-metric overlap of the shape with the symmetric pendulum's mode `nu_index`,
    /// in `[0, 1]`; exactly 1 for the symmetric pendulum.
    pub overlap: f64,
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
    /// The block's name, or `coupled`.
    pub fn block_name(&self) -> &'static str {
        self.block.map_or("coupled", Block::name)
    }

    /// The signed ratio of the mode's amplitude in `observable` to its amplitude in
    /// `reference` (NaN if the reference does not see the mode at all, an exact zero).
    pub fn ratio(&self, observable: Observable, reference: Observable) -> f64 {
        self.observable_amplitude[observable.index()] / self.observable_amplitude[reference.index()]
    }

    /// The observable of the same unit as `observable` with the largest amplitude in this mode
    /// (the first in [`Observable::ALL`] order on a tie).
    pub fn reference_for(&self, observable: Observable) -> Observable {
        let positions = [Observable::X, Observable::Y, Observable::Z];
        let group: &[Observable] = if positions.contains(&observable) {
            &positions
        } else {
            &[
                Observable::Theta,
                Observable::Eta,
                Observable::Phi,
                Observable::PhiA,
            ]
        };
        let amp = |o: &Observable| self.observable_amplitude[o.index()].abs();
        *group
            .iter()
            .reduce(|best, o| if amp(o) > amp(best) { o } else { best })
            .expect("a unit group is not empty")
    }

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
    /// `ratio[k][o]`: the amplitude of mode `k` in observable `o` relative to the mode's
    /// reference observable of the same unit ([`Mode::reference_for`]); 0 where the whole
    /// unit group does not see the mode.
    pub ratio: Vec<[f64; 7]>,
}

fn block_matrix(m: &Mat8, block: Block) -> Matrix4<f64> {
    Model::block_of(m, block)
}

/// The undamped eigenpairs `(block, w^2, mass-normalized shape)`, unsorted: per block when the
/// model is decoupled, of the full 8x8 pencil otherwise.
fn eigenpairs(model: &Model) -> Vec<(Option<Block>, f64, Vec8)> {
    let mass = model.mass();
    let stiffness = model.stiffness();
    if !model.decoupled() {
        return pencil_eigenpairs(mass, &stiffness)
            .into_iter()
            .map(|(omega_sq, shape)| (None, omega_sq, shape))
            .collect();
    }
    let mut pairs = Vec::with_capacity(8);
    for block in Block::ALL {
        let mb = block_matrix(mass, block);
        let kb = block_matrix(&stiffness, block);
        for (omega_sq, v4) in pencil_eigenpairs(&mb, &kb) {
            let mut shape = Vec8::zeros();
            for (i, c) in block.coords().into_iter().enumerate() {
                shape[c.index()] = v4[i];
            }
            pairs.push((Some(block), omega_sq, shape));
        }
    }
    pairs
}

/// The Cholesky reduction of the pencil `(K, M)` of `N` coordinates: `L^-1` and the symmetric
/// `L^-1 K L^-T` (symmetrized), whose eigenvalues are the pencil's; `None` when `M` is not
/// positive definite.
pub(crate) fn reduced_pencil<const N: usize>(
    m: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
) -> Option<(SMatrix<f64, N, N>, SMatrix<f64, N, N>)>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    let l_inv = m.cholesky()?.l().try_inverse()?;
    let a = l_inv * k * l_inv.transpose();
    Some((l_inv, (a + a.transpose()) * 0.5))
}

/// The eigenpairs of the pencil `(K, M)` of `N` coordinates (`M` positive definite, as
/// [`Model::new`] checked), shapes `v = L^-T y` mass-normalized.
fn pencil_eigenpairs<const N: usize>(
    m: &SMatrix<f64, N, N>,
    k: &SMatrix<f64, N, N>,
) -> Vec<(f64, SVector<f64, N>)>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>> + DimSub<U1>,
    DefaultAllocator: Allocator<DimDiff<Const<N>, U1>>,
{
    let (l_inv, a) = reduced_pencil(m, k)
        .expect("Model::new checked that M is positive definite (its Cholesky factor inverts)");
    let eig = a.symmetric_eigen();
    (0..N)
        .map(|j| {
            let y: SVector<f64, N> = eig.eigenvectors.column(j).into();
            let v = l_inv.transpose() * y;
            let v = v / (v.transpose() * m * v)[(0, 0)].sqrt();
            (eig.eigenvalues[j], v)
        })
        .collect()
}

/// Labels the modes of an asymmetric model by the symmetric pendulum's modes they overlap
/// most (see the module docs), turns each shape so that the overlap is positive, and sorts
/// them by label. Pairs are assigned greedily, largest overlap first. If the symmetric
/// pendulum of these parameters has no stable equilibrium itself (no mode to compare with),
/// the rank stays the label and the overlaps are 0.
fn label(model: &Model, modes: &mut [Mode]) {
    let params = crate::params::Params {
        asymmetry: Default::default(),
        ..model.params().clone()
    };
    let Ok(symmetric) = Model::new(&params) else {
        for m in modes.iter_mut() {
            m.overlap = 0.0;
        }
        return;
    };
    let reference = NormalModes::new_f64(&symmetric);
    let mass = model.mass();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(64);
    for (j, u) in reference.modes.iter().enumerate() {
        let u_norm = (u.shape.transpose() * mass * u.shape)[(0, 0)].sqrt();
        for (k, v) in modes.iter().enumerate() {
            let o = (u.shape.transpose() * mass * v.shape)[(0, 0)] / u_norm;
            pairs.push((o, j, k));
        }
    }
    pairs.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
    let (mut label_taken, mut mode_done) = ([false; 8], [false; 8]);
    for (o, j, k) in pairs {
        if label_taken[j] || mode_done[k] {
            continue;
        }
        (label_taken[j], mode_done[k]) = (true, true);
        let m = &mut modes[k];
        m.index = reference.modes[j].index;
        m.overlap = o.abs();
        if o < 0.0 {
            m.shape = -m.shape;
            m.observable_amplitude = m.observable_amplitude.map(|a| -a);
        }
    }
    modes.sort_by_key(|m| m.index);
}

impl Mode {
    /// A mode of `model` from its eigenpair, labelled by rank later.
    fn of_shape(model: &Model, block: Option<Block>, omega_sq: f64, shape: Vec8) -> Mode {
        let mass = model.mass();
        let loss_angle = modal_loss_angle(model, &shape, omega_sq);
        Mode {
            index: 0,
            omega_sq,
            frequency_hz: omega_sq.max(0.0).sqrt() / std::f64::consts::TAU,
            block,
            overlap: 1.0,
            shape,
            energy_share: std::array::from_fn(|i| shape[i] * (mass * shape)[i]),
            observable_amplitude: std::array::from_fn(|o| {
                (model.observation().row(o) * shape)[(0, 0)]
            }),
            loss_angle,
            quality_factor: 1.0 / loss_angle,
        }
    }
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
        let (m, _) = crate::geometry::dd_matrices(model.params());
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
        let mut modes: Vec<Mode> = eigenpairs(model)
            .into_iter()
            .map(|(block, omega_sq, shape)| Mode::of_shape(model, block, omega_sq, shape))
            .collect();
        modes.sort_by(|a, b| a.omega_sq.total_cmp(&b.omega_sq));
        for (k, m) in modes.iter_mut().enumerate() {
            m.index = k + 1;
        }
        if !model.is_symmetric() {
            label(model, &mut modes);
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
        let ratio = modes
            .iter()
            .map(|m| {
                Observable::ALL.map(|o| {
                    let reference = m.observable_amplitude[m.reference_for(o).index()];
                    if reference == 0.0 {
                        0.0
                    } else {
                        m.observable_amplitude[o.index()] / reference
                    }
                })
            })
            .collect();
        NormalModes {
            modes,
            visible,
            ratio,
        }
    }

    /// Observables whose amplitude in mode `k` (0-based position in `modes`) is at least
    /// [`RATIO_THRESHOLD`] of the mode's reference observable of the same unit.
    pub fn observables_above_ratio(&self, k: usize) -> Vec<Observable> {
        Observable::ALL
            .into_iter()
            .filter(|o| self.ratio[k][o.index()].abs() >= RATIO_THRESHOLD)
            .collect()
    }

    /// The first-order change of mode `k`'s mass-normalized shape (0-based position) when the
    /// mass and stiffness matrices change by `dm` and `dk`, for a simple eigenvalue:
    ///
    /// ```text
    /// dv_k = sum_{j != k} v_j v_j^T (dK - w_k^2 dM) v_k / (w_k^2 - w_j^2) - 1/2 v_k v_k^T dM v_k
    /// ```
    ///
    /// (the last term keeps `v^T M v = 1`). With the change `dC` of the observation matrix, the
    /// change of the amplitudes is `C dv_k + dC v_k`, and of a ratio `a_o / a_r` it is
    /// `(da_o - ratio da_r) / a_r`: what a fit to measured ratios needs.
    pub fn shape_derivative(&self, k: usize, dm: &Mat8, dk: &Mat8) -> Vec8 {
        let mode = &self.modes[k];
        let v = &mode.shape;
        let mut dv = v * (-0.5 * (v.transpose() * dm * v)[(0, 0)]);
        let rhs = (dk - dm * mode.omega_sq) * v;
        for (j, other) in self.modes.iter().enumerate() {
            if j != k {
                let u = &other.shape;
                dv += u * ((u.transpose() * rhs)[(0, 0)] / (mode.omega_sq - other.omega_sq));
            }
        }
        dv
    }

    /// Observables that see mode `k` (0-based position in `modes`).
    pub fn observables_seeing(&self, k: usize) -> Vec<Observable> {
        Observable::ALL
            .into_iter()
            .filter(|o| self.visible[k][o.index()])
            .collect()
    }

    /// The names of the observables that see mode `k` ([`NormalModes::observables_seeing`]).
    pub fn names_seeing(&self, k: usize) -> Vec<&'static str> {
        self.observables_seeing(k)
            .iter()
            .map(|o| o.name())
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
