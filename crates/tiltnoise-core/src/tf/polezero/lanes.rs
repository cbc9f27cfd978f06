//! [`LANES`] `f64` lanes for the pole-zero kernel: a portable array and, on x86_64, two AVX
//! registers.
//!
//! Both implement the same IEEE operations lane by lane (addition, subtraction, multiplication,
//! division, `abs`, ordered comparisons), each correctly rounded, so a kernel written once over
//! [`Lanes`] gives bit-identical results with either. Explicit AVX instructions rather than
//! the compiler's vectorizer: on the kernel's loops the vectorizer kept scalar code (it sank
//! the per-lane products into the stores of the last, partial chunk). Eight lanes rather than
//! four: the per-entry work that does not depend on the frequency (loading the factors,
//! loop control) is shared by twice as many frequencies.

/// Lanes per [`Lanes`] value: frequencies per chunk of the kernel.
pub(super) const LANES: usize = 8;

/// [`LANES`] `f64` lanes.
pub(super) trait Lanes: Copy {
    fn splat(x: f64) -> Self;
    fn from_array(a: [f64; LANES]) -> Self;
    fn to_array(self) -> [f64; LANES];
    fn load(src: &[f64; LANES]) -> Self;
    fn store(self, dst: &mut [f64; LANES]);
    fn add(self, o: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn mul(self, o: Self) -> Self;
    fn div(self, o: Self) -> Self;
    fn abs(self) -> Self;
    /// Whether `self < o` in some lane (false for NaN, as `f64`'s `<`).
    fn any_lt(self, o: Self) -> bool;
    /// Whether every lane is finite and >= 0 (`0 <= x < inf`).
    fn all_finite_nonneg(self) -> bool;
    /// Copies `src` into `dst` (same length) with non-temporal stores where the alignment of
    /// `dst` allows (else ordinary ones): the destination's cache lines are written without
    /// being read first and without evicting the cache, for outputs much larger than the
    /// cache, where ordinary stores first read every line from memory. Call [`stream_fence`]
    /// before the data is handed over.
    fn stream_copy(dst: &mut [f64], src: &[f64]);
}

/// Portable lanes: plain `f64` arithmetic.
#[derive(Clone, Copy)]
pub(super) struct Portable([f64; LANES]);

impl Lanes for Portable {
    #[inline(always)]
    fn splat(x: f64) -> Self {
        Portable([x; LANES])
    }
    #[inline(always)]
    fn from_array(a: [f64; LANES]) -> Self {
        Portable(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f64; LANES] {
        self.0
    }
    #[inline(always)]
    fn load(src: &[f64; LANES]) -> Self {
        Portable(*src)
    }
    #[inline(always)]
    fn store(self, dst: &mut [f64; LANES]) {
        *dst = self.0;
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Portable(std::array::from_fn(|l| self.0[l] + o.0[l]))
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Portable(std::array::from_fn(|l| self.0[l] - o.0[l]))
    }
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Portable(std::array::from_fn(|l| self.0[l] * o.0[l]))
    }
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Portable(std::array::from_fn(|l| self.0[l] / o.0[l]))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Portable(self.0.map(f64::abs))
    }
    #[inline(always)]
    fn any_lt(self, o: Self) -> bool {
        (0..LANES).any(|l| self.0[l] < o.0[l])
    }
    #[inline(always)]
    fn all_finite_nonneg(self) -> bool {
        self.0.iter().all(|&x| (0.0..f64::INFINITY).contains(&x))
    }
    #[inline(always)]
    fn stream_copy(dst: &mut [f64], src: &[f64]) {
        assert_eq!(dst.len(), src.len());
        #[cfg(target_arch = "x86_64")]
        if (dst.as_ptr() as usize) % 16 == 0 {
            use std::arch::x86_64::{_mm_loadu_pd, _mm_stream_pd};
            let (pairs, rest) = (dst.len() / 2, dst.len() % 2);
            for k in 0..pairs {
                // SAFETY: SSE2 is part of x86_64. `dst[2k..2k + 2]` is valid for writes and
                // 16-byte aligned (`dst` is, and the offset is a multiple of 16 bytes);
                // `src[2k..2k + 2]` is valid for reads (unaligned load).
                unsafe {
                    _mm_stream_pd(
                        dst.as_mut_ptr().add(2 * k),
                        _mm_loadu_pd(src.as_ptr().add(2 * k)),
                    );
                }
            }
            if rest == 1 {
                dst[2 * pairs] = src[2 * pairs];
            }
            return;
        }
        dst.copy_from_slice(src);
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) use avx::{Avx, AvxToken};

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{Lanes, LANES};
    use std::arch::x86_64::{
        __m256d, _mm256_add_pd, _mm256_and_pd, _mm256_andnot_pd, _mm256_cmp_pd, _mm256_div_pd,
        _mm256_loadu_pd, _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_set1_pd,
        _mm256_storeu_pd, _mm256_stream_pd, _mm256_sub_pd, _mm_loadu_pd, _mm_stream_pd, _CMP_GE_OQ,
        _CMP_LT_OQ,
    };

    /// Proof that the running CPU has AVX: a value exists only once feature detection said so
    /// ([`AvxToken::try_new`]), and the kernel's safe AVX entry point requires one.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub(in super::super) struct AvxToken(());

    impl AvxToken {
        /// The token, if the running CPU has AVX.
        pub(in super::super) fn try_new() -> Option<Self> {
            std::arch::is_x86_feature_detected!("avx").then_some(AvxToken(()))
        }
    }

    /// Two AVX registers, lanes 0..4 and 4..8. Only the pole-zero kernel's AVX entry point (a
    /// `#[target_feature(enable = "avx")]` function, reached only through an [`AvxToken`])
    /// makes and uses values of this type; its methods are inlined there.
    #[derive(Clone, Copy)]
    pub(in super::super) struct Avx(__m256d, __m256d);

    impl Avx {
        #[inline(always)]
        fn map2(self, o: Self, f: impl Fn(__m256d, __m256d) -> __m256d) -> Self {
            Avx(f(self.0, o.0), f(self.1, o.1))
        }
    }

    // SAFETY (every `unsafe` block): AVX instructions; values of `Avx` exist only in code that
    // runs on a CPU with AVX (see the type's docs).
    impl Lanes for Avx {
        #[inline(always)]
        fn splat(x: f64) -> Self {
            let v = unsafe { _mm256_set1_pd(x) };
            Avx(v, v)
        }
        #[inline(always)]
        fn from_array(a: [f64; LANES]) -> Self {
            // SAFETY: `a` is eight readable f64 (unaligned loads).
            unsafe {
                Avx(
                    _mm256_loadu_pd(a.as_ptr()),
                    _mm256_loadu_pd(a.as_ptr().add(4)),
                )
            }
        }
        #[inline(always)]
        fn to_array(self) -> [f64; LANES] {
            let mut a = [0.0; LANES];
            // SAFETY: `a` is eight writable f64 (unaligned stores).
            unsafe {
                _mm256_storeu_pd(a.as_mut_ptr(), self.0);
                _mm256_storeu_pd(a.as_mut_ptr().add(4), self.1);
            }
            a
        }
        #[inline(always)]
        fn load(src: &[f64; LANES]) -> Self {
            Self::from_array(*src)
        }
        #[inline(always)]
        fn store(self, dst: &mut [f64; LANES]) {
            // SAFETY: `dst` is eight writable f64 (unaligned stores).
            unsafe {
                _mm256_storeu_pd(dst.as_mut_ptr(), self.0);
                _mm256_storeu_pd(dst.as_mut_ptr().add(4), self.1);
            }
        }
        #[inline(always)]
        fn add(self, o: Self) -> Self {
            self.map2(o, |a, b| unsafe { _mm256_add_pd(a, b) })
        }
        #[inline(always)]
        fn sub(self, o: Self) -> Self {
            self.map2(o, |a, b| unsafe { _mm256_sub_pd(a, b) })
        }
        #[inline(always)]
        fn mul(self, o: Self) -> Self {
            self.map2(o, |a, b| unsafe { _mm256_mul_pd(a, b) })
        }
        #[inline(always)]
        fn div(self, o: Self) -> Self {
            self.map2(o, |a, b| unsafe { _mm256_div_pd(a, b) })
        }
        #[inline(always)]
        fn abs(self) -> Self {
            // Clears the sign bit, as `f64::abs`.
            Avx::splat(-0.0).map2(self, |m, x| unsafe { _mm256_andnot_pd(m, x) })
        }
        #[inline(always)]
        fn any_lt(self, o: Self) -> bool {
            let lt = self.map2(o, |a, b| unsafe { _mm256_cmp_pd::<_CMP_LT_OQ>(a, b) });
            unsafe { _mm256_movemask_pd(_mm256_or_pd(lt.0, lt.1)) != 0 }
        }
        #[inline(always)]
        fn all_finite_nonneg(self) -> bool {
            // Ordered comparisons: false for NaN, as in the portable `contains`.
            let ge0 = self.map2(Avx::splat(0.0), |a, b| unsafe {
                _mm256_cmp_pd::<_CMP_GE_OQ>(a, b)
            });
            let lt_inf = self.map2(Avx::splat(f64::INFINITY), |a, b| unsafe {
                _mm256_cmp_pd::<_CMP_LT_OQ>(a, b)
            });
            let ok = ge0.map2(lt_inf, |a, b| unsafe { _mm256_and_pd(a, b) });
            unsafe { _mm256_movemask_pd(_mm256_and_pd(ok.0, ok.1)) == 0b1111 }
        }
        #[inline(always)]
        fn stream_copy(dst: &mut [f64], src: &[f64]) {
            assert_eq!(dst.len(), src.len());
            let d = dst.as_mut_ptr();
            if (d as usize) % 16 != 0 {
                dst.copy_from_slice(src);
                return;
            }
            let s = src.as_ptr();
            let n = dst.len();
            let mut k = 0;
            // SAFETY: `d` and `s` are valid for `n` f64; `k < n`, `k + 2 <= n`, `k + 4 <= n` or
            // `k + 8 <= n` before each access; the 16-byte stores are at
            // 16-byte aligned addresses (`d` is, and `k` is even), the 32-byte ones at 32-byte
            // aligned addresses (after the first 16-byte store if `d` is not).
            unsafe {
                if (d as usize) % 32 != 0 && n >= 2 {
                    _mm_stream_pd(d, _mm_loadu_pd(s));
                    k = 2;
                }
                // Two stores per iteration: the loop's overhead is half of the copy's work.
                while k + 8 <= n {
                    _mm256_stream_pd(d.add(k), _mm256_loadu_pd(s.add(k)));
                    _mm256_stream_pd(d.add(k + 4), _mm256_loadu_pd(s.add(k + 4)));
                    k += 8;
                }
                if k + 4 <= n {
                    _mm256_stream_pd(d.add(k), _mm256_loadu_pd(s.add(k)));
                    k += 4;
                }
                if k + 2 <= n {
                    _mm_stream_pd(d.add(k), _mm_loadu_pd(s.add(k)));
                    k += 2;
                }
                if k < n {
                    // An odd length's last value (a compact real layout).
                    *d.add(k) = *s.add(k);
                }
            }
        }
    }
}

/// Orders the non-temporal stores of [`Lanes::stream_copy`] before any later store (the data is then
/// visible to other threads as ordinary stores are).
#[inline(always)]
pub(super) fn stream_fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86_64.
    unsafe {
        std::arch::x86_64::_mm_sfence();
    }
}
