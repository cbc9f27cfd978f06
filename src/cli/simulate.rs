//! The `simulate` subcommand: free motion of the undamped model (exact modal propagation),
//! readout noise, one-sided Welch ASDs, the resonance check against the observability table,
//! and the outputs (HDF5 series + ASDs, CSV ASDs, Figure 3, Figures 4/5). Owns the progress
//! bar (only when stderr is a terminal and the run is long). Documented in `docs/simulate.md`.

use super::args::{scientific, Format};
use super::figure_args::FigureArgs;
use super::progress::Bar;
use super::Run;
use anyhow::{bail, Result};
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::{
    aliased_frequency_hz, parse_coordinates, readout_text, Excitation, DEFAULT_MODE_ENERGY_J,
};
use tiltnoise_job::figures::SIMULATE_FIGURE_SIZE;
use tiltnoise_job::files::OutputKind;
use tiltnoise_job::simulate::{Keep, SimulateRequest, SimulateResult};
use tiltnoise_job::{Invocation, Outcome};

mod driven;

/// Runs with at least this many samples get a progress bar on a terminal (about 2 s of work).
const WORTH_A_BAR: u64 = 1 << 23;

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
          allow_negative_numbers = true, conflicts_with_all = ["init", "init_rate", "kick_x"])]
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
    /// Fine steps per record sample of the driven propagation (with --tilt; default 10).
    #[arg(
        long,
        value_name = "N",
        allow_negative_numbers = true,
        requires = "tilt"
    )]
    oversample: Option<usize>,
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
    /// Output format on the terminal: table (default) or json (the summary and the resonance
    /// check; `wrote` lines then go to standard error).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    #[command(flatten)]
    figure: FigureArgs,
}

/// `--readout OBS=ASD` items, in order (the job applies them over the default: the paper's
/// 9 nm/sqrt(Hz) on X; 0 removes one).
fn parse_readout(items: &[String]) -> Result<Vec<(Observable, f64)>> {
    items
        .iter()
        .map(|item| super::args::parse_readout_item(item))
        .collect()
}

/// The excitation asked for: the kick, the given coordinates and rates, or equal energy in
/// every mode.
fn excitation(args: &SimulateArgs) -> Result<Excitation> {
    Ok(if let Some(x_m) = args.kick_x {
        Excitation::KickX { x_m }
    } else if !args.init.is_empty() || !args.init_rate.is_empty() {
        let (mut q, mut qdot) = ([0.0; 8], [0.0; 8]);
        parse_coordinates(OptionKey::INIT, &args.init, false, &mut q)?;
        parse_coordinates(OptionKey::INIT_RATE, &args.init_rate, true, &mut qdot)?;
        Excitation::Given { q, qdot }
    } else {
        Excitation::EqualEnergy {
            energy_j: args.mode_energy,
        }
    })
}

/// Refuses the options that describe the channels of a record or how it drives the
/// pendulum, which free motion has not.
fn refuse_record_options(args: &SimulateArgs) -> Result<()> {
    let c = &args.channels;
    if let Some(option) = [
        ("--units", !c.units.is_empty()),
        ("--corrected", !c.corrected.is_empty()),
        ("--pendulum-tiltmeter", !c.pendulum_tiltmeter.is_empty()),
        ("--axes", args.axes.is_some()),
        ("--quantity", args.quantity.is_some()),
        ("--gaps", args.gaps.is_some()),
        ("--scale", !args.scale.is_empty()),
    ]
    .into_iter()
    .find_map(|(option, given)| given.then_some(option))
    {
        bail!("{option} describes the channels of a record and applies with --tilt FILE only");
    }
    if let Some(option) = [
        ("--oversample", args.oversample.is_some()),
        ("--drive-gain", !args.drive_gain.is_empty()),
        ("--drive-delay", args.drive_delay.is_some()),
    ]
    .into_iter()
    .find_map(|(option, given)| given.then_some(option))
    {
        bail!(
            "{option} applies to a simulation driven by a record (--tilt FILE); free motion \
             has no record"
        );
    }
    Ok(())
}

/// Runs `tiltnoise simulate`: free motion, or with `--tilt` the driven simulation
/// ([`driven`]). The options into the simulate job's request, the job run (a progress bar on
/// a terminal), the summary and the resonance check printed and the files written.
pub(crate) fn run_simulate(params: &Params, args: SimulateArgs, run: &mut Run) -> Result<()> {
    let model = Model::new(params)?;
    let figures: Vec<PathBuf> = args.save.iter().chain(&args.save_time).cloned().collect();
    args.figure.refuse_without_figure(&figures)?;
    let view = args.figure.view_for(SIMULATE_FIGURE_SIZE)?;
    if let Some(path) = &args.tilt {
        return driven::run(&model, &args, path, &view, run);
    }
    refuse_record_options(&args)?;
    for path in &args.save {
        tiltnoise_job::output_kind(path, tiltnoise_job::simulate::OUTPUT_KINDS)?;
    }
    for path in &args.save_time {
        tiltnoise_job::figures::image_format(path)?;
    }
    let hdf5: Vec<PathBuf> = args
        .save
        .iter()
        .filter(|p| matches!(OutputKind::from_path(p), Ok(OutputKind::Hdf5)))
        .cloned()
        .collect();
    if args.with_coordinates && hdf5.is_empty() {
        bail!("--with-coordinates: the coordinates go to an HDF5 file; add --save FILE.h5");
    }
    let outputs: Vec<PathBuf> = args.save.iter().chain(&args.save_time).cloned().collect();
    run.check_job_outputs(&outputs, Vec::new())?;
    let req = SimulateRequest {
        model: &model,
        duration_s: args.duration,
        step_s: args.step,
        excitation: excitation(&args)?,
        readout: parse_readout(&args.readout)?,
        seed: args.seed,
        nperseg: args.nperseg,
        chunk_samples: args.chunk_samples,
        keep: Keep {
            record: false,
            hdf5,
            hdf5_coordinates: args.with_coordinates,
            time_figure: !args.save_time.is_empty(),
        },
        view,
        invocation: Invocation::of_this_process(),
    };
    let bar = Bar::new("samples", WORTH_A_BAR);
    let result = tiltnoise_job::simulate::run(&req, &run.cancel, &bar).map_err(super::job_error)?;
    let json = args.format == Format::Json;
    match json {
        true => writeln!(run.out, "{}", serde_json::to_string_pretty(&result.json())?)?,
        false => write!(run.out, "{}{}", summary(&result), result.check.table())?,
    }
    run.write_outputs(json, |stage| {
        for path in &args.save {
            result.save(stage, path).map_err(super::job_error)?;
        }
        for path in &args.save_time {
            result
                .save_time_figure(stage, path)
                .map_err(super::job_error)?;
        }
        Ok(())
    })
}

/// The run, the spectra and the modes as the terminal shows them (the resonance check
/// follows).
fn summary(r: &SimulateResult) -> String {
    let (n, dt_s, fs) = (r.n_samples, r.dt_s, r.fs_hz());
    let mut s = String::new();
    let _ = writeln!(
        s,
        "free motion: {} samples at dt = {} s ({} s), Nyquist {} Hz",
        n,
        dt_s,
        n as f64 * dt_s,
        fs / 2.0
    );
    let _ = writeln!(s, "initial state: {}", r.init_source);
    let _ = writeln!(
        s,
        "readout (white, one-sided ASD): {}; seed {}",
        readout_text(&r.readout),
        r.seed
    );
    let a = &r.asd;
    let _ = writeln!(
        s,
        "ASDs: one-sided Welch, periodic Hann, {} samples per segment ({} s, df = {:.3e} Hz), \
         overlap {}, {} segments, mean",
        a.segment_len,
        a.segment_len as f64 / fs,
        fs / a.segment_len as f64,
        a.overlap,
        a.n_segments
    );
    for (k, m) in r.modes.modes.iter().enumerate() {
        let apparent = aliased_frequency_hz(m.frequency_hz, fs);
        let alias = if apparent != m.frequency_hz {
            format!(" (above Nyquist: appears at {apparent:.4e} Hz)")
        } else {
            String::new()
        };
        let seen = r.modes.names_seeing(k);
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
