//! A grid evaluated block by block, each block written to every HDF5 and CSV output (through
//! the run's staging) and, when nothing is saved, rendered as text for standard output before
//! the next is computed: memory that does not grow with the grid.

use super::Planned;
use crate::error::JobError;
use crate::outcome::output_kind;
use crate::progress::Progress;
use serde_json::{Map, Value};
use std::path::PathBuf;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::tf::{Method, TransferMatrix};
use tiltnoise_io::{
    push_tf_csv_rows, tf_csv_header, OutputKind, Staging, TfCsvWriter, TfHdf5Writer,
};

/// The text a streamed run renders for standard output when it saves nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TfText {
    /// The CSV file's text (`docs/schemas.md`, `tiltnoise.tf` CSV).
    Csv,
    /// One JSON document, one line per frequency (the value of [`crate::Outcome::json`]).
    Json,
}

/// The output kinds a streamed run writes.
const STREAMED: &[OutputKind] = &[OutputKind::Hdf5, OutputKind::Csv];

impl Planned {
    /// Evaluates the grid block by block and appends each block to every file of `saves`
    /// (`.h5`, `.csv`: the same files as [`super::TfOutcome`]'s `save`), each finished into
    /// `stage` after the last block (they appear when `stage` commits), and with `text`, hands
    /// `sink` each block's text before the next block is computed. Progress: frequencies done
    /// of the grid's.
    ///
    /// # Errors
    ///
    /// The first error of `sink`; [`JobError::Output`] for a path that is not `.h5`/`.csv`
    /// (before anything is computed) or a writer's failure; [`JobError::Tf`] as
    /// [`Planned::whole`]. Nothing of a failed run is left.
    pub fn stream<E: From<JobError>>(
        &self,
        saves: &[PathBuf],
        stage: &Staging,
        text: Option<TfText>,
        cancel: &Cancel,
        progress: &dyn Progress,
        sink: impl FnMut(&str) -> Result<(), E>,
    ) -> Result<(), E> {
        let result = self.stream_blocks(saves, stage, text, cancel, progress, sink);
        progress.finish();
        result
    }

    fn stream_blocks<E: From<JobError>>(
        &self,
        saves: &[PathBuf],
        stage: &Staging,
        text: Option<TfText>,
        cancel: &Cancel,
        progress: &dyn Progress,
        mut sink: impl FnMut(&str) -> Result<(), E>,
    ) -> Result<(), E> {
        let output = |e| E::from(JobError::from(e));
        let meta = &self.provenance;
        let (mut hdf5, mut csv) = (Vec::new(), Vec::new());
        for path in saves {
            match output_kind(path, STREAMED).map_err(output)? {
                OutputKind::Hdf5 => hdf5.push(TfHdf5Writer::create(path, meta).map_err(output)?),
                _ => csv.push(TfCsvWriter::create(path, meta).map_err(output)?),
            }
        }
        let n = self.len();
        let mut chunk = String::new();
        self.blocks(cancel, |block, done| -> Result<(), E> {
            for w in &mut hdf5 {
                w.append(block).map_err(output)?;
            }
            for w in &mut csv {
                w.append(block).map_err(output)?;
            }
            if let Some(text) = text {
                chunk.clear();
                let first = done == block.freqs_hz.len();
                match (text, first) {
                    (TfText::Json, true) => chunk.push_str(&json_head_text(block, self.method())),
                    (TfText::Csv, true) => chunk.push_str(&tf_csv_header(block, meta)),
                    _ => {}
                }
                match text {
                    TfText::Json => push_json_points(&mut chunk, block, first),
                    TfText::Csv => push_tf_csv_rows(&mut chunk, block),
                }
                if text == TfText::Json && done == n {
                    chunk.push_str(&json_tail_text(block));
                }
                sink(&chunk)?;
            }
            progress.report(done as u64, n as u64);
            Ok(())
        })?;
        for w in hdf5 {
            w.finish(stage).map_err(output)?;
        }
        for w in csv {
            w.finish(stage).map_err(output)?;
        }
        Ok(())
    }
}

/// A JSON value written by serde (a number that is not finite is `null`).
fn json_value(v: impl serde::Serialize) -> String {
    serde_json::to_string(&v).expect("JSON of plain data")
}

/// The keys of the document before its points: `inputs`, `method`, `observables`, `per`.
pub(super) fn json_head(block: &TransferMatrix, method: Method) -> Map<String, Value> {
    let mut doc = Map::new();
    let names = |v: Vec<&str>| Value::from(v);
    doc.insert(
        "inputs".into(),
        names(block.inputs.iter().map(|i| i.name()).collect()),
    );
    doc.insert("method".into(), Value::from(method.name()));
    doc.insert(
        "observables".into(),
        names(block.outputs.iter().map(|o| o.name()).collect()),
    );
    doc.insert("per".into(), Value::from(block.ground_quantity().name()));
    doc
}

/// [`json_head`] as text (keys in alphabetical order, as every JSON report), `points` opened.
fn json_head_text(block: &TransferMatrix, method: Method) -> String {
    let head = json_head(block, method);
    format!(
        "{{\n  \"inputs\": {},\n  \"method\": {},\n  \"observables\": {},\n  \"per\": {},\n  \
         \"points\": [",
        head["inputs"], head["method"], head["observables"], head["per"],
    )
}

/// The complex matrix at frequency `k`: `[[[re, im] per input] per observable]`.
fn point_h(block: &TransferMatrix, k: usize) -> Vec<Vec<[f64; 2]>> {
    (0..block.outputs.len())
        .map(|o| {
            (0..block.inputs.len())
                .map(|i| {
                    let z = block.get(k, o, i);
                    [z.re, z.im]
                })
                .collect()
        })
        .collect()
}

/// `{"H": ..., "frequency_hz": f}` of frequency `k`.
pub(super) fn point_json(block: &TransferMatrix, k: usize) -> Value {
    serde_json::json!({"H": point_h(block, k), "frequency_hz": block.freqs_hz[k]})
}

/// One line per frequency: `{"H": [[[re, im] per input] per observable], "frequency_hz": f}`.
fn push_json_points(s: &mut String, block: &TransferMatrix, first: bool) {
    for (k, &f) in block.freqs_hz.iter().enumerate() {
        let comma = if first && k == 0 { "" } else { "," };
        s.push_str(&format!(
            "{comma}\n    {{\"H\": {}, \"frequency_hz\": {}}}",
            json_value(point_h(block, k)),
            json_value(f)
        ));
    }
}

/// `units`: per observable, per input.
pub(super) fn json_tail_units(block: &TransferMatrix) -> Value {
    let units: Vec<Vec<String>> = (0..block.outputs.len())
        .map(|o| (0..block.inputs.len()).map(|i| block.unit(o, i)).collect())
        .collect();
    Value::from(units)
}

/// The end of the document: the points closed, then `units`.
fn json_tail_text(block: &TransferMatrix) -> String {
    format!("\n  ],\n  \"units\": {}\n}}\n", json_tail_units(block))
}
