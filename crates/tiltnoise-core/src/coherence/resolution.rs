//! Whether a Welch bin resolves the model's transfer function. A Welch estimate at bin `k` is
//! an average over the window's spectral kernel (for the periodic Hann window, a main lobe of
//! +/- 2 bins): where the model varies across it (a resonance narrower than a few bins, a steep
//! slope at the lowest bins), the estimate of a perfect measurement differs from the model at
//! the bin's centre, and comparing the two would blame the model for the resolution.
//!
//! For an input spectrum flat across the kernel, the estimate of a noiseless record is
//! `H_bar(f_k) = sum_j K(nu_j) H(f_k + nu_j df) / sum_j K(nu_j)`, `K(nu) = |W(nu)|^2` the
//! power response of the window at `nu` bins (exact DTFT of the periodic Hann window), sampled
//! at [`KERNEL_OFFSETS`]. A bin is **resolved** when `|H_bar - H(f_k)|` is at most
//! [`RESOLUTION_FRACTION`] of the bin's standard error: the model's own smearing is then
//! negligible beside the noise of the estimate it is compared with.

use num_complex::Complex64;

/// Offsets (bins) at which the model is sampled: -2 to 2 in steps of 1/8, the main lobe of
/// the periodic Hann window (its first side lobe, 31 dB down, is left out).
pub const KERNEL_OFFSETS: usize = 33;

/// Largest smearing of the model by the window that still counts as resolved, as a fraction of
/// the bin's standard error per real direction.
pub const RESOLUTION_FRACTION: f64 = 0.1;

/// `(offset in bins, weight)` of the kernel of a periodic Hann window of `segment_len`
/// samples: `|W(nu)|^2` at the [`KERNEL_OFFSETS`] offsets, with trapezoid weights, summing to 1.
pub fn kernel(segment_len: usize) -> Vec<(f64, f64)> {
    let w = crate::spectral::hann_periodic(segment_len);
    let len = segment_len as f64;
    let step = 4.0 / (KERNEL_OFFSETS - 1) as f64;
    let mut out: Vec<(f64, f64)> = (0..KERNEL_OFFSETS)
        .map(|j| {
            let nu = -2.0 + j as f64 * step;
            let (mut re, mut im) = (0.0, 0.0);
            for (n, v) in w.iter().enumerate() {
                let phase = -2.0 * std::f64::consts::PI * nu * n as f64 / len;
                re += v * phase.cos();
                im += v * phase.sin();
            }
            let trapezoid = if j == 0 || j == KERNEL_OFFSETS - 1 {
                0.5
            } else {
                1.0
            };
            (nu, (re * re + im * im) * trapezoid)
        })
        .collect();
    let total: f64 = out.iter().map(|p| p.1).sum();
    for p in &mut out {
        p.1 /= total;
    }
    out
}

/// The kernel-weighted model of each bin from `samples[k * KERNEL_OFFSETS + j]`, the model at
/// `f_k + nu_j df`; samples at frequencies `<= 0` (`usable` false) are left out and the
/// remaining weights renormalized.
pub fn smoothed(samples: &[Complex64], usable: &[bool], kernel: &[(f64, f64)]) -> Vec<Complex64> {
    samples
        .chunks(kernel.len())
        .zip(usable.chunks(kernel.len()))
        .map(|(h, ok)| {
            let (mut sum, mut weight) = (Complex64::new(0.0, 0.0), 0.0);
            for ((&z, &u), &(_, w)) in h.iter().zip(ok).zip(kernel) {
                if u {
                    sum += z * w;
                    weight += w;
                }
            }
            sum / weight
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_hann_kernel_is_symmetric_and_peaks_at_the_centre() {
        let k = kernel(256);
        assert_eq!(k.len(), KERNEL_OFFSETS);
        let total: f64 = k.iter().map(|p| p.1).sum();
        assert!((total - 1.0).abs() < 1e-14);
        for j in 0..KERNEL_OFFSETS {
            assert!((k[j].1 - k[KERNEL_OFFSETS - 1 - j].1).abs() < 1e-14);
        }
        // |W| at one bin is half the peak (the Hann main lobe), so the power a quarter.
        let centre = k[16].1;
        assert!(
            (k[24].1 / centre - 0.25).abs() < 1e-3,
            "{}",
            k[24].1 / centre
        );
        // The main lobe ends at two bins.
        assert!(k[0].1 / centre < 1e-6);
    }

    #[test]
    fn a_linear_model_is_its_own_smoothing() {
        let k = kernel(128);
        let samples: Vec<Complex64> = k
            .iter()
            .map(|&(nu, _)| Complex64::new(3.0 + nu, -nu))
            .collect();
        let s = smoothed(&samples, &vec![true; k.len()], &k);
        assert!((s[0] - Complex64::new(3.0, 0.0)).norm() < 1e-14);
    }
}
