//! Noise budgets: floor-tilt cross-spectra propagated through the transfer functions, other
//! noise terms, and their quadrature sum.
//!
//! Conventions at this boundary: every spectrum is **one-sided**; a PSD is in unit^2/Hz and an ASD
//! is its square root, in unit/sqrt(Hz). Tilt cross-spectra follow `scipy.signal.csd`:
//! `S_ij = <conj(T_i) T_j>` (rad^2/Hz). With `O = sum_i H_oi T_i`, the propagated PSD is
//! `S_o = sum_ij conj(H_oi) S_ij H_oj` (the diagonal of `conj(H) S H^T`, real and >= 0 for a
//! positive semi-definite `S`), so correlated tilt axes are handled exactly.
//!
//! Terms of each observable are typed ([`TermKind`]): `tilt` (full cross-spectral
//! propagation), `tilt.<axis>` (each axis alone, `|H_oi|^2 S_ii`: a diagnostic breakdown, which
//! does not add up to `tilt` when the axes are correlated), `readout` (white, configurable per
//! observable), `thermal` (the sum over the dissipative elements, [`crate::thermal`]; only for a
//! damped model) with `thermal.<element>` per element (independent sources: they add up to
//! `thermal`), and `measured` / `residual` when a measured spectrum is compared. The total is
//! never stored: [`ObservableBudget::total`] computes it, the sum in power of the terms whose
//! kind adds to it ([`TermKind::in_total`]). A damped budget also carries a [`Calibration`] per
//! observable that has an equivalent input: the squared response that refers every term to
//! the test mass's acceleration or torque ([`equivalent`]). A report also reads the budget at
//! chosen frequencies ([`SummaryAt`]: exact for model terms, band means with their statistical
//! error for Welch estimates). Pure numerics: depends on `model`, `tf` and `thermal` only.

pub mod equivalent;
mod given;
mod segments;
mod summary;
mod term;
mod user;
mod witness;

pub use equivalent::{add_equivalent_response, equivalent_input, Calibration};
pub use given::{loglog_at, GivenAsd, GivenAsdError};
pub use segments::{percentile, SegmentBand};
pub use summary::{BandMean, Evaluation, ObservableAt, SummaryAt, TermAt};
pub use term::{is_term_name, Component, TermGroup, TermKind};
pub use user::{add_user_terms, check_user_terms, UserSource, UserTerm, UserTermError};
pub use witness::{
    add_witness_noise, check_witness_noise, NoiseLevel, WitnessNoise, WitnessNoiseError,
    MAX_NOISE_REL,
};

use crate::model::{Observable, TiltAxis};
use crate::tf::{Input, TransferMatrix};
use num_complex::Complex64;

/// The readout noise of the paper's X channel: 9 nm/sqrt(Hz), white (section III).
pub const PAPER_X_READOUT_ASD_M: f64 = 9e-9;

/// The key under which the files store the computed total of an observable's budget.
pub const TOTAL_NAME: &str = "total";

/// One term of a budget: a one-sided PSD on the budget's frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct NoiseTerm {
    /// What the term is.
    pub kind: TermKind,
    /// One-sided PSD, (observable unit)^2/Hz.
    pub psd: Vec<f64>,
}

impl NoiseTerm {
    /// The term's key in the files ([`TermKind::name`]).
    pub fn name(&self) -> String {
        self.kind.name()
    }

    /// ASD = sqrt(PSD), observable unit/sqrt(Hz).
    pub fn asd(&self) -> Vec<f64> {
        self.psd.iter().map(|p| p.sqrt()).collect()
    }
}

/// The budget of one observable.
#[derive(Debug, Clone, PartialEq)]
pub struct ObservableBudget {
    /// The observable (X in m, phi and phi_a in rad).
    pub observable: Observable,
    /// Terms in display and file order (the computed total is not one of them).
    pub terms: Vec<NoiseTerm>,
    /// The calibration to the equivalent input (damped models, observables that have one).
    pub calibration: Option<Calibration>,
}

impl ObservableBudget {
    /// A budget of `observable` with `terms` and no calibration.
    pub fn new(observable: Observable, terms: Vec<NoiseTerm>) -> ObservableBudget {
        ObservableBudget {
            observable,
            terms,
            calibration: None,
        }
    }

    /// The term of a kind, if the budget has it.
    pub fn term(&self, kind: &TermKind) -> Option<&NoiseTerm> {
        self.terms.iter().find(|t| &t.kind == kind)
    }

    /// The term stored under a file key ([`TermKind::name`]), if any.
    pub fn term_named(&self, name: &str) -> Option<&NoiseTerm> {
        self.terms.iter().find(|t| t.kind.name() == name)
    }

    /// The total PSD: the sum in power, in term order, of every term that adds to it
    /// ([`TermKind::in_total`]), one value per frequency of `n_freqs`.
    pub fn total(&self) -> Vec<f64> {
        let n = self.terms.first().map_or(0, |t| t.psd.len());
        let mut total = vec![0.0; n];
        for t in self.terms.iter().filter(|t| t.kind.in_total()) {
            for (s, p) in total.iter_mut().zip(&t.psd) {
                *s += p;
            }
        }
        total
    }

    /// Every term and its PSD in file order, the computed total last: what the writers
    /// store and the figure draws.
    pub fn components(&self) -> Vec<(Component, Vec<f64>)> {
        let mut out: Vec<(Component, Vec<f64>)> = self
            .terms
            .iter()
            .map(|t| (Component::Term(t.kind.clone()), t.psd.clone()))
            .collect();
        out.push((Component::Total, self.total()));
        out
    }
}

/// A noise budget on one frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct Budget {
    /// Frequencies (Hz), increasing, all > 0.
    pub freqs_hz: Vec<f64>,
    /// One budget per observable.
    pub observables: Vec<ObservableBudget>,
}

impl Budget {
    /// The budget of one observable.
    pub fn observable(&self, o: Observable) -> Option<&ObservableBudget> {
        self.observables.iter().find(|b| b.observable == o)
    }
}

/// Readout noise per observable: white (an ASD in the observable's unit/sqrt(Hz)) or coloured
/// (a [`GivenAsd`]). An observable is in at most one of the two lists.
#[derive(Debug, Clone, PartialEq)]
pub struct Readout {
    /// White readout, `(observable, ASD)`.
    pub asd: Vec<(Observable, f64)>,
    /// Coloured readout, `(observable, ASD given on its own points)`.
    pub given: Vec<(Observable, GivenAsd)>,
}

impl Default for Readout {
    /// The paper's 9 nm/sqrt(Hz) on X; none on the angles (not given in the paper).
    fn default() -> Readout {
        Readout {
            asd: vec![(Observable::X, PAPER_X_READOUT_ASD_M)],
            given: Vec::new(),
        }
    }
}

impl Readout {
    /// No readout on any observable.
    pub fn none() -> Readout {
        Readout {
            asd: Vec::new(),
            given: Vec::new(),
        }
    }

    /// White readout ASD of an observable, if it has one.
    pub fn of(&self, o: Observable) -> Option<f64> {
        self.asd.iter().find(|(x, _)| *x == o).map(|&(_, a)| a)
    }

    /// Coloured readout of an observable, if it has one.
    pub fn given_of(&self, o: Observable) -> Option<&GivenAsd> {
        self.given.iter().find(|(x, _)| *x == o).map(|(_, g)| g)
    }

    /// Refuses a coloured readout that does not cover the band `[lo, hi]` (Hz).
    pub fn check_covers(&self, lo: f64, hi: f64) -> Result<(), GivenAsdError> {
        self.given
            .iter()
            .try_for_each(|(_, g)| g.check_covers(lo, hi))
    }

    /// The readout term of `o` on `freqs_hz` (white: ASD^2 everywhere; coloured: the given
    /// spectrum at each frequency, inside its band), if `o` has a readout: the same values on a
    /// budget's grid and at a summary's frequency.
    pub fn term(&self, o: Observable, freqs_hz: &[f64]) -> Option<NoiseTerm> {
        let psd = match (self.of(o), self.given_of(o)) {
            (Some(asd), _) => vec![asd * asd; freqs_hz.len()],
            (None, Some(g)) => g.psd_on(freqs_hz),
            (None, None) => return None,
        };
        Some(NoiseTerm {
            kind: TermKind::Readout,
            psd,
        })
    }
}

/// Tilt cross-spectral matrices on a frequency grid: `csd[(k * n + i) * n + j] = S_ij(f_k)`,
/// one-sided, rad^2/Hz, `S_ij = <conj(T_i) T_j>`.
#[derive(Debug, Clone, PartialEq)]
pub struct TiltCsd<'a> {
    /// Axis order of the matrix.
    pub axes: &'a [TiltAxis],
    /// Row-major `[freq][i][j]`.
    pub csd: &'a [Complex64],
}

/// Propagated tilt PSD of output `o` at bin `k`: `sum_ij conj(H_oi) S_ij H_oj`, and the
/// per-axis terms `|H_oi|^2 S_ii`. `cols[i]` is the column of axis `i` in `tf`.
fn propagate(
    tf: &TransferMatrix,
    tilt: &TiltCsd,
    cols: &[usize],
    k: usize,
    o: usize,
) -> (f64, [f64; 3]) {
    let n = tilt.axes.len();
    let s = &tilt.csd[k * n * n..(k + 1) * n * n];
    // At most the three tilt axes: fixed arrays, no allocation per bin.
    let mut h = [Complex64::new(0.0, 0.0); 3];
    for (hi, &c) in h.iter_mut().zip(cols) {
        *hi = tf.get(k, o, c);
    }
    let mut total = 0.0;
    let mut per_axis = [0.0; 3];
    for i in 0..n {
        for j in 0..n {
            total += (h[i].conj() * s[i * n + j] * h[j]).re;
        }
        per_axis[i] = h[i].norm_sqr() * s[i * n + i].re;
    }
    // A positive semi-definite S gives total >= 0; rounding can leave -eps * scale. A NaN (from
    // an overflow) stays NaN for the budget's finiteness check: `f64::max` would make it 0.
    (if total < 0.0 { 0.0 } else { total }, per_axis)
}

/// Builds the budget of every output of `tf` from the tilt cross-spectra (same grid as `tf`)
/// and the readout noise. `tf` must have a tilt column for every axis of `tilt`.
///
/// # Panics
/// If `tf` lacks a column for one of the tilt axes, or the grids differ in length.
pub fn tilt_budget(tf: &TransferMatrix, tilt: &TiltCsd, readout: &Readout) -> Budget {
    let n_f = tf.freqs_hz.len();
    let n = tilt.axes.len();
    assert_eq!(tilt.csd.len(), n_f * n * n, "tilt CSD and TF grids differ");
    let cols: Vec<usize> = tilt
        .axes
        .iter()
        .map(|&a| {
            tf.input_index(Input::Tilt(a))
                .unwrap_or_else(|| panic!("transfer matrix has no {} column", a.name()))
        })
        .collect();
    let observables = tf
        .outputs
        .iter()
        .enumerate()
        .map(|(o, &observable)| {
            let mut tilt_psd = vec![0.0; n_f];
            let mut axis_psd = vec![vec![0.0; n_f]; n];
            for k in 0..n_f {
                let (t, per) = propagate(tf, tilt, &cols, k, o);
                tilt_psd[k] = t;
                for (axis, p) in axis_psd.iter_mut().zip(per) {
                    axis[k] = p;
                }
            }
            let mut terms = vec![NoiseTerm {
                kind: TermKind::Tilt,
                psd: tilt_psd,
            }];
            for (i, psd) in axis_psd.into_iter().enumerate() {
                terms.push(NoiseTerm {
                    kind: TermKind::TiltAxis(tilt.axes[i]),
                    psd,
                });
            }
            terms.extend(readout.term(observable, &tf.freqs_hz));
            ObservableBudget::new(observable, terms)
        })
        .collect();
    Budget {
        freqs_hz: tf.freqs_hz.clone(),
        observables,
    }
}

/// Adds the thermal-noise terms of `thermal` (same grid as `budget`) to every observable it
/// has: `thermal` (sum over the elements, which adds to the total) and `thermal.<element>`,
/// after the terms already there. Does nothing when `thermal` has no element (undamped model).
/// Call it before [`add_measured`], whose residual is taken against the total.
///
/// # Panics
/// If the grids differ in length.
pub fn add_thermal(budget: &mut Budget, thermal: &crate::thermal::ThermalNoise) {
    if thermal.elements.is_empty() {
        return;
    }
    assert_eq!(
        budget.freqs_hz.len(),
        thermal.freqs_hz.len(),
        "thermal and budget grids differ"
    );
    for b in budget.observables.iter_mut() {
        let Some(o) = thermal.outputs.iter().position(|&x| x == b.observable) else {
            continue;
        };
        b.terms.push(NoiseTerm {
            kind: TermKind::Thermal,
            psd: thermal.total_psd(o),
        });
        for e in &thermal.elements {
            b.terms.push(NoiseTerm {
                kind: TermKind::ThermalElement(e.name.clone()),
                psd: e.psd[o].clone(),
            });
        }
    }
}

/// Adds a measured spectrum of an observable for comparison, with the unexplained residual
/// `measured - total` in power (clipped at 0 where the model explains everything; NaN where
/// the measured PSD is NaN, i.e. not measured at that frequency).
pub fn add_measured(budget: &mut Budget, o: Observable, measured_psd: Vec<f64>) {
    let Some(b) = budget.observables.iter_mut().find(|b| b.observable == o) else {
        return;
    };
    let residual = measured_psd
        .iter()
        .zip(&b.total())
        // f64::max would turn a NaN (not measured there) into 0: keep it NaN.
        .map(|(m, t)| {
            if m.is_nan() {
                f64::NAN
            } else {
                (m - t).max(0.0)
            }
        })
        .collect();
    b.terms.push(NoiseTerm {
        kind: TermKind::Measured,
        psd: measured_psd,
    });
    b.terms.push(NoiseTerm {
        kind: TermKind::Residual,
        psd: residual,
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tf::Method;

    fn toy_tf(h: [[Complex64; 2]; 1]) -> TransferMatrix {
        TransferMatrix::from_dense(
            vec![1e-3],
            vec![Observable::X],
            vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)],
            Method::Direct,
            &h[0],
        )
    }

    #[test]
    fn correlated_axes_propagate_with_cross_terms() {
        // O = a T1 + b T2 with S = [[s1, c], [conj c, s2]]:
        // S_O = |a|^2 s1 + |b|^2 s2 + 2 Re(conj(a) c b).
        let (a, b) = (Complex64::new(2.0, 1.0), Complex64::new(-1.0, 3.0));
        let (s1, s2, c) = (4.0, 9.0, Complex64::new(1.5, -2.0));
        let csd = [Complex64::from(s1), c, c.conj(), Complex64::from(s2)];
        let axes = [TiltAxis::ThetaT, TiltAxis::EtaT];
        let budget = tilt_budget(
            &toy_tf([[a, b]]),
            &TiltCsd {
                axes: &axes,
                csd: &csd,
            },
            &Readout::default(),
        );
        let x = budget.observable(Observable::X).unwrap();
        let expected = a.norm_sqr() * s1 + b.norm_sqr() * s2 + 2.0 * (a.conj() * c * b).re;
        // Sums of four products of O(10) numbers: a few ulps of the largest product.
        let tol = 8.0 * f64::EPSILON * 100.0;
        let tilt = x.term(&TermKind::Tilt).unwrap().psd[0];
        assert!((tilt - expected).abs() < tol);
        let theta = TermKind::TiltAxis(TiltAxis::ThetaT);
        assert_eq!(x.term(&theta).unwrap().psd[0], a.norm_sqr() * s1);
        let eta = TermKind::TiltAxis(TiltAxis::EtaT);
        assert_eq!(x.term(&eta).unwrap().psd[0], b.norm_sqr() * s2);
        let readout = PAPER_X_READOUT_ASD_M * PAPER_X_READOUT_ASD_M;
        assert_eq!(x.term(&TermKind::Readout).unwrap().psd[0], readout);
        assert_eq!(x.total()[0], tilt + readout);
    }

    #[test]
    fn residual_is_measured_minus_total_clipped() {
        let axes = [TiltAxis::ThetaT, TiltAxis::EtaT];
        let csd = [
            Complex64::from(1.0),
            Complex64::from(0.0),
            Complex64::from(0.0),
            Complex64::from(1.0),
        ];
        let one = Complex64::from(1.0);
        let mut budget = tilt_budget(
            &toy_tf([[one, one]]),
            &TiltCsd {
                axes: &axes,
                csd: &csd,
            },
            &Readout::none(),
        );
        add_measured(&mut budget, Observable::X, vec![5.0]);
        let x = budget.observable(Observable::X).unwrap();
        assert_eq!(x.term(&TermKind::Residual).unwrap().psd[0], 3.0);
        let last = x.components().pop().map(|(c, _)| c);
        assert_eq!(last, Some(Component::Total));
    }
}

/// How the tilt spectra of a budget were estimated, for provenance in the output files.
#[derive(Debug, Clone, PartialEq)]
pub enum SpectralSource {
    /// Welch estimate from a time series.
    Welch {
        /// Sample rate of the series (Hz).
        sample_rate_hz: f64,
        /// Samples per Welch segment.
        segment_len: usize,
        /// Overlapping samples between consecutive Welch segments.
        overlap: usize,
        /// `mean` or `median`.
        averaging: String,
        /// Welch segments averaged over the whole record.
        n_welch_segments: usize,
        /// Samples in the record.
        n_samples: usize,
    },
    /// Spectra given as input, interpolated log-log onto the model grid.
    Spectra {
        /// Frequency band covered by the input (Hz).
        data_band_hz: (f64, f64),
    },
}

/// A complete budget run: the whole-record budget, the per-segment statistics and what went in.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetReport {
    /// The budget of the whole record (or of the given spectra).
    pub budget: Budget,
    /// Per-segment statistics of the `tilt` term (PSD), one band per observable, when the record
    /// was split into segments (for example hourly).
    pub segment_bands: Vec<(Observable, SegmentBand)>,
    /// Segment length (s) of `segment_bands`, if any.
    pub segment_duration_s: Option<f64>,
    /// How the tilt spectra were obtained.
    pub source: SpectralSource,
    /// The tilt axes that entered the budget.
    pub axes: Vec<TiltAxis>,
    /// Readout noise used, white or coloured.
    pub readout: Readout,
    /// The user-named terms (their definitions, for provenance; their values are terms).
    pub user_terms: Vec<UserTerm>,
    /// Human-readable notes for the user and the files (band restrictions, assumptions).
    pub notes: Vec<String>,
    /// The budget read at chosen frequencies ([`SummaryAt`]), in increasing order of request.
    pub summary: Vec<SummaryAt>,
}

impl BudgetReport {
    /// Checks that every spectrum of `report` lies on its frequency grid and that names are usable
    /// as file keys (non-empty, no `/`, no `,`); shared by the budget writers and the figure.
    pub fn check(&self) -> Result<(), String> {
        let report = self;
        let n_f = report.budget.freqs_hz.len();
        let mut seen = Vec::new();
        for ob in &report.budget.observables {
            let o = ob.observable.name();
            if seen.contains(&o) {
                return Err(format!("observable {o} appears twice in the budget"));
            }
            seen.push(o);
            for term in &ob.terms {
                let name = term.name();
                let bad = name.is_empty() || name.contains(['/', ',', '\n']);
                if bad {
                    return Err(format!(
                        "term name `{name}` of {o} is not allowed: must be non-empty, without \
                         `/`, `,` or line breaks"
                    ));
                }
                if term.psd.len() != n_f {
                    return Err(format!(
                        "term {o}.{name} has {} values, expected {n_f} (one per frequency)",
                        term.psd.len()
                    ));
                }
            }
            if let Some(c) = &ob.calibration {
                if c.response_psd.len() != n_f {
                    return Err(format!(
                        "calibration of {o} has {} values, expected {n_f}",
                        c.response_psd.len()
                    ));
                }
            }
        }
        for at in &report.summary {
            for ob in &at.observables {
                for t in &ob.terms {
                    if !(t.psd.is_finite() && t.psd >= 0.0) {
                        return Err(format!(
                            "summary term {}.{} at {} Hz is {}: must be finite and >= 0",
                            ob.observable.name(),
                            t.kind,
                            at.freq_hz,
                            t.psd
                        ));
                    }
                }
            }
        }
        let mut seen = Vec::new();
        for (o, band) in &report.segment_bands {
            if seen.contains(o) {
                return Err(format!("segment band of {} appears twice", o.name()));
            }
            seen.push(*o);
            for (what, v) in [
                ("median", &band.median),
                ("lower", &band.lower),
                ("upper", &band.upper),
            ] {
                if v.len() != n_f {
                    return Err(format!(
                        "segment band {}.tilt {what} has {} values, expected {n_f}",
                        o.name(),
                        v.len()
                    ));
                }
            }
        }
        Ok(())
    }
}
