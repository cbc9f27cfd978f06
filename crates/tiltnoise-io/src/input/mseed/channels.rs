//! The records of a miniSEED file merged into one uniformly sampled channel per SEED code:
//! records in time order, the sample rate checked, gaps filled with NaN (the `--gaps` policy
//! decides what becomes of them), overlaps accepted when their samples are identical.

use super::record::{iso8601, Record, Samples, NS_PER_S};
use tiltnoise_core::limits::MAX_SERIES_SAMPLES;

/// One channel of the file.
#[derive(Debug, Clone)]
pub(crate) struct Channel {
    /// `NET.STA.LOC.CHA`.
    pub id: String,
    pub sample_rate_hz: f64,
    /// Time of sample 0 (ns since 1970, UTC).
    pub start_ns: i64,
    /// The coarsest time resolution of its records (ns).
    pub time_resolution_ns: i64,
    /// Samples as stored (counts or floating point); NaN in gaps.
    pub data: Vec<f64>,
    /// Integer encodings (counts) rather than floating point.
    pub counts: bool,
    /// The encodings met, e.g. `FLOAT64`.
    pub encodings: Vec<&'static str>,
    pub records: usize,
    /// Gaps as half-open sample-index ranges.
    pub gaps: Vec<(usize, usize)>,
    /// Samples present in two records with identical values.
    pub overlapping: usize,
}

impl Channel {
    /// Nanoseconds per sample.
    pub fn period_ns(&self) -> f64 {
        NS_PER_S as f64 / self.sample_rate_hz
    }

    /// Time of sample `k` (ns), to the nearest ns.
    pub fn time_ns(&self, k: usize) -> i64 {
        self.start_ns + (k as f64 * self.period_ns()).round() as i64
    }

    /// ISO 8601 time of sample `k`.
    pub fn time(&self, k: usize) -> String {
        iso8601(self.time_ns(k))
    }
}

/// A record of a channel, with where it is in the file (for messages).
pub(crate) struct Placed {
    pub record: Record,
    pub index: usize,
    pub offset: u64,
}

/// An error about one record (`Some((index, offset))`) or a whole channel.
pub(crate) type Fault = (Option<(usize, u64)>, String);

/// Merges the records of one channel (all with the same id, in file order).
pub(crate) fn merge(id: &str, mut records: Vec<Placed>) -> Result<Channel, Fault> {
    records.sort_by_key(|p| p.record.start_ns);
    let first = &records[0];
    let at = |p: &Placed| Some((p.index, p.offset));
    let rate = first.record.sample_rate_hz;
    let counts = matches!(first.record.samples, Samples::Int(_));
    let mut ch = Channel {
        id: id.to_string(),
        sample_rate_hz: rate,
        start_ns: first.record.start_ns,
        time_resolution_ns: 0,
        data: Vec::new(),
        counts,
        encodings: Vec::new(),
        records: records.len(),
        gaps: Vec::new(),
        overlapping: 0,
    };
    for p in &records {
        let r = &p.record;
        if r.sample_rate_hz != rate {
            return Err((
                at(p),
                format!(
                    "channel {id}: sample rate {} Hz differs from the {rate} Hz of its first \
                     record (record {}); allowed: one sample rate per channel",
                    r.sample_rate_hz, first.index
                ),
            ));
        }
        if matches!(r.samples, Samples::Int(_)) != counts {
            return Err((
                at(p),
                format!(
                    "channel {id}: {} samples in a channel whose first record (record {}) is {}; \
                     allowed: integer (counts) or floating-point encodings, not both",
                    r.encoding, first.index, first.record.encoding
                ),
            ));
        }
        if !ch.encodings.contains(&r.encoding) {
            ch.encodings.push(r.encoding);
        }
        ch.time_resolution_ns = ch.time_resolution_ns.max(r.time_resolution_ns);
        let samples: Vec<f64> = match &r.samples {
            Samples::Int(v) => v.iter().map(|&x| f64::from(x)).collect(),
            Samples::Float(v) => v.clone(),
            Samples::Text => unreachable!("text records are not merged"),
        };
        // Where the record's first sample falls on the channel's grid.
        let offset_ns = (r.start_ns - ch.start_ns) as f64;
        let pos = offset_ns / ch.period_ns();
        let k = pos.round();
        let deviation_ns = (offset_ns - k * ch.period_ns()).abs();
        let tolerance_ns = ch.time_resolution_ns as f64;
        if deviation_ns > tolerance_ns {
            return Err((
                at(p),
                format!(
                    "channel {id}: the record starts at {}, {:.6} s off the sample grid of the \
                     channel (which starts at {}, {rate} Hz); allowed: at most the time \
                     resolution of the headers, {} s (a time tear cannot be read as one \
                     uniformly sampled series)",
                    iso8601(r.start_ns),
                    deviation_ns / NS_PER_S as f64,
                    iso8601(ch.start_ns),
                    tolerance_ns / NS_PER_S as f64
                ),
            ));
        }
        let end = k + samples.len() as f64;
        if end > MAX_SERIES_SAMPLES as f64 {
            return Err((
                at(p),
                format!(
                    "channel {id}: the record starting at {} ends {end} samples after the \
                     channel's start ({}); allowed: at most {MAX_SERIES_SAMPLES} samples per \
                     channel, gaps included (see docs/limits.md)",
                    iso8601(r.start_ns),
                    iso8601(ch.start_ns)
                ),
            ));
        }
        let k = k as usize;
        let next = ch.data.len();
        if k > next {
            ch.gaps.push((next, k));
            ch.data.resize(k, f64::NAN);
        }
        let overlap = next.saturating_sub(k).min(samples.len());
        for (j, &new) in samples[..overlap].iter().enumerate() {
            let old = ch.data[k + j];
            if !(old == new || (old.is_nan() && new.is_nan())) {
                return Err((
                    at(p),
                    format!(
                        "channel {id}: overlapping records differ at {} (sample index {}): \
                         {old:?} before, {new:?} in this record; allowed: overlaps whose \
                         samples are identical",
                        ch.time(k + j),
                        k + j
                    ),
                ));
            }
        }
        ch.overlapping += overlap;
        ch.data.extend_from_slice(&samples[overlap..]);
    }
    Ok(ch)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(start_s: i64, samples: Vec<f64>, index: usize) -> Placed {
        Placed {
            record: Record {
                id: "XX.S..LJE".to_string(),
                start_ns: start_s * NS_PER_S,
                time_resolution_ns: 100_000,
                sample_rate_hz: 1.0,
                encoding: "FLOAT64",
                samples: Samples::Float(samples),
                len: 512,
            },
            index,
            offset: 512 * index as u64,
        }
    }

    #[test]
    fn gap_and_identical_overlap() {
        let ch = merge(
            "XX.S..LJE",
            vec![
                rec(5, vec![5.0, 6.0], 2),
                rec(0, vec![0.0, 1.0, 2.0], 0),
                rec(2, vec![2.0, 3.0], 1),
            ],
        )
        .unwrap();
        let shown: Vec<String> = ch.data.iter().map(|v| format!("{v}")).collect();
        assert_eq!(shown, ["0", "1", "2", "3", "NaN", "5", "6"]);
        assert_eq!(ch.gaps, vec![(4, 5)]);
        assert_eq!(ch.overlapping, 1);
    }

    #[test]
    fn differing_overlap_and_rate_refused() {
        let e = merge(
            "XX.S..LJE",
            vec![rec(0, vec![0.0, 1.0], 0), rec(1, vec![1.5], 1)],
        )
        .unwrap_err();
        assert_eq!(e.0, Some((1, 512)));
        assert!(
            e.1.contains("overlapping records differ") && e.1.contains("1.0 before, 1.5"),
            "{}",
            e.1
        );
        let mut other = rec(2, vec![2.0], 1);
        other.record.sample_rate_hz = 2.0;
        let e = merge("XX.S..LJE", vec![rec(0, vec![0.0, 1.0], 0), other]).unwrap_err();
        assert!(
            e.1.contains("sample rate 2 Hz differs from the 1 Hz"),
            "{}",
            e.1
        );
    }

    #[test]
    fn off_grid_start_refused() {
        let mut r = rec(2, vec![2.0], 1);
        r.record.start_ns += 300_000; // 0.3 ms late: more than the 0.1 ms resolution
        let e = merge("XX.S..LJE", vec![rec(0, vec![0.0, 1.0], 0), r]).unwrap_err();
        assert!(e.1.contains("off the sample grid"), "{}", e.1);
    }
}
