//! The budget job: a tilt input (time series or spectra) -> tilt cross-spectra -> transfer
//! functions on the same grid -> the noise budget of X, phi and phi_a, whole record and per
//! segment.
//!
//! Time series are streamed in chunks through Welch accumulators, so a month of 10 Hz data is
//! processed in bounded memory: one whole-record accumulator, one for the current segment, and
//! the `tilt` PSD of every finished segment (stored as `f32`, enough for percentile bands).
//! Progress is reported through a callback; the library never draws to the terminal.
//! Conventions: one-sided spectra, PSD in unit^2/Hz (see [`crate::noise`]).

mod measured;
pub mod option_checks;

pub use measured::{add_measured, series_psds, MeasuredPsds};

use crate::error::TfError;
use crate::input::{InputError, SeriesSource, TiltSpectra};
use crate::limits::{check_memory, planned_bytes, LimitError};
use crate::model::{Model, Observable, TiltAxis};
use crate::noise::{
    add_equivalent_response, add_thermal, tilt_budget, Budget, BudgetReport, Readout, SegmentBand,
    SpectralSource, TermKind, TiltCsd,
};
use crate::spectral::{Averaging, SpectralError, WelchAccumulator, WelchConfig};
use crate::tf::{self, Input, Request, TransferMatrix};

/// Samples per channel read from the input at a time: 2^18 samples x 3 channels x 8 bytes
/// = 6 MiB, large enough to amortize HDF5 calls, small against the 256 MB memory goal.
pub const CHUNK_SAMPLES: usize = 1 << 18;

/// Default Welch segment: 2^14 samples, or the largest power of two that fits four times
/// into a shorter record (so that at least 7 half-overlapping segments are averaged).
pub const DEFAULT_WELCH_SEGMENT: usize = 1 << 14;

/// Failures of a budget run.
#[derive(Debug, thiserror::Error)]
pub enum BudgetError {
    /// Reading the tilt input failed.
    #[error(transparent)]
    Input(#[from] InputError),
    /// The Welch configuration does not fit the series.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// A transfer function could not be evaluated on the grid.
    #[error(transparent)]
    Tf(#[from] TfError),
    /// More spectra to keep than fit into the memory available.
    #[error(transparent)]
    TooLarge(#[from] LimitError),
    /// Options that contradict each other or the input.
    #[error("{0}")]
    Config(String),
    /// A spectrum or budget term that overflowed `f64`.
    #[error("{0}")]
    NotFinite(String),
}

/// Options of a budget run.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetOptions {
    /// Observables to budget (X, phi, phi_a by default).
    pub outputs: Vec<Observable>,
    /// Welch segment length in samples (`None`: [`default_segment_len`]).
    pub welch_segment_len: Option<usize>,
    /// Welch overlap as a fraction of the segment, in [0, 1).
    pub welch_overlap_fraction: f64,
    /// Mean or median averaging of the Welch segments.
    pub averaging: Averaging,
    /// Split the record into segments of this duration (s) for the percentile band.
    pub segment_duration_s: Option<f64>,
    /// Percentiles of the band, e.g. (10, 90).
    pub percentiles: (f64, f64),
    /// Readout noise per observable.
    pub readout: Readout,
    /// Model grid for spectra input (Hz); time series use the Welch grid.
    pub spectra_grid_hz: Vec<f64>,
}

impl Default for BudgetOptions {
    fn default() -> BudgetOptions {
        BudgetOptions {
            outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
            welch_segment_len: None,
            welch_overlap_fraction: 0.5,
            averaging: Averaging::Mean,
            segment_duration_s: None,
            percentiles: (10.0, 90.0),
            readout: Readout::default(),
            spectra_grid_hz: Vec::new(),
        }
    }
}

/// [`DEFAULT_WELCH_SEGMENT`] or, for short records, the largest power of two <= n/4 (at least 2).
pub fn default_segment_len(n_samples: usize) -> usize {
    let quarter = (n_samples / 4).max(2);
    DEFAULT_WELCH_SEGMENT.min(1 << quarter.ilog2())
}

fn tilt_tf(
    model: &Model,
    outputs: &[Observable],
    axes: &[TiltAxis],
    grid: &[f64],
) -> Result<TransferMatrix, TfError> {
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: axes.iter().map(|&a| Input::Tilt(a)).collect(),
    };
    let (plan, _) = tf::plan_auto(model, &tf::Scene::over_grid(request, grid))?;
    tf::evaluate(plan.as_ref(), grid)
}

/// The terms of a damped model: `thermal`, `thermal.<element>` ([`crate::thermal`], added to
/// `total`) and the `response.<input>` of the equivalent input noise
/// ([`crate::noise::equivalent`]). Nothing for an undamped model.
pub fn add_damping_terms(model: &Model, budget: &mut Budget) -> Result<(), TfError> {
    if model.is_undamped() {
        return Ok(());
    }
    let outputs: Vec<Observable> = budget.observables.iter().map(|b| b.observable).collect();
    let thermal = crate::thermal::thermal_noise(model, &outputs, &budget.freqs_hz)?;
    add_thermal(budget, &thermal);
    add_equivalent_response(budget, model)
}

/// Drops the DC bin (index 0) of a Welch CSD: the budget is shown on log axes, and detrending
/// removed the mean anyway.
fn without_dc(csd: &[num_complex::Complex64], n: usize) -> &[num_complex::Complex64] {
    &csd[n * n..]
}

/// Budget from a time series. `progress(done, total)` is called with samples processed.
pub fn budget_from_series(
    model: &Model,
    series: &mut dyn SeriesSource,
    opts: &BudgetOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<BudgetReport, BudgetError> {
    let fs = series.sample_rate_hz();
    let n = series.len();
    let axes = series.axes().to_vec();
    let seg_len = opts
        .welch_segment_len
        .unwrap_or_else(|| default_segment_len(n));
    if !(0.0..1.0).contains(&opts.welch_overlap_fraction) {
        return Err(BudgetError::Config(format!(
            "Welch overlap {} is not allowed: must be a fraction in [0, 1)",
            opts.welch_overlap_fraction
        )));
    }
    let overlap = (seg_len as f64 * opts.welch_overlap_fraction).round() as usize;
    let cfg = WelchConfig::new(seg_len)
        .with_overlap(overlap.min(seg_len.saturating_sub(1)))
        .with_averaging(opts.averaging);
    cfg.validate()?;
    cfg.check_series_len(n)?;
    let segment_samples = match opts.segment_duration_s {
        None => None,
        Some(d) => {
            let s = (d * fs).round();
            if !(d.is_finite() && s >= seg_len as f64) {
                return Err(BudgetError::Config(format!(
                    "segment duration {} s is not allowed: must hold at least one Welch segment \
                     ({seg_len} samples = {} s at {fs} Hz)",
                    crate::error::Num(d),
                    seg_len as f64 / fs
                )));
            }
            if s > n as f64 {
                return Err(BudgetError::Config(format!(
                    "segment duration {} s is not allowed: it is longer than the record \
                     ({n} samples = {} s at {fs} Hz), which then has no segment to compare",
                    crate::error::Num(d),
                    crate::error::Num(n as f64 / fs)
                )));
            }
            Some(s as usize)
        }
    };
    let n_ax = axes.len();
    check_kept_memory(&cfg, n, n_ax, segment_samples, opts.outputs.len())?;
    let mut whole = WelchAccumulator::new(n_ax, fs, &cfg)?;
    let mut current: Option<WelchAccumulator> = None;
    let mut in_segment = 0usize;
    let mut tf_cache: Option<TransferMatrix> = None;
    let mut segment_tilt: Vec<Vec<Vec<f32>>> = vec![Vec::new(); opts.outputs.len()];

    let mut start = 0;
    while start < n {
        let len = CHUNK_SAMPLES.min(n - start);
        let chunk = series.read_chunk(start, len)?;
        let views: Vec<&[f64]> = chunk.iter().map(Vec::as_slice).collect();
        whole.push(&views)?;
        if let Some(seg) = segment_samples {
            let mut offset = 0;
            while offset < len {
                let acc = match current.as_mut() {
                    Some(acc) => acc,
                    None => current.insert(WelchAccumulator::new(n_ax, fs, &cfg)?),
                };
                let take = (seg - in_segment).min(len - offset);
                let part: Vec<&[f64]> = views.iter().map(|c| &c[offset..offset + take]).collect();
                acc.push(&part)?;
                in_segment += take;
                offset += take;
                if in_segment == seg {
                    let spectra = current.take().expect("segment in progress").finish()?;
                    in_segment = 0;
                    if tf_cache.is_none() {
                        tf_cache = Some(tilt_tf(
                            model,
                            &opts.outputs,
                            &axes,
                            &spectra.freqs_hz[1..],
                        )?);
                    }
                    let tf = tf_cache.as_ref().expect("computed above");
                    // Reduce each finished segment to its tilt PSDs at once (bounded memory).
                    let b = tilt_budget(
                        tf,
                        &TiltCsd {
                            axes: &axes,
                            csd: without_dc(&spectra.data, n_ax),
                        },
                        &Readout { asd: vec![] },
                    );
                    for (o, ob) in b.observables.iter().enumerate() {
                        let psd = &ob.term(&TermKind::Tilt).expect("tilt term").psd;
                        segment_tilt[o].push(psd.iter().map(|&p| p as f32).collect());
                    }
                }
            }
        }
        start += len;
        progress(start as u64, n as u64);
    }
    let spectra = whole.finish()?;
    let grid = &spectra.freqs_hz[1..];
    let tf = match tf_cache {
        Some(tf) => tf,
        None => tilt_tf(model, &opts.outputs, &axes, grid)?,
    };
    check_csd_finite(&spectra.data, &axes)?;
    let mut budget = tilt_budget(
        &tf,
        &TiltCsd {
            axes: &axes,
            csd: without_dc(&spectra.data, n_ax),
        },
        &opts.readout,
    );
    let mut notes = Vec::new();
    if in_segment > 0 {
        notes.push(format!(
            "the last {in_segment} samples ({:.0} s) do not fill a segment and are left out of \
             the segment statistics (they are in the whole-record budget)",
            in_segment as f64 / fs
        ));
    }
    let segment_bands = band_per_observable(&opts.outputs, &segment_tilt, opts.percentiles);
    add_damping_terms(model, &mut budget)?;
    check_budget_finite(&budget)?;
    Ok(BudgetReport {
        budget,
        segment_duration_s: segment_samples
            .map(|s| s as f64 / fs)
            .filter(|_| !segment_bands.is_empty()),
        segment_bands,
        source: SpectralSource::Welch {
            sample_rate_hz: fs,
            segment_len: cfg.segment_len,
            overlap: cfg.overlap,
            averaging: match opts.averaging {
                Averaging::Mean => "mean".into(),
                Averaging::Median => "median".into(),
            },
            n_welch_segments: spectra.n_segments,
            n_samples: n,
        },
        axes,
        readout: opts.readout.clone(),
        notes,
    })
}

/// Refuses a run whose memory grows with the record beyond the memory available: a median
/// keeps every Welch segment's spectrum (16 bytes per channel and frequency), and budget
/// segments keep their tilt PSDs (4 bytes per output and frequency). A mean over the whole
/// record keeps neither.
fn check_kept_memory(
    cfg: &WelchConfig,
    n: usize,
    n_ax: usize,
    segment_samples: Option<usize>,
    n_outputs: usize,
) -> Result<(), BudgetError> {
    let n_freqs = cfg.n_freqs() as u64;
    let mut bytes = cfg.kept_bytes(n, n_ax);
    if let Some(seg) = segment_samples {
        let per_segment = n_freqs.saturating_mul(4 * n_outputs as u64);
        bytes = bytes.saturating_add(planned_bytes(n / seg.max(1), per_segment));
    }
    check_memory(
        || {
            format!(
                "{} Welch segments of {} samples (overlap {}) over {n} samples",
                cfg.n_segments(n),
                cfg.segment_len,
                cfg.overlap
            )
        },
        bytes,
    )?;
    Ok(())
}

fn band_per_observable(
    outputs: &[Observable],
    per_segment: &[Vec<Vec<f32>>],
    (lo, hi): (f64, f64),
) -> Vec<(Observable, SegmentBand)> {
    outputs
        .iter()
        .zip(per_segment)
        .filter(|(_, segs)| !segs.is_empty())
        .map(|(&o, segs)| (o, SegmentBand::new(segs, lo, hi)))
        .collect()
}

/// Budget from given tilt spectra, interpolated log-log onto `opts.spectra_grid_hz` inside the
/// band the data cover.
pub fn budget_from_spectra(
    model: &Model,
    spectra: &TiltSpectra,
    opts: &BudgetOptions,
) -> Result<BudgetReport, BudgetError> {
    let (grid, on_grid) = spectra.interpolate_loglog(&opts.spectra_grid_hz);
    if grid.is_empty() {
        let (a, b) = spectra.band_hz();
        return Err(BudgetError::Config(format!(
            "the tilt spectra cover {a} to {b} Hz, which contains no point of the model grid"
        )));
    }
    let mut notes = Vec::new();
    let (lo, hi) = (opts.spectra_grid_hz.first(), opts.spectra_grid_hz.last());
    if let (Some(&lo), Some(&hi)) = (lo, hi) {
        if grid[0] > lo || grid[grid.len() - 1] < hi {
            notes.push(format!(
                "output band restricted to {:.4e} .. {:.4e} Hz, the band the tilt data cover \
                 (model grid {lo:.4e} .. {hi:.4e} Hz)",
                grid[0],
                grid[grid.len() - 1]
            ));
        }
    }
    let tf = tilt_tf(model, &opts.outputs, &on_grid.axes, &grid)?;
    let mut budget: Budget = tilt_budget(
        &tf,
        &TiltCsd {
            axes: &on_grid.axes,
            csd: &on_grid.csd,
        },
        &opts.readout,
    );
    add_damping_terms(model, &mut budget)?;
    check_budget_finite(&budget)?;
    Ok(BudgetReport {
        budget,
        segment_bands: Vec::new(),
        segment_duration_s: None,
        source: SpectralSource::Spectra {
            data_band_hz: spectra.band_hz(),
        },
        axes: on_grid.axes.clone(),
        readout: opts.readout.clone(),
        notes,
    })
}

/// Refuses tilt cross-spectra that overflowed `f64` (samples far beyond any tilt angle, e.g.
/// 1e200 rad, square to infinity), naming the axis.
fn check_csd_finite(csd: &[num_complex::Complex64], axes: &[TiltAxis]) -> Result<(), BudgetError> {
    let n = axes.len();
    if let Some(j) = csd
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        let axis = axes[(j % (n * n)) / n];
        return Err(BudgetError::NotFinite(format!(
            "the tilt power spectrum of {} overflows f64: its samples are far too large to be \
             tilt angles in rad (check the file's units and --quantity)",
            axis.name()
        )));
    }
    Ok(())
}

/// Refuses a budget with a non-finite model term: every number the budget reports is finite
/// (a measured term may hold NaN where the record does not reach, which is documented).
fn check_budget_finite(budget: &Budget) -> Result<(), BudgetError> {
    for ob in &budget.observables {
        for term in &ob.terms {
            if let Some(k) = term.psd.iter().position(|p| !p.is_finite()) {
                return Err(BudgetError::NotFinite(format!(
                    "the {} term of {} is not finite at {} Hz: the input or the parameters are \
                     beyond the range of f64",
                    term.kind,
                    ob.observable.name(),
                    crate::error::Num(budget.freqs_hz[k])
                )));
            }
        }
    }
    Ok(())
}

/// Log-log interpolation of a positive spectrum `(freqs, values)` at `f` (for reading a budget
/// at exactly 1, 2, 5 mHz). `None` outside the band.
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
