//! `tiltnoise budget` as a user meets it: the main job on the default input, and every kind of
//! bad input refused with exit code 2, a message naming the problem, and no output file.

use crate::common;

use common::{assert_fails_without_output, tiltnoise};
use std::path::Path;

/// Writes an HDF5 tilt series: `channels` as (name, samples), optional sample rate.
fn write_series(path: &Path, channels: &[(&str, Vec<f64>)], fs: Option<f64>) {
    let file = hdf5::File::create(path).unwrap();
    for (name, data) in channels {
        file.new_dataset_builder()
            .with_data(data.as_slice())
            .create(*name)
            .unwrap();
    }
    if let Some(fs) = fs {
        file.new_attr::<f64>()
            .create("sample_rate_hz")
            .unwrap()
            .write_scalar(&fs)
            .unwrap();
    }
}

fn noise(n: usize, seed: u64) -> Vec<f64> {
    // xorshift: deterministic, dependency-free test signal.
    let mut x = seed.max(1);
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x as f64 / u64::MAX as f64 - 0.5) * 1e-8
        })
        .collect()
}

#[test]
fn main_job_on_default_input_writes_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let outs: Vec<String> = ["b.h5", "b.csv", "b.png", "b.svg"]
        .iter()
        .map(|n| dir.path().join(n).to_str().unwrap().to_string())
        .collect();
    let input = common::repo("tilt_data/lab_tilt_24h.h5");
    let mut args = vec![
        "budget",
        "--tilt",
        input.to_str().unwrap(),
        "--nperseg",
        "4096",
        "--segment-duration",
        "14400",
    ];
    for o in &outs {
        args.extend(["--save", o.as_str()]);
    }
    let out = tiltnoise(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("X      at    1 mHz"), "{stdout}");
    for o in &outs {
        assert!(std::fs::metadata(o).unwrap().len() > 1000, "{o}");
    }
    let csv = std::fs::read_to_string(&outs[1]).unwrap();
    let header: Vec<&str> = csv
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    for col in [
        "frequency_hz",
        "X.tilt",
        "X.readout",
        "X.total",
        "phi.tilt",
        "phi_a.total",
    ] {
        assert!(header.contains(&col), "{col} missing from {header:?}");
    }
    let h5 = hdf5::File::open(&outs[0]).unwrap();
    let schema: hdf5::types::VarLenUnicode = h5.attr("schema").unwrap().read_scalar().unwrap();
    assert_eq!(schema.as_str(), "tiltnoise.budget");
    // 6 segments of 4 h in 24 h: the band is there.
    assert!(h5.group("segments").is_ok());
}

#[test]
fn bad_series_are_refused_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = tempfile::tempdir().unwrap();
    let save = out_dir.path().join("b.h5");
    let save = save.to_str().unwrap();
    let n = 8192;

    let mut with_nan = noise(n, 1);
    with_nan[1234] = f64::NAN;
    let nan_file = dir.path().join("nan.h5");
    write_series(
        &nan_file,
        &[("theta_t", with_nan), ("eta_t", noise(n, 2))],
        Some(1.0),
    );
    assert_fails_without_output(
        &[
            "budget",
            "--tilt",
            nan_file.to_str().unwrap(),
            "--save",
            save,
        ],
        out_dir.path(),
        &["1234", "theta_t"],
    );

    let uneven = dir.path().join("uneven.h5");
    write_series(
        &uneven,
        &[("theta_t", noise(n, 1)), ("eta_t", noise(n - 5, 2))],
        Some(1.0),
    );
    assert_fails_without_output(
        &["budget", "--tilt", uneven.to_str().unwrap(), "--save", save],
        out_dir.path(),
        &["8192", "8187"],
    );

    let no_rate = dir.path().join("norate.h5");
    write_series(
        &no_rate,
        &[("theta_t", noise(n, 1)), ("eta_t", noise(n, 2))],
        None,
    );
    assert_fails_without_output(
        &[
            "budget",
            "--tilt",
            no_rate.to_str().unwrap(),
            "--save",
            save,
        ],
        out_dir.path(),
        &["sample_rate_hz"],
    );

    let short = dir.path().join("short.h5");
    write_series(
        &short,
        &[("theta_t", noise(100, 1)), ("eta_t", noise(100, 2))],
        Some(1.0),
    );
    assert_fails_without_output(
        &[
            "budget",
            "--tilt",
            short.to_str().unwrap(),
            "--nperseg",
            "256",
            "--save",
            save,
        ],
        out_dir.path(),
        &["100", "256"],
    );
}

#[test]
fn bad_spectra_are_refused_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = tempfile::tempdir().unwrap();
    let save = out_dir.path().join("b.csv");
    let save = save.to_str().unwrap();
    let cases: [(&str, &[&str]); 3] = [
        (
            "freq_hz,theta_t,eta_t\n0.001,1e-9,1e-9\n0.001,1e-9,1e-9\n",
            &["increasing"],
        ),
        (
            "freq_hz,theta_t,eta_t\n-0.001,1e-9,1e-9\n0.002,1e-9,1e-9\n",
            &["-0.001"],
        ),
        (
            "freq_hz,theta_t,eta_t\n0.001,1e-9,1e-9\n0.002,-1e-9,1e-9\n",
            &["-1e-9", "theta_t"],
        ),
    ];
    for (i, (text, needles)) in cases.iter().enumerate() {
        let f = dir.path().join(format!("s{i}.csv"));
        std::fs::write(&f, text).unwrap();
        assert_fails_without_output(
            &["budget", "--tilt", f.to_str().unwrap(), "--save", save],
            out_dir.path(),
            needles,
        );
    }
}

#[test]
fn spectra_input_reports_band_restriction() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("s.csv");
    std::fs::write(
        &f,
        "freq_hz,theta_t,eta_t\n0.001,1e-9,2e-9\n0.01,1e-9,2e-9\n",
    )
    .unwrap();
    let out = tiltnoise(&["budget", "--tilt", f.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("restricted"), "{stdout}");
    // X at 2 mHz = |H_X,eta_t| * 2e-9 with |H| ~ 1.664 m/rad below the swing modes.
    let line = stdout
        .lines()
        .filter(|l| !l.starts_with('#'))
        .find(|l| l.contains("X") && l.contains("at    2 mHz"))
        .unwrap();
    let tilt: f64 = line
        .split("tilt ")
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!((tilt / 2e-9 - 1.664).abs() < 1e-3, "{line}");
}

#[test]
fn measured_spectrum_adds_measured_and_residual_terms() {
    let dir = tempfile::tempdir().unwrap();
    let measured = dir.path().join("m.csv");
    std::fs::write(&measured, "freq_hz,X\n1e-4,1e-6\n1e-1,1e-9\n").unwrap();
    let out_csv = dir.path().join("b.csv");
    let input = common::repo("tilt_data/lab_tilt_24h.h5");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        input.to_str().unwrap(),
        "--nperseg",
        "4096",
        "--measured",
        measured.to_str().unwrap(),
        "--save",
        out_csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&out_csv).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (f, m, r, t) = (
        col("frequency_hz"),
        col("X.measured"),
        col("X.residual"),
        col("X.total"),
    );
    let mut checked = 0;
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let expected_measured = 10f64.powf(-6.0 - (v[f] / 1e-4).log10());
        if v[f] > 1e-1 {
            assert!(
                v[m].is_nan() && v[r].is_nan(),
                "outside the measured band: NaN"
            );
            continue;
        }
        // The measured ASD is a power law between its two rows: log-log interpolation is exact
        // up to rounding in ln/exp (a few eps times |ln ASD| ~ 20).
        assert!(
            ((v[m] - expected_measured) / expected_measured).abs() < 1e-12,
            "{line}"
        );
        let residual = (v[m] * v[m] - v[t] * v[t]).max(0.0).sqrt();
        assert!((v[r] - residual).abs() <= 1e-12 * v[m], "{line}");
        checked += 1;
    }
    assert!(checked > 100);
}

#[test]
fn rate_series_budget_is_the_library_budget_of_the_rate() {
    // A streamed HDF5 rate goes through the same rate-to-angle path as an in-memory one (the
    // exactness of that path against an angle series is tested in tiltnoise-core's
    // `rate_spectra`); the run says what it did.
    use tiltnoise_core::budget::{budget_from_series, BudgetOptions, RATE_BUDGET_NOTE};
    use tiltnoise_core::input::{InputFormat, InputKind, Provenance, Quantity, TiltSeries};
    use tiltnoise_core::model::{Model, Observable, TiltAxis};
    let dir = tempfile::tempdir().unwrap();
    let (e, n) = (noise(4096, 5), noise(4096, 6));
    let path = dir.path().join("rate.h5");
    write_series(&path, &[("E", e.clone()), ("N", n.clone())], Some(2.0));
    let csv = dir.path().join("b.csv");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        path.to_str().unwrap(),
        "--quantity",
        "rate",
        "--nperseg",
        "512",
        "--save",
        csv.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("input: rate to angle"), "{stdout}");
    assert!(stdout.contains(RATE_BUDGET_NOTE), "{stdout}");

    let minus = |v: &[f64]| v.iter().map(|x| -x).collect::<Vec<f64>>();
    let mut series = TiltSeries {
        sample_rate_hz: 2.0,
        axes: vec![TiltAxis::ThetaT, TiltAxis::EtaT],
        data: vec![minus(&e), minus(&n)],
        translations: Vec::new(),
        sensors: Default::default(),
        provenance: Provenance {
            path: path.clone(),
            format: InputFormat::Hdf5,
            kind: InputKind::Series,
            quantity: Quantity::Rate,
            axis_map: "theta_t=-E,eta_t=-N".into(),
            start_time: None,
            notes: vec![],
        },
    };
    let model = Model::new(&tiltnoise_core::params::Params::table_i()).unwrap();
    let opts = BudgetOptions {
        welch_segment_len: Some(512),
        ..BudgetOptions::default()
    };
    let report = budget_from_series(&model, &mut series, &opts, &mut |_, _| {}).unwrap();
    let want = report
        .budget
        .observable(Observable::X)
        .unwrap()
        .term_named("tilt")
        .unwrap()
        .asd();
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    let col = header.iter().position(|h| *h == "X.tilt").unwrap();
    let got: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    assert_eq!(
        got, want,
        "the CSV holds the library's values, round-trip exact"
    );
}
