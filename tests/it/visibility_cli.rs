//! `tiltnoise visibility` and `tiltnoise fit --visibility` on the command line: a simulated
//! free motion of a pendulum as built, its visibilities measured into the CSV, and the fit of
//! the offset from them recovering it within its error; the refusals of both commands.

use crate::common::{assert_fails_without_output, stderr, tiltnoise};

/// The offset of the simulated test mass (m).
const TRUTH_M: f64 = 5e-4;

#[test]
fn simulated_record_to_fitted_offset() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (record, vis, params) = (path("rec.h5"), path("vis.csv"), path("p.toml"));
    let truth = format!("asymmetry.tm_com_x_m={TRUTH_M:e}");
    let mut sim = vec!["simulate", "--set", &truth, "--mode-energy", "1e-10"];
    let readout: Vec<String> = ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"]
        .iter()
        .map(|o| format!("{o}=1e-9"))
        .collect();
    for r in &readout {
        sim.extend(["--readout", r.as_str()]);
    }
    sim.extend(["--save", &record]);
    let out = tiltnoise(&sim);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = tiltnoise(&["visibility", "--measured", &record, "--save", &vis]);
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8(out.stdout).unwrap();
    assert!(table.contains("nu_6") && table.contains("Z/X"), "{table}");
    let csv = std::fs::read_to_string(&vis).unwrap();
    assert!(
        csv.starts_with("# mode visibilities measured from"),
        "{csv}"
    );
    // `--format csv` prints the file `--save` writes, and the table's ratios are its rows.
    let printed = tiltnoise(&["visibility", "--measured", &record, "--format", "csv"]);
    assert!(printed.status.success(), "{}", stderr(&printed));
    assert_eq!(String::from_utf8(printed.stdout).unwrap(), csv);
    for row in csv.lines().filter(|l| l.starts_with("6,Z,X,")) {
        let ratio: f64 = row.split(',').nth(3).unwrap().parse().unwrap();
        assert!(table.contains(&format!("{ratio:.5e}")), "{row}\n{table}");
    }
    // `--format json` holds the CSV's rows, bit for bit (shortest round-trip decimals).
    let printed = tiltnoise(&["visibility", "--measured", &record, "--format", "json"]);
    assert!(printed.status.success(), "{}", stderr(&printed));
    let doc: serde_json::Value = serde_json::from_slice(&printed.stdout).unwrap();
    let rows: Vec<Vec<&str>> = (csv.lines().filter(|l| !l.starts_with('#')).skip(1))
        .map(|l| l.split(',').collect())
        .collect();
    let items = doc["visibilities"].as_array().unwrap();
    assert_eq!(items.len(), rows.len());
    for (item, row) in items.iter().zip(&rows) {
        assert_eq!(item["mode"].as_u64().unwrap().to_string(), row[0]);
        assert_eq!(item["observable"].as_str().unwrap(), row[1]);
        assert_eq!(item["reference"].as_str().unwrap(), row[2]);
        for (key, column) in [("ratio", 3), ("sigma", 4)] {
            let parsed: f64 = row[column].parse().unwrap();
            assert_eq!(
                item[key].as_f64().unwrap().to_bits(),
                parsed.to_bits(),
                "{row:?}"
            );
        }
    }

    let toml = tiltnoise(&["params"]).stdout;
    let mut toml = String::from_utf8(toml).unwrap();
    toml.push_str("\n[uncertainty]\n\"asymmetry.tm_com_x_m\" = { sigma = 1e-3 }\n");
    std::fs::write(&params, toml).unwrap();
    let out = tiltnoise(&[
        "--params",
        &params,
        "fit",
        "--visibility",
        &vis,
        "--free",
        "asymmetry.tm_com_x_m",
        "--bound-sigmas",
        "3",
        "--format",
        "json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &v["parameters"][0];
    let (fitted, sigma) = (
        p["fitted"].as_f64().unwrap(),
        p["fitted_sigma"].as_f64().unwrap(),
    );
    println!("fitted {fitted:e} +/- {sigma:e} m, truth {TRUTH_M:e}");
    assert!(
        (fitted - TRUTH_M).abs() <= 4.0 * sigma,
        "{fitted} +/- {sigma}"
    );
    assert_eq!(v["modes"].as_array().unwrap().len(), 0);
    assert!(v["visibilities"].as_array().unwrap().len() >= 20);
}

/// A fit's HDF5 file holds the visibilities its JSON report holds, entry by entry, bit for
/// bit (the JSON's shortest round-trip decimals read back to the same doubles; a `null`
/// nominal is NaN in the file).
#[test]
fn fit_hdf5_holds_the_visibilities_of_its_json() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let (record, vis) = (path("rec.h5"), path("vis.csv"));
    let (json_path, h5_path) = (path("fit.json"), path("fit.h5"));
    let truth = format!("asymmetry.tm_com_x_m={TRUTH_M:e}");
    let mut sim = vec!["simulate", "--set", &truth, "--mode-energy", "1e-10"];
    let readout: Vec<String> = ["X", "Y", "Z", "theta", "eta", "phi", "phi_a"]
        .iter()
        .map(|o| format!("{o}=1e-9"))
        .collect();
    for r in &readout {
        sim.extend(["--readout", r.as_str()]);
    }
    sim.extend(["--save", &record]);
    let out = tiltnoise(&sim);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = tiltnoise(&["visibility", "--measured", &record, "--save", &vis]);
    assert!(out.status.success(), "{}", stderr(&out));
    let params = path("p.toml");
    let mut toml = String::from_utf8(tiltnoise(&["params"]).stdout).unwrap();
    toml.push_str("\n[uncertainty]\n\"asymmetry.tm_com_x_m\" = { sigma = 1e-3 }\n");
    std::fs::write(&params, toml).unwrap();
    let out = tiltnoise(&[
        "--params",
        &params,
        "fit",
        "--visibility",
        &vis,
        "--free",
        "asymmetry.tm_com_x_m",
        "--save",
        &json_path,
        "--save",
        &h5_path,
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let rows = v["visibilities"].as_array().unwrap();
    assert!(rows.len() >= 20, "{}", rows.len());
    let file = hdf5::File::open(&h5_path).unwrap();
    assert_eq!(
        file.attr("schema_version")
            .unwrap()
            .read_scalar::<i64>()
            .unwrap(),
        3
    );
    let g = file.group("visibilities").unwrap();
    let numbers = |name: &str| -> Vec<f64> { g.dataset(name).unwrap().read_raw().unwrap() };
    let texts = |name: &str| -> Vec<String> {
        let raw: Vec<hdf5::types::VarLenUnicode> = g.dataset(name).unwrap().read_raw().unwrap();
        raw.iter().map(|s| s.as_str().to_string()).collect()
    };
    let mode: Vec<i64> = g.dataset("mode").unwrap().read_raw().unwrap();
    assert_eq!(mode.len(), rows.len());
    for name in ["observable", "reference", "sigma_source"] {
        let column = texts(name);
        assert_eq!(column.len(), rows.len(), "{name}");
        for (row, text) in rows.iter().zip(&column) {
            assert_eq!(row[name].as_str().unwrap(), text, "{name}");
        }
    }
    for name in ["measured", "sigma", "nominal", "fitted", "residual_sigmas"] {
        let column = numbers(name);
        assert_eq!(column.len(), rows.len(), "{name}");
        for (row, &x) in rows.iter().zip(&column) {
            match row[name].as_f64() {
                Some(expected) => assert_eq!(x.to_bits(), expected.to_bits(), "{name}"),
                None => assert!(x.is_nan(), "{name}: {x} where the JSON has null"),
            }
        }
    }
    for (row, &m) in rows.iter().zip(&mode) {
        assert_eq!(row["mode"].as_i64().unwrap(), m);
    }
}

#[test]
fn bad_input_exits_2_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let file = |name: &str, text: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let out = dir.path().join("fit.json");
    let out_s = out.to_str().unwrap();
    let header = "mode,observable,reference,ratio,sigma\n";
    for (name, body, needles) in [
        (
            "mode.csv",
            "9,Y,X,0.1,0.01\n",
            vec!["mode.csv", "line 2", "mode `9`"],
        ),
        (
            "obs.csv",
            "6,W,X,0.1,0.01\n",
            vec!["obs.csv", "observable `W`"],
        ),
        (
            "ratio.csv",
            "6,Y,X,nan,0.01\n",
            vec!["ratio.csv", "ratio `nan`"],
        ),
        (
            "sigma.csv",
            "6,Y,X,0.1,-1\n",
            vec!["sigma.csv", "sigma `-1`"],
        ),
        (
            "dup.csv",
            "6,Y,X,0.1,0.01\n6,Y,X,0.2,0.01\n",
            vec!["dup.csv", "twice"],
        ),
    ] {
        let vis = file(name, &format!("{header}{body}"));
        assert_fails_without_output(
            &["fit", "--save", out_s, "--visibility", &vis],
            dir.path(),
            &needles,
        );
    }
    let missing = dir.path().join("missing.csv");
    assert_fails_without_output(
        &[
            "fit",
            "--save",
            out_s,
            "--visibility",
            missing.to_str().unwrap(),
        ],
        dir.path(),
        &["missing.csv"],
    );
    // The symmetric pendulum's nu_6 has no component in Y: not a reference.
    let vis = file("ref.csv", &format!("{header}6,X,Y,0.1,0.01\n"));
    assert_fails_without_output(
        &[
            "fit",
            "--save",
            out_s,
            "--visibility",
            &vis,
            "--free",
            "length.z_b_m",
        ],
        dir.path(),
        &["nu_6", "no component in the reference Y"],
    );
    let spectra = file("asd.csv", "freq_hz,X\n0.1,1e-9\n0.2,1e-9\n");
    let vis_out = dir.path().join("v.csv");
    let vis_s = vis_out.to_str().unwrap();
    for (args, needles) in [
        (
            vec![
                "visibility",
                "--measured",
                spectra.as_str(),
                "--save",
                vis_s,
            ],
            vec!["asd.csv", "spectra"],
        ),
        (
            vec![
                "visibility",
                "--measured",
                spectra.as_str(),
                "--save",
                "v.txt",
            ],
            vec!["v.txt", ".csv"],
        ),
        (
            vec![
                "visibility",
                "--measured",
                missing.to_str().unwrap(),
                "--save",
                vis_s,
            ],
            vec!["missing.csv"],
        ),
    ] {
        assert_fails_without_output(&args, dir.path(), &needles);
    }
    assert!(!out.exists() && !vis_out.exists());
}
