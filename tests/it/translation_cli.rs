//! The floor's translation through the command line: `tf --input x_t,...` against the
//! double-double reference, its files (units m/m and rad/m, the translation convention stated,
//! figure panels per floor translation), the report's limits per unit acceleration, and
//! `budget --term NAME=x_t:FILE` (an ASD of the floor's displacement through the model).

use crate::common;
use crate::tolerances::{CSV_ROUND_TRIP, LOGLOG_REL, POLE_EXCLUSION, TARGET_REL};

use common::{parse_tf_csv, repo, str_attr, tiltnoise};
use num_complex::Complex64;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{relative_errors, ReferenceModel};
use tiltnoise_core::tf::{Input, Request};

/// `tf --input translation` writes CSV, HDF5 and figures: the CSV's numbers are the reference's
/// within the `auto` tolerance (and the CSV round trip), in m/m and rad/m, with the translation
/// convention stated in both files; the report gives the limits per unit acceleration.
#[test]
fn tf_writes_translation_columns_with_their_units_and_convention() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let out = tiltnoise(&[
        "tf",
        "--input",
        "translation",
        "--observables",
        "X,Y,Z,phi",
        "--freq",
        "1e-4:120:30",
        "--save",
        &p("u.csv"),
        "--save",
        &p("u.h5"),
        "--save",
        &p("u.svg"),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(
        stdout.contains("X/x_t / (-w^2)") && stdout.contains("equivalence principle"),
        "{stdout}"
    );
    let csv = std::fs::read_to_string(p("u.csv")).unwrap();
    assert!(
        csv.contains("# note: floor translation: x_t, y_t, z_t"),
        "{csv}"
    );
    assert!(csv.contains("X.x_t.re=m/m") && csv.contains("phi.z_t.im=rad/m"));
    let (header, freqs, rows) = parse_tf_csv(&csv);
    assert_eq!(header[1], "X.x_t.re");
    let params = Params::table_i();
    let modes = NormalModes::new(&Model::new(&params).unwrap()).frequencies_hz();
    let reference = ReferenceModel::new(&params);
    let request = Request {
        outputs: vec![Observable::X, Observable::Y, Observable::Z, Observable::Phi],
        inputs: Input::all_translations(),
    };
    let mut checked = 0;
    for (&f, row) in freqs.iter().zip(&rows) {
        if modes.iter().any(|&m| (f - m).abs() <= POLE_EXCLUSION * m) {
            continue;
        }
        let want = reference.eval_dd(&request, f).unwrap();
        for (k, (err, w)) in relative_errors(row, &want).iter().zip(&want).enumerate() {
            if w.is_zero() {
                assert_eq!(
                    row[k],
                    Complex64::new(0.0, 0.0),
                    "{} at {f} Hz",
                    header[2 * k + 1]
                );
            } else {
                assert!(
                    *err <= TARGET_REL + CSV_ROUND_TRIP,
                    "{} at {f} Hz: relative error {err:e}",
                    header[2 * k + 1]
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 500, "only {checked} entries checked");
    common::disable_hdf5_file_locking();
    let file = hdf5::File::open(p("u.h5")).unwrap();
    assert!(str_attr(&file, "translation_convention").contains("equivalence principle"));
    assert_eq!(common::strs_dataset(&file, "inputs"), ["x_t", "y_t", "z_t"]);
    assert_eq!(common::strs_dataset(&file, "input_units"), ["m", "m", "m"]);
    let svg = std::fs::read_to_string(p("u.svg")).unwrap();
    assert!(svg.contains("m/m") && svg.contains("rad/m"), "panel units");
    assert!(svg.contains("per floor translation"), "panel titles");
}

/// Files of tilt inputs alone say nothing about translation: the outputs of the existing
/// requests are unchanged.
#[test]
fn tilt_files_do_not_mention_translation() {
    let out = tiltnoise(&["tf", "--freq", "1e-3:3:1"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let csv = String::from_utf8(out.stdout).unwrap();
    assert!(!csv.contains("translation"), "{csv}");
}

/// `budget --term seismic=x_t:FILE`: the floor's displacement ASD (m/sqrt(Hz)) through the
/// model: at the `--at` frequencies `|H_o,x_t|^2 ASD^2` against the reference (the planner's
/// TARGET_REL on H, twice in |H|^2, plus the log-log interpolation of the ASD), exactly 0 on
/// Y (x_t drives the swing-x+torsion block only), with the source and its unit in the file.
#[test]
fn budget_term_of_a_floor_translation() {
    let dir = tempfile::tempdir().unwrap();
    let asd_file = dir.path().join("seismic.csv");
    let asd = |f: f64| 1e-7 * (f / 1e-2).powf(-1.0);
    let mut text = "# floor displacement\nfreq_hz,x_t\n".to_string();
    for k in 0..40 {
        let f = 1e-5 * 1e5f64.powf(k as f64 / 39.0);
        text.push_str(&format!("{f},{}\n", asd(f)));
    }
    std::fs::write(&asd_file, text).unwrap();
    let h5 = dir.path().join("b.h5");
    let lab = repo("tilt_data/lab_tilt_24h.h5");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        lab.to_str().unwrap(),
        "--nperseg",
        "4096",
        "--observables",
        "X,Y,phi",
        "--term",
        &format!("seismic=x_t:{}", asd_file.display()),
        "--format",
        "json",
        "--save",
        h5.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let file = hdf5::File::open(&h5).unwrap();
    let term = file.group("X/user.seismic").unwrap();
    assert_eq!(str_attr(&term, "source"), "x_t");
    assert_eq!(str_attr(&term, "source_asd_unit"), "m/sqrt(Hz)");
    let y: Vec<f64> = file
        .dataset("Y/user.seismic/psd")
        .unwrap()
        .read_raw()
        .unwrap();
    assert!(y.iter().all(|&p| p == 0.0));
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let reference = ReferenceModel::new(&Params::table_i());
    let mut checked = 0;
    for at in doc["summary"].as_array().unwrap() {
        let f = at["frequency_hz"].as_f64().unwrap();
        for ob in at["observables"].as_array().unwrap() {
            let o = Observable::from_name(ob["observable"].as_str().unwrap()).unwrap();
            let got = ob["terms"]
                .as_array()
                .unwrap()
                .iter()
                .find(|t| t["term"] == "user.seismic")
                .unwrap()["psd"]
                .as_f64()
                .unwrap();
            let request = Request {
                outputs: vec![o],
                inputs: vec![Input::from_name("x_t").unwrap()],
            };
            let want = reference.eval(&request, f).unwrap()[0].norm_sqr() * asd(f).powi(2);
            if want == 0.0 {
                assert_eq!(got, 0.0, "{} at {f} Hz", o.name());
                continue;
            }
            assert!(
                ((got - want) / want).abs() <= 2.0 * TARGET_REL + LOGLOG_REL,
                "{} user.seismic at {f} Hz: {got:e} vs {want:e}",
                o.name()
            );
            checked += 1;
        }
    }
    assert!(checked >= 2, "only {checked} values checked");
}

/// `tf --per acceleration`: the floor's columns per unit acceleration (the displacement's
/// divided by `-w^2`, to the CSV round trip), in m/(m/s^2) and m/(rad/s^2), force columns
/// unchanged; as f -> 0 X/x_t tends to the equivalence principle's `-(Z + Z_b + h_c) / g`. A
/// frequency file with 0 Hz is refused, naming the frequency.
#[test]
fn tf_per_unit_floor_acceleration() {
    let args = [
        "--input",
        "x_t,eta_t,F_b.x",
        "--observables",
        "X",
        "--freq",
        "1e-6:4:10",
    ];
    let run = |per: &str| {
        let mut a = vec!["tf"];
        a.extend(args);
        a.extend(["--per", per]);
        let out = tiltnoise(&a);
        assert!(out.status.success(), "{}", common::stderr(&out));
        String::from_utf8(out.stdout).unwrap()
    };
    let (displacement, acceleration) = (run("displacement"), run("acceleration"));
    assert!(
        acceleration.contains("X.x_t.re=m/(m/s^2)"),
        "{acceleration}"
    );
    assert!(acceleration.contains("X.eta_t.re=m/(rad/s^2)"));
    assert!(acceleration.contains("X.F_b.x.re=m/N"));
    assert!(acceleration
        .contains("# note: floor motion (tilt and translation inputs) per unit acceleration"));
    let (_, freqs, d) = parse_tf_csv(&displacement);
    let (_, _, a) = parse_tf_csv(&acceleration);
    for ((f, d), a) in freqs.iter().zip(&d).zip(&a) {
        let w2 = (std::f64::consts::TAU * f).powi(2);
        for k in 0..2 {
            let want = d[k] / -w2;
            assert!(
                (a[k] - want).norm() <= 4.0 * CSV_ROUND_TRIP * want.norm(),
                "entry {k} at {f} Hz: {} vs {want}",
                a[k]
            );
        }
        assert_eq!(a[2], d[2], "force column at {f} Hz");
    }
    let p = Params::table_i();
    let lever = Model::new(&p).unwrap().derived().lever_m;
    let limit = -lever / p.environment.g_m_per_s2;
    // At 1e-6 Hz the approach to the limit is 2.7e-8 relative (tests of the library).
    assert!(
        (a[0][0].re - limit).abs() <= 1e-7 * limit.abs(),
        "{} vs {limit}",
        a[0][0]
    );

    let dir = tempfile::tempdir().unwrap();
    let freq_file = dir.path().join("f.txt");
    std::fs::write(&freq_file, "1e-3\n0\n1\n").unwrap();
    let out = tiltnoise(&[
        "tf",
        "--input",
        "x_t",
        "--per",
        "velocity",
        "--freq-file",
        freq_file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = common::stderr(&out);
    assert!(err.contains("--per velocity: frequency 2 of"), "{err}");
}
