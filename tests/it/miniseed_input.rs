//! miniSEED input through the public readers and the command line: channels by SEED code with
//! the axis map, counts scaled with `--scale`, gaps under both policies, overlaps, and the
//! samples ObsPy reads from the same files (`tests/fixtures/input/miniseed/`, written by its
//! `make_miniseed_fixtures.py`).

use crate::common::{assert_fails, repo, tiltnoise};
use tiltnoise_core::model::TiltAxis;
use tiltnoise_io::input::{
    read_tilt, read_tilt_series, read_tilt_spectra, AxisMap, ChannelScale, GapPolicy, InputFormat,
    Quantity, ReadOptions,
};

fn fixture(name: &str) -> std::path::PathBuf {
    repo("tests/fixtures/input/miniseed").join(name)
}

fn reference(stem: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(fixture(&format!("{stem}.json"))).unwrap())
        .unwrap()
}

fn scales(list: &[&str]) -> Vec<ChannelScale> {
    list.iter().map(|s| s.parse().unwrap()).collect()
}

#[test]
fn counts_scaled_and_signed_equal_obspy_exactly() {
    // theta_t = -(2 * BJE counts), eta_t = +(5e-9 * BAE counts), both integers from ObsPy.
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=-BJE,eta_t=XX.TILT.00.BAE").unwrap()),
        quantity: Some(Quantity::Angle),
        scale: scales(&["BJE=2", "XX.TILT.00.BAE=5e-9"]),
        ..ReadOptions::default()
    };
    let s = read_tilt_series(&fixture("little_endian.mseed"), &opts).unwrap();
    let r = reference("little_endian");
    assert_eq!(s.axes, vec![TiltAxis::ThetaT, TiltAxis::EtaT]);
    assert_eq!(s.sample_rate_hz, 10.0);
    assert_eq!(s.provenance.format, InputFormat::Miniseed);
    assert_eq!(
        s.provenance.start_time.as_deref(),
        Some("2018-01-23T09:31:42.000000Z")
    );
    for (axis, (id, factor)) in [("XX.TILT.00.BJE", -2.0), ("XX.TILT.00.BAE", 5e-9)]
        .iter()
        .enumerate()
    {
        let want = r["channels"][id]["samples"].as_array().unwrap();
        assert_eq!(s.data[axis].len(), want.len());
        for (k, (got, w)) in s.data[axis].iter().zip(want).enumerate() {
            // One rounding at most: the factor times an integer below 2^30.
            let exact = factor * w.as_i64().unwrap() as f64;
            assert_eq!(*got, exact, "{id}[{k}]");
        }
    }
    assert!(
        s.provenance
            .notes
            .iter()
            .any(|n| n.contains("XX.TILT.00.BJE") && n.contains("multiplied by 2e0")),
        "{:?}",
        s.provenance.notes
    );
}

#[test]
fn counts_without_a_scale_are_refused() {
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=-BJE").unwrap()),
        ..ReadOptions::default()
    };
    let e = read_tilt(&fixture("little_endian.mseed"), &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("XX.TILT.00.BJE")
            && e.contains("digitizer counts (Steim-1)")
            && e.contains("scale"),
        "{e}"
    );
    // A scale for a channel the file does not have names the ones it has.
    let opts = ReadOptions {
        scale: scales(&["LJE=1"]),
        ..ReadOptions::default()
    };
    let e = read_tilt(&fixture("little_endian.mseed"), &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`LJE` is not a channel") && e.contains("XX.TILT.00.BJN"),
        "{e}"
    );
}

#[test]
fn default_mapping_takes_the_rotation_channels_and_their_quantity() {
    // BJE (Steim-1, counts), BJN (FLOAT32), BJZ (INT16) map by default; BAE is a tiltmeter
    // channel (angle), so it is left out rather than mixed with the rates.
    let opts = ReadOptions {
        scale: scales(&["BJE=1e-9", "BJZ=1e-9"]),
        ..ReadOptions::default()
    };
    let s = read_tilt_series(&fixture("little_endian.mseed"), &opts).unwrap();
    assert_eq!(s.axes, TiltAxis::ALL.to_vec());
    assert_eq!(s.quantity(), Quantity::Rate);
    assert_eq!(
        s.provenance.axis_map,
        "theta_t=-XX.TILT.00.BJE,eta_t=-XX.TILT.00.BJN,phi_t=-XX.TILT.00.BJZ"
    );
    let notes = s.provenance.notes.join("\n");
    assert!(
        notes.contains("FLOAT32 samples taken to be in rad/s"),
        "{notes}"
    );
    assert!(
        notes.contains("ignored channels: XX.TILT.00.BAE"),
        "{notes}"
    );
    // A tiltmeter channel and a rotation sensor together are refused without a quantity.
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=BAE,eta_t=-BJN").unwrap()),
        scale: scales(&["BAE=1e-9"]),
        ..ReadOptions::default()
    };
    let e = read_tilt(&fixture("little_endian.mseed"), &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`XX.TILT.00.BAE` is in rad but `XX.TILT.00.BJN` is in rad/s"),
        "{e}"
    );
}

#[test]
fn gaps_follow_the_gap_policy_and_identical_overlaps_are_read_once() {
    let path = fixture("gap_overlap.mseed");
    let map = AxisMap::parse("theta_t=-BJE,eta_t=-BJN").unwrap();
    let reject = ReadOptions {
        axis_map: Some(map.clone()),
        scale: scales(&["BJE=1e-9"]),
        ..ReadOptions::default()
    };
    let e = read_tilt_series(&path, &reject).unwrap_err().to_string();
    assert!(
        e.contains(
            "XX.TILT.00.BJE: no records for 60 samples from 2018-01-23T09:32:02.000000Z \
                    to 2018-01-23T09:32:07.900000Z (sample indices 200..=259"
        ) && e.contains("gap interpolation"),
        "{e}"
    );
    let interpolate = ReadOptions {
        gaps: GapPolicy::Interpolate,
        ..reject
    };
    let s = read_tilt_series(&path, &interpolate).unwrap();
    assert_eq!(s.len(), 600);
    let r = reference("gap_overlap");
    let bje = r["channels"]["XX.TILT.00.BJE"]["samples"]
        .as_array()
        .unwrap();
    let (a, b) = (
        -1e-9 * bje[199].as_i64().unwrap() as f64,
        -1e-9 * bje[260].as_i64().unwrap() as f64,
    );
    for k in 200..260 {
        // The bridge between the gap's neighbours, as the gap policy computes it.
        let want = a + (b - a) * ((k - 199) as f64 / 61.0);
        assert_eq!(s.data[0][k], want, "bridged sample {k}");
    }
    let notes = s.provenance.notes.join("\n");
    assert!(notes.contains("1 gaps (60 samples"), "{notes}");
    assert!(
        notes.contains("50 samples in identical overlaps kept once"),
        "{notes}"
    );

    let e = read_tilt_series(
        &fixture("overlap_differs.mseed"),
        &ReadOptions {
            axis_map: Some(AxisMap::parse("eta_t=-BJN").unwrap()),
            ..ReadOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("overlapping records differ at 2018-01-23T09:32:09.000000Z (sample index 270)"),
        "{e}"
    );
    let e = read_tilt_spectra(&path, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("expected spectra but the file holds series"),
        "{e}"
    );
}

#[test]
fn budget_reads_miniseed_from_the_command_line() {
    let path = fixture("gap_overlap.mseed");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        path.to_str().unwrap(),
        "--axes",
        "theta_t=-BJE,eta_t=-BJN",
        "--scale",
        "BJE=1e-9",
        "--gaps",
        "interpolate",
        "--nperseg",
        "256",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("input: channel `XX.TILT.00.BJE`: samples multiplied by 1e-9 (given explicitly) before the axis map"),
        "{stdout}"
    );
    assert_fails(
        &[
            "budget",
            "--tilt",
            path.to_str().unwrap(),
            "--scale",
            "BJE=abc",
        ],
        &[
            "--scale",
            "factor `abc` of channel `BJE`",
            "finite, non-zero",
        ],
    );
    assert_fails(
        &["budget", "--tilt", path.to_str().unwrap()],
        &["XX.TILT.00.BJE", "digitizer counts (Steim-2)"],
    );
}

/// Channels whose samples fall between each other's: the message names the channel off the
/// grid and the one that sets it (the one starting last), each with its own start time.
#[test]
fn channels_off_each_others_grid_are_both_named() {
    let path = fixture("off_grid.mseed");
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=-BJE,eta_t=-BJN").unwrap()),
        quantity: Some(Quantity::Rate),
        ..ReadOptions::default()
    };
    let e = read_tilt_series(&path, &opts).unwrap_err().to_string();
    assert!(
        e.contains("channel XX.TILT.00.BJE starts at 2018-01-23T09:31:42")
            && e.contains("and XX.TILT.00.BJN at 2018-01-23T09:31:42.05"),
        "{e}"
    );
    assert!(e.contains("not on one time grid"), "{e}");
}
