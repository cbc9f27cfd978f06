//! The cleaned record judged against the raw one before it is written, band by band: in every
//! 1/3-decade band of the Welch grid of the whole overlap, the band-mean PSD of the cleaned
//! record against the raw record's, beside the residual the model expects. A band where the
//! cleaned record is above the raw one is left raw (its prediction masked out, with a
//! raised-cosine edge) and the check repeated; a record whose variance would still grow is left
//! raw entirely.
//!
//! The statistical error of a band ratio is that of the raw band mean, `sqrt(2 / nu)` with
//! `nu` the equivalent degrees of freedom of the band ([`crate::spectral::band_dof`]: overlap
//! and bin correlations included); the limit a statistically honest subtraction stays below on
//! fresh data is `1 + z sigma` with `z` the 3-sigma point corrected for the number of bands
//! (one-sided, `0.27 % / bands`; Bonferroni).

use crate::spectral::{band_dof, confidence::normal_quantile, WelchConfig};

/// Bands per decade.
pub const BANDS_PER_DECADE: f64 = 3.0;
/// Width of a left-out band's edge taper, as a fraction of a band's width in log frequency:
/// the mask rises from 0 to 1 over this much beyond each edge.
pub const EDGE_TAPER_FRACTION: f64 = 0.1;

/// One band of one observable.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Band {
    /// Edges (Hz); the first band reaches down to DC, the last includes Nyquist.
    pub lo_hz: f64,
    /// Upper edge (Hz).
    pub hi_hz: f64,
    /// Welch bins in the band.
    pub bins: usize,
    /// Band-mean PSD of the raw record (unit^2/Hz).
    pub raw_psd: f64,
    /// Band-mean PSD the model expects of the cleaned record.
    pub expected_psd: f64,
    /// Band-mean PSD of the cleaned record as written.
    pub cleaned_psd: f64,
    /// Band-mean PSD of the witness-limited residual (what no filter of the witness removes).
    pub witness_limited_psd: f64,
    /// `cleaned / raw` of the record as written.
    pub ratio: f64,
    /// Relative standard error of the raw band mean.
    pub sigma: f64,
    /// `1 + z sigma` ([`corrected_z`]).
    pub limit: f64,
    /// The prediction was worse than nothing here: the band is left raw.
    pub left_raw: bool,
}

/// The check of one observable.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BandCheck {
    /// The bands, increasing.
    pub bands: Vec<Band>,
    /// Variance of the cleaned record over that of the raw one (means removed).
    pub variance_ratio: f64,
    /// The cleaned record's variance would have grown: the record is left raw entirely.
    pub left_raw: bool,
}

/// The 1/3-decade bands covering bins `1 ..= last` of `freqs`: `(lo, hi, first bin, end bin)`,
/// edges at `10^(j/3)` Hz, the first band's `lo` set to 0 and the last band's `hi` to infinity
/// so that every frequency of a finer grid falls in one band.
pub fn third_decade_bands(freqs: &[f64]) -> Vec<(f64, f64, usize, usize)> {
    let last = freqs.len() - 1;
    let index = |f: f64| (f.log10() * BANDS_PER_DECADE).floor() as i64;
    let edge = |j: i64| 10f64.powf(j as f64 / BANDS_PER_DECADE);
    let mut out: Vec<(f64, f64, usize, usize)> = Vec::new();
    for k in 1..=last {
        let j = index(freqs[k]);
        match out.last_mut() {
            Some(b) if index(freqs[b.2]) == j => b.3 = k + 1,
            _ => out.push((edge(j), edge(j + 1), k, k + 1)),
        }
    }
    if let Some(b) = out.first_mut() {
        b.0 = 0.0;
    }
    if let Some(b) = out.last_mut() {
        b.1 = f64::INFINITY;
    }
    out
}

/// The one-sided standard normal point that pure noise exceeds in one of `n` bands with
/// probability 0.27 % (the 3-sigma point, corrected for `n` looks).
pub fn corrected_z(n: usize) -> f64 {
    normal_quantile(1.0 - 0.00135 / n.max(1) as f64)
}

/// The mask of a prediction with the bands `left` (edges in Hz) left out: 0 inside, 1 away
/// from them, a raised cosine in log frequency over [`EDGE_TAPER_FRACTION`] of a band beyond
/// each edge.
pub fn mask(left: &[(f64, f64)], f: f64) -> f64 {
    let width = EDGE_TAPER_FRACTION / BANDS_PER_DECADE;
    left.iter()
        .map(|&(lo, hi)| {
            if f >= lo && f <= hi {
                return 0.0;
            }
            let d = if f < lo {
                (lo / f).log10()
            } else {
                (f / hi).log10()
            };
            if d >= width {
                1.0
            } else {
                (0.5 * std::f64::consts::PI * d / width).sin().powi(2)
            }
        })
        .product()
}

/// Per-bin spectra of one observable on the Welch grid of the whole overlap.
pub struct BinSpectra<'a> {
    /// Raw PSD.
    pub raw: &'a [f64],
    /// Cleaned PSD.
    pub cleaned: &'a [f64],
    /// Expected cleaned PSD.
    pub expected: &'a [f64],
    /// Witness-limited residual PSD.
    pub witness_limited: &'a [f64],
}

/// The bands of one observable; `left` are the bands already left raw (marked so, whatever
/// their ratio now).
pub fn judge(
    freqs: &[f64],
    spectra: &BinSpectra,
    cfg: &WelchConfig,
    n_segments: usize,
    left: &[(f64, f64)],
) -> Vec<Band> {
    let bands = third_decade_bands(freqs);
    let z = corrected_z(bands.len());
    bands
        .iter()
        .map(|&(lo, hi, a, b)| {
            let mean = |v: &[f64]| v[a..b].iter().sum::<f64>() / (b - a) as f64;
            let raw = mean(spectra.raw);
            let cleaned = mean(spectra.cleaned);
            let sigma = band_dof(cfg, n_segments, b - a).map_or(f64::NAN, |nu| (2.0 / nu).sqrt());
            Band {
                lo_hz: lo,
                hi_hz: hi,
                bins: b - a,
                raw_psd: raw,
                expected_psd: mean(spectra.expected),
                cleaned_psd: cleaned,
                witness_limited_psd: mean(spectra.witness_limited),
                ratio: cleaned / raw,
                sigma,
                limit: 1.0 + z * sigma,
                left_raw: left.contains(&(lo, hi)),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bands follow the decade's thirds, cover every bin once, and reach DC and beyond Nyquist.
    #[test]
    fn bands_cover_the_grid() {
        let freqs: Vec<f64> = (0..=2048).map(|k| k as f64 / 4096.0).collect();
        let b = third_decade_bands(&freqs);
        assert_eq!(b[0].0, 0.0);
        assert!(b[b.len() - 1].1.is_infinite());
        assert_eq!(b[0].2, 1);
        assert_eq!(b[b.len() - 1].3, 2049);
        for w in b.windows(2) {
            assert_eq!(w[0].3, w[1].2);
            assert_eq!(w[0].1, w[1].0);
        }
        // 1/4096 Hz .. 0.5 Hz spans 3.3 decades: 11 bands.
        assert_eq!(b.len(), 11);
        let m = mask(&[(0.01, 0.02)], 0.015);
        assert_eq!(m, 0.0);
        assert_eq!(mask(&[(0.01, 0.02)], 0.03), 1.0);
        let edge = mask(
            &[(0.01, 0.02)],
            0.02 * 10f64.powf(0.5 * EDGE_TAPER_FRACTION / 3.0),
        );
        assert!((edge - 0.5).abs() < 1e-12, "{edge}");
    }
}
