//! Two sampled records on one time base: the tilt record (the witness) and the measured record
//! of the observables, aligned by their start times to the nearest sample, the remaining
//! fraction of a sample kept as a known part of the delay.

use super::SubtractError;
use crate::error::Num;

/// Most accumulated timing error allowed between two sample rates over the longer record, in
/// samples: rates that differ by more are different rates, and `subtract` does not resample.
pub const MAX_RATE_DRIFT_SAMPLES: f64 = 0.01;

/// An instant in UTC: whole seconds since 1970-01-01T00:00:00Z and the fraction of a second,
/// kept apart so that differences of start times a few seconds apart are exact to the
/// fraction's precision.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartTime {
    /// Whole seconds since the Unix epoch (leap seconds not counted, as POSIX time).
    pub unix_s: i64,
    /// Fraction of a second, `0 <= frac_s < 1`.
    pub frac_s: f64,
}

impl StartTime {
    /// `self - other` (s).
    pub fn seconds_after(&self, other: &StartTime) -> f64 {
        (self.unix_s - other.unix_s) as f64 + (self.frac_s - other.frac_s)
    }
}

/// Where the two records overlap, in samples of each.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Alignment {
    /// Sample rate of both records (Hz): the tilt record's.
    pub fs_hz: f64,
    /// First sample of the overlap in the tilt record.
    pub witness_first: usize,
    /// First sample of the overlap in the measured record.
    pub measured_first: usize,
    /// Samples in the overlap.
    pub len: usize,
    /// Time of a measured sample minus that of the tilt sample it is paired with (s),
    /// `|fraction_s| <= dt / 2`: a known part of the delay between the records.
    pub fraction_s: f64,
    /// Measured start minus tilt start (s) as the files state them; `None` when neither does.
    pub start_offset_s: Option<f64>,
    /// How the records were aligned, for the provenance.
    pub note: String,
}

/// Aligns a tilt record (`n_w` samples at `fs_w` Hz from `start_w`) with a measured record
/// (`n_m` at `fs_m` from `start_m`). Without start times in either file both are taken to
/// start together.
///
/// # Errors
///
/// [`SubtractError::RateMismatch`] when the rates differ by more than
/// [`MAX_RATE_DRIFT_SAMPLES`] over the longer record; [`SubtractError::OneStartTime`] when only
/// one file states its start; [`SubtractError::NoOverlap`] when the records share no sample.
pub fn align(
    (fs_w, n_w, start_w): (f64, usize, Option<StartTime>),
    (fs_m, n_m, start_m): (f64, usize, Option<StartTime>),
) -> Result<Alignment, SubtractError> {
    let longer = n_w.max(n_m) as f64;
    let drift = (fs_w - fs_m).abs() / fs_w * longer;
    if drift.is_nan() || drift > MAX_RATE_DRIFT_SAMPLES {
        return Err(SubtractError::RateMismatch {
            witness_hz: fs_w,
            measured_hz: fs_m,
            drift_samples: drift,
        });
    }
    let (offset_s, note) = match (start_w, start_m) {
        (Some(w), Some(m)) => {
            let d = m.seconds_after(&w);
            (
                Some(d),
                format!(
                    "aligned by start times: the measured record starts {} s after the tilt \
                     record",
                    Num(d)
                ),
            )
        }
        (None, None) => (
            None,
            "neither file states a start time: both records are taken to start together"
                .to_string(),
        ),
        (w, _) => {
            return Err(SubtractError::OneStartTime {
                stated_by: if w.is_some() { "tilt" } else { "measured" },
                missing_in: if w.is_some() { "measured" } else { "tilt" },
            })
        }
    };
    let dt = 1.0 / fs_w;
    let shift = offset_s.unwrap_or(0.0) * fs_w;
    let k = shift.round();
    // Overlap of tilt samples 0..n_w with measured samples shifted by k.
    let (w_lo, w_hi) = (0.0f64.max(k), (n_w as f64).min(n_m as f64 + k));
    if w_hi <= w_lo {
        return Err(SubtractError::NoOverlap {
            witness_s: (0.0, n_w as f64 * dt),
            measured_s: (shift * dt, (shift + n_m as f64) * dt),
        });
    }
    Ok(Alignment {
        fs_hz: fs_w,
        witness_first: w_lo as usize,
        measured_first: (w_lo - k) as usize,
        len: (w_hi - w_lo) as usize,
        fraction_s: (shift - k) * dt,
        start_offset_s: offset_s,
        note,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(s: i64, f: f64) -> Option<StartTime> {
        Some(StartTime {
            unix_s: s,
            frac_s: f,
        })
    }

    #[test]
    fn overlap_and_fraction() {
        // Measured starts 10.3 s later at 1 Hz: tilt samples 10.. pair with measured 0..,
        // measured times 0.3 s after the tilt times.
        let a = align((1.0, 100, at(1000, 0.0)), (1.0, 50, at(1010, 0.3))).unwrap();
        assert_eq!((a.witness_first, a.measured_first, a.len), (10, 0, 50));
        assert!((a.fraction_s - 0.3).abs() < 1e-12);
        // Measured starts earlier and ends inside the tilt record.
        let a = align((1.0, 100, at(1000, 0.5)), (1.0, 50, at(990, 0.0))).unwrap();
        assert_eq!((a.witness_first, a.measured_first, a.len), (0, 11, 39));
        assert!((a.fraction_s - 0.5).abs() < 1e-12);
        let a = align((1.0, 100, None), (1.0, 50, None)).unwrap();
        assert_eq!((a.witness_first, a.measured_first, a.len), (0, 0, 50));
        assert!(a.note.contains("start together"));
    }

    #[test]
    fn refusals() {
        assert!(matches!(
            align((1.0, 100, at(0, 0.0)), (1.0, 50, at(200, 0.0))),
            Err(SubtractError::NoOverlap { .. })
        ));
        assert!(matches!(
            align((1.0, 100, at(0, 0.0)), (1.0, 50, None)),
            Err(SubtractError::OneStartTime { .. })
        ));
        assert!(matches!(
            align((1.0, 100, None), (10.0, 50, None)),
            Err(SubtractError::RateMismatch { .. })
        ));
        // 1e-5 relative over 1e4 samples: 0.1 sample, refused; 1e-7: 0.001, accepted.
        assert!(align((1.0, 10_000, None), (1.0 + 1e-5, 50, None)).is_err());
        assert!(align((1.0, 10_000, None), (1.0 + 1e-7, 50, None)).is_ok());
    }
}
