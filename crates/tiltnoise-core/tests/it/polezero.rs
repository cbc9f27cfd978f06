//! The pole-zero method against the double-double reference evaluator.
//!
//! * Accuracy: the accuracy target, 1e-9 relative on every structurally nonzero entry, on a dense
//!   log grid 1e-5 .. 100 Hz (2000 points plus points just outside every exclusion zone),
//!   excluding 1 % in frequency around the entry's own poles and zeros (taken from the undamped
//!   model's factors); undamped, damped (loss 1e-3 on torsions and bouncings), and m_a = 1.3 kg;
//!   the tilt, force and floor-translation matrices.
//!   The grid is evaluated in one batch (`tf::evaluate`, the path `auto` takes);
//!   `tests/it/polezero_batch.rs` checks that it equals the point-by-point path bit for bit.
//! * Structure: the zeros at s = 0 and the degree drops found by the plan match the physics.
//! * Structural zeros are exactly 0.0; f = 0 agrees with the reference.
//!
//! Run with `cargo test --release -p tiltnoise-core --test it polezero:: -- --nocapture` to see the
//! numbers.

use crate::common;
use crate::tolerances::{POLE_EXCLUSION, TARGET_REL};

use num_complex::Complex64;
use tiltnoise_core::error::TfError;
use tiltnoise_core::model::{ForceInput, Model, Observable, TiltAxis};
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{relative_errors, ReferenceModel};
use tiltnoise_core::tf::{evaluate, plan, EntryFactors, Input, Method, PoleZero, Request};

const LOSS: f64 = 1e-3;

fn heavy_crossbar() -> Params {
    Params::table_i().with_override("mass.m_a_kg=1.3").unwrap()
}

/// (name, params, undamped params whose poles and zeros define the exclusion zones).
fn cases() -> Vec<(&'static str, Params, Params)> {
    vec![
        ("Table I", Params::table_i(), Params::table_i()),
        (
            "Table I, loss 1e-3",
            common::with_torsion_and_bouncing_loss(Params::table_i(), LOSS),
            Params::table_i(),
        ),
        ("m_a = 1.3 kg", heavy_crossbar(), heavy_crossbar()),
        (
            "m_a = 1.3 kg, loss 1e-3",
            common::with_torsion_and_bouncing_loss(heavy_crossbar(), LOSS),
            heavy_crossbar(),
        ),
    ]
}

fn force_request() -> Request {
    let forces = [
        "F_a.x", "F_b.x", "F_b.y", "F_b.z", "M_a.z", "M_b.x", "M_b.y", "M_b.z",
    ];
    Request {
        outputs: Observable::ALL.to_vec(),
        inputs: forces
            .iter()
            .map(|n| Input::Force(ForceInput::from_name(n).unwrap()))
            .collect(),
    }
}

fn translation_request() -> Request {
    Request {
        outputs: Observable::ALL.to_vec(),
        inputs: Input::all_translations(),
    }
}

fn hz(s: f64) -> f64 {
    s.abs().sqrt() / (2.0 * std::f64::consts::PI)
}

/// Per entry (row-major), the frequencies (Hz) of its poles and zeros: `sqrt(|s|) / 2 pi` of
/// each (complex zeros included, conservatively).
fn zones(params: &Params, request: &Request) -> Vec<Vec<f64>> {
    let n_in = request.inputs.len();
    let mut z = vec![Vec::new(); request.outputs.len() * n_in];
    for f in PoleZero::factors(params, request) {
        let v = &mut z[f.output * n_in + f.input];
        v.extend(f.poles.iter().map(|p| hz(p.abs_f64())));
        v.extend(f.zeros.iter().map(|p| hz(p.abs_f64())));
    }
    z
}

fn in_zone(f: f64, special: &[f64]) -> bool {
    special
        .iter()
        .any(|&s| (f - s).abs() <= POLE_EXCLUSION * s.min(f))
}

fn grid(special: &[Vec<f64>]) -> Vec<f64> {
    let n = 2000;
    let (lo, hi): (f64, f64) = (1e-5, 100.0);
    let mut f: Vec<f64> = (0..=n)
        .map(|k| lo * (hi / lo).powf(k as f64 / n as f64))
        .collect();
    for s in special.iter().flatten() {
        for r in [
            1.0 / (1.0 + 1.01 * POLE_EXCLUSION),
            1.0 + 1.01 * POLE_EXCLUSION,
            0.95,
            1.05,
        ] {
            let x = s * r;
            if (lo..=hi).contains(&x) {
                f.push(x);
            }
        }
    }
    f.sort_by(f64::total_cmp);
    f.dedup();
    f
}

fn label(r: &Request, k: usize) -> String {
    let n_in = r.inputs.len();
    format!(
        "{}/{}",
        r.outputs[k / n_in].name(),
        r.inputs[k % n_in].name()
    )
}

/// Max relative error outside the zones (entry, frequency), and the number of points checked;
/// panics on a structural zero that is not exactly 0.0.
fn accuracy(params: &Params, zone_params: &Params, request: &Request) -> (f64, String, f64, usize) {
    let model = Model::new(params).unwrap();
    let reference = ReferenceModel::new(params);
    let tf = plan(&model, request, Method::PoleZero).unwrap();
    let special = zones(zone_params, request);
    let mut worst = (0.0, String::new(), 0.0);
    let mut checked = 0;
    // The whole grid at once: the batch evaluation that `tf::evaluate` (and `auto`) uses.
    let freqs = grid(&special);
    let all = evaluate(tf.as_ref(), &freqs).expect("no grid point is on an undamped pole");
    let nv = request.outputs.len() * request.inputs.len();
    let dense = all.dense_values();
    for (&f, h) in freqs.iter().zip(dense.chunks_exact(nv)) {
        let Ok(r) = reference.eval_dd(request, f) else {
            continue;
        };
        let err = relative_errors(h, &r);
        for (k, e) in err.iter().enumerate() {
            if r[k].is_zero() {
                assert_eq!(
                    *e,
                    0.0,
                    "{} at {f} Hz: structural zero is {}",
                    label(request, k),
                    h[k]
                );
                continue;
            }
            if in_zone(f, &special[k]) {
                continue;
            }
            checked += 1;
            if *e > worst.0 {
                worst = (*e, label(request, k), f);
            }
        }
    }
    (worst.0, worst.1, worst.2, checked)
}

#[test]
fn tilt_matrix_meets_the_target() {
    let request = Request::all_tilt();
    for (name, params, zone_params) in cases() {
        let (err, entry, f, n) = accuracy(&params, &zone_params, &request);
        println!(
            "polezero tilt, {name}: max rel err {err:.2e} ({entry} at {f:.4e} Hz), {n} values"
        );
        assert!(err <= TARGET_REL, "{name}: {err:e} at {entry}, {f} Hz");
    }
}

#[test]
fn force_entries_meet_the_target() {
    let request = force_request();
    for (name, params, zone_params) in cases() {
        let (err, entry, f, n) = accuracy(&params, &zone_params, &request);
        println!(
            "polezero forces, {name}: max rel err {err:.2e} ({entry} at {f:.4e} Hz), {n} values"
        );
        assert!(err <= TARGET_REL, "{name}: {err:e} at {entry}, {f} Hz");
    }
}

#[test]
fn translation_entries_meet_the_target() {
    let request = translation_request();
    for (name, params, zone_params) in cases() {
        let (err, entry, f, n) = accuracy(&params, &zone_params, &request);
        println!(
            "polezero translation, {name}: max rel err {err:.2e} ({entry} at {f:.4e} Hz), {n} \
             values"
        );
        assert!(err <= TARGET_REL, "{name}: {err:e} at {entry}, {f} Hz");
    }
}

/// The floor's translation: `G0 = 0`, so every entry has a factor `s`, and a second one where
/// no static response reaches the observable (the balanced crossbar: no torsion from x_t, no
/// swing from z_t). theta/z_t has a third: the gravity stiffness is diagonal in absolute angles,
/// and the bounce drives the test mass's absolute tilt only through the crossbar's swing, itself
/// a second-order response (the mass coupling `m_b d` of theta_a and delta_b). At high frequency the mass line `-C M^-1 G2` is finite except where it vanishes:
/// the test mass's rotation about z has no mass-line response to a force at its centre
/// (phi/x_t); a vertical translation of both bodies is the elongation delta_a alone, which
/// neither Y nor theta reads (Y/z_t, theta/z_t); and under y_t the elongations, which move the
/// centres of mass only vertically, hold both at their height, so the cube's Z (its centre's
/// height, to first order) does not move on the mass line (Z/y_t). Those fall as f^-2.
#[test]
fn translation_structure_matches_the_physics() {
    use tiltnoise_core::model::TranslationAxis;
    let request = translation_request();
    for (name, params, _) in cases() {
        let fs = PoleZero::factors(&params, &request);
        // X, eta, phi, phi_a from x_t; Y, Z, theta from y_t and from z_t.
        assert_eq!(fs.len(), 10, "{name}");
        for f in &fs {
            let o = request.outputs[f.output];
            let Input::Translation(t) = request.inputs[f.input] else {
                unreachable!()
            };
            let power = match (o, t) {
                (Observable::Phi | Observable::PhiA, TranslationAxis::XT)
                | (Observable::Y, TranslationAxis::ZT) => 2,
                (Observable::Theta, TranslationAxis::ZT) => 3,
                _ => 1,
            };
            let falls = matches!(
                (o, t),
                (Observable::Phi, TranslationAxis::XT)
                    | (Observable::Z, TranslationAxis::YT)
                    | (Observable::Y | Observable::Theta, TranslationAxis::ZT)
            );
            let high = f.power as i32 + f.zeros.len() as i32 - 4;
            println!(
                "{name}: {}/{}: p = {}, {} zeros, s^{high} at high f, cancelled {:?}",
                o.name(),
                t.name(),
                f.power,
                f.zeros.len(),
                f.cancelled
            );
            let label = format!("{name}: {}/{}", o.name(), t.name());
            assert_eq!(f.power, power, "{label}");
            assert_eq!(high, if falls { -1 } else { 0 }, "{label}");
        }
    }
}

fn find<'a>(fs: &'a [EntryFactors], r: &Request, o: Observable, t: TiltAxis) -> &'a EntryFactors {
    let oi = r.outputs.iter().position(|&x| x == o).unwrap();
    let ii = r.inputs.iter().position(|&x| x == Input::Tilt(t)).unwrap();
    fs.iter()
        .find(|f| f.output == oi && f.input == ii)
        .unwrap_or_else(|| panic!("{}/{} has no factors", o.name(), t.name()))
}

#[test]
fn structure_matches_the_physics() {
    let request = Request::all_tilt();
    for (name, params, _) in cases() {
        let fs = PoleZero::factors(&params, &request);
        // 11 structurally nonzero entries: Y, Z, theta from theta_t; X, eta, phi, phi_a from
        // eta_t and phi_t.
        assert_eq!(fs.len(), 11, "{name}");
        for f in &fs {
            let o = request.outputs[f.output];
            let Input::Tilt(t) = request.inputs[f.input] else {
                unreachable!()
            };
            // Low-frequency power of s: f^4 for phi, phi_a per eta_t; phi_t forces through
            // w^2 M only.
            let want_power = match (o, t) {
                (Observable::Phi | Observable::PhiA, TiltAxis::EtaT) => 2,
                (_, TiltAxis::PhiT) => 1,
                _ => 0,
            };
            // High-frequency power of s: 0 (a finite limit) except the f^-2 of eta/phi_t and
            // phi/eta_t (the test mass's rotation about z has no mass-line response to a
            // translation; its rotation about y none to a turn about z).
            let high = f.power as i32 + f.zeros.len() as i32 - 4;
            let want_high = match (o, t) {
                (Observable::Eta, TiltAxis::PhiT) | (Observable::Phi, TiltAxis::EtaT) => -1,
                _ => 0,
            };
            println!(
                "{name}: {}/{}: p = {}, {} zeros, s^{high} at high f, zeros (Hz) {:?}, cancelled {:?}",
                o.name(),
                t.name(),
                f.power,
                f.zeros.len(),
                f.zeros
                    .iter()
                    .map(|z| format!("{:.6e}{:+.1e}i", hz(z.re.to_f64()), z.im.to_f64()))
                    .collect::<Vec<_>>(),
                f.cancelled
            );
            assert_eq!(f.power, want_power, "{name}: {}/{}", o.name(), t.name());
            assert_eq!(high, want_high, "{name}: {}/{}", o.name(), t.name());
        }
        // The poles are the block's eigenvalues: positive and real without loss.
        let f = find(&fs, &request, Observable::Phi, TiltAxis::EtaT);
        if !name.contains("loss") {
            assert!(f.poles.iter().all(|p| p.im.is_zero() && p.re.hi > 0.0));
        }
    }
}

#[test]
fn zero_frequency_and_structural_zeros() {
    let request = Request::all_tilt();
    for (name, params, _) in cases() {
        let model = Model::new(&params).unwrap();
        let reference = ReferenceModel::new(&params);
        let tf = plan(&model, &request, Method::PoleZero).unwrap();
        let h = tf.eval(0.0).unwrap();
        let r = reference.eval_dd(&request, 0.0).unwrap();
        let n_in = request.inputs.len();
        for (k, (h, r)) in h.iter().zip(&r).enumerate() {
            let col_scale = (0..request.outputs.len())
                .map(|o| reference.eval(&request, 0.0).unwrap()[o * n_in + k % n_in].norm())
                .fold(0.0, f64::max)
                .max(1.0);
            let r64 = r.to_c64();
            if *h == Complex64::new(0.0, 0.0) {
                // An exact zero here is either structural or the s^p factor: the reference
                // leaves at most double-double rounding there.
                assert!(
                    r64.norm() <= 1e-25 * col_scale,
                    "{name}: {} = 0 vs {r64}",
                    label(&request, k)
                );
            } else {
                let e = relative_errors(&[*h], &[*r])[0];
                assert!(e <= 1e-14, "{name}: {} at f = 0: {e:e}", label(&request, k));
            }
        }
    }
}

#[test]
fn undamped_pole_is_singular() {
    let params = Params::table_i();
    let model = Model::new(&params).unwrap();
    let tf = plan(&model, &Request::all_tilt(), Method::PoleZero).unwrap();
    let fs = PoleZero::factors(&params, &Request::all_tilt());
    let lambda = fs[0].poles[0].re.to_f64();
    // The frequency whose (2 pi f)^2 is nearest to lambda.
    let f = lambda.sqrt() / (2.0 * std::f64::consts::PI);
    match tf.eval(f) {
        Err(TfError::Singular { .. }) => {}
        other => panic!("expected singular at {f} Hz, got {other:?}"),
    }
    assert!(tf.eval(f * 1.001).is_ok());
    // The split method (equilibrated LU, condition check) agrees at these two points.
    let split = plan(&model, &Request::all_tilt(), Method::Split).unwrap();
    assert!(matches!(split.eval(f), Err(TfError::Singular { .. })));
    assert!(split.eval(f * 1.001).is_ok());
}
