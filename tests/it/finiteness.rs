//! The finiteness policy (`tiltnoise_core::limits::magnitude`, docs/limits.md) held by every
//! reader and command, one test per class of input: a sample outside 0 or 1e-40 .. 1e40 (after
//! the file's unit and the scale factor) is refused where it enters, naming the file, channel,
//! index and value, before anything is printed or written; zeros stay; sample rates and
//! spectrum frequencies have their ranges; `subtract` names a dead channel; and an output never
//! replaces an input, whatever its spelling (an HDF5 address included).

use crate::common::{
    assert_fails, assert_fails_without_output, disable_hdf5_file_locking, listing, repo, stderr,
    tiltnoise,
};
use ndarray::Array1;
use std::path::{Path, PathBuf};
use tiltnoise_core::model::TiltAxis;
use tiltnoise_io::input::{
    read_measured_input, read_tilt_series, AxisMap, ChannelScale, GapPolicy, InputError,
    ReadOptions, TiltSeriesSource,
};

fn lab() -> PathBuf {
    repo("tilt_data/lab_tilt_24h.h5")
}

/// Rewrites the 1-D dataset `channel` of the HDF5 file `path` through `f`.
fn edit_dataset(path: &Path, channel: &str, f: impl FnOnce(&mut Vec<f64>)) {
    disable_hdf5_file_locking();
    let file = hdf5::File::open_rw(path).unwrap();
    let ds = file.dataset(channel).unwrap();
    let mut data: Vec<f64> = ds.read_raw().unwrap();
    f(&mut data);
    ds.write(&Array1::from(data)).unwrap();
    file.close().unwrap();
}

/// A copy `dir/name` of the HDF5 file `source` with its dataset `channel` edited by `f`.
fn copy_edited(
    source: &Path,
    dir: &Path,
    name: &str,
    channel: &str,
    f: impl FnOnce(&mut Vec<f64>),
) -> PathBuf {
    let path = dir.join(name);
    std::fs::copy(source, &path).unwrap();
    edit_dataset(&path, channel, f);
    path
}

/// A copy of the lab tilt with `channel[index] = value`.
fn lab_with(dir: &Path, name: &str, channel: &str, index: usize, value: f64) -> PathBuf {
    copy_edited(&lab(), dir, name, channel, |x| x[index] = value)
}

/// gwpy TimeSeries datasets `theta`, `eta` (unit `urad`, `dx` 1 s) of `n` samples, `eta[3000]`
/// set to `value`.
fn gwpy_with(path: &Path, n: usize, value: f64) {
    disable_hdf5_file_locking();
    let file = hdf5::File::create(path).unwrap();
    for name in ["theta", "eta"] {
        let mut data: Vec<f64> = (0..n)
            .map(|k| 1e-3 * ((k * 7919 % 997) as f64).sin())
            .collect();
        if name == "eta" {
            data[3000] = value;
        }
        let ds = file
            .new_dataset_builder()
            .with_data(&Array1::from(data))
            .create(name)
            .unwrap();
        for (attr, v) in [("x0", 1.2e9), ("dx", 1.0)] {
            ds.new_attr::<f64>()
                .create(attr)
                .unwrap()
                .write_scalar(&v)
                .unwrap();
        }
        for (attr, v) in [("xunit", "s"), ("unit", "urad")] {
            let v: hdf5::types::VarLenUnicode = v.parse().unwrap();
            ds.new_attr::<hdf5::types::VarLenUnicode>()
                .create(attr)
                .unwrap()
                .write_scalar(&v)
                .unwrap();
        }
    }
    file.close().unwrap();
}

fn out_of_range(e: InputError) -> (String, usize, f64) {
    match e {
        InputError::OutOfRange {
            channel,
            index,
            value,
            ..
        } => (channel, index, value),
        other => panic!("not a sample out of range: {other}"),
    }
}

/// HDF5 series, read whole and streamed, under both gap policies; and a scale factor that
/// makes every sample underflow.
#[test]
fn hdf5_samples_outside_their_magnitudes_are_refused_naming_channel_and_index() {
    let dir = tempfile::tempdir().unwrap();
    for (value, name) in [(1e150, "big.h5"), (-1e41, "neg.h5"), (1e-310, "tiny.h5")] {
        let path = lab_with(dir.path(), name, "eta_t", 5000, value);
        for gaps in [GapPolicy::Reject, GapPolicy::Interpolate] {
            let opts = ReadOptions {
                gaps,
                ..ReadOptions::default()
            };
            let e = read_tilt_series(&path, &opts).unwrap_err();
            assert!(e.to_string().contains(name), "{e}");
            assert_eq!(out_of_range(e), ("eta_t".to_string(), 5000, value));
            // Streamed: a chunk holding the sample (bridging gaps scans the whole series when
            // the file is opened, and refuses it there).
            let e = match TiltSeriesSource::open(&path, &opts) {
                Ok(mut src) => {
                    assert!(src.read_chunk(0, 4096).is_ok());
                    src.read_chunk(4096, 4096).unwrap_err()
                }
                Err(e) => {
                    assert_eq!(gaps, GapPolicy::Interpolate);
                    e
                }
            };
            assert_eq!(out_of_range(e), ("eta_t".to_string(), 5000, value));
        }
    }
    let opts = ReadOptions {
        scale: vec!["eta_t=1e-300".parse::<ChannelScale>().unwrap()],
        ..ReadOptions::default()
    };
    let e = read_tilt_series(&lab(), &opts).unwrap_err();
    let (channel, index, value) = out_of_range(e);
    assert_eq!((channel.as_str(), index), ("eta_t", 0));
    assert!(value != 0.0 && value.abs() < 1e-300, "{value:e}");
    // Exact zeros are structural and stay zeros.
    let zero = lab_with(dir.path(), "zero.h5", "eta_t", 5000, 0.0);
    let s = read_tilt_series(&zero, &ReadOptions::default()).unwrap();
    assert_eq!(s.channel(TiltAxis::EtaT).unwrap()[5000], 0.0);
}

/// CSV series: the line is named too.
#[test]
fn csv_samples_outside_their_magnitudes_are_refused_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.csv");
    let mut text = String::from("time_s,theta_t,eta_t\n");
    for k in 0..64 {
        let eta = if k == 40 {
            "2e-41".to_string()
        } else {
            format!("{:e}", 1e-9 * (k as f64).sin())
        };
        text += &format!("{k},1e-9,{eta}\n");
    }
    std::fs::write(&path, text).unwrap();
    let e = read_tilt_series(&path, &ReadOptions::default()).unwrap_err();
    let message = e.to_string();
    assert_eq!(out_of_range(e), ("eta_t".to_string(), 40, 2e-41));
    assert!(
        message.contains("sample index 40 (line 42) is 2e-41 rad")
            && message.contains("0 or a magnitude from 1e-40 to 1e40 rad"),
        "{message}"
    );
}

/// gwpy addresses: the file's unit (urad) applies before the check.
#[test]
fn gwpy_samples_are_checked_in_rad() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gw.h5");
    gwpy_with(&path, 8192, 1e308);
    let address = PathBuf::from(format!("{}:/", path.display()));
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=theta,eta_t=eta").unwrap()),
        ..ReadOptions::default()
    };
    let (channel, index, value) = out_of_range(read_tilt_series(&address, &opts).unwrap_err());
    assert_eq!((channel.as_str(), index), ("eta", 3000));
    assert!((value / 1e302 - 1.0).abs() < 1e-12, "{value:e}");
}

/// miniSEED: a scale factor that takes the counts out of range, either way.
#[test]
fn miniseed_samples_are_checked_after_the_scale_factor() {
    let path = repo("tests/fixtures/input/miniseed/little_endian.mseed");
    for factor in ["1e-300", "1e300"] {
        let opts = ReadOptions {
            axis_map: Some(AxisMap::parse("theta_t=-BJE").unwrap()),
            scale: vec![format!("BJE={factor}").parse().unwrap()],
            ..ReadOptions::default()
        };
        let e = read_tilt_series(&path, &opts).unwrap_err();
        let text = e.to_string();
        let (channel, _, value) = out_of_range(e);
        assert!(channel.ends_with("BJE"), "{text}");
        assert!(!tiltnoise_core::limits::SAMPLES.admits(value), "{text}");
    }
}

/// Measured series (HDF5 from `simulate`, CSV) and their sample rates.
#[test]
fn measured_series_and_sample_rates_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let meas = dir.path().join("meas.h5");
    let out = tiltnoise(&[
        "simulate",
        "--duration",
        "2000",
        "--save",
        meas.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(read_measured_input(&meas).is_ok());
    edit_dataset(&meas, "X", |x| x[77] = 1e45);
    assert_eq!(
        out_of_range(read_measured_input(&meas).unwrap_err()),
        ("X".to_string(), 77, 1e45)
    );
    let csv = dir.path().join("m.csv");
    std::fs::write(&csv, "time_s,X\n0,1e-9\n1e-300,2e-9\n2e-300,3e-9\n").unwrap();
    let e = read_measured_input(&csv).unwrap_err().to_string();
    assert!(
        e.contains("column time_s (dt = 1e-300 s) gives a sample rate of 9.99")
            && e.contains("e299 Hz; allowed: from 1e-6 to 2e6 Hz"),
        "{e}"
    );
}

/// The commands refuse before printing anything: a budget's `--measured` with an overflowing
/// sample prints no table; `subtract` and `coherence` on samples that made the SVD panic, and
/// on dead channels, name the culprit.
#[test]
fn commands_refuse_bad_samples_before_printing_and_name_dead_channels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let meas = d.join("meas.h5");
    let lab = lab();
    let out = tiltnoise(&[
        "simulate",
        "--tilt",
        lab.to_str().unwrap(),
        "--oversample",
        "2",
        "--save",
        meas.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let huge = copy_edited(&meas, d, "huge.h5", "X", |x| x[5000] = 1e308);
    let huge = huge.display().to_string();
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        lab.to_str().unwrap(),
        "--measured",
        &huge,
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(out.stdout.is_empty(), "printed before refusing");
    assert!(stderr(&out).contains("channel `X` sample index 5000 is 1e308 m"));
    let lab = lab.display().to_string();
    for cmd in ["subtract", "coherence"] {
        assert_fails(
            &[cmd, "--tilt", &lab, "--measured", &huge],
            &["huge.h5", "channel `X` sample index 5000 is 1e308 m"],
        );
        let big_tilt = lab_with(d, "tilt_1e150.h5", "eta_t", 7000, 1e150);
        assert_fails(
            &[
                cmd,
                "--tilt",
                big_tilt.to_str().unwrap(),
                "--measured",
                &meas.display().to_string(),
            ],
            &[
                "tilt_1e150.h5",
                "channel `eta_t` sample index 7000 is 1e150 rad",
            ],
        );
    }
    let dead = copy_edited(&meas, d, "dead.h5", "X", |x| x.fill(0.0));
    let dead = dead.display().to_string();
    assert_fails(
        &["subtract", "--tilt", &lab, "--measured", &dead],
        &["X of the measured record is zero at every sample of the overlap"],
    );
    assert_fails(
        &["coherence", "--tilt", &lab, "--measured", &dead],
        &[&format!(
            "X of {dead} is zero at every sample over the common stretch"
        )],
    );
    let flat_tilt = copy_edited(Path::new(&lab), d, "flat.h5", "eta_t", |x| x.fill(0.0));
    assert_fails(
        &[
            "subtract",
            "--tilt",
            flat_tilt.to_str().unwrap(),
            "--measured",
            &meas.display().to_string(),
        ],
        &["eta_t of the tilt record is zero at every sample of the overlap"],
    );
    assert_fails(
        &[
            "subtract",
            "--tilt",
            &lab,
            "--measured",
            &meas.display().to_string(),
            "--tilt-noise",
            "eta_t=1e300",
        ],
        &[
            "--witness-noise eta_t: the ASD 1e300",
            "0 or a value from 1e-40 to 1e40 rad/sqrt(Hz)",
        ],
    );
}

/// `FILE.h5:/dataset` addresses are the file they address: no command saves onto it, whatever
/// the spelling of either path, and the file is left as it was.
#[test]
fn no_command_saves_onto_an_input_given_as_an_hdf5_address() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let gw = d.join("gw.h5");
    gwpy_with(&gw, 86400, 1e-3);
    std::os::unix::fs::symlink("gw.h5", d.join("link.h5")).unwrap();
    let meas = d.join("meas.h5");
    let out = tiltnoise(&[
        "simulate",
        "--duration",
        "2000",
        "--save",
        meas.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let before = std::fs::read(&gw).unwrap();
    let entries = listing(d);
    let g = |rel: &str| d.join(rel).display().to_string();
    let axes = ["--axes", "theta_t=theta,eta_t=eta"];
    let cases: Vec<Vec<String>> = vec![
        vec![
            "budget".into(),
            "--tilt".into(),
            format!("{}:/", g("gw.h5")),
            "--save".into(),
            g("gw.h5"),
        ],
        vec![
            "budget".into(),
            "--tilt".into(),
            format!("{}:/eta", g("link.h5")),
            "--save".into(),
            g("gw.h5"),
        ],
        vec![
            "simulate".into(),
            "--tilt".into(),
            format!("{}:/", g("gw.h5")),
            "--save".into(),
            g("./gw.h5"),
        ],
        vec![
            "coherence".into(),
            "--tilt".into(),
            format!("{}:/", g("gw.h5")),
            "--measured".into(),
            g("meas.h5"),
            "--save".into(),
            g("gw.h5"),
        ],
        vec![
            "subtract".into(),
            "--tilt".into(),
            format!("{}:/", g("gw.h5")),
            "--measured".into(),
            g("meas.h5"),
            "--save".into(),
            g("gw.h5"),
        ],
    ];
    for mut args in cases {
        args.extend(axes.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_fails(
            &args,
            &[
                "cannot save",
                "an output must not replace an input of the run",
            ],
        );
    }
    assert_eq!(
        std::fs::read(&gw).unwrap(),
        before,
        "an input was overwritten"
    );
    assert_eq!(listing(d), entries, "files were left behind");
}

/// The newest outputs, one class: what `subtract` with a co-located record and `fit` with
/// visibilities print and store is finite, or the input that would make it infinite is refused
/// where it enters (the huddle's noise ratio, an offset's error bar, a visibility's error),
/// naming the option or file, key or line, the value and the range, with nothing written. At
/// the ends of the ratio's range the relative gain is finite and near 1, in the JSON and in
/// the HDF5 file.
#[test]
fn newest_outputs_are_finite_or_their_inputs_refused_where_they_enter() {
    disable_hdf5_file_locking();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let lab_path = lab();
    let lab = lab_path.display().to_string();
    let meas = d.join("meas.h5").display().to_string();
    let out = tiltnoise(&[
        "simulate",
        "--tilt",
        &lab,
        "--oversample",
        "2",
        "--save",
        &meas,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let co = copy_edited(&lab_path, d, "co.h5", "eta_t", |x| {
        let mut rng = tiltnoise_core::rng::Rng::stream(5, 0);
        let sd = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        x.iter_mut().for_each(|v| *v += 0.1 * sd * rng.gaussian());
    });
    let co = co.display().to_string();
    // Every ratio from 0 (a noiseless co-located instrument) to the largest.
    for r in [
        0.0,
        1e-300,
        1e-3,
        1.0,
        tiltnoise_core::limits::MAX_NOISE_RATIO,
    ] {
        let save = d.join(format!("s_{r:e}.h5"));
        let ratio = format!("eta_t={r:e}");
        let out = tiltnoise(&[
            "subtract",
            "--tilt",
            &lab,
            "--measured",
            &meas,
            "--colocated",
            &co,
            "--colocated-ratio",
            &ratio,
            "--format",
            "json",
            "--save",
            save.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{r}: {}", stderr(&out));
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let eta = json["witness_noise"]
            .as_array()
            .unwrap()
            .iter()
            .find(|w| w["input"] == "eta_t")
            .unwrap();
        let g = eta["relative_gains"][0].as_f64().expect("a finite gain");
        assert!((g - 1.0).abs() < 0.1, "ratio {r}: gain {g}");
        let file = hdf5::File::open(&save).unwrap();
        for name in file.member_names().unwrap() {
            if let Ok(ds) = file.dataset(&name) {
                if let Ok(v) = ds.read_raw::<f64>() {
                    assert!(v.iter().all(|x| x.is_finite()), "{r}: /{name}");
                }
            }
        }
    }
    let before = listing(d);
    for r in ["1e150", "1e300", "1001", "-1e-3", "nan"] {
        let ratio = format!("eta_t={r}");
        assert_fails(
            &[
                "subtract",
                "--tilt",
                &lab,
                "--measured",
                &meas,
                "--colocated",
                &co,
                "--colocated-ratio",
                &ratio,
                "--save",
                &d.join("never.h5").display().to_string(),
            ],
            &["--colocated-ratio eta_t=", "must be from 0 to 1e3"],
        );
    }
    assert_eq!(listing(d), before, "a refused run wrote something");
    // fit: an offset's error bar and a visibility's error outside their ranges.
    let params = d.join("p.toml");
    let table = String::from_utf8(tiltnoise(&["params"]).stdout).unwrap();
    let vis = d.join("vis.csv");
    std::fs::write(
        &vis,
        "mode,observable,reference,ratio,sigma\n1,phi_a,phi,0.6458,1e-8\n6,Z,X,1e-3,1e-310\n",
    )
    .unwrap();
    let vis = vis.display().to_string();
    for sigma in ["1e-310", "1e-21", "2"] {
        std::fs::write(
            &params,
            format!("{table}\n[uncertainty]\n\"asymmetry.tm_com_x_m\" = {{ sigma = {sigma} }}\n"),
        )
        .unwrap();
        assert_fails_without_output(
            &[
                "--params",
                params.to_str().unwrap(),
                "fit",
                "--free",
                "asymmetry.tm_com_x_m",
                "--save",
                &d.join("never.json").display().to_string(),
            ],
            d,
            &[
                "p.toml",
                "sigma of `asymmetry.tm_com_x_m`",
                "from 1e-20 to 1e0",
            ],
        );
    }
    assert_fails_without_output(
        &[
            "fit",
            "--visibility",
            &vis,
            "--save",
            &d.join("never.json").display().to_string(),
        ],
        d,
        &[
            "vis.csv, line 3",
            "sigma `1e-310` of nu_6 Z/X",
            "from 1e-40 to 2e6",
        ],
    );
}
