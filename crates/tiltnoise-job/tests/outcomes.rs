//! The outcomes of tf, methods, modes and params: `save` writes by output kind and refuses
//! every other kind before writing anything, a streamed grid writes the files its whole
//! outcome saves, and the provenance is the job's (the invocation given, the model's modes).

use std::path::{Path, PathBuf};
use tiltnoise_core::freq::LogGrid;
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::limits::MAX_GRID_POINTS;
use tiltnoise_core::model::{Input, Model, Observable, Request};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_job::files::Staging;
use tiltnoise_job::methods::MethodsRequest;
use tiltnoise_job::modes::ModesRequest;
use tiltnoise_job::params::ParamsRequest;
use tiltnoise_job::tf::{FreqGrid, TfRequest, TfText};
use tiltnoise_job::{Cancel, Invocation, JobError, Outcome, Silent};

fn invocation() -> Invocation {
    Invocation {
        command_line: "tiltnoise tf --freq 1e-4:101:30".into(),
    }
}

fn tf_request(model: &Model) -> TfRequest<'_> {
    TfRequest {
        model,
        request: Request {
            outputs: Observable::ALL.to_vec(),
            inputs: Input::all_ground(),
        },
        grid: FreqGrid::Log(LogGrid::new(1e-4, 30.0, 101, MAX_GRID_POINTS).unwrap()),
        per: GroundQuantity::Displacement,
        method: None,
        rel_tol: None,
        block_freqs: Some(7),
        figure: None,
        figure_options: tiltnoise_job::tf::figure_options(
            model,
            vec![Observable::X],
            false,
            String::new(),
        ),
        invocation: invocation(),
    }
}

/// Saves `outcome` to each name of `names` in `dir`, all in one staging.
fn save_all(outcome: &dyn Outcome, dir: &Path, names: &[&str]) -> Vec<PathBuf> {
    let paths: Vec<PathBuf> = names.iter().map(|n| dir.join(n)).collect();
    let stage = Staging::new();
    for p in &paths {
        outcome.save(&stage, p).unwrap();
    }
    stage.commit().unwrap();
    paths
}

/// `outcome.save` refuses `name` (a kind not among its output kinds) and writes nothing.
fn refuses(outcome: &dyn Outcome, dir: &Path, name: &str) {
    let path = dir.join(name);
    let stage = Staging::new();
    match outcome.save(&stage, &path) {
        Err(JobError::Output(_)) => {}
        Err(e) => panic!("{name}: {e}"),
        Ok(()) => panic!("{name} accepted"),
    }
    stage.commit().unwrap();
    assert!(!path.exists(), "{name} written");
}

#[test]
fn a_streamed_grid_writes_the_files_its_whole_outcome_saves() {
    let model = Model::new(&Params::table_i()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let planned = tiltnoise_job::tf::prepare(&tf_request(&model)).unwrap();
    let streamed = [dir.path().join("s.csv"), dir.path().join("s.h5")];
    let stage = Staging::new();
    let mut text = String::new();
    planned
        .stream(
            &streamed,
            &stage,
            Some(TfText::Csv),
            &Cancel::never(),
            &Silent,
            |chunk| -> Result<(), JobError> {
                text.push_str(chunk);
                Ok(())
            },
        )
        .unwrap();
    assert!(
        !streamed[0].exists(),
        "a streamed file appears only on commit"
    );
    stage.commit().unwrap();
    let outcome = planned.outcome(&Cancel::never(), &Silent).unwrap();
    let saved = save_all(&outcome, dir.path(), &["w.csv", "w.h5", "w.png", "w.svg"]);
    let csv = std::fs::read_to_string(&saved[0]).unwrap();
    assert_eq!(std::fs::read_to_string(&streamed[0]).unwrap(), csv);
    // The text of standard output is the CSV file's.
    assert_eq!(text, csv);
    assert!(csv.contains("tiltnoise tf --freq 1e-4:101:30"), "{csv}");
    for p in &saved[1..] {
        assert!(
            std::fs::metadata(p).unwrap().len() > 1000,
            "{}",
            p.display()
        );
    }
    assert!(std::fs::metadata(&streamed[1]).unwrap().len() > 1000);
    refuses(&outcome, dir.path(), "w.txt");
    // A figure is not streamed: refused before anything is computed.
    let stage = Staging::new();
    let e = planned
        .stream(
            &[dir.path().join("f.png")],
            &stage,
            None,
            &Cancel::never(),
            &Silent,
            |_| -> Result<(), JobError> { panic!("nothing is computed") },
        )
        .unwrap_err();
    assert!(matches!(e, JobError::Output(_)), "{e}");
}

#[test]
fn the_tf_json_is_its_streamed_document() {
    let model = Model::new(&Params::table_i()).unwrap();
    let planned = tiltnoise_job::tf::prepare(&tf_request(&model)).unwrap();
    let mut text = String::new();
    planned
        .stream(
            &[],
            &Staging::new(),
            Some(TfText::Json),
            &Cancel::never(),
            &Silent,
            |chunk| -> Result<(), JobError> {
                text.push_str(chunk);
                Ok(())
            },
        )
        .unwrap();
    let streamed: serde_json::Value = serde_json::from_str(&text).unwrap();
    let outcome = planned.outcome(&Cancel::never(), &Silent).unwrap();
    assert_eq!(outcome.json(), streamed);
    assert_eq!(streamed["points"].as_array().unwrap().len(), 101);
}

#[test]
fn the_provenance_is_the_jobs() {
    let model = Model::new(&Params::table_i()).unwrap();
    let modes: Vec<(usize, f64)> = NormalModes::new(&model)
        .modes
        .iter()
        .map(|m| (m.index, m.frequency_hz))
        .collect();
    let outcome = tiltnoise_job::tf::run(&tf_request(&model), &Cancel::never(), &Silent).unwrap();
    let p = outcome.provenance();
    assert_eq!(p.command_line, invocation().command_line);
    assert_eq!(p.modes, modes);
    assert_eq!(p.params_toml, Params::table_i().to_toml());
    let req = ModesRequest {
        model: &model,
        invocation: invocation(),
    };
    let outcome = tiltnoise_job::modes::run(&req, &Cancel::never(), &Silent).unwrap();
    assert_eq!(outcome.provenance().modes, modes);
    assert_eq!(outcome.json()["modes"].as_array().unwrap().len(), 8);
    let dir = tempfile::tempdir().unwrap();
    refuses(&outcome, dir.path(), "m.h5");
    let req = ParamsRequest {
        params: Params::table_i(),
        invocation: invocation(),
    };
    let outcome = tiltnoise_job::params::run(&req, &Cancel::never(), &Silent).unwrap();
    assert!(outcome.provenance().modes.is_empty());
    let back = Params::from_toml_str(&outcome.toml(), "toml").unwrap();
    assert_eq!(back, Params::table_i());
    refuses(&outcome, dir.path(), "p.csv");
}

#[test]
fn the_methods_chart_is_saved_by_kind() {
    let model = Model::new(&Params::table_i()).unwrap();
    let req = MethodsRequest {
        model: &model,
        grid_hz: (0..20).map(|k| 1e-3 * 1.4f64.powi(k)).collect(),
        inputs: None,
        grid_spec: "1e-3:20:0.6".into(),
        view: Default::default(),
        invocation: invocation(),
    };
    let outcome = tiltnoise_job::methods::run(&req, &Cancel::never(), &Silent).unwrap();
    assert_eq!(outcome.json()["grid"], "1e-3:20:0.6");
    let dir = tempfile::tempdir().unwrap();
    for p in save_all(&outcome, dir.path(), &["c.png", "c.svg"]) {
        assert!(
            std::fs::metadata(&p).unwrap().len() > 1000,
            "{}",
            p.display()
        );
    }
    refuses(&outcome, dir.path(), "c.csv");
    refuses(&outcome, dir.path(), "c.h5");
}
