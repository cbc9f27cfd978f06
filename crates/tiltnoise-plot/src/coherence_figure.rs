//! Measured against model transfer functions (Bode: magnitude and phase) with their confidence
//! bands, and the coherence behind them: one row per observable and tilt axis, from a
//! [`CoherenceReport`].

use super::chart::{
    Band, Dash, LegendPlacement, LogLogFigure, Panel, Trace, TraceStyle, YScale, PALETTE,
};
use super::labels::{observable_symbol, tilt_symbol};
use super::{render, DrawError, ImageFormat, View};
use num_complex::Complex64;
use plotters::style::RGBColor;
use tiltnoise_core::coherence::{with_error, AxisEstimate, CoherenceReport, ObservableEstimate};

/// Options of [`coherence_figure`].
#[derive(Debug, Clone, PartialEq)]
pub struct CoherenceFigureOptions {
    /// Width in pixels; the height follows from the number of rows.
    pub width: u32,
    /// Height of one row of panels (pixels).
    pub row_height: u32,
    /// The tilt record's name for the title, e.g. the file.
    pub tilt_name: String,
    /// The measured record's name for the title.
    pub measured_name: String,
    /// Axis limits, size (replacing `width` x rows) and resolution.
    pub view: View,
}

impl Default for CoherenceFigureOptions {
    fn default() -> Self {
        CoherenceFigureOptions {
            width: 1650,
            row_height: 430,
            tilt_name: "tilt".into(),
            measured_name: "measured".into(),
            view: View::default(),
        }
    }
}

const MEASURED: RGBColor = PALETTE[0];
const MODEL: RGBColor = PALETTE[6];
const ORDINARY: RGBColor = PALETTE[1];
const MULTIPLE: RGBColor = PALETTE[2];
const THRESHOLD: RGBColor = RGBColor(120, 120, 120);

/// Draws the figure as a PNG or SVG file's bytes.
///
/// # Errors
///
/// [`DrawError`] for a report without anything to draw or any drawing failure.
pub fn coherence_figure(
    report: &CoherenceReport,
    format: ImageFormat,
    options: &CoherenceFigureOptions,
) -> Result<Vec<u8>, DrawError> {
    let figure = build_coherence_figure(report, options).map_err(|e| DrawError(e.into()))?;
    render(format, &options.view.apply(figure))
}

/// The rows drawn: every (observable, axis) pair whose model entry is not identically zero;
/// all pairs if none is.
fn rows(report: &CoherenceReport) -> Vec<(&ObservableEstimate, &AxisEstimate)> {
    let all: Vec<_> = report
        .observables
        .iter()
        .flat_map(|o| o.axes.iter().map(move |a| (o, a)))
        .collect();
    let nonzero: Vec<_> = all
        .iter()
        .copied()
        .filter(|(_, a)| a.model.iter().any(|z| z.norm() > 0.0))
        .collect();
    if nonzero.is_empty() {
        all
    } else {
        nonzero
    }
}

/// The figure as data, ready for [`render`]; errors are plain messages.
pub fn build_coherence_figure(
    report: &CoherenceReport,
    options: &CoherenceFigureOptions,
) -> Result<LogLogFigure, String> {
    let rows = rows(report);
    if rows.is_empty() || report.freqs_hz.is_empty() {
        return Err("the coherence report has no observable, tilt axis or frequency".into());
    }
    let level = format!("{:.0} %", 100.0 * report.confidence);
    let f = &report.freqs_hz;
    let x_range = (f[0], f[f.len() - 1]);
    let mut panels = Vec::new();
    for (ob, a) in &rows {
        let (o, t) = (observable_symbol(ob.observable), tilt_symbol(a.axis));
        let unit = format!("{}/rad", ob.observable.unit());
        let pair = format!("{o} / {t}");
        panels.push(magnitude_panel(f, a, &pair, &unit, &level));
        panels.push(phase_panel(f, a, &pair, &level));
        panels.push(coherence_panel(f, report, ob, a, &level));
    }
    for p in &mut panels {
        p.x_range = Some(x_range);
    }
    let mut caption = vec![format!(
        "Measured: multiple-input estimate H = S_xx⁻¹ s_xy over all {} tilt axes (each H with \
         the other axes held fixed), Welch {} samples at {} Hz, overlap {}, {} segments = {:.1} \
         independent averages. Shaded: {level} confidence (magnitude and phase from the \
         confidence circle of H; phase undetermined where the circle contains 0). Time \
         dependence exp(+iωt), tilt sign of the model: a lag is a negative phase.",
        report.axes.len(),
        report.welch.segment_len,
        report.welch.sample_rate_hz,
        report.welch.overlap,
        report.welch.n_segments,
        report.welch.n_equivalent
    )];
    let mut fits = Vec::new();
    for (ob, a) in &rows {
        if let Some(ag) = &a.agreement {
            let (gain, gain_sigma) = with_error(ag.gain(), ag.sigma);
            let (phase, phase_sigma) = with_error(ag.phase_deg(), ag.phase_sigma_deg());
            fits.push(format!(
                "{} / {}: measured = ({gain} ± {gain_sigma}) × model at {phase}° ± \
                 {phase_sigma}° ({} bins, {} to {} Hz, χ²/ν {:.2})",
                observable_symbol(ob.observable),
                tilt_symbol(a.axis),
                ag.n_bins,
                short(ag.band_hz.0),
                short(ag.band_hz.1),
                ag.chi2_per_dof
            ));
        }
    }
    if !fits.is_empty() {
        caption.push(format!(
            "Fit of one complex factor measured = g × model, weighted by the inverse variance of \
             each bin: {}.",
            fits.join("; ")
        ));
    }
    let hidden: Vec<String> = report
        .observables
        .iter()
        .flat_map(|o| o.axes.iter().map(move |a| (o, a)))
        .filter(|(o, a)| {
            !rows
                .iter()
                .any(|(ro, ra)| ro.observable == o.observable && ra.axis == a.axis)
        })
        .map(|(o, a)| {
            format!(
                "{} / {}",
                observable_symbol(o.observable),
                tilt_symbol(a.axis)
            )
        })
        .collect();
    if !hidden.is_empty() {
        caption.push(format!(
            "Not drawn (model identically 0): {}; their estimates are in the HDF5 and CSV files.",
            hidden.join(", ")
        ));
    }
    let title = format!(
        "Measured vs model transfer functions: {} against {}",
        options.measured_name, options.tilt_name
    );
    Ok(LogLogFigure {
        size: (options.width, options.row_height * rows.len() as u32 + 290),
        title: Some(title),
        panels,
        columns: 3,
        caption,
        // One legend below the grid: inside, it covers the low-frequency estimates and the
        // coherence near 1.
        shared_legend: true,
    })
}

fn style(color: RGBColor, dash: Dash, width: u32) -> TraceStyle {
    TraceStyle::new(color, dash, width)
}

fn magnitude_panel(f: &[f64], a: &AxisEstimate, pair: &str, unit: &str, level: &str) -> Panel {
    let mut p = Panel::new(
        format!("{pair}: magnitude"),
        ("frequency", "Hz"),
        (&format!("|{pair}|"), unit),
    );
    let points = |v: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        f.iter().enumerate().map(|(k, &x)| (x, v(k))).collect()
    };
    p.band = Some(Band::new(
        format!("{level} confidence"),
        points(&|k| a.tf[k].norm() - a.tf_radius[k]),
        points(&|k| a.tf[k].norm() + a.tf_radius[k]),
        MEASURED,
    ));
    // The model first: the measured estimate is drawn over it.
    p.traces.push(Trace::new(
        "model",
        points(&|k| a.model[k].norm()),
        style(MODEL, Dash::Solid, 2),
    ));
    p.traces.push(Trace::new(
        "measured",
        points(&|k| a.tf[k].norm()),
        style(MEASURED, Dash::Solid, 1),
    ));
    p.max_decades = Some(8.0);
    p.legend = LegendPlacement::Inside;
    p
}

/// Phases (degrees) in a window of 360 degrees centred on the model's typical phase (the
/// median of its phases, rounded to 90 degrees), so that a phase near 180 degrees does not
/// flip between the top and the bottom; lines break where they wrap.
fn phase_panel(f: &[f64], a: &AxisEstimate, pair: &str, level: &str) -> Panel {
    let mut model_deg: Vec<f64> = a
        .model
        .iter()
        .filter(|z| z.norm() > 0.0 && z.re.is_finite() && z.im.is_finite())
        .map(|z| z.arg().to_degrees())
        .collect();
    model_deg.sort_by(f64::total_cmp);
    let centre = model_deg
        .get(model_deg.len() / 2)
        .map_or(0.0, |m| (m / 90.0).round() * 90.0);
    let deg = |z: Complex64| {
        if z.norm() > 0.0 && z.re.is_finite() && z.im.is_finite() {
            wrap_near(z.arg().to_degrees(), centre)
        } else {
            f64::NAN
        }
    };
    let (mut lower, mut upper) = (Vec::new(), Vec::new());
    let mut measured = Vec::with_capacity(f.len());
    for (k, &x) in f.iter().enumerate() {
        let phi = deg(a.tf[k]);
        let (r, mag) = (a.tf_radius[k], a.tf[k].norm());
        let half = if r < mag {
            (r / mag).asin().to_degrees()
        } else {
            180.0
        };
        measured.push((x, phi));
        lower.push((x, phi - half));
        upper.push((x, phi + half));
    }
    let model: Vec<(f64, f64)> = f.iter().zip(&a.model).map(|(&x, &z)| (x, deg(z))).collect();
    let mut p = Panel::new(
        format!("{pair}: phase"),
        ("frequency", "Hz"),
        (&format!("arg({pair})"), "deg"),
    );
    p.y_scale = YScale::Linear {
        tick_step: Some(90.0),
    };
    p.y_range = Some((centre - 180.0, centre + 180.0));
    p.band = Some(Band::new(
        format!("{level} confidence"),
        lower,
        upper,
        MEASURED,
    ));
    p.traces.push(Trace::new(
        "model",
        break_at_wraps(&model),
        style(MODEL, Dash::Solid, 2),
    ));
    p.traces.push(Trace::new(
        "measured",
        break_at_wraps(&measured),
        style(MEASURED, Dash::Solid, 1),
    ));
    // The styles are those of the magnitude panel beside it, whose legend names them.
    p.legend = LegendPlacement::Hidden;
    p
}

/// `points` with a break (a NaN point) wherever the phase jumps by more than 180 degrees.
fn break_at_wraps(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(points.len());
    for (i, &(x, y)) in points.iter().enumerate() {
        if i > 0 && (y - points[i - 1].1).abs() > 180.0 {
            out.push((x, f64::NAN));
        }
        out.push((x, y));
    }
    out
}

fn coherence_panel(
    f: &[f64],
    report: &CoherenceReport,
    ob: &ObservableEstimate,
    a: &AxisEstimate,
    level: &str,
) -> Panel {
    let o = observable_symbol(ob.observable);
    let mut p = Panel::new(
        format!("{o}: coherence with {}", tilt_symbol(a.axis)),
        ("frequency", "Hz"),
        ("γ²", ""),
    );
    p.y_scale = YScale::Linear {
        tick_step: Some(0.2),
    };
    p.y_range = Some((0.0, 1.0));
    let line =
        |v: &[f64]| -> Vec<(f64, f64)> { f.iter().copied().zip(v.iter().copied()).collect() };
    p.band = Some(Band::new(
        format!("{level} interval"),
        line(&a.coherence_lower),
        line(&a.coherence_upper),
        ORDINARY,
    ));
    p.traces.push(Trace::new(
        format!("γ² with {}", tilt_symbol(a.axis)),
        line(&a.coherence),
        style(ORDINARY, Dash::Solid, 1),
    ));
    p.traces.push(Trace::new(
        "noise threshold",
        flat(f, report.coherence_threshold),
        style(THRESHOLD, Dash::Dashed, 2),
    ));
    if report.axes.len() > 1 {
        p.traces.push(Trace::new(
            "multiple γ², all axes",
            line(&ob.multiple_coherence),
            style(MULTIPLE, Dash::Solid, 1),
        ));
        p.traces.push(Trace::new(
            "its noise threshold",
            flat(f, report.multiple_coherence_threshold),
            style(MULTIPLE, Dash::Dashed, 2),
        ));
    }
    p.legend = LegendPlacement::Inside;
    p
}

fn flat(f: &[f64], y: f64) -> Vec<(f64, f64)> {
    vec![(f[0], y), (f[f.len() - 1], y)]
}

/// `deg` plus the multiple of 360 that brings it within 180 degrees of `centre`.
fn wrap_near(deg: f64, centre: f64) -> f64 {
    deg - 360.0 * ((deg - centre) / 360.0).round()
}

/// A frequency for prose, 3 significant digits.
fn short(v: f64) -> String {
    format!("{v:.2e}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_wrap_near_a_centre_and_lines_break_at_wraps() {
        assert!((wrap_near(-179.0, 180.0) - 181.0).abs() < 1e-12);
        assert_eq!(wrap_near(10.0, 0.0), 10.0);
        let p = break_at_wraps(&[(1.0, 170.0), (2.0, 175.0), (3.0, -175.0), (4.0, -170.0)]);
        assert_eq!(p.len(), 5);
        assert!(p[2].1.is_nan() && p[2].0 == 3.0);
    }
}
