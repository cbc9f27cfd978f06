//! What `tiltnoise budget` budgets: `--observables`, `--readout OBS=ASD|FILE` (white or
//! coloured) and `--term NAME=SOURCE:FILE` (an ASD of an observable, or of a force, torque or
//! tilt input propagated through the model). Every file is read and checked here, before the
//! budget is computed; a bad one is one error line naming the file, key and value.

use super::args::parse_readout_item;
use anyhow::{anyhow, bail, Context, Result};
use std::path::{Path, PathBuf};
use tiltnoise_core::error::Shown;
use tiltnoise_core::model::{Input, Observable};
use tiltnoise_core::noise::{is_term_name, GivenAsd, Readout, UserSource, UserTerm};
use tiltnoise_core::options;
use tiltnoise_core::repeats::refuse_repeated_keys;
use tiltnoise_io::input::{input_format, read_asd_column};

const OBSERVABLES: &str = "X, Y, Z, theta, eta, phi, phi_a";
const INPUTS: &str =
    "theta_t, eta_t, phi_t (rad), x_t, y_t, z_t (m), F_a.x .. F_b.z (N), M_a.x .. M_b.z (N m)";

/// `--observables X,phi,...`: known names, each once.
pub fn parse_observables(text: &str) -> Result<Vec<Observable>> {
    Ok(options::parse_outputs("--observables", &[text])?)
}

/// The unit of an ASD of a quantity of SI unit `unit`, as a static string for messages.
fn asd_unit(unit: &str) -> &'static str {
    match unit {
        "m" => "m/sqrt(Hz)",
        "rad" => "rad/sqrt(Hz)",
        "N" => "N/sqrt(Hz)",
        _ => "N m/sqrt(Hz)",
    }
}

/// Reads the ASD of `quantity` (SI unit `unit`) from `path` for the option `option` (e.g.
/// `--readout phi=r.csv`), which names it in messages.
pub(crate) fn read_given(
    option: &str,
    path: &Path,
    quantity: &str,
    unit: &str,
) -> Result<GivenAsd> {
    let column =
        read_asd_column(path, quantity, asd_unit(unit)).with_context(|| option.to_string())?;
    let origin = format!("{option} (column {})", column.column);
    GivenAsd::new(column.freqs_hz, column.asd, &origin).map_err(|e| anyhow!("{e}"))
}

/// `--readout OBS=ASD` (white, in the observable's unit/sqrt(Hz); 0 removes it) or
/// `--readout OBS=FILE` (coloured, a `.csv`, `.h5` or `.hdf5` ASD file), over the default 9e-9
/// m/sqrt(Hz) on X; every observable must be budgeted. Returns the readout and the files read.
pub fn parse_readout(items: &[String], budgeted: &[Observable]) -> Result<(Readout, Vec<PathBuf>)> {
    let mut readout = Readout::default();
    let mut files = Vec::new();
    refuse_repeated_keys("--readout", "observable", items)?;
    for item in items {
        // A value with the extension of an ASD file is a file; anything else must be a number.
        let file = item
            .split_once('=')
            .map(|(_, v)| Path::new(v.trim()))
            .filter(|p| input_format(p).is_ok());
        let o = match file {
            None => {
                let (o, asd) = parse_readout_item(item)?;
                readout.asd.retain(|(x, _)| *x != o);
                readout.given.retain(|(x, _)| *x != o);
                if asd > 0.0 {
                    readout.asd.push((o, asd));
                }
                o
            }
            Some(path) => {
                let name = item.split_once('=').map_or("", |(n, _)| n);
                let o = Observable::from_name(name.trim()).ok_or_else(|| {
                    anyhow!(
                        "--readout {}: unknown observable `{}`; allowed: {OBSERVABLES}",
                        Shown(item),
                        Shown(name)
                    )
                })?;
                let path = path.to_path_buf();
                let option = format!("--readout {}", Shown(item));
                let given = read_given(&option, &path, o.name(), o.unit())?;
                readout.asd.retain(|(x, _)| *x != o);
                readout.given.retain(|(x, _)| *x != o);
                readout.given.push((o, given));
                files.push(path);
                o
            }
        };
        if !budgeted.contains(&o) {
            bail!(
                "--readout {}: {} is not budgeted; allowed: {} (add it with --observables)",
                Shown(item),
                o.name(),
                budgeted
                    .iter()
                    .map(|o| o.name())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    // The default readout is on X; without X it has nothing to apply to.
    readout.asd.retain(|(o, _)| budgeted.contains(o));
    Ok((readout, files))
}

/// `--term NAME=SOURCE:FILE`: NAME a new term name, SOURCE a budgeted observable (the file
/// holds that observable's ASD) or an input of the model (its ASD, propagated through the
/// transfer functions), FILE a CSV or HDF5 ASD file. Returns the terms and the files read.
pub fn parse_terms(
    items: &[String],
    budgeted: &[Observable],
) -> Result<(Vec<UserTerm>, Vec<PathBuf>)> {
    let mut terms: Vec<UserTerm> = Vec::new();
    let mut files = Vec::new();
    refuse_repeated_keys("--term", "term name", items)?;
    for item in items {
        let shown = Shown(item);
        let (name, rest) = item.split_once('=').ok_or_else(|| {
            anyhow!("--term {shown}: expected NAME=SOURCE:FILE, e.g. actuation=F_b.x:force.csv")
        })?;
        let (source, file) = rest.split_once(':').ok_or_else(|| {
            anyhow!("--term {shown}: expected NAME=SOURCE:FILE, e.g. magnetic=phi:phi_mag.csv")
        })?;
        let name = name.trim();
        if !is_term_name(name) {
            bail!(
                "--term {shown}: the name `{}` is not allowed: 1 to 64 letters, digits or _, \
                 starting with a letter",
                Shown(name)
            );
        }
        let source = source.trim();
        let source = match (Observable::from_name(source), Input::from_name(source)) {
            (Some(o), _) => {
                if !budgeted.contains(&o) {
                    bail!(
                        "--term {shown}: {} is not budgeted; budgeted: {} (add it with \
                         --observables)",
                        o.name(),
                        budgeted
                            .iter()
                            .map(|o| o.name())
                            .collect::<Vec<_>>()
                            .join(", ")
                    );
                }
                UserSource::Observable(o)
            }
            (None, Some(i)) => UserSource::Input(i),
            (None, None) => bail!(
                "--term {shown}: unknown source `{}`; allowed: an observable ({OBSERVABLES}) or \
                 an input ({INPUTS})",
                Shown(source)
            ),
        };
        let unit = match source {
            UserSource::Observable(o) => o.unit(),
            UserSource::Input(i) => i.unit(),
        };
        let path = PathBuf::from(file.trim());
        let asd = read_given(&format!("--term {shown}"), &path, source.name(), unit)?;
        terms.push(UserTerm {
            name: name.to_string(),
            source,
            asd,
        });
        files.push(path);
    }
    Ok((terms, files))
}
