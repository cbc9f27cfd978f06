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
    let plan = tf::plan(&model, &Request::all_tilt(), method);
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
