//! Command-line interface: clap derive for the raw arguments, then conversion to validated
//! library inputs and the run of each subcommand. `main.rs` only maps the result to an exit code.
//! Everything printed goes to stdout; errors are returned to `main`.

use crate::freq;
use crate::model::Model;
use crate::modes::NormalModes;
use crate::params::Params;
use crate::tf::{Method, Request};
use anyhow::Result;
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
    /// Transfer functions from floor tilt (theta_t, eta_t, phi_t) and/or forces and torques
    /// (F_a.x .. M_b.z) to the observables.
    Tf(crate::cli_tf::TfArgs),
    /// Noise budget of X, phi, phi_a from measured floor tilt (time series or spectra).
    Budget(BudgetArgs),
    /// Free motion of the undamped model (exact modal propagation, 12 h at 0.1 s by default)
    /// with readout noise: ASDs as in Figure 3, the resonance check against the mode
    /// observability table, the X kick of Figures 4 and 5, HDF5 series the budget reads.
    Simulate(crate::cli_simulate::SimulateArgs),
    /// Constrained least-squares fit of chosen parameters, within their error bars, to measured
    /// mode frequencies (default: Table II's measured column).
    Fit(crate::cli_fit::FitArgs),
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
        /// Histograms (.png, .svg) or all draws (.h5), repeatable; see docs/schemas.md.
        #[arg(long, value_name = "PATH")]
        save: Vec<PathBuf>,
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
    /// Measured record of the observables for comparison: CSV `freq_hz,X[,phi,phi_a]` of
    /// one-sided ASDs (m/sqrt(Hz), rad/sqrt(Hz)), or a time series (HDF5 as written by
    /// `tiltnoise simulate`, or CSV `time_s,X,...` in m, rad) turned into ASDs with the
    /// budget's Welch settings; adds the terms `measured` and `residual`.
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
    /// First-order state space as python-control and scipy.signal evaluate it (comparison;
    /// loses accuracy where the tilt forcing cancels).
    Statespace,
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
            MethodArg::Statespace => Some(Method::StateSpace),
            MethodArg::Torsion2 => Some(Method::Torsion2),
        }
    }
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
        Command::Tf(args) => crate::cli_tf::run_tf(&params, args),
        Command::Budget(args) => crate::cli_budget::run_budget(&params, args),
        Command::Simulate(args) => crate::cli_simulate::run_simulate(&params, args),
        Command::Fit(args) => crate::cli_fit::run_fit(&params, args),
        Command::Methods { freq, format, save } => run_methods(&params, &freq, format, &save),
        Command::Mc {
            samples,
            seed,
            threads,
            format,
            save,
        } => crate::cli_mc::run_mc(
            &params,
            crate::cli_mc::McOptions {
                samples,
                seed,
                threads,
                json: format == Format::Json,
                save,
            },
        ),
    }
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
