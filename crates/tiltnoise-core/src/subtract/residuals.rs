//! What is left after subtraction, judged on the held-out stretch: the measured PSD, the
//! predicted tilt part, the model-cleaned residual, the residual of a multiple-input Wiener
//! filter trained on the training stretch, and the residual the coherence allows.
//!
//! * **Wiener filter**: per bin `W = S^-1 s` from the training stretch's spectra (the
//!   multiple-input optimum, Bendat and Piersol, *Random Data*, ch. 7); applied to the held-out
//!   stretch segment by segment, its residual PSD is
//!   `S_yy - 2 Re(sum_a W_a conj(s_a)) + W^H S W` with the held-out spectra: exactly the Welch
//!   PSD of `y - W^T w` on the Welch grid. A filter estimated from `n` averages leaves on fresh
//!   data, in expectation, `n / (n - A)` times the residual the exact filter would (the
//!   estimation error of `W`, complex Wishart with `A` inputs): its training-noise excess
//!   `A / (n - A)`, reported beside it and removed in its corrected value.
//! * **Expected residual**: `S_yy (1 - gamma^2)` with the multiple coherence
//!   `gamma^2 = s^H S^-1 s / S_yy` of the held-out stretch itself, corrected for the
//!   estimator's bias (`E[1 - gamma_hat^2] = (1 - gamma^2)(1 - A / n)` for `A` inputs and `n`
//!   independent averages, Bendat and Piersol sec. 9.3; `n` the effective number of the
//!   overlapped segments, [`crate::spectral::confidence::equivalent_averages`]): no linear
//!   filter of the witness record, whatever stretch it was trained on, can leave less on that
//!   stretch.
//! * **Witness-limited residual**: `G^H R G` of the fitted model and the training stretch's
//!   smoothed witness spectra ([`super::weighting`]): what the witness's own noise keeps any
//!   filter of it from removing, in total and per input.
//! * **Band summaries**: the mean PSD over the bins of a band, its relative statistical error
//!   `sqrt(c / (n m))` (`m` bins, `n` effective averages, `c` the variance factor of adjacent
//!   Hann bins), and the model-cleaned residual against the readout and against the expected
//!   residual; a cleaned residual more than 3 sigma below the expected one is flagged (the
//!   subtraction claims more than the coherence allows: overfitting or non-stationarity).

use super::problem::{coherence_residual, residual_psd};
use super::ModelSpectra;
use crate::model::Observable;
use crate::spectral::CrossSpectra;
use nalgebra::{DMatrix, DVector};
use num_complex::Complex64;

/// Spectra of one observable on the held-out stretch (one-sided PSDs, unit^2/Hz, on the Welch
/// grid with DC).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ResidualSpectra {
    /// The observable.
    pub observable: Observable,
    /// Welch frequencies (Hz), DC first.
    pub freqs_hz: Vec<f64>,
    /// Measured PSD.
    pub measured_psd: Vec<f64>,
    /// PSD of the predicted tilt part.
    pub predicted_psd: Vec<f64>,
    /// PSD of measured minus predicted.
    pub cleaned_psd: Vec<f64>,
    /// PSD of the Wiener filter's residual.
    pub wiener_psd: Vec<f64>,
    /// The residual the held-out stretch's coherence allows.
    pub expected_psd: Vec<f64>,
    /// The witness-limited residual of the fitted model (all inputs together).
    pub witness_limited_psd: Vec<f64>,
    /// The witness-limited residual per input, each alone.
    pub witness_limited_by_input: Vec<Vec<f64>>,
    /// The Wiener filter's expected training-noise excess `A / (n - A)` over the exact filter.
    pub wiener_training_excess: f64,
    /// White readout ASD (unit/sqrt(Hz)) if given.
    pub readout_asd: Option<f64>,
    /// Summary over the report band.
    pub band: BandSummary,
}

/// Mean PSDs over the report band, as ASDs (unit/sqrt(Hz)).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BandSummary {
    /// First and last bin frequency of the band (Hz).
    pub band_hz: (f64, f64),
    /// Bins averaged.
    pub bins: usize,
    /// Measured.
    pub measured_asd: f64,
    /// Predicted tilt part.
    pub predicted_asd: f64,
    /// Model-cleaned residual.
    pub cleaned_asd: f64,
    /// Wiener residual.
    pub wiener_asd: f64,
    /// Wiener residual with its training-noise excess removed.
    pub wiener_corrected_asd: f64,
    /// Witness-limited residual.
    pub witness_limited_asd: f64,
    /// Coherence-allowed residual.
    pub expected_asd: f64,
    /// Relative statistical error (1 sigma) of a band-mean PSD.
    pub psd_rel_sigma: f64,
    /// Cleaned / readout ASD and its 1-sigma error, when the readout is given.
    pub cleaned_to_readout: Option<(f64, f64)>,
    /// Cleaned / expected ASD and its 1-sigma error.
    pub cleaned_to_expected: (f64, f64),
    /// The cleaned residual is more than 3 sigma below the expected one.
    pub below_coherence_bound: bool,
}

/// Wiener filters of every observable from the training spectra.
pub struct Wiener {
    n_in: usize,
    /// `A / (n - A)` for `n` effective training averages.
    excess: f64,
    /// `[observable][bin]`.
    filters: Vec<Vec<Option<DVector<Complex64>>>>,
}

fn blocks(
    spectra: &CrossSpectra,
    k: usize,
    n_in: usize,
    y: usize,
) -> (DMatrix<Complex64>, DVector<Complex64>, f64) {
    let n = spectra.n_channels;
    let m = spectra.matrix(k);
    (
        DMatrix::from_fn(n_in, n_in, |a, b| m[a * n + b]),
        DVector::from_fn(n_in, |a, _| m[a * n + y]),
        m[y * n + y].re,
    )
}

impl Wiener {
    /// Trains on `spectra` (witness inputs `0..n_in`, then `n_out` observables) of `n_eff`
    /// effective averages.
    pub fn train(spectra: &CrossSpectra, n_in: usize, n_out: usize, n_eff: f64) -> Wiener {
        let filters = (0..n_out)
            .map(|o| {
                (0..spectra.n_freqs())
                    .map(|k| {
                        let (sww, s, _) = blocks(spectra, k, n_in, n_in + o);
                        sww.lu().solve(&s)
                    })
                    .collect()
            })
            .collect();
        let a = n_in as f64;
        let excess = if n_eff > a { a / (n_eff - a) } else { f64::NAN };
        Wiener {
            n_in,
            excess,
            filters,
        }
    }
}

/// The coherence limit `S_yy (1 - gamma^2)` of channel `y` against channels `0..n_in` of
/// `spectra` per bin, corrected for the estimator's bias with `n_eff` averages and clamped to
/// `[0, S_yy]` (`S_yy` where the inputs' matrix is singular).
pub fn coherence_limit(spectra: &CrossSpectra, n_in: usize, y: usize, n_eff: f64) -> Vec<f64> {
    let a = n_in as f64;
    let bias = if n_eff > a {
        n_eff / (n_eff - a)
    } else {
        f64::NAN
    };
    (0..spectra.n_freqs())
        .map(|k| {
            let (sww, s, syy) = blocks(spectra, k, n_in, y);
            coherence_residual(syy, &s, &sww).map_or(syy, |left| (left * bias).clamp(0.0, syy))
        })
        .collect()
}

/// Inputs of [`evaluate`]: the held-out spectra and series' PSDs.
pub struct HeldOut<'a> {
    /// Cross spectra of the tilt axes and the observables on the held-out stretch.
    pub spectra: &'a CrossSpectra,
    /// PSDs of the predicted tilt parts, per observable.
    pub predicted_psd: &'a [Vec<f64>],
    /// PSDs of the cleaned series, per observable.
    pub cleaned_psd: &'a [Vec<f64>],
    /// Effective averages of the held-out Welch estimate.
    pub n_eff: f64,
    /// Variance factor of a mean over adjacent bins.
    pub bin_variance_factor: f64,
    /// The model's spectra per observable (witness-limited residuals).
    pub witness_limited: &'a [ModelSpectra],
}

/// Residual spectra and band summaries of every observable.
pub fn evaluate(
    wiener: &Wiener,
    held: &HeldOut,
    outputs: &[Observable],
    readout: &[(Observable, f64)],
    band_hz: (f64, f64),
) -> Vec<ResidualSpectra> {
    let n_in = wiener.n_in;
    let freqs = &held.spectra.freqs_hz;
    let lo = freqs.partition_point(|&f| f < band_hz.0).max(1);
    let hi = freqs.partition_point(|&f| f <= band_hz.1);
    outputs
        .iter()
        .enumerate()
        .map(|(o, &obs)| {
            let ms = &held.witness_limited[o];
            let mut measured = Vec::with_capacity(freqs.len());
            let mut wien = Vec::with_capacity(freqs.len());
            for k in 0..freqs.len() {
                let (sww, s, syy) = blocks(held.spectra, k, n_in, n_in + o);
                measured.push(syy);
                wien.push(match &wiener.filters[o][k] {
                    Some(w) => residual_psd(syy, &s, &sww, w).max(0.0),
                    None => syy,
                });
            }
            let expected = coherence_limit(held.spectra, n_in, n_in + o, held.n_eff);
            let readout_asd = readout.iter().find(|(x, _)| *x == obs).map(|r| r.1);
            let mean = |v: &[f64]| -> f64 {
                if hi > lo {
                    v[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
                } else {
                    f64::NAN
                }
            };
            let m = hi.saturating_sub(lo);
            let rel = (held.bin_variance_factor / (held.n_eff * m as f64)).sqrt();
            let (pm, pc, pe) = (mean(&measured), mean(&held.cleaned_psd[o]), mean(&expected));
            // Ratio of ASDs: half the relative error of the PSD ratio; the cleaned and expected
            // band means come from the same segments, so their errors are taken as independent
            // (an upper bound on the ratio's error, their correlation being positive).
            let to_expected = ((pc / pe).sqrt(), (pc / pe).sqrt() * rel * 2f64.sqrt() / 2.0);
            let band = BandSummary {
                band_hz: (
                    freqs.get(lo).copied().unwrap_or(f64::NAN),
                    freqs.get(hi.max(1) - 1).copied().unwrap_or(f64::NAN),
                ),
                bins: m,
                measured_asd: pm.sqrt(),
                predicted_asd: mean(&held.predicted_psd[o]).sqrt(),
                cleaned_asd: pc.sqrt(),
                wiener_asd: mean(&wien).sqrt(),
                wiener_corrected_asd: (mean(&wien) / (1.0 + wiener.excess)).sqrt(),
                witness_limited_asd: mean(&ms.witness_limited).sqrt(),
                expected_asd: pe.sqrt(),
                psd_rel_sigma: rel,
                cleaned_to_readout: readout_asd.filter(|&r| r > 0.0).map(|r| {
                    let ratio = pc.sqrt() / r;
                    (ratio, ratio * rel / 2.0)
                }),
                cleaned_to_expected: to_expected,
                below_coherence_bound: pc < pe * (1.0 - 3.0 * rel * 2f64.sqrt()),
            };
            ResidualSpectra {
                observable: obs,
                freqs_hz: freqs.clone(),
                measured_psd: measured,
                predicted_psd: held.predicted_psd[o].clone(),
                cleaned_psd: held.cleaned_psd[o].clone(),
                wiener_psd: wien,
                expected_psd: expected,
                witness_limited_psd: ms.witness_limited.clone(),
                witness_limited_by_input: ms.witness_limited_by_input.clone(),
                wiener_training_excess: wiener.excess,
                readout_asd,
                band,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::spectral::confidence::equivalent_averages;
    use crate::spectral::{csd_matrix, WelchConfig};

    /// Two white inputs and an output `y = 0.8 x1 + 0.3 x2 + n` (`1 - gamma^2 = S_nn / S_yy`
    /// known), Welch over 15 half-overlapping Hann segments, 400 realisations of 128 bins:
    ///
    /// * the coherence limit, corrected with the effective number of averages of the
    ///   overlapped segments (`n_eff = 14.2` for `K = 15`), is unbiased for `S_nn` to its
    ///   Monte Carlo error (3 standard errors, about 0.4 %); corrected with `K` it would be
    ///   0.9 % low;
    /// * a Wiener filter trained on one realisation leaves on the next, in expectation,
    ///   `1 + A / (n_eff - A)` times `S_nn` (its training-noise excess, 16 % here).
    #[test]
    fn coherence_limit_and_wiener_excess_use_the_effective_averages() {
        let (seg, k) = (256usize, 15usize);
        let n = seg / 2 * (k + 1);
        let cfg = WelchConfig::new(seg);
        let n_eff = equivalent_averages(&cfg, k);
        let s_nn = 2.0 * 0.5f64.powi(2);
        let mut rng = Rng::stream(5, 0);
        let mut draw = || -> Vec<Vec<f64>> {
            let mut x1 = vec![0.0; n];
            let mut x2 = vec![0.0; n];
            let mut y = vec![0.0; n];
            for i in 0..n {
                x1[i] = rng.gaussian();
                x2[i] = rng.gaussian();
                y[i] = 0.8 * x1[i] + 0.3 * x2[i] + 0.5 * rng.gaussian();
            }
            vec![x1, x2, y]
        };
        let spectra = |d: &[Vec<f64>]| {
            let chans: Vec<&[f64]> = d.iter().map(Vec::as_slice).collect();
            csd_matrix(&chans, 1.0, &cfg).unwrap()
        };
        let (mut limit, mut wiener, mut count) = (0.0, 0.0, 0.0);
        let mut previous = spectra(&draw());
        for _ in 0..400 {
            let now = spectra(&draw());
            assert_eq!(now.n_segments, k);
            let l = coherence_limit(&now, 2, 2, n_eff);
            let w = Wiener::train(&previous, 2, 1, n_eff);
            // DC and Nyquist excluded: their Welch estimates have half the degrees of freedom.
            for (b, l_b) in l.iter().enumerate().take(now.n_freqs() - 1).skip(1) {
                limit += l_b / s_nn;
                let (sww, s, syy) = blocks(&now, b, 2, 2);
                let f = w.filters[0][b].as_ref().unwrap();
                wiener += residual_psd(syy, &s, &sww, f) / s_nn;
                count += 1.0;
            }
            previous = now;
        }
        let (limit, wiener) = (limit / count, wiener / count);
        eprintln!("coherence limit / S_nn = {limit:.5}, Wiener residual / S_nn = {wiener:.4}");
        // Per bin the ratio scatters by about 1/sqrt(n_eff); neighbouring bins are correlated
        // (variance factor 1.944 for Hann).
        let se = (1.944 / (n_eff * count)).sqrt();
        let excess = 2.0 / (n_eff - 2.0);
        assert!((limit - 1.0).abs() < 3.0 * se, "{limit} +- {se}");
        assert!(
            (wiener / (1.0 + excess) - 1.0).abs() < 3.0 * se * (1.0 + excess),
            "{wiener} vs {}",
            1.0 + excess
        );
    }
}
