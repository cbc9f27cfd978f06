//! `tiltnoise visibility`: mode visibilities measured from a recorded free motion
//! ([`tiltnoise_core::fit::peaks`]), written as the CSV that `fit --visibility` reads.

use super::Run;
use anyhow::{bail, Result};
use clap::Args;
use std::path::PathBuf;
use tiltnoise_core::model::Model;
use tiltnoise_core::params::Params;
use tiltnoise_job::visibility::{VisibilityRequest, VisibilityResult};
use tiltnoise_job::{Invocation, Outcome, Silent};

/// Arguments of `tiltnoise visibility`.
#[derive(Debug, Args)]
pub(crate) struct VisibilityArgs {
    /// A free-motion or ring-down record of the observables: HDF5 or CSV time series as
    /// `budget --measured` reads them (the layout `simulate --save` writes).
    #[arg(long = "measured", alias = "record", value_name = "FILE")]
    record: PathBuf,
    /// Output CSV `mode,observable,reference,ratio,sigma` for `fit --visibility`.
    #[arg(long, value_name = "PATH")]
    save: Option<PathBuf>,
    /// Output format on the terminal: table (the peaks and the ratios), csv (the file --save
    /// writes) or json (the peaks, the skipped modes and the ratios, as Python's
    /// `Visibilities.to_json()`); with csv and json, `wrote` lines go to standard error.
    #[arg(long, value_enum, default_value_t = VisibilityFormat::Table)]
    format: VisibilityFormat,
}

/// What `tiltnoise visibility` prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum VisibilityFormat {
    Table,
    Csv,
    Json,
}

/// Runs `tiltnoise visibility`: the visibility job run on `--measured`, the table or the CSV
/// printed and the CSV saved.
pub(crate) fn run_visibility(params: &Params, args: VisibilityArgs, run: &mut Run) -> Result<()> {
    if let Some(path) = &args.save {
        if path.extension().and_then(|e| e.to_str()) != Some("csv") {
            bail!(
                "--save {}: the visibility file is CSV; give a path ending in .csv",
                path.display()
            );
        }
    }
    let model = Model::new(params)?;
    let req = VisibilityRequest {
        model: &model,
        measured: args.record.clone(),
        invocation: Invocation::of_this_process(),
    };
    run.check_job_outputs(args.save.as_slice(), req.input_files())?;
    let result =
        tiltnoise_job::visibility::run(&req, &run.cancel, &Silent).map_err(super::job_error)?;
    match args.format {
        VisibilityFormat::Table => write!(run.out, "{}", table(&result))?,
        VisibilityFormat::Csv => write!(run.out, "{}", result.csv())?,
        VisibilityFormat::Json => {
            writeln!(run.out, "{}", serde_json::to_string_pretty(&result.json())?)?
        }
    }
    let Some(path) = &args.save else {
        return Ok(());
    };
    run.write_outputs(args.format != VisibilityFormat::Table, |stage| {
        result.save(stage, path).map_err(super::job_error)
    })
}

/// The peaks and the ratios, as the terminal shows them.
fn table(result: &VisibilityResult) -> String {
    use std::fmt::Write;
    let m = &result.measured;
    let channels: Vec<&str> = result.channels.iter().map(|o| o.name()).collect();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<5} {:>13} {:>13}  peak SNR in {}",
        "mode",
        "expected Hz",
        "peak Hz",
        channels.join(", ")
    );
    for p in &m.peaks {
        let snr: Vec<String> = p.snr.iter().map(|x| format!("{x:.3e}")).collect();
        let _ = writeln!(
            s,
            "nu_{:<2} {:>13.6e} {:>13.6e}  {}",
            p.mode,
            p.expected_hz,
            p.frequency_hz,
            snr.join(" ")
        );
    }
    for (k, why) in &m.skipped {
        let _ = writeln!(s, "nu_{k:<2} skipped: {why}");
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:<5} {:<13} {:>13} {:>11}",
        "mode", "ratio", "value", "sigma"
    );
    for v in &m.visibilities.items {
        let _ = writeln!(
            s,
            "nu_{:<2} {:<13} {:>13.5e} {:>11.2e}",
            v.mode,
            format!("{}/{}", v.observable.name(), v.reference.name()),
            v.ratio,
            v.sigma
        );
    }
    s
}
