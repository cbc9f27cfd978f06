//! One miniSEED 2 data record: the 48-byte fixed header (either byte order), the blockette
//! chain (1000 required; 1001 and 100 used when present) and the samples in the encodings a
//! tilt or rotation sensor writes (INT16, INT32, FLOAT32, FLOAT64, Steim-1, Steim-2).
//! Everything the header says is checked against the bytes there are, so a damaged record
//! is an error, never a read out of bounds.

pub(crate) use super::steim::WordOrder;
use super::steim::{self, Steim};
use jiff::{civil, tz::Offset, Timestamp};

/// Length of the fixed header section.
const FIXED_HEADER: usize = 48;
/// Smallest and largest record length exponent accepted in blockette 1000 (128 B .. 1 MiB).
const MIN_LEN_EXP: u8 = 7;
const MAX_LEN_EXP: u8 = 20;
/// Blockettes read per record at most (a chain longer than this is damaged).
const MAX_BLOCKETTES: usize = 64;

/// Nanoseconds in a second.
pub(crate) const NS_PER_S: i64 = 1_000_000_000;

/// The samples of a record, as encoded.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Samples {
    /// Integer encodings (INT16, INT32, Steim-1, Steim-2): digitizer counts.
    Int(Vec<i32>),
    /// Floating-point encodings (FLOAT32, FLOAT64), converted exactly to f64.
    Float(Vec<f64>),
    /// ASCII text (encoding 0): a log record, no samples.
    Text,
}

/// A decoded record.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Record {
    /// `NET.STA.LOC.CHA`, each code with its padding spaces removed.
    pub id: String,
    /// Start time of the first sample, ns since 1970-01-01T00:00:00 UTC (no leap seconds),
    /// with the time correction and the blockette 1001 microseconds applied.
    pub start_ns: i64,
    /// The resolution of `start_ns` (ns): 100 us, or 1 us with a blockette 1001.
    pub time_resolution_ns: i64,
    /// Sample rate (Hz): blockette 100's if present, else the header's factor and multiplier.
    pub sample_rate_hz: f64,
    /// Encoding name, e.g. `FLOAT64`, `Steim-2`.
    pub encoding: &'static str,
    pub samples: Samples,
    /// Record length (bytes).
    pub len: usize,
}

impl Record {
    /// Number of samples.
    pub fn n_samples(&self) -> usize {
        match &self.samples {
            Samples::Int(v) => v.len(),
            Samples::Float(v) => v.len(),
            Samples::Text => 0,
        }
    }
}

fn u16_at(b: &[u8], at: usize, o: WordOrder) -> u16 {
    let x = [b[at], b[at + 1]];
    match o {
        WordOrder::Big => u16::from_be_bytes(x),
        WordOrder::Little => u16::from_le_bytes(x),
    }
}

fn u32_at(b: &[u8], at: usize, o: WordOrder) -> u32 {
    let x = [b[at], b[at + 1], b[at + 2], b[at + 3]];
    match o {
        WordOrder::Big => u32::from_be_bytes(x),
        WordOrder::Little => u32::from_le_bytes(x),
    }
}

fn u64_at(b: &[u8], at: usize, o: WordOrder) -> u64 {
    let mut x = [0u8; 8];
    x.copy_from_slice(&b[at..at + 8]);
    match o {
        WordOrder::Big => u64::from_be_bytes(x),
        WordOrder::Little => u64::from_le_bytes(x),
    }
}

/// Whether a year and day-of-year are plausible (libmseed's test of the header byte order).
fn plausible(year: u16, day: u16) -> bool {
    (1900..=2100).contains(&year) && (1..=366).contains(&day)
}

/// Seconds from 1970-01-01T00:00:00 UTC to the start of day `day` (1-based) of `year`;
/// `None` for a day the year does not have.
fn start_of_day_s(year: i16, day: i16) -> Option<i64> {
    let date = civil::Date::new(year, 1, 1)
        .and_then(|d| d.with().day_of_year(day).build())
        .ok()?;
    Some(
        Offset::UTC
            .to_timestamp(date.to_datetime(civil::Time::midnight()))
            .ok()?
            .as_second(),
    )
}

/// The nominal sample rate of the header's factor and multiplier (SEED manual, fixed header
/// field 10), 0 when either is 0.
fn nominal_rate(factor: i16, multiplier: i16) -> f64 {
    let (f, m) = (f64::from(factor), f64::from(multiplier));
    match (factor, multiplier) {
        (0, _) | (_, 0) => 0.0,
        (1.., 1..) => f * m,
        (1.., _) => -f / m,
        (_, 1..) => -m / f,
        _ => 1.0 / (f * m),
    }
}

/// A field of a station, location, channel or network code: ASCII letters, digits or
/// spaces; returned without its padding.
fn code(b: &[u8], what: &str) -> Result<String, String> {
    if let Some(&c) = b
        .iter()
        .find(|c| !(c.is_ascii_alphanumeric() || **c == b' ' || **c == 0))
    {
        return Err(format!(
            "{what} code has byte 0x{c:02x}; allowed: ASCII letters, digits and spaces"
        ));
    }
    Ok(String::from_utf8_lossy(b)
        .trim_matches(|c| c == ' ' || c == '\0')
        .to_string())
}

/// Whether `b` starts like a miniSEED 3 record (`MS` and version 3).
pub(crate) fn is_v3(b: &[u8]) -> bool {
    b.len() >= 3 && b[0] == b'M' && b[1] == b'S' && b[2] == 3
}

/// Decodes the record at the start of `b` (which holds the rest of the file). Returns the
/// record; its length says where the next one starts.
/// The byte order of the fixed header at the start of `b`, after checking that it looks like a
/// miniSEED 2 data record at all.
fn header_order(b: &[u8]) -> Result<WordOrder, String> {
    if is_v3(b) {
        return Err(
            "this is a miniSEED 3 record; allowed: miniSEED 2 (SEED 2.4 data records \
                    with blockette 1000)"
                .to_string(),
        );
    }
    if b.len() < FIXED_HEADER {
        return Err(format!(
            "{} bytes left, fewer than the 48 of a fixed header: the file is truncated",
            b.len()
        ));
    }
    if let Some(&c) = b[..6]
        .iter()
        .find(|c| !(c.is_ascii_digit() || **c == b' ' || **c == 0))
    {
        return Err(format!(
            "sequence number has byte 0x{c:02x}; allowed: six ASCII digits (is this a \
             miniSEED 2 file?)"
        ));
    }
    if !matches!(b[6], b'D' | b'R' | b'Q' | b'M') {
        return Err(format!(
            "data quality indicator is byte 0x{:02x}; allowed: D, R, Q or M (is this a miniSEED \
             2 data record?)",
            b[6]
        ));
    }
    if plausible(u16_at(b, 20, WordOrder::Big), u16_at(b, 22, WordOrder::Big)) {
        Ok(WordOrder::Big)
    } else if plausible(
        u16_at(b, 20, WordOrder::Little),
        u16_at(b, 22, WordOrder::Little),
    ) {
        Ok(WordOrder::Little)
    } else {
        Err(format!(
            "start year {} / day {} (big-endian; little-endian {} / {}) is not plausible in \
             either byte order; allowed: year 1900..=2100, day 1..=366",
            u16_at(b, 20, WordOrder::Big),
            u16_at(b, 22, WordOrder::Big),
            u16_at(b, 20, WordOrder::Little),
            u16_at(b, 22, WordOrder::Little)
        ))
    }
}

pub(crate) fn decode(b: &[u8]) -> Result<Record, String> {
    let order = header_order(b)?;
    let station = code(&b[8..13], "station")?;
    let location = code(&b[13..15], "location")?;
    let channel = code(&b[15..18], "channel")?;
    let network = code(&b[18..20], "network")?;
    let id = format!("{network}.{station}.{location}.{channel}");

    let year = u16_at(b, 20, order);
    let day = u16_at(b, 22, order);
    let (hour, minute, second) = (b[24], b[25], b[26]);
    let fract = u16_at(b, 28, order);
    if hour > 23 || minute > 59 || second > 60 || fract > 9999 {
        return Err(format!(
            "start time {hour:02}:{minute:02}:{second:02}.{fract:04} is not a time of day; \
             allowed: hour <= 23, minute <= 59, second <= 60, 0.0001 s units <= 9999"
        ));
    }
    // `plausible` bounds the year and day, so only day 366 of a common year is refused here.
    let Some(day_start_s) = start_of_day_s(year as i16, day as i16) else {
        return Err(format!(
            "start day {day} of {year}, which is not a leap year"
        ));
    };
    let n = usize::from(u16_at(b, 30, order));
    let factor = u16_at(b, 32, order) as i16;
    let multiplier = u16_at(b, 34, order) as i16;
    let activity = b[36];
    let time_correction = u32_at(b, 40, order) as i32;
    let data_offset = usize::from(u16_at(b, 44, order));
    let first_blockette = usize::from(u16_at(b, 46, order));

    let Blockettes {
        b1000,
        usec,
        has_b1001,
        b100_rate,
        end: end_of_blockettes,
    } = blockettes(b, first_blockette, order)?;
    let Some((encoding_code, word_order, len_exp)) = b1000 else {
        return Err(
            "no blockette 1000 (data only SEED blockette); allowed: miniSEED 2 \
                    records, which carry one"
                .to_string(),
        );
    };
    if !(MIN_LEN_EXP..=MAX_LEN_EXP).contains(&len_exp) {
        return Err(format!(
            "blockette 1000 gives a record length of 2^{len_exp} bytes; allowed: 2^{MIN_LEN_EXP} \
             to 2^{MAX_LEN_EXP}"
        ));
    }
    let len = 1usize << len_exp;
    if len > b.len() {
        return Err(format!(
            "record length {len} bytes (blockette 1000) but only {} bytes are left: the file \
             is truncated",
            b.len()
        ));
    }
    if end_of_blockettes > len {
        return Err(format!(
            "the blockettes end at byte {end_of_blockettes}, past the record length {len}"
        ));
    }
    let data_order = match word_order {
        0 => WordOrder::Little,
        1 => WordOrder::Big,
        other => {
            return Err(format!(
                "blockette 1000 word order {other}; allowed: 0 (little-endian) or 1 \
                 (big-endian)"
            ))
        }
    };

    let mut sample_rate_hz = nominal_rate(factor, multiplier);
    if let Some(r) = b100_rate {
        sample_rate_hz = f64::from(r);
    }
    let (encoding, samples) = if encoding_code == 0 {
        ("ASCII", Samples::Text)
    } else {
        if n > 0 && (data_offset < end_of_blockettes || data_offset > len) {
            return Err(format!(
                "data offset {data_offset} is outside the record's data area \
                 ({end_of_blockettes}..{len})"
            ));
        }
        let data = if n > 0 { &b[data_offset..len] } else { &[][..] };
        decode_samples(encoding_code, data, n, data_order)?
    };
    if !matches!(samples, Samples::Text)
        && n > 0
        && !(sample_rate_hz.is_finite() && sample_rate_hz > 0.0)
    {
        return Err(format!(
            "sample rate {sample_rate_hz} Hz (factor {factor}, multiplier {multiplier}{}) for \
             {n} samples; allowed: a finite rate > 0",
            if b100_rate.is_some() {
                ", blockette 100"
            } else {
                ""
            }
        ));
    }

    // Second 60 (a leap second) runs on into the next minute, as in libmseed.
    let mut start_ns =
        day_start_s + (i64::from(hour) * 60 + i64::from(minute)) * 60 + i64::from(second);
    start_ns = start_ns * NS_PER_S + i64::from(fract) * 100_000 + i64::from(usec) * 1000;
    // Bit 1 of the activity flags: the time correction is already applied.
    if activity & 0x02 == 0 {
        start_ns += i64::from(time_correction) * 100_000;
    }
    Ok(Record {
        id,
        start_ns,
        time_resolution_ns: if has_b1001 { 1000 } else { 100_000 },
        sample_rate_hz,
        encoding,
        samples,
        len,
    })
}

/// What the blockette chain of a record says.
struct Blockettes {
    /// Blockette 1000: encoding, word order, record length exponent.
    b1000: Option<(u8, u8, u8)>,
    /// Blockette 1001: microseconds to add to the start time.
    usec: i8,
    has_b1001: bool,
    /// Blockette 100: the actual sample rate.
    b100_rate: Option<f32>,
    /// Where the last blockette ends.
    end: usize,
}

/// Walks the blockette chain from byte `first`: offsets strictly increasing (no cycle), each
/// inside the bytes there are; blockette 1000 gives the record length, which bounds them again
/// in [`decode`].
fn blockettes(b: &[u8], first: usize, order: WordOrder) -> Result<Blockettes, String> {
    let mut b1000: Option<(u8, u8, u8)> = None;
    let mut usec: i8 = 0;
    let mut has_b1001 = false;
    let mut b100_rate: Option<f32> = None;
    let mut end_of_blockettes = FIXED_HEADER;
    let mut at = first;
    let mut count = 0;
    while at != 0 {
        count += 1;
        if count > MAX_BLOCKETTES {
            return Err(format!(
                "more than {MAX_BLOCKETTES} blockettes; the chain is damaged"
            ));
        }
        if at < end_of_blockettes || at + 4 > b.len() {
            return Err(format!(
                "blockette at byte {at} of the record is outside the record or overlaps the \
                 header or the previous blockette"
            ));
        }
        let kind = u16_at(b, at, order);
        let next = usize::from(u16_at(b, at + 2, order));
        let size = match kind {
            1000 => 8,
            1001 => 8,
            100 => 12,
            _ => 4,
        };
        if at + size > b.len() {
            return Err(format!(
                "blockette {kind} at byte {at} runs past the end of the file"
            ));
        }
        match kind {
            1000 => b1000 = Some((b[at + 4], b[at + 5], b[at + 6])),
            1001 => {
                usec = b[at + 5] as i8;
                has_b1001 = true;
            }
            100 => b100_rate = Some(f32::from_bits(u32_at(b, at + 4, order))),
            _ => {}
        }
        end_of_blockettes = at + size;
        if next != 0 && next <= at {
            return Err(format!(
                "blockette {kind} at byte {at} points back to byte {next}; allowed: the next \
                 blockette further on, or 0 for the last"
            ));
        }
        at = next;
    }
    Ok(Blockettes {
        b1000,
        usec,
        has_b1001,
        b100_rate,
        end: end_of_blockettes,
    })
}

/// The samples of `data` in encoding `code` (SEED manual, blockette 1000).
fn decode_samples(
    code: u8,
    data: &[u8],
    n: usize,
    o: WordOrder,
) -> Result<(&'static str, Samples), String> {
    let need = |name: &str, size: usize| -> Result<(), String> {
        if n * size > data.len() {
            return Err(format!(
                "{n} {name} samples need {} bytes but the data area has {}",
                n * size,
                data.len()
            ));
        }
        Ok(())
    };
    Ok(match code {
        1 => {
            need("INT16", 2)?;
            let v = (0..n).map(|k| i32::from(u16_at(data, 2 * k, o) as i16));
            ("INT16", Samples::Int(v.collect()))
        }
        3 => {
            need("INT32", 4)?;
            let v = (0..n).map(|k| u32_at(data, 4 * k, o) as i32);
            ("INT32", Samples::Int(v.collect()))
        }
        4 => {
            need("FLOAT32", 4)?;
            let v = (0..n).map(|k| f64::from(f32::from_bits(u32_at(data, 4 * k, o))));
            ("FLOAT32", Samples::Float(v.collect()))
        }
        5 => {
            need("FLOAT64", 8)?;
            let v = (0..n).map(|k| f64::from_bits(u64_at(data, 8 * k, o)));
            ("FLOAT64", Samples::Float(v.collect()))
        }
        10 => (
            "Steim-1",
            Samples::Int(steim::decode(data, n, o, Steim::One)?),
        ),
        11 => (
            "Steim-2",
            Samples::Int(steim::decode(data, n, o, Steim::Two)?),
        ),
        other => {
            return Err(format!(
                "encoding {other} is not supported; allowed: 1 (INT16), 3 (INT32), 4 \
                 (FLOAT32), 5 (FLOAT64), 10 (Steim-1), 11 (Steim-2), 0 (ASCII log records, \
                 skipped)"
            ))
        }
    })
}

/// ISO 8601 UTC text of `ns` since 1970 (`YYYY-MM-DDThh:mm:ss.ffffffZ`, microseconds).
pub(crate) fn iso8601(ns: i64) -> String {
    // Every i64 of nanoseconds (years 1677..2262) is a valid instant.
    let instant = Timestamp::from_nanosecond(i128::from(ns)).expect("within jiff's range");
    super::super::start_time::utc_text_micros(instant)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times() {
        assert_eq!(start_of_day_s(1970, 1), Some(0));
        // Python: datetime(2018, 1, 1, tzinfo=timezone.utc).timestamp()
        assert_eq!(start_of_day_s(2018, 1), Some(1_514_764_800));
        assert_eq!(start_of_day_s(2000, 366), Some(978_220_800));
        assert_eq!(start_of_day_s(2100, 366), None);
        // 2018-01-23T09:31:42 = day 23 of 2018.
        let ns = (start_of_day_s(2018, 23).unwrap() + 9 * 3600 + 31 * 60 + 42) * NS_PER_S;
        assert_eq!(iso8601(ns), "2018-01-23T09:31:42.000000Z");
        assert_eq!(iso8601(-1000), "1969-12-31T23:59:59.999999Z");
        assert_eq!(
            iso8601(start_of_day_s(2000, 60).unwrap() * NS_PER_S),
            "2000-02-29T00:00:00.000000Z"
        );
    }

    #[test]
    fn rates() {
        assert_eq!(nominal_rate(1, 1), 1.0);
        assert_eq!(nominal_rate(-10, 1), 0.1);
        assert_eq!(nominal_rate(20, -2), 10.0);
        assert_eq!(nominal_rate(-10, -10), 0.01);
        assert_eq!(nominal_rate(0, 1), 0.0);
    }
}
