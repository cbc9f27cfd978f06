//! `tiltnoise mc`: Monte Carlo of the normal modes over the parameter errors (the error model of
//! the parameter file, see [`tiltnoise_core::params::uncertainty`]); a table or JSON on stdout, histograms
//! (PNG/SVG) and HDF5 with `--save`.

use super::figure_args::SizeArgs;
use super::Run;
use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::OutputError;
use tiltnoise_core::mc::{McConfig, McResult};
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_io::{write_mc_hdf5, RunMeta};

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

/// Runs `tiltnoise mc`. Every `--save` path is checked before computing.
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
    tiltnoise_core::mc::check_size(opts.samples, opts.threads, ("--samples", "--threads"))?;
    let saves: Vec<&Path> = opts.save.iter().map(PathBuf::as_path).collect();
    run.check_outputs(&saves, &[])?;
    let cfg = McConfig {
        samples: opts.samples,
        seed: opts.seed,
        threads: opts.threads,
        cancel: run.cancel.clone(),
        ..McConfig::default_for(params)
    };
    let bar = (std::io::stderr().is_terminal() && opts.samples >= 10_000)
        .then(|| indicatif::ProgressBar::new(opts.samples as u64));
    let result = tiltnoise_core::mc::run(params, &cfg, &|done| {
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
    })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let nominal: [f64; 8] = NormalModes::new(&Model::new(params)?)
        .frequencies_hz()
        .try_into()
        .map_err(|v: Vec<f64>| anyhow::anyhow!("expected 8 modes, got {}", v.len()))?;
    if opts.json {
        writeln!(run.out, "{}", json(&result, &nominal, opts.seed)?)?;
    } else {
        write!(run.out, "{}", table(&result, &nominal, opts.seed))?;
    }
    if opts.save.is_empty() {
        return Ok(());
    }
    let meta = RunMeta::of_this_run(params, None);
    let caption = caption(&result, &cfg);
    // JSON on standard output stays parseable: the `wrote` lines go to standard error.
    run.write_outputs(opts.json, || {
        for (path, kind) in opts.save.iter().zip(kinds) {
            match kind {
                McOutput::Hdf5 => write_mc_hdf5(path, &result, &cfg, &nominal, &meta)?,
                McOutput::Figure => super::output::save_image(path, |format| {
                    tiltnoise_plot::mc_figure::mc_figure(&result, &nominal, &caption, &view, format)
                })?,
            }
        }
        Ok(())
    })
}

/// The figure's caption: what is marked, counts, seed and the error model, grouped by error.
fn caption(result: &McResult, cfg: &McConfig) -> String {
    let mut groups: Vec<(f64, &str, Vec<&str>)> = Vec::new();
    for u in cfg.uncertainties.iter().filter(|u| u.rel_sigma > 0.0) {
        let name = u.key.split_once('.').map_or(u.key.as_str(), |(_, n)| n);
        let shape = u.distribution.name();
        match groups
            .iter_mut()
            .find(|g| g.0 == u.rel_sigma && g.1 == shape)
        {
            Some(g) => g.2.push(name),
            None => groups.push((u.rel_sigma, shape, vec![name])),
        }
    }
    let model: Vec<String> = groups
        .iter()
        .map(|(s, shape, names)| format!("{} % {shape} on {}", s * 100.0, names.join(", ")))
        .collect();
    // The [asymmetry] offsets have absolute errors, in their own unit.
    let offsets: Vec<String> = cfg
        .uncertainties
        .iter()
        .filter(|u| u.abs_sigma > 0.0)
        .map(|u| {
            let name = u.key.split_once('.').map_or(u.key.as_str(), |(_, n)| n);
            format!("{:e} {} on {name}", u.abs_sigma, u.distribution.name())
        })
        .collect();
    let absolute = if offsets.is_empty() {
        String::new()
    } else {
        format!(
            "; absolute errors (1 std, in the key's unit): {}",
            offsets.join("; ")
        )
    };
    format!(
        "Black dashed: nominal parameters; orange: mean; shaded: mean ± 1 std. {} draws, {} \
         rejected as non-physical, seed {}. Relative errors (1 std): {}{absolute}; all other \
         parameters exact.",
        result.samples,
        result.rejected,
        cfg.seed,
        model.join("; ")
    )
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
