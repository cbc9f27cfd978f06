//! The figure of a subtraction, as `subtract --save x.png` draws it and Python's
//! `Subtraction.save("x.png")`: per observable the held-out ASDs (measured, predicted,
//! cleaned, Wiener residual, coherence limit, witness-noise limit), the bands left raw, the
//! readout, and a caption with the fit.

use super::report::band_top;
use crate::subtract::SubtractOutcome;
use std::path::Path;
use tiltnoise_core::error::Num;
use tiltnoise_core::subtract::{Estimate, Status, SubtractResult};
use tiltnoise_io::{OutputError, Staging};
use tiltnoise_plot::subtract_figure::{subtract_figure, ObservablePanel, SubtractFigureData};
use tiltnoise_plot::View;

/// The layout size of the figure at the nominal resolution (pixels): two rows of panels.
pub const FIGURE_SIZE: (u32, u32) = (1800, 1360);

/// A value with its uncertainty, to the uncertainty's second digit: `0.97015 +/- 9.2e-05`;
/// an uncertainty that is not finite and positive says the value is not constrained at all.
pub fn with_sigma(value: f64, sigma: f64) -> String {
    if sigma.is_finite() && sigma > 0.0 {
        let digits = (-(sigma.log10().floor()) + 1.0).clamp(0.0, 12.0) as usize;
        format!("{value:.digits$} +/- {sigma:.2e}")
    } else {
        format!("{value} +/- (not constrained at all)")
    }
}

/// `x` with three significant digits, without an exponent for 1e-4 <= |x| < 1e4.
fn sig3(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || !(1e-4..1e4).contains(&x.abs()) {
        return format!("{x:.2e}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

impl SubtractOutcome {
    /// The data of the figure.
    pub fn figure_data(&self) -> SubtractFigureData {
        figure_data(&self.result)
    }

    /// Draws the figure in the format the extension of `path` names (`.png`, `.svg`) with
    /// `view`'s limits, size and resolution, and writes it as one of the
    /// outputs of `stage`.
    ///
    /// # Errors
    ///
    /// [`OutputError::UnknownFormat`] for another extension, [`OutputError::Write`] naming
    /// `path` when it cannot be drawn or written (nothing is left there).
    pub fn save_figure(
        &self,
        stage: &Staging,
        path: &Path,
        view: &View,
    ) -> Result<(), OutputError> {
        let data = self.figure_data();
        crate::save_image(stage, path, |format| subtract_figure(&data, view, format))
    }
}

/// One estimate in the caption: `gain.eta_t = 0.97015 ± 9.2e-05`.
fn caption_estimate(e: &Estimate) -> String {
    match (e.status, e.prior_sigma) {
        (Status::NotConstrained, None) => {
            format!("{} not constrained (held at {})", e.name, e.nominal)
        }
        _ => format!(
            "{} = {}",
            e.name,
            with_sigma(e.value, e.sigma).replace("+/-", "±")
        ),
    }
}

/// The caption: the fit, the report band, how the held-out curves were made.
fn caption(r: &SubtractResult) -> Vec<String> {
    let est: Vec<String> = r.fit.estimates.iter().map(caption_estimate).collect();
    let mut caption = vec![format!(
        "Fit ({}–{} Hz, χ²/dof = {:.3}): {}.",
        sig3(r.fit.band_hz.0),
        sig3(r.fit.band_hz.1),
        r.fit.chi2 / r.fit.dof as f64,
        est.join(", ")
    )];
    let ratios: Vec<String> = r
        .residuals
        .iter()
        .filter_map(|res| {
            res.band
                .cleaned_to_readout
                .map(|(ratio, sigma)| format!("{} {ratio:.3} ± {sigma:.3}", res.observable.name()))
        })
        .collect();
    if let Some(first) = r.residuals.first() {
        caption.push(format!(
            "Report band {}–{} Hz (dotted lines){}.",
            sig3(first.band.band_hz.0),
            sig3(first.band.band_hz.1),
            if ratios.is_empty() {
                String::new()
            } else {
                format!(": cleaned / readout ASD = {}", ratios.join(", "))
            }
        ));
    }
    let excess = r
        .residuals
        .first()
        .map_or(f64::NAN, |s| s.wiener_training_excess);
    let witness = if r
        .witness_noise_psd
        .iter()
        .any(|(_, m)| m.iter().any(|&v| v > 0.0))
    {
        " Witness-noise limit: what the witness's own noise keeps any filter of it from \
         removing, through the fitted model."
    } else {
        ""
    };
    caption.push(format!(
        "Held-out stretch: the last {} of {} samples at {} Hz; Welch {} samples, Hann, 50 % \
         overlap. Wiener residual: multiple-input filter trained on the first {} samples (its \
         training noise adds about {:.1} % to its PSD). Coherence limit: (1 − γ²) of the \
         measured PSD, the least any linear filter of the witness record can leave.{witness}",
        r.n_holdout,
        r.alignment.len,
        Num(r.alignment.fs_hz),
        r.segment_len,
        r.n_train,
        100.0 * excess
    ));
    caption
}

fn figure_data(r: &SubtractResult) -> SubtractFigureData {
    let asd = |p: &[f64]| p.iter().map(|v| v.max(0.0).sqrt()).collect::<Vec<f64>>();
    SubtractFigureData {
        panels: r
            .residuals
            .iter()
            .map(|s| ObservablePanel {
                observable: s.observable,
                freqs_hz: s.freqs_hz.clone(),
                measured: asd(&s.measured_psd),
                predicted: asd(&s.predicted_psd),
                cleaned: asd(&s.cleaned_psd),
                wiener: asd(&s.wiener_psd),
                expected: asd(&s.expected_psd),
                witness_limited: asd(&s.witness_limited_psd),
                left_raw: r
                    .bands
                    .iter()
                    .find(|(o, _)| *o == s.observable)
                    .map(|(_, c)| {
                        c.bands
                            .iter()
                            .filter(|b| b.left_raw || c.left_raw)
                            .map(|b| (b.lo_hz, band_top(b.hi_hz, r.alignment.fs_hz)))
                            .collect()
                    })
                    .unwrap_or_default(),
                readout: s.readout_asd,
            })
            .collect(),
        band_hz: r
            .residuals
            .first()
            .map_or((f64::NAN, f64::NAN), |s| s.band.band_hz),
        caption: caption(r),
    }
}
