//! Complex numbers with double-double parts.

use super::real::Dd;
use num_complex::Complex64;
use std::ops::{Add, AddAssign, Div, Mul, Neg, Sub, SubAssign};

/// A complex number `re + i im` with double-double parts.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CDd {
    /// Real part.
    pub re: Dd,
    /// Imaginary part.
    pub im: Dd,
}

impl CDd {
    /// Zero.
    pub const ZERO: CDd = CDd {
        re: Dd::ZERO,
        im: Dd::ZERO,
    };

    /// `re + i im`.
    #[inline]
    pub const fn new(re: Dd, im: Dd) -> CDd {
        CDd { re, im }
    }

    /// A real number.
    #[inline]
    pub const fn real(re: Dd) -> CDd {
        CDd { re, im: Dd::ZERO }
    }

    /// The exact value of a `Complex64`.
    #[inline]
    pub fn from_c64(z: Complex64) -> CDd {
        CDd::new(Dd::from_f64(z.re), Dd::from_f64(z.im))
    }

    /// Each part rounded to the nearest `f64`.
    #[inline]
    pub fn to_c64(self) -> Complex64 {
        Complex64::new(self.re.to_f64(), self.im.to_f64())
    }

    /// True when both parts are zero.
    #[inline]
    pub fn is_zero(self) -> bool {
        self.re.is_zero() && self.im.is_zero()
    }

    /// True when all four `f64` are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.re.is_finite() && self.im.is_finite()
    }

    /// Complex conjugate.
    #[inline]
    pub fn conj(self) -> CDd {
        CDd::new(self.re, -self.im)
    }

    /// `|z|^2` in double-double.
    #[inline]
    pub fn norm_sqr(self) -> Dd {
        self.re.sqr() + self.im.sqr()
    }

    /// `|z|` in double-double.
    #[inline]
    pub fn norm(self) -> Dd {
        self.norm_sqr().sqrt()
    }

    /// `|z|` to f64 accuracy (for pivoting and error estimates).
    #[inline]
    pub fn abs_f64(self) -> f64 {
        self.re.hi.hypot(self.im.hi)
    }

    /// Multiplication by a real double-double.
    #[inline]
    pub fn scale(self, s: Dd) -> CDd {
        CDd::new(self.re * s, self.im * s)
    }

    /// Multiplication by `2^k` (exact).
    #[inline]
    pub fn ldexp(self, k: i32) -> CDd {
        CDd::new(self.re.ldexp(k), self.im.ldexp(k))
    }
}

impl From<Dd> for CDd {
    fn from(re: Dd) -> CDd {
        CDd::real(re)
    }
}

impl Neg for CDd {
    type Output = CDd;
    #[inline]
    fn neg(self) -> CDd {
        CDd::new(-self.re, -self.im)
    }
}

impl Add for CDd {
    type Output = CDd;
    #[inline]
    fn add(self, w: CDd) -> CDd {
        CDd::new(self.re + w.re, self.im + w.im)
    }
}

impl Sub for CDd {
    type Output = CDd;
    #[inline]
    fn sub(self, w: CDd) -> CDd {
        CDd::new(self.re - w.re, self.im - w.im)
    }
}

impl Mul for CDd {
    type Output = CDd;
    #[inline]
    fn mul(self, w: CDd) -> CDd {
        // Real operands are common (undamped model): skip the products with an exact zero.
        if self.im.is_zero() && w.im.is_zero() {
            return CDd::real(self.re * w.re);
        }
        CDd::new(
            self.re * w.re - self.im * w.im,
            self.re * w.im + self.im * w.re,
        )
    }
}

impl Div for CDd {
    type Output = CDd;
    /// `z conj(w) / |w|^2`, with `w` first scaled by a power of two (exact) so that `|w|^2`
    /// can neither overflow nor underflow. Division by zero gives non-finite parts.
    #[inline]
    fn div(self, w: CDd) -> CDd {
        if w.im.is_zero() {
            return CDd::new(self.re / w.re, self.im / w.re);
        }
        let big = w.re.hi.abs().max(w.im.hi.abs());
        let k = if big > 0.0 && big.is_finite() {
            -(big.log2().round() as i32)
        } else {
            0
        };
        let ws = w.ldexp(k);
        let den = ws.norm_sqr();
        let num = self * ws.conj();
        CDd::new(num.re / den, num.im / den).ldexp(k)
    }
}

impl AddAssign for CDd {
    #[inline]
    fn add_assign(&mut self, w: CDd) {
        *self = *self + w;
    }
}

impl SubAssign for CDd {
    #[inline]
    fn sub_assign(&mut self, w: CDd) {
        *self = *self - w;
    }
}

#[cfg(test)]
mod tests {
    use super::super::real::DD_EPS;
    use super::*;

    fn c(re: f64, im: f64) -> CDd {
        CDd::new(Dd::from_f64(re), Dd::from_f64(im))
    }

    fn rel(got: CDd, want: CDd) -> f64 {
        ((got - want).norm() / want.norm()).to_f64()
    }

    #[test]
    fn arithmetic_on_exact_rationals() {
        // (1 + 2i)(3 + 4i) = -5 + 10i exactly.
        assert_eq!(c(1.0, 2.0) * c(3.0, 4.0), c(-5.0, 10.0));
        // (1 + 2i)/(3 + 4i) = (11 + 2i)/25.
        let q = c(1.0, 2.0) / c(3.0, 4.0);
        let want = CDd::new(
            Dd::from_f64(11.0) / Dd::from_f64(25.0),
            Dd::from_f64(2.0) / Dd::from_f64(25.0),
        );
        assert!(rel(q, want) <= 4.0 * DD_EPS, "{q:?}");
        // z / z = 1 and (z / w) w = z for awkward magnitudes.
        for (z, w) in [
            (c(1e-9, -3e-7), c(7.1e-9, 7.1e-12)),
            (c(1.0 / 3.0, 0.1), c(4804.0, 4.8)),
            (c(-2.0, 0.5), c(1e150, 1e149)),
        ] {
            assert!(rel(z / z, c(1.0, 0.0)) <= 8.0 * DD_EPS);
            assert!(rel((z / w) * w, z) <= 16.0 * DD_EPS);
        }
        assert_eq!(c(3.0, -4.0).norm_sqr(), Dd::from_f64(25.0));
        assert_eq!(c(3.0, -4.0).norm(), Dd::from_f64(5.0));
        assert_eq!(c(3.0, -4.0).abs_f64(), 5.0);
        assert!(c(0.0, 0.0).is_zero() && !c(0.0, 1e-300).is_zero());
        assert!(!(c(1.0, 0.0) / c(0.0, 0.0)).is_finite());
    }

    #[test]
    fn division_matches_mpmath() {
        // mpmath 1.3.0, mp.dps = 50:
        //   z = mp.mpc(0.1, -0.7) / mp.mpc(1.8e-6, 1.8e-9)
        //   dd = lambda x: (float(x), float(x - float(x))); dd(z.real), dd(z.imag)
        let q = c(0.1, -0.7) / c(1.8e-6, 1.8e-9);
        let want = CDd::new(
            Dd {
                hi: 55166.61150005517,
                lo: -4.537670686048371e-13,
            },
            Dd {
                hi: -388944.05550038896,
                lo: 2.3364476473584682e-11,
            },
        );
        assert!(rel(q, want) <= 4.0 * DD_EPS, "{q:?}");
    }
}
