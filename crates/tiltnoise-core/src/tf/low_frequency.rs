//! The floor's columns of a transfer function at frequencies so low that `w^2` and its powers
//! leave the range of `f64`, per unit displacement, velocity or acceleration.
//!
//! Per unit of the floor's velocity or acceleration an entry is `H_u (i w)^-n` (`n` = 1, 2; see
//! [`crate::ground`]). At `f = 1e-200` Hz the factor `-1 / w^2` overflows and the translation's
//! `H_u`, which carries a factor `w^2`, underflows, although their product (the equivalence
//! principle's limit) is of order 1; at `f = 5e-324` Hz even `w = 2 pi f` is a subnormal that
//! holds one significant bit. No method evaluated in `f64` at such a frequency, followed by
//! a multiplication, gives the value.
//!
//! Below [`EXACT_BELOW_HZ`] every floor column is therefore taken from the entry's exact
//! product form ([`super::PoleZero::factors`], double-double), with its power of `w` kept apart:
//!
//! ```text
//! H_u (i w)^-n = i^-n  w^(2p - n)  [ g prod_j (z_j - s) / prod_k (lambda_k - s) ],   s = w^2,
//! ```
//!
//! where `p` is the multiplicity of the entry's zero at `s = 0`, an exact integer decided with
//! the structural cancellations in double-double. The bracket is a regular function of `s`
//! (its value at `s = 0` is the entry's low-frequency coefficient) and is evaluated in
//! double-double; `w` is split as `(2 pi m) 2^e` with `f = m 2^e`, `m` in [0.5, 1), so that
//! `w^(2p - n)` is a power of a number in [pi, 2 pi) times an exact power of two. The result is
//! rounded once to `f64` by an exact scaling by powers of two: a value within the range of
//! `f64` (a subnormal one included) comes out with one rounding, and one beyond it is refused
//! ([`TfError::Overflow`]) from the exact exponent, never returned as infinite or NaN.
//!
//! Above [`EXACT_BELOW_HZ`] the plan's own values are multiplied by `(i w)^-n`, as everywhere
//! else: there, `w^k` for every power `k <= 18` a method or the conversion forms is a normal
//! `f64`, so nothing underflows that the value needs.
//!
//! Viscous damping adds a term `i w C` that the product form (structural damping only) does
//! not hold: its relative effect on an entry is of order `w max_i(C_ii / K_ii)`, so for a model
//! with viscous coefficients the exact form is used only below the frequency where that is
//! below `f64`'s rounding ([`LowFrequency::exact_below_hz`]).

use super::{EntryFactors, PoleZero, Request};
use crate::dd::{CDd, Dd};
use crate::error::TfError;
use crate::ground::GroundQuantity;
use crate::model::Model;
use num_complex::Complex64;

/// Below this frequency (Hz) the floor's columns come from the exact product form (see the
/// module docs): `w = 2 pi 1e-16 rad/s`, whose 18th power, `2e-290`, is still a normal `f64`.
pub const EXACT_BELOW_HZ: f64 = 1e-16;

/// One entry's exact form: `H = gain s^power prod(z_j - s) / prod(lambda_k - s)`.
#[derive(Debug, Clone)]
struct Form {
    at: usize,
    gain: CDd,
    power: u32,
    zeros: Vec<CDd>,
    poles: Vec<CDd>,
}

/// The exact low-frequency form of a request's floor columns (built once per plan).
#[derive(Debug, Clone)]
pub struct LowFrequency {
    request: Request,
    /// The forms of the floor entries that are not structurally zero.
    forms: Vec<Form>,
    exact_below_hz: f64,
}

/// `x 2^k` with one rounding: the steps of `2^±1000` that keep `x` normal first, the last step
/// (the only one that can round, into the subnormal range) last. Infinite when it overflows.
fn ldexp(mut x: f64, mut k: i64) -> f64 {
    while k > 1000 {
        x *= 2f64.powi(1000);
        k -= 1000;
        if x.is_infinite() {
            return x;
        }
    }
    while k < -1000 {
        x *= 2f64.powi(-1000);
        k += 1000;
    }
    // |k| <= 1000: 2^k is a normal f64.
    x * 2f64.powi(k as i32)
}

/// `x 2^k` for a double-double, in steps that stay exact while the parts are normal.
fn dd_ldexp(mut x: Dd, mut k: i64) -> Dd {
    while k.abs() > 1000 {
        let step = 1000 * k.signum();
        x = x.ldexp(step as i32);
        k -= step;
    }
    x.ldexp(k as i32)
}

/// `x = m 2^e` with `m` in [0.5, 1) for a finite positive `x` (subnormals included).
fn frexp(x: f64) -> (f64, i64) {
    debug_assert!(x > 0.0 && x.is_finite());
    // Bring a subnormal into the normal range first (exact).
    let (x, shift) = if x < f64::MIN_POSITIVE {
        (x * 2f64.powi(64), -64)
    } else {
        (x, 0)
    };
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1022;
    let m = f64::from_bits((bits & !(0x7ff << 52)) | (1022 << 52));
    (m, e + shift)
}

impl LowFrequency {
    /// The exact forms of `request`'s floor columns on `model`.
    pub fn new(model: &Model, request: &Request) -> LowFrequency {
        let ground = request.inputs.iter().any(|i| i.is_ground());
        let factors: Vec<EntryFactors> = match ground {
            true => PoleZero::factors(model.params(), request),
            false => Vec::new(),
        };
        let n_in = request.inputs.len();
        let forms = factors
            .into_iter()
            .filter(|f| request.inputs[f.input].is_ground())
            .map(|f| Form {
                at: f.output * n_in + f.input,
                gain: f.gain,
                power: f.power,
                zeros: f.zeros,
                poles: f.poles,
            })
            .collect();
        LowFrequency {
            request: request.clone(),
            forms,
            exact_below_hz: exact_below_hz(model),
        }
    }

    /// The frequency (Hz) below which the floor's columns are the exact form's:
    /// [`EXACT_BELOW_HZ`], lower for a model with viscous damping (see the module docs).
    pub fn exact_below_hz(&self) -> f64 {
        self.exact_below_hz
    }

    /// The request whose floor columns this converts.
    pub fn request(&self) -> &Request {
        &self.request
    }

    /// True when some frequency of `freqs_hz` lies below [`LowFrequency::exact_below_hz`],
    /// where even the values per unit displacement are the exact form's.
    pub fn applies_to(&self, freqs_hz: &[f64]) -> bool {
        self.request.inputs.iter().any(|i| i.is_ground())
            && freqs_hz.iter().any(|&f| f > 0.0 && f < self.exact_below_hz)
    }

    /// Converts one point's values `h` (row-major, the plan's, per unit displacement) at
    /// `freq_hz` to per unit `quantity` of the floor: below [`LowFrequency::exact_below_hz`]
    /// the floor columns are replaced by the exact form's, above they are multiplied by
    /// `(i w)^-n`. Force and torque columns are left as they are.
    ///
    /// # Errors
    ///
    /// [`TfError::NoGroundFactor`] at 0 Hz for a velocity or an acceleration;
    /// [`TfError::Overflow`] for an entry whose value is beyond the range of `f64`.
    ///
    /// # Panics
    ///
    /// If `h` does not hold one value per entry of the request.
    pub fn convert(
        &self,
        quantity: GroundQuantity,
        freq_hz: f64,
        h: &mut [Complex64],
    ) -> Result<(), TfError> {
        let n_in = self.request.inputs.len();
        assert_eq!(
            h.len(),
            self.request.outputs.len() * n_in,
            "one value per entry"
        );
        let ground = |at: usize| self.request.inputs[at % n_in].is_ground();
        let n = match quantity {
            GroundQuantity::Displacement => 0,
            GroundQuantity::Velocity => 1,
            GroundQuantity::Acceleration => 2,
        };
        let no_factor = TfError::NoGroundFactor {
            quantity: quantity.name(),
            freq_hz,
        };
        if n > 0 && !(freq_hz > 0.0 && freq_hz.is_finite()) {
            return Err(no_factor);
        }
        if freq_hz > 0.0 && freq_hz < self.exact_below_hz {
            for (at, z) in h.iter_mut().enumerate() {
                if ground(at) {
                    *z = Complex64::new(0.0, 0.0);
                }
            }
            for form in &self.forms {
                h[form.at] = self.exact(form, quantity, n, freq_hz)?;
            }
            return Ok(());
        }
        if n == 0 {
            return Ok(());
        }
        let c = quantity.to_displacement(freq_hz).ok_or(no_factor)?;
        for (at, z) in h.iter_mut().enumerate() {
            if ground(at) {
                let value = *z * c;
                if !(value.re.is_finite() && value.im.is_finite()) {
                    return Err(self.overflow(at, quantity, freq_hz, None));
                }
                *z = value;
            }
        }
        Ok(())
    }

    /// `H_u (i w)^-n` of `form` at `freq_hz` (> 0), rounded once (see the module docs).
    fn exact(
        &self,
        form: &Form,
        quantity: GroundQuantity,
        n: i64,
        freq_hz: f64,
    ) -> Result<Complex64, TfError> {
        let (mf, ef) = frexp(freq_hz);
        // w = wm 2^ef exactly up to the rounding of wm (2 pi mf in double-double).
        let wm = Dd::PI.ldexp(1) * Dd::from_f64(mf);
        // s = w^2, which may underflow to 0 where every s / z is far below rounding.
        let s = CDd::real(dd_ldexp(wm * wm, 2 * ef));
        let mut r = form.gain;
        for &z in &form.zeros {
            r = r * (z - s);
        }
        for &lambda in &form.poles {
            r = r / (lambda - s);
        }
        let m = 2 * i64::from(form.power) - n;
        // wm^m: |m| <= 18, wm in [pi, 2 pi).
        let mut wpow = CDd::real(Dd::ONE);
        for _ in 0..m.unsigned_abs() {
            wpow = wpow.scale(wm);
        }
        let r = if m >= 0 { r * wpow } else { r / wpow };
        // i^-n: 1, -i, -1.
        let r = match n {
            0 => r,
            1 => CDd::new(r.im, -r.re),
            _ => -r,
        };
        let (re, im) = (r.re.to_f64(), r.im.to_f64());
        let big = re.abs().max(im.abs());
        if big == 0.0 {
            return Ok(Complex64::new(0.0, 0.0));
        }
        // Scale the mantissa to [0.5, 1) first, so that only the final step rounds.
        let (_, er) = frexp(big);
        let k = er + ef * m;
        let (re, im) = (dd_ldexp(r.re, -er).to_f64(), dd_ldexp(r.im, -er).to_f64());
        let value = Complex64::new(ldexp(re, k), ldexp(im, k));
        if !(value.re.is_finite() && value.im.is_finite()) {
            // log10 |H| from the exact exponent.
            let log10 = (re.hypot(im)).log10() + k as f64 * std::f64::consts::LOG10_2;
            return Err(self.overflow(form.at, quantity, freq_hz, Some(log10)));
        }
        Ok(value)
    }

    fn overflow(
        &self,
        at: usize,
        quantity: GroundQuantity,
        freq_hz: f64,
        log10: Option<f64>,
    ) -> TfError {
        let n_in = self.request.inputs.len();
        let (output, input) = (
            self.request.outputs[at / n_in],
            self.request.inputs[at % n_in],
        );
        let unit = input.unit();
        TfError::Overflow {
            freq_hz,
            entry: format!("{}/{}", output.name(), input.name()),
            per: format!("{} ({})", quantity.name(), quantity.unit(unit)),
            log10_magnitude: log10,
        }
    }
}

/// [`EXACT_BELOW_HZ`], or the frequency below which `w max_i(C_ii / K_ii)` is below `f64`'s
/// rounding, if lower.
fn exact_below_hz(model: &Model) -> f64 {
    let (c, k) = (model.damping(), model.stiffness());
    let tau = (0..8)
        .filter(|&i| k[(i, i)] > 0.0)
        .map(|i| c[(i, i)].abs() / k[(i, i)])
        .fold(0.0f64, f64::max);
    match tau > 0.0 {
        true => EXACT_BELOW_HZ.min(f64::EPSILON / (std::f64::consts::TAU * tau)),
        false => EXACT_BELOW_HZ,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frexp_and_ldexp_are_exact() {
        for x in [
            5e-324,
            1e-310,
            f64::MIN_POSITIVE,
            1e-300,
            0.75,
            1.0,
            3.0,
            1e300,
        ] {
            let (m, e) = frexp(x);
            assert!((0.5..1.0).contains(&m), "{x:e}: {m}");
            assert_eq!(ldexp(m, e), x, "{x:e}");
        }
        assert_eq!(ldexp(1.0, 1024), f64::INFINITY);
        assert_eq!(ldexp(1.0, -1074), 5e-324);
        assert_eq!(ldexp(1.0, -1076), 0.0);
        // One rounding into the subnormal range: 0.75 2^-1073 = 1.5 ulp rounds to even, 2 ulp.
        assert_eq!(ldexp(0.75, -1073), 2.0 * 5e-324);
    }
}
