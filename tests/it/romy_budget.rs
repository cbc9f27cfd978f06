//! Real data through the whole time-series path: the two-axis ROMY tilt-rate record (LJN, LJE)
//! -> Welch CSD of the rates / (2 pi f)^2 (the angle's) -> transfer functions -> budget of X,
//! phi, phi_a, checked
//! against the independent reference of `scripts/reference/tilt_budget_reference.py` (SciPy for
//! the spectra, mpmath at 40 digits for the model, built from the paper, not from this crate).

use crate::common;
use crate::tolerances::{PEAK_FLOOR, PIPELINE_REL};

use common::{assert_close, floats, json, shared_tilt_data};
use tiltnoise_core::budget::{budget_from_series, BudgetOptions};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::params::Params;
use tiltnoise_io::input::{read_tilt_series, AxisMap, Quantity, ReadOptions};

/// The budget of the ROMY record, or `None` (with the line saying `test` was skipped) when the
/// record is not beside the repository.
fn romy_budget(test: &str) -> Option<tiltnoise_core::noise::BudgetReport> {
    let path = shared_tilt_data(
        test,
        "romy_6c_teleseism_20180123/ROMY_gulf_of_alaska_teleseism.csv",
    )?;
    let opts = ReadOptions {
        axis_map: Some(AxisMap::parse("theta_t=-LJE,eta_t=-LJN").unwrap()),
        quantity: Some(Quantity::Rate),
        ..ReadOptions::default()
    };
    let mut series = read_tilt_series(&path, &opts).unwrap();
    assert_eq!((series.len(), series.sample_rate_hz), (8192, 1.0));
    let model = Model::new(&Params::table_i()).unwrap();
    let budget_opts = BudgetOptions {
        welch_segment_len: Some(2048),
        ..BudgetOptions::default()
    };
    Some(budget_from_series(&model, &mut series, &budget_opts, &mut |_, _| {}).unwrap())
}

#[test]
fn romy_budget_matches_independent_reference() {
    let Some(report) = romy_budget("romy_budget_matches_independent_reference") else {
        return;
    };
    let reference = json("scripts/reference/romy_budget_reference.json");
    let b = &report.budget;
    let freqs = floats(&reference["freqs_hz"]);
    assert_eq!(b.freqs_hz.len(), freqs.len());
    for (k, (&got, &want)) in b.freqs_hz.iter().zip(&freqs).enumerate() {
        assert_eq!(got, want, "frequency bin {k}");
    }
    for o in [Observable::X, Observable::Phi, Observable::PhiA] {
        let ob = b.observable(o).unwrap();
        let r = &reference["outputs"][o.name()];
        for (term, key) in [
            ("tilt", &r["tilt_psd"]),
            ("tilt.theta_t", &r["per_axis_psd"]["theta_t"]),
            ("tilt.eta_t", &r["per_axis_psd"]["eta_t"]),
            ("total", &r["total_psd"]),
        ] {
            let want = floats(key);
            let got = match ob.term_named(term) {
                Some(t) => t.psd.clone(),
                None => ob.total(),
            };
            let peak = want.iter().cloned().fold(0.0, f64::max);
            for k in 0..want.len() {
                assert_close(
                    &format!("{}.{term} PSD", o.name()),
                    &format!("{} Hz", freqs[k]),
                    got[k],
                    want[k],
                    PIPELINE_REL,
                    PEAK_FLOOR * peak,
                );
            }
        }
    }
}

#[test]
fn romy_x_tilt_noise_is_the_lever_times_eta_t_below_the_torsion_modes() {
    // The quasi-static picture on real data: X = -eta_t (Z + Z_b + h_c), so their ASDs are in
    // the ratio 1.664 m/rad at 1 mHz, up to the f^2 approach (4e-5 relative at 0.5 mHz).
    let Some(report) =
        romy_budget("romy_x_tilt_noise_is_the_lever_times_eta_t_below_the_torsion_modes")
    else {
        return;
    };
    let x = report.budget.observable(Observable::X).unwrap();
    let (tilt, eta) = (
        &x.term_named("tilt").unwrap().psd,
        &x.term_named("tilt.eta_t").unwrap().psd,
    );
    let k = 1; // 0.488 mHz
    assert_eq!(
        tilt[k], eta[k],
        "X sees eta_t only (theta_t drives the other block)"
    );
    let reference = json("scripts/reference/romy_budget_reference.json");
    let s_eta = floats(&reference["csd"]["re"])[(k * 2 + 1) * 2 + 1];
    let ratio = (tilt[k] / s_eta).sqrt();
    assert!((ratio - 1.664).abs() < 1e-3, "|X|/|eta_t| = {ratio}");
}
