//! Metadata shared by the readers: unit strings, start times, the quantity decision.

use super::InputError;
use super::Quantity;
use std::path::Path;
use tiltnoise_core::error::{shown_list, Shown};
use tiltnoise_core::input::normalize_unit as normalize;

/// Accepted unit strings of ASD columns/datasets, for messages.
pub(crate) const ASD_UNITS: &str = "rad/sqrt(Hz) (angle) or rad/s/sqrt(Hz) (rate)";
/// Accepted unit strings of CSD datasets, for messages.
pub(crate) const CSD_UNITS: &str = "rad^2/Hz (angle) or rad^2/s^2/Hz (rate)";

/// What the unit string of a spectrum says: its quantity (the spectra are read in SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SpectrumUnit {
    pub quantity: Option<Quantity>,
}

impl SpectrumUnit {
    fn si(quantity: Quantity) -> SpectrumUnit {
        SpectrumUnit {
            quantity: Some(quantity),
        }
    }
}

/// `rad/sqrt(Hz)` -> angle, `rad/s/sqrt(Hz)` -> rate.
pub(crate) fn asd_unit(unit: &str) -> Option<SpectrumUnit> {
    match normalize(unit).as_str() {
        "rad/sqrt(hz)" => Some(SpectrumUnit::si(Quantity::Angle)),
        "rad/s/sqrt(hz)" | "rad/(sqrt(hz)s)" => Some(SpectrumUnit::si(Quantity::Rate)),
        _ => None,
    }
}

/// `rad^2/Hz` -> angle, `rad^2/s^2/Hz` -> rate.
pub(crate) fn csd_unit(unit: &str) -> Option<SpectrumUnit> {
    match normalize(unit).as_str() {
        "rad^2/hz" | "rad2/hz" => Some(SpectrumUnit::si(Quantity::Angle)),
        "rad^2/s^2/hz" | "rad2/s2/hz" | "rad2/(hzs2)" => Some(SpectrumUnit::si(Quantity::Rate)),
        _ => None,
    }
}

/// A declared unit of one tilt channel.
#[derive(Debug, Clone)]
pub(crate) struct Declared {
    pub channel: String,
    pub unit: String,
    /// `None` for digitizer counts.
    pub quantity: Option<Quantity>,
}

/// Decides the quantity from the override and the declared units of the mapped channels
/// (`undeclared`: mapped channels without a unit), appending provenance notes.
pub(crate) fn decide_quantity(
    path: &Path,
    override_q: Option<Quantity>,
    declared: &[Declared],
    undeclared: &[String],
    notes: &mut Vec<String>,
) -> Result<Quantity, InputError> {
    // Channels in counts declare no quantity: they take the others'.
    let mut undeclared = undeclared.to_vec();
    undeclared.extend(
        declared
            .iter()
            .filter(|d| d.quantity.is_none())
            .map(|d| d.channel.clone()),
    );
    let declared: Vec<(&Declared, Quantity)> = declared
        .iter()
        .filter_map(|d| d.quantity.map(|q| (d, q)))
        .collect();
    let from_file = declared.first().copied();
    if let (Some((first, q)), None) = (from_file, override_q) {
        if let Some((other, oq)) = declared.iter().find(|(_, oq)| *oq != q) {
            return Err(InputError::MixedQuantity {
                path: path.to_path_buf(),
                channel_a: first.channel.clone(),
                unit_a: q.unit(),
                channel_b: other.channel.clone(),
                unit_b: oq.unit(),
            });
        }
    }
    match (override_q, from_file) {
        (Some(q), _) => {
            notes.push(format!(
                "quantity: {} ({}) given explicitly",
                q.name(),
                q.unit()
            ));
            for (d, _) in declared.iter().filter(|(_, dq)| *dq != q) {
                notes.push(format!(
                    "the explicit quantity {} overrides the file's units `{}` of channel `{}`",
                    q.name(),
                    Shown(&d.unit),
                    Shown(&d.channel)
                ));
            }
            if q == Quantity::Rate {
                notes.push(RATE_NOTE.to_string());
            }
            Ok(q)
        }
        (None, Some((d, q))) => {
            notes.push(format!(
                "quantity: {} (from the file's units `{}`)",
                q.name(),
                d.unit
            ));
            if !undeclared.is_empty() {
                notes.push(format!(
                    "channels without units, assumed {}: {}",
                    q.name(),
                    shown_list(&undeclared)
                ));
            }
            if q == Quantity::Rate {
                notes.push(RATE_NOTE.to_string());
            }
            Ok(q)
        }
        (None, None) => {
            notes.push(
                "quantity: not given in the file or the options; assumed angle (rad)".to_string(),
            );
            Ok(Quantity::Angle)
        }
    }
}

/// How a rate is turned into angle (`tiltnoise_core::input::rate`), for the provenance.
const RATE_NOTE: &str = "rate to angle: spectra divided by (2 pi f)^2 at every f > 0, exact \
     up to Nyquist (a series' samples stay in rad/s, nothing is integrated in time); f = 0 \
     carries no angle information and is excluded";

/// Whether `s` is an ISO 8601 date or date-time: `YYYY-MM-DD`, optionally followed by `T` (or
/// a space) and `hh:mm`, `hh:mm:ss` or `hh:mm:ss.fff...`, optionally followed by `Z` or a UTC
/// offset `+hh:mm`, `-hh:mm`, `+hhmm`, `+hh`. Field ranges are checked (day against the month,
/// leap years included; second 60 allowed for leap seconds).
pub(crate) fn is_iso8601(s: &str) -> bool {
    fn num(s: &str, n: usize) -> Option<u32> {
        (s.len() == n && s.bytes().all(|b| b.is_ascii_digit()))
            .then(|| s.parse().ok())
            .flatten()
    }
    let b = s.as_bytes();
    // ASCII only: the fields below are sliced at fixed byte offsets.
    if !s.is_ascii() || b.len() < 10 || b[4] != b'-' || b[7] != b'-' {
        return false;
    }
    let (Some(y), Some(mo), Some(d)) = (num(&s[0..4], 4), num(&s[5..7], 2), num(&s[8..10], 2))
    else {
        return false;
    };
    let leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    let days = match mo {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => return false,
    };
    if d == 0 || d > days {
        return false;
    }
    let rest = &s[10..];
    if rest.is_empty() {
        return true;
    }
    let Some(rest) = rest.strip_prefix(['T', ' ']) else {
        return false;
    };
    // Split off the zone designator.
    let (time, zone) = match rest.find(['Z', '+', '-']) {
        Some(i) => (&rest[..i], &rest[i..]),
        None => (rest, ""),
    };
    let ok_zone = match zone {
        "" | "Z" => true,
        z => {
            let z = &z[1..];
            match z.len() {
                2 => num(z, 2).is_some_and(|h| h <= 23),
                4 => {
                    num(&z[..2], 2).is_some_and(|h| h <= 23)
                        && num(&z[2..], 2).is_some_and(|m| m <= 59)
                }
                5 => {
                    z.as_bytes()[2] == b':'
                        && num(&z[..2], 2).is_some_and(|h| h <= 23)
                        && num(&z[3..], 2).is_some_and(|m| m <= 59)
                }
                _ => false,
            }
        }
    };
    if !ok_zone {
        return false;
    }
    let (hms, frac) = match time.split_once(['.', ',']) {
        Some((hms, frac)) => (hms, Some(frac)),
        None => (time, None),
    };
    if let Some(f) = frac {
        if f.is_empty() || !f.bytes().all(|b| b.is_ascii_digit()) {
            return false;
        }
    }
    let parts: Vec<&str> = hms.split(':').collect();
    match parts.as_slice() {
        [h, m] => {
            frac.is_none()
                && num(h, 2).is_some_and(|h| h <= 23)
                && num(m, 2).is_some_and(|m| m <= 59)
        }
        [h, m, sec] => {
            num(h, 2).is_some_and(|h| h <= 23)
                && num(m, 2).is_some_and(|m| m <= 59)
                && num(sec, 2).is_some_and(|s| s <= 60)
        }
        _ => false,
    }
}

/// Seconds since 1970-01-01T00:00:00Z of an ISO 8601 date-time of the form the readers accept:
/// `(whole seconds, fraction in [0, 1))`. Without a zone designator the time is taken as UTC
/// (two records that both omit it are then compared in their common zone). A leap second
/// `:60` counts as the next second, as POSIX time has no leap seconds.
pub fn iso8601_to_unix(s: &str) -> Option<(i64, f64)> {
    if !is_iso8601(s) {
        return None;
    }
    let num = |a: usize, b: usize| s.get(a..b).and_then(|t| t.parse::<i64>().ok());
    let (y, mo, d) = (num(0, 4)?, num(5, 7)?, num(8, 10)?);
    // Days from the civil date (H. Hinnant's algorithm, proleptic Gregorian calendar).
    let y_adj = if mo <= 2 { y - 1 } else { y };
    let era = y_adj.div_euclid(400);
    let yoe = y_adj - era * 400;
    let mp = (mo + 9) % 12;
    let doy = (153 * mp + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    let rest = &s[10..];
    let (mut secs, mut frac) = (days * 86_400, 0.0);
    if rest.is_empty() {
        return Some((secs, frac));
    }
    let rest = &rest[1..];
    let (time, zone) = match rest.find(['Z', '+', '-']) {
        Some(i) => (&rest[..i], &rest[i..]),
        None => (rest, ""),
    };
    let (hms, fraction) = match time.split_once(['.', ',']) {
        Some((hms, f)) => (hms, Some(f)),
        None => (time, None),
    };
    let parts: Vec<i64> = hms
        .split(':')
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    secs += parts[0] * 3600 + parts[1] * 60 + parts.get(2).copied().unwrap_or(0);
    if let Some(f) = fraction {
        frac = format!("0.{f}").parse().ok()?;
    }
    if zone.len() > 1 {
        let sign = if zone.starts_with('-') { -1 } else { 1 };
        let digits: String = zone[1..].chars().filter(|c| c.is_ascii_digit()).collect();
        let h: i64 = digits.get(0..2)?.parse().ok()?;
        let m: i64 = digits.get(2..4).map_or(Some(0), |m| m.parse().ok())?;
        // The local time is ahead of UTC by the offset.
        secs -= sign * (h * 3600 + m * 60);
    }
    Some((secs, frac))
}

/// The ISO 8601 UTC date-time `YYYY-MM-DDThh:mm:ss[.ffffff]Z` of `unix_s + frac_s` seconds
/// since 1970-01-01T00:00:00Z (`0 <= frac_s < 1`; microseconds, when not whole), the inverse
/// of [`iso8601_to_unix`].
pub fn unix_to_iso8601(unix_s: i64, frac_s: f64) -> String {
    let mut micros = (frac_s * 1e6).round() as i64;
    let mut secs = unix_s;
    if micros >= 1_000_000 {
        secs += 1;
        micros -= 1_000_000;
    }
    let days = secs.div_euclid(86_400);
    let sod = secs.rem_euclid(86_400);
    // Civil date from days (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    let (h, mi, se) = (sod / 3600, sod % 3600 / 60, sod % 60);
    if micros == 0 {
        format!("{y:04}-{m:02}-{d:02}T{h:02}:{mi:02}:{se:02}Z")
    } else {
        format!("{y:04}-{m:02}-{d:02}T{h:02}:{mi:02}:{se:02}.{micros:06}Z")
    }
}

/// What `start_time` must look like, for messages.
pub(crate) const ISO8601_ALLOWED: &str = "an ISO 8601 date-time string, e.g. \
     2018-01-23T09:31:42Z or 2018-01-23T09:31:42.5+01:00";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iso8601() {
        for ok in [
            "2018-01-23",
            "2018-01-23T09:31",
            "2018-01-23T09:31:42",
            "2018-01-23T09:31:42.000000Z",
            "2018-01-23 09:31:42Z",
            "2020-02-29T00:00:00+01:00",
            "2020-02-29T00:00:00-0130",
            "2016-12-31T23:59:60Z",
        ] {
            assert!(is_iso8601(ok), "{ok}");
        }
        for bad in [
            "",
            "yesterday",
            "2018-1-23",
            "2019-02-29",
            "2018-13-01",
            "2018-01-23T25:00",
            "2018-01-23T09:31:42.Z",
            "2018-01-23T09",
            "2018-01-23T09:31+1",
            "2018-01-23X09:31",
            "2018-01-2\u{feff}3T09:31",
            "2018-01-23T09:31+0\u{e9}0",
            "2018-01-23T09:31-1\u{20ac}",
        ] {
            assert!(!is_iso8601(bad), "{bad}");
        }
    }

    #[test]
    fn iso8601_seconds() {
        // Reference values: Python's datetime(...).timestamp() with tzinfo=UTC.
        assert_eq!(iso8601_to_unix("1970-01-01"), Some((0, 0.0)));
        assert_eq!(
            iso8601_to_unix("2018-01-23T09:31:42Z"),
            Some((1_516_699_902, 0.0))
        );
        assert_eq!(
            iso8601_to_unix("2018-01-23T10:31:42.25+01:00"),
            Some((1_516_699_902, 0.25))
        );
        assert_eq!(
            iso8601_to_unix("2018-01-23T08:01:42-0130"),
            Some((1_516_699_902, 0.0))
        );
        assert_eq!(
            iso8601_to_unix("2000-02-29T00:00"),
            Some((951_782_400, 0.0))
        );
        assert_eq!(iso8601_to_unix("1969-12-31T23:59:59Z"), Some((-1, 0.0)));
        assert_eq!(
            iso8601_to_unix("2018-01-23T09:31"),
            Some((1_516_699_860, 0.0))
        );
        assert_eq!(iso8601_to_unix("not a date"), None);
        assert_eq!(unix_to_iso8601(1_516_699_902, 0.0), "2018-01-23T09:31:42Z");
        assert_eq!(
            unix_to_iso8601(951_782_400, 0.25),
            "2000-02-29T00:00:00.250000Z"
        );
        assert_eq!(unix_to_iso8601(-1, 0.0), "1969-12-31T23:59:59Z");
        for s in [
            -86_400_i64 * 700_000,
            -3,
            0,
            59,
            1_000_000_007,
            4_102_444_800,
        ] {
            assert_eq!(
                iso8601_to_unix(&unix_to_iso8601(s, 0.5)),
                Some((s, 0.5)),
                "{s}"
            );
        }
    }

    #[test]
    fn units() {
        let a = |u: &str| asd_unit(u).and_then(|u| u.quantity);
        let c = |u: &str| csd_unit(u).and_then(|u| u.quantity);
        assert_eq!(a("rad/√Hz"), Some(Quantity::Angle));
        assert_eq!(a("rad / Hz(1/2)"), Some(Quantity::Angle));
        assert_eq!(a("rad/s/sqrt(Hz)"), Some(Quantity::Rate));
        // astropy's text of the units gwpy writes
        assert_eq!(a("rad / (Hz(1/2) s)"), Some(Quantity::Rate));
        assert_eq!(c("rad2 / Hz"), Some(Quantity::Angle));
        assert_eq!(c("rad2 / (Hz s2)"), Some(Quantity::Rate));
        assert_eq!(c("rad²/Hz"), Some(Quantity::Angle));
        assert_eq!(c("rad**2/s**2/Hz"), Some(Quantity::Rate));
    }
}
