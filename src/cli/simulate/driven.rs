//! `tiltnoise simulate --tilt FILE`: the undamped model driven by a record of the floor's
//! motion, tilt and translation channels ([`tiltnoise_core::simulate::driven`]), optionally
//! through miscalibrated, late sensors (`--drive-gain`, `--drive-delay`): a controlled record
//! of the observables, for example to test `tiltnoise subtract`, which should find those gains
//! and that delay.

use super::{parse_readout, readout_text, SimulateArgs};
use crate::cli::output::save_image;
use crate::cli::Run;
use anyhow::{anyhow, bail, Result};
use std::path::{Path, PathBuf};
use tiltnoise_core::error::{Num, Shown};
use tiltnoise_core::input::GroundMap;
use tiltnoise_core::limits::GAINS;
use tiltnoise_core::model::{Input, Model, Observable};
use tiltnoise_core::modes::NormalModes;
use tiltnoise_core::params::Params;
use tiltnoise_core::repeats::{list_entries, refuse_repeated_keys};
use tiltnoise_core::simulate::aliased_frequency_hz;
use tiltnoise_core::simulate::default_sim_nperseg as default_nperseg;
use tiltnoise_core::simulate::driven::{
    drive_from_record, quasi_static_start, simulate_driven, DrivenConfig,
};
use tiltnoise_core::spectral::{welch, WelchConfig};
use tiltnoise_io::input::{read_tilt, TiltInput};
use tiltnoise_io::{write_observable_series_hdf5, OutputKind, RunMeta, SeriesAsd, SimulationMeta};
use tiltnoise_plot::simulate_figure::{asd_figure, ModeMark, SimAsdData, ASD_SIZE};

/// `--drive-gain INPUT=GAIN,...` for the inputs of the record (others 1).
fn parse_gains(items: &[String], inputs: &[Input]) -> Result<Vec<f64>> {
    let mut gains = vec![1.0; inputs.len()];
    let entries = list_entries(items);
    refuse_repeated_keys("--drive-gain", "input", &entries)?;
    for entry in entries {
        let shown = Shown(entry);
        let (name, value) = entry.split_once('=').ok_or_else(|| {
            anyhow!("--drive-gain {shown}: expected INPUT=GAIN, e.g. eta_t=0.97 or x_t=1.02")
        })?;
        let i = inputs
            .iter()
            .position(|a| a.name() == name.trim())
            .ok_or_else(|| {
                anyhow!(
                    "--drive-gain {shown}: the record has no input `{}`; it has {}",
                    Shown(name.trim()),
                    inputs
                        .iter()
                        .map(|a| a.name())
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })?;
        let g: f64 = value
            .trim()
            .parse()
            .map_err(|_| anyhow!("--drive-gain {shown}: `{}` is not a number", Shown(value)))?;
        if !GAINS.admits(g) {
            bail!(
                "--drive-gain {shown}: the gain {} is not allowed: must be {} (see \
                 docs/limits.md)",
                Num(g),
                GAINS.allowed("")
            );
        }
        gains[i] = g;
    }
    Ok(gains)
}

/// Runs the driven simulation of `args` with the tilt record at `path`.
pub(super) fn run(
    params: &Params,
    model: &Model,
    args: &SimulateArgs,
    path: &Path,
    run: &mut Run,
) -> Result<()> {
    for out in &args.save {
        OutputKind::from_path(out)?;
    }
    let saves: Vec<&Path> = args.save.iter().map(PathBuf::as_path).collect();
    run.check_outputs(&saves, &[("--tilt", path)])?;
    let view = args.figure.view_for(ASD_SIZE)?;
    let opts = crate::cli::args::read_options(
        args.axes.as_deref(),
        args.quantity.as_deref(),
        args.gaps.as_deref(),
        &args.scale,
        &args.channels,
    )?;
    let series = match read_tilt(path, &opts)? {
        TiltInput::Series(s) => s,
        TiltInput::Spectra(_) => bail!(
            "--tilt {}: holds spectra; a driven simulation needs a time series",
            path.display()
        ),
    };
    let map = GroundMap::new(&series.channels(), params.environment.g_m_per_s2)
        .map_err(|e| anyhow!("--tilt {}: {e}", path.display()))?;
    let inputs: Vec<Input> = map.inputs();
    let channel_data: Vec<Vec<f64>> = series.channel_data().iter().map(|c| c.to_vec()).collect();
    let displacements = map.displacements(&channel_data, series.sample_rate_hz);
    let gains = parse_gains(&args.drive_gain, &inputs)?;
    let fs = series.sample_rate_hz;
    let m = args.oversample;
    let fine_step = 1.0 / (fs * m as f64);
    let delay_s = args.drive_delay.unwrap_or(0.0);
    let steps = delay_s / fine_step;
    if !(steps.is_finite() && (steps - steps.round()).abs() <= 1e-9 * steps.abs().max(1.0)) {
        bail!(
            "--drive-delay {} s is not allowed: must be a whole number of fine steps of {} s \
             (the record's step / --oversample {m})",
            Num(delay_s),
            Num(fine_step)
        );
    }
    let readout = parse_readout(&args.readout)?;
    let drive = drive_from_record(
        1.0 / fs,
        &inputs,
        &displacements,
        m,
        &gains,
        steps.round() as i64,
    )?;
    let init = quasi_static_start(model, &drive)?;
    let sim = simulate_driven(
        model,
        &drive,
        &DrivenConfig {
            keep_every: m,
            readout_asd: readout.clone(),
            seed: args.seed,
            cancel: tiltnoise_core::cancel::Cancel::never(),
        },
    )?;
    let n = sim.len();
    let nperseg = args.nperseg.unwrap_or_else(|| default_nperseg(n));
    if nperseg < 16 || nperseg > n {
        bail!(
            "--nperseg {nperseg}: the Welch segment must have 16 to {n} samples (the record's \
             length)"
        );
    }
    let wcfg = WelchConfig::new(nperseg);
    let mut psds = Vec::new();
    for (o, x) in &sim.observables {
        psds.push((*o, welch(x, fs, &wcfg)?));
    }
    let modes = NormalModes::new(model);
    let drive_text = inputs
        .iter()
        .zip(&gains)
        .map(|(a, g)| format!("{} x {g}", a.name()))
        .collect::<Vec<_>>()
        .join(", ");
    let what = format!(
        "SIMULATED response of the undamped pendulum model (not a measurement) to the record \
         {} of the floor's motion ({drive_text}, delayed by {} s), interpolated band-limited to \
         {} s steps and propagated exactly for the interpolated motion; quasi-static start; \
         readout: {}; seed {}.",
        path.display(),
        Num(delay_s),
        Num(fine_step),
        readout_text(&readout),
        args.seed
    );
    for note in series
        .provenance
        .notes
        .iter()
        .chain(map.notes())
        .chain(&map.series_note())
    {
        writeln!(run.out, "input: {note}")?;
    }
    writeln!(
        run.out,
        "driven: {n} samples at {} Hz ({} s); {what}",
        Num(fs),
        Num(n as f64 / fs)
    )?;
    let freqs_hz = psds[0].1.freqs_hz.clone();
    let asd: Vec<(Observable, Vec<f64>)> = psds.iter().map(|(o, p)| (*o, p.asd())).collect();
    let meta = RunMeta::of_this_run(params, Some(&modes));
    let caption = vec![
        what.clone(),
        format!(
            "One-sided Welch ASDs: periodic Hann, {nperseg} samples per segment, 50 % overlap, \
             {} segments, mean.",
            psds[0].1.n_segments
        ),
    ];
    run.write_outputs(false, || {
        for out in &args.save {
            match OutputKind::from_path(out)? {
                OutputKind::Hdf5 => write_observable_series_hdf5(
                    out,
                    &sim,
                    &SeriesAsd {
                        freqs_hz: freqs_hz.clone(),
                        asd: asd.clone(),
                        segment_len: nperseg,
                        overlap: wcfg.overlap,
                        averaging: "mean".to_string(),
                        n_segments: psds[0].1.n_segments,
                    },
                    &SimulationMeta {
                        run: meta.clone(),
                        description: what.clone(),
                        start_time: series.provenance.start_time.clone(),
                        seed: args.seed,
                        init,
                        init_source: "quasi-static state of the drive's first sample".into(),
                        readout_asd: readout.clone(),
                        duration_s: n as f64 / fs,
                    },
                )?,
                OutputKind::Csv => tiltnoise_io::write_asd_csv(out, &freqs_hz, &asd, &meta)?,
                OutputKind::Png | OutputKind::Svg => {
                    let data = SimAsdData {
                        freqs_hz: freqs_hz.clone(),
                        asd: asd.clone(),
                        readout_asd: readout.clone(),
                        modes: modes
                            .modes
                            .iter()
                            .enumerate()
                            .map(|(k, mode)| ModeMark {
                                index: mode.index,
                                frequency_hz: mode.frequency_hz,
                                apparent_frequency_hz: aliased_frequency_hz(mode.frequency_hz, fs),
                                seen_by: modes.observables_seeing(k),
                            })
                            .collect(),
                        caption: caption.clone(),
                    };
                    save_image(out, |format| asd_figure(&data, &view, format))?;
                }
            }
        }
        Ok(())
    })
}
