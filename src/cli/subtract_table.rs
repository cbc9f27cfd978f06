//! The report of `subtract` as a table on the terminal: the alignment and the fit, the
//! estimates, the held-out residuals, the check of the cleaned record against the raw one,
//! the notes.

use std::fmt::Write as _;
use tiltnoise_core::error::Num;
use tiltnoise_core::subtract::{
    BandCheck, ColocatedEstimate, Estimate, Method, ResidualSpectra, Status, SubtractResult,
};
use tiltnoise_job::subtract::figure::with_sigma;
use tiltnoise_job::subtract::report::band_top;

/// The report as the table `subtract` prints.
pub(crate) fn report_table(r: &SubtractResult) -> String {
    let mut s = String::new();
    overview(&mut s, r);
    let _ = writeln!(s);
    estimates(&mut s, &r.fit.estimates);
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "held-out residuals, band means as ASD (unit/sqrt(Hz)), +/- relative 1 sigma of a band \
         PSD:"
    );
    for res in &r.residuals {
        residual(&mut s, res);
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "the cleaned record against the raw one over the whole overlap, per 1/3-decade band \
         (band means as ASD; limit: 1 + z sigma of the ratio, z corrected for the number of \
         bands):"
    );
    for (o, check) in &r.bands {
        band_check(&mut s, o.name(), check, r.alignment.fs_hz);
    }
    for note in &r.notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}

/// The alignment, the stretches, the fit's band and chi^2, the estimated witness noise.
fn overview(s: &mut String, r: &SubtractResult) {
    let a = &r.alignment;
    let _ = writeln!(s, "alignment: {}", a.note);
    let _ = writeln!(
        s,
        "overlap: {} samples at {} Hz ({} s); training {} samples, held out {} (the end); Welch \
         segment {} samples",
        a.len,
        Num(a.fs_hz),
        Num(a.len as f64 / a.fs_hz),
        r.n_train,
        r.n_holdout,
        r.segment_len
    );
    let f = &r.fit;
    let _ = writeln!(
        s,
        "fit band {} .. {} Hz, bins {}; chi^2 {:.1} for {} dof ({:.3}); uncertainties x {:.3}",
        Num(f.band_hz.0),
        Num(f.band_hz.1),
        f.bins
            .iter()
            .map(|(o, n)| format!("{} {n}", o.name()))
            .collect::<Vec<_>>()
            .join(", "),
        f.chi2,
        f.dof,
        f.chi2 / f.dof as f64,
        f.sigma_factor
    );
    for e in &r.colocated {
        colocated(s, e);
    }
}

/// How a witness noise was estimated from co-located records.
fn colocated(s: &mut String, e: &ColocatedEstimate) {
    let how = match &e.method {
        Method::Huddle {
            relative_gain,
            noise_ratio,
        } => format!(
            "huddle test with one co-located record (its gain relative to the witness \
             {relative_gain:.4}, its noise {noise_ratio} times the witness's)"
        ),
        Method::ThreeCorneredHat { relative_gains } => format!(
            "three-cornered hat with two co-located records (gains relative to the witness \
             {:.4}, {:.4})",
            relative_gains[0], relative_gains[1]
        ),
    };
    let _ = writeln!(
        s,
        "witness noise of {}: estimated by a {how}, +/- {:.1} % (ASD)",
        e.noise.input.name(),
        100.0 * e.noise.rel
    );
}

/// The table of the estimates: nominal value, estimate, status.
fn estimates(s: &mut String, estimates: &[Estimate]) {
    let _ = writeln!(
        s,
        "{:<28} {:>14} {:>34}  status",
        "parameter", "nominal", "estimate"
    );
    for e in estimates {
        let est = match (e.status, e.prior_sigma) {
            (Status::NotConstrained, None) => format!("{}", e.value),
            _ => with_sigma(e.value, e.sigma),
        };
        let _ = writeln!(
            s,
            "{:<28} {:>14} {:>34}  {}",
            format!("{} ({})", e.name, e.unit),
            Num(e.nominal).to_string(),
            est,
            status(e)
        );
    }
}

/// An estimate's status in words.
fn status(e: &Estimate) -> String {
    match e.status {
        Status::Fitted => match e.prior_sigma {
            Some(p) => format!("fitted, with its prior +/- {}", Num(p)),
            None => "fitted".to_string(),
        },
        Status::AtBound => format!("on the box [{}, {}]", Num(e.bounds.0), Num(e.bounds.1)),
        Status::NotConstrained if e.prior_sigma.is_some() => format!(
            "not constrained by the data alone: estimated with its prior {} +/- {}",
            Num(e.nominal),
            Num(e.scale)
        ),
        Status::NotConstrained => format!(
            "not constrained: held at nominal (the data would give +/- {}; scale {})",
            if e.sigma.is_finite() {
                format!("{:.2e}", e.sigma)
            } else {
                "infinity".to_string()
            },
            Num(e.scale)
        ),
    }
}

/// The held-out residuals of one observable in the report band.
fn residual(s: &mut String, res: &ResidualSpectra) {
    let b = &res.band;
    let _ = writeln!(
        s,
        "  {:<6} {} .. {} Hz ({} bins, +/- {:.1} %): measured {:.3e}, predicted {:.3e}, \
         cleaned {:.3e}, witness-noise limit {:.3e}, Wiener {:.3e} ({:.3e} without its \
         training noise), coherence limit {:.3e}",
        res.observable.name(),
        Num(b.band_hz.0),
        Num(b.band_hz.1),
        b.bins,
        100.0 * b.psd_rel_sigma,
        b.measured_asd,
        b.predicted_asd,
        b.cleaned_asd,
        b.witness_limited_asd,
        b.wiener_asd,
        b.wiener_corrected_asd,
        b.expected_asd
    );
    if let Some((ratio, sigma)) = b.cleaned_to_readout {
        let _ = writeln!(
            s,
            "         cleaned / readout = {ratio:.4} +/- {sigma:.4}; cleaned / coherence \
             limit = {:.4} +/- {:.4}",
            b.cleaned_to_expected.0, b.cleaned_to_expected.1
        );
    } else {
        let _ = writeln!(
            s,
            "         cleaned / coherence limit = {:.4} +/- {:.4} (no --readout given)",
            b.cleaned_to_expected.0, b.cleaned_to_expected.1
        );
    }
}

/// The cleaned record of one observable against the raw one, band by band.
fn band_check(s: &mut String, name: &str, check: &BandCheck, fs_hz: f64) {
    let _ = writeln!(
        s,
        "  {:<6} variance cleaned/raw {:.4}{}",
        name,
        check.variance_ratio,
        if check.left_raw {
            " (left raw entirely)"
        } else {
            ""
        }
    );
    let _ = writeln!(
        s,
        "         {:>9} .. {:<9} {:>5}  {:>10} {:>10} {:>10} {:>10}  {:>10}  {:>6}",
        "f_lo/Hz",
        "f_hi/Hz",
        "bins",
        "raw",
        "expected",
        "cleaned",
        "witness",
        "cleaned/raw",
        "limit"
    );
    for b in &check.bands {
        let _ = writeln!(
            s,
            "         {:>9.3e} .. {:<9.3e} {:>5}  {:>10.3e} {:>10.3e} {:>10.3e} {:>10.3e}  \
             {:>11.4} {:>6.3}{}",
            b.lo_hz,
            band_top(b.hi_hz, fs_hz),
            b.bins,
            b.raw_psd.sqrt(),
            b.expected_psd.sqrt(),
            b.cleaned_psd.sqrt(),
            b.witness_limited_psd.sqrt(),
            b.ratio,
            b.limit,
            if b.left_raw { "  left raw" } else { "" }
        );
    }
}
