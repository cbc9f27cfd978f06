//! `tiltnoise simulate --tilt FILE`: the undamped model driven by a record of the floor's
//! motion ([`tiltnoise_job::simulate::driven`]), optionally through miscalibrated, late
//! sensors (`--drive-gain`, `--drive-delay`): parse, request, run, render.

use super::{parse_readout, SimulateArgs};
use crate::cli::args::{read_options, Format};
use crate::cli::Run;
use anyhow::{anyhow, Result};
use std::path::Path;
use tiltnoise_core::error::{Num, Shown};
use tiltnoise_core::model::Model;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::repeats::{list_entries, refuse_repeated_keys};
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::figures::View;
use tiltnoise_job::simulate::driven::DrivenRequest;
use tiltnoise_job::{Invocation, Outcome, Silent};

/// Fine steps per record sample of the driven propagation when `--oversample` is not given.
const DEFAULT_OVERSAMPLE: usize = 10;

/// `--drive-gain INPUT=GAIN,...` as `(input, gain)`, each input once (the job checks them
/// against the record).
fn parse_gains(items: &[String]) -> Result<Vec<(String, f64)>> {
    let entries = list_entries(items);
    refuse_repeated_keys(OptionKey::DRIVE_GAIN, "input", &entries)?;
    entries
        .into_iter()
        .map(|entry| {
            let shown = Shown(entry);
            let (name, value) = entry.split_once('=').ok_or_else(|| {
                anyhow!("--drive-gain {shown}: expected INPUT=GAIN, e.g. eta_t=0.97 or x_t=1.02")
            })?;
            let g: f64 = value
                .trim()
                .parse()
                .map_err(|_| anyhow!("--drive-gain {shown}: `{}` is not a number", Shown(value)))?;
            Ok((name.trim().to_string(), g))
        })
        .collect()
}

/// The request of `args` with the record at `path`, its figures drawn with `view`.
fn request<'a>(
    model: &'a Model,
    args: &SimulateArgs,
    path: &Path,
    view: &View,
) -> Result<DrivenRequest<'a>> {
    let o = read_options(
        args.axes.as_deref(),
        args.quantity.as_deref(),
        args.gaps.as_deref(),
        &args.scale,
        &args.channels,
    )?;
    Ok(DrivenRequest {
        model,
        tilt: path.to_path_buf(),
        read: ReadRequest {
            axis_map: o.axis_map,
            quantity: o.quantity,
            units: o.units,
            corrected: o.corrected,
            pendulum_tiltmeter: o.pendulum,
            gaps: Some(o.gaps),
            scale: o.scale,
        },
        oversample: args.oversample.unwrap_or(DEFAULT_OVERSAMPLE),
        drive_gain: parse_gains(&args.drive_gain)?,
        drive_delay_s: args.drive_delay,
        readout: parse_readout(&args.readout)?,
        seed: args.seed,
        nperseg: args.nperseg,
        view: view.clone(),
        invocation: Invocation::of_this_process(),
    })
}

/// Runs the driven simulation of `args` with the tilt record at `path`.
pub(super) fn run(
    model: &Model,
    args: &SimulateArgs,
    path: &Path,
    view: &View,
    run: &mut Run,
) -> Result<()> {
    for out in &args.save {
        tiltnoise_job::output_kind(out, tiltnoise_job::simulate::OUTPUT_KINDS)?;
    }
    let req = request(model, args, path, view)?;
    run.check_job_outputs(&args.save, req.input_files())?;
    let r = tiltnoise_job::simulate::driven::run(&req, &run.cancel, &Silent)
        .map_err(crate::cli::job_error)?;
    let json = args.format == Format::Json;
    match json {
        true => writeln!(run.out, "{}", serde_json::to_string_pretty(&r.json())?)?,
        false => {
            for note in &r.notes {
                writeln!(run.out, "input: {note}")?;
            }
            writeln!(
                run.out,
                "driven: {} samples at {} Hz ({} s); {}",
                r.record.len(),
                Num(r.fs_hz),
                Num(r.record.len() as f64 / r.fs_hz),
                r.description
            )?;
        }
    }
    run.write_outputs(json, |stage| {
        for out in &args.save {
            r.save(stage, out).map_err(crate::cli::job_error)?;
        }
        Ok(())
    })
}
