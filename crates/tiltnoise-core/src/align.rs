//! Two uniformly sampled records on one time base: which samples of each overlap in time, and
//! the sub-sample offset left between their sample grids. Pure arithmetic on sample rates,
//! lengths and start times (instants, read from the files' text by `tiltnoise-io`); reads no
//! file.
//!
//! # Time of a sample
//!
//! Sample `k` of a record is at `start + k / sample_rate_hz`, `start` being the record's
//! `start_time` (the instant of sample 0). When **neither** record states a start time, both are taken to
//! start together; when only one does, the same assumption is made. [`Alignment::basis`] and
//! [`Alignment::notes`] say which.
//!
//! # Pairing
//!
//! With `delta = start_b - start_a` and `dt = 1 / sample_rate_hz`, sample `j` of `b` is at the
//! time of sample `j + delta / dt` of `a`. The integer part `s = round(delta / dt)` pairs
//! `a[k]` with `b[k - s]`; the pair is `residual_offset_s = delta - s dt` apart
//! (`|residual| <= dt/2`), `b` being later when it is positive. A spectral estimate from the
//! pairs sees `b` advanced by the residual: `exp(+i w residual)` on `b` (time dependence
//! `exp(+i w t)`), which the caller removes from a transfer function if it matters.
//!
//! # Sample rates
//!
//! The rates must agree so well that the two grids drift apart by at most
//! [`MAX_DRIFT_SAMPLES`] of a sample over the overlap; otherwise the records have different
//! rates and one must be resampled first (nothing here resamples).

use jiff::Timestamp;

/// Largest drift between the two sample grids over the overlap, in samples, that still counts
/// as one sample rate: 1 % of a sample shifts the phase of the highest (Nyquist) frequency by
/// 1.8 degrees at the far end of the record, below the resolution of any phase estimate.
pub const MAX_DRIFT_SAMPLES: f64 = 0.01;

/// What the alignment needs to know of a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordClock<'a> {
    /// The record's name in messages (the file, with the option that named it).
    pub name: &'a str,
    /// Sample rate (Hz), finite and > 0.
    pub sample_rate_hz: f64,
    /// Number of samples.
    pub n_samples: usize,
    /// The instant of sample 0, if the record states one.
    pub start_time: Option<Timestamp>,
}

/// How the records' times were related.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TimeBasis {
    /// Both records state a start time; they are aligned by it.
    StartTimes,
    /// At most one states a start time; sample 0 of each is taken as simultaneous.
    AssumedSimultaneous,
}

/// The overlapping samples of two records `a` and `b` ([`align`]).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Alignment {
    /// First sample of `a` in the overlap.
    pub start_a: usize,
    /// First sample of `b` in the overlap (paired with `start_a`).
    pub start_b: usize,
    /// Number of paired samples.
    pub len: usize,
    /// Common sample rate (Hz): that of `a`.
    pub sample_rate_hz: f64,
    /// `start_b - start_a` of the records' start times (s); 0 when assumed simultaneous.
    pub start_offset_s: f64,
    /// Time of `b`'s sample minus that of `a`'s within each pair (s), `|.| <= dt/2`.
    pub residual_offset_s: f64,
    /// How the times were related.
    pub basis: TimeBasis,
    /// What was assumed or cut, for the outputs' provenance.
    pub notes: Vec<String>,
}

/// Records that cannot be paired.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AlignError {
    /// The sample rates differ.
    #[error(
        "{name_a} is sampled at {rate_a} Hz and {name_b} at {rate_b} Hz: the records must have \
         the same sample rate (their grids would drift by {drift:.3} samples over the overlap, \
         at most {max} allowed); resample one of them first"
    )]
    SampleRates {
        /// First record.
        name_a: String,
        /// Its rate (Hz).
        rate_a: f64,
        /// Second record.
        name_b: String,
        /// Its rate (Hz).
        rate_b: f64,
        /// Drift over the overlap (samples).
        drift: f64,
        /// [`MAX_DRIFT_SAMPLES`].
        max: f64,
    },
    /// No common stretch of at least two samples.
    #[error(
        "{name_a} (from {start_a}, {dur_a} s) and {name_b} (from {start_b}, {dur_b} s) do not \
         overlap in time: the records must share at least two samples' worth of time"
    )]
    NoOverlap {
        /// First record.
        name_a: String,
        /// Its start time as stated.
        start_a: String,
        /// Its duration (s).
        dur_a: f64,
        /// Second record.
        name_b: String,
        /// Its start time as stated.
        start_b: String,
        /// Its duration (s).
        dur_b: f64,
    },
    /// A sample rate that is not finite and positive.
    #[error("{name}: sample rate {rate} Hz is not allowed: must be finite and > 0")]
    SampleRate {
        /// The record.
        name: String,
        /// The rate given (Hz).
        rate: f64,
    },
}

/// Pairs the samples of `a` and `b` that overlap in time (module docs).
///
/// # Errors
///
/// [`AlignError`] naming the record(s): a rate that is not finite and positive, rates that
/// differ ([`MAX_DRIFT_SAMPLES`]), or no common stretch of at
/// least two samples.
pub fn align(a: &RecordClock<'_>, b: &RecordClock<'_>) -> Result<Alignment, AlignError> {
    for r in [a, b] {
        if !(r.sample_rate_hz.is_finite() && r.sample_rate_hz > 0.0) {
            return Err(AlignError::SampleRate {
                name: r.name.to_string(),
                rate: r.sample_rate_hz,
            });
        }
    }
    let mut notes = Vec::new();
    let (basis, delta) = match (a.start_time, b.start_time) {
        (Some(ta), Some(tb)) => (TimeBasis::StartTimes, tb.duration_since(ta).as_secs_f64()),
        (None, None) => {
            notes.push(format!(
                "neither {} nor {} states a start time: sample 0 of each is taken as \
                 simultaneous",
                a.name, b.name
            ));
            (TimeBasis::AssumedSimultaneous, 0.0)
        }
        (Some(_), None) | (None, Some(_)) => {
            let (with, without) = if a.start_time.is_some() {
                (a, b)
            } else {
                (b, a)
            };
            notes.push(format!(
                "{} states no start time ({} does): sample 0 of each is taken as simultaneous",
                without.name, with.name
            ));
            (TimeBasis::AssumedSimultaneous, 0.0)
        }
    };
    let fs = a.sample_rate_hz;
    let dt = 1.0 / fs;
    let shift = (delta * fs).round();
    let residual = delta - shift * dt;
    let (na, nb) = (a.n_samples as f64, b.n_samples as f64);
    let first = shift.max(0.0);
    let end = na.min(nb + shift);
    let len = end - first;
    // `len` is finite: sample counts and a rounded, finite shift.
    if len < 2.0 {
        let shown = |r: &RecordClock<'_>| {
            r.start_time
                .map_or_else(|| "an unstated start".to_string(), |t| t.to_string())
        };
        return Err(AlignError::NoOverlap {
            name_a: a.name.to_string(),
            start_a: shown(a),
            dur_a: na / fs,
            name_b: b.name.to_string(),
            start_b: shown(b),
            dur_b: nb / b.sample_rate_hz,
        });
    }
    let drift = (1.0 / a.sample_rate_hz - 1.0 / b.sample_rate_hz).abs() * fs * len;
    if drift.is_nan() || drift > MAX_DRIFT_SAMPLES {
        return Err(AlignError::SampleRates {
            name_a: a.name.to_string(),
            rate_a: a.sample_rate_hz,
            name_b: b.name.to_string(),
            rate_b: b.sample_rate_hz,
            drift,
            max: MAX_DRIFT_SAMPLES,
        });
    }
    let (start_a, start_b, len) = (first as usize, (first - shift) as usize, len as usize);
    for (r, start, n) in [(a, start_a, a.n_samples), (b, start_b, b.n_samples)] {
        let left_out = n - len;
        if left_out > 0 {
            notes.push(format!(
                "{}: {left_out} of {n} samples lie outside the common stretch and are left out \
                 (the overlap starts at its sample {start})",
                r.name
            ));
        }
    }
    if residual != 0.0 {
        notes.push(format!(
            "the sample grids are offset by {residual:e} s ({:.4} samples): {} is paired with \
             the nearest sample of {}",
            residual * fs,
            b.name,
            a.name
        ));
    }
    Ok(Alignment {
        start_a,
        start_b,
        len,
        sample_rate_hz: fs,
        start_offset_s: delta,
        residual_offset_s: residual,
        basis,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clock<'a>(name: &'a str, fs: f64, n: usize, start: Option<&str>) -> RecordClock<'a> {
        RecordClock {
            name,
            sample_rate_hz: fs,
            n_samples: n,
            start_time: start.map(|t| t.parse().unwrap()),
        }
    }

    #[test]
    fn start_times_pair_the_overlapping_samples() {
        // b starts 10.25 s after a, both at 4 Hz: b[0] pairs with a[41], 0 s residual.
        let a = clock("a", 4.0, 100, Some("2020-01-01T00:00:00Z"));
        let b = clock("b", 4.0, 100, Some("2020-01-01T00:00:10.25Z"));
        let al = align(&a, &b).unwrap();
        assert_eq!((al.start_a, al.start_b, al.len), (41, 0, 59));
        assert_eq!(al.residual_offset_s, 0.0);
        assert_eq!(al.basis, TimeBasis::StartTimes);
        // The other way round.
        let al = align(&b, &a).unwrap();
        assert_eq!((al.start_a, al.start_b, al.len), (0, 41, 59));
        // A sub-sample offset: 0.1 s at 4 Hz is 0.4 samples, paired with the nearest.
        let c = clock("c", 4.0, 100, Some("2020-01-01T00:00:00.1Z"));
        let al = align(&a, &c).unwrap();
        assert_eq!((al.start_a, al.start_b, al.len), (0, 0, 100));
        assert!((al.residual_offset_s - 0.1).abs() < 1e-12);
        assert!(al.notes.iter().any(|n| n.contains("offset by")));
    }

    #[test]
    fn without_start_times_both_start_together() {
        let a = clock("tilt t.h5", 1.0, 50, None);
        let b = clock("measured m.h5", 1.0, 80, Some("2020-01-01T00:00:00Z"));
        let al = align(&a, &b).unwrap();
        assert_eq!((al.start_a, al.start_b, al.len), (0, 0, 50));
        assert_eq!(al.basis, TimeBasis::AssumedSimultaneous);
        assert!(
            al.notes[0].contains("tilt t.h5 states no start time"),
            "{:?}",
            al.notes
        );
        assert!(
            al.notes[1].contains("measured m.h5: 30 of 80 samples"),
            "{:?}",
            al.notes
        );
    }

    #[test]
    fn refusals_name_the_records() {
        let a = clock("a", 1.0, 100, Some("2020-01-01T00:00:00Z"));
        let late = clock("b", 1.0, 100, Some("2020-01-01T00:01:38Z"));
        assert_eq!(align(&a, &late).unwrap().len, 2);
        let later = clock("b", 1.0, 100, Some("2020-01-01T00:01:39Z"));
        let e = align(&a, &later).unwrap_err().to_string();
        assert!(
            e.contains("do not overlap") && e.contains("00:01:39Z"),
            "{e}"
        );
        let fast = clock("b", 1.001, 100, Some("2020-01-01T00:00:00Z"));
        let e = align(&a, &fast).unwrap_err().to_string();
        assert!(e.contains("1.001 Hz") && e.contains("resample"), "{e}");
        // 1e-6 relative over 100 samples drifts 1e-4 samples: the same rate.
        let close = clock("b", 1.000001, 100, Some("2020-01-01T00:00:00Z"));
        assert!(align(&a, &close).is_ok());
        let zero = clock("b", 0.0, 100, None);
        assert!(matches!(
            align(&a, &zero),
            Err(AlignError::SampleRate { .. })
        ));
    }
}
