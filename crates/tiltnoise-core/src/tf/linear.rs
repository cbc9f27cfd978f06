//! The pendulum as built with asymmetry keys at the edge of `f64`'s range, evaluated as its
//! linear response.
//!
//! An offset of 1e-300 m along x couples the blocks through entries of order `1e-300 x 1e-11`:
//! subnormal numbers, in which no `f64` method (and no double-double one) keeps relative
//! precision; the pole-zero factors' structural cancellations, decided against the rounding
//! scales of their terms, are then decided wrongly. Such a key is far below any length a
//! pendulum is built to, but it is a valid input and must give the right numbers.
//!
//! Below [`crate::params::asymmetry::LINEAR_BELOW`] (`2^-80`) a key's effect is linear to far
//! below any rounding, so the plan is built twice, on the pendulum without the tiny keys and on
//! the one with them multiplied by an exact power of two `2^k` (the largest into
//! `[2^-81, 2^-80)`, where every entry is a normal number), and evaluated as
//!
//! ```text
//! H = H(base) + (H(scaled) - H(base)) 2^-k,
//! ```
//!
//! with the scaling by `2^-k` exact (one rounding where the result is subnormal). The terms of
//! second order in the tiny keys are `2^-k` times their first-order terms at `scaled`, i.e.
//! below `1e-18` of them (see the constant). An entry that the tiny keys alone make nonzero is `H(scaled) 2^-k`;
//! one that the base already has is `H(base)` to its last bit when the keys' effect is below
//! its rounding.

use super::{Method, Request, TransferFunction};
use crate::error::TfError;
use num_complex::Complex64;

/// A plan evaluated as the linear response in its tiny asymmetry keys (see the module docs).
pub struct Linearized {
    pub(super) base: Box<dyn TransferFunction>,
    pub(super) scaled: Box<dyn TransferFunction>,
    /// The tiny keys of `scaled` are `2^k` times the model's.
    pub(super) k: i32,
}

impl TransferFunction for Linearized {
    fn method(&self) -> Method {
        self.base.method()
    }

    fn request(&self) -> &Request {
        self.base.request()
    }

    fn eval_into(&self, freq_hz: f64, out: &mut [Complex64]) -> Result<(), TfError> {
        self.base.eval_into(freq_hz, out)?;
        let mut scaled = vec![Complex64::new(0.0, 0.0); out.len()];
        self.scaled.eval_into(freq_hz, &mut scaled)?;
        // 2^-k in two exact steps (k <= 994).
        let (k1, k2) = (self.k / 2, self.k - self.k / 2);
        let (s1, s2) = (2f64.powi(-k1), 2f64.powi(-k2));
        for (h, s) in out.iter_mut().zip(&scaled) {
            let d = *s - *h;
            *h += Complex64::new(d.re * s1 * s2, d.im * s1 * s2);
        }
        Ok(())
    }
}
