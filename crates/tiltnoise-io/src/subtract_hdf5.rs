//! The cleaned record of `tiltnoise subtract` as HDF5: the observable-series layout that
//! `tiltnoise budget --measured` reads (schema `tiltnoise.observable_series`: root attribute
//! `sample_rate_hz`, one 1-D float64 dataset per observable with a `units` attribute, optional
//! `start_time`), holding the cleaned series; everything else in groups, which series readers
//! ignore: the predicted tilt parts (`/predicted_tilt`), the estimates (`/estimates`), the
//! held-out residual spectra (`/residuals/<observable>`), the alignment and the provenance.
//! Documented in `docs/subtract.md`.

use super::h5util::{dataset, scalar_attr, str_attr, strs_attr, unit_dataset, units_dataset};
use super::series_hdf5::{SCHEMA_OBSERVABLE_SERIES, SCHEMA_VERSION_OBSERVABLE_SERIES};
use super::{InputMeta, RunMeta, SPECTRAL_CONVENTION};
use crate::atomic::write_atomic;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::subtract::{Estimate, FitReport, SubtractResult};

/// Provenance of a subtraction run.
#[derive(Debug, Clone, PartialEq)]
pub struct SubtractMeta {
    /// Tool version, nominal parameters, command line, modes.
    pub run: RunMeta,
    /// The tilt record as read.
    pub tilt: InputMeta,
    /// The measured record's path, as given.
    pub measured_path: String,
    /// ISO 8601 time of the first sample of the overlap, when the inputs state start times.
    pub start_time: Option<String>,
}

/// A value of the report as it is stored: a non-finite number (the uncertainty of a parameter
/// the data do not constrain at all) becomes NaN, documented as "not available".
fn stored(v: f64) -> f64 {
    if v.is_finite() {
        v
    } else {
        f64::NAN
    }
}

/// Writes the result of `subtract` to `path` atomically (nothing is left there on error).
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O or HDF5 failure.
pub fn write_subtract_hdf5(
    path: &Path,
    result: &SubtractResult,
    meta: &SubtractMeta,
) -> Result<(), OutputError> {
    write_atomic(path, |temp| {
        write_file(temp, result, meta)
            .map_err(|e| format!("HDF5: {}", crate::first_line(&e.to_string())))
    })
}

fn write_file(path: &Path, r: &SubtractResult, meta: &SubtractMeta) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    write_cleaned(&file, r, meta)?;
    write_prediction(&file, r)?;
    write_estimates(&file, &r.fit)?;
    write_residuals(&file, r)?;
    write_alignment(&file, r)?;
    write_provenance(&file, r, meta)
}

/// The root: the cleaned series as a series reader reads them, and the run's attributes.
fn write_cleaned(file: &hdf5::File, r: &SubtractResult, meta: &SubtractMeta) -> hdf5::Result<()> {
    let a = &r.alignment;
    str_attr(file, "schema", SCHEMA_OBSERVABLE_SERIES)?;
    scalar_attr(file, "schema_version", SCHEMA_VERSION_OBSERVABLE_SERIES)?;
    scalar_attr(file, "sample_rate_hz", a.fs_hz)?;
    if let Some(t) = &meta.start_time {
        str_attr(file, "start_time", t)?;
    }
    str_attr(
        file,
        "description",
        "measured observables minus their tilt part predicted by tiltnoise subtract",
    )?;
    str_attr(file, "tool_version", &meta.run.tool_version)?;
    str_attr(file, "created_by", &meta.run.command_line)?;
    str_attr(file, "parameters_toml", &meta.run.params_toml)?;
    str_attr(file, "fitted_parameters_toml", &r.fit.params.to_toml())?;
    str_attr(file, "spectral_convention", SPECTRAL_CONVENTION)?;
    for (o, series) in &r.cleaned {
        let ds = dataset(file, o.name(), series)?;
        str_attr(&ds, "unit", o.unit())?;
    }
    Ok(())
}

/// `predicted_tilt`: the tilt part of each observable and the bands it is not predicted in.
fn write_prediction(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
    let g = file.create_group("predicted_tilt")?;
    str_attr(
        &g,
        "description",
        "tilt part of each observable predicted from the tilt record through the fitted model",
    )?;
    for (o, series) in &r.prediction.series {
        let ds = dataset(&g, o.name(), series)?;
        str_attr(&ds, "unit", o.unit())?;
        let bands = r
            .prediction
            .guarded
            .iter()
            .find(|(x, _)| x == o)
            .map(|(_, b)| {
                b.iter()
                    .flat_map(|(lo, hi)| [*lo, *hi])
                    .collect::<Vec<f64>>()
            })
            .unwrap_or_default();
        ds.new_attr_builder()
            .with_data(&ndarray::ArrayView1::from(&bands))
            .create("not_predicted_bands_hz")?;
    }

    Ok(())
}

/// One number of an [`Estimate`].
type EstimateField = fn(&Estimate) -> f64;

/// `estimates`: the fitted parameters, their errors and correlations, the fit's statistics.
fn write_estimates(file: &hdf5::File, f: &FitReport) -> hdf5::Result<()> {
    let g = file.create_group("estimates")?;
    let e = &f.estimates;
    strs_attr(&g, "estimator", [ESTIMATOR])?;
    strs_attr(&g, "name", e.iter().map(|x| x.name.as_str()))?;
    strs_attr(&g, "unit", e.iter().map(|x| x.unit.as_str()))?;
    strs_attr(&g, "status", e.iter().map(|x| x.status.name()))?;
    let columns: [(&str, EstimateField); 6] = [
        ("nominal", |x| x.nominal),
        ("value", |x| x.value),
        ("sigma", |x| x.sigma),
        ("scale", |x| x.scale),
        ("lower", |x| x.bounds.0),
        ("upper", |x| x.bounds.1),
    ];
    for (name, get) in columns {
        let values: Vec<f64> = e.iter().map(|x| stored(get(x))).collect();
        units_dataset(&g, name, &values, e.iter().map(|x| x.unit.as_str()))?;
    }
    scalar_attr(&g, "chi2", f.chi2)?;
    scalar_attr(&g, "dof", f.dof as u64)?;
    scalar_attr(&g, "sigma_factor", f.sigma_factor)?;
    unit_dataset(&g, "fit_band_hz", &[f.band_hz.0, f.band_hz.1], "Hz")?;
    strs_attr(&g, "bins_observable", f.bins.iter().map(|b| b.0.name()))?;
    unit_dataset(
        &g,
        "bins",
        &f.bins.iter().map(|b| b.1 as u64).collect::<Vec<_>>(),
        "1",
    )?;
    unit_dataset(&g, "witness_bias", &f.witness_bias, "1")?;
    scalar_attr(&g, "iterations", f.iterations as u64)?;
    str_attr(&g, "stop", f.stop.describe())?;
    strs_attr(&g, "fitted", f.fitted.iter().map(String::as_str))?;
    let flat: Vec<f64> = f.correlation.iter().flatten().map(|&v| stored(v)).collect();
    let n = f.fitted.len();
    let d = g
        .new_dataset_builder()
        .with_data(
            &ndarray::ArrayView2::from_shape((n, n), &flat)
                .map_err(|e| hdf5::Error::from(e.to_string()))?,
        )
        .create("correlation")?;
    str_attr(&d, "unit", "1")?;

    Ok(())
}

/// `residuals`: per observable the held-out spectra and their band summary.
fn write_residuals(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
    let g = file.create_group("residuals")?;
    str_attr(&g, "spectral_convention", SPECTRAL_CONVENTION)?;
    str_attr(&g, "stretch", "held-out (the end of the overlap)")?;
    scalar_attr(&g, "segment_len", r.segment_len as u64)?;
    scalar_attr(&g, "effective_averages", r.n_eff.1)?;
    for s in &r.residuals {
        let o = s.observable;
        let h = g.create_group(o.name())?;
        let unit = format!("{}/sqrt(Hz)", o.unit());
        str_attr(&h, "unit", &unit)?;
        unit_dataset(&h, "frequency_hz", &s.freqs_hz, "Hz")?;
        for (name, psd) in [
            ("measured_asd", &s.measured_psd),
            ("predicted_asd", &s.predicted_psd),
            ("cleaned_asd", &s.cleaned_psd),
            ("wiener_asd", &s.wiener_psd),
            ("expected_asd", &s.expected_psd),
        ] {
            let asd: Vec<f64> = psd.iter().map(|p| p.max(0.0).sqrt()).collect();
            unit_dataset(&h, name, &asd, &unit)?;
        }
        scalar_attr(&h, "readout_asd", stored(s.readout_asd.unwrap_or(f64::NAN)))?;
        let b = &s.band;
        unit_dataset(&h, "band_hz", &[b.band_hz.0, b.band_hz.1], "Hz")?;
        scalar_attr(&h, "band_bins", b.bins as u64)?;
        for (name, v) in [
            ("band_measured_asd", b.measured_asd),
            ("band_predicted_asd", b.predicted_asd),
            ("band_cleaned_asd", b.cleaned_asd),
            ("band_wiener_asd", b.wiener_asd),
            ("band_expected_asd", b.expected_asd),
            ("band_psd_rel_sigma", b.psd_rel_sigma),
            ("band_cleaned_to_expected", b.cleaned_to_expected.0),
            ("band_cleaned_to_expected_sigma", b.cleaned_to_expected.1),
            (
                "band_cleaned_to_readout",
                b.cleaned_to_readout.map_or(f64::NAN, |r| r.0),
            ),
            (
                "band_cleaned_to_readout_sigma",
                b.cleaned_to_readout.map_or(f64::NAN, |r| r.1),
            ),
        ] {
            scalar_attr(&h, name, stored(v))?;
        }
    }

    Ok(())
}

/// `alignment`: where the records overlap and how the overlap was split.
fn write_alignment(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
    let a = &r.alignment;
    let g = file.create_group("alignment")?;
    scalar_attr(&g, "tilt_first_sample", a.witness_first as u64)?;
    scalar_attr(&g, "measured_first_sample", a.measured_first as u64)?;
    scalar_attr(&g, "samples", a.len as u64)?;
    scalar_attr(&g, "fraction_s", a.fraction_s)?;
    scalar_attr(
        &g,
        "start_offset_s",
        stored(a.start_offset_s.unwrap_or(f64::NAN)),
    )?;
    str_attr(&g, "note", &a.note)?;
    scalar_attr(&g, "training_samples", r.n_train as u64)?;
    scalar_attr(&g, "holdout_samples", r.n_holdout as u64)?;
    scalar_attr(&g, "max_delay_s", r.max_delay_s)?;

    Ok(())
}

/// `provenance`: the inputs and the run's notes.
fn write_provenance(
    file: &hdf5::File,
    r: &SubtractResult,
    meta: &SubtractMeta,
) -> hdf5::Result<()> {
    let g = file.create_group("provenance")?;
    str_attr(&g, "tilt_path", &meta.tilt.path)?;
    str_attr(&g, "tilt_format", &meta.tilt.format)?;
    str_attr(&g, "tilt_quantity", &meta.tilt.quantity)?;
    str_attr(&g, "tilt_axis_map", &meta.tilt.axis_map)?;
    strs_attr(&g, "tilt_notes", meta.tilt.notes.iter().map(String::as_str))?;
    str_attr(&g, "measured_path", &meta.measured_path)?;
    strs_attr(&g, "notes", r.notes.iter().map(String::as_str))?;
    Ok(())
}

/// The estimator, in one line, for the file.
const ESTIMATOR: &str = "errors-in-variables-corrected weighted least squares on Welch cross \
     spectra: r = s_wy - (S_ww - S_mm) G(theta), whitened by S_ww S_ee / n_eff (docs/subtract.md)";
