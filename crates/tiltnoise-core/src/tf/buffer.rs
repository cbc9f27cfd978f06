//! Result buffers for transfer-function grids: zeroed `f64` vectors whose large allocations
//! are backed by transparent huge pages where the OS offers them.
//!
//! A grid result is written once, sequentially, and can be large (88 bytes per point for the
//! 7x3 tilt matrix in the pole-zero layout, 336 dense: 8.8 or 34 MB at 1e5 points), so memory
//! is a large part of its cost.
//! With 4 KiB pages every 4 KiB of output costs a TLB miss (a two-level page walk on a
//! virtual machine) and, on first touch, a page fault; with 2 MiB pages both happen 512 times
//! less often. On Linux, [`zeroed_f64`] asks for huge pages on the 2 MiB-aligned interior of
//! a large allocation with `madvise(MADV_HUGEPAGE)` before anything touches it (the default
//! THP policy of many distributions is `madvise`: huge pages only where asked for). NumPy does
//! the same for its large arrays. Elsewhere, or when the advice is refused, the buffer is an
//! ordinary zeroed vector: the advice changes speed only, never values. What it gains is
//! measured by `benches/methods.rs` (figures in `scripts/bench/README.md`, "Huge pages").

use num_complex::Complex64;

/// Allocations of at least this many bytes are advised to use huge pages: the advice only
/// applies to whole 2 MiB-aligned pages inside the allocation, so smaller buffers gain little.
pub const HUGE_PAGE_MIN_BYTES: usize = 4 << 20;

/// The huge-page size the advice aims at (x86_64 and aarch64 Linux with 4 KiB base pages).
const HUGE_PAGE_BYTES: usize = 2 << 20;

/// A vector of `len` zeros. `vec![0.0; len]` takes zeroed memory from the allocator (for a
/// large vector, fresh pages that nothing has touched yet); a large one
/// (4 MiB or more) is then advised, on Linux, to use transparent huge pages before
/// the first write (see the module docs).
pub fn zeroed_f64(len: usize) -> Vec<f64> {
    let v = vec![0.0; len];
    let bytes = std::mem::size_of_val(v.as_slice());
    if bytes >= HUGE_PAGE_MIN_BYTES {
        advise_huge_pages(v.as_ptr() as usize, bytes);
    }
    v
}

/// [`zeroed_f64`] for complex values: `len` zeros, huge pages advised when large.
#[allow(
    unsafe_code,
    reason = "reinterprets a zeroed f64 allocation as Complex64"
)]
pub fn zeroed_complex(len: usize) -> Vec<Complex64> {
    let mut v = std::mem::ManuallyDrop::new(zeroed_f64(2 * len));
    if v.capacity() != v.len() {
        // Not the exact allocation `vec!` makes today; never reinterpret another layout.
        return vec![Complex64::new(0.0, 0.0); len];
    }
    // SAFETY: the allocation holds exactly `2 len` f64 (capacity == length), allocated with
    // `Layout::array::<f64>(2 len)`: size `16 len`, alignment 8, the layout of
    // `Layout::array::<Complex64>(len)` (`Complex64` is `repr(C)` `{re: f64, im: f64}`, size
    // 16, alignment 8), so `Vec<Complex64>` may own and free it; every element is `0 + 0i`.
    // `v` is not dropped (ManuallyDrop), so the allocation has one owner.
    unsafe { Vec::from_raw_parts(v.as_mut_ptr().cast::<Complex64>(), len, len) }
}

/// `madvise(MADV_HUGEPAGE)` on the whole 2 MiB pages inside `[ptr, ptr + bytes)`; a refusal
/// (no THP in this kernel, policy `never`) is ignored: the pages stay ordinary.
#[cfg(target_os = "linux")]
#[allow(unsafe_code, reason = "madvise has no safe wrapper")]
fn advise_huge_pages(ptr: usize, bytes: usize) {
    let start = ptr.next_multiple_of(HUGE_PAGE_BYTES);
    let end = (ptr + bytes) / HUGE_PAGE_BYTES * HUGE_PAGE_BYTES;
    if end > start {
        // SAFETY: `[start, end)` lies inside one live allocation (page-aligned, as madvise
        // requires); MADV_HUGEPAGE changes how the range is backed, never its contents, so no
        // Rust-visible state changes.
        unsafe {
            libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise_huge_pages(_ptr: usize, _bytes: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_large_buffers_are_zero_and_usable() {
        for len in [
            0,
            1,
            7,
            HUGE_PAGE_MIN_BYTES / 8 - 1,
            3 * HUGE_PAGE_MIN_BYTES / 8 + 5,
        ] {
            let mut v = zeroed_f64(len);
            assert_eq!(v.len(), len);
            assert!(v.iter().all(|x| x.to_bits() == 0), "+0.0 everywhere");
            for (k, x) in v.iter_mut().enumerate() {
                *x = k as f64;
            }
            v.push(-1.0);
            assert_eq!(v[len], -1.0);
            if len > 0 {
                assert_eq!(v[len - 1], (len - 1) as f64);
            }
        }
    }

    #[test]
    fn complex_buffers_are_zero_and_usable() {
        for len in [0, 3, HUGE_PAGE_MIN_BYTES / 16 + 3] {
            let mut v = zeroed_complex(len);
            assert_eq!(v.len(), len);
            assert!(v.iter().all(|z| z.re.to_bits() == 0 && z.im.to_bits() == 0));
            v.push(Complex64::new(1.0, -1.0));
            assert_eq!(v[len], Complex64::new(1.0, -1.0));
        }
    }
}
