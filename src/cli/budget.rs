//! The `budget` subcommand: validated options -> the budget job -> files and a terminal summary.
//! Owns the progress bar (only when stderr is a terminal).

use super::args::{parse_readout_item, AverageArg};
use super::output::save_budget;
use super::Run;
use anyhow::{anyhow, Context, Result};
use clap::Args;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use tiltnoise_core::budget::option_checks::{self, InputKind};
use tiltnoise_core::budget::{budget_from_series, budget_from_spectra, loglog_at, BudgetOptions};
use tiltnoise_core::freq;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::noise::{BudgetReport, Readout, TermKind};
use tiltnoise_core::options::{self, Spelling};
use tiltnoise_core::params::Params;
use tiltnoise_core::spectral::Averaging;
use tiltnoise_io::input::{read_tilt, InputFormat, ReadOptions, TiltInput, TiltSeriesSource};
use tiltnoise_io::{InputMeta, OutputKind, RunMeta};

/// Arguments of `tiltnoise budget`.
#[derive(Debug, Args)]
pub struct BudgetArgs {
    /// Tilt input: HDF5 or CSV time series (angle or rate) or spectra; see docs/input_formats.md.
    #[arg(long, value_name = "FILE")]
    pub tilt: PathBuf,
    /// Axis map, e.g. `theta_t=-E,eta_t=-N` (default: from the file, else theta_t=-E, eta_t=-N).
    #[arg(long, value_name = "MAP", allow_hyphen_values = true)]
    pub axes: Option<String>,
    /// Quantity of the channels: angle (rad) or rate (rad/s); default from the file, else angle.
    #[arg(long, value_name = "angle|rate")]
    pub quantity: Option<String>,
    /// Non-finite samples of a time series: reject (default) or interpolate linearly across
    /// interior gaps.
    #[arg(long, value_name = "reject|interpolate")]
    pub gaps: Option<String>,
    /// Welch segment length in samples (default 2^14, or the largest power of two <= N/4).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nperseg: Option<usize>,
    /// Welch overlap as a fraction of the segment (default 0.5).
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub overlap: Option<f64>,
    /// Welch averaging: mean (default), or median (with scipy's bias correction).
    #[arg(long, value_enum)]
    pub average: Option<AverageArg>,
    /// Split the record into segments of this many seconds (e.g. 3600) for a percentile band.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub segment_duration: Option<f64>,
    /// Percentiles of the band across segments, LOWER,UPPER (default 10,90; with
    /// --segment-duration).
    #[arg(long, value_name = "LO,HI", allow_hyphen_values = true)]
    pub percentiles: Option<String>,
    /// White readout noise OBS=ASD in the observable's unit/sqrt(Hz) (repeatable; default
    /// X=9e-9 m/sqrt(Hz) from the paper; OBS=0 removes it).
    #[arg(long, value_name = "OBS=ASD", allow_hyphen_values = true)]
    pub readout: Vec<String>,
    /// Model grid for spectra input, FLO:N:FHI (default 1e-4:2000:30 plus resonance points);
    /// restricted to the band the data cover.
    #[arg(long, value_name = "FLO:N:FHI", allow_hyphen_values = true)]
    pub freq: Option<String>,
    /// Measured record of the observables for comparison: CSV `freq_hz,X[,phi,phi_a]` of
    /// one-sided ASDs (m/sqrt(Hz), rad/sqrt(Hz)), or a time series (HDF5 as written by
    /// `tiltnoise simulate`, or CSV `time_s,X,...` in m, rad) turned into ASDs with the
    /// budget's Welch settings; adds the terms `measured` and `residual`.
    #[arg(long, value_name = "FILE")]
    pub measured: Option<PathBuf>,
    /// Output file (.h5, .csv, .png, .svg), repeatable.
    #[arg(long, value_name = "PATH")]
    pub save: Vec<PathBuf>,
}

/// Frequencies (Hz) at which the terminal summary reads the budget.
const SUMMARY_FREQS_HZ: [f64; 3] = [1e-3, 2e-3, 5e-3];

/// The readout of `--readout` items over the default, on budgeted observables only.
fn parse_readout(items: &[String], budgeted: &[Observable]) -> Result<Readout> {
    let items: Vec<(Observable, f64)> = items
        .iter()
        .map(|i| parse_readout_item(i))
        .collect::<Result<_>>()?;
    Ok(options::apply_readout(
        "--readout",
        Readout::default(),
        &items,
        Some(budgeted),
    )?)
}

fn parse_percentiles(text: &str) -> Result<(f64, f64)> {
    let err = || option_checks::percentiles_error(Spelling::Flag, text);
    let (a, b) = text.split_once(',').ok_or_else(err)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| err())?,
        b.trim().parse().map_err(|_| err())?,
    );
    Ok(option_checks::check_percentiles(
        Spelling::Flag,
        text,
        a,
        b,
    )?)
}

fn read_options(args: &BudgetArgs) -> Result<ReadOptions> {
    Ok(ReadOptions {
        axis_map: args
            .axes
            .as_deref()
            .map(tiltnoise_io::input::AxisMap::parse)
            .transpose()?,
        quantity: args
            .quantity
            .as_deref()
            .map(str::parse)
            .transpose()
            .map_err(|e: String| anyhow!("--quantity: {e}"))?,
        gaps: args
            .gaps
            .as_deref()
            .unwrap_or("reject")
            .parse()
            .map_err(|e: String| anyhow!("--gaps: {e}"))?,
    })
}

fn summary(report: &BudgetReport) -> String {
    let mut s = String::from("noise budget (one-sided ASD):\n");
    let b = &report.budget;
    let damped = b
        .observables
        .iter()
        .any(|ob| ob.term(&TermKind::Thermal).is_some());
    for ob in &b.observables {
        let unit = format!("{}/sqrt(Hz)", ob.observable.unit());
        let total = ob.total();
        for f in SUMMARY_FREQS_HZ {
            let asd_at = |psd: &[f64]| loglog_at(&b.freqs_hz, psd, f).map(f64::sqrt);
            let at = |kind: TermKind| ob.term(&kind).and_then(|t| asd_at(&t.psd));
            if let (Some(t), Some(tot)) = (at(TermKind::Tilt), asd_at(&total)) {
                let thermal = at(TermKind::Thermal)
                    .map(|th| format!("thermal {th:.3e}  "))
                    .unwrap_or_default();
                let _ = writeln!(
                    s,
                    "  {:<6} at {:>4} mHz: tilt {t:.3e}  {thermal}total {tot:.3e} {unit}",
                    ob.observable.name(),
                    f * 1e3,
                );
            }
        }
    }
    if !damped {
        s.push_str(
            "thermal: none (undamped model: every loss angle and viscous coefficient is 0; \
             see docs/damping.md)\n",
        );
    }
    for note in &report.notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}

/// The options given that apply to one kind of input only (snake case).
fn kind_options_given(args: &BudgetArgs) -> Vec<&'static str> {
    [
        ("nperseg", args.nperseg.is_some()),
        ("overlap", args.overlap.is_some()),
        ("average", args.average.is_some()),
        ("segment_duration", args.segment_duration.is_some()),
        ("gaps", args.gaps.is_some()),
        ("freq", args.freq.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, given)| given.then_some(name))
    .collect()
}

/// Options of a time series, refused for spectra input rather than ignored.
fn refuse_series_options(args: &BudgetArgs, path: &std::path::Path) -> Result<()> {
    let source = path.display().to_string();
    let (given, kind) = (kind_options_given(args), InputKind::Spectra);
    Ok(option_checks::refuse_options_for_input(
        &given,
        kind,
        &source,
        Spelling::Flag,
    )?)
}

/// Options of spectra input, refused for a time series rather than ignored.
fn refuse_spectra_options(args: &BudgetArgs, path: &std::path::Path) -> Result<()> {
    let source = path.display().to_string();
    let (given, kind) = (kind_options_given(args), InputKind::Series);
    Ok(option_checks::refuse_options_for_input(
        &given,
        kind,
        &source,
        Spelling::Flag,
    )?)
}

/// Runs `tiltnoise budget`.
pub(crate) fn run_budget(params: &Params, args: BudgetArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        OutputKind::from_path(path)?;
    }
    let saves: Vec<&Path> = args.save.iter().map(PathBuf::as_path).collect();
    let mut inputs = vec![("--tilt", args.tilt.as_path())];
    inputs.extend(args.measured.as_deref().map(|p| ("--measured", p)));
    run.check_outputs(&saves, &inputs)?;
    let model = Model::new(params)?;
    if args.percentiles.is_some() {
        let given = args.segment_duration.is_some();
        option_checks::require_segments_for_percentiles(Spelling::Flag, given)?;
    }
    let defaults = BudgetOptions::default();
    let readout = parse_readout(&args.readout, &defaults.outputs)?;
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
        readout,
        spectra_grid_hz: match &args.freq {
            Some(spec) => freq::parse_spec(spec)?,
            None => freq::default_grid(&model),
        },
        ..BudgetOptions::default()
    };
    let ropts = read_options(&args)?;
    let path = &args.tilt;
    // Opened once: an HDF5 series streams from the file; anything else is read whole below
    // (which reports why an HDF5 file is not a series).
    let streamed = match InputFormat::from_path(path)? {
        InputFormat::Hdf5 => TiltSeriesSource::open(path, &ropts).ok(),
        InputFormat::Csv => None,
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
    if let Some(measured) = &args.measured {
        tiltnoise_io::input::add_measured_file(&mut report, measured, "--measured")?;
    }
    for note in &provenance.notes {
        writeln!(run.out, "input: {note}")?;
    }
    write!(run.out, "{}", summary(&report))?;
    let meta = RunMeta::of_this_run(params, Some(&NormalModes::new(&model)));
    let input = InputMeta::from(&provenance);
    run.write_outputs(false, || {
        for out in &args.save {
            save_budget(out, &report, &meta, &input)?;
        }
        Ok(())
    })
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
