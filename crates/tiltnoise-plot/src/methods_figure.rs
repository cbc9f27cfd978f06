//! The speed-against-accuracy chart of `tiltnoise methods`: time per point on a log x axis,
//! worst relative error against the reference on a log y axis, one marker per method, the
//! accuracy target shaded.

use super::chart::{pow10_label, PALETTE};
use super::{DrawError, Figure, ImageFormat, View, FONT_FAMILY};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One marker: method name, ns per point, worst relative error.
pub type MethodPoint = (String, f64, f64);

struct MethodsChart {
    points: Vec<MethodPoint>,
    target_rel_err: f64,
    title: String,
}

fn decade_bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(a, b), v| (a.min(v), b.max(v)));
    if lo > hi {
        return (1e-16, 1.0);
    }
    (
        10f64.powf(lo.log10().floor()),
        10f64.powf(hi.log10().ceil() + 0.01),
    )
}

/// Default size of the methods chart (pixels at 100 dpi).
pub const DEFAULT_SIZE: (u32, u32) = (900, 650);

impl Figure for MethodsChart {
    fn size(&self) -> (u32, u32) {
        DEFAULT_SIZE
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        _format: ImageFormat,
    ) -> Result<(), DrawError> {
        root.fill(&WHITE)?;
        // Text, markers and margins scale with the drawing area (--size, --dpi).
        let (w, h) = root.dim_in_pixel();
        let (w0, h0) = self.size();
        let s = (f64::from(w) / f64::from(w0)).min(f64::from(h) / f64::from(h0));
        let px = |v: f64| (v * s).round().max(1.0);
        // Errors below 1e-17 (exact results) are drawn at the axis floor.
        let floor = 1e-17;
        let (x0, x1) = decade_bounds(self.points.iter().map(|p| p.1));
        let (_, y1) = decade_bounds(self.points.iter().map(|p| p.2.max(floor)));
        // Six decades of headroom above the worst point: the legend's place (upper left).
        let y1 = y1.max(1.0) * 1e6;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, px(22.0)))
            .margin(px(20.0) as u32)
            .x_label_area_size(px(55.0) as u32)
            .y_label_area_size(px(80.0) as u32)
            .build_cartesian_2d((x0 / 2.0..x1 * 2.0).log_scale(), (floor..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("time per frequency point (ns), single thread")
            .y_desc("worst relative error vs 30-digit reference")
            .x_label_formatter(&|x| pow10_label(x.log10().round() as i32))
            .y_label_formatter(&|y| pow10_label(y.log10().round() as i32))
            .label_style((FONT_FAMILY, px(15.0)))
            .axis_desc_style((FONT_FAMILY, px(17.0)))
            .draw()?;
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(x0 / 2.0, floor), (x1 * 2.0, self.target_rel_err)],
                RGBColor(0, 158, 115).mix(0.15).filled(),
            )))?
            .label(format!(
                "target: relative error <= {:e}",
                self.target_rel_err
            ))
            .legend(move |(x, y)| {
                let r = px(6.0) as i32;
                Rectangle::new(
                    [(x, y - r), (x + 3 * r, y + r)],
                    RGBColor(0, 158, 115).mix(0.3).filled(),
                )
            });
        for (i, (name, ns, err)) in self.points.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let r = px(6.0) as i32;
            let at = (*ns, err.max(floor));
            chart
                .draw_series(std::iter::once(Circle::new(
                    at,
                    px(7.0) as u32,
                    color.filled(),
                )))?
                .label(format!("{name}: {err:.1e}, {ns:.0} ns"))
                .legend(move |(x, y)| Circle::new((x + r + 2, y), r, color.filled()));
            chart.draw_series(std::iter::once(Text::new(
                name.clone(),
                (at.0 * 1.15, at.1 * 2.0),
                (FONT_FAMILY, px(16.0)).into_font().color(&color),
            )))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.4))
            .label_font((FONT_FAMILY, px(14.0)))
            .draw()?;
        Ok(())
    }
}

/// Draws the methods chart as a PNG or SVG file's bytes.
///
/// # Errors
///
/// [`DrawError`] for any drawing failure.
pub fn methods_figure(
    points: &[MethodPoint],
    target_rel_err: f64,
    title: &str,
    view: &View,
    format: ImageFormat,
) -> Result<Vec<u8>, DrawError> {
    view.render_resized(
        format,
        &MethodsChart {
            points: points.to_vec(),
            target_rel_err,
            title: title.to_string(),
        },
    )
}
