//! From measurement to asymmetry, end to end on synthetic data: the free motion of a pendulum
//! as built whose test mass's centre of mass sits 0.5 mm off along x (every mode excited with
//! the same energy, white readout noise on every channel), its mode visibilities measured from
//! the record ([`peaks::measure`]), and the fit of `asymmetry.tm_com_x_m` to them from the
//! symmetric nominal pendulum. Tested as an estimator: over several noise realisations the
//! pulls `(estimate - truth) / sigma` must look like draws of a unit normal (each within
//! [`PULL_MAX`], their mean and spread within what that many draws allow), and the fit's chi^2
//! like a chi^2 with its degrees of freedom. Run with `--nocapture` for the figures.

use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::fit::{self, peaks, FitConfig, Measured, Visibilities};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::uncertainty::{Distribution, Uncertainty};
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{equal_energy_init, simulate, SimConfig};

/// The offset to recover (m).
const TRUTH_M: f64 = 5e-4;

/// The prior error bar of the offset (m): the fit's box is `+/- 3` of it.
const PRIOR_SIGMA_M: f64 = 1e-3;

/// Noise realisations.
const REALISATIONS: u64 = 6;

/// A single pull beyond 4 has probability 6e-5 for a unit normal.
const PULL_MAX: f64 = 4.0;

/// The nominal pendulum the fit starts from: Table I, the offset free with its error bar.
fn nominal() -> Params {
    let mut p = Params::table_i();
    p.uncertainty.entries.push(Uncertainty {
        key: "asymmetry.tm_com_x_m".into(),
        rel_sigma: 0.0,
        abs_sigma: PRIOR_SIGMA_M,
        distribution: Distribution::Gaussian,
    });
    p
}

/// 12 h at 0.1 s (the paper's record), 1e-10 J in every mode, white readout noise of
/// 1e-9 m/sqrt(Hz) or rad/sqrt(Hz) on all seven channels.
fn record(seed: u64) -> (Vec<(Observable, Vec<f64>)>, f64) {
    let truth = nominal()
        .with_override(&format!("asymmetry.tm_com_x_m={TRUTH_M:e}"))
        .unwrap();
    let model = Model::new(&truth).unwrap();
    let init = equal_energy_init(&model, 1e-10);
    let cfg = SimConfig {
        readout_asd: Observable::ALL.iter().map(|&o| (o, 1e-9)).collect(),
        seed,
        ..SimConfig::default()
    };
    let sim = simulate(&model, &init, &cfg).unwrap();
    (sim.observables, 1.0 / cfg.dt_s)
}

#[test]
fn fitted_offset_from_measured_visibilities_has_unit_pulls() {
    let params = nominal();
    let modes = NormalModes::new(&Model::new(&params).unwrap());
    let expected: [f64; 8] = std::array::from_fn(|k| modes.modes[k].frequency_hz);
    let config = FitConfig {
        free: vec!["asymmetry.tm_com_x_m".into()],
        bound_sigmas: 3.0,
        ..FitConfig::default()
    };
    // The visibilities alone: the frequencies move by parts in 1e5 for 0.5 mm, far below
    // what they are measured to, and are even in the offset.
    let measured = Measured {
        modes: Vec::new(),
        origin: "none".into(),
    };
    let mut pulls = Vec::new();
    for seed in 0..REALISATIONS {
        let (channels, fs) = record(seed);
        let measuredvis =
            peaks::measure(&channels, fs, &expected, "synthetic", &Cancel::never()).unwrap();
        let vis: &Visibilities = &measuredvis.visibilities;
        // The forbidden channels of the symmetric model carry the offset: nu_6 in Z and the
        // torsion mode nu_2 in Y (there the stronger channel, so the reference) are among the
        // measured ratios.
        for (mode, o) in [(6, Observable::Z), (2, Observable::Y)] {
            assert!(
                vis.items
                    .iter()
                    .any(|v| v.mode == mode && (v.observable == o || v.reference == o)),
                "seed {seed}: nu_{mode} in {} not measured: {:?}",
                o.name(),
                measuredvis.skipped
            );
        }
        let result = fit::fit_with_visibilities(&params, &measured, vis, &config).unwrap();
        let p = &result.params[0];
        let sigma = p.fitted_sigma.expect("the estimate is inside the box");
        let pull = (p.fitted - TRUTH_M) / sigma;
        let dof = result.dof as f64;
        println!(
            "seed {seed}: tm_com_x_m = {:.6e} +/- {:.2e} m (truth {TRUTH_M:e}): pull {pull:+.2}; \
             chi^2 {:.1} for {} dof; {} visibilities, start {:e}; {} iterations, {}",
            p.fitted,
            sigma,
            result.chi2,
            result.dof,
            vis.items.len(),
            result.start[0],
            result.iterations,
            result.stop.describe()
        );
        assert!(pull.abs() <= PULL_MAX, "seed {seed}: pull {pull}");
        // chi^2 with `dof` degrees of freedom: mean dof, sd sqrt(2 dof); 5 sd either side.
        assert!(
            (result.chi2 - dof).abs() <= 5.0 * (2.0 * dof).sqrt(),
            "seed {seed}: chi^2 {} for {dof} dof: the measured sigmas are not the ratios' errors",
            result.chi2
        );
        // The offset is determined by the data, far better than by its error bar.
        assert!(sigma < 0.1 * PRIOR_SIGMA_M, "seed {seed}: sigma {sigma:e}");
        pulls.push(pull);
    }
    let n = pulls.len() as f64;
    let mean = pulls.iter().sum::<f64>() / n;
    let sd = (pulls.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    println!("pulls over {n} realisations: mean {mean:+.2}, sd {sd:.2}");
    // The mean of n unit normals has sd 1/sqrt(n): 4 of those. The sample sd of 6 draws lies
    // within 0.25..1.9 with probability above 0.99 (chi^2 with 5 dof: 0.41..17.7, over 5).
    assert!(mean.abs() <= 4.0 / n.sqrt(), "mean pull {mean}");
    assert!((0.25..=1.9).contains(&sd), "pull sd {sd}");
}

/// With no visibility, a fit of an offset along x to frequencies alone has no sign to find
/// (every frequency is even in the offset), and the fit from the symmetric point does not
/// stall there: it starts on both sides and reports where it ended.
#[test]
fn offset_fit_starts_away_from_the_symmetric_point() {
    let params = nominal();
    let config = FitConfig {
        free: vec!["asymmetry.tm_com_x_m".into()],
        bound_sigmas: 3.0,
        ..FitConfig::default()
    };
    let result = fit::fit(&params, &Measured::table_ii(), &config).unwrap();
    assert_ne!(result.start[0], 0.0);
    assert!(
        (result.start[0].abs() - fit::START_FRACTION * 3.0 * PRIOR_SIGMA_M).abs()
            <= 1e-15 * PRIOR_SIGMA_M
    );
}

/// The finiteness of a fit, one class: a fit of model-made visibilities gives only finite
/// numbers (`check_finite` passes); a derived number made non-finite (a sigma, a correlation
/// of parameters inside the box, chi^2) is refused naming it; and rows whose errors sit at the
/// ends of their range, one of them far off its model value, make a fit that ends (with finite
/// numbers or a refusal naming what is not finite), never one that loops.
#[test]
fn every_derived_number_of_a_fit_is_finite_or_refused_by_name() {
    use tiltnoise_core::fit::visibility::model_ratio;
    use tiltnoise_core::fit::{FitError, MeasuredVisibility, SigmaSource};
    use tiltnoise_core::limits::VISIBILITY_SIGMA_RANGE;
    let params = nominal();
    let truth = params
        .with_override(&format!("asymmetry.tm_com_x_m={TRUTH_M:e}"))
        .unwrap();
    let model = Model::new(&truth).unwrap();
    let modes = NormalModes::new(&model);
    let row = |mode, observable, reference, sigma: f64, off: f64| {
        let mut v = MeasuredVisibility {
            mode,
            observable,
            reference,
            ratio: 0.0,
            sigma,
            sigma_source: SigmaSource::File,
        };
        v.ratio = model_ratio(&modes, model.observation(), &v, &[]).unwrap().0 + off;
        v
    };
    let vis = |rows: Vec<MeasuredVisibility>| Visibilities {
        items: rows,
        origin: "synthetic".into(),
    };
    let measured = Measured {
        modes: Vec::new(),
        origin: "none".into(),
    };
    let config = FitConfig {
        free: vec!["asymmetry.tm_com_x_m".into()],
        bound_sigmas: 3.0,
        ..FitConfig::default()
    };
    let good = vis(vec![
        row(6, Observable::Z, Observable::X, 1e-6, 0.0),
        row(2, Observable::Y, Observable::X, 1e-6, 0.0),
    ]);
    let result = fit::fit_with_visibilities(&params, &measured, &good, &config).unwrap();
    fit::check_finite(&result).unwrap();
    assert!(result.params[0].fitted_sigma.unwrap().is_finite());
    let refused = |r: &fit::FitResult, needle: &str| match fit::check_finite(r) {
        Err(FitError::NotFinite { quantity, .. }) => {
            assert!(
                quantity.contains(needle),
                "{quantity} does not name {needle}"
            )
        }
        other => panic!("{needle}: not refused: {other:?}"),
    };
    let mut r = result.clone();
    r.params[0].fitted_sigma = Some(f64::INFINITY);
    refused(&r, "fitted sigma of asymmetry.tm_com_x_m");
    let mut r = result.clone();
    r.correlation[0][0] = f64::NAN;
    refused(&r, "correlation of asymmetry.tm_com_x_m");
    let mut r = result.clone();
    r.chi2 = f64::INFINITY;
    refused(&r, "chi^2");
    // The ends of the error's range, one row a 1e-4 off its model value.
    for sigma in [VISIBILITY_SIGMA_RANGE.0, VISIBILITY_SIGMA_RANGE.1] {
        let extreme = vis(vec![
            row(6, Observable::Z, Observable::X, sigma, 1e-4),
            row(2, Observable::Y, Observable::X, 1e-6, 0.0),
        ]);
        match fit::fit_with_visibilities(&params, &measured, &extreme, &config) {
            Ok(r) => fit::check_finite(&r).unwrap(),
            Err(FitError::NotFinite { quantity, .. }) => assert!(!quantity.is_empty()),
            Err(e) => panic!("sigma {sigma:e}: {e}"),
        }
    }
}
