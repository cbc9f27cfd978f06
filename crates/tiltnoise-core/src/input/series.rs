//! [`TiltSeries`] and the sample-level processing shared by the in-memory and the streaming
//! readers: gap detection and linear bridging, the compensated mean, and the trapezoidal
//! integrator. Both readers push the same values through the same code in the same order, so
//! their results are bit-identical whatever the chunking.

use super::error::InputError;
use super::{GapPolicy, Provenance, Quantity};
use crate::model::TiltAxis;
use std::path::Path;

/// A uniformly sampled tilt time series, converted to angle (rad) in the crate's sign
/// convention.
#[derive(Debug, Clone, PartialEq)]
pub struct TiltSeries {
    /// Sample rate (Hz), finite and > 0.
    pub sample_rate_hz: f64,
    /// The axes present, in canonical order (theta_t, eta_t, phi_t), at least one.
    pub axes: Vec<TiltAxis>,
    /// One channel per entry of `axes`, all of length [`TiltSeries::len`]; tilt angle `t` (rad).
    pub data: Vec<Vec<f64>>,
    /// Where it came from.
    pub provenance: Provenance,
}

impl TiltSeries {
    /// Number of samples per channel (at least 2 for anything returned by the readers).
    pub fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The channel of `axis` (rad), if present.
    pub fn channel(&self, axis: TiltAxis) -> Option<&[f64]> {
        self.axes
            .iter()
            .position(|&a| a == axis)
            .map(|i| self.data[i].as_slice())
    }

    /// Duration `(len - 1) / sample_rate_hz` (s) from the first to the last sample.
    pub fn duration_s(&self) -> f64 {
        self.len().saturating_sub(1) as f64 / self.sample_rate_hz
    }
}

/// An interior run of non-finite samples, bridged linearly from `a` at index `before` to `b` at
/// index `after` (the finite neighbours).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Gap {
    pub before: usize,
    pub after: usize,
    pub a: f64,
    pub b: f64,
}

impl Gap {
    /// The bridged value at index `k` (`before < k < after`).
    pub fn value(&self, k: usize) -> f64 {
        let frac = (k - self.before) as f64 / (self.after - self.before) as f64;
        self.a + (self.b - self.a) * frac
    }

    /// The gap containing `k` in a sorted, disjoint list.
    pub fn find(gaps: &[Gap], k: usize) -> Option<&Gap> {
        let i = gaps.partition_point(|g| g.after <= k);
        gaps.get(i).filter(|g| g.before < k && k < g.after)
    }
}

/// Neumaier-compensated running sum, for the mean of a rate channel.
#[derive(Debug, Clone, Copy, Default)]
pub struct MeanAcc {
    sum: f64,
    comp: f64,
    n: usize,
}

impl MeanAcc {
    pub fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.comp += (self.sum - t) + x;
        } else {
            self.comp += (x - t) + self.sum;
        }
        self.sum = t;
        self.n += 1;
    }

    pub fn mean(&self) -> f64 {
        (self.sum + self.comp) / self.n as f64
    }
}

/// Trapezoidal integrator of `rate - mean`, `theta[0] = 0`. `Copy` so that its state can be
/// checkpointed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Integrator {
    mean: f64,
    half_dt: f64,
    prev: f64,
    theta: f64,
    started: bool,
}

impl Integrator {
    pub fn new(mean: f64, sample_rate_hz: f64) -> Self {
        Integrator {
            mean,
            half_dt: 0.5 / sample_rate_hz,
            prev: 0.0,
            theta: 0.0,
            started: false,
        }
    }

    /// Integrates the next rate sample in place (it becomes the angle).
    pub fn step_in_place(&mut self, values: &mut [f64]) {
        for v in values {
            let r = *v - self.mean;
            if self.started {
                self.theta += (self.prev + r) * self.half_dt;
            } else {
                self.theta = 0.0;
                self.started = true;
            }
            self.prev = r;
            *v = self.theta;
        }
    }
}

/// Context for error messages about one channel.
#[derive(Debug, Clone, Copy)]
pub struct ChannelCtx<'a> {
    pub path: &'a Path,
    pub channel: &'a str,
    pub unit: &'static str,
}

impl ChannelCtx<'_> {
    pub fn non_finite(&self, index: usize, value: f64, line: Option<usize>) -> InputError {
        InputError::NonFinite {
            path: self.path.to_path_buf(),
            channel: self.channel.to_string(),
            index,
            value,
            unit: self.unit,
            line,
        }
    }

    fn edge_gap(&self, edge: &'static str, first: usize, last: usize, len: usize) -> InputError {
        InputError::EdgeGap {
            path: self.path.to_path_buf(),
            channel: self.channel.to_string(),
            edge,
            first,
            last,
            len,
            unit: self.unit,
        }
    }
}

/// Streams over one (signed) channel in order, in blocks of any size: validates finiteness
/// under [`GapPolicy::Reject`], records interior gaps under [`GapPolicy::Interpolate`], and
/// accumulates the mean of the gap-bridged values.
#[derive(Debug)]
pub struct GapScanner {
    policy: GapPolicy,
    len: usize,
    pos: usize,
    last_finite: Option<(usize, f64)>,
    gap_start: Option<usize>,
    gaps: Vec<Gap>,
    mean: MeanAcc,
}

impl GapScanner {
    /// A scanner for a channel of `len` samples (used in messages).
    pub fn new(policy: GapPolicy, len: usize) -> Self {
        GapScanner {
            policy,
            len,
            pos: 0,
            last_finite: None,
            gap_start: None,
            gaps: Vec::new(),
            mean: MeanAcc::default(),
        }
    }

    pub fn push(&mut self, block: &[f64], ctx: &ChannelCtx<'_>) -> Result<(), InputError> {
        for &v in block {
            let k = self.pos;
            self.pos += 1;
            if v.is_finite() {
                if let Some(start) = self.gap_start.take() {
                    let Some((before, a)) = self.last_finite else {
                        return Err(ctx.edge_gap("leading", start, k - 1, self.len));
                    };
                    let gap = Gap {
                        before,
                        after: k,
                        a,
                        b: v,
                    };
                    for j in before + 1..k {
                        self.mean.add(gap.value(j));
                    }
                    self.gaps.push(gap);
                }
                self.mean.add(v);
                self.last_finite = Some((k, v));
            } else {
                match self.policy {
                    GapPolicy::Reject => return Err(ctx.non_finite(k, v, None)),
                    GapPolicy::Interpolate => {
                        if self.gap_start.is_none() {
                            self.gap_start = Some(k);
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// Ends the scan: `(gaps, mean)`.
    pub fn finish(self, ctx: &ChannelCtx<'_>) -> Result<(Vec<Gap>, f64), InputError> {
        if let Some(start) = self.gap_start {
            return Err(match self.last_finite {
                Some(_) => ctx.edge_gap("trailing", start, self.pos - 1, self.len),
                None => ctx.edge_gap("leading", start, self.pos - 1, self.len),
            });
        }
        Ok((self.gaps, self.mean.mean()))
    }
}

/// Replaces the non-finite samples of `block` (whose first sample has absolute index `start`)
/// by their bridged values.
pub fn fill_gaps(
    block: &mut [f64],
    start: usize,
    gaps: &[Gap],
    ctx: &ChannelCtx<'_>,
) -> Result<(), InputError> {
    for (i, v) in block.iter_mut().enumerate() {
        if !v.is_finite() {
            let k = start + i;
            *v = Gap::find(gaps, k)
                .ok_or_else(|| ctx.non_finite(k, *v, None))?
                .value(k);
        }
    }
    Ok(())
}

/// In-memory processing of a whole signed channel: gaps (policy), then integration when the
/// quantity is a rate. Returns the number of bridged samples.
pub fn process_channel(
    data: &mut [f64],
    policy: GapPolicy,
    quantity: Quantity,
    sample_rate_hz: f64,
    ctx: &ChannelCtx<'_>,
) -> Result<usize, InputError> {
    let mut scan = GapScanner::new(policy, data.len());
    scan.push(data, ctx)?;
    let (gaps, mean) = scan.finish(ctx)?;
    fill_gaps(data, 0, &gaps, ctx)?;
    if quantity == Quantity::Rate {
        Integrator::new(mean, sample_rate_hz).step_in_place(data);
    }
    Ok(gaps.iter().map(|g| g.after - g.before - 1).sum())
}

/// Provenance note for bridged gaps.
pub fn gap_note(channel: &str, bridged: usize) -> String {
    format!("channel `{channel}`: {bridged} non-finite samples bridged by linear interpolation")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaps_found_and_bridged() {
        let ctx = ChannelCtx {
            path: Path::new("x.csv"),
            channel: "c",
            unit: "rad",
        };
        let mut d = vec![0.0, f64::NAN, f64::NAN, 3.0, 4.0, f64::INFINITY, 6.0];
        let n =
            process_channel(&mut d, GapPolicy::Interpolate, Quantity::Angle, 1.0, &ctx).unwrap();
        assert_eq!(n, 3);
        assert_eq!(d, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let mut lead = vec![f64::NAN, 1.0, 2.0];
        let e = process_channel(
            &mut lead,
            GapPolicy::Interpolate,
            Quantity::Angle,
            1.0,
            &ctx,
        )
        .unwrap_err();
        assert!(e.to_string().contains("leading"), "{e}");
        let mut trail = vec![1.0, 2.0, f64::NAN];
        let e = process_channel(
            &mut trail,
            GapPolicy::Interpolate,
            Quantity::Angle,
            1.0,
            &ctx,
        )
        .unwrap_err();
        assert!(e.to_string().contains("trailing"), "{e}");
        assert!(e.to_string().contains("2..=2"), "{e}");
    }

    #[test]
    fn integrator_trapezoid() {
        let mut v = vec![1.0, 3.0, 5.0];
        Integrator::new(3.0, 2.0).step_in_place(&mut v);
        // r = -2, 0, 2; dt/2 = 0.25
        assert_eq!(v, vec![0.0, -0.5, 0.0]);
    }
}
