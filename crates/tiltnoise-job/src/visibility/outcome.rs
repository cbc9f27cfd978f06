//! The visibilities of a record: the CSV the fit reads (its one file) and the JSON document of
//! the measurement.

use crate::error::JobError;
use crate::outcome::{Outcome, Provenance};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use tiltnoise_core::fit::peaks::{RecordVisibilities, MIN_SNR};
use tiltnoise_core::model::Observable;
use tiltnoise_io::{OutputKind, Staging};

/// The kinds of file the visibilities are saved as: the CSV `fit --visibility` reads.
pub const OUTPUT_KINDS: &[OutputKind] = &[OutputKind::Csv];

/// The visibilities of a record, the peaks they were read from, and the record's channels.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct VisibilityResult {
    /// The measurement.
    pub measured: RecordVisibilities,
    /// The record's channels, in its order (the order of each peak's SNRs).
    pub channels: Vec<Observable>,
    /// The record, as given.
    pub origin: String,
    /// The parameters whose modes were looked for and the invocation.
    pub provenance: Provenance,
}

impl VisibilityResult {
    /// The visibilities as the CSV `mode,observable,reference,ratio,sigma` that the fit reads
    /// (`docs/fit.md`), with comment lines that say where and how they were measured.
    pub fn csv(&self) -> String {
        let comment = [
            format!(
                "mode visibilities measured from {} by tiltnoise visibility",
                self.origin
            ),
            format!(
                "Hann-windowed peaks of each mode near the model's frequency; reference: the \
                 strongest channel of each unit with SNR >= {MIN_SNR}; sigma: first-order \
                 error from the local noise"
            ),
        ];
        self.measured.visibilities.to_csv(&comment)
    }
}

impl Outcome for VisibilityResult {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// Writes [`VisibilityResult::csv`] to a `.csv` path.
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        crate::output_kind(path, OUTPUT_KINDS)?;
        let text = self.csv();
        Ok(stage.write(path, |tmp| {
            std::fs::write(tmp, text.as_bytes()).map_err(|e| e.to_string())
        })?)
    }

    /// `{"channels", "origin", "peaks": [{"expected_hz", "frequency_hz", "mode", "snr":
    /// {observable: amplitude SNR}}], "skipped": [{"mode", "reason"}], "visibilities":
    /// [{"mode", "observable", "ratio", "reference", "sigma"}]}`: frequencies in Hz, ratios
    /// and SNRs dimensionless, a non-finite number as `null`.
    fn json(&self) -> serde_json::Value {
        let m = &self.measured;
        let doc = VisibilityJson {
            channels: self.channels.iter().map(|o| o.name()).collect(),
            origin: &self.origin,
            peaks: (m.peaks.iter())
                .map(|p| PeakJson {
                    expected_hz: p.expected_hz,
                    frequency_hz: p.frequency_hz,
                    mode: p.mode,
                    snr: self
                        .channels
                        .iter()
                        .map(|o| o.name())
                        .zip(p.snr.iter().copied())
                        .collect(),
                })
                .collect(),
            skipped: (m.skipped.iter())
                .map(|(mode, reason)| SkippedJson {
                    mode: *mode,
                    reason,
                })
                .collect(),
            visibilities: (m.visibilities.items.iter())
                .map(|v| RatioJson {
                    mode: v.mode,
                    observable: v.observable.name(),
                    ratio: v.ratio,
                    reference: v.reference.name(),
                    sigma: v.sigma,
                })
                .collect(),
        };
        serde_json::to_value(doc).expect("a document with string keys serializes")
    }
}

// Keys in alphabetical order, as every JSON report of the tool: fields declared in that order.

#[derive(Serialize)]
struct VisibilityJson<'a> {
    channels: Vec<&'static str>,
    origin: &'a str,
    peaks: Vec<PeakJson>,
    skipped: Vec<SkippedJson<'a>>,
    visibilities: Vec<RatioJson>,
}

#[derive(Serialize)]
struct PeakJson {
    expected_hz: f64,
    frequency_hz: f64,
    mode: usize,
    snr: BTreeMap<&'static str, f64>,
}

#[derive(Serialize)]
struct SkippedJson<'a> {
    mode: usize,
    reason: &'a str,
}

#[derive(Serialize)]
struct RatioJson {
    mode: usize,
    observable: &'static str,
    ratio: f64,
    reference: &'static str,
    sigma: f64,
}
