//! `tiltnoise fit`: the command line of the fit job ([`tiltnoise_job::fit`]): argument
//! parsing, the request, the terminal table, and the job's JSON report and files (.json, .h5;
//! checked before the fit runs).

use super::Run;
use anyhow::Result;
use clap::{Args, ValueEnum};
use std::fmt::Write as _;
use std::path::PathBuf;
use tiltnoise_core::fit::{Bound, FitResult};
use tiltnoise_core::params::Params;
use tiltnoise_job::fit::FitRequest;
use tiltnoise_job::{Invocation, Outcome, Silent};

/// Arguments of `tiltnoise fit`.
#[derive(Debug, Args)]
pub(crate) struct FitArgs {
    /// Measured mode frequencies: CSV `mode,frequency_hz[,sigma_hz]` (any subset of modes
    /// 1..8; see docs/fit.md). Default: the measured column of Table II, or none with
    /// --visibility.
    #[arg(long = "measured-modes", alias = "measured", value_name = "FILE")]
    measured: Option<PathBuf>,
    /// Measured mode visibilities, fitted together with the frequencies: CSV
    /// `mode,observable,reference,ratio[,sigma]`, the signed ratio of mode nu_k's component in
    /// an observable to its component in a reference observable (docs/fit.md; `tiltnoise
    /// visibility` measures them from a free-motion record).
    #[arg(long, value_name = "FILE")]
    visibility: Option<PathBuf>,
    /// Free parameters, comma-separated dotted keys (default: k_a, k_b, kappa_a, kappa_b, Z,
    /// I^a_22, Z_b, d; see docs/fit.md).
    #[arg(long, value_name = "KEY,KEY,...", value_delimiter = ',')]
    free: Option<Vec<String>>,
    /// Box half-width in error bars: |p - p0| <= N sigma_p.
    #[arg(
        long,
        value_name = "N",
        default_value_t = 1.0,
        allow_negative_numbers = true
    )]
    bound_sigmas: f64,
    /// Add the Gaussian prior sum ((p - p0) / sigma_p)^2 to chi^2 (the box still applies).
    #[arg(long)]
    prior: bool,
    /// Output format on the terminal.
    #[arg(long, value_enum, default_value_t = FitFormat::Table)]
    format: FitFormat,
    /// Output file: .json (the JSON report) or .h5; repeatable.
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum FitFormat {
    Table,
    Json,
}

/// Runs `tiltnoise fit`: the options into the fit job's request, the job run, the report
/// printed and the files written.
pub(crate) fn run_fit(params: &Params, args: FitArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        tiltnoise_job::output_kind(path, tiltnoise_job::fit::OUTPUT_KINDS)?;
    }
    let req = FitRequest {
        params,
        measured: args.measured.clone(),
        visibility: args.visibility.clone(),
        free: args.free.clone(),
        bound_sigmas: args.bound_sigmas,
        prior: args.prior,
        invocation: Invocation::of_this_process(),
    };
    run.check_job_outputs(&args.save, req.input_files())?;
    let fit = tiltnoise_job::fit::run(&req, &run.cancel, &Silent).map_err(super::job_error)?;
    match args.format {
        FitFormat::Json => writeln!(run.out, "{}", serde_json::to_string_pretty(&fit.json())?)?,
        FitFormat::Table => write!(run.out, "{}", fit_table(&fit.result, &fit.origin))?,
    }
    // JSON on standard output stays parseable: the `wrote` lines go to standard error.
    run.write_outputs(args.format == FitFormat::Json, |stage| {
        for path in &args.save {
            fit.save(stage, path).map_err(super::job_error)?;
        }
        Ok(())
    })
}

/// The terminal report: the fit's header, the parameters, the modes and visibilities, the
/// correlations, the start and the weak directions.
fn fit_table(r: &FitResult, origin: &str) -> String {
    let mut s = String::new();
    header(&mut s, r, origin);
    parameters(&mut s, r);
    residuals(&mut s, r);
    correlations(&mut s, r);
    legend(&mut s, r);
    s
}

/// What was fitted to what, and how the solver ended.
fn header(s: &mut String, r: &FitResult, origin: &str) {
    let box_kind = match r.config.prior {
        true => "box + Gaussian prior",
        false => "box",
    };
    let _ = writeln!(
        s,
        "Fit of {} parameters to {} measured modes ({origin}){}; {box_kind} |p - p0| <= {} \
         sigma_p",
        r.params.len(),
        r.modes.len(),
        match r.visibilities.len() {
            0 => String::new(),
            n => format!(" and {n} visibilities"),
        },
        r.config.bound_sigmas
    );
    let _ = writeln!(
        s,
        "chi^2: nominal {} -> fitted {:.4e}, dof {}; {} iterations, stop: {} (projected \
         gradient {:.1e})",
        match r.chi2_nominal.is_finite() {
            true => format!("{:.4e}", r.chi2_nominal),
            false => "undefined (a visibility's reference does not see its mode there)".into(),
        },
        r.chi2,
        r.dof,
        r.iterations,
        r.stop.describe(),
        r.projected_gradient
    );
    let _ = writeln!(s);
}

/// The table of the free parameters.
fn parameters(s: &mut String, r: &FitResult) {
    let _ = writeln!(
        s,
        "{:<26} {:>12} {:>12} {:>11} {:>11} {:>6} {:>6}  unit",
        "parameter", "nominal", "fitted", "fit sigma", "prior sig", "bound", "poor"
    );
    for p in &r.params {
        let sigma = p
            .fitted_sigma
            .map_or("-".to_string(), |x| format!("{x:.3e}"));
        let _ = writeln!(
            s,
            "{:<26} {:>12.5e} {:>12.5e} {:>11} {:>11.3e} {:>6} {:>6}  {}",
            p.key,
            p.nominal,
            p.fitted,
            sigma,
            p.prior_sigma,
            p.at_bound.map_or("", Bound::name),
            if p.poorly_constrained { "yes" } else { "" },
            p.unit
        );
    }
    let _ = writeln!(s);
}

/// The tables of the modes and of the visibilities: measured, nominal, fitted, residual.
fn residuals(s: &mut String, r: &FitResult) {
    if !r.modes.is_empty() {
        let _ = writeln!(
            s,
            "{:<5} {:>13} {:>11} {:>13} {:>13} {:>12} {:>10}",
            "mode", "measured Hz", "sigma Hz", "nominal Hz", "fitted Hz", "resid Hz", "resid/sig"
        );
    }
    for m in &r.modes {
        let _ = writeln!(
            s,
            "nu_{:<2} {:>13.6e} {:>11.1e} {:>13.6e} {:>13.6e} {:>12.3e} {:>10.2}",
            m.measured.mode,
            m.measured.frequency_hz,
            m.measured.sigma_hz,
            m.nominal_hz,
            m.fitted_hz,
            m.residual_hz(),
            m.residual_sigmas()
        );
    }
    if r.visibilities.is_empty() {
        return;
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:<5} {:<13} {:>13} {:>11} {:>13} {:>13} {:>10}",
        "mode", "ratio", "measured", "sigma", "nominal", "fitted", "resid/sig"
    );
    for v in &r.visibilities {
        let _ = writeln!(
            s,
            "nu_{:<2} {:<13} {:>13.5e} {:>11.2e} {:>13.5e} {:>13.5e} {:>10.2}",
            v.measured.mode,
            format!(
                "{}/{}",
                v.measured.observable.name(),
                v.measured.reference.name()
            ),
            v.measured.ratio,
            v.measured.sigma,
            v.nominal,
            v.fitted,
            v.residual_sigmas()
        );
    }
}

/// The correlation matrix, and where the fit started when away from the nominal point.
fn correlations(s: &mut String, r: &FitResult) {
    if r.params.len() > 1 {
        let _ = writeln!(s);
        let _ = writeln!(s, "correlations (linearized covariance; - on a bound):");
        for (i, p) in r.params.iter().enumerate() {
            let row: Vec<String> = r.correlation[i]
                .iter()
                .map(|c| match c.is_finite() {
                    true => format!("{c:>7.3}"),
                    false => format!("{:>7}", "-"),
                })
                .collect();
            let _ = writeln!(s, "{:<26} {}", p.key, row.join(" "));
        }
    }
    let start: Vec<String> = r
        .params
        .iter()
        .zip(&r.start)
        .filter(|(p, s0)| **s0 != p.nominal)
        .map(|(p, s0)| format!("{} = {s0:e}", p.key))
        .collect();
    if !start.is_empty() {
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "start: away from the symmetric point, the best of the starts was {}",
            start.join(", ")
        );
    }
}

/// What `bound` and `poor` mean, and the weak directions.
fn legend(s: &mut String, r: &FitResult) {
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "bound: the parameter ended on the box (no sigma: the linearized covariance does not \
         apply there)."
    );
    let _ = writeln!(
        s,
        "poor: the data alone determine it no better than its error bar (data sigma >= prior \
         sigma)."
    );
    if r.weak_directions.is_empty() {
        let _ = writeln!(
            s,
            "No weak direction: every singular value of the weighted Jacobian is >= 1 \
             (smallest {:.3e}).",
            r.singular_values.last().copied().unwrap_or(f64::NAN)
        );
    }
    for w in &r.weak_directions {
        let mut comps: Vec<&(String, f64)> = w.direction.iter().collect();
        comps.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()));
        let text: Vec<String> = comps
            .iter()
            .filter(|(_, c)| c.abs() >= 0.1)
            .map(|(k, c)| format!("{c:+.2} {k}"))
            .collect();
        let _ = writeln!(
            s,
            "weak direction (singular value {:.3e} < 1, known to {:.2} error bars): {}",
            w.singular_value,
            1.0 / w.singular_value,
            text.join(" ")
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::report::assert_keys_sorted;
    use tiltnoise_job::fit::FitOutcome;

    #[test]
    fn json_lists_keys_alphabetically() {
        let req = FitRequest {
            params: &Params::table_i(),
            measured: None,
            visibility: None,
            free: None,
            bound_sigmas: 1.0,
            prior: false,
            invocation: Invocation::default(),
        };
        let fit: FitOutcome =
            tiltnoise_job::fit::run(&req, &tiltnoise_job::Cancel::never(), &Silent).unwrap();
        let text = serde_json::to_string_pretty(&fit.json()).unwrap();
        let value = assert_keys_sorted(&text);
        assert_eq!(value["measured_origin"], "embedded Table II");
    }
}
