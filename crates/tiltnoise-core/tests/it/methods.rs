//! Every evaluation method of `tiltnoise_core::tf` against the double-double reference
//! evaluator (`tiltnoise_core::reference`, about 30 digits) on every test model and every entry
//! point, with one named tolerance per method derived from that method's rounding model (STYLE.md
//! patterns 2, 3).
//!
//! * Test models: Table I undamped; Table I with loss angles 1e-3 on both torsions and both
//!   bouncings; and three pendulums as built ([asymmetry]): the crossbar's centre of mass 1 mm
//!   off along x (the coupled 8x8 system), the test mass's 1 mm off along x with loss angles
//!   1e-3 on the torsions, the bouncings and the lower fibre's swing (coupled and damped), and
//!   the crossbar's 1 mm off along y with the readout turned (decoupled, the observables mixing
//!   the blocks). On the coupled ones `block` refuses to plan, and on every one `split` (and
//!   `torsion2`): the refusal, with its reason, is what is checked there. Their zones are
//!   their own (the symmetric models share Table I's).
//! * Entry points: the 7x3 tilt matrix; the 7 observables from 8 force/torque components; the
//!   7x3 floor-translation matrix.
//! * Grid: 1e-5 .. 100 Hz, 40 points per decade, plus points 1 % and 5 % above and below every
//!   mode.
//!
//! Each method has one tolerance (`|H - H_ref|` at every entry and frequency of the grid):
//!
//! * direct and block: the componentwise (Skeel) bound of an LU solve of the full system,
//!   `gamma (|C| |D^-1| (|D| |x| + |G|) + |C| |x|)` with `gamma = 3 n eps`, `n = 8`. It is large
//!   exactly where an entry is a small difference of O(1) coordinates (phi/eta_t ~ f^4 at low
//!   frequency, eta/phi_t ~ f^-2 at high frequency, and several force entries).
//! * split: the accuracy target, 1e-9 relative, outside 1 % of the entry's own poles and zeros;
//!   the direct method's bound inside those zones.
//! * polezero: the bound of its own product form `g s^p prod(z_j - s) / prod(lambda_k - s)`,
//!   from the plan's factors: the f64 kernel's rounding, a few `u (1 + |z_j| / |z_j - s| +
//!   |lambda_k| / |lambda_k - s|)` (derived in `polezero_batch`), plus the rounding of `s = w^2`
//!   itself; and outside the zones the accuracy target as well.
//! * modal: the eigensolver's error carried by every modal term (shape error `8 eps lambda_max /
//!   gap_k` in the M norm, Davis-Kahan; eigenvalue error `8 eps lambda_max`, Weyl) plus, damped,
//!   the damping coupling between modes that it neglects, to all orders (a Neumann series).
//!
//! * statespace: the componentwise bound of its own operations: the LU of the 16x16
//!   `i w I - A` (backward error `gamma P^T |L| |U|`, with the growth of its own factors), the formation of `A = [[0, I], [-M^-1 K_c, 0]]` and of
//!   `B0 = G0 + K_c M^-1 G2` and `M^-1 B0` by LU solves with `M`, and the final sum with
//!   `D = -C M^-1 G2`, each `gamma = 3 n eps` with `n = 16`. It is large exactly where those sums
//!   cancel (phi/eta_t and phi_a/eta_t at low frequency).
//!
//! Structural zeros (reference exactly 0 at every frequency) must come out as exactly 0.0 from
//! every method.
//! Run with `--nocapture` to see the methods table (the maxima measured here).

use crate::common;
use crate::polezero_batch::product_form_bound;
use crate::tolerances::{
    DD_REF_FACTOR, EIG_GAMMA, EPS, LU_GAMMA, OMEGA_SQ_REL, POLE_EXCLUSION, POLYNOMIAL_GAMMA,
    SS_GAMMA, TARGET_REL,
};

use nalgebra::{Matrix2, RowVector2, SMatrix, SVector, Vector2};
use num_complex::Complex64;
use std::sync::OnceLock;
use tiltnoise_core::model::{Coord, ForceInput, Model, Observable, TiltAxis};
use tiltnoise_core::modes::{refined_omega_sq, NormalModes};
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{CDd, Dd, ReferenceModel, DD_EPS};
use tiltnoise_core::tf::{
    plan, EntryFactors, Input, Method, PlanError, PoleZero, Request, TransferFunction,
};
use tiltnoise_core::units::angular;

type CVec8 = SVector<Complex64, 8>;
type CMat8 = SMatrix<Complex64, 8, 8>;

const F_LO_HZ: f64 = 1e-5;
const F_HI_HZ: f64 = 100.0;
const PER_DECADE: f64 = 40.0;
/// Loss angle of the damped test model (rad).
const LOSS: f64 = 1e-3;

// ----------------------------------------------------------------------------------------------
// Test models and entry points.

struct Case {
    name: &'static str,
    model: Model,
    reference: ReferenceModel,
    modes: NormalModes,
}

impl Case {
    fn new(name: &'static str, params: Params) -> Case {
        let model = Model::new(&params).unwrap();
        Case {
            name,
            reference: ReferenceModel::new(&params),
            modes: NormalModes::new(&model),
            model,
        }
    }
}

fn cases() -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    CASES.get_or_init(|| {
        vec![
            Case::new("Table I", Params::table_i()),
            Case::new(
                "Table I, loss 1e-3",
                common::with_torsion_and_bouncing_loss(Params::table_i(), LOSS),
            ),
        ]
    })
}

/// The pendulums as built (see the module docs).
fn as_built_cases() -> &'static [Case] {
    static CASES: OnceLock<Vec<Case>> = OnceLock::new();
    let set = |p: Params, sets: &[&str]| sets.iter().fold(p, |p, s| p.with_override(s).unwrap());
    CASES.get_or_init(|| {
        vec![
            Case::new(
                "crossbar x 1 mm",
                set(Params::table_i(), &["asymmetry.crossbar_com_x_m=1e-3"]),
            ),
            Case::new(
                "test mass x 1 mm, loss 1e-3",
                set(
                    common::with_torsion_and_bouncing_loss(Params::table_i(), LOSS),
                    &["asymmetry.tm_com_x_m=1e-3", "loss.bending_b_rad=1e-3"],
                ),
            ),
            Case::new(
                "crossbar y 1 mm, readout turned",
                set(
                    Params::table_i(),
                    &[
                        "asymmetry.crossbar_com_y_m=1e-3",
                        "asymmetry.sensor_rot_x_rad=2e-3",
                        "asymmetry.sensor_rot_z_rad=-1e-3",
                    ],
                ),
            ),
        ]
    })
}

/// The zones of a pendulum as built, per entry point (its own poles and zeros).
fn as_built_zones(case: usize, entry_point: &str) -> &'static [Vec<f64>] {
    static ZONES: OnceLock<Vec<[Vec<Vec<f64>>; 3]>> = OnceLock::new();
    let all = ZONES.get_or_init(|| {
        as_built_cases()
            .iter()
            .map(|c| entry_points().map(|(_, r)| poles_and_zeros(c, &r)))
            .collect()
    });
    let k = entry_points()
        .iter()
        .position(|(name, _)| *name == entry_point)
        .expect("a known entry point");
    &all[case][k]
}

fn force(name: &str) -> Input {
    Input::Force(ForceInput::from_name(name).unwrap())
}

/// The entry points: all tilt inputs, eight force/torque components that drive both blocks
/// through both bodies (forces at the centres of mass and torques about them).
fn entry_points() -> [(&'static str, Request); 3] {
    let forces = [
        "F_a.x", "F_b.x", "F_b.y", "F_b.z", "M_a.z", "M_b.x", "M_b.y", "M_b.z",
    ];
    [
        ("tilt", Request::all_tilt()),
        (
            "forces",
            Request {
                outputs: Observable::ALL.to_vec(),
                inputs: forces.iter().map(|n| force(n)).collect(),
            },
        ),
        (
            "translation",
            Request {
                outputs: Observable::ALL.to_vec(),
                inputs: Input::all_translations(),
            },
        ),
    ]
}

fn log_grid(lo: f64, hi: f64, per_decade: f64) -> Vec<f64> {
    let n = ((hi / lo).log10() * per_decade).round() as usize;
    (0..=n)
        .map(|k| lo * (hi / lo).powf(k as f64 / n as f64))
        .collect()
}

/// The check grid: log-spaced, plus points just outside (1 %) and well outside (5 %) the
/// exclusion zone of every mode.
fn grid(case: &Case) -> Vec<f64> {
    let mut f = log_grid(F_LO_HZ, F_HI_HZ, PER_DECADE);
    for m in &case.modes.modes {
        for r in [
            0.95,
            1.0 / (1.0 + 1.01 * POLE_EXCLUSION),
            1.0 + 1.01 * POLE_EXCLUSION,
            1.05,
        ] {
            f.push(m.frequency_hz * r);
        }
    }
    f.sort_by(f64::total_cmp);
    f
}

fn label(request: &Request, o: usize, i: usize) -> String {
    format!("{}/{}", request.outputs[o].name(), request.inputs[i].name())
}

// ----------------------------------------------------------------------------------------------
// Poles and zeros of every entry (the zones the accuracy target excludes).

/// Per entry (row-major), the poles and zeros in Hz in the band: the modes of the entry's block
/// (its observable's amplitude is structurally nonzero), and every sign change of the undamped
/// reference (real for an undamped model) located by bisection; two sign changes closer than the
/// scan's 0.23 % would be missed. The damped model's poles are within `LOSS / 2` (relative) of
/// these and its zeros move by the same order (the stiffness changes by a relative 1e-3), far
/// inside the 1 % zone.
fn poles_and_zeros(case: &Case, request: &Request) -> Vec<Vec<f64>> {
    let (n_out, n_in) = (request.outputs.len(), request.inputs.len());
    let mut special = vec![Vec::new(); n_out * n_in];
    for (o, out) in request.outputs.iter().enumerate() {
        for mode in &case.modes.modes {
            if mode.observable_amplitude[out.index()] != 0.0 {
                for i in 0..n_in {
                    special[o * n_in + i].push(mode.frequency_hz);
                }
            }
        }
    }
    let scan = log_grid(F_LO_HZ / 1.02, F_HI_HZ * 1.02, 1000.0);
    let values: Vec<Option<Vec<Complex64>>> = scan
        .iter()
        .map(|&f| case.reference.eval(request, f).ok())
        .collect();
    for o in 0..n_out {
        for i in 0..n_in {
            let single = Request {
                outputs: vec![request.outputs[o]],
                inputs: vec![request.inputs[i]],
            };
            let sign = |f: f64| {
                case.reference
                    .eval(&single, f)
                    .map(|h| h[0].re.signum())
                    .unwrap_or(0.0)
            };
            let mut last: Option<(f64, f64)> = None;
            for (&f, v) in scan.iter().zip(&values) {
                let Some(v) = v else { continue };
                let h = v[o * n_in + i].re;
                if h == 0.0 {
                    continue;
                }
                if let Some((f0, s0)) = last {
                    if s0 != h.signum() {
                        let (mut a, mut b) = (f0, f);
                        for _ in 0..50 {
                            let m = (a * b).sqrt();
                            if sign(m) == s0 {
                                a = m;
                            } else {
                                b = m;
                            }
                        }
                        special[o * n_in + i].push(a);
                    }
                }
                last = Some((f, h.signum()));
            }
        }
    }
    special
}

/// Zones per entry point (computed once; the reference scan takes about a second).
fn zones(entry_point: &str) -> &'static [Vec<f64>] {
    static TILT: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    static FORCES: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    static TRANSLATION: OnceLock<Vec<Vec<f64>>> = OnceLock::new();
    let cell = match entry_point {
        "tilt" => &TILT,
        "forces" => &FORCES,
        _ => &TRANSLATION,
    };
    let request = entry_points()
        .into_iter()
        .find(|(name, _)| *name == entry_point)
        .unwrap()
        .1;
    cell.get_or_init(|| poles_and_zeros(&cases()[0], &request))
}

fn in_zone(f: f64, special: &[f64]) -> bool {
    special
        .iter()
        .any(|&s| (f - s).abs() <= POLE_EXCLUSION * s.min(f))
}

// ----------------------------------------------------------------------------------------------
// Rounding models.

fn forcing(model: &Model, input: Input, w2: f64) -> SVector<f64, 8> {
    match input {
        Input::Tilt(t) => model.tilt_forcing().at(w2.sqrt()).column(t.index()).into(),
        Input::Translation(t) => model
            .translation_forcing()
            .at(w2.sqrt())
            .column(t.index())
            .into(),
        Input::Force(f) => model.force_matrix().column(f.index()).into(),
    }
}

/// `(G0, G2)` of an input, its forcing being `G0 + w^2 G2`.
fn forcing_parts(model: &Model, input: Input) -> (SVector<f64, 8>, SVector<f64, 8>) {
    match input {
        Input::Tilt(t) => (
            model.tilt_forcing().g0.column(t.index()).into(),
            model.tilt_forcing().g2.column(t.index()).into(),
        ),
        Input::Translation(t) => (
            SVector::zeros(),
            model.translation_forcing().g2.column(t.index()).into(),
        ),
        Input::Force(f) => (
            model.force_matrix().column(f.index()).into(),
            SVector::zeros(),
        ),
    }
}

/// Componentwise (Skeel) bound of the LU solve of the full 8x8 system, for every entry.
fn lu_bound(case: &Case, request: &Request, freq_hz: f64) -> Vec<f64> {
    let m = &case.model;
    let w2 = angular(freq_hz).powi(2);
    let d: CMat8 = m.stiffness_complex() - m.mass().map(|x| Complex64::from(x * w2));
    let Some(d_inv) = d.try_inverse() else {
        return vec![f64::INFINITY; request.outputs.len() * request.inputs.len()];
    };
    let abs_d = d.map(|z| z.norm());
    let abs_inv = d_inv.map(|z| z.norm());
    let c = m.observation();
    let mut out = Vec::new();
    for o in &request.outputs {
        for &i in &request.inputs {
            let g = forcing(m, i, w2);
            let x: CVec8 = d_inv * g.map(Complex64::from);
            let abs_x = x.map(|z| z.norm());
            let inner = abs_inv * (abs_d * abs_x + g.abs());
            let row = c.row(o.index()).abs();
            out.push(LU_GAMMA * ((row * inner)[0] + (row * abs_x)[0]));
        }
    }
    out
}

/// First-order componentwise bound of the state-space method's operations (module docs), for
/// every entry: with `y = M^-1 G2`, `b0 = G0 + K_c y`, `z = M^-1 b0`, `x = S^-1 [0; z]` for
/// `S = i w I - A`, `h = C x_q - C y`,
///
/// ```text
/// |dy|  <= g |M^-1| (|M| |y| + |G2|)
/// |db0| <= g (|G0| + |K_c| |y|) + |K_c| |dy|
/// |dz|  <= g |M^-1| (|M| |z| + |b0|) + |M^-1| |db0|
/// |dA21| <= g |M^-1| (|M| |M^-1 K_c| + |K_c|)
/// |dx|  <= |S^-1| (g (P^T |L| |U| |x| + |[0; z]|) + |dA| |x| + |[0; dz]|)
/// |dh|  <= g (|C| |x_q| + |C| |y|) + |C| |dx_q| + |C| |dy|
/// ```
///
/// (`g` = [`SS_GAMMA`]; `|.|` elementwise; the inverses in f64, exact enough for a bound).
fn statespace_bound(case: &Case, request: &Request, freq_hz: f64) -> Vec<f64> {
    type CMat16 = SMatrix<Complex64, 16, 16>;
    type Vec16 = SVector<f64, 16>;
    let m = &case.model;
    let w = angular(freq_hz);
    let g = SS_GAMMA;
    let mass = *m.mass();
    let m_inv = mass.try_inverse().expect("M is positive definite");
    let (abs_m, abs_minv) = (mass.abs(), m_inv.abs());
    let k = m.stiffness_complex();
    let abs_k = k.map(|z| z.norm());
    let m_inv_c = m_inv.map(Complex64::from);
    let a21 = -(m_inv_c * k);
    let d_a21 = g * (abs_minv * (abs_m * a21.map(|z| z.norm()) + abs_k));
    let mut s_mat = CMat16::zeros();
    let mut d_a = SMatrix::<f64, 16, 16>::zeros();
    for r in 0..8 {
        s_mat[(r, 8 + r)] = Complex64::new(-1.0, 0.0);
        for c in 0..8 {
            s_mat[(8 + r, c)] = -a21[(r, c)];
            d_a[(8 + r, c)] = d_a21[(r, c)];
        }
    }
    for d in 0..16 {
        s_mat[(d, d)] += Complex64::new(0.0, w);
    }
    let Some(s_inv) = s_mat.try_inverse() else {
        return vec![f64::INFINITY; request.outputs.len() * request.inputs.len()];
    };
    // The LU's backward error is `|dS| <= gamma P^T |L| |U|` (with partial pivoting `|L| |U|`
    // can exceed `|S|`: the growth of this unequilibrated matrix), from the same f64
    // factorization the method computes.
    let lu = s_mat.lu();
    let mut abs_s = lu.l().map(|z| z.norm()) * lu.u().map(|z| z.norm());
    lu.p().inv_permute_rows(&mut abs_s);
    let abs_sinv = s_inv.map(|z| z.norm());
    let c_obs = m.observation();
    let mut out = Vec::new();
    for o in &request.outputs {
        let row = c_obs.row(o.index()).abs();
        for &i in &request.inputs {
            let (g0, g2) = forcing_parts(m, i);
            let y = m_inv * g2;
            let dy = g * (abs_minv * (abs_m * y.abs() + g2.abs()));
            let b0 = g0.map(Complex64::from) + k * y.map(Complex64::from);
            let db0 = g * (g0.abs() + abs_k * y.abs()) + abs_k * dy;
            let z = m_inv_c * b0;
            let abs_z = z.map(|v| v.norm());
            let dz = g * (abs_minv * (abs_m * abs_z + b0.map(|v| v.norm()))) + abs_minv * db0;
            let rhs =
                SVector::<Complex64, 16>::from_fn(|r, _| if r < 8 { 0.0.into() } else { z[r - 8] });
            let x = s_inv * rhs;
            let abs_x = x.map(|v| v.norm());
            let abs_rhs = rhs.map(|v| v.norm());
            let drhs = Vec16::from_fn(|r, _| if r < 8 { 0.0 } else { dz[r - 8] });
            let dx = abs_sinv * (g * (abs_s * abs_x + abs_rhs) + d_a * abs_x + drhs);
            let x_q = SVector::<f64, 8>::from_fn(|r, _| abs_x[r]);
            let dx_q = SVector::<f64, 8>::from_fn(|r, _| dx[r]);
            out.push(g * ((row * x_q)[0] + (row * y.abs())[0]) + (row * dx_q)[0] + (row * dy)[0]);
        }
    }
    out
}

/// `lambda_k + i v_k^T Im(K_c) v_k`: the modal method's eigenvalue with its modal loss.
fn modal_eigenvalue(case: &Case, k: usize) -> Complex64 {
    let loss = case.model.stiffness_complex().map(|z| z.im);
    let mode = &case.modes.modes[k];
    Complex64::new(
        mode.omega_sq,
        (mode.shape.transpose() * loss * mode.shape)[(0, 0)],
    )
}

/// The modal terms of an entry, `(C v_k)(v_k^T G(w)) / (mu_k - w^2)`.
fn modal_terms(case: &Case, o: Observable, input: Input, w2: f64) -> Vec<Complex64> {
    let g = forcing(&case.model, input, w2);
    (0..case.modes.modes.len())
        .map(|k| {
            let mode = &case.modes.modes[k];
            mode.observable_amplitude[o.index()] * mode.shape.dot(&g)
                / (modal_eigenvalue(case, k) - w2)
        })
        .collect()
}

/// Sum of the modal terms' magnitudes: the size an entry would have without cancellation.
fn modal_scale(case: &Case, o: Observable, input: Input, w2: f64) -> f64 {
    modal_terms(case, o, input, w2)
        .iter()
        .map(|t| t.norm())
        .sum()
}

/// `sqrt(x^T M^-1 x)`: against a mass-normalized shape error `dv`, `|dv^T x| <= ||dv||_M` times
/// this (Cauchy-Schwarz in the M inner product).
fn dual_norm(case: &Case, x: &SVector<f64, 8>) -> f64 {
    let m_inv = case.model.mass().try_inverse().unwrap();
    (x.transpose() * m_inv * x)[(0, 0)].sqrt()
}

/// The modal method's rounding model. The block eigensolver errs by `||dv_k||_M <= eps_k =
/// 8 eps lambda_max / gap_k` in a shape and by `8 eps lambda_max` in an eigenvalue (Davis-Kahan
/// and Weyl with `||E|| ~ 2n eps ||L^-1 K L^-T||`); the shape error enters `C v_k` and the two
/// parts of `v_k^T (G0 + w^2 G2)` separately, so a term's error is bounded by
/// `eps_k (|C v_k| (||G0||* + w^2 ||G2||*) + ||c||* |v_k^T G|) / |mu_k - w^2|` plus the
/// eigenvalue error times `|term_k| / |mu_k - w^2|`, with `||.||*` the `M^-1` norm.
fn modal_bound(case: &Case, o: Observable, input: Input, w2: f64) -> f64 {
    let modes = &case.modes.modes;
    let (g0, g2) = forcing_parts(&case.model, input);
    let g_size = dual_norm(case, &g0) + w2 * dual_norm(case, &g2);
    let c_size = dual_norm(case, &case.model.observation().row(o.index()).transpose());
    (0..modes.len())
        .map(|k| {
            let same_block = || modes.iter().filter(|m| m.block == modes[k].block);
            let lambda_max = same_block().map(|m| m.omega_sq).fold(0.0, f64::max);
            let gap = same_block()
                .filter(|m| m.index != modes[k].index)
                .map(|m| (m.omega_sq - modes[k].omega_sq).abs())
                .fold(f64::INFINITY, f64::min);
            let (shape_err, lambda_err) = (EIG_GAMMA * lambda_max / gap, EIG_GAMMA * lambda_max);
            let cv = modes[k].observable_amplitude[o.index()].abs();
            let vg = modes[k].shape.dot(&(g0 + g2 * w2)).abs();
            let denom = (modal_eigenvalue(case, k) - w2).norm();
            (shape_err * (cv * g_size + c_size * vg) + cv * vg * (lambda_err / denom + 8.0 * EPS))
                / denom
        })
        .sum()
}

/// The damping coupling `D_jk = v_j^T Im(K_c) v_k` (j != k) that modal superposition
/// neglects, to all orders: with `a = (Lambda - w^2)^-1 V^T g` (the modal method's modal
/// amplitudes, `Lambda` holding each mode's own loss) and `X = (Lambda - w^2)^-1 i D`, the exact
/// amplitudes are `(I + X)^-1 a`, so their difference from `a` is at most
/// `(I - |X|)^-1 |X| |a|` componentwise when the spectral radius of `|X|` is below 1 (the
/// Neumann series), and the entry's at most `sum_j |C v_j|` times that. Infinite when the
/// series does not converge.
fn modal_damping_coupling(case: &Case, o: Observable, input: Input, w2: f64) -> f64 {
    let loss = case.model.stiffness_complex().map(|z| z.im);
    let g = forcing(&case.model, input, w2);
    let modes = &case.modes.modes;
    let n = modes.len();
    let denominators: Vec<f64> = (0..n)
        .map(|j| (modal_eigenvalue(case, j) - w2).norm())
        .collect();
    let a = nalgebra::DVector::from_fn(n, |j, _| modes[j].shape.dot(&g).abs() / denominators[j]);
    let x = nalgebra::DMatrix::from_fn(n, n, |j, k| {
        if j == k || modes[j].block != modes[k].block {
            return 0.0;
        }
        (modes[j].shape.transpose() * loss * modes[k].shape)[(0, 0)].abs() / denominators[j]
    });
    if x.iter().all(|&v| v == 0.0) {
        return 0.0;
    }
    let radius = x
        .clone()
        .complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max);
    if radius >= 1.0 {
        return f64::INFINITY;
    }
    let Some(err) = (nalgebra::DMatrix::identity(n, n) - &x)
        .lu()
        .solve(&(&x * a))
    else {
        return f64::INFINITY;
    };
    (0..n)
        .map(|j| modes[j].observable_amplitude[o.index()].abs() * err[j])
        .sum()
}

/// The modal method's tolerance: its rounding model plus the damping coupling it neglects
/// (zero on the undamped model).
fn modal_tolerance(case: &Case, o: Observable, input: Input, w2: f64) -> f64 {
    modal_bound(case, o, input, w2) + modal_damping_coupling(case, o, input, w2)
}

/// The pole-zero method's rounding model, per entry (absolute): every block's contribution
/// `g s^p prod(z_j - s) / prod(lambda_k - s)` to the entry, from the plan's own `factors`, times
/// its relative error. That is the kernel's f64 arithmetic against the same product in
/// double-double at the same `s` ([`product_form_bound`], checked on its own in
/// `polezero_batch`), plus the rounding of `s` itself ([`OMEGA_SQ_REL`]), which moves `s^p` by
/// `p OMEGA_SQ_REL` and a factor `z - s` by `OMEGA_SQ_REL |s| / |z - s| <= OMEGA_SQ_REL (1 + |z| /
/// |z - s|)` relative. The factors are polished in double-double: their own error, of order
/// `DD_EPS` times their condition, is negligible here.
fn polezero_bound(
    factors: &[EntryFactors],
    complex: bool,
    request: &Request,
    freq_hz: f64,
) -> Vec<f64> {
    let s = angular(freq_hz).powi(2);
    let sd = CDd::real(Dd::from(s));
    let n_in = request.inputs.len();
    let mut out = vec![0.0; request.outputs.len() * n_in];
    for e in factors {
        let mut value = e.gain.abs_f64() * s.powi(e.power as i32);
        let mut moved_by_s = e.power as f64;
        for z in &e.zeros {
            let d = (*z - sd).abs_f64();
            value *= d;
            moved_by_s += 1.0 + z.abs_f64() / d;
        }
        for l in &e.poles {
            let d = (*l - sd).abs_f64();
            value /= d;
            moved_by_s += 1.0 + l.abs_f64() / d;
        }
        out[e.output * n_in + e.input] += value
            * (product_form_bound(e, s, complex)
                + OMEGA_SQ_REL * moved_by_s
                + coefficient_rounding(e, sd));
    }
    out
}

/// The relative error the rounding of the coefficients of `N` and `P` leaves in `N(s) / P(s)`:
/// each coefficient is within `POLYNOMIAL_GAMMA DD_EPS` of its magnitude (the terms of the
/// expansion, whose data carry their own rounding scales), so `N(s)` within
/// `POLYNOMIAL_GAMMA DD_EPS sum_k mag_k |s|^k` of its value, and likewise `P(s)`. Negligible
/// where nothing cancels; it is what limits an entry whose coefficients are small differences
/// of large terms (an entry of the coupled system that the symmetric one has as a structural
/// zero, say, at low frequency).
fn coefficient_rounding(e: &EntryFactors, s: CDd) -> f64 {
    let relative = |coefficients: &[(CDd, f64)]| {
        let (mut value, mut mag) = (CDd::ZERO, 0.0);
        for &(c, m) in coefficients.iter().rev() {
            value = value * s + c;
            mag = mag * s.abs_f64() + m;
        }
        POLYNOMIAL_GAMMA * DD_EPS * mag / value.abs_f64()
    };
    relative(&e.numerator) + relative(&e.denominator)
}

// ----------------------------------------------------------------------------------------------
// The shared harness.

/// The tolerance of a method, see the module docs.
#[derive(Clone, Copy)]
enum Tolerance {
    /// Direct and block: the LU bound everywhere.
    Lu,
    /// Split: the accuracy target outside the zones, the LU bound inside.
    Target,
    /// Pole-zero: the bound of its own product form everywhere, and the accuracy target outside
    /// the zones.
    PoleZero,
    /// Modal: its eigensolver and damping-coupling bound everywhere.
    Modal,
    /// State space: the bound of its own operations everywhere.
    StateSpace,
}

fn tolerance(method: Method) -> Tolerance {
    match method {
        Method::Direct | Method::Block => Tolerance::Lu,
        Method::Split => Tolerance::Target,
        Method::PoleZero => Tolerance::PoleZero,
        Method::Modal => Tolerance::Modal,
        Method::StateSpace => Tolerance::StateSpace,
        Method::Torsion2 => unreachable!("a reduced model; compared separately"),
    }
}

/// Maximum relative error of a method on one model and entry point.
#[derive(Default)]
struct Measured {
    outside_zones: f64,
    everywhere: f64,
    worst: String,
}

fn check_method(method: Method) {
    let tol = tolerance(method);
    let symmetric = cases().iter().map(|c| (c, None));
    let as_built = as_built_cases()
        .iter()
        .enumerate()
        .map(|(k, c)| (c, Some(k)));
    for (case, built) in symmetric.chain(as_built) {
        for (entry_point, request) in entry_points() {
            let tf = match plan(&case.model, &request, method) {
                Ok(tf) => tf,
                Err(e) => {
                    let refused = match method {
                        Method::Block => !case.model.decoupled(),
                        Method::Split => !case.model.is_symmetric(),
                        _ => false,
                    };
                    assert!(refused, "{} on {}: {e}", method.name(), case.name);
                    let PlanError::Unsupported { reason, .. } = &e;
                    assert!(reason.contains("polezero"), "{e}");
                    println!("{:>9} {:<32} refused: {e}", method.name(), case.name);
                    break;
                }
            };
            let zones = match built {
                Some(k) => as_built_zones(k, entry_point),
                None => zones(entry_point),
            };
            let m = check(case, &request, tf.as_ref(), zones, tol);
            println!(
                "{:>9} {:<32} {:<7} max rel error {:.1e} outside 1 % of poles/zeros ({}), \
                 {:.1e} everywhere",
                method.name(),
                case.name,
                entry_point,
                m.outside_zones,
                m.worst,
                m.everywhere
            );
        }
    }
}

fn check(
    case: &Case,
    request: &Request,
    tf: &dyn TransferFunction,
    zones: &[Vec<f64>],
    tol: Tolerance,
) -> Measured {
    let n_in = request.inputs.len();
    let mut measured = Measured::default();
    let mut failures = Vec::new();
    let factors = match tol {
        Tolerance::PoleZero => PoleZero::factors(case.model.params(), request),
        _ => Vec::new(),
    };
    // Complex arithmetic in the kernel: damped blocks, or complex gains or zeros.
    let complex = !case.model.is_undamped()
        || factors
            .iter()
            .any(|e| !e.gain.im.is_zero() || e.zeros.iter().any(|z| !z.im.is_zero()));
    for f in grid(case) {
        let want = case.reference.eval_dd(request, f).unwrap();
        let kappa = case.reference.entry_condition(request, f).unwrap();
        let got = tf.eval(f).unwrap();
        let lu = lu_bound(case, request, f);
        let ss = match tol {
            Tolerance::StateSpace => statespace_bound(case, request, f),
            _ => Vec::new(),
        };
        let pz = match tol {
            Tolerance::PoleZero => polezero_bound(&factors, complex, request, f),
            _ => Vec::new(),
        };
        let w2 = angular(f).powi(2);
        for (j, (&g, &r)) in got.iter().zip(&want).enumerate() {
            let (o, i) = (j / n_in, j % n_in);
            let name = label(request, o, i);
            if r.is_zero() {
                if g != Complex64::new(0.0, 0.0) {
                    failures.push(format!("{name} at {f:e} Hz: structural zero came out {g}"));
                }
                continue;
            }
            let err = (CDd::from_c64(g) - r).abs_f64();
            let size = r.abs_f64();
            let rel = err / size;
            let zone = in_zone(f, &zones[j]);
            if !zone && rel > measured.outside_zones {
                measured.outside_zones = rel;
                measured.worst = format!("{name} at {f:.4e} Hz");
            }
            measured.everywhere = measured.everywhere.max(rel);
            let (output, input) = (request.outputs[o], request.inputs[i]);
            let (rel_tol, bound) = match tol {
                Tolerance::Lu => (0.0, lu[j]),
                Tolerance::Target if zone => (0.0, lu[j]),
                Tolerance::Target => (TARGET_REL, 0.0),
                Tolerance::PoleZero if zone => (0.0, pz[j]),
                Tolerance::PoleZero => (0.0, pz[j].min(TARGET_REL * size)),
                Tolerance::Modal => (0.0, modal_tolerance(case, output, input, w2)),
                Tolerance::StateSpace => (0.0, ss[j]),
            };
            // The reference's own error, `DD_REF_FACTOR DD_EPS kappa` (negligible but for
            // entries of the coupled system with heavy cancellation at low frequency).
            let reference = DD_REF_FACTOR * DD_EPS * kappa[j] * size;
            if err > rel_tol * size + bound + reference {
                failures.push(format!(
                    "{name} at {f:.6e} Hz{}: got {g}, want {}, rel error {rel:.2e}, bound \
                     {:.2e} relative",
                    if zone { " (in zone)" } else { "" },
                    r.to_c64(),
                    bound / size
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} on {}: {} failures, first ones:\n{}",
        tf.method().name(),
        case.name,
        failures.len(),
        failures[..failures.len().min(12)].join("\n")
    );
    measured
}

#[test]
fn direct_within_the_lu_bound() {
    check_method(Method::Direct);
}

#[test]
fn block_within_the_lu_bound() {
    check_method(Method::Block);
}

#[test]
fn split_meets_the_target() {
    check_method(Method::Split);
}

#[test]
fn polezero_within_its_product_form_bound_and_the_target() {
    check_method(Method::PoleZero);
}

#[test]
fn modal_within_its_eigensolver_and_damping_bound() {
    check_method(Method::Modal);
}

#[test]
fn statespace_within_the_bound_of_its_operations() {
    check_method(Method::StateSpace);
}

// ----------------------------------------------------------------------------------------------
// Method-specific properties.

/// Block and direct perform the same floating-point operations within a block (the 8x8
/// elimination's multipliers across blocks are exactly zero): they agree to rounding, in fact
/// bit for bit on this grid.
#[test]
fn block_agrees_with_direct() {
    for case in cases() {
        for (_, request) in entry_points() {
            let direct = plan(&case.model, &request, Method::Direct).unwrap();
            let block = plan(&case.model, &request, Method::Block).unwrap();
            for f in grid(case) {
                let (d, b) = (direct.eval(f).unwrap(), block.eval(f).unwrap());
                for (j, (x, y)) in d.iter().zip(&b).enumerate() {
                    assert!(
                        (x - y).norm() <= 4.0 * EPS * x.norm(),
                        "{} at {f:e} Hz: direct {x}, block {y}",
                        label(&request, j / request.inputs.len(), j % request.inputs.len())
                    );
                }
            }
        }
    }
}

/// At f = 0 the split method returns its static part `C S` exactly: the plumb-line limits with
/// no rounding at all.
#[test]
fn split_static_limits_are_exact() {
    for case in cases() {
        let p = case.model.params();
        let lever = case.model.derived().lever_m;
        let h = plan(&case.model, &Request::all_tilt(), Method::Split)
            .unwrap()
            .eval(0.0)
            .unwrap();
        for o in Observable::ALL {
            for t in TiltAxis::ALL {
                let want = match (o, t) {
                    (Observable::X, TiltAxis::EtaT) => -lever,
                    (Observable::Y, TiltAxis::ThetaT) => lever,
                    (Observable::Z, TiltAxis::ThetaT) => -p.length.d_m,
                    (Observable::Theta, TiltAxis::ThetaT) | (Observable::Eta, TiltAxis::EtaT) => {
                        1.0
                    }
                    _ => 0.0,
                };
                let got = h[o.index() * 3 + t.index()];
                assert_eq!(got, Complex64::from(want), "{}/{}", o.name(), t.name());
            }
        }
    }
}

/// The split method's forcings against the library's tilt forcing. Tilt about x and y: the
/// translation forcing in closed form, `R = (h / g) K_gravity S`, equals `G2 + M S` to
/// rounding, with the closed form's phi and delta rows exactly zero. Rotation about the
/// vertical: `G0 = 0` exactly and `G2 = -M e_phi_a` (a rigid rotation) to rounding.
#[test]
fn split_forcings_match_the_library_matrices() {
    for case in cases() {
        let m = &case.model;
        let phi_t = TiltAxis::PhiT.index();
        assert!(m.tilt_forcing().g0.column(phi_t).iter().all(|&v| v == 0.0));
        for c in Coord::ALL {
            let (r, rigid) = (c.index(), m.mass()[(c.index(), Coord::PhiA.index())]);
            let g2 = m.tilt_forcing().g2[(r, phi_t)];
            assert!(
                (g2 + rigid).abs() <= 8.0 * EPS * rigid.abs(),
                "phi_t row {}: G2 = {g2:e}, -M e_phi_a = {:e}",
                c.name(),
                -rigid
            );
        }
        let p = m.params();
        let (h, g) = (p.length.h_m, p.environment.g_m_per_s2);
        let tilt = m.tilt_forcing();
        for (axis, coord) in [
            (TiltAxis::ThetaT, Coord::ThetaA),
            (TiltAxis::EtaT, Coord::EtaA),
        ] {
            let library = tilt.g2.column(axis.index()) + m.mass().column(coord.index());
            let closed = m.stiffness_gravity().column(coord.index()) * (h / g);
            for c in Coord::ALL {
                let r = c.index();
                if matches!(c, Coord::PhiA | Coord::PhiB | Coord::DeltaA | Coord::DeltaB) {
                    assert_eq!(closed[r], 0.0);
                }
                let scale = tilt.g2[(r, axis.index())].abs() + m.mass()[(r, coord.index())].abs();
                assert!(
                    (library[r] - closed[r]).abs() <= 8.0 * EPS * scale.max(closed[r].abs()),
                    "{} row {}: G2 + M S = {:e}, (h/g) K_g S = {:e}",
                    axis.name(),
                    c.name(),
                    library[r],
                    closed[r]
                );
            }
        }
    }
}

/// Modal superposition is accurate to the target where its terms do not cancel (their
/// magnitudes sum to at most 10 |H|) on the undamped model, outside the poles' and zeros' zones.
#[test]
fn modal_is_accurate_without_cancellation() {
    let case = &cases()[0];
    for (entry_point, request) in entry_points() {
        let tf = plan(&case.model, &request, Method::Modal).unwrap();
        let zones = zones(entry_point);
        let n_in = request.inputs.len();
        let (mut checked, mut worst) = (0, 0.0f64);
        for f in grid(case) {
            let want = case.reference.eval_dd(&request, f).unwrap();
            let got = tf.eval(f).unwrap();
            let w2 = angular(f).powi(2);
            for (j, (&g, &r)) in got.iter().zip(&want).enumerate() {
                let (o, i) = (j / n_in, j % n_in);
                if r.is_zero() || in_zone(f, &zones[j]) {
                    continue;
                }
                let (output, input) = (request.outputs[o], request.inputs[i]);
                if modal_scale(case, output, input, w2) > 10.0 * r.abs_f64() {
                    continue;
                }
                checked += 1;
                let rel = (CDd::from_c64(g) - r).abs_f64() / r.abs_f64();
                worst = worst.max(rel);
                assert!(
                    rel <= TARGET_REL,
                    "modal {} at {f:e} Hz: rel error {rel:e}",
                    label(&request, o, i)
                );
            }
        }
        assert!(
            checked > 1000,
            "{entry_point}: only {checked} entries checked"
        );
        println!(
            "    modal {:<20} {entry_point:<7} max rel error {worst:.1e} where the modal terms \
             do not cancel (sum |term| <= 10 |H|), outside 1 % of poles/zeros",
            case.name
        );
    }
}

/// The documented failure: phi/eta_t and phi_a/eta_t fall as f^4 at low frequency by an exact
/// cancellation of gravity and inertia, which the modal sum does not reproduce. At 1e-5 Hz its
/// relative error exceeds 1e-3 (measured: of order 1e2), and it stays within the eigensolver
/// bound, `|error| <= sum_k |term_k| eps_k`.
#[test]
fn modal_loses_phi_over_eta_t_at_low_frequency_as_documented() {
    let f = 1e-5;
    let w2 = angular(f).powi(2);
    for case in cases() {
        let request = Request::all_tilt();
        let h = plan(&case.model, &request, Method::Modal)
            .unwrap()
            .eval(f)
            .unwrap();
        let want = case.reference.eval_dd(&request, f).unwrap();
        for o in [Observable::Phi, Observable::PhiA] {
            let j = o.index() * 3 + TiltAxis::EtaT.index();
            let err = (CDd::from_c64(h[j]) - want[j]).abs_f64();
            let rel = err / want[j].abs_f64();
            let bound = modal_tolerance(case, o, Input::Tilt(TiltAxis::EtaT), w2);
            println!(
                "modal {}/eta_t at 1e-5 Hz on {}: rel error {rel:.1e}, bound {:.1e}",
                o.name(),
                case.name,
                bound / want[j].abs_f64()
            );
            assert!(rel > 1e-3, "{}/eta_t: rel error only {rel:e}", o.name());
            assert!(
                err <= bound,
                "{}/eta_t: error {err:e} > bound {bound:e}",
                o.name()
            );
        }
    }
}

/// The state-space form's documented failure, the one the Python tools have:
/// phi/eta_t and phi_a/eta_t at 1e-5 Hz, where `B0 = G0 + K_c M^-1 G2` and `C x - C M^-1 G2`
/// cancel in f64, come out with a relative error above 1e-3 (measured: of order 1e2), within
/// the bound of its operations.
#[test]
fn statespace_loses_phi_over_eta_t_at_low_frequency_as_documented() {
    let f = 1e-5;
    for case in cases() {
        let request = Request::all_tilt();
        let h = plan(&case.model, &request, Method::StateSpace)
            .unwrap()
            .eval(f)
            .unwrap();
        let want = case.reference.eval_dd(&request, f).unwrap();
        let bound = statespace_bound(case, &request, f);
        for o in [Observable::Phi, Observable::PhiA] {
            let j = o.index() * 3 + TiltAxis::EtaT.index();
            let err = (CDd::from_c64(h[j]) - want[j]).abs_f64();
            let rel = err / want[j].abs_f64();
            println!(
                "statespace {}/eta_t at 1e-5 Hz on {}: rel error {rel:.1e}, bound {:.1e}",
                o.name(),
                case.name,
                bound[j] / want[j].abs_f64()
            );
            assert!(rel > 1e-3, "{}/eta_t: rel error only {rel:e}", o.name());
            assert!(err <= bound[j], "{}/eta_t: error {err:e} > bound", o.name());
        }
    }
}

/// Direct, block, split, polezero, modal and statespace give exactly 0.0 on the structural zeros
/// (the entries across the two blocks, where the reference is exactly 0 at every frequency),
/// including f = 0.
#[test]
fn structural_zeros_are_exact() {
    let freqs = [0.0, 1e-5, 1e-3, 0.5, 10.0, 100.0];
    for case in cases() {
        for (_, request) in entry_points() {
            let want: Vec<Vec<CDd>> = freqs
                .iter()
                .map(|&f| case.reference.eval_dd(&request, f).unwrap())
                .collect();
            let structural: Vec<usize> = (0..want[0].len())
                .filter(|&j| want[1..].iter().all(|w| w[j].is_zero()))
                .collect();
            assert!(!structural.is_empty());
            for method in [
                Method::Direct,
                Method::Block,
                Method::Split,
                Method::PoleZero,
                Method::Modal,
                Method::StateSpace,
            ] {
                let tf = plan(&case.model, &request, method).unwrap();
                for &f in &freqs {
                    let got = tf.eval(f).unwrap();
                    for &j in &structural {
                        assert!(
                            got[j].re == 0.0 && got[j].im == 0.0,
                            "{} {} at {f} Hz: {}",
                            method.name(),
                            label(&request, j / request.inputs.len(), j % request.inputs.len()),
                            got[j]
                        );
                    }
                }
            }
        }
    }
}

/// At f = 0 some entries vanish by an exact cancellation rather than by structure (phi/eta_t,
/// phi_a/eta_t, eta/phi_t; Z/M_b.x and theta/F_b.z, where the gravity stiffness is diagonal in
/// absolute angles): the reference is exactly 0 there. The split and pole-zero methods give
/// exactly 0.0 on all of them (pole-zero through its factor `s^p`); direct and block on the tilt
/// entries but not on the force entries, where they leave rounding noise within their LU bound;
/// modal leaves noise within its eigensolver bound.
#[test]
fn static_zeros() {
    for case in cases() {
        for (entry_point, request) in entry_points() {
            let want = case.reference.eval_dd(&request, 0.0).unwrap();
            let lu = lu_bound(case, &request, 0.0);
            for method in [
                Method::Direct,
                Method::Block,
                Method::Split,
                Method::PoleZero,
                Method::Modal,
            ] {
                let got = plan(&case.model, &request, method)
                    .unwrap()
                    .eval(0.0)
                    .unwrap();
                let mut noise = 0.0f64;
                for (j, (g, r)) in got.iter().zip(&want).enumerate() {
                    if !r.is_zero() {
                        continue;
                    }
                    let (o, i) = (j / request.inputs.len(), j % request.inputs.len());
                    let bound = match method {
                        Method::Split | Method::PoleZero => 0.0,
                        Method::Direct | Method::Block if entry_point == "tilt" => 0.0,
                        Method::Modal => {
                            modal_tolerance(case, request.outputs[o], request.inputs[i], 0.0)
                        }
                        _ => lu[j],
                    };
                    assert!(
                        g.norm() <= bound,
                        "{} {} at f = 0: {g}, bound {bound:e}",
                        method.name(),
                        label(&request, o, i)
                    );
                    noise = noise.max(g.norm());
                }
                println!(
                    "{:>9} {:<20} {entry_point:<7} f = 0, largest value where the reference is \
                     exactly 0: {noise:.1e}",
                    method.name(),
                    case.name
                );
            }
        }
    }
}

// ----------------------------------------------------------------------------------------------
// The 2-DoF torsional model against the full model.

/// The first-order coupling error of the 2-DoF model for one entry, from the full model's
/// swing-x+torsion block partitioned into torsion `p = (phi_a, phi_b)` and swing
/// `e = (eta_a, eta_b)`. Exactly, `q_p = S^-1 (Q_p - D_pe D_ee^-1 Q_e)` with the Schur complement
/// `S = D_pp - D_pe D_ee^-1 D_ep`, and the observable also reads `q_e = D_ee^-1 (Q_e - D_ep q_p)`.
/// The 2-DoF model keeps `D_pp^-1 Q_p` only. Since `D_pe = -w^2 M_pe` (K does not couple torsion
/// and swing), every neglected term carries `w^2 M_pe D_ee^-1 ~ (w / w_swing)^2 M_pe / M_ee`:
///
/// ```text
/// H - H_2 = C_p D_pp^-1 D_pe D_ee^-1 (D_ep D_pp^-1 Q_p - Q_e)
///         + C_e D_ee^-1 (Q_e - D_ep D_pp^-1 Q_p) + O(coupling^2)
/// ```
fn torsion2_first_order(case: &Case, o: Observable, input: Input, freq_hz: f64) -> Complex64 {
    let m = &case.model;
    let w2 = angular(freq_hz).powi(2);
    let (p, e) = ([Coord::PhiA, Coord::PhiB], [Coord::EtaA, Coord::EtaB]);
    let k = m.stiffness_complex();
    let d = |a: [Coord; 2], b: [Coord; 2]| {
        Matrix2::from_fn(|r, c| {
            let (i, j) = (a[r].index(), b[c].index());
            k[(i, j)] - m.mass()[(i, j)] * w2
        })
    };
    let g = forcing(m, input, w2);
    let q = |a: [Coord; 2]| Vector2::from_fn(|r, _| Complex64::from(g[a[r].index()]));
    let c = |a: [Coord; 2]| {
        RowVector2::from_fn(|_, col| Complex64::from(m.observation()[(o.index(), a[col].index())]))
    };
    let d_pp_inv = d(p, p).try_inverse().unwrap();
    let d_ee_inv = d(e, e).try_inverse().unwrap();
    let (d_pe, d_ep) = (d(p, e), d(e, p));
    let q_p2 = d_pp_inv * q(p);
    let swing = d_ee_inv * (q(e) - d_ep * q_p2);
    (c(p) * d_pp_inv * d_pe * (-swing) + c(e) * swing)[0]
}

/// Section IV.C's model against the full 8-DoF reference at 0.5..5 mHz, around the torsion
/// modes, for the torques and forces that turn the pendulum (M_b.z, F_b.x, M_a.z, F_a.x) and the
/// floor's rotation phi_t: the difference is the first-order coupling error above to within 2 %
/// (its own second order), and that error is of order (f / f_swing)^2: about 1e-5 at the
/// torsion modes.
#[test]
fn torsion2_matches_the_full_model_to_the_coupling_error() {
    let request = Request {
        outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
        inputs: vec![
            force("M_b.z"),
            force("F_b.x"),
            force("M_a.z"),
            force("F_a.x"),
            Input::Tilt(TiltAxis::PhiT),
        ],
    };
    // Relative differences are reported away from the full model's poles and zeros (near a
    // zero of the entry any absolute difference is a large relative one).
    let special = poles_and_zeros(&cases()[0], &request);
    let n_in = request.inputs.len();
    for case in cases() {
        let tf = plan(&case.model, &request, Method::Torsion2).unwrap();
        let modes = &case.modes.modes;
        let f_swing = modes
            .iter()
            .filter(|m| m.block == modes[0].block)
            .map(|m| m.frequency_hz)
            .filter(|&f| f > 0.1)
            .fold(f64::INFINITY, f64::min);
        let torsion: Vec<f64> = modes[..2].iter().map(|m| m.frequency_hz).collect();
        let mut max_rel = vec![(0.0f64, 0.0f64, String::new()); n_in];
        for f in log_grid(5e-4, 5e-3, 100.0) {
            if in_zone(f, &torsion) {
                continue;
            }
            let got = tf.eval(f).unwrap();
            let want = case.reference.eval(&request, f).unwrap();
            for (j, (&g, &r)) in got.iter().zip(&want).enumerate() {
                let (o, i) = (j / n_in, j % n_in);
                let predicted =
                    torsion2_first_order(case, request.outputs[o], request.inputs[i], f);
                let diff = r - g;
                assert!(
                    (diff - predicted).norm() <= 0.02 * predicted.norm() + 1e-12 * r.norm(),
                    "{} on {} at {f:e} Hz: full - 2-DoF = {diff}, first order {predicted}",
                    label(&request, o, i),
                    case.name
                );
                if in_zone(f, &special[j]) {
                    continue;
                }
                let rel = diff.norm() / r.norm();
                let scaled = rel / (f / f_swing).powi(2);
                let m = &mut max_rel[i];
                if rel > m.0 {
                    m.0 = rel;
                    m.2 = format!("{} at {f:.3e} Hz", request.outputs[o].name());
                }
                m.1 = m.1.max(scaled);
            }
        }
        for (i, (rel, scaled, at)) in max_rel.iter().enumerate() {
            println!(
                " torsion2 {:<20} {:<7} 0.5-5 mHz: max |full - 2-DoF| / |full| {rel:.1e} ({at}), \
                 {scaled:.2} (f / f_swing)^2",
                case.name,
                request.inputs[i].name(),
            );
        }
    }
}

/// What the 2-DoF model cannot represent is refused at plan time, with the reason.
#[test]
fn torsion2_refuses_what_it_cannot_represent() {
    let model = Model::new(&Params::table_i()).unwrap();
    let refusal = |request: Request| match plan(&model, &request, Method::Torsion2) {
        Err(e @ PlanError::Unsupported { .. }) => e.to_string(),
        Ok(_) => panic!("torsion2 planned {request:?}"),
    };
    let msg = refusal(Request::all_tilt());
    assert!(msg.contains("torsion2") && msg.contains("theta_t"), "{msg}");
    let msg = refusal(Request {
        outputs: vec![Observable::X],
        inputs: vec![Input::Tilt(TiltAxis::EtaT)],
    });
    assert!(
        msg.contains("input eta_t") && msg.contains("no eta"),
        "{msg}"
    );
    let msg = refusal(Request {
        outputs: vec![Observable::Y],
        inputs: vec![force("M_b.z")],
    });
    assert!(msg.contains("output Y"), "{msg}");
    let msg = refusal(Request {
        outputs: vec![Observable::X],
        inputs: vec![force("F_b.y")],
    });
    assert!(
        msg.contains("input F_b.y") && msg.contains("Q_phi_a"),
        "{msg}"
    );
    // What it can represent.
    let ok = Request {
        outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
        inputs: vec![
            force("F_a.x"),
            force("F_b.x"),
            force("M_a.z"),
            force("M_b.z"),
            Input::Tilt(TiltAxis::PhiT),
        ],
    };
    assert!(plan(&model, &ok, Method::Torsion2).is_ok());
}

/// Every method reports an exact undamped resonance as singular, never silent garbage.
#[test]
fn every_method_reports_exact_resonances() {
    let case = &cases()[0];
    let request = Request {
        outputs: vec![Observable::X, Observable::Phi, Observable::PhiA],
        inputs: vec![force("M_b.z")],
    };
    for method in Method::ALL {
        let tf = plan(&case.model, &request, method).unwrap();
        let lambda = match method {
            Method::Torsion2 => {
                // The 2-DoF model's own lowest mode.
                let p = case.model.params();
                let (d, y_a) = (p.length.d_m, case.model.derived().y_a_m);
                let i_c = p.inertia.a33_kg_m2 + d * y_a * (p.mass.m_a_kg + p.mass.m_b_kg);
                let i_t = p.inertia.b33_kg_m2;
                let (k_a, k_b) = (p.torsion.k_a_n_m_per_rad, p.torsion.k_b_n_m_per_rad);
                let (a, b, c) = (i_c * i_t, -(k_a * i_t + k_b * (i_c + i_t)), k_a * k_b);
                // The smaller root, without cancellation.
                2.0 * c / (-b + (b * b - 4.0 * a * c).sqrt())
            }
            // The modal method's own eigenvalue; the refined one for the LU methods.
            Method::Modal => case.modes.modes[0].omega_sq,
            _ => refined_omega_sq(&case.model, &case.modes.modes[0]),
        };
        let f = lambda.sqrt() / std::f64::consts::TAU;
        let near = tf.eval(f);
        assert!(
            matches!(near, Err(tiltnoise_core::error::TfError::Singular { .. })),
            "{} at nu_1 = {f} Hz: {near:?}",
            method.name()
        );
    }
}

#[test]
fn methods_have_distinct_names_and_flags() {
    let names: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
    assert_eq!(
        names,
        [
            "direct",
            "block",
            "split",
            "polezero",
            "modal",
            "statespace",
            "torsion2"
        ]
    );
    assert!(!Method::Modal.exact_for_damping());
    assert!(!Method::Torsion2.full_model());
    assert!(Method::ALL
        .iter()
        .filter(|&&m| m != Method::Modal)
        .all(|m| m.exact_for_damping()));
}

/// Away from Table I's round numbers `G2 + M S` from the library matrices is no longer exactly
/// zero in its phi_a row (`y_a m_a` and `d m_b` round differently; here m_a = 1.3 kg, where it is
/// -3.5e-18 for eta_t); the split method, with the closed-form forcing, still meets the target
/// on the whole band.
#[test]
fn split_meets_the_target_off_table_i() {
    let params = Params::table_i().with_override("mass.m_a_kg=1.3").unwrap();
    let case = Case::new("m_a = 1.3 kg", params);
    let request = Request::all_tilt();
    let m = &case.model;
    let library = m.tilt_forcing().g2[(Coord::PhiA.index(), TiltAxis::EtaT.index())]
        + m.mass()[(Coord::PhiA.index(), Coord::EtaA.index())];
    assert!(library != 0.0, "this variant was chosen for its rounding");
    let zones = poles_and_zeros(&case, &request);
    let tf = plan(m, &request, Method::Split).unwrap();
    let measured = check(&case, &request, tf.as_ref(), &zones, Tolerance::Target);
    println!(
        "    split {:<20} tilt    max rel error {:.1e} outside 1 % of poles/zeros ({})",
        case.name, measured.outside_zones, measured.worst
    );
}
