//! `tiltnoise simulate` end to end: the default run (Figure 3 setting) and its resonance check,
//! the HDF5 layout, the kick figures, and bad input (exit 2, a message naming the option and
//! value, nothing written).

use crate::common;

use common::{assert_fails_without_output, listing, str_attr, tiltnoise};
use hdf5::types::VarLenUnicode;
use tiltnoise_core::model::{Coord, Observable};
use tiltnoise_core::spectral::{welch, WelchConfig};

fn stdout(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

#[test]
fn default_run_agrees_with_the_table_and_writes_the_budget_layout() {
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("sim.h5");
    let png = dir.path().join("fig3.png");
    let svg = dir.path().join("fig3.svg");
    let csv = dir.path().join("asd.csv");
    let out = tiltnoise(&[
        "simulate",
        "--save",
        h5.to_str().unwrap(),
        "--save",
        png.to_str().unwrap(),
        "--save",
        svg.to_str().unwrap(),
        "--save",
        csv.to_str().unwrap(),
    ]);
    let text = stdout(&out);
    assert!(out.status.success(), "{text}{}", common::stderr(&out));
    println!("{text}");
    // Every one of the 7 x 8 (channel, mode) pairs is testable and agrees with the table.
    assert!(
        text.contains("56 of 56 testable (channel, mode) pairs agree"),
        "{text}"
    );
    assert!(!text.contains("DISAGREES"));
    assert!(text.contains("432000 samples at dt = 0.1 s"));
    for p in [&png, &svg, &csv] {
        assert!(
            std::fs::metadata(p).unwrap().len() > 1000,
            "{}",
            p.display()
        );
    }

    let f = hdf5::File::open(&h5).unwrap();
    assert_eq!(str_attr(&f, "schema"), "tiltnoise.observable_series");
    // Writer and reader agree on the schema name.
    assert_eq!(
        tiltnoise_io::SCHEMA_OBSERVABLE_SERIES,
        tiltnoise_io::input::SCHEMA_OBSERVABLE_SERIES
    );
    let fs: f64 = f.attr("sample_rate_hz").unwrap().read_scalar().unwrap();
    assert_eq!(fs, 10.0);
    assert!(str_attr(&f, "parameters_toml").contains("[loss]"));
    assert!(str_attr(&f, "created_by").contains("simulate"));
    let seed: u64 = f.attr("seed").unwrap().read_scalar().unwrap();
    assert_eq!(seed, 0);
    for o in Observable::ALL {
        let ds = f.dataset(o.name()).unwrap();
        assert_eq!(ds.shape(), vec![432_000]);
        assert_eq!(str_attr(&ds, "unit"), o.unit());
    }
    let q0 = f
        .dataset("initial_state/q")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    assert_eq!(q0.len(), 8);
    let names = common::strs_attr(&f.group("initial_state").unwrap(), "coordinates");
    assert_eq!(
        names,
        Coord::ALL.iter().map(|c| c.name()).collect::<Vec<_>>()
    );
    // The stored ASD of X is the Welch ASD (2^17 samples, 50 % overlap, mean) of the stored X:
    // the same code on the same bits, so equal up to the final sqrt (1 ulp).
    let x = f.dataset("X").unwrap().read_raw::<f64>().unwrap();
    let want = welch(&x, fs, &WelchConfig::new(1 << 17)).unwrap().asd();
    let got = f.dataset("asd/X").unwrap().read_raw::<f64>().unwrap();
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert!((g - w).abs() <= 2.0 * f64::EPSILON * w, "{g} vs {w}");
    }
    let units: VarLenUnicode = f
        .dataset("asd/X")
        .unwrap()
        .attr("unit")
        .unwrap()
        .read_scalar()
        .unwrap();
    assert_eq!(units.as_str(), "m/sqrt(Hz)");
    // The CSV is the budget's measured-spectrum format.
    let m = tiltnoise_io::input::read_measured(&csv).unwrap();
    assert_eq!(m.asd.len(), 7);
    assert_eq!(m.freqs_hz.len(), want.len() - 1);
}

#[test]
fn kick_run_draws_figures_4_and_5() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("kick.png");
    let svg = dir.path().join("kick.svg");
    let out = tiltnoise(&[
        "simulate",
        "--kick-x",
        "1e-5",
        "--duration",
        "3600",
        "--save-time",
        png.to_str().unwrap(),
        "--save-time",
        svg.to_str().unwrap(),
    ]);
    let text = stdout(&out);
    assert!(out.status.success(), "{text}{}", common::stderr(&out));
    assert!(text.contains("kick: static X displacement of 1e-5 m released from rest"));
    // The kick excites only the swing-x + torsion block: the other block is not testable.
    assert!(
        text.contains("not testable: Y nu_3 (not excited)"),
        "{text}"
    );
    assert!(!text.contains("DISAGREES"));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let svg_text = std::fs::read_to_string(&svg).unwrap();
    assert!(svg_text.contains("Figure 4") && svg_text.contains("Figure 5"));
}

#[test]
fn bad_input_exits_2_names_the_option_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("out.h5");
    let png = dir.path().join("out.png");
    let save = |extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = vec!["simulate".into()];
        v.extend(extra.iter().map(|s| s.to_string()));
        v.extend([
            "--save".into(),
            h5.to_str().unwrap().into(),
            "--save".into(),
            png.to_str().unwrap().into(),
        ]);
        v
    };
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec!["--duration", "0"], vec!["--duration 0", "> 0"]),
        (vec!["--duration", "-5"], vec!["--duration -5", "> 0"]),
        (vec!["--duration", "nan"], vec!["--duration NaN", "finite"]),
        (vec!["--step", "0"], vec!["--step 0", "> 0"]),
        (vec!["--step", "-0.1"], vec!["--step -0.1", "> 0"]),
        (vec!["--step", "inf"], vec!["--step inf", "finite"]),
        (
            vec!["--duration", "0.1"],
            vec!["--duration 0.1", "1 sample", "at least 2"],
        ),
        (
            vec!["--duration", "100", "--nperseg", "2048"],
            vec![
                "--duration 100",
                "1000 samples",
                "shorter than one Welch segment",
                "--nperseg 2048",
            ],
        ),
        (
            vec!["--init", "theta_a=1e-5,foo=1"],
            vec!["--init foo=1", "unknown coordinate `foo`", "phi_b"],
        ),
        (
            vec!["--init", "phi_b=inf"],
            vec!["--init phi_b=inf", "finite"],
        ),
        (
            vec!["--init-rate", "phi_b=nan"],
            vec!["--init-rate phi_b=nan", "finite"],
        ),
        (vec!["--init", "phi_b"], vec!["--init phi_b", "COORD=VALUE"]),
        (vec!["--kick-x", "nan"], vec!["--kick-x NaN", "finite"]),
        (vec!["--mode-energy", "-1"], vec!["--mode-energy -1", "> 0"]),
        (
            vec!["--readout", "X=-1"],
            vec!["--readout X=-1", "0 or a value from 1e-40"],
        ),
        (vec!["--readout", "W=1"], vec!["unknown observable `W`"]),
        (
            vec!["--set", "loss.torsion_b_rad=1e-3"],
            vec!["undamped model", "loss"],
        ),
    ];
    for (args, needles) in cases {
        let full = save(&args);
        let refs: Vec<&str> = full.iter().map(String::as_str).collect();
        assert_fails_without_output(&refs, dir.path(), &needles);
    }
    // An unsupported output extension is refused before any work.
    let bad = dir.path().join("out.txt");
    assert_fails_without_output(
        &["simulate", "--save", bad.to_str().unwrap()],
        dir.path(),
        &["out.txt"],
    );
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn json_holds_the_numbers_of_the_table() {
    let run = |format: &str| {
        let out = tiltnoise(&["simulate", "--duration", "3600", "--format", format]);
        assert!(out.status.success(), "{}", common::stderr(&out));
        stdout(&out)
    };
    let (table, json) = (run("table"), run("json"));
    let json: serde_json::Value = serde_json::from_str(&json).expect("--format json is JSON");
    assert_eq!(json["samples"], 36_000);
    assert!(
        table.starts_with("free motion: 36000 samples at dt = 0.1 s"),
        "{table}"
    );
    let check = &json["resonance_check"];
    let pairs = check["channels"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|c| c["modes"].as_array().unwrap().clone())
        .collect::<Vec<_>>();
    let agree = pairs.iter().filter(|m| m["agrees"] == true).count();
    let tested = pairs.iter().filter(|m| !m["agrees"].is_null()).count();
    assert_eq!(check["tested"], tested);
    assert!(
        table.contains(&format!(
            "{agree} of {tested} testable (channel, mode) pairs agree"
        )),
        "{table}"
    );
    for m in json["modes"].as_array().unwrap() {
        let line = format!(
            "  nu_{} {:>11.4e} Hz",
            m["index"],
            m["frequency_hz"].as_f64().unwrap()
        );
        assert!(table.contains(&line), "{line} in {table}");
    }
}
