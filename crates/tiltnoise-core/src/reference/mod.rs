//! An independent high-precision reference evaluator of the transfer functions.
//!
//! # What it is for
//!
//! The oracle of the accuracy tests and of the methods table: it evaluates
//! `H(w) = C (K_c - w^2 M)^-1 (G0 + w^2 G2)` (the tilt forcing, the translation forcing with
//! `G0 = 0`, or a column of the force matrix) to about 30 significant digits, so that the error
//! of every `f64` method ([`crate::tf::Method`]) can be measured rather than estimated. It is
//! slower than the `f64` direct method (`tiltnoise methods` times both); no production path
//! uses it.
//!
//! # Independence
//!
//! It does **not** share code with the `f64` model builder ([`crate::model`]): the mass matrix
//! (Appendix A, eqs. (def_I) and (EM), with the crate's one generalization, I^b_22 wherever the
//! test mass turns about its own y axis), the stiffness (gravity part, fibres' elastic part with
//! loss factors `1 + i phi`, each fibre's diluted swing loss on its share of the gravity
//! stiffness), the viscous damping matrix `C` (the dynamic stiffness is then
//! `K_c + i w C - w^2 M`, with `w` the double-double square root of `w^2`), the zeroth-order
//! force matrix, the tilt forcing `G0 + w^2 G2` (the crate's sign convention, see
//! [`crate::model::tilt`]; `G2` from the apparent forces and torques
//! `F_i = -m_i (r_s'' + w' x r_gi0)`, `M_i = -I_i w'` themselves), the floor translation's
//! forcing `w^2 G2` (from the apparent forces `F_i = -m_i u''` themselves, see
//! [`crate::model::translation`]) and the observation matrix are all rebuilt here from the
//! [`Params`] values in double-double arithmetic. Shared with the rest
//! of the crate are only the parameter struct, the index order of coordinates, observables and
//! inputs (the paper's, restated here) and the error types. For the pendulum as built
//! ([`crate::params::asymmetry`]) the matrices are the exact kinematics linearized in
//! double-double ([`crate::geometry::dd_matrices`]), the same computation the `f64` model
//! rounds: the independent check of those matrices is the energy cross-check's own kinematics
//! (`tests/it/energy_crosscheck.rs`), and the reference stays the oracle of the methods' solves.
//! The tilt forcing is used as defined,
//! `G0 + w^2 G2`: not the rotation-plus-translation split that some `f64` methods use, so that a
//! mistake in that reformulation cannot be replicated here.
//!
//! # Method
//!
//! Every parameter is taken as its exact binary value; arithmetic is double-double ([`Dd`],
//! [`CDd`]: about 106 bits, one operation errs by at most [`DD_EPS`] = 2^-104 ~ 4.9e-32
//! relative). The system is transformed exactly to absolute test-mass angles
//! (theta_a + theta_b, eta_a + eta_b, phi_a + phi_b replace theta_b, eta_b, phi_b; each of
//! M, K, G0, G2, B, C is transformed separately, so structural cancellations such as
//! `M[phi_a][phi_b] - M[phi_b][phi_b] = 0` are exact). Then `w = 2 pi f` in double-double, the
//! dynamic stiffness is scaled symmetrically by powers of two (exact), factored by complex
//! double-double Gaussian elimination with partial pivoting on the full 8x8, and each column is
//! solved with one step of iterative refinement (componentwise backward stable).
//!
//! # Precision
//!
//! The error of an entry is bounded by a small multiple of `DD_EPS kappa`, where `kappa` is the
//! entry's componentwise condition number ([`ReferenceModel::entry_condition`]); the tests
//! measure at most `0.21 DD_EPS kappa` against 50-digit mpmath. In practice:
//!
//! * about 1e-31 relative for well-conditioned entries, ~3e-29 at the ROMY bin 3e-4 from a mode;
//! * `DD_EPS` times the inverse relative detuning near an undamped mode: ~1e-16 exactly on a
//!   mode rounded to f64, where f64 solvers give up;
//! * entries that are small remainders of cancellations inside the model lose the cancellation
//!   factor: phi and phi_a per eta_t fall as f^4 at low frequency (kappa ~ 5e5 at 1 mHz, error
//!   8e-28; kappa grows as f^-2, ~5e11 at 1e-6 Hz), eta per phi_t above the swing modes (kappa
//!   2e7 at 3 Hz, 2e10 at 100 Hz, error 5e-23 there). [`ReferenceModel::entry_condition`] gives
//!   `kappa` per entry, so a test can always state the reference's own error bar.
//!
//! Exact zeros are kept: the symmetric pendulum's model is block diagonal after a permutation,
//! multipliers across the blocks are exactly zero and are skipped, so entries such as X/theta_t
//! are exactly 0 (an offset along x couples the blocks, and those entries are not zero then).
//!
//! ```
//! use tiltnoise_core::params::Params;
//! use tiltnoise_core::reference::ReferenceModel;
//! use tiltnoise_core::model::Request;
//!
//! let reference = ReferenceModel::new(&Params::table_i());
//! let h = reference.eval_dd(&Request::all_tilt(), 0.0)?;
//! // X/eta_t at f = 0 is -(Z + Z_b + h_c) = -1.664 m/rad to ~32 digits.
//! assert_eq!(h[1].re.to_f64(), -1.664);
//! # Ok::<(), tiltnoise_core::error::TfError>(())
//! ```

pub use crate::dd::{CDd, Dd, DD_EPS};

use crate::dd::matrices::{self as build, Matrices, Scales};
use crate::error::{FreqError, TfError};
use crate::model::Observable;
use crate::model::{Input, Request};
use crate::params::Params;
use build::{OBS_ETA, OBS_PHI, OBS_PHI_A, OBS_THETA, OBS_X, OBS_Y, OBS_Z};
use num_complex::Complex64;

/// Below this ratio of the smallest pivot to the largest entry of the equilibrated dynamic
/// stiffness the matrix is singular to double-double precision (fewer than two digits would
/// survive `DD_EPS / ratio`): the frequency is on an undamped resonance to ~1e-30.
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-30;

const N: usize = 8;

/// Pairs (crossbar angle, test-mass angle relative to the crossbar): the test mass's absolute
/// angle is their sum.
const ANGLE_PAIRS: [(usize, usize); 3] = [
    (build::TA, build::TB),
    (build::EA, build::EB),
    (build::PA, build::PB),
];

/// The linear model in double-double, built from the parameters directly.
#[derive(Debug, Clone)]
pub struct ReferenceModel {
    /// The paper's matrices (relative test-mass angles).
    m: Matrices,
    /// The same system in absolute test-mass angles, where it is solved.
    absolute: Formulation,
    /// The paper's coordinates, for the condition numbers of methods that work in them.
    paper: Formulation,
    /// With asymmetry keys below [`crate::params::asymmetry::LINEAR_BELOW`]: the references
    /// without them and with them scaled by `2^k`, whose linear combination `eval_dd` returns.
    linear: Option<Box<(ReferenceModel, ReferenceModel, i32)>>,
}

/// `M` and `K_c` of one coordinate system.
#[derive(Debug, Clone)]
struct System {
    mass: [[Dd; N]; N],
    stiffness: [[CDd; N]; N],
    /// Viscous damping matrix (zero unless the parameters have viscous coefficients).
    damping: [[Dd; N]; N],
}

/// Dynamic stiffness, forcing and observation in one set of generalized coordinates.
#[derive(Debug, Clone)]
struct Formulation {
    system: System,
    g0: [[Dd; 3]; N],
    g2: [[Dd; 3]; N],
    translation_g2: [[Dd; 3]; N],
    force: [[Dd; 12]; N],
    observation: [[Dd; N]; 7],
    /// The rounding scale of each datum, for the condition numbers.
    scales: Scales,
}

/// `|a| + |b|`: the scale of a difference of two data.
fn sum_rows<const C: usize>(v: &[[f64; C]; N]) -> [[f64; C]; N] {
    let mut out = *v;
    for (a, b) in ANGLE_PAIRS {
        for c in 0..C {
            out[a][c] = v[a][c] + v[b][c];
        }
    }
    out
}

fn sum_cols<const R: usize>(a: &[[f64; N]; R]) -> [[f64; N]; R] {
    let mut out = *a;
    for (row, orig) in out.iter_mut().zip(a) {
        for (ca, cb) in ANGLE_PAIRS {
            row[ca] = orig[ca] + orig[cb];
        }
    }
    out
}

impl Scales {
    /// The scales after the change to absolute test-mass angles: sums where the data are
    /// differenced.
    fn absolute(&self) -> Scales {
        Scales {
            mass: sum_rows(&sum_cols(&self.mass)),
            stiffness: sum_rows(&sum_cols(&self.stiffness)),
            force: sum_rows(&self.force),
            g0: sum_rows(&self.g0),
            g2: sum_rows(&self.g2),
            translation_g2: sum_rows(&self.translation_g2),
            observation: sum_cols(&self.observation),
        }
    }
}

/// `T^T v` for the columns of `v` (generalized forces), see [`Formulation::absolute`].
fn to_abs_rows<T: Copy + std::ops::Sub<Output = T>, const C: usize>(
    v: &[[T; C]; N],
) -> [[T; C]; N] {
    let mut out = *v;
    for (a, b) in ANGLE_PAIRS {
        for c in 0..C {
            out[a][c] = v[a][c] - v[b][c];
        }
    }
    out
}

/// `A T` for a matrix with 8 columns, see [`Formulation::absolute`].
fn to_abs_cols<T: Copy + std::ops::Sub<Output = T>, const R: usize>(
    a: &[[T; N]; R],
) -> [[T; N]; R] {
    let mut out = *a;
    for (row, orig) in out.iter_mut().zip(a) {
        for (ca, cb) in ANGLE_PAIRS {
            row[ca] = orig[ca] - orig[cb];
        }
    }
    out
}

impl Formulation {
    /// The paper's coordinates q (relative test-mass angles).
    fn paper(m: &Matrices, scales: &Scales) -> Formulation {
        Formulation {
            scales: scales.clone(),
            system: System {
                mass: m.mass,
                stiffness: m.stiffness,
                damping: m.damping,
            },
            g0: m.g0,
            g2: m.g2,
            translation_g2: m.translation_g2,
            force: m.force,
            observation: m.observation,
        }
    }

    /// The exact change of variables `q = T p` with `p = (theta_a, eta_a, phi_a, delta_a,
    /// theta_a + theta_b, eta_a + eta_b, phi_a + phi_b, delta_b)`: `T^T M T`, `T^T K_c T`,
    /// `T^T G0`, `T^T G2`, `T^T B` and `C T`, each transformed separately so that structural
    /// cancellations are exact and never meet a `w^2`.
    fn absolute(m: &Matrices, scales: &Scales) -> Formulation {
        Formulation {
            scales: scales.absolute(),
            system: System {
                mass: to_abs_rows(&to_abs_cols(&m.mass)),
                stiffness: to_abs_rows(&to_abs_cols(&m.stiffness)),
                damping: to_abs_rows(&to_abs_cols(&m.damping)),
            },
            g0: to_abs_rows(&m.g0),
            g2: to_abs_rows(&m.g2),
            translation_g2: to_abs_rows(&m.translation_g2),
            force: to_abs_rows(&m.force),
            observation: to_abs_cols(&m.observation),
        }
    }

    /// Row `r` of the forcing column of `input` at `w^2`.
    fn forcing(&self, input: Input, r: usize, w2: Dd) -> Dd {
        match input {
            Input::Tilt(axis) => {
                let (g0, g2) = (self.g0[r][axis.index()], self.g2[r][axis.index()]);
                if g2.is_zero() || w2.is_zero() {
                    g0
                } else {
                    g0 + g2 * w2
                }
            }
            Input::Translation(axis) => {
                let g2 = self.translation_g2[r][axis.index()];
                if g2.is_zero() || w2.is_zero() {
                    Dd::ZERO
                } else {
                    g2 * w2
                }
            }
            Input::Force(f) => self.force[r][f.index()],
        }
    }

    /// `|forcing|` entry by entry with each datum's rounding scale: `|G0| + w^2 |G2|` or `|B|`.
    fn forcing_magnitude(&self, input: Input, r: usize, w2: f64) -> f64 {
        let s = &self.scales;
        match input {
            Input::Tilt(axis) => s.g0[r][axis.index()] + w2 * s.g2[r][axis.index()],
            Input::Translation(axis) => w2 * s.translation_g2[r][axis.index()],
            Input::Force(f) => s.force[r][f.index()],
        }
    }

    /// `c^T x` for observation row `row`.
    fn observe(&self, row: usize, x: &[CDd; N]) -> CDd {
        let mut acc = CDd::ZERO;
        for (c, x_c) in self.observation[row].iter().zip(x) {
            if !c.is_zero() && !x_c.is_zero() {
                acc += x_c.scale(*c);
            }
        }
        acc
    }

    fn eval_dd(&self, request: &Request, freq_hz: f64) -> Result<Vec<CDd>, TfError> {
        let w2 = omega_sq(freq_hz)?;
        let lu = self.system.factor(w2, freq_hz)?;
        let a = self.system.dynamic(w2, &[0; N]);
        let n_in = request.inputs.len();
        let mut out = vec![CDd::ZERO; request.outputs.len() * n_in];
        for (i, input) in request.inputs.iter().enumerate() {
            let rhs: [CDd; N] = std::array::from_fn(|r| CDd::real(self.forcing(*input, r, w2)));
            let x = lu.refined_solve(&a, rhs);
            for (o, output) in request.outputs.iter().enumerate() {
                out[o * n_in + i] = self.observe(obs_row(*output), &x);
            }
        }
        Ok(out)
    }

    fn entry_condition(&self, request: &Request, freq_hz: f64) -> Result<Vec<f64>, TfError> {
        let w2 = omega_sq(freq_hz)?;
        let w2f = w2.to_f64();
        let sys = &self.system;
        let lu = sys.factor(w2, freq_hz)?;
        let a = sys.dynamic(w2, &[0; N]);
        let scales = &self.scales;
        let abs_a: [[f64; N]; N] = std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                scales.stiffness[r][c]
                    + w2f.sqrt() * sys.damping[r][c].hi.abs()
                    + w2f * scales.mass[r][c]
            })
        });
        // y = A^-T c = A^-1 c: the dynamic stiffness is (complex) symmetric in both formulations.
        let ys: Vec<[CDd; N]> = request
            .outputs
            .iter()
            .map(|o| {
                let row = &self.observation[obs_row(*o)];
                lu.refined_solve(&a, std::array::from_fn(|k| CDd::real(row[k])))
            })
            .collect();
        let n_in = request.inputs.len();
        let mut out = vec![0.0; request.outputs.len() * n_in];
        for (i, input) in request.inputs.iter().enumerate() {
            let g: [CDd; N] = std::array::from_fn(|r| CDd::real(self.forcing(*input, r, w2)));
            let x = lu.refined_solve(&a, g);
            for (o, output) in request.outputs.iter().enumerate() {
                let row = obs_row(*output);
                let y = &ys[o];
                let mut num = 0.0;
                for r in 0..N {
                    let y_r = y[r].abs_f64();
                    num += scales.observation[row][r] * x[r].abs_f64()
                        + y_r * self.forcing_magnitude(*input, r, w2f);
                    for k in 0..N {
                        num += y_r * abs_a[r][k] * x[k].abs_f64();
                    }
                }
                let h = self.observe(row, &x).abs_f64();
                out[o * n_in + i] = if num == 0.0 {
                    0.0
                } else if h == 0.0 {
                    f64::INFINITY
                } else {
                    num / h
                };
            }
        }
        Ok(out)
    }
}

/// The dynamic stiffness after equilibration, factored in place: `P S A S = L U`.
struct Lu {
    /// `L` below the diagonal (unit diagonal implied), `U` on and above it.
    a: [[CDd; N]; N],
    /// Row `k` of the factorization is row `perm[k]` of the equilibrated matrix.
    perm: [usize; N],
    /// Power-of-two exponents of the symmetric scaling `S = diag(2^scale)`.
    scale: [i32; N],
}

impl ReferenceModel {
    /// Builds every matrix in double-double from the parameter values.
    ///
    /// # Panics
    ///
    /// For parameters with `[asymmetry]` offsets that have no stable rest configuration (those
    /// [`crate::model::Model::new`] refuses): see [`crate::geometry::dd_matrices`].
    pub fn new(params: &Params) -> ReferenceModel {
        let mut reference = ReferenceModel::exact(params);
        reference.linear = params.asymmetry.linear_split().map(|(base, scaled, k)| {
            let with = |asymmetry| {
                let mut p = params.clone();
                p.asymmetry = asymmetry;
                ReferenceModel::exact(&p)
            };
            Box::new((with(base), with(scaled), k))
        });
        reference
    }

    /// [`ReferenceModel::new`] without the linear response in tiny keys: the matrices of the
    /// parameters as they are, for the tests that check that response.
    pub fn exact(params: &Params) -> ReferenceModel {
        let (m, scales) = crate::geometry::dd_matrices(params);
        let scales = scales.unwrap_or_else(|| Scales::own(&m));
        ReferenceModel {
            absolute: Formulation::absolute(&m, &scales),
            paper: Formulation::paper(&m, &scales),
            m,
            linear: None,
        }
    }

    /// Mass matrix M (8x8, coordinate order of [`crate::model::Coord::ALL`]).
    pub fn mass(&self) -> &[[Dd; 8]; 8] {
        &self.m.mass
    }

    /// Gravity part of the stiffness (lossless).
    pub fn stiffness_gravity(&self) -> &[[Dd; 8]; 8] {
        &self.m.stiffness_gravity
    }

    /// Complex stiffness `K_gravity + K_elastic (1 + i phi)` plus the fibres' swing loss.
    pub fn stiffness(&self) -> &[[CDd; 8]; 8] {
        &self.m.stiffness
    }

    /// Viscous damping matrix `C` (the dynamic stiffness is `K_c + i w C - w^2 M`).
    pub fn damping(&self) -> &[[Dd; 8]; 8] {
        &self.m.damping
    }

    /// True when the parameters have a nonzero viscous coefficient.
    pub fn has_viscous(&self) -> bool {
        self.m.damping.iter().flatten().any(|d| !d.is_zero())
    }

    /// Zeroth-order generalized forces per unit force/torque (8x12, columns F_a.xyz, F_b.xyz,
    /// M_a.xyz, M_b.xyz as [`crate::model::ForceInput::ALL`]).
    pub fn force_matrix(&self) -> &[[Dd; 12]; 8] {
        &self.m.force
    }

    /// Tilt forcing per unit angle, frequency-independent part `G0` (8x3).
    pub fn tilt_g0(&self) -> &[[Dd; 3]; 8] {
        &self.m.g0
    }

    /// Tilt forcing per unit `w^2` angle, `G2` (8x3).
    pub fn tilt_g2(&self) -> &[[Dd; 3]; 8] {
        &self.m.g2
    }

    /// Floor-translation forcing per unit `w^2` displacement, `G2` (8x3, columns x_t, y_t,
    /// z_t); the frequency-independent part is zero.
    pub fn translation_g2(&self) -> &[[Dd; 3]; 8] {
        &self.m.translation_g2
    }

    /// Observation matrix C (7x8, rows in the order of [`Observable::ALL`]).
    pub fn observation(&self) -> &[[Dd; 8]; 7] {
        &self.m.observation
    }

    /// `H(f)` for the request, row-major `outputs x inputs`, each part rounded to the nearest
    /// `f64` from double-double.
    pub fn eval(&self, request: &Request, freq_hz: f64) -> Result<Vec<Complex64>, TfError> {
        Ok(self
            .eval_dd(request, freq_hz)?
            .into_iter()
            .map(CDd::to_c64)
            .collect())
    }

    /// `H(f)` in double-double, row-major `outputs x inputs` (for error analysis).
    ///
    /// Errors: [`TfError::Freq`] for a negative or non-finite frequency (as the direct method),
    /// [`TfError::Singular`] when a pivot is exactly zero or the equilibrated dynamic stiffness
    /// is singular to double-double precision (`rcond` is then the ratio of the smallest pivot
    /// to the largest entry, see [`SINGULAR_PIVOT_RATIO`]).
    ///
    /// With asymmetry keys below [`crate::params::asymmetry::LINEAR_BELOW`] (their effects then
    /// subnormal numbers, where double-double keeps no relative precision either) the value is
    /// their linear response, `H(base) + (H(scaled) - H(base)) 2^-k` in double-double from the
    /// references without those keys and with them scaled by `2^k` into `[2^-81, 2^-80)`
    /// ([`crate::params::Asymmetry::linear_split`]): exact to far below `DD_EPS`, the terms of
    /// second order below `1e-18` of the first-order ones (`docs/asymmetry.md`).
    pub fn eval_dd(&self, request: &Request, freq_hz: f64) -> Result<Vec<CDd>, TfError> {
        let Some(linear) = &self.linear else {
            return self.absolute.eval_dd(request, freq_hz);
        };
        let (base, scaled, k) = linear.as_ref();
        let h0 = base.eval_dd(request, freq_hz)?;
        let h1 = scaled.eval_dd(request, freq_hz)?;
        Ok(h0
            .into_iter()
            .zip(h1)
            .map(|(a, b)| a + (b - a).ldexp(-*k))
            .collect())
    }

    /// Componentwise relative condition number `kappa` of each entry of `H(f)` (row-major like
    /// [`ReferenceModel::eval_dd`]) in the formulation the reference solves (absolute test-mass
    /// angles). With the dynamic stiffness `A = K_c - w^2 M` (symmetric), forcing `g`,
    /// observation row `c`, `x = A^-1 g` and `y = A^-1 c`:
    ///
    /// ```text
    /// kappa = ( |y|^T (|K_c| + w^2 |M|) |x| + |y|^T (|G0| + w^2 |G2|) + |c|^T |x| ) / |c^T x|
    /// ```
    ///
    /// (`|B|` for a force input): a relative perturbation of at most `eps` of every datum moves
    /// the entry by at most about `kappa eps` relative, to first order. For the pendulum as
    /// built each `|datum|` is its rounding scale instead, the sum of the magnitudes of the terms
    /// the exact kinematics computed into it ([`build::Scales`]): its rounding is relative to
    /// that. The reference's data
    /// carry a few [`DD_EPS`] each and its solve is componentwise backward stable, so its error
    /// on an entry is a small multiple of `DD_EPS kappa`. Structural zeros get 0.
    pub fn entry_condition(&self, request: &Request, freq_hz: f64) -> Result<Vec<f64>, TfError> {
        self.absolute.entry_condition(request, freq_hz)
    }

    /// The same condition number in the paper's coordinates (relative test-mass angles, the
    /// crate's `f64` matrices): what limits a method that works with those matrices, such as
    /// the direct method, to about `eps kappa` (`eps = 2^-53`) per entry. Larger than
    /// [`ReferenceModel::entry_condition`] where an observable is a difference of large relative
    /// angles (phi = phi_a + phi_b above the torsion modes).
    pub fn entry_condition_paper(
        &self,
        request: &Request,
        freq_hz: f64,
    ) -> Result<Vec<f64>, TfError> {
        self.paper.entry_condition(request, freq_hz)
    }

    /// The 1-norm condition number of the symmetrically equilibrated dynamic stiffness
    /// `S (K_c - w^2 M) S` in the paper's coordinates, `S = diag((|K_ii| + w^2 M_ii)^-1/2)`
    /// rounded to powers of two: the matrix the `f64` direct method factors (up to the
    /// rounding of `S`). Computed from its explicit inverse in double-double. It measures the
    /// closeness to a resonance; the normwise forward error of an LU solve is of order
    /// `n eps cond` with the method's unit roundoff `eps`.
    pub fn condition_number(&self, freq_hz: f64) -> Result<f64, TfError> {
        let w2 = omega_sq(freq_hz)?;
        let sys = &self.paper.system;
        let lu = sys.factor(w2, freq_hz)?;
        let a = sys.dynamic(w2, &lu.scale);
        let mut inv_cols = Vec::with_capacity(N);
        for c in 0..N {
            // Columns of (S A S)^-1 = S^-1 A^-1 S^-1; solve works on A, so undo the scaling.
            let mut e = [CDd::ZERO; N];
            e[c] = CDd::real(Dd::ONE).ldexp(-lu.scale[c]);
            let mut x = lu.solve(e);
            for (r, x_r) in x.iter_mut().enumerate() {
                *x_r = x_r.ldexp(-lu.scale[r]);
            }
            inv_cols.push(x);
        }
        let norm1 = |col: &dyn Fn(usize) -> [CDd; N]| {
            (0..N)
                .map(|c| col(c).iter().map(|z| z.abs_f64()).sum::<f64>())
                .fold(0.0, f64::max)
        };
        let a_norm = norm1(&|c| std::array::from_fn(|r| a[r][c]));
        let inv_norm = norm1(&|c| inv_cols[c]);
        Ok(a_norm * inv_norm)
    }
}

impl System {
    /// `S (K_c + i w C - w^2 M) S` with the power-of-two scaling `S = diag(2^scale)` (exact).
    fn dynamic(&self, w2: Dd, scale: &[i32; N]) -> [[CDd; N]; N] {
        let w = w2.sqrt();
        std::array::from_fn(|r| {
            std::array::from_fn(|c| {
                let k = self.stiffness[r][c];
                let m = self.mass[r][c];
                let mut a = if m.is_zero() || w2.is_zero() {
                    k
                } else {
                    k - CDd::real(m * w2)
                };
                let d = self.damping[r][c];
                if !d.is_zero() && !w2.is_zero() {
                    a += CDd::new(Dd::ZERO, d * w);
                }
                a.ldexp(scale[r] + scale[c])
            })
        })
    }

    /// Equilibrates and factors the dynamic stiffness at `w^2`.
    fn factor(&self, w2: Dd, freq_hz: f64) -> Result<Lu, TfError> {
        // s_i ~ (|K_ii| + w^2 M_ii)^-1/2 rounded to a power of two: the entries of S A S are of
        // order one whatever the units, so pivot sizes measure closeness to a resonance.
        let w2f = w2.to_f64();
        let scale: [i32; N] = std::array::from_fn(|i| {
            let diag = self.stiffness[i][i].abs_f64()
                + w2f.sqrt() * self.damping[i][i].to_f64().abs()
                + w2f * self.mass[i][i].to_f64();
            if diag > 0.0 && diag.is_finite() {
                -((0.5 * diag.log2()).round() as i32)
            } else {
                0
            }
        });
        let mut a = self.dynamic(w2, &scale);
        let biggest = a.iter().flatten().map(|z| z.abs_f64()).fold(0.0, f64::max);
        let mut perm: [usize; N] = std::array::from_fn(|i| i);
        let mut min_pivot = f64::INFINITY;
        for k in 0..N {
            let p = (k..N)
                .max_by(|&x, &y| a[x][k].abs_f64().total_cmp(&a[y][k].abs_f64()))
                .unwrap_or(k);
            let pivot_abs = a[p][k].abs_f64();
            if pivot_abs == 0.0 || !pivot_abs.is_finite() {
                return Err(TfError::Singular {
                    freq_hz,
                    rcond: 0.0,
                });
            }
            min_pivot = min_pivot.min(pivot_abs);
            a.swap(k, p);
            perm.swap(k, p);
            let pivot = a[k][k];
            for i in k + 1..N {
                if a[i][k].is_zero() {
                    continue;
                }
                let l = a[i][k] / pivot;
                a[i][k] = l;
                let row_k = a[k];
                for (a_ij, &u_kj) in a[i].iter_mut().zip(&row_k).skip(k + 1) {
                    if !u_kj.is_zero() {
                        *a_ij -= l * u_kj;
                    }
                }
            }
        }
        let pivot_ratio = min_pivot / biggest;
        if pivot_ratio.is_nan() || pivot_ratio < SINGULAR_PIVOT_RATIO {
            return Err(TfError::Singular {
                freq_hz,
                rcond: pivot_ratio,
            });
        }
        Ok(Lu { a, perm, scale })
    }
}

impl Lu {
    /// Solves `A x = b` for the unscaled dynamic stiffness `A`: `x = S (S A S)^-1 S b`.
    fn solve(&self, b: [CDd; N]) -> [CDd; N] {
        let mut y: [CDd; N] = std::array::from_fn(|k| {
            let r = self.perm[k];
            b[r].ldexp(self.scale[r])
        });
        for k in 0..N {
            for i in k + 1..N {
                if !self.a[i][k].is_zero() && !y[k].is_zero() {
                    let t = self.a[i][k] * y[k];
                    y[i] -= t;
                }
            }
        }
        for k in (0..N).rev() {
            let mut s = y[k];
            for (u_kj, y_j) in self.a[k].iter().zip(&y).skip(k + 1) {
                if !u_kj.is_zero() && !y_j.is_zero() {
                    s -= *u_kj * *y_j;
                }
            }
            y[k] = if s.is_zero() { s } else { s / self.a[k][k] };
        }
        std::array::from_fn(|r| y[r].ldexp(self.scale[r]))
    }

    /// [`Lu::solve`] followed by one step of iterative refinement with the residual
    /// `b - A x` of the unscaled matrix `a`, which makes the solution componentwise backward
    /// stable (Skeel 1980): small components are then as accurate as their own sensitivity to
    /// the matrix entries allows, not merely to a fraction of the largest one.
    fn refined_solve(&self, a: &[[CDd; N]; N], b: [CDd; N]) -> [CDd; N] {
        let mut x = self.solve(b);
        let r: [CDd; N] = std::array::from_fn(|i| {
            let mut s = b[i];
            for (a_ij, x_j) in a[i].iter().zip(&x) {
                if !a_ij.is_zero() && !x_j.is_zero() {
                    s -= *a_ij * *x_j;
                }
            }
            s
        });
        if r.iter().all(|z| z.is_zero()) {
            return x;
        }
        let d = self.solve(r);
        for (x_j, d_j) in x.iter_mut().zip(d) {
            if !d_j.is_zero() {
                *x_j += d_j;
            }
        }
        x
    }
}

impl std::fmt::Debug for Lu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Lu")
            .field("perm", &self.perm)
            .field("scale", &self.scale)
            .finish()
    }
}

/// `(2 pi f)^2` in double-double, after the direct method's check of the frequency.
fn omega_sq(freq_hz: f64) -> Result<Dd, TfError> {
    if !(freq_hz.is_finite() && freq_hz >= 0.0) {
        return Err(FreqError::Invalid {
            value: freq_hz,
            origin: "transfer-function evaluation".into(),
        }
        .into());
    }
    Ok((Dd::PI * (2.0 * freq_hz)).sqr())
}

fn obs_row(o: Observable) -> usize {
    match o {
        Observable::X => OBS_X,
        Observable::Y => OBS_Y,
        Observable::Z => OBS_Z,
        Observable::Theta => OBS_THETA,
        Observable::Eta => OBS_ETA,
        Observable::Phi => OBS_PHI,
        Observable::PhiA => OBS_PHI_A,
    }
}

/// Relative error of each entry, `|got - ref| / |ref|` (computed in double-double). Entries
/// whose reference is exactly zero are structural zeros: their error is 0 if `got` is exactly
/// zero too and infinite otherwise.
///
/// # Panics
/// If the slices differ in length.
pub fn relative_errors(got: &[Complex64], reference: &[CDd]) -> Vec<f64> {
    assert_eq!(
        got.len(),
        reference.len(),
        "relative_errors: {} values against {} reference values",
        got.len(),
        reference.len()
    );
    got.iter()
        .zip(reference)
        .map(|(&g, &r)| {
            if r.is_zero() {
                if g.re == 0.0 && g.im == 0.0 {
                    0.0
                } else {
                    f64::INFINITY
                }
            } else {
                // Scale both by the same power of two so that the squares cannot underflow.
                let k = -(r.re.hi.abs().max(r.im.hi.abs()).log2().round() as i32);
                let k = k.clamp(-1000, 1000);
                let diff = (CDd::from_c64(g) - r).ldexp(k);
                (diff.norm_sqr() / r.ldexp(k).norm_sqr()).sqrt().to_f64()
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use build::{EA, EB, PA, PB};

    #[test]
    fn relative_errors_treat_exact_zeros_as_structural() {
        let reference = [
            CDd::ZERO,
            CDd::ZERO,
            CDd::real(Dd::from_f64(2.0)),
            CDd::real(Dd::from_parts(1e-200, 1e-217)),
        ];
        let got = [
            Complex64::new(0.0, 0.0),
            Complex64::new(1e-300, 0.0),
            Complex64::new(2.0, 2e-10),
            Complex64::new(1e-200, 0.0),
        ];
        let err = relative_errors(&got, &reference);
        assert_eq!(err[0], 0.0);
        assert_eq!(err[1], f64::INFINITY);
        assert!((err[2] - 1e-10).abs() < 1e-25);
        assert!((err[3] - 1e-17).abs() < 1e-30, "{}", err[3]);
    }

    #[test]
    fn absolute_angles_are_symmetric_with_exact_structural_zeros() {
        let reference = ReferenceModel::new(&Params::table_i());
        let abs = &reference.absolute.system;
        for r in 0..N {
            for c in 0..N {
                assert_eq!(abs.mass[r][c], abs.mass[c][r]);
                assert_eq!(abs.stiffness[r][c], abs.stiffness[c][r]);
            }
        }
        // The test mass's torsion couples to the crossbar only through the lower fibre.
        assert!(abs.mass[PB][PA].is_zero() && abs.mass[PB][EA].is_zero());
        assert!(abs.mass[PB][EB].is_zero());
        assert_eq!(abs.stiffness[PB][PA], -abs.stiffness[PB][PB]);
    }
}
