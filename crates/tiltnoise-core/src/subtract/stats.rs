//! Statistics of Welch averages with the periodic Hann window, for locally white processes
//! (spectra that vary little over a few bins): how many independent averages overlapping
//! segments are worth, how strongly neighbouring bins are correlated, and how a delay between
//! two channels attenuates their cross spectrum.
//!
//! References: P. D. Welch, IEEE Trans. Audio Electroacoust. 15, 70 (1967); D. B. Percival and
//! A. T. Walden, *Spectral Analysis for Physical Applications* (Cambridge, 1993), sec. 6.17
//! (equivalent degrees of freedom of WOSA, eq. 292b).

use crate::spectral::hann_periodic;

/// `sum_t w_t w_{t+lag} / sum_t w_t^2`: the window's normalized overlap with itself shifted by
/// `lag` samples.
fn self_overlap(w: &[f64], lag: usize) -> f64 {
    if lag >= w.len() {
        return 0.0;
    }
    let num: f64 = w.iter().zip(&w[lag..]).map(|(a, b)| a * b).sum();
    let den: f64 = w.iter().map(|a| a * a).sum();
    num / den
}

/// Effective number of independent averages of a Welch mean over `n_segments` segments of
/// `segment_len` samples stepped by `step`: `K / (1 + 2 sum_{m=1}^{K-1} (1 - m/K) rho(m step)^2)`
/// with `rho` the window's normalized self-overlap (Percival and Walden eq. 292b, divided by 2
/// to count complex averages rather than degrees of freedom). For 50 % overlap
/// (`rho = 1/6`) and many segments, `K / 1.056`.
pub fn effective_averages(segment_len: usize, step: usize, n_segments: usize) -> f64 {
    let w = hann_periodic(segment_len);
    let k = n_segments as f64;
    let mut sum = 0.0;
    for m in 1..n_segments {
        let rho = self_overlap(&w, m * step);
        if rho == 0.0 {
            break;
        }
        sum += (1.0 - m as f64 / k) * rho * rho;
    }
    k / (1.0 + 2.0 * sum)
}

/// Correlation of the periodogram (or cross-periodogram) values of white noise `d` bins apart:
/// `|sum_t w_t^2 exp(-2 pi i d t / L)|^2 / (sum_t w_t^2)^2`; 4/9 for `d = 1` and 1/36 for
/// `d = 2` with the periodic Hann window, 0 beyond.
pub fn bin_correlation(segment_len: usize, d: usize) -> f64 {
    let w = hann_periodic(segment_len);
    let l = segment_len as f64;
    let (mut re, mut im, mut den) = (0.0, 0.0, 0.0);
    for (t, &v) in w.iter().enumerate() {
        let phase = std::f64::consts::TAU * (d as f64) * (t as f64) / l;
        re += v * v * phase.cos();
        im -= v * v * phase.sin();
        den += v * v;
    }
    (re * re + im * im) / (den * den)
}

/// Variance of a mean over many bins spaced `spacing` bins apart, relative to independent
/// bins: `1 + 2 sum_{j >= 1} bin_correlation(j spacing)` (1.944 for adjacent Hann bins,
/// 1.056 for every other bin).
pub fn bin_variance_factor(segment_len: usize, spacing: usize) -> f64 {
    let mut sum = 0.0;
    let mut j = 1;
    while j * spacing < segment_len / 2 {
        let c = bin_correlation(segment_len, j * spacing);
        // Hann's correlations vanish beyond two bins up to rounding.
        if c < 1e-12 {
            break;
        }
        sum += c;
        j += 1;
    }
    1.0 + 2.0 * sum
}

/// Attenuation of the Welch cross spectrum of two channels when one lags the other by a
/// fraction `x = delay / segment duration` of the segment (`|x| <= 1`), for locally white
/// processes: the normalized overlap of the continuous Hann window with itself shifted by
/// `x`, `[(1 - |x|)(2 + cos 2 pi x) + (3 / 2 pi) sin 2 pi |x|] / 3 = 1 - (2/3) (pi x)^2 + ...`.
pub fn hann_delay_factor(x: f64) -> f64 {
    let a = x.abs().min(1.0);
    let t = std::f64::consts::TAU * a;
    ((1.0 - a) * (2.0 + t.cos()) + 3.0 / std::f64::consts::TAU * t.sin()) / 3.0
}

/// Derivative of [`hann_delay_factor`] with respect to `x`.
pub fn hann_delay_factor_slope(x: f64) -> f64 {
    let a = x.abs().min(1.0);
    let t = std::f64::consts::TAU * a;
    // d/da of the bracket: -(2 + cos t) - (1 - a) 2 pi sin t + 3 cos t.
    let d = (-(2.0 + t.cos()) - (1.0 - a) * std::f64::consts::TAU * t.sin() + 3.0 * t.cos()) / 3.0;
    d * x.signum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed forms of the Hann window: bin correlations 4/9 and 1/36 (from
    /// `sin^4 = 3/8 - cos/2 + cos(2.)/8`), 50 % self-overlap 1/6, and the delay factor equal
    /// to the discrete self-overlap at whole lags (to the O(1/L^2) of the sum against the
    /// integral).
    #[test]
    fn hann_closed_forms() {
        let l = 4096;
        let tol = 64.0 * f64::EPSILON * l as f64;
        assert!((bin_correlation(l, 1) - 4.0 / 9.0).abs() < tol);
        assert!((bin_correlation(l, 2) - 1.0 / 36.0).abs() < tol);
        assert!(bin_correlation(l, 3) < tol);
        let w = hann_periodic(l);
        assert!((self_overlap(&w, l / 2) - 1.0 / 6.0).abs() < tol);
        for lag in [1usize, 17, 300, 2048] {
            let x = lag as f64 / l as f64;
            let discrete = self_overlap(&w, lag);
            assert!(
                (hann_delay_factor(x) - discrete).abs() < 4.0 / (l as f64).powi(2),
                "lag {lag}: {} vs {discrete}",
                hann_delay_factor(x)
            );
        }
        // Many half-overlapping segments: K / (1 + 2 (1 - 1/K) / 36).
        let k = 1000;
        let ratio = k as f64 / effective_averages(l, l / 2, k);
        assert!((ratio - (1.0 + 2.0 / 36.0 * (1.0 - 1.0 / k as f64))).abs() < 1e-9);
        assert!((bin_variance_factor(l, 1) - (1.0 + 8.0 / 9.0 + 1.0 / 18.0)).abs() < 1e-9);
        assert!((bin_variance_factor(l, 2) - (1.0 + 1.0 / 18.0)).abs() < 1e-9);
        let h = 1e-6;
        for x in [-0.3, 0.01, 0.2] {
            let fd = (hann_delay_factor(x + h) - hann_delay_factor(x - h)) / (2.0 * h);
            assert!((fd - hann_delay_factor_slope(x)).abs() < 1e-8, "x = {x}");
        }
    }
}
