//! Noise-budget outputs: HDF5 and CSV read back bit for bit with the documented layout, figures
//! are written, failures leave nothing behind. A realistic Table I budget is rendered too; set
//! `TILTNOISE_PLOT_PREVIEW=<dir>` to keep its files (budget.png, .svg, .h5, .csv) in `<dir>`.

use crate::common;

use common::{listing, str_attr, strs_attr};
use num_complex::Complex64;
use std::path::PathBuf;
use tiltnoise_core::error::{OutputError, TfError};
use tiltnoise_core::model::{ForceInput, Model, Observable, TiltAxis};
use tiltnoise_core::noise::{
    add_measured, ground_budget, Budget, BudgetReport, Calibration, GroundCsd, NoiseTerm,
    ObservableBudget, Readout, SegmentBand, SpectralSource, TermKind,
};
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{evaluate, plan, Input, Method, Request, TransferFunction};
use tiltnoise_io::{
    budget_csv_string, write_budget_hdf5, InputMeta, RunMeta, Staging, SCHEMA_BUDGET,
    SCHEMA_VERSION_BUDGET, TOOL_VERSION,
};
use tiltnoise_job::budget::{BudgetOutcome, SaveOptions};
use tiltnoise_job::{save_image, JobError};
use tiltnoise_plot::budget_figure;

fn term(name: &str, psd: Vec<f64>) -> NoiseTerm {
    NoiseTerm {
        kind: TermKind::from_name(name).unwrap(),
        psd,
    }
}

/// A hand-made report: 5 frequencies, X (with readout) and phi, hourly segment bands at the
/// 10th and 90th percentile, values that are not exact squares (sqrt is inexact).
fn synthetic_report() -> BudgetReport {
    let freqs = vec![1e-4, 3.3e-4, 1e-3, 0.0123, 0.5];
    let x_tilt: Vec<f64> = freqs.iter().map(|f| 2.7e-15 * (1e-3 / f)).collect();
    let readout = 9e-9_f64 * 9e-9;
    let phi_tilt: Vec<f64> = freqs.iter().map(|f| 1.3e-17 * f * f + 1e-300).collect();
    // The total (tilt + readout in power) is computed by the budget, not given.
    let x = ObservableBudget::new(
        Observable::X,
        vec![
            term("tilt", x_tilt.clone()),
            term("tilt.theta_t", vec![0.0; 5]),
            term("tilt.eta_t", x_tilt.clone()),
            term("readout", vec![readout; 5]),
        ],
    );
    let phi = ObservableBudget::new(
        Observable::Phi,
        vec![
            term("tilt", phi_tilt.clone()),
            term("tilt.theta_t", vec![0.0; 5]),
            term("tilt.eta_t", phi_tilt.clone()),
        ],
    );
    let band = |psd: &[f64]| SegmentBand {
        term: TermKind::Tilt,
        lower_pct: 10.0,
        upper_pct: 90.0,
        median: psd.iter().map(|p| p * 0.9).collect(),
        lower: psd.iter().map(|p| p * 0.31).collect(),
        upper: psd.iter().map(|p| p * 3.7).collect(),
        n_segments: 24,
    };
    BudgetReport {
        budget: Budget {
            freqs_hz: freqs,
            observables: vec![x, phi],
        },
        segment_bands: vec![
            (Observable::X, band(&x_tilt)),
            (Observable::Phi, band(&phi_tilt)),
        ],
        segment_duration_s: Some(3600.0),
        source: SpectralSource::Welch {
            sample_rate_hz: 10.0,
            segment_len: 16384,
            overlap: 8192,
            averaging: "mean".to_string(),
            n_welch_segments: 104,
            n_samples: 864_000,
        },
        inputs: vec![Input::Tilt(TiltAxis::ThetaT), Input::Tilt(TiltAxis::EtaT)],
        readout: Readout::default(),
        user_terms: Vec::new(),
        notes: vec!["the last 12 samples do not fill a segment".to_string()],
        summary: Vec::new(),
    }
}

fn meta() -> RunMeta {
    RunMeta {
        tool_version: TOOL_VERSION.to_string(),
        params_toml: Params::table_i().to_toml(),
        command_line: "tiltnoise budget tilt.h5 --segment 1h --save b.h5".to_string(),
        modes: vec![],
    }
}

fn input_meta() -> InputMeta {
    InputMeta {
        path: "data/romy_tilt_2024-05-01.h5".to_string(),
        format: "hdf5".to_string(),
        kind: "series".to_string(),
        quantity: "angle".to_string(),
        axis_map: "theta_t=-LJE,eta_t=-LJN".to_string(),
        start_time: Some("2024-05-01T00:00:00Z".to_string()),
        notes: vec!["quantity: angle (from the file's units `rad`)".to_string()],
    }
}

fn f64_attr(loc: &hdf5::Location, name: &str) -> f64 {
    loc.attr(name)
        .unwrap_or_else(|e| panic!("attribute {name}: {e}"))
        .read_scalar::<f64>()
        .unwrap()
}

fn i64_attr(loc: &hdf5::Location, name: &str) -> i64 {
    loc.attr(name)
        .unwrap_or_else(|e| panic!("attribute {name}: {e}"))
        .read_scalar::<i64>()
        .unwrap()
}

fn assert_bits(got: &[f64], want: &[f64], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (k, (a, b)) in got.iter().zip(want).enumerate() {
        assert_eq!(a.to_bits(), b.to_bits(), "{what}[{k}]: {a:e} != {b:e}");
    }
}

fn sqrt_all(v: &[f64]) -> Vec<f64> {
    v.iter().map(|p| p.sqrt()).collect()
}

/// A dataset and its `units` attribute.
fn read(group: &hdf5::Group, name: &str) -> (Vec<f64>, String) {
    let d = group
        .dataset(name)
        .unwrap_or_else(|e| panic!("dataset {name}: {e}"));
    (d.read_raw::<f64>().unwrap(), str_attr(&d, "unit"))
}

/// Saves `report` to `path` as the budget outcome does, with the test's provenance and input
/// and every CSV column kept, as one of the outputs of `stage`.
fn save_budget(
    stage: &Staging,
    path: &std::path::Path,
    report: &BudgetReport,
) -> Result<(), OutputError> {
    let outcome = BudgetOutcome::new(report.clone(), input_meta(), meta());
    let options = SaveOptions {
        keep_zero_columns: true,
        ..SaveOptions::default()
    };
    outcome
        .save_with(stage, path, &options)
        .map_err(|e| match e {
            JobError::Output(e) => *e,
            other => panic!("saving a budget: {other}"),
        })
}

/// Saves `report` to `path` alone, with the test's provenance and input, committed at once.
fn save_one(path: &std::path::Path, report: &BudgetReport) -> Result<(), OutputError> {
    Staging::committed(|s| save_budget(s, path, report))
}

#[test]
fn hdf5_round_trip_is_bit_exact_and_self_describing() {
    let report = synthetic_report();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("budget.h5");
    save_one(&path, &report).unwrap();
    assert_eq!(listing(dir.path()), vec![path.clone()], "no temporary file");

    let file = hdf5::File::open(&path).unwrap();
    assert_eq!(str_attr(&file, "schema"), SCHEMA_BUDGET);
    assert_eq!(SCHEMA_BUDGET, "tiltnoise.budget");
    assert_eq!(i64_attr(&file, "schema_version"), SCHEMA_VERSION_BUDGET);
    assert_eq!(str_attr(&file, "tool_version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(str_attr(&file, "created_by"), meta().command_line);
    assert_eq!(
        Params::from_toml_str(&str_attr(&file, "parameters_toml"), "file").unwrap(),
        Params::table_i()
    );
    assert!(str_attr(&file, "sign_convention").starts_with("tilt t = small right-handed"));
    assert_eq!(
        str_attr(&file, "spectral_convention"),
        "one-sided; PSD in unit^2/Hz, ASD = sqrt(PSD) in unit/sqrt(Hz)"
    );
    let input = input_meta();
    assert_eq!(str_attr(&file, "input_path"), input.path);
    assert_eq!(str_attr(&file, "input_format"), "hdf5");
    assert_eq!(str_attr(&file, "input_kind"), "series");
    assert_eq!(str_attr(&file, "input_quantity"), "angle");
    assert_eq!(str_attr(&file, "input_axis_map"), input.axis_map);
    assert_eq!(str_attr(&file, "input_start_time"), "2024-05-01T00:00:00Z");
    assert_eq!(
        strs_attr(&file, "notes"),
        vec![input.notes[0].clone(), report.notes[0].clone()]
    );
    assert_eq!(str_attr(&file, "source"), "welch");
    assert_eq!(f64_attr(&file, "sample_rate_hz"), 10.0);
    assert_eq!(i64_attr(&file, "welch_segment_len"), 16384);
    assert_eq!(i64_attr(&file, "welch_overlap"), 8192);
    assert_eq!(str_attr(&file, "welch_averaging"), "mean");
    assert_eq!(i64_attr(&file, "welch_n_segments"), 104);
    assert_eq!(i64_attr(&file, "n_samples"), 864_000);
    assert_eq!(strs_attr(&file, "tilt_axes"), vec!["theta_t", "eta_t"]);
    assert_eq!(strs_attr(&file, "observables"), vec!["X", "phi"]);

    let root = file.as_group().unwrap();
    let (freqs, unit) = read(&root, "frequency_hz");
    assert_eq!(unit, "Hz");
    assert_bits(&freqs, &report.budget.freqs_hz, "frequency_hz");

    for ob in &report.budget.observables {
        let o = ob.observable.name();
        let u = ob.observable.unit();
        let g = file.group(o).unwrap();
        assert_eq!(str_attr(&g, "unit"), u);
        let components = ob.components();
        let names: Vec<String> = components.iter().map(|(c, _)| c.name()).collect();
        assert_eq!(strs_attr(&g, "terms"), names);
        for (c, t_psd) in &components {
            let name = c.name();
            let tg = g.group(&name).unwrap();
            let (psd, pu) = read(&tg, "psd");
            let (asd, au) = read(&tg, "asd");
            assert_bits(&psd, t_psd, &format!("{o}/{name}/psd"));
            assert_bits(&asd, &sqrt_all(t_psd), &format!("{o}/{name}/asd"));
            if let Some(t) = ob.term_named(&name) {
                assert_bits(&asd, &t.asd(), "NoiseTerm::asd");
            }
            assert_eq!(pu, format!("{u}^2/Hz"));
            assert_eq!(au, format!("{u}/sqrt(Hz)"));
        }
        // The path with a dot in the term name works directly too.
        assert!(file.dataset(&format!("{o}/tilt.eta_t/asd")).is_ok());
    }
    let x = file.group("X").unwrap();
    assert_eq!(f64_attr(&x, "readout_asd"), 9e-9);
    assert_eq!(str_attr(&x, "readout_asd_unit"), "m/sqrt(Hz)");
    assert!(file.group("phi").unwrap().attr("readout_asd").is_err());

    let seg = file.group("segments").unwrap();
    assert_eq!(f64_attr(&seg, "segment_duration_s"), 3600.0);
    assert_eq!(i64_attr(&seg, "n_segments"), 24);
    assert_eq!(f64_attr(&seg, "lower_pct"), 10.0);
    assert_eq!(f64_attr(&seg, "upper_pct"), 90.0);
    for (o, band) in &report.segment_bands {
        let g = seg.group(o.name()).unwrap();
        let u = o.unit();
        assert_eq!(str_attr(&g, "unit"), u);
        for (s, want) in [
            ("median", &band.median),
            ("lower", &band.lower),
            ("upper", &band.upper),
        ] {
            let (psd, pu) = read(&g, &format!("tilt_psd_{s}"));
            let (asd, au) = read(&g, &format!("tilt_asd_{s}"));
            assert_bits(&psd, want, s);
            assert_bits(&asd, &sqrt_all(want), s);
            assert_eq!((pu, au), (format!("{u}^2/Hz"), format!("{u}/sqrt(Hz)")));
        }
    }
}

#[test]
fn hdf5_for_spectra_input_without_segments() {
    let mut report = synthetic_report();
    report.segment_bands.clear();
    report.segment_duration_s = None;
    report.source = SpectralSource::Spectra {
        data_band_hz: (1e-4, 0.5),
    };
    let mut input = input_meta();
    input.start_time = None;
    input.notes.clear();
    report.notes.clear();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.hdf5");
    tiltnoise_io::Staging::committed(|s| write_budget_hdf5(s, &path, &report, &meta(), &input))
        .unwrap();
    let file = hdf5::File::open(&path).unwrap();
    assert_eq!(str_attr(&file, "source"), "spectra");
    let band = file.attr("data_band_hz").unwrap().read_1d::<f64>().unwrap();
    assert_eq!(band.to_vec(), vec![1e-4, 0.5]);
    assert!(file.attr("welch_segment_len").is_err());
    assert!(file.attr("input_start_time").is_err());
    assert!(strs_attr(&file, "notes").is_empty());
    assert!(file.group("segments").is_err());
}

#[test]
fn csv_header_and_values_round_trip() {
    let report = synthetic_report();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("budget.csv");
    save_one(&path, &report).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text, budget_csv_string(&report, &meta(), true).unwrap());
    let mut lines = text.lines().skip_while(|l| l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header,
        vec![
            "frequency_hz",
            "X.tilt",
            "X.tilt.theta_t",
            "X.tilt.eta_t",
            "X.readout",
            "X.total",
            "phi.tilt",
            "phi.tilt.theta_t",
            "phi.tilt.eta_t",
            "phi.total",
            "X.tilt.median",
            "X.tilt.p10",
            "X.tilt.p90",
            "phi.tilt.median",
            "phi.tilt.p10",
            "phi.tilt.p90",
        ]
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), report.budget.freqs_hz.len());
    let column = |c: usize| rows.iter().map(|r| r[c]).collect::<Vec<f64>>();
    assert_bits(&column(0), &report.budget.freqs_hz, "freq_hz");
    let mut c = 1;
    for ob in &report.budget.observables {
        for (_, psd) in ob.components() {
            assert_bits(&column(c), &sqrt_all(&psd), header[c]);
            c += 1;
        }
    }
    for (_, band) in &report.segment_bands {
        for v in [&band.median, &band.lower, &band.upper] {
            assert_bits(&column(c), &sqrt_all(v), header[c]);
            c += 1;
        }
    }
    assert_eq!(c, header.len());
}

/// With the response to the equivalent input in the budget (damped models), the CSV ends with
/// `OBS.equivalent.TERM` columns: `sqrt(S_o / |R_o|^2)` for every noise term but `measured`
/// and `residual`, and for the total, bit for bit, after the columns of the undamped layout
/// (which keep their places); the calibration's response itself is no column.
#[test]
fn csv_equivalent_columns_follow_the_bands() {
    let plain = synthetic_report();
    let mut report = synthetic_report();
    let n = report.budget.freqs_hz.len();
    let response: Vec<f64> = (0..n).map(|k| 1e-6 * (k as f64 + 1.5)).collect();
    let x = &mut report.budget.observables[0];
    x.terms.push(term("measured", vec![1e-16; n]));
    x.calibration = Some(Calibration {
        input: ForceInput::from_name("F_b.x").unwrap(),
        response_psd: response.clone(),
    });
    let text = budget_csv_string(&report, &meta(), true).unwrap();
    let plain_header = budget_csv_string(&plain, &meta(), true)
        .unwrap()
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .to_string();
    let header: Vec<String> = text
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    // The undamped columns, `X.measured` among the terms, then the referred ones.
    let expected_front: Vec<String> = plain_header
        .split(',')
        .flat_map(|c| {
            if c == "X.total" {
                vec!["X.measured".to_string(), c.to_string()]
            } else {
                vec![c.to_string()]
            }
        })
        .collect();
    assert_eq!(header[..expected_front.len()], expected_front[..]);
    let referred: Vec<&str> = header[expected_front.len()..]
        .iter()
        .map(String::as_str)
        .collect();
    assert_eq!(
        referred,
        [
            "X.equivalent.tilt",
            "X.equivalent.tilt.theta_t",
            "X.equivalent.tilt.eta_t",
            "X.equivalent.readout",
            "X.equivalent.total"
        ]
    );
    let rows: Vec<Vec<f64>> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    for (c, name) in header.iter().enumerate().skip(expected_front.len()) {
        let term = name.trim_start_matches("X.equivalent.");
        let x = &report.budget.observables[0];
        let psd = &match x.term_named(term) {
            Some(t) => t.psd.clone(),
            None => x.total(),
        };
        let want: Vec<f64> = psd
            .iter()
            .zip(&response)
            .map(|(p, r)| (p / r).sqrt())
            .collect();
        let got: Vec<f64> = rows.iter().map(|r| r[c]).collect();
        assert_bits(&got, &want, name);
    }
}

#[test]
fn csv_percentile_names_follow_the_band() {
    let mut report = synthetic_report();
    for (_, b) in &mut report.segment_bands {
        b.lower_pct = 2.5;
        b.upper_pct = 97.5;
    }
    let text = budget_csv_string(&report, &meta(), true).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    assert!(
        header.ends_with("phi.tilt.median,phi.tilt.p2.5,phi.tilt.p97.5"),
        "{header}"
    );
}

#[test]
fn inconsistent_report_is_rejected_and_leaves_nothing() {
    let mut report = synthetic_report();
    report.budget.observables[1].terms[0].psd.pop();
    let dir = tempfile::tempdir().unwrap();
    for name in ["b.h5", "b.csv", "b.png", "b.svg"] {
        let path = dir.path().join(name);
        let err = save_one(&path, &report).unwrap_err();
        let text = err.to_string();
        assert!(text.contains("phi.tilt") && text.contains(name), "{text}");
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn figures_are_written() {
    let report = synthetic_report();
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("budget.png");
    let svg = dir.path().join("budget.svg");
    save_one(&png, &report).unwrap();
    save_one(&svg, &report).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    assert!(bytes.len() > 30_000, "PNG only {} bytes", bytes.len());
    let text = std::fs::read_to_string(&svg).unwrap();
    // Curves reduced to the pixel grid: more than the frame and text, less than the bound.
    assert!(
        (15_000..300_000).contains(&text.len()),
        "SVG of {} bytes",
        text.len()
    );
    for needle in [
        "ASD of X (m/√Hz)",
        "ASD of φ (rad/√Hz)",
        "total",
        "tilt, hourly 10–90 %",
        "tilt, hourly median",
        "readout, 9 nm/√Hz",
        "θₜ alone: identically 0",
        "romy_tilt_2024-05-01.h5",
        "one-sided",
    ] {
        assert!(text.contains(needle), "SVG lacks {needle:?}");
    }
    assert_eq!(listing(dir.path()), vec![png, svg]);
}

#[test]
fn missing_directory_is_an_error_naming_the_path() {
    let report = synthetic_report();
    let dir = tempfile::tempdir().unwrap();
    for name in ["b.h5", "b.hdf5", "b.csv", "b.png", "b.svg"] {
        let path = dir.path().join("no-such-dir").join(name);
        let err = save_one(&path, &report).unwrap_err();
        match &err {
            OutputError::Write { path: p, .. } => assert_eq!(p, &path),
            other => panic!("{name}: unexpected error {other:?}"),
        }
        assert!(
            err.to_string().contains(&path.display().to_string()),
            "{err}"
        );
        assert!(!path.exists());
    }
    assert!(listing(dir.path()).is_empty());
}

#[test]
fn unknown_extension_is_rejected_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("b.pdf");
    let err = save_one(&path, &synthetic_report()).unwrap_err();
    assert!(matches!(err, OutputError::UnknownFormat { .. }), "{err:?}");
    assert!(listing(dir.path()).is_empty());
}

/// A budget from the real pipeline pieces: Table I transfer functions on a log grid, a white-in-
/// angle-rate tilt (ASD 1e-8 (1e-3/f) rad/sqrt(Hz) on both axes, uncorrelated), the paper's
/// readout, and a fake hourly band at 0.5x and 2x the tilt PSD.
fn realistic_report() -> BudgetReport {
    let model = Model::new(&Params::table_i()).unwrap();
    let axes = [TiltAxis::ThetaT, TiltAxis::EtaT];
    let request = Request {
        outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
        inputs: axes.iter().map(|&a| Input::Tilt(a)).collect(),
    };
    let tf = plan(&model, &request, Method::Direct).unwrap();
    let n = 1500;
    let freqs: Vec<f64> = (0..n)
        .map(|k| {
            let mut f = 1e-4 * 1e4f64.powf(k as f64 / (n - 1) as f64);
            while let Err(TfError::Singular { .. }) = tf.eval(f) {
                f *= 1.0 + 1e-9;
            }
            f
        })
        .collect();
    let tf = evaluate(&*tf as &dyn TransferFunction, &freqs).unwrap();
    let mut csd = Vec::with_capacity(freqs.len() * 4);
    for &f in &freqs {
        let s = (1e-8 * 1e-3 / f).powi(2);
        csd.extend([s, 0.0, 0.0, s].map(Complex64::from));
    }
    let inputs: Vec<Input> = axes.iter().map(|&a| Input::Tilt(a)).collect();
    let budget = ground_budget(
        &tf,
        &GroundCsd {
            inputs: &inputs,
            csd: &csd,
        },
        &Readout::default(),
    );
    let segment_bands = budget
        .observables
        .iter()
        .map(|ob| {
            let tilt = &ob.term(&TermKind::Tilt).unwrap().psd;
            let scaled = |s: f64| tilt.iter().map(|p| p * s).collect();
            let band = SegmentBand {
                term: TermKind::Tilt,
                lower_pct: 10.0,
                upper_pct: 90.0,
                median: scaled(0.9),
                lower: scaled(0.5),
                upper: scaled(2.0),
                n_segments: 24,
            };
            (ob.observable, band)
        })
        .collect();
    BudgetReport {
        budget,
        segment_bands,
        segment_duration_s: Some(3600.0),
        source: SpectralSource::Welch {
            sample_rate_hz: 1.0,
            segment_len: 10000,
            overlap: 5000,
            averaging: "mean".to_string(),
            n_welch_segments: 16,
            n_samples: 86_400,
        },
        inputs,
        readout: Readout::default(),
        user_terms: Vec::new(),
        notes: vec![],
        summary: Vec::new(),
    }
}

fn preview_dir() -> Option<PathBuf> {
    let dir = PathBuf::from(std::env::var_os("TILTNOISE_PLOT_PREVIEW")?);
    std::fs::create_dir_all(&dir).ok()?;
    Some(dir)
}

#[test]
fn realistic_budget_renders() {
    let report = realistic_report();
    let mut measured = report.clone();
    let x_total = measured.budget.observable(Observable::X).unwrap().total();
    let f = measured.budget.freqs_hz.clone();
    // A measured X spectrum: the model total plus an unexplained 1/f^2 excess at low frequency.
    let m = x_total
        .iter()
        .zip(&f)
        .map(|(t, f)| t * 1.2 + (3e-8 * (1e-3 / f).powi(1)).powi(2))
        .collect();
    add_measured(&mut measured.budget, Observable::X, m);

    // Given spectra, no segments, no input named: the plain `budget_figure`.
    let mut spectra = report.clone();
    spectra.segment_bands.clear();
    spectra.segment_duration_s = None;
    spectra.source = SpectralSource::Spectra {
        data_band_hz: (5e-5, 2.0),
    };
    spectra.notes = vec!["output band restricted to the band the tilt data cover".to_string()];

    let dir = tempfile::tempdir().unwrap();
    let out = preview_dir();
    for ext in ["png", "svg"] {
        let name = format!("budget_spectra.{ext}");
        tiltnoise_io::Staging::committed(|s| {
            save_image(s, &dir.path().join(&name), |format| {
                budget_figure(&spectra, format)
            })
        })
        .unwrap();
        if let Some(out) = &out {
            tiltnoise_io::Staging::committed(|s| {
                save_image(s, &out.join(&name), |format| {
                    budget_figure(&spectra, format)
                })
            })
            .unwrap();
        }
    }
    let text = std::fs::read_to_string(dir.path().join("budget_spectra.svg")).unwrap();
    assert!(text.contains("output band restricted"));
    assert!(!text.contains("hourly"));
    for (stem, r) in [("budget", &report), ("budget_measured", &measured)] {
        for ext in ["png", "svg", "h5", "csv"] {
            let path = dir.path().join(format!("{stem}.{ext}"));
            Staging::committed(|s| save_budget(s, &path, r)).unwrap();
            assert!(std::fs::metadata(&path).unwrap().len() > 1000);
            if let Some(out) = &out {
                Staging::committed(|s| save_budget(s, &out.join(format!("{stem}.{ext}")), r))
                    .unwrap();
            }
        }
    }
}
