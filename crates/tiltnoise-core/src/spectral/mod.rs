//! Welch power and cross spectral densities, numerically matching `scipy.signal`.
//!
//! Pure numerics: no I/O, no plotting, no dependency on the rest of the crate.
//!
//! # What is computed
//!
//! For real input series sampled at `fs_hz`, cut into segments of `segment_len` samples that
//! overlap by `overlap` samples (`step = segment_len - overlap`), each segment is optionally
//! detrended (its mean removed, [`Detrend::Constant`]), multiplied by the periodic Hann window
//! `w` ([`hann_periodic`]) and transformed with a real FFT. Per segment and frequency bin `k`
//!
//! ```text
//! S_ij[k] = c_k * conj(X_i[k]) * X_j[k] / (fs_hz * sum(w^2))
//! ```
//!
//! with `c_k = 1` for DC and (even `segment_len` only) the Nyquist bin, `c_k = 2` otherwise. The
//! segment values are then averaged: arithmetic mean ([`Averaging::Mean`]) or median
//! ([`Averaging::Median`], real and imaginary parts separately, divided by scipy's median bias
//! `1 + sum_{i=1}^{(n-1)/2} (1/(2i+1) - 1/(2i))` for `n` segments).
//!
//! This is exactly `scipy.signal.welch` / `scipy.signal.csd` with `window='hann'`,
//! `nperseg=segment_len`, `noverlap=overlap`, `nfft=None`, `detrend='constant'` (or `False`),
//! `return_onesided=True`, `scaling='density'`, `average='mean'|'median'`; the integration tests
//! compare against fixtures produced by scipy to a relative 1e-10. The only intended
//! differences: scipy zero-pads series of unequal length and shortens `nperseg` when the series
//! is shorter than one segment, whereas this module returns a [`SpectralError`] in both cases.
//!
//! # Units and conventions
//!
//! * **One-sided power spectral density.** If the input is in unit `U`, the PSD is in `U²/Hz`
//!   and covers `0 ..= fs_hz/2`; its integral over those frequencies,
//!   `sum(psd) * df` with `df = fs_hz / segment_len`, is the (windowed, detrended) mean square
//!   of the signal. Gaussian white noise of variance `σ²` has a one-sided PSD of `2σ²/fs_hz`.
//! * **Amplitude spectral density** `ASD = sqrt(PSD)`, in `U/√Hz` ([`Psd::asd`]).
//! * **Cross spectra** are in `U_i·U_j/Hz` and follow scipy: `S_ij = conj(X_i)·X_j`, so
//!   `S_ji = conj(S_ij)` (the matrix at each frequency is Hermitian) and `S_ii` is the real,
//!   non-negative PSD of channel `i`. If `x_j` is `x_i` delayed by `τ`, `arg S_ij = -2π f τ`.
//! * **Frequencies** are `k fs_hz / segment_len` for `k = 0 ..= segment_len/2`, rounded as
//!   scipy rounds them ([`bin_freqs`]).
//! * The number of segments is `(n - overlap) / step` (integer division), as in scipy; the
//!   trailing `(n - overlap) % step` samples that do not complete a segment are ignored.
//!
//! # Statistical error
//!
//! [`band_dof`] gives the equivalent chi-squared degrees of freedom of a mean Welch PSD
//! averaged over adjacent bins (overlap and window correlations included), hence the relative
//! standard deviation `sqrt(2 / nu)` of a band average.
//!
//! # Memory and streaming
//!
//! [`WelchAccumulator`] is fed chunks of samples of any size and finalised with
//! [`WelchAccumulator::finish`]. The real FFT is planned once and all buffers are allocated at
//! construction, so no allocation happens per segment. With [`Averaging::Mean`] the memory is
//! constant: one segment of samples per channel plus one `n_channels² × n_freqs` complex
//! accumulator, whatever the length of the series. [`Averaging::Median`] has to keep every
//! segment's spectrum (`n_segments × n_channels × n_freqs` complex values, 16 bytes each) until
//! `finish`; memory then grows linearly with the series length.
//!
//! # Coherence and transfer functions
//!
//! [`coherence`] and [`multiple_input`] turn a [`CrossSpectra`] into ordinary and multiple
//! coherence, multiple-input transfer functions and residual PSDs (channels chosen as inputs and
//! outputs by the caller); [`confidence`] holds the statistics of their confidence intervals.
//!
//! Non-finite input samples propagate: a NaN makes the affected mean NaN and, as `np.median`
//! does, the affected median NaN.

pub mod confidence;
mod config;
mod cross;
mod dof;
mod stats;
mod welch;
mod window;

pub use config::{Averaging, Detrend, WelchConfig};
pub use cross::{coherence, multiple_input, MultipleInput, INPUT_RCOND_MIN};
pub use dof::band_dof;
pub use welch::{
    bin_freqs, csd, csd_matrix, csd_matrix_cancellable, welch, CrossSpectra, Csd, Psd,
    WelchAccumulator,
};
pub use window::hann_periodic;

/// Invalid Welch parameters or input series. Every variant names the offending lengths.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpectralError {
    /// The computation was cancelled ([`crate::cancel`]).
    #[error(transparent)]
    Cancelled(#[from] crate::cancel::Cancelled),
    /// `segment_len` is below 2 samples.
    #[error("Welch segment length of {segment_len} samples is too short: must be at least 2")]
    SegmentTooShort {
        /// The segment length given.
        segment_len: usize,
    },
    /// `overlap` is not smaller than `segment_len`.
    #[error(
        "Welch overlap of {overlap} samples must be smaller than the segment length of \
         {segment_len} samples"
    )]
    OverlapTooLarge {
        /// The overlap given, in samples.
        overlap: usize,
        /// The segment length, in samples.
        segment_len: usize,
    },
    /// The series does not contain a single full segment.
    #[error(
        "series of {n_samples} samples is shorter than one Welch segment of {segment_len} \
         samples"
    )]
    SeriesTooShort {
        /// Number of samples in the series (per channel).
        n_samples: usize,
        /// The segment length, in samples.
        segment_len: usize,
    },
    /// A channel has a different number of samples than channel 0.
    #[error("channel {channel} has {len} samples but channel 0 has {expected}: channels must have equal length")]
    ChannelLengthMismatch {
        /// Index of the offending channel.
        channel: usize,
        /// Its number of samples.
        len: usize,
        /// Number of samples of channel 0.
        expected: usize,
    },
    /// A chunk with a different number of channels than the accumulator was built for.
    #[error("expected {expected} channels, got {got}")]
    ChannelCountMismatch {
        /// Number of channels the accumulator was created with.
        expected: usize,
        /// Number of channels given.
        got: usize,
    },
    /// A median whose segment spectra do not fit into the memory available.
    #[error(transparent)]
    TooLarge(#[from] crate::limits::LimitError),
    /// No channel at all was given.
    #[error("at least one channel is needed for a spectral estimate")]
    NoChannels,
    /// An interleaved chunk whose length is not a multiple of the channel count.
    #[error("interleaved chunk of {len} values is not a multiple of {n_channels} channels")]
    InterleavedLength {
        /// Number of values in the chunk.
        len: usize,
        /// Number of channels.
        n_channels: usize,
    },
    /// The sampling frequency is not finite and positive.
    #[error("sampling frequency {fs_hz} Hz is not allowed: must be finite and > 0")]
    InvalidSampleRate {
        /// The sampling frequency given, in Hz.
        fs_hz: f64,
    },
    /// The FFT library rejected a buffer (an internal invariant was violated).
    #[error("internal FFT error: {detail}")]
    Fft {
        /// The FFT library's message.
        detail: String,
    },
}
