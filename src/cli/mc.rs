//! `tiltnoise mc`: Monte Carlo of the normal modes over the parameter errors (the Monte Carlo
//! job, [`tiltnoise_job::monte_carlo`]); a table or JSON on stdout, histograms (PNG/SVG) and
//! HDF5 with `--save`.

use super::figure_args::SizeArgs;
use super::Run;
use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::OutputError;
use tiltnoise_core::mc::McResult;
use tiltnoise_core::params::Params;
use tiltnoise_io::{write_mc_hdf5, RunMeta};
use tiltnoise_job::monte_carlo::{self, McRequest};

/// Extensions `tiltnoise mc --save` accepts, for messages.
const MC_EXTENSIONS: &str = ".h5, .hdf5, .png, .svg";

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

/// What `--save PATH` writes.
#[derive(Clone, Copy)]
enum McOutput {
    Hdf5,
    Figure,
}

fn output_kind(path: &Path) -> Result<McOutput, OutputError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("h5" | "hdf5") => Ok(McOutput::Hdf5),
        Some("png" | "svg") => Ok(McOutput::Figure),
        _ => Err(OutputError::UnknownFormat {
            path: path.to_path_buf(),
            allowed: MC_EXTENSIONS,
        }),
    }
}

/// Runs `tiltnoise mc`: the sizes checked and every `--save` path before computing, the
/// Monte Carlo job run (with a progress bar on a terminal), the table or JSON printed and the
/// files written.
pub(crate) fn run_mc(params: &Params, opts: McOptions, run: &mut Run) -> Result<()> {
    use std::io::IsTerminal;
    let kinds = opts
        .save
        .iter()
        .map(|p| output_kind(p))
        .collect::<Result<Vec<_>, _>>()?;
    let view = opts
        .figure
        .view_for(tiltnoise_plot::mc_figure::DEFAULT_SIZE)?;
    let req = McRequest {
        params,
        samples: opts.samples,
        seed: opts.seed,
        threads: opts.threads,
    };
    monte_carlo::check(&req).map_err(super::job_error)?;
    let saves: Vec<&Path> = opts.save.iter().map(PathBuf::as_path).collect();
    run.check_outputs(&saves, &[])?;
    let bar = (std::io::stderr().is_terminal() && opts.samples >= 10_000)
        .then(|| indicatif::ProgressBar::new(opts.samples as u64));
    let mc = monte_carlo::run(req, &run.cancel, &|done| {
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
    })
    .map_err(super::job_error)?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let (result, nominal) = (&mc.result, &mc.nominal_hz);
    if opts.json {
        writeln!(run.out, "{}", json(result, nominal, opts.seed)?)?;
    } else {
        write!(run.out, "{}", table(result, nominal, opts.seed))?;
    }
    if opts.save.is_empty() {
        return Ok(());
    }
    let meta = RunMeta::of_this_run(params, None);
    let caption = monte_carlo::caption(&mc);
    // JSON on standard output stays parseable: the `wrote` lines go to standard error.
    run.write_outputs(opts.json, || {
        for (path, kind) in opts.save.iter().zip(kinds) {
            match kind {
                McOutput::Hdf5 => write_mc_hdf5(path, result, &mc.config, nominal, &meta)?,
                McOutput::Figure => super::output::save_image(path, |format| {
                    tiltnoise_plot::mc_figure::mc_figure(result, nominal, &caption, &view, format)
                })?,
            }
        }
        Ok(())
    })
}

fn json(result: &McResult, nominal: &[f64; 8], seed: u64) -> Result<String> {
    let modes = (0..8)
        .map(|k| McModeJson {
            index: k + 1,
            mean_hz: result.mean_hz[k],
            nominal_hz: nominal[k],
            std_hz: result.std_hz[k],
        })
        .collect();
    Ok(serde_json::to_string_pretty(&McJson {
        modes,
        rejected: result.rejected,
        samples: result.samples,
        seed,
    })?)
}

// Keys in alphabetical order, as the report has always listed them: fields declared in that
// order.

#[derive(Serialize)]
struct McJson {
    modes: Vec<McModeJson>,
    rejected: usize,
    samples: usize,
    seed: u64,
}

#[derive(Serialize)]
struct McModeJson {
    index: usize,
    mean_hz: f64,
    nominal_hz: f64,
    std_hz: f64,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cli::report::assert_keys_sorted;

    #[test]
    fn json_lists_keys_alphabetically_and_nan_as_null() {
        let result = McResult {
            samples: 2,
            rejected: 1,
            freqs_hz: vec![[1.0; 8]],
            sample_index: vec![0],
            mean_hz: [1.0; 8],
            std_hz: [f64::NAN; 8],
        };
        let value = assert_keys_sorted(&json(&result, &[1.0; 8], 7).unwrap());
        assert_eq!(value["modes"][7]["std_hz"], serde_json::Value::Null);
    }
}
