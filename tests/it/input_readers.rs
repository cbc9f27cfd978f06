//! Floor-tilt input readers: time series and spectra from HDF5 and CSV, strict validation,
//! axis mapping and signs, gap handling, rate integration, streaming == in-memory bit for bit,
//! log-log interpolation.

use crate::common;

use hdf5::types::{FixedAscii, VarLenUnicode};
use ndarray::{arr0, Array1, Array2, Array3};
use num_complex::Complex64;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::model::{Input, TiltAxis, TranslationAxis};
use tiltnoise_io::input::{
    read_tilt, read_tilt_series, read_tilt_spectra, AxisMap, FormatError, GapPolicy, InputError,
    InputFormat, InputKind, Quantity, ReadOptions, Sign, TiltInput, TiltSeriesSource, TiltSpectra,
};

// ---------------------------------------------------------------------------------------------
// Fixture writers
// ---------------------------------------------------------------------------------------------

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn vstr(s: &str) -> VarLenUnicode {
    s.parse().unwrap()
}

fn str_attr(loc: &hdf5::Location, name: &str, value: &str) {
    loc.new_attr_builder()
        .with_data(&arr0(vstr(value)))
        .create(name)
        .unwrap();
}

fn f64_attr(loc: &hdf5::Location, name: &str, value: f64) {
    loc.new_attr::<f64>()
        .create(name)
        .unwrap()
        .write_scalar(&value)
        .unwrap();
}

/// A channel of an HDF5 series fixture: name, samples, optional `units` attribute.
struct Ch<'a>(&'a str, &'a [f64], Option<&'a str>);

/// Writes an HDF5 tilt series; `attrs` are extra root string attributes.
fn write_series_h5(path: &Path, fs: Option<f64>, channels: &[Ch<'_>], attrs: &[(&str, &str)]) {
    let file = hdf5::File::create(path).unwrap();
    if let Some(fs) = fs {
        f64_attr(&file, "sample_rate_hz", fs);
    }
    for (k, v) in attrs {
        str_attr(&file, k, v);
    }
    for Ch(name, data, units) in channels {
        let ds = file
            .new_dataset_builder()
            .with_data(&Array1::from(data.to_vec()))
            .create(*name)
            .unwrap();
        if let Some(u) = units {
            str_attr(&ds, "units", u);
        }
    }
    file.close().unwrap();
}

fn write_text(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
}

/// `time_s,<names>` CSV with `fs` Hz; values printed with Rust's shortest round-trip format.
fn write_series_csv(path: &Path, fs: f64, names: &[&str], data: &[&[f64]], prelude: &str) {
    let mut s = String::from(prelude);
    s.push_str("time_s");
    for n in names {
        s.push(',');
        s.push_str(n);
    }
    s.push('\n');
    for i in 0..data[0].len() {
        s.push_str(&format!("{}", i as f64 / fs));
        for d in data {
            s.push_str(&format!(",{}", d[i]));
        }
        s.push('\n');
    }
    write_text(path, &s);
}

fn opts(map: Option<&str>, quantity: Option<Quantity>, gaps: GapPolicy) -> ReadOptions {
    ReadOptions {
        axis_map: map.map(|m| AxisMap::parse(m).unwrap()),
        quantity,
        gaps,
        ..ReadOptions::default()
    }
}

fn series(path: &Path, o: &ReadOptions) -> tiltnoise_io::input::TiltSeries {
    read_tilt_series(path, o).unwrap_or_else(|e| panic!("{e}"))
}

/// The error message, asserting it names the file and every `needle`.
fn err_msg(e: InputError, path: &Path, needles: &[&str]) -> String {
    let msg = e.to_string();
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(
        msg.contains(name),
        "message does not name the file {name}: {msg}"
    );
    for n in needles {
        assert!(msg.contains(n), "message does not contain `{n}`: {msg}");
    }
    msg
}

fn series_err(path: &Path, o: &ReadOptions) -> InputError {
    match read_tilt_series(path, o) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e,
    }
}

fn spectra_err(path: &Path, o: &ReadOptions) -> InputError {
    match read_tilt_spectra(path, o) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e,
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Deterministic pseudo-random numbers in [-1, 1) (xorshift).
fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/input")
        .join(name)
}

// ---------------------------------------------------------------------------------------------
// Axis map syntax
// ---------------------------------------------------------------------------------------------

#[test]
fn axis_map_parses_and_prints() {
    let m = AxisMap::parse("theta_t=-E,eta_t=-N").unwrap();
    assert_eq!(m.entries().len(), 2);
    assert_eq!(m.entries()[0].target, Input::Tilt(TiltAxis::ThetaT));
    assert_eq!(m.entries()[0].sign, Sign::Minus);
    assert_eq!(m.entries()[0].source, "E");
    assert_eq!(m.entries()[1].target, Input::Tilt(TiltAxis::EtaT));
    assert_eq!(m.to_string(), "theta_t=-E,eta_t=-N");
    let m: AxisMap = " phi_t = +LJZ ".parse().unwrap();
    assert_eq!(m.entries()[0].sign, Sign::Plus);
    assert_eq!(m.to_string(), "phi_t=LJZ");
}

#[test]
fn axis_map_syntax_errors_name_the_entry() {
    for (spec, entry, what) in [
        ("theta_t=-E,eta_t", "eta_t", "missing `=`"),
        ("u_t=E", "u_t=E", "unknown target `u_t`"),
        ("theta_t=", "theta_t=", "empty source"),
        ("theta_t=--E", "theta_t=--E", "more than one sign"),
        ("theta_t=E,theta_t=N", "theta_t=N", "assigned twice"),
        ("theta_t=E,eta_t=-E", "eta_t=-E", "used twice"),
        ("theta_t=E,", "", "empty entry"),
        ("", "", "empty specification"),
    ] {
        let e = AxisMap::parse(spec).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, InputError::AxisMapSyntax { .. }), "{msg}");
        assert!(msg.contains(&format!("entry `{entry}`")), "{msg}");
        assert!(msg.contains(what), "{msg}");
        assert!(msg.contains("theta_t, eta_t, phi_t"), "{msg}");
    }
}

// ---------------------------------------------------------------------------------------------
// Mapping signs
// ---------------------------------------------------------------------------------------------

#[test]
fn default_mapping_of_instrument_channels_is_minus_e_minus_n_minus_z() {
    let dir = tmp();
    let p = dir.path().join("enz.h5");
    let (e, n, z) = (
        vec![1.0, 2.0, 3.0],
        vec![10.0, 20.0, 30.0],
        vec![5e-3, -5e-3, 2.5e-3],
    );
    write_series_h5(
        &p,
        Some(4.0),
        &[
            Ch("E", &e, None),
            Ch("N", &n, None),
            Ch("Z", &z, None),
            Ch("T", &e, None),
        ],
        &[],
    );
    let s = series(&p, &ReadOptions::default());
    match read_tilt(&p, &ReadOptions::default()).unwrap() {
        TiltInput::Series(t) => assert_eq!(t, s),
        TiltInput::Spectra(_) => panic!("HDF5 series read as spectra"),
    }
    assert_eq!(
        s.axes,
        vec![TiltAxis::ThetaT, TiltAxis::EtaT, TiltAxis::PhiT]
    );
    assert_eq!(s.data[0], vec![-1.0, -2.0, -3.0]);
    assert_eq!(s.data[1], vec![-10.0, -20.0, -30.0]);
    assert_eq!(s.data[2], vec![-5e-3, 5e-3, -2.5e-3]);
    assert_eq!(s.sample_rate_hz, 4.0);
    assert_eq!(s.len(), 3);
    let pr = &s.provenance;
    assert_eq!(pr.axis_map, "theta_t=-E,eta_t=-N,phi_t=-Z");
    assert_eq!(pr.format, InputFormat::Hdf5);
    assert_eq!(pr.kind, InputKind::Series);
    assert_eq!(pr.quantity, Quantity::Angle);
    let notes = pr.notes.join("\n");
    assert!(notes.contains("default"), "{notes}");
    assert!(notes.contains("assumed angle"), "{notes}");
    assert!(notes.contains("ignored datasets: T"), "{notes}");

    // Explicit map: signs and sources as written; only the mapped axes.
    let s = series(
        &p,
        &opts(Some("theta_t=N,eta_t=-E"), None, GapPolicy::Reject),
    );
    assert_eq!(s.axes, vec![TiltAxis::ThetaT, TiltAxis::EtaT]);
    assert_eq!(s.data[0], n);
    assert_eq!(s.data[1], vec![-1.0, -2.0, -3.0]);
    assert_eq!(s.channel(TiltAxis::PhiT), None);
    assert_eq!(s.provenance.axis_map, "theta_t=N,eta_t=-E");
}

#[test]
fn tiltnoise_names_map_to_themselves_and_file_map_is_used_and_overridable() {
    let dir = tmp();
    let p = dir.path().join("named.h5");
    let (a, b) = (vec![1.0, 2.0], vec![3.0, 4.0]);
    write_series_h5(
        &p,
        Some(1.0),
        &[Ch("theta_t", &a, None), Ch("eta_t", &b, None)],
        &[],
    );
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.data, vec![a.clone(), b.clone()]);
    assert_eq!(s.provenance.axis_map, "theta_t=theta_t,eta_t=eta_t");

    let p = dir.path().join("filemap.h5");
    write_series_h5(
        &p,
        Some(1.0),
        &[Ch("X1", &a, None), Ch("X2", &b, None)],
        &[("axis_map", "eta_t=-X1,theta_t=X2")],
    );
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.axes, vec![TiltAxis::ThetaT, TiltAxis::EtaT]);
    assert_eq!(s.data, vec![b.clone(), vec![-1.0, -2.0]]);
    let s = series(&p, &opts(Some("theta_t=-X1"), None, GapPolicy::Reject));
    assert_eq!(s.data, vec![vec![-1.0, -2.0]]);
    assert!(s.provenance.notes.join(" ").contains("overrides"));

    // CSV: `# axes:` line.
    let p = dir.path().join("filemap.csv");
    write_series_csv(&p, 1.0, &["X1", "X2"], &[&a, &b], "# axes: theta_t=-X2\n");
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.data, vec![vec![-3.0, -4.0]]);
}

#[test]
fn mapping_errors() {
    let dir = tmp();
    let p = dir.path().join("amb.h5");
    let a = vec![1.0, 2.0];
    write_series_h5(
        &p,
        Some(1.0),
        &[Ch("E", &a, None), Ch("LJE", &a, None)],
        &[],
    );
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(e, InputError::AmbiguousAxis { .. }));
    err_msg(e, &p, &["E, LJE", "theta_t"]);

    let e = series_err(&p, &opts(Some("theta_t=-Q"), None, GapPolicy::Reject));
    assert!(matches!(e, InputError::AxisMapSource { .. }));
    err_msg(e, &p, &["`Q`", "theta_t", "E, LJE"]);

    let p = dir.path().join("none.csv");
    write_series_csv(&p, 1.0, &["LXN", "foo"], &[&a, &a], "");
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(e, InputError::NoAxes { .. }));
    err_msg(e, &p, &["LXN, foo", "theta_t=-E"]);

    let p = dir.path().join("badmap.h5");
    write_series_h5(
        &p,
        Some(1.0),
        &[Ch("E", &a, None)],
        &[("axis_map", "theta_t=E=F")],
    );
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["axis_map", "theta_t=E=F"]);
}

// ---------------------------------------------------------------------------------------------
// CSV series, ROMY
// ---------------------------------------------------------------------------------------------

#[test]
fn romy_layout_fixture_reads_with_mapping_and_rate() {
    // Synthetic file in the ROMY export's layout (comments, time_s,LHN,LHE,LHZ,LJN,LJE,LJZ).
    let p = fixture("romy_layout.csv");
    let o = opts(
        Some("theta_t=-LJE,eta_t=-LJN"),
        Some(Quantity::Rate),
        GapPolicy::Reject,
    );
    let s = series(&p, &o);
    assert_eq!(s.len(), 6);
    assert_eq!(s.sample_rate_hz, 1.0);
    assert_eq!(s.axes, vec![TiltAxis::ThetaT, TiltAxis::EtaT]);
    // A rate is kept as read, signed by the map: LJE = 1, 3, 1, ... nrad/s -> theta_t = -LJE;
    // LJN = 0, 2, 4, ... nrad/s -> eta_t = -LJN.
    assert_eq!(s.data[0], [-1e-9, -3e-9, -1e-9, -3e-9, -1e-9, -3e-9]);
    assert_eq!(s.data[1], [0.0, -2e-9, -4e-9, -6e-9, -8e-9, -1e-8]);
    let pr = &s.provenance;
    assert_eq!(
        (pr.quantity, s.quantity()),
        (Quantity::Rate, Quantity::Rate)
    );
    assert!(pr.notes.join(" ").contains("divided by (2 pi f)^2"));
    assert_eq!(pr.axis_map, "theta_t=-LJE,eta_t=-LJN");
    assert_eq!(pr.format, InputFormat::Csv);
    assert_eq!(pr.start_time, None);
    let notes = pr.notes.join("\n");
    assert!(
        notes.contains("ignored columns: LHN, LHE, LHZ, LJZ"),
        "{notes}"
    );
    assert!(notes.contains("given explicitly"), "{notes}");

    // The default mapping picks the SEED rotation channels ?JE/?JN/?JZ with minus signs and
    // the seismometer channels ?HE/?HN/?HZ as translations, which need their unit.
    let rate = opts(None, Some(Quantity::Rate), GapPolicy::Reject);
    let e = series_err(&p, &rate);
    assert!(matches!(e, InputError::ChannelUnit { .. }), "{e}");
    err_msg(
        e,
        &p,
        &[
            "channel `LHE`",
            "feeds x_t",
            "has no unit",
            // The option by its key: no front end spells it in a library call.
            "units LHE=m/s^2",
        ],
    );
    let units = ["LHE", "LHN", "LHZ"].map(|c| format!("{c}=m/s^2").parse().unwrap());
    let s2 = series(
        &p,
        &ReadOptions {
            units: units.to_vec(),
            ..rate
        },
    );
    assert_eq!(s2.axes, TiltAxis::ALL.to_vec());
    assert_eq!(
        s2.provenance.axis_map,
        "theta_t=-LJE,eta_t=-LJN,phi_t=-LJZ,x_t=LHE,y_t=LHN,z_t=LHZ"
    );
    assert_eq!(bits(&s2.data[0]), bits(&s.data[0]));
    assert_eq!(bits(&s2.data[1]), bits(&s.data[1]));
    let x = &s2.translations[0];
    assert_eq!(
        (x.axis, x.quantity),
        (TranslationAxis::XT, GroundQuantity::Acceleration)
    );
    assert_eq!(x.data[..2], [2e-8, -2e-8]);
}

#[test]
fn romy_teleseism_csv_reads() {
    let Some(p) = common::shared_tilt_data(
        "romy_teleseism_csv_reads",
        "romy_6c_teleseism_20180123/ROMY_gulf_of_alaska_teleseism.csv",
    ) else {
        return;
    };
    let p = p.as_path();
    let o = opts(
        Some("theta_t=-LJE,eta_t=-LJN"),
        Some(Quantity::Rate),
        GapPolicy::Reject,
    );
    let s = match read_tilt(p, &o).unwrap() {
        TiltInput::Series(s) => s,
        TiltInput::Spectra(_) => panic!("ROMY read as spectra"),
    };
    assert_eq!(s.len(), 8192);
    assert_eq!(s.sample_rate_hz, 1.0);
    assert_eq!(s.axes, vec![TiltAxis::ThetaT, TiltAxis::EtaT]);
    assert_eq!(s.quantity(), Quantity::Rate);
    // The rate as read from the raw text, signed by the map: theta_t = -LJE, bit for bit.
    let text = std::fs::read_to_string(p).unwrap();
    let lje: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("time_s"))
        .map(|l| l.split(',').nth(5).unwrap().parse::<f64>().unwrap())
        .collect();
    assert_eq!(lje.len(), 8192);
    let minus: Vec<f64> = lje.iter().map(|x| -x).collect();
    assert_eq!(bits(&s.data[0]), bits(&minus));
    // Rotation rates of a teleseism: of order 1e-10 .. 1e-6 rad/s.
    let max = s.data[0].iter().fold(0f64, |m, x| m.max(x.abs()));
    assert!(max > 1e-10 && max < 1e-4, "max |theta_t rate| = {max}");
}

#[test]
fn csv_units_line_sets_the_quantity() {
    let dir = tmp();
    let p = dir.path().join("units.csv");
    write_series_csv(
        &p,
        2.0,
        &["theta_t"],
        &[&[1.0, 3.0, 1.0]],
        "# units: rad/s\n",
    );
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.provenance.quantity, Quantity::Rate);
    assert_eq!(s.data[0], vec![1.0, 3.0, 1.0], "a rate is kept as read");

    let p = dir.path().join("units_per_column.csv");
    write_series_csv(
        &p,
        2.0,
        &["theta_t", "eta_t"],
        &[&[1.0, 3.0], &[1.0, 3.0]],
        "# units: theta_t=rad, eta_t=rad/s\n",
    );
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(e, InputError::MixedQuantity { .. }));
    err_msg(e, &p, &["theta_t", "eta_t", "rad/s"]);
    // An explicit quantity resolves the conflict, with a note.
    let s = series(&p, &opts(None, Some(Quantity::Angle), GapPolicy::Reject));
    assert!(s
        .provenance
        .notes
        .join(" ")
        .contains("overrides the file's units"));

    let p = dir.path().join("units_bad.csv");
    write_series_csv(&p, 2.0, &["theta_t"], &[&[1.0, 3.0]], "# units: deg\n");
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(e, InputError::Units { .. }));
    err_msg(e, &p, &["line 1", "`deg`", "rad/s"]);

    let p = dir.path().join("start.csv");
    write_series_csv(
        &p,
        2.0,
        &["theta_t"],
        &[&[1.0, 3.0]],
        "# start_time: 2018-01-23T09:31:42Z\n# description: quiet night\n",
    );
    let s = series(&p, &ReadOptions::default());
    assert_eq!(
        s.provenance.start_time.as_deref(),
        Some("2018-01-23T09:31:42Z")
    );
    assert!(s
        .provenance
        .notes
        .iter()
        .any(|n| n == "description: quiet night"));

    let p = dir.path().join("start_bad.csv");
    write_series_csv(
        &p,
        2.0,
        &["theta_t"],
        &[&[1.0, 3.0]],
        "# start_time: 23/01/2018\n",
    );
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["start_time", "23/01/2018", "ISO 8601"]);
}

#[test]
fn csv_time_column_errors_name_the_row() {
    let dir = tmp();
    let p = dir.path().join("t_dec.csv");
    write_text(&p, "time_s,theta_t\n0.0,1\n1.0,2\n1.0,3\n");
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::TimeNotIncreasing { .. })
    ));
    err_msg(e, &p, &["line 4", "sample index 2", "time_s = 1.0 s"]);

    let p = dir.path().join("t_nonuni.csv");
    write_text(
        &p,
        "# c\ntime_s,theta_t\n0.0,1\n1.0,2\n2.0,3\n3.5,4\n4.0,5\n",
    );
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::TimeNotUniform { .. })
    ));
    err_msg(
        e,
        &p,
        &["line 6", "sample index 3", "3.5", "printed precision"],
    );

    // Uniform within the printed precision: dt = 1/3 printed with 3 decimals.
    let p = dir.path().join("t_third.csv");
    write_text(&p, "time_s,theta_t\n0.000,1\n0.333,2\n0.667,3\n1.000,4\n");
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.sample_rate_hz, 3.0);
    // ... but not with an error of 2 ms.
    let p = dir.path().join("t_third_bad.csv");
    write_text(&p, "time_s,theta_t\n0.000,1\n0.335,2\n0.667,3\n1.000,4\n");
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["line 3", "sample index 1"]);

    let p = dir.path().join("t_nan.csv");
    write_text(&p, "time_s,theta_t\n0,1\nnan,2\n");
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["line 3", "time_s", "nan"]);

    let p = dir.path().join("short.csv");
    write_text(&p, "time_s,theta_t\n0,1\n");
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(e, InputError::TooShort { .. }));
    err_msg(e, &p, &["1 samples", "at least 2"]);
}

#[test]
fn csv_structure_errors() {
    let dir = tmp();
    let p = dir.path().join("fields.csv");
    write_text(&p, "time_s,theta_t,eta_t\n0,1,2\n1,2\n");
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["line 3", "2 fields", "header has 3"]);

    let p = dir.path().join("word.csv");
    write_text(&p, "time_s,theta_t\n0,1\n1,abc\n");
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::CsvNumber { .. })
    ));
    err_msg(e, &p, &["line 3", "theta_t", "`abc`", "rad"]);

    let p = dir.path().join("dup.csv");
    write_text(&p, "time_s,theta_t,theta_t\n0,1,1\n");
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["line 1", "`theta_t` appears twice"]);

    let p = dir.path().join("layout.csv");
    write_text(&p, "# hello\nt,theta_t\n0,1\n");
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, InputError::UnknownLayout { .. }));
    err_msg(
        e,
        &p,
        &["line 2", "`t`", "time_s", "freq_hz", "accepted layouts"],
    );

    let p = dir.path().join("empty.csv");
    write_text(&p, "# only a comment\n");
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    err_msg(e, &p, &["no header"]);

    let p = dir.path().join("tilt.txt");
    write_text(&p, "time_s,theta_t\n0,1\n1,2\n");
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, InputError::Extension { .. }));
    err_msg(e, &p, &["`txt`", ".h5", ".csv"]);

    let p = dir.path().join("missing.csv");
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, InputError::Io { .. }));
    err_msg(e, &p, &[]);

    let p = dir.path().join("not_hdf5.h5");
    write_text(&p, "time_s,theta_t\n0,1\n1,2\n");
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::Hdf5 { .. })
    ));
    err_msg(e, &p, &["HDF5"]);
}

// ---------------------------------------------------------------------------------------------
// HDF5 series validation
// ---------------------------------------------------------------------------------------------

#[test]
fn hdf5_series_attribute_and_shape_errors() {
    let dir = tmp();
    let a = vec![1.0, 2.0, 3.0];

    let p = dir.path().join("no_rate.h5");
    write_series_h5(&p, None, &[Ch("theta_t", &a, None)], &[]);
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::MissingAttribute { .. })
    ));
    err_msg(e, &p, &["sample_rate_hz", "missing", "Hz", "> 0"]);
    let e = TiltSeriesSource::open(&p, &ReadOptions::default()).unwrap_err();
    err_msg(e, &p, &["sample_rate_hz"]);
    // read_tilt cannot tell the kind: names both layouts and what is missing.
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    err_msg(e, &p, &["sample_rate_hz", "frequency_hz", "theta_t"]);

    for (fs, shown) in [
        (0.0, "= 0 "),
        (-10.0, "-10"),
        (f64::NAN, "NaN"),
        (f64::INFINITY, "inf"),
    ] {
        let p = dir.path().join("bad_rate.h5");
        write_series_h5(&p, Some(fs), &[Ch("theta_t", &a, None)], &[]);
        let e = series_err(&p, &ReadOptions::default());
        assert!(matches!(e, InputError::BadAttribute { .. }));
        err_msg(e, &p, &["sample_rate_hz", shown, "finite number > 0"]);
    }
    /// A series file that `read_tilt_series` refuses: the error `is` the right variant and its
    /// message names the file and every needle.
    struct Case<'a> {
        file: &'a str,
        fs: Option<f64>,
        channels: Vec<Ch<'a>>,
        attrs: &'a [(&'a str, &'a str)],
        is: fn(&InputError) -> bool,
        needles: &'a [&'a str],
    }
    let cases = [
        Case {
            file: "str_rate.h5",
            fs: None,
            channels: vec![Ch("theta_t", &a, None)],
            attrs: &[("sample_rate_hz", "10 Hz")],
            is: |_| true,
            needles: &["sample_rate_hz", "`10 Hz`"],
        },
        Case {
            file: "lengths.h5",
            fs: Some(1.0),
            channels: vec![Ch("theta_t", &a, None), Ch("eta_t", &[1.0, 2.0], None)],
            attrs: &[],
            is: |e| matches!(e, InputError::LengthMismatch { .. }),
            needles: &["`theta_t` has 3 samples", "`eta_t` has 2"],
        },
        Case {
            file: "one.h5",
            fs: Some(1.0),
            channels: vec![Ch("theta_t", &[1.0], None)],
            attrs: &[],
            is: |e| matches!(e, InputError::TooShort { .. }),
            needles: &["/theta_t", "1 samples", "at least 2"],
        },
        Case {
            file: "units.h5",
            fs: Some(1.0),
            channels: vec![Ch("theta_t", &a, Some("deg"))],
            attrs: &[],
            is: |e| matches!(e, InputError::Units { .. }),
            needles: &["units", "/theta_t", "`deg`", "rad/s"],
        },
        Case {
            file: "mixed.h5",
            fs: Some(1.0),
            channels: vec![
                Ch("theta_t", &a, Some("rad")),
                Ch("eta_t", &a, Some("rad/s")),
            ],
            attrs: &[],
            is: |_| true,
            needles: &["eta_t", "rad/s", "theta_t"],
        },
        Case {
            file: "start.h5",
            fs: Some(1.0),
            channels: vec![Ch("theta_t", &a, None)],
            attrs: &[("start_time", "noon")],
            is: |_| true,
            needles: &["start_time", "`noon`", "ISO 8601"],
        },
        Case {
            file: "schema.h5",
            fs: Some(1.0),
            channels: vec![Ch("theta_t", &a, None)],
            attrs: &[("schema", "tiltnoise.tf")],
            is: |_| true,
            needles: &["schema", "tiltnoise.tf", "tiltnoise.tilt_series"],
        },
    ];
    for case in cases {
        let p = dir.path().join(case.file);
        write_series_h5(&p, case.fs, &case.channels, case.attrs);
        let e = series_err(&p, &ReadOptions::default());
        assert!((case.is)(&e), "{}: unexpected error {e:?}", case.file);
        err_msg(e, &p, case.needles);
    }

    let p = dir.path().join("version.h5");
    write_series_h5(
        &p,
        Some(1.0),
        &[Ch("theta_t", &a, None)],
        &[("schema", "tiltnoise.tilt_series")],
    );
    {
        let f = hdf5::File::open_rw(&p).unwrap();
        f64_attr(&f, "schema_version", 2.0);
    }
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["schema_version", "= 2", "1"]);

    let p = dir.path().join("twod.h5");
    {
        let f = hdf5::File::create(&p).unwrap();
        f64_attr(&f, "sample_rate_hz", 1.0);
        f.new_dataset_builder()
            .with_data(&Array2::<f64>::zeros((2, 2)))
            .create("theta_t")
            .unwrap();
    }
    let e = series_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::BadDataset { .. })
    ));
    err_msg(e, &p, &["/theta_t", "[2, 2]", "1-D"]);

    let p = dir.path().join("ints.h5");
    {
        let f = hdf5::File::create(&p).unwrap();
        f64_attr(&f, "sample_rate_hz", 1.0);
        f.new_dataset_builder()
            .with_data(&Array1::from(vec![1i32, 2, 3]))
            .create("theta_t")
            .unwrap();
    }
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["/theta_t", "float64"]);
}

#[test]
fn hdf5_series_metadata_full_schema_and_fixed_strings() {
    let dir = tmp();
    let p = dir.path().join("full.h5");
    let a = vec![0.5, 1.5, 2.5, 3.5];
    write_series_h5(
        &p,
        Some(10.0),
        &[Ch("theta_t", &a, Some("rad")), Ch("eta_t", &a, Some("rad"))],
        &[
            ("schema", "tiltnoise.tilt_series"),
            ("start_time", "2024-03-01T00:00:00Z"),
            ("description", "PETER lab floor, tiltmeter A"),
        ],
    );
    {
        let f = hdf5::File::open_rw(&p).unwrap();
        f.new_attr::<i64>()
            .create("schema_version")
            .unwrap()
            .write_scalar(&1i64)
            .unwrap();
    }
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.sample_rate_hz, 10.0);
    assert_eq!(
        s.provenance.start_time.as_deref(),
        Some("2024-03-01T00:00:00Z")
    );
    assert_eq!(s.provenance.quantity, Quantity::Angle);
    let notes = s.provenance.notes.join("\n");
    assert!(notes.contains("PETER lab floor"), "{notes}");
    assert!(notes.contains("from the file's units `rad`"), "{notes}");
    assert!((s.duration_s() - 0.3).abs() < 1e-15);

    // Fixed-length ASCII strings (h5py's numpy bytes) and an integer sample rate.
    let p = dir.path().join("fixed.h5");
    {
        let f = hdf5::File::create(&p).unwrap();
        f.new_attr::<i64>()
            .create("sample_rate_hz")
            .unwrap()
            .write_scalar(&2i64)
            .unwrap();
        let ds = f
            .new_dataset_builder()
            .with_data(&Array1::from(a.clone()))
            .create("N")
            .unwrap();
        let u = FixedAscii::<5>::from_ascii(b"rad/s").unwrap();
        ds.new_attr::<FixedAscii<5>>()
            .create("units")
            .unwrap()
            .write_scalar(&u)
            .unwrap();
    }
    let s = series(&p, &ReadOptions::default());
    assert_eq!(s.sample_rate_hz, 2.0);
    assert_eq!(s.provenance.quantity, Quantity::Rate);
    assert_eq!(s.axes, vec![TiltAxis::EtaT]);
}

// ---------------------------------------------------------------------------------------------
// Gaps
// ---------------------------------------------------------------------------------------------

#[test]
fn nan_refused_or_interpolated() {
    let dir = tmp();
    let mut a: Vec<f64> = (0..10).map(|k| k as f64).collect();
    a[5] = f64::NAN;
    a[6] = f64::INFINITY;
    let b: Vec<f64> = (0..10).map(|k| 2.0 * k as f64).collect();

    let h5 = dir.path().join("gaps.h5");
    write_series_h5(&h5, Some(1.0), &[Ch("E", &a, None), Ch("N", &b, None)], &[]);
    let csv = dir.path().join("gaps.csv");
    write_series_csv(&csv, 1.0, &["E", "N"], &[&a, &b], "");

    let e = series_err(&h5, &ReadOptions::default());
    assert!(matches!(e, InputError::NonFinite { index: 5, .. }));
    err_msg(
        e,
        &h5,
        &["`E`", "sample index 5", "NaN", "rad", "interpolation"],
    );
    let e = series_err(&csv, &ReadOptions::default());
    err_msg(e, &csv, &["`E`", "sample index 5", "line 7", "NaN"]);

    // Streaming with gaps rejected: the chunk that contains the gap fails, naming the
    // absolute index; chunks before it are fine.
    let mut src = TiltSeriesSource::open(&h5, &ReadOptions::default()).unwrap();
    assert!(src.read_chunk(0, 5).is_ok());
    let e = src.read_chunk(4, 3).unwrap_err();
    err_msg(e, &h5, &["sample index 5"]);

    let o = opts(None, None, GapPolicy::Interpolate);
    let expect: Vec<f64> = (0..10).map(|k| -(k as f64)).collect();
    for p in [&h5, &csv] {
        let s = series(p, &o);
        assert_eq!(s.data[0], expect, "{}", p.display());
        assert!(s
            .provenance
            .notes
            .join(" ")
            .contains("2 non-finite samples bridged"));
    }

    // Empty CSV fields are gaps too.
    let p = dir.path().join("empty_field.csv");
    write_text(&p, "time_s,theta_t\n0,0\n1,\n2,4\n");
    let e = series_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["sample index 1", "line 3"]);
    assert_eq!(series(&p, &o).data[0], vec![0.0, 2.0, 4.0]);

    // Leading and trailing gaps cannot be bridged.
    for (name, data, edge, range) in [
        (
            "lead.h5",
            vec![f64::NAN, f64::NAN, 1.0, 2.0],
            "leading",
            "0..=1",
        ),
        (
            "trail.h5",
            vec![1.0, 2.0, 3.0, f64::NAN],
            "trailing",
            "3..=3",
        ),
    ] {
        let p = dir.path().join(name);
        write_series_h5(&p, Some(1.0), &[Ch("theta_t", &data, None)], &[]);
        let e = series_err(&p, &o);
        assert!(matches!(e, InputError::EdgeGap { .. }));
        err_msg(e, &p, &[edge, range, "theta_t", "of 4 samples"]);
    }
}

// ---------------------------------------------------------------------------------------------
// Rate series
// ---------------------------------------------------------------------------------------------

#[test]
fn rate_series_are_kept_as_rates_bit_for_bit() {
    // No time integration: the samples come back as stored (signed by the map), from HDF5 and
    // CSV alike, whole or in chunks; the spectra turn them into angle (budget tests).
    let dir = tmp();
    let (fs, f0, amp, n) = (10.0, 0.0123, 3e-9, 5000);
    let rate: Vec<f64> = (0..n)
        .map(|k| amp * (TAU * f0 * k as f64 / fs).cos() + 7e-9)
        .collect();
    let h5 = dir.path().join("rate.h5");
    write_series_h5(&h5, Some(fs), &[Ch("theta_t", &rate, Some("rad/s"))], &[]);
    let csv = dir.path().join("rate.csv");
    write_series_csv(&csv, fs, &["theta_t"], &[&rate], "# units: rad/s\n");
    for p in [&h5, &csv] {
        let s = series(p, &ReadOptions::default());
        assert_eq!(s.quantity(), Quantity::Rate, "{}", p.display());
        assert_eq!(bits(&s.data[0]), bits(&rate), "{}", p.display());
        let notes = s.provenance.notes.join(" ");
        assert!(notes.contains("nothing is integrated in time"), "{notes}");
        assert!(
            notes.contains("f = 0 carries no angle information"),
            "{notes}"
        );
    }
    let mut src = TiltSeriesSource::open(&h5, &ReadOptions::default()).unwrap();
    assert_eq!(src.quantity(), Quantity::Rate);
    assert_eq!(
        bits(&src.read_chunk(4000, 7).unwrap()[0]),
        bits(&rate[4000..4007])
    );
    // A minus sign in the map applies to the rate as it would to the angle.
    let o = opts(Some("theta_t=-theta_t"), None, GapPolicy::Reject);
    let minus: Vec<f64> = rate.iter().map(|x| -x).collect();
    assert_eq!(bits(&series(&h5, &o).data[0]), bits(&minus));
}

// ---------------------------------------------------------------------------------------------
// Streaming
// ---------------------------------------------------------------------------------------------

fn chunked(src: &mut TiltSeriesSource, sizes: &[usize]) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::new(); src.channels().len()];
    let (mut pos, mut i) = (0, 0);
    while pos < src.len() {
        let n = sizes[i % sizes.len()].min(src.len() - pos);
        for (o, c) in out.iter_mut().zip(src.read_chunk(pos, n).unwrap()) {
            o.extend(c);
        }
        pos += n;
        i += 1;
    }
    out
}

#[test]
fn chunked_reading_is_bit_identical_to_in_memory() {
    let dir = tmp();
    // Longer than the scanning block (2^18), with gaps at and around its boundaries.
    let n = 300_007;
    let mut e = noise(n, 1);
    let mut nn = noise(n, 2);
    let z = noise(n, 3);
    for k in [17, 18, 19, 65_535, 65_536, 262_143, 262_144, 262_145, n - 2] {
        e[k] = f64::NAN;
    }
    nn[100_000] = f64::NEG_INFINITY;
    let p = dir.path().join("long.h5");
    write_series_h5(
        &p,
        Some(10.0),
        &[
            Ch("E", &e, Some("rad/s")),
            Ch("N", &nn, Some("rad/s")),
            Ch("Z", &z, Some("rad/s")),
        ],
        &[],
    );
    for gaps in [GapPolicy::Interpolate] {
        for q in [None, Some(Quantity::Angle)] {
            let o = opts(None, q, gaps);
            let whole = series(&p, &o);
            assert_eq!(whole.len(), n);
            let mut src = TiltSeriesSource::open(&p, &o).unwrap();
            assert_eq!(src.len(), n);
            assert_eq!(src.sample_rate_hz(), 10.0);
            let inputs: Vec<Input> = src.channels().iter().map(|c| c.input).collect();
            assert_eq!(inputs, Input::all_tilts());
            assert_eq!(src.provenance(), &whole.provenance);
            for sizes in [&[n][..], &[1000], &[4097, 1, 65_539, 77], &[262_144]] {
                let got = chunked(&mut src, sizes);
                for (g, w) in got.iter().zip(&whole.data) {
                    assert_eq!(bits(g), bits(w), "chunks {sizes:?}, quantity {q:?}");
                }
            }
            // Random access, backwards and repeated.
            for (start, len) in [
                (250_000, 10_000),
                (3, 5),
                (131_072, 1),
                (299_000, 1007),
                (3, 5),
            ] {
                let c = src.read_chunk(start, len).unwrap();
                for (g, w) in c.iter().zip(&whole.data) {
                    assert_eq!(bits(g), bits(&w[start..start + len]), "at {start}");
                }
            }
            assert_eq!(src.read_chunk(n, 0).unwrap(), vec![Vec::<f64>::new(); 3]);
            let err = src.read_chunk(n - 5, 6).unwrap_err();
            assert!(matches!(err, InputError::ChunkOutOfRange { .. }));
            err_msg(err, &p, &["starting at sample index 300002", "300007"]);
        }
    }
    // CSV and HDF5 of the same numbers agree bit for bit (same processing code).
    let m = 3000;
    let small_p = dir.path().join("small.h5");
    let small_c = dir.path().join("small.csv");
    write_series_h5(
        &small_p,
        Some(10.0),
        &[Ch("E", &e[..m], None), Ch("N", &nn[..m], None)],
        &[],
    );
    write_series_csv(&small_c, 10.0, &["E", "N"], &[&e[..m], &nn[..m]], "");
    let o = ReadOptions {
        units: ["E=rad/s", "N=rad/s"].map(|u| u.parse().unwrap()).to_vec(),
        ..opts(None, Some(Quantity::Rate), GapPolicy::Interpolate)
    };
    let (a, b) = (series(&small_p, &o), series(&small_c, &o));
    for (x, y) in a.data.iter().zip(&b.data) {
        assert_eq!(bits(x), bits(y));
    }
}

#[test]
fn streaming_rejects_csv_and_spectra() {
    let dir = tmp();
    let p = dir.path().join("s.csv");
    write_series_csv(&p, 1.0, &["theta_t"], &[&[1.0, 2.0]], "");
    let e = TiltSeriesSource::open(&p, &ReadOptions::default()).unwrap_err();
    err_msg(e, &p, &["CSV"]);
    let p = dir.path().join("spec.h5");
    write_asd_h5(&p, &[1.0, 2.0], &["theta_t"], &[vec![1.0], vec![2.0]]);
    let e = TiltSeriesSource::open(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, InputError::WrongKind { .. }));
    err_msg(e, &p, &["expected series", "spectra"]);
    let e = read_tilt_series(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, InputError::WrongKind { .. }));
}

// ---------------------------------------------------------------------------------------------
// Spectra
// ---------------------------------------------------------------------------------------------

/// `/frequency_hz`, `/asd [n, m]` (rows given per frequency), root `axes`.
fn write_asd_h5(path: &Path, f: &[f64], axes: &[&str], rows: &[Vec<f64>]) {
    let file = hdf5::File::create(path).unwrap();
    file.new_dataset_builder()
        .with_data(&Array1::from(f.to_vec()))
        .create("frequency_hz")
        .unwrap();
    let m = axes.len();
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    file.new_dataset_builder()
        .with_data(&Array2::from_shape_vec((f.len(), m), flat).unwrap())
        .create("asd")
        .unwrap();
    let names: Vec<VarLenUnicode> = axes.iter().map(|a| vstr(a)).collect();
    file.new_attr_builder()
        .with_data(&Array1::from(names))
        .create("axes")
        .unwrap();
}

fn write_csd_h5(path: &Path, f: &[f64], axes: &[&str], csd: &[Complex64], units: Option<&str>) {
    let file = hdf5::File::create(path).unwrap();
    str_attr(&file, "schema", "tiltnoise.tilt_spectra");
    file.new_dataset_builder()
        .with_data(&Array1::from(f.to_vec()))
        .create("frequency_hz")
        .unwrap();
    let m = axes.len();
    let ds = file
        .new_dataset_builder()
        .with_data(&Array3::from_shape_vec((f.len(), m, m), csd.to_vec()).unwrap())
        .create("csd")
        .unwrap();
    if let Some(u) = units {
        str_attr(&ds, "units", u);
    }
    let names: Vec<VarLenUnicode> = axes.iter().map(|a| vstr(a)).collect();
    file.new_attr_builder()
        .with_data(&Array1::from(names))
        .create("axes")
        .unwrap();
}

fn c(re: f64, im: f64) -> Complex64 {
    Complex64::new(re, im)
}

#[test]
fn spectra_csv_round_trip() {
    let dir = tmp();
    let p = dir.path().join("asd.csv");
    let f = [1e-3, 1e-2, 0.1, 1.0];
    let th = [3e-9, 1e-9, 2.5e-10, 0.0];
    let et = [4e-9, 2e-9, 5e-10, 1e-11];
    let ph = [1e-8, 1e-9, 1e-10, 1e-11];
    let mut text = String::from("# description: model floor\nfreq_hz,eta_t,theta_t,phi_t\n");
    for k in 0..4 {
        text.push_str(&format!("{},{},{},{}\n", f[k], et[k], th[k], ph[k]));
    }
    write_text(&p, &text);
    let s = match read_tilt(&p, &ReadOptions::default()).unwrap() {
        TiltInput::Spectra(s) => s,
        TiltInput::Series(_) => panic!("read as series"),
    };
    assert_eq!(s.freqs_hz, f);
    assert_eq!(s.axes, TiltAxis::ALL.to_vec());
    for k in 0..4 {
        assert_eq!(s.csd_at(k, 0, 0), c(th[k] * th[k], 0.0));
        assert_eq!(s.csd_at(k, 1, 1), c(et[k] * et[k], 0.0));
        assert_eq!(s.csd_at(k, 2, 2), c(ph[k] * ph[k], 0.0));
        assert_eq!(s.csd_at(k, 0, 1), c(0.0, 0.0));
        assert_eq!(s.csd_at(k, 2, 1), c(0.0, 0.0));
    }
    assert_eq!(s.asd(TiltAxis::ThetaT).unwrap(), th.to_vec());
    let pr = &s.provenance;
    assert_eq!(
        (pr.kind, pr.format, pr.quantity),
        (InputKind::Spectra, InputFormat::Csv, Quantity::Angle)
    );
    assert!(pr.notes.join(" ").contains("uncorrelated"));
    assert_eq!(s.band_hz(), (1e-3, 1.0));

    // Rate ASD: divided by 2 pi f.
    let p = dir.path().join("rate_asd.csv");
    write_text(
        &p,
        "# units: rad/s/sqrt(Hz)\nfreq_hz,theta_t\n0.5,2.0\n2.0,4.0\n",
    );
    let s = read_tilt_spectra(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.provenance.quantity, Quantity::Rate);
    let expect = (2.0 / (TAU * 0.5)).powi(2);
    assert!((s.csd_at(0, 0, 0).re - expect).abs() <= 1e-15 * expect);

    // Wrong kind.
    let e = read_tilt_series(&p, &ReadOptions::default()).unwrap_err();
    err_msg(e, &p, &["expected series", "spectra"]);
}

#[test]
fn spectra_csv_errors_name_row_and_column() {
    let dir = tmp();
    let cases: [(&str, &str, &[&str]); 7] = [
        (
            "freq_hz,theta_t,eta_t\n1,1,1\n1,1,1\n",
            "nonincr",
            &[
                "line 3 (row 1)",
                "freq_hz",
                "frequency 1.0 Hz",
                "greater than the previous 1.0 Hz",
            ],
        ),
        (
            "freq_hz,theta_t,eta_t\n1,1,1\n0.5,1,1\n",
            "decr",
            &["line 3 (row 1)", "0.5", "strictly increasing"],
        ),
        (
            "freq_hz,theta_t\n-1,1\n1,1\n",
            "negf",
            &["line 2 (row 0)", "-1", "from 1e-9 to 1e6 Hz"],
        ),
        (
            "freq_hz,theta_t\n0,1\n1,1\n",
            "zerof",
            &["line 2 (row 0)", "frequency 0.0 Hz", "from 1e-9 to 1e6 Hz"],
        ),
        (
            "freq_hz,theta_t,eta_t\n1,1,1\n2,1,-1e-9\n",
            "negasd",
            &[
                "line 3 (row 1)",
                "`eta_t`",
                "-1e-9",
                "rad/sqrt(Hz)",
                "0 or a value from",
            ],
        ),
        (
            "freq_hz,theta_t\n1,1\n2,nan\n",
            "nanasd",
            &[
                "line 3 (row 1)",
                "`theta_t`",
                "NaN",
                "0 or a value from 1e-40",
            ],
        ),
        (
            "freq_hz,theta_t\n1,1\n",
            "short",
            &["1 frequencies", "at least 2"],
        ),
    ];
    for (text, name, needles) in cases {
        let p = dir.path().join(format!("{name}.csv"));
        write_text(&p, text);
        let e = spectra_err(&p, &ReadOptions::default());
        err_msg(e, &p, needles);
    }
    let p = dir.path().join("emptyasd.csv");
    write_text(&p, "freq_hz,theta_t\n1,1\n2,\n");
    let e = spectra_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["line 3", "theta_t", "not a number"]);
}

#[test]
fn spectra_hdf5_asd_and_csd_round_trip() {
    let dir = tmp();
    let f = [0.01, 0.1, 1.0];
    let p = dir.path().join("asd.h5");
    write_asd_h5(
        &p,
        &f,
        &["N", "E"],
        &[vec![1.0, 2.0], vec![3.0, 4.0], vec![5.0, 0.0]],
    );
    let s = read_tilt_spectra(&p, &ReadOptions::default()).unwrap();
    let TiltInput::Spectra(t) = read_tilt(&p, &ReadOptions::default()).unwrap() else {
        panic!("HDF5 spectra read as series")
    };
    assert_eq!(t, s);
    assert_eq!(t.provenance.kind, InputKind::Spectra);
    assert_eq!(s.axes, vec![TiltAxis::ThetaT, TiltAxis::EtaT]);
    assert_eq!(s.provenance.axis_map, "theta_t=-E,eta_t=-N");
    assert_eq!(s.psd(TiltAxis::ThetaT).unwrap(), vec![4.0, 16.0, 0.0]);
    assert_eq!(s.psd(TiltAxis::EtaT).unwrap(), vec![1.0, 9.0, 25.0]);
    assert_eq!(s.csd_at(1, 0, 1), c(0.0, 0.0));

    // Correlated CSD: source axes (E, N); theta_t = -E, eta_t = -N: the sign product is +1;
    // with theta_t = -E, eta_t = +N it flips the cross terms.
    let p = dir.path().join("csd.h5");
    let mut csd = Vec::new();
    for k in 0..3 {
        let (a, b) = (1.0 + k as f64, 2.0 + k as f64);
        let x = c(0.3 * (a * b).sqrt(), 0.4 * (a * b).sqrt());
        csd.extend([c(a, 0.0), x, x.conj(), c(b, 0.0)]);
    }
    write_csd_h5(&p, &f, &["E", "N"], &csd, Some("rad^2/Hz"));
    let s = read_tilt_spectra(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.csd, csd);
    assert_eq!(s.provenance.quantity, Quantity::Angle);
    let s = read_tilt_spectra(
        &p,
        &opts(Some("theta_t=-E,eta_t=N"), None, GapPolicy::Reject),
    )
    .unwrap();
    assert_eq!(s.csd_at(0, 0, 1), -csd[1]);
    assert_eq!(s.csd_at(0, 1, 0), -csd[2]);
    assert_eq!(s.csd_at(0, 1, 1), csd[3]);
    // Axis order in the file is not the canonical order: reordered.
    let s = read_tilt_spectra(
        &p,
        &opts(Some("eta_t=E,theta_t=N"), None, GapPolicy::Reject),
    )
    .unwrap();
    assert_eq!(s.csd_at(0, 0, 0), csd[3]);
    assert_eq!(s.csd_at(0, 0, 1), csd[2]);

    // Rate CSD: divided by (2 pi f)^2.
    let p = dir.path().join("csd_rate.h5");
    write_csd_h5(&p, &f, &["theta_t", "eta_t"], &csd, Some("rad^2/s^2/Hz"));
    let s = read_tilt_spectra(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.provenance.quantity, Quantity::Rate);
    let w2 = (TAU * 0.1).powi(2);
    assert_eq!(s.csd_at(1, 0, 1), csd[5] / w2);
}

#[test]
fn spectra_hdf5_errors() {
    let dir = tmp();
    let f = [0.01, 0.1];
    let good = |a: f64, b: f64| vec![c(a, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(b, 0.0)];

    let p = dir.path().join("herm.h5");
    let mut csd = good(1.0, 1.0);
    csd.extend([c(2.0, 0.0), c(0.5, 0.1), c(0.5, 0.1), c(2.0, 0.0)]);
    write_csd_h5(&p, &f, &["theta_t", "eta_t"], &csd, None);
    let e = spectra_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::Csd {
            index: 1,
            i: 0,
            j: 1,
            ..
        })
    ));
    err_msg(
        e,
        &p,
        &[
            "/csd[1, 0, 1]",
            "0.1 Hz",
            "theta_t, eta_t",
            "not Hermitian",
            "rad^2/Hz",
            "sqrt(S_ii S_jj)",
        ],
    );

    // Within the derived tolerance it is accepted (and made exactly Hermitian).
    let p = dir.path().join("herm_ok.h5");
    let mut csd = good(1.0, 1.0);
    let eps = 1e-14;
    csd.extend([c(2.0, 0.0), c(0.5, 0.1), c(0.5 + eps, -0.1), c(2.0, 0.0)]);
    write_csd_h5(&p, &f, &["theta_t", "eta_t"], &csd, None);
    let s = read_tilt_spectra(&p, &ReadOptions::default()).unwrap();
    assert_eq!(s.csd_at(1, 1, 0), s.csd_at(1, 0, 1).conj());

    let p = dir.path().join("coh.h5");
    let mut csd = good(1.0, 1.0);
    csd.extend([c(1.0, 0.0), c(1.5, 0.0), c(1.5, 0.0), c(1.0, 0.0)]);
    write_csd_h5(&p, &f, &["theta_t", "eta_t"], &csd, None);
    let e = spectra_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["/csd[1, 0, 1]", "coherence > 1"]);

    let p = dir.path().join("diag.h5");
    let mut csd = good(1.0, -1.0);
    csd.extend(good(1.0, 1.0));
    write_csd_h5(&p, &f, &["theta_t", "eta_t"], &csd, None);
    let e = spectra_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["/csd[0, 1, 1]", "eta_t, eta_t", "real PSD >= 0"]);

    let p = dir.path().join("csd_units.h5");
    write_csd_h5(
        &p,
        &f,
        &["theta_t", "eta_t"],
        &[good(1.0, 1.0), good(1.0, 1.0)].concat(),
        Some("rad/sqrt(Hz)"),
    );
    let e = spectra_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["units", "/csd", "rad^2/Hz"]);

    let p = dir.path().join("negasd.h5");
    write_asd_h5(
        &p,
        &f,
        &["theta_t", "eta_t"],
        &[vec![1.0, 1.0], vec![1.0, -2.0]],
    );
    let e = spectra_err(&p, &ReadOptions::default());
    assert!(matches!(e, InputError::Asd { .. }));
    err_msg(
        e,
        &p,
        &["/asd[1, 1]", "`eta_t`", "-2", "0 or a value from 1e-40"],
    );

    let p = dir.path().join("freq.h5");
    write_asd_h5(&p, &[0.1, 0.1], &["theta_t"], &[vec![1.0], vec![1.0]]);
    let e = spectra_err(&p, &ReadOptions::default());
    err_msg(
        e,
        &p,
        &["/frequency_hz[1]", "0.1 Hz", "strictly increasing"],
    );

    let p = dir.path().join("shape.h5");
    {
        let file = hdf5::File::create(&p).unwrap();
        file.new_dataset_builder()
            .with_data(&Array1::from(f.to_vec()))
            .create("frequency_hz")
            .unwrap();
        file.new_dataset_builder()
            .with_data(&Array2::<f64>::ones((2, 3)))
            .create("asd")
            .unwrap();
        let names = Array1::from(vec![vstr("theta_t"), vstr("eta_t")]);
        file.new_attr_builder()
            .with_data(&names)
            .create("axes")
            .unwrap();
    }
    let e = spectra_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::BadDataset { .. })
    ));
    err_msg(e, &p, &["/asd", "[2, 3]", "[2, 2]"]);

    let p = dir.path().join("noaxes.h5");
    {
        let file = hdf5::File::create(&p).unwrap();
        file.new_dataset_builder()
            .with_data(&Array1::from(f.to_vec()))
            .create("frequency_hz")
            .unwrap();
        file.new_dataset_builder()
            .with_data(&Array2::<f64>::ones((2, 1)))
            .create("asd")
            .unwrap();
    }
    let e = spectra_err(&p, &ReadOptions::default());
    assert!(matches!(
        FormatError::of(&e),
        Some(FormatError::MissingAttribute { .. })
    ));
    err_msg(e, &p, &["`axes`", "missing"]);

    let p = dir.path().join("novalues.h5");
    {
        let file = hdf5::File::create(&p).unwrap();
        file.new_dataset_builder()
            .with_data(&Array1::from(f.to_vec()))
            .create("frequency_hz")
            .unwrap();
    }
    let e = spectra_err(&p, &ReadOptions::default());
    err_msg(e, &p, &["dataset `/asd or /csd` is missing"]);

    // Neither marker: read_tilt names the accepted layouts.
    let p = dir.path().join("nothing.h5");
    hdf5::File::create(&p).unwrap();
    let e = read_tilt(&p, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e, InputError::UnknownLayout { .. }));
    err_msg(
        e,
        &p,
        &[
            "accepted layouts",
            "sample_rate_hz",
            "frequency_hz",
            "(none)",
        ],
    );
}

// ---------------------------------------------------------------------------------------------
// Log-log interpolation
// ---------------------------------------------------------------------------------------------

fn spectra_from(f: Vec<f64>, axes: Vec<TiltAxis>, csd: Vec<Complex64>) -> TiltSpectra {
    // Build through a real file, so that provenance is filled as for users.
    let dir = tmp();
    let p = dir.path().join("s.h5");
    let names: Vec<&str> = axes.iter().map(|a| a.name()).collect();
    write_csd_h5(&p, &f, &names, &csd, None);
    read_tilt_spectra(&p, &ReadOptions::default()).unwrap()
}

#[test]
fn loglog_interpolation_is_exact_for_a_power_law() {
    let cst = 3.7e-18;
    let f: Vec<f64> = (0..40)
        .map(|k| 1e-4 * 10f64.powf(k as f64 * 0.13))
        .collect();
    let csd: Vec<Complex64> = f.iter().map(|&x| c(cst * x.powi(-2), 0.0)).collect();
    let s = spectra_from(f.clone(), vec![TiltAxis::ThetaT], csd);
    let grid: Vec<f64> = noise(2000, 7)
        .iter()
        .map(|u| f[0] * (f[39] / f[0]).powf(0.5 * (u + 1.0)))
        .chain(f.iter().copied())
        .collect();
    let (g, out) = s.interpolate_loglog(&grid);
    assert_eq!(g.len(), grid.len());
    assert_eq!(out.freqs_hz, g);
    let mut worst = 0f64;
    for (k, &x) in g.iter().enumerate() {
        let expect = cst * x.powi(-2);
        worst = worst.max((out.csd_at(k, 0, 0).re - expect).abs() / expect);
        assert_eq!(out.csd_at(k, 0, 0).im, 0.0);
    }
    assert!(worst <= 1e-14, "worst relative error {worst:e}");
    // Data points are reproduced exactly.
    let (_, at) = s.interpolate_loglog(&f);
    assert_eq!(at.csd, s.csd);
    assert_eq!(at.provenance.notes, s.provenance.notes);
}

#[test]
fn interpolation_zeros_coherence_and_band_restriction() {
    let f = vec![1.0, 2.0, 4.0];
    // theta: 0 at 1 Hz (linear in PSD there), eta: power law; constant complex coherence.
    let (st, se): ([f64; 3], [f64; 3]) = ([0.0, 4.0, 1.0], [8.0, 2.0, 0.5]);
    let g = c(0.6, -0.3);
    let mut csd = Vec::new();
    for k in 0..3 {
        let x = g * (st[k] * se[k]).sqrt();
        csd.extend([c(st[k], 0.0), x, x.conj(), c(se[k], 0.0)]);
    }
    let s = spectra_from(f, vec![TiltAxis::ThetaT, TiltAxis::EtaT], csd);
    let grid = [0.5, 2f64.sqrt(), 2.0 * 2f64.sqrt(), 4.0, 9.0, f64::NAN];
    let (gr, out) = s.interpolate_loglog(&grid);
    assert_eq!(gr, vec![2f64.sqrt(), 2.0 * 2f64.sqrt(), 4.0]);
    // Between 1 and 2 Hz: t = 1/2; theta linear in PSD (neighbour 0): 2; eta: sqrt(8*2) = 4.
    assert!((out.csd_at(0, 0, 0).re - 2.0).abs() < 1e-15);
    assert!((out.csd_at(0, 1, 1).re - 4.0).abs() < 1e-14);
    // Coherence: 0 at 1 Hz (theta PSD 0), g at 2 Hz -> g/2 at t = 1/2.
    let want = g * 0.5 * (2.0f64 * 4.0).sqrt();
    assert!((out.csd_at(0, 0, 1) - want).norm() < 1e-14);
    assert_eq!(out.csd_at(0, 1, 0), out.csd_at(0, 0, 1).conj());
    // Between 2 and 4 Hz: power laws both, constant coherence g.
    let (pt, pe) = ((4.0f64 * 1.0).sqrt(), (2.0f64 * 0.5).sqrt());
    assert!((out.csd_at(1, 0, 0).re - pt).abs() < 1e-14);
    assert!((out.csd_at(1, 1, 1).re - pe).abs() < 1e-14);
    assert!((out.csd_at(1, 0, 1) - g * (pt * pe).sqrt()).norm() < 1e-14);
    // The band restriction is reported.
    assert_eq!(s.band_hz(), (1.0, 4.0));
    let note = out.provenance.notes.last().unwrap();
    assert!(
        note.contains("restricted to the data band [1, 4] Hz"),
        "{note}"
    );
    assert!(note.contains("3 of 6 points"), "{note}");
    assert!(note.contains("0.5 .. 9 Hz"), "{note}");
    // A grid inside the band: no note.
    let (_, inside) = s.interpolate_loglog(&[1.5, 3.0]);
    assert_eq!(inside.provenance.notes, s.provenance.notes);
    // A grid entirely outside: empty.
    let (none, empty) = s.interpolate_loglog(&[10.0, 20.0]);
    assert!(none.is_empty() && empty.is_empty());
}

/// Finite values whose spectrum overflows: an ASD too large to square (CSV) or of `f64::MAX`
/// (HDF5) is refused by the ASD bound, and a rate spectrum at a tiny frequency, whose division
/// by `(2 pi f)^2` would overflow, by the frequency bound, naming the line.
#[test]
fn spectra_that_overflow_are_refused() {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_corpus");
    for file in [
        "tilt_csv/regressions/asd_whose_square_overflows.csv",
        "h5_structured/regressions/asd_of_f64_max.h5",
    ] {
        let path = corpus.join(file);
        err_msg(
            spectra_err(&path, &ReadOptions::default()),
            &path,
            &["ASD", "0 or a value from 1e-40 to 1e40 rad/sqrt(Hz)"],
        );
    }
    let dir = tmp();
    let rate = dir.path().join("rate.csv");
    std::fs::write(&rate, "freq_hz,theta_t\n1e-160,1e-3\n1e-3,1e-3\n").unwrap();
    let opts = ReadOptions {
        quantity: Some(Quantity::Rate),
        ..ReadOptions::default()
    };
    err_msg(
        spectra_err(&rate, &opts),
        &rate,
        &[
            "line 2 (row 0)",
            "frequency 1e-160 Hz",
            "from 1e-9 to 1e6 Hz",
        ],
    );
}

/// A contiguous dataset whose storage is shorter than its extent (a damaged file): HDF5 would
/// hand back made-up values for the missing entries, so the reader refuses it.
#[test]
fn truncated_contiguous_storage_is_refused() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(
        "tests/fuzz_corpus/tilt_h5_bytes/regressions/contiguous_storage_smaller_than_extent.h5",
    );
    err_msg(
        series_err(&path, &ReadOptions::default()),
        &path,
        &[
            "dataset `/Z`",
            "45 bytes of storage for 12 entries of 4 bytes",
        ],
    );
}

/// An ASD whose square would overflow (or nearly, once summed over a band) is refused by every
/// spectra reader, naming file, line and column: the measured spectrum of a budget too.
#[test]
fn absurdly_large_asds_are_refused() {
    let dir = tmp();
    let measured = dir.path().join("measured.csv");
    std::fs::write(&measured, "freq_hz,X\n1e-3,1e-8\n2e-3,1e200\n").unwrap();
    let e = tiltnoise_io::input::read_measured(&measured).unwrap_err();
    err_msg(
        e,
        &measured,
        &[
            "line 3",
            "column `X`",
            "1e200",
            "from 1e-40 to 1e40 m/sqrt(Hz)",
        ],
    );
    let tilt = dir.path().join("tilt.csv");
    std::fs::write(&tilt, "freq_hz,theta_t\n1e-3,1e-8\n2e-3,2e150\n").unwrap();
    let e = spectra_err(&tilt, &ReadOptions::default());
    err_msg(
        e,
        &tilt,
        &["column `theta_t`", "2e150", "from 1e-40 to 1e40"],
    );
    // Nonzero ASDs whose PSD would underflow are refused too; zero stays.
    std::fs::write(&tilt, "freq_hz,theta_t\n1e-3,0\n2e-3,1e-200\n").unwrap();
    let e = spectra_err(&tilt, &ReadOptions::default());
    err_msg(
        e,
        &tilt,
        &[
            "line 3",
            "column `theta_t`",
            "1e-200",
            "0 or a value from 1e-40",
        ],
    );
}
