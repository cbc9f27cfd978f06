//! What `tiltnoise budget` budgets: `--observables`, `--readout OBS=ASD|FILE` (white or
//! coloured) and `--term NAME=SOURCE:FILE` (an ASD of an observable, or of a force, torque or
//! tilt input propagated through the model), parsed into the budget job's items; the job reads
//! the files and checks them against what is budgeted.

use super::args::parse_readout_item;
use anyhow::{anyhow, Result};
use std::path::{Path, PathBuf};
use tiltnoise_core::error::Shown;
use tiltnoise_core::model::Observable;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::options;
use tiltnoise_core::repeats::refuse_repeated_keys;
use tiltnoise_job::{AsdSpec, ReadoutItem, TermItem};

/// `--observables X,phi,...`: known names, each once.
pub fn parse_observables(text: &str) -> Result<Vec<Observable>> {
    Ok(options::parse_outputs(OptionKey::OBSERVABLES, &[text])?)
}

/// `--readout OBS=ASD` (white, in the observable's unit/sqrt(Hz); 0 removes it) or
/// `--readout OBS=FILE` (coloured, a `.csv`, `.h5` or `.hdf5` ASD file), each observable once.
pub fn parse_readout(items: &[String]) -> Result<Vec<ReadoutItem>> {
    refuse_repeated_keys(OptionKey::READOUT, "observable", items)?;
    items
        .iter()
        .map(|item| {
            // A value with the extension of an ASD file is a file; anything else must be a
            // number.
            let file = item
                .split_once('=')
                .map(|(_, v)| Path::new(v.trim()))
                .filter(|p| tiltnoise_job::files::input_format(p).is_ok());
            let Some(path) = file else {
                let (observable, asd) = parse_readout_item(item)?;
                return Ok(ReadoutItem {
                    observable,
                    asd: AsdSpec::White(asd),
                });
            };
            let name = item.split_once('=').map_or("", |(n, _)| n);
            let observable = Observable::from_name(name.trim()).ok_or_else(|| {
                anyhow!(
                    "--readout {}: unknown observable `{}`; allowed: {}",
                    Shown(item),
                    Shown(name),
                    options::observable_names()
                )
            })?;
            Ok(ReadoutItem {
                observable,
                asd: AsdSpec::File(path.to_path_buf()),
            })
        })
        .collect()
}

/// `--term NAME=SOURCE:FILE`: NAME a new term name, SOURCE an observable (the file holds that
/// observable's ASD) or an input of the model (its ASD, propagated through the transfer
/// functions), FILE a CSV or HDF5 ASD file.
pub fn parse_terms(items: &[String]) -> Result<Vec<TermItem>> {
    refuse_repeated_keys(OptionKey::TERM, "term name", items)?;
    items
        .iter()
        .map(|item| {
            let shown = Shown(item);
            let (name, rest) = item.split_once('=').ok_or_else(|| {
                anyhow!("--term {shown}: expected NAME=SOURCE:FILE, e.g. actuation=F_b.x:force.csv")
            })?;
            let (source, file) = rest.split_once(':').ok_or_else(|| {
                anyhow!("--term {shown}: expected NAME=SOURCE:FILE, e.g. magnetic=phi:phi_mag.csv")
            })?;
            let source = options::term_source(OptionKey::TERM, item, source)?;
            Ok(TermItem {
                name: name.trim().to_string(),
                source,
                file: PathBuf::from(file.trim()),
            })
        })
        .collect()
}
