//! The `subtract` subcommand: the options parsed into the subtract job's request
//! ([`tiltnoise_job::subtract`]: the records read and checked, the coupling fitted, the tilt
//! part predicted and removed), the job run, then the report (table or JSON) and the outputs
//! ([`tiltnoise_job::subtract::outputs`]: the cleaned record, the report, the figure).
//! Documented in `docs/subtract.md`.

use super::args::{parse_readout_item, ChannelArgs, Format};
use super::figure_args::FigureArgs;
use super::subtract_table::report_table;
use super::witness_noise::parse_witness_items;
use super::Run;
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;
use tiltnoise_core::error::Shown;
use tiltnoise_core::model::{Input, Model};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::figures::View;
use tiltnoise_job::subtract::figure::FIGURE_SIZE;
use tiltnoise_job::subtract::SubtractRequest;
use tiltnoise_job::{Invocation, Outcome, Silent};

/// Arguments of `tiltnoise subtract`.
#[derive(Debug, Args)]
pub(crate) struct SubtractArgs {
    /// Record of the floor's motion (the witness): HDF5, CSV or miniSEED time series of tilt
    /// (angle or rate) and, beside it, floor translation (displacement, velocity or
    /// acceleration, as each channel's unit says), as for `budget` (docs/input_formats.md).
    #[arg(long, value_name = "FILE")]
    tilt: PathBuf,
    /// Measured record of the observables: HDF5 (as `simulate` writes) or CSV `time_s,X,...`
    /// time series in m and rad, optional start time.
    #[arg(long, value_name = "FILE")]
    measured: PathBuf,
    /// Observables of the measured record to use, comma-separated (default: every one in the
    /// file).
    #[arg(long, value_name = "OBS,...", value_delimiter = ',')]
    observables: Vec<String>,
    /// Axis map of the tilt record, e.g. `theta_t=-E,eta_t=-N` (default: from the file, else
    /// that).
    #[arg(long, value_name = "MAP", allow_hyphen_values = true)]
    axes: Option<String>,
    /// Quantity of the tilt channels: angle (rad) or rate (rad/s); default from the file.
    #[arg(long, value_name = "angle|rate")]
    quantity: Option<String>,
    /// Non-finite samples of the tilt record: reject (default) or interpolate.
    #[arg(long, value_name = "reject|interpolate")]
    gaps: Option<String>,
    /// Scale factor of a source channel of the tilt record, `CHANNEL=FACTOR` (rad or rad/s per
    /// count, or per unit of the file), applied before the axis map; required for miniSEED
    /// channels in counts. Repeat for several channels.
    #[arg(long, value_name = "CHANNEL=FACTOR")]
    scale: Vec<String>,
    #[command(flatten)]
    channels: ChannelArgs,
    /// Model parameters to fit besides a gain per tilt axis and the delay, comma-separated
    /// parameter-file keys (e.g. `length.h_m`).
    #[arg(long, value_name = "KEY,...", value_delimiter = ',')]
    fit: Vec<String>,
    /// Fit band FLO:FHI (Hz); default: from the third Welch bin to 0.8 of the Nyquist
    /// frequency, resonances left out.
    #[arg(long, value_name = "FLO:FHI")]
    band: Option<String>,
    /// Band of the residual summaries FLO:FHI (Hz).
    #[arg(long, value_name = "FLO:FHI", default_value = "3e-3:3e-2")]
    report_band: String,
    /// Welch segment length in samples (default: the largest power of two fitting 8 times
    /// into the training stretch and twice into the held-out one, at most 2^16).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    nperseg: Option<usize>,
    /// Fraction of the overlap held out at its end for validation, in (0, 0.5].
    #[arg(
        long,
        value_name = "FRACTION",
        default_value_t = 0.25,
        allow_negative_numbers = true
    )]
    holdout: f64,
    /// Largest delay between the records to search (s); default 5 % of a Welch segment.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    max_delay: Option<f64>,
    /// Own noise of the witness instrument of a floor input, `INPUT=ASD|FILE[:REL]`
    /// (repeatable): the ASD in the input's unit/sqrt(Hz), white or an ASD file (as for
    /// --readout), REL its relative uncertainty (1 sigma, e.g. :0.1). The fit then models the
    /// witness noise (no errors-in-variables bias) and the prediction is weighted down where
    /// the witness records mostly its own noise. Also accepted as --tilt-noise.
    #[arg(
        long,
        alias = "tilt-noise",
        value_name = "INPUT=ASD|FILE[:REL]",
        allow_hyphen_values = true
    )]
    witness_noise: Vec<String>,
    /// A record of a second (or, repeated, a third) instrument beside the witness, recording
    /// the same inputs, read as --tilt (same --axes, --quantity, --gaps, --scale): the
    /// witness's noise is then estimated from them (two: a huddle test; three: a
    /// three-cornered hat) for every input they record.
    #[arg(long, value_name = "FILE")]
    colocated: Vec<PathBuf>,
    /// Huddle test: the co-located instrument's noise ASD over the witness's, INPUT=R
    /// (repeatable; default 1, equal noise).
    #[arg(long, value_name = "INPUT=R", allow_hyphen_values = true)]
    colocated_ratio: Vec<String>,
    /// White readout of a measured observable OBS=ASD in unit/sqrt(Hz) (repeatable): drawn,
    /// and the cleaned residual is compared with it.
    #[arg(long, value_name = "OBS=ASD", allow_hyphen_values = true)]
    readout: Vec<String>,
    /// Output format on the terminal.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Output (repeatable): .h5/.hdf5 the cleaned record (what `budget --measured` reads) with
    /// the predicted tilt parts, estimates and residual spectra; .json the report; .png/.svg
    /// the figure.
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
    #[command(flatten)]
    figure: FigureArgs,
}

/// `FLO:FHI` as numbers (the job checks the band).
fn parse_band(option: OptionKey, text: &str) -> Result<(f64, f64)> {
    Ok(options::parse_range(
        option,
        text,
        "expected FLO:FHI in Hz with 0 < FLO < FHI, e.g. 3e-3:3e-2",
    )?)
}

/// `--colocated-ratio INPUT=R` as an input and a number (the job checks them).
fn parse_colocated_ratio(items: &[String]) -> Result<Vec<(Input, f64)>> {
    items
        .iter()
        .map(|item| {
            let shown = Shown(item);
            let (name, value) = item.split_once('=').ok_or_else(|| {
                anyhow!("--colocated-ratio {shown}: expected INPUT=R, e.g. eta_t=1.5")
            })?;
            let input = options::floor_input(OptionKey::COLOCATED_RATIO, item, name)?;
            let r = value.trim().parse().map_err(|_| {
                anyhow!(
                    "--colocated-ratio {shown}: `{}` is not a number",
                    Shown(value)
                )
            })?;
            Ok((input, r))
        })
        .collect()
}

/// How to read `--tilt` and every `--colocated` record.
fn read_request(args: &SubtractArgs) -> Result<ReadRequest> {
    let o = super::args::read_options(
        args.axes.as_deref(),
        args.quantity.as_deref(),
        args.gaps.as_deref(),
        &args.scale,
        &args.channels,
    )?;
    Ok(ReadRequest {
        axis_map: o.axis_map,
        quantity: o.quantity,
        units: o.units,
        corrected: o.corrected,
        pendulum_tiltmeter: o.pendulum,
        gaps: Some(o.gaps),
        scale: o.scale,
    })
}

/// The job's request from the options.
fn request<'a>(args: &SubtractArgs, model: &'a Model) -> Result<SubtractRequest<'a>> {
    Ok(SubtractRequest {
        model,
        tilt: args.tilt.clone(),
        read: read_request(args)?,
        measured: args.measured.clone(),
        observables: match args.observables.is_empty() {
            true => None,
            false => Some(options::parse_outputs(
                OptionKey::OBSERVABLES,
                &args.observables,
            )?),
        },
        colocated: args.colocated.clone(),
        colocated_ratio: parse_colocated_ratio(&args.colocated_ratio)?,
        witness_noise: parse_witness_items(&args.witness_noise)?,
        readout_asd: args
            .readout
            .iter()
            .map(|item| parse_readout_item(item))
            .collect::<Result<_>>()?,
        fit: options::split_names(OptionKey::FIT, &args.fit)?
            .into_iter()
            .map(str::to_string)
            .collect(),
        band_hz: args
            .band
            .as_deref()
            .map(|b| parse_band(OptionKey::BAND, b))
            .transpose()?,
        report_band_hz: parse_band(OptionKey::REPORT_BAND, &args.report_band)?,
        nperseg: args.nperseg,
        holdout: args.holdout,
        max_delay_s: args.max_delay,
        invocation: Invocation::of_this_process(),
        figure: View::default(),
    })
}

/// Runs `tiltnoise subtract`: the options parsed into the subtract job's request, the job run,
/// the report printed and the files written.
pub(crate) fn run_subtract(params: &Params, args: SubtractArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        tiltnoise_job::output_kind(path, tiltnoise_job::subtract::outputs::OUTPUT_KINDS)?;
    }
    args.figure.refuse_without_figure(&args.save)?;
    let figure = args.figure.view_for(FIGURE_SIZE)?;
    let model = Model::new(params)?;
    let req = SubtractRequest {
        figure,
        ..request(&args, &model)?
    };
    run.check_job_outputs(&args.save, req.input_files())?;
    let outcome =
        tiltnoise_job::subtract::run(&req, &run.cancel, &Silent).map_err(super::job_error)?;
    for note in &outcome.input_notes {
        match args.format {
            Format::Json => super::note(&format!("input: {note}")),
            Format::Table => writeln!(run.out, "input: {note}")?,
        }
    }
    match args.format {
        Format::Json => writeln!(run.out, "{}", outcome.report().to_json())?,
        Format::Table => write!(run.out, "{}", report_table(&outcome.result))?,
    }
    run.write_outputs(args.format == Format::Json, |stage| {
        for path in &args.save {
            outcome.save(stage, path).map_err(super::job_error)?;
        }
        Ok(())
    })
}
