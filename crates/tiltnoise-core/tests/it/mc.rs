//! Monte Carlo of the normal modes: reproducibility across thread counts, the zero-sigma limit,
//! first-order error propagation, Table II's calculated column, refusals and speed.

use tiltnoise_core::mc::{
    default_uncertainties, run, Distribution, McConfig, McError, McResult, Uncertainty,
};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;

/// Table II of the paper, "calculated" column: (value, +/- error) in Hz. Paper data, not output of
/// this code.
const TABLE_II_CALCULATED_HZ: [(f64, f64); 8] = [
    (1.3e-3, 0.1e-3),
    (2.2e-3, 0.2e-3),
    (0.41, 0.01),
    (0.42, 0.01),
    (0.59, 0.01),
    (0.62, 0.01),
    (8.05, 0.6),
    (10.9, 0.8),
];

fn no_progress(_: usize) {}

fn cfg(samples: usize, seed: u64, threads: usize, uncertainties: Vec<Uncertainty>) -> McConfig {
    McConfig {
        samples,
        seed,
        threads,
        uncertainties,
        cancel: tiltnoise_core::cancel::Cancel::never(),
    }
}

fn run_ok(p: &Params, c: &McConfig) -> McResult {
    run(p, c, &no_progress).unwrap()
}

/// The nominal modes in the Monte Carlo's own arithmetic: the f64 eigensolver per block,
/// without the double-double refinement of `NormalModes::new` (which moves nu_1 by ~7e-12).
fn nominal_hz(p: &Params) -> Vec<f64> {
    NormalModes::new_f64(&Model::new(p).unwrap()).frequencies_hz()
}

#[test]
fn same_seed_is_bit_identical_across_thread_counts() {
    let p = Params::table_i();
    let u = default_uncertainties(&p);
    let one = run_ok(&p, &cfg(1001, 42, 1, u.clone()));
    for threads in [2, 3, 8] {
        let many = run_ok(&p, &cfg(1001, 42, threads, u.clone()));
        assert_eq!(one, many, "threads = {threads}");
        for k in 0..8 {
            assert_eq!(one.mean_hz[k].to_bits(), many.mean_hz[k].to_bits());
            assert_eq!(one.std_hz[k].to_bits(), many.std_hz[k].to_bits());
        }
    }
    let other = run_ok(&p, &cfg(1001, 43, 2, u));
    assert_ne!(one.freqs_hz, other.freqs_hz);
    assert!((0..8).all(|k| one.mean_hz[k] != other.mean_hz[k]));
    assert_eq!(one.samples, 1001);
    assert_eq!(one.freqs_hz.len() + one.rejected, 1001);
}

#[test]
fn progress_reaches_the_sample_count() {
    let p = Params::table_i();
    let last = std::sync::atomic::AtomicUsize::new(0);
    let progress = |k: usize| {
        last.fetch_max(k, std::sync::atomic::Ordering::Relaxed);
    };
    run(&p, &cfg(1000, 1, 2, default_uncertainties(&p)), &progress).unwrap();
    assert_eq!(last.into_inner(), 1000);
}

#[test]
fn zero_sigma_gives_the_nominal_modes_exactly() {
    let p = Params::table_i();
    let mut u = default_uncertainties(&p);
    for x in &mut u {
        x.rel_sigma = 0.0;
    }
    let r = run_ok(&p, &cfg(500, 7, 2, u));
    assert_eq!(r.rejected, 0);
    let nominal = nominal_hz(&p);
    for (k, &nu) in nominal.iter().enumerate() {
        assert_eq!(r.mean_hz[k], nu, "nu_{}", k + 1);
        assert_eq!(r.std_hz[k], 0.0, "nu_{}", k + 1);
    }
}

#[test]
fn small_sigma_std_matches_first_order_propagation() {
    const REL_SIGMA: f64 = 1e-3;
    const N: usize = 4000;
    // Central-difference step (relative): truncation ~h^2, rounding ~1e-11 / h relative.
    const H: f64 = 1e-5;
    let p = Params::table_i();
    let mut u = default_uncertainties(&p);
    // The parameters with a default error (the others include the dilution factors, which
    // cannot go below 1: no central difference there).
    u.retain(|x| x.rel_sigma > 0.0);
    for x in &mut u {
        x.rel_sigma = REL_SIGMA;
    }
    // Mix the two distributions: both have standard deviation rel_sigma.
    for x in u.iter_mut().step_by(3) {
        x.distribution = Distribution::Uniform;
    }
    let r = run_ok(&p, &cfg(N, 2024, 2, u.clone()));
    assert_eq!(r.rejected, 0);
    let mut var = [0.0; 8];
    for x in &u {
        let value = p.fields().iter().find(|f| f.key == x.key).unwrap().value;
        let at = |v: f64| nominal_hz(&p.with_override(&format!("{}={v:?}", x.key)).unwrap());
        let (up, down) = (at(value * (1.0 + H)), at(value * (1.0 - H)));
        for k in 0..8 {
            let d = (up[k] - down[k]) / (2.0 * H) * x.rel_sigma;
            var[k] += d * d;
        }
    }
    let rel_se = 1.0 / (2.0 * (N as f64 - 1.0)).sqrt();
    println!("first-order vs Monte Carlo std, rel sigma {REL_SIGMA}, N = {N}:");
    for (k, v) in var.iter().enumerate() {
        let lin = v.sqrt();
        let ratio = r.std_hz[k] / lin;
        println!(
            "  nu_{}: linear {lin:.4e} Hz, MC {:.4e} Hz, ratio {ratio:.4} (5 s.e. = {:.4})",
            k + 1,
            r.std_hz[k],
            5.0 * rel_se
        );
        assert!(
            (ratio - 1.0).abs() <= 5.0 * rel_se,
            "nu_{}: MC std {} vs first order {}",
            k + 1,
            r.std_hz[k],
            lin
        );
    }
}

#[test]
fn default_config_matches_table_ii_calculated_column() {
    let p = Params::table_i();
    let c = McConfig::default_for(&p);
    assert_eq!(c.samples, 10_000);
    let r = run_ok(&p, &c);
    let nominal = nominal_hz(&p);
    println!(
        "default Monte Carlo: {} samples, {} rejected",
        r.samples, r.rejected
    );
    println!("mode   nominal (Hz)    MC mean (Hz)    MC std (Hz)     Table II calculated (Hz)");
    for k in 0..8 {
        let (v, e) = TABLE_II_CALCULATED_HZ[k];
        println!(
            "nu_{}   {:<14.5e}  {:<14.5e}  {:<14.3e}  {v} +/- {e}",
            k + 1,
            nominal[k],
            r.mean_hz[k],
            r.std_hz[k]
        );
    }
    for (k, &(v, e)) in TABLE_II_CALCULATED_HZ.iter().enumerate() {
        assert!(
            (r.mean_hz[k] - v).abs() <= e,
            "nu_{}: MC mean {} Hz outside Table II {} +/- {}",
            k + 1,
            r.mean_hz[k],
            v,
            e
        );
        assert!(r.std_hz[k] > 0.0 && r.std_hz[k].is_finite());
    }
    let expected_keys = [
        ("mass.m_a_kg", 0.025),
        ("inertia.a23_kg_m2", 0.025),
        ("length.z_b_m", 0.025),
        ("torsion.k_b_n_m_per_rad", 0.10),
        ("bouncing.kappa_a_n_per_m", 0.10),
    ];
    for (key, s) in expected_keys {
        let u = c.uncertainties.iter().find(|u| u.key == key).unwrap();
        assert_eq!((u.rel_sigma, u.distribution), (s, Distribution::Gaussian));
    }
    for key in ["length.h_m", "environment.g_m_per_s2", "loss.torsion_a_rad"] {
        let u = c.uncertainties.iter().find(|u| u.key == key).unwrap();
        assert_eq!(u.rel_sigma, 0.0, "{key}");
    }
    // One entry per parameter, in file order; 18 of them drawn (2 masses, 7 inertias, 2 torsion
    // and 2 bouncing constants, 5 lengths).
    let keys: Vec<String> = p.fields().iter().map(|f| f.key.to_string()).collect();
    let listed: Vec<String> = c.uncertainties.iter().map(|u| u.key.clone()).collect();
    assert_eq!(listed, keys);
    assert_eq!(
        c.uncertainties.iter().filter(|u| u.rel_sigma > 0.0).count(),
        18
    );
}

#[test]
fn refuses_zero_samples_and_too_large_sigma() {
    let p = Params::table_i();
    let e = run(&p, &cfg(0, 1, 1, default_uncertainties(&p)), &no_progress).unwrap_err();
    assert!(matches!(e, McError::NoSamples));
    assert!(e.to_string().contains("samples = 0"), "{e}");

    // Gaussian: 4 sigma must stay below 100 %; uniform: sqrt(3) sigma must.
    for (dist, sigma, limit) in [
        (Distribution::Gaussian, 0.25, "< 0.2500"),
        (Distribution::Uniform, 0.58, "< 0.5774"),
    ] {
        let mut u = default_uncertainties(&p);
        let x = u
            .iter_mut()
            .find(|u| u.key == "torsion.k_b_n_m_per_rad")
            .unwrap();
        x.rel_sigma = sigma;
        x.distribution = dist;
        let e = run(&p, &cfg(10, 1, 1, u), &no_progress)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("torsion.k_b_n_m_per_rad")
                && e.contains(&format!("= {sigma}"))
                && e.contains(limit),
            "{e}"
        );
        println!("{e}");
    }
    // Just below the limits runs.
    for (dist, sigma) in [
        (Distribution::Gaussian, 0.249),
        (Distribution::Uniform, 0.577),
    ] {
        let mut u = default_uncertainties(&p);
        u[0].rel_sigma = sigma;
        u[0].distribution = dist;
        assert!(run(&p, &cfg(10, 1, 1, u), &no_progress).is_ok());
    }

    let bad = |key: &str, s: f64| {
        let u = vec![Uncertainty {
            key: key.into(),
            rel_sigma: s,
            abs_sigma: 0.0,
            distribution: Distribution::Gaussian,
        }];
        run(&p, &cfg(10, 1, 1, u), &no_progress)
            .unwrap_err()
            .to_string()
    };
    let e = bad("mass.m_c_kg", 0.01);
    assert!(e.contains("m_c_kg") && e.contains("mass.m_a_kg"), "{e}");
    let e = bad("mass.m_a_kg", -0.01);
    assert!(e.contains("mass.m_a_kg") && e.contains(">= 0"), "{e}");
    let e = bad("mass.m_a_kg", f64::NAN);
    assert!(e.contains("mass.m_a_kg"), "{e}");
    let mut u = default_uncertainties(&p);
    u.push(u[0].clone());
    let e = run(&p, &cfg(10, 1, 1, u), &no_progress)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("mass.m_a_kg") && e.contains("more than one"),
        "{e}"
    );
}

#[test]
fn non_physical_draws_are_rejected_and_counted() {
    // |I^a_23| close to sqrt(I22 I33): a 20 % error on it makes the crossbar tensor indefinite in
    // a fraction of the draws; they are rejected, the rest are kept.
    let p = Params::table_i();
    let limit = (p.inertia.a22_kg_m2 * p.inertia.a33_kg_m2).sqrt();
    let p = p
        .with_override(&format!("inertia.a23_kg_m2={:?}", -0.9 * limit))
        .unwrap();
    let u = vec![Uncertainty {
        key: "inertia.a23_kg_m2".into(),
        rel_sigma: 0.2,
        abs_sigma: 0.0,
        distribution: Distribution::Gaussian,
    }];
    let r = run_ok(&p, &cfg(2000, 5, 2, u));
    // P(1 + 0.2 z > 1/0.9) = P(z > 0.556) = 0.289.
    let frac = r.rejected as f64 / 2000.0;
    println!(
        "rejected {} of 2000 ({frac:.3}, expected 0.289)",
        r.rejected
    );
    assert!((frac - 0.289).abs() < 0.05, "{frac}");
    assert_eq!(r.freqs_hz.len(), 2000 - r.rejected);
}
