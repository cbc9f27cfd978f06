//! `tiltnoise mc`: Monte Carlo of the normal modes over the parameter errors (the Monte Carlo
//! job, [`tiltnoise_job::monte_carlo`]); a table or the job's JSON report on stdout, the job's
//! histograms (PNG/SVG) and HDF5 with `--save`.

use super::figure_args::SizeArgs;
use super::progress::Bar;
use super::Run;
use anyhow::Result;
use std::path::{Path, PathBuf};
use tiltnoise_core::mc::McResult;
use tiltnoise_core::params::Params;
use tiltnoise_job::figures::MC_FIGURE_SIZE;
use tiltnoise_job::monte_carlo::{self, McRequest};
use tiltnoise_job::{Invocation, Outcome};

/// The draws worth a progress bar.
const WORTH_A_BAR: u64 = 10_000;

/// The options of `tiltnoise mc`.
pub(crate) struct McOptions {
    /// Number of draws.
    pub(crate) samples: usize,
    /// Seed of the random streams.
    pub(crate) seed: u64,
    /// Worker threads (0: all cores).
    pub(crate) threads: usize,
    /// JSON instead of the table on stdout.
    pub(crate) json: bool,
    /// Output files (format from the extension).
    pub(crate) save: Vec<PathBuf>,
    /// Size and resolution of the histograms.
    pub(crate) figure: SizeArgs,
}

/// Runs `tiltnoise mc`: the sizes checked and every `--save` path before computing, the
/// Monte Carlo job run (with a progress bar on a terminal), the table or JSON printed and the
/// files written.
pub(crate) fn run_mc(params: &Params, opts: McOptions, run: &mut Run) -> Result<()> {
    for path in &opts.save {
        tiltnoise_job::output_kind(path, monte_carlo::OUTPUT_KINDS)?;
    }
    opts.figure.refuse_without_figure(&opts.save)?;
    let req = McRequest {
        params,
        samples: opts.samples,
        seed: opts.seed,
        threads: opts.threads,
        invocation: Invocation::of_this_process(),
        figure: opts.figure.view_for(MC_FIGURE_SIZE)?,
    };
    monte_carlo::check(&req).map_err(super::job_error)?;
    let saves: Vec<&Path> = opts.save.iter().map(PathBuf::as_path).collect();
    run.check_outputs(&saves, &[])?;
    let bar = Bar::new("draws", WORTH_A_BAR);
    let mc = monte_carlo::run(&req, &run.cancel, &bar).map_err(super::job_error)?;
    if opts.json {
        writeln!(run.out, "{}", serde_json::to_string_pretty(&mc.json())?)?;
    } else {
        write!(run.out, "{}", table(&mc.result, &mc.nominal_hz, opts.seed))?;
    }
    if opts.save.is_empty() {
        return Ok(());
    }
    // JSON on standard output stays parseable: the `wrote` lines go to standard error.
    run.write_outputs(opts.json, |stage| {
        for path in &opts.save {
            mc.save(stage, path).map_err(super::job_error)?;
        }
        Ok(())
    })
}

fn table(result: &McResult, nominal: &[f64; 8], seed: u64) -> String {
    let mut s = format!(
        "Monte Carlo of the normal modes: {} draws ({} rejected as non-physical), seed {seed}\n",
        result.samples, result.rejected
    );
    s.push_str(&format!(
        "{:<5} {:>14} {:>14} {:>12}\n",
        "mode", "nominal (Hz)", "mean (Hz)", "std (Hz)"
    ));
    for (k, f0) in nominal.iter().enumerate() {
        s.push_str(&format!(
            "nu_{:<2} {:>14.6e} {:>14.6e} {:>12.3e}\n",
            k + 1,
            f0,
            result.mean_hz[k],
            result.std_hz[k]
        ));
    }
    s
}
