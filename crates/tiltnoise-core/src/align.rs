//! Two uniformly sampled records on one time base: which samples of each overlap in time, and
//! the sub-sample offset left between their sample grids. Pure arithmetic on sample rates,
//! lengths and ISO 8601 start times; reads no file.
//!
//! # Time of a sample
//!
//! Sample `k` of a record is at `start + k / sample_rate_hz`, `start` being the record's
//! `start_time` (ISO 8601, the time of sample 0; a date alone is midnight, a time without zone
//! designator is taken as UTC). When **neither** record states a start time, both are taken to
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

use std::fmt;

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
    /// ISO 8601 time of sample 0, if the record states one.
    pub start_time: Option<&'a str>,
}

/// How the records' times were related.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeBasis {
    /// Both records state a start time; they are aligned by it.
    StartTimes,
    /// At most one states a start time; sample 0 of each is taken as simultaneous.
    AssumedSimultaneous,
}

/// The overlapping samples of two records `a` and `b` ([`align`]).
#[derive(Debug, Clone, PartialEq)]
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
    /// A start time that is not ISO 8601.
    #[error(
        "{name}: start time `{value}` is not allowed: must be ISO 8601, e.g. 2018-01-23T09:31:42Z"
    )]
    StartTime {
        /// The record.
        name: String,
        /// The value given.
        value: String,
    },
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

/// A point in time: whole days since 1970-01-01 and seconds into that day (UTC). Kept apart so
/// that the difference of two instants years from the epoch keeps sub-microsecond precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Instant {
    /// Days since 1970-01-01 (UTC).
    pub days: i64,
    /// Seconds since midnight UTC of that day (may fall outside `0..86400` after the zone
    /// offset is applied).
    pub seconds: f64,
    /// Whether the text had a zone designator (`Z` or an offset).
    pub zoned: bool,
}

impl Instant {
    /// `self - earlier` in seconds.
    pub fn seconds_since(&self, earlier: &Instant) -> f64 {
        (self.days - earlier.days) as f64 * 86_400.0 + (self.seconds - earlier.seconds)
    }
}

impl fmt::Display for Instant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "day {} + {} s", self.days, self.seconds)
    }
}

/// Parses the ISO 8601 subset the readers accept: `YYYY-MM-DD`, optionally `T` (or a space)
/// and `hh:mm`, `hh:mm:ss` or `hh:mm:ss.fff` (`,` also as decimal sign), optionally `Z` or a
/// UTC offset `+hh:mm`, `+hhmm`, `+hh` (or `-`). `None` for anything else, including
/// impossible dates. A leap second `:60` is the next minute's first second.
pub fn parse_iso8601(s: &str) -> Option<Instant> {
    fn num(s: &str, n: usize) -> Option<i64> {
        (s.len() == n && s.bytes().all(|b| b.is_ascii_digit()))
            .then(|| s.parse().ok())
            .flatten()
    }
    if !s.is_ascii() || s.len() < 10 || &s[4..5] != "-" || &s[7..8] != "-" {
        return None;
    }
    let (y, mo, d) = (num(&s[0..4], 4)?, num(&s[5..7], 2)?, num(&s[8..10], 2)?);
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let month_days = match mo {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => return None,
    };
    if d == 0 || d > month_days {
        return None;
    }
    let days = days_from_civil(y, mo, d);
    let rest = &s[10..];
    if rest.is_empty() {
        return Some(Instant {
            days,
            seconds: 0.0,
            zoned: false,
        });
    }
    let rest = rest.strip_prefix(['T', ' '])?;
    let (time, zone) = match rest.find(['Z', '+', '-']) {
        Some(i) => (&rest[..i], &rest[i..]),
        None => (rest, ""),
    };
    let offset_s = match zone {
        "" | "Z" => 0,
        z => {
            let sign = if z.starts_with('-') { -1 } else { 1 };
            let z = &z[1..];
            let (h, m) = match z.len() {
                2 => (num(z, 2)?, 0),
                4 => (num(&z[..2], 2)?, num(&z[2..], 2)?),
                5 if &z[2..3] == ":" => (num(&z[..2], 2)?, num(&z[3..], 2)?),
                _ => return None,
            };
            if h > 23 || m > 59 {
                return None;
            }
            sign * (h * 3600 + m * 60)
        }
    };
    let (hms, frac) = match time.split_once(['.', ',']) {
        Some((hms, frac)) => (hms, Some(frac)),
        None => (time, None),
    };
    let frac_s = match frac {
        None => 0.0,
        Some(f) if !f.is_empty() && f.bytes().all(|b| b.is_ascii_digit()) => {
            format!("0.{f}").parse::<f64>().ok()?
        }
        Some(_) => return None,
    };
    let parts: Vec<&str> = hms.split(':').collect();
    let (h, m, sec) = match parts.as_slice() {
        [h, m] if frac.is_none() => (num(h, 2)?, num(m, 2)?, 0),
        [h, m, sec] => (num(h, 2)?, num(m, 2)?, num(sec, 2)?),
        _ => return None,
    };
    if h > 23 || m > 59 || sec > 60 {
        return None;
    }
    let whole = h * 3600 + m * 60 + sec - offset_s;
    Some(Instant {
        days,
        seconds: whole as f64 + frac_s,
        zoned: !zone.is_empty(),
    })
}

/// Days from 1970-01-01 to the proleptic Gregorian date `y-m-d` (Hinnant's `days_from_civil`).
fn days_from_civil(y: i64, m: i64, d: i64) -> i64 {
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

/// Pairs the samples of `a` and `b` that overlap in time (module docs).
///
/// # Errors
///
/// [`AlignError`] naming the record(s): a rate that is not finite and positive, a start time
/// that is not ISO 8601, rates that differ ([`MAX_DRIFT_SAMPLES`]), or no common stretch of at
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
    let parse = |r: &RecordClock<'_>| -> Result<Option<Instant>, AlignError> {
        match r.start_time {
            None => Ok(None),
            Some(t) => parse_iso8601(t.trim())
                .map(Some)
                .ok_or_else(|| AlignError::StartTime {
                    name: r.name.to_string(),
                    value: t.to_string(),
                }),
        }
    };
    let (ta, tb) = (parse(a)?, parse(b)?);
    let mut notes = Vec::new();
    let (basis, delta) = match (ta, tb) {
        (Some(ta), Some(tb)) => {
            for (r, t) in [(a, ta), (b, tb)] {
                if !t.zoned {
                    notes.push(format!(
                        "{}: start time without zone designator, taken as UTC",
                        r.name
                    ));
                }
            }
            (TimeBasis::StartTimes, tb.seconds_since(&ta))
        }
        (None, None) => {
            notes.push(format!(
                "neither {} nor {} states a start time: sample 0 of each is taken as \
                 simultaneous",
                a.name, b.name
            ));
            (TimeBasis::AssumedSimultaneous, 0.0)
        }
        (Some(_), None) | (None, Some(_)) => {
            let (with, without) = if ta.is_some() { (a, b) } else { (b, a) };
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
        let shown = |r: &RecordClock<'_>| r.start_time.unwrap_or("an unstated start").to_string();
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

    fn clock<'a>(name: &'a str, fs: f64, n: usize, start: Option<&'a str>) -> RecordClock<'a> {
        RecordClock {
            name,
            sample_rate_hz: fs,
            n_samples: n,
            start_time: start,
        }
    }

    #[test]
    fn iso8601_instants() {
        let t = |s: &str| parse_iso8601(s).unwrap_or_else(|| panic!("{s}"));
        assert_eq!(t("1970-01-01").days, 0);
        assert_eq!(t("2000-03-01").days, 11_017);
        assert_eq!(t("2018-01-23T09:31:42Z").seconds, 34_302.0);
        // The same instant in three notations.
        let z = t("2024-03-19T23:00:00Z");
        for other in [
            "2024-03-20T00:00:00+01:00",
            "2024-03-20 00:00:00+0100",
            "2024-03-19T20:30-0230",
        ] {
            assert_eq!(t(other).seconds_since(&z), 0.0, "{other}");
        }
        assert_eq!(t("2018-01-23T09:31:42,25Z").seconds, 34_302.25);
        assert_eq!(
            t("2016-12-31T23:59:60Z").seconds_since(&t("2017-01-01T00:00:00Z")),
            0.0
        );
        assert!(!t("2018-01-23T09:31").zoned && t("2018-01-23T09:31Z").zoned);
        for bad in [
            "",
            "2018-1-23",
            "2019-02-29",
            "2018-13-01",
            "2018-01-23T25:00",
            "2018-01-23T09:31:42.Z",
            "2018-01-23T09",
            "2018-01-23T09:31+1",
            "2018-01-23X09:31",
        ] {
            assert!(parse_iso8601(bad).is_none(), "{bad}");
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
        let a = clock("--tilt t.h5", 1.0, 50, None);
        let b = clock("--measured m.h5", 1.0, 80, Some("2020-01-01"));
        let al = align(&a, &b).unwrap();
        assert_eq!((al.start_a, al.start_b, al.len), (0, 0, 50));
        assert_eq!(al.basis, TimeBasis::AssumedSimultaneous);
        assert!(
            al.notes[0].contains("--tilt t.h5 states no start time"),
            "{:?}",
            al.notes
        );
        assert!(
            al.notes[1].contains("--measured m.h5: 30 of 80 samples"),
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
        let bad = clock("b", 1.0, 100, Some("yesterday"));
        assert!(align(&a, &bad)
            .unwrap_err()
            .to_string()
            .contains("`yesterday`"));
        let zero = clock("b", 0.0, 100, None);
        assert!(matches!(
            align(&a, &zero),
            Err(AlignError::SampleRate { .. })
        ));
    }
}
