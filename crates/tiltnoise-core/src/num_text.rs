//! Numbers as error messages and notes show them.

use std::fmt;

/// A number as messages show it: the shortest decimal that reads back to the same `f64`, in
/// exponent form when it would be long (`|x| >= 1e7` or `|x| < 1e-5`), so that a value such as
/// `1e300` never turns into 301 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl fmt::Display for Num {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x != 0.0 && x.is_finite() && !(1e-5..1e7).contains(&x.abs()) {
            write!(f, "{x:e}")
        } else {
            write!(f, "{x}")
        }
    }
}
