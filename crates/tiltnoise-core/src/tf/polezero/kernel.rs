//! The pole-zero method's evaluation over a frequency grid: `f64` arithmetic on the plan's
//! product forms (built in the parent module), nothing else.
//!
//! The grid is cut into chunks of [`LANES`] (8) frequencies, one per lane of a [`Lanes`]
//! value (two AVX registers when the CPU has AVX, chosen at run time; a portable array
//! otherwise). In a chunk, each block forms its shared denominator `prod_k (lambda_k - s)` and
//! its reciprocal once per frequency, then each of its entries `gain prod_k (a_k + b_k s)`
//! times that reciprocal: the loops are over blocks, entries and factors, the lanes are
//! frequencies. The chunk's values go into a small buffer that stays in L1 cache and holds
//! the values no block writes (zeroed once, never written: each entry's first block stores
//! its value, later blocks add theirs); then the buffer goes to the output. Two outputs:
//!
//! * interleaved ([`Kernel::eval_grid`], the dense complex matrix, a point's values
//!   together): each lane's values are scattered into the buffer, which is copied in one
//!   sequential pass, with non-temporal stores for outputs larger than the cache
//!   ([`Destination::streams`]); one point alone ([`TransferFunction::eval_into`]) is written in
//!   place into the zeroed output;
//! * planar ([`Kernel::eval_planes`], a plane per value over the grid, the layout of
//!   `tf::evaluate`): a value's eight lanes are stored together with vector moves, and copied
//!   to its plane the same way.
//!
//! [`TransferFunction::eval_into`]: super::super::TransferFunction::eval_into
//!
//! Every lane does the same IEEE operations (multiplication, addition, subtraction, division;
//! no fused multiply-add, no reassociation) in the same order, so a value depends neither on
//! the chunk nor the lane it falls in, nor on the number of threads, nor on the CPU: AVX and
//! portable lanes give bit-identical results, and so do [`Kernel::eval_grid`] on a grid and
//! on each of its points alone, and [`Kernel::eval_planes`].
//!
//! A chunk with a frequency that is not finite and >= 0, or on which a block is singular, is
//! handed to a scalar pass over its points in order ([`Kernel::first_error`]) that returns the
//! error of the first such point: the error a point-by-point evaluation of the grid reports.
//! The interleaved output is also checked for values that overflowed, each as it is computed
//! (in registers, before the chunk goes to memory): [`TfError::NotFinite`] at the first such
//! point.

use super::super::direct::{omega_sq, SINGULAR_RCOND};
use super::lanes::{stream_fence, Lanes, Portable, LANES};
#[cfg(target_arch = "x86_64")]
use super::lanes::{Avx, AvxToken};
use crate::error::TfError;
use crate::tf::Destination;
use num_complex::Complex64;

/// One entry of an undamped block: `gain s^power prod_k (a_k + b_k s) prod_j (1 + c1_j s +
/// c2_j s^2)` times the block's `1 / prod(lambda - s)`, added at value `re` (its real part).
/// Linear factors: `s` for a zero at the origin (`a = 0, b = 1`), `1 - s / z` for a real zero
/// `z` (`a = 1, b = -1 / z`, `z` moved into the gain); the first `factors` of the `N` (the
/// block's size), the others padding (`a = 1, b = 0`), skipped (an exact 1 for every finite
/// `s`). The coupled system (`N = 8`) takes its zeros at the origin as `power` and the others
/// two by two, `(1 - s / z_1)(1 - s / z_2)` with both zeros moved into the gain: a conjugate
/// pair (real coefficients, so real arithmetic) or two real zeros (the smallest with the
/// largest in magnitude, so that two nearby zeros rarely share a factor); five operations per
/// two zeros against six; the first `pairs` of `c1`, `c2`, a zero left over as a linear factor.
#[derive(Debug, Clone, Copy)]
pub(super) struct RealEntry<const N: usize> {
    /// Position of the real part in a point's `f64` values.
    pub re: usize,
    /// The first block to write `out[re]`: it stores `0.0 + h` (what
    /// adding to a zeroed output gives) instead of adding (set by [`Kernel::new`]). Real
    /// blocks leave the imaginary part alone.
    pub first_re: bool,
    pub factors: usize,
    pub gain: f64,
    pub a: [f64; N],
    pub b: [f64; N],
    pub power: usize,
    pub pairs: usize,
    pub c1: [f64; N],
    pub c2: [f64; N],
}

/// [`RealEntry`] with complex gain and factors (damped blocks, or complex zeros).
#[derive(Debug, Clone, Copy)]
pub(super) struct ComplexEntry<const N: usize> {
    /// Positions of the real and imaginary parts in a point's `f64` values.
    pub re: usize,
    pub im: usize,
    /// As [`RealEntry::first_re`].
    pub first_re: bool,
    /// The first block to write `out[im]`.
    pub first_im: bool,
    pub factors: usize,
    pub gain: Complex64,
    pub a: [Complex64; N],
    pub b: [Complex64; N],
}

/// A block of `N` coordinates (4: one of the two decoupled blocks; 8: the coupled system of an
/// asymmetric pendulum) with real poles (undamped) whose entries are all real.
pub(super) struct RealBlock<const N: usize> {
    poles: [f64; N],
    /// `SINGULAR_RCOND lambda_k`.
    thresholds: [f64; N],
    entries: Vec<RealEntry<N>>,
}

/// A block in complex arithmetic.
pub(super) struct ComplexBlock<const N: usize> {
    poles: [Complex64; N],
    /// `(SINGULAR_RCOND |lambda_k|)^2`.
    thresholds: [f64; N],
    entries: Vec<ComplexEntry<N>>,
}

impl<const N: usize> RealBlock<N> {
    /// A block in real arithmetic with eigenvalues `poles` (`s`, rad^2/s^2).
    pub fn new(poles: [f64; N], entries: Vec<RealEntry<N>>) -> Self {
        RealBlock {
            poles,
            thresholds: poles.map(|l| SINGULAR_RCOND * l),
            entries,
        }
    }
}

impl<const N: usize> ComplexBlock<N> {
    /// A block in complex arithmetic with eigenvalues `poles`.
    pub fn new(poles: [Complex64; N], entries: Vec<ComplexEntry<N>>) -> Self {
        ComplexBlock {
            poles,
            thresholds: poles.map(|l| (SINGULAR_RCOND * l.norm()).powi(2)),
            entries,
        }
    }
}

/// One block's product forms.
pub(super) enum BlockForm {
    /// A decoupled block, undamped, every zero real: real arithmetic.
    Real(RealBlock<4>),
    /// A decoupled block, damped (or complex zeros): complex arithmetic.
    Complex(ComplexBlock<4>),
    /// The coupled 8x8 system, real arithmetic.
    Real8(RealBlock<8>),
    /// The coupled 8x8 system, complex arithmetic.
    Complex8(ComplexBlock<8>),
}

impl BlockForm {
    /// Adds the block's entries at the chunk's first `n` frequencies (`s` per lane) to `out`
    /// (`n` points of `stride` `f64` values), and `v - v` of each value added to `finite`
    /// (interleaved only); false, with `out` partly written, if the block is singular in
    /// some lane.
    #[inline(always)]
    fn add_chunk<V: Lanes, const PLANAR: bool>(
        &self,
        s: V,
        n: usize,
        stride: usize,
        out: &mut [f64],
        finite: &mut V,
    ) -> bool {
        match self {
            BlockForm::Real(b) => b.add_chunk::<V, PLANAR>(s, n, stride, out, finite),
            BlockForm::Complex(b) => b.add_chunk::<V, PLANAR>(s, n, stride, out, finite),
            BlockForm::Real8(b) => b.add_chunk::<V, PLANAR>(s, n, stride, out, finite),
            BlockForm::Complex8(b) => b.add_chunk::<V, PLANAR>(s, n, stride, out, finite),
        }
    }

    /// The smallest relative distance `|lambda_k - s| / |lambda_k|` of `s` to a pole, and
    /// whether it is below the singularity threshold.
    fn nearest_pole(&self, s: f64) -> (f64, bool) {
        match self {
            BlockForm::Real(b) => b.nearest_pole(s),
            BlockForm::Complex(b) => b.nearest_pole(s),
            BlockForm::Real8(b) => b.nearest_pole(s),
            BlockForm::Complex8(b) => b.nearest_pole(s),
        }
    }

    /// Sets the entries' `first_*` flags: `first(at)` is true for the first writer of `at`.
    fn mark_first(&mut self, first: &mut dyn FnMut(usize) -> bool) {
        match self {
            BlockForm::Real(b) => b.mark_first(first),
            BlockForm::Complex(b) => b.mark_first(first),
            BlockForm::Real8(b) => b.mark_first(first),
            BlockForm::Complex8(b) => b.mark_first(first),
        }
    }

    fn is_singular(&self, s: f64) -> bool {
        self.nearest_pole(s).1
    }

    /// The error at a frequency where [`BlockForm::is_singular`] holds.
    #[cold]
    fn singular(&self, s: f64, freq_hz: f64) -> TfError {
        TfError::Singular {
            freq_hz,
            rcond: self.nearest_pole(s).0,
        }
    }
}

/// `prod_k d_k` as a balanced tree, `(d_0 d_1)(d_2 d_3)` for `N = 4` (and so on for a power
/// of two): one fixed order of the same IEEE operations in every lane.
#[inline(always)]
fn product<T: Copy, const N: usize>(d: [T; N], mul: impl Fn(T, T) -> T) -> T {
    let mut acc = d;
    let mut n = N;
    while n > 1 {
        for i in 0..n / 2 {
            acc[i] = mul(acc[2 * i], acc[2 * i + 1]);
        }
        n /= 2;
    }
    acc[0]
}

// The kernels below use plain loops, no iterator adaptors with closures around the lane
// operations: those could be compiled outside the AVX entry point and lose its instructions.

impl<const N: usize> RealBlock<N> {
    fn nearest_pole(&self, s: f64) -> (f64, bool) {
        let rcond = self
            .poles
            .iter()
            .map(|&l| (l - s).abs() / l)
            .fold(f64::INFINITY, f64::min);
        let singular = (0..N).any(|k| (self.poles[k] - s).abs() < self.thresholds[k]);
        (rcond, singular)
    }

    fn mark_first(&mut self, first: &mut dyn FnMut(usize) -> bool) {
        for e in &mut self.entries {
            e.first_re = first(e.re);
        }
    }

    #[inline(always)]
    fn add_chunk<V: Lanes, const PLANAR: bool>(
        &self,
        s: V,
        n: usize,
        stride: usize,
        out: &mut [f64],
        finite: &mut V,
    ) -> bool {
        let mut d = [s; N];
        let mut singular = false;
        for ((dk, &p), &t) in d.iter_mut().zip(&self.poles).zip(&self.thresholds) {
            *dk = V::splat(p).sub(s);
            singular |= dk.abs().any_lt(V::splat(t));
        }
        if singular {
            return false;
        }
        #[inline(always)]
        fn mul<V: Lanes>(a: V, b: V) -> V {
            a.mul(b)
        }
        let inv = V::splat(1.0).div(product(d, mul::<V>));
        let s2 = s.mul(s);
        for e in &self.entries {
            // 1 - s / z: relative error ~ 1.5 eps |z| / |z - s| (the rounding of 1 / z and of
            // the product), as z - s with z rounded to f64.
            let mut h = V::splat(e.gain);
            for _ in 0..e.power {
                h = h.mul(s);
            }
            for k in 0..e.factors {
                h = h.mul(V::splat(e.a[k]).add(V::splat(e.b[k]).mul(s)));
            }
            for k in 0..e.pairs {
                let q = V::splat(1.0)
                    .add(V::splat(e.c1[k]).mul(s))
                    .add(V::splat(e.c2[k]).mul(s2));
                h = h.mul(q);
            }
            put::<V, PLANAR>(out, e.re, stride, n, e.first_re, h.mul(inv), finite);
        }
        true
    }
}

/// Lane `l < n` of `v` into `out[l * stride + at]` (interleaved: a point's values together),
/// or every lane into `out[at * LANES + l]` (`PLANAR`: a value's lanes together): stored as
/// `0.0 + v` if `first` (what adding to a zeroed output gives: +0.0 for -0.0), else added.
/// Interleaved, `v - v` (0 if finite, else NaN) is added to `finite`: the check of the value
/// while it is in a register (see [`Kernel::eval_with`]).
#[inline(always)]
#[allow(clippy::eq_op, reason = "`v - v` is the finiteness test")]
fn put<V: Lanes, const PLANAR: bool>(
    out: &mut [f64],
    at: usize,
    stride: usize,
    n: usize,
    first: bool,
    v: V,
    finite: &mut V,
) {
    if PLANAR {
        let lanes: &mut [f64; LANES] = (&mut out[at * LANES..(at + 1) * LANES])
            .try_into()
            .expect("LANES values");
        let v = if first {
            V::splat(0.0).add(v)
        } else {
            V::load(lanes).add(v)
        };
        v.store(lanes);
        return;
    }
    *finite = finite.add(v.sub(v));
    let v = if first { V::splat(0.0).add(v) } else { v }.to_array();
    // One bounds check for the column, none per lane (when `n == LANES`, the usual case, the
    // loop below has a constant count and is unrolled).
    let column = &mut out[at..=at + (n - 1) * stride];
    let mut one = |l: usize| {
        let x = &mut column[l * stride];
        if first {
            *x = v[l];
        } else {
            *x += v[l];
        }
    };
    if n == LANES {
        for l in 0..LANES {
            one(l);
        }
    } else {
        for l in 0..n {
            one(l);
        }
    }
}

/// `(a_re + i a_im) (b_re + i b_im)` in lanes, num_complex's formula.
#[inline(always)]
fn cmul<V: Lanes>((ar, ai): (V, V), (br, bi): (V, V)) -> (V, V) {
    (ar.mul(br).sub(ai.mul(bi)), ar.mul(bi).add(ai.mul(br)))
}

impl<const N: usize> ComplexBlock<N> {
    fn nearest_pole(&self, s: f64) -> (f64, bool) {
        let rcond = self
            .poles
            .iter()
            .map(|&l| (l - s).norm() / l.norm())
            .fold(f64::INFINITY, f64::min);
        let singular = (0..N).any(|k| (self.poles[k] - s).norm_sqr() < self.thresholds[k]);
        (rcond, singular)
    }

    fn mark_first(&mut self, first: &mut dyn FnMut(usize) -> bool) {
        for e in &mut self.entries {
            e.first_re = first(e.re);
            e.first_im = first(e.im);
        }
    }

    #[inline(always)]
    fn add_chunk<V: Lanes, const PLANAR: bool>(
        &self,
        s: V,
        n: usize,
        stride: usize,
        out: &mut [f64],
        finite: &mut V,
    ) -> bool {
        let mut d = [(s, s); N];
        let mut singular = false;
        for ((dk, p), &t) in d.iter_mut().zip(&self.poles).zip(&self.thresholds) {
            let (re, im) = (V::splat(p.re).sub(s), V::splat(p.im));
            *dk = (re, im);
            singular |= re.mul(re).add(im.mul(im)).any_lt(V::splat(t));
        }
        if singular {
            return false;
        }
        // 1 / den = conj(den) / |den|^2; the conjugation is folded into the last product.
        let (re, im) = product(d, cmul::<V>);
        let t = re.mul(re).add(im.mul(im));
        let (inv_re, inv_im_neg) = (re.div(t), im.div(t));
        for e in &self.entries {
            let mut h = (V::splat(e.gain.re), V::splat(e.gain.im));
            for k in 0..e.factors {
                let f_re = V::splat(e.a[k].re).add(V::splat(e.b[k].re).mul(s));
                let f_im = V::splat(e.a[k].im).add(V::splat(e.b[k].im).mul(s));
                h = cmul(h, (f_re, f_im));
            }
            let (h_re, h_im) = h;
            // (h_re + i h_im) (inv_re - i inv_im_neg).
            let re = h_re.mul(inv_re).add(h_im.mul(inv_im_neg));
            let im = h_im.mul(inv_re).sub(h_re.mul(inv_im_neg));
            put::<V, PLANAR>(out, e.re, stride, n, e.first_re, re, finite);
            put::<V, PLANAR>(out, e.im, stride, n, e.first_im, im, finite);
        }
        true
    }
}

/// The evaluation side of a pole-zero plan.
pub(super) struct Kernel {
    blocks: Vec<BlockForm>,
    /// `f64` values per frequency: `2 outputs x inputs` in the dense complex layout, fewer in
    /// a compact one (see [`super::super::Layout`]).
    stride: usize,
    /// Present when the CPU has AVX (detected at plan time): the same operations, four lanes
    /// per instruction.
    #[cfg(target_arch = "x86_64")]
    avx: Option<AvxToken>,
    /// Positions that more than one block adds to: a sum of finite contributions can still
    /// overflow, so these are checked once the chunk is complete.
    summed: Vec<usize>,
}

impl Kernel {
    /// The kernel of `blocks`, whose entries write at positions below `stride` in each
    /// point's `f64` values.
    pub fn new(mut blocks: Vec<BlockForm>, stride: usize) -> Kernel {
        let mut written = vec![0_usize; stride];
        let mut first = |at: usize| {
            written[at] += 1;
            written[at] == 1
        };
        for b in &mut blocks {
            b.mark_first(&mut first);
        }
        let summed = (0..stride).filter(|&at| written[at] > 1).collect();
        Kernel {
            blocks,
            stride,
            #[cfg(target_arch = "x86_64")]
            avx: AvxToken::try_new(),
            summed,
        }
    }

    /// `H` at every frequency of `freqs_hz` into `out` (`stride` values per frequency,
    /// length `freqs_hz.len() * stride`, checked by the caller), every value finite: else
    /// the error is [`TfError::NotFinite`] at the first frequency with a value that is not
    /// (checked chunk by chunk while the values are in cache). Large outputs are written with
    /// non-temporal stores unless `out` is [`Destination::Fresh`]. On error the contents of
    /// `out` are unspecified.
    pub fn eval_grid(
        &self,
        freqs_hz: &[f64],
        out: &mut [f64],
        destination: Destination,
    ) -> Result<(), TfError> {
        if self.stride > 0 && freqs_hz.len() == 1 {
            // One point (`eval_into`): written in place.
            out.fill(0.0);
            return self.dispatch(freqs_hz, out, &mut InPlace);
        }
        let mut chunk = self.chunk_buffer();
        self.dispatch(
            freqs_hz,
            &mut chunk,
            &mut Interleaved::new(out, destination),
        )
    }

    /// `H` at every frequency of `freqs_hz` into `planes` (`stride` of them, each as long as
    /// the grid): value `v` of frequency `k` at `planes[v][k]`. On error the contents of
    /// `planes` are unspecified.
    pub fn eval_planes(&self, freqs_hz: &[f64], planes: &mut [&mut [f64]]) -> Result<(), TfError> {
        assert_eq!(planes.len(), self.stride, "one plane per value");
        for p in planes.iter() {
            assert_eq!(p.len(), freqs_hz.len(), "planes as long as the grid");
        }
        let mut chunk = self.chunk_buffer();
        self.dispatch(freqs_hz, &mut chunk, &mut Planar(planes))
    }

    /// A chunk's values, zeroed: the values no block writes stay zero.
    fn chunk_buffer(&self) -> Vec<f64> {
        vec![0.0; LANES * self.stride]
    }

    /// [`Kernel::eval_with`] in AVX registers when the CPU has AVX, portable lanes otherwise.
    fn dispatch<S: Sink>(
        &self,
        freqs_hz: &[f64],
        chunk: &mut [f64],
        sink: &mut S,
    ) -> Result<(), TfError> {
        #[cfg(target_arch = "x86_64")]
        if let Some(token) = self.avx {
            return self.eval_avx(token, freqs_hz, chunk, sink);
        }
        self.eval_with::<Portable, S>(freqs_hz, chunk, sink)
    }

    /// The kernel in AVX registers, on the CPU `_avx` proves has them.
    #[cfg(target_arch = "x86_64")]
    fn eval_avx<S: Sink>(
        &self,
        _avx: AvxToken,
        freqs_hz: &[f64],
        chunk: &mut [f64],
        sink: &mut S,
    ) -> Result<(), TfError> {
        // SAFETY: an `AvxToken` exists only when the running CPU has AVX.
        unsafe { self.eval_avx_unchecked(freqs_hz, chunk, sink) }
    }

    /// The kernel in AVX registers: the same operations in the same order as the portable
    /// lanes (no fused multiply-add), so the results are bit-identical.
    ///
    /// # Safety
    ///
    /// The running CPU must have AVX ([`Kernel::eval_avx`] takes the proof).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    unsafe fn eval_avx_unchecked<S: Sink>(
        &self,
        freqs_hz: &[f64],
        chunk: &mut [f64],
        sink: &mut S,
    ) -> Result<(), TfError> {
        self.eval_with::<Avx, S>(freqs_hz, chunk, sink)
    }

    /// The grid chunk by chunk: each chunk's values into `chunk` (a buffer that stays in L1
    /// cache, whose values no block writes are zero), then handed to `sink`.
    #[inline(always)]
    fn eval_with<V: Lanes, S: Sink>(
        &self,
        freqs_hz: &[f64],
        chunk: &mut [f64],
        sink: &mut S,
    ) -> Result<(), TfError> {
        if self.stride == 0 {
            // Nothing to write; the frequencies are still checked, as point by point.
            return freqs_hz.iter().try_for_each(|&f| omega_sq(f).map(drop));
        }
        let mut result = Ok(());
        for (c, fc) in freqs_hz.chunks(LANES).enumerate() {
            let finite = if S::PLANAR {
                self.eval_chunk::<V, true>(fc, chunk)
            } else {
                self.eval_chunk::<V, false>(fc, chunk)
            };
            let finite = match finite {
                Ok(f) => f,
                Err(e) => {
                    result = Err(e);
                    break;
                }
            };
            // The interleaved values are checked here, as they were computed, rather than by
            // the caller after they went to memory; the planar ones by `tf::evaluate_into`,
            // block by block.
            if !S::PLANAR && !self.chunk_is_finite(finite, &chunk[..fc.len() * self.stride]) {
                result = Err(first_not_finite(fc, chunk, self.stride));
                break;
            }
            sink.take::<V>(c * LANES, fc.len(), self.stride, chunk);
        }
        sink.finish();
        result
    }

    /// `H` at the (at most [`LANES`]) frequencies `fc` into `dst` (`fc.len()` points of
    /// `stride`, or `stride` values of [`LANES`] lanes if `PLANAR`), whose structural zeros
    /// must already be zero. Returns the sum of `v - v` over the values added (interleaved;
    /// 0 if all are finite, else NaN).
    #[inline(always)]
    fn eval_chunk<V: Lanes, const PLANAR: bool>(
        &self,
        fc: &[f64],
        dst: &mut [f64],
    ) -> Result<V, TfError> {
        // A short chunk repeats its last frequency in the unused lanes.
        let last = fc.len() - 1;
        let f = V::from_array(std::array::from_fn(|l| fc[l.min(last)]));
        let valid = f.all_finite_nonneg();
        // `omega_sq`'s arithmetic: (2 pi f)^2, two roundings.
        let w = V::splat(std::f64::consts::TAU).mul(f);
        let s = w.mul(w);
        let mut ok = valid;
        let mut finite = V::splat(0.0);
        for b in &self.blocks {
            ok = ok && b.add_chunk::<V, PLANAR>(s, fc.len(), self.stride, dst, &mut finite);
        }
        if ok {
            Ok(finite)
        } else {
            Err(self.first_error(fc))
        }
    }

    /// Whether a complete chunk of interleaved `values` is finite, given the sum of `v - v`
    /// over every value its blocks added (`finite`): the structural zeros are, and a value
    /// one block wrote is if its contribution is; a value several blocks added to is checked
    /// itself.
    #[inline(always)]
    fn chunk_is_finite<V: Lanes>(&self, finite: V, values: &[f64]) -> bool {
        // Every lane 0 (one comparison, no chain of additions across the lanes).
        if !finite.all_finite_nonneg() {
            return false;
        }
        for &at in &self.summed {
            for point in values.chunks_exact(self.stride) {
                if !point[at].is_finite() {
                    return false;
                }
            }
        }
        true
    }

    /// The error of the first point of `freqs_hz` that is invalid or singular, checking the
    /// points in order and, at a point, the blocks in order.
    #[cold]
    #[inline(never)]
    fn first_error(&self, freqs_hz: &[f64]) -> TfError {
        for &f in freqs_hz {
            let s = match omega_sq(f) {
                Ok(s) => s,
                Err(e) => return e,
            };
            if let Some(b) = self.blocks.iter().find(|b| b.is_singular(s)) {
                return b.singular(s, f);
            }
        }
        unreachable!("a chunk failed its checks but none of its points does")
    }
}

/// [`TfError::NotFinite`] at the first point of `freqs_hz` (`stride` values each in `values`)
/// with a value that is not finite: an overflow (a frequency or parameters beyond the range of
/// `f64`), never a silent NaN.
#[cold]
#[inline(never)]
fn first_not_finite(freqs_hz: &[f64], values: &[f64], stride: usize) -> TfError {
    let k = values
        .chunks_exact(stride)
        .take(freqs_hz.len())
        .position(|p| p.iter().any(|v| !v.is_finite()))
        // A lane past the chunk's points repeats its last point, so a value that is not
        // finite is in one of the points.
        .unwrap_or(freqs_hz.len() - 1);
    TfError::NotFinite {
        freq_hz: freqs_hz[k],
    }
}

/// Where [`Kernel::eval_with`] puts each chunk of values.
trait Sink {
    /// Each value's lanes together in the chunk buffer (else each point's values together).
    const PLANAR: bool;

    /// The chunk of `n` points starting at point `first` (`stride` values each), from `chunk`.
    fn take<V: Lanes>(&mut self, first: usize, n: usize, stride: usize, chunk: &[f64]);

    /// After the last chunk.
    fn finish(&mut self) {}
}

/// A single point evaluated directly in the (zeroed) output, which is the chunk buffer.
struct InPlace;

impl Sink for InPlace {
    const PLANAR: bool = false;
    fn take<V: Lanes>(&mut self, _: usize, _: usize, _: usize, _: &[f64]) {}
}

/// A point's values together: each chunk copied in one sequential pass, with non-temporal
/// stores when `stream`.
struct Interleaved<'a> {
    out: &'a mut [f64],
    stream: bool,
}

impl<'a> Interleaved<'a> {
    /// Non-temporal stores where `destination` says so ([`Destination::streams`]).
    fn new(out: &'a mut [f64], destination: Destination) -> Self {
        let stream = destination.streams(std::mem::size_of_val(out));
        Interleaved { out, stream }
    }
}

impl Sink for Interleaved<'_> {
    const PLANAR: bool = false;
    #[inline(always)]
    fn take<V: Lanes>(&mut self, first: usize, n: usize, stride: usize, chunk: &[f64]) {
        let dst = &mut self.out[first * stride..(first + n) * stride];
        if self.stream {
            V::stream_copy(dst, &chunk[..dst.len()]);
        } else {
            dst.copy_from_slice(&chunk[..dst.len()]);
        }
    }
    fn finish(&mut self) {
        if self.stream {
            stream_fence();
        }
    }
}

/// One plane per value. Ordinary stores: a chunk writes 64 bytes to each plane, a whole
/// cache line only if the plane is 64-byte aligned, and partial lines written non-temporally
/// are an order of magnitude slower than ordinary stores in a copy test; a compact result is
/// also small enough to stay in L3 (8.8 MB at 1e5 points of Table I's tilt matrix).
struct Planar<'a, 'p>(&'a mut [&'p mut [f64]]);

impl Sink for Planar<'_, '_> {
    const PLANAR: bool = true;
    #[inline(always)]
    fn take<V: Lanes>(&mut self, first: usize, n: usize, _: usize, chunk: &[f64]) {
        for (p, plane) in self.0.iter_mut().enumerate() {
            let (dst, src) = (
                &mut plane[first..first + n],
                &chunk[p * LANES..p * LANES + n],
            );
            if let (Ok(d), Ok(s)) = (
                <&mut [f64; LANES]>::try_from(&mut *dst),
                <&[f64; LANES]>::try_from(src),
            ) {
                // A full chunk: a fixed-size copy (vector moves, no call to memcpy).
                V::load(s).store(d);
            } else {
                dst.copy_from_slice(src);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::model::Model;
    use crate::params::Params;
    use crate::tf::{PoleZero, Request};

    /// A value two blocks add to can overflow although each contribution is finite: it is
    /// checked itself ([`super::Kernel::chunk_is_finite`]), on every point of a chunk and of a
    /// short last chunk, as is a contribution that overflows alone.
    #[test]
    fn sums_of_blocks_that_overflow_are_refused() {
        use super::{BlockForm, Kernel, RealBlock, RealEntry};
        use crate::error::TfError;
        use crate::tf::Destination;
        // 1 / prod(1 - s): each block adds `gain` at 0 Hz, `gain / 14^4` at s = 15.
        let block = |gain: f64| {
            let entry = RealEntry {
                re: 0,
                first_re: false,
                factors: 0,
                gain,
                a: [1.0; 4],
                b: [0.0; 4],
                power: 0,
                pairs: 0,
                c1: [0.0; 4],
                c2: [0.0; 4],
            };
            BlockForm::Real(RealBlock::new([1.0; 4], vec![entry]))
        };
        let two = |gain: f64| Kernel::new(vec![block(gain), block(gain)], 1);
        let f_15 = 15f64.sqrt() / std::f64::consts::TAU;
        for n in [1, 3, 8, 11] {
            let mut f = vec![f_15; n];
            f[n - 1] = 0.0;
            let mut out = vec![f64::NAN; n];
            two(1e307)
                .eval_grid(&f, &mut out, Destination::Reused)
                .unwrap();
            assert_eq!(out[n - 1], 2e307);
            let cases = [
                (two(1.5e308), 0.0),
                (Kernel::new(vec![block(f64::INFINITY)], 1), f[0]),
            ];
            for (kernel, first_bad) in cases {
                match kernel.eval_grid(&f, &mut out, Destination::Reused) {
                    Err(TfError::NotFinite { freq_hz }) => {
                        assert_eq!(freq_hz, first_bad, "{n} points")
                    }
                    other => panic!("{n} points: {other:?}"),
                }
            }
        }
    }

    /// AVX and portable lanes on the same grid, bit for bit: undamped and damped (real and
    /// complex blocks, decoupled 4x4 and coupled 8x8), the dense and the compact kernel, interleaved and planar, a grid small
    /// enough for ordinary stores and one large enough for the non-temporal ones (and the
    /// same with ordinary stores into a fresh buffer), with a short last chunk.
    /// Skipped on a CPU without AVX.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn avx_and_portable_lanes_agree_bit_for_bit() {
        let Some(token) = super::AvxToken::try_new() else {
            return;
        };
        let mut damped = Params::table_i();
        for key in ["torsion_a_rad", "bouncing_b_rad"] {
            damped = damped.with_override(&format!("loss.{key}=1e-3")).unwrap();
        }
        // The coupled 8x8 system of a pendulum as built (real, with conjugate zero pairs;
        // and damped, complex).
        let coupled = |p: &Params| p.with_override("asymmetry.tm_com_x_m=1e-3").unwrap();
        let (built, built_damped) = (coupled(&Params::table_i()), coupled(&damped));
        for params in [Params::table_i(), damped, built, built_damped] {
            let pz = PoleZero::new(&Model::new(&params).unwrap(), Request::all_tilt());
            for kernel in [&pz.kernel, &pz.compact] {
                let stride = kernel.stride;
                // 0 Hz, then log-spaced to 1e5 Hz; the second grid exceeds STREAM_MIN_BYTES.
                let big = crate::tf::STREAM_MIN_BYTES / (8 * stride) + 1001;
                for n in [1001, big] {
                    let freqs: Vec<f64> = (0..n)
                        .map(|k| match k {
                            0 => 0.0,
                            _ => 1e-6 * 1e11_f64.powf(k as f64 / (n - 1) as f64),
                        })
                        .collect();
                    let mut portable = vec![f64::NAN; n * stride];
                    let mut avx = portable.clone();
                    let mut chunk = kernel.chunk_buffer();
                    kernel
                        .eval_with::<super::Portable, _>(
                            &freqs,
                            &mut chunk,
                            &mut super::Interleaved::new(&mut portable, super::Destination::Reused),
                        )
                        .unwrap();
                    let mut chunk = kernel.chunk_buffer();
                    let mut sink = super::Interleaved::new(&mut avx, super::Destination::Reused);
                    kernel
                        .eval_avx(token, &freqs, &mut chunk, &mut sink)
                        .unwrap();
                    for (k, (a, p)) in avx.iter().zip(&portable).enumerate() {
                        assert!(
                            a.to_bits() == p.to_bits(),
                            "stride {stride}, value {} at {} Hz: AVX {a} vs portable {p}",
                            k % stride,
                            freqs[k / stride]
                        );
                    }
                    // Ordinary stores into a new buffer (`Destination::Fresh`): the same values.
                    let mut fresh = vec![f64::NAN; n * stride];
                    kernel
                        .eval_grid(&freqs, &mut fresh, super::Destination::Fresh)
                        .unwrap();
                    assert!(fresh
                        .iter()
                        .zip(&avx)
                        .all(|(f, a)| f.to_bits() == a.to_bits()));
                    // The planar path (what `evaluate` uses) of the same kernel.
                    let planes_of = |avx: bool| {
                        let mut data = vec![f64::NAN; n * stride];
                        let mut planes: Vec<&mut [f64]> = data.chunks_exact_mut(n).collect();
                        let mut sink = super::Planar(&mut planes);
                        let mut chunk = kernel.chunk_buffer();
                        if avx {
                            kernel
                                .eval_avx(token, &freqs, &mut chunk, &mut sink)
                                .unwrap();
                        } else {
                            kernel
                                .eval_with::<super::Portable, _>(&freqs, &mut chunk, &mut sink)
                                .unwrap();
                        }
                        data
                    };
                    let (pa, pp) = (planes_of(true), planes_of(false));
                    for (k, (a, p)) in pa.iter().zip(&pp).enumerate() {
                        assert!(
                            a.to_bits() == p.to_bits(),
                            "planes: plane {} at {} Hz: AVX {a} vs portable {p}",
                            k / n,
                            freqs[k % n]
                        );
                        // The same values as the interleaved path.
                        assert_eq!(a.to_bits(), avx[(k % n) * stride + k / n].to_bits());
                    }
                }
            }
        }
    }
}
