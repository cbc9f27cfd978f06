//! The figure of `tiltnoise subtract`: per measured observable, on the held-out stretch, the
//! one-sided ASDs of the measured record, of its predicted floor part, of the model-cleaned
//! residual, of the Wiener filter's residual, of the residual the coherence allows and of the
//! residual the witness's own noise leaves, with the readout level, the report band and the
//! bands left raw marked; the estimates in the caption.
//!
//! Plain data in ([`SubtractFigureData`]), a [`LogLogFigure`] out; drawn by [`subtract_figure`].

use super::chart::{Band, Dash, LegendPlacement, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
use super::labels::{observable_symbol, observable_title, si_asd};
use super::{render, DrawError, ImageFormat, View};
use plotters::style::RGBColor;
use tiltnoise_core::model::Observable;

/// One observable's spectra (one-sided ASDs, unit/sqrt(Hz)) on the Welch grid (DC first,
/// skipped on the log axis).
#[derive(Debug, Clone, PartialEq)]
pub struct ObservablePanel {
    /// The observable.
    pub observable: Observable,
    /// Frequencies (Hz).
    pub freqs_hz: Vec<f64>,
    /// Measured.
    pub measured: Vec<f64>,
    /// Predicted tilt part.
    pub predicted: Vec<f64>,
    /// Measured minus predicted.
    pub cleaned: Vec<f64>,
    /// Residual of the Wiener filter.
    pub wiener: Vec<f64>,
    /// Residual the coherence allows.
    pub expected: Vec<f64>,
    /// Residual the witness's own noise leaves through the fitted model (all zero without a
    /// stated witness noise: not drawn).
    pub witness_limited: Vec<f64>,
    /// Bands left raw (Hz): the prediction did not lower the record there.
    pub left_raw: Vec<(f64, f64)>,
    /// White readout, if known.
    pub readout: Option<f64>,
}

/// Input of the figure.
#[derive(Debug, Clone, PartialEq)]
pub struct SubtractFigureData {
    /// One panel per observable.
    pub panels: Vec<ObservablePanel>,
    /// The report band (Hz), marked on every panel.
    pub band_hz: (f64, f64),
    /// Caption lines (estimates, band summaries, stretch).
    pub caption: Vec<String>,
}

const MEASURED: RGBColor = PALETTE[6];
const PREDICTED: RGBColor = PALETTE[1];
const CLEANED: RGBColor = PALETTE[0];
const WIENER: RGBColor = PALETTE[4];
const EXPECTED: RGBColor = PALETTE[2];
const WITNESS: RGBColor = PALETTE[5];
const READOUT: RGBColor = PALETTE[3];
const BAND: RGBColor = RGBColor(150, 150, 150);

/// Builds the figure: two columns, one panel per observable, the caption in a free cell or
/// below.
pub fn build_subtract_figure(data: &SubtractFigureData) -> Result<LogLogFigure, String> {
    let mut panels = Vec::new();
    for p in &data.panels {
        let n = p.freqs_hz.len();
        for (what, v) in [
            ("measured", &p.measured),
            ("predicted", &p.predicted),
            ("cleaned", &p.cleaned),
            ("wiener", &p.wiener),
            ("expected", &p.expected),
            ("witness-limited", &p.witness_limited),
        ] {
            if v.len() != n || n < 3 {
                return Err(format!(
                    "{} ASD of {} has {} values and the grid {} (at least 3 needed)",
                    what,
                    p.observable.name(),
                    v.len(),
                    n
                ));
            }
        }
        let o = p.observable;
        let mut panel = Panel::new(
            observable_title(o),
            ("frequency", "Hz"),
            (
                &format!("ASD of {}", observable_symbol(o)),
                &format!("{}/√Hz", o.unit()),
            ),
        );
        let pts = |v: &[f64]| -> Vec<(f64, f64)> {
            p.freqs_hz
                .iter()
                .zip(v)
                .skip(1)
                .map(|(&f, &a)| (f, a))
                .collect()
        };
        panel.x_range = Some((p.freqs_hz[1], p.freqs_hz[n - 1]));
        panel.traces.push(Trace::new(
            "measured",
            pts(&p.measured),
            TraceStyle::new(MEASURED, Dash::Solid, 2),
        ));
        panel.traces.push(Trace::new(
            "predicted tilt (model)",
            pts(&p.predicted),
            TraceStyle::new(PREDICTED, Dash::Dashed, 2),
        ));
        panel.traces.push(Trace::new(
            "Wiener residual",
            pts(&p.wiener),
            TraceStyle::new(WIENER, Dash::Solid, 1),
        ));
        panel.traces.push(Trace::new(
            "cleaned (model)",
            pts(&p.cleaned),
            TraceStyle::new(CLEANED, Dash::Solid, 2),
        ));
        panel.traces.push(Trace::new(
            "coherence limit",
            pts(&p.expected),
            TraceStyle::new(EXPECTED, Dash::Dashed, 2),
        ));
        if p.witness_limited.iter().skip(1).any(|&v| v > 0.0) {
            panel.traces.push(Trace::new(
                "witness-noise limit (model)",
                pts(&p.witness_limited),
                TraceStyle::new(WITNESS, Dash::Dotted, 2),
            ));
        }
        let x = panel.resolved_x_range();
        if let Some(r) = p.readout.filter(|r| *r > 0.0) {
            panel.traces.push(Trace::new(
                format!("readout {}", si_asd(r, p.observable.unit())),
                vec![(x.0, r), (x.1, r)],
                TraceStyle::new(READOUT, Dash::Dotted, 2),
            ));
        }
        panel.max_decades = Some(6.0);
        let y = panel.resolved_y_range();
        panel.y_range = Some(y);
        if !p.left_raw.is_empty() {
            let mut upper = Vec::new();
            for &(lo, hi) in &p.left_raw {
                let (lo, hi) = (lo.max(x.0), hi.min(x.1));
                upper.extend([(lo, 0.0), (lo, y.1), (hi, y.1), (hi, 0.0)]);
            }
            panel.band = Some(Band::new(
                "left raw (the prediction did not lower the record)",
                vec![(x.0, 0.0), (x.1, 0.0)],
                upper,
                BAND,
            ));
        }
        panel.traces.insert(
            0,
            Trace::new(
                "report band",
                vec![
                    (data.band_hz.0, y.0),
                    (data.band_hz.0, y.1),
                    (f64::NAN, f64::NAN),
                    (data.band_hz.1, y.0),
                    (data.band_hz.1, y.1),
                ],
                TraceStyle::new(BAND, Dash::Dotted, 1),
            ),
        );
        panel.legend = LegendPlacement::Inside;
        panels.push(panel);
    }
    if panels.is_empty() {
        return Err("no observable to draw".to_string());
    }
    let columns = if panels.len() == 1 { 1 } else { 2 };
    let rows = (panels.len() + 1).div_ceil(columns);
    Ok(LogLogFigure {
        size: (1800, 120 + 620 * rows as u32),
        title: Some(
            "Tilt subtraction on the held-out stretch: one-sided amplitude spectral densities"
                .to_string(),
        ),
        panels,
        columns,
        caption: data.caption.clone(),
        shared_legend: true,
    })
}

/// Draws the figure as a PNG or SVG file's bytes, with the limits, size and resolution of
/// `view`.
///
/// # Errors
///
/// [`DrawError`] for inconsistent data or any drawing failure.
pub fn subtract_figure(
    data: &SubtractFigureData,
    view: &View,
    format: ImageFormat,
) -> Result<Vec<u8>, DrawError> {
    let figure = build_subtract_figure(data).map_err(|e| DrawError(e.into()))?;
    render(format, &view.apply(figure))
}
