//! `auto` picks the smallest model and the cheapest method that meet a scene's tolerance; each
//! pick is verified here against the full model and the double-double reference on a fresh grid
//! (different from the planner's verification grid).

use tiltnoise_core::model::{ForceInput, Model, Observable, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::ReferenceModel;
use tiltnoise_core::tf::planner::{choose, measured_error, scene, Scene};
use tiltnoise_core::tf::{plan, Input, Method};

fn table_i() -> Model {
    Model::new(&Params::table_i()).unwrap()
}

/// A fresh verification grid: 37 points offset from the planner's 64-point grid, > 1 % away
/// from every mode.
fn fresh_grid(model: &Model, (lo, hi): (f64, f64)) -> Vec<f64> {
    let modes = tiltnoise_core::modes::NormalModes::new(model).frequencies_hz();
    (0..37)
        .map(|k| lo * (hi / lo).powf((k as f64 + 0.37) / 37.0))
        .filter(|f| modes.iter().all(|m| ((f - m) / m).abs() > 0.01))
        .collect()
}

fn verify(model: &Model, s: &Scene, picked: Method) {
    let reference = ReferenceModel::new(model.params());
    let grid = fresh_grid(model, s.band_hz);
    let err = measured_error(model, &reference, &s.request, picked, &grid).unwrap();
    assert!(
        err <= s.rel_tol,
        "{}: {err:e} > {:e}",
        picked.name(),
        s.rel_tol
    );
    // And against the full model's direct solve, where that is accurate (same tolerance plus
    // the direct method's own error on this grid, measured against the reference).
    let direct_err = measured_error(model, &reference, &s.request, Method::Direct, &grid).unwrap();
    let (a, b) = (
        plan(model, &s.request, picked).unwrap(),
        plan(model, &s.request, Method::Direct).unwrap(),
    );
    for &f in &grid {
        let want = reference.eval_dd(&s.request, f).unwrap();
        let direct = b.eval(f).unwrap();
        let got = a.eval(f).unwrap();
        let scale: Vec<f64> = want.iter().map(|w| w.to_c64().norm()).collect();
        for k in 0..got.len() {
            let diff = (got[k] - direct[k]).norm();
            assert!(
                diff <= (s.rel_tol + direct_err) * scale[k] * (1.0 + 1e-12),
                "{} vs direct, entry {k} at {f} Hz: {diff:e}",
                picked.name()
            );
        }
    }
}

#[test]
fn all_tilt_entries_at_full_accuracy_use_the_pole_zero_blocks() {
    let model = table_i();
    let s = scene(Input::all_tilts(), Observable::ALL.to_vec(), (1e-5, 100.0));
    let choice = choose(&model, &s).unwrap();
    assert_eq!(choice.method, Method::PoleZero, "{}", choice.explain());
    // The smaller model was tried first and refused for a stated reason.
    let first = &choice.verdicts[0];
    assert_eq!(first.method, Method::Torsion2);
    assert!(first.outcome.as_ref().unwrap_err().contains("eta"));
    verify(&model, &s, choice.method);
    assert!(choice.explain().contains("picked `polezero`"));
    // The block LU on the same 4-DoF blocks would not meet the target (f^-2 entries at high f).
    let reference = ReferenceModel::new(model.params());
    let grid = fresh_grid(&model, s.band_hz);
    let block = measured_error(&model, &reference, &s.request, Method::Block, &grid).unwrap();
    assert!(block > s.rel_tol, "block: {block:e}");
}

#[test]
fn tilt_to_x_below_the_swing_modes_needs_only_one_4dof_block() {
    let model = table_i();
    let s = scene(
        vec![Input::Tilt(TiltAxis::EtaT)],
        vec![Observable::X],
        (1e-4, 0.1),
    );
    let choice = choose(&model, &s).unwrap();
    assert_eq!(choice.method, Method::PoleZero, "{}", choice.explain());
    verify(&model, &s, choice.method);
    // Only the swing-x+torsion block is involved: one entry out.
    let tf = plan(&model, &s.request, choice.method).unwrap();
    assert_eq!(tf.eval(1e-3).unwrap().len(), 1);
}

#[test]
fn test_mass_torque_near_the_torsion_modes_uses_the_2dof_model() {
    // The 2-DoF model's coupling error is ~1.8 (f/f_swing)^2 for M_b.z (tests/it/methods.rs):
    // about 7e-5 at 5 mHz, so a 1e-4 scene over 0.5..5 mHz is within its reach.
    let model = table_i();
    let mut s = scene(
        vec![Input::Force(ForceInput::from_name("M_b.z").unwrap())],
        vec![Observable::Phi, Observable::PhiA, Observable::X],
        (5e-4, 5e-3),
    );
    s.rel_tol = 1e-4;
    let choice = choose(&model, &s).unwrap();
    assert_eq!(choice.method, Method::Torsion2, "{}", choice.explain());
    verify(&model, &s, choice.method);
    // At the 1e-9 default the reduced model is not enough and a 4-DoF block is picked.
    s.rel_tol = 1e-9;
    let choice = choose(&model, &s).unwrap();
    assert_ne!(choice.method, Method::Torsion2, "{}", choice.explain());
    verify(&model, &s, choice.method);
}

#[test]
fn impossible_scenes_are_refused_with_reasons() {
    let model = table_i();
    let mut s = scene(Input::all_tilts(), Observable::ALL.to_vec(), (1e-5, 100.0));
    s.rel_tol = 1e-20;
    let refusal = choose(&model, &s).unwrap_err();
    // One line naming the tolerance and the most accurate candidate; every verdict on its own
    // line only in the explanation.
    let e = refusal.to_string();
    assert!(
        e.contains("no method meets the relative tolerance 1e-20") && e.contains("reaches"),
        "{e}"
    );
    assert!(!e.contains('\n'), "{e}");
    let explained = refusal.explain();
    assert!(
        explained.ends_with("none meets the tolerance"),
        "{explained}"
    );
    for name in ["torsion2", "polezero", "block", "split", "modal", "direct"] {
        assert!(
            explained.contains(&format!("  {name}")),
            "{name}: {explained}"
        );
    }
    let bad = scene(Input::all_tilts(), vec![Observable::X], (0.0, 1.0));
    assert!(choose(&model, &bad)
        .unwrap_err()
        .to_string()
        .contains("band"));
}
