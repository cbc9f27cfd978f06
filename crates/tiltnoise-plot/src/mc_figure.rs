//! Histograms of the Monte Carlo of the normal modes (`tiltnoise mc --save mc.png`): one panel
//! per mode, frequency in Hz on a linear axis, draws per bin; the nominal frequency, the mean
//! and the band mean +/- 1 standard deviation are marked.

use super::chart::{TextSizes, PALETTE};
use super::{DrawError, Figure, ImageFormat, View, FONT_FAMILY};
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use tiltnoise_core::mc::McResult;

/// Half-width of a panel's axis in standard deviations: rare tails beyond it are counted in the
/// panel, not drawn, so that one outlier does not squeeze the histogram.
const AXIS_HALF_WIDTH_STD: f64 = 5.0;

/// Number of bins for `n` draws: the Rice rule `2 n^(1/3)`, between 10 and 80.
fn bin_count(n: usize) -> usize {
    ((2.0 * (n as f64).cbrt()).ceil() as usize).clamp(10, 80)
}

/// One panel's data: the frequencies of one mode over all accepted draws.
struct ModeHistogram {
    mode: usize,
    nominal_hz: f64,
    mean_hz: f64,
    std_hz: f64,
    /// Axis range (Hz).
    range_hz: (f64, f64),
    /// Draws per bin; bins split `range_hz` evenly.
    counts: Vec<usize>,
    /// Draws outside `range_hz`.
    outside: usize,
}

impl ModeHistogram {
    fn new(result: &McResult, nominal_hz: f64, k: usize) -> ModeHistogram {
        let (mean, std) = (result.mean_hz[k], result.std_hz[k]);
        let (lo, hi) = result
            .freqs_hz
            .iter()
            .map(|r| r[k])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let mut range = (
            lo.max(mean - AXIS_HALF_WIDTH_STD * std).min(nominal_hz),
            hi.min(mean + AXIS_HALF_WIDTH_STD * std).max(nominal_hz),
        );
        if range.1 <= range.0 {
            // Every draw equal (zero error): a small window around the value.
            let w = range.0.abs().max(f64::MIN_POSITIVE) * 1e-3;
            range = (range.0 - w, range.1 + w);
        }
        let bins = bin_count(result.freqs_hz.len());
        let mut counts = vec![0; bins];
        let mut outside = 0;
        let width = (range.1 - range.0) / bins as f64;
        for r in &result.freqs_hz {
            let v = r[k];
            if v < range.0 || v > range.1 {
                outside += 1;
                continue;
            }
            counts[(((v - range.0) / width) as usize).min(bins - 1)] += 1;
        }
        ModeHistogram {
            mode: k + 1,
            nominal_hz,
            mean_hz: mean,
            std_hz: std,
            range_hz: range,
            counts,
            outside,
        }
    }
}

/// The figure: eight histograms in a 2 x 4 grid, a title and a caption line.
struct McFigure {
    panels: Vec<ModeHistogram>,
    title: String,
    caption: String,
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    h: &ModeHistogram,
    ts: &TextSizes,
) -> Result<(), DrawError> {
    let (x0, x1) = h.range_hz;
    let bins = h.counts.len();
    let width = (x1 - x0) / bins as f64;
    let mut lines = statistics(h).to_vec();
    // The bin width here rather than in the axis title, which would run into the next panel.
    lines.push(format!("bin {}", super::labels::si_value(width, "Hz")));
    if h.outside > 0 {
        let s = if h.outside == 1 { "" } else { "s" };
        lines.push(format!("{} draw{s} beyond ±5 std, not shown", h.outside));
    }
    let font = ts.legend * 0.85;
    let line_height = font * 1.2;

    let (aw, _) = area.dim_in_pixel();
    let (title, body) = area.split_vertically((ts.panel_title * 1.6) as u32);
    title.draw_text(
        &format!("ν{}", subscript(h.mode)),
        &(FONT_FAMILY, ts.panel_title)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Center)),
        (aw as i32 / 2, (ts.panel_title * 0.9) as i32),
    )?;
    let builder = |top: f64| {
        ChartBuilder::on(&body)
            .margin(10)
            .x_label_area_size((ts.ticks * 3.2) as u32)
            .y_label_area_size((ts.ticks * 3.6) as u32)
            .build_cartesian_2d(x0..x1, 0.0..top)
    };
    // Headroom above the tallest bin for the statistics in the upper left corner: their
    // height plus a small gap, as a fraction of the plot's height (at most 70 %).
    let plot_h = builder(1.0)?.plotting_area().dim_in_pixel().1.max(1) as f64;
    let text_h = line_height * (lines.len() as f64 + 0.5);
    let free = 1.0 - ((text_h + 0.04 * plot_h) / plot_h).min(0.7);
    let top = h.counts.iter().copied().max().unwrap_or(0).max(1) as f64 / free;
    // Ticks as plain numbers in the prefixed unit of the axis title (`1.3` in mHz).
    let (e, prefix) = super::labels::si_prefix(x1.abs().max(x0.abs()));
    let scale = 10f64.powi(e);
    let decimals = (-(((x1 - x0) / 8.0 / scale).log10().floor())).max(0.0) as usize;
    let mut chart = builder(top)?;
    chart
        .configure_mesh()
        .x_labels(5)
        .y_labels(5)
        .x_desc(format!("frequency ({prefix}Hz)"))
        .y_desc("draws per bin")
        .x_label_formatter(&|x| {
            let text = format!("{:.decimals$}", x / scale);
            match text.contains('.') {
                true => text.trim_end_matches('0').trim_end_matches('.').to_string(),
                false => text,
            }
        })
        .y_label_formatter(&|y| format!("{y:.0}"))
        .label_style((FONT_FAMILY, ts.ticks))
        .axis_desc_style((FONT_FAMILY, ts.axis))
        .light_line_style(WHITE)
        .draw()?;
    let band = PALETTE[0];
    chart.draw_series(std::iter::once(Rectangle::new(
        [(h.mean_hz - h.std_hz, 0.0), (h.mean_hz + h.std_hz, top)],
        band.mix(0.15).filled(),
    )))?;
    chart.draw_series(h.counts.iter().enumerate().map(|(i, &c)| {
        let a = x0 + i as f64 * width;
        Rectangle::new([(a, 0.0), (a + width, c as f64)], band.mix(0.7).filled())
    }))?;
    let mean = PALETTE[1];
    chart.draw_series(std::iter::once(PathElement::new(
        vec![(h.mean_hz, 0.0), (h.mean_hz, top)],
        mean.stroke_width(2),
    )))?;
    let nominal = PALETTE[6];
    chart.draw_series(std::iter::once(DashedPathElement::new(
        vec![(h.nominal_hz, 0.0), (h.nominal_hz, top)],
        6,
        4,
        nominal.stroke_width(2),
    )))?;
    let style = (FONT_FAMILY, font).into_font().color(&BLACK);
    let plot = chart.plotting_area().strip_coord_spec();
    // A light backing keeps the text readable where the marker lines cross it.
    let longest = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0) as f64;
    plot.draw(&Rectangle::new(
        [
            (0, 0),
            (
                (font * (0.8 + 0.5 * longest)) as i32,
                (line_height * (lines.len() as f64 + 0.3)) as i32,
            ),
        ],
        WHITE.mix(0.85).filled(),
    ))?;
    for (i, line) in lines.iter().enumerate() {
        let y = line_height * (0.3 + i as f64);
        plot.draw_text(line, &style, ((font * 0.5) as i32, y as i32))?;
    }
    Ok(())
}

/// Splits `text` at spaces into lines of at most `width` characters (longer words stay whole).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// The nominal frequency, mean and standard deviation of a histogram in the SI-prefixed unit
/// of its frequency axis (`1.3102 mHz`): the nominal value to five significant digits, the
/// mean and the deviation with as many decimals, so the three read against each other and
/// against the ticks.
fn statistics(h: &ModeHistogram) -> [String; 3] {
    let (x0, x1) = h.range_hz;
    let (e, prefix) = super::labels::si_prefix(x1.abs().max(x0.abs()));
    let scale = 10f64.powi(e);
    let mantissa = (h.nominal_hz / scale).abs();
    let decimals = if mantissa > 0.0 && mantissa.is_finite() {
        (4 - mantissa.log10().floor() as i32).max(0) as usize
    } else {
        4
    };
    let text = |v: f64| format!("{:.decimals$} {prefix}Hz", v / scale);
    [
        format!("nominal {}", text(h.nominal_hz)),
        format!("mean {}", text(h.mean_hz)),
        format!("std {}", text(h.std_hz)),
    ]
}

/// `k` in Unicode subscript digits.
fn subscript(k: usize) -> String {
    const SUB: [char; 10] = ['₀', '₁', '₂', '₃', '₄', '₅', '₆', '₇', '₈', '₉'];
    k.to_string()
        .bytes()
        .map(|d| SUB[(d - b'0') as usize])
        .collect()
}

/// Default size of the Monte Carlo figure (pixels at 100 dpi).
pub const DEFAULT_SIZE: (u32, u32) = (1400, 1800);

impl Figure for McFigure {
    fn size(&self) -> (u32, u32) {
        DEFAULT_SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> Result<(), DrawError> {
        let (w, h) = root.dim_in_pixel();
        let ts = TextSizes::for_figure(w, h);
        let (top, rest) = root.split_vertically((ts.title * 2.2) as u32);
        let (tw, th) = top.dim_in_pixel();
        top.draw_text(
            &self.title,
            &(FONT_FAMILY, ts.title)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Center, VPos::Center)),
            (tw as i32 / 2, th as i32 / 2),
        )?;
        // Word-wrapped caption; DejaVu Sans averages about 0.55 em per character.
        let chars_per_line = (f64::from(w) / (ts.caption * 0.6)) as usize;
        let lines = wrap(&self.caption, chars_per_line);
        let line_height = ts.caption * 1.4;
        let (_, rh) = rest.dim_in_pixel();
        let strip = (line_height * (lines.len() as f64 + 1.0)) as u32;
        let (grid, bottom) = rest.split_vertically(rh.saturating_sub(strip));
        let style = (FONT_FAMILY, ts.caption).into_font().color(&BLACK);
        for (i, line) in lines.iter().enumerate() {
            let y = line_height * (0.5 + i as f64);
            bottom.draw_text(line, &style, ((ts.caption * 1.5) as i32, y as i32))?;
        }
        for (panel, cell) in self.panels.iter().zip(grid.split_evenly((4, 2)).iter()) {
            draw_panel(cell, panel, &ts)?;
        }
        Ok(())
    }
}

/// Writes the histograms of a Monte Carlo run (PNG or SVG by extension), atomically.
/// `nominal_hz` are the modes of the nominal parameters; `caption` goes below the panels (the
/// run's sample count, seed and error model, say).
///
/// # Errors
///
/// [`DrawError`] for any drawing failure.
pub fn mc_figure(
    result: &McResult,
    nominal_hz: &[f64; 8],
    caption: &str,
    view: &View,
    format: ImageFormat,
) -> Result<Vec<u8>, DrawError> {
    let panels = (0..8)
        .map(|k| ModeHistogram::new(result, nominal_hz[k], k))
        .collect();
    view.render_resized(
        format,
        &McFigure {
            panels,
            title: format!(
                "Monte Carlo of the normal modes: {} accepted draws",
                result.freqs_hz.len()
            ),
            caption: caption.to_string(),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_keep_the_digits_the_step_needs() {
        assert_eq!(subscript(8), "₈");
        assert_eq!(wrap("aa bb cc", 5), ["aa bb", "cc"]);
    }

    #[test]
    fn statistics_use_the_prefixed_unit_of_the_axis() {
        let draws = |centre: f64, spread: f64| McResult {
            samples: 3,
            rejected: 0,
            sample_index: vec![0, 1, 2],
            freqs_hz: vec![[centre - spread; 8], [centre; 8], [centre + spread; 8]],
            mean_hz: [centre; 8],
            std_hz: [spread; 8],
        };
        let h = ModeHistogram::new(&draws(1.31023e-3, 3.2e-5), 1.31023e-3, 0);
        assert_eq!(
            statistics(&h),
            ["nominal 1.3102 mHz", "mean 1.3102 mHz", "std 0.0320 mHz"]
        );
        let h = ModeHistogram::new(&draws(0.414912, 0.01), 0.414912, 1);
        assert_eq!(
            statistics(&h),
            ["nominal 414.91 mHz", "mean 414.91 mHz", "std 10.00 mHz"]
        );
    }

    #[test]
    fn histogram_counts_every_draw() {
        let freqs: Vec<[f64; 8]> = (0..1000)
            .map(|i| [1.0 + (i % 17) as f64 * 1e-3; 8])
            .collect();
        let mut r = McResult {
            samples: 1000,
            rejected: 0,
            sample_index: (0..1000).collect(),
            freqs_hz: freqs,
            mean_hz: [1.008; 8],
            std_hz: [0.005; 8],
        };
        let h = ModeHistogram::new(&r, 1.0, 3);
        assert_eq!(h.counts.iter().sum::<usize>() + h.outside, 1000);
        assert_eq!(h.outside, 0);
        // A far outlier is counted off axis, not drawn.
        r.freqs_hz[0][3] = 100.0;
        let h = ModeHistogram::new(&r, 1.0, 3);
        assert_eq!((h.counts.iter().sum::<usize>(), h.outside), (999, 1));
    }
}
