//! The decoder against ObsPy (libmseed): the fixtures and their references are written by
//! `tests/fixtures/input/miniseed/make_miniseed_fixtures.py`; every sample must agree exactly
//! (integers) or bit for bit (floats), gaps where ObsPy masks them.

use super::channels::{merge, Placed};
use super::record;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/fixtures/input/miniseed")
        .join(name)
}

/// Every record of the file, grouped by SEED code in order of appearance.
fn groups(name: &str) -> super::Groups {
    let bytes = std::fs::read(fixture(name)).unwrap();
    let (groups, text) = super::records(&fixture(name), &bytes).unwrap();
    assert_eq!(text, 0);
    groups
}

fn compare_with_obspy(stem: &str) -> usize {
    let reference: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture(&format!("{stem}.json"))).unwrap())
            .unwrap();
    let channels = reference["channels"].as_object().unwrap();
    let groups = groups(&format!("{stem}.mseed"));
    assert_eq!(groups.len(), channels.len());
    let mut compared = 0;
    for (id, recs) in groups {
        let want = &channels[&id];
        let ch = merge(&id, recs).unwrap();
        assert_eq!(
            ch.start_ns,
            want["start_ns"].as_i64().unwrap(),
            "{id}: start"
        );
        assert_eq!(
            record::iso8601(ch.start_ns),
            want["start"].as_str().unwrap().replace("Z", ".000000Z"),
            "{id}: start as text"
        );
        assert_eq!(ch.sample_rate_hz, want["sample_rate_hz"].as_f64().unwrap());
        let samples = want["samples"].as_array().unwrap();
        assert_eq!(ch.data.len(), samples.len(), "{id}: length");
        assert_eq!(ch.counts, want["kind"] == "int", "{id}: kind");
        for (k, (got, w)) in ch.data.iter().zip(samples).enumerate() {
            if w.is_null() {
                assert!(got.is_nan(), "{id}[{k}]: a gap in ObsPy, {got} here");
            } else if ch.counts {
                assert_eq!(*got, w.as_i64().unwrap() as f64, "{id}[{k}]");
            } else {
                let hex = w.as_str().unwrap();
                assert_eq!(*got, parse_hex_float(hex), "{id}[{k}]: {hex}");
            }
            compared += 1;
        }
    }
    compared
}

/// Parses Python's `float.hex()` text, e.g. `-0x1.8p-3`, exactly.
fn parse_hex_float(text: &str) -> f64 {
    let (neg, t) = match text.strip_prefix('-') {
        Some(t) => (true, t),
        None => (false, text),
    };
    if t == "0x0.0p+0" {
        return if neg { -0.0 } else { 0.0 };
    }
    let t = t.strip_prefix("0x").unwrap();
    let (mant, exp) = t.split_once('p').unwrap();
    let (int, frac) = mant.split_once('.').unwrap_or((mant, ""));
    let exp: i32 = exp.parse().unwrap();
    let mut bits: u64 = u64::from_str_radix(int, 16).unwrap();
    for c in frac.chars() {
        bits = (bits << 4) | c.to_digit(16).unwrap() as u64;
    }
    let shift = exp - 4 * frac.len() as i32;
    // `bits` has at most 53 significant bits and 2^shift is a normal number, so the product is
    // exact (the fixtures hold no subnormals).
    assert!(bits < 1 << 53 && shift >= -1022, "{text}");
    let v = bits as f64 * 2f64.powi(shift);
    if neg {
        -v
    } else {
        v
    }
}

#[test]
fn steim2_and_float64_with_a_gap_and_an_overlap_match_obspy() {
    assert_eq!(compare_with_obspy("gap_overlap"), 1200);
    let groups = groups("gap_overlap.mseed");
    let bje = merge(&groups[0].0, groups[0].1.iter().map(clone_placed).collect()).unwrap();
    assert_eq!(bje.gaps, vec![(200, 260)]);
    assert_eq!(bje.encodings, vec!["Steim-2"]);
    let bjn = merge(&groups[1].0, groups[1].1.iter().map(clone_placed).collect()).unwrap();
    assert_eq!(bjn.overlapping, 50);
    assert!(bjn.gaps.is_empty());
}

#[test]
fn little_endian_steim1_float32_int16_int32_match_obspy() {
    assert_eq!(compare_with_obspy("little_endian"), 2400);
}

#[test]
fn differing_overlap_is_refused() {
    let mut g = groups("overlap_differs.mseed");
    let (id, recs) = g.remove(0);
    let (at, message) = merge(&id, recs).unwrap_err();
    assert!(at.is_some());
    assert!(
        message.contains("overlapping records differ at 2018-01-23T09:32:09.000000Z"),
        "{message}"
    );
}

#[test]
fn damaged_records_are_errors() {
    let good = std::fs::read(fixture("gap_overlap.mseed")).unwrap();
    let rec = &good[..512];
    assert!(record::decode(rec).is_ok());
    let mut cases: Vec<(Vec<u8>, &str)> = Vec::new();
    let mut b = rec.to_vec();
    b[44] = 0xff; // data offset past the record
    cases.push((b, "data offset"));
    let mut b = rec.to_vec();
    let first = u16::from_be_bytes([b[46], b[47]]) as usize;
    b[first + 2] = (first >> 8) as u8; // blockette pointing to itself
    b[first + 3] = first as u8;
    cases.push((b, "points back"));
    let mut b = rec.to_vec();
    b[first + 6] = 40; // record length 2^40
    cases.push((b, "record length"));
    let mut b = rec.to_vec();
    b[20] = 0xff; // year
    b[21] = 0xff;
    cases.push((b, "not plausible"));
    let mut b = rec.to_vec();
    b[64 + 8..64 + 12].copy_from_slice(&12345i32.to_be_bytes()); // Xn
    cases.push((b, "reverse integration constant"));
    cases.push((rec[..300].to_vec(), "truncated"));
    cases.push((b"MS\x03rest of a version 3 record".to_vec(), "miniSEED 3"));
    for (bytes, needle) in cases {
        let e = record::decode(&bytes).unwrap_err();
        assert!(e.contains(needle), "{needle}: {e}");
    }
}

fn clone_placed(p: &Placed) -> Placed {
    Placed {
        record: p.record.clone(),
        index: p.index,
        offset: p.offset,
    }
}
