//! Open budgets: any observable, readout per observable (white or a given spectrum), and
//! user-named terms (an ASD of an observable, or an input noise through the model) composed in
//! quadrature into the total, with their groups in the files; and every kind of bad request
//! refused with exit code 2 and nothing written.

use crate::common;
use crate::tolerances::{LOGLOG_REL, TARGET_REL, U};

use common::{assert_fails_without_output, repo, str_attr, tiltnoise};
use std::path::Path;
use tiltnoise_core::model::{ForceInput, Input, Observable};
use tiltnoise_core::reference::ReferenceModel;
use tiltnoise_core::tf::Request;

/// A power law `a (f / 1 mHz)^p` on 40 log-spaced points from 1e-5 to 1 Hz: log-log
/// interpolation between them reproduces it to rounding.
fn power_law(a: f64, p: f64) -> impl Fn(f64) -> f64 {
    move |f: f64| a * (f / 1e-3).powf(p)
}

fn write_asd_csv(path: &Path, column: &str, asd: &dyn Fn(f64) -> f64) {
    let mut text = format!("# a test spectrum\nfreq_hz,{column}\n");
    for k in 0..40 {
        let f = 1e-5 * 1e5f64.powf(k as f64 / 39.0);
        text.push_str(&format!("{f},{}\n", asd(f)));
    }
    std::fs::write(path, text).unwrap();
}

fn psd(file: &hdf5::File, path: &str) -> Vec<f64> {
    file.dataset(&format!("{path}/psd"))
        .unwrap()
        .read_raw()
        .unwrap()
}

#[test]
fn user_terms_and_coloured_readout_add_in_quadrature_with_their_groups() {
    let dir = tempfile::tempdir().unwrap();
    let (force, mag, readout) = (
        dir.path().join("force.csv"),
        dir.path().join("mag.csv"),
        dir.path().join("phi_readout.csv"),
    );
    let force_asd = power_law(1e-13, -1.0);
    let mag_asd = power_law(3e-9, -0.5);
    let readout_asd = power_law(2e-9, -0.25);
    write_asd_csv(&force, "F_b.x", &force_asd);
    write_asd_csv(&mag, "asd", &mag_asd);
    write_asd_csv(&readout, "phi", &readout_asd);
    let h5 = dir.path().join("b.h5");
    let lab = repo("tilt_data/lab_tilt_24h.h5");
    let damped = repo("examples/damped.toml");
    let out = tiltnoise(&[
        "--params",
        damped.to_str().unwrap(),
        "budget",
        "--tilt",
        lab.to_str().unwrap(),
        "--nperseg",
        "4096",
        "--observables",
        "X,Y,phi",
        "--readout",
        &format!("phi={}", readout.display()),
        "--readout",
        "Y=2e-9",
        "--term",
        &format!("actuation=F_b.x:{}", force.display()),
        "--term",
        &format!("magnetic=phi:{}", mag.display()),
        "--format",
        "json",
        "--save",
        h5.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let file = hdf5::File::open(&h5).unwrap();
    let freqs: Vec<f64> = file.dataset("frequency_hz").unwrap().read_raw().unwrap();
    let observables = common::strs_attr(&file, "observables");
    assert_eq!(observables, vec!["X", "Y", "phi"]);

    // Given spectra on the grid: the power laws, to log-log rounding.
    let close = |got: &[f64], want: &dyn Fn(f64) -> f64, what: &str| {
        for (k, (&g, &f)) in got.iter().zip(&freqs).enumerate() {
            let w = want(f).powi(2);
            assert!(
                ((g - w) / w).abs() <= LOGLOG_REL,
                "{what} at bin {k} ({f} Hz): {g:e} vs {w:e}"
            );
        }
    };
    close(&psd(&file, "phi/readout"), &readout_asd, "phi readout");
    close(
        &psd(&file, "phi/user.magnetic"),
        &mag_asd,
        "phi user.magnetic",
    );
    assert_eq!(
        str_attr(&file.group("phi").unwrap(), "readout_given"),
        format!("{} (column phi)", readout.display())
    );
    let y_readout = psd(&file, "Y/readout");
    assert!(y_readout.iter().all(|&p| p == 2e-9 * 2e-9));
    // F_b.x drives the x-phi block only: exactly 0 on Y.
    assert!(psd(&file, "Y/user.actuation").iter().all(|&p| p == 0.0));

    // The groups, and the sums: user = its terms, total = tilt + readout + thermal + user
    // (each a sum of at most 4 non-negative terms: 4 u relative).
    for obs in ["X", "phi"] {
        let g = file.group(obs).unwrap();
        for (term, group) in [
            ("tilt", "tilt"),
            ("tilt.eta_t", "tilt"),
            ("thermal.torsion_b", "thermal"),
            ("user", "user"),
            ("user.actuation", "user"),
            ("total", "total"),
        ] {
            assert_eq!(
                str_attr(&g.group(term).unwrap(), "group"),
                group,
                "{obs}/{term}"
            );
        }
        let act = g.group("user.actuation").unwrap();
        assert_eq!(str_attr(&act, "source"), "F_b.x");
        assert_eq!(str_attr(&act, "source_asd_unit"), "N/sqrt(Hz)");
        let user = psd(&file, &format!("{obs}/user"));
        let named: Vec<String> = common::strs_attr(&g, "terms")
            .into_iter()
            .filter(|t| t.starts_with("user."))
            .collect();
        let total = psd(&file, &format!("{obs}/total"));
        for k in 0..freqs.len() {
            let sum: f64 = named
                .iter()
                .map(|t| psd(&file, &format!("{obs}/{t}"))[k])
                .sum();
            assert!((user[k] - sum).abs() <= 4.0 * U * sum, "{obs} user at {k}");
            let parts: f64 = ["tilt", "readout", "thermal", "user"]
                .iter()
                .filter(|t| g.group(t).is_ok())
                .map(|t| psd(&file, &format!("{obs}/{t}"))[k])
                .sum();
            assert!(
                (total[k] - parts).abs() <= 4.0 * U * parts,
                "{obs} total at {k}"
            );
        }
    }

    // At the --at frequencies: the input's ASD through the transfer function at exactly f,
    // against the double-double reference (the planner's TARGET_REL on H, twice in |H|^2).
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let reference = ReferenceModel::new(&tiltnoise_io::read_params(&damped).unwrap());
    let f_b_x = Input::Force(ForceInput::from_name("F_b.x").unwrap());
    for at in doc["summary"].as_array().unwrap() {
        let f = at["frequency_hz"].as_f64().unwrap();
        for ob in at["observables"].as_array().unwrap() {
            let o = Observable::from_name(ob["observable"].as_str().unwrap()).unwrap();
            let term = |name: &str| {
                ob["terms"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .find(|t| t["term"] == name)
                    .unwrap_or_else(|| panic!("{} has no {name}", o.name()))
                    .clone()
            };
            let act = term("user.actuation");
            assert_eq!(act["evaluation"], "exact");
            assert_eq!(act["group"], "user");
            let h = reference
                .eval(
                    &Request {
                        outputs: vec![o],
                        inputs: vec![f_b_x],
                    },
                    f,
                )
                .unwrap()[0];
            let want = h.norm_sqr() * force_asd(f).powi(2);
            let got = act["psd"].as_f64().unwrap();
            if want == 0.0 {
                assert_eq!(got, 0.0, "{} at {f} Hz", o.name());
            } else {
                assert!(
                    ((got - want) / want).abs() <= 2.0 * TARGET_REL + LOGLOG_REL,
                    "{} user.actuation at {f} Hz: {got:e} vs {want:e}",
                    o.name()
                );
            }
            if o == Observable::Phi {
                let mag = term("user.magnetic")["psd"].as_f64().unwrap();
                let want = mag_asd(f).powi(2);
                assert!(
                    ((mag - want) / want).abs() <= LOGLOG_REL,
                    "{mag:e} vs {want:e}"
                );
            }
        }
    }
}

#[test]
fn bad_open_budget_requests_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.csv");
    write_asd_csv(&good, "asd", &power_law(1e-13, -1.0));
    let narrow = dir.path().join("narrow.csv");
    std::fs::write(&narrow, "freq_hz,asd\n1e-3,1e-13\n1e-2,1e-14\n").unwrap();
    let negative = dir.path().join("negative.csv");
    std::fs::write(&negative, "freq_hz,phi\n1e-5,1e-9\n0.5,-1e-9\n1,1e-9\n").unwrap();
    let nan = dir.path().join("nan.csv");
    std::fs::write(&nan, "freq_hz,F_b.x\n1e-5,1e-13\n0.5,NaN\n1,1e-13\n").unwrap();
    let wrong_column = dir.path().join("wrong_column.csv");
    std::fs::write(&wrong_column, "freq_hz,X\n1e-5,1e-9\n1,1e-9\n").unwrap();
    let no_dataset = dir.path().join("no_dataset.h5");
    {
        let f = hdf5::File::create(&no_dataset).unwrap();
        f.new_dataset_builder()
            .with_data(&[1e-5, 1.0])
            .create("frequency_hz")
            .unwrap();
    }
    let missing = dir.path().join("missing.csv");
    let (g, n, ng, nn, wc, nd, m) = (
        good.display(),
        narrow.display(),
        negative.display(),
        nan.display(),
        wrong_column.display(),
        no_dataset.display(),
        missing.display(),
    );
    let out_dir = tempfile::tempdir().unwrap();
    let out = out_dir.path().join("b.h5");
    let cases: Vec<(Vec<String>, Vec<String>)> = vec![
        (
            vec!["--observables".into(), "X,Q".into()],
            vec!["--observables".into(), "unknown observable \"Q\"".into()],
        ),
        (
            vec!["--observables".into(), "X,X".into()],
            vec!["X is given twice".into()],
        ),
        (
            vec!["--term".into(), format!("a=F_c.x:{g}")],
            vec!["unknown source `F_c.x`".into(), "F_a.x".into()],
        ),
        (
            vec!["--term".into(), format!("a=phi:{m}")],
            vec![format!("{m}")],
        ),
        (
            vec!["--term".into(), format!("a=F_b.x:{n}")],
            vec![
                "covers 1e-3 .. 1e-2 Hz".into(),
                "never extrapolated".into(),
                format!("{n}"),
            ],
        ),
        (
            vec!["--readout".into(), format!("phi={ng}")],
            vec![
                format!("{ng}"),
                "line 3".into(),
                "`phi`".into(),
                "-1e-9".into(),
            ],
        ),
        (
            vec!["--term".into(), format!("a=F_b.x:{nn}")],
            vec![format!("{nn}"), "`F_b.x`".into(), "NaN".into()],
        ),
        (
            vec!["--term".into(), format!("a=phi:{wc}")],
            vec![
                format!("{wc}"),
                "no column `phi` or `asd`".into(),
                "`X`".into(),
            ],
        ),
        (
            vec!["--term".into(), format!("a=phi:{nd}")],
            vec![format!("{nd}"), "/phi (or /asd)".into()],
        ),
        (
            vec!["--readout".into(), "Y=1e-9".into()],
            vec!["Y is not budgeted".into(), "--observables".into()],
        ),
        (
            vec!["--term".into(), format!("a=Z:{g}")],
            vec!["Z is not budgeted".into()],
        ),
        (
            vec!["--term".into(), format!("1abc=phi:{g}")],
            vec!["the name `1abc` is not allowed".into()],
        ),
        (
            vec![
                "--term".into(),
                format!("a=phi:{g}"),
                "--term".into(),
                format!("a=X:{g}"),
            ],
            vec!["--term: a is given twice".into()],
        ),
        (
            vec!["--term".into(), "a=phi".into()],
            vec!["expected NAME=SOURCE:FILE".into()],
        ),
    ];
    let lab = repo("tilt_data/lab_tilt_24h.h5");
    for (extra, needles) in cases {
        let mut args: Vec<String> = vec![
            "budget".into(),
            "--tilt".into(),
            lab.display().to_string(),
            "--nperseg".into(),
            "4096".into(),
            "--save".into(),
            out.display().to_string(),
        ];
        args.extend(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
        assert_fails_without_output(&args, out_dir.path(), &needles);
    }
}
