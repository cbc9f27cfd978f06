//! [`TiltSeries`] and the sample-level processing shared by the in-memory and the streaming
//! readers: gap detection and linear bridging. Both readers push the same values through the
//! same code in the same order, so their results are bit-identical whatever the chunking. A
//! rate stays a rate here: spectra convert it to angle ([`super::rate`]).

use super::error::InputError;
use super::motion::{GroundChannel, Sensors};
use super::{GapPolicy, Provenance, Quantity};
use crate::ground::GroundQuantity;
use crate::limits::SAMPLES;
use crate::model::{Input, TiltAxis, TranslationAxis};
use std::path::Path;

/// A uniformly sampled record of the floor's motion in the crate's conventions: tilt channels
/// (angle `t` in rad, or its rate `dt/dt` in rad/s, as [`TiltSeries::quantity`] says) and
/// translation channels (displacement, velocity or acceleration along the lab axes, each as its
/// unit says), all of one length and rate.
#[derive(Debug, Clone, PartialEq)]
pub struct TiltSeries {
    /// Sample rate (Hz), finite and > 0.
    pub sample_rate_hz: f64,
    /// The tilt axes present, in canonical order (theta_t, eta_t, phi_t); with `translations`,
    /// at least one channel in all.
    pub axes: Vec<TiltAxis>,
    /// One channel per entry of `axes`, all of length [`TiltSeries::len`]; tilt angle `t` (rad)
    /// or tilt rate (rad/s), see [`TiltSeries::quantity`].
    pub data: Vec<Vec<f64>>,
    /// The translation channels, in canonical order (x_t, y_t, z_t), each of length
    /// [`TiltSeries::len`].
    pub translations: Vec<TranslationChannel>,
    /// The channels whose sensors are declared other than the default (pendulum tiltmeters,
    /// translation channels already free of tilt; see [`super::motion`]).
    pub sensors: Sensors,
    /// Where it came from.
    pub provenance: Provenance,
}

/// A translation channel of a record: the floor's displacement (m), velocity (m/s) or
/// acceleration (m/s^2) along a lab axis, as its unit says.
#[derive(Debug, Clone, PartialEq)]
pub struct TranslationChannel {
    /// The lab axis.
    pub axis: TranslationAxis,
    /// What the samples are of the floor's displacement.
    pub quantity: GroundQuantity,
    /// The samples, in SI (m, m/s or m/s^2).
    pub data: Vec<f64>,
}

impl TiltSeries {
    /// Number of samples per channel (at least 2 for anything returned by the readers).
    pub fn len(&self) -> usize {
        self.data
            .first()
            .or(self.translations.first().map(|t| &t.data))
            .map_or(0, Vec::len)
    }

    /// Every channel as an input of the model, tilt first then translations: what
    /// [`super::SeriesSource::read_chunk`] returns one vector for, in that order.
    pub fn channels(&self) -> Vec<GroundChannel> {
        let quantity = self.quantity();
        let tilts = self.axes.iter().map(|&a| GroundChannel {
            sensing: self.sensors.sensing(Input::Tilt(a)),
            ..GroundChannel::tilt(a, quantity)
        });
        let translations = self.translations.iter().map(|t| GroundChannel {
            input: Input::Translation(t.axis),
            quantity: t.quantity,
            sensing: self.sensors.sensing(Input::Translation(t.axis)),
        });
        tilts.chain(translations).collect()
    }

    /// Every channel's samples, in the order of [`TiltSeries::channels`].
    pub fn channel_data(&self) -> Vec<&[f64]> {
        self.data
            .iter()
            .map(Vec::as_slice)
            .chain(self.translations.iter().map(|t| t.data.as_slice()))
            .collect()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The series as tilt angles (rad): unchanged for an angle; a rate integrated in the
    /// frequency domain ([`super::rate::integrate_rate_spectrally`]: exact up to Nyquist, zero
    /// mean), with a provenance note. For the commands that need angles in the time domain.
    /// Translation channels are left as they are ([`super::GroundMap::displacements`] turns
    /// every channel into its input's displacement).
    pub fn into_angle(mut self) -> TiltSeries {
        if self.quantity() == Quantity::Rate {
            for channel in &mut self.data {
                *channel = super::rate::integrate_rate_spectrally(channel, self.sample_rate_hz);
            }
            self.provenance.quantity = Quantity::Angle;
            // The reader's note on rates (spectra divided by w^2) no longer applies.
            self.provenance
                .notes
                .retain(|note| !note.starts_with("rate to angle"));
            self.provenance.notes.push(
                "rate integrated to angle in the frequency domain (R / (i 2 pi f) on every DFT \
                 bin of the whole record, exact up to Nyquist; the angle's mean is unknown and set \
                 to 0)"
                    .to_string(),
            );
        }
        self
    }

    /// Angle (rad) or rate (rad/s) samples: the quantity of the file's channels, kept as read.
    pub fn quantity(&self) -> Quantity {
        self.provenance.quantity
    }

    /// The channel of `axis` (rad or rad/s, [`TiltSeries::quantity`]), if present.
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
    /// The bridged value at index `k` (`before < k < after`). Between two allowed samples
    /// ([`SAMPLES`]) it is allowed too: where a bridge between samples of opposite signs
    /// crosses zero, a value smaller than [`SAMPLES`]' smallest magnitude is 0.
    pub fn value(&self, k: usize) -> f64 {
        let frac = (k - self.before) as f64 / (self.after - self.before) as f64;
        let v = self.a + (self.b - self.a) * frac;
        if v.abs() < SAMPLES.smallest {
            0.0
        } else {
            v
        }
    }

    /// The gap containing `k` in a sorted, disjoint list.
    pub fn find(gaps: &[Gap], k: usize) -> Option<&Gap> {
        let i = gaps.partition_point(|g| g.after <= k);
        gaps.get(i).filter(|g| g.before < k && k < g.after)
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
    /// Refuses a finite sample outside [`SAMPLES`] (NaN and infinities are gaps, for the gap
    /// policy to decide): [`InputError::OutOfRange`] naming the file, channel, index and value.
    pub fn check_sample(
        &self,
        index: usize,
        value: f64,
        line: Option<usize>,
    ) -> Result<(), InputError> {
        if !value.is_finite() || SAMPLES.admits(value) {
            return Ok(());
        }
        Err(InputError::OutOfRange {
            path: self.path.to_path_buf(),
            channel: self.channel.to_string(),
            index,
            value,
            unit: self.unit,
            line,
        })
    }

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

/// Streams over one (signed, scaled) channel in order, in blocks of any size: refuses a finite
/// sample outside [`SAMPLES`] under either policy, validates finiteness under
/// [`GapPolicy::Reject`] and records interior gaps under [`GapPolicy::Interpolate`] (a bridge
/// between two allowed samples stays within their magnitudes).
#[derive(Debug)]
pub struct GapScanner {
    policy: GapPolicy,
    len: usize,
    pos: usize,
    last_finite: Option<(usize, f64)>,
    gap_start: Option<usize>,
    gaps: Vec<Gap>,
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
        }
    }

    pub fn push(&mut self, block: &[f64], ctx: &ChannelCtx<'_>) -> Result<(), InputError> {
        for &v in block {
            let k = self.pos;
            self.pos += 1;
            if v.is_finite() {
                ctx.check_sample(k, v, None)?;
                if let Some(start) = self.gap_start.take() {
                    let Some((before, a)) = self.last_finite else {
                        return Err(ctx.edge_gap("leading", start, k - 1, self.len));
                    };
                    self.gaps.push(Gap {
                        before,
                        after: k,
                        a,
                        b: v,
                    });
                }
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

    /// Ends the scan: the interior gaps, in order.
    pub fn finish(self, ctx: &ChannelCtx<'_>) -> Result<Vec<Gap>, InputError> {
        if let Some(start) = self.gap_start {
            return Err(match self.last_finite {
                Some(_) => ctx.edge_gap("trailing", start, self.pos - 1, self.len),
                None => ctx.edge_gap("leading", start, self.pos - 1, self.len),
            });
        }
        Ok(self.gaps)
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

/// In-memory processing of a whole signed channel (angle or rate alike): samples outside
/// [`SAMPLES`] refused, non-finite samples refused or bridged, as `policy` says. Returns the
/// number of bridged samples.
pub fn process_channel(
    data: &mut [f64],
    policy: GapPolicy,
    ctx: &ChannelCtx<'_>,
) -> Result<usize, InputError> {
    let mut scan = GapScanner::new(policy, data.len());
    scan.push(data, ctx)?;
    let gaps = scan.finish(ctx)?;
    fill_gaps(data, 0, &gaps, ctx)?;
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
        let n = process_channel(&mut d, GapPolicy::Interpolate, &ctx).unwrap();
        assert_eq!(n, 3);
        assert_eq!(d, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let mut lead = vec![f64::NAN, 1.0, 2.0];
        let e = process_channel(&mut lead, GapPolicy::Interpolate, &ctx).unwrap_err();
        assert!(e.to_string().contains("leading"), "{e}");
        let mut trail = vec![1.0, 2.0, f64::NAN];
        let e = process_channel(&mut trail, GapPolicy::Interpolate, &ctx).unwrap_err();
        assert!(e.to_string().contains("trailing"), "{e}");
        assert!(e.to_string().contains("2..=2"), "{e}");
    }

    #[test]
    fn samples_outside_their_magnitudes_are_refused_under_either_policy() {
        let ctx = ChannelCtx {
            path: Path::new("x.csv"),
            channel: "c",
            unit: "rad",
        };
        for policy in [GapPolicy::Reject, GapPolicy::Interpolate] {
            for bad in [1e308, -1e41, 1e-310, -2e-41] {
                let mut d = vec![0.0, 1e-9, bad, 0.0];
                let e = process_channel(&mut d, policy, &ctx).unwrap_err();
                assert!(matches!(e, InputError::OutOfRange { index: 2, .. }), "{e}");
                let text = e.to_string();
                assert!(
                    text.contains("channel `c` sample index 2")
                        && text.contains(&crate::error::Num(bad).to_string())
                        && text.contains("from 1e-40 to 1e40 rad"),
                    "{text}"
                );
            }
            // Exact zeros are structural and stay.
            let mut zeros = vec![0.0; 8];
            assert_eq!(process_channel(&mut zeros, policy, &ctx).unwrap(), 0);
        }
        // A bridge across zero between the smallest samples stays within the magnitudes.
        let mut d = vec![1e-40, f64::NAN, f64::NAN, f64::NAN, -1e-40];
        process_channel(&mut d, GapPolicy::Interpolate, &ctx).unwrap();
        assert_eq!(d, [1e-40, 0.0, 0.0, 0.0, -1e-40]);
        assert!(d.iter().all(|&v| SAMPLES.admits(v)));
    }
}
