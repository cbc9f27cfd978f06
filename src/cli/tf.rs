//! `tiltnoise tf`: transfer functions from floor tilt and from external forces and torques to the
//! observables, on a frequency grid, with the same outputs (CSV, HDF5, figures) and methods for
//! every kind of input.
//!
//! Inputs are named as in files: the tilt angles `theta_t`, `eta_t`, `phi_t` (rad), the floor's
//! translations `x_t`, `y_t`, `z_t` (m, along the lab axes: the crossbar arm along y), and the
//! twelve components `F_a.x` .. `M_b.z` of the forces (N, applied at the centres of mass) and
//! torques (N m, about the centres of mass) on the crossbar (`a`) and the test mass (`b`),
//! inertial axes (Appendix A of the paper, zeroth order). Observables: `X`, `Y`, `Z` (m), `theta`,
//! `eta`, `phi`, `phi_a` (rad). Entries are complex responses per unit input: m/rad, rad/rad,
//! m/m, rad/m, m/N, rad/(N m), ...

use super::args::{scientific, Format, MethodArg, PerArg};
use super::figure_args::FigureArgs;
use super::Run;
use anyhow::{bail, Result};
use clap::Args;
use std::io::IsTerminal;
use std::path::PathBuf;
use tiltnoise_core::freq;
use tiltnoise_core::limits::MAX_STREAMED_GRID_POINTS;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::planner::DEFAULT_REL_TOL;
use tiltnoise_core::tf::{Input, Request, TransferMatrix};
use tiltnoise_io::{OutputKind, RunMeta, TfCsvWriter, TfHdf5Writer};
use tiltnoise_job::tf::{FreqGrid, Planned, TfRequest};
use tiltnoise_job::JobError;

/// Arguments of `tiltnoise tf`.
#[derive(Debug, Args)]
pub struct TfArgs {
    /// Log-spaced grid FLO:N:FHI (Hz:count:Hz), e.g. 1e-4:2000:30, or one frequency F (Hz).
    /// Default: 0.1 mHz to 30 Hz, 2000 points, plus points around every resonance.
    #[arg(
        long,
        value_name = "FLO:N:FHI|F",
        conflicts_with = "freq_file",
        allow_hyphen_values = true
    )]
    freq: Option<String>,
    /// File with one frequency in Hz per line (# comments allowed).
    #[arg(long, value_name = "FILE")]
    freq_file: Option<PathBuf>,
    /// Inputs (columns), comma-separated and/or repeated: tilt angles theta_t, eta_t, phi_t
    /// (rad); floor translations x_t, y_t, z_t (m; the crossbar arm along y); force components
    /// F_a.x, F_a.y, F_a.z, F_b.x, F_b.y, F_b.z (N) and torque components M_a.x .. M_b.z (N m)
    /// on the crossbar (a) and the test mass (b); the groups `tilt` (the three tilt angles),
    /// `translation` (the three translations), `ground` (tilt and translation) and `forces`
    /// (all twelve components). Default: tilt.
    #[arg(long = "input", value_name = "NAME[,NAME...]")]
    inputs: Vec<String>,
    /// Express the transfer functions from the floor's motion (tilt and translation inputs) per
    /// unit of its displacement (rad, m), velocity (rad/s, m/s) or acceleration (rad/s^2,
    /// m/s^2): the response per unit displacement times 1/(i w) or -1/w^2. Force and torque
    /// inputs stay per N and N m. Velocity and acceleration need frequencies above 0 Hz.
    #[arg(long, value_enum, default_value_t = PerArg::Displacement)]
    per: PerArg,
    /// Observables (rows), comma-separated and/or repeated: X, Y, Z (m), theta, eta, phi, phi_a
    /// (rad). Default: all seven.
    #[arg(long = "observables", alias = "output", value_name = "OBS,...")]
    outputs: Vec<String>,
    /// Output file, format from the extension: .h5 (all numbers), .csv, .png/.svg (|H| per
    /// observable, one panel per kind of input: tilt, translation, forces, torques; tilt alone
    /// is the paper's Figure 5). Repeatable. Without --save the CSV goes to stdout.
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
    /// Evaluation method.
    #[arg(long, value_enum, default_value_t = MethodArg::Auto)]
    method: MethodArg,
    /// Relative tolerance for `--method auto`: the smallest model and cheapest method whose
    /// measured error against the double-double reference on the grid's band is at most this.
    #[arg(
        long,
        value_name = "REL",
        default_value = scientific(DEFAULT_REL_TOL),
        allow_negative_numbers = true
    )]
    rel_tol: f64,
    /// Frequencies evaluated and written per block (default 16384). Without a figure the
    /// grid is computed and written block by block, in memory that does not grow with it
    /// (`--freq` up to 10^8 points); the numbers do not depend on the block size.
    #[arg(long, value_name = "N")]
    block_freqs: Option<usize>,
    /// Say which method `auto` picked and why, or why none qualifies (every candidate's
    /// measured error, on standard error).
    #[arg(long)]
    explain: bool,
    /// Observables drawn in the figures, a subset of --observables (default: every one of
    /// --observables; without either option X, phi, phi_a as the paper's Figure 5).
    #[arg(long, value_name = "OBS,...")]
    plot_observables: Vec<String>,
    /// Bode figure: a phase panel (degrees) beside every magnitude panel.
    #[arg(long)]
    phase: bool,
    /// Output format on the terminal: table (default; the transfer functions as CSV rows
    /// without --save, else the modes and the static limits) or json (the transfer functions
    /// as one JSON document without --save, else the modes as `modes --format json` prints
    /// them, the `wrote` lines then on standard error).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    #[command(flatten)]
    figure: FigureArgs,
}

/// Parses `--input` values (see [`TfArgs`]); empty means the three tilt angles.
pub fn parse_inputs(specs: &[String]) -> Result<Vec<Input>> {
    Ok(options::parse_inputs(OptionKey::INPUTS, specs)?)
}

/// Parses `--observables` values (see [`TfArgs`]); empty means all seven observables.
pub fn parse_observables(specs: &[String]) -> Result<Vec<Observable>> {
    Ok(options::parse_outputs(OptionKey::OUTPUTS, specs)?)
}

/// The figure's options: panels from `--plot-observables` (each one of the computed
/// observables), else every one of `--observables`, else the paper's Figure 5 (X, phi, phi_a);
/// phase, limits, size, resolution.
fn figure_options(
    args: &TfArgs,
    request: &Request,
    model: &Model,
) -> Result<tiltnoise_plot::TfFigureOptions> {
    let mut given = args.figure.given();
    if !args.plot_observables.is_empty() {
        given.insert(0, "--plot-observables");
    }
    if args.phase {
        given.insert(0, "--phase");
    }
    super::figure_args::refuse_without_figure(&given, &args.save)?;
    let observables = if !args.plot_observables.is_empty() {
        let chosen = options::parse_outputs(OptionKey::DRAWN_OBSERVABLES, &args.plot_observables)?;
        if let Some(o) = chosen.iter().find(|o| !request.outputs.contains(o)) {
            let have: Vec<&str> = request.outputs.iter().map(|o| o.name()).collect();
            bail!(
                "--plot-observables: {} is not among the computed observables ({}); add it to \
                 --observables",
                o.name(),
                have.join(", ")
            );
        }
        chosen
    } else if !args.outputs.is_empty() {
        request.outputs.clone()
    } else {
        tiltnoise_job::tf::FIGURE5_OBSERVABLES.to_vec()
    };
    let options = tiltnoise_job::tf::figure_options(model, observables, args.phase);
    let size = tiltnoise_plot::tf_figure::default_size(&options, &request.inputs);
    Ok(tiltnoise_plot::TfFigureOptions {
        view: args.figure.view_for(size)?,
        ..options
    })
}

/// The request of the transfer-function job from the options.
fn request<'a>(args: &TfArgs, model: &'a Model, request: Request) -> Result<TfRequest<'a>> {
    let grid = match (&args.freq, &args.freq_file) {
        (Some(spec), _) => FreqGrid::Log(freq::parse_log_spec(spec, MAX_STREAMED_GRID_POINTS)?),
        (None, Some(path)) => FreqGrid::File(path.clone()),
        (None, None) => FreqGrid::Default,
    };
    let figure = args.save.iter().find(|p| {
        matches!(
            OutputKind::from_path(p),
            Ok(OutputKind::Png | OutputKind::Svg)
        )
    });
    Ok(TfRequest {
        model,
        request,
        grid,
        per: args.per.quantity(),
        method: args.method.fixed(),
        rel_tol: Some(args.rel_tol),
        block_freqs: args.block_freqs,
        figure: figure.cloned(),
    })
}

/// Runs `tiltnoise tf`: the options parsed into the job's request, the job planned (the
/// planner's reasoning on standard error with --explain), then the grid evaluated whole for a
/// figure, else block by block into every file (or standard output) as it is computed.
pub(crate) fn run_tf(params: &Params, args: TfArgs, run: &mut Run) -> Result<()> {
    let request_names = Request {
        outputs: parse_observables(&args.outputs)?,
        inputs: parse_inputs(&args.inputs)?,
    };
    tiltnoise_job::tf::rel_tol(Some(args.rel_tol)).map_err(super::job_error)?;
    // Check every output before computing, so a typo costs nothing.
    for path in &args.save {
        OutputKind::from_path(path)?;
    }
    let model = Model::new(params)?;
    let figure = figure_options(&args, &request_names, &model)?;
    let req = request(&args, &model, request_names)?;
    run.check_job_outputs(&args.save, req.input_files())?;
    let has_figure = req.figure.is_some();
    let planned = match tiltnoise_job::tf::prepare(req) {
        Ok(planned) => planned,
        Err(JobError::NoMethod(refusal)) if args.explain => {
            super::note(&refusal.explain());
            bail!("{refusal}");
        }
        Err(e) => return Err(super::job_error(e)),
    };
    if let (Some(choice), true) = (&planned.choice, args.explain) {
        super::note(&choice.explain());
    }
    let modes = NormalModes::new(&model);
    let meta = RunMeta::of_this_run(params, Some(&modes));
    let json = args.format == Format::Json;
    if !has_figure {
        return stream_tf(&planned, &args, &model, &meta, run);
    }
    let tf = planned.whole(&run.cancel).map_err(super::job_error)?;
    write_report(&mut run.out, &model, &modes, planned.request(), json)?;
    run.write_outputs(json, |stage| {
        for path in &args.save {
            tiltnoise_job::tf::save(stage, path, &tf, &meta, &figure)?;
        }
        Ok(())
    })
}

/// Grids with at least this many points get a progress bar on a terminal (about 2 s).
const TF_WORTH_A_BAR: usize = 1 << 19;

/// The modes table and, for tilt inputs, the static limits, for translations their limits per
/// unit acceleration (printed when files are saved); with `json`, the modes as JSON.
fn write_report(
    out: &mut super::stdout::Out,
    model: &Model,
    modes: &NormalModes,
    request: &Request,
    json: bool,
) -> Result<()> {
    if json {
        writeln!(out, "{}", super::report::modes_json(model, modes))?;
        return Ok(());
    }
    write!(out, "{}", super::report::modes_table(modes))?;
    if request.inputs.iter().any(|i| matches!(i, Input::Tilt(_))) {
        writeln!(out)?;
        write!(out, "{}", super::report::static_limits(model))?;
    }
    if request
        .inputs
        .iter()
        .any(|i| matches!(i, Input::Translation(_)))
    {
        writeln!(out)?;
        write!(out, "{}", super::report::translation_limits(model))?;
    }
    Ok(())
}

/// Evaluates the grid block by block and writes each block to every HDF5 and CSV output (or
/// to standard output, as CSV or JSON, without --save) before the next is computed.
fn stream_tf(
    planned: &Planned,
    args: &TfArgs,
    model: &Model,
    meta: &RunMeta,
    run: &mut Run,
) -> Result<()> {
    let mut hdf5 = Vec::new();
    let mut csv = Vec::new();
    for path in &args.save {
        match OutputKind::from_path(path)? {
            OutputKind::Hdf5 => hdf5.push(TfHdf5Writer::create(path, meta)?),
            OutputKind::Csv => csv.push(TfCsvWriter::create(path, meta)?),
            OutputKind::Png | OutputKind::Svg => unreachable!("figures are drawn from memory"),
        }
    }
    let n = planned.len();
    let bar = (n >= TF_WORTH_A_BAR && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new(n as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} {wide_bar} {pos}/{len} frequencies ({percent}%, eta {eta})",
            )
            .expect("valid template"),
        );
        b
    });
    let json = args.format == Format::Json;
    let to_stdout = args.save.is_empty();
    let mut text = String::new();
    let cancel = run.cancel.clone();
    planned
        .blocks(
            &cancel,
            |block, done| -> std::result::Result<(), Streamed> {
                let mut write = || -> Result<()> {
                    for w in &mut hdf5 {
                        w.append(block)?;
                    }
                    for w in &mut csv {
                        w.append(block)?;
                    }
                    if to_stdout {
                        text.clear();
                        let first = done == block.freqs_hz.len();
                        match (json, first) {
                            (true, true) => text.push_str(&json_head(block, planned)),
                            (false, true) => {
                                text.push_str(&tiltnoise_io::tf_csv_header(block, meta))
                            }
                            _ => {}
                        }
                        match json {
                            true => push_json_points(&mut text, block, first),
                            false => tiltnoise_io::push_tf_csv_rows(&mut text, block),
                        }
                        if json && done == n {
                            text.push_str(&json_tail(block));
                        }
                        write!(run.out, "{text}")?;
                    }
                    if let Some(b) = &bar {
                        b.set_position(done as u64);
                    }
                    Ok(())
                };
                write().map_err(Streamed)
            },
        )
        .map_err(|e| e.0)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if to_stdout {
        return Ok(());
    }
    let modes = NormalModes::new(model);
    write_report(&mut run.out, model, &modes, planned.request(), json)?;
    run.write_outputs(json, |stage| {
        for w in hdf5 {
            w.finish(stage)?;
        }
        for w in csv {
            w.finish(stage)?;
        }
        Ok(())
    })
}

/// A JSON value written by serde (a number that is not finite is `null`).
fn json_value(v: impl serde::Serialize) -> String {
    serde_json::to_string(&v).expect("JSON of plain data")
}

/// The keys of the JSON document before its points (keys in alphabetical order, as every JSON
/// report): `inputs`, `method`, `observables`, `per`, then `points` opened.
fn json_head(block: &TransferMatrix, planned: &Planned) -> String {
    let names = |v: Vec<&str>| json_value(v);
    format!(
        "{{\n  \"inputs\": {},\n  \"method\": {},\n  \"observables\": {},\n  \"per\": {},\n  \
         \"points\": [",
        names(block.inputs.iter().map(|i| i.name()).collect()),
        json_value(planned.method().name()),
        names(block.outputs.iter().map(|o| o.name()).collect()),
        json_value(block.ground_quantity().name()),
    )
}

/// One line per frequency: `{"H": [[[re, im] per input] per observable], "frequency_hz": f}`.
fn push_json_points(s: &mut String, block: &TransferMatrix, first: bool) {
    let (no, ni) = (block.outputs.len(), block.inputs.len());
    for (k, &f) in block.freqs_hz.iter().enumerate() {
        let h: Vec<Vec<[f64; 2]>> = (0..no)
            .map(|o| {
                (0..ni)
                    .map(|i| {
                        let z = block.get(k, o, i);
                        [z.re, z.im]
                    })
                    .collect()
            })
            .collect();
        let comma = if first && k == 0 { "" } else { "," };
        s.push_str(&format!(
            "{comma}\n    {{\"H\": {}, \"frequency_hz\": {}}}",
            json_value(h),
            json_value(f)
        ));
    }
}

/// The end of the JSON document: the points closed, then `units` (per observable, per input).
fn json_tail(block: &TransferMatrix) -> String {
    let units: Vec<Vec<String>> = (0..block.outputs.len())
        .map(|o| (0..block.inputs.len()).map(|i| block.unit(o, i)).collect())
        .collect();
    format!("\n  ],\n  \"units\": {}\n}}\n", json_value(units))
}

/// An error of the streamed evaluation: the job's errors with their one-line message (as
/// [`super::job_error`] gives it, not followed by their sources), the writers' as they are.
struct Streamed(anyhow::Error);

impl From<tiltnoise_job::JobError> for Streamed {
    fn from(e: tiltnoise_job::JobError) -> Streamed {
        Streamed(super::job_error(e))
    }
}
