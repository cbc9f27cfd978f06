//! The coherence estimate: a tilt record and a measured record of the pendulum's observables ->
//! their common stretch ([`crate::align`]) -> one Welch cross-spectral matrix of all channels
//! ([`crate::spectral::csd_matrix`]) -> for each observable its ordinary coherence with each tilt
//! axis, its multiple coherence with all axes, and the measured multiple-input transfer function
//! from each axis ([`crate::spectral::multiple_input`]) with confidence intervals
//! ([`crate::spectral::confidence`]) -> beside the model's transfer function from the planner
//! on the same frequencies, and a fit of one complex factor measured/model per entry
//! ([`Agreement`]).
//!
//! Pure numerics on samples in memory: the readers are in `tiltnoise-io`, the figure in
//! `tiltnoise-plot`.
//!
//! # Conventions
//!
//! Frequencies are the Welch bins `k fs / segment_len`, `k >= 1` (DC is left out, as in the
//! budget). PSDs are one-sided (unit^2/Hz). Transfer functions are complex amplitudes of
//! `exp(+i w t)`, in the observable's unit per rad of tilt `t` (the sign convention of
//! [`crate::model::tilt`]), measured and model alike: a measured observable that lags the tilt
//! has a negative phase. When the two records' sample grids are offset by a fraction of a
//! sample (`residual_offset_s` of [`crate::align::Alignment`]), the measured transfer functions
//! are multiplied by `exp(-i w residual_offset_s)`, which removes exactly the phase that offset
//! adds, so they refer to simultaneous samples.
//!
//! # Confidence
//!
//! Intervals are at [`CoherenceOptions::confidence`] (0.95 by default) with the overlap-corrected
//! number of averages `n_d` ([`crate::spectral::confidence::equivalent_averages`]): ordinary and
//! multiple coherence by Fisher's transform, the transfer function by the radius of its
//! confidence circle, the significance thresholds of coherence from its null distribution.
//! Bins where the tilt axes are linearly dependent or dead are not estimable (NaN, and
//! [`CoherenceReport::estimable`] false), with a note.

mod compare;
pub mod resolution;

pub use compare::{fit_agreement, with_error, Agreement};

use crate::align::{align, AlignError, Alignment, RecordClock};
use crate::budget::default_segment_len;
use crate::error::{Num, TfError};
use crate::model::{Input, Model, Observable, Request, TiltAxis};
use crate::option_key::OptionKey;
use crate::spectral::confidence::{
    bin_correlation, coherence_interval, coherence_threshold, equivalent_averages, tf_radius,
    tf_sigma,
};
use crate::spectral::{
    coherence, csd_matrix_cancellable, multiple_input, CrossSpectra, MultipleInput, SpectralError,
    WelchConfig,
};
use crate::tf::{self, Scene};
use num_complex::Complex64;
use resolution::{kernel, smoothed, RESOLUTION_FRACTION};

/// A uniformly sampled record to estimate from: its name for messages (the option and the
/// file), sample rate, start time and channels (all of equal length, finite samples).
#[derive(Debug, Clone, PartialEq)]
pub struct Record<'a, C> {
    /// The record's name in messages and notes, e.g. `--tilt tilt.h5`.
    pub name: &'a str,
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// The instant of sample 0, if the file states one.
    pub start_time: Option<jiff::Timestamp>,
    /// `(label, samples)`: tilt axes (rad, the crate's sign convention) or observables (m, rad).
    pub channels: Vec<(C, &'a [f64])>,
}

impl<C> Record<'_, C> {
    fn n_samples(&self) -> usize {
        self.channels.first().map_or(0, |(_, x)| x.len())
    }

    fn clock(&self) -> RecordClock<'_> {
        RecordClock {
            name: self.name,
            sample_rate_hz: self.sample_rate_hz,
            n_samples: self.n_samples(),
            start_time: self.start_time,
        }
    }
}

/// Options of the coherence estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct CoherenceOptions {
    /// Welch segment length in samples (`None`: the budget's default for the common stretch,
    /// [`default_segment_len`]).
    pub welch_segment_len: Option<usize>,
    /// Welch overlap as a fraction of the segment, in [0, 1).
    pub welch_overlap_fraction: f64,
    /// Confidence level of every interval, in (0, 1).
    pub confidence: f64,
    /// Band (Hz) of the measured/model fit ([`Agreement`]); `None`: every bin.
    pub fit_band_hz: Option<(f64, f64)>,
    /// What the tilt record holds: angles (rad) or rates (rad/s). A rate's cross-spectra are
    /// turned into the angle's bin by bin ([`crate::input::rate::rate_channels_to_angle`]), so
    /// the measured transfer functions are from the angle, as the model's.
    pub tilt_quantity: crate::input::Quantity,
    /// Polled before each Welch segment.
    pub cancel: crate::cancel::Cancel,
}

impl Default for CoherenceOptions {
    fn default() -> CoherenceOptions {
        CoherenceOptions {
            welch_segment_len: None,
            welch_overlap_fraction: 0.5,
            confidence: 0.95,
            fit_band_hz: None,
            tilt_quantity: crate::input::Quantity::Angle,
            cancel: crate::cancel::Cancel::never(),
        }
    }
}

/// The Welch estimate behind the report.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WelchSummary {
    /// Sample rate (Hz).
    pub sample_rate_hz: f64,
    /// Samples per segment.
    pub segment_len: usize,
    /// Samples shared by consecutive segments.
    pub overlap: usize,
    /// Segments averaged (mean).
    pub n_segments: usize,
    /// Equivalent number of independent averages `n_d` (overlap-corrected).
    pub n_equivalent: f64,
    /// Samples of each record used (the common stretch).
    pub n_samples: usize,
}

/// One observable against one tilt axis.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AxisEstimate {
    /// The tilt axis.
    pub axis: TiltAxis,
    /// Ordinary coherence with the axis, per bin (scipy.signal.coherence).
    pub coherence: Vec<f64>,
    /// Lower confidence bound of the true ordinary coherence.
    pub coherence_lower: Vec<f64>,
    /// Upper confidence bound of the true ordinary coherence.
    pub coherence_upper: Vec<f64>,
    /// Measured transfer function from the axis (multiple-input estimate, other axes held
    /// fixed), observable unit per rad, `exp(+i w t)`.
    pub tf: Vec<Complex64>,
    /// Radius of its confidence circle (same unit).
    pub tf_radius: Vec<f64>,
    /// Its standard error per real direction (same unit).
    pub tf_sigma: Vec<f64>,
    /// The model's transfer function on the same bins.
    pub model: Vec<Complex64>,
    /// Whether the Welch resolution resolves the model at each bin ([`resolution`]): only
    /// those bins enter [`AxisEstimate::agreement`].
    pub model_resolved: Vec<bool>,
    /// Measured/model fit; `None` when no bin qualifies or the model entry is zero.
    pub agreement: Option<Agreement>,
}

/// One measured observable against all tilt axes.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ObservableEstimate {
    /// The observable.
    pub observable: Observable,
    /// Its one-sided PSD (unit^2/Hz).
    pub psd: Vec<f64>,
    /// Multiple coherence with all tilt axes.
    pub multiple_coherence: Vec<f64>,
    /// Lower confidence bound of the true multiple coherence.
    pub multiple_coherence_lower: Vec<f64>,
    /// Upper confidence bound of the true multiple coherence.
    pub multiple_coherence_upper: Vec<f64>,
    /// PSD of the part not linearly explained by the tilt axes, `psd (1 - multiple coherence)`.
    pub residual_psd: Vec<f64>,
    /// One entry per tilt axis, in [`CoherenceReport::axes`] order.
    pub axes: Vec<AxisEstimate>,
}

/// Everything the coherence estimate found.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CoherenceReport {
    /// Welch bins (Hz), DC left out.
    pub freqs_hz: Vec<f64>,
    /// Tilt axes, in canonical order.
    pub axes: Vec<TiltAxis>,
    /// One-sided PSD of each tilt axis (rad^2/Hz), in `axes` order.
    pub tilt_psd: Vec<Vec<f64>>,
    /// One entry per measured observable analysed.
    pub observables: Vec<ObservableEstimate>,
    /// Per bin: whether the tilt axes could be inverted there (module docs).
    pub estimable: Vec<bool>,
    /// Per bin: reciprocal condition number of the tilt axes' normalized cross-spectral matrix.
    pub input_rcond: Vec<f64>,
    /// The Welch estimate.
    pub welch: WelchSummary,
    /// Confidence level of every interval.
    pub confidence: f64,
    /// Ordinary coherence that pure noise exceeds with probability `1 - confidence`.
    pub coherence_threshold: f64,
    /// Multiple coherence (all axes) that pure noise exceeds with probability
    /// `1 - confidence`.
    pub multiple_coherence_threshold: f64,
    /// How the records were paired.
    pub alignment: Alignment,
    /// Method of the model's transfer functions.
    pub model_method: String,
    /// Band (Hz) the measured/model fit was restricted to, if any.
    pub fit_band_hz: Option<(f64, f64)>,
    /// What was assumed, cut or could not be estimated.
    pub notes: Vec<String>,
}

/// Failures of the coherence estimate, each naming the record, channel or option.
#[derive(Debug, thiserror::Error)]
pub enum CoherenceError {
    /// The records cannot be paired in time.
    #[error(transparent)]
    Align(#[from] AlignError),
    /// The Welch estimate failed.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
    /// The model's transfer functions could not be evaluated.
    #[error(transparent)]
    Tf(#[from] TfError),
    /// Options or records that cannot give an estimate.
    #[error("{0}")]
    Config(crate::option_key::Message),
}

/// Estimates the coherence of a measured record with a tilt record, and the transfer
/// functions between them (module docs).
///
/// # Errors
///
/// [`CoherenceError`]: options out of range; a record without channels, with channels of
/// unequal length or a non-finite sample; records that do not overlap, have different
/// sample rates or a common stretch shorter than one Welch segment or too short for the number
/// of tilt axes; a channel without power or whose spectrum overflows; tilt axes dependent at
/// every frequency; a model transfer function that cannot be evaluated.
pub fn coherence_from_series(
    model: &Model,
    tilt: &Record<'_, TiltAxis>,
    measured: &Record<'_, Observable>,
    opts: &CoherenceOptions,
) -> Result<CoherenceReport, CoherenceError> {
    check_options(opts)?;
    check_record(tilt)?;
    check_record(measured)?;
    let alignment = align(&tilt.clock(), &measured.clock())?;
    let n = alignment.len;
    let fs = alignment.sample_rate_hz;
    let cfg = welch_config(opts, n, fs, tilt.name, measured.name)?;
    let q = tilt.channels.len();
    let n_segments = cfg.n_segments(n);
    let n_d = equivalent_averages(&cfg, n_segments);
    if n_d < q as f64 + 1.0 {
        return Err(CoherenceError::Config(crate::message!(
            "the common stretch of {} and {} ({n} samples) gives {n_segments} Welch segments of \
             {} samples, {n_d:.2} independent averages: {} tilt axes need at least {}; use a \
             shorter {}",
            tilt.name.to_string(),
            measured.name.to_string(),
            cfg.segment_len,
            q,
            q + 1,
            OptionKey::NPERSEG
        )));
    }
    let (channels, names) = common_stretch(tilt, measured, &alignment);
    check_not_constant(&channels, &names)?;
    let mut spectra = csd_matrix_cancellable(&channels, fs, &cfg, &opts.cancel)?;
    if opts.tilt_quantity == crate::input::Quantity::Rate {
        let rates: Vec<usize> = (0..tilt.channels.len()).collect();
        crate::input::rate::rate_channels_to_angle(&mut spectra, &rates);
    }
    check_spectra(&spectra, &names)?;
    let inputs: Vec<usize> = (0..q).collect();
    let outputs: Vec<usize> = (q..q + measured.channels.len()).collect();
    let mimo = multiple_input(&spectra, &inputs, &outputs)?;
    // Everything below on bins 1.. (DC left out).
    let nf = spectra.n_freqs() - 1;
    let freqs_hz = spectra.freqs_hz[1..].to_vec();
    let estimable = mimo.estimable[1..].to_vec();
    let input_rcond = mimo.input_rcond[1..].to_vec();
    let axes: Vec<TiltAxis> = tilt.channels.iter().map(|(a, _)| *a).collect();
    if !estimable.iter().any(|&e| e) {
        let worst = input_rcond.iter().copied().fold(0.0, f64::max);
        return Err(CoherenceError::Config(crate::message!(
            "the tilt axes {} of {} are linearly dependent at every frequency (largest \
             reciprocal condition {worst:.1e} of their cross-spectral matrix): analyse one of \
             them at a time ({})",
            axes.iter().map(|a| a.name()).collect::<Vec<_>>().join(", "),
            tilt.name.to_string(),
            OptionKey::AXES
        )));
    }
    let level = opts.confidence;
    let alpha = 1.0 - level;
    let (model_tf, model_smoothed) =
        model_tf(model, &measured.channels, &axes, &freqs_hz, cfg.segment_len)?;
    let mc_threshold = coherence_threshold(n_d, q, alpha);
    let mut notes = alignment.notes.clone();
    let estimation = Estimation {
        spectra: &spectra,
        mimo: &mimo,
        q,
        nf,
        n_d,
        level,
        freqs_hz: &freqs_hz,
        estimable: &estimable,
        residual_offset_s: alignment.residual_offset_s,
        model_tf: &model_tf,
        model_smoothed: &model_smoothed,
        correlation: bin_correlation(cfg.segment_len),
        fit_band_hz: opts.fit_band_hz,
    };
    let observables = measured
        .channels
        .iter()
        .enumerate()
        .map(|(o, (obs, _))| estimation.observable(o, *obs, &axes, &mut notes))
        .collect();
    let missing = estimable.iter().filter(|&&e| !e).count();
    if missing > 0 {
        let first = estimable.iter().position(|&e| !e).unwrap_or(0);
        notes.push(format!(
            "{missing} of {nf} bins (the first at {} Hz) are not estimable: the tilt axes are \
             linearly dependent or without power there; their transfer functions and multiple \
             coherence are NaN",
            freqs_hz[first]
        ));
    }
    Ok(CoherenceReport {
        tilt_psd: (0..q).map(|i| spectra.psd(i)[1..].to_vec()).collect(),
        freqs_hz,
        axes,
        observables,
        estimable,
        input_rcond,
        welch: WelchSummary {
            sample_rate_hz: fs,
            segment_len: cfg.segment_len,
            overlap: cfg.overlap,
            n_segments,
            n_equivalent: n_d,
            n_samples: n,
        },
        confidence: level,
        coherence_threshold: coherence_threshold(n_d, 1, alpha),
        multiple_coherence_threshold: mc_threshold,
        alignment,
        model_method: model_tf.method.name().to_string(),
        fit_band_hz: opts.fit_band_hz,
        notes,
    })
}

/// The channels over the common stretch (the tilt axes, then the measured observables), with
/// the names that messages give them.
fn common_stretch<'a>(
    tilt: &Record<'a, TiltAxis>,
    measured: &Record<'a, Observable>,
    alignment: &Alignment,
) -> (Vec<&'a [f64]>, Vec<String>) {
    let n = alignment.len;
    let mut channels: Vec<&[f64]> = tilt
        .channels
        .iter()
        .map(|(_, x)| &x[alignment.start_a..alignment.start_a + n])
        .collect();
    channels.extend(
        measured
            .channels
            .iter()
            .map(|(_, x)| &x[alignment.start_b..alignment.start_b + n]),
    );
    let names: Vec<String> = tilt
        .channels
        .iter()
        .map(|(a, _)| format!("{} of {}", a.name(), tilt.name))
        .chain(
            measured
                .channels
                .iter()
                .map(|(o, _)| format!("{} of {}", o.name(), measured.name)),
        )
        .collect();
    (channels, names)
}

/// A constant channel has no power above DC; its Welch estimate would be rounding noise.
fn check_not_constant(channels: &[&[f64]], names: &[String]) -> Result<(), CoherenceError> {
    for (x, name) in channels.iter().zip(names) {
        if let Some(&first) = x.first().filter(|&&v| x.iter().all(|&w| w == v)) {
            let what = match first == 0.0 {
                true => "zero at every sample".to_string(),
                false => format!("constant ({})", Num(first)),
            };
            return Err(CoherenceError::Config(
                format!(
                    "{name} is {what} over the common stretch: it has no power above DC to \
                 analyse; leave it out"
                )
                .into(),
            ));
        }
    }
    Ok(())
}

/// Every channel's power spectrum finite and not zero above DC.
fn check_spectra(spectra: &CrossSpectra, names: &[String]) -> Result<(), CoherenceError> {
    for (c, name) in names.iter().enumerate() {
        let psd = spectra.psd(c);
        if psd.iter().any(|p| !p.is_finite()) {
            return Err(CoherenceError::Config(
                format!(
                "the power spectrum of {name} overflows f64: its samples are far too large for \
                 its unit (check the file's units)"
            )
                .into(),
            ));
        }
        if psd[1..].iter().all(|&p| p == 0.0) {
            return Err(CoherenceError::Config(
                format!(
                    "{name} has no power at any frequency above DC (the series is constant): it \
                 cannot be analysed; leave it out"
                )
                .into(),
            ));
        }
    }
    Ok(())
}

/// What every observable's estimate reads, on bins 1.. (DC left out): the spectra (tilt axes
/// first, `q` of them) and their multiple-input solution, the model, the statistics.
struct Estimation<'a> {
    spectra: &'a CrossSpectra,
    mimo: &'a MultipleInput,
    q: usize,
    nf: usize,
    n_d: f64,
    level: f64,
    freqs_hz: &'a [f64],
    estimable: &'a [bool],
    residual_offset_s: f64,
    model_tf: &'a tf::TransferMatrix,
    model_smoothed: &'a [Vec<Complex64>],
    correlation: [f64; 3],
    fit_band_hz: Option<(f64, f64)>,
}

impl Estimation<'_> {
    /// The Welch bin of entry `k` (DC left out).
    fn at(k: usize) -> usize {
        k + 1
    }

    /// Removes the phase of a sub-sample offset between the grids: exp(-i w r).
    fn unshift(&self, k: usize) -> Complex64 {
        Complex64::from_polar(
            1.0,
            -2.0 * std::f64::consts::PI * self.freqs_hz[k] * self.residual_offset_s,
        )
    }

    /// Measured observable `o` against every tilt axis.
    fn observable(
        &self,
        o: usize,
        obs: Observable,
        axes: &[TiltAxis],
        notes: &mut Vec<String>,
    ) -> ObservableEstimate {
        let (mimo, nf, q) = (self.mimo, self.nf, self.q);
        let y = q + o;
        let mc: Vec<f64> = (0..nf)
            .map(|k| mimo.multiple_coherence_at(Self::at(k), o))
            .collect();
        let (mc_lo, mc_hi) = intervals(&mc, self.n_d, q, self.level);
        let residual_psd: Vec<f64> = (0..nf)
            .map(|k| mimo.residual_psd_at(Self::at(k), o))
            .collect();
        let per_axis = axes
            .iter()
            .enumerate()
            .map(|(i, &axis)| self.axis(o, obs, i, axis, &residual_psd, notes))
            .collect();
        ObservableEstimate {
            observable: obs,
            psd: self.spectra.psd(y)[1..].to_vec(),
            multiple_coherence: mc,
            multiple_coherence_lower: mc_lo,
            multiple_coherence_upper: mc_hi,
            residual_psd,
            axes: per_axis,
        }
    }

    /// Measured observable `o` against tilt axis `i`, and its agreement with the model.
    fn axis(
        &self,
        o: usize,
        obs: Observable,
        i: usize,
        axis: TiltAxis,
        residual_psd: &[f64],
        notes: &mut Vec<String>,
    ) -> AxisEstimate {
        let (mimo, nf, q, n_d, level) = (self.mimo, self.nf, self.q, self.n_d, self.level);
        let (freqs_hz, estimable) = (self.freqs_hz, self.estimable);
        let at = Self::at;
        let y = q + o;
        let coh = coherence(self.spectra, i, y)[1..].to_vec();
        let (coh_lo, coh_hi) = intervals(&coh, n_d, 1, level);
        let tf: Vec<Complex64> = (0..nf)
            .map(|k| mimo.tf_at(at(k), o, i) * self.unshift(k))
            .collect();
        let radius: Vec<f64> = (0..nf)
            .map(|k| {
                let (nn, inv) = (residual_psd[k], mimo.inverse_diagonal_at(at(k), i));
                tf_radius(nn, inv, n_d, q, level)
            })
            .collect();
        let sigma: Vec<f64> = (0..nf)
            .map(|k| tf_sigma(residual_psd[k], mimo.inverse_diagonal_at(at(k), i), n_d, q))
            .collect();
        let model_entry: Vec<Complex64> = (0..nf).map(|k| self.model_tf.get(k, o, i)).collect();
        let smoothed = &self.model_smoothed[o * q + i];
        let model_resolved: Vec<bool> = (0..nf)
            .map(|k| (smoothed[k] - model_entry[k]).norm() <= RESOLUTION_FRACTION * sigma[k])
            .collect();
        let unresolved = (0..nf)
            .filter(|&k| estimable[k] && !model_resolved[k])
            .count();
        if unresolved > 0 {
            notes.push(format!(
                "{}/{}: {unresolved} of {nf} bins are left out of the measured/model fit: \
                 the model varies across the Welch resolution there by more than {} of the \
                 bin's standard error (resonances, the lowest bins)",
                obs.name(),
                axis.name(),
                RESOLUTION_FRACTION
            ));
        }
        // Every estimable bin of the band, whatever its coherence: selecting bins by their
        // estimated coherence would select underestimated residuals, and so errors.
        let usable: Vec<bool> = (0..nf)
            .map(|k| {
                estimable[k]
                    && model_resolved[k]
                    && self
                        .fit_band_hz
                        .is_none_or(|(lo, hi)| (lo..=hi).contains(&freqs_hz[k]))
            })
            .collect();
        let agreement = fit_agreement(
            freqs_hz,
            &tf,
            &sigma,
            &model_entry,
            &usable,
            self.correlation,
        );
        AxisEstimate {
            axis,
            coherence: coh,
            coherence_lower: coh_lo,
            coherence_upper: coh_hi,
            tf,
            tf_radius: radius,
            tf_sigma: sigma,
            model: model_entry,
            model_resolved,
            agreement,
        }
    }
}

/// At least one channel, all of the same length, every sample finite.
fn check_record<C: Label>(record: &Record<'_, C>) -> Result<(), CoherenceError> {
    let name = record.name;
    let Some((first, x0)) = record.channels.first() else {
        return Err(CoherenceError::Config(
            format!("{name}: no channel to analyse").into(),
        ));
    };
    for (c, x) in &record.channels {
        if x.len() != x0.len() {
            return Err(CoherenceError::Config(
                format!(
                    "{name}: channel {} has {} samples but channel {} has {}: channels must have \
                 equal length",
                    c.label(),
                    x.len(),
                    first.label(),
                    x0.len()
                )
                .into(),
            ));
        }
        if let Some(k) = x.iter().position(|v| !v.is_finite()) {
            return Err(CoherenceError::Config(
                format!(
                "{name}: channel {} has the non-finite sample {} at index {k}: every sample must \
                 be finite",
                c.label(),
                x[k]
            )
                .into(),
            ));
        }
    }
    Ok(())
}

/// A channel's name in messages.
trait Label {
    fn label(&self) -> &'static str;
}

impl Label for TiltAxis {
    fn label(&self) -> &'static str {
        self.name()
    }
}

impl Label for Observable {
    fn label(&self) -> &'static str {
        self.name()
    }
}

fn check_options(opts: &CoherenceOptions) -> Result<(), CoherenceError> {
    if !(0.0..1.0).contains(&opts.welch_overlap_fraction) {
        return Err(CoherenceError::Config(
            format!(
                "Welch overlap {} is not allowed: must be a fraction in [0, 1)",
                opts.welch_overlap_fraction
            )
            .into(),
        ));
    }
    if !(opts.confidence > 0.0 && opts.confidence < 1.0) {
        return Err(CoherenceError::Config(
            format!(
                "confidence level {} is not allowed: must be in (0, 1), e.g. 0.95",
                opts.confidence
            )
            .into(),
        ));
    }
    if let Some((lo, hi)) = opts.fit_band_hz {
        if !(lo.is_finite() && hi.is_finite() && 0.0 <= lo && lo < hi) {
            return Err(CoherenceError::Config(
                format!(
                    "fit band {lo}..{hi} Hz is not allowed: must be finite with 0 <= low < high"
                )
                .into(),
            ));
        }
    }
    Ok(())
}

/// The Welch configuration of the common stretch of `n` samples: the given or default segment,
/// the overlap fraction rounded to samples, mean averaging.
fn welch_config(
    opts: &CoherenceOptions,
    n: usize,
    fs: f64,
    tilt: &str,
    measured: &str,
) -> Result<WelchConfig, CoherenceError> {
    let seg = opts
        .welch_segment_len
        .unwrap_or_else(|| default_segment_len(n));
    let overlap = (seg as f64 * opts.welch_overlap_fraction).round() as usize;
    let cfg = WelchConfig::new(seg).with_overlap(overlap.min(seg.saturating_sub(1)));
    cfg.validate()?;
    if n < seg {
        return Err(CoherenceError::Config(crate::message!(
            "the common stretch of {} and {} is {n} samples ({} s at {fs} Hz), \
             shorter than one Welch segment of {seg} samples: use a shorter {} or longer \
             records",
            tilt.to_string(),
            measured.to_string(),
            n as f64 / fs,
            OptionKey::NPERSEG
        )));
    }
    Ok(cfg)
}

/// Confidence intervals of coherence estimates with `q` inputs.
fn intervals(gamma2: &[f64], n_d: f64, q: usize, level: f64) -> (Vec<f64>, Vec<f64>) {
    gamma2
        .iter()
        .map(|&g| coherence_interval(g, n_d, q, level))
        .unzip()
}

/// The model's tilt transfer functions to the measured observables on the bins (through the
/// planner, as the budget and `tf` evaluate them), and per entry (`[output * n_axes + axis]`)
/// the model smoothed by the Welch kernel of `segment_len` samples ([`resolution`]).
fn model_tf(
    model: &Model,
    measured: &[(Observable, &[f64])],
    axes: &[TiltAxis],
    freqs_hz: &[f64],
    segment_len: usize,
) -> Result<(tf::TransferMatrix, Vec<Vec<Complex64>>), TfError> {
    let request = Request {
        outputs: measured.iter().map(|(o, _)| *o).collect(),
        inputs: axes.iter().map(|&a| Input::Tilt(a)).collect(),
    };
    let df = freqs_hz[0];
    let kernel = kernel(segment_len);
    let mut fine = Vec::with_capacity(freqs_hz.len() * kernel.len());
    let mut usable = Vec::with_capacity(fine.capacity());
    for &f in freqs_hz {
        for &(nu, _) in &kernel {
            let g = f + nu * df;
            usable.push(g > 0.0);
            fine.push(if g > 0.0 { g } else { f });
        }
    }
    let (plan, _) = tf::plan_auto(model, &Scene::over_grid(request, &fine))?;
    let at_bins = tf::evaluate(plan.as_ref(), freqs_hz)?;
    let at_fine = tf::evaluate(plan.as_ref(), &fine)?;
    let (no, ni) = (at_bins.outputs.len(), at_bins.inputs.len());
    let smoothed_entries = (0..no * ni)
        .map(|e| {
            let samples: Vec<Complex64> = (0..fine.len())
                .map(|k| at_fine.get(k, e / ni, e % ni))
                .collect();
            smoothed(&samples, &usable, &kernel)
        })
        .collect();
    Ok((at_bins, smoothed_entries))
}
