//! [`SeriesSource`]: what the noise budget needs of a record of the floor's motion, so that it
//! can stream a long record from a file (`tiltnoise-io`'s HDF5 reader) or run on one held in
//! memory ([`TiltSeries`], read from a file or built from arrays a caller holds) without knowing
//! which. Only samples and what each channel measures: where they came from
//! ([`super::Provenance`]) is the caller's to record.

use super::error::InputError;
use super::motion::GroundChannel;
use super::TiltSeries;
use std::path::Path;

/// A record of the floor's motion read in sequential chunks, uniformly sampled: tilt channels
/// (angle `t` in rad or its rate in rad/s, in the convention of [`crate::model::tilt`]) and
/// translation channels (m, m/s or m/s^2), each described by [`SeriesSource::channels`]. A
/// consumer that needs displacements converts the spectra ([`super::GroundMap`]).
pub trait SeriesSource {
    /// Sample rate (Hz).
    fn sample_rate_hz(&self) -> f64;

    /// Number of samples per channel.
    fn len(&self) -> usize;

    /// Whether there are no samples.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The channels, in canonical input order (theta_t .. phi_t, x_t .. z_t), each input once;
    /// [`SeriesSource::read_chunk`] returns one vector per entry.
    fn channels(&self) -> Vec<GroundChannel>;

    /// Samples `start .. start + len` of every channel, in the SI unit of its quantity
    /// ([`GroundChannel::unit`]).
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

    fn len(&self) -> usize {
        TiltSeries::len(self)
    }

    fn channels(&self) -> Vec<GroundChannel> {
        TiltSeries::channels(self)
    }

    fn read_chunk(&mut self, start: usize, len: usize) -> Result<Vec<Vec<f64>>, InputError> {
        chunk_of(&self.channel_data(), &self.provenance.path, start, len)
    }
}

/// Samples `start .. start + len` of every channel of a record held in memory (`channels`,
/// all of one length), as [`SeriesSource::read_chunk`] returns them: the one rule of every
/// in-memory source.
///
/// # Errors
///
/// [`InputError::ChunkOutOfRange`] naming `path` if `start + len` exceeds the channels' length.
pub fn chunk_of(
    channels: &[&[f64]],
    path: &Path,
    start: usize,
    len: usize,
) -> Result<Vec<Vec<f64>>, InputError> {
    let available = channels.first().map_or(0, |c| c.len());
    if start.checked_add(len).is_none_or(|end| end > available) {
        return Err(InputError::ChunkOutOfRange {
            path: path.to_path_buf(),
            start,
            len,
            available,
        });
    }
    Ok(channels
        .iter()
        .map(|c| c[start..start + len].to_vec())
        .collect())
}
