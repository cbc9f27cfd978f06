//! A spectrum given on its own frequency points (a coloured readout, a user-named noise term):
//! a one-sided ASD read between its points log-log (a power law between neighbours, exact at
//! them) and never beyond them: a budget whose band the spectrum does not cover is refused.

use crate::option_key::OptionKey;
use std::fmt;

/// A one-sided ASD on its own frequency points, with where it came from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GivenAsd {
    freqs_hz: Vec<f64>,
    asd: Vec<f64>,
    origin: String,
}

/// Why a [`GivenAsd`] cannot be made or used.
#[derive(Debug, Clone, PartialEq)]
pub struct GivenAsdError(pub crate::option_key::Message);

impl fmt::Display for GivenAsdError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl GivenAsd {
    /// An ASD (unit/sqrt(Hz)) at `freqs_hz`; `origin` names it in messages (a file and column).
    ///
    /// # Errors
    ///
    /// Fewer than 2 points, lengths that differ, a frequency that is not finite, > 0 and
    /// increasing, or an ASD that is not finite and >= 0, naming `origin`, the index and value.
    pub fn new(freqs_hz: Vec<f64>, asd: Vec<f64>, origin: &str) -> Result<GivenAsd, GivenAsdError> {
        let err = |m: String| Err(GivenAsdError(format!("{origin}: {m}").into()));
        if freqs_hz.len() != asd.len() {
            return err(format!(
                "{} frequencies but {} ASD values",
                freqs_hz.len(),
                asd.len()
            ));
        }
        if freqs_hz.len() < 2 {
            return err(format!(
                "{} point(s): at least 2 are needed",
                freqs_hz.len()
            ));
        }
        let mut previous = 0.0;
        for (k, &f) in freqs_hz.iter().enumerate() {
            if !(f.is_finite() && f > previous) {
                return err(format!(
                    "frequency {f:?} Hz at index {k} is not allowed: must be finite, > 0 and \
                     greater than the previous {previous} Hz"
                ));
            }
            previous = f;
        }
        if let Some(k) = asd.iter().position(|a| !(a.is_finite() && *a >= 0.0)) {
            return err(format!(
                "ASD {:?} at index {k} ({} Hz) is not allowed: must be finite and >= 0",
                asd[k], freqs_hz[k]
            ));
        }
        Ok(GivenAsd {
            freqs_hz,
            asd,
            origin: origin.to_string(),
        })
    }

    /// Where it came from.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// `[f_first, f_last]` (Hz).
    pub fn band_hz(&self) -> (f64, f64) {
        (self.freqs_hz[0], self.freqs_hz[self.freqs_hz.len() - 1])
    }

    /// Refuses a band `[lo, hi]` (Hz) that the spectrum does not cover: it is never
    /// extrapolated.
    pub fn check_covers(&self, lo: f64, hi: f64) -> Result<(), GivenAsdError> {
        let (a, b) = self.band_hz();
        if lo < a || hi > b {
            return Err(GivenAsdError(crate::message!(
                "{}: the spectrum covers {a:e} .. {b:e} Hz, the budget's band is {lo:e} .. \
                 {hi:e} Hz; a given spectrum is never extrapolated: give one that covers the \
                 band, or narrow the band (Welch segments, or {} for spectra input)",
                self.origin.clone(),
                OptionKey::FREQ
            )));
        }
        Ok(())
    }

    /// The one-sided PSD (unit^2/Hz) at every frequency of `grid_hz`, each inside the band
    /// ([`GivenAsd::check_covers`]).
    pub fn psd_on(&self, grid_hz: &[f64]) -> Vec<f64> {
        let psd: Vec<f64> = self.asd.iter().map(|a| a * a).collect();
        grid_hz
            .iter()
            .map(|&f| loglog_at(&self.freqs_hz, &psd, f).unwrap_or(f64::NAN))
            .collect()
    }
}

/// Log-log interpolation of a non-negative spectrum `(freqs, values)` at `f`: a power law
/// between the neighbouring points (linear where one of them is 0), the value itself at a
/// point. `None` outside `[freqs[0], freqs[last]]`.
pub fn loglog_at(freqs: &[f64], values: &[f64], f: f64) -> Option<f64> {
    let k = freqs.partition_point(|&x| x < f);
    if k == freqs.len() || (k == 0 && freqs[0] != f) {
        return None;
    }
    if freqs[k] == f {
        return Some(values[k]);
    }
    let (f0, f1, v0, v1) = (freqs[k - 1], freqs[k], values[k - 1], values[k]);
    if v0 <= 0.0 || v1 <= 0.0 {
        return Some(v0 + (v1 - v0) * (f - f0) / (f1 - f0));
    }
    let t = (f / f0).ln() / (f1 / f0).ln();
    Some((v0.ln() + t * (v1 / v0).ln()).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_power_law_is_read_exactly_between_points_and_never_beyond() {
        let g = GivenAsd::new(vec![1e-3, 1e-1], vec![1e-6, 1e-8], "r.csv").unwrap();
        let psd = g.psd_on(&[1e-3, 1e-2, 1e-1]);
        assert_eq!(psd[0], 1e-12);
        assert!((psd[1] / 1e-14 - 1.0).abs() < 1e-14, "{}", psd[1]);
        assert!(g.check_covers(1e-3, 1e-1).is_ok());
        let e = g.check_covers(1e-4, 1e-2).unwrap_err().to_string();
        assert!(
            e.starts_with("r.csv: the spectrum covers 1e-3 .. 1e-1 Hz"),
            "{e}"
        );
        for (f, a, what) in [
            (vec![1.0, 1.0], vec![1.0, 1.0], "greater than the previous"),
            (vec![0.0, 1.0], vec![1.0, 1.0], "> 0"),
            (vec![1.0, 2.0], vec![1.0, -1.0], "ASD -1.0 at index 1"),
            (vec![1.0, 2.0], vec![f64::NAN, 1.0], "ASD NaN at index 0"),
            (vec![1.0], vec![1.0], "at least 2"),
        ] {
            let e = GivenAsd::new(f, a, "x.csv").unwrap_err().to_string();
            assert!(e.starts_with("x.csv: ") && e.contains(what), "{e}");
        }
    }
}
