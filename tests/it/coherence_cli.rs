//! `tiltnoise coherence` as a user meets it: a tilt record and a pendulum record made from it
//! through the model (with a gain error) give back the model's transfer function times the
//! gain in every output format; bad input is refused with exit code 2, one line naming the
//! file or channel, and no file written.

use crate::common::{self, assert_fails_without_output, str_attr, through_model, tiltnoise};
use hdf5::types::VarLenUnicode;
use std::path::{Path, PathBuf};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::params::Params;

const N: usize = 1 << 14;
const GAIN: f64 = 1.25;

fn str_attribute(loc: &hdf5::Location, name: &str, value: &str) {
    let v: VarLenUnicode = value.parse().unwrap();
    loc.new_attr::<VarLenUnicode>()
        .create(name)
        .unwrap()
        .write_scalar(&v)
        .unwrap();
}

/// An HDF5 series: root `sample_rate_hz`, optional `schema` and `start_time`, one dataset per
/// channel with its `units`.
fn write_h5(
    path: &Path,
    fs: f64,
    schema: Option<&str>,
    start: Option<&str>,
    channels: &[(&str, &str, &[f64])],
) {
    let file = hdf5::File::create(path).unwrap();
    file.new_attr::<f64>()
        .create("sample_rate_hz")
        .unwrap()
        .write_scalar(&fs)
        .unwrap();
    if let Some(s) = schema {
        str_attribute(&file, "schema", s);
    }
    if let Some(t) = start {
        str_attribute(&file, "start_time", t);
    }
    for (name, unit, data) in channels {
        let ds = file
            .new_dataset_builder()
            .with_data(*data)
            .create(*name)
            .unwrap();
        str_attribute(&ds, "units", unit);
    }
}

/// The two input files in `dir`: `tilt.h5` (theta_t, eta_t) and `pendulum.h5` (X, phi_a)
/// with `GAIN` times the model's response, both starting at `start`; the pendulum's sample
/// rate and first `skip` samples adjustable for the error cases.
pub(crate) fn inputs(dir: &Path, fs_measured: f64, measured_start: &str) -> (PathBuf, PathBuf) {
    let model = Model::new(&Params::table_i()).unwrap();
    let outputs = [Observable::X, Observable::PhiA];
    let (tilt, measured) = through_model(&model, N, &outputs, &[9e-10, 1e-10], GAIN, 0.0, 5);
    let (t, m) = (dir.join("tilt.h5"), dir.join("pendulum.h5"));
    write_h5(
        &t,
        1.0,
        Some("tiltnoise.tilt_series"),
        Some("2024-03-20T00:00:00Z"),
        &[("theta_t", "rad", &tilt[0]), ("eta_t", "rad", &tilt[1])],
    );
    write_h5(
        &m,
        fs_measured,
        Some("tiltnoise.observable_series"),
        Some(measured_start),
        &[("X", "m", &measured[0]), ("phi_a", "rad", &measured[1])],
    );
    (t, m)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn the_model_times_the_gain_comes_back_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let (tilt, measured) = inputs(dir.path(), 1.0, "2024-03-20T00:00:00Z");
    let outs: Vec<PathBuf> = ["c.h5", "c.csv", "c.png", "c.svg"]
        .iter()
        .map(|n| dir.path().join(n))
        .collect();
    let mut args = vec![
        "coherence",
        "--tilt",
        s(&tilt),
        "--measured",
        s(&measured),
        "--nperseg",
        "1024",
    ];
    for o in &outs {
        args.extend(["--save", s(o)]);
    }
    let out = tiltnoise(&args);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("coherence: 16384 common samples at 1 Hz"),
        "{stdout}"
    );
    assert!(stdout.contains("    eta_t   max coherence"), "{stdout}");
    assert!(stdout.contains("theta_t max coherence") && stdout.contains("model identically 0"));
    for o in &outs {
        assert!(
            std::fs::metadata(o).unwrap().len() > 10_000,
            "{}",
            o.display()
        );
    }

    let file = hdf5::File::open(&outs[0]).unwrap();
    assert_eq!(str_attr(&file, "schema"), "tiltnoise.coherence");
    assert_eq!(str_attr(&file, "time_dependence"), "exp(+i w t)");
    assert_eq!(str_attr(&file, "alignment"), "start_times");
    let freqs = file.dataset("frequency_hz").unwrap();
    assert_eq!(str_attr(&freqs, "unit"), "Hz");
    let nf = freqs.read_raw::<f64>().unwrap().len();
    assert_eq!(nf, 512);
    for (obs, unit) in [("X", "m"), ("phi_a", "rad")] {
        let g = file.group(&format!("observables/{obs}/eta_t")).unwrap();
        assert_eq!(
            str_attr(&g.dataset("tf").unwrap(), "unit"),
            format!("{unit}/rad")
        );
        let attr = |name: &str| g.attr(name).unwrap().read_scalar::<f64>().unwrap();
        let (re, im, sigma) = (
            attr("agreement_factor_re"),
            attr("agreement_factor_im"),
            attr("agreement_sigma"),
        );
        // Five standard errors: the fit's own statistics, not a tuned allowance.
        assert!(
            ((re - GAIN).powi(2) + im * im).sqrt() < 5.0 * sigma,
            "{obs}/eta_t: factor {re} + {im} i +/- {sigma}, true {GAIN}"
        );
        assert!(sigma < 0.01 * GAIN, "{obs}: sigma {sigma}");
        let tf = g
            .dataset("tf")
            .unwrap()
            .read_raw::<num_complex::Complex64>()
            .unwrap();
        assert_eq!(tf.len(), nf);
    }
    // X does not respond to theta_t in the model: no factor to fit there.
    let g = file.group("observables/X/theta_t").unwrap();
    assert!(g.attr("agreement_factor_re").is_err());

    let csv = std::fs::read_to_string(&outs[1]).unwrap();
    let header: Vec<&str> = csv
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    for col in [
        "frequency_hz",
        "estimable",
        "eta_t.psd",
        "X.psd",
        "X.eta_t.coherence",
        "X.eta_t.tf_re",
        "phi_a.eta_t.tf_radius",
        "phi_a.multiple_coherence_lower",
    ] {
        assert!(header.contains(&col), "{col} missing from {header:?}");
    }
    // The units line: one `COLUMN=UNIT` per column after the frequency.
    let units = csv
        .lines()
        .find_map(|l| l.strip_prefix("# units: "))
        .unwrap();
    for unit in [
        "eta_t.psd=rad^2/Hz",
        "X.psd=m^2/Hz",
        "X.eta_t.coherence=1",
        "X.eta_t.tf_re=m/rad",
        "phi_a.eta_t.tf_radius=rad/rad",
    ] {
        assert!(
            units.split(", ").any(|u| u == unit),
            "{unit} missing from {units}"
        );
    }
    assert_eq!(units.split(", ").count(), header.len() - 1);
    assert_eq!(csv.lines().filter(|l| !l.starts_with('#')).count(), nf + 1);
    let png = std::fs::read(&outs[2]).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let svg = std::fs::read_to_string(&outs[3]).unwrap();
    assert!(
        svg.starts_with("<svg") && svg.contains("magnitude"),
        "{}",
        &svg[..100]
    );
}

/// Runs a refused command in a fresh directory: exit code 2, one line with every needle, no
/// output file left.
fn refused(setup: impl FnOnce(&Path) -> Vec<String>, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let mut args = setup(dir.path());
    let save = dir.path().join("out.h5");
    args.extend(["--save".to_string(), s(&save).to_string()]);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_fails_without_output(&args, dir.path(), needles);
}

fn command(t: &Path, m: &Path, extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = ["coherence", "--tilt", s(t), "--measured", s(m)]
        .iter()
        .map(|a| a.to_string())
        .collect();
    v.extend(extra.iter().map(|a| a.to_string()));
    v
}

#[test]
fn records_apart_in_time_or_rate_or_too_short_are_refused() {
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-21T00:00:00Z");
            command(&t, &m, &[])
        },
        &[
            "do not overlap in time",
            "tilt.h5",
            "pendulum.h5",
            "2024-03-21T00:00:00Z",
        ],
    );
    refused(
        |d| {
            let (t, m) = inputs(d, 2.0, "2024-03-20T00:00:00Z");
            command(&t, &m, &[])
        },
        &["sampled at 1 Hz", "pendulum.h5 at 2 Hz", "same sample rate"],
    );
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-20T04:00:00Z");
            command(&t, &m, &["--nperseg", "4096"])
        },
        &[
            "common stretch",
            "1984 samples",
            "shorter than one Welch segment of 4096",
        ],
    );
}

#[test]
fn bad_samples_channels_and_options_are_refused() {
    // A NaN in the measured record, named by channel and index.
    refused(
        |d| {
            let (t, _) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            let m = d.join("nan.h5");
            let mut x = vec![1e-9; N];
            x[77] = f64::NAN;
            write_h5(&m, 1.0, None, None, &[("X", "m", &x)]);
            command(&t, &m, &[])
        },
        &["nan.h5", "X", "77"],
    );
    // A NaN in the tilt record.
    refused(
        |d| {
            let (_, m) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            let t = d.join("badtilt.h5");
            let mut e = vec![1e-9; N];
            e[5] = f64::INFINITY;
            write_h5(&t, 1.0, None, None, &[("eta_t", "rad", &e)]);
            command(&t, &m, &[])
        },
        &["badtilt.h5", "eta_t", "5"],
    );
    // An observable the measured file does not have.
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            command(&t, &m, &["--observables", "phi"])
        },
        &[
            "--observables phi",
            "pendulum.h5 has no channel phi",
            "it has X, phi_a",
        ],
    );
    // An unknown observable name.
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            command(&t, &m, &["--observables", "psi"])
        },
        &["unknown observable", "psi"],
    );
    // A tilt axis map naming a channel the file lacks.
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            command(&t, &m, &["--axes", "theta_t=-E"])
        },
        &["tilt.h5", "E"],
    );
    // Spectra instead of a series.
    refused(
        |d| {
            let (t, _) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            let m = d.join("asd.csv");
            std::fs::write(&m, "freq_hz,X\n0.01,1e-9\n0.02,1e-9\n").unwrap();
            command(&t, &m, &[])
        },
        &["asd.csv", "holds spectra", "time series"],
    );
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            command(&t, &m, &["--confidence", "1.5"])
        },
        &["confidence level 1.5", "(0, 1)"],
    );
    refused(
        |d| {
            let (t, m) = inputs(d, 1.0, "2024-03-20T00:00:00Z");
            command(&t, &m, &["--fit-band", "0.1:0.01"])
        },
        &["--fit-band 0.1:0.01"],
    );
}

#[test]
fn outputs_are_checked_before_anything_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let (t, m) = inputs(dir.path(), 1.0, "2024-03-20T00:00:00Z");
    let missing = dir.path().join("no-such-dir/c.h5");
    let good = dir.path().join("c.csv");
    assert_fails_without_output(
        &[
            "coherence",
            "--tilt",
            s(&t),
            "--measured",
            s(&m),
            "--save",
            s(&good),
            "--save",
            s(&missing),
        ],
        dir.path(),
        &["no-such-dir", "does not exist"],
    );
    assert_fails_without_output(
        &[
            "coherence",
            "--tilt",
            s(&t),
            "--measured",
            s(&m),
            "--save",
            s(&m),
        ],
        dir.path(),
        &["--measured", "replace an input"],
    );
    assert_fails_without_output(
        &[
            "coherence",
            "--tilt",
            s(&t),
            "--measured",
            s(&m),
            "--save",
            s(&dir.path().join("c.pdf")),
        ],
        dir.path(),
        &["c.pdf", ".png"],
    );
}

#[test]
fn saved_files_hold_the_report_exactly() {
    use tiltnoise_core::coherence::{coherence_from_series, CoherenceOptions, Record};
    use tiltnoise_core::model::TiltAxis;
    use tiltnoise_io::{CoherenceInputs, InputMeta, RunMeta};
    let model = Model::new(&Params::table_i()).unwrap();
    let outputs = [Observable::X];
    let (tilt, measured) = through_model(&model, 4096, &outputs, &[9e-10], 1.0, 0.0, 9);
    let tilt_record = Record {
        name: "--tilt t",
        sample_rate_hz: 1.0,
        start_time: None,
        channels: vec![
            (TiltAxis::ThetaT, &tilt[0][..]),
            (TiltAxis::EtaT, &tilt[1][..]),
        ],
    };
    let measured_record = Record {
        name: "--measured m",
        sample_rate_hz: 1.0,
        start_time: None,
        channels: vec![(Observable::X, &measured[0][..])],
    };
    let opts = CoherenceOptions {
        welch_segment_len: Some(256),
        ..CoherenceOptions::default()
    };
    let report = coherence_from_series(&model, &tilt_record, &measured_record, &opts).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (h5, csv) = (dir.path().join("r.h5"), dir.path().join("r.csv"));
    let inputs = CoherenceInputs {
        tilt: InputMeta {
            path: "t".into(),
            ..InputMeta::default()
        },
        measured_path: "m".into(),
        measured_start_time: None,
    };
    let result = tiltnoise_job::coherence::CoherenceResult { report, inputs };
    let report = &result.report;
    for path in [&h5, &csv] {
        tiltnoise_io::Staging::committed(|s| {
            tiltnoise_job::coherence::save(
                s,
                path,
                &result,
                &RunMeta::default(),
                &tiltnoise_plot::View::default(),
            )
        })
        .unwrap();
    }
    let file = hdf5::File::open(&h5).unwrap();
    assert_eq!(str_attr(&file, "alignment"), "assumed_simultaneous");
    let read = |name: &str| file.dataset(name).unwrap().read_raw::<f64>().unwrap();
    assert_eq!(read("frequency_hz"), report.freqs_hz);
    let x = &report.observables[0];
    assert_eq!(
        read("observables/X/multiple_coherence"),
        x.multiple_coherence
    );
    let tf = file
        .dataset("observables/X/eta_t/tf")
        .unwrap()
        .read_raw::<num_complex::Complex64>()
        .unwrap();
    assert_eq!(tf, x.axes[1].tf);
    // CSV: every value parses back to the same f64.
    let text = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = text
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    let col = header.iter().position(|h| *h == "X.eta_t.tf_im").unwrap();
    let back: Vec<f64> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    let want: Vec<f64> = x.axes[1].tf.iter().map(|z| z.im).collect();
    assert_eq!(back, want);
    // A figure drawn from the same report.
    let png = dir.path().join("r.png");
    tiltnoise_io::Staging::committed(|s| {
        tiltnoise_job::coherence::save(
            s,
            &png,
            &result,
            &RunMeta::default(),
            &tiltnoise_plot::View::default(),
        )
    })
    .unwrap();
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
}
