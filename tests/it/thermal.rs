//! Thermal noise: the fluctuation-dissipation theorem per dissipative element against (1) the
//! textbook FDT identity `sum_e S_x,e = 4 k_B T |Im H_xx| / w`, (2) the closed form of a single
//! damped oscillator, (3) the torsion-band thermal floor of the 2-DoF model of section IV.C, (4)
//! the 1/f (structural) and white-force (viscous) shapes; and the budget terms in the HDF5 output
//! (total = sum of the independent terms).

use crate::common;
use crate::tolerances::{EPS, LU_GAMMA};

use common::{assert_fails, repo, tiltnoise};
use num_complex::Complex64;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::reference::ReferenceModel;
use tiltnoise_core::thermal::{conjugate_response, thermal_noise, BOLTZMANN_J_PER_K};
use tiltnoise_core::units::angular;

fn with(base: Params, sets: &[&str]) -> Params {
    sets.iter().fold(base, |p, s| {
        p.with_override(s).unwrap_or_else(|e| panic!("{s}: {e}"))
    })
}

fn damped_example() -> Params {
    tiltnoise_io::read_params(&repo("examples/damped.toml")).unwrap()
}

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo * (hi / lo).powf(k as f64 / (n - 1) as f64))
        .collect()
}

/// `sum_e S_x,e = 4 k_B T |Im H_xx| / w` (exact: `Im D^-1 = -D^-1 Im(D) D^-H`). The element sum
/// is a sum of non-negative terms; `Im H_xx` is the imaginary part of a direct solve, whose
/// error is `LU_GAMMA cond |H_xx|` (cond: the reference's condition number of the equilibrated
/// dynamic stiffness), i.e. `LU_GAMMA cond |H_xx| / |Im H_xx|` relative to it. Both sides
/// carry that error at most, hence the factor 2.
fn check_fdt_identity(params: &Params, label: &str) {
    let model = Model::new(params).unwrap();
    let reference = ReferenceModel::new(params);
    let outputs = [
        Observable::X,
        Observable::Phi,
        Observable::PhiA,
        Observable::Z,
    ];
    let mut freqs = log_grid(1e-4, 20.0, 41);
    freqs.extend(NormalModes::new(&model).frequencies_hz());
    let thermal = thermal_noise(&model, &outputs, &freqs).unwrap();
    let kt4 = 4.0 * BOLTZMANN_J_PER_K * params.environment.temperature_k;
    let mut worst = 0.0f64;
    for (o, &obs) in outputs.iter().enumerate() {
        let total = thermal.total_psd(o);
        for (k, &f) in freqs.iter().enumerate() {
            let h = conjugate_response(&model, obs, f).unwrap();
            let want = kt4 * h.im.abs() / angular(f);
            let cond = reference.condition_number(f).unwrap();
            let tol = 2.0 * LU_GAMMA * cond * h.norm() / h.im.abs();
            let rel = (total[k] - want).abs() / want;
            worst = worst.max(rel / tol);
            assert!(
                rel <= tol,
                "{label} {} at {f} Hz: sum {:e} vs 4kT|Im H|/w {want:e} (rel {rel:e} > {tol:e})",
                obs.name(),
                total[k]
            );
        }
    }
    println!("{label}: worst FDT-identity error / tolerance {worst:.2e}");
}

#[test]
fn element_sum_equals_the_textbook_fdt_structural() {
    check_fdt_identity(&damped_example(), "structural (examples/damped.toml)");
}

#[test]
fn element_sum_equals_the_textbook_fdt_viscous_and_mixed() {
    let p = with(
        damped_example(),
        &[
            "viscous.torsion_b_n_m_s_per_rad=1e-12",
            "viscous.swing_a_n_m_s_per_rad=1e-4",
            "viscous.bouncing_b_n_s_per_m=0.01",
        ],
    );
    check_fdt_identity(&p, "structural + viscous");
}

/// A single oscillator: only torsion_b lossy, and the crossbar's torsion pinned by a stiff upper
/// fibre (k_a = 1 N m/rad, 5.6e5 times Table I), so the test mass's absolute torsion phi is
/// the oscillator `I^b_33 phi'' + k_b (1 + i phi_l) phi = torque` with
/// `S_phi = 4 k_B T k phi_l / (w ((k - m w^2)^2 + k^2 phi_l^2))`, `m = I^b_33`, `k = k_b`.
/// What the pinned crossbar still does: it moves by `phi_a = w^2 I^b_33 phi_b / (k_a - w^2 M_aa)`,
/// which (a) is read by `phi = phi_a + phi_b`, a relative `r = w^2 I^b_33 / |k_a - w^2 M_aa|`
/// in amplitude, and (b) changes the oscillator's dynamic stiffness by
/// `dD = w^4 (I^b_33)^2 / (k_a - w^2 M_aa)`; the PSD changes by `2 (r + |dD| / |D|)` relative
/// (D the closed form's `k (1 + i phi_l) - m w^2`), plus the swing coupling through the crossbar
/// (second order, below that). The tolerance is four times that estimate plus the LU's
/// `LU_GAMMA cond` for both sides.
#[test]
fn single_oscillator_closed_form() {
    let p = with(
        Params::table_i(),
        &["torsion.k_a_n_m_per_rad=1.0", "loss.torsion_b_rad=1e-3"],
    );
    let model = Model::new(&p).unwrap();
    let reference = ReferenceModel::new(&p);
    let (m, k, phi_l) = (
        p.inertia.b33_kg_m2,
        p.torsion.k_b_n_m_per_rad,
        p.loss.torsion_b_rad,
    );
    let m_aa = model.mass()[(2, 2)];
    let f0 = (k / m).sqrt() / std::f64::consts::TAU;
    let mut freqs = log_grid(f0 / 100.0, f0 * 100.0, 41);
    freqs.push(f0);
    let thermal = thermal_noise(&model, &[Observable::Phi], &freqs).unwrap();
    assert_eq!(thermal.elements.len(), 1);
    assert_eq!(thermal.elements[0].name, "torsion_b");
    let kt4 = 4.0 * BOLTZMANN_J_PER_K * p.environment.temperature_k;
    let mut worst = 0.0f64;
    for (i, &f) in freqs.iter().enumerate() {
        let w = angular(f);
        let d = Complex64::new(k - m * w * w, k * phi_l);
        let want = kt4 * k * phi_l / (w * d.norm_sqr());
        let dd = w.powi(4) * m * m / (p.torsion.k_a_n_m_per_rad - w * w * m_aa).abs();
        let r = w * w * m / (p.torsion.k_a_n_m_per_rad - w * w * m_aa).abs();
        let tol = 4.0 * 2.0 * (r + dd / d.norm())
            + 2.0 * LU_GAMMA * reference.condition_number(f).unwrap();
        let got = thermal.elements[0].psd[0][i];
        let rel = (got - want).abs() / want;
        worst = worst.max(rel);
        assert!(
            rel <= tol,
            "at {f} Hz (f0 {f0}): {got:e} vs {want:e}, rel {rel:e} > {tol:e}"
        );
    }
    println!("single oscillator: worst relative difference {worst:.1e}");
}

/// The torsion-band thermal floor of phi from torsion_b loss against the 2-DoF model of section
/// IV.C in closed form (`M = [[I_c + I_t, I_t], [I_t, I_t]]`, `K = diag(k_a, k_b (1 + i phi))`,
/// `S_phi = 4 k_B T k_b phi / w |(D^-1)_{phi_a, phi_b} + (D^-1)_{phi_b, phi_b}|^2` with the 2x2
/// inverse by its adjugate). Tolerance: the 2-DoF model's own error against the full model,
/// `1.8 (f / f_swing)^2` in the response to a torque on the test mass (`src/tf/torsion2.rs`,
/// first-order coupling to the lowest swing mode of the block), doubled for a PSD and for a
/// safety factor of 2 on the geometric constant, at 0.2 .. 5 mHz away from 1 % of the torsion
/// modes (where the documented constant holds).
#[test]
fn torsion_band_floor_matches_the_two_dof_model() {
    let p = with(Params::table_i(), &["loss.torsion_b_rad=1e-3"]);
    let model = Model::new(&p).unwrap();
    let modes = NormalModes::new(&model);
    let (nu1, nu2) = (modes.modes[0].frequency_hz, modes.modes[1].frequency_hz);
    let f_swing = modes.modes[3].frequency_hz;
    let freqs: Vec<f64> = log_grid(2e-4, 5e-3, 60)
        .into_iter()
        .filter(|f| (f / nu1 - 1.0).abs() > 0.01 && (f / nu2 - 1.0).abs() > 0.01)
        .collect();
    let thermal = thermal_noise(&model, &[Observable::Phi], &freqs).unwrap();
    let (d, y_a) = (p.length.d_m, model.derived().y_a_m);
    let i_c = p.inertia.a33_kg_m2 + d * y_a * (p.mass.m_a_kg + p.mass.m_b_kg);
    let i_t = p.inertia.b33_kg_m2;
    let (k_a, k_b, phi_l) = (
        p.torsion.k_a_n_m_per_rad,
        p.torsion.k_b_n_m_per_rad,
        p.loss.torsion_b_rad,
    );
    let kt4 = 4.0 * BOLTZMANN_J_PER_K * p.environment.temperature_k;
    let mut worst = 0.0f64;
    for (i, &f) in freqs.iter().enumerate() {
        let w2 = angular(f).powi(2);
        let a = Complex64::from(k_a - w2 * (i_c + i_t));
        let b = Complex64::from(-w2 * i_t);
        let dd = Complex64::new(k_b - w2 * i_t, k_b * phi_l);
        let det = a * dd - b * b;
        // (D^-1)_{ab} = -b / det, (D^-1)_{bb} = a / det; phi = phi_a + phi_b.
        let h = (a - b) / det;
        let want = kt4 * k_b * phi_l / angular(f) * h.norm_sqr();
        let got = thermal.elements[0].psd[0][i];
        let tol = 2.0 * 2.0 * 1.8 * (f / f_swing).powi(2);
        let rel = (got - want).abs() / want;
        worst = worst.max(rel / tol);
        assert!(
            rel <= tol,
            "at {f} Hz: {got:e} vs 2-DoF {want:e}, rel {rel:e} > {tol:e}"
        );
    }
    println!("2-DoF torsion floor: worst difference / coupling bound {worst:.2e}");
}

/// Far below every mode the compliance is static, so structural thermal noise (force PSD
/// `4 k_B T Im(k) / w`) falls as 1/f and viscous (`4 k_B T c`) is flat. Corrections are of
/// relative order `(f / nu_1)^2` (the dynamic part of the compliance; nu_1 = 1.31 mHz),
/// `2 (f_hi / nu_1)^2` on a PSD ratio, tolerance twice that.
#[test]
fn structural_is_one_over_f_and_viscous_is_white_far_below_the_modes() {
    let (f_lo, f_hi): (f64, f64) = (1e-6, 1e-5);
    let nu1: f64 = 1.31e-3;
    let tol = 2.0 * 2.0 * (f_hi / nu1).powi(2);
    for (sets, exponent) in [
        (["loss.torsion_b_rad=1e-3"], -1.0),
        (["viscous.torsion_b_n_m_s_per_rad=1e-12"], 0.0),
    ] {
        let p = with(Params::table_i(), &sets);
        let model = Model::new(&p).unwrap();
        let t = thermal_noise(&model, &[Observable::Phi], &[f_lo, f_hi]).unwrap();
        let s = &t.elements[0].psd[0];
        let ratio = s[1] / s[0];
        let want = (f_hi / f_lo).powf(exponent);
        assert!(
            (ratio / want - 1.0).abs() <= tol,
            "{sets:?}: S(f_hi)/S(f_lo) = {ratio} vs {want} (tol {tol:e})"
        );
    }
}

#[test]
fn undamped_model_has_no_thermal_elements_and_dc_is_refused() {
    let model = Model::new(&Params::table_i()).unwrap();
    let t = thermal_noise(&model, &[Observable::X], &[1e-3]).unwrap();
    assert!(t.elements.is_empty());
    let damped = Model::new(&damped_example()).unwrap();
    let e = thermal_noise(&damped, &[Observable::X], &[0.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("> 0"), "{e}");
}

/// `tiltnoise budget` with the damped example on the Peterson spectra: the HDF5 carries
/// `thermal` and `thermal.<element>` for X, phi and phi_a, `thermal` is the sum of the elements
/// and `total` the sum of tilt, thermal and readout (independent terms; a sum of non-negative
/// numbers: a few ulps), and the `equivalent` group is `psd / |R|^2`. Undamped: no thermal term.
#[test]
fn budget_hdf5_carries_thermal_terms_that_add_up() {
    common::disable_hdf5_file_locking();
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("b.h5");
    let tilt = repo("tilt_data/peterson_tilt_asd.csv");
    let out = tiltnoise(&[
        "--params",
        repo("examples/damped.toml").to_str().unwrap(),
        "budget",
        "--tilt",
        tilt.to_str().unwrap(),
        "--save",
        h5.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("thermal"), "{stdout}");
    let file = hdf5::File::open(&h5).unwrap();
    let read = |path: &str| -> Vec<f64> { file.dataset(path).unwrap().read_raw().unwrap() };
    // Sums of at most 8 non-negative terms: 8 eps relative.
    let sum_tol = 8.0 * EPS;
    for o in ["X", "phi", "phi_a"] {
        let group = file.group(o).unwrap();
        let terms = common::strs_attr(&group, "terms");
        let elements: Vec<&String> = terms.iter().filter(|t| t.starts_with("thermal.")).collect();
        assert!(
            elements.iter().any(|t| *t == "thermal.torsion_b"),
            "{o}: {terms:?}"
        );
        let thermal = read(&format!("{o}/thermal/psd"));
        let tilt = read(&format!("{o}/tilt/psd"));
        let total = read(&format!("{o}/total/psd"));
        let readout = if terms.iter().any(|t| t == "readout") {
            read(&format!("{o}/readout/psd"))
        } else {
            vec![0.0; total.len()]
        };
        for k in 0..total.len() {
            let sum: f64 = elements
                .iter()
                .map(|e| read(&format!("{o}/{e}/psd"))[k])
                .sum();
            assert!(
                (sum - thermal[k]).abs() <= sum_tol * thermal[k],
                "{o} bin {k}"
            );
            let t = tilt[k] + thermal[k] + readout[k];
            assert!((t - total[k]).abs() <= sum_tol * total[k], "{o} bin {k}");
            assert!(thermal[k] > 0.0, "{o} bin {k}");
        }
        let eq_total = read(&format!("{o}/equivalent/total/psd"));
        let response = read(&format!("{o}/equivalent/response_abs"));
        for k in 0..total.len() {
            let want = total[k] / (response[k] * response[k]);
            // One division and one square of the stored |R|: a few ulps.
            assert!(
                (eq_total[k] - want).abs() <= 4.0 * EPS * want,
                "{o} bin {k}"
            );
        }
    }
    assert_eq!(
        common::str_attr(&file.group("X/equivalent").unwrap(), "unit"),
        "m s^-2"
    );
    // Undamped: no thermal term, and the summary says so.
    let h5u = dir.path().join("u.h5");
    let out = tiltnoise(&[
        "budget",
        "--tilt",
        tilt.to_str().unwrap(),
        "--save",
        h5u.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("thermal: none (undamped"));
    let file = hdf5::File::open(&h5u).unwrap();
    let terms = common::strs_attr(&file.group("X").unwrap(), "terms");
    assert!(terms.iter().all(|t| !t.starts_with("thermal")), "{terms:?}");
}

#[test]
fn negative_temperature_or_loss_exits_2() {
    let tilt = repo("tilt_data/peterson_tilt_asd.csv");
    assert_fails(
        &[
            "--set",
            "environment.temperature_k=-3",
            "budget",
            "--tilt",
            tilt.to_str().unwrap(),
        ],
        &["environment.temperature_k", "-3", "> 0"],
    );
    assert_fails(
        &[
            "--set",
            "loss.torsion_b_rad=-1e-4",
            "budget",
            "--tilt",
            tilt.to_str().unwrap(),
        ],
        &["loss.torsion_b_rad", "-0.0001", ">= 0"],
    );
}
