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
use super::progress::Bar;
use super::Run;
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use tiltnoise_core::freq;
use tiltnoise_core::limits::MAX_STREAMED_GRID_POINTS;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::planner::DEFAULT_REL_TOL;
use tiltnoise_core::tf::{Input, Request};
use tiltnoise_job::figures::{tf_figure_size, TfFigureOptions};
use tiltnoise_job::files::{OutputKind, Staging};
use tiltnoise_job::modes::ModesRequest;
use tiltnoise_job::tf::{FreqGrid, TfRequest, TfText};
use tiltnoise_job::{Invocation, JobError, Outcome};

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
fn figure_options(args: &TfArgs, request: &Request, model: &Model) -> Result<TfFigureOptions> {
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
    let options = tiltnoise_job::tf::figure_options(
        model,
        observables,
        args.phase,
        crate::option_style::rendered(&OptionKey::DRAWN_OBSERVABLES),
    );
    let size = tf_figure_size(&options, &request.inputs);
    Ok(TfFigureOptions {
        view: args.figure.view_for(size)?,
        ..options
    })
}

/// The request of the transfer-function job from the options.
fn request<'a>(
    args: &TfArgs,
    model: &'a Model,
    request: Request,
    figure_options: TfFigureOptions,
) -> Result<TfRequest<'a>> {
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
        figure_options,
        invocation: Invocation::of_this_process(),
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
        tiltnoise_job::output_kind(path, tiltnoise_job::tf::OUTPUT_KINDS)?;
    }
    let model = Model::new(params)?;
    let figure = figure_options(&args, &request_names, &model)?;
    let req = request(&args, &model, request_names, figure)?;
    run.check_job_outputs(&args.save, req.input_files())?;
    let has_figure = req.figure.is_some();
    let planned = match tiltnoise_job::tf::prepare(&req) {
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
    let json = args.format == Format::Json;
    let bar = Bar::new("frequencies", TF_WORTH_A_BAR);
    if has_figure {
        let outcome = planned
            .outcome(&run.cancel, &bar)
            .map_err(super::job_error)?;
        write_report(&mut run.out, &model, planned.request(), json)?;
        return run.write_outputs(json, |stage| {
            for path in &args.save {
                outcome.save(stage, path).map_err(super::job_error)?;
            }
            Ok(())
        });
    }
    // Streamed: every block into every file (or onto standard output) as it is computed.
    let to_stdout = args.save.is_empty();
    let text = to_stdout.then_some(match json {
        true => TfText::Json,
        false => TfText::Csv,
    });
    let stage = Staging::new();
    let cancel = run.cancel.clone();
    let out = &mut run.out;
    planned
        .stream(&args.save, &stage, text, &cancel, &bar, |chunk| {
            write!(out, "{chunk}").map_err(|e| Streamed(e.into()))
        })
        .map_err(|e| e.0)?;
    if to_stdout {
        return Ok(());
    }
    write_report(&mut run.out, &model, planned.request(), json)?;
    run.commit_outputs(stage, json)
}

/// Grids with at least this many points get a progress bar on a terminal (about 2 s).
const TF_WORTH_A_BAR: u64 = 1 << 19;

/// The modes table and, for tilt inputs, the static limits, for translations their limits per
/// unit acceleration (printed when files are saved); with `json`, the modes as JSON (the
/// modes job's).
fn write_report(
    out: &mut super::stdout::Out,
    model: &Model,
    request: &Request,
    json: bool,
) -> Result<()> {
    let modes = tiltnoise_job::modes::run(
        &ModesRequest {
            model,
            invocation: Invocation::of_this_process(),
        },
        &tiltnoise_core::cancel::Cancel::never(),
        &tiltnoise_job::Silent,
    )
    .map_err(super::job_error)?;
    if json {
        writeln!(out, "{}", serde_json::to_string_pretty(&modes.json())?)?;
        return Ok(());
    }
    write!(out, "{}", super::report::modes_table(&modes.modes))?;
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

/// An error of the streamed evaluation: the job's errors with their one-line message (as
/// [`super::job_error`] gives it, not followed by their sources), the writers' as they are.
struct Streamed(anyhow::Error);

impl From<tiltnoise_job::JobError> for Streamed {
    fn from(e: tiltnoise_job::JobError) -> Streamed {
        Streamed(super::job_error(e))
    }
}
