//! Floor-translation transfer functions against physics identities, on the double-double
//! reference (so the identities, not an `f64` method, are under test; `tests/it/methods.rs`
//! checks every method against the reference):
//!
//! * a translation is the apparent force on both centres of mass: `H_u = w^2 (m_a H_F_a.k +
//!   m_b H_F_b.k)` per axis `k`, to the reference's own error;
//! * the equivalence principle as `f -> 0`: per unit floor acceleration `a = -w^2 u` a
//!   horizontal translation acts as the tilt `eta_t = a_x / g`, `theta_t = -a_y / g` of this
//!   crate's convention, and a vertical one as a change of `g` (the fibres' stretch under the
//!   bodies' weight, in closed form), with a difference bounded by `C f^2`;
//! * the mass line: at high frequency the test mass stays where it is and the housing rises
//!   past it, `Z/z_t -> -1`;
//! * the planner and the 2-DoF model: what they do with a translation;
//! * the pendulum as built: the first two identities hold about its tilted rest configuration
//!   too (offsets along x couple the blocks; the identities do not care), and the model's
//!   translation columns are the double-double linearization's, rounded once.
//!
//! Run with `--nocapture` to see the equivalence figures.

use crate::tolerances::U;
use crate::tolerances::{DD_REF_FACTOR, EPS};
use num_complex::Complex64;
use tiltnoise_core::geometry::dd_matrices;
use tiltnoise_core::model::{ForceInput, Model, Observable, TiltAxis, TranslationAxis};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{CDd, Dd, ReferenceModel, DD_EPS};
use tiltnoise_core::tf::planner::{choose, scene};
use tiltnoise_core::tf::{plan, Input, Method, PlanError, Request};

/// `(2 pi f)^2` in double-double, as the reference forms it.
fn omega_sq(f: f64) -> Dd {
    (Dd::PI * (2.0 * f)).sqr()
}

fn params_set() -> Vec<(&'static str, Params)> {
    vec![
        ("Table I", Params::table_i()),
        (
            "loss 1e-3",
            crate::common::with_torsion_and_bouncing_loss(Params::table_i(), 1e-3),
        ),
        (
            "m_a = 1.3 kg, h = 2.1 m",
            Params::table_i()
                .with_override("mass.m_a_kg=1.3")
                .unwrap()
                .with_override("length.h_m=2.1")
                .unwrap(),
        ),
    ]
}

/// Pendulums as built whose offsets along x couple the two blocks: the crossbar's centre of
/// mass, the test mass's with structural loss, and every offset at once with the readout
/// turned.
fn as_built_set() -> Vec<(&'static str, Params)> {
    let with = |sets: &[&str], base: Params| {
        sets.iter()
            .fold(base, |p, s| p.with_override(s).expect("a valid offset"))
    };
    vec![
        (
            "crossbar x 1 mm",
            with(&["asymmetry.crossbar_com_x_m=1e-3"], Params::table_i()),
        ),
        (
            "test mass x 0.5 mm, loss 1e-3",
            with(
                &["asymmetry.tm_com_x_m=5e-4"],
                crate::common::with_torsion_and_bouncing_loss(Params::table_i(), 1e-3),
            ),
        ),
        (
            "every offset, readout turned",
            with(
                &[
                    "asymmetry.crossbar_com_x_m=-8e-4",
                    "asymmetry.crossbar_com_y_m=1.2e-3",
                    "asymmetry.tm_com_x_m=2e-3",
                    "asymmetry.tm_com_y_m=5e-4",
                    "asymmetry.lower_attachment_x_m=-3e-4",
                    "asymmetry.lower_attachment_y_m=9e-4",
                    "asymmetry.sensor_rot_z_rad=-4e-3",
                ],
                Params::table_i(),
            ),
        ),
    ]
}

/// The symmetric sets and the pendulums as built.
fn all_sets() -> Vec<(&'static str, Params)> {
    let mut sets = params_set();
    sets.extend(as_built_set());
    sets
}

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..=n)
        .map(|k| lo * (hi / lo).powf(k as f64 / n as f64))
        .collect()
}

fn translation(axis: TranslationAxis) -> Input {
    Input::Translation(axis)
}

fn force(name: &str) -> Input {
    Input::Force(ForceInput::from_name(name).unwrap())
}

/// `H_u = w^2 (m_a H_F_a.k + m_b H_F_b.k)` for every observable and axis, from 1e-6 to 100 Hz
/// (away from exact resonances), within the reference's own error bound on each of the three
/// entries: `DD_REF_FACTOR DD_EPS kappa |H|` each, `kappa` the entry's condition number.
#[test]
fn translation_is_the_apparent_force_at_both_centres_of_mass() {
    for (name, params) in all_sets() {
        let reference = ReferenceModel::new(&params);
        let (m_a, m_b) = (Dd::from(params.mass.m_a_kg), Dd::from(params.mass.m_b_kg));
        let modes = NormalModes::new(&Model::new(&params).unwrap()).frequencies_hz();
        let mut worst = 0.0f64;
        for (k, axis) in TranslationAxis::ALL.into_iter().enumerate() {
            let c = ["x", "y", "z"][k];
            let request = Request {
                outputs: Observable::ALL.to_vec(),
                inputs: vec![
                    translation(axis),
                    force(&format!("F_a.{c}")),
                    force(&format!("F_b.{c}")),
                ],
            };
            for f in log_grid(1e-6, 100.0, 400) {
                if modes.iter().any(|m| ((f - m) / m).abs() < 1e-6) {
                    continue;
                }
                let h = reference.eval_dd(&request, f).unwrap();
                let kappa = reference.entry_condition(&request, f).unwrap();
                let w2 = omega_sq(f);
                for o in 0..Observable::ALL.len() {
                    let at = |i: usize| (h[3 * o + i], kappa[3 * o + i] * h[3 * o + i].abs_f64());
                    let ((u, eu), (fa, ea), (fb, eb)) = (at(0), at(1), at(2));
                    let apparent = (fa.scale(m_a) + fb.scale(m_b)).scale(w2);
                    let label = format!(
                        "{name}: {}/{} at {f:e} Hz",
                        Observable::ALL[o].name(),
                        axis.name()
                    );
                    if u.is_zero() {
                        assert!(apparent.is_zero(), "{label}: {}", apparent.to_c64());
                        continue;
                    }
                    let scale = w2.to_f64();
                    let tol = DD_REF_FACTOR
                        * DD_EPS
                        * (eu + scale * (params.mass.m_a_kg * ea + params.mass.m_b_kg * eb));
                    let diff = (u - apparent).abs_f64();
                    assert!(diff <= tol, "{label}: |diff| {diff:e} > tol {tol:e}");
                    worst = worst.max(diff / u.abs_f64());
                }
            }
        }
        println!("{name}: translation vs apparent forces, max relative difference {worst:.1e}");
    }
}

/// `H_u / (-w^2) - sign H_t / g` per entry: the response per unit floor acceleration minus
/// that of the equivalent tilt (`eta_t = a_x / g`: sign +1; `theta_t = -a_y / g`: sign -1).
fn equivalence_gap(
    reference: &ReferenceModel,
    g: f64,
    (axis, tilt, sign): (TranslationAxis, TiltAxis, f64),
    f: f64,
) -> Vec<CDd> {
    let request = Request {
        outputs: Observable::ALL.to_vec(),
        inputs: vec![translation(axis), Input::Tilt(tilt)],
    };
    let h = reference.eval_dd(&request, f).unwrap();
    let minus_inv_w2 = -(Dd::ONE / omega_sq(f));
    let tilt_per_g = Dd::from(sign) / Dd::from(g);
    (0..Observable::ALL.len())
        .map(|o| h[2 * o].scale(minus_inv_w2) - h[2 * o + 1].scale(tilt_per_g))
        .collect()
}

const HORIZONTAL: [(TranslationAxis, TiltAxis, f64); 2] = [
    (TranslationAxis::XT, TiltAxis::EtaT, 1.0),
    (TranslationAxis::YT, TiltAxis::ThetaT, -1.0),
];

/// The equivalence principle for horizontal translations: per unit floor acceleration the
/// response equals that to the tilt `eta_t = a_x / g` (x_t) and `theta_t = -a_y / g` (y_t), up
/// to a difference `-(w^2 / g) C D^-1 G2_tilt` (derived in the docs of `model::translation`)
/// that is quadratic in f. As in `tilt_tf.rs`, C is read at 1e-5 Hz (130
/// times below the lowest mode, 1.3 mHz) and `|gap| <= 2 C f^2` is checked down to 1e-9 Hz for
/// every entry; for every entry with a nonzero gap the gap is a power law of even order, not
/// just small: between 1e-6 and 1e-7 Hz `|gap|` falls by `10^n` with `n` within 1 % of 2 or 4
/// (on the pendulum as built some entries lose the `f^2` term: theta/x_t with the crossbar
/// off along x, whose leading gap is `f^4`). The figures are printed relative to the static
/// tilt response per g.
#[test]
fn horizontal_acceleration_acts_as_tilt() {
    for (name, params) in all_sets() {
        let reference = ReferenceModel::new(&params);
        let g = params.environment.g_m_per_s2;
        let lever = Model::new(&params).unwrap().derived().lever_m;
        for pair @ (axis, tilt, _) in HORIZONTAL {
            let f_ref = 1e-5;
            let c: Vec<f64> = equivalence_gap(&reference, g, pair, f_ref)
                .iter()
                .map(|d| d.abs_f64() / (f_ref * f_ref))
                .collect();
            for f in log_grid(1e-9, f_ref, 40) {
                let gap = equivalence_gap(&reference, g, pair, f);
                for (o, d) in gap.iter().enumerate() {
                    assert!(
                        d.abs_f64() <= 2.0 * c[o] * f * f,
                        "{name}: {}/{} vs {}/{} at {f:e} Hz: gap {:e} > 2 C f^2 = {:e}",
                        Observable::ALL[o].name(),
                        axis.name(),
                        Observable::ALL[o].name(),
                        tilt.name(),
                        d.abs_f64(),
                        2.0 * c[o] * f * f
                    );
                }
            }
            let main = match axis {
                TranslationAxis::XT => Observable::X,
                _ => Observable::Y,
            };
            for o in Observable::ALL {
                if c[o.index()] == 0.0 {
                    continue;
                }
                let r = |f: f64| equivalence_gap(&reference, g, pair, f)[o.index()].abs_f64();
                let order = (r(1e-6) / r(1e-7)).log10();
                assert!(
                    [2.0, 4.0].iter().any(|n| ((order - n) / n).abs() < 1e-2),
                    "{name}: {}/{}: the gap falls as f^{order:.3} between 1e-6 and 1e-7 Hz",
                    o.name(),
                    axis.name()
                );
                if (order - 4.0).abs() < 0.04 {
                    println!("{name}: {}/{}: gap of order f^4", o.name(), axis.name());
                }
            }
            let figures: Vec<String> = [1e-6, 1e-5, 1e-4]
                .iter()
                .map(|&f| {
                    let d = equivalence_gap(&reference, g, pair, f)[main.index()].abs_f64();
                    format!("{:.1e} at {f:.0e} Hz", d / (lever / g))
                })
                .collect();
            println!(
                "{name}: |{m}/{} / (-w^2) - ({m}/{}) / g| / (lever / g): {}",
                axis.name(),
                tilt.name(),
                figures.join(", "),
                m = main.name(),
            );
        }
    }
}

/// The equivalence principle for the vertical: an upward floor acceleration `a_z` acts as a
/// change of `g` by `a_z`. Each fibre stretches by the extra weight it carries, `(m_a + m_b)
/// a_z / kappa_a` and `m_b a_z / kappa_b`, so per unit acceleration `Z -> -((m_a + m_b) /
/// kappa_a + m_b / kappa_b)` (Hooke's law, closed form; with structural loss each `kappa` is
/// the complex `kappa (1 + i phi)`), and the balanced crossbar does not swing: Y, theta -> 0.
/// Limit within the rounding of the closed form (8 eps), approached as `C f^2` (C read at
/// 1e-2 Hz, 40 times below the lowest mode of the block, 0.41 Hz).
#[test]
fn vertical_acceleration_acts_as_a_change_of_g() {
    for (name, params) in params_set() {
        let reference = ReferenceModel::new(&params);
        let (m_a, m_b) = (params.mass.m_a_kg, params.mass.m_b_kg);
        let (b, loss) = (&params.bouncing, &params.loss);
        let k_a = Complex64::new(b.kappa_a_n_per_m, b.kappa_a_n_per_m * loss.bouncing_a_rad);
        let k_b = Complex64::new(b.kappa_b_n_per_m, b.kappa_b_n_per_m * loss.bouncing_b_rad);
        let z_static = -((m_a + m_b) / k_a + m_b / k_b);
        let request = Request {
            outputs: Observable::ALL.to_vec(),
            inputs: vec![translation(TranslationAxis::ZT)],
        };
        let per_acceleration = |f: f64| -> Vec<Complex64> {
            let minus_inv_w2 = -(Dd::ONE / omega_sq(f));
            reference
                .eval_dd(&request, f)
                .unwrap()
                .iter()
                .map(|h| h.scale(minus_inv_w2).to_c64())
                .collect()
        };
        let limit = |o: Observable| match o {
            Observable::Z => z_static,
            _ => Complex64::new(0.0, 0.0),
        };
        let f_ref = 1e-2;
        let at_ref = per_acceleration(f_ref);
        for f in log_grid(1e-8, f_ref, 30) {
            let h = per_acceleration(f);
            for o in Observable::ALL {
                let want = limit(o);
                let c = (at_ref[o.index()] - want).norm() / (f_ref * f_ref);
                let gap = (h[o.index()] - want).norm();
                let tol = 8.0 * EPS * want.norm() + 2.0 * c * f * f;
                assert!(
                    gap <= tol,
                    "{name}: {}/z_t per unit acceleration at {f:e} Hz: {} vs {want}, gap \
                     {gap:e} > {tol:e}",
                    o.name(),
                    h[o.index()]
                );
            }
        }
        let z = per_acceleration(1e-4)[Observable::Z.index()];
        println!("{name}: Z/z_t / (-w^2) at 1e-4 Hz = {z:.6e} m/(m/s^2); Hooke: {z_static:.6e}");
    }
}

/// On the mass line the test mass stays where it is and the housing rises past it: a vertical
/// translation of both bodies is the upper fibre's elongation alone (`M^-1 G2 = -e_delta_a`
/// exactly), so `Z/z_t -> -1`, approached as `C / f^2` (C read at 1 kHz, 90 times above the
/// highest bounce mode, 10.8 Hz).
#[test]
fn housing_rises_past_the_test_mass_at_high_frequency() {
    let reference = ReferenceModel::new(&Params::table_i());
    let request = Request {
        outputs: vec![Observable::Z],
        inputs: vec![translation(TranslationAxis::ZT)],
    };
    let gap = |f: f64| (reference.eval(&request, f).unwrap()[0] + 1.0).norm();
    let f_ref = 1e3;
    let c = gap(f_ref) * f_ref * f_ref;
    assert!(c > 0.0);
    for f in log_grid(f_ref, 1e6, 30) {
        assert!(
            gap(f) <= 2.0 * c / (f * f),
            "Z/z_t + 1 at {f:e} Hz: {:e} > 2 C / f^2 = {:e}",
            gap(f),
            2.0 * c / (f * f)
        );
    }
}

/// The planner verifies translation scenes like any other, picking the pole-zero method for the
/// six ground inputs over the default band; the 2-DoF torsional model refuses a translation
/// with the reason.
#[test]
fn planner_and_torsion2_on_translations() {
    let model = Model::new(&Params::table_i()).unwrap();
    let ground = scene(Input::all_ground(), Observable::ALL.to_vec(), (1e-4, 30.0));
    let choice = choose(&model, &ground).unwrap();
    assert_eq!(choice.method, Method::PoleZero, "{}", choice.explain());
    for axis in TranslationAxis::ALL {
        let request = Request {
            outputs: vec![Observable::Phi],
            inputs: vec![translation(axis)],
        };
        match plan(&model, &request, Method::Torsion2) {
            Err(e @ PlanError::Unsupported { .. }) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(&format!("input {}", axis.name())) && msg.contains("balanced"),
                    "{msg}"
                );
            }
            Ok(_) => panic!("torsion2 planned {}", axis.name()),
        }
    }
}

/// The model's translation columns on the pendulum as built are the double-double
/// linearization's (the reference's data), each rounded once to the nearest `f64`: half an ulp.
/// Their physics is checked independently against the kinetic energy in
/// `energy_crosscheck.rs`; this checks that the `f64` model and the reference read the same
/// columns of the six ground inputs, entry by entry.
#[test]
fn translation_columns_as_built_are_the_reference_rounded() {
    for (name, params) in as_built_set() {
        let model = Model::new(&params).unwrap();
        assert!(
            !model.decoupled(),
            "{name}: an offset along x couples the blocks"
        );
        let (reference, _) = dd_matrices(&params);
        let g2 = &model.translation_forcing().g2;
        let mut nonzero = 0;
        for (r, row) in reference.translation_g2.iter().enumerate() {
            for (k, exact) in row.iter().enumerate() {
                let exact = exact.to_f64();
                let got = g2[(r, k)];
                assert!(
                    (got - exact).abs() <= U * exact.abs(),
                    "{name}: G2[{r}, {}] = {got:e}, reference {exact:e}",
                    TranslationAxis::ALL[k].name()
                );
                nonzero += usize::from(exact != 0.0);
            }
        }
        // Coupled: x_t now drives the swing-y+bounce block too (theta_a, delta_a, ...), so
        // more entries than the symmetric pendulum's 12 are nonzero.
        let symmetric = Model::new(&Params::table_i()).unwrap();
        let sym_nonzero = symmetric
            .translation_forcing()
            .g2
            .iter()
            .filter(|v| **v != 0.0)
            .count();
        assert!(
            nonzero > sym_nonzero,
            "{name}: {nonzero} nonzero translation entries, the symmetric pendulum has {sym_nonzero}"
        );
    }
}
