//! The layout of every CSV file tiltnoise writes (`docs/schemas.md`, "CSV files"):
//!
//! ```text
//! # schema: tiltnoise.budget_csv
//! # schema_version: 2
//! # created_by: tiltnoise budget --tilt lab.h5 --save b.csv
//! # tool_version: 0.1.0
//! # note: one-sided ASD = sqrt(PSD)
//! # units: X.tilt=m/sqrt(Hz), X.readout=m/sqrt(Hz), ...
//! frequency_hz,X.tilt,X.readout,...
//! 1e-4,3.1e-7,9e-9,...
//! ```
//!
//! `#` lines, the last of them `# units:` with one `COLUMN=UNIT` entry per column after the
//! first (the first is always `frequency_hz`, in Hz), then one header line of plain names, then
//! the data. The `# key: value` lines are those tiltnoise's own CSV readers take (`units`) or
//! ignore (the others), so an output can be read back; pandas reads it with
//! `pd.read_csv(path, comment="#")`.

use crate::run_meta::RunMeta;

/// Name of the first column of every CSV file tiltnoise writes (and of the frequency dataset
/// of every HDF5 file).
pub const FREQUENCY_COLUMN: &str = "frequency_hz";

/// What the `#` lines of a file say.
#[derive(Debug, Clone)]
pub struct CsvPreamble<'a> {
    /// `tiltnoise.<name>` (the layout, documented in `docs/schemas.md`).
    pub schema: &'a str,
    /// Bumped when the layout changes in a way that can break a reader.
    pub schema_version: u32,
    /// The run's provenance (tool version and command line).
    pub meta: &'a RunMeta,
    /// `# note:` lines (conventions, columns left out), one line each.
    pub notes: Vec<String>,
}

/// The `#` lines and the header line (each ending in a newline) of a file whose columns after
/// `frequency_hz` are `columns`, `(name, unit)`.
pub fn csv_head(preamble: &CsvPreamble<'_>, columns: &[(String, String)]) -> String {
    let mut s = String::new();
    let mut line = |key: &str, value: &str| {
        s.push_str("# ");
        s.push_str(key);
        s.push_str(": ");
        s.push_str(&one_line(value));
        s.push('\n');
    };
    line("schema", preamble.schema);
    line("schema_version", &preamble.schema_version.to_string());
    line("created_by", &preamble.meta.command_line);
    line("tool_version", &preamble.meta.tool_version);
    for note in &preamble.notes {
        line("note", note);
    }
    let units: Vec<String> = columns.iter().map(|(n, u)| format!("{n}={u}")).collect();
    line("units", &units.join(", "));
    s.push_str(FREQUENCY_COLUMN);
    for (name, _) in columns {
        s.push(',');
        s.push_str(name);
    }
    s.push('\n');
    s
}

/// `text` on one line: control characters (a newline in a command-line argument) as spaces.
fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// Columns whose every value is exactly zero, removed from `columns` (`(name, unit, values)`)
/// unless `keep`; returns the names removed, in column order.
pub fn drop_zero_columns(columns: &mut Vec<(String, String, Vec<f64>)>, keep: bool) -> Vec<String> {
    if keep {
        return Vec::new();
    }
    let mut dropped = Vec::new();
    columns.retain(|(name, _, values)| {
        let zero = !values.is_empty() && values.iter().all(|&v| v == 0.0);
        if zero {
            dropped.push(name.clone());
        }
        !zero
    });
    dropped
}

/// The `# note:` line for columns left out because they are identically zero.
pub fn zero_columns_note(dropped: &[String]) -> Option<String> {
    (!dropped.is_empty()).then(|| {
        format!(
            "identically zero, left out (the keep-zero-columns option keeps them): {}",
            dropped.join(", ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_has_one_unit_per_column_and_plain_names() {
        let meta = RunMeta {
            tool_version: "9.9.9".into(),
            command_line: "tiltnoise budget -x\nINJECTED".into(),
            ..RunMeta::default()
        };
        let p = CsvPreamble {
            schema: "tiltnoise.test_csv",
            schema_version: 3,
            meta: &meta,
            notes: vec!["one-sided".into()],
        };
        let cols = vec![
            ("X.tilt".to_string(), "m/sqrt(Hz)".to_string()),
            ("phi.tilt".to_string(), "rad/sqrt(Hz)".to_string()),
        ];
        let head = csv_head(&p, &cols);
        let lines: Vec<&str> = head.lines().collect();
        assert_eq!(
            lines,
            [
                "# schema: tiltnoise.test_csv",
                "# schema_version: 3",
                "# created_by: tiltnoise budget -x INJECTED",
                "# tool_version: 9.9.9",
                "# note: one-sided",
                "# units: X.tilt=m/sqrt(Hz), phi.tilt=rad/sqrt(Hz)",
                "frequency_hz,X.tilt,phi.tilt",
            ]
        );
    }

    #[test]
    fn only_identically_zero_columns_are_dropped() {
        let mut cols = vec![
            ("a".to_string(), "1".to_string(), vec![0.0, 0.0]),
            ("b".to_string(), "1".to_string(), vec![0.0, 1e-300]),
            ("c".to_string(), "1".to_string(), vec![-0.0, 0.0]),
        ];
        let kept = cols.clone();
        assert!(drop_zero_columns(&mut cols.clone(), true).is_empty());
        let dropped = drop_zero_columns(&mut cols, false);
        assert_eq!(dropped, ["a", "c"]);
        assert_eq!(cols, vec![kept[1].clone()]);
        assert_eq!(
            zero_columns_note(&dropped).unwrap(),
            "identically zero, left out (the keep-zero-columns option keeps them): a, c"
        );
    }
}
