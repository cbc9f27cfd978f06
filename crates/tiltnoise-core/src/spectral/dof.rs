//! Equivalent degrees of freedom of a Welch estimate averaged over adjacent bins: the
//! statistical error of a band average.
//!
//! For a Gaussian process whose spectrum is flat across the band, the mean of `M` adjacent
//! bins of a mean-averaged Welch PSD over `K` segments is distributed as `S chi^2_nu / nu` with
//!
//! ```text
//! nu = 2 (M K)^2 / sum_{|D| < M} (M - |D|) sum_{|d| < K} (K - |d|) |rho(d, D)|^2
//! rho(d, D) = sum_t w_t w_{t + d s} exp(-2 pi i D t / N) / sum_t w_t^2
//! ```
//!
//! (`N` the segment length, `s` the step between segments, `w` the window): `rho` is the
//! correlation of the windowed Fourier coefficients of two segments `d` steps apart at two bins
//! `D` apart, and the covariance of two periodogram values is `|rho|^2` times the product of
//! their means (Isserlis). One bin of one segment gives `nu = 2`; `K` disjoint segments `2K`;
//! the periodic Hann window at 50 % overlap `36 K^2 / (19 K - 1)` (Percival and Walden,
//! *Spectral Analysis for Physical Applications* (1993), eq. 292c). The pseudo-covariance terms
//! that appear next to DC and Nyquist are neglected. The relative standard deviation of the
//! band-averaged PSD is `sqrt(2 / nu)`, that of its square root (the ASD) about half of it.

use super::window::hann_periodic;
use super::{Averaging, WelchConfig};
use realfft::RealFftPlanner;

/// The equivalent chi-squared degrees of freedom of the mean of `n_bins` adjacent bins of a
/// Welch PSD over `n_segments` segments with `cfg` (see the module docs). `None` for
/// [`Averaging::Median`], whose distribution this formula does not describe, for an invalid
/// configuration, and for no segment or no bin.
pub fn band_dof(cfg: &WelchConfig, n_segments: usize, n_bins: usize) -> Option<f64> {
    if cfg.averaging == Averaging::Median || cfg.validate().is_err() {
        return None;
    }
    if n_segments == 0 || n_bins == 0 {
        return None;
    }
    let n = cfg.segment_len;
    let step = cfg.step();
    let w = hann_periodic(n);
    let norm: f64 = w.iter().map(|x| x * x).sum();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut input = vec![0.0; n];
    let mut spectrum = fft.make_output_vec();
    let (k, m) = (n_segments as f64, n_bins as f64);
    let mut denom = 0.0;
    // Segments d steps apart overlap only while d * step < n.
    for d in 0..n_segments.min(n.div_ceil(step)) {
        let shift = d * step;
        for (t, x) in input.iter_mut().enumerate() {
            *x = if t + shift < n {
                w[t] * w[t + shift]
            } else {
                0.0
            };
        }
        fft.process(&mut input, &mut spectrum).ok()?;
        let seg_weight = if d == 0 { k } else { 2.0 * (k - d as f64) };
        for (bin, z) in spectrum.iter().enumerate().take(n_bins) {
            let bin_weight = if bin == 0 { m } else { 2.0 * (m - bin as f64) };
            denom += seg_weight * bin_weight * (z.norm() / norm).powi(2);
        }
    }
    Some(2.0 * (m * k).powi(2) / denom)
}
