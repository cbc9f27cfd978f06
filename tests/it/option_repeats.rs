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

/// A copy `dir/name` of the lab tilt with 10 % of each channel's spread added as noise
/// (a co-located instrument of the same motion), without the channels `drop`.
fn colocated(dir: &std::path::Path, name: &str, drop: &[&str]) -> String {
    crate::common::disable_hdf5_file_locking();
    let path = dir.join(name);
    std::fs::copy(lab(), &path).unwrap();
    let file = hdf5::File::open_rw(&path).unwrap();
    for (k, ch) in ["theta_t", "eta_t"].into_iter().enumerate() {
        let ds = file.dataset(ch).unwrap();
        let mut x: Vec<f64> = ds.read_raw().unwrap();
        let sd = (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt();
        let mut rng = tiltnoise_core::rng::Rng::stream(11, k as u64);
        x.iter_mut().for_each(|v| *v += 0.1 * sd * rng.gaussian());
        ds.write(&ndarray::Array1::from(x)).unwrap();
    }
    for ch in drop {
        file.unlink(ch).unwrap();
    }
    file.close().unwrap();
    path.display().to_string()
}

/// An option naming an input, channel or observable the run does not have is refused, never
/// ignored: one line naming the option, the input and what the record holds; for the huddle's
/// noise ratio, the witness or the co-located record that lacks the input.
#[test]
fn an_option_naming_what_the_run_lacks_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (lab, meas) = (lab(), measured(dir.path()));
    let co = colocated(dir.path(), "co.h5", &[]);
    let co_theta = colocated(dir.path(), "co_theta.h5", &["eta_t"]);
    let pair = ["subtract", "--tilt", &lab, "--measured", &meas];
    let budget = ["budget", "--tilt", &lab, "--nperseg", "4096"];
    let cases: Vec<(Vec<&str>, Vec<String>)> = vec![
        (
            [
                &pair[..],
                &["--colocated", &co, "--colocated-ratio", "x_t=1"],
            ]
            .concat(),
            vec![
                "--colocated-ratio x_t=1".into(),
                format!("--tilt {lab} has no input x_t; it has theta_t, eta_t"),
            ],
        ),
        (
            [
                &pair[..],
                &["--colocated", &co_theta, "--colocated-ratio", "eta_t=2"],
            ]
            .concat(),
            vec![
                "--colocated-ratio eta_t=2".into(),
                format!("--colocated {co_theta} has no input eta_t; it has theta_t"),
            ],
        ),
        (
            [&pair[..], &["--witness-noise", "x_t=1e-9"]].concat(),
            vec!["--witness-noise x_t".into(), "has no input x_t".into()],
        ),
        (
            [&pair[..], &["--observables", "phi", "--readout", "X=1e-9"]].concat(),
            vec!["--readout X".into(), "no channel X; it has phi".into()],
        ),
        (
            [
                &budget[..],
                &["--observables", "phi", "--readout", "X=1e-9"],
            ]
            .concat(),
            vec!["--readout X=1e-9: X is not budgeted".into()],
        ),
        (
            [&budget[..], &["--scale", "foo=2"]].concat(),
            vec![
                "channel `foo`".into(),
                "available datasets: eta_t, theta_t".into(),
            ],
        ),
        (
            [&budget[..], &["--units", "foo=rad"]].concat(),
            vec!["channel `foo`".into(), "the unit `rad`".into()],
        ),
        (
            [&budget[..], &["--corrected", "foo"]].concat(),
            vec!["channel `foo` is declared corrected".into()],
        ),
        (
            [&budget[..], &["--pendulum-tiltmeter", "foo"]].concat(),
            vec!["channel `foo` is declared read by a pendulum tiltmeter".into()],
        ),
        (
            vec!["simulate", "--tilt", &lab, "--drive-gain", "x_t=1.1"],
            vec!["--drive-gain x_t=1.1: the record has no input `x_t`".into()],
        ),
        (
            vec![
                "tf",
                "--freq",
                "1e-3:5:1",
                "--observables",
                "X",
                "--plot-observables",
                "phi",
                "--save",
                "never.png",
            ],
            vec!["--plot-observables: phi is not among the computed observables (X)".into()],
        ),
        (
            vec!["--set", "length.nope_m=1", "modes"],
            vec!["length.nope_m".into()],
        ),
        (
            vec!["fit", "--free", "length.nope_m"],
            vec!["unknown parameter key `length.nope_m`".into()],
        ),
    ];
    for (args, needles) in cases {
        let needles: Vec<&str> = needles.iter().map(String::as_str).collect();
        crate::common::assert_fails_without_output(&args, dir.path(), &needles);
    }
}

/// An option the chosen mode does not use is refused, never ignored: figure options with no
/// figure saved (every command that draws), the default excitation's energy with another
/// excitation, the options of a record without one.
#[test]
fn an_option_the_mode_does_not_use_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (lab, meas) = (lab(), measured(dir.path()));
    let pair = ["--tilt", &lab, "--measured", &meas];
    let budget = ["budget", "--tilt", &lab, "--nperseg", "4096"];
    let tf = ["tf", "--freq", "1e-3:5:1"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            [&tf[..], &["--xlim", "1e-3:1"]].concat(),
            "--xlim applies to the figures",
        ),
        (
            [&tf[..], &["--phase"]].concat(),
            "--phase applies to the figures",
        ),
        (
            [&tf[..], &["--plot-observables", "X", "--save", "t.csv"]].concat(),
            "--plot-observables applies to the figures",
        ),
        (
            [&budget[..], &["--ylim", "1e-14:1e-6"]].concat(),
            "--ylim applies",
        ),
        ([&budget[..], &["--dpi", "200"]].concat(), "--dpi applies"),
        (
            vec!["mc", "--samples", "10", "--size", "800x600"],
            "--size applies",
        ),
        (
            vec!["methods", "--freq", "1e-3:5:1", "--dpi", "200"],
            "--dpi applies",
        ),
        (
            [&["coherence"][..], &pair, &["--xlim", "1e-3:1"]].concat(),
            "--xlim applies",
        ),
        (
            [&["subtract"][..], &pair, &["--size", "800x600"]].concat(),
            "--size applies",
        ),
        (
            vec!["simulate", "--duration", "1000", "--xlim", "1e-3:1"],
            "--xlim applies",
        ),
        (
            vec![
                "simulate",
                "--duration",
                "1000",
                "--init",
                "theta_a=1e-5",
                "--mode-energy",
                "1e-9",
            ],
            "cannot be used with '--mode-energy",
        ),
        (
            vec![
                "simulate",
                "--duration",
                "1000",
                "--kick-x",
                "1e-6",
                "--mode-energy",
                "1e-9",
            ],
            "cannot be used with '--mode-energy",
        ),
        (
            vec!["simulate", "--duration", "1000", "--units", "E=rad"],
            "--units describes the channels of a record and applies with --tilt FILE only",
        ),
        (
            vec!["simulate", "--duration", "1000", "--scale", "E=2"],
            "--scale describes the channels of a record and applies with --tilt FILE only",
        ),
        (
            vec!["simulate", "--duration", "1000", "--axes", "theta_t=E"],
            "--axes describes the channels of a record",
        ),
        (
            vec!["simulate", "--duration", "1000", "--oversample", "4"],
            "--oversample applies to a simulation driven by a record",
        ),
        (
            vec!["simulate", "--duration", "1000", "--drive-delay", "1"],
            "--drive-delay applies to a simulation driven by a record",
        ),
    ];
    for (args, needle) in cases {
        crate::common::assert_fails_without_output(&args, dir.path(), &[needle]);
    }
}
