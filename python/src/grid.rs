//! Frequency grids from Python arguments: a number or a 1-D array-like, copied to `f64` once
//! its size is checked ([`crate::arrays`]), and the band `auto` plans for.

use crate::arrays::{self, check_size, Size};
use numpy::{PyArray1, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::cell::RefCell;
use tiltnoise_core::freq::DEFAULT_F_LO_HZ;
use tiltnoise_core::limits::MAX_GRID_POINTS;

/// A grid held in memory with nothing else per point: [`MAX_GRID_POINTS`], 8 bytes a point.
pub const GRID: Size = grid_size(8);

/// A grid of at most [`MAX_GRID_POINTS`] points costing `bytes_each` bytes per point (the
/// frequency and what is computed on it).
pub const fn grid_size(bytes_each: u64) -> Size {
    Size {
        limit: MAX_GRID_POINTS,
        unit: "frequencies",
        bytes_each,
    }
}

/// Frequencies (Hz) from a number or a 1-D array-like, as `f64`, at most `size`: a float64
/// array is copied as it is; a NumPy array is asked before a number (a one-element array
/// converts to a number only with a deprecation warning, and trying the conversion costs
/// microseconds).
pub fn frequencies(arg: &Bound<'_, PyAny>, size: Size) -> PyResult<Vec<f64>> {
    let mut freqs = Vec::new();
    frequencies_into(arg, size, &mut freqs)?;
    Ok(freqs)
}

/// [`frequencies`] into `freqs` (cleared first, its allocation kept), and their
/// [`auto_band`] (found while a contiguous float64 array is copied, in the same pass).
#[allow(unsafe_code, reason = "a NumPy array's values read in place")]
fn frequencies_into(
    arg: &Bound<'_, PyAny>,
    size: Size,
    freqs: &mut Vec<f64>,
) -> PyResult<(f64, f64)> {
    freqs.clear();
    if let Ok(a) = arg.cast::<PyArray1<f64>>() {
        check_size("freq_hz", a.len(), size)?;
        // SAFETY: the values are copied at once, holding the GIL, so no Python code runs
        // meanwhile; no Rust code of this module holds a mutable view of an array here.
        if let Ok(slice) = unsafe { a.as_slice() } {
            arrays::reserve("freq_hz", freqs, slice.len())?;
            return Ok(copy_with_band(slice, freqs));
        }
    } else if arg.cast::<PyUntypedArray>().is_err() {
        if let Ok(f) = arg.extract::<f64>() {
            freqs.push(f);
            return Ok(auto_band(freqs));
        }
    }
    // A view, another dtype, a sequence; a 0-d array is one frequency, as a number.
    arrays::grid_into("freq_hz", arg, size, freqs)?;
    Ok(auto_band(freqs))
}

/// The band `auto` plans for (the command line's `--method auto`): that of the positive
/// finite frequencies, or the default lowest frequency when there is none.
pub fn auto_band(freqs: &[f64]) -> (f64, f64) {
    let mut band = Band::EMPTY;
    let rows = freqs.chunks_exact(WAYS);
    band.take(rows.remainder());
    for row in rows {
        band.take(row);
    }
    band.finish()
}

/// `src` copied into `dst` (emptied first), and its [`auto_band`], in one pass.
#[allow(unsafe_code, reason = "calls the AVX build after detecting AVX")]
fn copy_with_band(src: &[f64], dst: &mut Vec<f64>) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the running CPU has AVX.
        return unsafe { copy_with_band_avx(src, dst) };
    }
    copy_with_band_lanes(src, dst)
}

/// [`copy_with_band_lanes`] compiled for AVX: four lanes per instruction instead of two.
///
/// # Safety
///
/// The running CPU must support AVX (`is_x86_feature_detected!("avx")`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
#[allow(
    unsafe_code,
    reason = "target_feature functions are unsafe before Rust 1.86"
)]
unsafe fn copy_with_band_avx(src: &[f64], dst: &mut Vec<f64>) -> (f64, f64) {
    copy_with_band_lanes(src, dst)
}

#[inline(always)]
fn copy_with_band_lanes(src: &[f64], dst: &mut Vec<f64>) -> (f64, f64) {
    dst.clear();
    dst.reserve(src.len());
    let mut band = Band::EMPTY;
    let rows = src.chunks_exact(WAYS);
    let rest = rows.remainder();
    for row in rows {
        band.take(row);
        dst.extend_from_slice(row);
    }
    band.take(rest);
    dst.extend_from_slice(rest);
    band.finish()
}

/// Running extremes per lane of [`Band`].
const WAYS: usize = 8;

/// The lowest and highest frequency that counts for the band (> 0 and finite), as
/// [`WAYS`] running extremes updated by comparisons and selections only, so that the loop
/// runs in vector lanes: a frequency that does not count (<= 0, NaN, inf) is replaced by a
/// value that changes nothing. Written with `<` and `if` rather than `f64::min`, whose NaN
/// rule, or a finiteness test, the compiler keeps scalar.
struct Band {
    lo: [f64; WAYS],
    hi: [f64; WAYS],
}

impl Band {
    const EMPTY: Band = Band {
        lo: [f64::INFINITY; WAYS],
        hi: [0.0; WAYS],
    };

    /// Up to [`WAYS`] frequencies, one per lane.
    #[inline(always)]
    fn take(&mut self, row: &[f64]) {
        for ((lo, hi), &f) in self.lo.iter_mut().zip(&mut self.hi).zip(row) {
            let low = if f > 0.0 { f } else { f64::INFINITY };
            *lo = if low < *lo { low } else { *lo };
            let high = if f <= f64::MAX { f } else { 0.0 };
            *hi = if high > *hi { high } else { *hi };
        }
    }

    fn finish(self) -> (f64, f64) {
        let lo = self.lo.into_iter().fold(f64::INFINITY, f64::min);
        let hi = self.hi.into_iter().fold(0.0, f64::max);
        if hi > 0.0 {
            (lo, hi)
        } else {
            (DEFAULT_F_LO_HZ, DEFAULT_F_LO_HZ)
        }
    }
}

/// Grids of at most this many points keep their buffer for the calling thread's next
/// `transfer` (8 MB): a repeated call on the same grid then copies it into memory it already
/// holds rather than into a new allocation, whose pages the operating system zeroes first.
/// One buffer per Python thread that calls, whatever the number of models.
const KEPT_GRID_MAX_POINTS: usize = 1 << 20;

thread_local! {
    /// The buffer of this thread's last `transfer`.
    static KEPT_GRID: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// The calling thread's frequency buffer, taken for one call and put back when dropped (a
/// nested call, from Python code run while converting an argument, gets a new one).
pub struct GridBuffer {
    freqs: Vec<f64>,
}

impl GridBuffer {
    pub fn take() -> Self {
        let freqs = KEPT_GRID
            .try_with(|kept| std::mem::take(&mut *kept.borrow_mut()))
            .unwrap_or_default();
        GridBuffer { freqs }
    }

    /// The frequencies of `arg` ([`frequencies`], at most `size`) into the buffer, and their
    /// [`auto_band`].
    pub fn fill(&mut self, arg: &Bound<'_, PyAny>, size: Size) -> PyResult<(f64, f64)> {
        frequencies_into(arg, size, &mut self.freqs)
    }

    pub fn freqs(&self) -> &[f64] {
        &self.freqs
    }
}

impl Drop for GridBuffer {
    fn drop(&mut self) {
        if self.freqs.capacity() <= KEPT_GRID_MAX_POINTS {
            let freqs = std::mem::take(&mut self.freqs);
            // Fails only while the thread's locals are destroyed: the buffer is then freed.
            let _ = KEPT_GRID.try_with(|kept| {
                let mut kept = kept.borrow_mut();
                if kept.capacity() < freqs.capacity() {
                    *kept = freqs;
                }
            });
        }
    }
}
