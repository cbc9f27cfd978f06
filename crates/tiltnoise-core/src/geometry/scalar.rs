//! The scalars the exact kinematics is written for: `f64` (the model), double-double (the
//! reference and the pole-zero method), and hyper-dual numbers over either, which carry exact
//! first and mixed second derivatives through the same code.

use crate::dd::{Dd, DD_EPS};
use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A real scalar: field operations, `sin` and `cos`, and conversion from `f64` (exact for
/// the parameters, which are `f64`).
pub trait Real:
    Copy
    + Debug
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Relative rounding error of one operation.
    const EPSILON: f64;
    /// The value of an `f64` (exact).
    fn from_f64(x: f64) -> Self;
    /// The nearest `f64` (of the value part, for a hyper-dual number).
    fn to_f64(self) -> f64;
    /// `(sin x, cos x)`.
    fn sin_cos(self) -> (Self, Self);
}

impl Real for f64 {
    const EPSILON: f64 = f64::EPSILON;
    fn from_f64(x: f64) -> f64 {
        x
    }
    fn to_f64(self) -> f64 {
        self
    }
    fn sin_cos(self) -> (f64, f64) {
        f64::sin_cos(self)
    }
}

impl Real for Dd {
    const EPSILON: f64 = DD_EPS;
    fn from_f64(x: f64) -> Dd {
        Dd::from_f64(x)
    }
    fn to_f64(self) -> f64 {
        Dd::to_f64(self)
    }
    /// Taylor series after halving the argument below 1/4 (the pendulum's angles are small,
    /// so the halving is rarely needed); each series stops once its terms are below
    /// `DD_EPS / 16` of the first, so the result is within a few `DD_EPS`.
    fn sin_cos(self) -> (Dd, Dd) {
        let mut x = self;
        let mut halvings = 0;
        while x.hi.abs() > 0.25 {
            x = x.ldexp(-1);
            halvings += 1;
        }
        let x2 = x * x;
        let (mut s, mut term) = (x, x);
        let mut k = 1.0;
        while term.hi.abs() > DD_EPS / 16.0 * x.hi.abs() {
            term = -(term * x2) / ((k + 1.0) * (k + 2.0));
            s += term;
            k += 2.0;
        }
        let (mut c, mut term) = (Dd::ONE, Dd::ONE);
        let mut k = 0.0;
        while term.hi.abs() > DD_EPS / 16.0 {
            term = -(term * x2) / ((k + 1.0) * (k + 2.0));
            c += term;
            k += 2.0;
        }
        for _ in 0..halvings {
            (s, c) = ((s * c).ldexp(1), c * c - s * s);
        }
        (s, c)
    }
}

/// A hyper-dual number `a + b e1 + c e2 + d e1 e2` with `e1^2 = e2^2 = 0`: `f(x + e1 + e2)`
/// carries `f(x)`, `f'(x)` twice and `f''(x)` exactly (no truncation), so a function seeded on
/// two variables yields a mixed second derivative in its `e1 e2` part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HyperDual<S> {
    /// Value.
    pub re: S,
    /// Derivative along the first seed.
    pub e1: S,
    /// Derivative along the second seed.
    pub e2: S,
    /// Mixed second derivative.
    pub e12: S,
}

impl<S: Real> HyperDual<S> {
    /// A constant.
    pub fn constant(x: S) -> Self {
        let z = S::from_f64(0.0);
        HyperDual {
            re: x,
            e1: z,
            e2: z,
            e12: z,
        }
    }

    /// A variable with value `x`, seeded along `e1` and/or `e2`.
    pub fn variable(x: S, e1: bool, e2: bool) -> Self {
        let (z, one) = (S::from_f64(0.0), S::from_f64(1.0));
        HyperDual {
            re: x,
            e1: if e1 { one } else { z },
            e2: if e2 { one } else { z },
            e12: z,
        }
    }

    /// `f(self)` from `f`, `f'`, `f''` at the value.
    fn chain(self, f: S, df: S, d2f: S) -> Self {
        HyperDual {
            re: f,
            e1: df * self.e1,
            e2: df * self.e2,
            e12: df * self.e12 + d2f * self.e1 * self.e2,
        }
    }
}

impl<S: Real> Add for HyperDual<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        HyperDual {
            re: self.re + o.re,
            e1: self.e1 + o.e1,
            e2: self.e2 + o.e2,
            e12: self.e12 + o.e12,
        }
    }
}

impl<S: Real> Sub for HyperDual<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        HyperDual {
            re: self.re - o.re,
            e1: self.e1 - o.e1,
            e2: self.e2 - o.e2,
            e12: self.e12 - o.e12,
        }
    }
}

impl<S: Real> Neg for HyperDual<S> {
    type Output = Self;
    fn neg(self) -> Self {
        HyperDual {
            re: -self.re,
            e1: -self.e1,
            e2: -self.e2,
            e12: -self.e12,
        }
    }
}

impl<S: Real> Mul for HyperDual<S> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        HyperDual {
            re: self.re * o.re,
            e1: self.re * o.e1 + self.e1 * o.re,
            e2: self.re * o.e2 + self.e2 * o.re,
            e12: self.re * o.e12 + self.e1 * o.e2 + self.e2 * o.e1 + self.e12 * o.re,
        }
    }
}

impl<S: Real> Div for HyperDual<S> {
    type Output = Self;
    /// `self * (1 / o)`, the reciprocal by the chain rule.
    fn div(self, o: Self) -> Self {
        let inv = S::from_f64(1.0) / o.re;
        let two = S::from_f64(2.0);
        self * o.chain(inv, -(inv * inv), two * inv * inv * inv)
    }
}

impl<S: Real> Real for HyperDual<S> {
    const EPSILON: f64 = S::EPSILON;
    fn from_f64(x: f64) -> Self {
        HyperDual::constant(S::from_f64(x))
    }
    fn to_f64(self) -> f64 {
        self.re.to_f64()
    }
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.re.sin_cos();
        (self.chain(s, c, -s), self.chain(c, -s, -c))
    }
}

/// A scalar with a running bound on its rounding error (Wilkinson's running error analysis):
/// `mag` is the sum of the magnitudes of the terms computed into `value`, so that `value` is
/// within a modest multiple (the depth of the computation) of `EPSILON mag` of its exact value.
/// An entry far below its `mag` is a cancellation; one within rounding of zero is a structural
/// zero of the exact computation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tracked<S> {
    /// The computed value.
    pub value: S,
    /// Sum of the magnitudes of the terms behind it.
    pub mag: f64,
}

impl<S: Real> Tracked<S> {
    /// An exact input.
    pub fn exact(value: S) -> Self {
        Tracked {
            value,
            mag: value.to_f64().abs(),
        }
    }

    /// `value`, or exactly 0 when it is within `depth EPSILON mag` of 0 (a structural zero
    /// blurred by rounding).
    pub fn cleaned(self, depth: f64) -> S {
        if self.value.to_f64().abs() <= depth * S::EPSILON * self.mag {
            S::from_f64(0.0)
        } else {
            self.value
        }
    }
}

impl<S: Real> Add for Tracked<S> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Tracked {
            value: self.value + o.value,
            mag: self.mag + o.mag,
        }
    }
}

impl<S: Real> Sub for Tracked<S> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Tracked {
            value: self.value - o.value,
            mag: self.mag + o.mag,
        }
    }
}

impl<S: Real> Neg for Tracked<S> {
    type Output = Self;
    fn neg(self) -> Self {
        Tracked {
            value: -self.value,
            mag: self.mag,
        }
    }
}

impl<S: Real> Mul for Tracked<S> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Tracked {
            value: self.value * o.value,
            mag: self.mag * o.mag,
        }
    }
}

impl<S: Real> Div for Tracked<S> {
    type Output = Self;
    /// The numerator's terms scaled by the divisor, plus the divisor's relative error carried
    /// into the quotient.
    fn div(self, o: Self) -> Self {
        let value = self.value / o.value;
        let d = o.value.to_f64().abs();
        Tracked {
            value,
            mag: self.mag / d + value.to_f64().abs() * (o.mag / d),
        }
    }
}

impl<S: Real> Real for Tracked<S> {
    const EPSILON: f64 = S::EPSILON;
    fn from_f64(x: f64) -> Self {
        Tracked::exact(S::from_f64(x))
    }
    fn to_f64(self) -> f64 {
        self.value.to_f64()
    }
    /// The function's own rounding plus the argument's, carried by the slope.
    fn sin_cos(self) -> (Self, Self) {
        let (s, c) = self.value.sin_cos();
        let (s64, c64) = (s.to_f64().abs(), c.to_f64().abs());
        (
            Tracked {
                value: s,
                mag: s64 + c64 * self.mag,
            },
            Tracked {
                value: c,
                mag: c64 + s64 * self.mag,
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Double-double sine and cosine against mpmath at 50 digits, each split into two doubles,
    /// generated by
    /// `for x in [0.0013157887, 0.3, -1.7]: X = mp.mpf(x); s, c = mp.sin(X), mp.cos(X);`
    /// `print(x, float(s), float(s - float(s)), float(c), float(c - float(c)))` with
    /// `mp.mp.dps = 50`. The halving path is taken at 0.3 and -1.7.
    #[test]
    fn dd_sin_cos_match_mpmath() {
        // (x, sin hi, sin lo, cos hi, cos lo); x = 0.0013157887, 0.3 and -1.7 rounded to f64.
        let cases = [
            (
                0.0013157887_f64,
                0.0013157883203292248,
                3.040854184121136e-20,
                0.9999991343501734,
                -3.423188900978877e-17,
            ),
            (
                0.3,
                0.29552020666133955,
                1.8315357276792536e-17,
                0.955336489125606,
                4.1935600297907467e-17,
            ),
            (
                -1.7,
                -0.9916648104524686,
                -5.077812604198573e-17,
                -0.12884449429552464,
                -3.6530675885303595e-18,
            ),
        ];
        for (x, s_hi, s_lo, c_hi, c_lo) in cases {
            let (s, c) = Dd::from_f64(x).sin_cos();
            for (got, want) in [
                (s, Dd::from_parts(s_hi, s_lo)),
                (c, Dd::from_parts(c_hi, c_lo)),
            ] {
                let err = (got - want).abs().to_f64() / want.abs().to_f64();
                assert!(
                    err < 64.0 * DD_EPS,
                    "x = {x}: {got:?} vs {want:?}, rel {err:e}"
                );
            }
        }
    }

    /// `f = x sin(x) / cos(y)` at (0.3, -0.7): every hyper-dual part against its closed form.
    #[test]
    fn hyper_dual_derivatives_are_exact() {
        let (x0, y0) = (0.3_f64, -0.7_f64);
        let f = |ex: (bool, bool), ey: (bool, bool)| {
            let x = HyperDual::variable(x0, ex.0, ex.1);
            let y = HyperDual::variable(y0, ey.0, ey.1);
            x * x.sin_cos().0 / y.sin_cos().1
        };
        let (sx, cx, sy, cy) = (x0.sin(), x0.cos(), y0.sin(), y0.cos());
        let close = |a: f64, b: f64| (a - b).abs() <= 8.0 * f64::EPSILON * b.abs();
        let fxy = f((true, false), (false, true));
        assert!(close(fxy.e12, (sx + x0 * cx) * sy / (cy * cy)));
        assert!(close(fxy.e1, (sx + x0 * cx) / cy));
        assert!(close(fxy.e2, x0 * sx * sy / (cy * cy)));
        let fxx = f((true, true), (false, false));
        assert!(close(fxx.e12, (2.0 * cx - x0 * sx) / cy));
    }
}
