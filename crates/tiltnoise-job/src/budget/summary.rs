//! The budget read at its summary frequencies as a JSON document: what `tiltnoise budget
//! --format json` prints and what the Python package's `Budget.summary` holds (the budget
//! outcome's `json()`). Fields in alphabetical order, as every JSON report of the tool.

use serde::Serialize;
use tiltnoise_core::noise::{BudgetReport, Evaluation, TermAt};

/// Relative 1-sigma error of an ASD from the PSD's standard deviation: `std / (2 psd)` (to
/// first order).
pub fn asd_rel_std(psd: f64, psd_std: f64) -> f64 {
    if psd > 0.0 {
        psd_std / (2.0 * psd)
    } else {
        0.0
    }
}

#[derive(Serialize)]
struct SummaryJson<'a> {
    notes: Vec<&'a str>,
    summary: Vec<FrequencyJson>,
}

#[derive(Serialize)]
struct FrequencyJson {
    band_hz: [f64; 2],
    frequency_hz: f64,
    observables: Vec<ObservableJson>,
}

#[derive(Serialize)]
struct ObservableJson {
    asd_unit: String,
    observable: &'static str,
    terms: Vec<TermJson>,
    total: TotalJson,
}

#[derive(Serialize)]
struct TermJson {
    asd: f64,
    /// Relative 1-sigma error of the ASD (`null`: exact, or degrees of freedom unknown).
    asd_rel_std: Option<f64>,
    band: Option<BandJson>,
    evaluation: &'static str,
    group: &'static str,
    psd: f64,
    term: String,
}

#[derive(Serialize)]
struct BandJson {
    dof: Option<f64>,
    first_bin_hz: f64,
    last_bin_hz: f64,
    n_bins: usize,
}

#[derive(Serialize)]
struct TotalJson {
    asd: f64,
    asd_rel_std: Option<f64>,
    psd: f64,
}

/// The summary as JSON, with the input's and the budget's notes; non-finite numbers are
/// `null`.
pub(crate) fn summary_json(report: &BudgetReport, input_notes: &[String]) -> serde_json::Value {
    let doc = SummaryJson {
        notes: input_notes
            .iter()
            .chain(&report.notes)
            .map(String::as_str)
            .collect(),
        summary: report
            .summary
            .iter()
            .map(|at| FrequencyJson {
                band_hz: [at.band_hz.0, at.band_hz.1],
                frequency_hz: at.freq_hz,
                observables: at
                    .observables
                    .iter()
                    .map(|ob| ObservableJson {
                        asd_unit: format!("{}/sqrt(Hz)", ob.observable.unit()),
                        observable: ob.observable.name(),
                        terms: ob.terms.iter().map(term_json).collect(),
                        total: TotalJson {
                            asd: ob.total_psd().sqrt(),
                            asd_rel_std: ob
                                .total_psd_std()
                                .map(|std| asd_rel_std(ob.total_psd(), std)),
                            psd: ob.total_psd(),
                        },
                    })
                    .collect(),
            })
            .collect(),
    };
    // Plain structs of strings and numbers: their serialization cannot fail.
    serde_json::to_value(&doc).unwrap_or_default()
}

fn term_json(t: &TermAt) -> TermJson {
    let band = match &t.evaluation {
        Evaluation::Exact => None,
        Evaluation::BandMean(b) => Some(BandJson {
            dof: b.dof,
            first_bin_hz: b.first_bin_hz,
            last_bin_hz: b.last_bin_hz,
            n_bins: b.n_bins,
        }),
    };
    TermJson {
        asd: t.psd.sqrt(),
        asd_rel_std: match t.evaluation {
            Evaluation::Exact => None,
            Evaluation::BandMean(_) => t.psd_std().map(|std| asd_rel_std(t.psd, std)),
        },
        band,
        evaluation: t.evaluation.name(),
        group: t.kind.group().name(),
        psd: t.psd,
        term: t.kind.name(),
    }
}
