//! `tiltnoise methods`: every evaluation method's worst error against the double-double
//! reference and its time per point (table, JSON, chart), measured by the methods job.

use super::args::Format;
use super::figure_args::SizeArgs;
use super::Run;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};
use tiltnoise_core::freq;
use tiltnoise_core::model::Model;
use tiltnoise_core::params::Params;
use tiltnoise_job::figures::METHODS_FIGURE_SIZE;
use tiltnoise_job::methods::{MethodsOutcome, MethodsRequest};
use tiltnoise_job::{Invocation, Outcome};

/// Arguments of `tiltnoise methods`.
#[derive(Debug, Args)]
pub struct MethodsArgs {
    /// Log grid FLO:N:FHI (Hz:count:Hz).
    #[arg(
        long,
        value_name = "FLO:N:FHI",
        default_value = "1e-5:400:100",
        allow_hyphen_values = true
    )]
    freq: String,
    /// Inputs of the matrix, as `tf --input` takes them (names or the groups `tilt`,
    /// `translation`, `ground`, `forces`). Default: tilt.
    #[arg(long = "input", value_name = "NAME[,NAME...]")]
    inputs: Vec<String>,
    /// Output format on the terminal.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Chart of time per point against error (.png or .svg), repeatable.
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
    // Size and resolution of the chart (its axes follow the results).
    #[command(flatten)]
    figure: SizeArgs,
}

/// Runs `tiltnoise methods`: the grid and inputs parsed into the methods job's request, the
/// job run, the table or JSON printed and the chart saved.
pub(crate) fn run_methods(params: &Params, args: MethodsArgs, run: &mut Run) -> Result<()> {
    let MethodsArgs {
        freq: spec,
        inputs,
        format,
        save,
        figure,
    } = args;
    let (spec, save) = (spec.as_str(), save.as_slice());
    for path in save {
        tiltnoise_job::figures::image_format(path)?;
    }
    figure.refuse_without_figure(save)?;
    let view = figure.view_for(METHODS_FIGURE_SIZE)?;
    let saves: Vec<&Path> = save.iter().map(PathBuf::as_path).collect();
    run.check_outputs(&saves, &[])?;
    let model = Model::new(params)?;
    let req = MethodsRequest {
        model: &model,
        grid_hz: freq::parse_spec(spec)?,
        inputs: Some(super::tf::parse_inputs(&inputs)?),
        grid_spec: spec.to_string(),
        view,
        invocation: Invocation::of_this_process(),
    };
    let result = tiltnoise_job::methods::run(&req, &run.cancel, &tiltnoise_job::Silent)
        .map_err(super::job_error)?;
    let out = &mut run.out;
    match format {
        Format::Json => writeln!(out, "{}", serde_json::to_string_pretty(&result.json())?)?,
        Format::Table => write!(out, "{}", table(&result, spec))?,
    }
    // JSON on standard output stays parseable: the `wrote` lines go to standard error.
    run.write_outputs(format == Format::Json, |stage| {
        for path in save {
            result.save(stage, path).map_err(super::job_error)?;
        }
        Ok(())
    })
}

/// The table of the grid `spec`.
fn table(result: &MethodsOutcome, spec: &str) -> String {
    let mut s = format!(
        "{} on {spec} Hz ({} points; accuracy checked > 1 % from every mode)\n",
        result.matrix_label(),
        result.grid_hz.len()
    );
    s.push_str(&format!(
        "{:<9} {:>13} {:>14} {:>12} {:>12}  exact zeros\n",
        "method", "max rel err", "worst entry", "at (Hz)", "ns/point"
    ));
    for r in &result.rows {
        match (&r.worst, r.ns_per_point) {
            (Some((e, entry, f)), Some(ns)) => s.push_str(&format!(
                "{:<9} {:>13.2e} {:>14} {:>12.4e} {:>12.0}  {}\n",
                r.method.name(),
                e,
                entry,
                f,
                ns,
                if r.exact_zeros == Some(true) {
                    "yes"
                } else {
                    "no"
                }
            )),
            _ => s.push_str(&format!(
                "{:<9} not usable: {}\n",
                r.method.name(),
                r.unusable.as_deref().unwrap_or("")
            )),
        }
    }
    s.push_str(&format!(
        "auto picks: {} (target: relative error <= {:e})\n",
        result.auto_text(),
        result.target_rel_err
    ));
    s
}
