//! Statistics of Welch estimates: the equivalent number of independent averages of an
//! overlapped Welch mean, and the sampling distributions behind the confidence intervals of
//! coherence and transfer-function estimates ([`super::coherence`], [`super::multiple_input`]).
//!
//! # The number of averages
//!
//! A Welch mean of `K` periodograms of segments that overlap is less stable than a mean of `K`
//! independent ones. For Gaussian data whose spectrum is flat across a window's resolution,
//! Welch (1967) gives the normalized variance of the mean as
//!
//! ```text
//! Var / E^2 = (1/K) [1 + 2 sum_{j=1}^{K-1} (1 - j/K) rho(j S)^2],
//! rho(tau) = sum_n w[n] w[n + tau] / sum_n w[n]^2        (0 for tau >= L)
//! ```
//!
//! (`L` the segment length, `S` the step between segment starts). A mean of `n_d` independent
//! periodograms has `Var / E^2 = 1 / n_d`, so [`equivalent_averages`] returns
//! `n_d = 1 / (Var / E^2)`: for the periodic Hann window at 50 % overlap `rho = 1/6` and
//! `n_d -> 0.947 K`. Every formula below takes this `n_d` as its number of averages.
//!
//! # Distributions
//!
//! * `F(2, m)`: the upper `alpha` point has the closed form `(m/2) (alpha^(-2/m) - 1)`
//!   ([`f2_upper_quantile`]).
//! * `Beta(q, n - q)` with integer `q`: its upper tail is the finite sum
//!   `sum_{j=0}^{q-1} C(n-1, j) x^j (1-x)^(n-1-j)` with generalized binomial coefficients,
//!   valid for any real `n > q` ([`beta_upper_tail`]), inverted by bisection.
//! * Standard normal quantile: Acklam's rational approximation, relative error below
//!   `1.15e-9` ([`normal_quantile`]).
//!
//! # Confidence intervals
//!
//! [`tf_radius`] and [`tf_sigma`] (transfer functions), [`coherence_threshold`] and
//! [`coherence_interval`] (coherence) state their formulas and sources. All assume Gaussian
//! data, spectra flat across a bin, and `n_d` from [`equivalent_averages`]; none corrects the
//! resolution bias of the window (a spectral feature narrower than a few bins).

use super::window::hann_periodic;
use super::WelchConfig;

/// Equivalent number of independent averages `n_d` of a Welch mean of `n_segments` periodic
/// Hann segments with the overlap of `cfg` (module docs; Welch 1967). Equals `n_segments`
/// without overlap, and never exceeds it.
pub fn equivalent_averages(cfg: &WelchConfig, n_segments: usize) -> f64 {
    let k = n_segments as f64;
    if n_segments <= 1 {
        return k;
    }
    let w = hann_periodic(cfg.segment_len);
    let energy: f64 = w.iter().map(|v| v * v).sum();
    let step = cfg.step().max(1);
    let mut sum = 0.0;
    for j in 1..n_segments {
        let lag = j * step;
        if lag >= w.len() {
            break;
        }
        let rho: f64 = w.iter().zip(&w[lag..]).map(|(a, b)| a * b).sum::<f64>() / energy;
        sum += (1.0 - j as f64 / k) * rho * rho;
    }
    k / (1.0 + 2.0 * sum)
}

/// Correlation `c_j` of the estimation errors of Welch bins `j = 0, 1, 2` apart (periodograms,
/// and transfer-function estimates, for spectra flat across a few bins):
/// `c_j = |sum_n w[n]^2 exp(-2 pi i j n / L)|^2 / (sum_n w[n]^2)^2`; the square of the periodic
/// Hann window has Fourier components at 0, 1 and 2 bins only, so `c = [1, 4/9, 1/36]` and
/// `c_j = 0` beyond.
pub fn bin_correlation(segment_len: usize) -> [f64; 3] {
    let w2: Vec<f64> = hann_periodic(segment_len).iter().map(|v| v * v).collect();
    let energy: f64 = w2.iter().sum();
    let len = segment_len as f64;
    let mut c = [1.0; 3];
    for (j, cj) in c.iter_mut().enumerate().skip(1) {
        let (mut re, mut im) = (0.0, 0.0);
        for (n, v) in w2.iter().enumerate() {
            let phase = -2.0 * std::f64::consts::PI * (j * n) as f64 / len;
            re += v * phase.cos();
            im += v * phase.sin();
        }
        *cj = (re * re + im * im) / (energy * energy);
    }
    c
}

/// Upper `alpha` point of the `F(2, m)` distribution, `P(F > x) = alpha`:
/// `(m/2) (alpha^(-2/m) - 1)`, from its survival function `(1 + 2x/m)^(-m/2)`.
pub fn f2_upper_quantile(m: f64, alpha: f64) -> f64 {
    0.5 * m * (alpha.powf(-2.0 / m) - 1.0)
}

/// `P(B > x)` for `B ~ Beta(q, n - q)`, integer `q >= 1`, real `n > q`:
/// `sum_{j=0}^{q-1} C(n-1, j) x^j (1-x)^(n-1-j)` with `C(a, j) = a (a-1) ... (a-j+1) / j!`.
pub fn beta_upper_tail(q: usize, n: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    if x >= 1.0 {
        return 0.0;
    }
    let mut coef = 1.0;
    let mut sum = 0.0;
    for j in 0..q {
        if j > 0 {
            coef *= (n - j as f64) / j as f64;
        }
        sum += coef * x.powi(j as i32) * (1.0 - x).powf(n - 1.0 - j as f64);
    }
    sum
}

/// The `x` with `P(B > x) = alpha` for `B ~ Beta(q, n - q)` ([`beta_upper_tail`]): for `q = 1`
/// the closed form `1 - alpha^(1/(n-1))`, otherwise bisection to the last bit.
pub fn beta_upper_quantile(q: usize, n: f64, alpha: f64) -> f64 {
    if q == 1 {
        return 1.0 - alpha.powf(1.0 / (n - 1.0));
    }
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if beta_upper_tail(q, n, mid) > alpha {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Quantile of the standard normal distribution at probability `p` in (0, 1): Acklam's
/// rational approximation (relative error below 1.15e-9; ample for a confidence level).
/// NaN outside (0, 1).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.383_577_518_672_69e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [
        7.784695709041462e-3,
        3.224671290700398e-1,
        2.445134137142996,
        3.754408661907416,
    ];
    const P_LOW: f64 = 0.02425;
    if !(p > 0.0 && p < 1.0) {
        return f64::NAN;
    }
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < P_LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p <= 1.0 - P_LOW {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    }
}

/// Radius of the joint confidence circle, at confidence `level`, of one coefficient `H_oi` of a
/// multiple-input estimate with `q` inputs and `n_d` averages (Goodman 1965; Bendat & Piersol,
/// Random Data, 4th ed., section 9.3): the true `H_oi` lies within
///
/// ```text
/// r^2 = F(2, 2(n_d - q); 1 - level) S_nn (S_xx^-1)_ii / (n_d - q)
///     = ((1 - level)^(-1/(n_d - q)) - 1) S_nn (S_xx^-1)_ii
/// ```
///
/// of the estimate (`S_nn` the residual PSD, `(S_xx^-1)_ii` the input term of
/// [`super::MultipleInput`]). For one input, `S_nn (S_xx^-1)_ii = (1 - gamma^2) S_yy / S_xx`,
/// Bendat & Piersol's gain-and-phase circle. Magnitude bounds are `|H| -/+ r`, phase bounds
/// `+/- asin(r / |H|)` (undetermined when `r >= |H|`). NaN unless `n_d > q`.
pub fn tf_radius(residual_psd: f64, inverse_diagonal: f64, n_d: f64, q: usize, level: f64) -> f64 {
    let dof = n_d - q as f64;
    if dof <= 0.0 {
        return f64::NAN;
    }
    let f = f2_upper_quantile(2.0 * dof, 1.0 - level);
    (f * residual_psd * inverse_diagonal / dof).sqrt()
}

/// Standard error of the magnitude of `H_oi` (and of `|H_oi|` times its phase, in rad):
/// `sqrt(S_nn (S_xx^-1)_ii / (2 (n_d - q)))`, half the variance of the complex error per real
/// direction. For one input and large `n_d` it is Bendat & Piersol's
/// `|H| sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))`. NaN unless `n_d > q`.
pub fn tf_sigma(residual_psd: f64, inverse_diagonal: f64, n_d: f64, q: usize) -> f64 {
    let dof = n_d - q as f64;
    if dof <= 0.0 {
        return f64::NAN;
    }
    (residual_psd * inverse_diagonal / (2.0 * dof)).sqrt()
}

/// The level-`(1 - alpha)` significance threshold of a coherence estimate with `q` inputs and
/// `n_d` averages: pure noise (true coherence 0) exceeds it with probability `alpha`. The
/// estimate is then `Beta(q, n_d - q)` distributed (Goodman 1963), so the threshold is
/// [`beta_upper_quantile`]; `1 - alpha^(1/(n_d - 1))` for the ordinary coherence. NaN unless
/// `n_d > q`.
pub fn coherence_threshold(n_d: f64, q: usize, alpha: f64) -> f64 {
    if n_d <= q as f64 {
        return f64::NAN;
    }
    beta_upper_quantile(q, n_d, alpha)
}

/// Confidence interval `(lower, upper)` at `level` of a true coherence given the estimate
/// `gamma2` from `n_d` averages and `q` inputs (`q = 1`: ordinary coherence): Fisher's
/// transform `z = atanh(|gamma|)` is approximately normal with mean
/// `atanh(|gamma_true|) + 1/(2 nu)` and variance `1/(2 nu)`, `nu = n_d - q` (Enochson & Goodman
/// 1965; Bendat & Piersol, Random Data, 4th ed., section 9.2.3, with `nu = n_d - 1` for one
/// input; the `q - 1` further inputs take one complex degree of freedom each). The bounds are
/// `tanh^2` of `z - 1/(2 nu) -/+ z_p / sqrt(2 nu)`, `z_p` the normal quantile at
/// `(1 + level) / 2`, floored at 0. NaN unless `n_d > q`.
pub fn coherence_interval(gamma2: f64, n_d: f64, q: usize, level: f64) -> (f64, f64) {
    let nu = n_d - q as f64;
    if nu <= 0.0 || gamma2.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    let z = gamma2.clamp(0.0, 1.0).sqrt().atanh() - 0.5 / nu;
    let half = normal_quantile(0.5 * (1.0 + level)) / (2.0 * nu).sqrt();
    let back = |z: f64| z.max(0.0).tanh().powi(2);
    (back(z - half), back(z + half))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_overlap_means_independent_segments() {
        let cfg = WelchConfig::new(64).with_overlap(0);
        assert_eq!(equivalent_averages(&cfg, 10), 10.0);
        assert_eq!(equivalent_averages(&cfg, 1), 1.0);
    }

    #[test]
    fn hann_at_half_overlap_has_rho_one_sixth() {
        // rho(L/2) = 1/6 exactly for the periodic Hann window, so for K segments
        // n_d = K / (1 + 2 (1 - 1/K) / 36).
        let cfg = WelchConfig::new(256);
        for k in [2usize, 7, 100] {
            let kf = k as f64;
            let want = kf / (1.0 + 2.0 * (1.0 - 1.0 / kf) / 36.0);
            let got = equivalent_averages(&cfg, k);
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "K = {k}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn adjacent_bins_of_hann_correlate_four_ninths_and_one_thirty_sixth() {
        let c = bin_correlation(128);
        let want = [1.0, 4.0 / 9.0, 1.0 / 36.0];
        for (g, w) in c.iter().zip(want) {
            assert!((g - w).abs() < 1e-14, "{c:?}");
        }
    }

    #[test]
    fn f2_quantile_inverts_its_survival_function() {
        for (m, alpha) in [(2.0, 0.05), (17.3, 0.01), (400.0, 0.32)] {
            let x = f2_upper_quantile(m, alpha);
            let survival = (1.0f64 + 2.0 * x / m).powf(-m / 2.0);
            assert!((survival - alpha).abs() < 1e-13, "m = {m}");
        }
    }

    #[test]
    fn beta_tail_and_quantile_agree_for_one_input() {
        // q = 1: P(B > x) = (1 - x)^(n-1).
        let n = 12.5;
        let x = 0.2;
        assert!((beta_upper_tail(1, n, x) - 0.8f64.powf(11.5)).abs() < 1e-15);
        let q1 = beta_upper_quantile(1, n, 0.05);
        assert!((beta_upper_tail(1, n, q1) - 0.05).abs() < 1e-14);
        for q in [2usize, 3] {
            let t = beta_upper_quantile(q, n, 0.05);
            assert!((beta_upper_tail(q, n, t) - 0.05).abs() < 1e-12, "q = {q}");
            assert!(t > q1, "more inputs explain more of pure noise");
        }
    }

    #[test]
    fn normal_quantile_symmetry_and_known_points() {
        assert_eq!(normal_quantile(0.5), 0.0);
        let z = normal_quantile(0.975);
        assert!((z - 1.959963984540054).abs() < 1.15e-9 * z);
        assert!((normal_quantile(0.025) + z).abs() < 1e-12);
        assert!(normal_quantile(0.0).is_nan() && normal_quantile(1.0).is_nan());
    }
}
