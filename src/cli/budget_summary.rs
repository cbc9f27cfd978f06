//! The budget read at the `--at` frequencies, for the terminal: a table (values exact at the
//! frequency for the model's terms, band means with their 1-sigma statistical error for Welch
//! estimates); `--format json` prints the budget outcome's summary document
//! (`BudgetOutcome::json`).

use std::fmt::Write as _;
use tiltnoise_core::noise::{BandMean, BudgetReport, Evaluation, ObservableAt, TermAt, TermKind};
use tiltnoise_job::budget::asd_rel_std;

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
