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
enum MethodArg {
    /// Per-frequency LU of the full model (the reference method).
    Direct,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Direct => Method::Direct,
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
    #[arg(long, value_enum, default_value_t = MethodArg::Direct)]
    method: MethodArg,
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
    let method = Method::from(args.method);
    let plan = tf::plan(&model, &Request::all_tilt(), method)?;
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
