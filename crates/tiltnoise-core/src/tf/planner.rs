//! The planner: scenes and the automatic choice of model and method ("model no more than a
//! scene needs"). Every caller that wants a transfer function without naming a method (the
//! `auto` method of the command line, the budget, the equivalent-noise calibration) comes here.
//!
//! A scene names its inputs, its observables, its band and a relative tolerance. [`choose`]
//! tries the candidates from the smallest model and cheapest method upwards -- the 2-DoF
//! torsional model, the 4-DoF pole-zero product form, the block LU, the split formulation, modal
//! superposition, the full 8x8 LU -- and takes the first that meets the tolerance **measured**
//! against the ~30-digit reference ([`crate::reference`]) on a verification grid of the band.
//! Points within 1 % of a normal mode are left out of the verification (the accuracy
//! target excludes the poles), and a structurally zero entry must come out exactly zero. The
//! [`Choice`] keeps every candidate's verdict, so `--explain` can say what was picked and why;
//! so does [`NoChoice`] when nothing meets the tolerance, whose message names only the best.

use crate::error::{Num, TfError};
use crate::model::{Input, Request};
use crate::model::{Model, Observable};
use crate::modes::NormalModes;
use crate::reference::{relative_errors, CDd, ReferenceModel};
use crate::tf::{plan, Method, TransferFunction};
use num_complex::Complex64;

/// Points of the verification grid (log-spaced over the band, before removing near-mode points).
pub const VERIFY_POINTS: usize = 64;
/// Verification points closer than this relative distance to a mode frequency are skipped.
pub const POLE_EXCLUSION: f64 = 0.01;
/// The default tolerance of a scene: the accuracy target of every transfer function.
pub const DEFAULT_REL_TOL: f64 = 1e-9;

/// What a user wants computed, and how well.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Inputs and observables.
    pub request: Request,
    /// Frequency band (Hz), lo <= hi, both > 0.
    pub band_hz: (f64, f64),
    /// Largest acceptable relative error on any structurally nonzero entry.
    pub rel_tol: f64,
}

impl Scene {
    /// The scene of a frequency grid: `request` over the band from the grid's lowest positive
    /// frequency to its highest, at [`DEFAULT_REL_TOL`]. A grid without a positive finite
    /// frequency gives an empty band, which [`choose`] refuses.
    pub fn over_grid(request: Request, grid_hz: &[f64]) -> Scene {
        let positive = grid_hz
            .iter()
            .copied()
            .filter(|f| *f > 0.0 && f.is_finite());
        let lo = positive.clone().fold(f64::INFINITY, f64::min);
        let hi = positive.fold(0.0, f64::max);
        Scene {
            request,
            band_hz: (lo, hi),
            rel_tol: DEFAULT_REL_TOL,
        }
    }
}

/// One candidate's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// The method tried.
    pub method: Method,
    /// Degrees of freedom of the model it solves.
    pub dofs: usize,
    /// Measured worst relative error on the verification grid, or why it was not usable.
    pub outcome: Result<f64, String>,
}

/// The pick and the evidence.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// The chosen method.
    pub method: Method,
    /// Every candidate tried, in order.
    pub verdicts: Vec<Verdict>,
    /// The scene.
    pub scene: Scene,
}

/// Why [`choose`] picked no method. Its message is one line; [`NoChoice::explain`] lists
/// every candidate's verdict.
#[derive(Debug, Clone, PartialEq)]
pub enum NoChoice {
    /// The band cannot be verified: empty, not positive or not finite.
    Band(String),
    /// Every point of the band lies within [`POLE_EXCLUSION`] of a normal mode, where no
    /// method can be checked against the reference (the undamped response is infinite on the
    /// mode, and within that distance the mode frequency's own uncertainty decides the value):
    /// the caller chooses a method, or frequencies away from the mode.
    NearMode {
        /// The band asked for (Hz).
        band_hz: (f64, f64),
        /// The frequency of the nearest normal mode (Hz).
        mode_hz: f64,
    },
    /// Every candidate was tried and none meets the tolerance.
    Tolerance {
        /// The scene.
        scene: Scene,
        /// Every candidate's outcome, in order.
        verdicts: Vec<Verdict>,
    },
}

impl std::fmt::Display for NoChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (scene, verdicts) = match self {
            NoChoice::Band(why) => return f.write_str(why),
            NoChoice::NearMode { band_hz, mode_hz } => {
                let at = if band_hz.0 == band_hz.1 {
                    format!("{} Hz lies", Num(band_hz.0))
                } else {
                    format!(
                        "every frequency of {} .. {} Hz lies",
                        Num(band_hz.0),
                        Num(band_hz.1)
                    )
                };
                return write!(
                    f,
                    "{at} within {} % of the normal mode at {:.5e} Hz, where the automatic choice \
                     cannot check any method against the reference (on an undamped mode the \
                     response is infinite); choose the method yourself (pole-zero stays \
                     accurate next to a mode), or ask for frequencies at least {} % away from \
                     the mode",
                    100.0 * POLE_EXCLUSION,
                    mode_hz,
                    100.0 * POLE_EXCLUSION
                );
            }
            NoChoice::Tolerance { scene, verdicts } => (scene, verdicts),
        };
        let (lo, hi) = scene.band_hz;
        write!(
            f,
            "no method meets the relative tolerance {:e} on {} .. {} Hz",
            scene.rel_tol,
            Num(lo),
            Num(hi)
        )?;
        let best = verdicts
            .iter()
            .filter_map(|v| v.outcome.as_ref().ok().map(|e| (v, *e)))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match (best, verdicts.first()) {
            (Some((v, e)), _) => write!(
                f,
                "; the most accurate, `{}` ({} DoF), reaches {e:.1e}",
                v.method.name(),
                v.dofs
            ),
            (None, Some(v)) => write!(
                f,
                "; no candidate is usable (`{}`: {})",
                v.method.name(),
                v.outcome.as_ref().err().map_or("", String::as_str)
            ),
            (None, None) => Ok(()),
        }
    }
}

impl std::error::Error for NoChoice {}

impl NoChoice {
    /// A human explanation over several lines: the scene and every candidate's verdict (for a
    /// refused band, the message).
    pub fn explain(&self) -> String {
        match self {
            NoChoice::Band(why) => why.clone(),
            NoChoice::NearMode { .. } => self.to_string(),
            NoChoice::Tolerance { scene, verdicts } => format!(
                "{}\n{}\nnone meets the tolerance",
                explain_scene(scene),
                explain_verdicts(verdicts)
            ),
        }
    }
}

/// Candidates in order of model size, then cost per point as `tiltnoise methods` measures it
/// (pole-zero cheapest, then modal, block and split, direct last; figures in
/// `scripts/bench/README.md`). The state-space method is not one: slower than direct and
/// never more accurate, it is there for comparison.
const CANDIDATES: [(Method, usize); 6] = [
    (Method::Torsion2, 2),
    (Method::PoleZero, 4),
    (Method::Block, 4),
    (Method::Split, 4),
    (Method::Modal, 8),
    (Method::Direct, 8),
];

/// The verification grid: log-spaced over the band, without points near a mode.
pub fn verification_grid(model: &Model, band_hz: (f64, f64)) -> Vec<f64> {
    let modes = NormalModes::new(model).frequencies_hz();
    let (lo, hi) = band_hz;
    (0..VERIFY_POINTS)
        .map(|k| {
            if VERIFY_POINTS == 1 || lo == hi {
                lo
            } else {
                lo * (hi / lo).powf(k as f64 / (VERIFY_POINTS - 1) as f64)
            }
        })
        .filter(|f| modes.iter().all(|m| ((f - m) / m).abs() > POLE_EXCLUSION))
        .collect()
}

/// Worst relative error of `method` against the reference over `grid` (structural zeros must be
/// exact), or the reason the method cannot serve the request.
pub fn measured_error(
    model: &Model,
    reference: &ReferenceModel,
    request: &Request,
    method: Method,
    grid: &[f64],
) -> Result<f64, String> {
    let tf = plan(model, request, method).map_err(|e| e.to_string())?;
    let mut worst = 0.0f64;
    for &f in grid {
        let got = tf.eval(f).map_err(|e| e.to_string())?;
        let want = reference.eval_dd(request, f).map_err(|e| e.to_string())?;
        worst = verification_errors(&got, &want)
            .into_iter()
            .fold(worst, f64::max);
    }
    Ok(worst)
}

/// One unit in the last place of `f64`'s subnormal range, `2^-1074`: an entry whose value lies
/// below the normal range is represented only to this absolute granularity, so a method's
/// value rounded once to it and the reference rounded once to `f64` may differ by it.
pub const SUBNORMAL_UNIT: f64 = 5e-324;

/// The verification's error of each entry: [`relative_errors`], except that a difference of
/// at most [`SUBNORMAL_UNIT`] counts as none. For an entry in the normal range this changes
/// nothing (a relative error of `rel_tol >= 2^-52` is far above `2^-1074 / |ref|`); for one in
/// the subnormal range it accepts the granularity of the number format, which no method can
/// beat, and nothing more. Structural zeros must still come out exactly zero.
pub fn verification_errors(got: &[Complex64], reference: &[CDd]) -> Vec<f64> {
    relative_errors(got, reference)
        .into_iter()
        .zip(got.iter().zip(reference))
        .map(|(rel, (g, r))| {
            if r.is_zero() {
                return rel;
            }
            // hypot keeps subnormal differences (a sum of squares would underflow).
            let diff = CDd::from_c64(*g) - *r;
            match diff.re.to_f64().hypot(diff.im.to_f64()) <= SUBNORMAL_UNIT {
                true => 0.0,
                false => rel,
            }
        })
        .collect()
}

/// Picks the smallest model and cheapest method meeting the scene's tolerance.
///
/// # Errors
///
/// [`NoChoice::Band`] for a band that cannot be verified, [`NoChoice::Tolerance`] when no
/// candidate meets the tolerance.
pub fn choose(model: &Model, scene: &Scene) -> Result<Choice, NoChoice> {
    let (lo, hi) = scene.band_hz;
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Err(NoChoice::Band(format!(
            "scene band {} .. {} Hz is not allowed: need 0 < lo <= hi, finite",
            Num(lo),
            Num(hi)
        )));
    }
    let grid = verification_grid(model, scene.band_hz);
    if grid.is_empty() {
        let middle = (lo * hi).sqrt();
        let mode_hz = NormalModes::new(model)
            .frequencies_hz()
            .into_iter()
            .min_by(|a, b| {
                ((a - middle) / a)
                    .abs()
                    .total_cmp(&((b - middle) / b).abs())
            })
            .unwrap_or(middle);
        return Err(NoChoice::NearMode {
            band_hz: (lo, hi),
            mode_hz,
        });
    }
    let reference = ReferenceModel::new(model.params());
    let mut verdicts = Vec::new();
    for (method, block_dofs) in CANDIDATES {
        // A block method solves the whole 8x8 system when the blocks are coupled.
        let dofs = if block_dofs == 4 && !model.decoupled() {
            8
        } else {
            block_dofs
        };
        let outcome = measured_error(model, &reference, &scene.request, method, &grid);
        let ok = matches!(outcome, Ok(e) if e <= scene.rel_tol);
        verdicts.push(Verdict {
            method,
            dofs,
            outcome,
        });
        if ok {
            return Ok(Choice {
                method,
                verdicts,
                scene: scene.clone(),
            });
        }
    }
    Err(NoChoice::Tolerance {
        scene: scene.clone(),
        verdicts,
    })
}

fn explain_verdicts(verdicts: &[Verdict]) -> String {
    verdicts
        .iter()
        .map(|v| match &v.outcome {
            Ok(e) => format!(
                "  {:<9} ({} DoF): max relative error {e:.1e}",
                v.method.name(),
                v.dofs
            ),
            Err(why) => format!(
                "  {:<9} ({} DoF): not usable: {why}",
                v.method.name(),
                v.dofs
            ),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

impl Choice {
    /// A human explanation: the scene, every candidate's verdict, and the pick.
    pub fn explain(&self) -> String {
        format!(
            "{}\n{}\npicked `{}`: the smallest model and cheapest method that meets the tolerance",
            explain_scene(&self.scene),
            explain_verdicts(&self.verdicts),
            self.method.name()
        )
    }
}

fn explain_scene(s: &Scene) -> String {
    let inputs: Vec<&str> = s.request.inputs.iter().map(|i| i.name()).collect();
    let outputs: Vec<&str> = s.request.outputs.iter().map(|o| o.name()).collect();
    format!(
        "scene: inputs {}; outputs {}; band {:e} .. {:e} Hz; tolerance {:e} (relative, vs the \
         double-double reference on {} points, skipping 1 % around each mode)",
        inputs.join(", "),
        outputs.join(", "),
        s.band_hz.0,
        s.band_hz.1,
        s.rel_tol,
        VERIFY_POINTS,
    )
}

/// Convenience: a scene for `inputs` -> `outputs` over a band at the default tolerance.
pub fn scene(inputs: Vec<Input>, outputs: Vec<Observable>, band_hz: (f64, f64)) -> Scene {
    Scene {
        request: Request { outputs, inputs },
        band_hz,
        rel_tol: DEFAULT_REL_TOL,
    }
}

/// Plans the transfer function of `scene` with the method [`choose`] picks: the smallest model
/// and cheapest method whose error, measured against the double-double reference on the
/// scene's band, is within its tolerance. Returns the plan and the evidence.
///
/// # Errors
///
/// [`TfError::NoMethod`] when no candidate meets the tolerance (its message names the most
/// accurate) or the band is not allowed.
pub fn plan_auto(
    model: &Model,
    scene: &Scene,
) -> Result<(Box<dyn TransferFunction>, Choice), TfError> {
    let choice = choose(model, scene).map_err(|e| TfError::NoMethod {
        message: e.to_string(),
    })?;
    let tf = plan(model, &scene.request, choice.method).map_err(|e| TfError::NoMethod {
        message: e.to_string(),
    })?;
    Ok((tf, choice))
}
