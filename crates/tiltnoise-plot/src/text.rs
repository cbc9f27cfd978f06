//! Correct glyph placement for raster output.
//!
//! plotters 0.3.7 renders text with ab_glyph but places every glyph's ink at the pen position,
//! ignoring the glyph's left side bearing: letters with wide bearings (`i`, `l`, `1`, `t`) sit
//! too far left and words look unevenly spaced ("iden tically"). [`GlyphPlacement`] wraps a
//! raster backend and draws text one glyph at a time, each shifted by its left side bearing
//! read from the embedded font's `hmtx` table; the rasterisation itself stays plotters'.
//! Vector backends (SVG) keep text as text and do not need it.

use plotters::backend::DrawingBackend;
use plotters::style::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
};
use std::collections::HashMap;
use std::sync::OnceLock;

/// Horizontal metrics of one glyph, in font units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct HMetric {
    /// Advance width.
    pub advance: u16,
    /// Left side bearing.
    pub lsb: i16,
}

/// The metrics of a TrueType font needed to lay out a line of text as ab_glyph scales it.
#[derive(Debug, Clone)]
pub(crate) struct FontMetrics {
    /// `hhea.ascender - hhea.descender` (font units): ab_glyph's scale is px per this height.
    pub height: f64,
    /// Per character.
    glyphs: HashMap<char, HMetric>,
    /// `.notdef` (glyph 0), for characters the font lacks.
    notdef: HMetric,
}

impl FontMetrics {
    /// Parses `hhea`, `hmtx` and the Unicode `cmap` subtable (format 4 or 12) of a TrueType
    /// font. `None` if a table is missing or malformed.
    pub fn parse(font: &[u8]) -> Option<FontMetrics> {
        let u16_at = |o: usize| -> Option<u16> {
            Some(u16::from_be_bytes(font.get(o..o + 2)?.try_into().ok()?))
        };
        let u32_at = |o: usize| -> Option<u32> {
            Some(u32::from_be_bytes(font.get(o..o + 4)?.try_into().ok()?))
        };
        let num_tables = u16_at(4)? as usize;
        let mut table = HashMap::new();
        for i in 0..num_tables {
            let rec = 12 + 16 * i;
            let tag = font.get(rec..rec + 4)?;
            table.insert(tag.to_vec(), u32_at(rec + 8)? as usize);
        }
        let hhea = *table.get(&b"hhea"[..])?;
        let hmtx = *table.get(&b"hmtx"[..])?;
        let cmap = *table.get(&b"cmap"[..])?;
        let maxp = *table.get(&b"maxp"[..])?;
        let ascender = u16_at(hhea + 4)? as i16 as f64;
        let descender = u16_at(hhea + 6)? as i16 as f64;
        let n_hmetrics = u16_at(hhea + 34)? as usize;
        let n_glyphs = u16_at(maxp + 4)? as usize;
        if n_hmetrics == 0 {
            return None;
        }
        let metric = |gid: usize| -> Option<HMetric> {
            if gid < n_hmetrics {
                Some(HMetric {
                    advance: u16_at(hmtx + 4 * gid)?,
                    lsb: u16_at(hmtx + 4 * gid + 2)? as i16,
                })
            } else {
                Some(HMetric {
                    advance: u16_at(hmtx + 4 * (n_hmetrics - 1))?,
                    lsb: u16_at(hmtx + 4 * n_hmetrics + 2 * (gid - n_hmetrics))? as i16,
                })
            }
        };

        // Prefer a full-Unicode subtable (3,10) format 12, else BMP (3,1) / (0,x) format 4.
        let n_sub = u16_at(cmap + 2)? as usize;
        let mut best: Option<(u8, usize)> = None;
        for i in 0..n_sub {
            let rec = cmap + 4 + 8 * i;
            let (platform, encoding) = (u16_at(rec)?, u16_at(rec + 2)?);
            let offset = cmap + u32_at(rec + 4)? as usize;
            let format = u16_at(offset)?;
            let rank = match (platform, encoding, format) {
                (3, 10, 12) | (0, 4, 12) | (0, 6, 12) => 2,
                (3, 1, 4) | (0, _, 4) => 1,
                _ => continue,
            };
            if best.is_none_or(|(r, _)| rank > r) {
                best = Some((rank, offset));
            }
        }
        let (_, sub) = best?;
        let mut glyphs = HashMap::new();
        let mut add = |code: u32, gid: usize| {
            if gid != 0 && gid < n_glyphs {
                if let (Some(c), Some(m)) = (char::from_u32(code), metric(gid)) {
                    glyphs.insert(c, m);
                }
            }
        };
        match u16_at(sub)? {
            4 => {
                let seg_x2 = u16_at(sub + 6)? as usize;
                let ends = sub + 14;
                let starts = ends + seg_x2 + 2;
                let deltas = starts + seg_x2;
                let ranges = deltas + seg_x2;
                for s in 0..seg_x2 / 2 {
                    let end = u16_at(ends + 2 * s)? as u32;
                    let start = u16_at(starts + 2 * s)? as u32;
                    let delta = u16_at(deltas + 2 * s)? as u32;
                    let range = u16_at(ranges + 2 * s)? as usize;
                    if start > end || start == 0xFFFF {
                        continue;
                    }
                    for code in start..=end {
                        let gid = if range == 0 {
                            (code + delta) & 0xFFFF
                        } else {
                            let at = ranges + 2 * s + range + 2 * (code - start) as usize;
                            match u16_at(at)? as u32 {
                                0 => 0,
                                g => (g + delta) & 0xFFFF,
                            }
                        };
                        add(code, gid as usize);
                    }
                }
            }
            12 => {
                let n_groups = u32_at(sub + 12)? as usize;
                for g in 0..n_groups {
                    let rec = sub + 16 + 12 * g;
                    let (start, end, gid0) = (u32_at(rec)?, u32_at(rec + 4)?, u32_at(rec + 8)?);
                    if end < start || end - start > 0x10FFFF {
                        return None;
                    }
                    for code in start..=end {
                        add(code, (gid0 + (code - start)) as usize);
                    }
                }
            }
            _ => return None,
        }
        let height = ascender - descender;
        if height <= 0.0 {
            return None;
        }
        Some(FontMetrics {
            height,
            glyphs,
            notdef: metric(0)?,
        })
    }

    /// Metrics of `c` (`.notdef` if the font lacks it).
    pub fn get(&self, c: char) -> HMetric {
        self.glyphs.get(&c).copied().unwrap_or(self.notdef)
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
                let x = pen.round() as i32 + (m.lsb as f64 * scale).floor() as i32;
                pen += m.advance as f64 * scale;
                x
            })
            .collect();
        (offsets, pen)
    }
}

/// Metrics of the embedded font, parsed once.
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
            assert!(m.glyphs.contains_key(&c), "{c:?} missing");
        }
        // `i` and `l` have a wide left bearing, `j` a small one.
        assert!(m.get('i').lsb > 150);
        assert!(m.get('l').lsb > 150);
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
