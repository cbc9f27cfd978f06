//! Rendering tests on the Table I model: the bytes [`render`] returns. Writing them to a file
//! (atomically, errors naming the file) is the caller's job and is tested with the command
//! line's output dispatch (`tests/it/figures.rs`). Set `TILTNOISE_PLOT_PREVIEW=<dir>` to also
//! keep the rendered figures in `<dir>` for visual inspection.

use super::chart::{Band, Dash, LegendPlacement, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
use super::*;
use tiltnoise_core::error::TfError;
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

/// Writes `bytes` as `<TILTNOISE_PLOT_PREVIEW>/<name>` when that variable is set.
fn preview(name: &str, bytes: &[u8]) {
    let Some(dir) = std::env::var_os("TILTNOISE_PLOT_PREVIEW") else {
        return;
    };
    let dir = std::path::PathBuf::from(dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join(name), bytes).unwrap();
}

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

#[test]
fn tf_figure_png_and_svg() {
    let tf = table_i_matrix(800, 1e-4, 30.0);
    let options = TfFigureOptions {
        note: Some("undamped, Table I parameters".to_string()),
        observables: Some(vec![
            tiltnoise_core::model::Observable::X,
            tiltnoise_core::model::Observable::Phi,
            tiltnoise_core::model::Observable::PhiA,
        ]),
        ..TfFigureOptions::default()
    };
    let bytes = tf_figure_with(&tf, ImageFormat::Png, &options).unwrap();
    let svg = tf_figure_with(&tf, ImageFormat::Svg, &options).unwrap();

    assert!(bytes.len() > 20_000, "PNG only {} bytes", bytes.len());
    assert_eq!(&bytes[..8], PNG_SIGNATURE);
    // IHDR: width and height.
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), (1200, 1000));

    let text = String::from_utf8(svg).unwrap();
    assert!(text.len() > 20_000, "SVG only {} bytes", text.len());
    assert!(text.starts_with("<svg"), "{}", &text[..40]);
    assert!(text.contains("frequency") && !text.contains("frequency (Hz)"));
    assert!(text.contains("1 mHz"));
    assert!(text.contains("|X / tilt| (m/rad)"));
    assert!(text.contains("|φ / tilt| (rad/rad)"));
    assert!(text.contains("θₜ: identically 0"));
    assert!(text.contains("100 µHz"));
    assert!(text.trim_end().ends_with("</svg>"));

    preview("tf_figure5.png", &bytes);
    preview("tf_figure5.svg", text.as_bytes());
}

#[test]
fn default_tf_figure_renders_png() {
    let tf = table_i_matrix(60, 1e-4, 30.0);
    let png = tf_figure(&tf, ImageFormat::Png).unwrap();
    assert_eq!(&png[..8], PNG_SIGNATURE);
    assert!(png.len() > 10_000);
}

#[test]
fn drawing_error_is_returned_in_every_format() {
    struct Failing;
    impl Figure for Failing {
        fn size(&self) -> (u32, u32) {
            (100, 100)
        }
        fn draw<DB: DrawingBackend>(
            &self,
            _: &DrawingArea<DB, Shift>,
            _: ImageFormat,
        ) -> Result<(), DrawError> {
            Err(DrawError("deliberate".to_string().into()))
        }
    }
    for format in [ImageFormat::Png, ImageFormat::Svg] {
        let err = render(format, &Failing).unwrap_err();
        assert!(err.to_string().contains("deliberate"), "{err}");
    }
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
        shared_legend: false,
    };
    for format in [ImageFormat::Png, ImageFormat::Svg] {
        let bytes = render(format, &fig).unwrap();
        assert!(bytes.len() > 10_000);
        preview(&format!("budget.{}", format.extension()), &bytes);
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
        shared_legend: false,
    };
    let svg = String::from_utf8(render(ImageFormat::Svg, &fig).unwrap()).unwrap();
    assert!(svg.contains("term 6: slope -0.5"));
    preview("crowded.png", &render(ImageFormat::Png, &fig).unwrap());
}

#[test]
fn subtract_figure_png_and_svg() {
    use crate::subtract_figure::{subtract_figure, ObservablePanel, SubtractFigureData};
    use tiltnoise_core::model::Observable;
    let freqs: Vec<f64> = (0..257).map(|k| k as f64 / 512.0).collect();
    let curve = |a: f64, p: f64| -> Vec<f64> {
        freqs
            .iter()
            .map(|&f| a * (f.max(1e-3) / 1e-2).powf(p) + 1e-9)
            .collect()
    };
    let panel = |o| ObservablePanel {
        observable: o,
        freqs_hz: freqs.clone(),
        measured: curve(1e-7, -1.0),
        predicted: curve(1e-7, -1.0),
        cleaned: curve(0.0, 0.0),
        wiener: curve(1e-10, 0.0),
        expected: curve(0.0, 0.0),
        witness_limited: curve(3e-10, 0.5),
        left_raw: vec![(0.2, 0.3)],
        readout: Some(1e-9),
    };
    let data = SubtractFigureData {
        panels: vec![
            panel(Observable::X),
            panel(Observable::Y),
            panel(Observable::Phi),
        ],
        band_hz: (3e-3, 3e-2),
        caption: vec!["Fit: gain.eta_t = 0.97 ± 1e-4.".into()],
    };
    let png = subtract_figure(&data, &View::default(), ImageFormat::Png).unwrap();
    assert_eq!(&png[..8], PNG_SIGNATURE);
    let (w, h) = (
        u32::from_be_bytes(png[16..20].try_into().unwrap()),
        u32::from_be_bytes(png[20..24].try_into().unwrap()),
    );
    assert_eq!((w, h), (1800, 120 + 620 * 2));
    preview("subtract.png", &png);
    let svg =
        String::from_utf8(subtract_figure(&data, &View::default(), ImageFormat::Svg).unwrap())
            .unwrap();
    for text in [
        "cleaned (model)",
        "coherence limit",
        "readout 1 nm/√Hz",
        "readout 1 nrad/√Hz",
        "witness-noise limit (model)",
        "left raw",
        "gain.eta_t",
    ] {
        assert!(svg.contains(text), "{text} missing from the SVG");
    }
    let mut bad = data.clone();
    bad.panels[0].cleaned.pop();
    let e = subtract_figure(&bad, &View::default(), ImageFormat::Png).unwrap_err();
    assert!(
        e.0.to_string().contains("cleaned ASD of X has 256 values"),
        "{}",
        e.0
    );
}

/// Dense noisy spectra with a Welch estimate's scatter (three panels of four curves of 20,000 points each, a budget with a long
/// Welch segment) make an SVG of bounded size: the curves are reduced to the pixel grid, so the
/// file grows with the figure's width, not with the data.
#[test]
fn svg_size_is_bounded_by_the_pixel_grid() {
    let n = 20_000;
    let mut rng = 0x2545_f491_4f6c_dd1d_u64;
    let mut noise = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        // The scatter of a Welch estimate with about 40 averages: +/- 15 %.
        0.85 + 0.3 * (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut panels = Vec::new();
    for p in 0..3 {
        let mut panel = Panel::new(format!("panel {p}"), ("frequency", "Hz"), ("ASD", "m/√Hz"));
        // Solid lines: plotters draws every dash of a dashed line as an element of its own, so
        // a dashed noisy curve costs more (the README budget, with one dashed curve a panel,
        // stays below the bound; see the figures test of the command line).
        for (t, dash) in [Dash::Solid; 4].into_iter().enumerate() {
            let pts = (1..=n)
                .map(|k| {
                    let f = k as f64 * 0.5 / n as f64;
                    (f, 1e-9 * (1.0 + t as f64) * noise())
                })
                .collect();
            panel.traces.push(Trace::new(
                format!("term {t}"),
                pts,
                TraceStyle::new(PALETTE[t], dash, 2),
            ));
        }
        panels.push(panel);
    }
    let mut fig = LogLogFigure::new((1400, 1100), None, panels, 2, vec!["caption".to_string()]);
    fig.shared_legend = true;
    let svg = render(ImageFormat::Svg, &fig).unwrap();
    assert!(svg.len() < 300_000, "SVG of {} bytes", svg.len());
    // The resolution scales the pixels, not the layout.
    let view = View {
        dpi: 200.0,
        ..View::default()
    };
    let png = render(ImageFormat::Png, &view.apply(fig)).unwrap();
    let w = u32::from_be_bytes(png[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(png[20..24].try_into().unwrap());
    assert_eq!((w, h), (2800, 2200));
}
