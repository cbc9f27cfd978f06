//! Every repeatable `KEY=VALUE` option and every list option of every command refuses a key or
//! name given twice (`tiltnoise_core::repeats`), in one occurrence or across several, with one
//! line naming the option and the key.

use crate::common::{assert_fails, repo, tiltnoise};

fn lab() -> String {
    repo("tilt_data/lab_tilt_24h.h5").display().to_string()
}

/// The observables `simulate --tilt` answers the lab tilt with, written into `dir`.
fn measured(dir: &std::path::Path) -> String {
    let path = dir.join("meas.h5").display().to_string();
    let out = tiltnoise(&[
        "simulate",
        "--tilt",
        &lab(),
        "--oversample",
        "2",
        "--save",
        &path,
    ]);
    assert!(out.status.success(), "{out:?}");
    path
}

#[test]
fn a_key_or_name_given_twice_is_refused_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let (lab, meas) = (lab(), measured(dir.path()));
    let asd = dir.path().join("asd.csv");
    std::fs::write(&asd, "frequency_hz,asd\n1e-5,1e-9\n10,1e-9\n").unwrap();
    let term = |name: &str, source: &str| format!("{name}={source}:{}", asd.display());
    let (term_x, term_phi) = (term("a", "X"), term("a", "phi"));
    let budget = ["budget", "--tilt", &lab, "--nperseg", "4096"];
    let pair = ["--tilt", &lab, "--measured", &meas];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["--set", "length.h_m=1", "--set", "length.h_m=2", "modes"],
            "--set: length.h_m is given twice; name each parameter key once",
        ),
        (
            [
                &budget[..],
                &["--readout", "X=1e-9", "--readout", " X =2e-9"],
            ]
            .concat(),
            "--readout: X is given twice; name each observable once",
        ),
        (
            [
                &budget[..],
                &["--scale", "theta_t=1", "--scale", "theta_t=2"],
            ]
            .concat(),
            "--scale: theta_t is given twice; name each channel once",
        ),
        (
            [&budget[..], &["--term", &term_x, "--term", &term_phi]].concat(),
            "--term: a is given twice; name each term name once",
        ),
        (
            [&budget[..], &["--observables", "X,phi,X"]].concat(),
            "--observables: X is given twice; name each observable once",
        ),
        (
            [&budget[..], &["--at", "1e-3,2e-3,0.001"]].concat(),
            "--at: 0.001 is given twice; name each frequency once",
        ),
        (
            vec![
                "tf", "--freq", "1e-3:5:1", "--input", "tilt", "--input", "eta_t",
            ],
            "--input: eta_t is given twice; name each input once",
        ),
        (
            vec![
                "tf",
                "--freq",
                "1e-3:5:1",
                "--observables",
                "X",
                "--observables",
                "X",
            ],
            "--observables: X is given twice; name each observable once",
        ),
        (
            vec![
                "simulate",
                "--duration",
                "1000",
                "--init",
                "theta_a=1e-5,theta_a=2e-5",
            ],
            "--init: theta_a is given twice; name each coordinate once",
        ),
        (
            vec![
                "simulate",
                "--duration",
                "1000",
                "--init-rate",
                "phi_b=1e-6",
                "--init-rate",
                "phi_b=2e-6",
            ],
            "--init-rate: phi_b is given twice; name each coordinate once",
        ),
        (
            vec![
                "simulate",
                "--duration",
                "1000",
                "--readout",
                "X=1e-9",
                "--readout",
                "X=0",
            ],
            "--readout: X is given twice; name each observable once",
        ),
        (
            vec![
                "simulate",
                "--tilt",
                &lab,
                "--drive-gain",
                "eta_t=1,eta_t=2",
            ],
            "--drive-gain: eta_t is given twice; name each input once",
        ),
        (
            [&["subtract"][..], &pair, &["--observables", "X,X"]].concat(),
            "--observables: X is given twice; name each observable once",
        ),
        (
            [
                &["subtract"][..],
                &pair,
                &["--tilt-noise", "eta_t=1e-9", "--tilt-noise", "eta_t=2e-9"],
            ]
            .concat(),
            "--witness-noise: eta_t is given twice; name each input once",
        ),
        (
            [
                &["subtract"][..],
                &pair,
                &["--readout", "X=1e-9", "--readout", "X=2e-9"],
            ]
            .concat(),
            "--readout: X is given twice; name each observable once",
        ),
        (
            [
                &["subtract"][..],
                &pair,
                &["--fit", "length.h_m,length.h_m"],
            ]
            .concat(),
            "--fit: length.h_m is given twice; name each parameter key once",
        ),
        (
            [&["coherence"][..], &pair, &["--observables", "X,phi,X"]].concat(),
            "--observables: X is given twice; name each observable once",
        ),
        (
            [
                &["coherence"][..],
                &pair,
                &["--scale", "eta_t=1", "--scale", "eta_t=1"],
            ]
            .concat(),
            "--scale: eta_t is given twice; name each channel once",
        ),
        (
            vec!["fit", "--free", "mass.m_a_kg,mass.m_a_kg"],
            "--free: mass.m_a_kg is given twice; name each parameter key once",
        ),
    ];
    for (args, message) in cases {
        assert_fails(&args, &[message]);
    }
}
