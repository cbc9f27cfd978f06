//! [`SeriesSource`]: what the budget job needs of a tilt time series, so that it can stream a
//! long record from a file (`tiltnoise-io`'s HDF5 reader) or run on one held in memory
//! ([`TiltSeries`], or arrays handed over by the Python package) without knowing which. Only
//! samples: where they came from ([`super::Provenance`]) is the caller's to record.

use super::error::InputError;
use super::{Quantity, TiltSeries};
use crate::model::TiltAxis;

/// A tilt time series read in sequential chunks: tilt angle `t` (rad) or its rate (rad/s) in the
/// convention of [`crate::model::tilt`], one channel per axis, uniformly sampled. A consumer
/// that needs the angle converts the rate's spectra ([`super::rate`]).
pub trait SeriesSource {
    /// Sample rate (Hz).
    fn sample_rate_hz(&self) -> f64;

    /// Whether the samples are angles (rad) or rates (rad/s).
    fn quantity(&self) -> Quantity;

    /// Number of samples per channel.
    fn len(&self) -> usize;

    /// Whether there are no samples.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The axes, in canonical order; [`SeriesSource::read_chunk`] returns one vector per entry.
    fn axes(&self) -> &[TiltAxis];

    /// Samples `start .. start + len` of every axis, in rad or rad/s
    /// ([`SeriesSource::quantity`]).
    ///
    /// # Errors
    ///
    /// [`InputError::ChunkOutOfRange`] if `start + len > self.len()`, or the source's own
    /// read or validation error.
    fn read_chunk(&mut self, start: usize, len: usize) -> Result<Vec<Vec<f64>>, InputError>;
}

impl SeriesSource for TiltSeries {
    fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    fn quantity(&self) -> Quantity {
        TiltSeries::quantity(self)
    }

    fn len(&self) -> usize {
        TiltSeries::len(self)
    }

    fn axes(&self) -> &[TiltAxis] {
        &self.axes
    }

    fn read_chunk(&mut self, start: usize, len: usize) -> Result<Vec<Vec<f64>>, InputError> {
        let available = TiltSeries::len(self);
        if start.checked_add(len).is_none_or(|end| end > available) {
            return Err(InputError::ChunkOutOfRange {
                path: self.provenance.path.clone(),
                start,
                len,
                available,
            });
        }
        Ok(self
            .data
            .iter()
            .map(|c| c[start..start + len].to_vec())
            .collect())
    }
}
