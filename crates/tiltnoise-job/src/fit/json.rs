//! The files of a fit: the JSON report (also what the command line prints with `--format
//! json`) and the HDF5 file, written atomically, the same for every front end.

use super::FitOutcome;
use crate::error::JobError;
use crate::outcome::{Outcome, Provenance};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use tiltnoise_core::fit::{Bound, FitResult, SigmaSource};
use tiltnoise_io::{write_fit_hdf5, OutputError, OutputKind, RunMeta, Staging};

/// The kinds of file a fit is saved as: the report ([`Outcome::json`]) and HDF5.
pub const OUTPUT_KINDS: &[OutputKind] = &[OutputKind::Json, OutputKind::Hdf5];

impl Outcome for FitOutcome {
    fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    fn output_kinds(&self) -> &'static [OutputKind] {
        OUTPUT_KINDS
    }

    /// Saves `.json` (the report) or `.h5`/`.hdf5` (schema `tiltnoise.fit`).
    fn save(&self, stage: &Staging, path: &Path) -> Result<(), JobError> {
        Ok(save(stage, path, self, &self.provenance)?)
    }

    /// The report: keys in alphabetical order, non-finite numbers as `null` (JSON has no
    /// infinity); a saved `.json` file holds it pretty-printed with a final newline.
    fn json(&self) -> serde_json::Value {
        serde_json::to_value(fit_json(&self.result, &self.origin))
            .expect("a report with string keys serializes")
    }
}

/// Saves a fit in the format named by the extension of `path`: `.json` (the JSON report) or
/// `.h5`/`.hdf5` (schema `tiltnoise.fit`, with `meta`), as one of the outputs of `stage`.
///
/// # Errors
///
/// [`OutputError::UnknownFormat`] for another extension (nothing is written), or the writer's
/// [`OutputError::Write`] naming `path`.
pub fn save(
    stage: &Staging,
    path: &Path,
    fit: &FitOutcome,
    meta: &RunMeta,
) -> Result<(), OutputError> {
    match crate::output_kind(path, OUTPUT_KINDS)? {
        OutputKind::Json => {
            let text =
                serde_json::to_string_pretty(&fit.json()).map_err(|e| OutputError::Write {
                    path: path.to_path_buf(),
                    message: e.to_string().into(),
                })? + "\n";
            stage.write(path, |tmp| {
                std::fs::write(tmp, text.as_bytes()).map_err(|e| e.to_string())
            })
        }
        _ => write_fit_hdf5(stage, path, &fit.result, &fit.origin, meta),
    }
}

fn sigma_source(s: SigmaSource) -> &'static str {
    match s {
        SigmaSource::File => "file",
        SigmaSource::Digits => "digits",
    }
}

/// The JSON report (also the content of a saved .json file). Non-finite numbers are written
/// as `null` (JSON has no infinity).
fn fit_json<'a>(r: &'a FitResult, origin: &'a str) -> FitJson<'a> {
    FitJson {
        bound_sigmas: r.config.bound_sigmas,
        chi2: r.chi2,
        chi2_nominal: r.chi2_nominal,
        correlation: &r.correlation,
        dof: r.dof,
        evaluations: r.evaluations,
        fitted_params_toml: r.fitted_params.to_toml(),
        iterations: r.iterations,
        measured_origin: origin,
        modes: r
            .modes
            .iter()
            .map(|m| ModeJson {
                fitted_hz: m.fitted_hz,
                index: m.measured.mode,
                measured_hz: m.measured.frequency_hz,
                nominal_hz: m.nominal_hz,
                residual_hz: m.residual_hz(),
                residual_sigmas: m.residual_sigmas(),
                sigma_hz: m.measured.sigma_hz,
                sigma_source: sigma_source(m.measured.sigma_source),
            })
            .collect(),
        parameters: r
            .params
            .iter()
            .zip(&r.start)
            .map(|(p, &start)| ParamJson {
                at_bound: p.at_bound.map(Bound::name),
                data_sigma_rel: p.data_sigma_rel,
                fitted: p.fitted,
                fitted_sigma: p.fitted_sigma,
                key: &p.key,
                nominal: p.nominal,
                poorly_constrained: p.poorly_constrained,
                prior_sigma: p.prior_sigma,
                start,
                unit: &p.unit,
            })
            .collect(),
        prior: r.config.prior,
        prior_term: r.prior_term,
        projected_gradient: r.projected_gradient,
        singular_values: &r.singular_values,
        stop: r.stop.describe(),
        visibilities: r
            .visibilities
            .iter()
            .map(|v| VisibilityJson {
                fitted: v.fitted,
                measured: v.measured.ratio,
                mode: v.measured.mode,
                nominal: v.nominal,
                observable: v.measured.observable.name(),
                reference: v.measured.reference.name(),
                residual_sigmas: v.residual_sigmas(),
                sigma: v.measured.sigma,
                sigma_source: sigma_source(v.measured.sigma_source),
            })
            .collect(),
        weak_directions: r
            .weak_directions
            .iter()
            .map(|w| WeakJson {
                direction: w.direction.iter().map(|(k, c)| (k.as_str(), *c)).collect(),
                singular_value: w.singular_value,
            })
            .collect(),
    }
}

// Keys in alphabetical order, as the report has always listed them: fields declared in that
// order, maps as BTreeMaps.

#[derive(Serialize)]
struct FitJson<'a> {
    bound_sigmas: f64,
    chi2: f64,
    chi2_nominal: f64,
    /// Correlation matrix of the parameters (their order); null on a bound.
    correlation: &'a [Vec<f64>],
    dof: usize,
    evaluations: usize,
    fitted_params_toml: String,
    iterations: usize,
    measured_origin: &'a str,
    modes: Vec<ModeJson>,
    parameters: Vec<ParamJson<'a>>,
    prior: bool,
    prior_term: f64,
    projected_gradient: f64,
    singular_values: &'a [f64],
    stop: &'static str,
    visibilities: Vec<VisibilityJson>,
    weak_directions: Vec<WeakJson<'a>>,
}

#[derive(Serialize)]
struct VisibilityJson {
    fitted: f64,
    measured: f64,
    mode: usize,
    nominal: f64,
    observable: &'static str,
    reference: &'static str,
    residual_sigmas: f64,
    sigma: f64,
    sigma_source: &'static str,
}

#[derive(Serialize)]
struct ModeJson {
    fitted_hz: f64,
    index: usize,
    measured_hz: f64,
    nominal_hz: f64,
    residual_hz: f64,
    residual_sigmas: f64,
    sigma_hz: f64,
    sigma_source: &'static str,
}

#[derive(Serialize)]
struct ParamJson<'a> {
    at_bound: Option<&'static str>,
    data_sigma_rel: f64,
    fitted: f64,
    fitted_sigma: Option<f64>,
    key: &'a str,
    nominal: f64,
    poorly_constrained: bool,
    prior_sigma: f64,
    start: f64,
    unit: &'a str,
}

#[derive(Serialize)]
struct WeakJson<'a> {
    direction: BTreeMap<&'a str, f64>,
    singular_value: f64,
}
