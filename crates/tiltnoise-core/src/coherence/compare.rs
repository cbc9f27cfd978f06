//! One complex factor between a measured transfer function and the model's: how well the
//! model's coupling matches the data, in one number with its error.
//!
//! With `H_k` the measured estimate at bin `k`, `sigma_k` its standard error per real
//! direction and `M_k` the model, the weighted least-squares fit of `H_k = g M_k` is
//!
//! ```text
//! g = sum_k conj(M_k) H_k / sigma_k^2  /  sum_k |M_k|^2 / sigma_k^2
//! ```
//!
//! Its error follows from the correlation `c_j` of the estimates of bins `j` apart
//! ([`crate::spectral::confidence::bin_correlation`]): with `a_k = conj(M_k) / sigma_k^2 / W`,
//! `W = sum |M_k|^2 / sigma_k^2`, the variance per real direction is
//! `sum_{k,l} Re(a_k conj(a_l)) c_|k-l| sigma_k sigma_l` (for independent bins `1 / W`). The
//! misfit `chi^2 = sum_k |H_k - g M_k|^2 / sigma_k^2` over `nu = 2 (n - 1)` real degrees
//! of freedom tells whether one factor describes the data (`chi^2 / nu` near 1; adjacent-bin
//! correlation lowers its spread but not its mean) or the model's shape differs from the data.
//! `|g|` is the measured/model gain, `arg g` the phase of the data relative to the model; a
//! model with the wrong sign shows `arg g = 180 deg`.

use num_complex::Complex64;

/// The measured/model factor of one transfer-function entry (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Agreement {
    /// Bins used.
    pub n_bins: usize,
    /// Lowest and highest frequency used (Hz).
    pub band_hz: (f64, f64),
    /// The factor `g`: measured = `g` x model.
    pub factor: Complex64,
    /// Standard error of `g` per real direction: of `|g|`, and of `arg g` times `|g|` (rad).
    pub sigma: f64,
    /// `chi^2 / nu` of the fit (NaN for a single bin).
    pub chi2_per_dof: f64,
}

impl Agreement {
    /// `|g|`, the measured/model gain.
    pub fn gain(&self) -> f64 {
        self.factor.norm()
    }

    /// `arg g` in degrees, in (-180, 180].
    pub fn phase_deg(&self) -> f64 {
        self.factor.arg().to_degrees()
    }

    /// Standard error of [`Agreement::phase_deg`] (degrees).
    pub fn phase_sigma_deg(&self) -> f64 {
        (self.sigma / self.gain()).to_degrees()
    }
}

/// `value` and its standard error `error` as text, the error to two significant digits and the
/// value to the same decimal place: `(1.10012, 0.00013)` gives `("1.10012", "0.00013")`. Plain
/// `{:e}`-free decimals for errors down to 1e-12, scientific notation below or for a non-finite
/// error.
pub fn with_error(value: f64, error: f64) -> (String, String) {
    if !(error.is_finite() && error > 1e-12 && value.is_finite()) {
        return (format!("{value:.3e}"), format!("{error:.1e}"));
    }
    let decimals = (1 - error.log10().floor() as i64).max(0) as usize;
    (format!("{value:.decimals$}"), format!("{error:.decimals$}"))
}

/// Fits `tf = g model` over the bins where `usable` holds and the model, the estimate and its
/// error are finite with `sigma > 0`, `model != 0` (module docs). `correlation` is `c_0, c_1,
/// c_2` of adjacent-bin estimation errors. `None` when no bin qualifies.
pub fn fit_agreement(
    freqs_hz: &[f64],
    tf: &[Complex64],
    sigma: &[f64],
    model: &[Complex64],
    usable: &[bool],
    correlation: [f64; 3],
) -> Option<Agreement> {
    let finite = |z: Complex64| z.re.is_finite() && z.im.is_finite();
    let bins: Vec<usize> = (0..freqs_hz.len())
        .filter(|&k| {
            usable[k]
                && finite(tf[k])
                && finite(model[k])
                && model[k].norm() > 0.0
                && sigma[k].is_finite()
                && sigma[k] > 0.0
        })
        .collect();
    if bins.is_empty() {
        return None;
    }
    let weight: f64 = bins
        .iter()
        .map(|&k| model[k].norm_sqr() / (sigma[k] * sigma[k]))
        .sum();
    let a: Vec<Complex64> = bins
        .iter()
        .map(|&k| model[k].conj() / (sigma[k] * sigma[k] * weight))
        .collect();
    let factor: Complex64 = bins.iter().zip(&a).map(|(&k, ak)| ak * tf[k]).sum();
    let mut variance = 0.0;
    for (x, &k) in bins.iter().enumerate() {
        // Bins more than two apart are uncorrelated; `bins` is increasing.
        for (y, &l) in bins.iter().enumerate().skip(x) {
            let lag = l - k;
            if lag > 2 {
                break;
            }
            let term = (a[x] * a[y].conj()).re * correlation[lag] * sigma[k] * sigma[l];
            variance += if lag == 0 { term } else { 2.0 * term };
        }
    }
    let chi2: f64 = bins
        .iter()
        .map(|&k| (tf[k] - factor * model[k]).norm_sqr() / (sigma[k] * sigma[k]))
        .sum();
    let dof = 2.0 * (bins.len() as f64 - 1.0);
    Some(Agreement {
        n_bins: bins.len(),
        band_hz: (freqs_hz[bins[0]], freqs_hz[bins[bins.len() - 1]]),
        factor,
        sigma: variance.sqrt(),
        chi2_per_dof: if dof > 0.0 { chi2 / dof } else { f64::NAN },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_shown_to_the_precision_of_their_error() {
        assert_eq!(
            with_error(1.100_123, 0.000_134),
            ("1.10012".into(), "0.00013".into())
        );
        assert_eq!(with_error(27.85, 9.78), ("27.9".into(), "9.8".into()));
        assert_eq!(with_error(1234.5, 250.0), ("1234".into(), "250".into()));
        assert_eq!(with_error(1.0, f64::NAN).1, "NaN");
    }

    #[test]
    fn exact_scaled_model_gives_its_factor_and_no_misfit() {
        let f = [1.0, 2.0, 3.0, 4.0, 5.0];
        let model: Vec<Complex64> = f.iter().map(|&x| Complex64::new(1.0 / x, -x)).collect();
        let g = Complex64::from_polar(1.2, -0.3);
        let tf: Vec<Complex64> = model.iter().map(|m| g * m).collect();
        let sigma = [0.1, 0.2, 0.1, 0.3, 0.1];
        let usable = [true, true, false, true, true];
        let a = fit_agreement(&f, &tf, &sigma, &model, &usable, [1.0, 0.0, 0.0]).unwrap();
        assert!((a.factor - g).norm() < 1e-15);
        assert_eq!(a.n_bins, 4);
        assert_eq!(a.band_hz, (1.0, 5.0));
        assert!(a.chi2_per_dof < 1e-28);
        // Independent bins: sigma = 1 / sqrt(W).
        let w: f64 = [0usize, 1, 3, 4]
            .iter()
            .map(|&k| model[k].norm_sqr() / (sigma[k] * sigma[k]))
            .sum();
        assert!((a.sigma - 1.0 / w.sqrt()).abs() < 1e-15);
        assert!((a.phase_deg() + 0.3f64.to_degrees()).abs() < 1e-12);
    }

    #[test]
    fn correlated_neighbours_inflate_the_error_and_nothing_usable_is_none() {
        let f = [1.0, 2.0, 3.0];
        let model = [Complex64::new(1.0, 0.0); 3];
        let tf = model;
        let sigma = [1.0; 3];
        let usable = [true; 3];
        let independent = fit_agreement(&f, &tf, &sigma, &model, &usable, [1.0, 0.0, 0.0]);
        let hann = fit_agreement(
            &f,
            &tf,
            &sigma,
            &model,
            &usable,
            [1.0, 4.0 / 9.0, 1.0 / 36.0],
        );
        let (i, h) = (independent.unwrap().sigma, hann.unwrap().sigma);
        // Equal weights 1/3: variance = (3 + 2 * 2 * 4/9 + 2 / 36) / 9.
        let want = ((3.0 + 16.0 / 9.0 + 2.0 / 36.0) / 9.0f64).sqrt();
        assert!((h - want).abs() < 1e-15 && (i - (1.0f64 / 3.0).sqrt()).abs() < 1e-15);
        assert!(fit_agreement(
            &f,
            &tf,
            &sigma,
            &[Complex64::new(0.0, 0.0); 3],
            &usable,
            [1.0; 3]
        )
        .is_none());
    }
}
