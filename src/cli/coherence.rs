//! `tiltnoise coherence`: a tilt time series and a measured time series of the observables ->
//! coherence, measured transfer functions with confidence intervals, the model's beside them ->
//! files and a terminal summary.

use super::args::{tilt_read_options, Format};
use super::figure_args::FigureArgs;
use super::tf::parse_observables;
use super::Run;
use anyhow::Result;
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;
use tiltnoise_core::coherence::{with_error, CoherenceReport, ObservableEstimate};
use tiltnoise_core::model::Model;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::coherence::{peak_bin, significant_bins, CoherenceOutcome, CoherenceRequest};
use tiltnoise_job::{Invocation, Outcome};

/// Arguments of `tiltnoise coherence`.
#[derive(Debug, Args)]
pub struct CoherenceArgs {
    /// Tilt time series (HDF5 or CSV, angle or rate); see docs/input_formats.md.
    #[arg(long, value_name = "FILE")]
    pub tilt: PathBuf,
    /// Measured time series of the observables: HDF5 as `tiltnoise simulate` writes it, or CSV
    /// `time_s,X,...` (m, rad). Records are aligned by their start times (`start_time`
    /// attribute, `# start_time:` line); without them both start together.
    #[arg(long, value_name = "FILE")]
    pub measured: PathBuf,
    /// Axis map of the tilt file, e.g. `theta_t=-E,eta_t=-N` (default: from the file, else
    /// theta_t=-E, eta_t=-N).
    #[arg(long, value_name = "MAP", allow_hyphen_values = true)]
    pub axes: Option<String>,
    /// Quantity of the tilt channels: angle (rad) or rate (rad/s); default from the file, else
    /// angle.
    #[arg(long, value_name = "angle|rate")]
    pub quantity: Option<String>,
    /// Non-finite tilt samples: reject (default) or interpolate linearly across interior gaps.
    #[arg(long, value_name = "reject|interpolate")]
    pub gaps: Option<String>,
    /// Scale factor of a source channel of the tilt record, `CHANNEL=FACTOR` (rad or rad/s per
    /// count, or per unit of the file), applied before the axis map; required for miniSEED
    /// channels in counts. Repeat for several channels.
    #[arg(long, value_name = "CHANNEL=FACTOR")]
    pub scale: Vec<String>,
    /// Observables to analyse, comma-separated (default: every observable in the measured file).
    #[arg(long = "observables", alias = "output", value_name = "OBS,...")]
    pub outputs: Vec<String>,
    /// Welch segment length in samples (default 2^14, or the largest power of two <= N/4 of the
    /// common stretch).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub nperseg: Option<usize>,
    /// Welch overlap as a fraction of the segment (default 0.5).
    #[arg(long, value_name = "FRACTION", allow_negative_numbers = true)]
    pub overlap: Option<f64>,
    /// Confidence level of every interval and threshold (default 0.95).
    #[arg(long, value_name = "LEVEL", allow_negative_numbers = true)]
    pub confidence: Option<f64>,
    /// Band of the measured/model fit, FLO:FHI in Hz (default: every bin).
    #[arg(long, value_name = "FLO:FHI", allow_hyphen_values = true)]
    pub fit_band: Option<String>,
    /// Output format on the terminal: table (default) or json (the summary, the input notes
    /// and the notes; `wrote` lines then go to standard error).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Output file (.h5, .csv, .png, .svg), repeatable.
    #[arg(long, value_name = "PATH")]
    pub save: Vec<PathBuf>,
    #[command(flatten)]
    pub figure: FigureArgs,
}

/// Size of a coherence figure of two rows at 100 dpi, for the early check of `--dpi`.
const COHERENCE_SIZE: (u32, u32) = (1650, 900);

/// `--fit-band FLO:FHI` as numbers (the job checks the band).
fn parse_fit_band(text: &str) -> Result<(f64, f64)> {
    Ok(options::parse_range(
        OptionKey::FIT_BAND,
        text,
        "expected FLO:FHI in Hz, e.g. 1e-3:0.1",
    )?)
}

/// Runs `tiltnoise coherence`: the options parsed into the coherence job's request, the job
/// run, the summary printed and the files written.
pub(crate) fn run_coherence(params: &Params, args: CoherenceArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        tiltnoise_job::output_kind(path, tiltnoise_job::coherence::OUTPUT_KINDS)?;
    }
    args.figure.refuse_without_figure(&args.save)?;
    let view = args.figure.view_for(COHERENCE_SIZE)?;
    let model = Model::new(params)?;
    let o = tilt_read_options(
        args.axes.as_deref(),
        args.quantity.as_deref(),
        args.gaps.as_deref(),
        &args.scale,
    )?;
    let req = CoherenceRequest {
        model: &model,
        tilt: args.tilt.clone(),
        read: ReadRequest {
            axis_map: o.axis_map,
            quantity: o.quantity,
            gaps: Some(o.gaps),
            scale: o.scale,
            ..ReadRequest::default()
        },
        measured: args.measured.clone(),
        observables: match args.outputs.is_empty() {
            true => None,
            false => Some(parse_observables(&args.outputs)?),
        },
        nperseg: args.nperseg,
        overlap: args.overlap,
        confidence: args.confidence,
        fit_band_hz: args.fit_band.as_deref().map(parse_fit_band).transpose()?,
        view,
        invocation: Invocation::of_this_process(),
    };
    run.check_job_outputs(&args.save, req.input_files())?;
    let outcome: CoherenceOutcome =
        tiltnoise_job::coherence::run(&req, &run.cancel, &tiltnoise_job::Silent)
            .map_err(super::job_error)?;
    let CoherenceOutcome { report, inputs, .. } = &outcome;
    match args.format {
        Format::Table => {
            for note in &inputs.tilt.notes {
                writeln!(run.out, "input: {note}")?;
            }
            write!(run.out, "{}", summary(report))?;
        }
        Format::Json => {
            writeln!(
                run.out,
                "{}",
                serde_json::to_string_pretty(&outcome.json())?
            )?;
        }
    }
    run.write_outputs(args.format == Format::Json, |stage| {
        for out in &args.save {
            outcome.save(stage, out).map_err(super::job_error)?;
        }
        Ok(())
    })
}

/// A band of bins as text: `N bins in FLO..FHI Hz`.
fn bins_text(freqs: &[f64], selected: &[usize]) -> String {
    match (selected.first(), selected.last()) {
        (Some(&a), Some(&b)) => format!(
            "{} of {} bins, {:.3e}..{:.3e} Hz",
            selected.len(),
            freqs.len(),
            freqs[a],
            freqs[b]
        ),
        _ => format!("none of {} bins", freqs.len()),
    }
}

fn summary(report: &CoherenceReport) -> String {
    let mut s = String::new();
    let w = &report.welch;
    let pct = 100.0 * report.confidence;
    let _ = writeln!(
        s,
        "coherence: {} common samples at {} Hz ({:.4} h); Welch {} samples (overlap {}), {} \
         segments, {:.1} independent averages",
        w.n_samples,
        w.sample_rate_hz,
        w.n_samples as f64 / w.sample_rate_hz / 3600.0,
        w.segment_len,
        w.overlap,
        w.n_segments,
        w.n_equivalent
    );
    let _ = writeln!(
        s,
        "  noise thresholds at {pct:.0} %: ordinary coherence {:.3}, multiple coherence with {} \
         axes {:.3}",
        report.coherence_threshold,
        report.axes.len(),
        report.multiple_coherence_threshold
    );
    for ob in &report.observables {
        observable_summary(&mut s, report, ob);
    }
    for note in &report.notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}

fn observable_summary(s: &mut String, report: &CoherenceReport, ob: &ObservableEstimate) {
    let f = &report.freqs_hz;
    let unit = ob.observable.unit();
    let significant = significant_bins(report, ob);
    let _ = writeln!(
        s,
        "  {}: multiple coherence significant in {} (about {:.0} expected from noise alone)",
        ob.observable.name(),
        bins_text(f, &significant),
        (1.0 - report.confidence) * f.len() as f64
    );
    for a in &ob.axes {
        let peak = peak_bin(a)
            .map(|k| format!("max coherence {:.3} at {:.3e} Hz", a.coherence[k], f[k]))
            .unwrap_or_else(|| "no finite coherence".into());
        let model_zero = a.model.iter().all(|z| z.norm() == 0.0);
        let fit = match (&a.agreement, model_zero) {
            (_, true) => "model identically 0".to_string(),
            (Some(g), false) => {
                let (gain, gain_sigma) = with_error(g.gain(), g.sigma);
                let (phase, phase_sigma) = with_error(g.phase_deg(), g.phase_sigma_deg());
                format!(
                    "measured/model = {gain} +/- {gain_sigma} at {phase} +/- {phase_sigma} deg \
                     ({} bins, {:.3e}..{:.3e} Hz, chi2/nu {:.2})",
                    g.n_bins, g.band_hz.0, g.band_hz.1, g.chi2_per_dof
                )
            }
            (None, false) => "no bin to compare with the model".to_string(),
        };
        let _ = writeln!(
            s,
            "    {:<7} {peak}; {fit} [H in {unit}/rad]",
            a.axis.name()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_band_parses_and_refuses() {
        assert_eq!(parse_fit_band("1e-3:0.1").unwrap(), (1e-3, 0.1));
        for bad in ["1e-3", "a:1", "1:b"] {
            let e = crate::option_style::rendered(&parse_fit_band(bad).unwrap_err());
            assert!(e.starts_with("--fit-band"), "{bad}: {e}");
        }
    }
}
