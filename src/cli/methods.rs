//! `tiltnoise methods`: every evaluation method's worst error against the double-double
//! reference and its time per point (table, JSON, chart).

use super::args::Format;
use super::figure_args::SizeArgs;
use super::output::save_image;
use super::Run;
use anyhow::Result;
use clap::Args;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tiltnoise_core::freq;
use tiltnoise_core::model::{Input, Model, Observable, Request};
use tiltnoise_core::params::Params;

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

/// One method's row of the JSON output (keys in alphabetical order, as documented).
#[derive(Serialize)]
struct MethodJson {
    exact_zeros: Option<bool>,
    max_rel_err: Option<f64>,
    name: &'static str,
    ns_per_point: Option<f64>,
    unusable: Option<String>,
    worst_entry: Option<String>,
    worst_freq_hz: Option<f64>,
}

/// The JSON output of `tiltnoise methods` (keys in alphabetical order).
#[derive(Serialize)]
struct MethodsJson<'a> {
    auto: String,
    grid: &'a str,
    methods: Vec<MethodJson>,
    target_rel_err: f64,
}

/// Runs `tiltnoise methods`.
pub(crate) fn run_methods(params: &Params, args: MethodsArgs, run: &mut Run) -> Result<()> {
    let MethodsArgs {
        freq: spec,
        inputs,
        format,
        save,
        figure,
    } = args;
    let (spec, save) = (spec.as_str(), save.as_slice());
    use tiltnoise_core::methods::methods_table;
    use tiltnoise_core::tf::{choose, Scene, DEFAULT_REL_TOL};
    for path in save {
        tiltnoise_plot::ImageFormat::from_path(path)?;
    }
    let view = figure.view_for(tiltnoise_plot::methods_figure::DEFAULT_SIZE)?;
    let saves: Vec<&Path> = save.iter().map(PathBuf::as_path).collect();
    run.check_outputs(&saves, &[])?;
    let out = &mut run.out;
    let model = Model::new(params)?;
    let grid = freq::parse_spec(spec)?;
    let request = Request {
        outputs: Observable::ALL.to_vec(),
        inputs: super::tf::parse_inputs(&inputs)?,
    };
    let matrix = matrix_label(&request);
    let band = (grid[0], grid[grid.len() - 1]);
    let auto = choose(
        &model,
        &Scene {
            request: request.clone(),
            band_hz: band,
            rel_tol: DEFAULT_REL_TOL,
        },
    )
    .map(|c| c.method.name().to_string())
    .unwrap_or_else(|refusal| format!("none ({refusal})"));
    let rows = methods_table(&model, &request, &grid);
    match format {
        Format::Json => {
            let methods = rows
                .iter()
                .map(|r| MethodJson {
                    name: r.method.name(),
                    max_rel_err: r.worst.as_ref().map(|w| w.0),
                    worst_entry: r.worst.as_ref().map(|w| w.1.clone()),
                    worst_freq_hz: r.worst.as_ref().map(|w| w.2),
                    ns_per_point: r.ns_per_point,
                    exact_zeros: r.exact_zeros,
                    unusable: r.unusable.clone(),
                })
                .collect();
            let json = MethodsJson {
                auto,
                target_rel_err: DEFAULT_REL_TOL,
                grid: spec,
                methods,
            };
            writeln!(out, "{}", serde_json::to_string_pretty(&json)?)?;
        }
        Format::Table => {
            writeln!(
                out,
                "{matrix} on {spec} Hz ({} points; accuracy checked > 1 % from every mode)",
                grid.len()
            )?;
            writeln!(
                out,
                "{:<9} {:>13} {:>14} {:>12} {:>12}  exact zeros",
                "method", "max rel err", "worst entry", "at (Hz)", "ns/point"
            )?;
            for r in &rows {
                match (&r.worst, r.ns_per_point) {
                    (Some((e, entry, f)), Some(ns)) => writeln!(
                        out,
                        "{:<9} {:>13.2e} {:>14} {:>12.4e} {:>12.0}  {}",
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
                    )?,
                    _ => writeln!(
                        out,
                        "{:<9} not usable: {}",
                        r.method.name(),
                        r.unusable.as_deref().unwrap_or("")
                    )?,
                }
            }
            writeln!(
                out,
                "auto picks: {auto} (target: relative error <= {DEFAULT_REL_TOL:e})"
            )?;
        }
    }
    let points: Vec<tiltnoise_plot::methods_figure::MethodPoint> = rows
        .iter()
        .filter_map(|r| {
            Some((
                r.method.name().to_string(),
                r.ns_per_point?,
                r.worst.as_ref()?.0,
            ))
        })
        .collect();
    // JSON on standard output stays parseable: the `wrote` lines go to standard error.
    run.write_outputs(format == Format::Json, || {
        for path in save {
            save_image(path, |format| {
                tiltnoise_plot::methods_figure::methods_figure(
                    &points,
                    DEFAULT_REL_TOL,
                    &format!("Speed against accuracy, {matrix}, {spec} Hz"),
                    &view,
                    format,
                )
            })?;
        }
        Ok(())
    })
}

/// `7x3 tilt matrix`, `7x6 ground matrix`, or the inputs named: what the table measures.
fn matrix_label(request: &Request) -> String {
    let size = format!("{}x{}", request.outputs.len(), request.inputs.len());
    let groups = [
        ("tilt", Input::all_tilts()),
        ("translation", Input::all_translations()),
        ("ground", Input::all_ground()),
    ];
    match groups.iter().find(|(_, inputs)| *inputs == request.inputs) {
        Some((name, _)) => format!("{size} {name} matrix"),
        None => {
            let names: Vec<&str> = request.inputs.iter().map(|i| i.name()).collect();
            format!("{size} matrix from {}", names.join(", "))
        }
    }
}
