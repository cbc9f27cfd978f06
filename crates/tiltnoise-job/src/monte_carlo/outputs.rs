//! The Monte Carlo's report and files: the JSON document (what `tiltnoise mc --format json`
//! prints and the Python package's `MonteCarlo.summary` holds), the HDF5 file and the
//! histograms, written atomically, the same for every front end.

use super::McRun;
use crate::error::JobError;
use crate::outcome::{Outcome, Provenance};
use serde::Serialize;
use std::path::Path;
use tiltnoise_io::{write_mc_hdf5, OutputError, OutputKind, RunMeta, Staging};

/// The kinds of file a Monte Carlo is saved as: the draws (HDF5) and the histograms.
pub const OUTPUT_KINDS: &[OutputKind] = &[OutputKind::Hdf5, OutputKind::Png, OutputKind::Svg];

impl Outcome for McRun {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        Ok(save(stage, path, self, &self.provenance, &self.figure)?)
    }

    fn json(&self) -> serde_json::Value {
        serde_json::to_value(summary(self)).expect("a report of numbers serializes")
    }
}

/// Saves a Monte Carlo in the format named by the extension of `path`: `.h5`/`.hdf5` (schema
/// `tiltnoise.mc`, every draw, the error model and `meta`) or the histograms of the eight
/// modes as `.png`/`.svg`, drawn with `view`, as one of the outputs of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for another extension (nothing is written), or the
/// writer's [`OutputError::Write`] naming `path`.
pub fn save(
    stage: &Staging,
    path: &Path,
    run: &McRun,
    meta: &RunMeta,
    view: &tiltnoise_plot::View,
) -> Result<(), OutputError> {
    match crate::output_kind(path, OUTPUT_KINDS)? {
        OutputKind::Hdf5 => {
            write_mc_hdf5(stage, path, &run.result, &run.config, &run.nominal_hz, meta)
        }
        _ => {
            let caption = caption(run);
            crate::save_image(stage, path, |format| {
                tiltnoise_plot::mc_figure::mc_figure(
                    &run.result,
                    &run.nominal_hz,
                    &caption,
                    view,
                    format,
                )
            })
        }
    }
}

// Keys in alphabetical order, as every JSON report of the tool: fields declared in that order.

#[derive(Serialize)]
struct McJson {
    modes: Vec<McModeJson>,
    rejected: usize,
    samples: usize,
    seed: u64,
}

#[derive(Serialize)]
struct McModeJson {
    index: usize,
    mean_hz: f64,
    nominal_hz: f64,
    std_hz: f64,
}

/// The report, pretty-printed: draws, rejected draws, seed and, per mode (`index` 1..8), the
/// nominal frequency, mean and standard deviation (Hz); non-finite numbers as `null`.
///
/// # Errors
///
/// The serializer's error (none is expected: every key is a string).
pub fn summary_json(run: &McRun) -> serde_json::Result<String> {
    serde_json::to_string_pretty(&summary(run))
}

fn summary(run: &McRun) -> McJson {
    let result = &run.result;
    let modes = (0..8)
        .map(|k| McModeJson {
            index: k + 1,
            mean_hz: result.mean_hz[k],
            nominal_hz: run.nominal_hz[k],
            std_hz: result.std_hz[k],
        })
        .collect();
    McJson {
        modes,
        rejected: result.rejected,
        samples: result.samples,
        seed: run.config.seed,
    }
}

/// The histograms' caption: what is marked, counts, seed and the error model, grouped by
/// error.
pub fn caption(run: &McRun) -> String {
    let (result, cfg) = (&run.result, &run.config);
    let mut groups: Vec<(f64, &str, Vec<&str>)> = Vec::new();
    for u in cfg.uncertainties.iter().filter(|u| u.rel_sigma > 0.0) {
        let name = u.key.split_once('.').map_or(u.key.as_str(), |(_, n)| n);
        let shape = u.distribution.name();
        match groups
            .iter_mut()
            .find(|g| g.0 == u.rel_sigma && g.1 == shape)
        {
            Some(g) => g.2.push(name),
            None => groups.push((u.rel_sigma, shape, vec![name])),
        }
    }
    let model: Vec<String> = groups
        .iter()
        .map(|(s, shape, names)| format!("{} % {shape} on {}", s * 100.0, names.join(", ")))
        .collect();
    // The [asymmetry] offsets have absolute errors, in their own unit.
    let offsets: Vec<String> = cfg
        .uncertainties
        .iter()
        .filter(|u| u.abs_sigma > 0.0)
        .map(|u| {
            let name = u.key.split_once('.').map_or(u.key.as_str(), |(_, n)| n);
            format!("{:e} {} on {name}", u.abs_sigma, u.distribution.name())
        })
        .collect();
    let absolute = if offsets.is_empty() {
        String::new()
    } else {
        format!(
            "; absolute errors (1 std, in the key's unit): {}",
            offsets.join("; ")
        )
    };
    format!(
        "Black dashed: nominal parameters; orange: mean; shaded: mean ± 1 std. {} draws, {} \
         rejected as non-physical, seed {}. Relative errors (1 std): {}{absolute}; all other \
         parameters exact.",
        result.samples,
        result.rejected,
        cfg.seed,
        model.join("; ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiltnoise_core::mc::{McConfig, McResult};
    use tiltnoise_core::params::Params;

    #[test]
    fn the_report_lists_keys_alphabetically_and_nan_as_null() {
        let run = McRun {
            result: McResult {
                samples: 2,
                rejected: 1,
                freqs_hz: vec![[1.0; 8]],
                sample_index: vec![0],
                mean_hz: [1.0; 8],
                std_hz: [f64::NAN; 8],
            },
            config: McConfig {
                seed: 7,
                ..McConfig::default_for(&Params::table_i())
            },
            nominal_hz: [1.0; 8],
            provenance: Provenance::default(),
            figure: tiltnoise_plot::View::default(),
        };
        let text = summary_json(&run).unwrap();
        // A `serde_json::Value`'s objects are sorted maps: printed again, a document whose
        // keys are in alphabetical order is unchanged.
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(text, serde_json::to_string_pretty(&value).unwrap());
        assert_eq!(value["modes"][7]["std_hz"], serde_json::Value::Null);
        assert_eq!(value["seed"], 7);
    }

    #[test]
    fn only_hdf5_and_images_are_saved() {
        for ok in ["a.h5", "a.HDF5", "a.png", "a.svg"] {
            assert!(
                crate::output_kind(Path::new(ok), OUTPUT_KINDS).is_ok(),
                "{ok}"
            );
        }
        let err = crate::output_kind(Path::new("a.csv"), OUTPUT_KINDS)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("a.csv") && err.contains(".h5, .hdf5, .png, .svg"),
            "{err}"
        );
    }
}
