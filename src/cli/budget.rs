//! The `budget` subcommand: validated options -> the budget job -> files and a terminal summary.
//! Owns the progress bar (only when stderr is a terminal).

use super::args::{AverageArg, ChannelArgs, Format};
use super::budget_terms::{parse_observables, parse_readout, parse_terms};
use super::figure_args::FigureArgs;
use super::output::save_budget;
use super::witness_noise::parse_witness_noise;
use super::Run;
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use tiltnoise_core::budget::{
    add_measured, budget_from_series, budget_from_spectra, series_psds, BudgetOptions,
    MeasuredPsds, SummaryRequest, DEFAULT_BAND_FRACTION,
};
use tiltnoise_core::error::{Num, Shown};
use tiltnoise_core::freq;
use tiltnoise_core::model::Model;
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::noise::BudgetReport;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::refuse_repeats;
use tiltnoise_core::spectral::Averaging;
use tiltnoise_io::input::{read_tilt, InputFormat, ReadOptions, TiltInput, TiltSeriesSource};
use tiltnoise_io::{InputMeta, OutputKind, RunMeta};

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
    /// Percentiles of the band across segments, LOWER,UPPER (default 10,90; with
    /// --segment-duration).
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true)]
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

/// The `--at` and `--at-band` request: explicit frequencies are refused when the budget cannot
/// be read there; the default ones are left out with a note.
fn summary_request(args: &BudgetArgs) -> Result<SummaryRequest> {
    let mut req = SummaryRequest {
        band_fraction: args.at_band.unwrap_or(DEFAULT_BAND_FRACTION),
        ..SummaryRequest::default()
    };
    if let Some(text) = &args.at {
        req.strict = true;
        req.freqs_hz = text
            .split(',')
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
            .collect::<Result<_>>()?;
        refuse_repeats("--at", "frequency", &req.freqs_hz, |f| Num(*f).to_string())?;
    }
    req.validate().map_err(|e| {
        anyhow!(
            "{}: {e}",
            if args.at_band.is_some() {
                "--at-band"
            } else {
                "--at"
            }
        )
    })?;
    Ok(req)
}

fn parse_percentiles(text: &str) -> Result<(f64, f64)> {
    let err = || {
        anyhow!(
            "--percentiles {}: expected LOWER,UPPER with 0 <= LOWER < UPPER <= 100",
            Shown(text)
        )
    };
    let (a, b) = text.split_once(',').ok_or_else(err)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| err())?,
        b.trim().parse().map_err(|_| err())?,
    );
    if !(0.0 <= a && a < b && b <= 100.0) {
        return Err(err());
    }
    Ok((a, b))
}

fn read_options(args: &BudgetArgs) -> Result<ReadOptions> {
    super::args::read_options(
        args.axes.as_deref(),
        args.quantity.as_deref(),
        args.gaps.as_deref(),
        &args.scale,
        &args.channels,
    )
}

/// Options of a time series, refused for spectra input rather than ignored.
fn refuse_series_options(args: &BudgetArgs, path: &std::path::Path) -> Result<()> {
    let given = [
        ("--nperseg", args.nperseg.is_some()),
        ("--overlap", args.overlap.is_some()),
        ("--average", args.average.is_some()),
        ("--segment-duration", args.segment_duration.is_some()),
        ("--gaps", args.gaps.is_some()),
        ("--scale", !args.scale.is_empty()),
        ("--units", !args.channels.units.is_empty()),
        ("--corrected", !args.channels.corrected.is_empty()),
        (
            "--pendulum-tiltmeter",
            !args.channels.pendulum_tiltmeter.is_empty(),
        ),
    ];
    if let Some((name, _)) = given.iter().find(|(_, g)| *g) {
        bail!(
            "{name} applies to time-series input, and {} holds spectra; leave it out (the \
             model grid of spectra input is set with --freq)",
            path.display()
        );
    }
    Ok(())
}

/// Options of spectra input, refused for a time series rather than ignored.
fn refuse_spectra_options(args: &BudgetArgs, path: &std::path::Path) -> Result<()> {
    if args.freq.is_some() {
        bail!(
            "--freq applies to spectra input, and {} holds a time series, whose budget is on \
             the Welch grid (set its resolution with --nperseg)",
            path.display()
        );
    }
    Ok(())
}

/// Runs `tiltnoise budget`.
pub(crate) fn run_budget(params: &Params, args: BudgetArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        OutputKind::from_path(path)?;
    }
    let figure = tiltnoise_plot::BudgetFigureOptions {
        view: args
            .figure
            .view_for(tiltnoise_plot::BudgetFigureOptions::default().size)?,
        ..tiltnoise_plot::BudgetFigureOptions::default()
    };
    let defaults = BudgetOptions::default();
    let outputs = match &args.observables {
        Some(text) => parse_observables(text)?,
        None => defaults.outputs.clone(),
    };
    let (readout, readout_files) = parse_readout(&args.readout, &outputs)?;
    let (user_terms, term_files) = parse_terms(&args.term, &outputs)?;
    let (witness_noise, witness_files) = parse_witness_noise(&args.witness_noise)?;
    let saves: Vec<&Path> = args.save.iter().map(PathBuf::as_path).collect();
    let mut inputs = vec![("--tilt", args.tilt.as_path())];
    inputs.extend(args.measured.as_deref().map(|p| ("--measured", p)));
    inputs.extend(readout_files.iter().map(|p| ("--readout", p.as_path())));
    inputs.extend(term_files.iter().map(|p| ("--term", p.as_path())));
    inputs.extend(
        witness_files
            .iter()
            .map(|p| ("--witness-noise", p.as_path())),
    );
    run.check_outputs(&saves, &inputs)?;
    let model = Model::new(params)?;
    if args.percentiles.is_some() {
        tiltnoise_core::budget::option_checks::require_segments_for_percentiles(
            args.segment_duration.is_some(),
        )?;
    }
    let opts = BudgetOptions {
        welch_segment_len: args.nperseg,
        welch_overlap_fraction: args.overlap.unwrap_or(defaults.welch_overlap_fraction),
        averaging: match args.average.unwrap_or(AverageArg::Mean) {
            AverageArg::Mean => Averaging::Mean,
            AverageArg::Median => Averaging::Median,
        },
        segment_duration_s: args.segment_duration,
        percentiles: match &args.percentiles {
            Some(text) => parse_percentiles(text)?,
            None => defaults.percentiles,
        },
        outputs,
        readout,
        user_terms,
        witness_noise,
        spectra_grid_hz: match &args.freq {
            Some(spec) => freq::parse_spec(spec)?,
            None => freq::default_grid(&model),
        },
        summary: summary_request(&args)?,
        cancel: run.cancel.clone(),
    };
    let ropts = read_options(&args)?;
    let path = &args.tilt;
    // Opened once: an HDF5 series streams from the file; anything else is read whole below
    // (which reports why an HDF5 file is not a series).
    let streamed = match tiltnoise_io::input::input_format(path)? {
        InputFormat::Hdf5 => TiltSeriesSource::open(path, &ropts).ok(),
        InputFormat::Csv | InputFormat::Miniseed => None,
    };
    let (report, provenance) = if let Some(mut source) = streamed {
        refuse_spectra_options(&args, path)?;
        let provenance = source.provenance().clone();
        let bar = progress_bar(source.len() as u64);
        let report = budget_from_series(&model, &mut source, &opts, &mut |done, _| {
            bar.as_ref().map_or((), |b| b.set_position(done))
        });
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        (report, provenance)
    } else {
        match read_tilt(path, &ropts)? {
            TiltInput::Series(mut series) => {
                refuse_spectra_options(&args, path)?;
                let provenance = series.provenance.clone();
                let report = budget_from_series(&model, &mut series, &opts, &mut |_, _| {});
                (report, provenance)
            }
            TiltInput::Spectra(spectra) => {
                refuse_series_options(&args, path)?;
                let provenance = spectra.provenance.clone();
                (budget_from_spectra(&model, &spectra, &opts), provenance)
            }
        }
    };
    let mut report = report.with_context(|| format!("budget of {}", path.display()))?;
    for x in &opts.witness_noise {
        if !report.inputs.contains(&x.input) {
            bail!(
                "--witness-noise {}: the record {} has no input {}; it has {}",
                x.input.name(),
                path.display(),
                x.input.name(),
                report
                    .inputs
                    .iter()
                    .map(|a| a.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    if let Some(measured) = &args.measured {
        add_measured_file(&mut report, measured)?;
    }
    let json = args.format == Format::Json;
    if json {
        writeln!(
            run.out,
            "{}",
            super::budget_summary::json(&report, &provenance.notes)?
        )?;
    } else {
        for note in &provenance.notes {
            writeln!(run.out, "input: {note}")?;
        }
        write!(run.out, "{}", super::budget_summary::table(&report))?;
    }
    let meta = RunMeta::of_this_run(params, Some(&NormalModes::new(&model)));
    let input = InputMeta::from(&provenance);
    run.write_outputs(json, || {
        for out in &args.save {
            save_budget(out, &report, &meta, &input, &figure, args.keep_zero_columns)?;
        }
        Ok(())
    })
}

/// Adds the `measured` and `residual` terms from `--measured FILE`: a CSV of ASDs is
/// interpolated log-log onto the budget grid (NaN where it does not reach); a time series of
/// the observables (HDF5 from `tiltnoise simulate`, or CSV `time_s,...`) is first turned into
/// one-sided PSDs by [`series_psds`].
fn add_measured_file(report: &mut BudgetReport, path: &std::path::Path) -> Result<()> {
    use tiltnoise_io::input::MeasuredInput;
    let (freqs_hz, psds, what, welch) = match tiltnoise_io::input::read_measured_input(path)? {
        MeasuredInput::Spectra(m) => {
            let psds = m
                .asd
                .iter()
                .map(|(o, asd)| (*o, asd.iter().map(|a| a * a).collect()))
                .collect();
            (m.freqs_hz, psds, "measured spectrum".to_string(), None)
        }
        MeasuredInput::Series(series) => {
            let m = series_psds(&series.channels, series.sample_rate_hz, &report.source)
                .with_context(|| format!("--measured {}", path.display()))?;
            (m.freqs_hz, m.psds, m.description, m.welch)
        }
    };
    let measured = MeasuredPsds {
        freqs_hz,
        psds,
        description: what,
        welch,
    };
    add_measured(report, &measured, &path.display().to_string());
    Ok(())
}

/// A progress bar on stderr when it is a terminal and the input is long enough to wait for.
fn progress_bar(total: u64) -> Option<indicatif::ProgressBar> {
    const WORTH_A_BAR: u64 = 1 << 22;
    if total < WORTH_A_BAR || !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} {wide_bar} {pos}/{len} samples ({percent}%, eta {eta})",
        )
        .expect("valid template"),
    );
    Some(bar)
}
