//! The speed-against-accuracy chart of `tiltnoise methods`: time per point on a log x axis,
//! worst relative error against the reference on a log y axis, one marker per method, the
//! accuracy target shaded.

use super::chart::{pow10_label, PALETTE};
use super::{render, DrawError, Figure, ImageFormat, FONT_FAMILY};
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

impl Figure for MethodsChart {
    fn size(&self) -> (u32, u32) {
        (900, 650)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        root.fill(&WHITE)?;
        // Errors below 1e-17 (exact results) are drawn at the axis floor.
        let floor = 1e-17;
        let (x0, x1) = decade_bounds(self.points.iter().map(|p| p.1));
        let (_, y1) = decade_bounds(self.points.iter().map(|p| p.2.max(floor)));
        // Six decades of headroom above the worst point: the legend's place (upper left).
        let y1 = y1.max(1.0) * 1e6;
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 22))
            .margin(20)
            .x_label_area_size(55)
            .y_label_area_size(80)
            .build_cartesian_2d((x0 / 2.0..x1 * 2.0).log_scale(), (floor..y1).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("time per frequency point (ns), single thread")
            .y_desc("worst relative error vs 30-digit reference")
            .x_label_formatter(&|x| pow10_label(x.log10().round() as i32))
            .y_label_formatter(&|y| pow10_label(y.log10().round() as i32))
            .label_style((FONT_FAMILY, 15))
            .axis_desc_style((FONT_FAMILY, 17))
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
            .legend(|(x, y)| {
                Rectangle::new(
                    [(x, y - 6), (x + 16, y + 6)],
                    RGBColor(0, 158, 115).mix(0.3).filled(),
                )
            });
        for (i, (name, ns, err)) in self.points.iter().enumerate() {
            let color = PALETTE[i % PALETTE.len()];
            let at = (*ns, err.max(floor));
            chart
                .draw_series(std::iter::once(Circle::new(at, 7, color.filled())))?
                .label(format!("{name}: {err:.1e}, {ns:.0} ns"))
                .legend(move |(x, y)| Circle::new((x + 8, y), 6, color.filled()));
            chart.draw_series(std::iter::once(Text::new(
                name.clone(),
                (at.0 * 1.15, at.1 * 2.0),
                (FONT_FAMILY, 16).into_font().color(&color),
            )))?;
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.mix(0.4))
            .label_font((FONT_FAMILY, 14))
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
    format: ImageFormat,
) -> Result<Vec<u8>, DrawError> {
    render(
        format,
        &MethodsChart {
            points: points.to_vec(),
            target_rel_err,
            title: title.to_string(),
        },
    )
}
