//! The `subtract` subcommand: the tilt record and the measured record read and checked, the
//! coupling fitted, the tilt part predicted and removed ([`tiltnoise_core::subtract`]), then
//! the report (table or JSON) and the outputs: the cleaned record (.h5, the observable-series
//! layout `budget --measured` reads), the report (.json), the figure (.png, .svg). Documented
//! in `docs/subtract.md`.

use super::args::{parse_readout_item, ChannelArgs, Format};
use super::figure_args::FigureArgs;
use super::output::save_image;
use super::witness_noise::{is_floor_input, parse_witness_noise};
use super::Run;
use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tiltnoise_core::error::{Num, OutputError, Shown};
use tiltnoise_core::input::{GroundMap, Provenance, Sensors, TiltSeries};
use tiltnoise_core::model::{Input, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::{refuse_repeated_keys, refuse_repeats};
use tiltnoise_core::subtract::{
    subtract, MeasuredRecord, Method, NoiseLevel, StartTime, Status, SubtractConfig,
    SubtractResult, WitnessNoise, WitnessRecord,
};
use tiltnoise_io::input::{
    parse_start_time, read_measured_input, read_tilt, utc_text, MeasuredInput, ReadOptions,
    TiltInput,
};
use tiltnoise_io::{write_atomic, write_subtract_hdf5, InputMeta, RunMeta, SubtractMeta};
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

fn read_options(args: &SubtractArgs) -> Result<ReadOptions> {
    super::args::read_options(
        args.axes.as_deref(),
        args.quantity.as_deref(),
        args.gaps.as_deref(),
        &args.scale,
        &args.channels,
    )
}

/// A witness record as the subtraction takes it: one series per input, each the input's
/// displacement (rad, m), with the provenance of the file it came from.
struct Witness {
    inputs: Vec<Input>,
    data: Vec<Vec<f64>>,
    sample_rate_hz: f64,
    provenance: Provenance,
}

impl Witness {
    /// The record's channels as displacements. A record of tilt alone keeps its angles (a rate
    /// integrated as `budget`'s series are); with translation channels, or sensors declared
    /// other than the default, every channel goes through the floor's [`GroundMap`]: velocity
    /// and acceleration integrated to displacement in the frequency domain, an inertial
    /// seismometer's tilt part removed with the record's tilt (`x_t = u - g II(eta_t)`,
    /// `y_t = u + g II(theta_t)`), a pendulum tiltmeter's translation part with the record's
    /// translation.
    fn from_series(series: TiltSeries, g_m_per_s2: f64) -> std::result::Result<Witness, String> {
        if series.translations.is_empty() && series.sensors == Sensors::default() {
            let series = series.into_angle();
            return Ok(Witness {
                inputs: series.axes.iter().map(|&a| Input::Tilt(a)).collect(),
                data: series.data,
                sample_rate_hz: series.sample_rate_hz,
                provenance: series.provenance,
            });
        }
        let map = GroundMap::new(&series.channels(), g_m_per_s2)?;
        let channel_data: Vec<Vec<f64>> =
            series.channel_data().iter().map(|c| c.to_vec()).collect();
        let data = map.displacements(&channel_data, series.sample_rate_hz);
        let mut provenance = series.provenance;
        provenance
            .notes
            .retain(|note| !note.starts_with("rate to angle"));
        provenance.notes.extend(map.series_note());
        provenance.notes.extend(map.notes().iter().cloned());
        Ok(Witness {
            inputs: map.inputs(),
            data,
            sample_rate_hz: series.sample_rate_hz,
            provenance,
        })
    }
}

fn start_of(path: &Path, what: &str, start: &Option<String>) -> Result<Option<StartTime>> {
    start
        .as_deref()
        .map(|s| {
            parse_start_time(s)
                .map(|t| {
                    let ns = t.as_nanosecond();
                    StartTime {
                        unix_s: ns.div_euclid(1_000_000_000) as i64,
                        frac_s: ns.rem_euclid(1_000_000_000) as f64 * 1e-9,
                    }
                })
                .ok_or_else(|| {
                    anyhow!(
                        "{what} {}: start time `{}` is not an ISO 8601 date-time",
                        path.display(),
                        Shown(s)
                    )
                })
        })
        .transpose()
}

/// The channels of the measured record named by `--observables` (all when none is named).
fn select_observables(
    path: &Path,
    names: &[String],
    channels: Vec<(Observable, Vec<f64>)>,
) -> Result<Vec<(Observable, Vec<f64>)>> {
    for (i, (o, _)) in channels.iter().enumerate() {
        if channels[..i].iter().any(|(x, _)| x == o) {
            bail!(
                "--measured {}: channel {} appears twice; give each observable once",
                path.display(),
                o.name()
            );
        }
    }
    if names.is_empty() {
        return Ok(channels);
    }
    let available = || {
        channels
            .iter()
            .map(|c| c.0.name())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let wanted = options::parse_outputs("--observables", names)?;
    for o in &wanted {
        if !channels.iter().any(|c| c.0 == *o) {
            bail!(
                "--observables {0}: --measured {1} has no channel {0}; it has {2}",
                o.name(),
                path.display(),
                available()
            );
        }
    }
    Ok(channels
        .into_iter()
        .filter(|c| wanted.contains(&c.0))
        .collect())
}

/// Runs `tiltnoise subtract`.
pub(crate) fn run_subtract(params: &Params, args: SubtractArgs, run: &mut Run) -> Result<()> {
    for path in &args.save {
        save_kind(path)?;
    }
    // A figure of two rows of panels at 100 dpi, for the early check of `--dpi`.
    let view = args.figure.view_for((1800, 1360))?;
    let saves: Vec<&Path> = args.save.iter().map(PathBuf::as_path).collect();
    let (witness_noise, noise_files) = parse_witness_noise(&args.witness_noise)?;
    let mut inputs: Vec<(&str, &Path)> =
        vec![("--tilt", &args.tilt), ("--measured", &args.measured)];
    inputs.extend(noise_files.iter().map(|p| ("--witness-noise", p.as_path())));
    inputs.extend(args.colocated.iter().map(|p| ("--colocated", p.as_path())));
    run.check_outputs(&saves, &inputs)?;
    if args.colocated.len() > 2 {
        bail!(
            "--colocated is given {} times: give one record (a huddle test with the witness) or \
             two (a three-cornered hat)",
            args.colocated.len()
        );
    }
    let colocated_noise_ratio = parse_colocated_ratio(&args.colocated_ratio)?;
    if !colocated_noise_ratio.is_empty() && args.colocated.len() != 1 {
        bail!(
            "--colocated-ratio applies to a huddle test: give exactly one --colocated record \
             (a three-cornered hat needs no noise ratio)"
        );
    }
    refuse_repeated_keys("--readout", "observable", &args.readout)?;
    let readout = args
        .readout
        .iter()
        .map(|item| parse_readout_item(item))
        .collect::<Result<Vec<_>>>()?;
    let cfg = SubtractConfig {
        segment_len: args.nperseg,
        holdout_fraction: args.holdout,
        keys: fit_keys(&args.fit)?,
        fit_band_hz: args
            .band
            .as_deref()
            .map(|b| parse_band("--band", b))
            .transpose()?,
        max_delay_s: args.max_delay,
        witness_noise,
        colocated_noise_ratio,
        readout_asd: readout,
        report_band_hz: parse_band("--report-band", &args.report_band)?,
    };
    let read_series = |option: &str, path: &Path| -> Result<Witness> {
        match read_tilt(path, &read_options(&args)?)? {
            TiltInput::Series(s) => Witness::from_series(s, params.environment.g_m_per_s2)
                .map_err(|e| anyhow!("{option} {}: {e}", path.display())),
            TiltInput::Spectra(_) => bail!(
                "{option} {}: holds spectra; subtract needs a time series of the floor's motion \
                 (tilt angle or rate, and translation)",
                path.display()
            ),
        }
    };
    let series = read_series("--tilt", &args.tilt)?;
    let colocated_series = args
        .colocated
        .iter()
        .map(|p| read_series("--colocated", p))
        .collect::<Result<Vec<_>>>()?;
    let measured = match read_measured_input(&args.measured)? {
        MeasuredInput::Series(m) => m,
        MeasuredInput::Spectra(_) => bail!(
            "--measured {}: holds spectra; subtract needs a time series of the observables \
             (HDF5 as `tiltnoise simulate` writes, or CSV time_s,X,...)",
            args.measured.display()
        ),
    };
    let channels = select_observables(&args.measured, &args.observables, measured.channels)?;
    let tilt_start = start_of(&args.tilt, "--tilt", &series.provenance.start_time)?;
    let measured_start = start_of(&args.measured, "--measured", &measured.start_time)?;
    let context = || {
        format!(
            "subtract --tilt {} --measured {}",
            args.tilt.display(),
            args.measured.display()
        )
    };
    let colocated = colocated_series
        .iter()
        .zip(&args.colocated)
        .map(|(s, path)| {
            Ok(WitnessRecord {
                fs_hz: s.sample_rate_hz,
                inputs: &s.inputs,
                data: &s.data,
                start: start_of(path, "--colocated", &s.provenance.start_time)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let result = subtract(
        params,
        &WitnessRecord {
            fs_hz: series.sample_rate_hz,
            inputs: &series.inputs,
            data: &series.data,
            start: tilt_start,
        },
        &colocated,
        &MeasuredRecord {
            fs_hz: measured.sample_rate_hz,
            channels: &channels,
            start: measured_start,
        },
        &cfg,
    )
    .with_context(context)?;
    check_finite(&result).with_context(context)?;
    let skipped =
        Duration::from_secs_f64(result.alignment.measured_first as f64 / result.alignment.fs_hz);
    let overlap_start = measured
        .start_time
        .as_deref()
        .and_then(parse_start_time)
        .and_then(|t| t.checked_add(skipped).ok())
        .map(utc_text);
    let input = InputMeta::from(&series.provenance);
    for note in &series.provenance.notes {
        match args.format {
            Format::Json => super::note(&format!("input: {note}")),
            Format::Table => writeln!(run.out, "input: {note}")?,
        }
    }
    let json = report_json(&result, &args, &cfg.witness_noise, &overlap_start);
    match args.format {
        Format::Json => writeln!(run.out, "{}", serde_json::to_string_pretty(&json)?)?,
        Format::Table => write!(run.out, "{}", report_table(&result))?,
    }
    let model = tiltnoise_core::model::Model::new(params)?;
    let meta = SubtractMeta {
        run: RunMeta::of_this_run(params, Some(&NormalModes::new(&model))),
        tilt: input,
        measured_path: args.measured.display().to_string(),
        start_time: overlap_start.clone(),
    };
    run.write_outputs(args.format == Format::Json, || {
        for path in &args.save {
            match save_kind(path)? {
                SaveKind::Hdf5 => write_subtract_hdf5(path, &result, &meta)?,
                SaveKind::Json => {
                    let text = serde_json::to_string_pretty(&json)? + "\n";
                    write_atomic(path, |tmp| {
                        std::fs::write(tmp, text.as_bytes()).map_err(|e| e.to_string())
                    })?
                }
                SaveKind::Image => {
                    let data = figure_data(&result);
                    save_image(path, |format| subtract_figure(&data, &view, format))?
                }
            }
        }
        Ok(())
    })
}

/// Every number the run reports or writes must be finite, except the uncertainty of a
/// parameter the data do not constrain at all (reported as not available).
fn check_finite(r: &SubtractResult) -> Result<()> {
    for e in &r.fit.estimates {
        if !e.value.is_finite() || (e.status != Status::NotConstrained && !e.sigma.is_finite()) {
            bail!(
                "the fit of {} gave {} +/- {}: not finite (the data may be degenerate; fit \
                 fewer parameters)",
                e.name,
                e.value,
                e.sigma
            );
        }
    }
    if !(r.fit.chi2.is_finite() && r.fit.sigma_factor.is_finite()) {
        bail!("the fit's chi^2 is {}: not finite", r.fit.chi2);
    }
    for res in &r.residuals {
        let b = &res.band;
        let values = [
            ("measured", b.measured_asd),
            ("predicted", b.predicted_asd),
            ("cleaned", b.cleaned_asd),
            ("Wiener residual", b.wiener_asd),
            ("coherence limit", b.expected_asd),
            ("cleaned / coherence limit", b.cleaned_to_expected.0),
            ("its sigma", b.cleaned_to_expected.1),
        ];
        let readout = b.cleaned_to_readout.map_or([0.0; 2], |(x, s)| [x, s]);
        if let Some((what, v)) = values
            .into_iter()
            .chain([("cleaned / readout", readout[0]), ("its sigma", readout[1])])
            .find(|(_, v)| !v.is_finite())
        {
            bail!(
                "the {what} ASD of {} in the report band is {v}: not finite (is the channel \
                 constant or noiseless there? leave it out with --observables)",
                res.observable.name()
            );
        }
    }
    for (o, x) in r.cleaned.iter().chain(&r.prediction.series) {
        if let Some((i, v)) = x.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            bail!(
                "the prediction of {} at sample {i} is {v}: not finite",
                o.name()
            );
        }
    }
    Ok(())
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

// Keys in alphabetical order (fields declared in that order), as every JSON report of the tool.

#[derive(Serialize)]
struct ReportJson {
    alignment: AlignmentJson,
    bands: Vec<BandCheckJson>,
    estimates: Vec<EstimateJson>,
    fit: FitJson,
    measured: String,
    notes: Vec<String>,
    residuals: Vec<ResidualJson>,
    tilt: String,
    witness_noise: Vec<NoiseJson>,
}

#[derive(Serialize)]
struct BandCheckJson {
    bands: Vec<BandJson>,
    left_raw: bool,
    observable: &'static str,
    unit: String,
    variance_ratio: f64,
}

#[derive(Serialize)]
struct BandJson {
    band_hz: [f64; 2],
    bins: usize,
    cleaned_asd: f64,
    expected_asd: f64,
    left_raw: bool,
    limit: f64,
    ratio: f64,
    raw_asd: f64,
    sigma: f64,
    witness_limited_asd: f64,
}

#[derive(Serialize)]
struct NoiseJson {
    asd: Option<f64>,
    file: Option<String>,
    fitted_scale: f64,
    input: &'static str,
    method: &'static str,
    rel: f64,
    relative_gains: Vec<f64>,
    unit: String,
}

#[derive(Serialize)]
struct AlignmentJson {
    fraction_s: f64,
    holdout_samples: usize,
    measured_first_sample: usize,
    note: String,
    overlap_start_time: Option<String>,
    sample_rate_hz: f64,
    samples: usize,
    segment_len: usize,
    start_offset_s: Option<f64>,
    tilt_first_sample: usize,
    training_samples: usize,
}

#[derive(Serialize)]
struct EstimateJson {
    lower: f64,
    name: String,
    nominal: f64,
    prior_sigma: Option<f64>,
    scale: f64,
    sigma: Option<f64>,
    status: &'static str,
    unit: String,
    upper: f64,
    value: f64,
}

#[derive(Serialize)]
struct FitJson {
    band_hz: [f64; 2],
    bins: std::collections::BTreeMap<&'static str, usize>,
    chi2: f64,
    coherent_top_hz: Option<f64>,
    dof: usize,
    fitted: Vec<String>,
    iterations: usize,
    max_delay_s: f64,
    sigma_factor: f64,
    stop: &'static str,
    witness_bias: std::collections::BTreeMap<&'static str, f64>,
}

#[derive(Serialize)]
struct ResidualJson {
    band_hz: [f64; 2],
    bins: usize,
    below_coherence_bound: bool,
    cleaned_asd: f64,
    cleaned_to_expected: [f64; 2],
    cleaned_to_readout: Option<[f64; 2]>,
    expected_asd: f64,
    measured_asd: f64,
    observable: &'static str,
    predicted_asd: f64,
    psd_rel_sigma: f64,
    readout_asd: Option<f64>,
    unit: String,
    wiener_asd: f64,
    wiener_corrected_asd: f64,
    wiener_training_excess: f64,
    witness_limited_asd: f64,
}

/// The upper edge of a band as reported: the last band reaches the Nyquist frequency.
fn band_top(hi: f64, fs_hz: f64) -> f64 {
    hi.min(fs_hz / 2.0)
}

fn report_json(
    r: &SubtractResult,
    args: &SubtractArgs,
    noise: &[WitnessNoise],
    start: &Option<String>,
) -> ReportJson {
    let a = &r.alignment;
    let fs = a.fs_hz;
    ReportJson {
        bands: r
            .bands
            .iter()
            .map(|(o, c)| BandCheckJson {
                bands: c
                    .bands
                    .iter()
                    .map(|b| BandJson {
                        band_hz: [b.lo_hz, band_top(b.hi_hz, fs)],
                        bins: b.bins,
                        cleaned_asd: b.cleaned_psd.sqrt(),
                        expected_asd: b.expected_psd.sqrt(),
                        left_raw: b.left_raw,
                        limit: b.limit,
                        ratio: b.ratio,
                        raw_asd: b.raw_psd.sqrt(),
                        sigma: b.sigma,
                        witness_limited_asd: b.witness_limited_psd.sqrt(),
                    })
                    .collect(),
                left_raw: c.left_raw,
                observable: o.name(),
                unit: format!("{}/sqrt(Hz)", o.unit()),
                variance_ratio: c.variance_ratio,
            })
            .collect(),
        witness_noise: noise
            .iter()
            .map(|x| (x, None))
            .chain(r.colocated.iter().map(|e| (&e.noise, Some(&e.method))))
            .map(|(x, method)| {
                let a = r
                    .witness_noise_psd
                    .iter()
                    .position(|(i, _)| *i == x.input)
                    .expect("every stated noise belongs to a witness input");
                let (asd, file) = match &x.level {
                    NoiseLevel::White(v) => (Some(*v), None),
                    NoiseLevel::Curve(c) => (None, Some(c.origin().to_string())),
                };
                let (method, relative_gains) = match method {
                    None => ("given", Vec::new()),
                    Some(Method::Huddle { relative_gain, .. }) => ("huddle", vec![*relative_gain]),
                    Some(Method::ThreeCorneredHat { relative_gains }) => {
                        ("three-cornered hat", relative_gains.to_vec())
                    }
                };
                NoiseJson {
                    asd,
                    file,
                    fitted_scale: r.fit.noise_factors[a].sqrt(),
                    input: x.input.name(),
                    method,
                    rel: x.rel,
                    relative_gains,
                    unit: format!("{}/sqrt(Hz)", x.input.unit()),
                }
            })
            .collect(),
        alignment: AlignmentJson {
            fraction_s: a.fraction_s,
            holdout_samples: r.n_holdout,
            measured_first_sample: a.measured_first,
            note: a.note.clone(),
            overlap_start_time: start.clone(),
            sample_rate_hz: a.fs_hz,
            samples: a.len,
            segment_len: r.segment_len,
            start_offset_s: a.start_offset_s,
            tilt_first_sample: a.witness_first,
            training_samples: r.n_train,
        },
        estimates: r
            .fit
            .estimates
            .iter()
            .map(|e| EstimateJson {
                lower: e.bounds.0,
                name: e.name.clone(),
                nominal: e.nominal,
                prior_sigma: e.prior_sigma,
                scale: e.scale,
                sigma: finite(e.sigma),
                status: e.status.name(),
                unit: e.unit.clone(),
                upper: e.bounds.1,
                value: e.value,
            })
            .collect(),
        fit: FitJson {
            band_hz: [r.fit.band_hz.0, r.fit.band_hz.1],
            bins: r.fit.bins.iter().map(|(o, n)| (o.name(), *n)).collect(),
            chi2: r.fit.chi2,
            coherent_top_hz: r.fit.coherent_top_hz,
            dof: r.fit.dof,
            fitted: r.fit.fitted.clone(),
            iterations: r.fit.iterations,
            max_delay_s: r.max_delay_s,
            sigma_factor: r.fit.sigma_factor,
            stop: r.fit.stop.describe(),
            witness_bias: r
                .witness_noise_psd
                .iter()
                .map(|(i, _)| i.name())
                .zip(r.fit.witness_bias.iter().copied())
                .collect(),
        },
        measured: args.measured.display().to_string(),
        notes: r.notes.clone(),
        residuals: r
            .residuals
            .iter()
            .map(|s| {
                let b = &s.band;
                ResidualJson {
                    band_hz: [b.band_hz.0, b.band_hz.1],
                    bins: b.bins,
                    below_coherence_bound: b.below_coherence_bound,
                    cleaned_asd: b.cleaned_asd,
                    cleaned_to_expected: [b.cleaned_to_expected.0, b.cleaned_to_expected.1],
                    cleaned_to_readout: b.cleaned_to_readout.map(|(x, s)| [x, s]),
                    expected_asd: b.expected_asd,
                    measured_asd: b.measured_asd,
                    observable: s.observable.name(),
                    predicted_asd: b.predicted_asd,
                    psd_rel_sigma: b.psd_rel_sigma,
                    readout_asd: s.readout_asd,
                    unit: format!("{}/sqrt(Hz)", s.observable.unit()),
                    wiener_asd: b.wiener_asd,
                    wiener_corrected_asd: b.wiener_corrected_asd,
                    wiener_training_excess: s.wiener_training_excess,
                    witness_limited_asd: b.witness_limited_asd,
                }
            })
            .collect(),
        tilt: args.tilt.display().to_string(),
    }
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
