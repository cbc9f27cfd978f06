//! The optimal linear weighting of the prediction given the witness noise.
//!
//! The witness records `w = t + m`: the true floor motion `t` (the model's inputs) plus the
//! instrument's own noise `m`, uncorrelated with `t`, with a known PSD `S_mm` (diagonal: the
//! instruments' noises are independent). Given `w`, the best linear estimate of `t` in each
//! frequency bin is `E[t | w]`; with `S_ab = <conj(w_a) w_b>` (the crate's convention) the
//! observable's tilt part `G^T t` is then predicted as `F^T w` with
//!
//! ```text
//! F = S_ww^-1 S_tt G,      S_tt = S_ww - S_mm,
//! ```
//!
//! the multiple-input Wiener filter with the model `G` as the coupling (scalar: `F = G S_tt /
//! (S_tt + S_mm)`). It leaves of the tilt part the residual PSD
//!
//! ```text
//! G^H R G,     R = S_tt - S_tt S_ww^-1 S_tt      (scalar: |G|^2 S_tt S_mm / (S_tt + S_mm)),
//! ```
//!
//! what no filter of this witness can remove (the witness-noise limit). Where the witness is
//! all noise `F -> 0`: the model's gain, however large near a resonance, then passes nothing.
//!
//! `S_ww` comes from the data: a Welch estimate smoothed over neighbouring bins
//! ([`smoothing_window`]), so that the weight is smooth across bins (the prediction's
//! time-domain filter then has a short response and does not ring) and, in the fit, nearly
//! independent of the bin it weights (the bin itself and its neighbours, correlated 4/9 for
//! Hann, are left out of its own average). `S_tt` is `S_ww - S_mm` with negative eigenvalues
//! set to zero, taken in the basis normalized by the witnesses' own PSDs (the coherence
//! matrix), which makes the regularisation independent of the inputs' units.
//!
//! For the prediction the noise is inflated by a margin ([`prediction_margin`]): a tilt PSD
//! not significantly above the witness noise, given the smoothed estimate's statistical error,
//! is taken as zero. Where the model's gain is large a weight estimated at a few per cent from
//! noise would otherwise pass the witness noise through that gain.

use crate::spectral::CrossSpectra;
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Half-width of the smoothing window relative to the bin's frequency (+-10 %).
pub const SMOOTH_FRACTION: f64 = 0.1;
/// Fewest bins on either side of the smoothing window.
pub const SMOOTH_MIN_HALF_WIDTH: usize = 4;
/// One-sided significance of the tilt PSD above the witness noise for the prediction
/// ([`prediction_margin`]): 3 standard errors.
pub const PREDICTION_SIGNIFICANCE: f64 = 3.0;

/// The indices averaged for entry `i` of a sorted frequency grid: those within
/// [`SMOOTH_FRACTION`] of `freqs[i]`, at least [`SMOOTH_MIN_HALF_WIDTH`] on either side where
/// the grid has them, without `i` itself and its `exclude` nearest neighbours on each side.
pub fn smoothing_window(freqs: &[f64], i: usize, exclude: usize) -> Vec<usize> {
    let f = freqs[i];
    let reach = SMOOTH_FRACTION * f;
    let mut lo = i;
    while lo > 0 && (i - (lo - 1) <= SMOOTH_MIN_HALF_WIDTH + exclude || f - freqs[lo - 1] <= reach)
    {
        lo -= 1;
    }
    let mut hi = i;
    while hi + 1 < freqs.len()
        && (hi + 1 - i <= SMOOTH_MIN_HALF_WIDTH + exclude || freqs[hi + 1] - f <= reach)
    {
        hi += 1;
    }
    (lo..=hi).filter(|&j| j.abs_diff(i) > exclude).collect()
}

/// The mean of `values` over [`smoothing_window`] of every entry.
pub fn smooth(freqs: &[f64], values: &[f64], exclude: usize) -> Vec<f64> {
    (0..freqs.len())
        .map(|i| {
            let w = smoothing_window(freqs, i, exclude);
            if w.is_empty() {
                values[i]
            } else {
                w.iter().map(|&j| values[j]).sum::<f64>() / w.len() as f64
            }
        })
        .collect()
}

/// The witnesses' spectral matrix smoothed across bins, on the Welch grid.
#[derive(Debug, Clone)]
pub struct WitnessSpectra {
    /// Welch frequencies (Hz), DC first.
    pub freqs_hz: Vec<f64>,
    /// Smoothed `S_ww` per bin (DC: that of bin 1).
    pub smoothed: Vec<DMatrix<Complex64>>,
    /// Equivalent degrees of freedom of each smoothed PSD.
    pub dof: Vec<f64>,
}

impl WitnessSpectra {
    /// Smooths the first `n_in` channels of `spectra` (each bin from its neighbours, not from
    /// itself nor the bins next to it). `n_eff` is the Welch estimate's effective number of
    /// averages and `adjacent_factor` the variance factor of a mean over adjacent bins.
    pub fn new(spectra: &CrossSpectra, n_in: usize, n_eff: f64, adjacent_factor: f64) -> Self {
        let n = spectra.n_channels;
        let freqs = &spectra.freqs_hz;
        let last = freqs.len() - 1;
        // Bins 1 ..= last: DC carries the segments' detrending.
        let grid = &freqs[1..];
        let mut smoothed = Vec::with_capacity(freqs.len());
        let mut dof = Vec::with_capacity(freqs.len());
        for i in 0..last {
            let window = smoothing_window(grid, i, 1);
            let mut s = DMatrix::<Complex64>::zeros(n_in, n_in);
            for &j in &window {
                let m = spectra.matrix(j + 1);
                for a in 0..n_in {
                    for b in 0..n_in {
                        s[(a, b)] += m[a * n + b];
                    }
                }
            }
            s /= Complex64::new(window.len().max(1) as f64, 0.0);
            smoothed.push(s);
            dof.push(2.0 * n_eff * window.len() as f64 / adjacent_factor);
        }
        smoothed.insert(0, smoothed[0].clone());
        dof.insert(0, dof[0]);
        WitnessSpectra {
            freqs_hz: freqs.clone(),
            smoothed,
            dof,
        }
    }
}

/// The noise margin of the prediction for a smoothed PSD of `dof` degrees of freedom: the
/// witness noise is multiplied by `1 + z sqrt(2 / dof)` ([`PREDICTION_SIGNIFICANCE`] `= z`),
/// so that a tilt PSD within `z` standard errors of zero is taken as zero.
pub fn prediction_margin(dof: f64) -> f64 {
    1.0 + PREDICTION_SIGNIFICANCE * (2.0 / dof).sqrt()
}

/// The weighting of one bin.
#[derive(Debug, Clone, PartialEq)]
pub struct Weighting {
    /// `S_ww^-1 S_tt`: the coupling seen from the witness is `F = at G`.
    pub at: DMatrix<Complex64>,
    /// `R = S_tt - S_tt (S_tt + S_mm)^-1 S_tt` (PSD of the witness-limited residual:
    /// `G^H R G`), with the noise as given (without the margin).
    pub limit: DMatrix<Complex64>,
}

/// Weighting for a witness spectral matrix `sww` (Hermitian, PSD) and the witnesses' noise
/// PSDs `noise_psd` (same order), the noise multiplied by `margin` (1 for the estimate itself).
/// Without noise the weighting is the identity and the limit 0. A witness without power
/// (a non-positive or non-finite PSD) gets no weight.
pub fn weighting(sww: &DMatrix<Complex64>, noise_psd: &[f64], margin: f64) -> Weighting {
    let q = sww.nrows();
    if noise_psd.iter().all(|&m| m == 0.0) {
        return Weighting {
            at: DMatrix::identity(q, q),
            limit: DMatrix::zeros(q, q),
        };
    }
    // N = diag(S_ww)^-1/2: K = N S_ww N is the coherence matrix, T = N S_tt N.
    let scale: Vec<f64> = (0..q)
        .map(|a| {
            let p = sww[(a, a)].re;
            if p > 0.0 && p.is_finite() {
                1.0 / p.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let k = DMatrix::from_fn(q, q, |a, b| sww[(a, b)] * (scale[a] * scale[b]));
    let mut t = k.clone();
    for a in 0..q {
        t[(a, a)] -= margin * noise_psd[a] * scale[a] * scale[a];
    }
    let t_plus = clamp_negative(&t);
    let k_inv = pseudo_inverse(&k);
    let k_inv_t = &k_inv * &t_plus;
    // at = N K^-1 T+ N^-1; limit = N^-1 (T+ - T+ (T+ + M)^-1 T+) N^-1 with M = N S_mm N: the
    // error of the best estimate of a floor motion of spectrum S_tt+ seen through the noise
    // S_mm (T+ + M = K where nothing is clamped and the margin is 1).
    let at = DMatrix::from_fn(q, q, |a, b| {
        if scale[a] == 0.0 || scale[b] == 0.0 {
            Complex64::new(0.0, 0.0)
        } else {
            k_inv_t[(a, b)] * (scale[a] / scale[b])
        }
    });
    let mut seen = t_plus.clone();
    for a in 0..q {
        seen[(a, a)] += noise_psd[a] * scale[a] * scale[a];
    }
    let inner = clamp_negative(&(&t_plus - &t_plus * pseudo_inverse(&seen) * &t_plus));
    let limit = DMatrix::from_fn(q, q, |a, b| {
        if scale[a] == 0.0 || scale[b] == 0.0 {
            Complex64::new(0.0, 0.0)
        } else {
            inner[(a, b)] / (scale[a] * scale[b])
        }
    });
    Weighting { at, limit }
}

/// The Hermitian part of `m` with its negative eigenvalues set to zero.
fn clamp_negative(m: &DMatrix<Complex64>) -> DMatrix<Complex64> {
    let h = (m + m.adjoint()) * Complex64::new(0.5, 0.0);
    let eig = h.symmetric_eigen();
    let v = &eig.eigenvectors;
    let q = m.nrows();
    DMatrix::from_fn(q, q, |a, b| {
        (0..q)
            .map(|l| v[(a, l)] * v[(b, l)].conj() * eig.eigenvalues[l].max(0.0))
            .sum()
    })
}

/// Inverse of a Hermitian positive semi-definite matrix through its eigenvalues, directions
/// whose eigenvalue is below [`crate::spectral::INPUT_RCOND_MIN`] of the largest left out.
fn pseudo_inverse(m: &DMatrix<Complex64>) -> DMatrix<Complex64> {
    let eig = m.clone().symmetric_eigen();
    let top = eig.eigenvalues.max();
    let v = &eig.eigenvectors;
    let q = m.nrows();
    DMatrix::from_fn(q, q, |a, b| {
        (0..q)
            .filter(|&l| top > 0.0 && eig.eigenvalues[l] > top * crate::spectral::INPUT_RCOND_MIN)
            .map(|l| v[(a, l)] * v[(b, l)].conj() / eig.eigenvalues[l])
            .sum()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    /// One witness: the weight is `S_tt / S_ww`, the limit `S_tt S_mm / S_ww`, both exact; a
    /// witness below its noise gets no weight and leaves no limit.
    #[test]
    fn scalar_weighting_is_the_wiener_factor() {
        let s = DMatrix::from_element(1, 1, c(5.0, 0.0));
        let w = weighting(&s, &[2.0], 1.0);
        assert!((w.at[(0, 0)] - c(0.6, 0.0)).norm() < 1e-15);
        assert!((w.limit[(0, 0)] - c(1.2, 0.0)).norm() < 1e-15);
        let w = weighting(&s, &[6.0], 1.0);
        assert_eq!(w.at[(0, 0)], c(0.0, 0.0));
        assert_eq!(w.limit[(0, 0)], c(0.0, 0.0));
        let w = weighting(&s, &[0.0], 1.0);
        assert_eq!(w.at[(0, 0)], c(1.0, 0.0));
    }

    /// Two correlated witnesses whose noise leaves `S_ww - S_mm` positive definite: the
    /// weighting is `S_ww^-1 (S_ww - S_mm)` exactly and the limit `S_mm - S_mm S_ww^-1 S_mm`
    /// (the same matrix written without the regularisation); scaling one input's unit (a
    /// factor 1e3 on its channel) scales the weighting as the physics says.
    #[test]
    fn matrix_weighting_without_clamp_is_exact_and_unit_free() {
        let s =
            DMatrix::from_row_slice(2, 2, &[c(4.0, 0.0), c(1.0, 0.5), c(1.0, -0.5), c(3.0, 0.0)]);
        let m = [0.5, 0.25];
        let w = weighting(&s, &m, 1.0);
        let smm = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
            2,
            m.iter().map(|&x| c(x, 0.0)),
        ));
        let s_inv = s.clone().try_inverse().unwrap();
        let at = &s_inv * (&s - &smm);
        let limit = &smm - &smm * &s_inv * &smm;
        assert!((&w.at - &at).norm() < 1e-14, "{} vs {at}", w.at);
        assert!((&w.limit - &limit).norm() < 1e-14, "{} vs {limit}", w.limit);
        let d =
            DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![c(1.0, 0.0), c(1e3, 0.0)]));
        let w2 = weighting(&(&d * &s * &d), &[m[0], m[1] * 1e6], 1.0);
        let d_inv = d.clone().try_inverse().unwrap();
        assert!((&w2.at - &d_inv * &w.at * &d).norm() < 1e-12 * w.at.norm());
    }

    /// A matrix whose noise exceeds it in one direction (indefinite `S_ww - S_mm`): the
    /// negative eigenvalue is found (a Cholesky factorization of a complex Hermitian matrix
    /// need not report it) and that direction gets no weight.
    #[test]
    fn an_indefinite_difference_is_clamped() {
        // Fully coherent witnesses: S_ww has the direction (1, -1) with eigenvalue 0.2 only.
        let s =
            DMatrix::from_row_slice(2, 2, &[c(1.1, 0.0), c(0.9, 0.0), c(0.9, 0.0), c(1.1, 0.0)]);
        let w = weighting(&s, &[0.5, 0.5], 1.0);
        // In the eigenbasis: (1, 1) has 2.0 - 0.5 > 0, (1, -1) has 0.2 - 0.5 < 0 -> 0.
        // S_tt+ = 1.5 u u^H with u = (1, 1)/sqrt 2, so at = S^-1 S_tt+ = (1.5 / 2.0) u u^H.
        let expect = DMatrix::from_element(2, 2, c(0.375, 0.0));
        assert!((&w.at - &expect).norm() < 1e-14, "{}", w.at);
        assert!(w.limit.symmetric_eigenvalues().min() >= -1e-15);
    }

    /// The window reaches +-10 % of the frequency, at least 4 bins either side, and leaves out
    /// the bin and its `exclude` neighbours.
    #[test]
    fn smoothing_window_shape() {
        let f: Vec<f64> = (1..=200).map(|k| k as f64).collect();
        assert_eq!(smoothing_window(&f, 0, 1), vec![2, 3, 4, 5]);
        assert_eq!(smoothing_window(&f, 9, 1), vec![4, 5, 6, 7, 11, 12, 13, 14]);
        let w = smoothing_window(&f, 99, 1);
        assert_eq!((w[0], w[w.len() - 1], w.len()), (89, 109, 18));
        assert_eq!(smoothing_window(&f, 199, 0).len(), 20);
    }
}
