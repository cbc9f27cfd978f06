//! The named tolerances of the integration tests, each with its derivation: machine epsilon
//! times the size of the problem (the `gamma_n = n eps` of a rounding-error analysis), scaled by
//! the conditioning of what is computed where the test says so. The command line's test binary
//! includes this very file (`tests/it/main.rs`), so both binaries check against the same
//! numbers. Values the library itself defines are taken from it.
//!
//! Tolerances that belong to a single test and are not rounding bounds (a finite-difference
//! step, a statistical allowance in standard errors) stay with that test.
// Each test binary uses a different subset of these constants.
#![allow(dead_code)]

use tiltnoise_core::tf;

/// Machine epsilon of f64, `2^-52`: the spacing of f64 at 1.
pub const EPS: f64 = f64::EPSILON;

/// Unit roundoff of f64, `eps / 2 = 2^-53`: the relative error of one correctly rounded
/// operation.
pub const U: f64 = EPS / 2.0;

/// Relative error of `s = w^2 = (2 pi f)^2` formed in f64 from the f64 `2 pi` (as the pole-zero
/// kernel forms it), against the exact `s` of the reference: the rounding of `2 pi` (0.35 u)
/// and of the product with `f` (u) each count twice through the square, the square's own rounding
/// once: `3.7 u`, rounded up to `4 u`.
pub const OMEGA_SQ_REL: f64 = 4.0 * U;

/// Unknowns of the full system: the 8 coordinates of the pendulum.
pub const N_DOF: f64 = 8.0;

/// `gamma_3n` with `n = 8`: componentwise backward error of an LU solve of the 8x8 dynamic
/// stiffness (factorization and two triangular solves, at most `3n` roundings per entry). Times
/// an entry's componentwise (Skeel) condition number it bounds the entry's error; it is also the
/// normwise relative error of the equilibrated LU per unit condition number.
pub const LU_GAMMA: f64 = 3.0 * N_DOF * EPS;

/// `gamma_3n` with `n = 16`: the state-space method's LU solves of the 16x16 `i w I - A`; also
/// used, generously, for its 8x8 solves with `M`.
pub const SS_GAMMA: f64 = 3.0 * 16.0 * EPS;

/// `2n eps` with `n = 4` per block: normwise backward error of the block eigensolver (the
/// Cholesky reduction `L^-1 K L^-T` and the symmetric eigensolver) per unit `lambda_max`. By Weyl
/// it bounds an eigenvalue's error; by Davis-Kahan, divided by the gap to the nearest eigenvalue
/// of the same block, a mode shape's error in the M norm.
pub const EIG_GAMMA: f64 = 8.0 * EPS;

/// Constant `c` of the eigen residual bound `c n eps (|K| + |lambda| |M|) |v| cond(M_block)^(1/2)`
/// (`n = 4` per block; the square root of the condition of `M` is what the Cholesky reduction
/// adds): `c = 4` covers the three stages (Cholesky, triangular inverse, symmetric QR) with their
/// small constants.
pub const EIG_RESIDUAL_C: f64 = 4.0;

/// `2n eps` with `n = 8`: rounding of a modal sum itself, a projection `v^T G` of length `n` and
/// a sum over `n` modes.
pub const SUM_GAMMA: f64 = 2.0 * N_DOF * EPS;

/// Rounding of a scaled parameter set's effect on the model data: each matrix entry is a product
/// of at most three parameters (`m g L`, `m L^2`, `m L h`), each rounded once (`eps / 2`), summed
/// with entries of the same scale: at most `4 eps` relative per datum, hence `DATA_GAMMA kappa`
/// per transfer-function entry (`kappa` its condition number with respect to the data).
pub const DATA_GAMMA: f64 = 4.0 * EPS;

/// The accuracy target of every transfer function: relative error of every structurally nonzero
/// entry against the double-double reference, outside [`POLE_EXCLUSION`] of the entry's own poles
/// and zeros. It is the planner's default tolerance (`tf::DEFAULT_REL_TOL`), the one `auto` is
/// asked to meet; 1e-9 is far above any method's `eps kappa` away from the poles and zeros.
pub const TARGET_REL: f64 = tf::DEFAULT_REL_TOL;

/// Half-width, relative in frequency, of the zone around an entry's own poles and zeros that
/// [`TARGET_REL`] excludes (`tf::POLE_EXCLUSION`, 1 %): there the entry's condition number grows
/// as `1 / |f - f_pole|`, and at 1 % it is about 100 times its value away from the pole.
pub const POLE_EXCLUSION: f64 = tf::POLE_EXCLUSION;

/// Rounding of a coefficient of the pole-zero method's polynomials `N(s)`, `P(s)` (Laplace
/// expansions of a 9x9 matrix of linear polynomials, in double-double) in units of `DD_EPS`
/// times the coefficient's magnitude (the sum of the magnitudes of its terms): each term is a
/// product of at most 9 data, each within `CLEAN_DEPTH = 64` of its own scale (the exact
/// kinematics' depth), and the expansion adds about `3 x 9` roundings along a path:
/// `64 x 9 + 27 = 603`, rounded up.
pub const POLYNOMIAL_GAMMA: f64 = 640.0;

/// Allowed error of a double-double reference entry in units of `DD_EPS kappa` (`kappa` the
/// entry's condition number): the longest chain of double-double operations behind one datum
/// (about 12) plus the solve's componentwise backward error, rounded up. The measured maximum is
/// about 0.2.
pub const DD_REF_FACTOR: f64 = 16.0;

/// Allowed error of the f64 direct method on an entry, in units of `EPS kappa_paper`
/// (`kappa_paper` the entry's condition number in the paper's coordinates, with which the direct
/// method works): the LU backward-error constant `gamma_3n = 3n` (n = 8) times the worst-case
/// growth factor `2^(n-1)` of partial pivoting. Not a rigorous componentwise bound for an
/// unrefined LU, but the textbook constants; the measured ratio is about 2 on the tilt grid and
/// about 200 for phi/F_b.x at 10 Hz in the damped case.
pub const DIRECT_TOL_FACTOR: f64 = 3.0 * N_DOF * 128.0;

/// Rounding-bound factor of the energy cross-check, `|lib - ref| <= ENERGY_C_TOL eps mag`: by
/// running error analysis an entry computed in `n` floating-point steps is off by at most
/// `n eps mag`, `mag` being the sum of `|terms|` entering it. A reference entry takes at most ~40
/// steps along any path (rotation entry 5, `A_b = R_a^T R_b^T` 5, position 6, energy and dot
/// products ~10, Jacobian contractions ~10) and a library entry fewer than ~10, so
/// `n_ref + n_lib < 50 <= 64`; a genuine modelling error is O(mag), 1e13 times larger.
pub const ENERGY_C_TOL: f64 = 64.0;

/// A CSV written with shortest round-trip decimals parses back exactly; this allows the
/// last-bit differences of the decimal conversion only.
pub const CSV_ROUND_TRIP: f64 = 4.0 * EPS;

/// Two log-log interpolations between the same table rows differ only by rounding: about ten
/// roundings of relative eps in the conversion chain, amplified by `|ln ASD|` (~23 for 1e-10)
/// through `exp(ln)`: `64 eps * 32 ~ 4.5e-13`.
pub const LOGLOG_REL: f64 = 64.0 * 32.0 * EPS;

/// Relative agreement required of Welch PSD and CSD with `scipy.signal`. Both sides compute in
/// double precision but with different FFTs (pocketfft vs rustfft), different window scaling
/// order and different summation orders. A radix-2/mixed-radix FFT has a normwise relative error
/// of order `eps * log2(n)` (~2e-16 * 10 for the test lengths); a periodogram value doubles that,
/// and averaging over at most ~40 segments adds at most `n_seg * eps` more. The expected
/// discrepancy is therefore ~1e-14 at worst, and 1e-10 leaves a wide margin while any convention
/// error (scale, doubling, window, bias, conjugation) shows up at >= 1e-3. (Observed: see the
/// `max normalised error` line printed by `scipy_fixtures_match`; about 1e-14.)
pub const WELCH_REL: f64 = 1e-10;

/// Bins smaller than `WELCH_FLOOR_FRAC` times the largest magnitude of the same spectrum are
/// compared against that floor instead of their own magnitude, i.e. with an absolute tolerance of
/// `WELCH_REL * WELCH_FLOOR_FRAC * max = 1e-13 * max`. FFT rounding errors are absolute
/// (relative to the norm of the segment, not to the bin), so the relative error of a bin far
/// below the maximum grows like `sqrt(max / bin)`; cross spectra of weakly correlated channels
/// and their imaginary parts also pass arbitrarily close to zero. Above `1e-3 * max` the test is
/// purely relative.
pub const WELCH_FLOOR_FRAC: f64 = 1e-3;

/// Agreement required between this crate's budget pipeline and the independent SciPy + mpmath
/// one, relative per bin: the criterion for equal results. The spectral parts agree with SciPy
/// to ~1e-14 ([`WELCH_REL`]) and the budget's transfer functions with the reference to ~1e-11,
/// so 1e-8 leaves a wide margin rather than being tuned to it.
pub const PIPELINE_REL: f64 = 1e-8;

/// Floor of the pipeline comparison for bins far below a spectrum's peak, as a fraction of the
/// peak: FFT rounding is normwise (`log2 n FFT_STAGE_REL ~ 5e-15` of a segment's norm), so a PSD
/// bin is off by up to `2 * 5e-15 * ||X|| / |X_peak| <= 1e-14 sqrt(n_bins) ~ 3e-13` of the peak
/// (1025 bins), and the rate-to-angle division by `(2 pi f)^2` only lowers the bins above the
/// (red) peak; 1e-11 is a wide margin.
pub const PEAK_FLOOR: f64 = 1e-11;

/// Normwise relative error of an f64 FFT per stage (`log2 n` stages): Higham, *Accuracy and
/// Stability of Numerical Algorithms* (2002), Thm 24.2, for radix-2 Cooley-Tukey with twiddle
/// factors correct to `u`: `||dy|| / ||y|| <= log2(n) eta`, `eta = u + gamma_4 (sqrt 2 + u)`
/// `~ 6.7 u = 3.4 eps`, rounded up to 4 eps (rustfft's mixed-radix butterflies have the same
/// per-stage structure).
pub const FFT_STAGE_REL: f64 = 4.0 * EPS;

/// Absolute error of one sampled sinusoid `A cos(2 pi j / N + phase)` (or `sin`), per unit of
/// `A`, with `j = m n mod N` exact: the argument, at most `4 pi` in magnitude, is formed with two
/// roundings (absolute error `<= 2 * 4 pi u`, passed on with slope `<= 1`), `cos` is faithful
/// (1 ulp) and the product with `A` rounds once: `8 pi u + 3 u < 29 u`, rounded up to `32 u`.
pub const TONE_SAMPLE_ABS: f64 = 32.0 * U;

/// Relative error of `spectral::band_dof` for segments of up to 2^16 samples and bands of up to
/// 1000 bins: each `|rho|^2` comes from an FFT (`2 log2 n FFT_STAGE_REL` = 32 x 4 eps, relative
/// to the largest term, which dominates the sum) and the weighted sum has up to 6000 rounded
/// terms (6000 u): 1.4e-12, rounded up to 2e-12.
pub const DOF_REL: f64 = 2e-12;
/// Agreement of coherence with `scipy.signal.coherence`, absolute on its `[0, 1]` scale: the
/// ratio `|S_xy|^2 / S_xx / S_yy` of Welch values that are each within [`WELCH_REL`] of scipy's
/// is within `4 WELCH_REL` relative, and coherence is at most 1.
pub const COHERENCE_ABS: f64 = 4.0 * WELCH_REL;

/// Agreement of multiple-input estimates (transfer functions, multiple coherence, residual PSD)
/// with `numpy.linalg.solve` on scipy's CSD matrix, per unit condition number of the normalized
/// input matrix: the data of the two solves differ by [`WELCH_REL`] (this crate's Welch values
/// against scipy's), which a solve amplifies by at most the condition number, once through the
/// matrix and once through the right-hand side.
pub const MIMO_REL_PER_COND: f64 = 2.0 * WELCH_REL;

/// Relative rounding of a sum of at most 128 products of window values (a lag product of a
/// Welch segment of up to 128 samples, or its energy): `gamma_n = n eps` with one rounding per
/// product and per addition, `n = 2 x 128`.
pub const WINDOW_SUM_REL: f64 = 256.0 * EPS;

/// The published bound of Acklam's rational approximation of the normal quantile, relative:
/// the approximation error itself, far above the rounding of its evaluation.
pub const NORMAL_QUANTILE_REL: f64 = 1.15e-9;

/// Agreement of the F(2, m) and Beta(q, n - q) quantiles with scipy.stats, relative: a closed
/// form or a tail sum of at most 3 terms, each a few roundings (`~8 eps`), is inverted through
/// `x f(x) / S(x)` (density over tail), which stays below `n` = 500 for the test cases, and
/// `1 - alpha^(1/(n-1))` cancels by up to the same factor: `500 x 8 eps ~ 1e-12`, times 10
/// for scipy's own error.
pub const QUANTILE_REL: f64 = 1e-11;

/// Welch bin frequencies computed as `k fs / L` here and `k / (L / fs)` by scipy: each side
/// rounds twice, so they agree to `2 eps` relative.
pub const BIN_FREQ_REL: f64 = 2.0 * EPS;

/// Relative error of a floor column below [`tf::EXACT_BELOW_HZ`] against the split method's
/// asymptote (`tests/it/low_frequency.rs`): the split method's own error outside the poles'
/// zones (`4e-13`, its row of the table in `tf`), the pole-zero factors' (`3e-14`, same table),
/// and the logarithms the reference is formed in (`ln |H|` up to ~745, each rounding `u` of it:
/// `745 * 2 u = 1.7e-13`), summed and rounded up: `1e-12`. The asymptote's own correction at
/// the frequencies it is taken from is measured by the test and added.
pub const LOW_FREQ_REL: f64 = 1e-12;

/// One unit in the last place of the subnormal range, `2^-1074`: a value below the normal
/// range rounded once (half a unit) plus the reference's relative error on it (less than half
/// a unit there).
pub const SUBNORMAL_ABS: f64 = 5e-324;

/// Per-segment budget PSD by projection (`|sum_c g_c X_c|^2` per Welch segment) against the
/// cross-spectral matrix carried through the ground map and propagated (`h^H S h`), in units
/// of `eps (n^2 + n_seg) B^2`, `B = sum_c |g|_c sqrt(S_cc)` (`S_cc` the channels' PSDs, `|g|`
/// the map's weights taken in absolute value). Both sum the same `n_seg` segments (`n_seg u`
/// of the sum of the moduli each, which Cauchy-Schwarz bounds by `B^2`); the matrix road rounds
/// each of the `n (n + 1) / 2` products `conj(X_i) X_j` (a complex product: `sqrt(2) 2 u`),
/// scales and corrects them (one product and one sum each, `2 u`), and propagates them (a
/// triple complex product and a doubling each, `3 sqrt(2) 2 u`, summed over `n^2` terms:
/// `n^2 u`); the projection rounds `n` complex products and their sum, and a square. Every term
/// is at most `(2 + 2 + 9) u <= 8 eps` of its bound `B^2` per unit of `n^2 + n_seg`.
pub const PROJECTION_C: f64 = 8.0;

/// The unit roundoff of `f32`, in which a budget keeps its per-segment PSDs: one rounding of
/// the value.
pub const F32_U: f64 = f32::EPSILON as f64 / 2.0;
