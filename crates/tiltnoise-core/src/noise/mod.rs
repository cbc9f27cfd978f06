//! Noise budgets: the cross-spectra of the floor's motion (tilt and translation) propagated
//! through the transfer functions, other noise terms, and their quadrature sum.
//!
//! Conventions at this boundary: every spectrum is **one-sided**; a PSD is in unit^2/Hz and an ASD
//! is its square root, in unit/sqrt(Hz). Cross-spectra of the floor's inputs (tilt angles in
//! rad, translations in m) follow `scipy.signal.csd`: `S_ij = <conj(U_i) U_j>`. With `O = sum_i
//! H_oi U_i`, the propagated PSD is `S_o = sum_ij conj(H_oi) S_ij H_oj` (the diagonal of
//! `conj(H) S H^T`, real and >= 0 for a positive semi-definite `S`), so correlated inputs are
//! handled exactly.
//!
//! Terms of each observable are typed ([`TermKind`]): `tilt` (full cross-spectral propagation
//! of the tilt axes), `tilt.<axis>` (each axis alone, `|H_oi|^2 S_ii`: a diagnostic breakdown,
//! which does not add up to `tilt` when the axes are correlated), `translation` and
//! `translation.<axis>` likewise for the floor's translations, and, for a record of both,
//! `ground` (all six with every cross-spectrum, the term that then adds to the total, of which
//! `tilt` and `translation` are the breakdown), `readout` (white, configurable per
//! observable), `thermal` (the sum over the dissipative elements, [`crate::thermal`]; only for a
//! damped model) with `thermal.<element>` per element (independent sources: they add up to
//! `thermal`), and `measured` / `residual` when a measured spectrum is compared. The total is
//! never stored: [`ObservableBudget::total`] computes it, the sum in power of the terms whose
//! kind adds to it ([`TermKind::adds_to_total`]). A damped budget also carries a [`Calibration`] per
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

use crate::input::{motion_of, Motion};
use crate::model::Observable;
use crate::tf::{Input, TransferMatrix};
use num_complex::Complex64;

/// The readout noise of the paper's X channel: 9 nm/sqrt(Hz), white (section III).
pub const PAPER_X_READOUT_ASD_M: f64 = 9e-9;

/// The key under which the files store the computed total of an observable's budget.
pub const TOTAL_NAME: &str = "total";

/// One term of a budget: a one-sided PSD on the budget's frequency grid.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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

    /// Whether a term of `kind` adds to this budget's total ([`TermKind::adds_to_total`]: the
    /// `tilt` and `translation` terms do only when there is no `ground` term).
    pub fn adds_to_total(&self, kind: &TermKind) -> bool {
        kind.adds_to_total(self.term(&TermKind::Ground).is_some())
    }

    /// The term of the floor's motion that adds to the total: `ground`, else `tilt` or
    /// `translation`; `None` for a budget without one.
    pub fn ground_total_term(&self) -> Option<&NoiseTerm> {
        [TermKind::Ground, TermKind::Tilt, TermKind::Translation]
            .iter()
            .find_map(|k| self.term(k))
    }

    /// The total PSD: the sum in power, in term order, of every term that adds to it
    /// ([`ObservableBudget::adds_to_total`]), one value per frequency of `n_freqs`.
    pub fn total(&self) -> Vec<f64> {
        let n = self.terms.first().map_or(0, |t| t.psd.len());
        let mut total = vec![0.0; n];
        for t in self.terms.iter().filter(|t| self.adds_to_total(&t.kind)) {
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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

/// Cross-spectral matrices of the floor's inputs (tilt angles in rad, translations in m) on a
/// frequency grid: `csd[(k * n + i) * n + j] = S_ij(f_k)`, one-sided, `S_ij = <conj(U_i) U_j>`
/// (rad^2/Hz, rad m/Hz, m^2/Hz). Each matrix is Hermitian, as every estimate of one is: the
/// budget reads its diagonal and upper triangle.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundCsd<'a> {
    /// Input order of the matrix: tilt axes and translations, each once.
    pub inputs: &'a [Input],
    /// Row-major `[freq][i][j]`.
    pub csd: &'a [Complex64],
}

/// The ground terms of one observable at bin `k`: the whole motion `sum_ij conj(H_oi) S_ij
/// H_oj`, the same over the tilt inputs and over the translations alone, and each input alone
/// `|H_oi|^2 S_ii`. `cols[i]` is the column of input `i` in `tf`.
struct Propagated {
    all: f64,
    rotations: f64,
    translations: f64,
    per_input: [f64; 6],
}

fn propagate(
    tf: &TransferMatrix,
    ground: &GroundCsd,
    is_rotation: &[bool],
    cols: &[usize],
    k: usize,
    o: usize,
) -> Propagated {
    let n = ground.inputs.len();
    let s = &ground.csd[k * n * n..(k + 1) * n * n];
    // At most the six inputs of the floor: fixed arrays, no allocation per bin.
    let mut h = [Complex64::new(0.0, 0.0); 6];
    for (hi, &c) in h.iter_mut().zip(cols) {
        *hi = tf.get(k, o, c);
    }
    let (mut all, mut rotations, mut translations) = (0.0, 0.0, 0.0);
    let mut per_input = [0.0; 6];
    // S is Hermitian: each pair (i, j), i < j, adds 2 Re(conj(H_oi) S_ij H_oj) with (j, i).
    for i in 0..n {
        per_input[i] = h[i].norm_sqr() * s[i * n + i].re;
        let row = h[i].conj();
        for j in i..n {
            let term = if j == i {
                per_input[i]
            } else {
                2.0 * (row * s[i * n + j] * h[j]).re
            };
            all += term;
            match (is_rotation[i], is_rotation[j]) {
                (true, true) => rotations += term,
                (false, false) => translations += term,
                _ => {}
            }
        }
    }
    // A positive semi-definite S gives sums >= 0; rounding can leave -eps * scale. A NaN (from
    // an overflow) stays NaN for the budget's finiteness check: `f64::max` would make it 0.
    let clip = |v: f64| if v < 0.0 { 0.0 } else { v };
    Propagated {
        all: clip(all),
        rotations: clip(rotations),
        translations: clip(translations),
        per_input,
    }
}

/// The whole motion's term `sum_ij conj(h_i) S_ij h_j` of one observable at one bin, from its
/// transfer row `h` (one entry per input) and the inputs' Hermitian cross-spectral matrix `s`
/// (row-major): the `all` of [`propagate`], summed in the same order (so equal to it bit for
/// bit) and clipped the same way, without the breakdown per input and per motion.
pub(crate) fn propagate_total(h: &[Complex64], s: &[Complex64]) -> f64 {
    let n = h.len();
    let mut all = 0.0;
    for i in 0..n {
        let diagonal = h[i].norm_sqr() * s[i * n + i].re;
        all += diagonal;
        let row = h[i].conj();
        for j in i + 1..n {
            all += 2.0 * (row * s[i * n + j] * h[j]).re;
        }
    }
    if all < 0.0 {
        0.0
    } else {
        all
    }
}

/// Builds the budget of every output of `tf` from the cross-spectra of the floor's inputs (same
/// grid as `tf`) and the readout noise: `tilt` and `tilt.<axis>` for the tilt inputs,
/// `translation` and `translation.<axis>` for the translations, and `ground` (first) when there
/// are both. `tf` must have a column for every input of `ground`.
///
/// # Panics
/// If `tf` lacks a column for one of the inputs, an input is not one of the floor's, there are
/// more than six, or the grids differ in length.
pub fn ground_budget(tf: &TransferMatrix, ground: &GroundCsd, readout: &Readout) -> Budget {
    let n_f = tf.freqs_hz.len();
    let n = ground.inputs.len();
    assert!(n <= 6, "at most the six inputs of the floor");
    assert_eq!(
        ground.csd.len(),
        n_f * n * n,
        "ground CSD and TF grids differ"
    );
    let cols: Vec<usize> = ground
        .inputs
        .iter()
        .map(|&a| {
            assert!(a.is_ground(), "{} is not an input of the floor", a.name());
            tf.input_index(a)
                .unwrap_or_else(|| panic!("transfer matrix has no {} column", a.name()))
        })
        .collect();
    let is_rotation: Vec<bool> = ground
        .inputs
        .iter()
        .map(|&a| motion_of(a) == Motion::Rotation)
        .collect();
    let (has_rotation, has_translation) = (
        is_rotation.iter().any(|&r| r),
        is_rotation.iter().any(|&r| !r),
    );
    let axis_kind = |input: Input| match input {
        Input::Tilt(a) => TermKind::TiltAxis(a),
        Input::Translation(t) => TermKind::TranslationAxis(t),
        Input::Force(_) => unreachable!("checked above"),
    };
    let observables = tf
        .outputs
        .iter()
        .enumerate()
        .map(|(o, &observable)| {
            let mut all = vec![0.0; n_f];
            let mut rotations = vec![0.0; n_f];
            let mut translations = vec![0.0; n_f];
            let mut per_input = vec![vec![0.0; n_f]; n];
            for k in 0..n_f {
                let p = propagate(tf, ground, &is_rotation, &cols, k, o);
                all[k] = p.all;
                rotations[k] = p.rotations;
                translations[k] = p.translations;
                for (input, v) in per_input.iter_mut().zip(p.per_input) {
                    input[k] = v;
                }
            }
            let mut terms = Vec::new();
            match (has_rotation, has_translation) {
                (true, true) => {
                    terms.push(NoiseTerm {
                        kind: TermKind::Ground,
                        psd: all,
                    });
                    terms.push(NoiseTerm {
                        kind: TermKind::Tilt,
                        psd: rotations,
                    });
                    terms.push(NoiseTerm {
                        kind: TermKind::Translation,
                        psd: translations,
                    });
                }
                (true, false) => terms.push(NoiseTerm {
                    kind: TermKind::Tilt,
                    psd: all,
                }),
                (false, _) => terms.push(NoiseTerm {
                    kind: TermKind::Translation,
                    psd: all,
                }),
            }
            for (&input, psd) in ground.inputs.iter().zip(per_input) {
                terms.push(NoiseTerm {
                    kind: axis_kind(input),
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
    use crate::model::{TiltAxis, TranslationAxis};
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
        let inputs = [Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)];
        let budget = ground_budget(
            &toy_tf([[a, b]]),
            &GroundCsd {
                inputs: &inputs,
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

    /// A tilt and a translation correlated: `ground` holds the cross term, `tilt` and
    /// `translation` each input alone; the total is `ground` plus readout, never the two parts
    /// in quadrature.
    #[test]
    fn tilt_and_translation_add_as_ground_with_their_cross_spectrum() {
        let (a, b) = (Complex64::new(1.5, -0.5), Complex64::new(-2.0, 0.25));
        let (s1, s2, c) = (2.0, 3.0, Complex64::new(-1.2, 0.7));
        let csd = [Complex64::from(s1), c, c.conj(), Complex64::from(s2)];
        let inputs = [
            Input::Tilt(TiltAxis::EtaT),
            Input::Translation(TranslationAxis::XT),
        ];
        let tf = TransferMatrix::from_dense(
            vec![1e-2],
            vec![Observable::X],
            inputs.to_vec(),
            Method::Direct,
            &[a, b],
        );
        let budget = ground_budget(
            &tf,
            &GroundCsd {
                inputs: &inputs,
                csd: &csd,
            },
            &Readout::none(),
        );
        let x = budget.observable(Observable::X).unwrap();
        let names: Vec<String> = x.terms.iter().map(|t| t.name()).collect();
        assert_eq!(
            names,
            [
                "ground",
                "tilt",
                "translation",
                "tilt.eta_t",
                "translation.x_t"
            ]
        );
        let ground = x.term(&TermKind::Ground).unwrap().psd[0];
        let expected = a.norm_sqr() * s1 + b.norm_sqr() * s2 + 2.0 * (a.conj() * c * b).re;
        assert!((ground - expected).abs() <= 8.0 * f64::EPSILON * 100.0);
        assert_eq!(x.term(&TermKind::Tilt).unwrap().psd[0], a.norm_sqr() * s1);
        assert_eq!(
            x.term(&TermKind::Translation).unwrap().psd[0],
            b.norm_sqr() * s2
        );
        assert_eq!(x.total(), vec![ground]);
        assert_eq!(x.ground_total_term().unwrap().kind, TermKind::Ground);
    }

    #[test]
    fn residual_is_measured_minus_total_clipped() {
        let inputs = [Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)];
        let csd = [
            Complex64::from(1.0),
            Complex64::from(0.0),
            Complex64::from(0.0),
            Complex64::from(1.0),
        ];
        let one = Complex64::from(1.0);
        let mut budget = ground_budget(
            &toy_tf([[one, one]]),
            &GroundCsd {
                inputs: &inputs,
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BudgetReport {
    /// The budget of the whole record (or of the given spectra).
    pub budget: Budget,
    /// Per-segment statistics of the term of the floor's motion that adds to the total (`tilt`,
    /// `translation` or `ground`; [`SegmentBand::term`]), one band per observable, when the
    /// record was split into segments (for example hourly).
    pub segment_bands: Vec<(Observable, SegmentBand)>,
    /// Segment length (s) of `segment_bands`, if any.
    pub segment_duration_s: Option<f64>,
    /// How the tilt spectra were obtained.
    pub source: SpectralSource,
    /// The inputs of the floor's motion that entered the budget (tilt axes, translations), in
    /// canonical order.
    pub inputs: Vec<Input>,
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
            let term = band.term.name();
            seen.push(*o);
            for (what, v) in [
                ("median", &band.median),
                ("lower", &band.lower),
                ("upper", &band.upper),
            ] {
                if v.len() != n_f {
                    return Err(format!(
                        "segment band {}.{term} {what} has {} values, expected {n_f}",
                        o.name(),
                        v.len()
                    ));
                }
            }
        }
        Ok(())
    }
}
