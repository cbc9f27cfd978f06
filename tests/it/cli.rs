//! The command line as a user meets it: exit codes, one-line errors naming the problem, no
//! partial output files, and machine-readable output.

use crate::common;

use common::{assert_fails, stderr, tiltnoise};
use std::path::Path;

fn dir_is_empty(dir: &Path) -> bool {
    std::fs::read_dir(dir).unwrap().next().is_none()
}

#[test]
fn params_prints_toml_that_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let out = tiltnoise(&["--set", "length.h_m=1.5", "params"]);
    assert!(out.status.success());
    let path = dir.path().join("p.toml");
    std::fs::write(&path, &out.stdout).unwrap();
    let back = tiltnoise_io::read_params(&path).unwrap();
    assert_eq!(back.length.h_m, 1.5);
    assert_eq!(
        back.with_override("length.h_m=2.0").unwrap(),
        tiltnoise_core::params::Params::table_i()
    );
}

#[test]
fn bad_parameter_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "[mass\nm_a_kg = 1").unwrap();
    let bad = bad.to_str().unwrap();
    assert_fails(&["--params", bad, "modes"], &["bad.toml"]);
    assert_fails(
        &["--params", "/nonexistent/p.toml", "modes"],
        &["/nonexistent/p.toml"],
    );
    // The operating system's reason, once (it is in the message, not also a chained source).
    for (args, what) in [
        (
            &["--params", "/nonexistent/p.toml", "modes"][..],
            "parameter file",
        ),
        (&["budget", "--tilt", "/nonexistent/t.h5"][..], "input file"),
        (
            &["budget", "--tilt", "/nonexistent/t.csv"][..],
            "input file",
        ),
    ] {
        let err = stderr(&tiltnoise(args));
        assert!(
            err.contains(&format!("cannot read {what} /nonexistent/")),
            "{err}"
        );
        assert_eq!(err.matches("os error").count(), 1, "{err}");
    }
    assert_fails(
        &["--set", "inertia.a11_kg_m2=-0.1", "modes"],
        &["inertia.a11_kg_m2", "-0.1", "kg m^2", "> 0"],
    );
    assert_fails(
        &["--set", "length.hh=1", "modes"],
        &["unknown key", "length.hh"],
    );
    assert_fails(
        &["--set", "mass.m_b_kg=nan", "modes"],
        &["mass.m_b_kg", "NaN"],
    );
    // An offset that would move a centre of mass out of its body: the key, the value, the
    // bound and what it is a fraction of.
    assert_fails(
        &["--set", "asymmetry.tm_com_x_m=0.08", "modes"],
        &[
            "asymmetry.tm_com_x_m",
            "0.08 m",
            "7.6000e-2 m",
            "10 % of Z_b",
        ],
    );
    assert_fails(
        &["--set", "asymmetry.sensor_rot_z_rad=inf", "modes"],
        &["asymmetry.sensor_rot_z_rad", "inf"],
    );
    // A relative error of an offset whose nominal value is 0 means nothing.
    let p = dir.path().join("sigma.toml");
    let text = String::from_utf8(tiltnoise(&["params"]).stdout).unwrap()
        + "\n[uncertainty]\n\"asymmetry.crossbar_com_x_m\" = { rel_sigma = 0.1 }\n";
    std::fs::write(&p, text).unwrap();
    assert_fails(
        &["--params", p.to_str().unwrap(), "modes"],
        &[
            "sigma.toml",
            "asymmetry.crossbar_com_x_m",
            "allowed fields: sigma",
        ],
    );
}

/// The pendulum as built on the command line: the rest configuration, mode labels with their
/// overlaps and the amplitude ratios, in JSON as in the library, and `auto` picks the pole-zero
/// method for the coupled system (block and split refuse it).
#[test]
fn modes_and_tf_of_the_pendulum_as_built() {
    let set = ["--set", "asymmetry.crossbar_com_x_m=1e-3"];
    let out = tiltnoise(&[&set[..], &["modes", "--format", "json"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let params = tiltnoise_core::params::Params::table_i()
        .with_override("asymmetry.crossbar_com_x_m=1e-3")
        .unwrap();
    let model = tiltnoise_core::model::Model::new(&params).unwrap();
    let lib = tiltnoise_core::modes::NormalModes::new(&model);
    assert_eq!(
        v["rest_configuration"]["eta_a"].as_f64().unwrap(),
        model.rest_configuration()[1]
    );
    for (k, (j, m)) in v["modes"]
        .as_array()
        .unwrap()
        .iter()
        .zip(&lib.modes)
        .enumerate()
    {
        assert_eq!(j["index"].as_u64().unwrap() as usize, m.index);
        assert_eq!(j["block"], "coupled");
        assert_eq!(j["overlap"].as_f64().unwrap(), m.overlap);
        assert_eq!(j["ratio"]["Y"].as_f64().unwrap(), lib.ratio[k][1]);
    }
    let table = String::from_utf8(tiltnoise(&[&set[..], &["modes"]].concat()).stdout).unwrap();
    assert!(
        table.contains("rest configuration") && table.contains("overlap"),
        "{table}"
    );

    let out = tiltnoise(&[&set[..], &["tf", "--freq", "1e-3:20:10", "--explain"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
    assert!(text.contains("picked `polezero`"), "{text}");
    assert_fails(
        &[
            &set[..],
            &["tf", "--freq", "1e-3:20:10", "--method", "block"],
        ]
        .concat(),
        &["block", "coupled model", "polezero"],
    );
    assert_fails(
        &[
            &set[..],
            &["tf", "--freq", "1e-3:20:10", "--method", "split"],
        ]
        .concat(),
        &["split", "pendulum as built"],
    );
}

#[test]
fn bad_frequency_input_is_refused_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out_csv = dir.path().join("out.csv");
    let out = out_csv.to_str().unwrap();
    let cases: [(&str, &[&str]); 4] = [
        ("", &["no frequencies"]),
        ("0.1\nabc\n", &["line 2", "abc"]),
        ("0.1\n-2\n", &["-2", "line 2", ">= 0"]),
        ("NaN\n", &["NaN"]),
    ];
    for (i, (text, needles)) in cases.iter().enumerate() {
        let f = dir.path().join(format!("f{i}.txt"));
        std::fs::write(&f, text).unwrap();
        let f = f.to_str().unwrap();
        assert_fails(&["tf", "--freq-file", f, "--save", out], needles);
        assert!(!out_csv.exists());
    }
    assert_fails(&["tf", "--freq=-1:10:1", "--save", out], &["FLO"]);
    assert!(!out_csv.exists());
}

#[test]
fn unwritable_or_unknown_outputs_leave_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("no/such/dir/tf.h5");
    assert_fails(
        &[
            "tf",
            "--freq",
            "1e-3:5:1",
            "--save",
            missing.to_str().unwrap(),
        ],
        &["no/such/dir/tf.h5"],
    );
    let unknown = dir.path().join("tf.xyz");
    assert_fails(
        &[
            "tf",
            "--freq",
            "1e-3:5:1",
            "--save",
            unknown.to_str().unwrap(),
        ],
        &["tf.xyz", ".h5"],
    );
    assert!(dir_is_empty(dir.path()));
}

#[test]
fn exact_resonance_in_a_frequency_file_is_an_error_not_garbage() {
    // The Rayleigh-refined nu_8 of the undamped model, written with full precision.
    let model =
        tiltnoise_core::model::Model::new(&tiltnoise_core::params::Params::table_i()).unwrap();
    let mode = tiltnoise_core::modes::NormalModes::new(&model).modes[7].clone();
    let lambda = tiltnoise_core::modes::refined_omega_sq(&model, &mode);
    let f = lambda.sqrt() / std::f64::consts::TAU;
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("f.txt");
    std::fs::write(&file, format!("1.0\n{f:e}\n")).unwrap();
    let out = dir.path().join("tf.csv");
    assert_fails(
        &[
            "tf",
            "--freq-file",
            file.to_str().unwrap(),
            "--save",
            out.to_str().unwrap(),
        ],
        &["singular", "resonance"],
    );
    assert!(!out.exists());
}

#[test]
fn modes_json_is_machine_readable() {
    let out = tiltnoise(&["modes", "--format", "json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 8);
    let lib = tiltnoise_core::modes::NormalModes::new(
        &tiltnoise_core::model::Model::new(&tiltnoise_core::params::Params::table_i()).unwrap(),
    );
    for (j, m) in modes.iter().zip(&lib.modes) {
        assert_eq!(j["index"].as_u64().unwrap() as usize, m.index);
        // serde_json prints f64 with round-trip precision.
        assert_eq!(j["frequency_hz"].as_f64().unwrap(), m.frequency_hz);
    }
    let seen: Vec<&str> = modes[5]["seen_by"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap())
        .collect();
    assert!(seen.contains(&"X"), "{seen:?}");
}

#[test]
fn tf_writes_every_requested_format() {
    let dir = tempfile::tempdir().unwrap();
    let paths: Vec<String> = ["tf.h5", "tf.csv", "tf.png", "tf.svg"]
        .iter()
        .map(|n| dir.path().join(n).to_str().unwrap().to_string())
        .collect();
    let mut args = vec!["tf", "--freq", "1e-4:50:10"];
    for p in &paths {
        args.push("--save");
        args.push(p);
    }
    let out = tiltnoise(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    for p in &paths {
        assert!(std::fs::metadata(p).unwrap().len() > 1000, "{p}");
    }
    let csv = std::fs::read_to_string(&paths[1]).unwrap();
    assert_eq!(csv.lines().filter(|l| !l.starts_with('#')).count(), 51);
    assert!(csv
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .starts_with("frequency_hz,X.theta_t.re,X.theta_t.im,X.eta_t.re"));
}

#[test]
fn mc_json_reports_every_mode_and_refuses_zero_samples() {
    let out = tiltnoise(&["mc", "--samples", "2000", "--seed", "7", "--format", "json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 8);
    assert_eq!(v["samples"].as_u64(), Some(2000));
    // The statistics are tested in crates/tiltnoise-core/tests/it/mc.rs; here the command must
    // reproduce the library's result for the same seed exactly (JSON floats round-trip).
    let params = tiltnoise_core::params::Params::table_i();
    let cfg = tiltnoise_core::mc::McConfig {
        samples: 2000,
        seed: 7,
        ..tiltnoise_core::mc::McConfig::default_for(&params)
    };
    let lib = tiltnoise_core::mc::run(&params, &cfg, &|_| {}).unwrap();
    for (k, m) in modes.iter().enumerate() {
        assert_eq!(m["index"].as_u64(), Some(k as u64 + 1));
        assert_eq!(m["mean_hz"].as_f64().unwrap(), lib.mean_hz[k], "{m}");
        assert_eq!(m["std_hz"].as_f64().unwrap(), lib.std_hz[k], "{m}");
    }
    assert_fails(&["mc", "--samples", "0"], &["samples = 0"]);
}

/// `--freq F` is the grid of the one frequency F; a request next to a mode that the planner
/// cannot verify names the mode and the two ways out, and the first of them works.
#[test]
fn tf_takes_one_frequency_and_explains_a_point_next_to_a_mode() {
    let out = tiltnoise(&[
        "tf",
        "--freq",
        "1e-3",
        "--input",
        "eta_t",
        "--observables",
        "X",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (_, freqs, values) = common::parse_tf_csv(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(freqs, vec![1e-3]);
    // X -> -eta_t (Z + Z_b + h_c) as f -> 0: negative and finite at 1 mHz.
    assert!(values[0][0].re.is_finite() && values[0][0].re < 0.0);

    let near = [
        "tf",
        "--freq",
        "0.415",
        "--input",
        "eta_t",
        "--observables",
        "X",
    ];
    assert_fails(
        &near,
        &[
            "0.415 Hz lies within 1 % of the normal mode at ",
            "--method polezero",
            "another --freq",
        ],
    );
    let err = stderr(&tiltnoise(&near));
    let mode_hz: f64 = err
        .split("normal mode at ")
        .nth(1)
        .and_then(|rest| rest.split(' ').next())
        .and_then(|x| x.parse().ok())
        .unwrap_or_else(|| panic!("no mode frequency in: {err}"));
    assert!(((mode_hz - 0.415) / mode_hz).abs() < 0.01, "{err}");
    let out = tiltnoise(&[&near[..], &["--method", "polezero"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
}

/// A segment duration shorter than the Welch segment says how short the Welch segment must be.
#[test]
fn a_segment_shorter_than_the_welch_segment_names_nperseg() {
    let lab = concat!(env!("CARGO_MANIFEST_DIR"), "/tilt_data/lab_tilt_24h.h5");
    assert_fails(
        &["budget", "--tilt", lab, "--segment-duration", "3600"],
        &[
            "segment duration 3600 s",
            "(nperseg) to at most 3600 samples",
        ],
    );
}

/// A segment duration that is not a positive number is refused naming the option.
#[test]
fn a_segment_duration_that_is_not_positive_names_the_option() {
    let lab = concat!(env!("CARGO_MANIFEST_DIR"), "/tilt_data/lab_tilt_24h.h5");
    for (given, shown) in [("nan", "NaN"), ("0", "0"), ("-60", "-60")] {
        assert_fails(
            &["budget", "--tilt", lab, "--segment-duration", given],
            &[
                &format!("--segment-duration {shown} is not allowed"),
                "a positive number of seconds",
            ],
        );
    }
}

#[test]
fn tf_json_holds_the_numbers_of_its_csv_bit_for_bit() {
    let args = [
        "tf",
        "--freq",
        "1e-4:37:30",
        "--input",
        "eta_t,x_t",
        "--observables",
        "X,phi",
        "--per",
        "acceleration",
        "--block-freqs",
        "5",
    ];
    let csv = tiltnoise(&args);
    assert!(csv.status.success(), "{}", stderr(&csv));
    let (header, freqs, rows) = common::parse_tf_csv(&String::from_utf8(csv.stdout).unwrap());
    let out = tiltnoise(&[&args[..], &["--format", "json"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).expect("--format json is JSON");
    assert_eq!(json["inputs"], serde_json::json!(["eta_t", "x_t"]));
    assert_eq!(json["observables"], serde_json::json!(["X", "phi"]));
    assert_eq!(json["per"], "acceleration");
    assert_eq!(json["units"][0][0], "m/(rad/s^2)");
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), freqs.len());
    assert_eq!(header[1], "X.eta_t.re");
    for (k, p) in points.iter().enumerate() {
        assert_eq!(p["frequency_hz"].as_f64(), Some(freqs[k]));
        let h = &p["H"];
        let from_json: Vec<num_complex::Complex64> = (0..2)
            .flat_map(|o| (0..2).map(move |i| (o, i)))
            .map(|(o, i)| {
                num_complex::Complex64::new(
                    h[o][i][0].as_f64().unwrap(),
                    h[o][i][1].as_f64().unwrap(),
                )
            })
            .collect();
        assert_eq!(from_json, rows[k], "frequency {}", freqs[k]);
    }
}
