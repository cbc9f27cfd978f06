//! The start time of a series file (tilt or observables): HDF5 root attribute `start_time`,
//! CSV line `# start_time:`, the instant of sample 0 in ISO 8601 text. The text is read by
//! jiff's parser of ISO 8601 (the grammar of RFC 3339 and Temporal) and kept as stated for the
//! outputs' provenance; the numerics receive the instant ([`parse_start_time`]).
//!
//! # Accepted text
//!
//! A date `YYYY-MM-DD` (midnight), optionally followed by `T` or a space and a time `hh`,
//! `hh:mm`, `hh:mm:ss` or `hh:mm:ss.fffffffff` (`,` also as decimal sign, at most nine
//! fraction digits; the basic forms without separators too), optionally followed by `Z` or a
//! UTC offset `+hh:mm`, `+hhmm`, `+hh` (or `-`). A time without zone designator is taken as
//! UTC, with a note. A leap second `:60` reads as `:59`, POSIX time having no leap seconds.
//! Refused: impossible dates and times, and time zone names (`[Europe/Berlin]`), which would
//! need a time zone database.

use jiff::fmt::temporal::{DateTimeParser, DateTimePrinter, PiecesOffset};
use jiff::tz::Offset;
use jiff::{civil, Timestamp, Unit};
use std::path::Path;
use tiltnoise_core::error::Shown;
use tiltnoise_core::input::InputError;

/// What `start_time` must look like, for messages.
pub(crate) const ISO8601_ALLOWED: &str = "an ISO 8601 date-time string, e.g. \
     2018-01-23T09:31:42Z or 2018-01-23T09:31:42.5+01:00";

static PARSER: DateTimeParser = DateTimeParser::new();

/// The instant of an ISO 8601 date or date-time (module docs), and whether the text has a zone
/// designator; `None` for anything else.
fn parse(text: &str) -> Option<(Timestamp, bool)> {
    let pieces = PARSER.parse_pieces(text).ok()?;
    if pieces.time_zone_annotation().is_some() {
        return None;
    }
    let time = pieces.time().unwrap_or(civil::Time::midnight());
    let (offset, zoned) = match pieces.offset() {
        None => (Offset::UTC, false),
        Some(PiecesOffset::Zulu) => (Offset::UTC, true),
        Some(PiecesOffset::Numeric(n)) => (n.offset(), true),
        // A kind of offset added by a later jiff: not one of the accepted forms.
        Some(_) => return None,
    };
    let instant = offset.to_timestamp(pieces.date().to_datetime(time)).ok()?;
    Some((instant, zoned))
}

/// The instant an ISO 8601 start time names (module docs); `None` when the text is not one.
/// The readers have validated every start time they return, so `None` means the text came
/// from elsewhere.
pub fn parse_start_time(text: &str) -> Option<Timestamp> {
    parse(text).map(|(instant, _)| instant)
}

/// The ISO 8601 UTC text of `instant`, to the microsecond: `YYYY-MM-DDThh:mm:ssZ` when the
/// microseconds are 0, else `YYYY-MM-DDThh:mm:ss.ffffffZ`.
pub fn utc_text(instant: Timestamp) -> String {
    // Rounding moves an instant by half a microsecond at most, far inside the range.
    let rounded = instant.round(Unit::Microsecond).unwrap_or(instant);
    let digits = if rounded.subsec_nanosecond() == 0 {
        0
    } else {
        6
    };
    DateTimePrinter::new()
        .precision(Some(digits))
        .timestamp_to_string(&rounded)
}

/// The ISO 8601 UTC text of `instant` with microseconds always written
/// (`YYYY-MM-DDThh:mm:ss.ffffffZ`, truncated to the microsecond), as ObsPy shows a miniSEED
/// record's times.
pub(crate) fn utc_text_micros(instant: Timestamp) -> String {
    DateTimePrinter::new()
        .precision(Some(6))
        .timestamp_to_string(&instant)
}

/// `text`, the value of `attribute` of `object` in `path`, if it is a start time (module docs);
/// appends a note when it has no zone designator.
///
/// # Errors
///
/// [`InputError::BadAttribute`] naming the file, the attribute, the value and what is allowed.
pub(crate) fn checked(
    path: &Path,
    object: String,
    attribute: &'static str,
    text: String,
    notes: &mut Vec<String>,
) -> Result<String, InputError> {
    match parse(&text) {
        Some((_, true)) => Ok(text),
        Some((_, false)) => {
            notes.push(format!(
                "start time `{}` has no zone designator: taken as UTC",
                Shown(&text)
            ));
            Ok(text)
        }
        None => Err(InputError::BadAttribute {
            path: path.to_path_buf(),
            object,
            attribute,
            value: format!("`{}`", Shown(&text)),
            allowed: ISO8601_ALLOWED,
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn unix(text: &str) -> Option<(i64, i32)> {
        parse_start_time(text).map(|t| (t.as_second(), t.subsec_nanosecond()))
    }

    #[test]
    fn accepted_and_refused_text() {
        for ok in [
            "2018-01-23",
            "2018-01-23T09",
            "2018-01-23T09:31",
            "2018-01-23T09:31:42",
            "2018-01-23T09:31:42.000000Z",
            "2018-01-23 09:31:42Z",
            "2020-02-29T00:00:00+01:00",
            "2020-02-29T00:00:00-0130",
            "2016-12-31T23:59:60Z",
        ] {
            assert!(parse(ok).is_some(), "{ok}");
        }
        for bad in [
            "",
            "yesterday",
            "2018-1-23",
            "2019-02-29",
            "2018-13-01",
            "2018-01-23T25:00",
            "2018-01-23T09:31:42.Z",
            "2018-01-23T09:31+1",
            "2018-01-23X09:31",
            "2018-01-23T09:31:42Z[Europe/Berlin]",
            "2018-01-23T09:31:42 ",
            "99999999999-01-01",
            "2018-01-2\u{feff}3T09:31",
            "2018-01-23T09:31+0\u{e9}0",
            "2018-01-23T09:31-1\u{20ac}",
        ] {
            assert!(parse(bad).is_none(), "{bad}");
        }
        assert_eq!(parse("2018-01-23T09:31").map(|p| p.1), Some(false));
        assert_eq!(parse("2018-01-23T09:31Z").map(|p| p.1), Some(true));
    }

    #[test]
    fn instants() {
        // Reference values: Python's datetime(...).timestamp() with tzinfo=UTC.
        assert_eq!(unix("1970-01-01"), Some((0, 0)));
        assert_eq!(unix("2018-01-23T09:31:42Z"), Some((1_516_699_902, 0)));
        assert_eq!(
            unix("2018-01-23T10:31:42.25+01:00"),
            Some((1_516_699_902, 250_000_000))
        );
        assert_eq!(
            unix("2018-01-23T09:31:42,25Z"),
            unix("2018-01-23T09:31:42.25Z")
        );
        assert_eq!(unix("2018-01-23T08:01:42-0130"), Some((1_516_699_902, 0)));
        assert_eq!(unix("2000-02-29T00:00"), Some((951_782_400, 0)));
        assert_eq!(unix("1969-12-31T23:59:59Z"), Some((-1, 0)));
        assert_eq!(unix("2018-01-23T09:31"), Some((1_516_699_860, 0)));
        assert_eq!(unix("2016-12-31T23:59:60Z"), unix("2016-12-31T23:59:59Z"));
        // The same instant in three notations.
        let z = unix("2024-03-19T23:00:00Z");
        for other in [
            "2024-03-20T00:00:00+01:00",
            "2024-03-20 00:00:00+0100",
            "2024-03-19T20:30-0230",
        ] {
            assert_eq!(unix(other), z, "{other}");
        }
    }

    #[test]
    fn text_of_instants() {
        let at = |s: i64, ns: i32| Timestamp::new(s, ns).unwrap();
        assert_eq!(utc_text(at(1_516_699_902, 0)), "2018-01-23T09:31:42Z");
        assert_eq!(
            utc_text(at(951_782_400, 250_000_000)),
            "2000-02-29T00:00:00.250000Z"
        );
        assert_eq!(utc_text(at(-1, 0)), "1969-12-31T23:59:59Z");
        assert_eq!(utc_text(at(59, 999_999_600)), "1970-01-01T00:01:00Z");
        assert_eq!(
            utc_text_micros(at(-1, 999_999_000)),
            "1969-12-31T23:59:59.999999Z"
        );
        for s in [
            -86_400_i64 * 700_000,
            -3,
            0,
            59,
            1_000_000_007,
            4_102_444_800,
        ] {
            let t = at(s, 500_000_000);
            assert_eq!(parse_start_time(&utc_text(t)), Some(t), "{s}");
        }
    }
}
