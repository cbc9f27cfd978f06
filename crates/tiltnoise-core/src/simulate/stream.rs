//! Free motion in chunks: [`FreeMotion`] produces the record of [`super::simulate`] a chunk at a
//! time, so that a caller can write it out and accumulate its spectra in memory that does not
//! grow with the duration.
//!
//! The chunks are the same numbers as the one-shot result, bit for bit, whatever their length:
//! the propagation is the same sequence of exact rotations, and the readout noise of the `j`-th
//! noisy observable is the `j`-th block of `n` normals of stream 0 of the seed, as when the
//! whole record is held ([`super::simulate`] is itself built on this iterator). Each
//! observable's generator is positioned at its block once, by [`Rng::skip_gaussians`]
//! (`j n` raw draws, no transcendental function).
//!
//! [`MinMaxEnvelope`] keeps a bounded picture of a long series for a time-domain figure.

use super::{check_initial_state, InitialState, ModalPropagator, SimConfig, SimError};
use crate::error::Num;
use crate::limits::{check_count, LimitError, MAX_STREAMED_SIM_SAMPLES};
use crate::model::{Model, Observable};
use crate::rng::Rng;

/// One chunk of a record: samples `start .. start + len()` of every observable and, if asked
/// for, of the generalized coordinates.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SimChunk {
    /// Index of the chunk's first sample in the record (sample `i` is at `t = i dt`).
    pub start: usize,
    /// The seven observables in [`Observable::ALL`] order (m or rad), with readout noise
    /// where configured, each as long as the chunk.
    pub observables: [Vec<f64>; 7],
    /// Generalized coordinates per sample, crate coordinate order (rad, m; noiseless); empty
    /// unless the [`FreeMotion`] keeps them.
    pub q: Vec<[f64; 8]>,
}

impl SimChunk {
    /// Samples in the chunk.
    pub fn len(&self) -> usize {
        self.observables[0].len()
    }

    /// True when the chunk holds no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The chunk's samples of one observable.
    pub fn observable(&self, o: Observable) -> &[f64] {
        &self.observables[o.index()]
    }
}

/// White readout noise of one entry of [`SimConfig::readout_asd`]: its observable, its
/// per-sample standard deviation and its generator, positioned at the sample to come.
#[derive(Debug, Clone)]
struct ReadoutNoise {
    observable: usize,
    sigma: f64,
    rng: Rng,
}

/// The free motion of [`super::simulate`], sample by sample in chunks.
#[derive(Debug, Clone)]
pub struct FreeMotion {
    prop: ModalPropagator,
    /// Observables from modal coordinates: `P = C V` (7 x 8).
    p: [[f64; 8]; 7],
    noise: Vec<ReadoutNoise>,
    n_samples: usize,
    next: usize,
    keep_coordinates: bool,
}

/// Refuses a record of `n_samples` (a float: `floor(duration / dt)` may be beyond any integer)
/// over [`MAX_STREAMED_SIM_SAMPLES`]; `what` names the request in the message. The memory of a
/// streamed record does not depend on its length, so this is the only size check it needs.
pub fn check_streamed_samples<W: Into<crate::option_key::Message>>(
    what: impl Fn() -> W,
    n_samples: f64,
) -> Result<(), LimitError> {
    check_count(&what, n_samples, "samples", MAX_STREAMED_SIM_SAMPLES)
}

/// `floor(duration / dt)` of a valid configuration, at least 2 and at most `limit`.
pub(super) fn sample_count(cfg: &SimConfig, limit: usize) -> Result<usize, SimError> {
    let (dt_s, duration_s) = (cfg.dt_s, cfg.duration_s);
    if !(dt_s.is_finite() && dt_s > 0.0) {
        return Err(SimError::InvalidStep { dt_s });
    }
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(SimError::InvalidDuration { duration_s });
    }
    let n_samples = cfg.n_samples_f64();
    if n_samples.is_nan() || n_samples < 2.0 {
        return Err(SimError::TooFewSamples {
            duration_s,
            dt_s,
            n_samples,
        });
    }
    check_count(
        || format!("duration {} s at dt = {} s", Num(duration_s), Num(dt_s)),
        n_samples,
        "samples",
        limit,
    )?;
    Ok(n_samples as usize)
}

impl FreeMotion {
    /// The free motion from `init` sampled as `cfg` says (at most
    /// [`MAX_STREAMED_SIM_SAMPLES`] samples), keeping the generalized coordinates in the chunks
    /// when `keep_coordinates`. Refuses what [`super::simulate`] refuses, except that the
    /// record's length is not checked against memory (it is never held).
    pub fn new(
        model: &Model,
        init: &InitialState,
        cfg: &SimConfig,
        keep_coordinates: bool,
    ) -> Result<FreeMotion, SimError> {
        FreeMotion::with_limit(model, init, cfg, keep_coordinates, MAX_STREAMED_SIM_SAMPLES)
    }

    pub(super) fn with_limit(
        model: &Model,
        init: &InitialState,
        cfg: &SimConfig,
        keep_coordinates: bool,
        limit: usize,
    ) -> Result<FreeMotion, SimError> {
        let n_samples = sample_count(cfg, limit)?;
        for &(o, asd) in &cfg.readout_asd {
            if !(asd.is_finite() && asd >= 0.0) {
                return Err(SimError::InvalidReadout {
                    observable: o.name(),
                    asd,
                });
            }
        }
        check_initial_state(init)?;
        let prop = ModalPropagator::new(model, init, cfg.dt_s)?;
        let c = model.observation();
        let p: [[f64; 8]; 7] = std::array::from_fn(|o| {
            std::array::from_fn(|k| (0..8).map(|i| c[(o, i)] * prop.shapes[k][i]).sum())
        });
        let sigma_per_asd = (0.5 / cfg.dt_s).sqrt();
        let noise = cfg
            .readout_asd
            .iter()
            .filter(|(_, asd)| *asd != 0.0)
            .enumerate()
            .map(|(j, &(o, asd))| {
                let mut rng = Rng::stream(cfg.seed, 0);
                rng.skip_gaussians(j as u64 * n_samples as u64);
                ReadoutNoise {
                    observable: o.index(),
                    sigma: asd * sigma_per_asd,
                    rng,
                }
            })
            .collect();
        Ok(FreeMotion {
            prop,
            p,
            noise,
            n_samples,
            next: 0,
            keep_coordinates,
        })
    }

    /// Samples in the whole record.
    pub fn len(&self) -> usize {
        self.n_samples
    }

    /// True for a record without samples (never: at least 2 are required).
    pub fn is_empty(&self) -> bool {
        self.n_samples == 0
    }

    /// Samples produced so far.
    pub fn samples_done(&self) -> usize {
        self.next
    }

    /// The sampling step (s).
    pub fn dt_s(&self) -> f64 {
        self.prop.dt_s
    }

    /// Fills `chunk` with the next samples, at most `max_len` of them (at least one), reusing
    /// its buffers. Returns `false`, leaving `chunk` empty, once the record is complete.
    pub fn next_chunk(&mut self, max_len: usize, chunk: &mut SimChunk) -> bool {
        let len = max_len.max(1).min(self.n_samples - self.next);
        chunk.start = self.next;
        for o in &mut chunk.observables {
            o.clear();
        }
        chunk.q.clear();
        if len == 0 {
            return false;
        }
        for i in self.next..self.next + len {
            if i > 0 {
                self.prop.step();
            }
            let a = &self.prop.u;
            if self.keep_coordinates {
                chunk.q.push(self.prop.combine(a, 1.0));
            }
            for (row, series) in self.p.iter().zip(&mut chunk.observables) {
                let mut y = 0.0;
                for k in 0..8 {
                    y += row[k] * a[k];
                }
                series.push(y);
            }
        }
        for noise in &mut self.noise {
            for x in &mut chunk.observables[noise.observable] {
                *x += noise.sigma * noise.rng.gaussian();
            }
        }
        self.next += len;
        true
    }
}

/// A bounded picture of a long series for a figure: the minimum, then the maximum, of each
/// block of `block` consecutive samples, so that oscillations faster than a block keep their
/// envelope. With `block = 1` the series itself is kept.
#[derive(Debug, Clone, PartialEq)]
pub struct MinMaxEnvelope {
    block: usize,
    filled: usize,
    lo: f64,
    hi: f64,
    values: Vec<f64>,
}

impl MinMaxEnvelope {
    /// An envelope of a series of `n_samples` with at most about `2 * max_blocks` values: the
    /// series itself when it has at most `2 * max_blocks` samples.
    pub fn new(n_samples: usize, max_blocks: usize) -> MinMaxEnvelope {
        let max_blocks = max_blocks.max(1);
        let block = match n_samples <= 2 * max_blocks {
            true => 1,
            false => n_samples.div_ceil(max_blocks),
        };
        MinMaxEnvelope {
            block,
            filled: 0,
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
            values: Vec::new(),
        }
    }

    /// Samples per block (1: the series is kept as it is).
    pub fn block(&self) -> usize {
        self.block
    }

    /// Appends the next samples.
    pub fn push(&mut self, samples: &[f64]) {
        if self.block == 1 {
            self.values.extend_from_slice(samples);
            return;
        }
        for &x in samples {
            self.lo = self.lo.min(x);
            self.hi = self.hi.max(x);
            self.filled += 1;
            if self.filled == self.block {
                self.flush();
            }
        }
    }

    fn flush(&mut self) {
        if self.filled > 0 {
            self.values.push(self.lo);
            self.values.push(self.hi);
        }
        self.filled = 0;
        self.lo = f64::INFINITY;
        self.hi = f64::NEG_INFINITY;
    }

    /// The values and their spacing in samples (`block / 2` for an envelope, whose values
    /// alternate minimum and maximum, else 1).
    pub fn finish(mut self) -> (Vec<f64>, f64) {
        if self.block == 1 {
            return (self.values, 1.0);
        }
        self.flush();
        (self.values, self.block as f64 / 2.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_keeps_short_series_and_extremes_of_long_ones() {
        let mut e = MinMaxEnvelope::new(4, 2);
        e.push(&[1.0, 2.0]);
        e.push(&[3.0, 4.0]);
        assert_eq!(e.finish(), (vec![1.0, 2.0, 3.0, 4.0], 1.0));
        let x: Vec<f64> = (0..10).map(|i| ((i * 7) % 10) as f64).collect();
        let mut e = MinMaxEnvelope::new(10, 2);
        assert_eq!(e.block(), 5);
        e.push(&x[..3]);
        e.push(&x[3..]);
        // Blocks [0 7 4 1 8] and [5 2 9 6 3].
        assert_eq!(e.finish(), (vec![0.0, 8.0, 2.0, 9.0], 2.5));
    }
}
