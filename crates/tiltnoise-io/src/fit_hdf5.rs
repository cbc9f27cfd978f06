//! The fit's HDF5 file (`tiltnoise fit --save fit.h5`; schema `tiltnoise.fit`, layout in
//! `docs/fit.md` and `docs/schemas.md`).

use super::h5util::{dataset, provenance, scalar_attr, str_attr, strings, strs_attr};
use crate::atomic::Staging;
use crate::run_meta::RunMeta;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::fit::{Bound, FitResult, SigmaSource, VisibilityFit};

/// Value of the root attribute `schema`.
pub const SCHEMA_FIT: &str = "tiltnoise.fit";

/// Value of the root attribute `schema_version`. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_FIT: i64 = 3;

/// Writes the result of a fit to `path` as HDF5, atomically: root attributes (schema and
/// provenance, origin of the measured frequencies, stop reason, fitted parameter file, chi^2),
/// group `/parameters` (one entry per free parameter), `/modes` (one per measured mode) and
/// `/visibilities` (one per measured visibility, the entries of the JSON report's
/// `visibilities`), and the singular values of the weighted Jacobian. Every numeric dataset has a `unit`
/// attribute (an array of one unit per entry where the entries differ); indices and counts
/// are integers.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path`; nothing is left there.
pub fn write_fit_hdf5(
    stage: &Staging,
    path: &Path,
    r: &FitResult,
    origin: &str,
    meta: &RunMeta,
) -> Result<(), OutputError> {
    stage.write(path, |tmp| {
        write_h5(tmp, r, origin, meta).map_err(|e| crate::messages::first_line(&e.to_string()))
    })
}

fn write_h5(path: &Path, r: &FitResult, origin: &str, meta: &RunMeta) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    provenance(&file, SCHEMA_FIT, SCHEMA_VERSION_FIT, meta)?;
    str_attr(&file, "measured_origin", origin)?;
    str_attr(&file, "stop", r.stop.describe())?;
    str_attr(&file, "fitted_params_toml", &r.fitted_params.to_toml())?;
    scalar_attr(&file, "bound_sigmas", r.config.bound_sigmas)?;
    scalar_attr(&file, "chi2_nominal", r.chi2_nominal)?;
    scalar_attr(&file, "chi2", r.chi2)?;
    scalar_attr(&file, "prior_term", r.prior_term)?;
    scalar_attr(&file, "dof", int(r.dof)?)?;
    scalar_attr(&file, "prior", u8::from(r.config.prior))?;
    let with_unit = |g: &hdf5::Group, name: &str, data: &[f64], unit: &str| {
        let d = dataset(g, name, data)?;
        str_attr(&d, "unit", unit)
    };
    let units: Vec<&str> = r.params.iter().map(|x| x.unit.as_str()).collect();
    let per_param = |g: &hdf5::Group, name: &str, data: Vec<f64>| -> hdf5::Result<()> {
        let d = dataset(g, name, &data)?;
        strs_attr(&d, "unit", &units)
    };
    let strs = |g: &hdf5::Group, name: &str, data: Vec<String>| -> hdf5::Result<()> {
        dataset(g, name, &strings(&data)?)?;
        Ok(())
    };
    let p = file.create_group("parameters")?;
    strs(&p, "key", r.params.iter().map(|x| x.key.clone()).collect())?;
    strs(
        &p,
        "unit",
        r.params.iter().map(|x| x.unit.clone()).collect(),
    )?;
    per_param(&p, "nominal", r.params.iter().map(|x| x.nominal).collect())?;
    per_param(&p, "fitted", r.params.iter().map(|x| x.fitted).collect())?;
    per_param(
        &p,
        "fitted_sigma",
        r.params
            .iter()
            .map(|x| x.fitted_sigma.unwrap_or(f64::NAN))
            .collect(),
    )?;
    per_param(
        &p,
        "prior_sigma",
        r.params.iter().map(|x| x.prior_sigma).collect(),
    )?;
    strs(
        &p,
        "at_bound",
        r.params
            .iter()
            .map(|x| x.at_bound.map_or("", Bound::name).to_string())
            .collect(),
    )?;
    let rel: Vec<f64> = r.params.iter().map(|x| x.data_sigma_rel).collect();
    with_unit(&p, "data_sigma_rel", &rel, "1")?;
    let m = file.create_group("modes")?;
    let index: Vec<i64> = r
        .modes
        .iter()
        .map(|x| int(x.measured.mode))
        .collect::<hdf5::Result<_>>()?;
    let d = dataset(&m, "index", &index)?;
    str_attr(&d, "unit", "1")?;
    let hz = |f: fn(&tiltnoise_core::fit::ModeFit) -> f64| -> Vec<f64> {
        r.modes.iter().map(f).collect()
    };
    with_unit(&m, "measured_hz", &hz(|x| x.measured.frequency_hz), "Hz")?;
    with_unit(&m, "sigma_hz", &hz(|x| x.measured.sigma_hz), "Hz")?;
    with_unit(&m, "nominal_hz", &hz(|x| x.nominal_hz), "Hz")?;
    with_unit(&m, "fitted_hz", &hz(|x| x.fitted_hz), "Hz")?;
    with_unit(&m, "residual_hz", &hz(|x| x.residual_hz()), "Hz")?;
    write_visibilities(&file, r)?;
    // Of the Jacobian weighted by the measurement errors: dimensionless.
    with_unit(&file, "singular_values", &r.singular_values, "1")?;
    Ok(())
}

/// Group `/visibilities`: one entry per measured visibility, in the order of the JSON report's
/// `visibilities` (empty datasets when the fit had none). Ratios are dimensionless; `nominal`
/// is NaN where the reference channel does not see the mode at the nominal parameters (null in
/// the JSON).
fn write_visibilities(file: &hdf5::File, r: &FitResult) -> hdf5::Result<()> {
    let v = file.create_group("visibilities")?;
    let mode: Vec<i64> = r
        .visibilities
        .iter()
        .map(|x| int(x.measured.mode))
        .collect::<hdf5::Result<_>>()?;
    let d = dataset(&v, "mode", &mode)?;
    str_attr(&d, "unit", "1")?;
    let text = |name: &str, f: fn(&VisibilityFit) -> &'static str| -> hdf5::Result<()> {
        let data: Vec<String> = r.visibilities.iter().map(|x| f(x).to_string()).collect();
        dataset(&v, name, &strings(&data)?)?;
        Ok(())
    };
    text("observable", |x| x.measured.observable.name())?;
    text("reference", |x| x.measured.reference.name())?;
    text("sigma_source", |x| match x.measured.sigma_source {
        SigmaSource::File => "file",
        SigmaSource::Digits => "digits",
    })?;
    let ratio = |name: &str, f: fn(&VisibilityFit) -> f64| -> hdf5::Result<()> {
        let data: Vec<f64> = r.visibilities.iter().map(f).collect();
        let d = dataset(&v, name, &data)?;
        str_attr(&d, "unit", "1")
    };
    ratio("measured", |x| x.measured.ratio)?;
    ratio("sigma", |x| x.measured.sigma)?;
    ratio("nominal", |x| x.nominal)?;
    ratio("fitted", |x| x.fitted)?;
    ratio("residual_sigmas", VisibilityFit::residual_sigmas)?;
    Ok(())
}

fn int(n: usize) -> hdf5::Result<i64> {
    i64::try_from(n).map_err(|e| e.to_string().into())
}
