//! The noise budget, computed from series or spectra: a record of the floor's motion (a time series of tilt and translation
//! channels, or tilt spectra) -> the cross-spectra of the model's inputs -> transfer functions
//! on the same grid -> the noise budget of the chosen observables (tilt, translation and
//! ground, readout, thermal, user-named terms), whole record and per segment, and read at
//! chosen frequencies.
//!
//! Time series are streamed in chunks through Welch accumulators, so a month of 10 Hz data is
//! processed in bounded memory: one whole-record accumulator, one for the current segment, and
//! the PSD of the term that adds to the total (`tilt`, `translation` or `ground`) of every
//! finished segment (stored as `f32`, enough for percentile bands). The channels' cross-spectra
//! are carried to the inputs' by [`GroundMap`]: bin by bin, in each channel's own quantity, with
//! inertial sensors corrected.
//! Progress is reported through a callback; the library never draws to the terminal.
//! Conventions: one-sided spectra, PSD in unit^2/Hz (see [`crate::noise`]).

mod measured;
pub mod option_checks;
mod summary;

pub use crate::noise::loglog_at;
pub use measured::{add_measured, series_psds, MeasuredPsds};
pub use summary::{SummaryRequest, DEFAULT_BAND_FRACTION, DEFAULT_SUMMARY_FREQS_HZ};

use crate::cancel::{Cancel, Cancelled};
use crate::error::TfError;
use crate::ground::GroundQuantity;
use crate::input::{GroundChannel, GroundMap, InputError, SeriesSource, TiltSpectra};
use crate::limits::{check_memory, planned_bytes, LimitError};
use crate::model::{Input, Model, Observable};
use crate::noise::{
    add_equivalent_response, add_thermal, add_user_terms, add_witness_noise, check_user_terms,
    check_witness_noise, ground_budget, Budget, BudgetReport, GroundCsd, Readout, SegmentBand,
    SpectralSource, TermKind, UserTerm, UserTermError, WitnessNoise, WitnessNoiseError,
};
use crate::spectral::{Averaging, CrossSpectra, SpectralError, WelchAccumulator, WelchConfig};
use crate::tf::{self, Request, TransferMatrix};
use num_complex::Complex64;

/// Samples per channel read from the input at a time: 2^18 samples x 3 channels x 8 bytes
/// = 6 MiB, large enough to amortize HDF5 calls, small against the 256 MB memory goal.
pub const CHUNK_SAMPLES: usize = 1 << 18;

/// Default Welch segment: 2^14 samples, or the largest power of two that fits four times
/// into a shorter record (so that at least 7 half-overlapping segments are averaged).
pub const DEFAULT_WELCH_SEGMENT: usize = 1 << 14;

/// Failures of a budget run.
#[derive(Debug, thiserror::Error)]
pub enum BudgetError {
    /// Cancelled through [`BudgetOptions::cancel`].
    #[error(transparent)]
    Cancelled(#[from] Cancelled),
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
    /// A user term or a coloured readout that does not fit the budget.
    #[error(transparent)]
    User(#[from] UserTermError),
    /// A witness noise that does not fit the budget.
    #[error(transparent)]
    Witness(#[from] WitnessNoiseError),
    /// Options that contradict each other or the input.
    #[error("{0}")]
    Config(crate::option_key::Message),
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
    /// Readout noise per observable, white or coloured.
    pub readout: Readout,
    /// User-named terms (ASDs of observables, or input noises through the model).
    pub user_terms: Vec<UserTerm>,
    /// The tiltmeter's own noise per tilt axis: shown through the model as `witness_noise`,
    /// not in the total.
    pub witness_noise: Vec<WitnessNoise>,
    /// Model grid for spectra input (Hz); time series use the Welch grid.
    pub spectra_grid_hz: Vec<f64>,
    /// Frequencies to read the budget at ([`crate::noise::SummaryAt`]).
    pub summary: SummaryRequest,
    /// Polled before each chunk of a series ([`CHUNK_SAMPLES`]).
    pub cancel: Cancel,
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
            user_terms: Vec::new(),
            witness_noise: Vec::new(),
            spectra_grid_hz: Vec::new(),
            summary: SummaryRequest::default(),
            cancel: Cancel::never(),
        }
    }
}

/// [`DEFAULT_WELCH_SEGMENT`] or, for short records, the largest power of two <= n/4 (at least 2).
pub fn default_segment_len(n_samples: usize) -> usize {
    let quarter = (n_samples / 4).max(2);
    DEFAULT_WELCH_SEGMENT.min(1 << quarter.ilog2())
}

/// The transfer functions from the floor's `inputs` (per unit displacement: rad, m) to
/// `outputs` on `grid`, by the planner's method.
fn ground_tf(
    model: &Model,
    outputs: &[Observable],
    inputs: &[Input],
    grid: &[f64],
) -> Result<TransferMatrix, TfError> {
    let request = Request {
        outputs: outputs.to_vec(),
        inputs: inputs.to_vec(),
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

/// The note of a budget from a tilt-rate series.
pub const RATE_BUDGET_NOTE: &str = "tilt rate: the Welch cross-spectra of the rate \
     (rad^2/s^2/Hz) divided by (2 pi f)^2 at every bin f > 0, exact up to Nyquist (no time \
     integration); the DC bin carries no angle information and is excluded";

/// The term of the floor's motion that adds to the total of a budget of `inputs`: `ground` for
/// tilt and translation together, else `tilt` or `translation`.
fn total_ground_term(inputs: &[Input]) -> TermKind {
    let tilt = inputs.iter().any(|i| matches!(i, Input::Tilt(_)));
    let translation = inputs.iter().any(|i| matches!(i, Input::Translation(_)));
    match (tilt, translation) {
        (true, true) => TermKind::Ground,
        (false, true) => TermKind::Translation,
        _ => TermKind::Tilt,
    }
}

/// The Welch settings of a series of `n` samples: the options' segment (or the default for
/// `n`) and overlap, checked against the record.
fn welch_config(opts: &BudgetOptions, n: usize) -> Result<WelchConfig, BudgetError> {
    let seg_len = opts
        .welch_segment_len
        .unwrap_or_else(|| default_segment_len(n));
    if !(0.0..1.0).contains(&opts.welch_overlap_fraction) {
        return Err(BudgetError::Config(
            format!(
                "Welch overlap {} is not allowed: must be a fraction in [0, 1)",
                opts.welch_overlap_fraction
            )
            .into(),
        ));
    }
    let overlap = (seg_len as f64 * opts.welch_overlap_fraction).round() as usize;
    let cfg = WelchConfig::new(seg_len)
        .with_overlap(overlap.min(seg_len.saturating_sub(1)))
        .with_averaging(opts.averaging);
    cfg.validate()?;
    cfg.check_series_len(n)?;
    Ok(cfg)
}

/// Samples per segment of the percentile band, if asked for: at least one Welch segment of
/// `seg_len`, at most the record of `n` samples at `fs` Hz.
fn segment_samples(
    opts: &BudgetOptions,
    fs: f64,
    n: usize,
    seg_len: usize,
) -> Result<Option<usize>, BudgetError> {
    Ok(match opts.segment_duration_s {
        None => None,
        Some(d) => {
            if !(d.is_finite() && d > 0.0) {
                return Err(BudgetError::Config(crate::message!(
                    "{} is not allowed: the segment duration must be a positive number of \
                     seconds",
                    crate::option_key::OptionKey::SEGMENT_DURATION.given(crate::error::Num(d))
                )));
            }
            let s = (d * fs).round();
            if s < seg_len as f64 {
                return Err(BudgetError::Config(
                    format!(
                    "segment duration {} s is not allowed: must hold at least one Welch segment \
                     ({seg_len} samples = {} s at {fs} Hz); shorten the Welch segment (nperseg) \
                     to at most {} samples, or lengthen the segment duration",
                    crate::error::Num(d),
                    seg_len as f64 / fs,
                    s.max(0.0)
                )
                    .into(),
                ));
            }
            if s > n as f64 {
                return Err(BudgetError::Config(
                    format!(
                        "segment duration {} s is not allowed: it is longer than the record \
                     ({n} samples = {} s at {fs} Hz), which then has no segment to compare",
                        crate::error::Num(d),
                        crate::error::Num(n as f64 / fs)
                    )
                    .into(),
                ));
            }
            Some(s as usize)
        }
    })
}

/// Budget from a time series of the floor's motion ([`SeriesSource::channels`]: tilt angles or
/// rates, translations as displacement, velocity or acceleration; their spectra become the
/// inputs' by [`GroundMap`], with inertial sensors corrected, and the DC bin is dropped).
/// `progress(done, total)` is called with samples processed.
pub fn budget_from_series(
    model: &Model,
    series: &mut dyn SeriesSource,
    opts: &BudgetOptions,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<BudgetReport, BudgetError> {
    opts.summary.validate()?;
    let fs = series.sample_rate_hz();
    let n = series.len();
    let channels = series.channels();
    let map = GroundMap::new(&channels, model.params().environment.g_m_per_s2)
        .map_err(|e| BudgetError::Config(e.into()))?;
    let inputs = map.inputs();
    let segment_term = total_ground_term(&inputs);
    let cfg = welch_config(opts, n)?;
    let seg_len = cfg.segment_len;
    // The Welch grid's band, known before the record is read: refuse given spectra that do not
    // cover it now rather than after a long pass.
    check_given_spectra(
        opts,
        fs / seg_len as f64,
        (seg_len / 2) as f64 * fs / seg_len as f64,
    )?;
    let segment_samples = segment_samples(opts, fs, n, seg_len)?;
    let n_ax = channels.len();
    check_kept_memory(&cfg, n, n_ax, segment_samples, opts.outputs.len())?;
    // Polled per Welch segment, not only per chunk: a chunk of short segments of many channels
    // can take a second.
    let mut whole = WelchAccumulator::new(n_ax, fs, &cfg)?.with_cancel(opts.cancel.clone());
    let mut segments = segment_samples.map(|samples| Segments {
        model,
        opts,
        map: &map,
        inputs: &inputs,
        cfg: &cfg,
        fs,
        samples,
        current: None,
        spectra: CrossSpectra {
            freqs_hz: Vec::new(),
            n_channels: n_ax,
            data: Vec::new(),
            n_segments: 0,
        },
        filled: 0,
        projected: opts.averaging == Averaging::Mean,
        psds: Vec::new(),
        tf: None,
        rows: Vec::new(),
        tilt: vec![Vec::new(); opts.outputs.len()],
    });

    let mut start = 0;
    while start < n {
        let len = CHUNK_SAMPLES.min(n - start);
        opts.cancel.check()?;
        let chunk = series.read_chunk(start, len)?;
        let views: Vec<&[f64]> = chunk.iter().map(Vec::as_slice).collect();
        whole.push(&views)?;
        if let Some(segments) = segments.as_mut() {
            segments.push(&views, len)?;
        }
        start += len;
        progress(start as u64, n as u64);
    }
    let (tf_cache, in_segment, segment_tilt) = match segments {
        Some(s) => (s.tf, s.filled, s.tilt),
        None => (None, 0, vec![Vec::new(); opts.outputs.len()]),
    };
    let spectra = whole.finish()?;
    let (grid, csd) = map.apply(&spectra);
    let tf = match tf_cache {
        Some(tf) => tf,
        None => ground_tf(model, &opts.outputs, &inputs, &grid)?,
    };
    check_csd_finite(&csd, &channels)?;
    let mut budget = ground_budget(
        &tf,
        &GroundCsd {
            inputs: &inputs,
            csd: &csd,
        },
        &opts.readout,
    );
    let notes = series_notes(&channels, &map, in_segment, fs);
    opts.cancel.check()?;
    let segment_bands = band_per_observable(
        &segment_term,
        &opts.outputs,
        &segment_tilt,
        opts.percentiles,
    );
    add_damping_terms(model, &mut budget)?;
    add_user_terms(&mut budget, model, &opts.user_terms)?;
    add_witness_noise(&mut budget, model, &opts.witness_noise)?;
    check_budget_finite(&budget)?;
    let report = BudgetReport {
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
        inputs,
        readout: opts.readout.clone(),
        user_terms: opts.user_terms.clone(),
        notes,
        summary: Vec::new(),
    };
    let tilt = summary::TiltData::Welch {
        freqs_hz: &grid,
        csd: &csd,
        cfg,
        n_segments: spectra.n_segments,
    };
    with_summary(model, report, &tilt, opts)
}

/// The notes of a budget from a record: a tilt read as a rate, the map's notes, and the
/// `left_over` samples (at `fs` Hz) that fill no budget segment.
fn series_notes(
    channels: &[GroundChannel],
    map: &GroundMap,
    left_over: usize,
    fs: f64,
) -> Vec<String> {
    let mut notes = Vec::new();
    if channels
        .iter()
        .any(|c| matches!(c.input, Input::Tilt(_)) && c.quantity == GroundQuantity::Velocity)
    {
        notes.push(RATE_BUDGET_NOTE.to_string());
    }
    notes.extend(map.notes().iter().cloned());
    notes.extend(map.spectra_notes());
    if left_over > 0 {
        notes.push(format!(
            "the last {left_over} samples ({:.0} s) do not fill a segment and are left out of \
             the segment statistics (they are in the whole-record budget)",
            left_over as f64 / fs
        ));
    }
    notes
}

/// The budget segments of a record read in chunks: each segment's Welch spectra, reduced to
/// the tilt PSDs of the outputs as soon as the segment is complete, so that memory stays
/// bounded.
struct Segments<'a> {
    model: &'a Model,
    opts: &'a BudgetOptions,
    map: &'a GroundMap,
    inputs: &'a [Input],
    cfg: &'a WelchConfig,
    fs: f64,
    /// Samples per segment.
    samples: usize,
    /// One accumulator and one matrix buffer for every segment, emptied and reused: a month of
    /// hourly segments of six channels would otherwise map and clear 5 MB twice an hour.
    current: Option<WelchAccumulator>,
    spectra: CrossSpectra,
    /// Samples of the current segment pushed so far.
    filled: usize,
    /// A mean: every Welch segment's spectra are projected on the transfer functions at once
    /// ([`WelchAccumulator::with_projections`]), and only the total's PSD of each output is
    /// summed. A median keeps the cross-spectra and propagates their median.
    projected: bool,
    /// The last segment's projected PSDs, `[output][bin]` from DC, reused.
    psds: Vec<Vec<f64>>,
    /// The transfer functions on the segments' grid, computed with the first segment.
    tf: Option<TransferMatrix>,
    /// The same, dense, for the segments' propagation: `[bin][output][input]`.
    rows: Vec<Complex64>,
    /// Per output, the PSDs of every finished segment: the term of the floor's motion that
    /// adds to the total ([`total_ground_term`]).
    tilt: Vec<Vec<Vec<f32>>>,
}

impl Segments<'_> {
    /// The transfer functions on the segments' grid (kept for the whole record's budget) as
    /// weights of the channels' spectra ([`GroundMap::channel_weights`]), `[bin][output]
    /// [channel]` from DC (whose weights are 0: the budget drops that bin).
    fn channel_weights(&mut self) -> Result<Vec<Complex64>, BudgetError> {
        let (n_in, n_out) = (self.inputs.len(), self.opts.outputs.len());
        let n_freqs = self.cfg.n_freqs();
        let grid: Vec<f64> = crate::spectral::bin_freqs(self.cfg.segment_len, self.fs, n_freqs)
            .skip(1)
            .collect();
        let tf = ground_tf(self.model, &self.opts.outputs, self.inputs, &grid)?;
        let rows = dense_rows(&tf, self.inputs);
        self.tf = Some(tf);
        let mut weights = vec![Complex64::new(0.0, 0.0); n_out * n_in];
        weights.extend_from_slice(&rows);
        for (row, &f) in weights[n_out * n_in..]
            .chunks_exact_mut(n_in)
            .zip(grid.iter().flat_map(|f| std::iter::repeat_n(f, n_out)))
        {
            self.map.channel_weights(f, row);
        }
        Ok(weights)
    }

    /// Pushes the next `len` samples of every channel (`views`), finishing the segments they
    /// complete.
    fn push(&mut self, views: &[&[f64]], len: usize) -> Result<(), BudgetError> {
        let (opts, seg) = (self.opts, self.samples);
        let mut offset = 0;
        while offset < len {
            if self.current.is_none() {
                let acc = WelchAccumulator::new(self.spectra.n_channels, self.fs, self.cfg)?
                    .with_cancel(opts.cancel.clone());
                self.current = Some(if self.projected {
                    let weights = self.channel_weights()?;
                    acc.with_projections(opts.outputs.len(), &weights)
                } else {
                    acc
                });
            }
            let acc = self.current.as_mut().expect("made above");
            let take = (seg - self.filled).min(len - offset);
            let part: Vec<&[f64]> = views.iter().map(|c| &c[offset..offset + take]).collect();
            acc.push(&part)?;
            self.filled += take;
            offset += take;
            if self.filled == seg {
                opts.cancel.check()?;
                self.filled = 0;
                if self.projected {
                    acc.finish_projections_into(&mut self.psds)?;
                    for (kept, psd) in self.tilt.iter_mut().zip(&self.psds) {
                        kept.push(psd[1..].iter().map(|&p| p as f32).collect());
                    }
                    continue;
                }
                acc.finish_into(&mut self.spectra)?;
                if self.tf.is_none() {
                    let grid = &self.spectra.freqs_hz[1..];
                    let tf = ground_tf(self.model, &opts.outputs, self.inputs, grid)?;
                    self.rows = dense_rows(&tf, self.inputs);
                    self.tf = Some(tf);
                }
                self.map.apply_in_place(&mut self.spectra);
                let nn = self.spectra.n_channels * self.spectra.n_channels;
                let csd = &self.spectra.data[nn..];
                for (o, kept) in self.tilt.iter_mut().enumerate() {
                    let shape = (opts.outputs.len(), self.inputs.len());
                    kept.push(ground_total_psd(&self.rows, shape, o, csd));
                }
            }
        }
        Ok(())
    }
}

/// `tf`'s columns of `inputs`, dense: `rows[(k * n_outputs + o) * inputs.len() + i]` is
/// `H_o,inputs[i]` at bin `k`.
fn dense_rows(tf: &TransferMatrix, inputs: &[Input]) -> Vec<Complex64> {
    let cols: Vec<usize> = inputs
        .iter()
        .map(|&a| {
            tf.input_index(a)
                .expect("the budget's transfer matrix has every input")
        })
        .collect();
    let n_out = tf.outputs.len();
    let mut rows = Vec::with_capacity(tf.freqs_hz.len() * n_out * cols.len());
    for k in 0..tf.freqs_hz.len() {
        for o in 0..n_out {
            rows.extend(cols.iter().map(|&c| tf.get(k, o, c)));
        }
    }
    rows
}

/// The PSD (f32, enough for percentile bands) of output `o` driven by the whole motion of the
/// floor, from one segment's cross-spectra of the inputs `csd` (`[bin][i][j]`, Hermitian) and
/// the dense transfer rows ([`dense_rows`]): the term of [`ground_budget`] that adds to the
/// total (`ground`, or `tilt` or `translation` alone), summed in its order so that the value is
/// its value bit for bit, without the breakdown a segment does not keep.
fn ground_total_psd(
    rows: &[Complex64],
    (n_out, n): (usize, usize),
    o: usize,
    csd: &[Complex64],
) -> Vec<f32> {
    (0..csd.len() / (n * n))
        .map(|k| {
            let h = &rows[(k * n_out + o) * n..(k * n_out + o + 1) * n];
            let s = &csd[k * n * n..(k + 1) * n * n];
            crate::noise::propagate_total(h, s) as f32
        })
        .collect()
}

/// `report` with its summary ([`summary::summarize`]), and a note for every frequency left out.
fn with_summary(
    model: &Model,
    mut report: BudgetReport,
    tilt: &summary::TiltData<'_>,
    opts: &BudgetOptions,
) -> Result<BudgetReport, BudgetError> {
    let (summary, notes) = summary::summarize(model, &report, tilt, opts)?;
    report.summary = summary;
    report.notes.extend(notes);
    Ok(report)
}

/// Refuses a coloured readout or a user term whose spectrum does not cover the budget's band
/// `[lo, hi]` (Hz), or that is an ASD of an observable not budgeted.
fn check_given_spectra(opts: &BudgetOptions, lo: f64, hi: f64) -> Result<(), BudgetError> {
    opts.readout
        .check_covers(lo, hi)
        .map_err(|e| BudgetError::User(UserTermError::Coverage(e)))?;
    check_user_terms(&opts.user_terms, &opts.outputs, lo, hi)?;
    check_witness_noise(&opts.witness_noise, lo, hi)
        .map_err(|e| BudgetError::Witness(WitnessNoiseError::Coverage(e)))?;
    Ok(())
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
    term: &TermKind,
    outputs: &[Observable],
    per_segment: &[Vec<Vec<f32>>],
    (lo, hi): (f64, f64),
) -> Vec<(Observable, SegmentBand)> {
    outputs
        .iter()
        .zip(per_segment)
        .filter(|(_, segs)| !segs.is_empty())
        .map(|(&o, segs)| (o, SegmentBand::new(term.clone(), segs, lo, hi)))
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
        return Err(BudgetError::Config(
            format!(
                "the tilt spectra cover {a} to {b} Hz, which contains no point of the model grid"
            )
            .into(),
        ));
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
    check_given_spectra(opts, grid[0], grid[grid.len() - 1])?;
    let inputs: Vec<Input> = on_grid.axes.iter().map(|&a| Input::Tilt(a)).collect();
    let tf = ground_tf(model, &opts.outputs, &inputs, &grid)?;
    let mut budget: Budget = ground_budget(
        &tf,
        &GroundCsd {
            inputs: &inputs,
            csd: &on_grid.csd,
        },
        &opts.readout,
    );
    add_damping_terms(model, &mut budget)?;
    add_user_terms(&mut budget, model, &opts.user_terms)?;
    add_witness_noise(&mut budget, model, &opts.witness_noise)?;
    check_budget_finite(&budget)?;
    let report = BudgetReport {
        budget,
        segment_bands: Vec::new(),
        segment_duration_s: None,
        source: SpectralSource::Spectra {
            data_band_hz: spectra.band_hz(),
        },
        inputs,
        readout: opts.readout.clone(),
        user_terms: opts.user_terms.clone(),
        notes,
        summary: Vec::new(),
    };
    with_summary(model, report, &summary::TiltData::Spectra(spectra), opts)
}

/// Refuses cross-spectra of the inputs that overflowed `f64` (samples far beyond any tilt or
/// floor motion, e.g. 1e200 rad, square to infinity), naming the input.
fn check_csd_finite(
    csd: &[num_complex::Complex64],
    channels: &[crate::input::GroundChannel],
) -> Result<(), BudgetError> {
    let n = channels.len();
    if let Some(j) = csd
        .iter()
        .position(|z| !(z.re.is_finite() && z.im.is_finite()))
    {
        let c = channels[(j % (n * n)) / n];
        return Err(BudgetError::NotFinite(format!(
            "the power spectrum of {} overflows f64: its samples are far too large to be a \
             {} of the floor in {} (check the file's units)",
            c.input.name(),
            c.quantity.name(),
            c.unit()
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
