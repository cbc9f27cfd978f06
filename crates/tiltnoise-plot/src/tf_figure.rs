//! The paper's Figure 5: moduli of the transfer functions from the floor tilt angles
//! (θₜ solid, ηₜ dashed, φₜ dotted) to the soft-DoF observables X, φ and φₐ; and the same
//! layout for the floor's translations and for force and torque inputs (one panel per observable
//! and kind of input, so each panel has one unit: m/m, m/N, rad/(N m), ...).

use super::chart::{Dash, LogLogFigure, Panel, Trace, TraceStyle, PALETTE};
use tiltnoise_core::option_key::OptionKey;
// Re-exported: `plot::tf_figure::observable_symbol` is a public path.
use super::chart::{LegendPlacement, YScale};
pub use super::labels::observable_symbol;
use super::labels::{observable_title, tilt_symbol, translation_symbol};
use super::{render, DrawError, ImageFormat, View};
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::model::{ForceInput, Input, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::tf::TransferMatrix;

/// Options of [`tf_figure_with`].
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TfFigureOptions {
    /// Appended to the figure title in parentheses, e.g. `undamped, Table I parameters`.
    pub note: Option<String>,
    /// Observables to draw, one row of panels each, in this order; each must be an output of
    /// the matrix. `None`: every output of the matrix.
    pub observables: Option<Vec<Observable>>,
    /// Bode plot: a phase panel (degrees) beside every magnitude panel.
    pub phase: bool,
    /// Whether the model has loss angles or viscous damping (said in the caption: an undamped
    /// model's peak heights are set by the frequency grid alone).
    pub damped: bool,
    /// Axis limits, size, resolution; the default size grows with the number of panels.
    pub view: View,
    /// The option that chooses the panels, as the front end that draws the figure spells it
    /// (`--plot-observables`, `observables`): the caption names it when computed observables
    /// are left out. Empty: its canonical key, `drawn_observables`.
    pub panels_option: String,
}

/// Draws Figure 5 of the paper as a PNG or SVG file's bytes: |H| of X (m/rad), φ (rad/rad)
/// and φₐ (rad/rad) per floor tilt angle versus frequency, log-log. Entries that are exactly
/// zero at every frequency are not drawn but listed in the legend as identically 0. Panels for
/// observables absent from `tf` are skipped. Force and torque inputs get panels of their own
/// (m/N, rad/N, m/(N m), rad/(N m)) beside the tilt panels.
///
/// # Errors
///
/// [`DrawError`] for a transfer matrix that cannot be drawn or any drawing failure.
pub fn tf_figure(tf: &TransferMatrix, format: ImageFormat) -> Result<Vec<u8>, DrawError> {
    tf_figure_with(tf, format, &TfFigureOptions::default())
}

/// [`tf_figure`] with a different size, title note or set of observables.
pub fn tf_figure_with(
    tf: &TransferMatrix,
    format: ImageFormat,
    options: &TfFigureOptions,
) -> Result<Vec<u8>, DrawError> {
    let figure = build_tf_figure(tf, options).map_err(|e| DrawError(e.into()))?;
    render(format, &options.view.apply(figure))
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

/// Display name and line style of a floor-translation axis: xₜ solid, yₜ dashed, zₜ dotted, in
/// colours of their own (the tilt's are taken).
pub fn translation_symbol_style(t: TranslationAxis) -> (&'static str, TraceStyle) {
    let style = match t {
        TranslationAxis::XT => TraceStyle::new(PALETTE[3], Dash::Solid, 2),
        TranslationAxis::YT => TraceStyle::new(PALETTE[4], Dash::Dashed, 2),
        TranslationAxis::ZT => TraceStyle::new(PALETTE[5], Dash::Dotted, 3),
    };
    (translation_symbol(t), style)
}

/// The kinds of input a panel groups: one panel per observable and kind, since the units differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum InputKind {
    /// Floor tilt angles (rad).
    Tilt,
    /// Floor translations (m).
    Translation,
    /// Force components (N).
    Force,
    /// Torque components (N m).
    Torque,
}

impl InputKind {
    /// Every kind, in panel order.
    const ALL: [InputKind; 4] = [
        InputKind::Tilt,
        InputKind::Translation,
        InputKind::Force,
        InputKind::Torque,
    ];

    fn of(input: Input) -> InputKind {
        match input {
            Input::Tilt(_) => InputKind::Tilt,
            Input::Translation(_) => InputKind::Translation,
            Input::Force(f) if f.unit() == "N" => InputKind::Force,
            Input::Force(_) => InputKind::Torque,
        }
    }

    /// `(y-axis symbol of the input, unit of the response per unit input, title suffix)`, the
    /// floor's motion per unit `per` (its displacement, velocity or acceleration).
    fn labels(self, o: Observable, per: GroundQuantity) -> (&'static str, String, &'static str) {
        let floor = |unit: &str| match per.unit(unit) {
            u if u.contains('/') => format!("{}/({u})", o.unit()),
            u => format!("{}/{u}", o.unit()),
        };
        match self {
            InputKind::Tilt => ("tilt", floor("rad"), ""),
            InputKind::Translation => ("u", floor("m"), ", per floor translation"),
            InputKind::Force => ("F", format!("{}/N", o.unit()), ", per force"),
            InputKind::Torque => ("M", format!("{}/(N m)", o.unit()), ", per torque"),
        }
    }
}

/// What a tilt (`radian`) or translation (`metre`) column is per, for the caption.
fn per_unit_text(per: GroundQuantity, unit: &str) -> String {
    let symbol = if unit == "radian" { "rad" } else { "m" };
    match per {
        GroundQuantity::Displacement => unit.to_string(),
        GroundQuantity::Velocity => format!("{symbol}/s"),
        GroundQuantity::Acceleration => format!("{symbol}/s²"),
    }
}

/// Display name (the command-line name, e.g. `F_b.x`) and line style of a force or torque
/// component: colour by axis (x, y, z), solid on the test mass (`b`), dashed on the crossbar (`a`).
pub fn force_symbol_style(f: ForceInput) -> (String, TraceStyle) {
    let name = f.name();
    let axis = match name.as_bytes()[name.len() - 1] {
        b'x' => 0,
        b'y' => 1,
        _ => 2,
    };
    let on_test_mass = name.as_bytes()[2] == b'b';
    let dash = if on_test_mass {
        Dash::Solid
    } else {
        Dash::Dashed
    };
    (name.to_string(), TraceStyle::new(PALETTE[axis], dash, 2))
}

/// The default pixel size of the figure for `inputs` under `options` (observables `None`:
/// counted as the paper's three): two columns, rows of about 320 px, at least 1200 x 1000.
pub fn default_size(options: &TfFigureOptions, inputs: &[Input]) -> (u32, u32) {
    let kinds = InputKind::ALL
        .into_iter()
        .filter(|&k| inputs.iter().any(|&i| InputKind::of(i) == k))
        .count();
    let observables = options.observables.as_ref().map_or(3, Vec::len);
    size_for_panels(observables * kinds.max(1) * if options.phase { 2 } else { 1 })
}

/// Two columns, the caption in a free cell or a strip below; rows of about 320 px.
fn size_for_panels(panels: usize) -> (u32, u32) {
    let rows = (panels + 1).div_ceil(2) as u32;
    (1200, (110 + 320 * rows).max(1000))
}

/// The figure as data, ready for [`render`]; errors are plain messages.
///
/// One panel per requested observable and kind of input present (tilt in rad, forces in N,
/// torques in N m), so every panel has a single unit; a tilt-only matrix gives the paper's
/// Figure 5 layout.
pub fn build_tf_figure(
    tf: &TransferMatrix,
    options: &TfFigureOptions,
) -> Result<LogLogFigure, String> {
    let kinds: Vec<InputKind> = InputKind::ALL
        .into_iter()
        .filter(|&k| tf.inputs.iter().any(|&i| InputKind::of(i) == k))
        .collect();
    if kinds.is_empty() {
        return Err("the transfer matrix has no input".to_string());
    }
    let observables = match &options.observables {
        None => tf.outputs.clone(),
        Some(list) => list.clone(),
    };
    if observables.is_empty() {
        return Err("no observable to draw".to_string());
    }
    let mut panels = Vec::new();
    for &o in &observables {
        let Some(oi) = tf.output_index(o) else {
            let have: Vec<&str> = tf.outputs.iter().map(|o| o.name()).collect();
            return Err(format!(
                "observable {} is not an output of the transfer matrix (outputs: {})",
                o.name(),
                have.join(", ")
            ));
        };
        for &kind in &kinds {
            let (panel, phase) = magnitude_and_phase(tf, o, oi, kind);
            panels.push(panel);
            if options.phase {
                panels.push(phase);
            }
        }
    }
    let has_tilt = kinds.contains(&InputKind::Tilt);
    let has_translation = kinds.contains(&InputKind::Translation);
    let has_forces = kinds.contains(&InputKind::Force) || kinds.contains(&InputKind::Torque);
    let floor = match (has_tilt, has_translation) {
        (true, false) => Some("Floor tilt"),
        (false, true) => Some("Floor translation"),
        (true, true) => Some("Floor tilt and translation"),
        (false, false) => None,
    };
    let what = match (floor, has_forces) {
        (Some(floor), false) => floor.to_string(),
        (None, _) => "Forces and torques".to_string(),
        (Some(floor), true) => format!("{floor}, forces and torques"),
    };
    let shown = if options.phase {
        "|H(f)| and phase"
    } else {
        "|H(f)|"
    };
    let mut title = format!("{what} → observables: {shown}, method {}", tf.method.name());
    if let Some(note) = &options.note {
        title.push_str(&format!(" ({note})"));
    }
    let caption = caption(
        tf,
        options,
        (has_tilt, has_translation, has_forces),
        &observables,
    );
    Ok(LogLogFigure {
        size: size_for_panels(panels.len()),
        title: Some(title),
        panels,
        columns: 2,
        caption,
        // With phase panels, one legend below the grid: beside each magnitude panel it would
        // take half its width.
        shared_legend: options.phase,
    })
}

/// The magnitude panel of observable `o` (output `oi` of `tf`) against the inputs of `kind`,
/// and its phase panel.
fn magnitude_and_phase(
    tf: &TransferMatrix,
    o: Observable,
    oi: usize,
    kind: InputKind,
) -> (Panel, Panel) {
    let (input_symbol, unit, suffix) = kind.labels(o, tf.ground_quantity());
    let mut panel = Panel::new(
        format!("{}{suffix}", observable_title(o)),
        ("frequency", "Hz"),
        (
            &format!("|{} / {input_symbol}|", observable_symbol(o)),
            &unit,
        ),
    );
    // Undamped peaks reach 1e6 while phi/eta_t falls as f^4 to 1e-10 at 0.1 mHz and
    // force responses as f^-4 to 1e-14 at 30 Hz: the automatic range clips the peaks,
    // and up to 24 decades keep those tails visible.
    panel.max_decades = Some(24.0);
    let mut phase = Panel::new(
        format!("{}{suffix}: phase", observable_symbol(o)),
        ("frequency", "Hz"),
        (
            &format!("arg({} / {input_symbol})", observable_symbol(o)),
            "deg",
        ),
    );
    phase.y_scale = YScale::Linear {
        tick_step: Some(90.0),
    };
    // A little beyond ±180 so a phase of 180 (an undamped sign) is not on the frame.
    phase.y_range = Some((-200.0, 200.0));
    phase.legend = LegendPlacement::Hidden;
    for (ii, &input) in tf.inputs.iter().enumerate() {
        if InputKind::of(input) != kind {
            continue;
        }
        let (name, style) = match input {
            Input::Tilt(t) => {
                let (name, style) = tilt_symbol_style(t);
                (name.to_string(), style)
            }
            Input::Translation(t) => {
                let (name, style) = translation_symbol_style(t);
                (name.to_string(), style)
            }
            Input::Force(f) => force_symbol_style(f),
        };
        let identically_zero = (0..tf.freqs_hz.len()).all(|k| tf.get(k, oi, ii).norm() == 0.0);
        if identically_zero {
            panel.notes.push(format!("{name}: identically 0"));
            phase.notes.push(format!("{name}: identically 0"));
            continue;
        }
        let points = tf
            .freqs_hz
            .iter()
            .enumerate()
            .map(|(k, &f)| (f, tf.get(k, oi, ii).norm()))
            .collect();
        panel.traces.push(Trace::new(name.clone(), points, style));
        let degrees = phase_points(
            &tf.freqs_hz,
            (0..tf.freqs_hz.len()).map(|k| tf.get(k, oi, ii).arg().to_degrees()),
        );
        phase.traces.push(Trace::new(name, degrees, style));
    }
    (panel, phase)
}

/// The lines under the figure: the conventions of the inputs present (tilt, translation, forces),
/// the grid, the phase's convention, the outputs not drawn.
fn caption(
    tf: &TransferMatrix,
    options: &TfFigureOptions,
    (has_tilt, has_translation, has_forces): (bool, bool, bool),
    observables: &[Observable],
) -> Vec<String> {
    let mut caption = Vec::new();
    if has_tilt {
        caption.extend([
            format!(
                "Tilt lines: θₜ solid, ηₜ dashed, φₜ dotted. |H| is the modulus of the complex \
                 response per {} of floor tilt.",
                per_unit_text(tf.ground_quantity(), "radian")
            ),
            "Sign convention: tilt t = small rotation taking the floor frame to the inertial \
             frame (the floor turns by −t); observables are read in the enclosure frame."
                .to_string(),
            "Quasi-static limit f → 0: X → −ηₜ (Z + Z_b + h_c), Y → θₜ (Z + Z_b + h_c); the \
             other entries shown tend to 0 (φ/ηₜ and φₐ/ηₜ as f⁴)."
                .to_string(),
        ]);
    }
    if has_translation {
        caption.extend([
            format!(
                "Translation lines: xₜ solid, yₜ dashed, zₜ dotted. |H| is the modulus of the \
                 response per {} of floor translation (the floor, the suspension point and the \
                 housing move together; the crossbar arm lies along y).",
                per_unit_text(tf.ground_quantity(), "metre")
            ),
            "Equivalence principle, f → 0: per unit floor acceleration a = −ω² u, xₜ acts as the \
             tilt ηₜ = aₓ/g and yₜ as θₜ = −a_y/g; zₜ as a change of g (the fibres' stretch). \
             Every response per metre falls at least as f² at low frequency (φ/xₜ and φₐ/xₜ \
             as f⁴)."
                .to_string(),
        ]);
    }
    if (has_tilt || has_translation) && tf.ground_quantity() != GroundQuantity::Displacement {
        caption.push(format!(
            "Per unit {} of the floor's motion: the response per unit displacement divided by \
             {}.",
            tf.ground_quantity().name(),
            match tf.ground_quantity() {
                GroundQuantity::Velocity => "iω",
                _ => "−ω²",
            }
        ));
    }
    if has_forces {
        caption.push(
            "Forces F (N) act at the centres of mass, torques M (N m) about them, inertial axes \
             (Appendix A, zeroth order). Colour: x, y, z component; solid: on the test mass (b), \
             dashed: on the crossbar (a)."
                .to_string(),
        );
    }
    if let (Some(first), Some(last)) = (tf.freqs_hz.first(), tf.freqs_hz.last()) {
        let peaks = if options.damped {
            "With the damping of the parameters (loss angles, viscous terms) the peak heights \
             are the model's, where the grid resolves them."
        } else {
            "Without loss angles the resonance peaks are limited only by the frequency grid."
        };
        caption.push(format!(
            "Evaluated at {} frequencies from {} to {} Hz. {peaks}",
            tf.freqs_hz.len(),
            compact_number(*first),
            compact_number(*last)
        ));
    }
    if options.phase {
        caption.push(
            "Phase: arg H in degrees, time dependence exp(+iωt); a lag is a negative phase."
                .to_string(),
        );
    }
    let omitted: Vec<&str> = tf
        .outputs
        .iter()
        .filter(|o| !observables.contains(o))
        .map(|o| o.name())
        .collect();
    if !omitted.is_empty() {
        let option = match options.panels_option.as_str() {
            "" => OptionKey::DRAWN_OBSERVABLES.key(),
            spelled => spelled,
        };
        caption.push(format!(
            "Not drawn (in the files): {}; {option} chooses the panels.",
            omitted.join(", "),
        ));
    }
    caption
}

/// Largest phase step (degrees) drawn as a line between neighbouring frequencies: a larger
/// step (a wrap from +180 to −180, an undamped sign change, a resonance narrower than the
/// grid) is not resolved by the grid, so the line breaks there instead of drawing a vertical
/// stroke across the panel.
pub const PHASE_JUMP_DEG: f64 = 90.0;

/// `(f, phase)` points with the phase wrapped to (−180, 180] degrees and a break (a NaN
/// point, which the chart does not connect) wherever it steps by more than [`PHASE_JUMP_DEG`].
fn phase_points(freqs_hz: &[f64], degrees: impl Iterator<Item = f64>) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(freqs_hz.len());
    let mut prev: Option<(f64, f64)> = None;
    for (&f, d) in freqs_hz.iter().zip(degrees) {
        let wrapped = if d <= -180.0 { d + 360.0 } else { d };
        if let Some((pf, pd)) = prev {
            if (wrapped - pd).abs() > PHASE_JUMP_DEG {
                out.push((0.5 * (pf + f), f64::NAN));
            }
        }
        out.push((f, wrapped));
        prev = Some((f, wrapped));
    }
    out
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
    use tiltnoise_core::model::Model;
    use tiltnoise_core::params::Params;
    use tiltnoise_core::tf::{evaluate, plan, Method, Request};

    fn matrix() -> TransferMatrix {
        let model = Model::new(&Params::table_i()).unwrap();
        let tf = plan(&model, &Request::all_tilt(), Method::Direct).unwrap();
        let freqs: Vec<f64> = (0..4).map(|k| 10f64.powi(k - 3)).collect();
        evaluate(&*tf, &freqs).unwrap()
    }

    #[test]
    fn phase_wraps_and_breaks_at_unresolved_jumps() {
        let f = [1.0, 2.0, 3.0, 4.0, 5.0];
        let p = phase_points(&f, [170.0, 179.0, -180.0, -170.0, 0.0].into_iter());
        let ys: Vec<f64> = p.iter().map(|q| q.1).collect();
        // -180 is drawn as 180, continuing the line; 180 -> -170 and -170 -> 0 break.
        assert_eq!(ys[..3], [170.0, 179.0, 180.0]);
        assert!(ys[3].is_nan());
        assert_eq!(ys[4], -170.0);
        assert!(ys[5].is_nan());
        assert_eq!((p.len(), ys[6]), (7, 0.0));
    }

    #[test]
    fn structural_zero_goes_to_legend_note() {
        let tf = matrix();
        let options = TfFigureOptions {
            observables: Some(vec![Observable::X, Observable::Phi, Observable::PhiA]),
            ..TfFigureOptions::default()
        };
        let fig = build_tf_figure(&tf, &options).unwrap();
        assert_eq!(fig.panels.len(), 3);
        // The caption names the outputs left out.
        assert!(
            fig.caption.iter().any(|c| c.contains("Y, Z, theta, eta")),
            "{:?}",
            fig.caption
        );
        // Every output by default; with --phase a phase panel beside each.
        let all = build_tf_figure(&tf, &TfFigureOptions::default()).unwrap();
        assert_eq!(all.panels.len(), 7);
        let bode = TfFigureOptions {
            phase: true,
            ..options
        };
        let fig = build_tf_figure(&tf, &bode).unwrap();
        assert_eq!(fig.panels.len(), 6);
        assert_eq!(
            fig.panels[1].y_scale,
            YScale::Linear {
                tick_step: Some(90.0)
            }
        );
        let x = &fig.panels[0];
        assert!(x.y_unit == "m/rad");
        let total = x.traces.len() + x.notes.len();
        assert_eq!(total, 3);
        // X does not respond to theta_t (the 4-DoF blocks decouple).
        assert!(x.notes.iter().any(|n| n.starts_with("θₜ")), "{:?}", x.notes);
    }

    #[test]
    fn force_inputs_get_their_own_panels_and_units() {
        let model = Model::new(&Params::table_i()).unwrap();
        let mut request = Request::all_tilt();
        request.inputs.truncate(2);
        for name in ["F_b.x", "M_b.z", "M_a.z"] {
            request
                .inputs
                .push(Input::Force(ForceInput::from_name(name).unwrap()));
        }
        request.outputs = vec![Observable::X, Observable::Phi];
        let tf = plan(&model, &request, Method::Direct).unwrap();
        let tf = evaluate(&*tf, &[1e-3, 1e-2, 1.0]).unwrap();
        let fig = build_tf_figure(&tf, &TfFigureOptions::default()).unwrap();
        // 2 observables x (tilt, force, torque).
        assert_eq!(fig.panels.len(), 6);
        let units: Vec<&str> = fig.panels.iter().map(|p| p.y_unit.as_str()).collect();
        assert_eq!(
            units,
            ["m/rad", "m/N", "m/(N m)", "rad/rad", "rad/N", "rad/(N m)"]
        );
        // The torque panel of phi has both torques drawn, the force panel F_b.x only.
        assert_eq!(fig.panels[5].traces.len(), 2);
        assert_eq!(fig.panels[4].traces.len(), 1);
        assert!(fig
            .title
            .as_deref()
            .unwrap()
            .starts_with("Floor tilt, forces and torques"));
        // Styles: test-mass torque solid, crossbar torque dashed, same z colour.
        let (_, b) = force_symbol_style(ForceInput::from_name("M_b.z").unwrap());
        let (_, a) = force_symbol_style(ForceInput::from_name("M_a.z").unwrap());
        assert_ne!(a, b);
    }

    #[test]
    fn compact_numbers() {
        assert_eq!(compact_number(1e-4), "10⁻⁴");
        assert_eq!(compact_number(30.0), "30");
        assert_eq!(compact_number(0.0123456), "0.0123");
        assert_eq!(compact_number(2.5e-6), "2.50e-6");
    }

    #[test]
    fn absent_observables_are_refused_by_name() {
        let tf = matrix();
        let keep = tf.output_index(Observable::Phi).unwrap();
        let tf = tf.select_outputs(&[keep]);
        assert_eq!(tf.outputs, vec![Observable::Phi]);
        let fig = build_tf_figure(&tf, &TfFigureOptions::default()).unwrap();
        assert_eq!(fig.panels.len(), 1);
        let options = TfFigureOptions {
            observables: Some(vec![Observable::Z]),
            ..TfFigureOptions::default()
        };
        let e = build_tf_figure(&tf, &options).unwrap_err();
        assert!(e.contains("Z is not an output") && e.contains("phi"), "{e}");
    }

    #[test]
    fn the_caption_says_whether_the_model_is_damped() {
        let tf = matrix();
        let undamped = build_tf_figure(&tf, &TfFigureOptions::default()).unwrap();
        assert!(undamped
            .caption
            .iter()
            .any(|c| c.contains("Without loss angles")));
        let options = TfFigureOptions {
            damped: true,
            ..TfFigureOptions::default()
        };
        let damped = build_tf_figure(&tf, &options).unwrap();
        assert!(!damped
            .caption
            .iter()
            .any(|c| c.contains("Without loss angles")));
        assert!(damped
            .caption
            .iter()
            .any(|c| c.contains("damping of the parameters")));
    }
}
