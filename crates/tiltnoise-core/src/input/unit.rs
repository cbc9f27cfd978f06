//! A channel's unit, and what it says the channel measures: a **rotation** sensor (ring laser,
//! rotation sensor, tiltmeter read as an angle) in `rad` (angle) or `rad/s` (rate), or a
//! **translation** sensor (seismometer, accelerometer, displacement sensor) in `m`
//! (displacement), `m/s` (velocity) or `m/s^2` (acceleration); each with an SI prefix (`c` for
//! metres only, `m`, `u` or `µ`, `n`, `p`). Or digitizer `counts`, which say nothing of the
//! quantity and need a scale factor.
//!
//! Also the bound on a series whose unit nobody states ([`unstated_rms_bound`]): it is taken in
//! rad or rad/s, which a record in microradians silently is not.

use super::Quantity;
use crate::error::Shown;
use crate::ground::GroundQuantity;
use std::fmt;
use std::str::FromStr;

/// What a channel's sensor measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motion {
    /// A rotation of the floor: an angle (rad) or its rate (rad/s).
    Rotation,
    /// A translation of the floor: a displacement (m), velocity (m/s) or acceleration (m/s^2).
    Translation,
}

impl Motion {
    /// `rotation` or `translation`.
    pub fn name(self) -> &'static str {
        match self {
            Motion::Rotation => "rotation",
            Motion::Translation => "translation",
        }
    }
}

/// A physical unit of a channel: the motion, which derivative of it, and the factor that turns
/// the channel's values into SI (rad, rad/s, m, m/s, m/s^2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unit {
    /// Rotation or translation.
    pub motion: Motion,
    /// Displacement (rad, m), velocity (rad/s, m/s) or acceleration (m/s^2).
    pub quantity: GroundQuantity,
    /// The SI prefix: values times `factor` are in [`Unit::si`].
    pub factor: f64,
}

/// The SI unit of `quantity` of a `motion`: `rad`, `rad/s`, `m`, `m/s`, `m/s^2` (`rad/s^2` is
/// no channel's).
pub fn si_unit(motion: Motion, quantity: GroundQuantity) -> &'static str {
    match (motion, quantity) {
        (Motion::Rotation, GroundQuantity::Displacement) => "rad",
        (Motion::Rotation, GroundQuantity::Velocity) => "rad/s",
        (Motion::Rotation, GroundQuantity::Acceleration) => "rad/s^2",
        (Motion::Translation, GroundQuantity::Displacement) => "m",
        (Motion::Translation, GroundQuantity::Velocity) => "m/s",
        (Motion::Translation, GroundQuantity::Acceleration) => "m/s^2",
    }
}

impl Unit {
    /// The SI unit of the channel's values after `factor`: `rad`, `rad/s`, `m`, `m/s`, `m/s^2`.
    pub fn si(&self) -> &'static str {
        si_unit(self.motion, self.quantity)
    }

    /// The tilt quantity of a rotation unit (angle or rate); `None` for a translation.
    pub fn tilt_quantity(&self) -> Option<Quantity> {
        match (self.motion, self.quantity) {
            (Motion::Rotation, GroundQuantity::Displacement) => Some(Quantity::Angle),
            (Motion::Rotation, _) => Some(Quantity::Rate),
            (Motion::Translation, _) => None,
        }
    }

    /// The unit of a tilt quantity, in SI.
    pub fn of_tilt(quantity: Quantity) -> Unit {
        Unit {
            motion: Motion::Rotation,
            quantity: match quantity {
                Quantity::Angle => GroundQuantity::Displacement,
                Quantity::Rate => GroundQuantity::Velocity,
            },
            factor: 1.0,
        }
    }
}

/// What a unit string says: a physical unit, or digitizer counts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ParsedUnit {
    /// A unit of angle, rate, length, velocity or acceleration.
    Physical(Unit),
    /// Digitizer counts: the quantity comes from elsewhere and a scale factor is required.
    Counts,
}

macro_rules! physical_units {
    () => {
        "rad, mrad, urad, nrad (angle); rad/s, mrad/s, urad/s, nrad/s (rate); m, cm, mm, um, nm \
         (displacement); m/s, mm/s, um/s, nm/s (velocity); m/s^2, mm/s^2, um/s^2, nm/s^2 \
         (acceleration)"
    };
}

/// The physical units a channel may be given, for messages.
pub const PHYSICAL_UNITS: &str = physical_units!();

/// The unit strings a file may state for a channel, for messages.
pub const UNITS_ALLOWED: &str = concat!(
    physical_units!(),
    "; or counts (with a scale factor for the channel)"
);

/// A unit string in a canonical spelling: no whitespace, lower case, `µ`/`μ` as `u`, `**` and
/// `²` as powers, the spellings of sqrt(Hz) as `sqrt(hz)`. So astropy's `nrad / s` and
/// `rad / (Hz(1/2) s)` are read as `nrad/s` and `rad/(sqrt(hz)s)`.
pub fn normalize_unit(unit: &str) -> String {
    unit.chars()
        .filter(|c| !c.is_whitespace())
        .collect::<String>()
        .to_ascii_lowercase()
        .replace(['\u{b5}', '\u{3bc}'], "u")
        .replace("**", "^")
        .replace('²', "^2")
        .replace("√hz", "sqrt(hz)")
        .replace("hz^0.5", "sqrt(hz)")
        .replace("hz^(1/2)", "sqrt(hz)")
        .replace("hz(1/2)", "sqrt(hz)")
}

/// The SI prefix of `p` for a base unit: `c` (metres only), `m`, `u`, `n`, `p`.
fn prefix_factor(p: &str, motion: Motion) -> Option<f64> {
    Some(match p {
        "" => 1.0,
        "c" if motion == Motion::Translation => 1e-2,
        "m" => 1e-3,
        "u" => 1e-6,
        "n" => 1e-9,
        "p" => 1e-12,
        _ => return None,
    })
}

/// Reads a channel's unit string (case and whitespace ignored, see [`normalize_unit`]): a
/// [`ParsedUnit`], or `None` for anything that is not a unit of angle, rate, length, velocity or
/// acceleration (an angular acceleration `rad/s^2` included: no sensor of the floor's rotation
/// gives one).
///
/// ```
/// use tiltnoise_core::ground::GroundQuantity;
/// use tiltnoise_core::input::{parse_unit, Motion, ParsedUnit};
/// let ParsedUnit::Physical(u) = parse_unit("nm / s^2").unwrap() else { panic!() };
/// assert_eq!((u.motion, u.quantity, u.factor), (Motion::Translation, GroundQuantity::Acceleration, 1e-9));
/// assert_eq!(parse_unit("µrad"), parse_unit("urad"));
/// assert_eq!(parse_unit("counts"), Some(ParsedUnit::Counts));
/// assert_eq!(parse_unit("rad/s^2"), None);
/// assert_eq!(parse_unit("deg"), None);
/// ```
pub fn parse_unit(text: &str) -> Option<ParsedUnit> {
    let n = normalize_unit(text);
    if matches!(n.as_str(), "counts" | "count" | "ct") {
        return Some(ParsedUnit::Counts);
    }
    let (numerator, quantity) = if let Some(a) = ["/s^2", "/s2", "/s/s"]
        .iter()
        .find_map(|d| n.strip_suffix(d))
    {
        (a, GroundQuantity::Acceleration)
    } else if let Some(v) = n.strip_suffix("/s") {
        (v, GroundQuantity::Velocity)
    } else {
        (n.as_str(), GroundQuantity::Displacement)
    };
    let (prefix, motion) = if let Some(p) = numerator.strip_suffix("rad") {
        (p, Motion::Rotation)
    } else if let Some(p) = numerator.strip_suffix('m') {
        (p, Motion::Translation)
    } else {
        return None;
    };
    if motion == Motion::Rotation && quantity == GroundQuantity::Acceleration {
        return None;
    }
    Some(ParsedUnit::Physical(Unit {
        motion,
        quantity,
        factor: prefix_factor(prefix, motion)?,
    }))
}

/// `CHANNEL=UNIT`: the unit of a source channel, for files that do not state it (miniSEED, CSV
/// without a `# units:` line, HDF5 datasets without a `units` attribute).
///
/// ```
/// use tiltnoise_core::input::{ChannelUnit, Motion};
/// let u: ChannelUnit = "LHE=m/s^2".parse().unwrap();
/// assert_eq!((u.channel.as_str(), u.unit.motion), ("LHE", Motion::Translation));
/// assert!("LHE=counts".parse::<ChannelUnit>().is_err());
/// assert!("LHE=furlong".parse::<ChannelUnit>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelUnit {
    /// The source channel (CSV column, HDF5 dataset, or SEED code `NET.STA.LOC.CHA` / `CHA`).
    pub channel: String,
    /// The unit as given.
    pub text: String,
    /// What it says.
    pub unit: Unit,
}

impl FromStr for ChannelUnit {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let syntax = "syntax: CHANNEL=UNIT, e.g. LHE=m/s^2 or LJE=rad/s";
        let Some((channel, text)) = s.split_once('=') else {
            return Err(format!("`{}` has no `=`; {syntax}", Shown(s)));
        };
        let (channel, text) = (channel.trim(), text.trim());
        if channel.is_empty() {
            return Err(format!("`{}` names no channel; {syntax}", Shown(s)));
        }
        match parse_unit(text) {
            Some(ParsedUnit::Physical(unit)) => Ok(ChannelUnit {
                channel: channel.to_string(),
                text: text.to_string(),
                unit,
            }),
            _ => Err(format!(
                "unit `{}` of channel `{}` is not allowed: must be a unit of angle, rate, length, \
                 velocity or acceleration: {PHYSICAL_UNITS} (counts take a scale factor \
                 instead)",
                Shown(text),
                Shown(channel),
            )),
        }
    }
}

impl fmt::Display for ChannelUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.channel, self.text)
    }
}

/// The largest detrended RMS (rad) of a tilt angle whose unit is not stated: 1e-2 rad, half a
/// degree. No laboratory floor tilts that much about its mean and trend (its tilt noise is
/// 1e-10 to 1e-5 rad), while a record in microradians or nanoradians read as radians exceeds
/// it by orders of magnitude as soon as it holds more than 10^4 urad of motion.
pub const UNSTATED_ANGLE_RMS_MAX_RAD: f64 = 1e-2;

/// The largest detrended RMS of a series whose unit is not stated, taken in the SI unit of
/// `quantity` and sampled at `sample_rate_hz`: [`UNSTATED_ANGLE_RMS_MAX_RAD`] for an angle; for
/// a rate, the most that an angle bounded by it can reach up to Nyquist, `pi fs` times it
/// (rad/s): a sinusoid of amplitude `A` at `f <= fs / 2` has the rate `2 pi f A <= pi fs A`.
pub fn unstated_rms_bound(quantity: Quantity, sample_rate_hz: f64) -> f64 {
    match quantity {
        Quantity::Angle => UNSTATED_ANGLE_RMS_MAX_RAD,
        Quantity::Rate => UNSTATED_ANGLE_RMS_MAX_RAD * std::f64::consts::PI * sample_rate_hz,
    }
}

/// What is wrong with a series whose unit nobody states and whose detrended RMS exceeds
/// [`unstated_rms_bound`]: the numbers each front end's message names.
#[derive(Debug, Clone, PartialEq)]
pub struct UnstatedExcess {
    /// The detrended RMS, read in the SI unit of the quantity.
    pub rms: f64,
    /// The bound it exceeds.
    pub bound: f64,
    /// The likely units, most likely first ([`likely_units`]); empty when even nrad is too
    /// large.
    pub likely: Vec<String>,
}

/// The excess of a series of `quantity` sampled at `sample_rate_hz` whose detrended RMS is
/// `rms` and whose unit nobody states, or `None` when it is within [`unstated_rms_bound`] (a
/// NaN RMS, of a series without finite samples, exceeds nothing).
pub fn unstated_excess(
    rms: f64,
    quantity: Quantity,
    sample_rate_hz: f64,
) -> Option<UnstatedExcess> {
    let bound = unstated_rms_bound(quantity, sample_rate_hz);
    (rms.partial_cmp(&bound) == Some(std::cmp::Ordering::Greater)).then(|| UnstatedExcess {
        rms,
        bound,
        likely: likely_units(rms, quantity, sample_rate_hz),
    })
}

/// The prefixed units (`urad`, `nrad`, or their rates) that would bring a detrended RMS of
/// `rms` (read as SI) under [`unstated_rms_bound`], most likely first: what the message of a
/// refused series suggests.
pub fn likely_units(rms: f64, quantity: Quantity, sample_rate_hz: f64) -> Vec<String> {
    let bound = unstated_rms_bound(quantity, sample_rate_hz);
    let suffix = match quantity {
        Quantity::Angle => "",
        Quantity::Rate => "/s",
    };
    [("urad", 1e-6), ("nrad", 1e-9)]
        .into_iter()
        .filter(|(_, f)| rms * f <= bound)
        .map(|(u, _)| format!("{u}{suffix}"))
        .collect()
}

/// The RMS of a series about its least-squares straight line, accumulated block by block in
/// one pass (the streaming reader checks a record it does not hold). Non-finite samples (gaps)
/// are left out of the fit. The index is centred and the first sample subtracted, so that an
/// offset or a trend large against the fluctuations costs no precision the bound check needs.
#[derive(Debug, Clone)]
pub struct DetrendedRms {
    mid: f64,
    pos: usize,
    origin: Option<f64>,
    count: f64,
    sum_k: f64,
    sum_kk: f64,
    sum_y: f64,
    sum_ky: f64,
    sum_yy: f64,
}

impl DetrendedRms {
    /// An accumulator for a series of `n` samples (the index is centred on its middle).
    pub fn new(n: usize) -> DetrendedRms {
        DetrendedRms {
            mid: (n as f64 - 1.0) / 2.0,
            pos: 0,
            origin: None,
            count: 0.0,
            sum_k: 0.0,
            sum_kk: 0.0,
            sum_y: 0.0,
            sum_ky: 0.0,
            sum_yy: 0.0,
        }
    }

    /// The next samples, in order (finite ones; others are skipped, as gaps).
    pub fn push(&mut self, block: &[f64]) {
        for &x in block {
            let k = self.pos as f64 - self.mid;
            self.pos += 1;
            if !x.is_finite() {
                continue;
            }
            let y = x - *self.origin.get_or_insert(x);
            self.count += 1.0;
            self.sum_k += k;
            self.sum_kk += k * k;
            self.sum_y += y;
            self.sum_ky += k * y;
            self.sum_yy += y * y;
        }
    }

    /// The RMS about the fitted line, over the finite samples (0 for fewer than 3).
    pub fn finish(&self) -> f64 {
        let m = self.count;
        if m < 3.0 {
            return 0.0;
        }
        let kk = self.sum_kk - self.sum_k * self.sum_k / m;
        let ky = self.sum_ky - self.sum_k * self.sum_y / m;
        let yy = self.sum_yy - self.sum_y * self.sum_y / m;
        let residual = if kk > 0.0 { yy - ky * ky / kk } else { yy };
        (residual.max(0.0) / m).sqrt()
    }

    /// [`DetrendedRms`] of a whole series.
    pub fn of(data: &[f64]) -> f64 {
        let mut acc = DetrendedRms::new(data.len());
        acc.push(data);
        acc.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::option_key::OptionKey;
    use crate::options::parse_keyed_items;

    #[test]
    fn units_say_what_they_measure() {
        let phys = |t: &str| match parse_unit(t) {
            Some(ParsedUnit::Physical(u)) => Some((u.motion, u.quantity, u.factor)),
            _ => None,
        };
        use GroundQuantity::*;
        use Motion::*;
        assert_eq!(phys(" RAD/s "), Some((Rotation, Velocity, 1.0)));
        assert_eq!(phys("nrad / s"), Some((Rotation, Velocity, 1e-9)));
        assert_eq!(phys("µrad"), Some((Rotation, Displacement, 1e-6)));
        assert_eq!(phys("m"), Some((Translation, Displacement, 1.0)));
        assert_eq!(phys("mm"), Some((Translation, Displacement, 1e-3)));
        assert_eq!(phys("cm/s"), Some((Translation, Velocity, 1e-2)));
        assert_eq!(phys("m/s**2"), Some((Translation, Acceleration, 1.0)));
        assert_eq!(phys("um/s/s"), Some((Translation, Acceleration, 1e-6)));
        assert_eq!(phys("nm/s2"), Some((Translation, Acceleration, 1e-9)));
        assert_eq!(phys("m/s²"), Some((Translation, Acceleration, 1.0)));
        for bad in [
            "deg", "krad", "rad/s/s", "crad", "km", "m/h", "g", "s", "", "rad/m",
        ] {
            assert_eq!(parse_unit(bad), None, "{bad}");
        }
        assert_eq!(parse_unit("Counts"), Some(ParsedUnit::Counts));
    }

    #[test]
    fn channel_units_are_parsed_once_per_channel() {
        let items = ["LHE=m/s^2", " LJE = rad/s"];
        let u: Vec<ChannelUnit> = parse_keyed_items(OptionKey::UNITS, "channel", &items).unwrap();
        assert_eq!(u[1].channel, "LJE");
        assert_eq!(u[1].unit.si(), "rad/s");
        let e = parse_keyed_items::<ChannelUnit, _>(
            OptionKey::UNITS,
            "channel",
            &["LHE=m/s^2", "LHE=m/s"],
        )
        .unwrap_err();
        assert_eq!(
            e.to_string(),
            "units: LHE is given twice; name each channel once"
        );
        let e = parse_keyed_items::<ChannelUnit, _>(OptionKey::UNITS, "channel", &["LJE=rad/s^2"])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("units: unit `rad/s^2` of channel `LJE`"),
            "{e}"
        );
    }

    /// A line `a + b k` plus a sinusoid of amplitude `c` has the detrended RMS `c / sqrt(2)`
    /// up to the part of the sinusoid the line fits (its correlation with a ramp is about
    /// `sqrt(6) / (pi m)` for `m` whole periods: 1.6 % for 50, 1.2e-4 of its variance),
    /// whatever the offset and the slope, and whatever the blocks it arrives in.
    #[test]
    fn detrended_rms_ignores_offset_and_trend() {
        let n = 10_000;
        let c = 2e-9;
        let x: Vec<f64> = (0..n)
            .map(|k| {
                3e-3 + 1e-10 * k as f64
                    + c * (std::f64::consts::TAU * 50.0 * k as f64 / n as f64).sin()
            })
            .collect();
        let whole = DetrendedRms::of(&x);
        // Subtracting the first sample leaves values of the trend's size, 1e-6: their squares'
        // rounding over n sums is about sqrt(n) eps 1e-12 per sample, 1e-9 of c^2 / 2.
        assert!((whole / (c / 2f64.sqrt()) - 1.0).abs() < 1e-3, "{whole:e}");
        let mut acc = DetrendedRms::new(n);
        for block in x.chunks(777) {
            acc.push(block);
        }
        assert_eq!(acc.finish(), whole);
        // Gaps are left out of the fit: a line with holes has no fluctuation.
        let mut line: Vec<f64> = (0..100).map(|k| 2.0 + 0.5 * k as f64).collect();
        line[17] = f64::NAN;
        line[40] = f64::INFINITY;
        assert!(
            DetrendedRms::of(&line) < 1e-12,
            "{}",
            DetrendedRms::of(&line)
        );
    }

    #[test]
    fn the_bound_and_the_likely_units() {
        assert_eq!(unstated_rms_bound(Quantity::Angle, 10.0), 1e-2);
        let rate = unstated_rms_bound(Quantity::Rate, 10.0);
        assert!((rate - 0.1 * std::f64::consts::PI).abs() < 1e-15);
        assert_eq!(likely_units(3.0, Quantity::Angle, 1.0), ["urad", "nrad"]);
        assert_eq!(likely_units(3e5, Quantity::Angle, 1.0), ["nrad"]);
        assert_eq!(
            likely_units(50.0, Quantity::Rate, 1.0),
            ["urad/s", "nrad/s"]
        );
        assert_eq!(unstated_excess(1e-2, Quantity::Angle, 10.0), None);
        assert_eq!(unstated_excess(f64::NAN, Quantity::Angle, 10.0), None);
        let e = unstated_excess(3.0, Quantity::Angle, 10.0).unwrap();
        assert_eq!((e.rms, e.bound), (3.0, 1e-2));
        assert_eq!(e.likely, ["urad", "nrad"]);
    }
}
