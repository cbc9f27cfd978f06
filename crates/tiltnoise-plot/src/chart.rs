//! Reusable line charts on a logarithmic frequency axis: panels of traces with legend, ticks and
//! grid, arranged in a grid with an optional title and caption. The y axis is logarithmic
//! (decade ticks) or, with [`YScale::Linear`], linear (phase, coherence).
//!
//! The data model is plain: a [`Trace`] is a label, `(x, y)` points and a [`TraceStyle`]; a
//! [`Band`] is a shaded area between two curves (e.g. a percentile band of a noise budget); a
//! [`Panel`] holds traces, an optional band, legend-only notes and axis labels with units; a
//! [`LogLogFigure`] arranges panels and implements [`Figure`] so that
//! [`render`](super::render) can draw it as PNG or SVG.
//!
//! Points with a non-finite or non-positive coordinate cannot be shown on log axes: the line is
//! broken there. Automatic axis ranges cover the finite positive data, the y range is padded to
//! whole decades and limited to [`Panel::max_decades`] below its top, and lines are clipped at
//! the frame (not flattened onto it).

use super::{DrawError, Figure, ImageFormat, FONT_FAMILY};
use plotters::coord::Shift;
use plotters::element::{Circle, DashedPathElement, DottedPathElement, PathElement, Polygon};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// Okabe-Ito colours, distinguishable with the common forms of colour blindness and in grey
/// scale print when combined with dash styles.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),   // blue
    RGBColor(213, 94, 0),    // vermillion
    RGBColor(0, 158, 115),   // bluish green
    RGBColor(204, 121, 167), // reddish purple
    RGBColor(230, 159, 0),   // orange
    RGBColor(86, 180, 233),  // sky blue
    RGBColor(0, 0, 0),       // black
];

/// Line pattern of a trace.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dash {
    /// Continuous line.
    Solid,
    /// Dashes about four line widths long.
    Dashed,
    /// Round dots.
    Dotted,
}

/// How a trace is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceStyle {
    /// Line colour.
    pub color: RGBColor,
    /// Line pattern.
    pub dash: Dash,
    /// Line width in pixels (>= 1).
    pub width: u32,
}

impl TraceStyle {
    /// A style from its parts.
    pub fn new(color: RGBColor, dash: Dash, width: u32) -> TraceStyle {
        TraceStyle {
            color,
            dash,
            width: width.max(1),
        }
    }
}

/// One curve of a panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// Legend text.
    pub label: String,
    /// `(x, y)` in axis units, ordered along the curve (usually by increasing x). Points with a
    /// non-finite or non-positive coordinate break the line.
    pub points: Vec<(f64, f64)>,
    /// Colour, pattern, width.
    pub style: TraceStyle,
    /// Which points the automatic y range must show (same length as `points`); `None`: all.
    /// A noise term, for instance, matters only where it contributes to the total.
    pub range_mask: Option<Vec<bool>>,
}

impl Trace {
    /// A trace from its parts; every point counts for the automatic y range.
    pub fn new(label: impl Into<String>, points: Vec<(f64, f64)>, style: TraceStyle) -> Trace {
        Trace {
            label: label.into(),
            points,
            style,
            range_mask: None,
        }
    }

    /// The points the automatic y range must show (all, or those of [`Trace::range_mask`]).
    fn range_points(&self) -> impl Iterator<Item = &(f64, f64)> {
        let mask = self.range_mask.as_deref();
        self.points
            .iter()
            .enumerate()
            .filter(move |(k, _)| mask.is_none_or(|m| m.get(*k).copied().unwrap_or(false)))
            .map(|(_, p)| p)
    }
}

/// A shaded area between two curves, drawn below all traces.
#[derive(Debug, Clone, PartialEq)]
pub struct Band {
    /// Legend text.
    pub label: String,
    /// Lower boundary `(x, y)`, increasing x. Values below the axis range (including zero and
    /// negative values) shade down to the bottom of the frame.
    pub lower: Vec<(f64, f64)>,
    /// Upper boundary `(x, y)`, increasing x; need not share the x values of `lower`.
    pub upper: Vec<(f64, f64)>,
    /// Fill colour.
    pub color: RGBColor,
    /// Fill opacity in `0..=1`.
    pub opacity: f64,
}

impl Band {
    /// A band in `color` at 25 % opacity.
    pub fn new(
        label: impl Into<String>,
        lower: Vec<(f64, f64)>,
        upper: Vec<(f64, f64)>,
        color: RGBColor,
    ) -> Band {
        Band {
            label: label.into(),
            lower,
            upper,
            color,
            opacity: 0.25,
        }
    }
}

/// Scale of a panel's y axis; the x axis is always logarithmic.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum YScale {
    /// Logarithmic, decade ticks (the default).
    #[default]
    Log,
    /// Linear (phase, coherence): ticks every `tick_step` (`None`: 1, 2 or 5 times a power of
    /// ten); the automatic range is the data extended to whole steps. Values need not be
    /// positive.
    Linear {
        /// Distance between ticks, in y units.
        tick_step: Option<f64>,
    },
}

/// One chart: logarithmic frequency axis, logarithmic or linear y axis.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Title above the frame.
    pub title: String,
    /// Quantity on the x axis, e.g. `frequency`.
    pub x_label: String,
    /// Unit of the x axis, e.g. `Hz`; shown as `frequency (Hz)`. Empty for dimensionless.
    pub x_unit: String,
    /// Quantity on the y axis, e.g. `|H|`.
    pub y_label: String,
    /// Unit of the y axis, e.g. `m/rad`.
    pub y_unit: String,
    /// Curves, drawn in order (later ones on top).
    pub traces: Vec<Trace>,
    /// Optional shaded band, drawn first.
    pub band: Option<Band>,
    /// Legend lines without a curve, e.g. `θₜ: identically 0`.
    pub notes: Vec<String>,
    /// Fixed x range; `None`: the extent of the finite positive data.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y range; `None`: the finite positive data padded to whole decades.
    pub y_range: Option<(f64, f64)>,
    /// With an automatic y range: at most this many decades below the top, so exact zeros,
    /// rounding noise or deep notches do not squash the curves. `None`: no limit.
    pub max_decades: Option<f64>,
    /// Where the legend goes.
    pub legend: LegendPlacement,
    /// Logarithmic (default) or linear y axis.
    pub y_scale: YScale,
}

impl Panel {
    /// An empty panel with at most 12 decades on the automatic y axis.
    pub fn new(
        title: impl Into<String>,
        (x_label, x_unit): (&str, &str),
        (y_label, y_unit): (&str, &str),
    ) -> Panel {
        Panel {
            title: title.into(),
            x_label: x_label.to_string(),
            x_unit: x_unit.to_string(),
            y_label: y_label.to_string(),
            y_unit: y_unit.to_string(),
            traces: Vec::new(),
            band: None,
            notes: Vec::new(),
            x_range: None,
            y_range: None,
            max_decades: Some(12.0),
            legend: LegendPlacement::Auto,
            y_scale: YScale::Log,
        }
    }

    /// The x range that will be drawn: [`Panel::x_range`] or the data extent.
    pub fn resolved_x_range(&self) -> (f64, f64) {
        if let Some(r) = self.x_range.filter(|r| valid_range(*r)) {
            return r;
        }
        let xs = self.all_points().map(|p| p.0).filter(|x| positive(*x));
        match min_max(xs) {
            Some((lo, hi)) if hi > lo => (lo, hi),
            Some((v, _)) => (v / 10.0, v * 10.0),
            None => (1.0, 10.0),
        }
    }

    /// The y range that will be drawn: [`Panel::y_range`] or the finite positive y values
    /// (within the x range) padded to whole decades and limited by [`Panel::max_decades`].
    pub fn resolved_y_range(&self) -> (f64, f64) {
        if let YScale::Linear { tick_step } = self.y_scale {
            if let Some((a, b)) = self.y_range.filter(|(a, b)| a.is_finite() && b > a) {
                return (a, b);
            }
            let (x0, x1) = self.resolved_x_range();
            let ys = self
                .all_points()
                .filter(|p| p.0 >= x0 && p.0 <= x1)
                .map(|p| p.1);
            return super::linear_axis::auto_range(ys, tick_step);
        }
        if let Some(r) = self.y_range.filter(|r| valid_range(*r)) {
            return r;
        }
        let curves: Vec<Vec<(f64, f64)>> = self
            .traces
            .iter()
            .map(|t| t.range_points().copied().collect())
            .collect();
        auto_log_range(
            curves.iter().map(Vec::as_slice),
            self.resolved_x_range(),
            self.max_decades,
        )
    }

    fn all_points(&self) -> impl Iterator<Item = &(f64, f64)> {
        let band = self
            .band
            .iter()
            .flat_map(|b| b.lower.iter().chain(b.upper.iter()));
        self.traces.iter().flat_map(|t| t.points.iter()).chain(band)
    }
}

/// Columns (in log x) over which the automatic y range takes its quantiles: the resolution of
/// a typical panel, so a curve counts by how much of the axis it covers, not by how many
/// points its grid puts there (a grid refined around a resonance does not make it weigh more).
pub const RANGE_COLUMNS: usize = 200;
/// Quantile of a curve's column maxima taken as its broadband top: a resonance covering fewer
/// than 5 % of the columns does not set it.
pub const TOP_QUANTILE: f64 = 0.95;
/// Quantile of a curve's column minima taken as its floor: notches covering fewer than 3 % of
/// the columns do not pull the axis down.
pub const BOTTOM_QUANTILE: f64 = 0.03;
/// Peaks are shown up to this many decades above the highest broadband top, clipped above.
pub const PEAK_HEADROOM_DECADES: f64 = 2.0;

/// The automatic range of a log y axis for `curves` over the x range `(x0, x1)`: from the
/// lowest floor of any curve ([`BOTTOM_QUANTILE`] of its minima per log-x column) to the
/// highest peak, but at most [`PEAK_HEADROOM_DECADES`] above the highest broadband top
/// ([`TOP_QUANTILE`] of a curve's maxima per column), padded by a tenth of a decade and
/// rounded out to whole decades; at most `max_decades` deep (counted from the top). Non-finite
/// and non-positive values are ignored; `(0.1, 10)` without data.
///
/// Every curve is thus visible over at least 97 % of the columns it occupies, and a resonance
/// peak is clipped at the top rather than pushing the floor down.
pub fn auto_log_range<'a>(
    curves: impl IntoIterator<Item = &'a [(f64, f64)]>,
    (x0, x1): (f64, f64),
    max_decades: Option<f64>,
) -> (f64, f64) {
    let (lx0, lx1) = (x0.log10(), x1.log10());
    let span = (lx1 - lx0).max(f64::MIN_POSITIVE);
    let (mut top_broad, mut peak, mut floor) =
        (f64::NEG_INFINITY, f64::NEG_INFINITY, f64::INFINITY);
    for curve in curves {
        let mut hi = vec![f64::NEG_INFINITY; RANGE_COLUMNS];
        let mut lo = vec![f64::INFINITY; RANGE_COLUMNS];
        for &(x, y) in curve {
            if !(positive(x) && positive(y) && x >= x0 && x <= x1) {
                continue;
            }
            let c = (((x.log10() - lx0) / span) * RANGE_COLUMNS as f64) as usize;
            let c = c.min(RANGE_COLUMNS - 1);
            let ly = y.log10();
            hi[c] = hi[c].max(ly);
            lo[c] = lo[c].min(ly);
        }
        let mut hi: Vec<f64> = hi.into_iter().filter(|v| v.is_finite()).collect();
        let mut lo: Vec<f64> = lo.into_iter().filter(|v| v.is_finite()).collect();
        if hi.is_empty() {
            continue;
        }
        hi.sort_by(f64::total_cmp);
        lo.sort_by(f64::total_cmp);
        top_broad = top_broad.max(quantile(&hi, TOP_QUANTILE));
        peak = peak.max(hi[hi.len() - 1]);
        floor = floor.min(quantile(&lo, BOTTOM_QUANTILE));
    }
    if !peak.is_finite() {
        return (0.1, 10.0);
    }
    let top = (peak.min(top_broad + PEAK_HEADROOM_DECADES) + 0.1).ceil();
    let mut bottom = (floor - 0.1).floor();
    if let Some(d) = max_decades.filter(|d| d.is_finite() && *d >= 1.0) {
        bottom = bottom.max(top - d.floor());
    }
    if bottom >= top {
        bottom = top - 1.0;
    }
    (10f64.powf(bottom), 10f64.powf(top))
}

/// The `q` quantile of sorted, non-empty `v` (nearest rank).
fn quantile(v: &[f64], q: f64) -> f64 {
    let k = (q * (v.len() - 1) as f64).round() as usize;
    v[k.min(v.len() - 1)]
}

/// Several panels in a grid, with an optional figure title and caption.
#[derive(Debug, Clone, PartialEq)]
pub struct LogLogFigure {
    /// Size in pixels.
    pub size: (u32, u32),
    /// Title across the top; `None` for none.
    pub title: Option<String>,
    /// Panels, filling the grid row by row.
    pub panels: Vec<Panel>,
    /// Number of grid columns (>= 1); rows follow from the number of cells needed.
    pub columns: usize,
    /// Caption paragraphs, word-wrapped. Drawn in the first free grid cell if there is one
    /// and it fits there, else in a strip below the grid.
    pub caption: Vec<String>,
    /// One legend for the whole figure (every distinct entry of the panels once) instead of
    /// one per panel: in the free grid cell above the caption if there is one, else in columns
    /// in a strip below the grid. No legend then covers a curve.
    pub shared_legend: bool,
}

impl LogLogFigure {
    /// A figure with one legend per panel.
    pub fn new(
        size: (u32, u32),
        title: Option<String>,
        panels: Vec<Panel>,
        columns: usize,
        caption: Vec<String>,
    ) -> LogLogFigure {
        LogLogFigure {
            size,
            title,
            panels,
            columns,
            caption,
            shared_legend: false,
        }
    }

    /// The same figure at `factor` times the pixel size: text scales with the size, line
    /// widths are multiplied here (at least 1 px), so the layout is unchanged.
    pub fn scaled(mut self, factor: f64) -> LogLogFigure {
        if !(factor.is_finite() && factor > 0.0) || factor == 1.0 {
            return self;
        }
        let px = |v: u32| ((v as f64 * factor).round() as u32).max(1);
        self.size = (px(self.size.0), px(self.size.1));
        for panel in &mut self.panels {
            for t in &mut panel.traces {
                t.style.width = px(t.style.width);
            }
        }
        self
    }

    /// Applies axis limits to every panel: `x` (Hz) to all, `y` to the panels with a log y
    /// axis (magnitudes, ASDs; not phase or coherence).
    pub fn with_limits(mut self, x: Option<(f64, f64)>, y: Option<(f64, f64)>) -> LogLogFigure {
        for panel in &mut self.panels {
            if x.is_some() {
                panel.x_range = x;
            }
            if y.is_some() && panel.y_scale == YScale::Log {
                panel.y_range = y;
            }
        }
        self
    }

    /// The distinct legend rows of all panels, in order of first appearance. A note that not
    /// every panel has names the panels it belongs to (the part of their titles before `:`).
    fn shared_rows(&self) -> Vec<(Sample, String)> {
        let mut rows: Vec<(Sample, String)> = Vec::new();
        for panel in &self.panels {
            for row in legend_rows(panel) {
                if !rows.iter().any(|r| r.1 == row.1) {
                    rows.push(row);
                }
            }
        }
        for (sample, text) in &mut rows {
            if !matches!(sample, Sample::None) {
                continue;
            }
            let owners: Vec<&str> = self
                .panels
                .iter()
                .filter(|p| p.notes.contains(text))
                .map(|p| p.title.split(':').next().unwrap_or(&p.title))
                .collect();
            if owners.len() < self.panels.len() {
                *text = format!("{text} ({})", owners.join(", "));
            }
        }
        rows
    }
}

impl Figure for LogLogFigure {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> Result<(), DrawError> {
        let (w, h) = root.dim_in_pixel();
        let ts = TextSizes::for_figure(w, h);
        let raster = format == ImageFormat::Png;
        let mut area = root.clone();
        if let Some(title) = &self.title {
            let (top, rest) = area.split_vertically((ts.title * 2.0).round() as u32);
            let style = text_style(ts.title, &BLACK).pos(Pos::new(HPos::Center, VPos::Center));
            let (tw, th) = top.dim_in_pixel();
            top.draw_text(title, &style, (tw as i32 / 2, th as i32 / 2))?;
            area = rest;
        }
        let columns = self.columns.max(1);
        let n = self.panels.len();
        let free_cell = n % columns != 0;
        let rows = (n + usize::from(free_cell)).div_ceil(columns).max(1);
        let margin = ts.caption * 1.5;
        let (aw, ah) = area.dim_in_pixel();
        let (cell_w, cell_h) = (aw as f64 / columns as f64, ah as f64 / rows as f64);
        let shared = if self.shared_legend {
            let width = if free_cell { cell_w } else { aw as f64 } - 2.0 * margin;
            LegendBox::measure_rows(&area, self.shared_rows(), ts.legend, Some(width))?
        } else {
            None
        };
        let legend_h = shared.as_ref().map_or(0.0, |lb| lb.height as f64 + margin);
        // The caption goes into the free cell only if it fits there (below the legend).
        let caption_in_cell = !self.caption.is_empty() && free_cell && {
            let lines = wrap_lines(&area, &self.caption, ts.caption, cell_w - 2.0 * margin)?;
            legend_h + caption_height(&lines, ts.caption) + 2.0 * margin <= cell_h
        };
        let legend_in_cell = shared.is_some() && free_cell;
        let mut strip_parts: Vec<f64> = Vec::new();
        if let (Some(lb), false) = (&shared, legend_in_cell) {
            strip_parts.push(lb.height as f64 + margin);
        }
        let mut caption_lines = 0;
        if !self.caption.is_empty() && !caption_in_cell {
            let lines = wrap_lines(&area, &self.caption, ts.caption, aw as f64 - 2.0 * margin)?;
            caption_lines = lines.len();
            strip_parts.push(caption_height(&lines, ts.caption) + 1.5 * margin);
        }
        if !strip_parts.is_empty() {
            let strip = strip_parts.iter().sum::<f64>().ceil() as u32;
            let (upper, lower) = area.split_vertically(ah.saturating_sub(strip));
            let mut rest = lower;
            if let (Some(lb), false) = (&shared, legend_in_cell) {
                lb.draw(&rest, (margin as i32, (margin * 0.5) as i32))?;
                let (_, below) = rest.split_vertically((lb.height as f64 + margin) as u32);
                rest = below;
            }
            if caption_lines > 0 {
                draw_caption(&rest, &self.caption, ts.caption, margin * 0.5)?;
            }
            area = upper;
        }
        let cells = area.split_evenly((rows, columns));
        for (panel, cell) in self.panels.iter().zip(cells.iter()) {
            if self.shared_legend {
                let mut quiet = panel.clone();
                quiet.legend = LegendPlacement::Hidden;
                draw_panel(cell, &quiet, &ts, raster)?;
            } else {
                draw_panel(cell, panel, &ts, raster)?;
            }
        }
        if free_cell {
            let mut cell = cells[n].clone();
            if let (Some(lb), true) = (&shared, legend_in_cell) {
                lb.draw(&cell, (margin as i32, margin as i32))?;
                let (_, below) = cell.split_vertically((lb.height as f64 + margin) as u32);
                cell = below;
            }
            if caption_in_cell {
                draw_caption(&cell, &self.caption, ts.caption, margin)?;
            }
        }
        Ok(())
    }
}

/// Text sizes in plotters units (about the pixel height of a line of text).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextSizes {
    /// Figure title.
    pub title: f64,
    /// Panel titles.
    pub panel_title: f64,
    /// Axis titles.
    pub axis: f64,
    /// Tick labels.
    pub ticks: f64,
    /// Legend entries.
    pub legend: f64,
    /// Caption text.
    pub caption: f64,
}

impl TextSizes {
    /// Sizes for a figure of `w` x `h` pixels: 17 px tick labels up to 1200 x 1000, scaled up
    /// for larger (high-resolution) figures and down to 75 % for small ones.
    pub fn for_figure(w: u32, h: u32) -> TextSizes {
        let s = (w as f64 / 1200.0).max(h as f64 / 1000.0).clamp(0.75, 4.0);
        TextSizes {
            title: 26.0 * s,
            panel_title: 20.0 * s,
            axis: 18.0 * s,
            ticks: 17.0 * s,
            legend: 16.0 * s,
            caption: 17.0 * s,
        }
    }
}

fn text_style(size: f64, color: &RGBColor) -> TextStyle<'static> {
    (FONT_FAMILY, size).into_font().color(color)
}

/// Where a panel's legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LegendPlacement {
    /// Inside the frame in the corner (or top/bottom centre) that hides the fewest curve
    /// pixels; outside on the right if every inside position would hide curves.
    #[default]
    Auto,
    /// Inside the frame at the least obstructive position, even if it hides curves.
    Inside,
    /// To the right of the frame, top-aligned (the frame gets narrower).
    OutsideRight,
    /// No legend.
    Hidden,
}

/// Size of a plotting rectangle; positions are relative to its top-left corner.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PlotRect {
    pub(crate) width: f64,
    pub(crate) height: f64,
}

impl PlotRect {
    /// Pixel position (relative to the plotting rectangle) of a data point.
    pub(crate) fn map(
        &self,
        (x, y): (f64, f64),
        (x0, x1): (f64, f64),
        (y0, y1): (f64, f64),
    ) -> (f64, f64) {
        let fx = (x.log10() - x0.log10()) / (x1.log10() - x0.log10());
        let fy = (y.log10() - y0.log10()) / (y1.log10() - y0.log10());
        (fx * (self.width - 1.0), (1.0 - fy) * (self.height - 1.0))
    }
}

/// Draws one panel into `area` (its whole extent: title, axes, frame, curves, legend); `raster`
/// when the figure is a bitmap (PNG), whose polylines are split where they turn back.
pub fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    ts: &TextSizes,
    raster: bool,
) -> Result<(), DrawError> {
    match panel.y_scale {
        YScale::Log => draw_log_panel(area, panel, ts, None, raster),
        YScale::Linear { tick_step } => {
            let (log, ticks) = linear_as_log(panel, panel.resolved_y_range(), tick_step);
            draw_log_panel(area, &log, ts, Some(ticks), raster)
        }
    }
}

/// [`draw_panel`] of a log-y panel; `linear_ticks` (positions on the log axis and their labels)
/// replace the decade ticks of a panel mapped from a linear one.
fn draw_log_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    ts: &TextSizes,
    linear_ticks: Option<Vec<(f64, String)>>,
    raster: bool,
) -> Result<(), DrawError> {
    let xr = panel.resolved_x_range();
    let yr = panel.resolved_y_range();
    let body = if panel.title.is_empty() {
        area.clone()
    } else {
        let spaced = area.margin((0.3 * ts.panel_title) as u32, 0, 0, 0);
        spaced.titled(&panel.title, text_style(ts.panel_title, &BLACK))?
    };
    let (w, h) = body.dim_in_pixel();
    let (w, h) = (w as f64, h as f64);

    let tick_style = text_style(ts.ticks, &BLACK);
    let axis_style = text_style(ts.axis, &BLACK);
    let text_h = |style: &TextStyle| -> Result<f64, DrawError> {
        Ok(body.estimate_text_size("10⁰", style)?.1 as f64)
    };
    let (tick_h, axis_h) = (text_h(&tick_style)?, text_h(&axis_style)?);
    const TICK: i32 = 5; // tick mark length; plotters puts labels 2 * TICK from the axis
    let x_label_area = (tick_h + 2.0 * TICK as f64 + 9.0 + axis_h + 4.0).ceil();
    let (m_top, m_bottom, m_left) = ((0.6 * tick_h).ceil(), 4.0, 4.0);
    let m_right = (1.4 * tick_h).ceil();
    let plot_h = (h - m_top - m_bottom - x_label_area).max(10.0);

    let y_ticks = match linear_ticks {
        Some(labelled) => labelled_ticks(labelled),
        None => decade_ticks(yr.0, yr.1, plot_h, 2.5 * tick_h),
    };
    let y_label_w = widest_label(&body, &y_ticks, &tick_style)?;
    let y_label_area = (y_label_w + 2.0 * TICK as f64 + 8.0 + axis_h + 2.0).ceil();

    // Curves in data space, clipped to the frame; bands as polygons.
    let lines = clipped_traces(panel, xr, yr);
    let band_outline = panel.band.as_ref().and_then(|b| band_outline(b, xr, yr));

    let legend = match panel.legend {
        LegendPlacement::Hidden => None,
        _ => LegendBox::measure(&body, panel, ts.legend)?,
    };
    let inside_rect = PlotRect {
        width: (w - m_left - y_label_area - m_right).max(10.0),
        height: plot_h,
    };
    let outside_w = outside_legend_width(
        legend.as_ref(),
        panel.legend,
        || Obstacles::new(&lines, &band_outline, &inside_rect, xr, yr),
        &inside_rect,
    );
    let outside = outside_w > 0.0;
    let rect = PlotRect {
        width: (inside_rect.width - outside_w).max(10.0),
        ..inside_rect
    };
    let x_unit = super::labels::si_unit(&panel.x_unit).then(|| panel.x_unit.clone());
    let x_ticks = Ticks {
        unit: x_unit.clone(),
        ..decade_ticks(
            xr.0,
            xr.1,
            rect.width,
            x_label_spacing(&body, xr, x_unit.as_deref(), &tick_style)?,
        )
    };

    let mut chart = ChartBuilder::on(&body)
        .margin_top(m_top as u32)
        .margin_bottom(m_bottom as u32)
        .margin_left(m_left as u32)
        .margin_right((m_right + outside_w) as u32)
        .x_label_area_size(x_label_area as u32)
        .y_label_area_size(y_label_area as u32)
        .build_cartesian_2d(
            (xr.0..xr.1)
                .log_scale()
                .with_key_points(x_ticks.major.clone())
                .with_light_points(x_ticks.minor.clone()),
            (yr.0..yr.1)
                .log_scale()
                .with_key_points(y_ticks.major.clone())
                .with_light_points(y_ticks.minor.clone()),
        )?;
    let x_fmt = |v: &f64| x_ticks.label(*v);
    let y_fmt = |v: &f64| y_ticks.label(*v);
    chart
        .configure_mesh()
        .bold_line_style(RGBColor(205, 205, 205).stroke_width(1))
        .light_line_style(RGBColor(236, 236, 236).stroke_width(1))
        .axis_style(BLACK.stroke_width(1))
        .set_all_tick_mark_size(TICK)
        .label_style(tick_style.clone())
        .axis_desc_style(axis_style.clone())
        // Ticks that carry the unit (`1 mHz`) leave it out of the axis title.
        .x_desc(match x_unit {
            Some(_) => panel.x_label.clone(),
            None => axis_title(&panel.x_label, &panel.x_unit),
        })
        .y_desc(axis_title(&panel.y_label, &panel.y_unit))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .draw()?;

    let data = PanelData {
        lines: &lines,
        band: panel.band.as_ref().zip(band_outline.as_ref()),
        rect: &rect,
        xr,
        yr,
        raster,
    };
    draw_data(&mut chart, &data)?;

    // Close the frame: plotters draws only the left and bottom axes.
    let plot = chart.plotting_area();
    let (px, py) = plot.get_pixel_range();
    let frame = plot.strip_coord_spec();
    let (fw, fh) = frame.dim_in_pixel();
    let (fw, fh) = (fw as i32, fh as i32);
    frame.draw(&PathElement::new(
        vec![(0, 0), (fw - 1, 0), (fw - 1, fh - 1)],
        BLACK.stroke_width(1),
    ))?;

    match legend {
        Some(lb) if outside => {
            let (bx, by) = body.get_base_pixel();
            lb.draw(&body, (px.end - bx + 12, py.start - by))
        }
        Some(lb) => {
            let actual = PlotRect {
                width: fw as f64,
                height: fh as f64,
            };
            let obstacles = Obstacles::new(&lines, &band_outline, &actual, xr, yr);
            lb.draw(&frame, lb.best_inside(&actual, &obstacles).0)
        }
        None => Ok(()),
    }
}

/// The width the legend takes to the right of the frame (pixels), 0 when it goes inside or
/// there is none: outside always when asked, never when hidden or inside, and with
/// [`LegendPlacement::Auto`] when the best place inside hides too much of the `obstacles`
/// ([`AUTO_INSIDE_MAX_COST`]).
fn outside_legend_width(
    legend: Option<&LegendBox>,
    placement: LegendPlacement,
    obstacles: impl FnOnce() -> Obstacles,
    inside: &PlotRect,
) -> f64 {
    let outside = legend.is_some_and(|lb| match placement {
        LegendPlacement::OutsideRight => true,
        LegendPlacement::Auto => lb.best_inside(inside, &obstacles()).1 > AUTO_INSIDE_MAX_COST,
        _ => false,
    });
    match legend {
        Some(lb) if outside => lb.width as f64 + 12.0,
        _ => 0.0,
    }
}

/// The width (pixels) of the widest major tick label of `ticks`.
fn widest_label<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    ticks: &Ticks,
    style: &TextStyle,
) -> Result<f64, DrawError> {
    let mut widest: f64 = 0.0;
    for v in &ticks.major {
        widest = widest.max(area.estimate_text_size(&ticks.label(*v), style)?.0 as f64);
    }
    Ok(widest)
}

/// The panel's curves clipped to the frame `xr` x `yr` (log-log), each piece with its style.
fn clipped_traces(
    panel: &Panel,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Vec<(Vec<(f64, f64)>, TraceStyle)> {
    panel
        .traces
        .iter()
        .flat_map(|t| {
            clip_loglog(&t.points, xr, yr)
                .into_iter()
                .map(|l| (l, t.style))
        })
        .collect()
}

/// Ticks at given positions of a log axis, with their labels (a panel mapped from linear).
fn labelled_ticks(labelled: Vec<(f64, String)>) -> Ticks {
    Ticks {
        major: labelled.iter().map(|t| t.0).collect(),
        minor: Vec::new(),
        step: 1,
        anchor: 0,
        labels: labelled,
        unit: None,
    }
}

/// A band's upper and lower edge, in data space.
type Outline = (Vec<(f64, f64)>, Vec<(f64, f64)>);

/// What a log-log panel draws inside its frame, in data space.
struct PanelData<'a> {
    /// Curves clipped to the frame, with their styles.
    lines: &'a [(Vec<(f64, f64)>, TraceStyle)],
    /// The band and its outline (upper edge, lower edge), if there is one.
    band: Option<(&'a Band, &'a Outline)>,
    /// The frame in pixels.
    rect: &'a PlotRect,
    xr: (f64, f64),
    yr: (f64, f64),
    /// A bitmap (PNG): polylines are split at reversals (see [`split_at_reversals`]).
    raster: bool,
}

/// The band, then the curves, each reduced to the pixel grid.
fn draw_data<DB: DrawingBackend, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    d: &PanelData<'_>,
) -> Result<(), DrawError>
where
    X: plotters::coord::ranged1d::Ranged<ValueType = f64>,
    Y: plotters::coord::ranged1d::Ranged<ValueType = f64>,
{
    if let Some((band, (upper, lower))) = d.band {
        let fill = band.color.mix(band.opacity.clamp(0.0, 1.0)).filled();
        // Both edges reduced to the pixel grid, as the curves are.
        let (upper, lower) = (
            decimate(upper, d.rect, d.xr, d.yr),
            decimate(lower, d.rect, d.xr, d.yr),
        );
        let poly: Vec<_> = upper.iter().chain(lower.iter().rev()).copied().collect();
        chart.draw_series(std::iter::once(Polygon::new(poly, fill)))?;
    }
    for (line, style) in d.lines {
        let line = decimate(line, d.rect, d.xr, d.yr);
        if d.raster {
            for run in split_at_reversals(&line, d.rect, d.xr, d.yr) {
                draw_polyline(chart, run, *style)?;
            }
        } else {
            draw_polyline(chart, line, *style)?;
        }
    }
    Ok(())
}

/// With [`LegendPlacement::Auto`], the legend goes inside only if it hides at most this much
/// (about one pixel of curve per unit, band area counts 1 % per pixel).
const AUTO_INSIDE_MAX_COST: f64 = 12.0;

/// Minimum distance between x tick labels: the widest label (with `unit`: SI-prefixed) plus a
/// gap.
fn x_label_spacing<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
    unit: Option<&str>,
    style: &TextStyle,
) -> Result<f64, DrawError> {
    let mut widest: f64 = 0.0;
    let (e0, e1) = (x0.log10().floor() as i32, x1.log10().ceil() as i32);
    for e in e0..=e1 {
        let label = match unit {
            Some(u) => super::labels::si_value(10f64.powi(e), u),
            None => pow10_label(e),
        };
        widest = widest.max(area.estimate_text_size(&label, style)?.0 as f64);
    }
    Ok(widest + style.font.get_size() * 1.2)
}

fn axis_title(label: &str, unit: &str) -> String {
    if unit.is_empty() {
        label.to_string()
    } else {
        format!("{label} ({unit})")
    }
}

fn draw_polyline<DB: DrawingBackend, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    line: Vec<(f64, f64)>,
    style: TraceStyle,
) -> Result<(), DrawError>
where
    X: plotters::coord::ranged1d::Ranged<ValueType = f64>,
    Y: plotters::coord::ranged1d::Ranged<ValueType = f64>,
{
    let w = style.width.max(1);
    let shape = style.color.stroke_width(w);
    match style.dash {
        Dash::Solid => {
            chart.draw_series(std::iter::once(PathElement::new(line, shape)))?;
        }
        Dash::Dashed => {
            let (dash, gap) = dash_pattern(w);
            chart.draw_series(std::iter::once(DashedPathElement::new(
                line, dash, gap, shape,
            )))?;
        }
        Dash::Dotted => {
            let (radius, spacing) = dot_pattern(w);
            let color = style.color;
            chart.draw_series(std::iter::once(DottedPathElement::new(
                line,
                0,
                spacing,
                move |c| Circle::new(c, radius, color.filled()),
            )))?;
        }
    }
    Ok(())
}

/// Dash length and gap (px) for a line width.
fn dash_pattern(width: u32) -> (i32, i32) {
    let w = width as i32;
    (5 * w + 4, 3 * w + 3)
}

/// Dot radius and spacing (px) for a line width.
fn dot_pattern(width: u32) -> (i32, i32) {
    let w = width as i32;
    ((w + 2) / 2, 3 * w + 3)
}

/// Decade tick positions of a log axis and which of them carry a label.
#[derive(Debug, Clone, PartialEq)]
struct Ticks {
    /// Decades inside the range (grid lines and tick marks).
    major: Vec<f64>,
    /// 2..9 times each decade, when there is room for them (light grid lines).
    minor: Vec<f64>,
    /// Label every `step`-th decade: exponents `e` with `e - anchor` divisible by `step`.
    step: i32,
    /// See `step`: 0 (exponents divisible by `step`, `10⁻⁶, 10⁻⁴, ...`) unless that labels
    /// fewer decades of the range than starting at its first decade does.
    anchor: i32,
    /// Explicit labels of a linear axis mapped onto a log one: `(position, text)`.
    labels: Vec<(f64, String)>,
    /// Unit written on every label with an SI prefix (`1 mHz`); `None`: powers of ten (`10⁻³`).
    unit: Option<String>,
}

impl Ticks {
    fn label(&self, v: f64) -> String {
        if !self.labels.is_empty() {
            return self
                .labels
                .iter()
                .find(|(p, _)| (p - v).abs() <= 1e-9 * p.abs())
                .map(|(_, text)| text.clone())
                .unwrap_or_default();
        }
        let e = v.log10().round() as i32;
        if (e - self.anchor).rem_euclid(self.step) == 0 {
            match &self.unit {
                Some(unit) => super::labels::si_value(10f64.powi(e), unit),
                None => pow10_label(e),
            }
        } else {
            String::new()
        }
    }
}

/// Ticks for `[lo, hi]` on an axis `pixels` long, labels at least `min_spacing` px apart.
fn decade_ticks(lo: f64, hi: f64, pixels: f64, min_spacing: f64) -> Ticks {
    let (e0, e1) = (lo.log10(), hi.log10());
    let first = (e0 - 1e-9).ceil() as i32;
    let last = (e1 + 1e-9).floor() as i32;
    let major: Vec<f64> = (first..=last).map(|e| 10f64.powi(e)).collect();
    let per_decade = pixels.max(1.0) / (e1 - e0).max(1e-9);
    let step = (1..=12)
        .find(|&k| per_decade * k as f64 >= min_spacing)
        .unwrap_or(12);
    // Divisible exponents when they label as many decades as possible, else from the first
    // (three decades with every second labelled: 1 mHz and 100 mHz rather than 10 mHz alone).
    let divisible = (first..=last).filter(|e| e.rem_euclid(step) == 0).count() as i32;
    let most = if last >= first {
        (last - first) / step + 1
    } else {
        0
    };
    let anchor = if divisible >= most { 0 } else { first };
    let mut minor = Vec::new();
    if per_decade >= 45.0 {
        for e in (first - 1)..=last {
            for m in 2..=9 {
                let v = m as f64 * 10f64.powi(e);
                if v > lo && v < hi {
                    minor.push(v);
                }
            }
        }
    }
    Ticks {
        major,
        minor,
        step,
        anchor,
        labels: Vec::new(),
        unit: None,
    }
}

/// `10ⁿ` with a Unicode superscript exponent (`10⁻⁴`, `10⁰`, `10¹`).
pub fn pow10_label(exponent: i32) -> String {
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::from("10");
    if exponent < 0 {
        s.push('⁻');
    }
    for d in exponent.unsigned_abs().to_string().bytes() {
        s.push(SUP[(d - b'0') as usize]);
    }
    s
}

fn positive(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

fn valid_range((a, b): (f64, f64)) -> bool {
    positive(a) && positive(b) && b > a
}

fn min_max(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Splits `points` into polylines that lie inside `[x0, x1] x [y0, y1]`, in log-log space:
/// points with a non-finite or non-positive coordinate break the line, segments leaving the box
/// are cut at its edge (interpolated in log coordinates).
pub fn clip_loglog(
    points: &[(f64, f64)],
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let bx = (x0.log10(), x1.log10());
    let by = (y0.log10(), y1.log10());
    let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let mut prev: Option<(f64, f64)> = None;
    let flush = |current: &mut Vec<(f64, f64)>, out: &mut Vec<Vec<(f64, f64)>>| {
        if current.len() >= 2 {
            out.push(std::mem::take(current));
        } else {
            current.clear();
        }
    };
    for &(x, y) in points {
        if !(positive(x) && positive(y)) {
            flush(&mut current, &mut out);
            prev = None;
            continue;
        }
        let p = (x.log10(), y.log10());
        if let Some(q) = prev {
            match clip_segment(q, p, bx, by) {
                Some((a, b, entered, left)) => {
                    if entered || current.is_empty() {
                        flush(&mut current, &mut out);
                        current.push(a);
                    }
                    current.push(b);
                    if left {
                        flush(&mut current, &mut out);
                    }
                }
                None => flush(&mut current, &mut out),
            }
        }
        prev = Some(p);
    }
    flush(&mut current, &mut out);
    out.into_iter()
        .map(|l| {
            l.into_iter()
                .map(|(lx, ly)| (10f64.powf(lx), 10f64.powf(ly)))
                .collect()
        })
        .collect()
}

/// Liang-Barsky: the part of segment `p -> q` inside the box, with flags "start was cut" and
/// "end was cut".
#[allow(clippy::type_complexity)]
fn clip_segment(
    p: (f64, f64),
    q: (f64, f64),
    (xa, xb): (f64, f64),
    (ya, yb): (f64, f64),
) -> Option<((f64, f64), (f64, f64), bool, bool)> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let mut t0: f64 = 0.0;
    let mut t1: f64 = 1.0;
    for (den, num) in [
        (-dx, p.0 - xa),
        (dx, xb - p.0),
        (-dy, p.1 - ya),
        (dy, yb - p.1),
    ] {
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let a = (p.0 + t0 * dx, p.1 + t0 * dy);
    let b = (p.0 + t1 * dx, p.1 + t1 * dy);
    Some((a, b, t0 > 0.0, t1 < 1.0))
}

/// A band's boundaries clamped into the axis range (non-positive lower values shade to the
/// bottom), NaN points dropped: `(upper, lower)`, both by increasing x. `None` if either has
/// fewer than two points.
#[allow(clippy::type_complexity)]
fn band_outline(band: &Band, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> Option<Outline> {
    let clamp = |&(x, y): &(f64, f64)| -> Option<(f64, f64)> {
        if x.is_nan() || y.is_nan() || x <= 0.0 {
            return None;
        }
        let y = if y > 0.0 { y } else { y0 };
        Some((x.clamp(x0, x1), y.clamp(y0, y1)))
    };
    let upper: Vec<_> = band.upper.iter().filter_map(clamp).collect();
    let lower: Vec<_> = band.lower.iter().filter_map(clamp).collect();
    (upper.len() >= 2 && lower.len() >= 2).then_some((upper, lower))
}

/// What hides behind a legend: curve pixels (sampled every ~2 px) and per pixel column the
/// vertical extent of the band, in plotting-rectangle pixels.
struct Obstacles {
    curve: Vec<(f64, f64)>,
    band: Vec<Option<(f64, f64)>>,
}

impl Obstacles {
    #[allow(clippy::type_complexity)]
    fn new(
        lines: &[(Vec<(f64, f64)>, TraceStyle)],
        band: &Option<(Vec<(f64, f64)>, Vec<(f64, f64)>)>,
        rect: &PlotRect,
        xr: (f64, f64),
        yr: (f64, f64),
    ) -> Obstacles {
        let mut curve = Vec::new();
        for (line, style) in lines {
            let px: Vec<_> = line.iter().map(|&p| rect.map(p, xr, yr)).collect();
            // A thick line hides more: count it once per pixel of width.
            let weight = style.width.max(1) as usize;
            for s in px.windows(2) {
                let (a, b) = (s[0], s[1]);
                let steps = ((b.0 - a.0).hypot(b.1 - a.1) / 2.0).ceil().max(1.0) as usize;
                for k in 0..steps {
                    let t = k as f64 / steps as f64;
                    let p = (a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1));
                    curve.extend(std::iter::repeat_n(p, weight));
                }
            }
        }
        let columns = rect.width.max(1.0) as usize;
        let mut band_cols = vec![None; columns];
        if let Some((upper, lower)) = band {
            let up = column_profile(upper, rect, xr, yr, columns);
            let lo = column_profile(lower, rect, xr, yr, columns);
            for (c, slot) in band_cols.iter_mut().enumerate() {
                if let (Some(a), Some(b)) = (up[c], lo[c]) {
                    *slot = Some((a.min(b), a.max(b)));
                }
            }
        }
        Obstacles {
            curve,
            band: band_cols,
        }
    }

    /// Cost of covering the box `[x, x + w] x [y, y + h]` (3 px clearance around it).
    fn cost(&self, (x, y): (f64, f64), (w, h): (f64, f64)) -> f64 {
        let (x0, x1, y0, y1) = (x - 3.0, x + w + 3.0, y - 3.0, y + h + 3.0);
        let curve = self
            .curve
            .iter()
            .filter(|p| p.0 >= x0 && p.0 <= x1 && p.1 >= y0 && p.1 <= y1)
            .count() as f64;
        let mut band = 0.0;
        let c0 = x0.max(0.0) as usize;
        let c1 = (x1.max(0.0) as usize).min(self.band.len());
        for (top, bottom) in self.band[c0.min(c1)..c1].iter().flatten() {
            band += (bottom.min(y1) - top.max(y0)).max(0.0);
        }
        curve + 0.01 * band
    }
}

/// y pixel of a polyline at each pixel column (linear interpolation), `None` outside it.
fn column_profile(
    line: &[(f64, f64)],
    rect: &PlotRect,
    xr: (f64, f64),
    yr: (f64, f64),
    columns: usize,
) -> Vec<Option<f64>> {
    let mut out = vec![None; columns];
    let px: Vec<_> = line.iter().map(|&p| rect.map(p, xr, yr)).collect();
    for s in px.windows(2) {
        let (a, b) = if s[0].0 <= s[1].0 {
            (s[0], s[1])
        } else {
            (s[1], s[0])
        };
        let c0 = a.0.ceil().max(0.0) as usize;
        let c1 = (b.0.floor().max(0.0) as usize).min(columns.saturating_sub(1));
        for (c, slot) in out.iter_mut().enumerate().take(c1 + 1).skip(c0) {
            let t = if b.0 > a.0 {
                (c as f64 - a.0) / (b.0 - a.0)
            } else {
                0.0
            };
            *slot = Some(a.1 + t * (b.1 - a.1));
        }
    }
    out
}

/// Reduces a polyline to the pixel grid: within each pixel column it keeps the first and last
/// point and the points of least and greatest y, in their original order, so every peak and
/// notch keeps its full height while a curve costs at most four vertices per column (SVG files
/// stay small, PNG lines rasterise without integer-rounding zigzags).
pub(crate) fn decimate(
    line: &[(f64, f64)],
    rect: &PlotRect,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(line.len().min(4 * rect.width as usize + 4));
    let mut k = 0;
    while k < line.len() {
        let column = rect.map(line[k], xr, yr).0.floor();
        let start = k;
        let (mut lo, mut hi) = (k, k);
        while k < line.len() && rect.map(line[k], xr, yr).0.floor() == column {
            // Pixel y grows downwards: the least pixel y is the greatest value.
            if line[k].1 < line[lo].1 {
                lo = k;
            }
            if line[k].1 > line[hi].1 {
                hi = k;
            }
            k += 1;
        }
        if k == start {
            // A point without a pixel column (non-finite; clipping removes those): kept as is.
            out.push(line[k]);
            k += 1;
            continue;
        }
        let mut keep = [start, lo, hi, k - 1];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for i in keep {
            if i != last {
                out.push(line[i]);
                last = i;
            }
        }
    }
    out
}

// Vector output never splits a polyline at reversals: SVG viewers limit miters themselves
// (stroke-miterlimit 4), and a noisy curve stays one element instead of thousands. Raster
// output splits at every reversal (the bitmap backend draws unlimited miters: spikes above a
// noisy thick line, capped undamped peaks).
/// Cuts a polyline where it turns back on itself by more than 90 degrees in pixel space (the two
/// sides of a resonance peak drawn in one pixel column): a thick plotters path joins such a
/// U-turn with a degenerate miter and drops the segments around it, so an undamped peak would
/// look capped far below its height. Consecutive runs share the turning vertex.
fn split_at_reversals(
    line: &[(f64, f64)],
    rect: &PlotRect,
    xr: (f64, f64),
    yr: (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let px: Vec<(f64, f64)> = line.iter().map(|&p| rect.map(p, xr, yr)).collect();
    let mut runs = Vec::new();
    let mut current: Vec<(f64, f64)> = line.iter().take(1).copied().collect();
    for k in 1..line.len() {
        if k >= 2 {
            let a = (px[k - 1].0 - px[k - 2].0, px[k - 1].1 - px[k - 2].1);
            let b = (px[k].0 - px[k - 1].0, px[k].1 - px[k - 1].1);
            if a.0 * b.0 + a.1 * b.1 < 0.0 {
                runs.push(std::mem::replace(&mut current, vec![line[k - 1]]));
            }
        }
        current.push(line[k]);
    }
    if current.len() >= 2 {
        runs.push(current);
    }
    runs
}

/// Legend rows: a sample (line, band swatch or nothing) and text.
enum Sample {
    Line(TraceStyle),
    Swatch(RGBColor, f64),
    None,
}

/// A measured legend, its rows in `columns` columns (filled column by column).
struct LegendBox {
    rows: Vec<(Sample, String)>,
    font: f64,
    width: i32,
    height: i32,
    pad: i32,
    sample_len: i32,
    row_h: i32,
    text_x: i32,
    /// Width of one column (sample, text, gap).
    column_w: i32,
    columns: usize,
}

/// Legend rows of a panel: its traces, band and notes.
fn legend_rows(panel: &Panel) -> Vec<(Sample, String)> {
    let mut rows: Vec<(Sample, String)> = Vec::new();
    for t in &panel.traces {
        rows.push((Sample::Line(t.style), t.label.clone()));
    }
    if let Some(b) = &panel.band {
        rows.push((Sample::Swatch(b.color, b.opacity), b.label.clone()));
    }
    for n in &panel.notes {
        rows.push((Sample::None, n.clone()));
    }
    rows
}

impl LegendBox {
    /// Rows for the panel's traces, band and notes; `None` if there is nothing to list.
    fn measure<DB: DrawingBackend>(
        area: &DrawingArea<DB, Shift>,
        panel: &Panel,
        font: f64,
    ) -> Result<Option<LegendBox>, DrawError> {
        LegendBox::measure_rows(area, legend_rows(panel), font, None)
    }

    /// A legend of `rows`, in as many columns as fit in `max_width` pixels (one without).
    fn measure_rows<DB: DrawingBackend>(
        area: &DrawingArea<DB, Shift>,
        rows: Vec<(Sample, String)>,
        font: f64,
        max_width: Option<f64>,
    ) -> Result<Option<LegendBox>, DrawError> {
        if rows.is_empty() {
            return Ok(None);
        }
        let style = text_style(font, &BLACK);
        let pad = (font * 0.5).round() as i32;
        let sample_len = (font * 2.4).round() as i32;
        let row_h = (font * 1.3).round() as i32;
        let has_samples = rows.iter().any(|r| !matches!(r.0, Sample::None));
        let text_x = pad + if has_samples { sample_len + pad } else { 0 };
        let mut text_w = 0;
        for (_, text) in &rows {
            text_w = text_w.max(area.estimate_text_size(text, &style)?.0 as i32);
        }
        let column_w = text_x + text_w + 2 * pad;
        let columns = match max_width {
            Some(w) => ((w as i32 - pad) / column_w.max(1)).clamp(1, rows.len() as i32) as usize,
            None => 1,
        };
        let per_column = rows.len().div_ceil(columns);
        Ok(Some(LegendBox {
            width: column_w * columns as i32 - pad + 2,
            height: 2 * pad + row_h * per_column as i32 - pad / 2,
            rows,
            font,
            pad,
            sample_len,
            row_h,
            text_x,
            column_w,
            columns,
        }))
    }

    /// The least obstructive inside position (top-left corner, plotting-rectangle pixels) and
    /// its cost; ties go to the earlier of upper right, upper left, lower left, lower right,
    /// upper centre, lower centre.
    fn best_inside(&self, rect: &PlotRect, obstacles: &Obstacles) -> ((i32, i32), f64) {
        let (fw, fh) = (rect.width as i32, rect.height as i32);
        let (bw, bh) = (self.width, self.height);
        let m = 8;
        let candidates = [
            (fw - m - bw, m),
            (m, m),
            (m, fh - m - bh),
            (fw - m - bw, fh - m - bh),
            ((fw - bw) / 2, m),
            ((fw - bw) / 2, fh - m - bh),
        ];
        let mut best = (candidates[0], f64::INFINITY);
        for c in candidates {
            let cost = obstacles.cost((c.0 as f64, c.1 as f64), (bw as f64, bh as f64));
            if cost < best.1 {
                best = (c, cost);
            }
        }
        best
    }

    /// Draws the legend with its top-left corner at `(bx, by)` of `area`.
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        (bx, by): (i32, i32),
    ) -> Result<(), DrawError> {
        let corners = [(bx, by), (bx + self.width, by + self.height)];
        area.draw(&Rectangle::new(corners, WHITE.mix(0.9).filled()))?;
        area.draw(&Rectangle::new(
            corners,
            RGBColor(160, 160, 160).stroke_width(1),
        ))?;
        let style = text_style(self.font, &BLACK).pos(Pos::new(HPos::Left, VPos::Center));
        let note_style =
            text_style(self.font, &RGBColor(85, 85, 85)).pos(Pos::new(HPos::Left, VPos::Center));
        let per_column = self.rows.len().div_ceil(self.columns.max(1));
        for (i, (sample, text)) in self.rows.iter().enumerate() {
            let (col, row) = ((i / per_column) as i32, (i % per_column) as i32);
            let cx = bx + col * self.column_w;
            let cy = by + self.pad + self.row_h * row + self.row_h / 2;
            let sx = cx + self.pad;
            let len = self.sample_len;
            match sample {
                Sample::Line(s) => {
                    let pts = vec![(sx, cy), (sx + len, cy)];
                    let w = s.width.max(1);
                    let shape = s.color.stroke_width(w);
                    match s.dash {
                        Dash::Solid => area.draw(&PathElement::new(pts, shape))?,
                        Dash::Dashed => {
                            // Shorter dashes so that at least two show in the sample.
                            let (d, g) = dash_pattern(w);
                            area.draw(&DashedPathElement::new(
                                pts,
                                d.min(len * 2 / 5),
                                g.min(len / 5),
                                shape,
                            ))?
                        }
                        Dash::Dotted => {
                            let (r, sp) = dot_pattern(w);
                            let color = s.color;
                            area.draw(&DottedPathElement::new(pts, 0, sp, move |c| {
                                Circle::new(c, r, color.filled())
                            }))?
                        }
                    }
                }
                Sample::Swatch(color, opacity) => {
                    let hh = self.row_h / 3;
                    area.draw(&Rectangle::new(
                        [(sx, cy - hh), (sx + len, cy + hh)],
                        color.mix(opacity.clamp(0.0, 1.0)).filled(),
                    ))?;
                }
                Sample::None => {}
            }
            let st = if matches!(sample, Sample::None) {
                &note_style
            } else {
                &style
            };
            area.draw_text(text, st, (cx + self.text_x, cy))?;
        }
        Ok(())
    }
}

/// Word-wraps paragraphs to `width` pixels; an empty line separates paragraphs.
fn wrap_lines<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    paragraphs: &[String],
    fs: f64,
    width: f64,
) -> Result<Vec<String>, DrawError> {
    let style = text_style(fs, &BLACK);
    let mut lines = Vec::new();
    for (i, para) in paragraphs.iter().enumerate() {
        if i > 0 {
            lines.push(String::new());
        }
        let mut line = String::new();
        for word in para.split_whitespace() {
            let candidate = if line.is_empty() {
                word.to_string()
            } else {
                format!("{line} {word}")
            };
            if !line.is_empty() && area.estimate_text_size(&candidate, &style)?.0 as f64 > width {
                lines.push(std::mem::replace(&mut line, word.to_string()));
            } else {
                line = candidate;
            }
        }
        lines.push(line);
    }
    Ok(lines)
}

/// Caption text, word-wrapped, top-left aligned with `margin` pixels all round.
fn draw_caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    paragraphs: &[String],
    fs: f64,
    margin: f64,
) -> Result<(), DrawError> {
    let (w, _) = area.dim_in_pixel();
    let lines = wrap_lines(area, paragraphs, fs, w as f64 - 2.0 * margin)?;
    let style = text_style(fs, &BLACK).pos(Pos::new(HPos::Left, VPos::Top));
    let mut y = margin;
    for line in &lines {
        if !line.is_empty() {
            area.draw_text(line, &style, (margin as i32, y as i32))?;
        }
        y += line_advance(line, fs);
    }
    Ok(())
}

/// Distance between the tops of two caption lines, in units of the font size.
const CAPTION_LINE_SPACING: f64 = 1.3;
/// Extra space between caption paragraphs (the empty line [`wrap_lines`] puts between them),
/// in units of the font size.
const CAPTION_PARAGRAPH_GAP: f64 = 0.45;

/// Vertical advance after a caption line: a text line's spacing, or the paragraph gap for the
/// empty separator line.
fn line_advance(line: &str, fs: f64) -> f64 {
    fs * if line.is_empty() {
        CAPTION_PARAGRAPH_GAP
    } else {
        CAPTION_LINE_SPACING
    }
}

/// Height of wrapped caption `lines` (as [`draw_caption`] sets them), in pixels.
fn caption_height(lines: &[String], fs: f64) -> f64 {
    lines.iter().map(|l| line_advance(l, fs)).sum()
}

/// `panel` (linear y over `(y0, y1)`) as a log-y panel of `10^((y - y0) / (y1 - y0))` over
/// `(1, 10)`, and its ticks `(position on the log axis, label)`.
fn linear_as_log(
    panel: &Panel,
    (y0, y1): (f64, f64),
    step: Option<f64>,
) -> (Panel, Vec<(f64, String)>) {
    let map = |y: f64| 10f64.powf((y - y0) / (y1 - y0));
    let points =
        |p: &[(f64, f64)]| -> Vec<(f64, f64)> { p.iter().map(|&(x, y)| (x, map(y))).collect() };
    let mut log = panel.clone();
    log.y_scale = YScale::Log;
    log.y_range = Some((1.0, 10.0));
    log.max_decades = None;
    log.traces = panel
        .traces
        .iter()
        .map(|t| Trace::new(t.label.clone(), points(&t.points), t.style))
        .collect();
    log.band = panel.band.as_ref().map(|b| Band {
        lower: points(&b.lower),
        upper: points(&b.upper),
        ..b.clone()
    });
    let ticks = super::linear_axis::ticks(y0, y1, step)
        .into_iter()
        .map(|(v, label)| (map(v), label))
        .collect();
    (log, ticks)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pow10_labels() {
        assert_eq!(pow10_label(-4), "10⁻⁴");
        assert_eq!(pow10_label(0), "10⁰");
        assert_eq!(pow10_label(12), "10¹²");
    }

    #[test]
    fn clip_breaks_at_invalid_and_cuts_at_box() {
        let pts = vec![
            (1.0, 1.0),
            (2.0, 2.0),
            (3.0, f64::NAN),
            (4.0, 1.0),
            (5.0, 0.0),
            (6.0, 1.0),
            (7.0, 1e-30),
            (8.0, 1.0),
        ];
        let lines = clip_loglog(&pts, (0.5, 10.0), (1e-3, 10.0));
        // [1,2] | [4] dropped (single point) | [6 -> cut at 1e-3] | [cut -> 8]
        assert_eq!(lines.len(), 3);
        assert_eq!(lines[0].len(), 2);
        let last_of_second = *lines[1].last().unwrap();
        assert!((last_of_second.1 - 1e-3).abs() < 1e-12);
        let first_of_third = lines[2][0];
        assert!((first_of_third.1 - 1e-3).abs() < 1e-12);
        assert!((lines[2][1].0 - 8.0).abs() < 1e-12);
    }

    #[test]
    fn reversals_split_peaks_and_keep_monotone_lines_whole() {
        let rect = PlotRect {
            width: 500.0,
            height: 300.0,
        };
        let (xr, yr) = ((1e-3, 2e-3), (1e2, 1e11));
        // An undamped peak: up and back down within one pixel column.
        let peak = [
            (1.3e-3, 1e5),
            (1.31e-3, 1e10),
            (1.3100001e-3, 1e9),
            (1.4e-3, 1e5),
        ];
        let runs = split_at_reversals(&peak, &rect, xr, yr);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0], peak[..2].to_vec());
        assert_eq!(runs[1], peak[1..].to_vec());
        let rising = [(1e-3, 1e3), (1.2e-3, 1e4), (1.5e-3, 1e6), (2e-3, 1e7)];
        assert_eq!(
            split_at_reversals(&rising, &rect, xr, yr),
            vec![rising.to_vec()]
        );
    }

    #[test]
    fn clip_keeps_inside_lines_whole() {
        let pts: Vec<_> = (1..=10).map(|k| (k as f64, k as f64)).collect();
        let lines = clip_loglog(&pts, (1.0, 10.0), (1.0, 10.0));
        assert_eq!(lines.len(), 1);
        assert_eq!(lines[0].len(), 10);
    }

    #[test]
    fn auto_y_range_pads_to_decades_and_limits_depth() {
        let mut p = Panel::new("t", ("f", "Hz"), ("y", "m"));
        p.traces.push(Trace::new(
            "a",
            vec![
                (1.0, 3e-3),
                (2.0, 0.0),
                (3.0, 1e-30),
                (4.0, 40.0),
                (5.0, f64::NAN),
            ],
            TraceStyle::new(PALETTE[0], Dash::Solid, 2),
        ));
        assert_eq!(p.resolved_x_range(), (1.0, 5.0));
        let (lo, hi) = p.resolved_y_range();
        assert!((hi - 100.0).abs() < 1e-9);
        assert!((lo - 1e-10).abs() < 1e-22, "{lo}");
        p.max_decades = None;
        let (lo, _) = p.resolved_y_range();
        // 1e-30 padded by a tenth of a decade, rounded out to whole decades.
        assert!((lo - 1e-31).abs() < 1e-43, "{lo}");
    }

    /// A budget-like panel: a broadband term at 1e-13..1e-12 with an undamped resonance peak
    /// of 1e-3 covering 1 % of the axis, and a white readout at 9e-9 over part of the band.
    /// Every curve stays visible where it lies, the peak is clipped at the top.
    #[test]
    fn auto_range_keeps_broadband_terms_and_clips_peaks() {
        let f: Vec<f64> = (0..2000)
            .map(|k| 1e-4 * 10f64.powf(k as f64 * 5.0 / 1999.0))
            .collect();
        let tilt: Vec<(f64, f64)> = f
            .iter()
            .map(|&x| {
                let peak = if (0.40..0.41).contains(&x) { 1e-3 } else { 0.0 };
                (x, 1e-13 * (1.0 + 9.0 * (x / 10.0)) + peak)
            })
            .collect();
        let readout: Vec<(f64, f64)> = f.iter().map(|&x| (x, 9e-9)).collect();
        let curves = [tilt.as_slice(), readout.as_slice()];
        let (lo, hi) = auto_log_range(curves, (1e-4, 10.0), Some(12.0));
        assert!(
            lo <= 1e-13,
            "the broadband floor 1e-13 is below the axis: {lo}"
        );
        assert!(hi >= 9e-9, "the readout 9e-9 is above the axis: {hi}");
        // Peak clipped: at most PEAK_HEADROOM_DECADES (+ rounding) above the broadband tops.
        assert!(hi <= 9e-9 * 10f64.powf(PEAK_HEADROOM_DECADES + 1.1), "{hi}");
        assert!(hi < 1e-3);
        // A lone notch covering less than BOTTOM_QUANTILE of the columns does not set the floor.
        let mut notched = tilt.clone();
        notched[1000].1 = 1e-30;
        let (lo2, _) = auto_log_range([notched.as_slice()], (1e-4, 10.0), None);
        assert!(lo2 >= 1e-14, "{lo2}");
    }

    /// Pixel-grid decimation keeps, per pixel column, the least and greatest value and the
    /// endpoints, and at most four vertices per column.
    #[test]
    fn decimation_keeps_min_and_max_per_column() {
        let rect = PlotRect {
            width: 100.0,
            height: 100.0,
        };
        let (xr, yr) = ((1.0, 10.0), (1e-3, 1e3));
        let n = 10_000;
        let line: Vec<(f64, f64)> = (0..n)
            .map(|k| {
                let x = 10f64.powf(k as f64 / (n - 1) as f64);
                // A zigzag of 2 decades with a spike in the middle.
                let y = if k == n / 2 {
                    900.0
                } else if k % 2 == 0 {
                    0.1
                } else {
                    10.0
                };
                (x, y)
            })
            .collect();
        let out = decimate(&line, &rect, xr, yr);
        assert!(out.len() <= 4 * 100, "{} vertices", out.len());
        assert_eq!(out[0], line[0]);
        assert_eq!(*out.last().unwrap(), line[n - 1]);
        assert!(out.contains(&line[n / 2]), "the spike is lost");
        let column = |p: (f64, f64)| rect.map(p, xr, yr).0.floor() as i64;
        for c in 0..100 {
            let in_col: Vec<f64> = line
                .iter()
                .filter(|p| column(**p) == c)
                .map(|p| p.1)
                .collect();
            if in_col.is_empty() {
                continue;
            }
            let kept: Vec<f64> = out
                .iter()
                .filter(|p| column(**p) == c)
                .map(|p| p.1)
                .collect();
            let max = |v: &[f64]| v.iter().copied().fold(f64::MIN, f64::max);
            let min = |v: &[f64]| v.iter().copied().fold(f64::MAX, f64::min);
            assert_eq!(max(&kept), max(&in_col), "column {c}");
            assert_eq!(min(&kept), min(&in_col), "column {c}");
        }
    }

    #[test]
    fn ticks_thin_out_labels() {
        let t = decade_ticks(1e-10, 1e2, 300.0, 36.0);
        assert_eq!(t.major.len(), 13);
        assert!(t.step >= 2);
        assert!(t.minor.is_empty());
        let t = decade_ticks(1e-4, 30.0, 500.0, 60.0);
        assert_eq!(t.step, 1);
        assert_eq!(t.label(1e-4), "10⁻⁴");
        // Three decades, room for every second label: the first and the third, not the
        // middle one alone.
        let t = decade_ticks(2.4e-4, 0.5, 170.0, 94.0);
        assert_eq!(t.step, 2);
        let labelled: Vec<f64> = t
            .major
            .iter()
            .copied()
            .filter(|&v| !t.label(v).is_empty())
            .collect();
        assert_eq!(labelled, [1e-3, 1e-1]);
    }

    #[test]
    fn the_mapping_is_linear_on_the_log_axis() {
        let mut p = Panel::new("t", ("f", "Hz"), ("y", ""));
        p.traces.push(Trace::new(
            "a",
            vec![(1.0, 0.0), (2.0, 0.5), (3.0, 1.0)],
            TraceStyle::new(PALETTE[0], Dash::Solid, 1),
        ));
        let (log, ticks) = linear_as_log(&p, (0.0, 1.0), Some(0.5));
        let ys: Vec<f64> = log.traces[0].points.iter().map(|q| q.1.log10()).collect();
        assert_eq!(ys, [0.0, 0.5, 1.0]);
        assert_eq!(ticks.len(), 3);
        assert_eq!(log.resolved_y_range(), (1.0, 10.0));
    }
}
