//! Noise-budget figure in the style of gravitational-wave noise budgets (pygwinc): one log-log
//! panel of amplitude spectral densities per observable, one curve per noise term, the total
//! thick and black, the spread of the floor's noise across segments as a shaded band.

use super::chart::{Band, Dash, LegendPlacement, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
use super::labels::{
    observable_symbol, observable_title, si_asd, significant, tilt_symbol, translation_symbol,
};
use super::{render, DrawError, ImageFormat, View};
use plotters::style::RGBColor;
use std::path::Path;
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::model::{Input, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::noise::equivalent::referred_terms;
use tiltnoise_core::noise::{
    BudgetReport, Component, Readout, SegmentBand, SpectralSource, TermKind, UserSource,
};

/// Options of [`budget_figure_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetFigureOptions {
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Appended to the figure title in parentheses.
    pub note: Option<String>,
    /// The tilt input, named in the caption.
    pub input: Option<InputMeta>,
    /// At most this many decades below the top of each panel's y axis (default 12). The
    /// range follows the curves where they contribute (see [`CONTRIBUTION_PSD_RATIO`]), so
    /// this only guards against pathological spans.
    pub max_decades: f64,
    /// Axis limits, size, resolution.
    pub view: View,
}

impl Default for BudgetFigureOptions {
    fn default() -> Self {
        BudgetFigureOptions {
            size: (1400, 1100),
            note: None,
            input: None,
            max_decades: 12.0,
            view: View::default(),
        }
    }
}

/// Draws the noise budget of `report` as a PNG or SVG file's bytes: one panel per observable
/// (in the report's order, e.g. X, φ, φₐ), ASD versus frequency, log-log. Terms: `total` thick
/// black, `tilt` and `translation` solid, `ground` (both with their cross-spectra) thicker,
/// `tilt.<axis>` and `translation.<axis>` (each axis alone) dashed (left out beside `ground`:
/// the files keep them), `readout` grey, `user` solid and each `user.<name>` dashed,
/// `measured` black thin, `residual` dotted, and the segment band of the ASD of the floor's
/// term of the total (lower to upper percentile, with its median as a thin line) shaded. Terms that are exactly zero at every frequency are listed in the legend as
/// identically 0 instead of drawn (thermal elements and user terms of the other block of the
/// model are left out). More than four panels: three columns, legends inside, no per-axis or
/// per-element curves, a one-paragraph caption.
///
/// # Errors
///
/// [`DrawError`] for an empty or inconsistent report or any drawing failure.
pub fn budget_figure(report: &BudgetReport, format: ImageFormat) -> Result<Vec<u8>, DrawError> {
    budget_figure_with(report, format, &BudgetFigureOptions::default())
}

/// [`budget_figure`] with a different size, title note, y depth, or the input named in the
/// caption.
pub fn budget_figure_with(
    report: &BudgetReport,
    format: ImageFormat,
    options: &BudgetFigureOptions,
) -> Result<Vec<u8>, DrawError> {
    let figure = build_budget_figure(report, options).map_err(|e| DrawError(e.into()))?;
    render(format, &options.view.apply(figure))
}

/// A term sets the automatic y range where its PSD is at least this fraction of the total's
/// (1 % in ASD): every term is visible where it contributes, and terms many decades below
/// the total do not stretch the axis.
pub const CONTRIBUTION_PSD_RATIO: f64 = 1e-4;

/// Where `psd` contributes to `total` (see [`CONTRIBUTION_PSD_RATIO`]).
fn contributes(psd: &[f64], total: &[f64]) -> Vec<bool> {
    psd.iter()
        .zip(total)
        .map(|(&p, &t)| p >= CONTRIBUTION_PSD_RATIO * t)
        .collect()
}

/// Colour of the whole tilt term and of its segment band.
const TILT_COLOR: RGBColor = PALETTE[0];
/// Colour of the whole translation term.
const TRANSLATION_COLOR: RGBColor = PALETTE[1];
/// Colour of the ground term (tilt and translation with their cross-spectra).
const GROUND_COLOR: RGBColor = PALETTE[2];

/// The colour of a term of the floor's motion that may add to the total (and of its band).
fn ground_color(kind: &TermKind) -> RGBColor {
    match kind {
        TermKind::Ground => GROUND_COLOR,
        TermKind::Translation => TRANSLATION_COLOR,
        _ => TILT_COLOR,
    }
}
/// Grey of the readout term.
const READOUT_COLOR: RGBColor = RGBColor(128, 128, 128);
/// Black of `total` and `measured`.
const BLACK: RGBColor = PALETTE[6];
/// Red of the `thermal` term.
const THERMAL_COLOR: RGBColor = RGBColor(200, 30, 30);
/// Element names, for a stable colour per element of `thermal.<element>`.
const THERMAL_ELEMENTS: [&str; 6] = [
    "torsion_a",
    "torsion_b",
    "bouncing_a",
    "bouncing_b",
    "swing_a",
    "swing_b",
];

/// Colour of the `user` term (the user-named terms together).
const USER_COLOR: RGBColor = RGBColor(120, 60, 160);

/// How the readout of a panel is labelled: its white value, or as a given spectrum (whose file
/// the caption names).
#[derive(Clone, Copy)]
enum ReadoutLabel {
    White(f64, Observable),
    Given,
}

/// Legend label and style of a budget component: the kind decides, not its name.
fn term_style(component: &Component, readout: Option<ReadoutLabel>) -> (String, TraceStyle) {
    let style = |c, d, w| TraceStyle::new(c, d, w);
    let kind = match component {
        Component::Total => return ("total".to_string(), style(BLACK, Dash::Solid, 4)),
        Component::Term(kind) => kind,
    };
    match kind {
        TermKind::Tilt => ("tilt".to_string(), style(TILT_COLOR, Dash::Solid, 2)),
        TermKind::Translation => (
            "translation".to_string(),
            style(TRANSLATION_COLOR, Dash::Solid, 2),
        ),
        TermKind::Ground => (
            "ground (tilt + translation)".to_string(),
            style(GROUND_COLOR, Dash::Solid, 3),
        ),
        TermKind::TranslationAxis(axis) => {
            let color = match axis {
                TranslationAxis::XT => PALETTE[4],
                TranslationAxis::YT => PALETTE[3],
                TranslationAxis::ZT => PALETTE[5],
            };
            (
                format!("translation, {} alone", translation_symbol(*axis)),
                style(color, Dash::Dashed, 2),
            )
        }
        TermKind::WitnessNoise => (
            "tiltmeter noise in the tilt term (not in the total)".to_string(),
            style(TILT_COLOR, Dash::Dotted, 2),
        ),
        TermKind::Readout => {
            let label = match readout {
                Some(ReadoutLabel::White(asd, o)) => format!("readout, {}", si_asd(asd, o.unit())),
                Some(ReadoutLabel::Given) => "readout (given spectrum)".to_string(),
                None => "readout".to_string(),
            };
            (label, style(READOUT_COLOR, Dash::Solid, 2))
        }
        TermKind::User => ("user terms".to_string(), style(USER_COLOR, Dash::Solid, 2)),
        TermKind::UserNamed(name) => {
            // A stable colour per name.
            let k = name.bytes().map(usize::from).sum::<usize>() % OTHER_COLORS.len();
            (
                format!("user, {}", name.replace('_', " ")),
                style(OTHER_COLORS[k], Dash::Dashed, 2),
            )
        }
        TermKind::Measured => ("measured".to_string(), style(BLACK, Dash::Solid, 1)),
        TermKind::Residual => ("residual".to_string(), style(PALETTE[3], Dash::Dotted, 2)),
        TermKind::Thermal => (
            "thermal (FDT)".to_string(),
            style(THERMAL_COLOR, Dash::Solid, 2),
        ),
        TermKind::ThermalElement(element) => {
            let k = THERMAL_ELEMENTS
                .iter()
                .position(|e| element.starts_with(e))
                .unwrap_or(0);
            let dash = if element.ends_with("_viscous") {
                Dash::Dashed
            } else {
                Dash::Dotted
            };
            (
                format!("thermal, {}", element.replace('_', " ")),
                style(OTHER_COLORS[k % OTHER_COLORS.len()], dash, 2),
            )
        }
        TermKind::TiltAxis(axis) => {
            let color = match axis {
                TiltAxis::ThetaT => PALETTE[5],
                TiltAxis::EtaT => PALETTE[1],
                TiltAxis::PhiT => PALETTE[2],
            };
            (
                format!("tilt, {} alone", tilt_symbol(*axis)),
                style(color, Dash::Dashed, 2),
            )
        }
    }
}

/// Drawing order (and legend order): total first, so that the terms lie on top of it where
/// they dominate, as in pygwinc.
fn draw_rank(component: &Component) -> u8 {
    match component {
        Component::Total => 0,
        Component::Term(kind) => match kind {
            TermKind::Measured => 1,
            TermKind::Residual => 2,
            TermKind::Ground => 3,
            TermKind::Tilt => 4,
            TermKind::Translation => 5,
            TermKind::TiltAxis(_) => 6,
            TermKind::WitnessNoise => 6,
            TermKind::TranslationAxis(_) => 7,
            TermKind::Readout => 8,
            TermKind::Thermal => 9,
            TermKind::ThermalElement(_) => 10,
            TermKind::User => 11,
            TermKind::UserNamed(_) => 12,
        },
    }
}

/// Colours of the thermal elements.
const OTHER_COLORS: [RGBColor; 6] = [
    PALETTE[4], PALETTE[2], PALETTE[3], PALETTE[5], PALETTE[1], PALETTE[0],
];

/// The figure as data, ready for [`render`]; errors are plain messages.
pub fn build_budget_figure(
    report: &BudgetReport,
    options: &BudgetFigureOptions,
) -> Result<LogLogFigure, String> {
    report.check()?;
    let freqs = &report.budget.freqs_hz;
    if report.budget.observables.is_empty() {
        return Err("the budget has no observable to draw".to_string());
    }
    // More than the four cells of the usual 2 x 2 grid: small panels, so the diagnostic
    // breakdowns (one tilt axis, one thermal element) stay in the files only.
    let compact = report.budget.observables.len() + usize::from(equivalent_x(report)) > 4;
    let mut panels = Vec::new();
    for ob in &report.budget.observables {
        let o = ob.observable;
        let unit = o.unit();
        let mut panel = Panel::new(
            observable_title(o),
            ("frequency", "Hz"),
            (
                &format!("ASD of {}", observable_symbol(o)),
                &format!("{unit}/√Hz"),
            ),
        );
        panel.max_decades = Some(options.max_decades);
        if compact {
            // A legend beside a third of the width would leave the curves no room.
            panel.legend = LegendPlacement::Inside;
        }
        let total = ob.total();
        let mut components = ob.components();
        components.sort_by_key(|(c, _)| draw_rank(c));
        let with_ground = ob.term(&TermKind::Ground).is_some();
        for (component, psd) in components {
            let axis = matches!(
                component,
                Component::Term(TermKind::TiltAxis(_) | TermKind::TranslationAxis(_))
            );
            let breakdown =
                axis || matches!(component, Component::Term(TermKind::ThermalElement(_)));
            // Beside ground, tilt and translation are the breakdown; one axis each is too fine.
            if (compact && breakdown) || (with_ground && axis) {
                continue;
            }
            let readout = match (report.readout.of(o), report.readout.given_of(o)) {
                (Some(a), _) => Some(ReadoutLabel::White(a, o)),
                (None, Some(_)) => Some(ReadoutLabel::Given),
                (None, None) => None,
            };
            let (label, style) = term_style(&component, readout);
            if psd.iter().all(|&p| p == 0.0) {
                // An element, or an input, of the other block: exactly 0 by the model's
                // structure, not news (the files keep the zeros).
                if matches!(
                    component,
                    Component::Term(
                        TermKind::ThermalElement(_) | TermKind::User | TermKind::UserNamed(_)
                    )
                ) {
                    continue;
                }
                let short = label
                    .strip_prefix("tilt, ")
                    .or(label.strip_prefix("translation, "))
                    .unwrap_or(&label);
                panel.notes.push(format!("{short}: identically 0"));
                continue;
            }
            let points = freqs
                .iter()
                .zip(&psd)
                .map(|(&f, p)| (f, p.sqrt()))
                .collect();
            let mut trace = Trace::new(label, points, style);
            // The floor's terms, the tool's main result, are always in range; the others where
            // they contribute.
            let always = matches!(
                component,
                Component::Total
                    | Component::Term(
                        TermKind::Measured
                            | TermKind::Tilt
                            | TermKind::Translation
                            | TermKind::Ground
                    )
            );
            if !always {
                trace.range_mask = Some(contributes(&psd, &total));
            }
            panel.traces.push(trace);
        }
        if let Some((_, band)) = report.segment_bands.iter().find(|(b, _)| *b == o) {
            let median_mask = contributes(&band.median, &total);
            let (band, mut median) = segment_band(freqs, band, report.segment_duration_s);
            panel.band = Some(band);
            // The median of the segments sets the range where it contributes to the total.
            median.range_mask = Some(median_mask);
            panel.traces.push(median);
        }
        panels.push(panel);
    }
    if let Some(mut panel) = equivalent_panel(report, options) {
        if compact {
            panel.legend = LegendPlacement::Inside;
        }
        panels.push(panel);
    }
    let has = |kind: TermKind| {
        report
            .budget
            .observables
            .iter()
            .any(|b| b.term(&kind).is_some())
    };
    let (damped, user) = (has(TermKind::Thermal), has(TermKind::User));
    let floor = floor_name(report);
    let mut title = if damped || user {
        let mut groups = vec![floor];
        if damped {
            groups.push("thermal");
        }
        groups.push("readout");
        if user {
            groups.push("user terms");
        }
        format!(
            "Noise budget ({}): one-sided amplitude spectral densities",
            groups.join(", ")
        )
    } else {
        let mut name = floor.to_string();
        name[..1].make_ascii_uppercase();
        format!("{name} noise budget: one-sided amplitude spectral densities")
    };
    if let Some(note) = &options.note {
        title.push_str(&format!(" ({note})"));
    }
    let caption = caption(report, options.input.as_ref(), compact);
    Ok(LogLogFigure {
        size: options.size,
        title: Some(title),
        panels,
        // Three columns for more than four panels: the caption then takes a free cell.
        columns: if compact { 3 } else { 2 },
        caption,
        shared_legend: true,
    })
}

/// With a damped model (a `response.F_b.x` term on X), the X budget referred to the test
/// mass's acceleration, `S_X / |m_b H_X,F_b.x|^2` (m s^-2/sqrt(Hz)): the free-fall figure of
/// merit, in the fourth slot of the 2x2 grid. Terms as in the X panel, without the measured
/// ones and the per-axis or per-element breakdown.
/// Whether the figure gets the X acceleration panel: a budget of X with its calibration.
fn equivalent_x(report: &BudgetReport) -> bool {
    report
        .budget
        .observable(Observable::X)
        .is_some_and(|ob| referred_terms(ob).is_some())
}

fn equivalent_panel(report: &BudgetReport, options: &BudgetFigureOptions) -> Option<Panel> {
    let ob = report
        .budget
        .observables
        .iter()
        .find(|b| b.observable == Observable::X)?;
    let referred = referred_terms(ob)?;
    let mut panel = Panel::new(
        "Test-mass acceleration noise equivalent to X",
        ("frequency", "Hz"),
        ("ASD of aₓ", "m s⁻²/√Hz"),
    );
    panel.max_decades = Some(options.max_decades);
    let mut terms: Vec<&(Component, Vec<f64>)> = referred
        .terms
        .iter()
        .filter(|(c, _)| match c {
            Component::Total => true,
            Component::Term(kind) => ob.adds_to_total(kind),
        })
        .collect();
    terms.sort_by_key(|(c, _)| draw_rank(c));
    // The range rule of the other panels: the total and the tilt term everywhere, every other
    // term where it contributes. The response's zeros (antiresonances), where every
    // equivalent term peaks, are narrow: the automatic range clips them at the top.
    let (_, total) = referred
        .terms
        .iter()
        .find(|(c, _)| *c == Component::Total)?;
    for (component, psd) in terms {
        // The readout's label as in the X panel, so the shared legend lists it once.
        let readout = match (
            report.readout.of(Observable::X),
            report.readout.given_of(Observable::X),
        ) {
            (Some(a), _) => Some(ReadoutLabel::White(a, Observable::X)),
            (None, Some(_)) => Some(ReadoutLabel::Given),
            (None, None) => None,
        };
        let (label, style) = term_style(component, readout);
        let identically_zero = match component {
            Component::Total => ob.total().iter().all(|&p| p == 0.0),
            Component::Term(kind) => ob.term(kind)?.psd.iter().all(|&p| p == 0.0),
        };
        if identically_zero {
            continue;
        }
        let points = report
            .budget
            .freqs_hz
            .iter()
            .zip(psd)
            .map(|(&f, p)| (f, p.sqrt()))
            .collect();
        let mut trace = Trace::new(label, points, style);
        let floor = matches!(component, Component::Term(k) if k.is_ground_motion());
        if !(floor || *component == Component::Total) {
            trace.range_mask = Some(contributes(psd, total));
        }
        panel.traces.push(trace);
    }
    Some(panel)
}

/// The shaded band between the lower and upper percentile of the ASD of the band's term
/// (`tilt`, `translation` or `ground`) and the median line.
fn segment_band(freqs: &[f64], band: &SegmentBand, duration_s: Option<f64>) -> (Band, Trace) {
    let asd = |v: &[f64]| -> Vec<(f64, f64)> {
        freqs.iter().zip(v).map(|(&f, &p)| (f, p.sqrt())).collect()
    };
    let per = segment_adjective(duration_s);
    let (term, color) = (band.term.name(), ground_color(&band.term));
    let label = format!(
        "{term}, {per} {}–{} %",
        compact(band.lower_pct),
        compact(band.upper_pct)
    );
    let mut shaded = Band::new(label, asd(&band.lower), asd(&band.upper), color);
    shaded.opacity = 0.22;
    let median = Trace::new(
        format!("{term}, {per} median"),
        asd(&band.median),
        TraceStyle::new(color, Dash::Solid, 1),
    );
    (shaded, median)
}

/// What the report's floor terms are of: `tilt`, `translation`, or `ground` for both.
fn floor_name(report: &BudgetReport) -> &'static str {
    let tilt = report.inputs.iter().any(|i| matches!(i, Input::Tilt(_)));
    let translation = report
        .inputs
        .iter()
        .any(|i| matches!(i, Input::Translation(_)));
    match (tilt, translation) {
        (true, true) => "ground",
        (false, true) => "translation",
        _ => "tilt",
    }
}

/// `hourly`, `daily`, `per-minute`, or `per 4 h segment`, `per 90 s segment`.
pub fn segment_adjective(duration_s: Option<f64>) -> String {
    let Some(d) = duration_s.filter(|d| d.is_finite() && *d > 0.0) else {
        return "per segment".to_string();
    };
    match d {
        60.0 => "per-minute".to_string(),
        3600.0 => "hourly".to_string(),
        86400.0 => "daily".to_string(),
        _ => format!("per {} segment", duration(d)),
    }
}

/// A duration in the largest unit that keeps it short: `4 h`, `90 min`, `2 d`, `1638 s`,
/// `27.8 h` (whole minutes below 2 h are shown in minutes; 3 significant digits).
pub fn duration(d: f64) -> String {
    let whole = |x: f64| (x - x.round()).abs() < 1e-9 * x.abs().max(1.0);
    if d >= 86400.0 && whole(d / 86400.0) {
        format!("{} d", compact(d / 86400.0))
    } else if d >= 3600.0 && whole(d / 3600.0) {
        format!("{} h", compact(d / 3600.0))
    } else if d >= 60.0 && whole(d / 60.0) && d < 7200.0 {
        format!("{} min", compact(d / 60.0))
    } else if d >= 7200.0 {
        format!("{} h", significant(d / 3600.0, 3))
    } else {
        format!("{} s", significant(d, 4))
    }
}

/// A number with at most 4 significant digits and no trailing zeros: `10`, `2.5`, `0.001`,
/// `1.5e-7`.
fn compact(v: f64) -> String {
    significant(v, 4)
}

/// A number for prose: `0.25`, `30`, `5·10⁻⁵`, `10⁻⁴` (powers of ten outside 1e-3..1e6).
fn pretty(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return compact(v);
    }
    let e = v.log10().floor() as i32;
    if (-3..6).contains(&e) {
        return compact(v);
    }
    let m = significant(v / 10f64.powi(e), 4);
    if m == "1" {
        super::chart::pow10_label(e)
    } else if m == "10" {
        super::chart::pow10_label(e + 1)
    } else {
        format!("{m}·{}", super::chart::pow10_label(e))
    }
}

/// Caption paragraphs: input, spectral estimate, segments, readout, conventions, notes.
/// With `many_panels` (more than four) the conventions are said in one short paragraph.
/// What the caption calls the floor's motion of `report` (`Tilt`, `Translation`, `Floor
/// motion`), and the symbols of its inputs.
fn floor_inputs(report: &BudgetReport) -> (String, String) {
    let symbols: Vec<&str> = report
        .inputs
        .iter()
        .filter_map(|i| match i {
            Input::Tilt(a) => Some(tilt_symbol(*a)),
            Input::Translation(t) => Some(translation_symbol(*t)),
            Input::Force(_) => None,
        })
        .collect();
    let mut name = floor_name(report).to_string();
    name[..1].make_ascii_uppercase();
    if name == "Ground" {
        name = "Floor motion".to_string();
    }
    (name, symbols.join(", "))
}

fn caption(report: &BudgetReport, input: Option<&InputMeta>, many_panels: bool) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(i) = input {
        let name = Path::new(&i.path)
            .file_name()
            .map_or_else(|| i.path.clone(), |n| n.to_string_lossy().into_owned());
        let mut s = format!("Input: {name} ({} {}, {}", i.format, i.kind, i.quantity);
        if !i.axis_map.is_empty() && !many_panels {
            s.push_str(&format!("; {}", i.axis_map));
        }
        s.push(')');
        if let Some(t) = i.start_time.as_ref().filter(|_| !many_panels) {
            s.push_str(&format!(", start {t}"));
        }
        s.push('.');
        out.push(s);
    }
    let (floor, axes) = floor_inputs(report);
    out.push(match &report.source {
        SpectralSource::Welch {
            sample_rate_hz,
            segment_len,
            overlap,
            averaging,
            n_welch_segments,
            n_samples,
        } => {
            let fs = *sample_rate_hz;
            if many_panels {
                format!(
                    "{floor} ({axes}): Welch, {n_welch_segments} segments of {segment_len} \
                     samples at {} Hz, {averaging}.",
                    compact(fs)
                )
            } else {
                format!(
                    "{floor} ({axes}): Welch estimate at {} Hz, {} segments of {segment_len} \
                     samples ({}), overlap {overlap}, {averaging} averaging; {n_samples} samples \
                     ({}).",
                    compact(fs),
                    n_welch_segments,
                    duration(*segment_len as f64 / fs),
                    duration(*n_samples as f64 / fs),
                )
            }
        }
        SpectralSource::Spectra { data_band_hz } => format!(
            "Tilt ({axes}): spectra given from {} to {} Hz, interpolated log-log onto the model \
             grid.",
            pretty(data_band_hz.0),
            pretty(data_band_hz.1)
        ),
    });
    if let Some((_, band)) = report.segment_bands.first() {
        let per = match report.segment_duration_s {
            Some(d) => format!("{} segments of {}", band.n_segments, duration(d)),
            None => format!("{} segments", band.n_segments),
        };
        out.push(format!(
            "Band: {}th to {}th percentile of the {} ASD over {per}; thin line: median.",
            compact(band.lower_pct),
            compact(band.upper_pct),
            band.term.name()
        ));
    }
    out.push(readout_sentence(&report.readout, report));
    if !report.user_terms.is_empty() {
        let terms: Vec<String> = report
            .user_terms
            .iter()
            .map(|t| {
                let file = short_origin(t.asd.origin());
                match t.source {
                    UserSource::Observable(o) => {
                        format!("{} ({} ASD, {file})", t.name, observable_symbol(o))
                    }
                    UserSource::Input(i) => {
                        format!("{} ({} ASD via the model, {file})", t.name, i.name())
                    }
                }
            })
            .collect();
        out.push(format!(
            "User terms (independent, summed in power): {}.",
            terms.join("; ")
        ));
    }
    let damped = report
        .budget
        .observables
        .iter()
        .any(|b| b.term(&TermKind::Thermal).is_some());
    let floor_terms = match floor_name(report) {
        "ground" => {
            "ground: tilt and translation with every cross-spectrum between them (tilt and \
             translation: each alone, not added: they are correlated and act alike at low \
             frequency)"
        }
        "translation" => "translation: all axes with their cross-spectra",
        _ => "tilt: all axes with their cross-spectra",
    };
    let floor = floor_name(report);
    let conventions = match (damped, !report.user_terms.is_empty()) {
        (_, true) => format!(
            "All curves are one-sided ASDs (√PSD). {floor_terms}; “alone”: one axis, for \
             diagnosis; thermal: fluctuation-dissipation theorem, sum over the dissipative \
             elements (dotted: each element alone); user terms: their sum (dashed: each alone); \
             total: quadrature sum of {floor}, thermal, readout and user terms."
        ),
        (true, false) => format!(
            "All curves are one-sided ASDs (√PSD). {floor_terms}; “alone”: one axis, for \
             diagnosis; thermal: fluctuation-dissipation theorem, sum over the dissipative \
             elements (dotted: each element alone); total: quadrature sum of {floor}, thermal \
             and readout."
        ),
        (false, false) => format!(
            "All curves are one-sided ASDs (√PSD). {floor_terms}; “alone”: one axis, for \
             diagnosis; total: quadrature sum of {floor} and readout."
        ),
    };
    // With many panels the title says what the curves are; the rest is in the files.
    if !many_panels {
        out.push(conventions);
    }
    out.extend(report.notes.iter().map(|n| {
        let n = n.trim();
        let end = if n.ends_with(['.', '!', '?']) {
            ""
        } else {
            "."
        };
        format!("Note: {n}{end}")
    }));
    if many_panels {
        // One paragraph: the caption shares a cell with the panels.
        out = vec![out.join(" ")];
    }
    out
}

/// The file named in a given spectrum's origin (`--term a=F_b.x:dir/f.csv (column F_b.x)` ->
/// `f.csv`), for the caption.
fn short_origin(origin: &str) -> String {
    let head = origin.rfind(" (column ").map_or(origin, |i| &origin[..i]);
    let file = head.rsplit(['=', ':']).next().unwrap_or(head);
    Path::new(file)
        .file_name()
        .map_or_else(|| file.to_string(), |n| n.to_string_lossy().into_owned())
}

fn readout_sentence(readout: &Readout, report: &BudgetReport) -> String {
    let mut with = Vec::new();
    let mut without = Vec::new();
    for ob in &report.budget.observables {
        let o = ob.observable;
        match (readout.of(o), readout.given_of(o)) {
            (Some(a), _) => with.push(format!("{} {}", observable_symbol(o), si_asd(a, o.unit()))),
            (None, Some(g)) => with.push(format!(
                "{} coloured, given by {}",
                observable_symbol(o),
                short_origin(g.origin())
            )),
            (None, None) => without.push(observable_symbol(o)),
        }
    }
    let white_only = readout.given.is_empty();
    let mut s = String::from(if white_only {
        "Readout noise (white, assumed): "
    } else {
        "Readout noise: "
    });
    if with.is_empty() {
        s.push_str("none");
    } else {
        s.push_str(&with.join(", "));
    }
    if !without.is_empty() && !with.is_empty() {
        s.push_str(&format!("; none on {}", without.join(", ")));
    }
    s.push('.');
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_and_adjectives() {
        assert_eq!(segment_adjective(Some(3600.0)), "hourly");
        assert_eq!(segment_adjective(Some(86400.0)), "daily");
        assert_eq!(segment_adjective(Some(4.0 * 3600.0)), "per 4 h segment");
        assert_eq!(segment_adjective(Some(5400.0)), "per 90 min segment");
        assert_eq!(segment_adjective(Some(90.0)), "per 90 s segment");
        assert_eq!(segment_adjective(None), "per segment");
        assert_eq!(duration(1638.4), "1638 s");
        assert_eq!(duration(2.0 * 86400.0), "2 d");
        assert_eq!(duration(100_000.0), "27.8 h");
        assert_eq!(duration(10_000.0), "2.78 h");
        assert_eq!(duration(2.5), "2.5 s");
        assert_eq!(compact(1.5e-7), "1.5e-7");
        assert_eq!(compact(97.5), "97.5");
        assert_eq!(pretty(5e-5), "5·10⁻⁵");
        assert_eq!(pretty(1e-4), "10⁻⁴");
        assert_eq!(pretty(0.5), "0.5");
    }
}
