//! The `simulate` subcommand: free motion of the undamped model (exact modal propagation),
//! readout noise, one-sided Welch ASDs, the resonance check against the observability table,
//! and the outputs (HDF5 series + ASDs, CSV ASDs, Figure 3, Figures 4/5). Owns the progress
//! bar (only when stderr is a terminal and the run is long). Documented in `docs/simulate.md`.

use super::output::save_image;
use super::Run;
use anyhow::{bail, Context, Result};
use clap::Args;
use std::fmt::Write as _;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use tiltnoise_core::model::{Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::noise::Readout;
use tiltnoise_core::options::{self, Spelling};
use tiltnoise_core::params::Params;
use tiltnoise_core::simulate::resonance::check_resonances;
use tiltnoise_core::simulate::{
    aliased_frequency_hz, check_sampling, describe_run, parse_coordinates, readout_text,
    record_description, simulate_with_progress, Excitation, InitialState, ModalPropagator,
    SimConfig, Simulation, DEFAULT_MODE_ENERGY_J,
};
use tiltnoise_core::spectral::{welch, WelchConfig};
use tiltnoise_io::{write_observable_series_hdf5, OutputKind, RunMeta, SeriesAsd, SimulationMeta};
use tiltnoise_plot::simulate_figure::{
    asd_figure, time_series_figure, ModeMark, SimAsdData, TimePanel, TimeSeriesData,
};

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
    #[arg(long, value_name = "JOULES", default_value_t = DEFAULT_MODE_ENERGY_J,
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
    /// it), .csv ASDs (freq_hz,X,...), .png/.svg Figure 3 (ASDs).
    #[arg(long, value_name = "PATH")]
    save: Vec<PathBuf>,
    /// Time-series figure (.png/.svg, repeatable): phi over the whole run and X over the first
    /// quarter of the nu_1 period, as the paper's Figures 4 and 5 for --kick-x.
    #[arg(long = "save-time", value_name = "PATH")]
    save_time: Vec<PathBuf>,
}

fn parse_readout(items: &[String]) -> Result<Vec<(Observable, f64)>> {
    let items: Vec<(Observable, f64)> = items
        .iter()
        .map(|i| super::args::parse_readout_item(i))
        .collect::<Result<_>>()?;
    let mut readout = options::apply_readout("--readout", Readout::default(), &items, None)?.asd;
    readout.sort_by_key(|(o, _)| o.index());
    Ok(readout)
}

/// The run's initial state and a description of where it came from.
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
    Ok(tiltnoise_core::simulate::initial_state(
        model,
        &excitation,
        Spelling::Flag,
    )?)
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
    let (n, nperseg) = check_sampling(Spelling::Flag, args.duration, args.step, args.nperseg)?;
    for path in &args.save {
        OutputKind::from_path(path)?;
    }
    for path in &args.save_time {
        tiltnoise_plot::ImageFormat::from_path(path)?;
    }
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
    };

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
    let sim = simulate_with_progress(&model, &init, &cfg, &mut |done, _| {
        if let Some(b) = &bar {
            b.set_position(done as u64);
        }
    })?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }

    let fs = sim.fs_hz();
    let wcfg = WelchConfig::new(nperseg);
    let mut psds = Vec::new();
    for (o, x) in &sim.observables {
        psds.push((*o, welch(x, fs, &wcfg)?));
    }
    let modes = NormalModes::new(&model);
    let prop = ModalPropagator::new(&model, &init, cfg.dt_s)?;
    let (u0, v0) = prop.initial_modal_state();
    let amplitude: [f64; 8] = std::array::from_fn(|k| u0[k].hypot(v0[k]));
    let check = check_resonances(&modes, &amplitude, &psds, fs, nperseg, &readout);

    write!(
        run.out,
        "{}",
        summary(
            &sim,
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
    let meta = RunMeta::of_this_run(params, Some(&modes));
    let caption = vec![
        describe_run(&sim, &init_source, &readout, args.seed),
        format!(
            "One-sided Welch ASDs: periodic Hann, {} samples per segment, 50 % overlap, {} \
             segments, mean. Modes above Nyquist ({} Hz) are marked at their aliases.",
            nperseg,
            psds[0].1.n_segments,
            fs / 2.0
        ),
    ];
    run.write_outputs(false, || {
        for path in &args.save {
            match OutputKind::from_path(path)? {
                OutputKind::Hdf5 => {
                    let series_asd = SeriesAsd {
                        freqs_hz: freqs_hz.clone(),
                        asd: asd.clone(),
                        segment_len: nperseg,
                        overlap: wcfg.overlap,
                        averaging: "mean".to_string(),
                        n_segments: psds[0].1.n_segments,
                    };
                    let smeta = SimulationMeta {
                        run: meta.clone(),
                        description: record_description(&caption[0]),
                        start_time: None,
                        seed: args.seed,
                        init,
                        init_source: init_source.clone(),
                        readout_asd: readout.clone(),
                        duration_s: args.duration,
                    };
                    write_observable_series_hdf5(path, &sim, &series_asd, &smeta)?;
                }
                OutputKind::Csv => tiltnoise_io::write_asd_csv(path, &freqs_hz, &asd)
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
                    save_image(path, |format| asd_figure(&data, format))?;
                }
            }
        }
        for path in &args.save_time {
            let data = time_series_data(&sim, &modes, &init_source);
            save_image(path, |format| time_series_figure(&data, format))?;
        }
        Ok(())
    })
}

fn summary(
    sim: &Simulation,
    modes: &NormalModes,
    init_source: &str,
    readout: &[(Observable, f64)],
    seed: u64,
    wcfg: &WelchConfig,
    n_segments: usize,
) -> String {
    let fs = sim.fs_hz();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "free motion: {} samples at dt = {} s ({} s), Nyquist {} Hz",
        sim.len(),
        sim.dt_s,
        sim.len() as f64 * sim.dt_s,
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

/// Figures 4 and 5: phi over the whole run, X over the first quarter of the nu_1 period (a
/// fraction of a torsion period, to show the swinging oscillations).
fn time_series_data(sim: &Simulation, modes: &NormalModes, init_source: &str) -> TimeSeriesData {
    let quarter_s = 0.25 / modes.modes[0].frequency_hz;
    let n_x = ((quarter_s / sim.dt_s).ceil() as usize).clamp(2, sim.len());
    TimeSeriesData {
        title: format!("Simulated free motion ({init_source})"),
        panels: vec![
            TimePanel {
                title: "φ: test-mass torsion, whole run (cf. Figure 4)".to_string(),
                observable: Observable::Phi,
                dt_s: sim.dt_s,
                t0_s: 0.0,
                values: sim.observable(Observable::Phi).to_vec(),
            },
            TimePanel {
                title: format!(
                    "X: test-mass displacement, first {:.0} s = 1/4 of the ν1 period (cf. Figure 5)",
                    n_x as f64 * sim.dt_s
                ),
                observable: Observable::X,
                dt_s: sim.dt_s,
                t0_s: 0.0,
                values: sim.observable(Observable::X)[..n_x].to_vec(),
            },
        ],
    }
}
