//! Command-line interface: clap derive for the raw arguments, then conversion to validated
//! library inputs and the run of each subcommand. `main.rs` only maps the result to an exit code.
//! Results are printed on standard output through [`Out`]; errors are returned to `main`.
//! Every command that saves files checks all their paths before it computes anything
//! (`Run::check_outputs`) and writes them all or none (`Run::write_outputs`).

mod args;
mod budget;
mod budget_summary;
mod budget_terms;
mod coherence;
mod figure_args;
mod fit;
mod mc;
mod methods;
mod progress;
mod report;
mod simulate;
mod stdout;
mod subtract;
mod subtract_table;
mod tf;
mod visibility;
mod witness_noise;

pub use stdout::{is_closed_pipe, note, Out};

use anyhow::Result;
use args::Format;
use clap::{Args, Parser, Subcommand};
use std::path::{Path, PathBuf};
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::model::Model;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::refuse_repeated_keys;
use tiltnoise_job::files::Staging;
use tiltnoise_job::modes::ModesRequest;
use tiltnoise_job::params::ParamsRequest;
use tiltnoise_job::{Invocation, Outcome};

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
    #[arg(
        long = "set",
        global = true,
        value_name = "KEY=VALUE",
        allow_hyphen_values = true
    )]
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
    Tf(tf::TfArgs),
    /// Noise budget of X, phi, phi_a (or any observables: --observables) from measured floor tilt (time series or spectra), with readout, thermal and user-named terms.
    Budget(budget::BudgetArgs),
    /// Coherence of measured observables with the tilt axes, and their measured transfer
    /// functions (multiple-input estimate with confidence intervals) against the model's.
    Coherence(coherence::CoherenceArgs),
    /// Free motion of the undamped model (exact modal propagation, 12 h at 0.1 s by default)
    /// with readout noise: ASDs as in Figure 3, the resonance check against the mode
    /// observability table, the X kick of Figures 4 and 5, HDF5 series the budget reads.
    Simulate(simulate::SimulateArgs),
    /// Tilt subtraction: fit the coupling (a gain per tilt axis, a delay, chosen parameters) of
    /// a tilt record to a measured record of the observables, predict the tilt part through
    /// the model and remove it; held-out residuals against the coherence and a Wiener filter.
    Subtract(subtract::SubtractArgs),
    /// Constrained least-squares fit of chosen parameters, within their error bars, to measured
    /// mode frequencies (default: Table II's measured column).
    Fit(fit::FitArgs),
    /// Mode visibilities measured from a free-motion record (the signed ratio of each mode's
    /// peaks in two channels, with its error), as the CSV `fit --visibility` reads.
    Visibility(visibility::VisibilityArgs),
    /// Monte Carlo of the normal modes over the parameter uncertainties (default: Gaussian,
    /// 2.5 % on masses, lengths, inertias; 10 % on torsion and bouncing constants; g, h exact).
    Mc {
        /// Number of draws.
        #[arg(long, default_value_t = 10_000, allow_negative_numbers = true)]
        samples: usize,
        /// Seed of the random streams (results do not depend on the thread count).
        #[arg(long, default_value_t = 1, allow_negative_numbers = true)]
        seed: u64,
        /// Worker threads (0: all cores).
        #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
        threads: usize,
        /// Output format on the terminal.
        #[arg(long, value_enum, default_value_t = Format::Table)]
        format: Format,
        /// Histograms (.png, .svg) or all draws (.h5), repeatable; see docs/schemas.md.
        #[arg(long, value_name = "PATH")]
        save: Vec<PathBuf>,
        // Size and resolution of the histograms (their axes follow the draws).
        #[command(flatten)]
        figure: figure_args::SizeArgs,
    },
    /// Every evaluation method's worst error against the double-double reference and its time
    /// per point, for the 7x3 tilt matrix on the given grid (table, JSON, chart).
    Methods(methods::MethodsArgs),
}

impl ParamArgs {
    fn resolve(&self) -> Result<Params> {
        let mut params = match &self.params {
            Some(path) => tiltnoise_job::params::read(path)?,
            None => Params::table_i(),
        };
        refuse_repeated_keys(OptionKey::SET, "parameter key", &self.set)?;
        for assignment in &self.set {
            params = params.with_override(assignment)?;
        }
        Ok(params)
    }
}

/// What every command shares besides its parameters: standard output, and the parameter file,
/// which no output of the run may replace.
pub(crate) struct Run {
    /// Standard output.
    pub(crate) out: Out,
    params_file: Option<PathBuf>,
    /// Set by the interrupt handler; the computations poll it.
    pub(crate) cancel: Cancel,
}

impl Run {
    /// Checks every output path of the command before anything is computed (the rules of
    /// [`tiltnoise_job::files::check_outputs`]); `inputs` are the files the command reads besides the
    /// parameter file, with the options that name them.
    pub(crate) fn check_outputs(&self, outputs: &[&Path], inputs: &[(&str, &Path)]) -> Result<()> {
        let mut all = inputs.to_vec();
        if let Some(p) = &self.params_file {
            all.push(("--params", p));
        }
        Ok(tiltnoise_job::files::check_outputs(outputs, &all)?)
    }

    /// [`Run::check_outputs`] for a job: `files` are the job's inputs, named by their options
    /// in snake case (`BudgetRequest::input_files`).
    pub(crate) fn check_job_outputs(
        &self,
        outputs: &[PathBuf],
        files: Vec<(&'static str, &Path)>,
    ) -> Result<()> {
        let outputs: Vec<&Path> = outputs.iter().map(PathBuf::as_path).collect();
        let flags: Vec<(String, &Path)> = files
            .into_iter()
            .map(|(option, path)| (crate::option_style::rendered(&OptionKey::new(option)), path))
            .collect();
        let inputs: Vec<(&str, &Path)> = flags.iter().map(|(o, p)| (o.as_str(), *p)).collect();
        self.check_outputs(&outputs, &inputs)
    }

    /// Writes every output of the run all or none: `write` saves them, each as one of the
    /// outputs of the run's [`Staging`], and they appear only once all are written and standard
    /// output has taken everything printed before (so a run whose standard output fails
    /// leaves none). Then one `wrote PATH` line per output, on standard error when
    /// `report_on_stderr` (standard output carries JSON). Writers created before (streamed
    /// outputs) are finished into the same `Staging` by `write`.
    pub(crate) fn write_outputs(
        &mut self,
        report_on_stderr: bool,
        write: impl FnOnce(&Staging) -> Result<()>,
    ) -> Result<()> {
        let stage = Staging::new();
        write(&stage)?;
        self.commit_outputs(stage, report_on_stderr)
    }

    /// The end of [`Run::write_outputs`] for outputs a job wrote into `stage` itself (a
    /// streamed run): standard output flushed, then every output committed and reported.
    pub(crate) fn commit_outputs(&mut self, stage: Staging, report_on_stderr: bool) -> Result<()> {
        self.out.flush()?;
        for path in stage.commit()? {
            match report_on_stderr {
                true => note(&format!("wrote {}", path.display())),
                false => writeln!(self.out, "wrote {}", path.display())?,
            }
        }
        Ok(())
    }
}

/// A job's error in the command line's spelling of its options.
pub(crate) fn job_error(e: tiltnoise_job::JobError) -> anyhow::Error {
    // Its message whole (it names its causes itself), spelled when `main` renders it.
    anyhow::Error::msg(e)
}

/// Runs the parsed command line. Everything printed is flushed before it returns; when the
/// command fails, what it printed before is still flushed (its failure is not reported).
pub fn run(cli: Cli, cancel: Cancel) -> Result<()> {
    let mut run = Run {
        out: Out::stdout(),
        params_file: cli.params.params.clone(),
        cancel,
    };
    let result = run_command(cli, &mut run);
    let flushed = run.out.flush();
    result?;
    Ok(flushed?)
}

fn run_command(cli: Cli, run: &mut Run) -> Result<()> {
    let params = cli.params.resolve()?;
    match cli.command {
        Command::Params => {
            let req = ParamsRequest {
                params,
                invocation: Invocation::of_this_process(),
            };
            let outcome = tiltnoise_job::params::run(&req, &run.cancel, &tiltnoise_job::Silent)
                .map_err(job_error)?;
            write!(run.out, "{}", outcome.toml())?;
            Ok(())
        }
        Command::Modes { format } => {
            let model = Model::new(&params)?;
            let req = ModesRequest {
                model: &model,
                invocation: Invocation::of_this_process(),
            };
            let outcome = tiltnoise_job::modes::run(&req, &run.cancel, &tiltnoise_job::Silent)
                .map_err(job_error)?;
            match format {
                Format::Table => {
                    write!(run.out, "{}", report::modes_report(&model, &outcome.modes))?
                }
                Format::Json => writeln!(
                    run.out,
                    "{}",
                    serde_json::to_string_pretty(&outcome.json())?
                )?,
            }
            Ok(())
        }
        Command::Tf(args) => tf::run_tf(&params, args, run),
        Command::Budget(args) => budget::run_budget(&params, args, run),
        Command::Coherence(args) => coherence::run_coherence(&params, args, run),
        Command::Simulate(args) => simulate::run_simulate(&params, args, run),
        Command::Fit(args) => fit::run_fit(&params, args, run),
        Command::Visibility(args) => visibility::run_visibility(&params, args, run),
        Command::Subtract(args) => subtract::run_subtract(&params, args, run),
        Command::Methods(args) => methods::run_methods(&params, args, run),
        Command::Mc {
            samples,
            seed,
            threads,
            format,
            save,
            figure,
        } => mc::run_mc(
            &params,
            mc::McOptions {
                samples,
                seed,
                threads,
                json: format == Format::Json,
                save,
                figure,
            },
            run,
        ),
    }
}
