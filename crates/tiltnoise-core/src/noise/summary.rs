//! The budget read at chosen frequencies (for example 1, 2 and 5 mHz): every term's PSD there
//! and how it was obtained, never an interpolation between the bins of an estimate.
//!
//! * [`Evaluation::Exact`]: a term of the model evaluated at exactly that frequency: the thermal
//!   formula, a white readout, a given spectrum (tilt spectra input) taken at the frequency
//!   (log-log between its points, exact at them) through the transfer functions evaluated
//!   there.
//! * [`Evaluation::BandMean`]: a term estimated by Welch's method from a time series (tilt from
//!   a measured record, a measured spectrum): the mean PSD over the estimate's bins within a
//!   stated band around the frequency, with its equivalent chi-squared degrees of freedom
//!   ([`crate::spectral::band_dof`]) when they are known.
//!
//! PSDs are one-sided, in (observable unit)^2/Hz, as everywhere in [`crate::noise`].

use super::TermKind;
use crate::model::Observable;

/// A Welch term averaged over the bins of a band.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BandMean {
    /// Frequency of the first bin in the band (Hz).
    pub first_bin_hz: f64,
    /// Frequency of the last bin in the band (Hz).
    pub last_bin_hz: f64,
    /// Number of bins averaged.
    pub n_bins: usize,
    /// Equivalent chi-squared degrees of freedom of the mean; `None` where they are not known
    /// (median averaging, a spectrum given without its averaging).
    pub dof: Option<f64>,
}

impl BandMean {
    /// Relative standard deviation of the band-averaged PSD, `sqrt(2 / dof)`.
    pub fn psd_rel_std(&self) -> Option<f64> {
        self.dof.map(|nu| (2.0 / nu).sqrt())
    }
}

/// How a summary value was obtained (see the module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Evaluation {
    /// At exactly the frequency.
    Exact,
    /// Mean over the bins of a band.
    BandMean(BandMean),
}

impl Evaluation {
    /// `exact` or `band_mean`, the key in the files.
    pub fn name(&self) -> &'static str {
        match self {
            Evaluation::Exact => "exact",
            Evaluation::BandMean(_) => "band_mean",
        }
    }
}

/// One term at one frequency.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TermAt {
    /// What the term is.
    pub kind: TermKind,
    /// One-sided PSD, (observable unit)^2/Hz.
    pub psd: f64,
    /// How it was obtained.
    pub evaluation: Evaluation,
}

impl TermAt {
    /// Standard deviation of the PSD from the estimate's statistics: 0 for an exact value,
    /// `psd sqrt(2 / dof)` for a band mean, `None` when the degrees of freedom are unknown.
    pub fn psd_std(&self) -> Option<f64> {
        match &self.evaluation {
            Evaluation::Exact => Some(0.0),
            Evaluation::BandMean(b) => b.psd_rel_std().map(|r| r * self.psd),
        }
    }
}

/// The terms of one observable at one frequency, in the budget's term order.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ObservableAt {
    /// The observable.
    pub observable: Observable,
    /// Its terms (no `residual`: the summary does not subtract estimates of different kinds).
    pub terms: Vec<TermAt>,
}

impl ObservableAt {
    /// The term of a kind, if present.
    pub fn term(&self, kind: &TermKind) -> Option<&TermAt> {
        self.terms.iter().find(|t| &t.kind == kind)
    }

    /// Whether a term of `kind` adds to the total here ([`TermKind::adds_to_total`]).
    pub fn adds_to_total(&self, kind: &TermKind) -> bool {
        kind.adds_to_total(self.term(&TermKind::Ground).is_some())
    }

    /// The total PSD: the sum of the terms that add to the total ([`TermKind::adds_to_total`]).
    pub fn total_psd(&self) -> f64 {
        self.terms
            .iter()
            .filter(|t| self.adds_to_total(&t.kind))
            .map(|t| t.psd)
            .sum()
    }

    /// Standard deviation of the total PSD, the terms' errors added in quadrature (independent
    /// estimates); `None` if a term of the total has unknown degrees of freedom.
    pub fn total_psd_std(&self) -> Option<f64> {
        let mut var = 0.0;
        for t in self.terms.iter().filter(|t| self.adds_to_total(&t.kind)) {
            var += t.psd_std()?.powi(2);
        }
        Some(var.sqrt())
    }
}

/// The budget at one frequency.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SummaryAt {
    /// The frequency (Hz).
    pub freq_hz: f64,
    /// The band of the band means, `(f (1 - b), f (1 + b))` (Hz).
    pub band_hz: (f64, f64),
    /// One entry per budgeted observable, in the budget's order.
    pub observables: Vec<ObservableAt>,
}

impl SummaryAt {
    /// The entry of an observable, if budgeted.
    pub fn observable(&self, o: Observable) -> Option<&ObservableAt> {
        self.observables.iter().find(|x| x.observable == o)
    }
}
