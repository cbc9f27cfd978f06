//! Linear y axes for the log-x charts of `chart` (phase in degrees, coherence from 0 to 1):
//! nice tick steps, ranges and labels in the original units. `chart` maps a linear panel onto a
//! logarithmic axis of `10^((y - y0) / (y1 - y0))` in `[1, 10]` and draws it with the log-log
//! machinery (clipping, decimation, legend placement) unchanged.

/// A nice tick step for `[lo, hi]`: the smallest of 1, 2 or 5 times a power of ten that
/// divides the span into at most 8 intervals.
pub(crate) fn nice_step(lo: f64, hi: f64) -> f64 {
    let span = (hi - lo).abs().max(f64::MIN_POSITIVE);
    let p = 10f64.powf((span / 8.0).log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|s| span / s <= 8.0)
        .unwrap_or(10.0 * p)
}

/// The automatic linear range of finite `values`: extended outwards to multiples of the tick
/// step (`step`, or [`nice_step`]); `(0, 1)` without data, `v -/+ 1` for a constant.
pub(crate) fn auto_range(values: impl Iterator<Item = f64>, step: Option<f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite()) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi <= lo {
        return (lo - 1.0, hi + 1.0);
    }
    let s = step
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| nice_step(lo, hi));
    ((lo / s).floor() * s, (hi / s).ceil() * s)
}

/// Tick values `k step` inside `[lo, hi]` and their labels (`-` as the typographic minus,
/// just enough decimals for the step).
pub(crate) fn ticks(lo: f64, hi: f64, step: Option<f64>) -> Vec<(f64, String)> {
    let s = step
        .filter(|s| s.is_finite() && *s > 0.0)
        .unwrap_or_else(|| nice_step(lo, hi));
    let decimals = (-(s.log10().floor())).max(0.0) as usize;
    let first = (lo / s - 1e-9).ceil() as i64;
    let last = (hi / s + 1e-9).floor() as i64;
    (first..=last)
        .map(|k| {
            let v = k as f64 * s;
            let text = format!("{:.*}", decimals, if v == 0.0 { 0.0 } else { v });
            (v, text.replace('-', "\u{2212}"))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps_and_labels() {
        assert_eq!(nice_step(0.0, 1.0), 0.2);
        assert_eq!(nice_step(-180.0, 180.0), 50.0);
        let t = ticks(0.0, 1.0, None);
        let labels: Vec<&str> = t.iter().map(|(_, l)| l.as_str()).collect();
        assert_eq!(labels, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        let t = ticks(-200.0, 100.0, Some(90.0));
        let labels: Vec<&str> = t.iter().map(|(_, l)| l.as_str()).collect();
        assert_eq!(labels, ["\u{2212}180", "\u{2212}90", "0", "90"]);
        assert_eq!(
            auto_range([-3.0, 170.0].into_iter(), Some(90.0)),
            (-90.0, 180.0)
        );
        assert_eq!(auto_range(std::iter::empty(), None), (0.0, 1.0));
    }
}
