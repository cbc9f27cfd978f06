//! Statistics of Welch averages with the periodic Hann window, for locally white processes
//! (spectra that vary little over a few bins): the variance of a mean over bins, and how a
//! delay between two channels attenuates their cross spectrum. (The number of averages
//! overlapping segments are worth is [`crate::spectral::confidence::equivalent_averages`].)
//!
//! References: P. D. Welch, IEEE Trans. Audio Electroacoust. 15, 70 (1967); D. B. Percival and
//! A. T. Walden, *Spectral Analysis for Physical Applications* (Cambridge, 1993), sec. 6.17
//! (equivalent degrees of freedom of WOSA, eq. 292b).

use crate::spectral::confidence::bin_correlation;

/// Variance of a mean over many bins spaced `spacing` bins apart, relative to independent
/// bins: `1 + 2 sum_{j >= 1} c(j spacing)` with `c` the bin correlation (1.944 for adjacent
/// Hann bins, 1.056 for every other bin).
pub fn bin_variance_factor(segment_len: usize, spacing: usize) -> f64 {
    // Hann's correlations vanish beyond two bins.
    let c = bin_correlation(segment_len);
    let sum: f64 = (1..)
        .map(|j| j * spacing)
        .take_while(|&d| d < c.len())
        .map(|d| c[d])
        .sum();
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

    /// The bin-variance factors of the Hann window (`1 + 2 (4/9 + 1/36)` and `1 + 2/36`), and
    /// the delay factor equal to the discrete self-overlap at whole lags (to the O(1/L^2) of
    /// the sum against the integral), with its slope.
    #[test]
    fn hann_closed_forms() {
        let l = 4096;
        let w = crate::spectral::hann_periodic(l);
        let energy: f64 = w.iter().map(|a| a * a).sum();
        for lag in [1usize, 17, 300, 2048] {
            let x = lag as f64 / l as f64;
            let discrete: f64 = w.iter().zip(&w[lag..]).map(|(a, b)| a * b).sum::<f64>() / energy;
            assert!(
                (hann_delay_factor(x) - discrete).abs() < 4.0 / (l as f64).powi(2),
                "lag {lag}: {} vs {discrete}",
                hann_delay_factor(x)
            );
        }
        assert!((bin_variance_factor(l, 1) - (1.0 + 8.0 / 9.0 + 1.0 / 18.0)).abs() < 1e-9);
        assert!((bin_variance_factor(l, 2) - (1.0 + 1.0 / 18.0)).abs() < 1e-9);
        let h = 1e-6;
        for x in [-0.3, 0.01, 0.2] {
            let fd = (hann_delay_factor(x + h) - hann_delay_factor(x - h)) / (2.0 * h);
            assert!((fd - hann_delay_factor_slope(x)).abs() < 1e-8, "x = {x}");
        }
    }
}
