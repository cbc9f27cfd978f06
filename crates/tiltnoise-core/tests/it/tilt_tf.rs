//! Tilt transfer functions of the direct method: the quasi-static limits stated in section IV.B
//! (and the rest of the plumb-line picture), the f^2 approach to them, structural zeros, the
//! sign convention, and singular reporting at exact undamped resonances.

use nalgebra::DMatrix;
use num_complex::Complex64;
use tiltnoise_core::error::TfError;
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{plan, Method, Request, TransferFunction};

use Observable::*;
use TiltAxis::*;

fn entry(h: &[Complex64], o: Observable, t: TiltAxis) -> Complex64 {
    h[o.index() * 3 + t.index()]
}

fn direct(model: &Model) -> Box<dyn TransferFunction> {
    plan(model, &Request::all_tilt(), Method::Direct).unwrap()
}

/// 1-norm condition number of the symmetrically equilibrated stiffness: the direct method's
/// forward error at f = 0 is bounded by `n eps cond` relative to the solution scale.
fn equilibrated_cond(model: &Model) -> f64 {
    let k = model.stiffness();
    let s: Vec<f64> = (0..8).map(|i| 1.0 / k[(i, i)].sqrt()).collect();
    let ks = DMatrix::from_fn(8, 8, |r, c| k[(r, c)] * s[r] * s[c]);
    let inv = ks.clone().try_inverse().unwrap();
    let norm1 = |m: &DMatrix<f64>| (0..8).map(|c| m.column(c).abs().sum()).fold(0.0, f64::max);
    norm1(&ks) * norm1(&inv)
}

/// Expected quasi-static response: the test mass hangs plumb, the GRS tilts with the floor.
/// (X/eta_t, Y/theta_t from section IV.B; Z/theta_t = -d, theta/theta_t = eta/eta_t = 1 from the
/// same picture; every other entry 0.)
fn expected_static(p: &Params, o: Observable, t: TiltAxis) -> f64 {
    let lever = p.length.z_m + p.length.z_b_m + p.length.h_c_m;
    match (o, t) {
        (X, EtaT) => -lever,
        (Y, ThetaT) => lever,
        (Z, ThetaT) => -p.length.d_m,
        (Theta, ThetaT) | (Eta, EtaT) => 1.0,
        _ => 0.0,
    }
}

fn check_static_limits(p: &Params) {
    let model = Model::new(p).unwrap();
    let h = direct(&model).eval(0.0).unwrap();
    let lever = model.derived().lever_m;
    // Forward error of the LU solve: n eps cond, on a solution of scale `lever` (m/rad).
    let tol = 8.0 * f64::EPSILON * equilibrated_cond(&model) * lever;
    for o in Observable::ALL {
        for t in TiltAxis::ALL {
            let got = entry(&h, o, t);
            let want = expected_static(p, o, t);
            assert!(
                (got - want).norm() <= tol,
                "f=0 {}/{}: got {got}, want {want}, tol {tol:e}",
                o.name(),
                t.name()
            );
        }
    }
}

#[test]
fn quasi_static_limits_table_i() {
    check_static_limits(&Params::table_i());
}

#[test]
fn quasi_static_limits_other_geometry_and_damping() {
    let p = Params::table_i()
        .with_override("length.h_m=0.5")
        .unwrap()
        .with_override("length.z_b_m=0.3")
        .unwrap()
        .with_override("inertia.a23_kg_m2=0.01")
        .unwrap()
        .with_override("loss.torsion_a_rad=1e-3")
        .unwrap()
        .with_override("loss.bouncing_b_rad=1e-2")
        .unwrap();
    check_static_limits(&p);
}

/// The approach to the static limit is quadratic in f: `|H(f) - H(0)| <= C f^2` on
/// 1e-7 .. 1e-4 Hz (well below nu_1 = 1.3 mHz), with C read at 1e-4 Hz and allowed a factor
/// (1 + (f/nu_1)^2)-type slack of 2. Checked for every entry, the zero-limit ones included.
#[test]
fn approach_to_static_limit_is_bounded_by_c_f_squared() {
    let model = Model::new(&Params::table_i()).unwrap();
    let tf = direct(&model);
    let h0 = tf.eval(0.0).unwrap();
    let f_ref = 1e-4;
    let h_ref = tf.eval(f_ref).unwrap();
    // Rounding floor of the difference: n eps cond times the entry's scale.
    let floor = 8.0 * f64::EPSILON * equilibrated_cond(&model) * model.derived().lever_m;
    for (idx, (a, b)) in h_ref.iter().zip(&h0).enumerate() {
        let c = (a - b).norm() / (f_ref * f_ref);
        for k in 0..=30 {
            let f = 1e-7 * 10f64.powf(k as f64 / 10.0);
            let h = tf.eval(f).unwrap();
            let dev = (h[idx] - h0[idx]).norm();
            assert!(
                dev <= 2.0 * c * f * f + floor,
                "entry {idx} at {f} Hz: |H - H0| = {dev:e} > 2 C f^2 = {:e}",
                2.0 * c * f * f
            );
        }
    }
    // And for the nonzero limits the deviation really is quadratic, not just small: between
    // 1e-5 and 1e-6 Hz the ratio |H - H0| / f^2 changes by less than 1 %.
    for (o, t) in [(X, EtaT), (Y, ThetaT)] {
        let r = |f: f64| (entry(&tf.eval(f).unwrap(), o, t) - entry(&h0, o, t)).norm() / (f * f);
        let (r5, r6) = (r(1e-5), r(1e-6));
        assert!(
            ((r5 - r6) / r5).abs() < 1e-2,
            "{}/{}: {r5:e} vs {r6:e}",
            o.name(),
            t.name()
        );
    }
}

#[test]
fn structural_zeros_are_exactly_zero_on_a_wide_grid() {
    let model = Model::new(&Params::table_i()).unwrap();
    let tf = direct(&model);
    let zero_pairs = [
        (X, ThetaT),
        (Eta, ThetaT),
        (Phi, ThetaT),
        (PhiA, ThetaT),
        (Y, EtaT),
        (Z, EtaT),
        (Theta, EtaT),
        (Y, PhiT),
        (Z, PhiT),
        (Theta, PhiT),
    ];
    for k in 0..=70 {
        let f = 1e-5 * 10f64.powf(k as f64 / 10.0);
        let h = match tf.eval(f) {
            Ok(h) => h,
            Err(TfError::Singular { .. }) => continue,
            Err(e) => panic!("{e}"),
        };
        for (o, t) in zero_pairs {
            assert_eq!(
                entry(&h, o, t),
                Complex64::new(0.0, 0.0),
                "{}/{} at {f}",
                o.name(),
                t.name()
            );
        }
        for (o, t) in [
            (X, EtaT),
            (Phi, EtaT),
            (PhiA, PhiT),
            (Y, ThetaT),
            (Z, ThetaT),
        ] {
            assert_ne!(
                entry(&h, o, t).norm(),
                0.0,
                "{}/{} at {f}",
                o.name(),
                t.name()
            );
        }
    }
}

#[test]
fn exact_undamped_resonance_is_reported_singular() {
    let model = Model::new(&Params::table_i()).unwrap();
    let tf = direct(&model);
    for mode in NormalModes::new(&model).modes {
        let lambda = tiltnoise_core::modes::refined_omega_sq(&model, &mode);
        let f = lambda.sqrt() / std::f64::consts::TAU;
        match tf.eval(f) {
            Err(TfError::Singular { freq_hz, rcond }) => {
                assert_eq!(freq_hz, f);
                assert!(rcond < tiltnoise_core::tf::SINGULAR_RCOND);
            }
            other => panic!(
                "nu_{} at {f} Hz: expected Singular, got {other:?}",
                mode.index
            ),
        }
        // Slightly off the pole the answer is finite and large, not an error.
        let h = tf.eval(f * (1.0 + 1e-6)).unwrap();
        assert!(h.iter().all(|z| z.re.is_finite() && z.im.is_finite()));
    }
}

#[test]
fn damped_torsion_resonance_is_finite_and_scales_as_one_over_loss() {
    // With loss on both torsion fibres the torsion peaks are finite; the peak of phi/eta_t at
    // nu_2 scales as 1/phi_loss (halving the loss doubles the peak to within the shift of the
    // peak frequency, a relative O(phi) effect).
    let peak = |loss: f64| {
        let p = Params::table_i()
            .with_override(&format!("loss.torsion_a_rad={loss}"))
            .unwrap()
            .with_override(&format!("loss.torsion_b_rad={loss}"))
            .unwrap();
        let model = Model::new(&p).unwrap();
        let f2 = NormalModes::new(&model).modes[1].frequency_hz;
        let h = direct(&model).eval(f2).unwrap();
        entry(&h, Phi, PhiT).norm()
    };
    let (a, b) = (peak(1e-3), peak(5e-4));
    assert!(a.is_finite() && b.is_finite());
    assert!(((b / a) - 2.0).abs() < 1e-2, "peak ratio {}", b / a);
}

#[test]
fn negative_and_nan_frequencies_are_refused() {
    let model = Model::new(&Params::table_i()).unwrap();
    let tf = direct(&model);
    for f in [-1.0, f64::NAN, f64::INFINITY] {
        let e = tf.eval(f).unwrap_err().to_string();
        assert!(e.contains("must be finite and >= 0"), "{e}");
    }
}
