//! Reading a budget at chosen frequencies ([`crate::noise::SummaryAt`]) by the code that fills
//! its grid, at exactly each frequency: the transfer functions, the thermal formula, the readout
//! and the user terms at `f` (given spectra taken at `f`, log-log between their points). The
//! tilt cross-spectra there are the given spectra taken at `f` (spectra input: the value is
//! exact), or for a time series the mean of the Welch cross-spectral
//! matrices of the bins in a band around `f`, with its chi-squared degrees of freedom: the
//! floor's spectrum is averaged over the band, the pendulum's resonances are not (they are in
//! the transfer functions, evaluated at `f`). Never an interpolation between bins: across a
//! resonance that is off by tens of percent.

use super::{ground_tf, BudgetError};
use crate::input::TiltSpectra;
use crate::model::{Model, Observable};
use crate::noise::{
    add_thermal, add_user_terms, add_witness_noise, ground_budget, BandMean, BudgetReport,
    Evaluation, GroundCsd, ObservableAt, SummaryAt, TermAt,
};
use crate::spectral::{band_dof, WelchConfig};
use num_complex::Complex64;

/// The frequencies the summary reads by default (Hz): 1, 2 and 5 mHz.
pub const DEFAULT_SUMMARY_FREQS_HZ: [f64; 3] = [1e-3, 2e-3, 5e-3];

/// Default half-width of the band of a band mean, relative to the frequency: `f (1 +- 0.1)`.
pub const DEFAULT_BAND_FRACTION: f64 = 0.1;

/// Which frequencies to read the budget at, and the band of the Welch band means.
#[derive(Debug, Clone, PartialEq)]
pub struct SummaryRequest {
    /// Frequencies (Hz), finite and > 0.
    pub freqs_hz: Vec<f64>,
    /// Half-width of the band relative to the frequency, in (0, 1): the band is
    /// `[f (1 - b), f (1 + b)]`.
    pub band_fraction: f64,
    /// Refuse a frequency the budget cannot be read at (outside its band, or no Welch bin in
    /// the band) instead of leaving it out with a note.
    pub strict: bool,
}

impl Default for SummaryRequest {
    fn default() -> SummaryRequest {
        SummaryRequest {
            freqs_hz: DEFAULT_SUMMARY_FREQS_HZ.to_vec(),
            band_fraction: DEFAULT_BAND_FRACTION,
            strict: false,
        }
    }
}

impl SummaryRequest {
    /// Checks the frequencies (finite, > 0) and the band fraction (in (0, 1)).
    pub fn validate(&self) -> Result<(), BudgetError> {
        if let Some(&f) = self.freqs_hz.iter().find(|f| !(f.is_finite() && **f > 0.0)) {
            return Err(BudgetError::Config(
                format!(
                    "summary frequency {} Hz is not allowed: must be finite and > 0",
                    crate::error::Num(f)
                )
                .into(),
            ));
        }
        let b = self.band_fraction;
        if !(b > 0.0 && b < 1.0) {
            return Err(BudgetError::Config(
                format!(
                    "band fraction {} is not allowed: the band f (1 +- b) needs 0 < b < 1",
                    crate::error::Num(b)
                )
                .into(),
            ));
        }
        Ok(())
    }
}

/// The tilt data of a budget, for reading it at any frequency.
pub(super) enum TiltData<'a> {
    /// Welch cross-spectra of the angle on the bins above DC (`csd[(k n + i) n + j]`, `n`
    /// the report's axes), the Welch settings and the number of segments averaged.
    Welch {
        freqs_hz: &'a [f64],
        csd: &'a [Complex64],
        cfg: WelchConfig,
        n_segments: usize,
    },
    /// Given spectra.
    Spectra(&'a TiltSpectra),
}

/// The tilt cross-spectral matrix at `f` and how it was obtained: the mean of the Welch
/// matrices of the bins in `band`, or the given spectra taken at `f`; `Err` with the reason
/// when there is none.
fn tilt_csd_at(
    tilt: &TiltData<'_>,
    n_axes: usize,
    f: f64,
    band: (f64, f64),
) -> Result<(Vec<Complex64>, Evaluation), String> {
    match tilt {
        TiltData::Welch {
            freqs_hz,
            csd,
            cfg,
            n_segments,
        } => {
            let nn = n_axes * n_axes;
            let bins: Vec<usize> = (0..freqs_hz.len())
                .filter(|&k| freqs_hz[k] >= band.0 && freqs_hz[k] <= band.1)
                .collect();
            let (Some(&first), Some(&last)) = (bins.first(), bins.last()) else {
                let df = freqs_hz[0];
                return Err(format!(
                    "no Welch bin in {:.4e} .. {:.4e} Hz (bin spacing {df:.4e} Hz): widen the \
                     band or use longer Welch segments",
                    band.0, band.1
                ));
            };
            let mut mean = vec![Complex64::new(0.0, 0.0); nn];
            for &k in &bins {
                for (m, s) in mean.iter_mut().zip(&csd[k * nn..(k + 1) * nn]) {
                    *m += s;
                }
            }
            for m in mean.iter_mut() {
                *m /= bins.len() as f64;
            }
            let evaluation = Evaluation::BandMean(BandMean {
                first_bin_hz: freqs_hz[first],
                last_bin_hz: freqs_hz[last],
                n_bins: bins.len(),
                dof: band_dof(cfg, *n_segments, bins.len()),
            });
            Ok((mean, evaluation))
        }
        TiltData::Spectra(spectra) => {
            let (grid, on_grid) = spectra.interpolate_loglog(&[f]);
            if grid.is_empty() {
                let (a, b) = spectra.band_hz();
                return Err(format!(
                    "outside the band the tilt spectra cover ({a:e} .. {b:e} Hz)"
                ));
            }
            Ok((on_grid.csd, Evaluation::Exact))
        }
    }
}

/// Reads `report` at the frequencies of `req` (see the module docs): the budget at each
/// frequency is made by the code that makes it on the grid, [`ground_budget`] with the transfer
/// functions at exactly `f` and [`add_thermal`], from the tilt cross-spectra at `f`
/// ([`tilt_csd_at`]). Returns the summary and one note per frequency left out (not
/// `req.strict`).
///
/// # Errors
///
/// [`BudgetError::Config`] for an invalid request, or (with `req.strict`) a frequency outside
/// the budget's band or without a Welch bin in its band; [`BudgetError::Tf`] if a transfer
/// function cannot be evaluated there; [`BudgetError::NotFinite`] for a value beyond `f64`.
pub(super) fn summarize(
    model: &Model,
    report: &BudgetReport,
    tilt: &TiltData<'_>,
    opts: &super::BudgetOptions,
) -> Result<(Vec<SummaryAt>, Vec<String>), BudgetError> {
    let req = &opts.summary;
    req.validate()?;
    let outputs: Vec<Observable> = report
        .budget
        .observables
        .iter()
        .map(|b| b.observable)
        .collect();
    let grid = &report.budget.freqs_hz;
    let (lo, hi) = (grid[0], grid[grid.len() - 1]);
    let mut summary = Vec::new();
    let mut skipped = Vec::new();
    for &f in &req.freqs_hz {
        let band = (f * (1.0 - req.band_fraction), f * (1.0 + req.band_fraction));
        let csd = if f < lo || f > hi {
            Err(format!(
                "outside the budget's band ({lo:.4e} .. {hi:.4e} Hz)"
            ))
        } else {
            tilt_csd_at(tilt, report.inputs.len(), f, band)
        };
        let (csd, tilt_evaluation) = match csd {
            Ok(c) => c,
            Err(why) if req.strict => {
                return Err(BudgetError::Config(
                    format!(
                        "the budget cannot be read at {} Hz: {why}",
                        crate::error::Num(f)
                    )
                    .into(),
                ))
            }
            Err(why) => {
                skipped.push(format!(
                    "summary at {} Hz left out: {why}",
                    crate::error::Num(f)
                ));
                continue;
            }
        };
        let at_f = [f];
        let tf = ground_tf(model, &outputs, &report.inputs, &at_f)?;
        let mut point = ground_budget(
            &tf,
            &GroundCsd {
                inputs: &report.inputs,
                csd: &csd,
            },
            &report.readout,
        );
        if !model.is_undamped() {
            add_thermal(
                &mut point,
                &crate::thermal::thermal_noise(model, &outputs, &at_f)?,
            );
        }
        add_user_terms(&mut point, model, &opts.user_terms)?;
        add_witness_noise(&mut point, model, &opts.witness_noise)?;
        let observables = report
            .budget
            .observables
            .iter()
            .zip(&point.observables)
            .map(|(ob, here)| ObservableAt {
                observable: ob.observable,
                // In the budget's order; measured and residual are not the model's.
                terms: ob
                    .terms
                    .iter()
                    .filter_map(|t| here.term(&t.kind))
                    .map(|t| TermAt {
                        kind: t.kind.clone(),
                        psd: t.psd[0],
                        // The witness noise is a given spectrum through the model: exact at f.
                        evaluation: if t.kind.is_ground_motion() {
                            tilt_evaluation.clone()
                        } else {
                            Evaluation::Exact
                        },
                    })
                    .collect(),
            })
            .collect();
        let at = SummaryAt {
            freq_hz: f,
            band_hz: band,
            observables,
        };
        check_finite(&at)?;
        summary.push(at);
    }
    Ok((summary, skipped))
}

/// Refuses a summary value that is not finite (the budget's grid was checked; a frequency
/// between its bins was not), naming the term.
fn check_finite(at: &SummaryAt) -> Result<(), BudgetError> {
    for ob in &at.observables {
        if let Some(t) = ob.terms.iter().find(|t| !t.psd.is_finite()) {
            return Err(BudgetError::NotFinite(format!(
                "the {} term of {} is not finite at {} Hz: the input or the parameters are \
                 beyond the range of f64",
                t.kind,
                ob.observable.name(),
                crate::error::Num(at.freq_hz)
            )));
        }
    }
    Ok(())
}
