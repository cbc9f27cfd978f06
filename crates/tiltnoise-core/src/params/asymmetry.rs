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
