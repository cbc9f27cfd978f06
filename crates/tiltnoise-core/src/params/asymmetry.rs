//! The `[asymmetry]` section: how the pendulum as built departs from the drawing.
//!
//! Lab axes: z up, y along the crossbar arm that carries the test mass (which hangs at
//! `y = -d`), x = y cross z. Every offset is in the displaced body's own axes at the symmetric
//! reference (the crossbar's axes for the crossbar and the lower clamp, the test mass's for the
//! test mass), in metres; all default to 0, the ideal pendulum of the paper.
//!
//! * `crossbar_com_x_m`, `crossbar_com_y_m`: the crossbar's centre of mass displaced
//!   horizontally from its nominal point `(0, y_a, -Z_a)` below the lower end of the upper
//!   fibre (`y_a = d m_b / m_a`);
//! * `tm_com_x_m`, `tm_com_y_m`: the test mass's centre of mass displaced horizontally from its
//!   nominal point on the lower fibre's axis, `Z_b` below the lower fibre's clamp;
//! * `lower_attachment_x_m`, `lower_attachment_y_m`: the lower fibre's clamp displaced from
//!   `(0, -d)` on the crossbar;
//! * `sensor_rot_x_rad`, `sensor_rot_y_rad`, `sensor_rot_z_rad`: the readout's axes (the
//!   GRS's and the autocollimator's) turned from the lab axes by these angles, composed as the
//!   bodies' angles are (about x, then the new y, then the new z; eq. (matriceR)).
//!
//! Offsets move centres of mass only: the inertia tensors are those about the displaced centre
//! of mass in the body's axes, masses, lengths and fibre tensions stay nominal, and each body
//! stays rigid with the fibre above it (no rocking). The cube's geometric centre, which the
//! sensor reads, is fixed in the test mass on the lower fibre's axis, `h_c` below the nominal
//! centre of mass: a centre-of-mass offset does not move it. How the model uses them:
//! [`crate::geometry`].

use serde::{Deserialize, Serialize};

/// An offset may be at most this fraction of the length of the body it moves in (see
/// [`Asymmetry::limits`]): beyond it the centre of mass leaves the body, and the tilted
/// equilibrium is no longer a small departure from the drawing.
pub const MAX_OFFSET_FRACTION: f64 = 0.1;

/// Keys whose magnitude is below this (`2^-80`, about 8.3e-25 m or rad) are taken as a linear
/// response ([`Asymmetry::linear_split`]). Their effects on the transfer functions are of order
/// `key x 1e-11` and below: near the bottom of `f64`'s range subnormal numbers, where neither
/// `f64` nor double-double keeps relative precision, and below about 1e-28 already small enough
/// against the terms they are computed with to be taken for structural cancellations (by the
/// pole-zero factors for a readout rotation about x of 1e-30 rad, by the double-double
/// reference's solve for offsets along x of 1e-29 m). At `2^-80` the terms of second order in a
/// key are about `3e-19` of its first-order ones (`tests/it/tiny_asymmetry.rs` measures it),
/// far below `f64`'s rounding, and the key is far above those 1e-28.
pub const LINEAR_BELOW: f64 = 8.271806125530277e-25;

/// The largest rotation of the readout's axes from the lab axes (rad).
pub const MAX_SENSOR_ROT_RAD: f64 = 0.1;

/// Assembly asymmetries and readout misalignment (see the module docs). The whole section is
/// optional; every key defaults to 0.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Asymmetry {
    /// Crossbar centre of mass along the crossbar's x axis, from its nominal point (m).
    #[serde(default)]
    pub crossbar_com_x_m: f64,
    /// Crossbar centre of mass along the crossbar's y axis (the arm), from its nominal point (m).
    #[serde(default)]
    pub crossbar_com_y_m: f64,
    /// Test-mass centre of mass along the test mass's x axis, off the lower fibre's axis (m).
    #[serde(default)]
    pub tm_com_x_m: f64,
    /// Test-mass centre of mass along the test mass's y axis, off the lower fibre's axis (m).
    #[serde(default)]
    pub tm_com_y_m: f64,
    /// Lower fibre's clamp on the crossbar along x, from `(0, -d)` (m).
    #[serde(default)]
    pub lower_attachment_x_m: f64,
    /// Lower fibre's clamp on the crossbar along y, from `(0, -d)` (m).
    #[serde(default)]
    pub lower_attachment_y_m: f64,
    /// Readout axes turned about x (rad).
    #[serde(default)]
    pub sensor_rot_x_rad: f64,
    /// Readout axes turned about the new y (rad).
    #[serde(default)]
    pub sensor_rot_y_rad: f64,
    /// Readout axes turned about the new z (rad).
    #[serde(default)]
    pub sensor_rot_z_rad: f64,
}

/// The bound of one key, as [`Asymmetry::limits`] gives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OffsetLimit {
    /// Dotted key.
    pub key: &'static str,
    /// The value.
    pub value: f64,
    /// Its unit, `m` or `rad`.
    pub unit: &'static str,
    /// Largest allowed `|value|` (exclusive), in the key's unit.
    pub limit: f64,
    /// Why: the length it is a fraction of, e.g. `10 % of min(d, Z_a)`.
    pub reason: &'static str,
}

impl Asymmetry {
    /// Every key 0: the symmetric pendulum of the paper.
    pub fn is_zero(&self) -> bool {
        self.values().iter().all(|&v| v == 0.0)
    }

    /// True when some centre of mass or the lower clamp is displaced, i.e. the equilibrium
    /// differs from the drawing's (a readout rotation alone leaves it as drawn).
    pub fn moves_mass(&self) -> bool {
        self.values()[..6].iter().any(|&v| v != 0.0)
    }

    /// True when nothing breaks the mirror plane x = 0 of the bodies: no offset along x. The
    /// dynamics then keep the two decoupled blocks of the symmetric model ([`crate::model::Block`]).
    pub fn keeps_mirror_plane(&self) -> bool {
        self.crossbar_com_x_m == 0.0 && self.tm_com_x_m == 0.0 && self.lower_attachment_x_m == 0.0
    }

    /// The pendulum with tiny keys as a linear response: when some key is nonzero with
    /// `|value| < LINEAR_BELOW`, `(base, scaled, k)` with those keys set to 0 in `base` and
    /// multiplied by the exact power of two `2^k` in `scaled` (the largest of them then in
    /// `[LINEAR_BELOW / 2, LINEAR_BELOW)`, 2^-81 to 2^-80); the other keys as they are in both. A transfer
    /// function is then `H = H(base) + (H(scaled) - H(base)) 2^-k`, exact to far below any
    /// rounding (see [`LINEAR_BELOW`] and `docs/asymmetry.md`). `None` when no key is that
    /// small.
    pub fn linear_split(&self) -> Option<(Asymmetry, Asymmetry, i32)> {
        let values = self.values();
        let tiny = |v: f64| v != 0.0 && v.abs() < LINEAR_BELOW;
        let largest = values
            .iter()
            .copied()
            .filter(|&v| tiny(v))
            .map(f64::abs)
            .fold(0.0f64, f64::max);
        if largest == 0.0 {
            return None;
        }
        // 2^k largest in [LINEAR_BELOW / 2, LINEAR_BELOW): k from the exponents, exact.
        let mut k = (LINEAR_BELOW / largest).log2().floor() as i32;
        while largest * 2f64.powi(k) >= LINEAR_BELOW {
            k -= 1;
        }
        while largest * 2f64.powi(k + 1) < LINEAR_BELOW {
            k += 1;
        }
        let map = |f: &dyn Fn(f64) -> f64| {
            let v = values.map(|v| if tiny(v) { f(v) } else { v });
            Asymmetry {
                crossbar_com_x_m: v[0],
                crossbar_com_y_m: v[1],
                tm_com_x_m: v[2],
                tm_com_y_m: v[3],
                lower_attachment_x_m: v[4],
                lower_attachment_y_m: v[5],
                sensor_rot_x_rad: v[6],
                sensor_rot_y_rad: v[7],
                sensor_rot_z_rad: v[8],
            }
        };
        // v 2^k is exact: v is at least 2^-1074 and the product below 2^-80 (k <= 994).
        let scale = |v: f64| v * 2f64.powi(k.min(1023)) * 2f64.powi(k - k.min(1023));
        Some((map(&|_| 0.0), map(&scale), k))
    }

    /// The nine values in key order: crossbar x, y; test mass x, y; lower attachment x, y;
    /// sensor rotation x, y, z.
    pub fn values(&self) -> [f64; 9] {
        [
            self.crossbar_com_x_m,
            self.crossbar_com_y_m,
            self.tm_com_x_m,
            self.tm_com_y_m,
            self.lower_attachment_x_m,
            self.lower_attachment_y_m,
            self.sensor_rot_x_rad,
            self.sensor_rot_y_rad,
            self.sensor_rot_z_rad,
        ]
    }

    /// The bound of every key for the lengths `d`, `Z_a`, `Z_b` (m): an offset of a centre of
    /// mass below [`MAX_OFFSET_FRACTION`] of its body (the crossbar: `min(d, Z_a)`; the test
    /// mass: `Z_b`; the clamp on the arm: `d`), a readout rotation below
    /// [`MAX_SENSOR_ROT_RAD`].
    pub fn limits(&self, d_m: f64, z_a_m: f64, z_b_m: f64) -> [OffsetLimit; 9] {
        let f = MAX_OFFSET_FRACTION;
        let keys = [
            "asymmetry.crossbar_com_x_m",
            "asymmetry.crossbar_com_y_m",
            "asymmetry.tm_com_x_m",
            "asymmetry.tm_com_y_m",
            "asymmetry.lower_attachment_x_m",
            "asymmetry.lower_attachment_y_m",
            "asymmetry.sensor_rot_x_rad",
            "asymmetry.sensor_rot_y_rad",
            "asymmetry.sensor_rot_z_rad",
        ];
        let crossbar = (
            f * d_m.min(z_a_m),
            "10 % of min(d, Z_a), the crossbar's size",
        );
        let tm = (
            f * z_b_m,
            "10 % of Z_b, the test mass's length below its clamp",
        );
        let clamp = (f * d_m, "10 % of the arm d");
        let sensor = (MAX_SENSOR_ROT_RAD, "a small rotation of the readout's axes");
        let bounds = [
            crossbar, crossbar, tm, tm, clamp, clamp, sensor, sensor, sensor,
        ];
        let values = self.values();
        std::array::from_fn(|k| OffsetLimit {
            key: keys[k],
            value: values[k],
            unit: if k < 6 { "m" } else { "rad" },
            limit: bounds[k].0,
            reason: bounds[k].1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The split scales exactly the tiny keys by a power of two into `[2^-81, 2^-80)` and
    /// leaves the others.
    #[test]
    fn linear_split_scales_the_tiny_keys_by_a_power_of_two() {
        assert_eq!(LINEAR_BELOW, 2f64.powi(-80));
        assert_eq!(Asymmetry::default().linear_split(), None);
        let a = Asymmetry {
            tm_com_x_m: 5e-324,
            sensor_rot_z_rad: -1e-310,
            crossbar_com_y_m: 1e-4,
            ..Asymmetry::default()
        };
        let (base, scaled, k) = a.linear_split().unwrap();
        assert_eq!((base.tm_com_x_m, base.sensor_rot_z_rad), (0.0, 0.0));
        assert_eq!(
            (base.crossbar_com_y_m, scaled.crossbar_com_y_m),
            (1e-4, 1e-4)
        );
        assert_eq!(scaled.sensor_rot_z_rad.abs(), 1e-310 * 2f64.powi(k));
        assert!((LINEAR_BELOW / 2.0..LINEAR_BELOW).contains(&scaled.sensor_rot_z_rad.abs()));
        assert_eq!(scaled.tm_com_x_m, 2f64.powi(k - 1074));
        for v in [1e-25, 1e-150, 1e-300, 8.2e-25] {
            let b = Asymmetry {
                tm_com_x_m: v,
                ..Asymmetry::default()
            };
            let (_, s, k) = b.linear_split().unwrap();
            assert!(
                (LINEAR_BELOW / 2.0..LINEAR_BELOW).contains(&s.tm_com_x_m),
                "{v:e}: {k}"
            );
        }
    }

    #[test]
    fn classification() {
        let mut a = Asymmetry::default();
        assert!(a.is_zero() && !a.moves_mass() && a.keeps_mirror_plane());
        a.sensor_rot_z_rad = 1e-3;
        assert!(!a.is_zero() && !a.moves_mass() && a.keeps_mirror_plane());
        a.crossbar_com_y_m = 1e-3;
        assert!(a.moves_mass() && a.keeps_mirror_plane());
        a.lower_attachment_x_m = -1e-4;
        assert!(!a.keeps_mirror_plane());
    }
}
