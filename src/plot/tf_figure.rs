//! The paper's Figure 5: moduli of the transfer functions from the floor tilt angles
//! (θₜ solid, ηₜ dashed, φₜ dotted) to the soft-DoF observables X, φ and φₐ.

use super::chart::{Dash, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
// Re-exported: `plot::tf_figure::observable_symbol` is a public path.
pub use super::labels::observable_symbol;
use super::labels::{observable_title, tilt_symbol};
use super::save_figure;
use crate::error::OutputError;
use crate::model::{Observable, TiltAxis};
use crate::tf::{Input, TransferMatrix};
use std::path::Path;

/// Options of [`tf_figure_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct TfFigureOptions {
    /// Image size in pixels.
    pub size: (u32, u32),
    /// Appended to the figure title in parentheses, e.g. `undamped, Table I parameters`.
    pub note: Option<String>,
    /// Observables to draw, one panel each, in this order; those absent from the matrix are
    /// skipped.
    pub observables: Vec<Observable>,
}

impl Default for TfFigureOptions {
    fn default() -> Self {
        TfFigureOptions {
            size: (1200, 1000),
            note: None,
            observables: vec![Observable::X, Observable::Phi, Observable::PhiA],
        }
    }
}

/// Writes Figure 5 of the paper to `path` (`.png` or `.svg`): |H| of X (m/rad), φ (rad/rad)
/// and φₐ (rad/rad) per floor tilt angle versus frequency, log-log. Entries that are exactly
/// zero at every frequency are not drawn but listed in the legend as identically 0. Panels for
/// observables absent from `tf` are skipped; non-tilt inputs are ignored.
pub fn tf_figure(tf: &TransferMatrix, path: &Path) -> Result<(), OutputError> {
    tf_figure_with(tf, path, &TfFigureOptions::default())
}

/// [`tf_figure`] with a different size, title note or set of observables.
pub fn tf_figure_with(
    tf: &TransferMatrix,
    path: &Path,
    options: &TfFigureOptions,
) -> Result<(), OutputError> {
    let figure = build_tf_figure(tf, options).map_err(|message| OutputError::Write {
        path: path.to_path_buf(),
        message,
    })?;
    save_figure(path, &figure)
}

/// Display name and line style of a tilt axis: θₜ solid, ηₜ dashed, φₜ dotted (as in the paper).
pub fn tilt_symbol_style(t: TiltAxis) -> (&'static str, TraceStyle) {
    let style = match t {
        TiltAxis::ThetaT => TraceStyle::new(PALETTE[0], Dash::Solid, 2),
        TiltAxis::EtaT => TraceStyle::new(PALETTE[1], Dash::Dashed, 2),
        TiltAxis::PhiT => TraceStyle::new(PALETTE[2], Dash::Dotted, 3),
    };
    (tilt_symbol(t), style)
}

/// The figure as data, ready for [`save_figure`]; errors are plain messages.
pub fn build_tf_figure(
    tf: &TransferMatrix,
    options: &TfFigureOptions,
) -> Result<LogLogFigure, String> {
    let tilts: Vec<(usize, TiltAxis)> = TiltAxis::ALL
        .into_iter()
        .filter_map(|t| tf.input_index(Input::Tilt(t)).map(|i| (i, t)))
        .collect();
    if tilts.is_empty() {
        return Err("the transfer matrix has no tilt input (theta_t, eta_t, phi_t)".to_string());
    }
    let mut panels = Vec::new();
    for &o in &options.observables {
        let Some(oi) = tf.output_index(o) else {
            continue;
        };
        let unit = format!("{}/rad", o.unit());
        let mut panel = Panel::new(
            observable_title(o),
            ("frequency", "Hz"),
            (&format!("|{} / tilt|", observable_symbol(o)), &unit),
        );
        // Undamped peaks reach 1e6 while phi/eta_t falls as f^4 to 1e-10 at 0.1 mHz: show
        // 18 decades so the low-frequency cancellation stays visible.
        panel.max_decades = Some(18.0);
        for &(ii, t) in &tilts {
            let (name, style) = tilt_symbol_style(t);
            let identically_zero = (0..tf.freqs_hz.len()).all(|k| tf.get(k, oi, ii).norm() == 0.0);
            if identically_zero {
                panel.notes.push(format!("{name}: identically 0"));
                continue;
            }
            let points = tf
                .freqs_hz
                .iter()
                .enumerate()
                .map(|(k, &f)| (f, tf.get(k, oi, ii).norm()))
                .collect();
            panel.traces.push(Trace::new(name, points, style));
        }
        panels.push(panel);
    }
    if panels.is_empty() {
        let names: Vec<&str> = options.observables.iter().map(|o| o.name()).collect();
        return Err(format!(
            "the transfer matrix has none of the observables {}",
            names.join(", ")
        ));
    }
    let mut title = format!(
        "Floor tilt → observables: |H(f)|, method {}",
        tf.method.name()
    );
    if let Some(note) = &options.note {
        title.push_str(&format!(" ({note})"));
    }
    let mut caption = vec![
        "Lines: θₜ solid, ηₜ dashed, φₜ dotted. |H| is the modulus of the complex response \
         per radian of floor tilt."
            .to_string(),
        "Sign convention: tilt t = small rotation taking the floor frame to the inertial \
         frame (the floor turns by −t); observables are read in the enclosure frame."
            .to_string(),
        "Quasi-static limit f → 0: X → −ηₜ (Z + Z_b + h_c), Y → θₜ (Z + Z_b + h_c); the other \
         entries shown tend to 0 (φ/ηₜ and φₐ/ηₜ as f⁴)."
            .to_string(),
    ];
    if let (Some(first), Some(last)) = (tf.freqs_hz.first(), tf.freqs_hz.last()) {
        caption.push(format!(
            "Evaluated at {} frequencies from {} to {} Hz. Without loss angles the resonance \
             peaks are limited only by the frequency grid.",
            tf.freqs_hz.len(),
            compact_number(*first),
            compact_number(*last)
        ));
    }
    Ok(LogLogFigure {
        size: options.size,
        title: Some(title),
        panels,
        columns: 2,
        caption,
    })
}

/// A frequency for prose: `10⁻⁴` for exact powers of ten, else 3 significant digits.
fn compact_number(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return format!("{v}");
    }
    let e = v.log10();
    if (e - e.round()).abs() < 1e-9 {
        return super::chart::pow10_label(e.round() as i32);
    }
    if (1e-3..1e4).contains(&v) {
        let decimals = (2 - e.floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.2e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::params::Params;
    use crate::tf::{evaluate, plan, Method, Request};

    fn matrix() -> TransferMatrix {
        let model = Model::new(&Params::table_i()).unwrap();
        let tf = plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
        let freqs: Vec<f64> = (0..4).map(|k| 10f64.powi(k - 3)).collect();
        evaluate(&*tf, &freqs).unwrap()
    }

    #[test]
    fn structural_zero_goes_to_legend_note() {
        let tf = matrix();
        let fig = build_tf_figure(&tf, &TfFigureOptions::default()).unwrap();
        assert_eq!(fig.panels.len(), 3);
        let x = &fig.panels[0];
        assert!(x.y_unit == "m/rad");
        let total = x.traces.len() + x.notes.len();
        assert_eq!(total, 3);
        // X does not respond to theta_t (the 4-DoF blocks decouple).
        assert!(x.notes.iter().any(|n| n.starts_with("θₜ")), "{:?}", x.notes);
    }

    #[test]
    fn compact_numbers() {
        assert_eq!(compact_number(1e-4), "10⁻⁴");
        assert_eq!(compact_number(30.0), "30");
        assert_eq!(compact_number(0.0123456), "0.0123");
        assert_eq!(compact_number(2.5e-6), "2.50e-6");
    }

    #[test]
    fn absent_observables_are_skipped() {
        let mut tf = matrix();
        let keep = tf.output_index(Observable::Phi).unwrap();
        let (no, ni) = (tf.outputs.len(), tf.inputs.len());
        let mut values = Vec::new();
        for k in 0..tf.freqs_hz.len() {
            for i in 0..ni {
                values.push(tf.values[(k * no + keep) * ni + i]);
            }
        }
        tf.values = values;
        tf.outputs = vec![Observable::Phi];
        let fig = build_tf_figure(&tf, &TfFigureOptions::default()).unwrap();
        assert_eq!(fig.panels.len(), 1);
        tf.outputs = vec![Observable::Z];
        assert!(build_tf_figure(&tf, &TfFigureOptions::default()).is_err());
    }
}
