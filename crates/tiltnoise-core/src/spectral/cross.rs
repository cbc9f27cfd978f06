//! Coherence and multiple-input transfer functions from a cross spectral density matrix
//! ([`CrossSpectra`]): which channels are inputs (witnesses, e.g. tilt axes) and which are
//! outputs (e.g. the pendulum's observables) is the caller's choice, so the same estimator
//! serves a coherence analysis and a data-driven multiple-input Wiener filter.
//!
//! # Conventions
//!
//! `S_ij = <conj(X_i) X_j>` as in [`super`] (scipy's `csd(x_i, x_j)`). For inputs `x` (`q`
//! channels) and an output `y`, the linear model `Y = sum_i H_i X_i + N` with complex amplitudes
//! of `exp(+i w t)` gives `S_{x_i y} = sum_j S_{x_i x_j} H_j`, so per frequency
//!
//! ```text
//! H = S_xx^-1 s_xy                       (the "H = S_yx S_xx^-1" of the row-vector convention)
//! gamma^2_{y:x} = s_xy^H S_xx^-1 s_xy / S_yy     (multiple coherence)
//! S_nn = S_yy - s_xy^H S_xx^-1 s_xy = S_yy (1 - gamma^2_{y:x})   (residual PSD)
//! gamma^2_{ij} = |S_ij|^2 / (S_ii S_jj)          (ordinary coherence, scipy.signal.coherence)
//! ```
//!
//! A delay `tau` of the output (`y(t) = x(t - tau)`) gives `H = exp(-i w tau)`: a lag is a
//! negative phase, the same convention as the model's transfer functions. This is the H1
//! estimator of Bendat & Piersol (Random Data, 4th ed., Wiley 2010, chapters 6 and 7): noise on
//! the inputs biases `|H|` low by `S_xx / (S_xx + S_mm)`, noise on the output does not bias it.
//!
//! # The solve
//!
//! `S_xx` is Hermitian and non-negative. It is scaled to unit diagonal,
//! `C = D^-1/2 S_xx D^-1/2` (`D` its diagonal: the input PSDs), whose off-diagonal entries are
//! the complex coherencies of the inputs and whose eigenvalues lie in `[0, q]`; `C` is
//! inverted through its eigen-decomposition. A bin is **estimable** when every input PSD is
//! positive and finite and the reciprocal condition number of `C`, `rcond = l_min / l_max`, is
//! at least [`INPUT_RCOND_MIN`]; otherwise (a dead input, inputs that are copies of each other,
//! fewer segments than inputs) its estimates are NaN and [`MultipleInput::estimable`] says so.

use super::{CrossSpectra, SpectralError};
use nalgebra::DMatrix;
use num_complex::Complex64;

/// Smallest reciprocal condition number of the normalized input matrix `C` at which a bin is
/// estimated: the solve's relative error, about `eps / rcond`, then stays below `1e-6`, which
/// is smaller than the statistical error `1/sqrt(n_d)` of any Welch estimate of fewer than
/// `1e12` averages. Below it the inputs are (numerically) linearly dependent at that frequency.
pub const INPUT_RCOND_MIN: f64 = f64::EPSILON / 1e-6;

/// Ordinary (magnitude-squared) coherence `|S_ij|^2 / (S_ii S_jj)` of channels `i` and `j` at
/// every bin, computed as `scipy.signal.coherence` does (`|Pxy|^2 / Pxx / Pyy`); NaN where
/// either PSD is zero. Panics if a channel index is out of range.
pub fn coherence(m: &CrossSpectra, i: usize, j: usize) -> Vec<f64> {
    (0..m.n_freqs())
        .map(|k| {
            let (sii, sjj) = (m.get(k, i, i).re, m.get(k, j, j).re);
            if sii > 0.0 && sjj > 0.0 {
                m.get(k, i, j).norm_sqr() / sii / sjj
            } else {
                f64::NAN
            }
        })
        .collect()
}

/// The multiple-input estimate of [`multiple_input`] at every bin of a [`CrossSpectra`].
///
/// Arrays are row-major with the frequency outermost. For an output in unit `U_y` and inputs
/// in `U_x`, `tf` is in `U_y/U_x`, `residual_psd` in `U_y^2/Hz` (one-sided), `inverse_diagonal`
/// in `Hz/U_x^2`.
#[derive(Debug, Clone, PartialEq)]
pub struct MultipleInput {
    /// Bin frequencies (Hz), those of the cross spectra.
    pub freqs_hz: Vec<f64>,
    /// Number of inputs `q`.
    pub n_inputs: usize,
    /// Number of outputs.
    pub n_outputs: usize,
    /// `[freq][output][input]`: `H_oi`, the response of output `o` to input `i` with the other
    /// inputs held fixed (complex amplitudes of `exp(+i w t)`).
    pub tf: Vec<Complex64>,
    /// `[freq][output]`: multiple coherence `gamma^2_{y:x}` in `[0, 1]`.
    pub multiple_coherence: Vec<f64>,
    /// `[freq][output]`: residual PSD `S_nn = S_yy (1 - gamma^2_{y:x})`, the part of the output
    /// not linearly explained by the inputs (clamped at 0 against rounding).
    pub residual_psd: Vec<f64>,
    /// `[freq][input]`: the diagonal of `S_xx^-1` (what the variance of `H_oi` scales with).
    pub inverse_diagonal: Vec<f64>,
    /// `[freq]`: reciprocal condition number of the normalized input matrix (1 for a single
    /// input with power, 0 for a dead input).
    pub input_rcond: Vec<f64>,
    /// `[freq]`: whether the bin was estimated (module docs); the other arrays hold NaN where
    /// it was not.
    pub estimable: Vec<bool>,
}

impl MultipleInput {
    /// `H_oi` at bin `k`.
    pub fn tf_at(&self, k: usize, o: usize, i: usize) -> Complex64 {
        self.tf[(k * self.n_outputs + o) * self.n_inputs + i]
    }

    /// Multiple coherence of output `o` at bin `k`.
    pub fn multiple_coherence_at(&self, k: usize, o: usize) -> f64 {
        self.multiple_coherence[k * self.n_outputs + o]
    }

    /// Residual PSD of output `o` at bin `k`.
    pub fn residual_psd_at(&self, k: usize, o: usize) -> f64 {
        self.residual_psd[k * self.n_outputs + o]
    }

    /// `(S_xx^-1)_ii` at bin `k`.
    pub fn inverse_diagonal_at(&self, k: usize, i: usize) -> f64 {
        self.inverse_diagonal[k * self.n_inputs + i]
    }
}

/// Multiple-input transfer functions, multiple coherence and residual PSD of each channel in
/// `outputs` with respect to all channels in `inputs` (indices into `m`), at every bin (module
/// docs for the formulas and the estimability test).
///
/// # Errors
///
/// [`SpectralError::NoChannels`] for an empty `inputs` or `outputs`;
/// [`SpectralError::ChannelCountMismatch`] for an index beyond `m.n_channels` (naming the
/// index as `got` and the number of channels as `expected`).
pub fn multiple_input(
    m: &CrossSpectra,
    inputs: &[usize],
    outputs: &[usize],
) -> Result<MultipleInput, SpectralError> {
    if inputs.is_empty() || outputs.is_empty() {
        return Err(SpectralError::NoChannels);
    }
    if let Some(&bad) = inputs.iter().chain(outputs).find(|&&c| c >= m.n_channels) {
        return Err(SpectralError::ChannelCountMismatch {
            expected: m.n_channels,
            got: bad,
        });
    }
    let (q, no, nf) = (inputs.len(), outputs.len(), m.n_freqs());
    let nan = Complex64::new(f64::NAN, f64::NAN);
    let mut est = MultipleInput {
        freqs_hz: m.freqs_hz.clone(),
        n_inputs: q,
        n_outputs: no,
        tf: vec![nan; nf * no * q],
        multiple_coherence: vec![f64::NAN; nf * no],
        residual_psd: vec![f64::NAN; nf * no],
        inverse_diagonal: vec![f64::NAN; nf * q],
        input_rcond: vec![0.0; nf],
        estimable: vec![false; nf],
    };
    for k in 0..nf {
        let Some((inv, rcond)) = normalized_inverse(m, k, inputs) else {
            continue;
        };
        est.input_rcond[k] = rcond;
        if rcond < INPUT_RCOND_MIN {
            continue;
        }
        est.estimable[k] = true;
        for i in 0..q {
            est.inverse_diagonal[k * q + i] = inv[(i, i)].re;
        }
        for (o, &y) in outputs.iter().enumerate() {
            let s_xy: Vec<Complex64> = inputs.iter().map(|&x| m.get(k, x, y)).collect();
            let s_yy = m.get(k, y, y).re;
            let mut explained = 0.0;
            for i in 0..q {
                let h: Complex64 = (0..q).map(|j| inv[(i, j)] * s_xy[j]).sum();
                est.tf[(k * no + o) * q + i] = h;
                explained += (s_xy[i].conj() * h).re;
            }
            let (gamma2, residual) = if s_yy > 0.0 {
                (explained / s_yy, (s_yy - explained).max(0.0))
            } else {
                (f64::NAN, 0.0)
            };
            est.multiple_coherence[k * no + o] = gamma2;
            est.residual_psd[k * no + o] = residual;
        }
    }
    Ok(est)
}

/// `S_xx^-1` of the `inputs` at bin `k` and the reciprocal condition number of the normalized
/// matrix; `None` when an input PSD is not positive and finite (rcond 0).
fn normalized_inverse(
    m: &CrossSpectra,
    k: usize,
    inputs: &[usize],
) -> Option<(DMatrix<Complex64>, f64)> {
    let q = inputs.len();
    let scale: Vec<f64> = inputs
        .iter()
        .map(|&i| m.get(k, i, i).re)
        .map(|p| {
            if p > 0.0 && p.is_finite() {
                1.0 / p.sqrt()
            } else {
                f64::NAN
            }
        })
        .collect();
    if scale.iter().any(|s| s.is_nan()) {
        return None;
    }
    let c = DMatrix::from_fn(q, q, |a, b| {
        if a == b {
            Complex64::new(1.0, 0.0)
        } else {
            m.get(k, inputs[a], inputs[b]) * (scale[a] * scale[b])
        }
    });
    if c.iter().any(|z| !(z.re.is_finite() && z.im.is_finite())) {
        return None;
    }
    let eig = c.symmetric_eigen();
    let l_max = eig.eigenvalues.max();
    let l_min = eig.eigenvalues.min();
    let rcond = if l_max > 0.0 {
        (l_min / l_max).max(0.0)
    } else {
        0.0
    };
    if rcond < INPUT_RCOND_MIN {
        return Some((DMatrix::zeros(q, q), rcond));
    }
    let v = &eig.eigenvectors;
    let inv = DMatrix::from_fn(q, q, |a, b| {
        let c_inv: Complex64 = (0..q)
            .map(|l| v[(a, l)] * v[(b, l)].conj() / eig.eigenvalues[l])
            .sum();
        c_inv * (scale[a] * scale[b])
    });
    Some((inv, rcond))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cross-spectral matrix with given per-bin blocks.
    fn spectra(blocks: &[Vec<Complex64>], n: usize) -> CrossSpectra {
        CrossSpectra {
            freqs_hz: (0..blocks.len()).map(|k| k as f64).collect(),
            n_channels: n,
            data: blocks.concat(),
            n_segments: 10,
        }
    }

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    #[test]
    fn exact_linear_system_is_recovered() {
        // Two inputs with S_xx = [[2, 1+i], [1-i, 3]], y = H1 x1 + H2 x2 without noise:
        // s_xy = S_xx H, S_yy = H^H S_xx H.
        let sxx = [[c(2.0, 0.0), c(1.0, 1.0)], [c(1.0, -1.0), c(3.0, 0.0)]];
        let h = [c(0.5, -2.0), c(-1.5, 0.25)];
        let s_xy: Vec<Complex64> = (0..2)
            .map(|i| (0..2).map(|j| sxx[i][j] * h[j]).sum())
            .collect();
        let s_yy: f64 = (0..2).map(|i| (h[i].conj() * s_xy[i]).re).sum();
        let block = vec![
            sxx[0][0],
            sxx[0][1],
            s_xy[0],
            sxx[1][0],
            sxx[1][1],
            s_xy[1],
            s_xy[0].conj(),
            s_xy[1].conj(),
            c(s_yy, 0.0),
        ];
        let m = spectra(&[block], 3);
        let est = multiple_input(&m, &[0, 1], &[2]).unwrap();
        assert!(est.estimable[0]);
        for (i, hi) in h.iter().enumerate() {
            assert!((est.tf_at(0, 0, i) - hi).norm() < 1e-14, "{i}");
        }
        assert!((est.multiple_coherence_at(0, 0) - 1.0).abs() < 1e-14);
        assert!(est.residual_psd_at(0, 0) < 1e-13 * s_yy);
        // (S_xx^-1)_00 = 3 / det, det = 6 - 2 = 4.
        assert!((est.inverse_diagonal_at(0, 0) - 0.75).abs() < 1e-15);
    }

    #[test]
    fn dependent_or_dead_inputs_are_not_estimable() {
        // x2 = 2 x1: S_xx singular.
        let dependent = vec![
            c(1.0, 0.0),
            c(2.0, 0.0),
            c(1.0, 0.0),
            c(2.0, 0.0),
            c(4.0, 0.0),
            c(2.0, 0.0),
            c(1.0, 0.0),
            c(2.0, 0.0),
            c(1.0, 0.0),
        ];
        // x1 dead (zero PSD).
        let dead = vec![
            c(0.0, 0.0),
            c(0.0, 0.0),
            c(0.0, 0.0),
            c(0.0, 0.0),
            c(1.0, 0.0),
            c(0.5, 0.0),
            c(0.0, 0.0),
            c(0.5, 0.0),
            c(1.0, 0.0),
        ];
        let m = spectra(&[dependent, dead], 3);
        let est = multiple_input(&m, &[0, 1], &[2]).unwrap();
        assert_eq!(est.estimable, [false, false]);
        assert!(est.input_rcond[0] < INPUT_RCOND_MIN);
        assert_eq!(est.input_rcond[1], 0.0);
        assert!(est.tf_at(0, 0, 0).re.is_nan() && est.multiple_coherence_at(1, 0).is_nan());
        assert!(coherence(&m, 0, 2)[1].is_nan());
        assert!((coherence(&m, 1, 2)[1] - 0.25).abs() < 1e-15);
    }

    #[test]
    fn bad_indices_are_refused() {
        let m = spectra(&[vec![c(1.0, 0.0)]], 1);
        assert_eq!(
            multiple_input(&m, &[], &[0]).unwrap_err(),
            SpectralError::NoChannels
        );
        assert_eq!(
            multiple_input(&m, &[0], &[1]).unwrap_err(),
            SpectralError::ChannelCountMismatch {
                expected: 1,
                got: 1
            }
        );
    }
}
