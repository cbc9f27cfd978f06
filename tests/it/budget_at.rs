//! `tiltnoise budget --at`: the budget read at chosen frequencies. Model terms are exact at the
//! frequency (thermal against the independent mpmath computation of
//! `scripts/reference/thermal_at_reference.py`), Welch terms are band means with their degrees
//! of freedom (single bins against the SciPy + mpmath lab-day reference), in the table, the JSON
//! and the HDF5 file; bad requests exit 2 and write nothing.

use crate::common;
use crate::tolerances::{DOF_REL, LU_GAMMA, PIPELINE_REL};

use common::{assert_fails_without_output, floats, json, repo, tiltnoise};
use serde_json::Value;
use tiltnoise_core::reference::ReferenceModel;

fn run_json(args: &[&str]) -> Value {
    let out = tiltnoise(args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The PSD of `term` of `obs` at summary entry `i`.
fn psd(doc: &Value, i: usize, obs: &str, term: &str) -> f64 {
    doc["summary"][i]["observables"]
        .as_array()
        .unwrap()
        .iter()
        .find(|o| o["observable"] == obs)
        .unwrap()["terms"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["term"] == term)
        .unwrap_or_else(|| panic!("no {obs}.{term}"))["psd"]
        .as_f64()
        .unwrap()
}

#[test]
fn thermal_at_f_is_exact_not_interpolated_between_bins() {
    // With 4096-sample segments of the lab day, 2 mHz lies between bins next to the torsion
    // mode at 2.20 mHz, where a log-log interpolation of the thermal term printed phi 2.854e-6
    // rad/sqrt(Hz) instead of 1.701e-6.
    let lab = repo("tilt_data/lab_tilt_24h.h5");
    let damped = repo("examples/damped.toml");
    let args = [
        "--params",
        damped.to_str().unwrap(),
        "budget",
        "--tilt",
        lab.to_str().unwrap(),
        "--nperseg",
        "4096",
    ];
    let reference = json("scripts/reference/thermal_at_reference.json");
    let mut with_json = args.to_vec();
    with_json.extend(["--format", "json"]);
    let doc = run_json(&with_json);
    let model = ReferenceModel::new(&tiltnoise_io::read_params(&damped).unwrap());
    for (i, row) in reference["thermal_psd"]
        .as_array()
        .unwrap()
        .iter()
        .enumerate()
    {
        let f = row["freq_hz"].as_f64().unwrap();
        assert_eq!(doc["summary"][i]["frequency_hz"].as_f64(), Some(f));
        // sum_j w_j |y^T v_j|^2 with D y = c: y carries LU_GAMMA cond of the solve, the PSD
        // twice that; the reference (40 digits) is exact in comparison.
        let tol = 2.0 * LU_GAMMA * model.condition_number(f).unwrap();
        for obs in ["X", "phi", "phi_a"] {
            let (got, want) = (psd(&doc, i, obs, "thermal"), row[obs].as_f64().unwrap());
            assert!(
                ((got - want) / want).abs() <= tol,
                "{obs} thermal at {f} Hz: {got:e} vs {want:e} (tol {tol:e})"
            );
        }
    }
    let out = tiltnoise(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.contains("phi    at    2 mHz"))
        .unwrap();
    assert!(line.contains("thermal 1.701e-6"), "{line}");
    let line = stdout
        .lines()
        .find(|l| l.contains("X      at    2 mHz"))
        .unwrap();
    assert!(line.contains("thermal 2.203e-9"), "{line}");
    assert!(
        stdout.contains("at 2 mHz: tilt is the mean of 2 Welch bins in 1.8 .. 2.2 mHz"),
        "{stdout}"
    );
}

#[test]
fn welch_band_of_one_bin_is_the_reference_bin_with_its_degrees_of_freedom() {
    // Segments of 4000 samples put 1, 2, 5, 10 mHz on bins 4, 8, 20, 40; a band of +-1 % holds
    // that bin alone, and the transfer functions at f are the reference's at that bin.
    let lab = repo("tilt_data/lab_tilt_24h.h5");
    let dir = tempfile::tempdir().unwrap();
    let h5 = dir.path().join("b.h5");
    let doc = run_json(&[
        "budget",
        "--tilt",
        lab.to_str().unwrap(),
        "--nperseg",
        "4000",
        "--at",
        "1e-3,2e-3,5e-3,1e-2",
        "--at-band",
        "0.01",
        "--format",
        "json",
        "--save",
        h5.to_str().unwrap(),
    ]);
    let reference = json("scripts/reference/lab_budget_reference.json");
    let day = &reference["cases"][0];
    assert_eq!(day["segment"], "day");
    // 86400 samples, step 2000: K = 42 segments, 36 K^2 / (19 K - 1) degrees of freedom.
    let k = 42.0;
    let nu = 36.0 * k * k / (19.0 * k - 1.0);
    for (i, &f) in floats(&day["freqs_hz"]).iter().enumerate() {
        assert_eq!(doc["summary"][i]["frequency_hz"].as_f64(), Some(f));
        for obs in ["X", "phi", "phi_a"] {
            let want = floats(&day["tilt_psd"][obs])[i];
            let got = psd(&doc, i, obs, "tilt");
            assert!(
                ((got - want) / want).abs() <= PIPELINE_REL,
                "{obs} tilt at {f} Hz: {got:e} vs {want:e}"
            );
        }
        let tilt = &doc["summary"][i]["observables"][0]["terms"][0];
        assert_eq!(tilt["term"], "tilt");
        assert_eq!(tilt["evaluation"], "band_mean");
        assert_eq!(tilt["band"]["n_bins"], 1);
        assert_eq!(tilt["band"]["first_bin_hz"].as_f64(), Some(f));
        let dof = tilt["band"]["dof"].as_f64().unwrap();
        assert!((dof - nu).abs() <= DOF_REL * nu, "dof {dof} vs {nu}");
        let (rel, want) = (
            tilt["asd_rel_std"].as_f64().unwrap(),
            (2.0 / nu).sqrt() / 2.0,
        );
        assert!((rel - want).abs() <= DOF_REL * want, "{rel} vs {want}");
    }
    // The HDF5 file holds the same numbers.
    let file = hdf5::File::open(&h5).unwrap();
    let g = file.group("summary/1/phi/tilt").unwrap();
    let got: f64 = g.attr("psd").unwrap().read_scalar().unwrap();
    assert_eq!(got, psd(&doc, 1, "phi", "tilt"));
    let ev = common::str_attr(&g, "evaluation");
    assert_eq!(ev, "band_mean");
    let freq: f64 = file
        .group("summary/1")
        .unwrap()
        .attr("frequency_hz")
        .unwrap()
        .read_scalar()
        .unwrap();
    assert_eq!(freq, 2e-3);
}

#[test]
fn bad_summary_requests_exit_2_and_write_nothing() {
    let lab = repo("tilt_data/lab_tilt_24h.h5");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.h5");
    for (extra, needles) in [
        (
            vec!["--at", "1e-3,abc"],
            vec!["--at", "`abc` is not a frequency"],
        ),
        (vec!["--at", "-2e-3"], vec!["--at", "-0.002", "> 0"]),
        (
            vec!["--at", "0.7"],
            vec!["0.7 Hz", "outside the budget's band"],
        ),
        (
            vec!["--at", "5e-3", "--nperseg", "256"],
            vec!["0.005 Hz", "no Welch bin"],
        ),
        (
            vec!["--at-band", "1.5"],
            vec!["--at-band", "1.5", "0 < b < 1"],
        ),
    ] {
        let mut args = vec![
            "budget",
            "--tilt",
            lab.to_str().unwrap(),
            "--save",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        assert_fails_without_output(&args, dir.path(), &needles);
    }
}
