//! Published noise models through the spectra input path: the GSN horizontal low-noise model
//! (Berger et al. 2004) and Peterson's NHNM, converted to tilt-equivalent ASD (a / g), read as
//! tilt spectra, interpolated log-log, and propagated to X. Expected levels come from
//! `scripts/reference/noise_model_levels.py` (NumPy, independent of this crate).

use crate::common;
use crate::tolerances::LOGLOG_REL;

use common::{assert_close, floats, json, shared_tilt_data};
use tiltnoise_core::budget::{budget_from_spectra, BudgetOptions};
use tiltnoise_core::model::{Model, Observable, TiltAxis};
use tiltnoise_core::noise::Readout;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::{plan, Input, Method, Request};
use tiltnoise_io::input::{read_tilt_spectra, ReadOptions};

/// Writes a tiltnoise spectra CSV (same ASD on both axes, uncorrelated).
fn write_spectra_csv(dir: &std::path::Path, rows: &[(f64, f64)]) -> std::path::PathBuf {
    let mut rows = rows.to_vec();
    rows.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut text = String::from("freq_hz,theta_t,eta_t\n");
    for (f, asd) in rows {
        text.push_str(&format!("{f:e},{asd:e},{asd:e}\n"));
    }
    let path = dir.join("model.csv");
    std::fs::write(&path, text).unwrap();
    path
}

fn check_model(rows: &[(f64, f64)], expected_key: &str) {
    let levels = json("scripts/reference/noise_model_levels.json");
    let freqs = floats(&levels["freqs_hz"]);
    let expected = floats(&levels["models"][expected_key]["tilt_asd_rad_per_rthz"]);
    let dir = tempfile::tempdir().unwrap();
    let path = write_spectra_csv(dir.path(), rows);
    let spectra = read_tilt_spectra(&path, &ReadOptions::default()).unwrap();
    let (grid, on_grid) = spectra.interpolate_loglog(&freqs);
    assert_eq!(
        grid, freqs,
        "all four frequencies lie inside the model's band"
    );
    for (k, (&f, &want)) in freqs.iter().zip(&expected).enumerate() {
        let eta = TiltAxis::EtaT.index().min(on_grid.axes.len() - 1);
        let n = on_grid.axes.len();
        let psd = on_grid.csd[(k * n + eta) * n + eta].re;
        assert_close(
            expected_key,
            &format!("{f} Hz"),
            psd.sqrt(),
            want,
            LOGLOG_REL,
            0.0,
        );
    }
    // Propagated to X: |X| = |H_X,eta_t| |eta_t| (X does not see theta_t).
    let model = Model::new(&Params::table_i()).unwrap();
    let opts = BudgetOptions {
        spectra_grid_hz: freqs.clone(),
        readout: Readout::none(),
        ..BudgetOptions::default()
    };
    let report = budget_from_spectra(&model, &spectra, &opts).unwrap();
    let x = report.budget.observable(Observable::X).unwrap();
    let tf = plan(
        &model,
        &Request {
            outputs: vec![Observable::X],
            inputs: vec![Input::Tilt(TiltAxis::EtaT)],
        },
        Method::Direct,
    )
    .unwrap();
    for (k, (&f, &level)) in freqs.iter().zip(&expected).enumerate() {
        let h = tf.eval(f).unwrap()[0].norm();
        assert_close(
            &format!("X tilt ASD from {expected_key}"),
            &format!("{f} Hz"),
            x.total()[k].sqrt(),
            h * level,
            2.0 * LOGLOG_REL,
            0.0,
        );
    }
}

#[test]
fn gsn_horizontal_low_noise_model_levels() {
    let g = 9.80665;
    let Some(path) = shared_tilt_data(
        "gsn_horizontal_low_noise_model_levels",
        "brotzer2023_rlnm/GSN_noise_model.csv",
    ) else {
        return;
    };
    let text = std::fs::read_to_string(path).unwrap();
    let rows: Vec<(f64, f64)> = text
        .lines()
        .skip(1)
        .map(|line| {
            let cols: Vec<f64> = line.split(',').map(|c| c.trim().parse().unwrap()).collect();
            (1.0 / cols[0], 10f64.powf(cols[1] / 10.0).sqrt() / g)
        })
        .collect();
    check_model(&rows, "gsn_min_h");
}

#[test]
fn peterson_nhnm_levels() {
    let g = 9.80665;
    let Some(path) = shared_tilt_data(
        "peterson_nhnm_levels",
        "brotzer2023_rlnm/RLNM_model_data.csv",
    ) else {
        return;
    };
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (fi, ni) = (col("frequency"), col("nhnm_acc"));
    let rows: Vec<(f64, f64)> = lines
        .map(|line| {
            let cols: Vec<&str> = line.split(',').collect();
            let f: f64 = cols[fi].parse().unwrap();
            let psd: f64 = cols[ni].parse().unwrap();
            (f, psd.sqrt() / g)
        })
        .collect();
    check_model(&rows, "nhnm");
}

/// Breakpoints of Peterson's NHNM (Hz) with the change of the ASD log-log slope there, from the
/// committed coefficient table (`b_db` is dB per decade of period; ASD slope in log f is -b/20).
fn nhnm_breakpoints() -> Vec<(f64, f64)> {
    let text =
        std::fs::read_to_string(common::repo("tilt_data/peterson1993_coefficients.csv")).unwrap();
    let bands: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| l.starts_with("NHNM,"))
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[1].parse().unwrap(), c[4].parse().unwrap())
        })
        .collect();
    bands
        .windows(2)
        .map(|w| (1.0 / w[1].0, (w[1].1 - w[0].1).abs() / 20.0))
        .collect()
}

#[test]
fn embedded_default_spectra_are_the_nhnm_tilt_envelope() {
    // tilt_data/peterson_tilt_asd.csv holds NHNM / g sampled on a log grid. Log-log
    // interpolation between two grid points is exact for a power law; where a breakpoint of
    // slope change ds lies inside an interval of width dx (in ln f), the interpolation error of
    // ln ASD is at most ds * dx / 4. The bound below is computed per interval from the committed
    // coefficient table, plus rounding where there is no breakpoint.
    let levels = json("scripts/reference/noise_model_levels.json");
    let exact = floats(&levels["models"]["peterson_nhnm_exact"]["tilt_asd_rad_per_rthz"]);
    let path = common::repo("tilt_data/peterson_tilt_asd.csv");
    let spectra = read_tilt_spectra(&path, &ReadOptions::default()).unwrap();
    let (grid, on_grid) = spectra.interpolate_loglog(&floats(&levels["freqs_hz"]));
    let breaks = nhnm_breakpoints();
    for (k, &f) in grid.iter().enumerate() {
        let j = spectra.freqs_hz.partition_point(|&x| x < f);
        let (lo, hi) = (spectra.freqs_hz[j.saturating_sub(1)], spectra.freqs_hz[j]);
        let dx = (hi / lo).ln();
        let ds: f64 = breaks
            .iter()
            .filter(|(fb, _)| *fb > lo && *fb < hi)
            .map(|(_, ds)| ds)
            .sum();
        let bound = (ds * dx / 4.0).exp() - 1.0 + LOGLOG_REL;
        let n = on_grid.axes.len();
        let psd = on_grid.csd[(k * n + 1) * n + 1].re;
        assert_close(
            "default NHNM tilt",
            &format!("{f} Hz"),
            psd.sqrt(),
            exact[k],
            bound,
            0.0,
        );
    }
}
