//! Units of time-series inputs: prefixed angles and rates (`urad`, `nrad/s`, ...) scaled into
//! rad or rad/s, channels in counts with `--scale CHANNEL=FACTOR`, unknown units refused with
//! the allowed list. The scaling multiplies each raw sample once, before the axis map's sign.

use crate::common::assert_fails;
use hdf5::types::VarLenUnicode;
use ndarray::{arr0, Array1};
use tiltnoise_io::input::{
    read_tilt, read_tilt_series, AxisMap, ChannelScale, Quantity, ReadOptions,
};

const RAW: [f64; 4] = [1.5, -2.25, 3.0, 0.125];

fn csv(dir: &std::path::Path, units: &str) -> std::path::PathBuf {
    let path = dir.join("s.csv");
    let mut text = format!("# units: {units}\ntime_s,E,N\n");
    for (k, v) in RAW.iter().enumerate() {
        text.push_str(&format!("{k},{v},{}\n", 2.0 * v));
    }
    std::fs::write(&path, text).unwrap();
    path
}

fn scales(list: &[&str]) -> Vec<ChannelScale> {
    list.iter().map(|s| s.parse().unwrap()).collect()
}

#[test]
fn prefixed_units_scale_csv_columns() {
    let dir = tempfile::tempdir().unwrap();
    let s = read_tilt_series(
        &csv(dir.path(), "E=nrad/s, N=urad/s"),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(s.quantity(), Quantity::Rate);
    for (k, v) in RAW.iter().enumerate() {
        // Default map: theta_t = -E, eta_t = -N.
        assert_eq!(s.data[0][k], -(1e-9 * v));
        assert_eq!(s.data[1][k], -(1e-6 * (2.0 * v)));
    }
    let notes = s.provenance.notes.join("\n");
    assert!(
        notes.contains(
            "channel `E`: samples multiplied by 1e-9 (units `nrad/s` to rad/s) before the axis map"
        ),
        "{notes}"
    );
    let e = read_tilt(&csv(dir.path(), "deg"), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("units `deg`; allowed: rad, mrad, urad, nrad (angle); rad/s, mrad/s, urad/s, nrad/s (rate); m, cm")
            && e.contains("m/s^2, mm/s^2, um/s^2, nm/s^2 (acceleration); or counts"),
        "{e}"
    );
}

#[test]
fn counts_need_a_scale_which_applies_before_the_sign() {
    let dir = tempfile::tempdir().unwrap();
    let path = csv(dir.path(), "E=counts, N=rad");
    let e = read_tilt(&path, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("channel `E` is in counts") && e.contains("CHANNEL=FACTOR"),
        "{e}"
    );
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=-E,eta_t=N").unwrap()),
        scale: scales(&["E=2.5e-9"]),
        ..ReadOptions::default()
    };
    let s = read_tilt_series(&path, &opts).unwrap();
    assert_eq!(s.quantity(), Quantity::Angle);
    for (k, v) in RAW.iter().enumerate() {
        assert_eq!(s.data[0][k], -(2.5e-9 * v));
        assert_eq!(s.data[1][k], 2.0 * v);
    }
    let opts = ReadOptions {
        scale: scales(&["X=1"]),
        ..ReadOptions::default()
    };
    let e = read_tilt(&path, &opts).unwrap_err().to_string();
    assert!(
        e.contains("channel `X` is not a column of the file; available columns: E, N"),
        "{e}"
    );
}

#[test]
fn hdf5_units_as_gwpy_writes_them_and_scales_stream_alike() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("s.h5");
    {
        let f = hdf5::File::create(&path).unwrap();
        f.new_attr::<f64>()
            .create("sample_rate_hz")
            .unwrap()
            .write_scalar(&1.0)
            .unwrap();
        for (name, unit) in [("E", "nrad / s"), ("N", "counts")] {
            let ds = f
                .new_dataset_builder()
                .with_data(&Array1::from(RAW.to_vec()))
                .create(name)
                .unwrap();
            ds.new_attr_builder()
                .with_data(&arr0(unit.parse::<VarLenUnicode>().unwrap()))
                .create("units")
                .unwrap();
        }
    }
    let opts = ReadOptions {
        scale: scales(&["N=4e-9"]),
        ..ReadOptions::default()
    };
    let s = read_tilt_series(&path, &opts).unwrap();
    assert_eq!(s.quantity(), Quantity::Rate);
    for (k, v) in RAW.iter().enumerate() {
        assert_eq!(s.data[0][k], -(1e-9 * v));
        assert_eq!(s.data[1][k], -(4e-9 * v));
    }
    let mut src = tiltnoise_io::input::TiltSeriesSource::open(&path, &opts).unwrap();
    assert_eq!(src.read_chunk(1, 2).unwrap()[1], s.data[1][1..3].to_vec());
}

#[test]
fn scale_on_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = csv(dir.path(), "E=counts, N=rad");
    let p = path.to_str().unwrap();
    assert_fails(&["budget", "--tilt", p], &["channel `E` is in counts"]);
    assert_fails(
        &["budget", "--tilt", p, "--scale", "E"],
        &["--scale", "`E` has no `=`", "CHANNEL=FACTOR"],
    );
    assert_fails(
        &["budget", "--tilt", p, "--scale", "E=inf"],
        &["--scale", "must be a finite, non-zero number"],
    );
}

/// The library's error about an item of an option names the option by its key, spelled by the
/// front end: the flag here, the keyword in Python (`units: unit ...`, python/tests).
#[test]
fn an_item_error_names_the_option_as_a_flag() {
    let dir = tempfile::tempdir().unwrap();
    let path = csv(dir.path(), "E=counts, N=rad");
    let p = path.to_str().unwrap();
    assert_fails(
        &["budget", "--tilt", p, "--units", "E=furlong"],
        &["--units: unit `furlong` of channel `E`"],
    );
    assert_fails(
        &["budget", "--tilt", p, "--scale", "E=0"],
        &["--scale: factor `0` of channel `E` is not allowed"],
    );
}

fn gwpy(name: &str) -> std::path::PathBuf {
    crate::common::repo("tests/fixtures/input/gwpy").join(name)
}

#[test]
fn gwpy_timeseries_in_a_group_read_by_address() {
    // Written by gwpy 4.1 (TimeSeriesDict.write(group="tilt")): E = k/2, N = -k/4 in nrad/s.
    let file = gwpy("timeseries_dict.h5");
    let address = format!("{}:/tilt", file.display());
    let s = read_tilt_series(std::path::Path::new(&address), &ReadOptions::default()).unwrap();
    assert_eq!(s.sample_rate_hz, 2.0);
    assert_eq!(s.quantity(), Quantity::Rate);
    assert_eq!(s.len(), 64);
    for k in 0..64 {
        let kf = k as f64;
        assert_eq!(s.data[0][k], -(1e-9 * (kf / 2.0)), "theta_t = -E");
        assert_eq!(s.data[1][k], -(1e-9 * (-kf / 4.0)), "eta_t = -N");
    }
    let notes = s.provenance.notes.join("\n");
    assert!(
        notes.contains("from attribute dx = 0.5 s of /tilt/E (gwpy TimeSeries layout)"),
        "{notes}"
    );
    // One dataset of the group by its path.
    let one = format!("{}:/tilt/N", file.display());
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("eta_t=N").unwrap()),
        ..ReadOptions::default()
    };
    let s = read_tilt(std::path::Path::new(&one), &opts).unwrap();
    let tiltnoise_io::input::TiltInput::Series(s) = s else {
        panic!("a series")
    };
    assert_eq!(s.data.len(), 1);
    assert_eq!(s.data[0][4], 1e-9 * (-4.0 / 4.0), "N[4] = -4/4 nrad/s");
    // Without an address the error lists the datasets inside the group by path.
    let e = read_tilt(&file, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("datasets: /tilt/E, /tilt/N"), "{e}");
    let missing = format!("{}:/nothing", file.display());
    let e = read_tilt(std::path::Path::new(&missing), &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("`/nothing` is missing") && e.contains("/tilt/E, /tilt/N"),
        "{e}"
    );
}

#[test]
fn gwpy_timeseries_at_the_root_is_detected() {
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=theta").unwrap()),
        ..ReadOptions::default()
    };
    let s = read_tilt_series(&gwpy("timeseries.h5"), &opts).unwrap();
    assert_eq!((s.sample_rate_hz, s.quantity()), (2.0, Quantity::Angle));
    assert_eq!(s.data[0][6], 1e-6 * 3.0);
}

#[test]
fn gwpy_frequencyseries_asds_are_tilt_spectra() {
    // Written by gwpy 4.1: ASDs (k + 1) / 8 (E) and (k + 1) / 16 (N) rad/sqrt(Hz) at f = k / 4.
    let address = format!("{}:/asd", gwpy("frequencyseries.h5").display());
    let input = read_tilt(std::path::Path::new(&address), &ReadOptions::default()).unwrap();
    let tiltnoise_io::input::TiltInput::Spectra(s) = input else {
        panic!("spectra")
    };
    // The DC bin is dropped; 8 bins remain.
    assert_eq!(
        s.freqs_hz,
        (1..9).map(|k| k as f64 / 4.0).collect::<Vec<_>>()
    );
    assert_eq!(s.axes.len(), 2);
    for (i, f) in s.freqs_hz.iter().enumerate() {
        let k = (f * 4.0) as usize;
        let (e, n) = ((k + 1) as f64 / 8.0, (k + 1) as f64 / 16.0);
        // Default map theta_t = -E, eta_t = -N: the signs cancel on the diagonal.
        assert_eq!(s.csd[i * 4].re, e * e, "S(theta_t) at {f} Hz");
        assert_eq!(s.csd[i * 4 + 3].re, n * n, "S(eta_t) at {f} Hz");
        assert_eq!(s.csd[i * 4 + 1].norm(), 0.0, "uncorrelated");
    }
    let notes = s.provenance.notes.join("\n");
    assert!(notes.contains("1 bins at f <= 0 Hz dropped"), "{notes}");
    let e = tiltnoise_io::input::read_tilt_series(
        std::path::Path::new(&address),
        &ReadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("xunit") && e.contains("FrequencySeries"), "{e}");
}

/// A record of `n` samples at 1 Hz with `E` in counts (`e_scale` times the angle in rad) and
/// `N` in rad.
fn record_in_counts(path: &std::path::Path, e_unit: &str, e_scale: f64, n: usize) {
    let mut text = format!("# units: E={e_unit}, N=rad\ntime_s,E,N\n");
    for k in 0..n {
        let t = k as f64;
        let e = 1e-7 * (0.05 * t).sin();
        let nn = 2e-7 * (0.03 * t).cos();
        text.push_str(&format!("{k},{:e},{nn:e}\n", e_scale * e));
    }
    std::fs::write(path, text).unwrap();
}

/// The data lines of a CSV output (comment lines and the header left out).
fn csv_values(path: &std::path::Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(str::to_string)
        .collect()
}

#[test]
fn every_command_that_reads_tilt_takes_scale() {
    let dir = tempfile::tempdir().unwrap();
    let counts = dir.path().join("counts.csv");
    let rad = dir.path().join("rad.csv");
    // 2 counts per rad: a factor of 0.5 recovers the angle exactly
    // (a power of two), so the driven simulations below agree bit for bit.
    record_in_counts(&counts, "counts", 2.0, 4096);
    record_in_counts(&rad, "rad", 1.0, 4096);
    let (c, r) = (counts.to_str().unwrap(), rad.to_str().unwrap());
    for command in [
        vec!["coherence", "--tilt", c, "--measured", r],
        vec!["subtract", "--tilt", c, "--measured", r],
        vec!["simulate", "--tilt", c],
    ] {
        assert_fails(&command, &["channel `E` is in counts", "CHANNEL=FACTOR"]);
    }
    let simulate = |tilt: &str, scale: Option<&str>, save: &std::path::Path| {
        let mut args = vec!["simulate", "--tilt", tilt, "--seed", "3"];
        if let Some(s) = scale {
            args.extend(["--scale", s]);
        }
        args.extend(["--save", save.to_str().unwrap()]);
        let out = crate::common::tiltnoise(&args);
        assert!(out.status.success(), "{}", crate::common::stderr(&out));
    };
    let (from_counts, from_rad) = (dir.path().join("c.csv"), dir.path().join("r.csv"));
    simulate(c, Some("E=0.5"), &from_counts);
    simulate(r, None, &from_rad);
    let values = csv_values(&from_counts);
    assert!(values.len() > 100, "{} lines", values.len());
    assert_eq!(values, csv_values(&from_rad));
}
