//! Rendering tests on the Table I model. Set `TILTNOISE_PLOT_PREVIEW=<dir>` to also keep the
//! rendered figures in `<dir>` for visual inspection.

use super::chart::{Band, Dash, LegendPlacement, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
use super::*;
use tiltnoise_core::error::{OutputError, TfError};
use tiltnoise_core::model::Model;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{evaluate, plan, Method, Request, TransferMatrix};

/// Table I, all tilt inputs, `n` log-spaced frequencies in `[lo, hi]`; a frequency that hits an
/// undamped resonance exactly is nudged by 1e-9 relative.
fn table_i_matrix(n: usize, lo: f64, hi: f64) -> TransferMatrix {
    let model = Model::new(&Params::table_i()).unwrap();
    let tf = plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
    let mut freqs = Vec::with_capacity(n);
    for k in 0..n {
        let mut f = lo * (hi / lo).powf(k as f64 / (n - 1) as f64);
        let mut tries = 0;
        while let Err(TfError::Singular { .. }) = tf.eval(f) {
            f *= 1.0 + 1e-9;
            tries += 1;
            assert!(tries < 100, "cannot step off the resonance at {f} Hz");
        }
        freqs.push(f);
    }
    evaluate(&*tf, &freqs).unwrap()
}

fn preview_dir() -> Option<std::path::PathBuf> {
    let dir = std::path::PathBuf::from(std::env::var_os("TILTNOISE_PLOT_PREVIEW")?);
    std::fs::create_dir_all(&dir).ok()?;
    Some(dir)
}

fn leftovers(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".tiltnoise-plot-"))
        .collect()
}

#[test]
fn tf_figure_png_and_svg() {
    let tf = table_i_matrix(800, 1e-4, 30.0);
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("fig5.png");
    let svg = dir.path().join("fig5.svg");
    let options = TfFigureOptions {
        note: Some("undamped, Table I parameters".to_string()),
        ..TfFigureOptions::default()
    };
    tf_figure_with(&tf, &png, &options).unwrap();
    tf_figure_with(&tf, &svg, &options).unwrap();

    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.len() > 20_000, "PNG only {} bytes", bytes.len());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // IHDR: width and height.
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (1200, 1000));

    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.len() > 20_000, "SVG only {} bytes", text.len());
    assert!(text.starts_with("<svg"), "{}", &text[..40]);
    assert!(text.contains("frequency (Hz)"));
    assert!(text.contains("|X / tilt| (m/rad)"));
    assert!(text.contains("|φ / tilt| (rad/rad)"));
    assert!(text.contains("θₜ: identically 0"));
    assert!(text.contains("10⁻⁴"));
    assert!(text.trim_end().ends_with("</svg>"));
    assert!(leftovers(dir.path()).is_empty());

    if let Some(out) = preview_dir() {
        tf_figure_with(&tf, &out.join("tf_figure5.png"), &options).unwrap();
        tf_figure_with(&tf, &out.join("tf_figure5.svg"), &options).unwrap();
    }
}

#[test]
fn default_tf_figure_writes_png() {
    let tf = table_i_matrix(60, 1e-4, 30.0);
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("F.PNG");
    tf_figure(&tf, &png).unwrap();
    assert!(std::fs::metadata(&png).unwrap().len() > 10_000);
}

#[test]
fn missing_directory_is_an_error_and_leaves_nothing() {
    let tf = table_i_matrix(20, 1e-3, 10.0);
    let dir = tempfile::tempdir().unwrap();
    for name in ["fig.png", "fig.svg"] {
        let path = dir.path().join("no-such-dir").join(name);
        let err = tf_figure(&tf, &path).unwrap_err();
        match &err {
            OutputError::Write { path: p, .. } => assert_eq!(p, &path),
            other => panic!("unexpected error {other:?}"),
        }
        assert!(err.to_string().contains("no-such-dir"), "{err}");
        assert!(!path.exists());
    }
    assert!(!dir.path().join("no-such-dir").exists());
}

#[test]
fn unknown_extension_is_rejected() {
    let tf = table_i_matrix(20, 1e-3, 10.0);
    let dir = tempfile::tempdir().unwrap();
    for name in ["fig.pdf", "fig"] {
        let path = dir.path().join(name);
        let err = tf_figure(&tf, &path).unwrap_err();
        assert!(matches!(err, OutputError::UnknownFormat { .. }), "{err:?}");
        assert!(!path.exists());
    }
    assert_eq!(
        ImageFormat::from_path(Path::new("a.Svg")).unwrap(),
        ImageFormat::Svg
    );
}

#[test]
fn drawing_error_leaves_existing_target_untouched() {
    struct Failing;
    impl Figure for Failing {
        fn size(&self) -> (u32, u32) {
            (100, 100)
        }
        fn draw<DB: DrawingBackend>(&self, _: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
            Err(DrawError("deliberate".to_string()))
        }
    }
    let dir = tempfile::tempdir().unwrap();
    for name in ["old.png", "old.svg"] {
        let path = dir.path().join(name);
        std::fs::write(&path, b"previous").unwrap();
        let err = save_figure(&path, &Failing).unwrap_err();
        assert!(err.to_string().contains("deliberate"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), b"previous");
    }
    assert!(leftovers(dir.path()).is_empty());
}

#[test]
fn overwrite_replaces_target() {
    let tf = table_i_matrix(20, 1e-3, 10.0);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("fig.svg");
    std::fs::write(&path, b"previous").unwrap();
    tf_figure(&tf, &path).unwrap();
    assert!(std::fs::read_to_string(&path).unwrap().starts_with("<svg"));
    assert!(leftovers(dir.path()).is_empty());
}

/// The chart helper with a noise-budget-like content: a band, a thick total, zeros and NaNs.
#[test]
fn budget_like_chart_with_band() {
    let f: Vec<f64> = (0..400)
        .map(|k| 1e-4 * 10f64.powf(k as f64 / 80.0))
        .collect();
    let asd =
        |a: f64, p: f64| -> Vec<(f64, f64)> { f.iter().map(|&x| (x, a * x.powf(p))).collect() };
    let a = asd(1e-12, -1.0);
    let b = asd(3e-11, 0.0);
    let total: Vec<(f64, f64)> = a
        .iter()
        .zip(&b)
        .map(|(p, q)| (p.0, p.1.hypot(q.1)))
        .collect();
    let mut c = asd(1e-9, 1.0);
    c[100].1 = f64::NAN;
    c[200].1 = 0.0;
    let mut panel = Panel::new("X noise budget", ("frequency", "Hz"), ("ASD of X", "m/√Hz"));
    panel.band = Some(Band::new(
        "tilt, 5-95 %",
        a.iter().map(|p| (p.0, p.1 * 0.3)).collect(),
        a.iter().map(|p| (p.0, p.1 * 3.0)).collect(),
        PALETTE[0],
    ));
    panel.traces = vec![
        Trace::new("tilt", a, TraceStyle::new(PALETTE[0], Dash::Solid, 2)),
        Trace::new("readout", b, TraceStyle::new(PALETTE[1], Dash::Dashed, 2)),
        Trace::new("other", c, TraceStyle::new(PALETTE[2], Dash::Dotted, 3)),
        Trace::new("total", total, TraceStyle::new(PALETTE[6], Dash::Solid, 4)),
    ];
    panel.notes.push("thermal: identically 0".to_string());
    let fig = LogLogFigure {
        size: (1000, 700),
        title: None,
        panels: vec![panel],
        columns: 1,
        caption: vec!["A caption strip under a single panel.".to_string()],
    };
    let dir = tempfile::tempdir().unwrap();
    for name in ["budget.png", "budget.svg"] {
        let path = dir.path().join(name);
        save_figure(&path, &fig).unwrap();
        assert!(std::fs::metadata(&path).unwrap().len() > 10_000);
        if let Some(out) = preview_dir() {
            save_figure(&out.join(name), &fig).unwrap();
        }
    }
}

/// Many curves: `LegendPlacement::Auto` finds the free spot, `OutsideRight` narrows the frame.
#[test]
fn crowded_panel_legend() {
    let f: Vec<f64> = (0..300)
        .map(|k| 1e-3 * 10f64.powf(k as f64 / 100.0))
        .collect();
    let mut panel = Panel::new("crowded", ("frequency", "Hz"), ("ASD", "rad/√Hz"));
    for (i, p) in [-2.0, -1.0, 0.0, 1.0, 2.0, 0.5, -0.5]
        .into_iter()
        .enumerate()
    {
        let dash = [Dash::Solid, Dash::Dashed, Dash::Dotted][i % 3];
        let pts = f.iter().map(|&x| (x, 1e-9 * (x / 0.03).powf(p))).collect();
        panel.traces.push(Trace::new(
            format!("term {i}: slope {p}"),
            pts,
            TraceStyle::new(PALETTE[i % PALETTE.len()], dash, 2),
        ));
    }
    let mut outside = panel.clone();
    outside.title = "explicitly outside".to_string();
    outside.legend = LegendPlacement::OutsideRight;
    let fig = LogLogFigure {
        size: (1100, 1000),
        title: Some("Legend placement".to_string()),
        panels: vec![panel, outside],
        columns: 1,
        caption: Vec::new(),
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("crowded.svg");
    save_figure(&path, &fig).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.contains("term 6: slope -0.5"));
    if let Some(out) = preview_dir() {
        save_figure(&out.join("crowded.png"), &fig).unwrap();
    }
}
