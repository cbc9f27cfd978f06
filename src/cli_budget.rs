//! The `budget` subcommand: validated options -> the budget job -> files and a terminal summary.
//! Owns the progress bar (only when stderr is a terminal).

use crate::budget::{
    budget_from_series, budget_from_spectra, loglog_at, BudgetOptions, SeriesInput,
};
use crate::cli::{AverageArg, BudgetArgs};
use crate::freq;
use crate::input::{read_tilt, InputFormat, ReadOptions, TiltInput, TiltSeriesSource};
use crate::io::{save_budget, InputMeta, OutputKind, RunMeta, TOOL_VERSION};
use crate::model::{Model, Observable};
use crate::modes::NormalModes;
use crate::noise::{BudgetReport, Readout};
use crate::params::Params;
use crate::spectral::Averaging;
use anyhow::{anyhow, bail, Context, Result};
use std::fmt::Write as _;
use std::io::IsTerminal;

/// Frequencies (Hz) at which the terminal summary reads the budget.
const SUMMARY_FREQS_HZ: [f64; 3] = [1e-3, 2e-3, 5e-3];

fn parse_readout(items: &[String]) -> Result<Readout> {
    let mut readout = Readout::default();
    for item in items {
        let (name, value) = item
            .split_once('=')
            .ok_or_else(|| anyhow!("--readout {item}: expected OBS=ASD, e.g. X=9e-9"))?;
        let o = Observable::ALL
            .into_iter()
            .find(|o| o.name() == name.trim())
            .ok_or_else(|| {
                anyhow!(
                    "--readout {item}: unknown observable `{name}`; allowed: X, Y, Z, theta, eta, phi, phi_a"
                )
            })?;
        let asd: f64 = value
            .trim()
            .parse()
            .map_err(|_| anyhow!("--readout {item}: `{value}` is not a number"))?;
        if !(asd.is_finite() && asd >= 0.0) {
            bail!(
                "--readout {item}: ASD {asd} {}/sqrt(Hz) is not allowed: must be finite and >= 0",
                o.unit()
            );
        }
        readout.asd.retain(|(x, _)| *x != o);
        if asd > 0.0 {
            readout.asd.push((o, asd));
        }
    }
    Ok(readout)
}

fn parse_percentiles(text: &str) -> Result<(f64, f64)> {
    let err =
        || anyhow!("--percentiles {text}: expected LOWER,UPPER with 0 <= LOWER < UPPER <= 100");
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
    Ok(ReadOptions {
        axis_map: args
            .axes
            .as_deref()
            .map(crate::input::AxisMap::parse)
            .transpose()?,
        quantity: args
            .quantity
            .as_deref()
            .map(str::parse)
            .transpose()
            .map_err(|e: String| anyhow!("--quantity: {e}"))?,
        gaps: args
            .gaps
            .parse()
            .map_err(|e: String| anyhow!("--gaps: {e}"))?,
    })
}

fn summary(report: &BudgetReport) -> String {
    let mut s = String::from("tilt-noise budget (one-sided ASD):\n");
    let b = &report.budget;
    for ob in &b.observables {
        let unit = format!("{}/sqrt(Hz)", ob.observable.unit());
        for f in SUMMARY_FREQS_HZ {
            let tilt = loglog_at(&b.freqs_hz, &ob.term("tilt").expect("tilt term").psd, f);
            let total = loglog_at(&b.freqs_hz, &ob.total().psd, f);
            if let (Some(t), Some(tot)) = (tilt, total) {
                let _ = writeln!(
                    s,
                    "  {:<6} at {:>4} mHz: tilt {:.3e}  total {:.3e} {unit}",
                    ob.observable.name(),
                    f * 1e3,
                    t.sqrt(),
                    tot.sqrt()
                );
            }
        }
    }
    for note in &report.notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}

/// Runs `tiltnoise budget`.
pub(crate) fn run_budget(params: &Params, args: BudgetArgs) -> Result<()> {
    let model = Model::new(params)?;
    for path in &args.save {
        OutputKind::from_path(path)?;
    }
    let opts = BudgetOptions {
        welch_segment_len: args.nperseg,
        welch_overlap_fraction: args.overlap,
        averaging: match args.average {
            AverageArg::Mean => Averaging::Mean,
            AverageArg::Median => Averaging::Median,
        },
        segment_duration_s: args.segment_duration,
        percentiles: parse_percentiles(&args.percentiles)?,
        readout: parse_readout(&args.readout)?,
        spectra_grid_hz: match &args.freq {
            Some(spec) => freq::parse_spec(spec)?,
            None => freq::default_grid(&model),
        },
        ..BudgetOptions::default()
    };
    let ropts = read_options(&args)?;
    let path = &args.tilt;
    // HDF5 time series stream from disk; everything else is read at once.
    let streamable = InputFormat::from_path(path)? == InputFormat::Hdf5
        && TiltSeriesSource::open(path, &ropts).is_ok();
    let (report, provenance) = if streamable {
        let source = TiltSeriesSource::open(path, &ropts)?;
        let provenance = source.provenance().clone();
        let bar = progress_bar(source.len() as u64);
        let report = budget_from_series(
            &model,
            SeriesInput::Stream(Box::new(source)),
            &opts,
            &mut |done, _| bar.as_ref().map_or((), |b| b.set_position(done)),
        );
        if let Some(b) = bar {
            b.finish_and_clear();
        }
        (report, provenance)
    } else {
        match read_tilt(path, &ropts)? {
            TiltInput::Series(series) => {
                let provenance = series.provenance.clone();
                let report =
                    budget_from_series(&model, SeriesInput::Memory(series), &opts, &mut |_, _| {});
                (report, provenance)
            }
            TiltInput::Spectra(spectra) => {
                let provenance = spectra.provenance.clone();
                (budget_from_spectra(&model, &spectra, &opts), provenance)
            }
        }
    };
    let mut report = report.with_context(|| format!("budget of {}", path.display()))?;
    if let Some(measured) = &args.measured {
        add_measured_file(&mut report, measured)?;
    }
    for note in &provenance.notes {
        println!("input: {note}");
    }
    print!("{}", summary(&report));
    let meta = RunMeta {
        tool_version: TOOL_VERSION.to_string(),
        params_toml: params.to_toml(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
        modes: NormalModes::new(&model)
            .modes
            .iter()
            .map(|m| (m.index, m.frequency_hz))
            .collect(),
    };
    let input = InputMeta {
        path: provenance.path.display().to_string(),
        format: provenance.format.name().to_string(),
        kind: provenance.kind.name().to_string(),
        quantity: provenance.quantity.name().to_string(),
        axis_map: provenance.axis_map.clone(),
        start_time: provenance.start_time.clone(),
        notes: provenance.notes.clone(),
    };
    for out in &args.save {
        save_budget(out, &report, &meta, &input)?;
        println!("wrote {}", out.display());
    }
    Ok(())
}

/// Interpolates a measured ASD file log-log onto the budget grid (NaN where it does not reach)
/// and adds the `measured` and `residual` terms.
fn add_measured_file(report: &mut BudgetReport, path: &std::path::Path) -> Result<()> {
    let measured = crate::input::read_measured(path)?;
    for (o, asd) in &measured.asd {
        if report.budget.observable(*o).is_none() {
            continue;
        }
        let psd: Vec<f64> = asd.iter().map(|a| a * a).collect();
        let on_grid = report
            .budget
            .freqs_hz
            .iter()
            .map(|&f| loglog_at(&measured.freqs_hz, &psd, f).unwrap_or(f64::NAN))
            .collect();
        crate::noise::add_measured(&mut report.budget, *o, on_grid);
    }
    let (lo, hi) = (
        measured.freqs_hz[0],
        measured.freqs_hz[measured.freqs_hz.len() - 1],
    );
    report.notes.push(format!(
        "measured spectrum {} covers {lo:e} .. {hi:e} Hz (NaN outside)",
        path.display()
    ));
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
