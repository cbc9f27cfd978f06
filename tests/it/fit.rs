//! `tiltnoise fit`: the eigenvalue-derivative Jacobian against finite differences of the
//! frequencies, recovery of known parameters from synthetic frequencies (exact and noisy, with
//! the reported covariance checked against the scatter of an ensemble), the box bounds, the
//! refusals, and the embedded Table II example.

use crate::common;

use common::{assert_fails_without_output, tiltnoise};
use tiltnoise_core::fit::jacobian::{frequencies_and_jacobian, value_of, with_value};
use tiltnoise_core::fit::{fit, Bound, FitConfig, FitError, FitResult, Measured, MeasuredMode};
use tiltnoise_core::fit::{SigmaSource, DEFAULT_FREE};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::{refined_omega_sq, NormalModes};
use tiltnoise_core::params::Params;

/// Relative measurement error of the synthetic frequencies: the order of Table II's printed
/// digits (5e-7 Hz on 1.3 mHz is 4e-4; 5e-6 Hz on 0.588 Hz is 8.5e-6).
const SYNTH_REL_SIGMA: f64 = 1e-4;

/// Relative error of a mode frequency from `NormalModes` (the block eigensolver's error
/// `eps |K| / |M|` relative to the 1e-4 rad^2/s^2 torsion eigenvalues is 1e-11 in w^2, see
/// `modes::refined_omega_sq`), the floor of any synthetic-data residual.
const EIGEN_REL_ERR: f64 = 1e-11;

fn sigma_p(params: &Params, key: &str) -> f64 {
    let rel = tiltnoise_core::mc::uncertainties(params)
        .into_iter()
        .find(|u| u.key == key)
        .map_or(0.0, |u| u.rel_sigma);
    rel * value_of(params, key).unwrap().abs()
}

/// `params` with each `keys[j]` moved by `u[j]` error bars.
fn shifted(params: &Params, keys: &[&str], u: &[f64]) -> Params {
    keys.iter().zip(u).fold(params.clone(), |p, (k, &uj)| {
        let v = value_of(params, k).unwrap() + uj * sigma_p(params, k);
        with_value(&p, k, v).unwrap()
    })
}

/// Frequencies of `params` as measurements of relative error `SYNTH_REL_SIGMA`, plus `noise[k]`
/// sigmas on mode k.
fn synthetic(params: &Params, modes: &[usize], noise: &[f64]) -> Measured {
    let f = NormalModes::new(&Model::new(params).unwrap()).frequencies_hz();
    Measured {
        modes: modes
            .iter()
            .zip(noise)
            .map(|(&k, &z)| {
                let sigma_hz = SYNTH_REL_SIGMA * f[k - 1];
                MeasuredMode {
                    mode: k,
                    frequency_hz: f[k - 1] + z * sigma_hz,
                    sigma_hz,
                    sigma_source: SigmaSource::File,
                }
            })
            .collect(),
        origin: "synthetic".into(),
    }
}

fn config(keys: &[&str]) -> FitConfig {
    FitConfig {
        free: keys.iter().map(|k| k.to_string()).collect(),
        ..FitConfig::default()
    }
}

/// Scaled fitted value `(p - p0) / sigma_p` of every free parameter.
fn fitted_u(r: &FitResult) -> Vec<f64> {
    r.params
        .iter()
        .map(|p| (p.fitted - p.nominal) / p.prior_sigma)
        .collect()
}

const ALL_MODES: [usize; 8] = [1, 2, 3, 4, 5, 6, 7, 8];

/// Every parameter with an error bar, analytic `d f_k / d p` against central differences of
/// frequencies computed to working precision (Rayleigh-quotient refinement).
#[test]
fn eigenvalue_derivatives_match_finite_differences() {
    let p = Params::table_i();
    let keys: Vec<String> = tiltnoise_core::mc::uncertainties(&p)
        .into_iter()
        .filter(|u| u.rel_sigma > 0.0)
        .map(|u| u.key)
        .collect();
    assert!(keys.len() >= 17, "{keys:?}");
    let (freqs, jac) = frequencies_and_jacobian(&p, &keys).unwrap();
    let refined = |q: &Params| -> Vec<f64> {
        let model = Model::new(q).unwrap();
        let modes = NormalModes::new(&model);
        let mut f: Vec<f64> = modes
            .modes
            .iter()
            .map(|m| refined_omega_sq(&model, m).sqrt() / std::f64::consts::TAU)
            .collect();
        f.sort_by(f64::total_cmp);
        f
    };
    // Step eps^(1/3) |p|: truncation O(s^2) and rounding O(eps / s) of the central difference,
    // each ~ eps^(2/3) = 4e-11 in units of the natural scale f / |p| of the derivative; the
    // analytic side has the same matrix-difference error plus the shape error
    // eps |A| / gap ~ 3e-11 (torsion pair, gap 1.2e-4 rad^2/s^2 in a block of norm ~15). A
    // factor 100 over their sum covers the constants of the O(.) terms.
    const STEP_REL: f64 = 6.0554544523933395e-6;
    const TOL: f64 = 100.0 * (4e-11 + 4e-11 + 3e-11);
    let mut worst = 0.0_f64;
    for (j, key) in keys.iter().enumerate() {
        let v = value_of(&p, key).unwrap();
        let (lo, hi) = (v - STEP_REL * v.abs(), v + STEP_REL * v.abs());
        let f_lo = refined(&with_value(&p, key, lo).unwrap());
        let f_hi = refined(&with_value(&p, key, hi).unwrap());
        for k in 0..8 {
            let fd = (f_hi[k] - f_lo[k]) / (hi - lo);
            let scale = freqs[k] / v.abs();
            let err = (jac[(k, j)] - fd).abs() / scale;
            worst = worst.max(err);
            assert!(
                err <= TOL,
                "d nu_{}/d {key}: analytic {:e}, finite difference {fd:e} (error {err:e} of f/|p|, tol {TOL:e})",
                k + 1,
                jac[(k, j)]
            );
        }
    }
    eprintln!("worst Jacobian error, in units of f/|p|: {worst:e}");
}

/// Bound on |u - u_true| (in error bars) for a fit of exact synthetic data: at a stopping point
/// with projected gradient `pg` (not on a bound) `|g|_2 <= sqrt(n) pg` and `|u - u*| <= |g| /
/// s_min^2`; the eigensolver's rounding moves the minimizer u* by at most `|dr| / s_min` with
/// `|dr|_2 <= sqrt(m) EIGEN_REL_ERR / SYNTH_REL_SIGMA`. Factor 10: the Jacobian changes between
/// solution and truth (second-order terms) and the bounds' constants.
fn recovery_tol(r: &FitResult) -> f64 {
    let n = r.params.len() as f64;
    let m = r.modes.len() as f64;
    let s_min = *r.singular_values.last().unwrap();
    10.0 * (n.sqrt() * r.projected_gradient / s_min.powi(2)
        + m.sqrt() * EIGEN_REL_ERR / SYNTH_REL_SIGMA / s_min)
}

#[test]
fn recovers_known_parameters_from_exact_frequencies() {
    let p = Params::table_i();
    // Inside the default box (|u| <= 1), every parameter moved, signs mixed.
    let truth_u = [0.6, -0.4, 0.7, -0.5, 0.3, -0.8, 0.5, -0.2];
    let truth = shifted(&p, &DEFAULT_FREE, &truth_u);
    let measured = synthetic(&truth, &ALL_MODES, &[0.0; 8]);
    let r = fit(&p, &measured, &FitConfig::default()).unwrap();
    let tol = recovery_tol(&r);
    eprintln!(
        "exact recovery: chi2 {:e}, pg {:e}, s = {:?}, tol {tol:e} error bars, stop {:?}, {} iterations",
        r.chi2, r.projected_gradient, r.singular_values, r.stop, r.iterations
    );
    assert!(
        tol < 1e-3,
        "the default set must be well conditioned: tol {tol:e}"
    );
    for (got, (want, key)) in fitted_u(&r).iter().zip(truth_u.iter().zip(DEFAULT_FREE)) {
        assert!(
            (got - want).abs() <= tol,
            "{key}: fitted {got} error bars, truth {want} (tol {tol:e})"
        );
    }
    assert!(r.params.iter().all(|q| q.at_bound.is_none()));
    assert!(r.params.iter().all(|q| !q.poorly_constrained));
}

/// Noisy synthetic data: each fitted parameter within a few fitted sigmas of the truth, and
/// over an ensemble each parameter's normalized deviations `(p_fit - p_true) / sigma_fit` have
/// unit variance (the reported covariance describes the scatter).
#[test]
fn noisy_fits_scatter_as_the_reported_covariance() {
    let p = Params::table_i();
    // Well inside the box (fitted sigmas are <~ 0.1 error bar at this noise level), so that
    // noise never pushes a parameter onto a bound, where the linearization would not apply.
    let keys = DEFAULT_FREE;
    let truth_u = [0.3, -0.2, 0.2, -0.1, 0.1, -0.2, 0.2, -0.1];
    let truth = shifted(&p, &keys, &truth_u);
    let mut rng = tiltnoise_core::rng::Rng::stream(42, 0);
    const RUNS: usize = 400;
    let mut sum_z2 = [0.0; 8];
    let mut sum_chi2 = 0.0;
    for run in 0..RUNS {
        let noise: Vec<f64> = (0..8).map(|_| rng.gaussian()).collect();
        let r = fit(&p, &synthetic(&truth, &ALL_MODES, &noise), &config(&keys)).unwrap();
        sum_chi2 += r.chi2;
        for (j, (q, want)) in r.params.iter().zip(truth_u).enumerate() {
            assert!(q.at_bound.is_none(), "run {run}: {} on a bound", q.key);
            let sigma = q.fitted_sigma.unwrap();
            let z = (q.fitted - (q.nominal + want * q.prior_sigma)) / sigma;
            // 5.5 sigma: for 3200 Gaussian deviates P(any |z| > 5.5) < 1.3e-4.
            assert!(
                z.abs() < 5.5,
                "run {run}: {} off by {z} fitted sigmas",
                q.key
            );
            sum_z2[j] += z * z;
        }
    }
    // Per parameter, the runs are independent: sum z^2 is chi^2 with RUNS degrees of freedom,
    // mean RUNS and standard deviation sqrt(2 RUNS) = 28; 5 standard deviations (+/- 35 %)
    // when the linearized covariance is right.
    let n = RUNS as f64;
    let spread = 5.0 * (2.0 * n).sqrt();
    eprintln!(
        "sum z^2 per parameter over {RUNS} runs: {sum_z2:.1?} (allowed {n} +/- {spread:.1}); mean chi2 {:e}",
        sum_chi2 / n
    );
    for (key, s) in keys.iter().zip(sum_z2) {
        assert!(
            (s - n).abs() <= spread,
            "{key}: sum z^2 = {s}, want {n} +/- {spread}"
        );
    }
    // 8 parameters for 8 modes: exactly determined, so the fit matches the noisy data to
    // solver precision (chi^2 ~ (pg / s_min)^2, far below 1e-6).
    assert!(sum_chi2 / n < 1e-6, "mean chi2 {}", sum_chi2 / n);
}

#[test]
fn truth_outside_the_box_ends_on_the_bound_and_is_flagged() {
    let p = Params::table_i();
    let keys = [
        "torsion.k_a_n_m_per_rad",
        "torsion.k_b_n_m_per_rad",
        "bouncing.kappa_a_n_per_m",
        "bouncing.kappa_b_n_per_m",
    ];
    // k_b two error bars up: outside the 1-sigma box.
    let truth = shifted(&p, &keys, &[0.2, 2.0, -0.3, 0.1]);
    let r = fit(
        &p,
        &synthetic(&truth, &ALL_MODES, &[0.0; 8]),
        &config(&keys),
    )
    .unwrap();
    let kb = &r.params[1];
    assert_eq!(kb.at_bound, Some(Bound::Upper), "{kb:?}");
    assert_eq!(kb.fitted_sigma, None);
    let want = kb.nominal + kb.prior_sigma;
    // The box edge is computed as p0 + 1 * sigma_p: equal to a few ulps.
    assert!(
        (kb.fitted - want).abs() <= 4.0 * f64::EPSILON * want,
        "{} vs {want}",
        kb.fitted
    );
    assert!(
        r.chi2 > 1.0,
        "a parameter held off its truth leaves a misfit: chi2 {}",
        r.chi2
    );
    for q in &r.params[..1]
        .iter()
        .chain(&r.params[2..])
        .collect::<Vec<_>>()
    {
        assert!(q.at_bound.is_none() && q.fitted_sigma.is_some(), "{q:?}");
    }
    // Widened to 3 error bars the truth is inside again and is recovered.
    let wide = FitConfig {
        bound_sigmas: 3.0,
        ..config(&keys)
    };
    let r = fit(&p, &synthetic(&truth, &ALL_MODES, &[0.0; 8]), &wide).unwrap();
    let tol = recovery_tol(&r);
    assert!(
        (fitted_u(&r)[1] - 2.0).abs() <= tol,
        "{:?} tol {tol:e}",
        fitted_u(&r)
    );
}

#[test]
fn refusals_name_the_problem() {
    let p = Params::table_i();
    let three = synthetic(&p, &[1, 2, 7], &[0.0; 3]);
    let four = [
        "torsion.k_a_n_m_per_rad",
        "torsion.k_b_n_m_per_rad",
        "bouncing.kappa_a_n_per_m",
        "bouncing.kappa_b_n_per_m",
    ];
    match fit(&p, &three, &config(&four)) {
        Err(FitError::TooManyFree {
            free: 4,
            modes: 3,
            visibilities: 0,
        }) => {}
        other => panic!("{other:?}"),
    }
    let r = fit(&p, &three, &config(&four[..3])).unwrap();
    assert_eq!(r.dof, 0);
    for (keys, needle) in [
        (vec!["length.h_m"], "exact"),
        (vec!["mass.m_q_kg"], "unknown parameter key `mass.m_q_kg`"),
        (
            vec!["torsion.k_a_n_m_per_rad", "torsion.k_a_n_m_per_rad"],
            "torsion.k_a_n_m_per_rad is given twice",
        ),
        (vec![], "no free parameter"),
    ] {
        let e = fit(&p, &three, &config(&keys)).unwrap_err().to_string();
        assert!(e.contains(needle), "{keys:?}: {e}");
    }
    let e = fit(
        &p,
        &three,
        &FitConfig {
            bound_sigmas: 12.0,
            ..config(&["torsion.k_a_n_m_per_rad"])
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("non-physical") && e.contains("torsion.k_a_n_m_per_rad"),
        "{e}"
    );
}

#[test]
fn embedded_example_lowers_chi2() {
    let r = fit(
        &Params::table_i(),
        &Measured::table_ii(),
        &FitConfig::default(),
    )
    .unwrap();
    assert!(r.chi2 < r.chi2_nominal, "{} vs {}", r.chi2, r.chi2_nominal);
    assert_eq!(r.modes.len(), 8);
    // The torsion modes need +1.6 % (nu_1) and -4.0 % (nu_2); one error bar of k_a, k_b moves
    // them by 5 % (f ~ sqrt(k)), so both are reachable inside the box and must be matched.
    for m in &r.modes[..2] {
        assert!(m.residual_sigmas().abs() < 1.0, "{m:?}");
    }
    // With the prior the objective is chi^2 + sum u^2, which is chi2_nominal at the start.
    let with_prior = FitConfig {
        prior: true,
        ..FitConfig::default()
    };
    let rp = fit(&Params::table_i(), &Measured::table_ii(), &with_prior).unwrap();
    assert!(rp.prior_term > 0.0 && rp.chi2 + rp.prior_term < rp.chi2_nominal);
    assert_eq!(rp.dof, 8);
    for m in &r.modes {
        eprintln!(
            "nu_{}: measured {:e} Hz, nominal {:e}, fitted {:e} ({:+.1} sigma)",
            m.measured.mode,
            m.measured.frequency_hz,
            m.nominal_hz,
            m.fitted_hz,
            m.residual_sigmas()
        );
    }
    for q in &r.params {
        eprintln!(
            "{}: {:e} -> {:e} +/- {:?} (prior {:e}) bound {:?} poor {}",
            q.key,
            q.nominal,
            q.fitted,
            q.fitted_sigma,
            q.prior_sigma,
            q.at_bound,
            q.poorly_constrained
        );
    }
}

#[test]
fn cli_table_json_and_saved_files() {
    let dir = tempfile::tempdir().unwrap();
    let json_path = dir.path().join("fit.json");
    let h5_path = dir.path().join("fit.h5");
    let out = tiltnoise(&[
        "fit",
        "--format",
        "json",
        "--save",
        json_path.to_str().unwrap(),
        "--save",
        h5_path.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", common::stderr(&out));
    let stdout = String::from_utf8(out.stdout).unwrap();
    let json_start = stdout.find('{').unwrap();
    let json_end = stdout.rfind('}').unwrap();
    let v: serde_json::Value = serde_json::from_str(&stdout[json_start..=json_end]).unwrap();
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    assert_eq!(v, saved);
    assert_eq!(v["modes"].as_array().unwrap().len(), 8);
    assert_eq!(
        v["parameters"].as_array().unwrap().len(),
        DEFAULT_FREE.len()
    );
    assert!(v["chi2"].as_f64().unwrap() < v["chi2_nominal"].as_f64().unwrap());
    let file = hdf5::File::open(&h5_path).unwrap();
    let fitted: Vec<f64> = file.dataset("modes/fitted_hz").unwrap().read_raw().unwrap();
    for (k, f) in fitted.iter().enumerate() {
        assert_eq!(*f, v["modes"][k]["fitted_hz"].as_f64().unwrap());
    }
    let table = tiltnoise(&["fit"]);
    let text = String::from_utf8(table.stdout).unwrap();
    assert!(
        text.contains("nu_8") && text.contains("torsion.k_b_n_m_per_rad"),
        "{text}"
    );
}

#[test]
fn cli_bad_input_exits_2_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fit.json");
    let out_s = out.to_str().unwrap();
    let file = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let three = file(
        "three.csv",
        "mode,frequency_hz\n1,0.001331\n2,0.002117\n7,7.926\n",
    );
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec!["--measured-modes".into(), three.clone(), "--free".into(),
                 "torsion.k_a_n_m_per_rad,torsion.k_b_n_m_per_rad,bouncing.kappa_a_n_per_m,bouncing.kappa_b_n_per_m".into()],
            vec!["4 free parameters", "3 measured modes"],
        ),
        (vec!["--measured-modes".into(), three.clone()], vec!["8 free parameters", "3 measured modes"]),
        (vec!["--free".into(), "length.hh_m".into()], vec!["`length.hh_m`", "allowed keys"]),
        (vec!["--free".into(), "environment.g_m_per_s2".into()], vec!["`environment.g_m_per_s2`", "exact"]),
        (vec!["--free".into(), "mass.m_a_kg,mass.m_a_kg".into()], vec!["--free: mass.m_a_kg is given twice"]),
        (vec!["--bound-sigmas".into(), "0".into()], vec!["--bound-sigmas 0", "> 0"]),
        (vec!["--measured-modes".into(), file("neg.csv", "mode,frequency_hz\n1,-0.001\n")], vec!["neg.csv", "`-0.001`", ">= 1e-9 Hz"]),
        (vec!["--measured-modes".into(), file("nan.csv", "mode,frequency_hz\n1,NaN\n")], vec!["nan.csv", "`NaN`", "finite"]),
        (vec!["--measured-modes".into(), file("nine.csv", "mode,frequency_hz\n9,1.0\n")], vec!["nine.csv", "mode `9`", "1..8"]),
        (vec!["--measured-modes".into(), file("dup.csv", "mode,frequency_hz\n2,1.0\n2,1.1\n")], vec!["dup.csv", "mode 2", "twice"]),
        (vec!["--measured-modes".into(), file("bad.csv", "freq\n1\n")], vec!["bad.csv", "header"]),
        (vec!["--measured-modes".into(), dir.path().join("missing.csv").to_str().unwrap().into()], vec!["missing.csv"]),
    ];
    for (extra, needles) in cases {
        let mut args: Vec<&str> = vec!["fit", "--save", out_s];
        args.extend(extra.iter().map(String::as_str));
        assert_fails_without_output(&args, dir.path(), &needles);
    }
    assert!(!out.exists());
}
