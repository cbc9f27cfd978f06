//! The `simulate` subcommand: free motion of the undamped model (exact modal propagation),
//! readout noise, one-sided Welch ASDs, the resonance check against the observability table,
//! and the outputs (HDF5 series + ASDs, CSV ASDs, Figure 3, Figures 4/5). Owns the progress
//! bar (only when stderr is a terminal and the run is long). Documented in `docs/simulate.md`.

use super::args::scientific;
use super::figure_args::FigureArgs;
use super::output::save_image;
use super::Run;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use tiltnoise_core::error::Num;
use tiltnoise_core::limits::{check_memory, planned_bytes, STREAMED_WELCH_BYTES_PER_SAMPLE};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::noise::Readout;
use tiltnoise_core::options;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::resonance::check_resonances;
use tiltnoise_core::simulate::stream::{
    check_streamed_samples, FreeMotion, MinMaxEnvelope, SimChunk,
};
use tiltnoise_core::simulate::{
    self, aliased_frequency_hz, default_sim_nperseg, parse_coordinates, Excitation, InitialState,
    ModalPropagator, SimConfig, DEFAULT_MODE_ENERGY_J,
};
use tiltnoise_core::spectral::{Psd, WelchAccumulator, WelchConfig};
use tiltnoise_io::{
    ObservableSeriesWriter, OutputKind, RunMeta, SeriesAsd, SimulationMeta, SERIES_CHUNK_SAMPLES,
};
use tiltnoise_plot::simulate_figure::{
    asd_figure, time_series_figure, ModeMark, SimAsdData, TimePanel, TimeSeriesData, ASD_SIZE,
};

mod driven;

/// Runs with at least this many samples get a progress bar on a terminal (about 2 s of work).
const WORTH_A_BAR: usize = 1 << 23;

/// Options of `tiltnoise simulate`.
#[derive(Debug, Args)]
pub(crate) struct SimulateArgs {
    /// Length of the record (s); default 12 h like the paper.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 43_200.0,
        allow_negative_numbers = true
    )]
    duration: f64,
    /// Sampling step (s); default the paper's 0.1 s.
    #[arg(
        long,
        value_name = "SECONDS",
        default_value_t = 0.1,
        allow_negative_numbers = true
    )]
    step: f64,
    /// Initial coordinates in crate names, e.g. `theta_a=1e-5,phi_b=0.01` (rad; delta_a,
    /// delta_b in m); repeatable; unlisted coordinates start at 0. Replaces the default
    /// excitation (equal energy in every mode).
    #[arg(long, value_name = "COORD=VALUE,...", allow_hyphen_values = true)]
    init: Vec<String>,
    /// Initial velocities, same syntax (rad/s, m/s).
    #[arg(
        long = "init-rate",
        value_name = "COORD=RATE,...",
        allow_hyphen_values = true
    )]
    init_rate: Vec<String>,
    /// The paper's kick test: the test mass displaced statically along X by this many metres
    /// (a static force on the test mass along x) and released from rest.
    #[arg(long = "kick-x", value_name = "METRES", allow_negative_numbers = true,
          conflicts_with_all = ["init", "init_rate"])]
    kick_x: Option<f64>,
    /// Energy per mode (J) of the default excitation (no --init, --init-rate, --kick-x).
    #[arg(long, value_name = "JOULES", default_value = scientific(DEFAULT_MODE_ENERGY_J),
          allow_negative_numbers = true)]
    mode_energy: f64,
    /// White readout noise OBS=ASD in the observable's unit/sqrt(Hz) (repeatable; default
    /// X=9e-9 m/sqrt(Hz) from the paper, angles noiseless; OBS=0 removes it).
    #[arg(long, value_name = "OBS=ASD", allow_hyphen_values = true)]
    readout: Vec<String>,
    /// Seed of the readout-noise generator.
    #[arg(long, default_value_t = 0, allow_negative_numbers = true)]
    seed: u64,
    /// Welch segment length in samples for the ASDs (default: the largest power of two that
    /// fits three times into the record, 2^17 for 12 h at 0.1 s; 50 % overlap, mean).
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    nperseg: Option<usize>,
    /// Output (repeatable): .h5/.hdf5 time series + ASDs + run (the budget's --measured reads
    /// it), .csv ASDs (frequency_hz,X,...), .png/.svg Figure 3 (ASDs).
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
    /// Also write the eight generalized coordinates (noiseless; rad, m) to the HDF5 output,
    /// group /coordinates. By default only the seven observables are written.
    #[arg(long, conflicts_with = "tilt")]
    with_coordinates: bool,
    /// Samples computed and written per chunk (default 65536). The record streams through
    /// the outputs and the spectra chunk by chunk; the numbers do not depend on the chunk size,
    /// only the memory and the speed do.
    #[arg(long, value_name = "N", conflicts_with = "tilt")]
    chunk_samples: Option<usize>,
    /// Time-series figure (.png/.svg, repeatable): phi over the whole run and X over the first
    /// quarter of the nu_1 period, as the paper's Figures 4 and 5 for --kick-x.
    #[arg(long = "save-time", value_name = "PATH")]
    save_time: Vec<PathBuf>,
    /// Drive the pendulum with a record of the floor's motion instead of free motion (HDF5, CSV
    /// or miniSEED time series of tilt and translation channels, as for `budget`): every
    /// channel becomes its input's displacement in the frequency domain (inertial sensors
    /// corrected), the response is interpolated band-limited and propagated exactly, from the
    /// quasi-static state; the record's rate and length set the output's.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["duration", "step", "init", "init_rate", "kick_x", "mode_energy", "save_time"])]
    tilt: Option<PathBuf>,
    /// Axis map of the record (with --tilt), e.g. `theta_t=-E,eta_t=-N` or
    /// `eta_t=-LJN,x_t=LHE`.
    #[arg(
        long,
        value_name = "MAP",
        allow_hyphen_values = true,
        requires = "tilt"
    )]
    axes: Option<String>,
    /// Quantity of the tilt channels (with --tilt): angle or rate.
    #[arg(long, value_name = "angle|rate", requires = "tilt")]
    quantity: Option<String>,
    /// Non-finite tilt samples (with --tilt): reject or interpolate.
    #[arg(long, value_name = "reject|interpolate", requires = "tilt")]
    gaps: Option<String>,
    /// Scale factor of a source channel of the tilt record (with --tilt), `CHANNEL=FACTOR` (rad or rad/s per
    /// count, or per unit of the file), applied before the axis map; required for miniSEED
    /// channels in counts. Repeat for several channels.
    #[arg(long, value_name = "CHANNEL=FACTOR", requires = "tilt")]
    scale: Vec<String>,
    /// Units and sensors of the record's channels (with --tilt).
    #[command(flatten)]
    channels: super::args::ChannelArgs,
    /// Fine steps per record sample of the driven propagation (with --tilt).
    #[arg(
        long,
        value_name = "N",
        default_value_t = 10,
        allow_negative_numbers = true,
        requires = "tilt"
    )]
    oversample: usize,
    /// The pendulum sees GAIN times the record's channel of an input, INPUT=GAIN,... (with
    /// --tilt; default 1; e.g. eta_t=0.97, x_t=1.02): a sensor's calibration error.
    #[arg(
        long,
        value_name = "INPUT=GAIN,...",
        allow_hyphen_values = true,
        requires = "tilt"
    )]
    drive_gain: Vec<String>,
    /// The pendulum sees the record's tilt this many seconds late (with --tilt; a whole number
    /// of fine steps): a clock offset.
    #[arg(
        long,
        value_name = "SECONDS",
        allow_negative_numbers = true,
        requires = "tilt"
    )]
    drive_delay: Option<f64>,
    #[command(flatten)]
    figure: FigureArgs,
}

/// `--readout OBS=ASD` items over the default (the paper's 9 nm/sqrt(Hz) on X; 0 removes
/// one), each observable once, in observable order.
fn parse_readout(items: &[String]) -> Result<Vec<(Observable, f64)>> {
    let items = items
        .iter()
        .map(|item| super::args::parse_readout_item(item))
        .collect::<Result<Vec<_>>>()?;
    let mut readout = options::apply_readout("--readout", Readout::default(), &items, None)?.asd;
    readout.sort_by_key(|(o, _)| o.index());
    Ok(readout)
}

/// The run's initial state and a description of where it came from: the kick, the given
/// coordinates and rates, or equal energy in every mode.
fn initial_state(model: &Model, args: &SimulateArgs) -> Result<(InitialState, String)> {
    let excitation = if let Some(x_m) = args.kick_x {
        Excitation::KickX { x_m }
    } else if !args.init.is_empty() || !args.init_rate.is_empty() {
        let (mut q, mut qdot) = ([0.0; 8], [0.0; 8]);
        parse_coordinates("--init", &args.init, false, &mut q)?;
        parse_coordinates("--init-rate", &args.init_rate, true, &mut qdot)?;
        Excitation::Given { q, qdot }
    } else {
        Excitation::EqualEnergy {
            energy_j: args.mode_energy,
        }
    };
    Ok(simulate::initial_state(model, &excitation)?)
}

/// Runs `tiltnoise simulate`.
pub(crate) fn run_simulate(params: &Params, args: SimulateArgs, run: &mut Run) -> Result<()> {
    let model = Model::new(params)?;
    if !model.is_undamped() {
        bail!(
            "tiltnoise simulate supports only the undamped model (exact modal propagation of \
             free motion); the parameters have non-zero loss angles in [loss]: set every \
             loss.*_rad to 0, e.g. with --set"
        );
    }
    let view = args.figure.view_for(ASD_SIZE)?;
    if let Some(path) = &args.tilt {
        return driven::run(params, &model, &args, path, run);
    }
    let c = &args.channels;
    if let Some(option) = [
        ("--units", c.units.is_empty()),
        ("--corrected", c.corrected.is_empty()),
        ("--pendulum-tiltmeter", c.pendulum_tiltmeter.is_empty()),
    ]
    .into_iter()
    .find_map(|(option, empty)| (!empty).then_some(option))
    {
        bail!("{option} describes the channels of a record and applies with --tilt FILE only");
    }
    if !(args.step.is_finite() && args.step > 0.0) {
        bail!(
            "--step {}: the sampling step (s) must be finite and > 0",
            args.step
        );
    }
    if !(args.duration.is_finite() && args.duration > 0.0) {
        bail!(
            "--duration {}: the duration (s) must be finite and > 0",
            args.duration
        );
    }
    let n_f = (args.duration / args.step * (1.0 + 1e-9)).floor();
    if n_f < 2.0 {
        bail!(
            "--duration {} s at --step {} s gives {n_f} sample(s): at least 2 are needed",
            args.duration,
            args.step
        );
    }
    check_streamed_samples(
        || {
            format!(
                "--duration {} s at --step {} s",
                Num(args.duration),
                Num(args.step)
            )
        },
        n_f,
    )?;
    let n = n_f as usize;
    let nperseg = args.nperseg.unwrap_or_else(|| default_sim_nperseg(n));
    if nperseg < 16 {
        bail!("--nperseg {nperseg}: the Welch segment must have at least 16 samples");
    }
    if nperseg > n {
        bail!(
            "--duration {} s at --step {} s gives {n} samples, shorter than one Welch segment \
             (--nperseg {nperseg} = {} s): lengthen --duration or lower --nperseg",
            Num(args.duration),
            Num(args.step),
            Num(nperseg as f64 * args.step)
        );
    }
    check_memory(
        || format!("--nperseg {nperseg}: Welch segments of the 7 observables"),
        planned_bytes(nperseg, 7 * STREAMED_WELCH_BYTES_PER_SAMPLE),
    )?;
    for path in &args.save {
        OutputKind::from_path(path)?;
    }
    for path in &args.save_time {
        tiltnoise_plot::ImageFormat::from_path(path)?;
    }
    let hdf5_paths: Vec<&PathBuf> = args
        .save
        .iter()
        .filter(|p| matches!(OutputKind::from_path(p), Ok(OutputKind::Hdf5)))
        .collect();
    if args.with_coordinates && hdf5_paths.is_empty() {
        bail!("--with-coordinates: the coordinates go to an HDF5 file; add --save FILE.h5");
    }
    let chunk_samples = match args.chunk_samples {
        Some(0) => bail!("--chunk-samples 0: a chunk must hold at least 1 sample"),
        Some(c) => c,
        None => SERIES_CHUNK_SAMPLES,
    };
    let saves: Vec<&Path> = args
        .save
        .iter()
        .chain(&args.save_time)
        .map(PathBuf::as_path)
        .collect();
    run.check_outputs(&saves, &[])?;
    let readout = parse_readout(&args.readout)?;
    let (init, init_source) = initial_state(&model, &args)?;
    let cfg = SimConfig {
        dt_s: args.step,
        duration_s: args.duration,
        readout_asd: readout.clone(),
        seed: args.seed,
        cancel: run.cancel.clone(),
    };
    let mut motion = FreeMotion::new(&model, &init, &cfg, args.with_coordinates)?;
    let dt_s = motion.dt_s();
    let fs = 1.0 / dt_s;
    let wcfg = WelchConfig::new(nperseg);
    let modes = NormalModes::new(&model);
    let meta = RunMeta::of_this_run(params, Some(&modes));
    let run_caption = format!(
        "{n} samples at {dt_s} s ({} s), exact modal propagation of the undamped model; initial \
         state: {init_source}; readout: {}; seed {}.",
        n as f64 * dt_s,
        readout_text(&readout),
        args.seed
    );
    let smeta = SimulationMeta {
        run: meta.clone(),
        description: format!(
            "SIMULATED free motion of the double torsion pendulum model (not a measurement). \
             {run_caption}"
        ),
        start_time: None,
        seed: args.seed,
        init,
        init_source: init_source.clone(),
        readout_asd: readout.clone(),
        duration_s: args.duration,
    };

    // The record streams through the HDF5 writers, the Welch accumulators and the pieces the
    // time-series figure needs; it is never held whole.
    let mut writers = hdf5_paths
        .iter()
        .map(|p| ObservableSeriesWriter::create(p, dt_s, &smeta, args.with_coordinates))
        .collect::<Result<Vec<_>, _>>()?;
    let mut accumulators = Observable::ALL
        .iter()
        .map(|_| WelchAccumulator::new(1, fs, &wcfg))
        .collect::<Result<Vec<_>, _>>()?;
    let want_time = !args.save_time.is_empty();
    let mut phi = want_time.then(|| MinMaxEnvelope::new(n, TIME_FIGURE_BLOCKS));
    let n_x = x_samples_shown(&modes, dt_s, n);
    let mut x_start = Vec::new();
    let bar = (n >= WORTH_A_BAR && std::io::stderr().is_terminal()).then(|| {
        let b = indicatif::ProgressBar::new(n as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} {wide_bar} {pos}/{len} samples ({percent}%, eta {eta})",
            )
            .expect("valid template"),
        );
        b
    });
    let mut chunk = SimChunk::default();
    while {
        cfg.cancel.check()?;
        motion.next_chunk(chunk_samples, &mut chunk)
    } {
        for w in &mut writers {
            w.append(&chunk)?;
        }
        for (acc, x) in accumulators.iter_mut().zip(&chunk.observables) {
            acc.push(&[x])?;
        }
        if let Some(e) = &mut phi {
            e.push(chunk.observable(Observable::Phi));
        }
        if want_time && x_start.len() < n_x {
            let x = chunk.observable(Observable::X);
            x_start.extend_from_slice(&x[..x.len().min(n_x - x_start.len())]);
        }
        if let Some(b) = &bar {
            b.set_position(motion.samples_done() as u64);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }

    let mut psds = Vec::with_capacity(7);
    for (o, acc) in Observable::ALL.into_iter().zip(accumulators) {
        let m = acc.finish()?;
        psds.push((
            o,
            Psd {
                psd: m.psd(0),
                freqs_hz: m.freqs_hz,
                n_segments: m.n_segments,
            },
        ));
    }
    let prop = ModalPropagator::new(&model, &init, cfg.dt_s)?;
    let (u0, v0) = prop.initial_modal_state();
    let amplitude: [f64; 8] = std::array::from_fn(|k| u0[k].hypot(v0[k]));
    let check = check_resonances(&modes, &amplitude, &psds, fs, nperseg, &readout);

    write!(
        run.out,
        "{}",
        summary(
            (n, dt_s),
            &modes,
            &init_source,
            &readout,
            args.seed,
            &wcfg,
            psds[0].1.n_segments
        )
    )?;
    write!(run.out, "{}", check.table())?;

    let freqs_hz = psds[0].1.freqs_hz.clone();
    let asd: Vec<(Observable, Vec<f64>)> = psds.iter().map(|(o, p)| (*o, p.asd())).collect();
    let caption = vec![
        run_caption,
        format!(
            "One-sided Welch ASDs: periodic Hann, {} samples per segment, 50 % overlap, {} \
             segments, mean. Modes above Nyquist ({} Hz) are marked at their aliases.",
            nperseg,
            psds[0].1.n_segments,
            fs / 2.0
        ),
    ];
    let series_asd = SeriesAsd {
        freqs_hz: freqs_hz.clone(),
        asd: asd.clone(),
        segment_len: nperseg,
        overlap: wcfg.overlap,
        averaging: "mean".to_string(),
        n_segments: psds[0].1.n_segments,
    };
    let time_data = phi.map(|phi| {
        let (values, spacing) = phi.finish();
        time_series_data((values, spacing * dt_s), (x_start, dt_s), &init_source)
    });
    run.write_outputs(false, || {
        for writer in writers {
            writer.finish(&series_asd)?;
        }
        for path in &args.save {
            match OutputKind::from_path(path)? {
                OutputKind::Hdf5 => {}
                OutputKind::Csv => tiltnoise_io::write_asd_csv(path, &freqs_hz, &asd, &meta)
                    .with_context(|| format!("writing {}", path.display()))?,
                OutputKind::Png | OutputKind::Svg => {
                    let data = SimAsdData {
                        freqs_hz: freqs_hz.clone(),
                        asd: asd.clone(),
                        readout_asd: readout.clone(),
                        modes: modes
                            .modes
                            .iter()
                            .enumerate()
                            .map(|(k, m)| ModeMark {
                                index: m.index,
                                frequency_hz: m.frequency_hz,
                                apparent_frequency_hz: aliased_frequency_hz(m.frequency_hz, fs),
                                seen_by: modes.observables_seeing(k),
                            })
                            .collect(),
                        caption: caption.clone(),
                    };
                    save_image(path, |format| asd_figure(&data, &view, format))?;
                }
            }
        }
        if let Some(data) = &time_data {
            for path in &args.save_time {
                save_image(path, |format| time_series_figure(data, &view, format))?;
            }
        }
        Ok(())
    })
}

/// The readout as the summary and the files describe it (the library's wording).
pub(crate) use tiltnoise_core::simulate::readout_text;

fn summary(
    (n, dt_s): (usize, f64),
    modes: &NormalModes,
    init_source: &str,
    readout: &[(Observable, f64)],
    seed: u64,
    wcfg: &WelchConfig,
    n_segments: usize,
) -> String {
    let fs = 1.0 / dt_s;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "free motion: {} samples at dt = {} s ({} s), Nyquist {} Hz",
        n,
        dt_s,
        n as f64 * dt_s,
        fs / 2.0
    );
    let _ = writeln!(s, "initial state: {init_source}");
    let _ = writeln!(
        s,
        "readout (white, one-sided ASD): {}; seed {seed}",
        readout_text(readout)
    );
    let _ = writeln!(
        s,
        "ASDs: one-sided Welch, periodic Hann, {} samples per segment ({} s, df = {:.3e} Hz), \
         overlap {}, {} segments, mean",
        wcfg.segment_len,
        wcfg.segment_len as f64 / fs,
        fs / wcfg.segment_len as f64,
        wcfg.overlap,
        n_segments
    );
    for (k, m) in modes.modes.iter().enumerate() {
        let apparent = aliased_frequency_hz(m.frequency_hz, fs);
        let alias = if apparent != m.frequency_hz {
            format!(" (above Nyquist: appears at {apparent:.4e} Hz)")
        } else {
            String::new()
        };
        let seen: Vec<&str> = modes
            .observables_seeing(k)
            .iter()
            .map(|o| o.name())
            .collect();
        let _ = writeln!(
            s,
            "  nu_{} {:>11.4e} Hz{alias}  seen by {}",
            m.index,
            m.frequency_hz,
            seen.join(" ")
        );
    }
    s
}

/// Points of the whole-run panel of the time-series figure: the minimum and maximum of at most
/// this many blocks of samples (the figure shows 4000 columns).
const TIME_FIGURE_BLOCKS: usize = 1 << 15;

/// Samples of X in the second panel of the time-series figure: the first quarter of the nu_1
/// period (a fraction of a torsion period, to show the swinging oscillations).
fn x_samples_shown(modes: &NormalModes, dt_s: f64, n: usize) -> usize {
    let quarter_s = 0.25 / modes.modes[0].frequency_hz;
    ((quarter_s / dt_s).ceil() as usize).clamp(2, n)
}

/// Figures 4 and 5: phi over the whole run (`(values, spacing in s)`: the series, or its
/// min/max envelope for a long run), X over the first quarter of the nu_1 period.
fn time_series_data(
    (phi, phi_dt_s): (Vec<f64>, f64),
    (x, dt_s): (Vec<f64>, f64),
    init_source: &str,
) -> TimeSeriesData {
    TimeSeriesData {
        title: format!("Simulated free motion ({init_source})"),
        panels: vec![
            TimePanel {
                title: "φ: test-mass torsion, whole run (cf. Figure 4)".to_string(),
                observable: Observable::Phi,
                dt_s: phi_dt_s,
                t0_s: 0.0,
                values: phi,
            },
            TimePanel {
                title: format!(
                    "X: test-mass displacement, first {:.0} s = 1/4 of the ν1 period (cf. Figure 5)",
                    x.len() as f64 * dt_s
                ),
                observable: Observable::X,
                dt_s,
                t0_s: 0.0,
                values: x,
            },
        ],
    }
}
