//! The `subtract` subcommand: the options parsed into the subtract job's request
//! ([`tiltnoise_job::subtract`]: the records read and checked, the coupling fitted, the tilt
//! part predicted and removed), the job run, then the report (table or JSON) and the outputs:
//! the cleaned record (.h5, the observable-series layout `budget --measured` reads), the
//! report (.json), the figure (.png, .svg). Documented in `docs/subtract.md`.

use super::args::{parse_readout_item, ChannelArgs, Format};
use super::figure_args::FigureArgs;
use super::output::save_image;
use super::witness_noise::{is_floor_input, parse_witness_items};
use super::Run;
use anyhow::{anyhow, bail, Result};
use clap::Args;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::{Num, OutputError, Shown};
use tiltnoise_core::model::{Input, Model};
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::{refuse_repeated_keys, refuse_repeats};
use tiltnoise_core::subtract::{Method, Status, SubtractResult};
use tiltnoise_io::write_subtract_hdf5;
use tiltnoise_job::budget::ReadRequest;
use tiltnoise_job::subtract::SubtractRequest;
use tiltnoise_job::subtract_report::band_top;
use tiltnoise_plot::subtract_figure::{subtract_figure, ObservablePanel, SubtractFigureData};

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

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SaveKind {
    Hdf5,
    Json,
    Image,
}

fn save_kind(path: &Path) -> Result<SaveKind, OutputError> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("h5" | "hdf5") => Ok(SaveKind::Hdf5),
        Some("json") => Ok(SaveKind::Json),
        Some("png" | "svg") => Ok(SaveKind::Image),
        _ => Err(OutputError::UnknownFormat {
            path: path.to_path_buf(),
            allowed: ".h5, .hdf5, .json, .png, .svg",
        }),
    }
}

fn parse_band(option: &str, text: &str) -> Result<(f64, f64)> {
    let err = || {
        anyhow!(
            "{option} {}: expected FLO:FHI in Hz with 0 < FLO < FHI, e.g. 3e-3:3e-2",
            Shown(text)
        )
    };
    let (a, b) = text.split_once(':').ok_or_else(err)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| err())?,
        b.trim().parse().map_err(|_| err())?,
    );
    if !(a.is_finite() && b.is_finite() && 0.0 < a && a < b) {
        return Err(err());
    }
    Ok((a, b))
}

/// `--fit KEY,...`: the parameter keys, each once.
fn fit_keys(specs: &[String]) -> Result<Vec<String>> {
    let keys = options::split_names("--fit", specs)?;
    refuse_repeats("--fit", "parameter key", &keys, |k| k.to_string())?;
    Ok(keys.into_iter().map(str::to_string).collect())
}

/// `--colocated-ratio INPUT=R`, each input once.
fn parse_colocated_ratio(items: &[String]) -> Result<Vec<(Input, f64)>> {
    let mut out: Vec<(Input, f64)> = Vec::new();
    for item in items {
        let shown = Shown(item);
        let (name, value) = item.split_once('=').ok_or_else(|| {
            anyhow!("--colocated-ratio {shown}: expected INPUT=R, e.g. eta_t=1.5")
        })?;
        let input = Input::from_name(name.trim())
            .filter(|&i| is_floor_input(i))
            .ok_or_else(|| {
                anyhow!(
                    "--colocated-ratio {shown}: `{}` is not a floor input of the model",
                    Shown(name)
                )
            })?;
        let r: f64 = value.trim().parse().map_err(|_| {
            anyhow!(
                "--colocated-ratio {shown}: `{}` is not a number",
                Shown(value)
            )
        })?;
        if !(r.is_finite() && r > 0.0) {
            bail!(
                "--colocated-ratio {shown}: the ratio {r} is not allowed: must be finite and > 0"
            );
        }
        if out.iter().any(|x| x.0 == input) {
            bail!(
                "--colocated-ratio {shown}: {} is given twice; give each input once",
                input.name()
            );
        }
        out.push((input, r));
    }
    Ok(out)
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

/// Runs `tiltnoise subtract`: the options parsed into the subtract job's request, the job run,
/// the report printed and the files written.
pub(crate) fn run_subtract(params: &Params, args: SubtractArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        save_kind(path)?;
    }
    // A figure of two rows of panels at 100 dpi, for the early check of `--dpi`.
    let view = args.figure.view_for((1800, 1360))?;
    let witness_noise = parse_witness_items(&args.witness_noise)?;
    let colocated_ratio = parse_colocated_ratio(&args.colocated_ratio)?;
    refuse_repeated_keys("--readout", "observable", &args.readout)?;
    let readout_asd = args
        .readout
        .iter()
        .map(|item| parse_readout_item(item))
        .collect::<Result<Vec<_>>>()?;
    let model = Model::new(params)?;
    let req = SubtractRequest {
        model: &model,
        tilt: args.tilt.clone(),
        read: read_request(&args)?,
        measured: args.measured.clone(),
        observables: match args.observables.is_empty() {
            true => None,
            false => Some(options::parse_outputs("--observables", &args.observables)?),
        },
        colocated: args.colocated.clone(),
        colocated_ratio,
        witness_noise,
        readout_asd,
        fit: fit_keys(&args.fit)?,
        band_hz: args
            .band
            .as_deref()
            .map(|b| parse_band("--band", b))
            .transpose()?,
        report_band_hz: parse_band("--report-band", &args.report_band)?,
        nperseg: args.nperseg,
        holdout: args.holdout,
        max_delay_s: args.max_delay,
    };
    run.check_job_outputs(&args.save, req.input_files())?;
    let outcome = tiltnoise_job::subtract::run(req, &run.cancel).map_err(super::job_error)?;
    let (result, meta) = (&outcome.result, &outcome.meta);
    for note in &outcome.input_notes {
        match args.format {
            Format::Json => super::note(&format!("input: {note}")),
            Format::Table => writeln!(run.out, "input: {note}")?,
        }
    }
    let json = outcome.report();
    match args.format {
        Format::Json => writeln!(run.out, "{}", json.to_json())?,
        Format::Table => write!(run.out, "{}", report_table(result))?,
    }
    run.write_outputs(args.format == Format::Json, || {
        for path in &args.save {
            match save_kind(path)? {
                SaveKind::Hdf5 => write_subtract_hdf5(path, result, meta)?,
                SaveKind::Json => json.write(path)?,
                SaveKind::Image => {
                    let data = figure_data(result);
                    save_image(path, |format| subtract_figure(&data, &view, format))?
                }
            }
        }
        Ok(())
    })
}

/// A value with its uncertainty for the table: `0.97015 +/- 9.2e-05`.
fn with_sigma(value: f64, sigma: f64) -> String {
    if sigma.is_finite() && sigma > 0.0 {
        let digits = (-(sigma.log10().floor()) + 1.0).clamp(0.0, 12.0) as usize;
        format!("{value:.digits$} +/- {sigma:.2e}")
    } else {
        format!("{value} +/- (not constrained at all)")
    }
}

fn report_table(r: &SubtractResult) -> String {
    let mut s = String::new();
    let a = &r.alignment;
    let _ = writeln!(s, "alignment: {}", a.note);
    let _ = writeln!(
        s,
        "overlap: {} samples at {} Hz ({} s); training {} samples, held out {} (the end); Welch \
         segment {} samples",
        a.len,
        Num(a.fs_hz),
        Num(a.len as f64 / a.fs_hz),
        r.n_train,
        r.n_holdout,
        r.segment_len
    );
    let f = &r.fit;
    let _ = writeln!(
        s,
        "fit band {} .. {} Hz, bins {}; chi^2 {:.1} for {} dof ({:.3}); uncertainties x {:.3}",
        Num(f.band_hz.0),
        Num(f.band_hz.1),
        f.bins
            .iter()
            .map(|(o, n)| format!("{} {n}", o.name()))
            .collect::<Vec<_>>()
            .join(", "),
        f.chi2,
        f.dof,
        f.chi2 / f.dof as f64,
        f.sigma_factor
    );
    for e in &r.colocated {
        let how = match &e.method {
            Method::Huddle {
                relative_gain,
                noise_ratio,
            } => format!(
                "huddle test with one co-located record (its gain relative to the witness {relative_gain:.4}, \
                 its noise {noise_ratio} times the witness's)"
            ),
            Method::ThreeCorneredHat { relative_gains } => format!(
                "three-cornered hat with two co-located records (gains relative to the witness \
                 {:.4}, {:.4})",
                relative_gains[0], relative_gains[1]
            ),
        };
        let _ = writeln!(
            s,
            "witness noise of {}: estimated by a {how}, +/- {:.1} % (ASD)",
            e.noise.input.name(),
            100.0 * e.noise.rel
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:<28} {:>14} {:>34}  status",
        "parameter", "nominal", "estimate"
    );
    for e in &f.estimates {
        let status = match e.status {
            Status::Fitted => match e.prior_sigma {
                Some(p) => format!("fitted, with its prior +/- {}", Num(p)),
                None => "fitted".to_string(),
            },
            Status::AtBound => format!("on the box [{}, {}]", Num(e.bounds.0), Num(e.bounds.1)),
            Status::NotConstrained if e.prior_sigma.is_some() => format!(
                "not constrained by the data alone: estimated with its prior {} +/- {}",
                Num(e.nominal),
                Num(e.scale)
            ),
            Status::NotConstrained => format!(
                "not constrained: held at nominal (the data would give +/- {}; scale {})",
                if e.sigma.is_finite() {
                    format!("{:.2e}", e.sigma)
                } else {
                    "infinity".to_string()
                },
                Num(e.scale)
            ),
        };
        let est = match (e.status, e.prior_sigma) {
            (Status::NotConstrained, None) => format!("{}", e.value),
            _ => with_sigma(e.value, e.sigma),
        };
        let _ = writeln!(
            s,
            "{:<28} {:>14} {:>34}  {status}",
            format!("{} ({})", e.name, e.unit),
            Num(e.nominal).to_string(),
            est
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "held-out residuals, band means as ASD (unit/sqrt(Hz)), +/- relative 1 sigma of a band \
         PSD:"
    );
    for res in &r.residuals {
        let b = &res.band;
        let _ = writeln!(
            s,
            "  {:<6} {} .. {} Hz ({} bins, +/- {:.1} %): measured {:.3e}, predicted {:.3e}, \
             cleaned {:.3e}, witness-noise limit {:.3e}, Wiener {:.3e} ({:.3e} without its \
             training noise), coherence limit {:.3e}",
            res.observable.name(),
            Num(b.band_hz.0),
            Num(b.band_hz.1),
            b.bins,
            100.0 * b.psd_rel_sigma,
            b.measured_asd,
            b.predicted_asd,
            b.cleaned_asd,
            b.witness_limited_asd,
            b.wiener_asd,
            b.wiener_corrected_asd,
            b.expected_asd
        );
        if let Some((ratio, sigma)) = b.cleaned_to_readout {
            let _ = writeln!(
                s,
                "         cleaned / readout = {ratio:.4} +/- {sigma:.4}; cleaned / coherence \
                 limit = {:.4} +/- {:.4}",
                b.cleaned_to_expected.0, b.cleaned_to_expected.1
            );
        } else {
            let _ = writeln!(
                s,
                "         cleaned / coherence limit = {:.4} +/- {:.4} (no --readout given)",
                b.cleaned_to_expected.0, b.cleaned_to_expected.1
            );
        }
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "the cleaned record against the raw one over the whole overlap, per 1/3-decade band \
         (band means as ASD; limit: 1 + z sigma of the ratio, z corrected for the number of \
         bands):"
    );
    for (o, check) in &r.bands {
        let _ = writeln!(
            s,
            "  {:<6} variance cleaned/raw {:.4}{}",
            o.name(),
            check.variance_ratio,
            if check.left_raw {
                " (left raw entirely)"
            } else {
                ""
            }
        );
        let _ = writeln!(
            s,
            "         {:>9} .. {:<9} {:>5}  {:>10} {:>10} {:>10} {:>10}  {:>10}  {:>6}",
            "f_lo/Hz",
            "f_hi/Hz",
            "bins",
            "raw",
            "expected",
            "cleaned",
            "witness",
            "cleaned/raw",
            "limit"
        );
        for b in &check.bands {
            let _ = writeln!(
                s,
                "         {:>9.3e} .. {:<9.3e} {:>5}  {:>10.3e} {:>10.3e} {:>10.3e} {:>10.3e}  {:>11.4} {:>6.3}{}",
                b.lo_hz,
                band_top(b.hi_hz, a.fs_hz),
                b.bins,
                b.raw_psd.sqrt(),
                b.expected_psd.sqrt(),
                b.cleaned_psd.sqrt(),
                b.witness_limited_psd.sqrt(),
                b.ratio,
                b.limit,
                if b.left_raw { "  left raw" } else { "" }
            );
        }
    }
    for note in &r.notes {
        let _ = writeln!(s, "note: {note}");
    }
    s
}

/// `x` with three significant digits, without an exponent for 1e-4 <= |x| < 1e4.
fn sig3(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || !(1e-4..1e4).contains(&x.abs()) {
        return format!("{x:.2e}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

fn figure_data(r: &SubtractResult) -> SubtractFigureData {
    let asd = |p: &[f64]| p.iter().map(|v| v.max(0.0).sqrt()).collect::<Vec<f64>>();
    let mut caption = Vec::new();
    let est: Vec<String> = r
        .fit
        .estimates
        .iter()
        .map(|e| match (e.status, e.prior_sigma) {
            (Status::NotConstrained, None) => {
                format!("{} not constrained (held at {})", e.name, e.nominal)
            }
            _ => format!(
                "{} = {}",
                e.name,
                with_sigma(e.value, e.sigma).replace("+/-", "±")
            ),
        })
        .collect();
    caption.push(format!(
        "Fit ({}–{} Hz, χ²/dof = {:.3}): {}.",
        sig3(r.fit.band_hz.0),
        sig3(r.fit.band_hz.1),
        r.fit.chi2 / r.fit.dof as f64,
        est.join(", ")
    ));
    let ratios: Vec<String> = r
        .residuals
        .iter()
        .filter_map(|res| {
            res.band
                .cleaned_to_readout
                .map(|(ratio, sigma)| format!("{} {ratio:.3} ± {sigma:.3}", res.observable.name()))
        })
        .collect();
    if let Some(first) = r.residuals.first() {
        caption.push(format!(
            "Report band {}–{} Hz (dotted lines){}.",
            sig3(first.band.band_hz.0),
            sig3(first.band.band_hz.1),
            if ratios.is_empty() {
                String::new()
            } else {
                format!(": cleaned / readout ASD = {}", ratios.join(", "))
            }
        ));
    }
    let excess = r
        .residuals
        .first()
        .map_or(f64::NAN, |s| s.wiener_training_excess);
    let witness = if r
        .witness_noise_psd
        .iter()
        .any(|(_, m)| m.iter().any(|&v| v > 0.0))
    {
        " Witness-noise limit: what the witness's own noise keeps any filter of it from \
         removing, through the fitted model."
    } else {
        ""
    };
    caption.push(format!(
        "Held-out stretch: the last {} of {} samples at {} Hz; Welch {} samples, Hann, 50 % \
         overlap. Wiener residual: multiple-input filter trained on the first {} samples (its \
         training noise adds about {:.1} % to its PSD). Coherence limit: (1 − γ²) of the \
         measured PSD, the least any linear filter of the witness record can leave.{witness}",
        r.n_holdout,
        r.alignment.len,
        Num(r.alignment.fs_hz),
        r.segment_len,
        r.n_train,
        100.0 * excess
    ));
    SubtractFigureData {
        panels: r
            .residuals
            .iter()
            .map(|s| ObservablePanel {
                observable: s.observable,
                freqs_hz: s.freqs_hz.clone(),
                measured: asd(&s.measured_psd),
                predicted: asd(&s.predicted_psd),
                cleaned: asd(&s.cleaned_psd),
                wiener: asd(&s.wiener_psd),
                expected: asd(&s.expected_psd),
                witness_limited: asd(&s.witness_limited_psd),
                left_raw: r
                    .bands
                    .iter()
                    .find(|(o, _)| *o == s.observable)
                    .map(|(_, c)| {
                        c.bands
                            .iter()
                            .filter(|b| b.left_raw || c.left_raw)
                            .map(|b| (b.lo_hz, band_top(b.hi_hz, r.alignment.fs_hz)))
                            .collect()
                    })
                    .unwrap_or_default(),
                readout: s.readout_asd,
            })
            .collect(),
        band_hz: r
            .residuals
            .first()
            .map_or((f64::NAN, f64::NAN), |s| s.band.band_hz),
        caption,
    }
}
