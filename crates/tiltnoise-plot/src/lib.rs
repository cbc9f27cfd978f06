//! tiltnoise-plot: figures as PNG or SVG, drawn in pure Rust (plotters with an embedded font,
//! no system font libraries).
//!
//! Every figure is one drawing routine, [`Figure::draw`], generic over the plotters
//! [`DrawingBackend`]; [`render`] runs it on a [`BitMapBackend`] (PNG) or an [`SVGBackend`]
//! (SVG) and returns the file's bytes. This crate writes no file and does not depend on
//! `tiltnoise-io`: the caller writes the bytes atomically (`tiltnoise_io::write_atomic`), so on
//! error nothing is left at the target path.
//!
//! The module consumes plain data: [`chart`] has the reusable log-log chart
//! ([`chart::LogLogFigure`] of [`chart::Panel`]s of [`chart::Trace`]s and an optional
//! [`chart::Band`]), [`tf_figure()`] builds the paper's Figure 5 from a
//! [`TransferMatrix`](tiltnoise_core::tf::TransferMatrix), [`budget_figure()`] a noise budget from a
//! [`BudgetReport`](tiltnoise_core::noise::BudgetReport), [`coherence_figure()`] measured against
//! model transfer functions from a
//! [`CoherenceReport`](tiltnoise_core::coherence::CoherenceReport).
//!
//! Text is rendered with DejaVu Sans (`assets/DejaVuSans.ttf`, licence in
//! `assets/DejaVuSans-LICENSE.txt`), embedded in the binary and registered with plotters once
//! under the family name `sans-serif`. PNG text goes through [`GlyphPlacement`], which fixes
//! plotters' glyph spacing. In SVG output text stays text (`<text font-family="sans-serif">`),
//! so the viewer's sans-serif font is used there.

#![forbid(unsafe_code)]

pub mod budget_figure;
pub mod chart;
pub mod coherence_figure;
mod labels;
mod linear_axis;
pub mod mc_figure;
pub mod methods_figure;
pub mod simulate_figure;
pub mod subtract_figure;
mod text;
pub mod tf_figure;

pub use budget_figure::{budget_figure, budget_figure_with, BudgetFigureOptions};
pub use chart::{
    Band, Dash, LegendPlacement, LogLogFigure, Panel, TextSizes, Trace, TraceStyle, YScale,
};
pub use coherence_figure::{coherence_figure, CoherenceFigureOptions};
pub use text::GlyphPlacement;
pub use tf_figure::{tf_figure, tf_figure_with, TfFigureOptions};

use image::ImageEncoder;
use plotters::coord::Shift;
use plotters::prelude::{BitMapBackend, DrawingArea, DrawingAreaErrorKind, DrawingBackend};
use plotters::prelude::{IntoDrawingArea, SVGBackend};
use std::sync::OnceLock;
use tiltnoise_core::option_key::OptionKey;

/// The embedded font (DejaVu Sans 2.37, Bitstream Vera / DejaVu licence).
static FONT_BYTES: &[u8] = include_bytes!("../../../assets/DejaVuSans.ttf");

/// Family name under which the embedded font is registered; plotters' default styles use it.
pub const FONT_FAMILY: &str = "sans-serif";

/// Supported image formats.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ImageFormat {
    /// Raster image, 8-bit RGB, lossless.
    Png,
    /// Vector image; text stays selectable text.
    Svg,
}

impl ImageFormat {
    /// The canonical extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            ImageFormat::Png => "png",
            ImageFormat::Svg => "svg",
        }
    }
}

/// What the reader asks of a figure beyond its data: axis limits, pixel size, resolution.
/// Every field is optional; the default leaves the figure as its builder made it.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Frequency range (Hz) of every panel; `None`: the data's.
    pub x_range: Option<(f64, f64)>,
    /// Range of every log y axis (magnitudes, ASDs; not phase or coherence), in the panels'
    /// units; `None`: chosen from the curves ([`chart::auto_log_range`]).
    pub y_range: Option<(f64, f64)>,
    /// Layout size in pixels at the nominal resolution; `None`: the figure's default.
    pub size: Option<(u32, u32)>,
    /// Resolution in dots per inch; the image has `size * dpi / 100` pixels with text and
    /// lines scaled alike, so the layout does not change ([`NOMINAL_DPI`] by default).
    pub dpi: f64,
}

/// Largest image drawn (pixels): 100 megapixels, 300 MB of RGB.
pub const MAX_PIXELS: u64 = 100_000_000;

/// The resolution at which a figure's size is given: `--dpi 200` doubles the pixels.
pub const NOMINAL_DPI: f64 = 100.0;

impl Default for View {
    fn default() -> Self {
        View {
            x_range: None,
            y_range: None,
            size: None,
            dpi: NOMINAL_DPI,
        }
    }
}

impl View {
    /// `figure` with these limits, size and resolution.
    pub fn apply(&self, mut figure: LogLogFigure) -> LogLogFigure {
        if let Some(size) = self.size {
            figure.size = size;
        }
        figure
            .with_limits(self.x_range, self.y_range)
            .scaled(self.dpi / NOMINAL_DPI)
    }

    /// Draws a figure whose layout follows its drawing area (histograms, time series, the
    /// methods chart) at this view's size and resolution. Axis limits do not apply to it: the
    /// caller refuses or ignores them.
    ///
    /// # Errors
    ///
    /// [`DrawError`] as [`render`].
    pub fn render_resized(
        &self,
        format: ImageFormat,
        figure: &impl Figure,
    ) -> Result<Vec<u8>, DrawError> {
        let size = self.pixels(figure.size());
        render(
            format,
            &Resized {
                inner: figure,
                size,
            },
        )
    }

    /// A figure's pixel size under this view: `default` or [`View::size`], times the resolution.
    pub fn pixels(&self, default: (u32, u32)) -> (u32, u32) {
        let (w, h) = self.size.unwrap_or(default);
        let s = self.dpi / NOMINAL_DPI;
        let px = |v: u32| ((v as f64 * s).round() as u32).max(1);
        (px(w), px(h))
    }
}

/// A figure drawn at another pixel size; its drawing reads the size from the drawing area.
struct Resized<'a, F> {
    inner: &'a F,
    size: (u32, u32),
}

impl<F: Figure> Figure for Resized<'_, F> {
    fn size(&self) -> (u32, u32) {
        self.size
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> Result<(), DrawError> {
        self.inner.draw(root, format)
    }
}

/// A failure while drawing: a backend error, a font that cannot be used, or data that cannot be
/// plotted. The caller turns it into an error naming the file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DrawError(pub tiltnoise_core::option_key::Message);

impl std::fmt::Display for DrawError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0)
    }
}

impl std::error::Error for DrawError {}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for DrawError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        DrawError(format!("drawing failed: {e}").into())
    }
}

/// A figure: its pixel size and one drawing routine that serves every backend.
///
/// Closures cannot be generic, so the "draw function generic over the backend" is this trait's
/// method. Implementations draw everything onto `root` (already cleared to white) and must not
/// call `present`; [`render`] does that and reports its errors.
pub trait Figure {
    /// Width and height in pixels (SVG: user units of the same size).
    fn size(&self) -> (u32, u32);

    /// Draws the figure onto `root`, a drawing of the file kind `format` (a bitmap draws some
    /// lines otherwise than a vector image).
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        format: ImageFormat,
    ) -> Result<(), DrawError>;
}

/// Registers the embedded font with plotters, once per process. Every later call returns the
/// first call's result. [`render`] calls it; call it yourself only when drawing onto a
/// backend of your own.
pub fn ensure_font() -> Result<(), DrawError> {
    static REGISTERED: OnceLock<Result<(), DrawError>> = OnceLock::new();
    REGISTERED
        .get_or_init(|| {
            plotters::style::register_font(
                FONT_FAMILY,
                plotters::style::FontStyle::Normal,
                FONT_BYTES,
            )
            .map_err(|_| {
                DrawError(
                    "the embedded font assets/DejaVuSans.ttf is not a usable TrueType font \
                     (rebuild with an intact assets/ directory)"
                        .to_string()
                        .into(),
                )
            })
        })
        .clone()
}

/// Draws `figure` and returns the bytes of a PNG or SVG file. Writing them is the caller's job
/// (atomically, through `tiltnoise-io`'s `write_atomic`): this crate touches no file.
///
/// PNG: 8-bit RGB, encoded with the `image` crate's default PNG settings (the same bytes
/// plotters writes to a file). SVG: UTF-8 text.
///
/// # Errors
///
/// [`DrawError`] if the font cannot be registered, drawing fails or the PNG cannot be encoded.
pub fn render(format: ImageFormat, figure: &impl Figure) -> Result<Vec<u8>, DrawError> {
    ensure_font()?;
    let (w, h) = figure.size();
    if u64::from(w) * u64::from(h) > MAX_PIXELS {
        return Err(DrawError(tiltnoise_core::message!(
            "a {w} x {h} pixel image is too large (at most {} megapixels; lower {} or {})",
            MAX_PIXELS / 1_000_000,
            OptionKey::SIZE,
            OptionKey::DPI
        )));
    }
    match format {
        ImageFormat::Png => {
            let n = (w as usize)
                .checked_mul(h as usize)
                .and_then(|n| n.checked_mul(3))
                .ok_or_else(|| DrawError(format!("a {w} x {h} pixel image is too large").into()))?;
            let mut rgb = vec![0u8; n];
            {
                let root = GlyphPlacement::new(BitMapBackend::with_buffer(&mut rgb, (w, h)))
                    .into_drawing_area();
                draw_on(&root, figure, format)?;
                root.present()
                    .map_err(|e| DrawError(format!("cannot finish the bitmap: {e}").into()))?;
            }
            let mut png = Vec::new();
            image::codecs::png::PngEncoder::new(&mut png)
                .write_image(&rgb, w, h, image::ColorType::Rgb8)
                .map_err(|e| DrawError(format!("cannot encode PNG: {e}").into()))?;
            Ok(png)
        }
        ImageFormat::Svg => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, (w, h)).into_drawing_area();
                draw_on(&root, figure, format)?;
                root.present()
                    .map_err(|e| DrawError(format!("cannot finish SVG: {e}").into()))?;
            }
            Ok(text.into_bytes())
        }
    }
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figure: &impl Figure,
    format: ImageFormat,
) -> Result<(), DrawError> {
    root.fill(&plotters::style::WHITE)?;
    figure.draw(root, format)
}

#[cfg(test)]
mod tests;
