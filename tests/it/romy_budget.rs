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

/// Half a unit in the last of the 10 significant digits the ROMY CSV export prints: the most
/// its values can differ from the float64 samples of the miniSEED file they were printed from.
fn csv_print_bound(printed: f64) -> f64 {
    if printed == 0.0 {
        return 0.0;
    }
    let exponent = printed.abs().log10().floor();
    0.5 * 10f64.powf(exponent - 9.0)
}

#[test]
fn romy_miniseed_gives_the_budget_of_its_csv_export() {
    // The verbatim miniSEED file beside the CSV export: channels chosen by SEED code, the
    // quantity (rate) from the instrument code J, FLOAT64 samples taken as rad/s.
    let test = "romy_miniseed_gives_the_budget_of_its_csv_export";
    let Some(mseed) = shared_tilt_data(
        test,
        "romy_6c_teleseism_20180123/ROMY_gulf_of_alaska_teleseism.mseed",
    ) else {
        return;
    };
    let csv = mseed.with_extension("csv");
    let map = AxisMap::parse("theta_t=-LJE,eta_t=-LJN").unwrap();
    let from_mseed = read_tilt_series(
        &mseed,
        &ReadOptions {
            axis_map: Some(map.clone()),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    let from_csv = read_tilt_series(
        &csv,
        &ReadOptions {
            axis_map: Some(map),
            quantity: Some(Quantity::Rate),
            ..ReadOptions::default()
        },
    )
    .unwrap();
    let p = &from_mseed.provenance;
    assert_eq!(p.quantity, Quantity::Rate);
    assert_eq!(p.start_time.as_deref(), Some("2018-01-23T09:31:42.000000Z"));
    assert_eq!(p.axis_map, "theta_t=-BW.ROMY.11.LJE,eta_t=-BW.ROMY.11.LJN");
    assert_eq!(
        (
            from_mseed.len(),
            from_mseed.sample_rate_hz,
            &from_mseed.axes
        ),
        (from_csv.len(), from_csv.sample_rate_hz, &from_csv.axes)
    );

    budgets_agree(
        &from_mseed,
        &from_csv,
        &["tilt", "tilt.theta_t", "tilt.eta_t"],
    );
}

/// The six channels of the miniSEED (rotation rates and accelerations, `--units` for each, as
/// miniSEED states none) give the six-component budget of the CSV export, `tilt`,
/// `translation` and `ground` alike.
#[test]
fn romy_six_component_miniseed_gives_the_budget_of_its_csv_export() {
    let test = "romy_six_component_miniseed_gives_the_budget_of_its_csv_export";
    let Some(mseed) = shared_tilt_data(
        test,
        "romy_6c_teleseism_20180123/ROMY_gulf_of_alaska_teleseism.mseed",
    ) else {
        return;
    };
    let units: Vec<_> = ["LJE=rad/s", "LJN=rad/s", "LJZ=rad/s"]
        .into_iter()
        .chain(["LHE=m/s^2", "LHN=m/s^2", "LHZ=m/s^2"])
        .map(|u| u.parse().unwrap())
        .collect();
    let read = |path: &std::path::Path| {
        read_tilt_series(
            path,
            &ReadOptions {
                units: units.clone(),
                ..ReadOptions::default()
            },
        )
        .unwrap()
    };
    let (from_mseed, from_csv) = (read(&mseed), read(&mseed.with_extension("csv")));
    assert_eq!(
        from_mseed.provenance.axis_map,
        "theta_t=-BW.ROMY.11.LJE,eta_t=-BW.ROMY.11.LJN,phi_t=-BW.ROMY.11.LJZ,\
         x_t=BW.ROMY.11.LHE,y_t=BW.ROMY.11.LHN,z_t=BW.ROMY.11.LHZ"
    );
    assert_eq!(from_mseed.translations.len(), 3);
    budgets_agree(
        &from_mseed,
        &from_csv,
        &["ground", "tilt", "translation", "translation.x_t"],
    );
}

/// The series of `from_mseed` and `from_csv` agree sample by sample within the CSV's printed
/// precision, and so do the `terms` of their budgets, within what that difference can make.
fn budgets_agree(
    from_mseed: &tiltnoise_io::input::TiltSeries,
    from_csv: &tiltnoise_io::input::TiltSeries,
    terms: &[&str],
) {
    let mut difference = from_mseed.clone();
    let mut differences: Vec<Vec<f64>> = Vec::new();
    for (a, (m, c)) in from_mseed
        .channel_data()
        .iter()
        .zip(from_csv.channel_data())
        .enumerate()
    {
        assert_eq!(m.len(), c.len());
        let mut d = Vec::with_capacity(m.len());
        for (k, (&x, &y)) in m.iter().zip(c.iter()).enumerate() {
            assert!(
                (x - y).abs() <= csv_print_bound(y),
                "channel {a}, sample {k}: miniSEED {x:e}, CSV {y:e}"
            );
            d.push(x - y);
        }
        differences.push(d);
    }
    let n_tilt = difference.data.len();
    for (slot, d) in difference
        .data
        .iter_mut()
        .chain(difference.translations.iter_mut().map(|t| &mut t.data))
        .zip(differences)
    {
        *slot = d;
    }
    assert_eq!(n_tilt, from_csv.axes.len());
    // The budget terms are quadratic forms of the (linear) Welch transforms of the samples, so
    // with d = miniSEED - CSV, |P(csv + d) - P(csv)| <= 2 sqrt(P(csv) P(d)) + P(d) bin by bin
    // (Cauchy-Schwarz over the segments), plus the pipeline's own rounding (PEAK_FLOOR).
    let model = Model::new(&Params::table_i()).unwrap();
    let budget_opts = BudgetOptions {
        welch_segment_len: Some(2048),
        ..BudgetOptions::default()
    };
    let budget = |s: &mut tiltnoise_io::input::TiltSeries| {
        budget_from_series(&model, s, &budget_opts, &mut |_, _| {})
            .unwrap()
            .budget
    };
    let (mut m, mut c) = (from_mseed.clone(), from_csv.clone());
    let (bm, bc, bd) = (budget(&mut m), budget(&mut c), budget(&mut difference));
    assert_eq!(bm.freqs_hz, bc.freqs_hz);
    for o in [Observable::X, Observable::Phi, Observable::PhiA] {
        let (om, oc, od) = (
            bm.observable(o).unwrap(),
            bc.observable(o).unwrap(),
            bd.observable(o).unwrap(),
        );
        for &term in terms {
            let (pm, pc, pd) = (
                &om.term_named(term).unwrap().psd,
                &oc.term_named(term).unwrap().psd,
                &od.term_named(term).unwrap().psd,
            );
            let peak = pc.iter().cloned().fold(0.0, f64::max);
            let mut worst_rel: f64 = 0.0;
            for k in 0..pc.len() {
                let bound = 2.0 * (pc[k] * pd[k]).sqrt() + pd[k] + PEAK_FLOOR * peak;
                let diff = (pm[k] - pc[k]).abs();
                assert!(
                    diff <= bound,
                    "{}.{term} at {} Hz: miniSEED {:e}, CSV {:e}, bound {bound:e}",
                    o.name(),
                    bc.freqs_hz[k],
                    pm[k],
                    pc[k]
                );
                if pc[k] > 0.0 {
                    worst_rel = worst_rel.max(diff / pc[k]);
                }
            }
            println!(
                "ROMY miniSEED vs CSV: {}.{term} PSD, largest relative difference {worst_rel:.2e} \
                 over {} bins",
                o.name(),
                pc.len()
            );
        }
    }
}
