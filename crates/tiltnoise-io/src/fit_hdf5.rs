//! The fit's HDF5 file (`tiltnoise fit --save fit.h5`; layout in `docs/fit.md`).

use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::fit::{Bound, FitResult};

/// Writes the result of a fit to `path` as HDF5, atomically: root attributes (tool version,
/// origin of the measured frequencies, stop reason, fitted parameter file, chi^2), group
/// `/parameters` (one entry per free parameter) and `/modes` (one per measured mode), and the
/// singular values of the weighted Jacobian.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path`; nothing is left there.
pub fn write_fit_hdf5(path: &Path, r: &FitResult, origin: &str) -> Result<(), OutputError> {
    crate::write_atomic(path, |tmp| {
        write_h5(tmp, r, origin).map_err(|e| crate::first_line(&e.to_string()))
    })
}

fn write_h5(path: &Path, r: &FitResult, origin: &str) -> hdf5::Result<()> {
    use hdf5::types::VarLenUnicode;
    use ndarray::{arr0, ArrayView1};
    let file = hdf5::File::create(path)?;
    let vstr = |s: &str| -> hdf5::Result<VarLenUnicode> {
        s.parse::<VarLenUnicode>().map_err(|e| e.to_string().into())
    };
    let attr_str = |loc: &hdf5::Location, name: &str, value: &str| -> hdf5::Result<()> {
        loc.new_attr_builder()
            .with_data(&arr0(vstr(value)?))
            .create(name)?;
        Ok(())
    };
    let attr_f64 = |loc: &hdf5::Location, name: &str, value: f64| -> hdf5::Result<()> {
        loc.new_attr_builder()
            .with_data(&arr0(value))
            .create(name)?;
        Ok(())
    };
    attr_str(&file, "tool_version", crate::TOOL_VERSION)?;
    attr_str(&file, "measured_origin", origin)?;
    attr_str(&file, "stop", r.stop.describe())?;
    attr_str(&file, "fitted_params_toml", &r.fitted_params.to_toml())?;
    attr_f64(&file, "bound_sigmas", r.config.bound_sigmas)?;
    attr_f64(&file, "chi2_nominal", r.chi2_nominal)?;
    attr_f64(&file, "chi2", r.chi2)?;
    attr_f64(&file, "prior_term", r.prior_term)?;
    attr_f64(&file, "dof", r.dof as f64)?;
    attr_f64(&file, "prior", if r.config.prior { 1.0 } else { 0.0 })?;
    let ds_f64 = |g: &hdf5::Group, name: &str, data: Vec<f64>| -> hdf5::Result<()> {
        g.new_dataset_builder()
            .with_data(ArrayView1::from(&data))
            .create(name)?;
        Ok(())
    };
    let ds_str = |g: &hdf5::Group, name: &str, data: Vec<String>| -> hdf5::Result<()> {
        let v: Vec<VarLenUnicode> = data.iter().map(|s| vstr(s)).collect::<Result<_, _>>()?;
        g.new_dataset_builder()
            .with_data(ArrayView1::from(&v))
            .create(name)?;
        Ok(())
    };
    let p = file.create_group("parameters")?;
    ds_str(&p, "key", r.params.iter().map(|x| x.key.clone()).collect())?;
    ds_str(
        &p,
        "unit",
        r.params.iter().map(|x| x.unit.clone()).collect(),
    )?;
    ds_f64(&p, "nominal", r.params.iter().map(|x| x.nominal).collect())?;
    ds_f64(&p, "fitted", r.params.iter().map(|x| x.fitted).collect())?;
    ds_f64(
        &p,
        "fitted_sigma",
        r.params
            .iter()
            .map(|x| x.fitted_sigma.unwrap_or(f64::NAN))
            .collect(),
    )?;
    ds_f64(
        &p,
        "prior_sigma",
        r.params.iter().map(|x| x.prior_sigma).collect(),
    )?;
    ds_str(
        &p,
        "at_bound",
        r.params
            .iter()
            .map(|x| x.at_bound.map_or("", Bound::name).to_string())
            .collect(),
    )?;
    ds_f64(
        &p,
        "data_sigma_rel",
        r.params.iter().map(|x| x.data_sigma_rel).collect(),
    )?;
    let m = file.create_group("modes")?;
    ds_f64(
        &m,
        "index",
        r.modes.iter().map(|x| x.measured.mode as f64).collect(),
    )?;
    ds_f64(
        &m,
        "measured_hz",
        r.modes.iter().map(|x| x.measured.frequency_hz).collect(),
    )?;
    ds_f64(
        &m,
        "sigma_hz",
        r.modes.iter().map(|x| x.measured.sigma_hz).collect(),
    )?;
    ds_f64(
        &m,
        "nominal_hz",
        r.modes.iter().map(|x| x.nominal_hz).collect(),
    )?;
    ds_f64(
        &m,
        "fitted_hz",
        r.modes.iter().map(|x| x.fitted_hz).collect(),
    )?;
    ds_f64(
        &m,
        "residual_hz",
        r.modes.iter().map(|x| x.residual_hz()).collect(),
    )?;
    ds_f64(&file, "singular_values", r.singular_values.clone())?;
    Ok(())
}
