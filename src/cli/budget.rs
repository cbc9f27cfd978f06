//! The `budget` subcommand: validated options -> the budget job -> files and a terminal summary.
//! Owns the progress bar (only when stderr is a terminal).

use super::args::{AverageArg, ChannelArgs, Format};
use super::budget_terms::{parse_observables, parse_readout, parse_terms};
use super::figure_args::FigureArgs;
use super::progress::Bar;
use super::witness_noise::parse_witness_items;
use super::Run;
use anyhow::{anyhow, Result};
use clap::Args;
use std::path::PathBuf;
use tiltnoise_core::error::Shown;
use tiltnoise_core::freq;
use tiltnoise_core::model::Model;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::spectral::Averaging;
use tiltnoise_job::budget::{
    BudgetOutcome, BudgetRequest, ReadRequest, SaveOptions, TiltSource, WelchRequest,
};
use tiltnoise_job::figures::BudgetFigureOptions;
use tiltnoise_job::{Invocation, Outcome};

/// Arguments of `tiltnoise budget`.
#[derive(Debug, Args)]
pub struct BudgetArgs {
    /// The floor's motion: HDF5, CSV or miniSEED time series of tilt (angle or rate) and
    /// translation channels (displacement, velocity or acceleration), or tilt spectra; see
    /// docs/input_formats.md.
    #[arg(long, value_name = "FILE")]
    pub tilt: PathBuf,
    /// Axis map, e.g. `theta_t=-E,eta_t=-N` or `theta_t=-LJE,eta_t=-LJN,x_t=LHE,y_t=LHN`
    /// (default: from the file, else theta_t=-E, eta_t=-N for rotation channels and x_t=E,
    /// y_t=N, z_t=Z for translation channels).
    #[arg(long, value_name = "MAP", allow_hyphen_values = true)]
    pub axes: Option<String>,
    /// Quantity of the tilt channels: angle (rad) or rate (rad/s); default from the file, else
    /// angle.
    #[arg(long, value_name = "angle|rate")]
    pub quantity: Option<String>,
    #[command(flatten)]
    pub channels: ChannelArgs,
    /// Non-finite samples of a time series: reject (default) or interpolate linearly across
    /// interior gaps.
    #[arg(long, value_name = "reject|interpolate")]
    pub gaps: Option<String>,
    /// Scale factor of a source channel of a time series, `CHANNEL=FACTOR` (rad or rad/s per
    /// count, or per unit of the file), applied before the axis map; required for miniSEED
    /// channels in counts. Repeat for several channels.
    #[arg(long, value_name = "CHANNEL=FACTOR")]
    pub scale: Vec<String>,
    /// Welch segment length in samples (default 2^14, or the largest power of two <= N/4).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nperseg: Option<usize>,
    /// Welch overlap as a fraction of the segment (default 0.5).
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub overlap: Option<f64>,
    /// Welch averaging: mean (default), or median (with scipy's bias correction).
    #[arg(long, value_enum)]
    pub average: Option<AverageArg>,
    /// Split the record into segments of this many seconds for a percentile band; each must
    /// hold one Welch segment (--nperseg samples), e.g. 14400 with --nperseg 4096 at 1 Hz.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub segment_duration: Option<f64>,
    /// Percentiles of the band across segments, LO:HI (default 10:90; with
    /// --segment-duration; LO,HI is accepted too).
    #[arg(long, value_name = "LO:HI", allow_hyphen_values = true)]
    pub percentiles: Option<String>,
    /// Observables to budget, e.g. X,Y,Z,theta,eta,phi,phi_a (default X,phi,phi_a).
    #[arg(long, value_name = "OBS,...")]
    pub observables: Option<String>,
    /// Readout noise of an observable (repeatable): OBS=ASD white, in the observable's
    /// unit/sqrt(Hz) (default X=9e-9 m/sqrt(Hz) from the paper; OBS=0 removes it), or OBS=FILE
    /// coloured, a CSV (frequency_hz,OBS or frequency_hz,asd) or HDF5 (/frequency_hz, /OBS or /asd) ASD
    /// file that covers the budget's band.
    #[arg(long, value_name = "OBS=ASD|FILE", allow_hyphen_values = true)]
    pub readout: Vec<String>,
    /// A user-named noise term NAME=SOURCE:FILE (repeatable): SOURCE an observable (the file is
    /// its ASD) or an input of the model, theta_t..phi_t, F_a.x..F_b.z, M_a.x..M_b.z (the file
    /// is the input's ASD, propagated through the transfer functions); FILE as for --readout.
    /// Added in quadrature to the total as `user.NAME`.
    #[arg(long, value_name = "NAME=SOURCE:FILE", allow_hyphen_values = true)]
    pub term: Vec<String>,
    /// Own noise of the tiltmeter that recorded a tilt axis, `AXIS=ASD|FILE[:REL]` (repeatable;
    /// as for `subtract`): shown through the model as `witness_noise` beside the tilt term,
    /// which already contains it; not added to the total.
    #[arg(long, value_name = "AXIS=ASD|FILE[:REL]", allow_hyphen_values = true)]
    pub witness_noise: Vec<String>,
    /// Model grid for spectra input, FLO:N:FHI (default 1e-4:2000:30 plus resonance points);
    /// restricted to the band the data cover.
    #[arg(long, value_name = "FLO:N:FHI", allow_hyphen_values = true)]
    pub freq: Option<String>,
    /// Measured record of the observables for comparison: CSV `frequency_hz,X[,phi,phi_a]` of
    /// one-sided ASDs (m/sqrt(Hz), rad/sqrt(Hz)), or a time series (HDF5 as written by
    /// `tiltnoise simulate`, or CSV `time_s,X,...` in m, rad) turned into ASDs with the
    /// budget's Welch settings; adds the terms `measured` and `residual`.
    #[arg(long, value_name = "FILE")]
    pub measured: Option<PathBuf>,
    /// Frequencies (Hz) to read the budget at, e.g. 1e-3,2e-3,5e-3 (the default): model terms
    /// exact there, Welch estimates as band means with their statistical error; each must lie
    /// in the budget's band.
    #[arg(long, value_name = "F1,F2,...", allow_hyphen_values = true)]
    pub at: Option<String>,
    /// Half-width of the band of the Welch band means, relative to the frequency: the bins in
    /// f (1 - B) .. f (1 + B) are averaged (default 0.1).
    #[arg(long, value_name = "B", allow_negative_numbers = true)]
    pub at_band: Option<f64>,
    /// Output format on the terminal: table (default) or json (the --at summary and the notes).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Output file (.h5, .csv, .png, .svg), repeatable.
    #[arg(long, value_name = "PATH")]
    pub save: Vec<PathBuf>,
    /// Keep the CSV columns that are zero at every frequency (left out by default and named in
    /// a `# note:` line; the HDF5 file always has every term).
    #[arg(long)]
    pub keep_zero_columns: bool,
    #[command(flatten)]
    pub figure: FigureArgs,
}

/// `--at F1,F2,...`: frequencies in Hz (the job checks them against the budget).
fn parse_at(text: &str) -> Result<Vec<f64>> {
    text.split(',')
        .map(|item| {
            item.trim().parse::<f64>().map_err(|_| {
                anyhow!(
                    "--at {}: `{}` is not a frequency in Hz; expected F1,F2,... e.g. \
                     1e-3,2e-3,5e-3",
                    Shown(text),
                    Shown(item)
                )
            })
        })
        .collect()
}

/// `--percentiles LO:HI`: two numbers (the job checks 0 <= LO < HI <= 100).
fn parse_percentiles(text: &str) -> Result<(f64, f64)> {
    Ok(options::parse_range(
        OptionKey::PERCENTILES,
        text,
        "expected LO:HI with 0 <= LO < HI <= 100, e.g. 10:90",
    )?)
}

/// How to read `--tilt`: the channel options as every command reads them, `--gaps` kept as
/// given (the job refuses it for spectra).
fn read_request(args: &BudgetArgs) -> Result<ReadRequest> {
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
        gaps: args.gaps.as_ref().map(|_| o.gaps),
        scale: o.scale,
    })
}

/// Runs `tiltnoise budget`: the options parsed into the budget job's request, the job run
/// (with a progress bar on a terminal), the summary printed and the outcome saved.
pub(crate) fn run_budget(params: &Params, args: BudgetArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        tiltnoise_job::output_kind(path, tiltnoise_job::budget::OUTPUT_KINDS)?;
    }
    args.figure.refuse_without_figure(&args.save)?;
    let save = SaveOptions {
        keep_zero_columns: args.keep_zero_columns,
        figure: BudgetFigureOptions {
            view: args.figure.view_for(BudgetFigureOptions::default().size)?,
            ..BudgetFigureOptions::default()
        },
    };
    let model = Model::new(params)?;
    let req = BudgetRequest {
        model: &model,
        tilt: TiltSource::File {
            path: args.tilt.clone(),
            read: read_request(&args)?,
        },
        welch: WelchRequest {
            nperseg: args.nperseg,
            overlap: args.overlap,
            averaging: args.average.map(|a| match a {
                AverageArg::Mean => Averaging::Mean,
                AverageArg::Median => Averaging::Median,
            }),
            segment_duration_s: args.segment_duration,
            percentiles: args
                .percentiles
                .as_deref()
                .map(parse_percentiles)
                .transpose()?,
        },
        freq_hz: args.freq.as_deref().map(freq::parse_spec).transpose()?,
        observables: args
            .observables
            .as_deref()
            .map(parse_observables)
            .transpose()?,
        readout: parse_readout(&args.readout)?,
        terms: parse_terms(&args.term)?,
        witness_noise: parse_witness_items(&args.witness_noise)?,
        measured: args.measured.clone(),
        at_hz: args.at.as_deref().map(parse_at).transpose()?,
        at_band: args.at_band,
        invocation: Invocation::of_this_process(),
    };
    run.check_job_outputs(&args.save, req.input_files())?;
    let bar = Bar::new("samples", WORTH_A_BAR);
    let outcome: BudgetOutcome =
        tiltnoise_job::budget::run(req, &run.cancel, &bar).map_err(super::job_error)?;
    let json = args.format == Format::Json;
    if json {
        writeln!(
            run.out,
            "{}",
            serde_json::to_string_pretty(&outcome.json())?
        )?;
    } else {
        for note in &outcome.input.notes {
            writeln!(run.out, "input: {note}")?;
        }
        write!(run.out, "{}", super::budget_summary::table(&outcome.report))?;
    }
    run.write_outputs(json, |stage| {
        for out in &args.save {
            outcome
                .save_with(stage, out, &save)
                .map_err(super::job_error)?;
        }
        Ok(())
    })
}

/// Samples of a budget's input worth a progress bar.
const WORTH_A_BAR: u64 = 1 << 22;
