//! The floor's motion given as displacement, velocity or acceleration: one typed conversion for
//! its spectra and for transfer functions.
//!
//! The model's ground inputs are displacements: the tilt angles (rad) and the floor's
//! translations (m). Instruments record their rates (rotation sensors: rad/s; seismometers: m/s)
//! or their second derivatives (accelerometers: m/s^2). With time dependence `exp(+i w t)`,
//! `w = 2 pi f`, a velocity has the amplitude `v = i w u` and an acceleration `a = -w^2 u`, so
//!
//! ```text
//! u = c q,   c = 1 (displacement), 1 / (i w) (velocity), -1 / w^2 (acceleration)
//! ```
//!
//! for a quantity `q` of the same axis. A one-sided PSD or CSD of the displacement is `|c|^2`
//! times that of `q` (the phases cancel when both channels carry the same quantity), and a
//! transfer function per unit `q` is `H_u c`: per unit floor acceleration, `H_u / (-w^2)`.
//!
//! **DC.** At `f = 0` a velocity or an acceleration carries no information on the displacement
//! (its constant is lost, and the mean of the rate is the displacement's trend): the factor does
//! not exist there and [`GroundQuantity::to_displacement`] returns `None`, never an infinite or
//! NaN value. Callers drop the bin (spectra) or refuse the point (transfer functions). Note that
//! a translation's transfer function per unit acceleration has a finite limit at f = 0 (every
//! response to a translation vanishes as `w^2`): that limit is
//! [`crate::model::translation::acceleration_limit`], not this conversion.

use num_complex::Complex64;

/// What a record or a spectrum of the floor's motion measures, per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GroundQuantity {
    /// The displacement itself: rad (tilt) or m (translation). What the model takes.
    Displacement,
    /// Its time derivative: rad/s or m/s.
    Velocity,
    /// Its second time derivative: rad/s^2 or m/s^2.
    Acceleration,
}

impl GroundQuantity {
    /// All three, displacement first.
    pub const ALL: [GroundQuantity; 3] = [
        GroundQuantity::Displacement,
        GroundQuantity::Velocity,
        GroundQuantity::Acceleration,
    ];

    /// `displacement`, `velocity` or `acceleration`.
    pub fn name(self) -> &'static str {
        match self {
            GroundQuantity::Displacement => "displacement",
            GroundQuantity::Velocity => "velocity",
            GroundQuantity::Acceleration => "acceleration",
        }
    }

    /// Parses [`GroundQuantity::name`].
    pub fn from_name(name: &str) -> Option<GroundQuantity> {
        GroundQuantity::ALL.into_iter().find(|q| q.name() == name)
    }

    /// The unit of this quantity for an input whose displacement unit is `unit` (`rad` or `m`):
    /// `m`, `m/s`, `m/s^2`.
    pub fn unit(self, unit: &str) -> String {
        match self {
            GroundQuantity::Displacement => unit.to_string(),
            GroundQuantity::Velocity => format!("{unit}/s"),
            GroundQuantity::Acceleration => format!("{unit}/s^2"),
        }
    }

    /// The factor `c` with `u = c q` at `f_hz` (see the module docs): 1, `1 / (i w)` or
    /// `-1 / w^2`. `None` for a velocity or an acceleration at `f = 0` (or a frequency that is
    /// not finite and positive), where it does not exist.
    pub fn to_displacement(self, f_hz: f64) -> Option<Complex64> {
        let w = crate::units::angular(f_hz);
        match self {
            GroundQuantity::Displacement => Some(Complex64::new(1.0, 0.0)),
            _ if !(f_hz > 0.0 && w.is_finite()) => None,
            GroundQuantity::Velocity => Some(Complex64::new(0.0, -1.0 / w)),
            GroundQuantity::Acceleration => Some(Complex64::new(-1.0 / (w * w), 0.0)),
        }
    }

    /// `|c|^2`: the factor that turns a one-sided PSD (or a CSD between channels of this same
    /// quantity) into that of the displacement. `None` where [`GroundQuantity::to_displacement`]
    /// is.
    pub fn psd_to_displacement(self, f_hz: f64) -> Option<f64> {
        self.to_displacement(f_hz).map(|c| c.norm_sqr())
    }

    /// A transfer function per unit displacement, `h_per_displacement`, expressed per unit of
    /// this quantity: `H_u c`. `None` where [`GroundQuantity::to_displacement`] is.
    pub fn per_unit(self, h_per_displacement: Complex64, f_hz: f64) -> Option<Complex64> {
        self.to_displacement(f_hz).map(|c| h_per_displacement * c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sinusoid `u = cos(w t)` has velocity `-w sin(w t)` and acceleration `-w^2 cos(w t)`:
    /// as complex amplitudes of `exp(+i w t)`, `1`, `i w` and `-w^2`. The factor turns each back
    /// into the displacement's amplitude 1, within one rounding per operation.
    #[test]
    fn factors_undo_the_derivatives_of_a_sinusoid() {
        for f in [1e-4, 0.3, 17.0] {
            let w = crate::units::angular(f);
            let amplitudes = [
                (GroundQuantity::Displacement, Complex64::new(1.0, 0.0)),
                (GroundQuantity::Velocity, Complex64::new(0.0, w)),
                (GroundQuantity::Acceleration, Complex64::new(-w * w, 0.0)),
            ];
            for (q, amplitude) in amplitudes {
                let u = amplitude * q.to_displacement(f).unwrap();
                assert!(
                    (u - 1.0).norm() <= 4.0 * f64::EPSILON,
                    "{} at {f}: {u}",
                    q.name()
                );
                let psd = q.psd_to_displacement(f).unwrap() * amplitude.norm_sqr();
                assert!((psd - 1.0).abs() <= 8.0 * f64::EPSILON, "{}", q.name());
            }
        }
    }

    /// At DC, and at a frequency that is not finite and positive, a rate carries no
    /// displacement: `None`, never an infinite factor. A displacement passes unchanged.
    #[test]
    fn no_factor_at_dc() {
        for f in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(GroundQuantity::Velocity.to_displacement(f), None);
            assert_eq!(GroundQuantity::Acceleration.psd_to_displacement(f), None);
        }
        assert_eq!(
            GroundQuantity::Displacement.per_unit(Complex64::new(2.0, -1.0), 0.0),
            Some(Complex64::new(2.0, -1.0))
        );
    }

    #[test]
    fn names_and_units() {
        for q in GroundQuantity::ALL {
            assert_eq!(GroundQuantity::from_name(q.name()), Some(q));
        }
        assert_eq!(GroundQuantity::Acceleration.unit("m"), "m/s^2");
        assert_eq!(GroundQuantity::Velocity.unit("rad"), "rad/s");
        assert_eq!(GroundQuantity::from_name("jerk"), None);
    }
}
