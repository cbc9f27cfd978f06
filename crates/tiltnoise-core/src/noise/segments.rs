//! Statistics of per-segment budgets (for example hourly): the median and a percentile band at
//! every frequency, because floor tilt changes through the day.

/// Median and percentile band of one term's PSD across segments, per frequency.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SegmentBand {
    /// The term whose PSD the band is of.
    pub term: super::TermKind,
    /// Lower percentile (e.g. 10).
    pub lower_pct: f64,
    /// Upper percentile (e.g. 90).
    pub upper_pct: f64,
    /// Median across segments, per frequency (same unit as the inputs).
    pub median: Vec<f64>,
    /// Lower percentile per frequency.
    pub lower: Vec<f64>,
    /// Upper percentile per frequency.
    pub upper: Vec<f64>,
    /// Number of segments.
    pub n_segments: usize,
}

/// Percentile `p` (0..=100) of `values` with linear interpolation between order statistics
/// (NumPy's default `method='linear'`). `values` is sorted in place. Panics if empty.
pub fn percentile(values: &mut [f64], p: f64) -> f64 {
    assert!(!values.is_empty(), "percentile of no values");
    values.sort_by(f64::total_cmp);
    percentile_of_sorted(values, p)
}

/// [`percentile`] of values already sorted by `f64::total_cmp`.
fn percentile_of_sorted(values: &[f64], p: f64) -> f64 {
    let pos = (p / 100.0).clamp(0.0, 1.0) * (values.len() - 1) as f64;
    let (lo, frac) = (pos.floor() as usize, pos - pos.floor());
    if lo + 1 < values.len() {
        values[lo] + (values[lo + 1] - values[lo]) * frac
    } else {
        values[lo]
    }
}

impl SegmentBand {
    /// Band of `per_segment[s][k]` (segment `s`, frequency `k`) at the given percentiles. The
    /// values may be stored as `f32` (converted exactly to `f64`); each frequency's column is
    /// copied and sorted once for all three statistics.
    pub fn new<T: Copy + Into<f64>>(
        term: super::TermKind,
        per_segment: &[Vec<T>],
        lower_pct: f64,
        upper_pct: f64,
    ) -> SegmentBand {
        let n_f = per_segment.first().map_or(0, Vec::len);
        let mut column = vec![0.0; per_segment.len()];
        let mut median = Vec::with_capacity(n_f);
        let mut lower = Vec::with_capacity(n_f);
        let mut upper = Vec::with_capacity(n_f);
        for k in 0..n_f {
            for (c, seg) in column.iter_mut().zip(per_segment) {
                *c = seg[k].into();
            }
            column.sort_by(f64::total_cmp);
            median.push(percentile_of_sorted(&column, 50.0));
            lower.push(percentile_of_sorted(&column, lower_pct));
            upper.push(percentile_of_sorted(&column, upper_pct));
        }
        SegmentBand {
            term,
            lower_pct,
            upper_pct,
            median,
            lower,
            upper,
            n_segments: per_segment.len(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentile_matches_numpy_linear_definition() {
        // numpy.percentile([1, 2, 3, 4], [0, 10, 50, 90, 100]) = [1, 1.3, 2.5, 3.7, 4]
        let v = [4.0, 1.0, 3.0, 2.0];
        let p = |q| percentile(&mut v.clone(), q);
        assert_eq!(p(0.0), 1.0);
        assert!((p(10.0) - 1.3).abs() < 4.0 * f64::EPSILON);
        assert_eq!(p(50.0), 2.5);
        assert!((p(90.0) - 3.7).abs() < 4.0 * f64::EPSILON);
        assert_eq!(p(100.0), 4.0);
    }

    #[test]
    fn band_orders_lower_median_upper() {
        let segs = vec![vec![1.0, 10.0], vec![3.0, 30.0], vec![2.0, 20.0]];
        let b = SegmentBand::new(super::super::TermKind::Tilt, &segs, 10.0, 90.0);
        assert_eq!(b.median, vec![2.0, 20.0]);
        assert!(b.lower[0] < b.median[0] && b.median[0] < b.upper[0]);
        assert_eq!(b.n_segments, 3);
    }
}
