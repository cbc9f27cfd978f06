//! `tiltnoise subtract` end to end: the verification case (a known tilt through the model
//! with another h, a tiltmeter gain error and a delay, plus white readout; records aligned by
//! their start times), the outputs (the cleaned record that `budget --measured` reads, the JSON
//! report, the figure), the real ROMY record as the witness of a simulated pendulum, and the
//! refusals of bad input.

use crate::common::{self, assert_fails_without_output, tiltnoise};
use hdf5::types::VarLenUnicode;
use std::path::Path;

#[path = "../../crates/tiltnoise-core/tests/it/synthetic.rs"]
mod synthetic;
use synthetic::{make, Record, Spec};

fn str_attr(loc: &hdf5::Location, name: &str, value: &str) {
    loc.new_attr_builder()
        .with_data(&ndarray::arr0(value.parse::<VarLenUnicode>().unwrap()))
        .create(name)
        .unwrap();
}

/// The tilt record as `tiltnoise.tilt_series` HDF5: samples `range` of every axis.
fn write_tilt(
    path: &Path,
    rec: &Record,
    fs: f64,
    range: std::ops::Range<usize>,
    start: Option<&str>,
) {
    let f = hdf5::File::create(path).unwrap();
    str_attr(&f, "schema", "tiltnoise.tilt_series");
    f.new_attr_builder()
        .with_data(&ndarray::arr0(fs))
        .create("sample_rate_hz")
        .unwrap();
    if let Some(s) = start {
        str_attr(&f, "start_time", s);
    }
    for (axis, x) in rec.axes.iter().zip(&rec.tilt) {
        let ds = f
            .new_dataset_builder()
            .with_data(&x[range.clone()])
            .create(axis.name())
            .unwrap();
        str_attr(&ds, "units", "rad");
    }
}

/// The measured record as `tiltnoise.observable_series` HDF5: samples `range`.
fn write_measured(
    path: &Path,
    rec: &Record,
    fs: f64,
    range: std::ops::Range<usize>,
    start: Option<&str>,
) {
    let f = hdf5::File::create(path).unwrap();
    str_attr(&f, "schema", "tiltnoise.observable_series");
    f.new_attr_builder()
        .with_data(&ndarray::arr0(fs))
        .create("sample_rate_hz")
        .unwrap();
    if let Some(s) = start {
        str_attr(&f, "start_time", s);
    }
    for (o, x) in &rec.measured {
        let ds = f
            .new_dataset_builder()
            .with_data(&x[range.clone()])
            .create(o.name())
            .unwrap();
        str_attr(&ds, "units", o.unit());
    }
}

fn run_json(args: &[&str]) -> serde_json::Value {
    let out = tiltnoise(args);
    assert!(out.status.success(), "{args:?}: {}", common::stderr(&out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn estimate<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["estimates"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["name"] == name)
        .unwrap_or_else(|| panic!("no estimate {name}"))
}

/// The issue's verification. The tilt record covers 2^16 s at 1 Hz from 00:00:00; the
/// measured record starts 600 s later and ends 300 s earlier (alignment by start times). The
/// pendulum has h = 2.5 m, sees the tilt of theta_t times 1.03 and of eta_t times 0.97, 2.3 s
/// late; X, Y read out with 1 nm/sqrt(Hz), phi with 1 nrad/sqrt(Hz). Fitted from the nominal
/// Table I (h = 2.0 m) with `--fit length.h_m`:
///
/// * every estimate within 3 of its stated sigmas of the truth, each sigma below an upper
///   bound (the fit is informative: 1e-3 on the gains and the delay, 1 cm on h), and chi^2/dof
///   within 4 standard deviations (`sqrt(2 / dof)`) of 1, so that the weights behind the
///   sigmas are right (their honesty over realizations is tested in the core's tests);
/// * the cleaned ASD of X and Y, averaged over 3-30 mHz on the held-out stretch, equal to the
///   readout within 3 of its statistical sigmas;
/// * `budget --measured cleaned.h5` reads the cleaned record, and its measured X term averages
///   to the readout in the same band within 3 sigmas of its Welch average.
#[test]
fn verification_end_to_end() {
    let spec = Spec::verification();
    let rec = make(&spec);
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let n = spec.n;
    write_tilt(
        Path::new(&p("tilt.h5")),
        &rec,
        spec.fs_hz,
        0..n,
        Some("2024-03-01T00:00:00Z"),
    );
    write_measured(
        Path::new(&p("measured.h5")),
        &rec,
        spec.fs_hz,
        600..n - 300,
        Some("2024-03-01T00:10:00Z"),
    );
    let (tilt, measured, cleaned) = (p("tilt.h5"), p("measured.h5"), p("cleaned.h5"));
    let (json_file, png) = (p("report.json"), p("subtract.png"));
    let report = run_json(&[
        "subtract",
        "--tilt",
        &tilt,
        "--measured",
        &measured,
        "--fit",
        "length.h_m",
        "--readout",
        "X=1e-9",
        "--readout",
        "Y=1e-9",
        "--readout",
        "phi=1e-9",
        "--format",
        "json",
        "--save",
        &cleaned,
        "--save",
        &json_file,
        "--save",
        &png,
    ]);
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_file).unwrap()).unwrap();
    assert_eq!(saved, report);
    let a = &report["alignment"];
    assert_eq!(a["tilt_first_sample"], 600);
    assert_eq!(a["measured_first_sample"], 0);
    assert_eq!(a["samples"], n - 900);
    assert_eq!(a["overlap_start_time"], "2024-03-01T00:10:00Z");

    eprintln!("closing note: true and estimated parameters");
    for (name, truth, max_sigma) in [
        ("gain.theta_t", 1.03, 1e-3),
        ("gain.eta_t", 0.97, 1e-3),
        ("delay_s", spec.delay_s(), 1e-3),
        ("length.h_m", 2.5, 1e-2),
    ] {
        let e = estimate(&report, name);
        let (value, sigma) = (e["value"].as_f64().unwrap(), e["sigma"].as_f64().unwrap());
        eprintln!(
            "  {name}: true {truth}, estimated {value:.6} +/- {sigma:.2e} ({:+.2} sigma)",
            (value - truth) / sigma
        );
        assert_eq!(e["status"], "fitted", "{name}");
        assert!(
            (value - truth).abs() < 3.0 * sigma,
            "{name}: {value} +/- {sigma} vs {truth}"
        );
        assert!(sigma > 0.0 && sigma < max_sigma, "{name}: sigma {sigma}");
    }
    let (chi2, dof) = (
        report["fit"]["chi2"].as_f64().unwrap(),
        report["fit"]["dof"].as_f64().unwrap(),
    );
    eprintln!("  chi2/dof = {:.4} ({dof} dof)", chi2 / dof);
    assert!(
        (chi2 / dof - 1.0).abs() < 4.0 * (2.0 / dof).sqrt(),
        "chi2/dof {}",
        chi2 / dof
    );

    eprintln!("closing note: cleaned / readout ASD in 3-30 mHz (held-out stretch)");
    for r in report["residuals"].as_array().unwrap() {
        let [ratio, sigma] = [0, 1].map(|i| r["cleaned_to_readout"][i].as_f64().unwrap());
        eprintln!(
            "  {}: {ratio:.4} +/- {sigma:.4} over {}..{} Hz; measured {:.3e}, cleaned {:.3e}, \
             Wiener {:.3e}, coherence limit {:.3e}",
            r["observable"],
            r["band_hz"][0],
            r["band_hz"][1],
            r["measured_asd"].as_f64().unwrap(),
            r["cleaned_asd"].as_f64().unwrap(),
            r["wiener_asd"].as_f64().unwrap(),
            r["expected_asd"].as_f64().unwrap()
        );
        assert!(
            (ratio - 1.0).abs() < 3.0 * sigma,
            "{}: {ratio} +/- {sigma}",
            r["observable"]
        );
        assert_eq!(r["below_coherence_bound"], false);
    }

    // The cleaned record: the observable-series layout, plus the groups.
    let f = hdf5::File::open(&cleaned).unwrap();
    assert_eq!(
        common::str_attr(&f, "schema"),
        "tiltnoise.observable_series"
    );
    assert_eq!(common::str_attr(&f, "start_time"), "2024-03-01T00:10:00Z");
    for o in ["X", "Y", "phi"] {
        let x = f.dataset(o).unwrap().read_raw::<f64>().unwrap();
        assert_eq!(x.len(), n - 900);
        let pred = f
            .dataset(&format!("predicted_tilt/{o}"))
            .unwrap()
            .read_raw::<f64>()
            .unwrap();
        assert_eq!(pred.len(), n - 900);
    }
    let names = common::strs_attr(&f.group("estimates").unwrap(), "name");
    assert_eq!(
        names,
        ["gain.theta_t", "gain.eta_t", "delay_s", "length.h_m"]
    );
    let png_bytes = std::fs::read(&png).unwrap();
    assert_eq!(&png_bytes[..4], b"\x89PNG");

    // `budget --measured` reads the cleaned record: its X averages to the readout in 3-30 mHz.
    let csv = p("budget.csv");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        &tilt,
        "--measured",
        &cleaned,
        "--nperseg",
        "4096",
        "--readout",
        "X=1e-9",
        "--save",
        &csv,
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "X.measured")
        .expect("X.measured column");
    let psd: Vec<f64> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().unwrap())
                .collect::<Vec<f64>>()
        })
        .filter(|row| (3e-3..=3e-2).contains(&row[0]))
        .map(|row| row[col].powi(2))
        .collect();
    let mean = psd.iter().sum::<f64>() / psd.len() as f64;
    // Welch of the whole cleaned record: (n - 900) / 2048 - 1 half-overlapping segments of
    // 4096 (about 30), bins correlated as for adjacent Hann bins (variance factor 1.944).
    let segments = ((n - 900) / 2048 - 1) as f64;
    let rel = (1.944 * 1.056 / (segments * psd.len() as f64)).sqrt();
    eprintln!(
        "  budget --measured cleaned.h5: X measured ASD {:.4e} in 3-30 mHz (+/- {:.1} %)",
        mean.sqrt(),
        50.0 * rel
    );
    assert!(
        (mean / 1e-18 - 1.0).abs() < 3.0 * rel,
        "budget's X PSD {mean:e}"
    );
}

/// The same pipeline on the real ROMY record (kept beside the repository): the record as the
/// witness, a pendulum simulated from it (`simulate --tilt`, h = 2.5 m, gains 1.03 and 0.97,
/// 2.3 s late, oversampled 100 times), fitted from Table I. The estimates are within 3 sigma
/// of the truth, and the cleaned Y reaches its readout within 3 sigma in 8-30 mHz (X keeps
/// the free torsion oscillation the earthquake excites, which no prediction of an undamped
/// model can know; docs/subtract.md).
#[test]
fn romy_record_as_witness() {
    let Some(romy) = common::shared_tilt_data(
        "romy_record_as_witness",
        "romy_6c_teleseism_20180123/ROMY_gulf_of_alaska_teleseism.csv",
    ) else {
        return;
    };
    let romy = romy.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let pend = dir.path().join("pendulum.h5");
    let pend = pend.to_str().unwrap();
    let axes = ["--quantity", "rate", "--axes", "theta_t=-LJE,eta_t=-LJN"];
    let mut args = vec!["--set", "length.h_m=2.5", "simulate", "--tilt", romy];
    args.extend(axes);
    args.extend([
        "--oversample",
        "100",
        "--drive-gain",
        "theta_t=1.03,eta_t=0.97",
        "--drive-delay",
        "2.3",
        "--readout",
        "X=1e-9",
        "--readout",
        "Y=1e-9",
        "--readout",
        "phi=1e-9",
        "--save",
        pend,
    ]);
    let out = tiltnoise(&args);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let mut args = vec!["subtract", "--tilt", romy, "--measured", pend];
    args.extend(axes);
    args.extend([
        "--observables",
        "X,Y,phi",
        "--fit",
        "length.h_m",
        "--readout",
        "X=1e-9",
        "--readout",
        "Y=1e-9",
        "--readout",
        "phi=1e-9",
        "--report-band",
        "6e-3:3e-2",
        "--format",
        "json",
    ]);
    let report = run_json(&args);
    for (name, truth) in [
        ("gain.theta_t", 1.03),
        ("gain.eta_t", 0.97),
        ("delay_s", 2.3),
        ("length.h_m", 2.5),
    ] {
        let e = estimate(&report, name);
        let (value, sigma) = (e["value"].as_f64().unwrap(), e["sigma"].as_f64().unwrap());
        eprintln!("ROMY {name}: true {truth}, estimated {value} +/- {sigma:.2e}");
        assert!(
            (value - truth).abs() < 3.0 * sigma,
            "{name}: {value} +/- {sigma}"
        );
    }
    let y = report["residuals"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["observable"] == "Y")
        .unwrap();
    let [ratio, sigma] = [0, 1].map(|i| y["cleaned_to_readout"][i].as_f64().unwrap());
    eprintln!("ROMY Y cleaned / readout: {ratio:.3} +/- {sigma:.3}");
    assert!((ratio - 1.0).abs() < 3.0 * sigma);
}

/// Writes the noisy-witness case ([`Spec::noisy_witness`]: a tiltmeter whose white noise is
/// 30 % of the tilt at 10 mHz, the pendulum with h = 1.7 m) as `tilt.h5` and `measured.h5`
/// into the directory `TILTNOISE_CASE_DIR` (noise realisation `TILTNOISE_CASE_SEED`, default
/// the spec's), for running any build of the command on it (`scripts/subtract/band_ratios.py`
/// then judges a cleaned record against the raw one):
///
/// ```sh
/// TILTNOISE_CASE_DIR=/tmp/case cargo test --release --test it write_noisy_witness_case -- --ignored
/// ```
#[test]
#[ignore = "writes files for a manual comparison; needs TILTNOISE_CASE_DIR"]
fn write_noisy_witness_case() {
    let dir = std::env::var("TILTNOISE_CASE_DIR").expect("TILTNOISE_CASE_DIR");
    let dir = Path::new(&dir);
    std::fs::create_dir_all(dir).unwrap();
    let mut spec = Spec::noisy_witness();
    if let Ok(seed) = std::env::var("TILTNOISE_CASE_SEED") {
        spec.seed = seed.parse().expect("TILTNOISE_CASE_SEED: an integer");
    }
    let rec = make(&spec);
    let start = Some("2024-03-01T00:00:00Z");
    write_tilt(&dir.join("tilt.h5"), &rec, spec.fs_hz, 0..spec.n, start);
    write_measured(&dir.join("measured.h5"), &rec, spec.fs_hz, 0..spec.n, start);
}

/// The noisy-witness case through the command line, with the noise stated three ways: a
/// spectrum file for theta_t and a white level for eta_t, both uncertain by 10 % (`:0.1`);
/// estimated from a co-located tiltmeter of equal noise (a huddle test); and in a budget of the
/// same tilt record, where it is shown through the model beside the tilt term and not added to
/// the total.
///
/// * gains and delay within 3 of their sigmas of the truth, every noise scale within 3 sigma of
///   1, and every band of the record as written no higher than the raw record, with a lower
///   variance, in X and Y;
/// * the huddle finds the co-located instrument's gain (1) to 1e-2 and the witness noise of
///   eta_t within 3 of its stated uncertainty in 0.05-0.25 Hz (where the noise dominates);
/// * the budget's `witness_noise` term equals the same ASD given as a user term through the
///   model (`--term`), the total does not change with it, and the tilt term, which contains
///   it, lies above it in every 1/3-decade band.
#[test]
fn noisy_witness_end_to_end() {
    let mut spec = Spec::noisy_witness();
    spec.colocated_noise = vec![spec.witness_noise];
    let rec = make(&spec);
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let t0 = Some("2024-03-01T00:00:00Z");
    let n = spec.n;
    write_tilt(Path::new(&p("tilt.h5")), &rec, spec.fs_hz, 0..n, t0);
    write_measured(Path::new(&p("measured.h5")), &rec, spec.fs_hz, 0..n, t0);
    let other = Record {
        axes: rec.axes.clone(),
        tilt: rec.colocated[0].clone(),
        translation: Vec::new(),
        colocated: Vec::new(),
        measured: Vec::new(),
    };
    write_tilt(Path::new(&p("colocated.h5")), &other, spec.fs_hz, 0..n, t0);
    std::fs::write(
        p("theta_noise.csv"),
        format!(
            "frequency_hz,theta_t\n1e-5,{0:e}\n1,{0:e}\n",
            spec.witness_noise[0]
        ),
    )
    .unwrap();
    let (tilt, measured, cleaned) = (p("tilt.h5"), p("measured.h5"), p("cleaned.h5"));
    let theta = format!("theta_t={}:0.1", p("theta_noise.csv"));
    let eta = format!("eta_t={:e}:0.1", spec.witness_noise[1]);
    let report = run_json(&[
        "subtract",
        "--tilt",
        &tilt,
        "--measured",
        &measured,
        "--witness-noise",
        &theta,
        "--witness-noise",
        &eta,
        "--format",
        "json",
        "--save",
        &cleaned,
    ]);
    let truth = [
        ("gain.theta_t", 1.03),
        ("gain.eta_t", 0.97),
        ("delay_s", spec.delay_s()),
        ("noise_scale.theta_t", 1.0),
        ("noise_scale.eta_t", 1.0),
    ];
    let check = |report: &serde_json::Value, names: &[(&str, f64)]| {
        for &(name, t) in names {
            let e = estimate(report, name);
            let (v, s) = (e["value"].as_f64().unwrap(), e["sigma"].as_f64().unwrap());
            eprintln!("{name}: {v} +/- {s:.2e} (true {t})");
            assert!((v - t).abs() < 3.0 * s, "{name}: {v} +/- {s} vs {t}");
        }
        for b in report["bands"].as_array().unwrap() {
            if b["observable"] == "phi" {
                continue;
            }
            assert!(b["variance_ratio"].as_f64().unwrap() < 1.0, "{b}");
            for band in b["bands"].as_array().unwrap() {
                // A band left raw keeps, of the prediction, only the static response to the
                // line through the record's end samples (its leakage is ~1e-10 of the band).
                let allowed = if band["left_raw"] == true { 1e-6 } else { 0.0 };
                assert!(band["ratio"].as_f64().unwrap() <= 1.0 + allowed, "{band}");
            }
        }
    };
    check(&report, &truth);
    assert_eq!(report["fit"]["stop"], "projected gradient below tolerance");
    let f = hdf5::File::open(&cleaned).unwrap();
    let ratio = f
        .dataset("bands/X/ratio")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    assert!(ratio.iter().all(|&r| r <= 1.0 + 1e-6), "{ratio:?}");
    let method: String = common::str_attr(&f.dataset("witness_noise/eta_t").unwrap(), "method");
    assert_eq!(method, "given");
    drop(f);

    let report = run_json(&[
        "subtract",
        "--tilt",
        &tilt,
        "--measured",
        &measured,
        "--colocated",
        &p("colocated.h5"),
        "--format",
        "json",
        "--save",
        &cleaned,
    ]);
    check(&report, &truth[..3]);
    for x in report["witness_noise"].as_array().unwrap() {
        assert_eq!(x["method"], "huddle");
        let g = x["relative_gains"][0].as_f64().unwrap();
        assert!((g - 1.0).abs() < 1e-2, "{x}");
    }
    let f = hdf5::File::open(&cleaned).unwrap();
    let freqs = f
        .dataset("witness_noise/frequency_hz")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let asd = f
        .dataset("witness_noise/eta_t")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let rel = report["witness_noise"][1]["rel"].as_f64().unwrap();
    let band: Vec<f64> = freqs
        .iter()
        .zip(&asd)
        .filter(|(f, _)| (0.05..=0.25).contains(*f))
        .map(|(_, a)| a / spec.witness_noise[1] - 1.0)
        .collect();
    let mean = band.iter().sum::<f64>() / band.len() as f64;
    eprintln!(
        "huddle: eta_t noise ASD off by {mean:+.4} on average in 0.05-0.25 Hz (+/- {rel:.4})"
    );
    assert!(mean.abs() < 3.0 * rel, "{mean} vs {rel}");

    let flat = p("eta_noise.csv");
    std::fs::write(
        &flat,
        format!(
            "frequency_hz,asd\n1e-5,{0:e}\n1,{0:e}\n",
            spec.witness_noise[1]
        ),
    )
    .unwrap();
    let budget = |extra: &[&str], csv: &str| -> Vec<(String, Vec<f64>)> {
        let mut args = vec![
            "budget",
            "--tilt",
            &tilt,
            "--nperseg",
            "4096",
            "--save",
            csv,
        ];
        args.extend(extra);
        let out = tiltnoise(&args);
        assert!(out.status.success(), "{}", common::stderr(&out));
        let text = std::fs::read_to_string(csv).unwrap();
        let mut lines = text.lines().filter(|l| !l.starts_with('#'));
        let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect();
        header
            .into_iter()
            .enumerate()
            .map(|(c, h)| (h, rows.iter().map(|r| r[c]).collect()))
            .collect()
    };
    let col = |t: &[(String, Vec<f64>)], name: &str| -> Vec<f64> {
        t.iter()
            .find(|(h, _)| h == name)
            .unwrap_or_else(|| panic!("no column {name}"))
            .1
            .clone()
    };
    let eta_only = format!("eta_t={:e}", spec.witness_noise[1]);
    let term = format!("wn=eta_t:{flat}");
    let with = budget(
        &["--witness-noise", &eta_only, "--term", &term],
        &p("with.csv"),
    );
    let without = budget(&["--term", &term], &p("without.csv"));
    assert_eq!(col(&with, "X.total"), col(&without, "X.total"));
    let (wn, user, tilt_term) = (
        col(&with, "X.witness_noise"),
        col(&with, "X.user.wn"),
        col(&with, "X.tilt"),
    );
    for (a, b) in wn.iter().zip(&user) {
        assert!((a - b).abs() <= 1e-12 * b.abs(), "{a} vs {b}");
    }
    let freqs = col(&with, "frequency_hz");
    for decade in [1e-3, 1e-2, 1e-1] {
        let sel = |v: &[f64]| -> f64 {
            let pts: Vec<f64> = freqs
                .iter()
                .zip(v)
                .filter(|(f, _)| **f >= decade && **f < 2.0 * decade)
                .map(|(_, x)| x * x)
                .collect();
            pts.iter().sum::<f64>() / pts.len() as f64
        };
        assert!(
            sel(&tilt_term) > sel(&wn),
            "{decade} Hz: tilt below the witness noise in it"
        );
    }
}

/// The second derivative of a periodic series, taken on its DFT (`-(2 pi f)^2` on every bin
/// `0 < k < n/2`, DC and Nyquist set to 0): the acceleration a seismometer would record of a
/// displacement, made here independently of the command line's integration.
fn acceleration_of(x: &[f64], fs_hz: f64) -> Vec<f64> {
    let n = x.len();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let (fwd, inv) = (planner.plan_fft_forward(n), planner.plan_fft_inverse(n));
    let mut time = x.to_vec();
    let mut bins = fwd.make_output_vec();
    fwd.process(&mut time, &mut bins).unwrap();
    let last = bins.len() - 1;
    for (k, b) in bins.iter_mut().enumerate() {
        let w = 2.0 * std::f64::consts::PI * k as f64 * fs_hz / n as f64;
        *b = if k == 0 || (n % 2 == 0 && k == last) {
            num_complex::Complex64::new(0.0, 0.0)
        } else {
            -*b * w * w / n as f64
        };
    }
    let mut out = inv.make_output_vec();
    inv.process(&mut bins, &mut out).unwrap();
    out
}

/// A witness record of tilt and floor translation as CSV, its units in a `# units:` line.
fn write_ground_csv(path: &str, names: &[&str], units: &[&str], series: &[Vec<f64>]) {
    let pairs: Vec<String> = names
        .iter()
        .zip(units)
        .map(|(n, u)| format!("{n}={u}"))
        .collect();
    let mut csv = format!(
        "# start_time: 2024-03-01T00:00:00Z\n# units: {}\ntime_s,{}\n",
        pairs.join(", "),
        names.join(",")
    );
    for i in 0..series[0].len() {
        csv.push_str(&i.to_string());
        for x in series {
            csv.push_str(&format!(",{x:e}", x = x[i]));
        }
        csv.push('\n');
    }
    std::fs::write(path, csv).unwrap();
}

/// Translation witnesses from the command line ([`Spec::ground`]: tilt on theta_t and eta_t,
/// floor translation along x and y that partly moves with the tilt, every witness noisy, the
/// pendulum with h = 1.4 m against Table I's 2.0, fitted with `--fit length.h_m`):
///
/// * read as displacement (m) and declared free of tilt (`--corrected`), every estimate (four
///   gains, the delay, h) within the Bonferroni-corrected 3-sigma point of the truth, and the
///   cleaned record never worse than the raw one in any band;
/// * the same seismometers read as inertial accelerometers (`m/s^2`, the default sensor:
///   `a_x + g eta_t`, `a_y - g theta_t`, with the tiltmeter's record as the tilt they sense),
///   integrated and corrected by the command line: the same estimates. The two records differ
///   only in their DC and Nyquist bins, which the fit band (from the third Welch bin to 0.8 of
///   Nyquist) leaves out, so the estimates agree to the fit's own convergence, a millionth of
///   their sigmas.
#[test]
fn translation_witnesses_from_the_command_line() {
    let spec = Spec::ground();
    let rec = make(&spec);
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let n = spec.n;
    write_measured(
        Path::new(&p("measured.h5")),
        &rec,
        spec.fs_hz,
        0..n,
        Some("2024-03-01T00:00:00Z"),
    );
    let names = ["theta_t", "eta_t", "x_t", "y_t"];
    let mut noise_args = Vec::new();
    let levels = spec
        .witness_noise
        .iter()
        .map(|&w| (w, spec.witness_noise_rise))
        .chain(
            spec.translations
                .iter()
                .map(|t| (t.witness_noise, t.witness_noise_rise)),
        );
    // Each witness's noise ASD as a file, 100 points per decade from 1e-7 Hz to Nyquist (as
    // `Spec::witness_noise_levels` gives it to the library).
    for (input, (white, rise)) in spec.witness_inputs().iter().zip(levels) {
        let file = p(&format!("{}_noise.csv", input.name()));
        let mut csv = String::from("frequency_hz,asd\n");
        let top = (spec.fs_hz / 2.0).log10();
        let points = ((top + 7.0) * 100.0).ceil() as usize;
        for i in 0..=points {
            let f = if i == points {
                spec.fs_hz / 2.0
            } else {
                10f64.powf(-7.0 + (top + 7.0) * i as f64 / points as f64)
            };
            let asd = rise.map_or(white, |r| r.asd(white, f));
            csv.push_str(&format!("{f:e},{asd:e}\n"));
        }
        std::fs::write(&file, csv).unwrap();
        noise_args.push(format!("{}={file}", input.name()));
    }
    let run = |witness: &str, extra: &[&str]| -> (serde_json::Value, String) {
        let mut args = vec![
            "subtract".to_string(),
            "--tilt".into(),
            witness.into(),
            "--measured".into(),
            p("measured.h5"),
            "--fit".into(),
            "length.h_m".into(),
            "--format".into(),
            "json".into(),
            "--save".into(),
            p("cleaned.h5"),
        ];
        for a in &noise_args {
            args.extend(["--witness-noise".to_string(), a.clone()]);
        }
        args.extend(extra.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = tiltnoise(&args);
        assert!(out.status.success(), "{args:?}: {}", common::stderr(&out));
        (
            serde_json::from_slice(&out.stdout).unwrap(),
            common::stderr(&out),
        )
    };
    let truth: Vec<(String, f64)> = spec
        .witness_inputs()
        .iter()
        .zip(spec.witness_gains())
        .map(|(i, g)| (format!("gain.{}", i.name()), g))
        .chain([
            ("delay_s".to_string(), spec.delay_s()),
            ("length.h_m".to_string(), spec.truth.length.h_m),
        ])
        .collect();
    let bound = tiltnoise_core::subtract::bands::corrected_z(truth.len());

    write_ground_csv(
        &p("ground_m.csv"),
        &names,
        &["rad", "rad", "m", "m"],
        &rec.witness(),
    );
    let (displacement, _) = run(&p("ground_m.csv"), &["--corrected", "x_t,y_t"]);
    for (name, t) in &truth {
        let e = estimate(&displacement, name);
        let (v, s) = (e["value"].as_f64().unwrap(), e["sigma"].as_f64().unwrap());
        eprintln!(
            "{name}: {v} +/- {s:.2e} (true {t}, pull {:+.2})",
            (v - t) / s
        );
        assert_eq!(e["status"], "fitted", "{name}: {e}");
        assert!((v - t).abs() < bound * s, "{name}: {v} +/- {s} vs {t}");
    }
    for b in displacement["bands"].as_array().unwrap() {
        for band in b["bands"].as_array().unwrap() {
            let allowed = if band["left_raw"] == true { 1e-6 } else { 0.0 };
            assert!(band["ratio"].as_f64().unwrap() <= 1.0 + allowed, "{band}");
        }
    }

    let g = spec.truth.environment.g_m_per_s2;
    let (theta, eta) = (&rec.tilt[0], &rec.tilt[1]);
    let inertial = |x: &[f64], tilt: &[f64], sign: f64| -> Vec<f64> {
        acceleration_of(x, spec.fs_hz)
            .iter()
            .zip(tilt)
            .map(|(a, t)| a + sign * g * t)
            .collect()
    };
    let accelerometers = vec![
        theta.clone(),
        eta.clone(),
        inertial(&rec.translation[0], eta, 1.0),
        inertial(&rec.translation[1], theta, -1.0),
    ];
    write_ground_csv(
        &p("ground_acc.csv"),
        &names,
        &["rad", "rad", "m/s^2", "m/s^2"],
        &accelerometers,
    );
    let (acceleration, notes) = run(&p("ground_acc.csv"), &[]);
    for needle in [
        "x_t, y_t: integrated to displacement",
        "the x_t channel is an inertial sensor",
        "the y_t channel is an inertial sensor",
    ] {
        assert!(
            notes.contains(needle),
            "no {needle:?} in the notes: {notes}"
        );
    }
    for (name, _) in &truth {
        let (a, b) = (estimate(&displacement, name), estimate(&acceleration, name));
        let (va, vb) = (a["value"].as_f64().unwrap(), b["value"].as_f64().unwrap());
        let s = a["sigma"].as_f64().unwrap();
        eprintln!(
            "{name}: from m {va}, from m/s^2 {vb}: {:.1e} sigma",
            (va - vb) / s
        );
        assert!(
            (va - vb).abs() < 1e-6 * s,
            "{name}: {va} vs {vb} (sigma {s})"
        );
    }
}

/// Bad input: one line naming the file, channel or key, exit code 2, nothing written.
#[test]
fn bad_input_is_refused_without_output() {
    let mut spec = Spec::verification();
    spec.n = 1 << 12;
    spec.oversample = 1;
    spec.delay_steps = 2;
    let rec = make(&spec);
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let n = spec.n;
    let t0 = Some("2024-03-01T00:00:00Z");
    write_tilt(Path::new(&p("tilt.h5")), &rec, 1.0, 0..n, t0);
    write_measured(Path::new(&p("m.h5")), &rec, 1.0, 0..n, t0);
    write_measured(
        Path::new(&p("late.h5")),
        &rec,
        1.0,
        0..n,
        Some("2024-03-02T00:00:00Z"),
    );
    write_measured(Path::new(&p("fast.h5")), &rec, 2.0, 0..n, t0);
    write_measured(Path::new(&p("nostart.h5")), &rec, 1.0, 0..n, None);
    let mut bad = Record {
        axes: rec.axes.clone(),
        tilt: rec.tilt.clone(),
        translation: Vec::new(),
        colocated: Vec::new(),
        measured: rec.measured.clone(),
    };
    bad.measured[0].1[5] = f64::NAN;
    write_measured(Path::new(&p("nan.h5")), &bad, 1.0, 0..n, t0);
    write_measured(
        Path::new(&p("badstart.h5")),
        &rec,
        1.0,
        0..n,
        Some("yesterday"),
    );
    // A CSV measured series states its start in a `# start_time:` line.
    let mut csv = String::from("# start_time: 2024-03-05T00:00:00Z\ntime_s,X\n");
    for (i, x) in rec.measured[0].1.iter().enumerate() {
        csv.push_str(&format!("{i},{x:e}\n"));
    }
    std::fs::write(p("late.csv"), csv).unwrap();
    // A witness noise spectrum that covers only 1-10 mHz of the record's band.
    std::fs::write(p("short.csv"), "frequency_hz,asd\n1e-3,1e-9\n1e-2,1e-9\n").unwrap();
    let save = out_dir.join("c.h5");
    let save = save.to_str().unwrap();
    let tilt = p("tilt.h5");
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (vec![p("late.h5")], vec!["late.h5", "do not overlap"]),
        (
            vec![p("late.csv")],
            vec!["late.csv", "do not overlap", "345600"],
        ),
        (
            vec![p("badstart.h5")],
            vec!["badstart.h5", "start_time", "yesterday"],
        ),
        (
            vec![p("fast.h5")],
            vec!["fast.h5", "2 Hz", "does not resample"],
        ),
        (vec![p("nostart.h5")], vec!["nostart.h5", "start time"]),
        (vec![p("nan.h5")], vec!["nan.h5", "X", "5"]),
        (
            vec![p("m.h5"), "--fit".into(), "length.hh_m".into()],
            vec!["length.hh_m", "unknown parameter key"],
        ),
        (
            vec![
                p("m.h5"),
                "--fit".into(),
                "environment.temperature_k".into(),
            ],
            vec!["environment.temperature_k", "not a free parameter"],
        ),
        (
            vec![p("m.h5"), "--fit".into(), "asymmetry.tm_com_x_m".into()],
            vec!["asymmetry.tm_com_x_m", "gives it none", "[uncertainty]"],
        ),
        (
            vec![p("m.h5"), "--nperseg".into(), "4096".into()],
            vec!["m.h5", "overlap for 4096 samples", "--nperseg"],
        ),
        (
            vec![p("m.h5"), "--observables".into(), "Z".into()],
            vec!["m.h5", "no channel Z", "X, Y, phi"],
        ),
        (
            vec![p("m.h5"), "--tilt-noise".into(), "eta_t=-1".into()],
            vec![
                "--witness-noise",
                "eta_t=-1",
                "must be 0 or a value from 1e-40 to 1e40",
            ],
        ),
        (
            vec![
                p("m.h5"),
                "--witness-noise".into(),
                "eta_t=1e-9".into(),
                "--witness-noise".into(),
                "eta_t=2e-9".into(),
            ],
            vec!["--witness-noise: eta_t is given twice; name each input once"],
        ),
        (
            vec![p("m.h5"), "--witness-noise".into(), "F_b.x=1e-9".into()],
            vec![
                "--witness-noise F_b.x=1e-9",
                "not a floor input",
                "theta_t, eta_t, phi_t (rad), x_t, y_t, z_t (m)",
            ],
        ),
        (
            vec![p("m.h5"), "--witness-noise".into(), "x_t=1e-9".into()],
            vec![
                "--witness-noise x_t",
                "the witness record has no input x_t",
                "theta_t, eta_t",
            ],
        ),
        (
            vec![p("m.h5"), "--witness-noise".into(), "eta_t=1e-9:1.5".into()],
            vec![
                "--witness-noise",
                "eta_t=1e-9:1.5",
                "relative uncertainty 1.5",
            ],
        ),
        (
            vec![
                p("m.h5"),
                "--witness-noise".into(),
                format!("eta_t={}", p("short.csv")),
            ],
            vec!["short.csv", "never extrapolated"],
        ),
        (
            vec![p("m.h5"), "--colocated-ratio".into(), "eta_t=2".into()],
            vec!["--colocated-ratio", "exactly one --colocated"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args: Vec<&str> = vec!["subtract", "--tilt", &tilt, "--measured", &extra[0]];
        args.extend(extra[1..].iter().map(String::as_str));
        args.extend(["--save", save]);
        assert_fails_without_output(&args, &out_dir, &needles);
    }
    let m = p("m.h5");
    // Tilt spectra are not a record to subtract; an unknown output kind is refused first.
    let spectra = common::repo("tilt_data/peterson_tilt_asd.csv");
    assert_fails_without_output(
        &[
            "subtract",
            "--tilt",
            spectra.to_str().unwrap(),
            "--measured",
            &m,
            "--save",
            save,
        ],
        &out_dir,
        &["peterson_tilt_asd.csv", "spectra", "time series"],
    );
    let txt = out_dir.join("c.txt");
    assert_fails_without_output(
        &[
            "subtract",
            "--tilt",
            &tilt,
            "--measured",
            &m,
            "--save",
            txt.to_str().unwrap(),
        ],
        &out_dir,
        &["c.txt", ".h5, .hdf5, .json, .png, .svg"],
    );
}

/// `simulate --tilt` makes the pendulum record from a tilt record (here the synthetic one,
/// without its pendulum), through a tiltmeter with gains 0.95 and 1.04 and 1.5 s of delay;
/// `subtract` finds them within 3 sigma. The driven run's own refusals name the option.
#[test]
fn simulate_tilt_then_subtract() {
    let mut spec = Spec::verification();
    spec.n = 1 << 13;
    spec.oversample = 1;
    spec.delay_steps = 0;
    let rec = make(&spec);
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    write_tilt(
        Path::new(&p("tilt.h5")),
        &rec,
        1.0,
        0..spec.n,
        Some("2024-03-01T00:00:00Z"),
    );
    let (tilt, pend) = (p("tilt.h5"), p("pend.h5"));
    let out = tiltnoise(&[
        "simulate",
        "--tilt",
        &tilt,
        "--oversample",
        "50",
        "--drive-gain",
        "theta_t=0.95,eta_t=1.04",
        "--drive-delay",
        "1.5",
        "--readout",
        "X=1e-9",
        "--readout",
        "Y=1e-9",
        "--save",
        &pend,
    ]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let f = hdf5::File::open(&pend).unwrap();
    assert_eq!(common::str_attr(&f, "start_time"), "2024-03-01T00:00:00Z");
    let report = run_json(&[
        "subtract",
        "--tilt",
        &tilt,
        "--measured",
        &pend,
        "--observables",
        "X,Y",
        "--format",
        "json",
    ]);
    assert_eq!(report["alignment"]["samples"], spec.n);
    for (name, truth) in [
        ("gain.theta_t", 0.95),
        ("gain.eta_t", 1.04),
        ("delay_s", 1.5),
    ] {
        let e = estimate(&report, name);
        let (value, sigma) = (e["value"].as_f64().unwrap(), e["sigma"].as_f64().unwrap());
        eprintln!("{name}: true {truth}, estimated {value} +/- {sigma:.2e}");
        assert!(
            (value - truth).abs() < 3.0 * sigma,
            "{name}: {value} +/- {sigma}"
        );
    }
    let out_dir = dir.path().join("out");
    std::fs::create_dir(&out_dir).unwrap();
    let save = out_dir.join("s.h5");
    let save = save.to_str().unwrap();
    let base = ["simulate", "--tilt", &tilt, "--save", save];
    for (extra, needles) in [
        (
            vec!["--drive-delay", "0.03"],
            vec!["--drive-delay 0.03 s", "0.1 s"],
        ),
        (
            vec!["--drive-gain", "phi_t=2"],
            vec!["--drive-gain phi_t=2", "theta_t, eta_t"],
        ),
        (vec!["--oversample", "0"], vec!["oversampling factor 0"]),
        (vec!["--duration", "100"], vec!["--duration", "--tilt"]),
    ] {
        let mut args = base.to_vec();
        args.extend(extra);
        assert_fails_without_output(&args, &out_dir, &needles);
    }
}
