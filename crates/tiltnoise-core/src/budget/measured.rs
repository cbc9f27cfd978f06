//! A measured record of the observables beside the model's budget: its one-sided PSDs on its
//! own grid, put onto the budget's grid as the terms `measured` and `residual`, and into the
//! summary as band means over its own points.

use super::BudgetError;
use crate::model::Observable;
use crate::noise::{BandMean, BudgetReport, Evaluation, SpectralSource, TermAt, TermKind};
use crate::option_key::OptionKey;
use crate::spectral::{band_dof, welch, Averaging, WelchConfig};

/// A measured record on its own grid: frequencies (Hz), one-sided PSD per observable
/// (unit^2/Hz), and a description for the budget's notes.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredPsds {
    /// Frequencies (Hz), increasing; may start at DC.
    pub freqs_hz: Vec<f64>,
    /// One-sided PSD per observable, (observable unit)^2/Hz, one value per frequency.
    pub psds: Vec<(Observable, Vec<f64>)>,
    /// What the record is (spectrum, or series and its Welch settings).
    pub description: String,
    /// The Welch settings and the number of segments averaged, for a series (the statistical
    /// error of a band mean); `None` for a given spectrum, whose averaging is not known.
    pub welch: Option<(WelchConfig, usize)>,
}

/// Adds the terms `measured` and `residual` of every budgeted observable of `measured` to
/// `report`: on the budget's own grid when the budget's bins are bins 1.. of the measured
/// grid, otherwise interpolated log-log onto it (NaN where the record does not reach), with a
/// note naming `origin` (the file) and the band covered. In the summary the term `measured` is
/// the mean of the record's own points in each frequency's band, with its degrees of freedom
/// for a series; a frequency whose band holds no point of the record gets a note instead.
pub fn add_measured(report: &mut BudgetReport, measured: &MeasuredPsds, origin: &str) {
    let (freqs_hz, psds, what) = (&measured.freqs_hz, &measured.psds, &measured.description);
    let grid = report.budget.freqs_hz.clone();
    // Same grid when the budget's bins are bins 1.. of the measured Welch grid (the budget
    // drops DC): compared to 4 eps relative, the rounding of k fs / N computed two ways.
    let same_grid = freqs_hz.len() > grid.len()
        && grid
            .iter()
            .zip(&freqs_hz[1..])
            .all(|(a, b)| (a - b).abs() <= 4.0 * f64::EPSILON * a.abs());
    let mut used = Vec::new();
    for (o, psd) in psds {
        if report.budget.observable(*o).is_none() {
            continue;
        }
        let on_grid = if same_grid {
            psd[1..=grid.len()].to_vec()
        } else {
            grid.iter()
                .map(|&f| super::loglog_at(freqs_hz, psd, f).unwrap_or(f64::NAN))
                .collect()
        };
        crate::noise::add_measured(&mut report.budget, *o, on_grid);
        used.push(o.name());
    }
    add_measured_summary(report, measured, origin);
    let (lo, hi) = (freqs_hz[0], freqs_hz[freqs_hz.len() - 1]);
    report.notes.push(format!(
        "{what} {} ({}) covers {lo:e} .. {hi:e} Hz (NaN outside); {}",
        origin,
        if used.is_empty() {
            "no budgeted observable".to_string()
        } else {
            used.join(", ")
        },
        if same_grid {
            "on the budget's own grid"
        } else {
            "interpolated log-log onto the budget grid"
        }
    ));
}

/// The `measured` term of every summary frequency: the mean of the record's points in the band.
fn add_measured_summary(report: &mut BudgetReport, measured: &MeasuredPsds, origin: &str) {
    let f = &measured.freqs_hz;
    let mut notes = Vec::new();
    for at in report.summary.iter_mut() {
        let (lo, hi) = at.band_hz;
        let points: Vec<usize> = (0..f.len()).filter(|&k| f[k] >= lo && f[k] <= hi).collect();
        let (Some(&first), Some(&last)) = (points.first(), points.last()) else {
            notes.push(format!(
                "summary at {} Hz: the measured record {origin} has no point in {lo:.4e} .. \
                 {hi:.4e} Hz, so no measured value there",
                crate::error::Num(at.freq_hz)
            ));
            continue;
        };
        let mean = BandMean {
            first_bin_hz: f[first],
            last_bin_hz: f[last],
            n_bins: points.len(),
            dof: measured
                .welch
                .as_ref()
                .and_then(|(cfg, n_seg)| band_dof(cfg, *n_seg, points.len())),
        };
        for ob in at.observables.iter_mut() {
            let Some((_, psd)) = measured.psds.iter().find(|(o, _)| *o == ob.observable) else {
                continue;
            };
            let sum: f64 = points.iter().map(|&k| psd[k]).sum();
            ob.terms.push(TermAt {
                kind: TermKind::Measured,
                psd: sum / points.len() as f64,
                evaluation: Evaluation::BandMean(mean.clone()),
            });
        }
    }
    report.notes.extend(notes);
}

/// One-sided PSDs (unit^2/Hz) of a measured time series with the budget's own Welch settings:
/// the same segment duration (`segment_len * fs_measured / fs_budget` samples, rounded), the
/// same overlap fraction and averaging, periodic Hann, constant detrend. For a budget from
/// spectra (no Welch settings): the budget's default segment for the series' length, 50 %
/// overlap, mean. Returns the Welch grid (with DC), the PSDs and a description for the notes.
///
/// # Errors
///
/// [`BudgetError::Config`] when the record is shorter than the budget's Welch segment;
/// [`BudgetError::Spectral`] from the Welch estimate.
pub fn series_psds(
    channels: &[(Observable, Vec<f64>)],
    fs: f64,
    source: &SpectralSource,
) -> Result<MeasuredPsds, BudgetError> {
    let n = channels.first().map_or(0, |(_, x)| x.len());
    let cfg = match source {
        SpectralSource::Welch {
            sample_rate_hz,
            segment_len,
            overlap,
            averaging,
            ..
        } => {
            let seg = (*segment_len as f64 * fs / sample_rate_hz).round() as usize;
            let ov = (*overlap as f64 / *segment_len as f64 * seg as f64).round() as usize;
            if seg < 2 || seg > n {
                return Err(BudgetError::Config(crate::message!(
                    "the measured series has {n} samples ({:.6e} s at {fs} Hz): the budget's \
                     Welch segment of {:.6e} s needs {seg} samples at this rate; use a longer \
                     record or a shorter {}",
                    n as f64 / fs,
                    *segment_len as f64 / sample_rate_hz,
                    OptionKey::NPERSEG
                )));
            }
            WelchConfig::new(seg)
                .with_overlap(ov.min(seg - 1))
                .with_averaging(if averaging == "median" {
                    Averaging::Median
                } else {
                    Averaging::Mean
                })
        }
        SpectralSource::Spectra { .. } => WelchConfig::new(super::default_segment_len(n)),
    };
    let mut freqs = Vec::new();
    let mut psds = Vec::new();
    let mut n_segments = 0;
    for (o, x) in channels {
        let p = welch(x, fs, &cfg)?;
        freqs = p.freqs_hz;
        n_segments = p.n_segments;
        psds.push((*o, p.psd));
    }
    let what = format!(
        "measured series at {fs} Hz (Welch: {} samples per segment, overlap {}, {} segments)",
        cfg.segment_len, cfg.overlap, n_segments
    );
    Ok(MeasuredPsds {
        freqs_hz: freqs,
        psds,
        description: what,
        welch: Some((cfg, n_segments)),
    })
}
