//! Correct glyph placement for raster output.
//!
//! plotters 0.3.7 renders text with ab_glyph but places every glyph's ink at the pen position,
//! ignoring the glyph's left side bearing: letters with wide bearings (`i`, `l`, `1`, `t`) sit
//! too far left and words look unevenly spaced ("iden tically"). [`GlyphPlacement`] wraps a
//! raster backend and draws text one glyph at a time, each shifted by its left side bearing
//! as ab_glyph reads it from the embedded font; the rasterisation itself stays plotters'.
//! Vector backends (SVG) keep text as text and do not need it.

use ab_glyph::{Font, FontRef};
use plotters::backend::DrawingBackend;
use plotters::style::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
};
use std::sync::OnceLock;

/// Horizontal metrics of one glyph, in font units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct HMetric {
    /// Advance width.
    pub advance: f64,
    /// Left side bearing.
    pub lsb: f64,
}

/// The metrics of a font needed to lay out a line of text as ab_glyph scales it.
#[derive(Debug, Clone)]
pub(crate) struct FontMetrics {
    font: FontRef<'static>,
    /// `ascent - descent` (font units): ab_glyph's scale is px per this height.
    pub height: f64,
}

impl FontMetrics {
    /// The metrics of a TrueType or OpenType font. `None` if ab_glyph cannot read it or its
    /// height is not positive.
    pub fn parse(font: &'static [u8]) -> Option<FontMetrics> {
        let font = FontRef::try_from_slice(font).ok()?;
        let height = f64::from(font.height_unscaled());
        (height > 0.0).then_some(FontMetrics { font, height })
    }

    /// Metrics of `c` (those of `.notdef`, glyph 0, if the font lacks it).
    pub fn get(&self, c: char) -> HMetric {
        let id = self.font.glyph_id(c);
        HMetric {
            advance: f64::from(self.font.h_advance_unscaled(id)),
            lsb: f64::from(self.font.h_side_bearing_unscaled(id)),
        }
    }

    /// Ink offsets (px, relative to the start of the line, as plotters rasterises each glyph
    /// from the floor of its left bearing) and the total advance width of `text` at `size`.
    pub fn layout(&self, text: &str, size: f64) -> (Vec<i32>, f64) {
        let scale = size / self.height;
        let mut pen: f64 = 0.0;
        let offsets = text
            .chars()
            .map(|c| {
                let m = self.get(c);
                let x = pen.round() as i32 + (m.lsb * scale).floor() as i32;
                pen += m.advance * scale;
                x
            })
            .collect();
        (offsets, pen)
    }
}

/// Metrics of the embedded font, read once.
pub(crate) fn embedded_metrics() -> Option<&'static FontMetrics> {
    static METRICS: OnceLock<Option<FontMetrics>> = OnceLock::new();
    METRICS
        .get_or_init(|| FontMetrics::parse(super::FONT_BYTES))
        .as_ref()
}

/// A raster backend whose text has each glyph placed by its left side bearing. Everything
/// else is passed through unchanged. Text in a family other than the embedded one falls back
/// to the inner backend's own rendering.
pub struct GlyphPlacement<DB: DrawingBackend> {
    inner: DB,
}

impl<DB: DrawingBackend> GlyphPlacement<DB> {
    /// Wraps a backend.
    pub fn new(inner: DB) -> Self {
        GlyphPlacement { inner }
    }

    fn metrics_for<S: BackendTextStyle>(style: &S) -> Option<&'static FontMetrics> {
        if style.family().as_str() == super::FONT_FAMILY {
            embedded_metrics()
        } else {
            None
        }
    }
}

impl<DB: DrawingBackend> DrawingBackend for GlyphPlacement<DB> {
    type ErrorType = DB::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        let (w, h) = self.inner.estimate_text_size(text, style)?;
        match Self::metrics_for(style) {
            Some(m) => Ok((m.layout(text, style.size()).1.ceil() as u32, h)),
            None => Ok((w, h)),
        }
    }

    /// plotters' default text routine (anchor, rotation, clipping to the image), with each
    /// glyph drawn separately at its own ink offset.
    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let Some(metrics) = Self::metrics_for(style) else {
            return self.inner.draw_text(text, style, pos);
        };
        if style.color().alpha == 0.0 {
            return Ok(());
        }
        let ((_, min_y), (_, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (offsets, width) = metrics.layout(text, style.size());
        let width = width.round() as i32;
        let height = max_y - min_y;
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        let trans = style.transform();
        let (w, h) = self.inner.get_size();
        let mut buf = [0u8; 4];
        for (c, x0) in text.chars().zip(offsets) {
            if c.is_whitespace() {
                continue;
            }
            let glyph = c.encode_utf8(&mut buf);
            let inner = &mut self.inner;
            let drawn = style.draw(glyph, (0, 0), |x, y, color| {
                let (x, y) = trans.transform(x + x0 + dx, y + dy - min_y);
                let (x, y) = (pos.0 + x, pos.1 + y);
                if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
                    inner.draw_pixel((x, y), color)
                } else {
                    Ok(())
                }
            });
            match drawn {
                Ok(r) => r?,
                Err(e) => return Err(DrawingErrorKind::FontError(Box::new(e))),
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    #[test]
    fn embedded_font_metrics() {
        let m = embedded_metrics().expect("embedded font parses");
        // DejaVu Sans: hhea ascender 1901, descender -483.
        assert_eq!(m.height, 2384.0);
        for c in "0123456789abcdefghijklmnopqrstuvwxyzABCXYZθηφₜₐ⁰¹⁻→−()|/".chars()
        {
            assert_ne!(m.font.glyph_id(c).0, 0, "{c:?} missing");
        }
        // `i` and `l` have a wide left bearing, `j` a small one.
        assert!(m.get('i').lsb > 150.0);
        assert!(m.get('l').lsb > 150.0);
        // A character the font lacks takes the metrics of `.notdef`.
        assert_eq!(m.get('\u{10FFFD}'), m.get('\u{10FFFE}'));
    }

    #[test]
    fn widths_agree_with_plotters() {
        super::super::ensure_font().unwrap();
        let m = embedded_metrics().unwrap();
        let style: TextStyle = (super::super::FONT_FAMILY, 40.0).into_font().into();
        for text in [
            "identically 0",
            "frequency (Hz)",
            "|φₐ / tilt| (rad/rad)",
            "10⁻¹²",
        ] {
            let ((x0, _), (x1, _)) = style.font.layout_box(text).unwrap();
            let ours = m.layout(text, 40.0).1;
            assert!(
                ((x1 - x0) as f64 - ours).abs() <= 2.0 + 0.01 * ours,
                "{text}: plotters {} vs {ours}",
                x1 - x0
            );
        }
    }
}
