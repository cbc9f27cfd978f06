//! The pole-zero method: every entry as a product of its own poles and zeros, built once per plan
//! in double-double.
//!
//! Within a block ([`Block`], 4x4 in absolute test-mass angles, as the split method and the
//! reference solve it) `D(s) = K_c - s M` with `s = w^2`, and an entry is
//!
//! ```text
//! H(s) = c^T D(s)^-1 g(s) = N(s) / P(s),   P = det D,   N = -det [[D, g], [c^T, 0]],
//! ```
//!
//! with `g = G0 + s G2` (tilt; `G0 = 0` for the floor's translation, so its entries have at
//! least one factor `s`) or a column of the force matrix. Both determinants are expanded
//! at plan time as polynomials in `s` (Laplace expansion of matrices of polynomials of degree
//! <= 1) in double-double, from the paper's matrices in double-double ([`crate::dd::matrices`]). Alongside each coefficient the sum
//! of the magnitudes of its terms is kept; a coefficient below `ZERO_REL` times that sum is a
//! structural cancellation (the f^4 of phi/eta_t and phi_a/eta_t at low frequency, the f^-2 of
//! eta/phi_t and phi/eta_t at high frequency) and is set to exactly zero. The roots of `P`
//! (the block's eigenvalues) and of `N / s^p` (the entry's zeros) are found in `f64` (Aberth)
//! and polished in double-double (Aberth-Newton on the double-double coefficients). Then per
//! frequency
//!
//! ```text
//! H = g s^p prod_j (z_j - s) / prod_k (lambda_k - s)
//!   = (g prod_j z_j) s^p prod_j (1 - s / z_j) / prod_k (lambda_k - s),
//! ```
//!
//! the second form with `1 / z_j` rounded once to `f64`, in real arithmetic for undamped blocks
//! whose zeros are all real, in complex arithmetic otherwise (damped blocks, or complex zeros).
//! `power + #zeros <= 4` in a block, so every entry is at most four factors `a + b s` (`s` or
//! `1 - s / z`). Every factor is relatively accurate: the relative error of an entry is a few
//! `eps (1 + sum |z| / |z - s| + sum |lambda| / |lambda - s|)`, about `1e2 eps` at 1 % from a
//! pole or zero and `~eps` elsewhere, with no cancellation at low or high frequency
//! (`tests/it/polezero.rs` measures 3e-14 at most outside the 1 % zones against the reference;
//! `tests/it/polezero_batch.rs` checks the f64 evaluation against the same product form in
//! double-double within this bound, from 0 Hz to 1e5 Hz). Entries whose observation row or
//! forcing column misses a block get nothing from it; entries no block reaches are exactly 0.0.
//!
//! The pendulum as built: with an offset along x the two blocks couple into one system of 8
//! coordinates, factored as a whole the same way (the determinants then have up to 9 rows: each
//! minor is expanded once). Its zeros go two by two into quadratic factors
//! `(1 - s / z_1)(1 - s / z_2) = 1 + c1 s + c2 s^2`, whose coefficients are real for a conjugate
//! pair too, so an undamped coupled system stays in real arithmetic whatever its zeros; a
//! coefficient of the polynomials is set to zero as a structural cancellation against the sum
//! of the rounding scales of its terms, which for the pendulum as built carry the data's own
//! ([`crate::dd::matrices::Scales`]).
//!
//! Evaluation (`kernel`): a grid is evaluated eight frequencies at a time in vector lanes, each
//! block's denominator and its reciprocal once per frequency, each entry a few
//! multiplications. Two outputs: [`super::evaluate`] stores the plan's own [`Layout`] (planes
//! of only the entries some block reaches, real when every block is: 11 real planes, 88 bytes
//! per frequency, for Table I's 7x3 tilt matrix), each chunk's lanes stored with vector moves;
//! [`TransferFunction::eval_grid_into`] writes the dense complex matrix, a point's values
//! together (non-temporal stores for outputs larger than the cache).
//! [`TransferFunction::eval_into`] is the dense path on a grid of one point. The results are
//! bit-identical whatever the output, the grid, the lane, the number of threads
//! ([`super::evaluate_into`], [`super::eval_grid_threads`]) or the CPU (AVX, chosen at run
//! time, or portable: the same IEEE operations in the same order, no fused multiply-add).
//! Its speed is measured by `benches/methods.rs` (figures in `scripts/bench/README.md`).
//!
//! Singularity: an undamped block with `|lambda_k - s| < SINGULAR_RCOND lambda_k` (the rounding
//! of `s` and of `lambda_k` then leaves fewer than three digits of the factor) is reported as
//! [`TfError::Singular`] with `rcond = |lambda_k - s| / lambda_k`.

mod kernel;
mod lanes;

use super::{Destination, Input, Layout, Method, Request, TransferFunction};
use crate::dd::matrices::{Matrices, Scales};
use crate::dd::{CDd, Dd, DD_EPS};
use crate::error::TfError;
use crate::model::{Block, Coord, Model};
use crate::params::Params;
use kernel::{BlockForm, ComplexBlock, ComplexEntry, Kernel, RealBlock, RealEntry};
use num_complex::Complex64;

/// A coefficient smaller than this times the sum of its terms' magnitudes is a structural
/// cancellation: exactly zero in exact arithmetic (rounding of the double-double data and the
/// expansion leaves a few `DD_EPS`).
const ZERO_REL: f64 = 1e3 * DD_EPS;

/// Plan of the pole-zero method.
pub struct PoleZero {
    request: Request,
    /// Writes the dense complex layout ([`TransferFunction::eval_grid_into`]).
    kernel: Kernel,
    /// Writes [`PoleZero::layout`]: only the entries some block reaches, real when every
    /// block is.
    compact: Kernel,
    layout: Layout,
}

/// An entry's product form in double-double, ready for a block of `N` coordinates: gain,
/// `power` of `s`, linear factors `(a, b)` (the first `count` of them not padding) and
/// quadratic factors `1 + c1 s + c2 s^2` (the first `n_pairs`), see [`RealEntry`].
struct Prepared<const N: usize> {
    at: usize,
    gain: CDd,
    power: usize,
    factors: [(CDd, CDd); N],
    count: usize,
    pairs: [(Dd, Dd); N],
    n_pairs: usize,
}

/// The product form of one entry: each zero `z` a linear factor `1 - s / z` with `z` in the
/// gain, a zero at the origin the factor `s`. With `quadratic` (the coupled system's real
/// arithmetic) the zeros at the origin are a `power` instead, and the others go two by two into
/// `(1 - s / z_1)(1 - s / z_2)`: each conjugate pair (exact conjugates: [`symmetrize`] made
/// them so), then the real zeros sorted by magnitude, the smallest with the largest; a real
/// zero left over stays linear.
fn prepare<const N: usize>(f: &EntryFactors, at: usize, quadratic: bool) -> Prepared<N> {
    let one = CDd::real(Dd::ONE);
    let mut p = Prepared {
        at,
        gain: f.gain,
        power: 0,
        factors: [(one, CDd::ZERO); N],
        count: 0,
        pairs: [(Dd::ZERO, Dd::ZERO); N],
        n_pairs: 0,
    };
    let linear = |p: &mut Prepared<N>, z: CDd| {
        p.factors[p.count] = (one, -(one / z));
        p.gain = p.gain * z;
        p.count += 1;
    };
    if !quadratic {
        for _ in 0..f.power {
            p.factors[p.count] = (CDd::ZERO, one);
            p.count += 1;
        }
        for &z in &f.zeros {
            linear(&mut p, z);
        }
        return p;
    }
    p.power = f.power as usize;
    let pair = |p: &mut Prepared<N>, a: CDd, b: CDd| {
        // 1 - s (1/a + 1/b) + s^2 / (a b): real for a conjugate pair or two real zeros.
        let (wa, wb) = (one / a, one / b);
        p.pairs[p.n_pairs] = ((-(wa + wb)).re, (wa * wb).re);
        p.gain = p.gain * a * b;
        p.n_pairs += 1;
    };
    for &z in f.zeros.iter().filter(|z| z.im.hi > 0.0) {
        pair(&mut p, z, z.conj());
    }
    let mut real: Vec<CDd> = f.zeros.iter().copied().filter(|z| z.im.is_zero()).collect();
    real.sort_by(|a, b| a.abs_f64().total_cmp(&b.abs_f64()));
    while real.len() >= 2 {
        let (small, large) = (real.remove(0), real.pop().expect("two zeros left"));
        pair(&mut p, small, large);
    }
    if let Some(&z) = real.first() {
        linear(&mut p, z);
    }
    p
}

/// The kernel's form of one block of `N` coordinates: its poles and entries in real
/// arithmetic (`Ok`) when the block is undamped and every entry's gain is real and its zeros
/// real or, in the coupled system (`N = 8`), complex in conjugate pairs; else in complex
/// arithmetic (`Err`).
#[allow(clippy::type_complexity, reason = "the two arms of one block's form")]
fn block_form<const N: usize>(
    fs: &[&EntryFactors],
    n_in: usize,
    position: &dyn Fn(usize) -> (usize, usize),
) -> Result<([f64; N], Vec<RealEntry<N>>), ([Complex64; N], Vec<ComplexEntry<N>>)> {
    let poles = &fs[0].poles;
    let quadratic = N == 8;
    let real_zeros = |f: &EntryFactors| {
        f.zeros
            .iter()
            .all(|z| z.im.is_zero() || (quadratic && f.zeros.contains(&z.conj())))
    };
    let real = poles.iter().all(|p| p.im.is_zero())
        && fs.iter().all(|f| f.gain.im.is_zero() && real_zeros(f));
    if real {
        let entries = fs
            .iter()
            .map(|f| {
                let p = prepare::<N>(f, f.output * n_in + f.input, quadratic);
                RealEntry {
                    re: position(p.at).0,
                    first_re: false,
                    factors: p.count,
                    gain: p.gain.re.to_f64(),
                    a: p.factors.map(|(a, _)| a.re.to_f64()),
                    b: p.factors.map(|(_, b)| b.re.to_f64()),
                    power: p.power,
                    pairs: p.n_pairs,
                    c1: p.pairs.map(|(c1, _)| c1.to_f64()),
                    c2: p.pairs.map(|(_, c2)| c2.to_f64()),
                }
            })
            .collect();
        Ok((std::array::from_fn(|k| poles[k].re.to_f64()), entries))
    } else {
        let entries = fs
            .iter()
            .map(|f| {
                let p = prepare::<N>(f, f.output * n_in + f.input, false);
                ComplexEntry {
                    re: position(p.at).0,
                    im: position(p.at).1,
                    first_re: false,
                    first_im: false,
                    factors: p.count,
                    gain: p.gain.to_c64(),
                    a: p.factors.map(|(a, _)| a.to_c64()),
                    b: p.factors.map(|(_, b)| b.to_c64()),
                }
            })
            .collect();
        Err((std::array::from_fn(|k| poles[k].to_c64()), entries))
    }
}

/// One entry's factored form in double-double (exposed for the tests).
#[derive(Debug, Clone)]
pub struct EntryFactors {
    /// Request row.
    pub output: usize,
    /// Request column.
    pub input: usize,
    /// The entry's block; `None` for the coupled 8x8 system of an asymmetric pendulum.
    pub block: Option<Block>,
    /// `H = gain s^power prod(z_j - s) / prod(lambda_k - s)`.
    pub gain: CDd,
    /// Multiplicity of the zero at `s = 0`.
    pub power: u32,
    /// The other zeros (`s = w^2`, rad^2/s^2).
    pub zeros: Vec<CDd>,
    /// The block's poles (`s`).
    pub poles: Vec<CDd>,
    /// Coefficients of `N` zeroed as structural cancellations: `(power of s, |c| / scale)`.
    pub cancelled: Vec<(usize, f64)>,
    /// `H = N(s) / P(s)` before factoring: the coefficients of `N` (ascending, after the
    /// cancellations) and of `P = det(K_c - s M)`, each with the sum of the magnitudes of the
    /// terms computed into it. A coefficient errs by a few `DD_EPS` of its magnitude (the
    /// expansion's roundings and the data's own), which bounds the factors' error.
    pub numerator: Vec<(CDd, f64)>,
    /// See [`EntryFactors::numerator`].
    pub denominator: Vec<(CDd, f64)>,
}

/// A polynomial in `s` (ascending coefficients) with the magnitude sums of its coefficients.
#[derive(Clone, Debug)]
struct Poly {
    c: Vec<CDd>,
    mag: Vec<f64>,
}

impl Poly {
    fn zero() -> Poly {
        Poly {
            c: Vec::new(),
            mag: Vec::new(),
        }
    }

    fn is_zero(&self) -> bool {
        self.c.iter().all(|c| c.is_zero())
    }

    fn mul(&self, o: &Poly) -> Poly {
        if self.c.is_empty() || o.c.is_empty() {
            return Poly::zero();
        }
        let n = self.c.len() + o.c.len() - 1;
        let mut c = vec![CDd::ZERO; n];
        let mut mag = vec![0.0; n];
        for (i, (a, ma)) in self.c.iter().zip(&self.mag).enumerate() {
            if a.is_zero() {
                continue;
            }
            for (j, (b, mb)) in o.c.iter().zip(&o.mag).enumerate() {
                if b.is_zero() {
                    continue;
                }
                c[i + j] += *a * *b;
                mag[i + j] += ma * mb;
            }
        }
        Poly { c, mag }
    }

    fn add_signed(&mut self, o: &Poly, negate: bool) {
        if self.c.len() < o.c.len() {
            self.c.resize(o.c.len(), CDd::ZERO);
            self.mag.resize(o.c.len(), 0.0);
        }
        for (k, (b, mb)) in o.c.iter().zip(&o.mag).enumerate() {
            if negate {
                self.c[k] -= *b;
            } else {
                self.c[k] += *b;
            }
            self.mag[k] += mb;
        }
    }
}

/// Determinant of the leading `n x n` part of the square matrix of polynomials `a`, by Laplace
/// expansion along the first row, each minor along its own first row, columns in increasing
/// order. Minors are computed once each (by the set of columns they keep: the rows are the
/// last ones), which makes the expansion of an 8x8 or 9x9 matrix cost `2^n n` products
/// instead of `n!`; the arithmetic is that of the plain recursion.
fn det(a: &[Vec<Poly>], n: usize) -> Poly {
    let mut minors: Vec<Poly> = vec![Poly::zero(); 1 << n];
    for mask in 1_usize..1 << n {
        let size = mask.count_ones() as usize;
        let row = n - size;
        let cols = (0..n).filter(|c| mask & (1 << c) != 0);
        if size == 1 {
            minors[mask] = a[row][mask.trailing_zeros() as usize].clone();
            continue;
        }
        let mut acc = Poly::zero();
        for (k, c) in cols.enumerate() {
            let e = &a[row][c];
            if e.is_zero() {
                continue;
            }
            acc.add_signed(&e.mul(&minors[mask & !(1 << c)]), k % 2 == 1);
        }
        minors[mask] = acc;
    }
    minors.pop().unwrap_or_else(Poly::zero)
}

fn lin(c0: CDd, c1: CDd) -> Poly {
    lin_scaled(c0, c0.abs_f64(), c1, c1.abs_f64())
}

/// `c0 + c1 s` whose coefficients carry the rounding scales `m0`, `m1`.
fn lin_scaled(c0: CDd, m0: f64, c1: CDd, m1: f64) -> Poly {
    Poly {
        c: vec![c0, c1],
        mag: vec![m0, m1],
    }
}

/// The rounding scales of the data of the pendulum as built ([`Scales`]) after the change to
/// absolute test-mass angles: the scale of a difference is the sum of its terms' scales.
struct Scaled {
    mass: [[f64; 8]; 8],
    stiffness: [[f64; 8]; 8],
    /// Per request input: the forcing's scales, frequency-independent and per `w^2`.
    forcing: Vec<([f64; 8], [f64; 8])>,
    /// Per request output.
    observation: Vec<[f64; 8]>,
}

impl Scaled {
    fn new(scales: Option<&Scales>, request: &Request) -> Option<Scaled> {
        let s = scales?;
        let rows = |col: [f64; 8]| {
            let mut out = col;
            for (a, b) in PAIRS {
                out[a] = col[a] + col[b];
            }
            out
        };
        Some(Scaled {
            mass: abs_matrix_scale(&s.mass),
            stiffness: abs_matrix_scale(&s.stiffness),
            forcing: request
                .inputs
                .iter()
                .map(|input| match input {
                    Input::Tilt(t) => (
                        rows(std::array::from_fn(|r| s.g0[r][t.index()])),
                        rows(std::array::from_fn(|r| s.g2[r][t.index()])),
                    ),
                    Input::Translation(t) => (
                        [0.0; 8],
                        rows(std::array::from_fn(|r| s.translation_g2[r][t.index()])),
                    ),
                    Input::Force(f) => (
                        rows(std::array::from_fn(|r| s.force[r][f.index()])),
                        [0.0; 8],
                    ),
                })
                .collect(),
            observation: request
                .outputs
                .iter()
                .map(|o| {
                    let row = s.observation[o.index()];
                    let mut out = row;
                    for (a, b) in PAIRS {
                        out[a] = row[a] + row[b];
                    }
                    out
                })
                .collect(),
        })
    }
}

/// [`abs_matrix`] of the scales: sums where it takes differences.
fn abs_matrix_scale(m: &[[f64; 8]; 8]) -> [[f64; 8]; 8] {
    let mut a = *m;
    for row in a.iter_mut() {
        let orig = *row;
        for (ca, cb) in PAIRS {
            row[ca] = orig[ca] + orig[cb];
        }
    }
    let b = a;
    for (ra, rb) in PAIRS {
        for c in 0..8 {
            a[ra][c] = b[ra][c] + b[rb][c];
        }
    }
    a
}

/// Evaluates the polynomial and its derivative (ascending coefficients) at `z` in double-double.
fn horner_dd(c: &[CDd], z: CDd) -> (CDd, CDd) {
    let mut p = CDd::ZERO;
    let mut dp = CDd::ZERO;
    for &a in c.iter().rev() {
        dp = dp * z + p;
        p = p * z + a;
    }
    (p, dp)
}

fn horner(c: &[Complex64], z: Complex64) -> (Complex64, Complex64) {
    let mut p = Complex64::new(0.0, 0.0);
    let mut dp = p;
    for &a in c.iter().rev() {
        dp = dp * z + p;
        p = p * z + a;
    }
    (p, dp)
}

/// Roots of the polynomial with ascending double-double coefficients `c` (nonzero constant and
/// leading terms): Aberth in `f64` from the Newton-polygon magnitudes, then Aberth steps in
/// double-double until the corrections are below double-double precision.
fn roots(c: &[CDd]) -> Vec<CDd> {
    let n = c.len() - 1;
    if n == 0 {
        return Vec::new();
    }
    let cf: Vec<Complex64> = c.iter().map(|x| x.to_c64()).collect();
    // Starting magnitudes: ratios of consecutive coefficient magnitudes (exact for widely
    // separated roots), on rotated angles so that complex pairs can be found.
    let mut z: Vec<Complex64> = (0..n)
        .map(|k| {
            let r = (cf[k].norm() / cf[k + 1].norm()).max(1e-300);
            Complex64::from_polar(r, 0.4 + 2.0 * std::f64::consts::PI * k as f64 / n as f64)
        })
        .collect();
    for _ in 0..500 {
        let mut done = true;
        for k in 0..n {
            let (p, dp) = horner(&cf, z[k]);
            if p.norm() == 0.0 {
                continue;
            }
            let w = p / dp;
            let s: Complex64 = (0..n)
                .filter(|&j| j != k)
                .map(|j| 1.0 / (z[k] - z[j]))
                .sum();
            let step = w / (1.0 - w * s);
            if step.is_finite() {
                z[k] -= step;
                if step.norm() > 1e-15 * z[k].norm() {
                    done = false;
                }
            }
        }
        if done {
            break;
        }
    }
    let mut zd: Vec<CDd> = z.iter().map(|&x| CDd::from_c64(x)).collect();
    for _ in 0..8 {
        for k in 0..n {
            let (p, dp) = horner_dd(c, zd[k]);
            if p.is_zero() {
                continue;
            }
            let w = p / dp;
            let mut s = CDd::ZERO;
            for j in 0..n {
                if j != k {
                    s += CDd::real(Dd::ONE) / (zd[k] - zd[j]);
                }
            }
            let step = w / (CDd::real(Dd::ONE) - w * s);
            if step.is_finite() {
                zd[k] -= step;
            }
        }
    }
    zd
}

/// For real coefficients: make nearly real roots exactly real and complex roots exact
/// conjugate pairs.
fn symmetrize(z: &mut [CDd]) {
    let n = z.len();
    for x in z.iter_mut() {
        if x.im.hi.abs() <= 1e-20 * x.abs_f64() {
            x.im = Dd::ZERO;
        }
    }
    for k in 0..n {
        if z[k].im.hi > 0.0 {
            // The partner: the root nearest to the conjugate.
            let conj = z[k].conj();
            if let Some(j) = (0..n)
                .filter(|&j| z[j].im.hi < 0.0)
                .min_by(|&a, &b| (z[a] - conj).abs_f64().total_cmp(&(z[b] - conj).abs_f64()))
            {
                let re = (z[k].re + z[j].re).ldexp(-1);
                let im = (z[k].im - z[j].im).ldexp(-1);
                z[k] = CDd::new(re, im);
                z[j] = CDd::new(re, -im);
            }
        }
    }
}

/// Pairs (crossbar angle, relative test-mass angle), full indices.
const PAIRS: [(usize, usize); 3] = [(0, 4), (1, 5), (2, 6)];

fn abs_matrix<T: Copy + std::ops::Sub<Output = T>>(m: &[[T; 8]; 8]) -> [[T; 8]; 8] {
    let mut a = *m;
    for row in a.iter_mut() {
        let orig = *row;
        for (ca, cb) in PAIRS {
            row[ca] = orig[ca] - orig[cb];
        }
    }
    let b = a;
    for (ra, rb) in PAIRS {
        for c in 0..8 {
            a[ra][c] = b[ra][c] - b[rb][c];
        }
    }
    a
}

impl PoleZero {
    /// Builds the product forms of every entry of `request` (about a millisecond per block).
    pub fn new(model: &Model, request: Request) -> PoleZero {
        let factors = Self::factors(model.params(), &request);
        let n_in = request.inputs.len();
        let n_values = request.outputs.len() * n_in;
        let dense = Self::blocks(&factors, n_in, &|at| (2 * at, 2 * at + 1));
        let mut nonzero = vec![false; n_values];
        for f in &factors {
            nonzero[f.output * n_in + f.input] = true;
        }
        let all_real = dense
            .iter()
            .all(|b| matches!(b, BlockForm::Real(_) | BlockForm::Real8(_)));
        let layout = Layout::compact(&nonzero, all_real);
        let compact = Self::blocks(&factors, n_in, &|at| match layout.position(at) {
            // A real layout has only real blocks, which never write the imaginary part.
            (Some(re), im) => (re, im.unwrap_or(usize::MAX)),
            (None, _) => unreachable!("entry {at} has factors, so a slot"),
        });
        PoleZero {
            kernel: Kernel::new(dense, 2 * n_values),
            compact: Kernel::new(compact, layout.n_planes()),
            layout,
            request,
        }
    }

    /// The kernel's blocks for `factors`, entry `at = output * n_in + input` written at the
    /// `f64` positions `position(at) = (re, im)` of each point.
    fn blocks(
        factors: &[EntryFactors],
        n_in: usize,
        position: &dyn Fn(usize) -> (usize, usize),
    ) -> Vec<BlockForm> {
        [Some(Block::SwingYBounce), Some(Block::SwingXTorsion), None]
            .into_iter()
            .filter_map(|block| {
                let fs: Vec<&EntryFactors> = factors.iter().filter(|f| f.block == block).collect();
                fs.first()?;
                Some(match block {
                    Some(_) => block_form::<4>(&fs, n_in, position).map_or_else(
                        |(poles, entries)| BlockForm::Complex(ComplexBlock::new(poles, entries)),
                        |(poles, entries)| BlockForm::Real(RealBlock::new(poles, entries)),
                    ),
                    None => block_form::<8>(&fs, n_in, position).map_or_else(
                        |(poles, entries)| BlockForm::Complex8(ComplexBlock::new(poles, entries)),
                        |(poles, entries)| BlockForm::Real8(RealBlock::new(poles, entries)),
                    ),
                })
            })
            .collect()
    }

    /// The factored form in double-double of every entry (and block) of `request` that is not
    /// structurally zero.
    pub fn factors(params: &Params, request: &Request) -> Vec<EntryFactors> {
        let (m, scales): (Matrices, Option<Scales>) = crate::geometry::dd_matrices(params);
        let mass = abs_matrix(&m.mass);
        let stiffness = abs_matrix(&m.stiffness);
        // T^T on forcing rows, C T on observation columns.
        let to_abs_rows = |col: [Dd; 8]| -> [Dd; 8] {
            let mut out = col;
            for (a, b) in PAIRS {
                out[a] = col[a] - col[b];
            }
            out
        };
        let obs: Vec<[Dd; 8]> = request
            .outputs
            .iter()
            .map(|o| {
                let row = m.observation[o.index()];
                let mut out = row;
                for (a, b) in PAIRS {
                    out[a] = row[a] - row[b];
                }
                out
            })
            .collect();
        let forcing: Vec<([Dd; 8], [Dd; 8])> = request
            .inputs
            .iter()
            .map(|input| match input {
                Input::Tilt(t) => (
                    to_abs_rows(std::array::from_fn(|r| m.g0[r][t.index()])),
                    to_abs_rows(std::array::from_fn(|r| m.g2[r][t.index()])),
                ),
                Input::Translation(t) => (
                    [Dd::ZERO; 8],
                    to_abs_rows(std::array::from_fn(|r| m.translation_g2[r][t.index()])),
                ),
                Input::Force(f) => (
                    to_abs_rows(std::array::from_fn(|r| m.force[r][f.index()])),
                    [Dd::ZERO; 8],
                ),
            })
            .collect();
        // The rounding scale of each transformed datum: a sum of the scales of the terms
        // (asymmetric), or its own magnitude (the closed forms).
        let scale = Scaled::new(scales.as_ref(), request);
        let mut out = Vec::new();
        for (block, idx) in groups(&m) {
            let n = idx.len();
            let mut a: Vec<Vec<Poly>> = (0..=n)
                .map(|r| {
                    (0..=n)
                        .map(|c| {
                            if r < n && c < n {
                                let (i, j) = (idx[r], idx[c]);
                                let (k, m) = (stiffness[i][j], CDd::real(-mass[i][j]));
                                match &scale {
                                    Some(sc) => lin_scaled(k, sc.stiffness[i][j], m, sc.mass[i][j]),
                                    None => lin(k, m),
                                }
                            } else {
                                Poly::zero()
                            }
                        })
                        .collect()
                })
                .collect();
            let p = det(&a, n);
            let poles = roots(&p.c);
            let mut poles_sorted = poles;
            poles_sorted.sort_by(|x, y| x.re.hi.total_cmp(&y.re.hi));
            let undamped_block = p.c.iter().all(|c| c.im.is_zero());
            if undamped_block {
                symmetrize(&mut poles_sorted);
            }
            let det_m = p.c[n];
            for (o, c_row) in obs.iter().enumerate() {
                let c_b: Vec<Dd> = idx.iter().map(|&k| c_row[k]).collect();
                if c_b.iter().all(|x| x.is_zero()) {
                    continue;
                }
                for (i, (g0, g2)) in forcing.iter().enumerate() {
                    let g0b: Vec<Dd> = idx.iter().map(|&k| g0[k]).collect();
                    let g2b: Vec<Dd> = idx.iter().map(|&k| g2[k]).collect();
                    if g0b.iter().chain(&g2b).all(|x| x.is_zero()) {
                        continue;
                    }
                    for k in 0..n {
                        let (g0, g2, c) = (CDd::real(g0b[k]), CDd::real(g2b[k]), CDd::real(c_b[k]));
                        (a[k][n], a[n][k]) = match &scale {
                            Some(sc) => (
                                lin_scaled(
                                    g0,
                                    sc.forcing[i].0[idx[k]],
                                    g2,
                                    sc.forcing[i].1[idx[k]],
                                ),
                                lin_scaled(c, sc.observation[o][idx[k]], CDd::ZERO, 0.0),
                            ),
                            None => (lin(g0, g2), lin(c, CDd::ZERO)),
                        };
                    }
                    let mut num = det(&a, n + 1);
                    for c in num.c.iter_mut() {
                        *c = -*c;
                    }
                    let mut cancelled = Vec::new();
                    for (k, (c, m)) in num.c.iter_mut().zip(&num.mag).enumerate() {
                        let rel = c.abs_f64() / m;
                        if !c.is_zero() && rel <= ZERO_REL {
                            cancelled.push((k, rel));
                            *c = CDd::ZERO;
                        }
                    }
                    let Some(top) = num.c.iter().rposition(|c| !c.is_zero()) else {
                        continue;
                    };
                    let power = num.c.iter().position(|c| !c.is_zero()).unwrap_or(0);
                    let reduced = &num.c[power..=top];
                    let mut zeros = roots(reduced);
                    if reduced.iter().all(|c| c.im.is_zero()) {
                        symmetrize(&mut zeros);
                    }
                    let nz = zeros.len();
                    let sign = if nz % 2 == 1 { -1.0 } else { 1.0 };
                    let gain = (num.c[top] / det_m).scale(Dd::from_f64(sign));
                    out.push(EntryFactors {
                        output: o,
                        input: i,
                        block,
                        gain,
                        power: power as u32,
                        zeros,
                        poles: poles_sorted.clone(),
                        cancelled,
                        numerator: num.c.iter().copied().zip(num.mag.iter().copied()).collect(),
                        denominator: p.c.iter().copied().zip(p.mag.iter().copied()).collect(),
                    });
                }
            }
        }
        out
    }
}

/// The independent systems of `m`: the two blocks of [`Block`] when no entry of `M`, `K_c` or
/// the viscous damping couples them (the symmetric pendulum, or offsets that keep its mirror
/// plane), else the whole coupled system (`None`). Full indices of each system's coordinates.
fn groups(m: &Matrices) -> Vec<(Option<Block>, Vec<usize>)> {
    let [a, b] = Block::ALL.map(|block| block.coords().map(Coord::index));
    let coupled = a.iter().any(|&i| {
        b.iter().any(|&j| {
            [(i, j), (j, i)].iter().any(|&(r, c)| {
                !(m.mass[r][c].is_zero()
                    && m.stiffness[r][c].is_zero()
                    && m.damping[r][c].is_zero())
            })
        })
    });
    if coupled {
        vec![(None, (0..8).collect())]
    } else {
        Block::ALL
            .into_iter()
            .map(|block| (Some(block), block.coords().map(Coord::index).to_vec()))
            .collect()
    }
}

impl TransferFunction for PoleZero {
    fn method(&self) -> Method {
        Method::PoleZero
    }

    fn request(&self) -> &Request {
        &self.request
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        self.eval_grid_into(std::slice::from_ref(&freq_hz), out)
    }

    /// The whole grid in chunks of frequencies (see the module docs): the same values, bit
    /// for bit, as [`TransferFunction::eval_into`] at each point, and the same error.
    fn eval_grid_into(&self, freqs_hz: &[f64], out: &mut [Complex64]) -> Result<(), TfError> {
        self.eval_grid_into_dest(freqs_hz, out, Destination::Reused)
    }

    /// Non-temporal stores for a large output unless it is [`Destination::Fresh`].
    fn eval_grid_into_dest(
        &self,
        freqs_hz: &[f64],
        out: &mut [Complex64],
        destination: Destination,
    ) -> Result<(), TfError> {
        super::check_grid_len(&self.request, freqs_hz, out);
        self.kernel
            .eval_grid(freqs_hz, as_f64_mut(out), destination)
    }

    /// Only the entries some block reaches, in entry order; real (one `f64` per entry) when
    /// every block is real (undamped, real zeros). The 7x3 tilt matrix of Table I: 11 real
    /// entries, 88 bytes per frequency.
    fn layout(&self) -> Layout {
        self.layout.clone()
    }

    /// The same operations as [`TransferFunction::eval_grid_into`] (bit-identical values, the
    /// same errors), stored in [`PoleZero::layout`].
    fn eval_grid_layout_into(
        &self,
        freqs_hz: &[f64],
        planes: &mut [&mut [f64]],
    ) -> Result<(), TfError> {
        self.compact.eval_planes(freqs_hz, planes)
    }
}

/// The `re, im` pairs of `z` as consecutive `f64`.
fn as_f64_mut(z: &mut [Complex64]) -> &mut [f64] {
    // SAFETY: `Complex64` is `repr(C)` `{re: f64, im: f64}` (size 16, alignment 8, no
    // padding): `z` is `2 z.len()` initialized, 8-byte aligned `f64`, any value of which is a
    // valid `Complex64` part; the result borrows `z` mutably for its lifetime.
    unsafe { std::slice::from_raw_parts_mut(z.as_mut_ptr().cast::<f64>(), 2 * z.len()) }
}
