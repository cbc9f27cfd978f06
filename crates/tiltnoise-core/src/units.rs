//! Unit aliases so that signatures read like physics. They are plain `f64`: documentation, not
//! type safety. Every quantity in the library is SI.

/// Frequency in hertz.
pub type Hz = f64;
/// Angular frequency in rad/s.
pub type RadPerSec = f64;
/// Angle in radians.
pub type Rad = f64;
/// Length in metres.
pub type Meter = f64;
/// Mass in kilograms.
pub type Kg = f64;
/// Moment of inertia in kg m^2.
pub type KgM2 = f64;

/// `2 pi f`: angular frequency of a frequency in hertz.
pub fn angular(freq: Hz) -> RadPerSec {
    std::f64::consts::TAU * freq
}
