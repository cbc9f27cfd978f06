//! Command-line interface: clap derive for the raw arguments, then conversion to validated
//! library inputs and the run of each subcommand. `main.rs` only maps the result to an exit code.
//! Everything printed goes to stdout; errors are returned to `main`.

use crate::freq;
use crate::io::{save_tf, RunMeta, TOOL_VERSION};
use crate::model::Model;
use crate::modes::NormalModes;
use crate::params::Params;
use crate::tf::{self, Method, Request};
use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;

/// Tilt-noise budgets for double torsion pendulums (the 8-DoF PETER model of
/// De Marchi et al., Phys. Rev. D 87, 122006, 2013).
#[derive(Debug, Parser)]
#[command(name = "tiltnoise", version, about, long_about = None)]
pub struct Cli {
    #[command(flatten)]
    params: ParamArgs,
    #[command(subcommand)]
    command: Command,
}

/// Parameter selection, shared by every subcommand.
#[derive(Debug, Args)]
struct ParamArgs {
    /// TOML parameter file (default: the embedded Table I set; see `tiltnoise params`).
    #[arg(long, global = true, value_name = "FILE")]
    params: Option<PathBuf>,
    /// Override one parameter, e.g. `--set length.h_m=1.5` (repeatable; SI units as in the key).
    #[arg(long = "set", global = true, value_name = "KEY=VALUE")]
    set: Vec<String>,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print the effective parameter set as TOML (edit it and pass it back with --params).
    Params,
    /// Normal modes (Table II): frequencies, dominant coordinates, observables that see them.
    Modes {
        /// Output format.
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Transfer functions from floor tilt (theta_t, eta_t, phi_t) to the 7 observables.
    Tf(TfArgs),
    /// Noise budget of X, phi, phi_a from measured floor tilt (time series or spectra).
    Budget(BudgetArgs),
    /// Monte Carlo of the normal modes over the parameter uncertainties (default: Gaussian,
    /// 2.5 % on masses, lengths, inertias; 10 % on torsion and bouncing constants; g, h exact).
    Mc {
        /// Number of draws.
        #[arg(long, default_value_t = 10_000)]
        samples: usize,
        /// Seed of the random streams (results do not depend on the thread count).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Worker threads (0: all cores).
        #[arg(long, default_value_t = 0)]
        threads: usize,
        /// Output format on the terminal.
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
    },
    /// Every evaluation method's worst error against the double-double reference and its time
    /// per point, for the 7x3 tilt matrix on the given grid (table, JSON, chart).
    Methods {
        /// Log grid FLO:N:FHI (Hz:count:Hz).
        #[arg(long, value_name = "FLO:N:FHI", default_value = "1e-5:400:100")]
        freq: String,
        /// Output format on the terminal.
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        /// Chart of time per point against error (.png or .svg), repeatable.
        #[arg(long, value_name = "PATH")]
        save: Vec<PathBuf>,
    },
}

#[derive(Debug, Args)]
pub(crate) struct BudgetArgs {
    /// Tilt input: HDF5 or CSV time series (angle or rate) or spectra; see docs/input_formats.md.
    #[arg(long, value_name = "FILE")]
    pub(crate) tilt: PathBuf,
    /// Axis map, e.g. `theta_t=-E,eta_t=-N` (default: from the file, else theta_t=-E, eta_t=-N).
    #[arg(long, value_name = "MAP")]
    pub(crate) axes: Option<String>,
    /// Quantity of the channels: angle (rad) or rate (rad/s); default from the file, else angle.
    #[arg(long, value_name = "angle|rate")]
    pub(crate) quantity: Option<String>,
    /// Non-finite samples: reject (default) or interpolate linearly across interior gaps.
    #[arg(long, value_name = "reject|interpolate", default_value = "reject")]
    pub(crate) gaps: String,
    /// Welch segment length in samples (default 2^14, or the largest power of two <= N/4).
    #[arg(long, value_name = "N")]
    pub(crate) nperseg: Option<usize>,
    /// Welch overlap as a fraction of the segment.
    #[arg(long, value_name = "FRACTION", default_value_t = 0.5)]
    pub(crate) overlap: f64,
    /// Welch averaging: mean, or median (with scipy's bias correction).
    #[arg(long, value_enum, default_value_t = AverageArg::Mean)]
    pub(crate) average: AverageArg,
    /// Split the record into segments of this many seconds (e.g. 3600) for a percentile band.
    #[arg(long, value_name = "SECONDS")]
    pub(crate) segment_duration: Option<f64>,
    /// Percentiles of the band across segments, LOWER,UPPER.
    #[arg(long, value_name = "LO,HI", default_value = "10,90")]
    pub(crate) percentiles: String,
    /// White readout noise OBS=ASD in the observable's unit/sqrt(Hz) (repeatable; default
    /// X=9e-9 m/sqrt(Hz) from the paper; OBS=0 removes it).
    #[arg(long, value_name = "OBS=ASD")]
    pub(crate) readout: Vec<String>,
    /// Model grid for spectra input, FLO:N:FHI (default 1e-4:2000:30 plus resonance points);
    /// restricted to the band the data cover.
    #[arg(long, value_name = "FLO:N:FHI")]
    pub(crate) freq: Option<String>,
    /// Measured spectrum of the observables for comparison: CSV `freq_hz,X[,phi,phi_a]`, one-sided
    /// ASD (m/sqrt(Hz), rad/sqrt(Hz)); adds the terms `measured` and `residual`.
    #[arg(long, value_name = "FILE")]
    pub(crate) measured: Option<PathBuf>,
    /// Output file (.h5, .csv, .png, .svg), repeatable.
    #[arg(long, value_name = "PATH")]
    pub(crate) save: Vec<PathBuf>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum AverageArg {
    Mean,
    Median,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum Format {
    Table,
    Json,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub(crate) enum MethodArg {
    /// Smallest model and cheapest method meeting 1e-9 relative on the grid's band, verified
    /// against the double-double reference (see --explain).
    Auto,
    /// Per-frequency LU of the full 8x8 model (the oracle of the fast methods).
    Direct,
    /// Per-frequency LU of the decoupled 4x4 blocks the request needs.
    Block,
    /// Block LU in absolute angles with the static / mass-line split: full relative accuracy.
    Split,
    /// Pole-zero product form per entry, built once in double-double: accurate and fastest.
    Polezero,
    /// Modal superposition (fast; loses accuracy where modal terms cancel).
    Modal,
    /// The 2-DoF torsional model of section IV.C (no tilt inputs).
    Torsion2,
}

impl MethodArg {
    /// The fixed method, or `None` for `auto`.
    pub(crate) fn fixed(self) -> Option<Method> {
        match self {
            MethodArg::Auto => None,
            MethodArg::Direct => Some(Method::Direct),
            MethodArg::Block => Some(Method::Block),
            MethodArg::Split => Some(Method::Split),
            MethodArg::Polezero => Some(Method::PoleZero),
            MethodArg::Modal => Some(Method::Modal),
            MethodArg::Torsion2 => Some(Method::Torsion2),
        }
    }
}

#[derive(Debug, Args)]
struct TfArgs {
    /// Log-spaced grid FLO:N:FHI (Hz:count:Hz), e.g. 1e-4:2000:30. Default: 0.1 mHz to 30 Hz,
    /// 2000 points, plus points around every resonance.
    #[arg(long, value_name = "FLO:N:FHI", conflicts_with = "freq_file")]
    freq: Option<String>,
    /// File with one frequency in Hz per line (# comments allowed).
    #[arg(long, value_name = "FILE")]
    freq_file: Option<PathBuf>,
    /// Output file, format from the extension: .h5 (all numbers), .csv, .png/.svg (Figure 5).
    /// Repeatable. Without --save the CSV goes to stdout.
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
    /// Evaluation method.
    #[arg(long, value_enum, default_value_t = MethodArg::Auto)]
    method: MethodArg,
    /// Say which method `auto` picked and why (every candidate's measured error).
    #[arg(long)]
    explain: bool,
}

impl ParamArgs {
    fn resolve(&self) -> Result<Params> {
        let mut params = match &self.params {
            Some(path) => Params::from_file(path)?,
            None => Params::table_i(),
        };
        for assignment in &self.set {
            params = params.with_override(assignment)?;
        }
        Ok(params)
    }
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<()> {
    let params = cli.params.resolve()?;
    match cli.command {
        Command::Params => {
            print!("{}", params.to_toml());
            Ok(())
        }
        Command::Modes { format } => {
            let model = Model::new(&params)?;
            let modes = NormalModes::new(&model);
            match format {
                Format::Table => print!("{}", crate::report::modes_table(&modes)),
                Format::Json => println!("{}", crate::report::modes_json(&modes)),
            }
            Ok(())
        }
        Command::Tf(args) => run_tf(&params, args),
        Command::Budget(args) => crate::cli_budget::run_budget(&params, args),
        Command::Methods { freq, format, save } => run_methods(&params, &freq, format, &save),
        Command::Mc {
            samples,
            seed,
            threads,
            format,
        } => run_mc(&params, samples, seed, threads, format),
    }
}

fn run_tf(params: &Params, args: TfArgs) -> Result<()> {
    let model = Model::new(params)?;
    let freqs = match (&args.freq, &args.freq_file) {
        (Some(spec), _) => freq::parse_spec(spec)?,
        (None, Some(path)) => freq::read_freq_file(path)?,
        (None, None) => freq::default_grid(&model),
    };
    // Check every output's format before computing, so a typo costs nothing.
    for path in &args.save {
        crate::io::OutputKind::from_path(path)?;
    }
    let request = Request::all_tilt();
    let method = match args.method.fixed() {
        Some(m) => m,
        None => {
            let positive: Vec<f64> = freqs.iter().copied().filter(|&f| f > 0.0).collect();
            let band = match positive.is_empty() {
                true => (crate::freq::DEFAULT_F_LO_HZ, crate::freq::DEFAULT_F_LO_HZ),
                false => (
                    positive.iter().copied().fold(f64::INFINITY, f64::min),
                    positive.iter().copied().fold(0.0, f64::max),
                ),
            };
            let scene = crate::scene::Scene {
                request: request.clone(),
                band_hz: band,
                rel_tol: crate::scene::DEFAULT_REL_TOL,
            };
            let choice = crate::scene::choose(&model, &scene).map_err(anyhow::Error::msg)?;
            if args.explain {
                eprintln!("{}", choice.explain());
            }
            choice.method
        }
    };
    let plan = tf::plan(&model, &request, method)?;
    let tf = tf::evaluate(plan.as_ref(), &freqs).context("evaluating the transfer functions")?;
    let modes = NormalModes::new(&model);
    if args.save.is_empty() {
        print!("{}", crate::io::tf_csv_string(&tf));
        return Ok(());
    }
    let meta = RunMeta {
        tool_version: TOOL_VERSION.to_string(),
        params_toml: params.to_toml(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
        modes: modes
            .modes
            .iter()
            .map(|m| (m.index, m.frequency_hz))
            .collect(),
    };
    print!("{}", crate::report::modes_table(&modes));
    println!();
    print!("{}", crate::report::static_limits(&model));
    for path in &args.save {
        save_tf(path, &tf, &meta)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn run_methods(params: &Params, spec: &str, format: Format, save: &[PathBuf]) -> Result<()> {
    use crate::methods::methods_table;
    use crate::scene::{choose, Scene, DEFAULT_REL_TOL};
    for path in save {
        crate::plot::ImageFormat::from_path(path)?;
    }
    let model = Model::new(params)?;
    let grid = freq::parse_spec(spec)?;
    let request = Request::all_tilt();
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
    .unwrap_or_else(|why| format!("none ({why})"));
    let rows = methods_table(&model, &request, &grid);
    match format {
        Format::Json => {
            let methods: Vec<_> = rows
                .iter()
                .map(|r| {
                    serde_json::json!({
                        "name": r.method.name(),
                        "max_rel_err": r.worst.as_ref().map(|w| w.0),
                        "worst_entry": r.worst.as_ref().map(|w| w.1.clone()),
                        "worst_freq_hz": r.worst.as_ref().map(|w| w.2),
                        "ns_per_point": r.ns_per_point,
                        "exact_zeros": r.exact_zeros,
                        "unusable": r.unusable,
                    })
                })
                .collect();
            println!(
                "{}",
                serde_json::to_string_pretty(&serde_json::json!({
                    "auto": auto,
                    "target_rel_err": DEFAULT_REL_TOL,
                    "grid": spec,
                    "methods": methods,
                }))?
            );
        }
        Format::Table => {
            println!(
                "7x3 tilt matrix on {spec} Hz ({} points; accuracy checked > 1 % from every mode)",
                grid.len()
            );
            println!(
                "{:<9} {:>13} {:>14} {:>12} {:>12}  exact zeros",
                "method", "max rel err", "worst entry", "at (Hz)", "ns/point"
            );
            for r in &rows {
                match (&r.worst, r.ns_per_point) {
                    (Some((e, entry, f)), Some(ns)) => println!(
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
                    ),
                    _ => println!(
                        "{:<9} not usable: {}",
                        r.method.name(),
                        r.unusable.as_deref().unwrap_or("")
                    ),
                }
            }
            println!("auto picks: {auto} (target: relative error <= {DEFAULT_REL_TOL:e})");
        }
    }
    let points: Vec<crate::plot::methods_figure::MethodPoint> = rows
        .iter()
        .filter_map(|r| {
            Some((
                r.method.name().to_string(),
                r.ns_per_point?,
                r.worst.as_ref()?.0,
            ))
        })
        .collect();
    for path in save {
        crate::plot::methods_figure::methods_figure(
            &points,
            DEFAULT_REL_TOL,
            &format!("Speed against accuracy, 7x3 tilt matrix, {spec} Hz"),
            path,
        )?;
        println!("wrote {}", path.display());
    }
    Ok(())
}

fn run_mc(
    params: &Params,
    samples: usize,
    seed: u64,
    threads: usize,
    format: Format,
) -> Result<()> {
    use std::io::IsTerminal;
    let cfg = crate::mc::McConfig {
        samples,
        seed,
        threads,
        ..crate::mc::McConfig::default_for(params)
    };
    let bar = (std::io::stderr().is_terminal() && samples >= 10_000)
        .then(|| indicatif::ProgressBar::new(samples as u64));
    let result = crate::mc::run(params, &cfg, &|done| {
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
    })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let nominal = NormalModes::new(&Model::new(params)?).frequencies_hz();
    match format {
        Format::Json => {
            let modes: Vec<_> = (0..8)
                .map(|k| {
                    serde_json::json!({
                        "index": k + 1,
                        "nominal_hz": nominal[k],
                        "mean_hz": result.mean_hz[k],
                        "std_hz": result.std_hz[k],
                    })
                })
                .collect();
            println!(
                "{}",
                serde_json::to_string_pretty(&serde_json::json!({
                    "samples": result.samples,
                    "rejected": result.rejected,
                    "seed": seed,
                    "modes": modes,
                }))?
            );
        }
        Format::Table => {
            println!(
                "Monte Carlo of the normal modes: {} draws ({} rejected as non-physical), seed {seed}",
                result.samples, result.rejected
            );
            println!(
                "{:<5} {:>14} {:>14} {:>12}",
                "mode", "nominal (Hz)", "mean (Hz)", "std (Hz)"
            );
            for (k, f0) in nominal.iter().enumerate() {
                println!(
                    "nu_{:<2} {:>14.6e} {:>14.6e} {:>12.3e}",
                    k + 1,
                    f0,
                    result.mean_hz[k],
                    result.std_hz[k]
                );
            }
        }
    }
    Ok(())
}
