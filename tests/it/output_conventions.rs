//! Every file every command writes follows the house conventions (`docs/schemas.md`, "Every
//! output"): HDF5 files carry `schema`, `schema_version` (an integer), `created_by` and
//! `tool_version` at the root and a `unit` attribute on every numeric dataset; CSV files start
//! with the `#` lines `schema`, `schema_version`, `created_by`, `tool_version`, end them with
//! `# units:` (one `COLUMN=UNIT` per column after the first), and name their first column
//! `frequency_hz`.

use crate::common::{self, tiltnoise};
use hdf5::types::TypeDescriptor;
use std::path::Path;

fn ok(args: &[&str]) {
    let out = tiltnoise(args);
    assert!(out.status.success(), "{args:?}: {}", common::stderr(&out));
}

/// Checks one HDF5 output; returns the number of numeric datasets checked.
fn check_hdf5(path: &Path) -> usize {
    let file = hdf5::File::open(path).unwrap();
    let schema = common::str_attr(&file, "schema");
    assert!(
        schema.starts_with("tiltnoise."),
        "{}: schema {schema}",
        path.display()
    );
    let version = file.attr("schema_version").unwrap();
    assert!(
        matches!(
            version.dtype().unwrap().to_descriptor().unwrap(),
            TypeDescriptor::Integer(_) | TypeDescriptor::Unsigned(_)
        ),
        "{}: schema_version is not an integer",
        path.display()
    );
    assert!(!common::str_attr(&file, "created_by").is_empty());
    assert_eq!(
        common::str_attr(&file, "tool_version"),
        env!("CARGO_PKG_VERSION")
    );
    let mut numeric = 0;
    walk(path, &file, "", &mut numeric);
    numeric
}

fn walk(path: &Path, group: &hdf5::Group, at: &str, numeric: &mut usize) {
    for name in group.member_names().unwrap() {
        let full = format!("{at}/{name}");
        if let Ok(g) = group.group(&name) {
            walk(path, &g, &full, numeric);
            continue;
        }
        let ds = group.dataset(&name).unwrap();
        let is_numeric = matches!(
            ds.dtype().unwrap().to_descriptor().unwrap(),
            TypeDescriptor::Float(_)
                | TypeDescriptor::Integer(_)
                | TypeDescriptor::Unsigned(_)
                | TypeDescriptor::Compound(_)
        );
        if is_numeric {
            *numeric += 1;
            let names = ds.attr_names().unwrap();
            assert!(
                names.iter().any(|n| n == "unit"),
                "{}: numeric dataset {full} has no `unit` attribute (attributes: {names:?})",
                path.display()
            );
        }
    }
}

/// Checks one CSV output; returns its number of columns.
fn check_csv(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let comments: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
    let keys: Vec<&str> = comments
        .iter()
        .map(|l| l[1..].trim_start().split(':').next().unwrap())
        .collect();
    assert_eq!(
        keys[..4],
        ["schema", "schema_version", "created_by", "tool_version"],
        "{}",
        path.display()
    );
    assert_eq!(keys.last(), Some(&"units"), "{}", path.display());
    assert!(comments[0].starts_with("# schema: tiltnoise."));
    let header: Vec<&str> = text
        .lines()
        .nth(comments.len())
        .unwrap()
        .split(',')
        .collect();
    assert_eq!(header[0], "frequency_hz", "{}", path.display());
    let units: Vec<&str> = comments
        .last()
        .unwrap()
        .trim_start_matches("# units: ")
        .split(", ")
        .collect();
    assert_eq!(
        units.len(),
        header.len() - 1,
        "{}: one unit per column",
        path.display()
    );
    for (u, name) in units.iter().zip(&header[1..]) {
        let (column, unit) = u.split_once('=').unwrap();
        assert_eq!(column, *name, "{}", path.display());
        assert!(!unit.is_empty());
    }
    header.len()
}

#[test]
fn every_file_of_every_command_names_its_schema_units_and_provenance() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let lab = common::repo("tilt_data/lab_tilt_24h.h5");
    let lab = lab.to_str().unwrap();
    let damped = common::repo("examples/damped.toml");
    let damped = damped.to_str().unwrap();
    ok(&[
        "--params",
        damped,
        "budget",
        "--tilt",
        lab,
        "--nperseg",
        "4096",
        "--segment-duration",
        "14400",
        "--save",
        &p("b.h5"),
        "--save",
        &p("b.csv"),
    ]);
    ok(&["tf", "--save", &p("t.h5"), "--save", &p("t.csv")]);
    ok(&["mc", "--samples", "200", "--save", &p("m.h5")]);
    ok(&["fit", "--save", &p("f.h5")]);
    ok(&[
        "simulate",
        "--duration",
        "3600",
        "--save",
        &p("s.h5"),
        "--save",
        &p("s.csv"),
    ]);
    // A record of the pendulum driven by the lab tilt, for coherence and subtraction.
    ok(&[
        "simulate",
        "--tilt",
        lab,
        "--oversample",
        "2",
        "--save",
        &p("driven.h5"),
    ]);
    let driven = p("driven.h5");
    ok(&[
        "coherence",
        "--tilt",
        lab,
        "--measured",
        &driven,
        "--nperseg",
        "4096",
        "--save",
        &p("c.h5"),
        "--save",
        &p("c.csv"),
    ]);
    ok(&[
        "subtract",
        "--tilt",
        lab,
        "--measured",
        &driven,
        "--nperseg",
        "4096",
        "--save",
        &p("sub.h5"),
    ]);
    let mut numeric = 0;
    for h5 in [
        "b.h5",
        "t.h5",
        "m.h5",
        "f.h5",
        "s.h5",
        "driven.h5",
        "c.h5",
        "sub.h5",
    ] {
        numeric += check_hdf5(&dir.path().join(h5));
    }
    assert!(numeric > 50, "{numeric} numeric datasets checked");
    for csv in ["b.csv", "t.csv", "s.csv", "c.csv"] {
        assert!(check_csv(&dir.path().join(csv)) > 2);
    }

    // The damped budget has terms that are zero at every frequency (thermal elements the
    // axis does not see): left out of the CSV, named in a note, and kept on request.
    let text = std::fs::read_to_string(dir.path().join("b.csv")).unwrap();
    let note = text
        .lines()
        .find(|l| l.starts_with("# note: identically zero, left out"))
        .expect("a note naming the columns left out");
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    let left_out: Vec<&str> = note.split(": ").nth(2).unwrap().split(", ").collect();
    assert!(!left_out.is_empty());
    for name in &left_out {
        assert!(
            !header.split(',').any(|h| h == *name),
            "{name} still a column"
        );
    }
    ok(&[
        "--params",
        damped,
        "budget",
        "--tilt",
        lab,
        "--nperseg",
        "4096",
        "--segment-duration",
        "14400",
        "--keep-zero-columns",
        "--save",
        &p("all.csv"),
    ]);
    let all = std::fs::read_to_string(dir.path().join("all.csv")).unwrap();
    let all_header: Vec<&str> = all
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .split(',')
        .collect();
    assert_eq!(all_header.len(), header.split(',').count() + left_out.len());
    let col = all_header.iter().position(|h| *h == left_out[0]).unwrap();
    for line in all.lines().filter(|l| !l.starts_with('#')).skip(1) {
        assert_eq!(line.split(',').nth(col).unwrap(), "0", "{}", left_out[0]);
    }
    // Fed back: the simulated ASD CSV is a measured spectrum for the budget.
    ok(&[
        "budget",
        "--tilt",
        lab,
        "--nperseg",
        "4096",
        "--measured",
        &p("s.csv"),
        "--save",
        &p("back.h5"),
    ]);
}
