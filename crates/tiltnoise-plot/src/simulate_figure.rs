//! Figures of `tiltnoise simulate`: the paper's Figure 3 (one-sided ASDs of the simulated
//! observables X, Y, Z and theta, eta, phi, with the mode frequencies marked) and Figures 4 and 5
//! (time series of phi and X, e.g. after the X kick).
//!
//! Plain data in ([`SimAsdData`], [`TimeSeriesData`]), a [`Figure`] out; written by
//! [`render`] (PNG or SVG bytes).

use super::chart::{Dash, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
use super::labels::{observable_symbol, observable_title, si_asd};
use super::{render, DrawError, Figure, ImageFormat, TextSizes, View, FONT_FAMILY};
use plotters::coord::Shift;
use plotters::prelude::*;
use tiltnoise_core::model::Observable;

/// The observables of Figure 3, in panel order (two rows of three).
pub const FIGURE3_OBSERVABLES: [Observable; 6] = [
    Observable::X,
    Observable::Y,
    Observable::Z,
    Observable::Theta,
    Observable::Eta,
    Observable::Phi,
];

/// A mode to mark on the ASD panels.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeMark {
    /// 1-based mode index.
    pub index: usize,
    /// Mode frequency (Hz).
    pub frequency_hz: f64,
    /// Where it appears in the sampled record (Hz): aliased if above Nyquist.
    pub apparent_frequency_hz: f64,
    /// Observables the observability table says see the mode.
    pub seen_by: Vec<Observable>,
}

/// Input of the ASD figure.
#[derive(Debug, Clone, PartialEq)]
pub struct SimAsdData {
    /// Welch frequencies (Hz), with DC first (skipped on the log axis).
    pub freqs_hz: Vec<f64>,
    /// One-sided ASD per observable (unit/sqrt(Hz)).
    pub asd: Vec<(Observable, Vec<f64>)>,
    /// White readout ASD per observable (unit/sqrt(Hz)); others noiseless.
    pub readout_asd: Vec<(Observable, f64)>,
    /// The normal modes.
    pub modes: Vec<ModeMark>,
    /// Caption lines (run description).
    pub caption: Vec<String>,
}

const ASD_COLOR: RGBColor = PALETTE[0];
/// Mode markers: thin and light, drawn under the spectrum, so they never hide a peak. A tint
/// of the vermillion for the modes the observable sees, light grey for the others.
const SEEN_COLOR: RGBColor = RGBColor(236, 160, 110);
const OTHER_MODE_COLOR: RGBColor = RGBColor(200, 200, 200);
const READOUT_COLOR: RGBColor = PALETTE[2];

/// Vertical marker lines at `xs` spanning `(lo, hi)`, as one broken trace.
fn markers(xs: &[f64], (lo, hi): (f64, f64)) -> Vec<(f64, f64)> {
    let mut pts = Vec::new();
    for &x in xs {
        pts.extend([(x, lo), (x, hi), (f64::NAN, f64::NAN)]);
    }
    pts
}

fn mode_list(marks: &[&ModeMark]) -> String {
    marks
        .iter()
        .map(|m| {
            if (m.apparent_frequency_hz - m.frequency_hz).abs() > 1e-9 * m.frequency_hz {
                format!("ν{} (alias)", m.index)
            } else {
                format!("ν{}", m.index)
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Builds Figure 3: one panel per observable of [`FIGURE3_OBSERVABLES`], ASD on log-log axes,
/// dashed lines at the modes the panel's observable sees (vermillion), dotted at the others (grey),
/// at their apparent (aliased) frequencies, and the readout level where there is one.
pub fn build_asd_figure(data: &SimAsdData) -> Result<LogLogFigure, String> {
    let mut panels = Vec::new();
    for o in FIGURE3_OBSERVABLES {
        let Some((_, asd)) = data.asd.iter().find(|(x, _)| *x == o) else {
            return Err(format!("no ASD of {} to draw", o.name()));
        };
        if asd.len() != data.freqs_hz.len() || asd.len() < 3 {
            return Err(format!(
                "ASD of {} has {} values and the grid {} (at least 3 needed)",
                o.name(),
                asd.len(),
                data.freqs_hz.len()
            ));
        }
        let unit = o.unit();
        let mut panel = Panel::new(
            observable_title(o),
            ("frequency", "Hz"),
            (
                &format!("ASD of {}", observable_symbol(o)),
                &format!("{unit}/√Hz"),
            ),
        );
        let points: Vec<(f64, f64)> = data
            .freqs_hz
            .iter()
            .zip(asd)
            .skip(1)
            .map(|(&f, &a)| (f, a))
            .collect();
        panel.traces.push(Trace::new(
            "simulated",
            points,
            TraceStyle::new(ASD_COLOR, Dash::Solid, 1),
        ));
        let last = data.freqs_hz.len() - 1;
        panel.x_range = Some((data.freqs_hz[1], data.freqs_hz[last]));
        let readout = data
            .readout_asd
            .iter()
            .find(|(x, _)| *x == o)
            .map(|r| r.1)
            .filter(|&r| r > 0.0);
        let x_range = panel.resolved_x_range();
        if let Some(r) = readout {
            panel.traces.push(Trace::new(
                format!("readout {}", si_asd(r, o.unit())),
                vec![(x_range.0, r), (x_range.1, r)],
                TraceStyle::new(READOUT_COLOR, Dash::Dashed, 2),
            ));
        }
        let y_range = panel.resolved_y_range();
        panel.y_range = Some(y_range);
        let seen: Vec<&ModeMark> = data
            .modes
            .iter()
            .filter(|m| m.seen_by.contains(&o))
            .collect();
        let other: Vec<&ModeMark> = data
            .modes
            .iter()
            .filter(|m| !m.seen_by.contains(&o))
            .collect();
        if !other.is_empty() {
            let xs: Vec<f64> = other.iter().map(|m| m.apparent_frequency_hz).collect();
            panel.traces.insert(
                0,
                Trace::new(
                    "other modes (not seen by the panel's observable)",
                    markers(&xs, y_range),
                    TraceStyle::new(OTHER_MODE_COLOR, Dash::Dotted, 1),
                ),
            );
        }
        if !seen.is_empty() {
            let xs: Vec<f64> = seen.iter().map(|m| m.apparent_frequency_hz).collect();
            panel.traces.insert(
                0,
                Trace::new(
                    "modes seen by the panel's observable",
                    markers(&xs, y_range),
                    TraceStyle::new(SEEN_COLOR, Dash::Dashed, 1),
                ),
            );
        }
        if !seen.is_empty() {
            panel
                .notes
                .push(format!("modes seen: {}", mode_list(&seen)));
        }
        panels.push(panel);
    }
    Ok(LogLogFigure {
        size: ASD_SIZE,
        title: Some(
            "Simulated free motion: one-sided amplitude spectral densities (Figure 3)".to_string(),
        ),
        panels,
        columns: 3,
        caption: data.caption.clone(),
        // One legend below the panels: inside, it would cover the low-frequency curve and
        // the peaks; each panel's list of the modes it sees is a row naming the panels.
        shared_legend: true,
    })
}

/// Default size of Figure 3 (pixels at 100 dpi).
pub const ASD_SIZE: (u32, u32) = (1800, 1250);

/// Draws Figure 3 as a PNG or SVG file's bytes, with the limits, size and resolution of
/// `view`.
///
/// # Errors
///
/// [`DrawError`] for inconsistent data or any drawing failure.
pub fn asd_figure(
    data: &SimAsdData,
    view: &View,
    format: ImageFormat,
) -> Result<Vec<u8>, DrawError> {
    let figure = build_asd_figure(data).map_err(|e| DrawError(e.into()))?;
    render(format, &view.apply(figure))
}

/// One time-series panel: `(t_s, value)` samples of one observable.
#[derive(Debug, Clone, PartialEq)]
pub struct TimePanel {
    /// Panel title.
    pub title: String,
    /// The observable (for the axis label and unit).
    pub observable: Observable,
    /// Sampling step (s); sample `i` is at `t0_s + i dt_s`.
    pub dt_s: f64,
    /// Time of the first sample (s).
    pub t0_s: f64,
    /// Samples (m or rad).
    pub values: Vec<f64>,
}

/// Input of the time-series figure (Figures 4 and 5): panels stacked vertically.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeSeriesData {
    /// Figure title.
    pub title: String,
    /// Panels, top to bottom.
    pub panels: Vec<TimePanel>,
}

/// Most points drawn per panel as a line; a longer series is drawn as the band between the
/// minimum and the maximum of each of `MAX_COLUMNS / 2` time bins, which keeps the envelope of
/// oscillations faster than a pixel (a thick polyline zigzagging that fast would draw spikes
/// at its sharp corners, far outside the frame in a bitmap).
const MAX_COLUMNS: usize = 4000;

/// What a panel draws: its samples as a line, or the min/max band of time bins.
enum TimeTrace {
    Line(Vec<(f64, f64)>),
    /// `(t, min, max)` per bin, in time order.
    Band(Vec<(f64, f64, f64)>),
}

impl TimeTrace {
    /// Time and value range `((t0, t1), (lo, hi))`.
    fn extent(&self) -> ((f64, f64), (f64, f64)) {
        let (ts, lo, hi): (Vec<f64>, f64, f64) = match self {
            TimeTrace::Line(p) => (
                p.iter().map(|q| q.0).collect(),
                p.iter().map(|q| q.1).fold(f64::INFINITY, f64::min),
                p.iter().map(|q| q.1).fold(f64::NEG_INFINITY, f64::max),
            ),
            TimeTrace::Band(b) => (
                b.iter().map(|q| q.0).collect(),
                b.iter().map(|q| q.1).fold(f64::INFINITY, f64::min),
                b.iter().map(|q| q.2).fold(f64::NEG_INFINITY, f64::max),
            ),
        };
        let t0 = ts.first().copied().unwrap_or(0.0);
        let t1 = ts.last().copied().unwrap_or(0.0);
        ((t0, t1), (lo, hi))
    }
}

impl TimeTrace {
    /// The same trace with its times divided by `per_unit_s`.
    fn in_time_unit(self, per_unit_s: f64) -> TimeTrace {
        match self {
            TimeTrace::Line(p) => {
                TimeTrace::Line(p.into_iter().map(|(t, v)| (t / per_unit_s, v)).collect())
            }
            TimeTrace::Band(b) => TimeTrace::Band(
                b.into_iter()
                    .map(|(t, lo, hi)| (t / per_unit_s, lo, hi))
                    .collect(),
            ),
        }
    }
}

/// The panel's samples as a line, or as a min/max band when there are more than
/// [`MAX_COLUMNS`] (see there).
fn decimate(p: &TimePanel) -> TimeTrace {
    let n = p.values.len();
    let t = |i: usize| p.t0_s + i as f64 * p.dt_s;
    if n <= MAX_COLUMNS {
        return TimeTrace::Line((0..n).map(|i| (t(i), p.values[i])).collect());
    }
    let bins = MAX_COLUMNS / 2;
    let band = (0..bins)
        .map(|b| {
            let (lo, hi) = (b * n / bins, ((b + 1) * n / bins).max(b * n / bins + 1));
            let values = &p.values[lo..hi];
            let min = values.iter().copied().fold(f64::INFINITY, f64::min);
            let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (t((lo + hi - 1) / 2), min, max)
        })
        .collect();
    TimeTrace::Band(band)
}

/// The unit of a time axis spanning `span_s`: seconds, hours beyond 3 h, days beyond 3 d.
fn time_unit(span_s: f64) -> (&'static str, f64) {
    if span_s >= 3.0 * 86_400.0 {
        ("d", 86_400.0)
    } else if span_s >= 3.0 * 3_600.0 {
        ("h", 3_600.0)
    } else {
        ("s", 1.0)
    }
}

impl Figure for TimeSeriesData {
    fn size(&self) -> (u32, u32) {
        (1400, 450 * self.panels.len().max(1) as u32 + 60)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> Result<(), DrawError> {
        let (w, h) = root.dim_in_pixel();
        let ts = TextSizes::for_figure(w, h);
        let (top, rest) = root.split_vertically((ts.title * 2.0).round() as u32);
        let style = (FONT_FAMILY, ts.title).into_font().color(&BLACK).pos(
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Center,
                plotters::style::text_anchor::VPos::Center,
            ),
        );
        let (tw, th) = top.dim_in_pixel();
        top.draw_text(&self.title, &style, (tw as i32 / 2, th as i32 / 2))?;
        let cells = rest.split_evenly((self.panels.len().max(1), 1));
        for (p, cell) in self.panels.iter().zip(cells.iter()) {
            if p.values.is_empty() {
                return Err(DrawError(
                    format!("panel `{}` has no samples", p.title).into(),
                ));
            }
            let trace = decimate(p);
            let ((x0, x1), (mut y0, mut y1)) = trace.extent();
            let x1 = x1.max(x0 + p.dt_s);
            // Time drawn in the axis's unit, so that the ticks fall on round values of it.
            let (unit, per_unit_s) = time_unit(x1 - x0);
            let (x0, x1) = (x0 / per_unit_s, x1 / per_unit_s);
            let trace = trace.in_time_unit(per_unit_s);
            if !(y0.is_finite() && y1.is_finite()) {
                return Err(DrawError(
                    format!("panel `{}` has non-finite samples", p.title).into(),
                ));
            }
            let pad = if y1 > y0 {
                0.05 * (y1 - y0)
            } else {
                y0.abs().max(1e-30)
            };
            y0 -= pad;
            y1 += pad;
            let mut chart = ChartBuilder::on(cell)
                .caption(&p.title, (FONT_FAMILY, ts.panel_title))
                .margin(12)
                .x_label_area_size((ts.axis * 3.0) as u32)
                .y_label_area_size((ts.axis * 6.0) as u32)
                .build_cartesian_2d(x0..x1, y0..y1)?;
            let x_desc = format!("time ({unit})");
            chart
                .configure_mesh()
                .x_desc(x_desc)
                .y_desc(observable_symbol(p.observable))
                .axis_desc_style((FONT_FAMILY, ts.axis))
                .label_style((FONT_FAMILY, ts.ticks))
                .y_label_formatter(&|v| {
                    // A tick at zero computed as a tiny rounding residue prints as 0.
                    if v.abs() < 1e-9 * (y1 - y0) {
                        "0".to_string()
                    } else {
                        super::labels::si_value(*v, p.observable.unit())
                    }
                })
                .x_label_formatter(&|v| {
                    // Whole values of the unit; a fraction only when the ticks need one.
                    if (v - v.round()).abs() < 1e-9 * (x1 - x0) {
                        format!("{:.0}", v.round())
                    } else {
                        format!("{v:.1}")
                    }
                })
                .light_line_style(RGBColor(235, 235, 235))
                .draw()?;
            match trace {
                TimeTrace::Line(pts) => {
                    chart.draw_series(LineSeries::new(pts, ASD_COLOR.stroke_width(2)))?;
                }
                TimeTrace::Band(band) => {
                    // The band's outline: the maxima forward, the minima backward.
                    let outline: Vec<(f64, f64)> = band
                        .iter()
                        .map(|q| (q.0, q.2))
                        .chain(band.iter().rev().map(|q| (q.0, q.1)))
                        .collect();
                    chart.draw_series(std::iter::once(Polygon::new(
                        outline,
                        ASD_COLOR.mix(0.85).filled(),
                    )))?;
                }
            }
        }
        Ok(())
    }
}

/// Draws the time-series figure as a PNG or SVG file's bytes at the size and resolution of
/// `view` (its axes are the run's: the view's frequency and ASD limits do not apply).
///
/// # Errors
///
/// [`DrawError`] for any drawing failure.
pub fn time_series_figure(
    data: &TimeSeriesData,
    view: &View,
    format: ImageFormat,
) -> Result<Vec<u8>, DrawError> {
    view.render_resized(format, data)
}

#[cfg(test)]
mod time_figure_tests {
    use super::*;

    fn panel(values: Vec<f64>, dt_s: f64) -> TimePanel {
        TimePanel {
            title: "t".into(),
            observable: Observable::Phi,
            dt_s,
            t0_s: 0.0,
            values,
        }
    }

    #[test]
    fn long_series_become_a_band_that_keeps_every_extreme() {
        // An oscillation far faster than a pixel, with one spike in each direction.
        let n = 100 * MAX_COLUMNS;
        let mut values: Vec<f64> = (0..n)
            .map(|i| if i % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        values[12_345] = 5.0;
        values[300_001] = -7.0;
        let TimeTrace::Band(band) = decimate(&panel(values.clone(), 0.1)) else {
            panic!("a long series is drawn as a band");
        };
        assert_eq!(band.len(), MAX_COLUMNS / 2);
        let hi = band.iter().map(|b| b.2).fold(f64::NEG_INFINITY, f64::max);
        let lo = band.iter().map(|b| b.1).fold(f64::INFINITY, f64::min);
        assert_eq!((lo, hi), (-7.0, 5.0));
        assert!(
            band.windows(2).all(|w| w[0].0 < w[1].0),
            "bins in time order"
        );
        // Short series stay a line through every sample.
        let TimeTrace::Line(line) = decimate(&panel(values[..100].to_vec(), 0.1)) else {
            panic!("a short series is drawn as a line");
        };
        assert_eq!(line.len(), 100);
    }

    #[test]
    fn time_axes_read_in_seconds_hours_or_days() {
        assert_eq!(time_unit(3600.0), ("s", 1.0));
        assert_eq!(time_unit(12.0 * 3600.0), ("h", 3600.0));
        assert_eq!(time_unit(30.0 * 86_400.0), ("d", 86_400.0));
    }
}
