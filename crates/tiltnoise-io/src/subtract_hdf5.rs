//! The cleaned record of `tiltnoise subtract` as HDF5: the observable-series layout that
//! `tiltnoise budget --measured` reads (schema `tiltnoise.observable_series`: root attribute
//! `sample_rate_hz`, one 1-D float64 dataset per observable with a `units` attribute, optional
//! `start_time`), holding the cleaned series; everything else in groups, which series readers
//! ignore: the predicted floor parts (`/predicted_tilt`), the estimates (`/estimates`), the
//! held-out residual spectra (`/residuals/<observable>`), the check of the cleaned record per
//! band (`/bands/<observable>`), the witness noise as used (`/witness_noise`), the alignment
//! and the provenance.
//! Documented in `docs/subtract.md`.

use super::h5util::{dataset, scalar_attr, str_attr, strs_attr, unit_dataset, units_dataset};
use super::series_hdf5::{SCHEMA_OBSERVABLE_SERIES, SCHEMA_VERSION_OBSERVABLE_SERIES};
use crate::atomic::Staging;
use crate::budget_hdf5::SPECTRAL_CONVENTION;
use crate::run_meta::RunMeta;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::subtract::{FitReport, Method, SubtractResult};

/// Provenance of a subtraction run.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
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
    stage: &Staging,
    path: &Path,
    result: &SubtractResult,
    meta: &SubtractMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        write_file(temp, result, meta)
            .map_err(|e| format!("HDF5: {}", crate::messages::first_line(&e.to_string())))
    })
}

fn write_file(path: &Path, r: &SubtractResult, meta: &SubtractMeta) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    write_cleaned(&file, r, meta)?;
    write_predicted(&file, r)?;
    write_estimates(&file, &r.fit)?;
    write_residuals(&file, r)?;
    write_bands(&file, r)?;
    write_witness_noise(&file, r)?;
    write_alignment(&file, r)?;
    write_provenance(&file, r, meta)
}

/// One-sided ASDs of the PSDs `psd` (a PSD rounded below zero counts as zero).
fn asd(psd: &[f64]) -> Vec<f64> {
    psd.iter().map(|p| p.max(0.0).sqrt()).collect()
}

/// The root: the observable-series attributes and the cleaned series.
fn write_cleaned(file: &hdf5::File, r: &SubtractResult, meta: &SubtractMeta) -> hdf5::Result<()> {
    str_attr(file, "schema", SCHEMA_OBSERVABLE_SERIES)?;
    scalar_attr(file, "schema_version", SCHEMA_VERSION_OBSERVABLE_SERIES)?;
    scalar_attr(file, "sample_rate_hz", r.alignment.fs_hz)?;
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

/// `/predicted_tilt`: the tilt part of each observable, and the bands it was not predicted in.
fn write_predicted(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
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

/// `/estimates`: the fitted parameters, their errors and correlation, and the fit's figures.
fn write_estimates(file: &hdf5::File, f: &FitReport) -> hdf5::Result<()> {
    let g = file.create_group("estimates")?;
    let e = &f.estimates;
    strs_attr(&g, "estimator", [ESTIMATOR])?;
    strs_attr(&g, "name", e.iter().map(|x| x.name.as_str()))?;
    strs_attr(&g, "unit", e.iter().map(|x| x.unit.as_str()))?;
    strs_attr(&g, "status", e.iter().map(|x| x.status.name()))?;
    let nums = |get: fn(&tiltnoise_core::subtract::Estimate) -> f64| -> Vec<f64> {
        e.iter().map(|x| stored(get(x))).collect()
    };
    units_dataset(
        &g,
        "nominal",
        &nums(|x| x.nominal),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    units_dataset(
        &g,
        "value",
        &nums(|x| x.value),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    units_dataset(
        &g,
        "sigma",
        &nums(|x| x.sigma),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    units_dataset(
        &g,
        "scale",
        &nums(|x| x.scale),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    units_dataset(
        &g,
        "lower",
        &nums(|x| x.bounds.0),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    units_dataset(
        &g,
        "upper",
        &nums(|x| x.bounds.1),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    units_dataset(
        &g,
        "prior_sigma",
        &nums(|x| x.prior_sigma.unwrap_or(f64::NAN)),
        e.iter().map(|x| x.unit.as_str()),
    )?;
    scalar_attr(
        &g,
        "coherent_top_hz",
        stored(f.coherent_top_hz.unwrap_or(f64::NAN)),
    )?;
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

/// `/residuals/<observable>`: the held-out spectra and their band figures.
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
            ("witness_limited_asd", &s.witness_limited_psd),
        ] {
            unit_dataset(&h, name, &asd(psd), &unit)?;
        }
        for ((input, _), psd) in r.witness_noise_psd.iter().zip(&s.witness_limited_by_input) {
            unit_dataset(
                &h,
                &format!("witness_limited_{}_asd", input.name()),
                &asd(psd),
                &unit,
            )?;
        }
        scalar_attr(
            &h,
            "wiener_training_excess",
            stored(s.wiener_training_excess),
        )?;
        scalar_attr(&h, "readout_asd", stored(s.readout_asd.unwrap_or(f64::NAN)))?;
        let b = &s.band;
        unit_dataset(&h, "band_hz", &[b.band_hz.0, b.band_hz.1], "Hz")?;
        scalar_attr(&h, "band_bins", b.bins as u64)?;
        for (name, v) in [
            ("band_measured_asd", b.measured_asd),
            ("band_predicted_asd", b.predicted_asd),
            ("band_cleaned_asd", b.cleaned_asd),
            ("band_wiener_asd", b.wiener_asd),
            ("band_wiener_corrected_asd", b.wiener_corrected_asd),
            ("band_witness_limited_asd", b.witness_limited_asd),
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

/// `/bands/<observable>`: the cleaned record against the raw one, per band.
fn write_bands(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
    let g = file.create_group("bands")?;
    str_attr(
        &g,
        "description",
        "the cleaned record against the raw one over the whole overlap, per 1/3-decade band \
         (band means of Welch PSDs as ASDs); a band left raw had its prediction masked out",
    )?;
    let fs = r.alignment.fs_hz;
    for (o, check) in &r.bands {
        let h = g.create_group(o.name())?;
        let unit = format!("{}/sqrt(Hz)", o.unit());
        let b = &check.bands;
        let col = |get: fn(&tiltnoise_core::subtract::Band) -> f64| -> Vec<f64> {
            b.iter().map(get).collect()
        };
        unit_dataset(&h, "band_lo_hz", &col(|x| x.lo_hz), "Hz")?;
        unit_dataset(
            &h,
            "band_hi_hz",
            &b.iter().map(|x| x.hi_hz.min(fs / 2.0)).collect::<Vec<_>>(),
            "Hz",
        )?;
        unit_dataset(
            &h,
            "bins",
            &b.iter().map(|x| x.bins as u64).collect::<Vec<_>>(),
            "1",
        )?;
        for (name, get) in [
            (
                "raw_asd",
                (|x| x.raw_psd) as fn(&tiltnoise_core::subtract::Band) -> f64,
            ),
            ("expected_asd", |x| x.expected_psd),
            ("cleaned_asd", |x| x.cleaned_psd),
            ("witness_limited_asd", |x| x.witness_limited_psd),
        ] {
            unit_dataset(&h, name, &asd(&col(get)), &unit)?;
        }
        unit_dataset(&h, "ratio", &col(|x| x.ratio), "1")?;
        unit_dataset(&h, "sigma", &col(|x| x.sigma), "1")?;
        unit_dataset(&h, "limit", &col(|x| x.limit), "1")?;
        unit_dataset(
            &h,
            "left_raw",
            &b.iter().map(|x| u8::from(x.left_raw)).collect::<Vec<_>>(),
            "1",
        )?;
        scalar_attr(&h, "variance_ratio", check.variance_ratio)?;
        scalar_attr(&h, "left_raw", u8::from(check.left_raw))?;
    }
    Ok(())
}

/// `/witness_noise`: the witness noise as used, with how it was found.
fn write_witness_noise(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
    let g = file.create_group("witness_noise")?;
    str_attr(
        &g,
        "description",
        "the witness noise as used, after any fitted scale: one-sided ASD per input on the \
         Welch grid (0 where none was stated)",
    )?;
    if let Some(first) = r.residuals.first() {
        unit_dataset(&g, "frequency_hz", &first.freqs_hz, "Hz")?;
    }
    for (a, (input, psd)) in r.witness_noise_psd.iter().enumerate() {
        let ds = unit_dataset(
            &g,
            input.name(),
            &asd(psd),
            &format!("{}/sqrt(Hz)", input.unit()),
        )?;
        scalar_attr(&ds, "fitted_scale", r.fit.noise_factors[a].sqrt())?;
        let estimated = r.colocated.iter().find(|e| e.noise.input == *input);
        let (method, gains): (&str, Vec<f64>) = match estimated.map(|e| &e.method) {
            Some(Method::Huddle { relative_gain, .. }) => ("huddle", vec![*relative_gain]),
            Some(Method::ThreeCorneredHat { relative_gains }) => {
                ("three-cornered hat", relative_gains.to_vec())
            }
            None if psd.iter().any(|&v| v > 0.0) => ("given", Vec::new()),
            None => ("none", Vec::new()),
        };
        str_attr(&ds, "method", method)?;
        ds.new_attr_builder()
            .with_data(&ndarray::ArrayView1::from(&gains))
            .create("relative_gains")?;
    }
    Ok(())
}

/// `/alignment`: how the two records were aligned and split.
fn write_alignment(file: &hdf5::File, r: &SubtractResult) -> hdf5::Result<()> {
    let g = file.create_group("alignment")?;
    let a = &r.alignment;
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

/// `/provenance`: the inputs and the run's notes.
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
const ESTIMATOR: &str = "instrumental-variable least squares on Welch cross spectra: \
     r = s_wy - (S_ww - S_mm) G(theta), whitened by its covariance and pseudo-covariance, \
     instruments from the smoothed witness spectrum (docs/subtract.md)";
