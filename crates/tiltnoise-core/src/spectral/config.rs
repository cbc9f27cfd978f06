//! Parameters of a Welch estimate and their validation.

use super::SpectralError;

/// How the per-segment spectra are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Averaging {
    /// Arithmetic mean (scipy `average='mean'`). Streams in constant memory.
    #[default]
    Mean,
    /// Median with scipy's bias correction (`average='median'`); for complex cross spectra the
    /// median of the real and of the imaginary parts separately. Robust against glitches, but
    /// keeps every segment's spectrum in memory until the end.
    Median,
}

/// What is removed from each segment before windowing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Detrend {
    /// Subtract the segment mean (scipy `detrend='constant'`).
    #[default]
    Constant,
    /// Leave the segment as it is (scipy `detrend=False`).
    None,
}

/// Welch parameters: periodic Hann window of `segment_len` samples, `overlap` samples shared by
/// consecutive segments.
///
/// Build with [`WelchConfig::new`] (50 % overlap, mean, constant detrend) and adjust the public
/// fields or use the `with_*` methods. [`Default`] uses scipy's default `nperseg = 256`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WelchConfig {
    /// Samples per segment (`nperseg`); also the FFT length. Must be at least 2.
    pub segment_len: usize,
    /// Samples shared by consecutive segments (`noverlap`). Must be smaller than `segment_len`.
    pub overlap: usize,
    /// Mean or median averaging over segments.
    pub averaging: Averaging,
    /// Per-segment detrending.
    pub detrend: Detrend,
}

impl Default for WelchConfig {
    fn default() -> Self {
        Self::new(Self::DEFAULT_SEGMENT_LEN)
    }
}

impl WelchConfig {
    /// scipy's default `nperseg` for a string window.
    pub const DEFAULT_SEGMENT_LEN: usize = 256;

    /// `segment_len` samples per segment, 50 % overlap (`segment_len / 2`, rounded down as
    /// scipy does), mean averaging, constant detrend.
    pub fn new(segment_len: usize) -> Self {
        Self {
            segment_len,
            overlap: segment_len / 2,
            averaging: Averaging::Mean,
            detrend: Detrend::Constant,
        }
    }

    /// The same configuration with `overlap` samples of overlap.
    pub fn with_overlap(mut self, overlap: usize) -> Self {
        self.overlap = overlap;
        self
    }

    /// The same configuration with another averaging.
    pub fn with_averaging(mut self, averaging: Averaging) -> Self {
        self.averaging = averaging;
        self
    }

    /// The same configuration with another detrending.
    pub fn with_detrend(mut self, detrend: Detrend) -> Self {
        self.detrend = detrend;
        self
    }

    /// Checks `segment_len >= 2` and `overlap < segment_len`.
    pub fn validate(&self) -> Result<(), SpectralError> {
        if self.segment_len < 2 {
            return Err(SpectralError::SegmentTooShort {
                segment_len: self.segment_len,
            });
        }
        if self.overlap >= self.segment_len {
            return Err(SpectralError::OverlapTooLarge {
                overlap: self.overlap,
                segment_len: self.segment_len,
            });
        }
        Ok(())
    }

    /// Hop between segment starts, `segment_len - overlap` (0 for an invalid configuration).
    pub fn step(&self) -> usize {
        self.segment_len.saturating_sub(self.overlap)
    }

    /// Bytes a [`Averaging::Median`] keeps for a series of `n_samples` on `n_channels`
    /// channels: every segment's spectrum, 16 bytes per channel and frequency (saturating at
    /// `u64::MAX`); 0 for a mean, whose memory does not grow with the series.
    pub fn kept_bytes(&self, n_samples: usize, n_channels: usize) -> u64 {
        match self.averaging {
            Averaging::Mean => 0,
            Averaging::Median => crate::limits::planned_bytes(
                self.n_segments(n_samples),
                (self.n_freqs() as u64).saturating_mul(16 * n_channels as u64),
            ),
        }
    }

    /// Number of one-sided frequency bins, `segment_len / 2 + 1`.
    pub fn n_freqs(&self) -> usize {
        self.segment_len / 2 + 1
    }

    /// Number of full segments in a series of `n_samples`: `(n_samples - overlap) / step`, or 0
    /// if the series is shorter than one segment or the configuration is invalid.
    pub fn n_segments(&self, n_samples: usize) -> usize {
        if self.validate().is_err() || n_samples < self.segment_len {
            return 0;
        }
        (n_samples - self.overlap) / self.step()
    }

    /// Validates the configuration and that a series of `n_samples` holds at least one segment;
    /// returns the number of segments.
    pub fn check_series_len(&self, n_samples: usize) -> Result<usize, SpectralError> {
        self.validate()?;
        if n_samples < self.segment_len {
            return Err(SpectralError::SeriesTooShort {
                n_samples,
                segment_len: self.segment_len,
            });
        }
        Ok(self.n_segments(n_samples))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_median_keeps_every_segment_a_mean_nothing() {
        // Segments of 8 samples, step 4: 24 segments of 5 frequencies in 100 samples.
        let mean = WelchConfig::new(8);
        assert_eq!(mean.kept_bytes(100, 2), 0);
        let median = mean.with_averaging(Averaging::Median);
        assert_eq!(median.kept_bytes(100, 2), 24 * 5 * 2 * 16);
        let huge = WelchConfig::new(usize::MAX / 2).with_averaging(Averaging::Median);
        assert_eq!(huge.kept_bytes(usize::MAX, 3), u64::MAX);
    }

    #[test]
    fn defaults_are_scipy_defaults() {
        let c = WelchConfig::default();
        assert_eq!(c.segment_len, 256);
        assert_eq!(c.overlap, 128);
        assert_eq!(c.averaging, Averaging::Mean);
        assert_eq!(c.detrend, Detrend::Constant);
        assert_eq!(WelchConfig::new(63).overlap, 31);
    }

    #[test]
    fn segment_count_matches_scipy_formula() {
        let c = WelchConfig::new(100).with_overlap(75);
        assert_eq!(c.step(), 25);
        assert_eq!(c.n_segments(1024), (1024 - 75) / 25);
        assert_eq!(c.n_segments(100), 1);
        assert_eq!(c.n_segments(124), 1);
        assert_eq!(c.n_segments(125), 2);
        assert_eq!(c.n_segments(99), 0);
        assert_eq!(c.n_freqs(), 51);
        assert_eq!(WelchConfig::new(63).n_freqs(), 32);
    }

    #[test]
    fn validation_names_the_lengths() {
        assert_eq!(
            WelchConfig::new(1).validate(),
            Err(SpectralError::SegmentTooShort { segment_len: 1 })
        );
        let e = WelchConfig::new(64)
            .with_overlap(64)
            .validate()
            .unwrap_err();
        assert_eq!(
            e,
            SpectralError::OverlapTooLarge {
                overlap: 64,
                segment_len: 64
            }
        );
        let msg = e.to_string();
        assert!(msg.contains("64"), "{msg}");
        let e = WelchConfig::new(64).check_series_len(10).unwrap_err();
        assert_eq!(
            e,
            SpectralError::SeriesTooShort {
                n_samples: 10,
                segment_len: 64
            }
        );
        assert!(e.to_string().contains("10") && e.to_string().contains("64"));
        assert_eq!(WelchConfig::new(64).check_series_len(64), Ok(1));
    }
}
