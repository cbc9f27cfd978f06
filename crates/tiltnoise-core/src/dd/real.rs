//! Double-double ("double-word") arithmetic: a real number as the unevaluated sum `hi + lo` of
//! two `f64` with `|lo| <= ulp(hi) / 2`, about 106 significant bits (~32 decimal digits).
//!
//! The algorithms are the error-free transformations `two_sum`, `fast_two_sum` and `two_prod`
//! (the latter with a fused multiply-add) and the double-word algorithms analysed by Joldes,
//! Muller and Popescu, *Tight and rigorous error bounds for basic building blocks of double-word
//! arithmetic*, ACM TOMS 44 (2017):
//!
//! | operation | algorithm | relative error bound (`u = 2^-53`) |
//! |---|---|---|
//! | `Dd + f64` | DWPlusFP (Alg. 4) | `2 u^2` |
//! | `Dd + Dd` | AccurateDWPlusDW (Alg. 6) | `3 u^2 + 13 u^3` |
//! | `Dd * f64` | DWTimesFP3 (Alg. 9) | `2 u^2` (exact for a power of two) |
//! | `Dd * Dd` | DWTimesDW3 (Alg. 12) | `4 u^2` |
//! | `Dd / Dd` | three-quotient long division (QD library's `accurate_div`) | a few `u^2` |
//! | `sqrt` | one Newton step on the f64 reciprocal square root (QD's `sqrt`) | a few `u^2` |
//!
//! [`DD_EPS`] = `2^-104 = 4 u^2` bounds every one of them; it is the "unit roundoff" used in the
//! error analyses of the reference evaluator. The exponent range is that of `f64`; nothing here
//! guards against overflow or underflow (the pendulum's numbers are far from both).

use std::cmp::Ordering;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// Bound on the relative error of one double-double operation: `2^-104` (about 4.9e-32).
pub const DD_EPS: f64 = 4.930380657631324e-32;

/// `s + e = a + b` exactly, with `s = fl(a + b)` (Knuth's TwoSum, no precondition).
#[inline]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// `s + e = a + b` exactly, with `s = fl(a + b)`, provided `|a| >= |b|` (or `a = 0`)
/// (Dekker's Fast2Sum).
#[inline]
pub fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let e = b - (s - a);
    (s, e)
}

/// `p + e = a * b` exactly, with `p = fl(a * b)` (the error term from a fused multiply-add).
#[inline]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    let e = a.mul_add(b, -p);
    (p, e)
}

/// A double-double number `hi + lo`, normalized so that `hi = fl(hi + lo)`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Dd {
    /// Leading part: the `f64` nearest to the value.
    pub hi: f64,
    /// Trailing part, `|lo| <= ulp(hi) / 2`.
    pub lo: f64,
}

/// High part of pi: `std::f64::consts::PI`.
pub const PI_HI: f64 = std::f64::consts::PI;
/// Low part of pi: `pi - PI_HI` rounded to `f64` (mpmath: `float(mp.pi - mp.mpf(math.pi))`).
pub const PI_LO: f64 = 1.2246467991473532e-16;

impl Dd {
    /// Zero.
    pub const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };
    /// One.
    pub const ONE: Dd = Dd { hi: 1.0, lo: 0.0 };
    /// Pi to about 107 bits.
    pub const PI: Dd = Dd {
        hi: PI_HI,
        lo: PI_LO,
    };

    /// The exact value of an `f64`.
    #[inline]
    pub const fn from_f64(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    /// Builds a normalized value from two `f64` of any relative size (exact).
    #[inline]
    pub fn from_parts(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_sum(a, b);
        Dd { hi, lo }
    }

    /// The exact product of two `f64`.
    #[inline]
    pub fn mul_f64_exact(a: f64, b: f64) -> Dd {
        let (hi, lo) = two_prod(a, b);
        Dd { hi, lo }
    }

    /// The `f64` nearest to `hi + lo` (correctly rounded: `fl(hi + lo)` of the exact sum).
    #[inline]
    pub fn to_f64(self) -> f64 {
        self.hi + self.lo
    }

    /// True for (positive or negative) zero.
    #[inline]
    pub fn is_zero(self) -> bool {
        self.hi == 0.0
    }

    /// True when both parts are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.hi.is_finite() && self.lo.is_finite()
    }

    /// Absolute value.
    #[inline]
    pub fn abs(self) -> Dd {
        if self.hi < 0.0 || (self.hi == 0.0 && self.lo < 0.0) {
            -self
        } else {
            self
        }
    }

    /// `self * self`.
    #[inline]
    pub fn sqr(self) -> Dd {
        self * self
    }

    /// Square root (NaN for negative arguments, 0 for 0).
    pub fn sqrt(self) -> Dd {
        if self.hi == 0.0 {
            return Dd::ZERO;
        }
        if self.hi < 0.0 {
            return Dd::from_f64(f64::NAN);
        }
        // x ~ 1/sqrt(a); ax ~ sqrt(a); one Newton correction (a - ax^2) x / 2 in double-double.
        let x = 1.0 / self.hi.sqrt();
        let ax = self.hi * x;
        let residual = self - Dd::mul_f64_exact(ax, ax);
        Dd::from_parts(ax, residual.hi * (x * 0.5))
    }

    /// `self * 2^k` (exact unless it overflows or underflows).
    #[inline]
    pub fn ldexp(self, k: i32) -> Dd {
        let s = 2f64.powi(k);
        Dd {
            hi: self.hi * s,
            lo: self.lo * s,
        }
    }
}

impl From<f64> for Dd {
    fn from(x: f64) -> Dd {
        Dd::from_f64(x)
    }
}

impl Neg for Dd {
    type Output = Dd;
    #[inline]
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Add for Dd {
    type Output = Dd;
    /// AccurateDWPlusDW (Joldes-Muller-Popescu Alg. 6).
    #[inline]
    fn add(self, y: Dd) -> Dd {
        let (sh, sl) = two_sum(self.hi, y.hi);
        let (th, tl) = two_sum(self.lo, y.lo);
        let c = sl + th;
        let (vh, vl) = fast_two_sum(sh, c);
        let w = tl + vl;
        let (hi, lo) = fast_two_sum(vh, w);
        Dd { hi, lo }
    }
}

impl Add<f64> for Dd {
    type Output = Dd;
    /// DWPlusFP (Alg. 4).
    #[inline]
    fn add(self, y: f64) -> Dd {
        let (sh, sl) = two_sum(self.hi, y);
        let v = self.lo + sl;
        let (hi, lo) = fast_two_sum(sh, v);
        Dd { hi, lo }
    }
}

impl Sub for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, y: Dd) -> Dd {
        self + (-y)
    }
}

impl Sub<f64> for Dd {
    type Output = Dd;
    #[inline]
    fn sub(self, y: f64) -> Dd {
        self + (-y)
    }
}

impl Mul for Dd {
    type Output = Dd;
    /// DWTimesDW3 (Alg. 12).
    #[inline]
    fn mul(self, y: Dd) -> Dd {
        let (ch, cl1) = two_prod(self.hi, y.hi);
        let tl0 = self.lo * y.lo;
        let tl1 = self.hi.mul_add(y.lo, tl0);
        let cl2 = self.lo.mul_add(y.hi, tl1);
        let cl3 = cl1 + cl2;
        let (hi, lo) = fast_two_sum(ch, cl3);
        Dd { hi, lo }
    }
}

impl Mul<f64> for Dd {
    type Output = Dd;
    /// DWTimesFP3 (Alg. 9).
    #[inline]
    fn mul(self, y: f64) -> Dd {
        let (ch, cl1) = two_prod(self.hi, y);
        let cl3 = self.lo.mul_add(y, cl1);
        let (hi, lo) = fast_two_sum(ch, cl3);
        Dd { hi, lo }
    }
}

impl Div for Dd {
    type Output = Dd;
    /// Long division with three f64 quotient digits (QD's `accurate_div`).
    #[inline]
    fn div(self, y: Dd) -> Dd {
        let q1 = self.hi / y.hi;
        let r = self - y * q1;
        let q2 = r.hi / y.hi;
        let r = r - y * q2;
        let q3 = r.hi / y.hi;
        let (q1, q2) = fast_two_sum(q1, q2);
        Dd { hi: q1, lo: q2 } + q3
    }
}

impl Div<f64> for Dd {
    type Output = Dd;
    #[inline]
    fn div(self, y: f64) -> Dd {
        self / Dd::from_f64(y)
    }
}

impl AddAssign for Dd {
    #[inline]
    fn add_assign(&mut self, y: Dd) {
        *self = *self + y;
    }
}

impl SubAssign for Dd {
    #[inline]
    fn sub_assign(&mut self, y: Dd) {
        *self = *self - y;
    }
}

impl MulAssign for Dd {
    #[inline]
    fn mul_assign(&mut self, y: Dd) {
        *self = *self * y;
    }
}

impl PartialOrd for Dd {
    /// Lexicographic on (hi, lo), which is the order of the values for normalized numbers.
    fn partial_cmp(&self, other: &Dd) -> Option<Ordering> {
        match self.hi.partial_cmp(&other.hi)? {
            Ordering::Equal => self.lo.partial_cmp(&other.lo),
            ord => Some(ord),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(m, e)` with `x = m 2^e` exactly, `m` an integer.
    fn decompose(x: f64) -> (i128, i32) {
        if x == 0.0 {
            return (0, 0);
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        let frac = (bits & ((1u64 << 52) - 1)) as i128;
        let (m, e) = if exp == 0 {
            (frac, -1074)
        } else {
            (frac | (1i128 << 52), exp - 1075)
        };
        // Strip trailing zero bits: the exponent is then the value's true granularity.
        let tz = m.trailing_zeros() as i32;
        let (m, e) = (m >> tz, e + tz);
        (if x < 0.0 { -m } else { m }, e)
    }

    /// `x 2^-e` as an exact integer (panics if it is not one or does not fit).
    fn scaled(x: f64, e: i32) -> i128 {
        let (m, ex) = decompose(x);
        if m == 0 {
            return 0;
        }
        let shift = ex - e;
        assert!((0..127).contains(&shift), "shift {shift} out of range");
        m.checked_mul(1i128 << shift)
            .unwrap_or_else(|| panic!("{x:e} x 2^{} does not fit in i128", -e))
    }

    /// `(hi + lo) 2^-e` exactly.
    fn scaled_dd(x: Dd, e: i32) -> i128 {
        scaled(x.hi, e) + scaled(x.lo, e)
    }

    #[test]
    fn error_free_transformations_are_exact() {
        // Rational check in i128: s + e == a + b and p + e == a b exactly.
        let cases = [
            (1.0, 1e-20),
            (0.1, 0.2),
            (1.0 / 3.0, -2.0 / 7.0),
            (1.2345678901234567, 9.876543210987654e-3),
            (-8.13e-3, 2.76e-4),
        ];
        for (a, b) in cases {
            let e_min = decompose(a).1.min(decompose(b).1);
            let (s, e) = two_sum(a, b);
            assert_eq!(s, a + b);
            let lo = e_min.min(if e == 0.0 { e_min } else { decompose(e).1 });
            assert_eq!(
                scaled(s, lo) + scaled(e, lo),
                scaled(a, lo) + scaled(b, lo),
                "two_sum({a}, {b})"
            );
            let (p, e) = two_prod(a, b);
            assert_eq!(p, a * b);
            let (ma, ea) = decompose(a);
            let (mb, eb) = decompose(b);
            let ep = ea + eb;
            assert_eq!(
                scaled(p, ep) + if e == 0.0 { 0 } else { scaled(e, ep) },
                ma * mb,
                "two_prod({a}, {b})"
            );
        }
    }

    #[test]
    fn one_third_times_three_is_one() {
        let third = Dd::ONE / Dd::from_f64(3.0);
        let back = third * Dd::from_f64(3.0);
        assert!((back - Dd::ONE).abs().to_f64() <= 1e-31, "{back:?}");
        // Exact rational check: |3 (hi + lo) - 1| in units of 2^-120, bounded by 2^-104.
        let e = -120;
        let err = 3 * scaled_dd(third, e) - (1i128 << 120);
        assert!(err.abs() <= 1i128 << 16, "3 x (1/3) - 1 = {err} x 2^-120");
    }

    #[test]
    fn division_of_integers_is_correct_to_dd_precision() {
        // |b q - a| <= 2^-104 |a| checked exactly in i128.
        for (a, b) in [
            (1.0, 7.0),
            (22.0, 7.0),
            (2.0, 3.0),
            (1.0, 10.0),
            (355.0, 113.0),
        ] {
            let q = Dd::from_f64(a) / Dd::from_f64(b);
            let e = decompose(q.hi).1 - 60;
            let err = (b as i128) * scaled_dd(q, e) - scaled(a, e);
            let bound = scaled(a, e) >> 104;
            assert!(
                err.abs() <= bound.max(1),
                "{a}/{b}: residual {err} > {bound}"
            );
        }
    }

    #[test]
    fn values_match_mpmath() {
        // Generated with mpmath 1.3.0 (mp.dps = 50):
        //   from mpmath import mp; mp.dps = 50
        //   def dd(x): hi = float(x); return hi, float(x - hi)
        //   dd(mp.sqrt(2)); dd(mp.mpf(1)/7); dd(mp.pi); dd(2*mp.pi*mp.mpf(0.4150390625));
        //   dd(mp.sqrt(mp.mpf(0.11)))
        let sqrt2 = Dd {
            hi: std::f64::consts::SQRT_2,
            lo: -9.667293313452913e-17,
        };
        let seventh = Dd {
            hi: 0.14285714285714285,
            lo: 7.93016446160826e-18,
        };
        // mpmath's pi: hi is exactly std's PI, lo the PI_LO literal.
        let pi = Dd {
            hi: std::f64::consts::PI,
            lo: 1.2246467991473532e-16,
        };
        let w = Dd {
            hi: 2.6077673394055902,
            lo: -1.550838225622188e-16,
        };
        let sqrt011 = Dd {
            hi: 0.33166247903553997,
            lo: 1.5852348315086713e-17,
        };
        let close = |got: Dd, want: Dd, what: &str| {
            let rel = ((got - want) / want).abs().to_f64();
            assert!(rel <= 2.0 * DD_EPS, "{what}: rel error {rel:e}");
        };
        close(Dd::from_f64(2.0).sqrt(), sqrt2, "sqrt 2");
        close(Dd::ONE / Dd::from_f64(7.0), seventh, "1/7");
        assert_eq!(Dd::PI, pi);
        close(Dd::PI * 2.0 * 0.4150390625, w, "2 pi f");
        close(Dd::from_f64(0.11).sqrt(), sqrt011, "sqrt 0.11");
        // sqrt(2)^2 == 2 to DD precision.
        let two = Dd::from_f64(2.0).sqrt().sqr();
        assert!((two - 2.0).abs().to_f64() <= 4.0 * DD_EPS, "{two:?}");
    }

    #[test]
    fn identities_and_ordering() {
        let a = Dd::from_f64(0.1) / Dd::from_f64(3.0);
        let b = Dd::PI.sqrt();
        // (a + b)^2 = a^2 + 2ab + b^2
        let lhs = (a + b).sqr();
        let rhs = a.sqr() + a * b * 2.0 + b.sqr();
        assert!(((lhs - rhs) / lhs).abs().to_f64() <= 8.0 * DD_EPS);
        // (a - b)(a + b) = a^2 - b^2
        let lhs = (a - b) * (a + b);
        let rhs = a.sqr() - b.sqr();
        assert!(((lhs - rhs) / lhs).abs().to_f64() <= 8.0 * DD_EPS);
        // Values differing only in lo are ordered.
        let x = Dd::from_parts(1.0, 1e-20);
        let y = Dd::from_parts(1.0, 2e-20);
        assert_eq!(x.partial_cmp(&y), Some(Ordering::Less));
        assert_eq!(y.partial_cmp(&x), Some(Ordering::Greater));
        assert_eq!((-y).partial_cmp(&-x), Some(Ordering::Less));
        assert_eq!(x.partial_cmp(&x), Some(Ordering::Equal));
        assert!(Dd::from_f64(1e-300) > Dd::ZERO);
        // Correct rounding to f64: 1 + 2^-53 (a tie) rounds to even, 1 + 2^-53 + tiny rounds up.
        assert_eq!(Dd::from_parts(1.0, 2f64.powi(-53)).to_f64(), 1.0);
        let above = Dd::from_parts(1.0, 2f64.powi(-53)) + 1e-30;
        assert_eq!(above.to_f64(), 1.0 + f64::EPSILON);
        assert!(Dd::from_f64(-4.0).sqrt().hi.is_nan());
        assert_eq!(Dd::ZERO.sqrt(), Dd::ZERO);
        assert_eq!(Dd::from_f64(3.0).ldexp(-2), Dd::from_f64(0.75));
    }
}
