//! The Welch estimator: streaming accumulator and the one-shot `welch`, `csd`, `csd_matrix`.

use std::sync::Arc;

use num_complex::Complex64;
use realfft::{RealFftPlanner, RealToComplex};

use super::stats::{median_bias, median_in_place, pairwise_sum};
use super::window::hann_periodic;
use super::{Averaging, Detrend, SpectralError, WelchConfig};
use crate::cancel::Cancel;
use crate::limits::check_memory;

/// One-sided power spectral density of one series.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Bin frequencies ([`bin_freqs`]), `k = 0 ..= segment_len/2`, in Hz.
    pub freqs_hz: Vec<f64>,
    /// One-sided PSD in `U²/Hz` for an input in `U`.
    pub psd: Vec<f64>,
    /// Number of segments that were averaged.
    pub n_segments: usize,
}

impl Psd {
    /// Amplitude spectral density `sqrt(psd)`, in `U/√Hz`.
    pub fn asd(&self) -> Vec<f64> {
        self.psd.iter().map(|p| p.sqrt()).collect()
    }
}

/// One-sided cross spectral density of a pair of series, `conj(X)·Y` as `scipy.signal.csd(x, y)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Csd {
    /// Bin frequencies in Hz.
    pub freqs_hz: Vec<f64>,
    /// One-sided CSD in `U_x·U_y/Hz`.
    pub csd: Vec<Complex64>,
    /// Number of segments that were averaged.
    pub n_segments: usize,
}

/// Full one-sided cross spectral density matrix of `n_channels` series.
///
/// `data[(k * n_channels + i) * n_channels + j] = S_ij(f_k) = <conj(X_i) X_j>` in
/// `U_i·U_j/Hz`; for every `k` the `n_channels × n_channels` block is Hermitian and its
/// diagonal is the real, non-negative PSD of each channel.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossSpectra {
    /// Bin frequencies ([`bin_freqs`]), in Hz.
    pub freqs_hz: Vec<f64>,
    /// Number of channels (the matrix dimension).
    pub n_channels: usize,
    /// Row-major `[freq][i][j]` matrix entries.
    pub data: Vec<Complex64>,
    /// Number of segments that were averaged.
    pub n_segments: usize,
}

impl CrossSpectra {
    /// Number of frequency bins.
    pub fn n_freqs(&self) -> usize {
        self.freqs_hz.len()
    }

    /// `S_ij` at bin `k`. Panics if an index is out of range.
    pub fn get(&self, k: usize, i: usize, j: usize) -> Complex64 {
        let n = self.n_channels;
        assert!(
            i < n && j < n,
            "channel index ({i}, {j}) out of range for {n} channels"
        );
        self.data[(k * n + i) * n + j]
    }

    /// The `n_channels × n_channels` row-major matrix at bin `k`.
    pub fn matrix(&self, k: usize) -> &[Complex64] {
        let nn = self.n_channels * self.n_channels;
        &self.data[k * nn..(k + 1) * nn]
    }

    /// PSD of channel `i` (the real diagonal), in `U_i²/Hz`.
    pub fn psd(&self, i: usize) -> Vec<f64> {
        (0..self.n_freqs()).map(|k| self.get(k, i, i).re).collect()
    }

    /// CSD `S_ij` over all bins, as `scipy.signal.csd(x_i, x_j)`.
    pub fn csd(&self, i: usize, j: usize) -> Vec<Complex64> {
        (0..self.n_freqs()).map(|k| self.get(k, i, j)).collect()
    }
}

/// Streaming Welch estimator for one or more channels sampled together.
///
/// Feed chunks of any length with [`push`](Self::push) (one slice per channel) or
/// [`push_interleaved`](Self::push_interleaved) (frame-major samples), then call
/// [`finish`](Self::finish). Chunk boundaries do not matter: the result is bit-for-bit the same
/// as for one call with the whole series. Segments are processed as soon as they are complete.
///
/// With [`Averaging::Mean`] memory is constant. With [`Averaging::Median`] every segment's
/// spectrum (`n_channels × n_freqs` complex values) is kept until `finish`.
pub struct WelchAccumulator {
    cfg: WelchConfig,
    fs_hz: f64,
    n_channels: usize,
    n_freqs: usize,
    window: Vec<f64>,
    /// `1 / (fs_hz * sum(w²))`.
    scale: f64,
    fft: Arc<dyn RealToComplex<f64>>,
    fft_in: Vec<f64>,
    fft_scratch: Vec<Complex64>,
    /// Channel-major `[channel][segment_len]` samples of the segment being filled.
    segment: Vec<f64>,
    /// Samples of the current segment already present (same for all channels).
    filled: usize,
    /// Channel-major `[channel][n_freqs]` FFT of the last segment.
    spectra: Vec<Complex64>,
    /// Mean: running sums of `conj(X_i) X_j` over the upper triangle `j >= i`, pair by pair in
    /// row order ([`pair_index`]), each pair's real parts over the bins, then its imaginary
    /// parts: `[pair][re, im][freq]`, so that one pair's update is a pass over contiguous bins.
    sums: Vec<f64>,
    /// Median: `[segment][channel][freq]` all segment spectra.
    stored: Vec<Complex64>,
    /// Mean of projections ([`WelchAccumulator::with_projections`]) instead of the pair sums.
    projection: Option<Projection>,
    n_segments: usize,
    n_samples: usize,
    /// Polled before each segment.
    cancel: Cancel,
}

impl std::fmt::Debug for WelchAccumulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WelchAccumulator")
            .field("cfg", &self.cfg)
            .field("fs_hz", &self.fs_hz)
            .field("n_channels", &self.n_channels)
            .field("n_segments", &self.n_segments)
            .field("n_samples", &self.n_samples)
            .finish_non_exhaustive()
    }
}

impl WelchAccumulator {
    /// Plans the FFT and allocates all buffers for `n_channels` channels sampled at `fs_hz`.
    pub fn new(n_channels: usize, fs_hz: f64, cfg: &WelchConfig) -> Result<Self, SpectralError> {
        cfg.validate()?;
        if n_channels == 0 {
            return Err(SpectralError::NoChannels);
        }
        if !(fs_hz.is_finite() && fs_hz > 0.0) {
            return Err(SpectralError::InvalidSampleRate { fs_hz });
        }
        let len = cfg.segment_len;
        let n_freqs = cfg.n_freqs();
        let window = hann_periodic(len);
        let w2: Vec<f64> = window.iter().map(|w| w * w).collect();
        let scale = 1.0 / (fs_hz * pairwise_sum(&w2));
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(len);
        let fft_scratch = fft.make_scratch_vec();
        let sums = match cfg.averaging {
            Averaging::Mean => vec![0.0; 2 * n_freqs * n_pairs(n_channels)],
            Averaging::Median => Vec::new(),
        };
        Ok(Self {
            cfg: *cfg,
            fs_hz,
            n_channels,
            n_freqs,
            window,
            scale,
            fft,
            fft_in: vec![0.0; len],
            fft_scratch,
            segment: vec![0.0; n_channels * len],
            filled: 0,
            spectra: vec![Complex64::new(0.0, 0.0); n_channels * n_freqs],
            sums,
            stored: Vec::new(),
            projection: None,
            n_segments: 0,
            n_samples: 0,
            cancel: Cancel::never(),
        })
    }

    /// The accumulator of the PSDs of `n_outputs` combinations of the channels instead of their
    /// cross-spectra: output `o` at bin `k` is `Y_o = sum_c weights[(k * n_outputs + o) *
    /// n_channels + c] X_c`, and its mean `|Y_o|^2` over the segments, scaled as a PSD, is what
    /// [`WelchAccumulator::finish_projections_into`] returns. Equal, up to rounding, to
    /// `sum_ij conj(w_i) S_ij w_j` of the cross-spectral matrix `S` ([`WelchAccumulator::finish`])
    /// at bin `k`, at `n_outputs * n_channels` products per bin instead of the
    /// matrix's `n_channels (n_channels + 1) / 2` and a propagation: the cheaper road when only
    /// a few combinations of many channels are wanted, and never negative.
    ///
    /// # Panics
    ///
    /// If the averaging is not [`Averaging::Mean`] (a median of cross-spectra is not the median
    /// of a projection), or `weights` has not `n_freqs * n_outputs * n_channels` entries.
    pub fn with_projections(mut self, n_outputs: usize, weights: &[Complex64]) -> Self {
        assert_eq!(
            self.cfg.averaging,
            Averaging::Mean,
            "projections are averaged by their mean"
        );
        assert_eq!(
            weights.len(),
            self.n_freqs * n_outputs * self.n_channels,
            "one weight per bin, output and channel"
        );
        self.sums = Vec::new();
        self.projection = Some(Projection::new(
            n_outputs,
            self.n_channels,
            self.n_freqs,
            weights,
        ));
        self
    }

    /// The accumulator polling `cancel` before each segment: a push after the token is set
    /// returns [`SpectralError::Cancelled`].
    pub fn with_cancel(mut self, cancel: Cancel) -> Self {
        self.cancel = cancel;
        self
    }

    /// Number of channels.
    pub fn n_channels(&self) -> usize {
        self.n_channels
    }

    /// Samples per channel pushed so far.
    pub fn n_samples(&self) -> usize {
        self.n_samples
    }

    /// Complete segments processed so far.
    pub fn n_segments(&self) -> usize {
        self.n_segments
    }

    /// With [`Averaging::Median`], reserves room for `n_segments` more segment spectra so that
    /// pushing them does not reallocate. Does nothing for [`Averaging::Mean`].
    pub fn reserve_segments(&mut self, n_segments: usize) {
        if self.cfg.averaging == Averaging::Median {
            self.stored
                .reserve(n_segments * self.n_channels * self.n_freqs);
        }
    }

    /// Appends the next samples of every channel: `chunk[c]` continues channel `c`. All slices
    /// must have the same length (which may be anything, including 0).
    pub fn push(&mut self, chunk: &[&[f64]]) -> Result<(), SpectralError> {
        if chunk.len() != self.n_channels {
            return Err(SpectralError::ChannelCountMismatch {
                expected: self.n_channels,
                got: chunk.len(),
            });
        }
        let n = chunk[0].len();
        check_equal_lengths(chunk)?;
        let len = self.cfg.segment_len;
        self.feed(n, |segment, at, pos, take| {
            for (c, ch) in chunk.iter().enumerate() {
                let dst = c * len + at;
                segment[dst..dst + take].copy_from_slice(&ch[pos..pos + take]);
            }
        })
    }

    /// Appends frame-major samples: `frames[t * n_channels + c]` is sample `t` of channel `c`
    /// (e.g. a row-major `[time][channel]` array). The length must be a multiple of
    /// `n_channels`.
    pub fn push_interleaved(&mut self, frames: &[f64]) -> Result<(), SpectralError> {
        let nc = self.n_channels;
        if frames.len() % nc != 0 {
            return Err(SpectralError::InterleavedLength {
                len: frames.len(),
                n_channels: nc,
            });
        }
        let n = frames.len() / nc;
        let len = self.cfg.segment_len;
        self.feed(n, |segment, at, pos, take| {
            for t in 0..take {
                let frame = &frames[(pos + t) * nc..(pos + t + 1) * nc];
                for (c, &v) in frame.iter().enumerate() {
                    segment[c * len + at + t] = v;
                }
            }
        })
    }

    /// Takes the next `n` samples of every channel into the segment buffer, processing each
    /// segment as it fills. `copy(segment, at, pos, take)` copies samples `pos .. pos + take`
    /// of every channel `c` to `segment[c * segment_len + at ..][..take]`.
    fn feed(
        &mut self,
        n: usize,
        mut copy: impl FnMut(&mut [f64], usize, usize, usize),
    ) -> Result<(), SpectralError> {
        let len = self.cfg.segment_len;
        let mut pos = 0;
        while pos < n {
            let take = (len - self.filled).min(n - pos);
            copy(&mut self.segment, self.filled, pos, take);
            self.filled += take;
            pos += take;
            if self.filled == len {
                self.cancel.check()?;
                self.process_segment()?;
            }
        }
        self.n_samples += n;
        Ok(())
    }

    /// Detrends, windows and transforms the full segment buffer, accumulates, and shifts the
    /// overlap to the front.
    fn process_segment(&mut self) -> Result<(), SpectralError> {
        let len = self.cfg.segment_len;
        let nf = self.n_freqs;
        let nc = self.n_channels;
        for c in 0..nc {
            let seg = &self.segment[c * len..(c + 1) * len];
            let mean = match self.cfg.detrend {
                // As scipy's detrend('constant'): np.mean = pairwise sum / n.
                Detrend::Constant => pairwise_sum(seg) / len as f64,
                Detrend::None => 0.0,
            };
            for ((dst, &x), &w) in self.fft_in.iter_mut().zip(seg).zip(&self.window) {
                *dst = (x - mean) * w;
            }
            self.fft
                .process_with_scratch(
                    &mut self.fft_in,
                    &mut self.spectra[c * nf..(c + 1) * nf],
                    &mut self.fft_scratch,
                )
                .map_err(|e| SpectralError::Fft {
                    detail: e.to_string(),
                })?;
        }
        match self.cfg.averaging {
            Averaging::Mean if self.projection.is_some() => {
                let p = self.projection.as_mut().expect("checked");
                p.push(&mut self.spectra, nc, nf);
            }
            Averaging::Mean => {
                let mut pairs = self.sums.chunks_exact_mut(2 * nf);
                for i in 0..nc {
                    let xi = &self.spectra[i * nf..(i + 1) * nf];
                    for j in i..nc {
                        let xj = &self.spectra[j * nf..(j + 1) * nf];
                        let (re, im) = pairs.next().expect("one sum per pair").split_at_mut(nf);
                        accumulate_pair(xi, xj, re, im);
                    }
                }
            }
            Averaging::Median => self.stored.extend_from_slice(&self.spectra),
        }
        self.n_segments += 1;
        let step = self.cfg.step();
        for c in 0..nc {
            self.segment[c * len..(c + 1) * len].copy_within(step.., 0);
        }
        self.filled = self.cfg.overlap;
        Ok(())
    }

    /// Averages the segments and returns the cross spectral density matrix. Samples after the
    /// last complete segment are ignored (as in scipy). Fails if not even one segment was
    /// complete.
    pub fn finish(self) -> Result<CrossSpectra, SpectralError> {
        let mut out = CrossSpectra {
            freqs_hz: Vec::new(),
            n_channels: self.n_channels,
            data: Vec::new(),
            n_segments: 0,
        };
        self.write_into(&mut out)?;
        Ok(out)
    }

    /// [`WelchAccumulator::finish`] into `out`, whose buffers are reused, and the accumulator
    /// emptied for the next record of the same channels (samples after the last complete
    /// segment are dropped): a caller that averages many consecutive records (the budget's
    /// hourly segments) allocates, and the system maps, the matrices once rather than per
    /// record.
    ///
    /// # Errors
    ///
    /// As [`WelchAccumulator::finish`]; the accumulator is emptied all the same.
    pub fn finish_into(&mut self, out: &mut CrossSpectra) -> Result<(), SpectralError> {
        let written = self.write_into(out);
        self.reset();
        written
    }

    /// Empties the accumulator for the next record of the same channels.
    fn reset(&mut self) {
        self.sums.fill(0.0);
        self.stored.clear();
        if let Some(p) = self.projection.as_mut() {
            p.sums.fill(0.0);
            p.held = 0;
        }
        self.n_segments = 0;
        self.n_samples = 0;
        self.filled = 0;
    }

    /// The PSDs of the projections ([`WelchAccumulator::with_projections`]) into `out`
    /// (`out[o][k]`, `n_freqs` bins from DC, in the squared unit of the weighted sum per Hz,
    /// one-sided), and the accumulator emptied for the next record as
    /// [`WelchAccumulator::finish_into`] does.
    ///
    /// # Errors
    ///
    /// [`SpectralError::SeriesTooShort`] if not even one segment was complete; the
    /// accumulator is emptied all the same.
    ///
    /// # Panics
    ///
    /// If the accumulator was not made with projections.
    pub fn finish_projections_into(
        &mut self,
        out: &mut Vec<Vec<f64>>,
    ) -> Result<(), SpectralError> {
        if let Some(p) = self.projection.as_mut() {
            p.flush(self.n_channels, self.n_freqs);
        }
        let written = self.write_projections(out);
        self.reset();
        written
    }

    fn write_projections(&self, out: &mut Vec<Vec<f64>>) -> Result<(), SpectralError> {
        let p = self
            .projection
            .as_ref()
            .expect("an accumulator made with projections");
        if self.n_segments == 0 {
            return Err(SpectralError::SeriesTooShort {
                n_samples: self.n_samples,
                segment_len: self.cfg.segment_len,
            });
        }
        let (nf, len, nseg) = (self.n_freqs, self.cfg.segment_len, self.n_segments);
        out.resize(p.n_outputs, Vec::new());
        for (o, psd) in out.iter_mut().enumerate() {
            psd.clear();
            psd.extend(
                p.sums[o * nf..(o + 1) * nf]
                    .iter()
                    .enumerate()
                    .map(|(k, &s)| {
                        // The one-sided doubling of every bin but DC and an even length's Nyquist.
                        let one_sided = if k == 0 || (len % 2 == 0 && k == nf - 1) {
                            1.0
                        } else {
                            2.0
                        };
                        s * (self.scale * one_sided / nseg as f64)
                    }),
            );
        }
        Ok(())
    }

    fn write_into(&self, out: &mut CrossSpectra) -> Result<(), SpectralError> {
        if self.n_segments == 0 {
            return Err(SpectralError::SeriesTooShort {
                n_samples: self.n_samples,
                segment_len: self.cfg.segment_len,
            });
        }
        let nc = self.n_channels;
        let nf = self.n_freqs;
        let len = self.cfg.segment_len;
        let nseg = self.n_segments;
        let one_sided = |k: usize| -> f64 {
            // Doubling of all bins but DC and, for even lengths, Nyquist.
            if k == 0 || (len % 2 == 0 && k == nf - 1) {
                1.0
            } else {
                2.0
            }
        };
        // Every entry is written below (the upper triangle, then its Hermitian completion).
        let data = &mut out.data;
        data.resize(nf * nc * nc, Complex64::new(0.0, 0.0));
        match self.cfg.averaging {
            Averaging::Mean => {
                for i in 0..nc {
                    for j in i..nc {
                        let p = pair_index(nc, i, j);
                        let (re, im) = self.sums[2 * p * nf..2 * (p + 1) * nf].split_at(nf);
                        for (k, (&r, &m)) in re.iter().zip(im).enumerate() {
                            let f = self.scale * one_sided(k) / nseg as f64;
                            data[(k * nc + i) * nc + j] = Complex64::new(r, m) * f;
                        }
                    }
                }
            }
            Averaging::Median => {
                let bias = median_bias(nseg);
                let mut re = vec![0.0; nseg];
                let mut im = vec![0.0; nseg];
                for k in 0..nf {
                    let f = self.scale * one_sided(k);
                    for i in 0..nc {
                        for j in i..nc {
                            for (s, (r, m)) in re.iter_mut().zip(im.iter_mut()).enumerate() {
                                let base = s * nc * nf;
                                let v = self.stored[base + i * nf + k].conj()
                                    * self.stored[base + j * nf + k]
                                    * f;
                                *r = v.re;
                                *m = v.im;
                            }
                            data[(k * nc + i) * nc + j] = Complex64::new(
                                median_in_place(&mut re) / bias,
                                median_in_place(&mut im) / bias,
                            );
                        }
                    }
                }
            }
        }
        // Hermitian completion (exact: conj(X_j) X_i is bitwise conj(conj(X_i) X_j)).
        for k in 0..nf {
            for i in 0..nc {
                for j in 0..i {
                    data[(k * nc + i) * nc + j] = data[(k * nc + j) * nc + i].conj();
                }
            }
        }
        out.freqs_hz.clear();
        out.freqs_hz.extend(bin_freqs(len, self.fs_hz, nf));
        out.n_channels = nc;
        out.n_segments = nseg;
        Ok(())
    }
}

/// Segments whose spectra a projection holds before it adds them: the weights, the largest
/// array of the work (`n_outputs * n_channels` complex numbers per bin), are then read once
/// for this many segments rather than once per segment.
const PROJECTION_BATCH: usize = 4;

/// Bins of one pass of a batch's projection: the outputs' sums of every held segment for
/// these bins stay in the first-level caches.
const PROJECTION_BINS: usize = 512;

/// Per-bin linear combinations of the channels and the running sums of their squared moduli.
struct Projection {
    n_outputs: usize,
    /// Planar weights, `[output][channel][freq]`: real parts, then imaginary parts.
    weights_re: Vec<f64>,
    weights_im: Vec<f64>,
    /// `[output][freq]`: sums over the segments of `|sum_c w_c X_c|^2`.
    sums: Vec<f64>,
    /// The spectra (`[channel][freq]`) of the segments held, the first `held` of them.
    batch: Vec<Vec<Complex64>>,
    held: usize,
    /// One pass's `sum_c w_c X_c` of every held segment, planar `[segment][bin]`.
    y_re: Vec<f64>,
    y_im: Vec<f64>,
}

impl Projection {
    /// From weights `[freq][output][channel]`.
    fn new(n_outputs: usize, nc: usize, nf: usize, weights: &[Complex64]) -> Projection {
        let mut weights_re = vec![0.0; n_outputs * nc * nf];
        let mut weights_im = vec![0.0; n_outputs * nc * nf];
        for (k, w) in weights.chunks_exact(n_outputs * nc).enumerate() {
            for (oc, w) in w.iter().enumerate() {
                weights_re[oc * nf + k] = w.re;
                weights_im[oc * nf + k] = w.im;
            }
        }
        Projection {
            n_outputs,
            weights_re,
            weights_im,
            sums: vec![0.0; n_outputs * nf],
            batch: Vec::new(),
            held: 0,
            y_re: vec![0.0; PROJECTION_BATCH * PROJECTION_BINS],
            y_im: vec![0.0; PROJECTION_BATCH * PROJECTION_BINS],
        }
    }

    /// Holds one segment's channel-major `[channel][freq]` spectra, swapping `spectra` for an
    /// earlier buffer (the caller overwrites it), and adds the batch once it is full.
    fn push(&mut self, spectra: &mut Vec<Complex64>, nc: usize, nf: usize) {
        if self.batch.len() == self.held {
            self.batch
                .push(vec![Complex64::new(0.0, 0.0); spectra.len()]);
        }
        std::mem::swap(spectra, &mut self.batch[self.held]);
        self.held += 1;
        if self.held == PROJECTION_BATCH {
            self.flush(nc, nf);
        }
    }

    /// Adds the held segments' `|Y_o|^2`, segment after segment at every bin (the order of
    /// adding them one at a time): output by output, channel by channel over contiguous bins,
    /// with the complex product and sum written out as `Complex64` forms them (`w X = (w_r x_r
    /// - w_i x_i, w_r x_i + w_i x_r)`, summed from 0 in channel order).
    fn flush(&mut self, nc: usize, nf: usize) {
        let held = &self.batch[..self.held];
        let mut start = 0;
        while start < nf {
            let end = (start + PROJECTION_BINS).min(nf);
            let len = end - start;
            for o in 0..self.n_outputs {
                self.y_re.fill(0.0);
                self.y_im.fill(0.0);
                for c in 0..nc {
                    let at = (o * nc + c) * nf;
                    let wr = &self.weights_re[at + start..at + end];
                    let wi = &self.weights_im[at + start..at + end];
                    for (s, spectra) in held.iter().enumerate() {
                        let x = &spectra[c * nf + start..c * nf + end];
                        let yr = &mut self.y_re[s * len..(s + 1) * len];
                        let yi = &mut self.y_im[s * len..(s + 1) * len];
                        for ((((yr, yi), x), &a), &b) in
                            yr.iter_mut().zip(yi.iter_mut()).zip(x).zip(wr).zip(wi)
                        {
                            *yr += a * x.re - b * x.im;
                            *yi += a * x.im + b * x.re;
                        }
                    }
                }
                let sums = &mut self.sums[o * nf + start..o * nf + end];
                for s in 0..held.len() {
                    let yr = &self.y_re[s * len..(s + 1) * len];
                    let yi = &self.y_im[s * len..(s + 1) * len];
                    for ((sum, &r), &m) in sums.iter_mut().zip(yr).zip(yi) {
                        *sum += r * r + m * m;
                    }
                }
            }
            start = end;
        }
        self.held = 0;
    }
}

/// Number of pairs `(i, j)`, `j >= i`, of `n` channels: the upper triangle with its diagonal.
fn n_pairs(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Position of the pair `(i, j)`, `i <= j < n`, in the row order of the upper triangle.
fn pair_index(n: usize, i: usize, j: usize) -> usize {
    // Rows 0 .. i hold n, n - 1, ..., n - i + 1 pairs.
    i * n - i * i.saturating_sub(1) / 2 + (j - i)
}

/// `re[k] + i im[k] += conj(a[k]) b[k]` over the bins, rounded as `Complex64` arithmetic
/// rounds it (`conj(a) * b` then the sum), so that the planar sums are the complex ones bit for
/// bit; a loop over contiguous bins that the compiler vectorizes.
#[inline]
fn accumulate_pair(a: &[Complex64], b: &[Complex64], re: &mut [f64], im: &mut [f64]) {
    for (((a, b), r), m) in a.iter().zip(b).zip(re.iter_mut()).zip(im.iter_mut()) {
        let p = a.conj() * b;
        *r += p.re;
        *m += p.im;
    }
}

/// The first `n_bins` bin frequencies (Hz) of a segment of `segment_len` samples at `fs_hz`,
/// `k / (segment_len / fs_hz)`, rounded as NumPy's `rfftfreq(segment_len, 1 / fs_hz)` rounds them
/// (`k * (1 / (segment_len * (1 / fs_hz)))`), which `scipy.signal.welch` and `csd` return: so a
/// grid compared with scipy's or gwpy's is equal bit for bit, not within an ulp.
pub fn bin_freqs(segment_len: usize, fs_hz: f64, n_bins: usize) -> impl Iterator<Item = f64> {
    let df = 1.0 / (segment_len as f64 * (1.0 / fs_hz));
    (0..n_bins).map(move |k| k as f64 * df)
}

fn check_equal_lengths(channels: &[&[f64]]) -> Result<(), SpectralError> {
    let expected = channels.first().map_or(0, |c| c.len());
    for (channel, c) in channels.iter().enumerate().skip(1) {
        if c.len() != expected {
            return Err(SpectralError::ChannelLengthMismatch {
                channel,
                len: c.len(),
                expected,
            });
        }
    }
    Ok(())
}

/// Cross spectral density matrix of equally long `channels` sampled at `fs_hz`, entry `(i, j)`
/// equal to `scipy.signal.csd(channels[i], channels[j], fs_hz, window='hann', ...)` and the
/// diagonal to `scipy.signal.welch(channels[i], ...)`.
///
/// Errors: no channel, channels of different lengths, invalid configuration or sampling
/// frequency, series shorter than one segment.
pub fn csd_matrix(
    channels: &[&[f64]],
    fs_hz: f64,
    cfg: &WelchConfig,
) -> Result<CrossSpectra, SpectralError> {
    csd_matrix_cancellable(channels, fs_hz, cfg, &Cancel::never())
}

/// [`csd_matrix`] polling `cancel` before each segment.
///
/// Errors: those of [`csd_matrix`], and [`SpectralError::Cancelled`] once `cancel` is set.
pub fn csd_matrix_cancellable(
    channels: &[&[f64]],
    fs_hz: f64,
    cfg: &WelchConfig,
    cancel: &Cancel,
) -> Result<CrossSpectra, SpectralError> {
    if channels.is_empty() {
        return Err(SpectralError::NoChannels);
    }
    check_equal_lengths(channels)?;
    let n = channels[0].len();
    let n_segments = cfg.check_series_len(n)?;
    check_memory(
        || {
            format!(
                "median of {n_segments} Welch segments of {} samples (overlap {})",
                cfg.segment_len, cfg.overlap
            )
        },
        cfg.kept_bytes(n, channels.len()),
    )?;
    let mut acc = WelchAccumulator::new(channels.len(), fs_hz, cfg)?.with_cancel(cancel.clone());
    acc.reserve_segments(n_segments);
    acc.push(channels)?;
    acc.finish()
}

/// One-sided PSD of `x` sampled at `fs_hz`, as `scipy.signal.welch(x, fs_hz, window='hann',
/// nperseg, noverlap, detrend, scaling='density', average)`. In `U²/Hz` for `x` in `U`.
pub fn welch(x: &[f64], fs_hz: f64, cfg: &WelchConfig) -> Result<Psd, SpectralError> {
    let m = csd_matrix(&[x], fs_hz, cfg)?;
    Ok(Psd {
        psd: m.data.iter().map(|z| z.re).collect(),
        freqs_hz: m.freqs_hz,
        n_segments: m.n_segments,
    })
}

/// One-sided CSD `<conj(X) Y>` of `x` and `y` sampled at `fs_hz`, as
/// `scipy.signal.csd(x, y, fs_hz, window='hann', ...)`. Unlike scipy, `x` and `y` must have the
/// same length.
pub fn csd(x: &[f64], y: &[f64], fs_hz: f64, cfg: &WelchConfig) -> Result<Csd, SpectralError> {
    let m = csd_matrix(&[x, y], fs_hz, cfg)?;
    Ok(Csd {
        csd: m.csd(0, 1),
        freqs_hz: m.freqs_hz,
        n_segments: m.n_segments,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Linux only: elsewhere the memory available is unknown and the run would start.
    #[cfg(target_os = "linux")]
    #[test]
    fn a_median_beyond_any_memory_is_refused_before_allocating() {
        // 5e5 segments of 2.5e5 frequencies: 2 TB of spectra to keep.
        let x = vec![0.0; 1_000_000];
        let cfg = WelchConfig::new(500_000)
            .with_overlap(499_999)
            .with_averaging(Averaging::Median);
        match welch(&x, 1.0, &cfg) {
            Err(SpectralError::TooLarge(e)) => {
                let e = e.to_string();
                assert!(
                    e.starts_with("median of 500001 Welch segments of 500000"),
                    "{e}"
                );
            }
            other => panic!("{:?}", other.map(|p| p.n_segments)),
        }
    }

    fn series(n: usize, seed: u64) -> Vec<f64> {
        // Deterministic, non-trivial test signal (a cheap LCG plus a tone).
        let mut s = seed;
        (0..n)
            .map(|i| {
                s = s
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5 + (0.1 * i as f64).sin()
            })
            .collect()
    }

    #[test]
    fn chunked_pushes_equal_one_shot_bitwise() {
        let a = series(1000, 1);
        let b = series(1000, 2);
        for averaging in [Averaging::Mean, Averaging::Median] {
            let cfg = WelchConfig::new(64)
                .with_overlap(48)
                .with_averaging(averaging);
            let whole = csd_matrix(&[&a, &b], 10.0, &cfg).unwrap();
            let mut acc = WelchAccumulator::new(2, 10.0, &cfg).unwrap();
            let mut pos = 0;
            for (i, len) in [1usize, 0, 7, 63, 64, 65, 200, 3]
                .iter()
                .cycle()
                .enumerate()
            {
                if pos >= a.len() || i > 1000 {
                    break;
                }
                let end = (pos + len).min(a.len());
                acc.push(&[&a[pos..end], &b[pos..end]]).unwrap();
                pos = end;
            }
            assert_eq!(acc.n_samples(), 1000);
            assert_eq!(acc.n_segments(), cfg.n_segments(1000));
            let chunked = acc.finish().unwrap();
            assert_eq!(whole, chunked);

            let mut acc = WelchAccumulator::new(2, 10.0, &cfg).unwrap();
            let frames: Vec<f64> = a.iter().zip(&b).flat_map(|(&x, &y)| [x, y]).collect();
            acc.push_interleaved(&frames[..402]).unwrap();
            acc.push_interleaved(&frames[402..]).unwrap();
            assert_eq!(whole, acc.finish().unwrap());
        }
    }

    /// An accumulator emptied by `finish_into` and reused gives, record after record, what a
    /// fresh one gives (the partial segment left over is dropped), for both averagings.
    #[test]
    fn a_reused_accumulator_is_a_fresh_one() {
        let (a, b) = (series(1000, 5), series(1000, 6));
        for averaging in [Averaging::Mean, Averaging::Median] {
            let cfg = WelchConfig {
                averaging,
                ..WelchConfig::new(64)
            };
            let mut reused = WelchAccumulator::new(2, 4.0, &cfg).unwrap();
            let mut out = CrossSpectra {
                freqs_hz: Vec::new(),
                n_channels: 2,
                data: Vec::new(),
                n_segments: 0,
            };
            // Records of 300 samples: 8 segments of 64 with a step of 32 and 12 samples left.
            for record in [0..300, 300..600, 600..900] {
                let (x, y) = (&a[record.clone()], &b[record]);
                let mut fresh = WelchAccumulator::new(2, 4.0, &cfg).unwrap();
                fresh.push(&[x, y]).unwrap();
                reused.push(&[x, y]).unwrap();
                reused.finish_into(&mut out).unwrap();
                assert_eq!(out, fresh.finish().unwrap(), "{averaging:?}");
            }
            assert!(matches!(
                reused.finish_into(&mut out),
                Err(SpectralError::SeriesTooShort { n_samples: 0, .. })
            ));
        }
    }

    /// The accumulation walks the pairs in row order; `pair_index` must name the same slots.
    #[test]
    fn pairs_are_indexed_in_row_order() {
        for n in 1..8 {
            let mut next = 0;
            for i in 0..n {
                for j in i..n {
                    assert_eq!(pair_index(n, i, j), next, "({i}, {j}) of {n}");
                    next += 1;
                }
            }
            assert_eq!(next, n_pairs(n));
        }
    }

    /// The planar sums are the complex arithmetic's, bit for bit: six channels against the
    /// sums written out as `Complex64` operations, the way the estimator has always formed them.
    #[test]
    fn planar_sums_are_the_complex_sums_bitwise() {
        let chans: Vec<Vec<f64>> = (0..6).map(|c| series(900, 10 + c)).collect();
        let views: Vec<&[f64]> = chans.iter().map(Vec::as_slice).collect();
        let cfg = WelchConfig::new(128);
        let got = csd_matrix(&views, 3.0, &cfg).unwrap();
        // The same segments by hand: detrend, window, FFT, then complex sums per bin.
        let (len, nf, nc) = (128, 65, 6);
        let window = hann_periodic(len);
        let w2: Vec<f64> = window.iter().map(|w| w * w).collect();
        let scale = 1.0 / (3.0 * pairwise_sum(&w2));
        let fft = RealFftPlanner::<f64>::new().plan_fft_forward(len);
        let mut sums = vec![Complex64::new(0.0, 0.0); nf * nc * nc];
        let n_seg = cfg.n_segments(900);
        for s in 0..n_seg {
            let spectra: Vec<Vec<Complex64>> = chans
                .iter()
                .map(|x| {
                    let seg = &x[s * cfg.step()..s * cfg.step() + len];
                    let mean = pairwise_sum(seg) / len as f64;
                    let mut input: Vec<f64> = seg
                        .iter()
                        .zip(&window)
                        .map(|(v, w)| (v - mean) * w)
                        .collect();
                    let mut out = fft.make_output_vec();
                    fft.process(&mut input, &mut out).unwrap();
                    out
                })
                .collect();
            for k in 0..nf {
                for i in 0..nc {
                    for j in i..nc {
                        sums[(k * nc + i) * nc + j] += spectra[i][k].conj() * spectra[j][k];
                    }
                }
            }
        }
        for k in 0..nf {
            let f = scale * if k == 0 || k == nf - 1 { 1.0 } else { 2.0 } / n_seg as f64;
            for i in 0..nc {
                for j in i..nc {
                    let want = sums[(k * nc + i) * nc + j] * f;
                    assert_eq!(got.get(k, i, j), want, "bin {k}, ({i}, {j})");
                    assert_eq!(got.get(k, j, i), want.conj(), "bin {k}, ({j}, {i})");
                }
            }
        }
    }

    /// A projection on one channel (weight 1) is that channel's PSD bit for bit (the same
    /// products, sums and scaling), and a reused projecting accumulator is a fresh one; a
    /// combination of two channels is `w^H S w` of their matrix to rounding.
    #[test]
    fn projections_are_the_matrix_seen_through_the_weights() {
        let (a, b) = (series(700, 21), series(700, 22));
        let cfg = WelchConfig::new(64);
        let m = csd_matrix(&[&a, &b], 5.0, &cfg).unwrap();
        let nf = m.n_freqs();
        let (one, zero) = (Complex64::new(1.0, 0.0), Complex64::new(0.0, 0.0));
        let w2 = Complex64::new(0.3, -1.7);
        let weights: Vec<Complex64> = (0..nf).flat_map(|_| [zero, one, one, w2]).collect();
        let mut acc = WelchAccumulator::new(2, 5.0, &cfg)
            .unwrap()
            .with_projections(2, &weights);
        let mut out = Vec::new();
        for _ in 0..2 {
            acc.push(&[&a, &b]).unwrap();
            acc.finish_projections_into(&mut out).unwrap();
            assert_eq!(out[0], m.psd(1));
            for (k, &got) in out[1].iter().enumerate() {
                let s = m.matrix(k);
                let want = (s[0] + w2.conj() * s[2] * one + s[1] * w2 + w2.norm_sqr() * s[3]).re;
                let bound = (m.psd(0)[k].sqrt() + w2.norm() * m.psd(1)[k].sqrt()).powi(2);
                // The rounding bound of the integration tests' `PROJECTION_C`: 8 eps per unit
                // of n^2 + n_segments.
                let gamma = 8.0 * (4.0 + m.n_segments as f64) * f64::EPSILON;
                assert!((got - want).abs() <= gamma * bound, "bin {k}");
            }
        }
        assert!(matches!(
            acc.finish_projections_into(&mut out),
            Err(SpectralError::SeriesTooShort { n_samples: 0, .. })
        ));
    }

    #[test]
    fn welch_and_csd_are_views_of_the_matrix() {
        let a = series(500, 3);
        let b = series(500, 4);
        let cfg = WelchConfig::new(50);
        let m = csd_matrix(&[&a, &b], 2.0, &cfg).unwrap();
        assert_eq!(welch(&a, 2.0, &cfg).unwrap().psd, m.psd(0));
        assert_eq!(welch(&b, 2.0, &cfg).unwrap().psd, m.psd(1));
        let c = csd(&a, &b, 2.0, &cfg).unwrap();
        assert_eq!(c.csd, m.csd(0, 1));
        assert_eq!(c.freqs_hz.len(), 26);
        assert_eq!(c.freqs_hz[25], 1.0);
        assert_eq!(c.n_segments, (500 - 25) / 25);
    }

    #[test]
    fn accumulator_errors() {
        let cfg = WelchConfig::new(16);
        assert_eq!(
            WelchAccumulator::new(0, 1.0, &cfg).unwrap_err(),
            SpectralError::NoChannels
        );
        assert!(matches!(
            WelchAccumulator::new(1, 0.0, &cfg).unwrap_err(),
            SpectralError::InvalidSampleRate { .. }
        ));
        assert!(matches!(
            WelchAccumulator::new(1, f64::NAN, &cfg).unwrap_err(),
            SpectralError::InvalidSampleRate { .. }
        ));
        let mut acc = WelchAccumulator::new(2, 1.0, &cfg).unwrap();
        assert_eq!(
            acc.push(&[&[1.0]]).unwrap_err(),
            SpectralError::ChannelCountMismatch {
                expected: 2,
                got: 1
            }
        );
        assert_eq!(
            acc.push_interleaved(&[1.0, 2.0, 3.0]).unwrap_err(),
            SpectralError::InterleavedLength {
                len: 3,
                n_channels: 2
            }
        );
        acc.push(&[&[0.0; 15], &[0.0; 15]]).unwrap();
        assert_eq!(
            acc.finish().unwrap_err(),
            SpectralError::SeriesTooShort {
                n_samples: 15,
                segment_len: 16
            }
        );
    }

    #[test]
    fn median_of_nan_segment_is_nan() {
        let mut a = series(256, 5);
        a[10] = f64::NAN;
        let cfg = WelchConfig::new(32).with_averaging(Averaging::Median);
        let p = welch(&a, 1.0, &cfg).unwrap();
        assert!(p.psd.iter().all(|v| v.is_nan()));
        let p = welch(&a, 1.0, &WelchConfig::new(32)).unwrap();
        assert!(p.psd.iter().all(|v| v.is_nan()));
    }
}
