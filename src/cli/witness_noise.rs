//! `--witness-noise INPUT=ASD|FILE[:REL]` (`subtract`, `budget`): the own noise of the
//! instrument that records a floor input of the model, as a one-sided ASD in the input's unit
//! per sqrt(Hz): white (a number) or a spectrum (a `.csv`, `.h5` or `.hdf5` ASD file, read as
//! for `--readout`), and optionally its relative uncertainty REL (1 sigma of the ASD, e.g.
//! `:0.1` for 10 %). `--tilt-noise` is the same option under its former name.

use anyhow::{anyhow, Result};
use std::path::{Path, PathBuf};
use tiltnoise_core::error::Shown;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::repeats::refuse_repeated_keys;
use tiltnoise_job::{AsdSpec, WitnessItem};

/// Parses every `--witness-noise` item into the job's items, each input once.
pub fn parse_witness_items(items: &[String]) -> Result<Vec<WitnessItem>> {
    refuse_repeated_keys(OptionKey::WITNESS_NOISE, "input", items)?;
    items
        .iter()
        .map(|item| {
            let shown = Shown(item);
            let (name, value) = item.split_once('=').ok_or_else(|| {
                anyhow!(
                    "--witness-noise {shown}: expected INPUT=ASD|FILE[:REL], e.g. eta_t=6e-8 or \
                     eta_t=noise.csv:0.1"
                )
            })?;
            let input = options::floor_input(OptionKey::WITNESS_NOISE, item, name)?;
            let (level, rel) = match value.rsplit_once(':') {
                Some((head, tail))
                    if !head.trim().is_empty() && tail.trim().parse::<f64>().is_ok() =>
                {
                    (head.trim(), tail.trim().parse::<f64>().expect("checked"))
                }
                _ => (value.trim(), 0.0),
            };
            let asd = if tiltnoise_job::files::input_format(Path::new(level)).is_ok() {
                AsdSpec::File(PathBuf::from(level))
            } else {
                AsdSpec::White(level.parse().map_err(|_| {
                    anyhow!(
                        "--witness-noise {shown}: `{}` is neither a number (the ASD in \
                         {}/sqrt(Hz)) nor an ASD file (.csv, .h5, .hdf5)",
                        Shown(level),
                        input.unit()
                    )
                })?)
            };
            Ok(WitnessItem { input, asd, rel })
        })
        .collect()
}
