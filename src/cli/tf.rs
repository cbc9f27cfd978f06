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

use super::args::{scientific, MethodArg, PerArg};
use super::figure_args::FigureArgs;
use super::output::save_tf;
use super::Run;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use tiltnoise_core::freq;
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::limits::{MAX_GRID_POINTS, MAX_STREAMED_GRID_POINTS};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::tf::planner::{choose, NoChoice, Scene, DEFAULT_REL_TOL};
use tiltnoise_core::tf::{self, Input, Request};
use tiltnoise_io::{read_freq_file, RunMeta};

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
    #[command(flatten)]
    figure: FigureArgs,
}

/// Parses `--input` values (see [`TfArgs`]); empty means the three tilt angles.
pub fn parse_inputs(specs: &[String]) -> Result<Vec<Input>> {
    Ok(options::parse_inputs("--input", specs)?)
}

/// Parses `--observables` values (see [`TfArgs`]); empty means all seven observables.
pub fn parse_observables(specs: &[String]) -> Result<Vec<Observable>> {
    Ok(options::parse_outputs("--observables", specs)?)
}

/// The figure's options: panels from `--plot-observables` (each one of the computed
/// observables), else every one of `--observables`, else the paper's Figure 5 (X, phi, phi_a);
/// phase, limits, size, resolution.
fn figure_options(
    args: &TfArgs,
    request: &Request,
    params: &Params,
) -> Result<tiltnoise_plot::TfFigureOptions> {
    let observables = if !args.plot_observables.is_empty() {
        let chosen = options::parse_outputs("--plot-observables", &args.plot_observables)?;
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
        vec![Observable::X, Observable::Phi, Observable::PhiA]
    };
    let options = tiltnoise_plot::TfFigureOptions {
        observables: Some(observables),
        phase: args.phase,
        damped: !Model::new(params)?.is_undamped(),
        view: tiltnoise_plot::View::default(),
        note: None,
    };
    let size = tiltnoise_plot::tf_figure::default_size(&options, &request.inputs);
    Ok(tiltnoise_plot::TfFigureOptions {
        view: args.figure.view_for(size)?,
        ..options
    })
}

/// Runs `tiltnoise tf`.
pub(crate) fn run_tf(params: &Params, args: TfArgs, run: &mut Run) -> Result<()> {
    let request = Request {
        outputs: parse_observables(&args.outputs)?,
        inputs: parse_inputs(&args.inputs)?,
    };
    if !(args.rel_tol.is_finite() && args.rel_tol > 0.0 && args.rel_tol < 1.0) {
        bail!(
            "--rel-tol {}: the tolerance must be a finite relative error in (0, 1)",
            args.rel_tol
        );
    }
    // Check every output before computing, so a typo costs nothing.
    for path in &args.save {
        tiltnoise_io::OutputKind::from_path(path)?;
    }
    let figure = figure_options(&args, &request, params)?;
    let saves: Vec<&Path> = args.save.iter().map(PathBuf::as_path).collect();
    let inputs: Vec<(&str, &Path)> = args
        .freq_file
        .iter()
        .map(|p| ("--freq-file", p.as_path()))
        .collect();
    run.check_outputs(&saves, &inputs)?;
    let block_freqs = match args.block_freqs {
        Some(0) => bail!("--block-freqs 0: a block must hold at least 1 frequency"),
        Some(b) => b,
        None => TF_BLOCK_FREQS,
    };
    let figure_path = args.save.iter().find(|p| {
        matches!(
            tiltnoise_io::OutputKind::from_path(p),
            Ok(tiltnoise_io::OutputKind::Png | tiltnoise_io::OutputKind::Svg)
        )
    });
    let per = args.per.quantity();
    let model = Model::new(params)?;
    let grid = match (&args.freq, &args.freq_file) {
        (Some(spec), _) => Grid::Log(freq::parse_log_spec(spec, MAX_STREAMED_GRID_POINTS)?),
        (None, Some(path)) => Grid::Points(read_freq_file(path)?),
        (None, None) => Grid::Points(freq::default_grid(&model)),
    };
    if let (Grid::Points(freqs), Some(path)) = (&grid, &args.freq_file) {
        let ground = request.inputs.iter().any(|i| i.is_ground());
        if let Some(k) = freqs.iter().position(|&f| per.to_displacement(f).is_none()) {
            if ground {
                bail!(
                    "--per {q}: frequency {} of {} is 0 Hz, where a transfer function per unit \
                     floor {q} has no value (a {q} carries no displacement at DC); use \
                     frequencies above 0 Hz",
                    k + 1,
                    path.display(),
                    q = per.name(),
                );
            }
        }
    }
    if let (Some(path), Grid::Log(g)) = (figure_path, &grid) {
        if g.len() > MAX_GRID_POINTS {
            bail!(
                "--save {}: a figure is drawn from at most {MAX_GRID_POINTS} frequency points \
                 and --freq asks for {}; draw it from a smaller grid (the default grid \
                 resolves every resonance) and write the large one to .h5 or .csv only (see \
                 docs/limits.md)",
                path.display(),
                g.len()
            );
        }
    }
    let method = match args.method.fixed() {
        Some(m) => m,
        None => {
            let band = grid.positive_band();
            let scene = Scene {
                request: request.clone(),
                band_hz: band,
                rel_tol: args.rel_tol,
            };
            let choice = match choose(&model, &scene) {
                Ok(choice) => choice,
                Err(refusal) if args.explain => {
                    super::note(&refusal.explain());
                    return Err(refusal.into());
                }
                Err(refusal @ NoChoice::Tolerance { .. }) => {
                    bail!("{refusal}; run with --explain for every candidate")
                }
                Err(refusal @ NoChoice::NearMode { .. }) => {
                    bail!("{refusal} (--method polezero, or another --freq)")
                }
                Err(refusal) => return Err(refusal.into()),
            };
            if args.explain {
                super::note(&choice.explain());
            }
            choice.method
        }
    };
    let plan = tf::plan(&model, &request, method)?;
    let modes = NormalModes::new(&model);
    let meta = RunMeta::of_this_run(params, Some(&modes));
    if figure_path.is_none() {
        return stream_tf(plan.as_ref(), &grid, block_freqs, &args, &model, &meta, run);
    }
    let freqs = grid.block(0, grid.len());
    let tf = tf::evaluate(plan.as_ref(), &freqs)
        .and_then(|tf| per_unit(tf, per))
        .context("evaluating the transfer functions")?;
    write_report(&mut run.out, &model, &modes, &request)?;
    run.write_outputs(false, || {
        for path in &args.save {
            save_tf(path, &tf, &meta, &figure)?;
        }
        Ok(())
    })
}

/// `tf` with the floor's motion per unit `per` (as it is when `per` is the displacement).
fn per_unit(
    tf: tf::TransferMatrix,
    per: GroundQuantity,
) -> Result<tf::TransferMatrix, tiltnoise_core::error::TfError> {
    match per {
        GroundQuantity::Displacement => Ok(tf),
        _ => tf.per_ground_quantity(per),
    }
}

/// Frequencies per block of a streamed grid: 16384 points of the largest request (7 x 15
/// complex values) are 27 MB with the CSV text of the block.
const TF_BLOCK_FREQS: usize = 1 << 14;

/// Grids with at least this many points get a progress bar on a terminal (about 2 s).
const TF_WORTH_A_BAR: usize = 1 << 19;

/// A frequency grid: held (a file, the default grid) or computed point by point (`--freq`).
enum Grid {
    Points(Vec<f64>),
    Log(freq::LogGrid),
}

impl Grid {
    fn len(&self) -> usize {
        match self {
            Grid::Points(v) => v.len(),
            Grid::Log(g) => g.len(),
        }
    }

    fn block(&self, start: usize, len: usize) -> Vec<f64> {
        match self {
            Grid::Points(v) => {
                let end = start.saturating_add(len).min(v.len());
                v[start.min(end)..end].to_vec()
            }
            Grid::Log(g) => g.block(start, len),
        }
    }

    /// The lowest and highest positive frequencies (Hz), for the planner.
    fn positive_band(&self) -> (f64, f64) {
        match self {
            Grid::Log(g) => (g.lo_hz(), g.hi_hz()),
            Grid::Points(freqs) => {
                let positive: Vec<f64> = freqs.iter().copied().filter(|&f| f > 0.0).collect();
                match positive.is_empty() {
                    true => (freq::DEFAULT_F_LO_HZ, freq::DEFAULT_F_LO_HZ),
                    false => (
                        positive.iter().copied().fold(f64::INFINITY, f64::min),
                        positive.iter().copied().fold(0.0, f64::max),
                    ),
                }
            }
        }
    }
}

/// The modes table and, for tilt inputs, the static limits, for translations their limits per
/// unit acceleration (printed when files are saved).
fn write_report(
    out: &mut super::stdout::Out,
    model: &Model,
    modes: &NormalModes,
    request: &Request,
) -> Result<()> {
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
/// as CSV to standard output without --save) before the next is computed.
fn stream_tf(
    plan: &dyn tf::TransferFunction,
    grid: &Grid,
    block_freqs: usize,
    args: &TfArgs,
    model: &Model,
    meta: &RunMeta,
    run: &mut Run,
) -> Result<()> {
    use tiltnoise_io::{OutputKind, TfCsvWriter, TfHdf5Writer};
    let mut hdf5 = Vec::new();
    let mut csv = Vec::new();
    for path in &args.save {
        match OutputKind::from_path(path)? {
            OutputKind::Hdf5 => hdf5.push(TfHdf5Writer::create(path, meta)?),
            OutputKind::Csv => csv.push(TfCsvWriter::create(path, meta)?),
            OutputKind::Png | OutputKind::Svg => unreachable!("figures are drawn from memory"),
        }
    }
    let n = grid.len();
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
    let mut text = String::new();
    let mut start = 0;
    while start < n {
        let freqs = grid.block(start, block_freqs);
        let block = tf::evaluate(plan, &freqs)
            .and_then(|tf| per_unit(tf, args.per.quantity()))
            .context("evaluating the transfer functions")?;
        for w in &mut hdf5 {
            w.append(&block)?;
        }
        for w in &mut csv {
            w.append(&block)?;
        }
        if args.save.is_empty() {
            text.clear();
            if start == 0 {
                text.push_str(&tiltnoise_io::tf_csv_header(&block, meta));
            }
            tiltnoise_io::push_tf_csv_rows(&mut text, &block);
            write!(run.out, "{text}")?;
        }
        start += freqs.len();
        if let Some(b) = &bar {
            b.set_position(start as u64);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if args.save.is_empty() {
        return Ok(());
    }
    write_report(
        &mut run.out,
        model,
        &NormalModes::new(model),
        plan.request(),
    )?;
    run.write_outputs(false, || {
        for w in hdf5 {
            w.finish()?;
        }
        for w in csv {
            w.finish()?;
        }
        Ok(())
    })
}
