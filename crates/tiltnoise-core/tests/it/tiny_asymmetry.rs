//! The pendulum as built with asymmetry keys at the edge of `f64`'s range: an offset along x of
//! 1e-150, 1e-300, 1e-310 or 5e-324 m, or a readout rotation of as much, gives the planner a
//! method (never a false verdict on all of them) whose values are those of an independent
//! reference within the planner's tolerance.
//!
//! The reference is the linear response formed here, not the library's: the double-double
//! reference on the symmetric pendulum and on the one with the key at `D0 = 2^-80`
//! ([`ReferenceModel::exact`], without the reference's own linear response in tiny keys; every
//! entry a normal number there, and the key far above the 1e-28 below which the reference's
//! own structural decisions break down), combined as `H(0) + (H(D0) - H(0)) d / D0` in
//! double-double (`d / D0` exact: `d 2^80`). Its terms of second order in the key are about
//! `3e-19` of the first-order ones, far below the tolerance; that the response is linear
//! there is checked too (from `D0 / 4` to `D0` the difference doubles, to 1e-17).

use crate::tolerances::TARGET_REL;
use num_complex::Complex64;
use tiltnoise_core::model::{ForceInput, Model, Observable};
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::{CDd, ReferenceModel, DD_EPS};
use tiltnoise_core::tf::planner::{plan_auto, scene, verification_grid, SUBNORMAL_UNIT};
use tiltnoise_core::tf::{self, Input, Method, Request};

const KEYS: [&str; 6] = [
    "asymmetry.crossbar_com_x_m",
    "asymmetry.tm_com_x_m",
    "asymmetry.lower_attachment_x_m",
    "asymmetry.sensor_rot_x_rad",
    "asymmetry.sensor_rot_y_rad",
    "asymmetry.sensor_rot_z_rad",
];

const OFFSETS: [f64; 4] = [1e-150, 1e-300, 1e-310, 5e-324];

fn with(key: &str, value: f64) -> Params {
    Params::table_i()
        .with_override(&format!("{key}={value:e}"))
        .unwrap()
}

fn inputs() -> Vec<Input> {
    let mut i = Input::all_ground();
    i.extend([
        Input::Force(ForceInput::ALL[0]),
        Input::Force(ForceInput::ALL[10]),
    ]);
    i
}

/// The linear response `H(0) + (H(D0) - H(0)) d / D0` of the reference, and a check that the
/// response is linear at `D0`: `H(D0) - H(D0 / 2) = 2 (H(D0 / 2) - H(D0 / 4))` within its
/// rounding (three points of the as-built kinematics: the symmetric pendulum's closed forms
/// differ from them by their rounding, which `d / D0 < 2^-100` makes vanish in the response).
fn linear_reference(key: &str, d: f64, request: &Request, f: f64) -> Vec<CDd> {
    let d0 = 2f64.powi(-80);
    let eval = |v: f64| {
        let p = if v == 0.0 {
            Params::table_i()
        } else {
            with(key, v)
        };
        ReferenceModel::exact(&p).eval_dd(request, f).unwrap()
    };
    let (h0, h1) = (eval(0.0), eval(d0));
    let (h_half, h_quarter) = (eval(d0 / 2.0), eval(d0 / 4.0));
    for ((b, c), q) in h1.iter().zip(&h_half).zip(&h_quarter) {
        let (full, half) = (*b - *c, (*c - *q).ldexp(1));
        let dev = (full - half).abs_f64();
        // Second-order terms: at most 3e-19 of the first-order ones at D0 (the largest second
        // derivative, of an entry per tm_com_x_m, ~3e5 / m), bounded by 1e-17; rounding of
        // the three values: a few DD_EPS of each.
        assert!(
            dev <= 1e-17 * full.abs_f64() + 16.0 * DD_EPS * c.abs_f64(),
            "{key} at {f} Hz: not linear at {d0:e}: {:?} vs {:?}",
            full.to_c64(),
            half.to_c64()
        );
    }
    // d / D0 = d 2^80, exact.
    h0.iter()
        .zip(&h1)
        .map(|(a, b)| *a + (*b - *a).ldexp(80).scale(d.into()))
        .collect()
}

#[test]
fn tiny_symmetry_breaking_keys_give_the_planner_a_method_with_the_right_numbers() {
    let request = Request {
        outputs: Observable::ALL.to_vec(),
        inputs: inputs(),
    };
    for key in KEYS {
        for d in OFFSETS {
            let p = with(key, d);
            let model = Model::new(&p).unwrap();
            let s = scene(
                request.inputs.clone(),
                request.outputs.clone(),
                (1e-4, 30.0),
            );
            let (plan, choice) = plan_auto(&model, &s)
                .unwrap_or_else(|e| panic!("{key} = {d:e}: the planner refused: {e}"));
            let grid = verification_grid(&model, s.band_hz);
            for &f in grid.iter().step_by(9) {
                let got = plan.eval(f).unwrap();
                let want = linear_reference(key, d, &request, f);
                for (e, (g, w)) in got.iter().zip(&want).enumerate() {
                    let w64 = w.to_c64();
                    let err = (*g - w64).norm();
                    assert!(
                        err <= TARGET_REL * w64.norm() + SUBNORMAL_UNIT,
                        "{key} = {d:e}, {} at {f} Hz, entry {e}: {g} vs {w64} (error {err:e})",
                        choice.method.name()
                    );
                }
                // Every method asked for by name gives the same numbers (the linear response
                // in the tiny keys is the plan's, not only the planner's).
                if d < 1e-300 {
                    let pz = tf::plan(&model, &request, Method::PoleZero).unwrap();
                    let values = pz.eval(f).unwrap();
                    for (g, w) in values.iter().zip(&want) {
                        let w64: Complex64 = w.to_c64();
                        assert!((*g - w64).norm() <= TARGET_REL * w64.norm() + SUBNORMAL_UNIT);
                    }
                }
            }
        }
    }
}
