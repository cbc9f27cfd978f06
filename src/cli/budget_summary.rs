//! The budget read at the `--at` frequencies, for the terminal: a table (values exact at the
//! frequency for the model's terms, band means with their 1-sigma statistical error for Welch
//! estimates) or JSON (`--format json`).

use serde::Serialize;
use std::fmt::Write as _;
use tiltnoise_core::noise::{BandMean, BudgetReport, Evaluation, ObservableAt, TermAt, TermKind};

/// A frequency for a line of the table: `1`, `2.5`, `0.25` (mHz, up to 4 significant digits).
fn mhz(f: f64) -> String {
    let s = format!("{:.4}", f * 1e3);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A relative error as a percentage with two significant digits: `26 %`, `8.0 %`, `0.42 %`;
/// `<0.01 %` below that.
fn pct(rel: f64) -> String {
    let p = 100.0 * rel;
    if p < 0.01 {
        return "<0.01 %".to_string();
    }
    let decimals = if p >= 10.0 {
        0
    } else if p > 0.0 {
        (1.0 - p.log10().floor()).clamp(1.0, 6.0) as usize
    } else {
        0
    };
    format!("{p:.decimals$} %")
}

/// Relative 1-sigma error of an ASD from the PSD's standard deviation: `std / (2 psd)` (to
/// first order).
fn asd_rel_std(psd: f64, psd_std: f64) -> f64 {
    if psd > 0.0 {
        psd_std / (2.0 * psd)
    } else {
        0.0
    }
}

/// ` ±12 %` for a band mean with known degrees of freedom, ` (error unknown)` without, nothing
/// for an exact value.
fn error_text(t: &TermAt) -> String {
    match (&t.evaluation, t.psd_std()) {
        (Evaluation::Exact, _) => String::new(),
        (Evaluation::BandMean(_), Some(std)) => {
            format!(" ±{}", pct(asd_rel_std(t.psd, std)))
        }
        (Evaluation::BandMean(_), None) => " (band mean, error unknown)".to_string(),
    }
}

/// The terms printed: every term that adds to the total, the floor's tilt and translation
/// (beside ground, its breakdown), each user-named one, and the measured one.
fn printed(ob: &ObservableAt, t: &TermAt) -> bool {
    ob.adds_to_total(&t.kind)
        || matches!(
            t.kind,
            TermKind::Tilt | TermKind::Translation | TermKind::Measured | TermKind::UserNamed(_)
        )
}

/// The table of the summary, then the notes.
pub fn table(report: &BudgetReport) -> String {
    let mut s = String::from(
        "noise budget (one-sided ASD): model terms exact at each frequency; Welch estimates the \
         mean PSD of their bins in the stated band, +- the 1-sigma statistical error of the ASD \
         (chi-squared degrees of freedom of the band mean)\n",
    );
    let damped = report
        .budget
        .observables
        .iter()
        .any(|ob| ob.term(&TermKind::Thermal).is_some());
    for at in &report.summary {
        let floor_band = at
            .observables
            .iter()
            .flat_map(|ob| &ob.terms)
            .find_map(|t| match &t.evaluation {
                Evaluation::BandMean(b) if t.kind.is_ground_motion() => Some((&t.kind, b)),
                _ => None,
            });
        if let Some((kind, b)) = floor_band {
            let _ = writeln!(s, "  {}", band_text(kind, at.freq_hz, at.band_hz, b));
        }
        for ob in &at.observables {
            let _ = writeln!(s, "  {}", line(at.freq_hz, ob));
        }
    }
    if !damped {
        s.push_str(
            "thermal: none (undamped model: every loss angle and viscous coefficient is 0; \
             see docs/damping.md)\n",
        );
    }
    for note in &report.notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}

fn band_text(kind: &TermKind, f: f64, band: (f64, f64), b: &BandMean) -> String {
    let dof = match b.dof {
        Some(nu) => format!("{nu:.1} degrees of freedom"),
        None => "degrees of freedom unknown (median averaging)".to_string(),
    };
    format!(
        "at {} mHz: {} is the mean of {} Welch bin{} in {} .. {} mHz (f +- {:.0} %, bins \
         {} .. {} mHz), {dof}",
        mhz(f),
        match kind {
            TermKind::Tilt | TermKind::TiltAxis(_) => "tilt",
            _ => "the floor's motion",
        },
        b.n_bins,
        if b.n_bins == 1 { "" } else { "s" },
        mhz(band.0),
        mhz(band.1),
        100.0 * (band.1 / f - 1.0),
        mhz(b.first_bin_hz),
        mhz(b.last_bin_hz),
    )
}

fn line(f: f64, ob: &ObservableAt) -> String {
    let mut s = format!("{:<6} at {:>4} mHz:", ob.observable.name(), mhz(f));
    for t in ob.terms.iter().filter(|t| printed(ob, t)) {
        let _ = write!(s, "  {} {:.3e}{}", t.kind, t.psd.sqrt(), error_text(t));
    }
    let total = ob.total_psd();
    let total_err = match ob.total_psd_std() {
        Some(std) if std > 0.0 => format!(" ±{}", pct(asd_rel_std(total, std))),
        _ => String::new(),
    };
    let _ = write!(
        s,
        "  total {:.3e}{total_err} {}/sqrt(Hz)",
        total.sqrt(),
        ob.observable.unit()
    );
    s
}

// JSON: fields in alphabetical order, as every JSON report of the tool.

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

/// The summary as JSON, with the input's and the budget's notes.
pub fn json(report: &BudgetReport, input_notes: &[String]) -> serde_json::Result<String> {
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
    serde_json::to_string_pretty(&doc)
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
