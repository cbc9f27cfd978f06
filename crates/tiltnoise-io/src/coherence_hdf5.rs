//! Coherence and measured transfer functions as HDF5 (schema `tiltnoise.coherence`, documented
//! in `docs/schemas.md` and `docs/coherence.md`).

use super::h5util::{dataset, provenance, scalar_attr, str_attr, strs_attr};
use crate::atomic::Staging;
use crate::budget_hdf5::SPECTRAL_CONVENTION;
use crate::run_meta::RunMeta;
use crate::tf_hdf5::{SIGN_CONVENTION, TIME_DEPENDENCE};
use num_complex::Complex64;
use std::path::Path;
use tiltnoise_core::align::TimeBasis;
use tiltnoise_core::coherence::CoherenceReport;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::input::InputMeta;

/// Value of the root attribute `schema`.
pub const SCHEMA_COHERENCE: &str = "tiltnoise.coherence";

/// Value of the root attribute `schema_version`. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_COHERENCE: i64 = 2;

/// Where the two records of a coherence run came from.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CoherenceInputs {
    /// The tilt record (`--tilt`).
    pub tilt: InputMeta,
    /// The measured record's file (`--measured`).
    pub measured_path: String,
    /// Its start time (ISO 8601), if it states one.
    pub measured_start_time: Option<String>,
}

/// Writes a coherence report with the run's provenance as an HDF5 file of schema
/// [`SCHEMA_COHERENCE`], as one of the outputs of `stage` (see [`Staging::write`]).
///
/// Layout: root attributes (schema, provenance, conventions, Welch settings, confidence level
/// and thresholds, how the records were aligned, notes); `/frequency_hz`, `/estimable`,
/// `/input_rcond`; `/tilt/<axis>/psd`; `/observables/<obs>/` with `psd`, `residual_psd`,
/// `multiple_coherence[_lower|_upper]` and one group per tilt axis holding
/// `coherence[_lower|_upper]`, `tf`, `tf_radius`, `tf_sigma`, `model_tf`, `model_resolved` and the
/// measured/model factor as attributes. Every item is described in `docs/schemas.md`.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` on any I/O or HDF5 failure; nothing is left at `path`.
pub fn write_coherence_hdf5(
    stage: &Staging,
    path: &Path,
    report: &CoherenceReport,
    meta: &RunMeta,
    inputs: &CoherenceInputs,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        write_file(temp, report, meta, inputs)
            .map_err(|e| format!("HDF5: {}", crate::messages::first_line(&e.to_string())))
    })
}

fn unit_dataset<T: hdf5::H5Type>(
    group: &hdf5::Group,
    name: &str,
    data: &[T],
    units: &str,
) -> hdf5::Result<()> {
    let ds = dataset(group, name, data)?;
    str_attr(&ds, "unit", units)
}

fn write_file(
    path: &Path,
    report: &CoherenceReport,
    meta: &RunMeta,
    inputs: &CoherenceInputs,
) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;
    provenance(&file, SCHEMA_COHERENCE, SCHEMA_VERSION_COHERENCE, meta)?;
    str_attr(&file, "parameters_toml", &meta.params_toml)?;
    str_attr(&file, "sign_convention", SIGN_CONVENTION)?;
    str_attr(&file, "time_dependence", TIME_DEPENDENCE)?;
    str_attr(&file, "spectral_convention", SPECTRAL_CONVENTION)?;
    str_attr(
        &file,
        "estimator",
        "H = S_xx^-1 s_xy (multiple-input H1), S_ij = <conj(X_i) X_j> as scipy.signal.csd",
    )?;
    str_attr(&file, "model_method", &report.model_method)?;

    let tilt = &inputs.tilt;
    str_attr(&file, "tilt_path", &tilt.path)?;
    str_attr(&file, "tilt_format", &tilt.format)?;
    str_attr(&file, "tilt_quantity", &tilt.quantity)?;
    str_attr(&file, "tilt_axis_map", &tilt.axis_map)?;
    if let Some(t) = &tilt.start_time {
        str_attr(&file, "tilt_start_time", t)?;
    }
    str_attr(&file, "measured_path", &inputs.measured_path)?;
    if let Some(t) = &inputs.measured_start_time {
        str_attr(&file, "measured_start_time", t)?;
    }
    let al = &report.alignment;
    str_attr(
        &file,
        "alignment",
        match al.basis {
            TimeBasis::StartTimes => "start_times",
            TimeBasis::AssumedSimultaneous => "assumed_simultaneous",
        },
    )?;
    scalar_attr(&file, "tilt_first_sample", al.start_a as u64)?;
    scalar_attr(&file, "measured_first_sample", al.start_b as u64)?;
    scalar_attr(&file, "start_offset_s", al.start_offset_s)?;
    scalar_attr(&file, "residual_offset_s", al.residual_offset_s)?;

    let w = &report.welch;
    scalar_attr(&file, "sample_rate_hz", w.sample_rate_hz)?;
    scalar_attr(&file, "n_samples", w.n_samples as u64)?;
    scalar_attr(&file, "welch_segment_len", w.segment_len as u64)?;
    scalar_attr(&file, "welch_overlap", w.overlap as u64)?;
    scalar_attr(&file, "welch_segments", w.n_segments as u64)?;
    scalar_attr(&file, "welch_equivalent_averages", w.n_equivalent)?;
    str_attr(
        &file,
        "welch_window",
        "hann (periodic), constant detrend, mean",
    )?;
    scalar_attr(&file, "confidence", report.confidence)?;
    scalar_attr(&file, "coherence_threshold", report.coherence_threshold)?;
    scalar_attr(
        &file,
        "multiple_coherence_threshold",
        report.multiple_coherence_threshold,
    )?;
    if let Some((lo, hi)) = report.fit_band_hz {
        let band = dataset(&file, "fit_band_hz", &[lo, hi])?;
        str_attr(&band, "unit", "Hz")?;
    }
    let notes: Vec<&str> = tilt
        .notes
        .iter()
        .chain(&report.notes)
        .map(String::as_str)
        .collect();
    strs_attr(&file, "notes", &notes)?;

    unit_dataset(&file, "frequency_hz", &report.freqs_hz, "Hz")?;
    let estimable: Vec<u8> = report.estimable.iter().map(|&e| u8::from(e)).collect();
    unit_dataset(&file, "estimable", &estimable, "1")?;
    unit_dataset(&file, "input_rcond", &report.input_rcond, "1")?;

    let tilt_group = file.create_group("tilt")?;
    for (axis, psd) in report.axes.iter().zip(&report.tilt_psd) {
        let g = tilt_group.create_group(axis.name())?;
        str_attr(&g, "unit", "rad")?;
        unit_dataset(&g, "psd", psd, "rad^2/Hz")?;
    }
    let observables = file.create_group("observables")?;
    for ob in &report.observables {
        let unit = ob.observable.unit();
        let g = observables.create_group(ob.observable.name())?;
        str_attr(&g, "unit", unit)?;
        unit_dataset(&g, "psd", &ob.psd, &format!("{unit}^2/Hz"))?;
        unit_dataset(
            &g,
            "residual_psd",
            &ob.residual_psd,
            &format!("{unit}^2/Hz"),
        )?;
        unit_dataset(&g, "multiple_coherence", &ob.multiple_coherence, "1")?;
        unit_dataset(
            &g,
            "multiple_coherence_lower",
            &ob.multiple_coherence_lower,
            "1",
        )?;
        unit_dataset(
            &g,
            "multiple_coherence_upper",
            &ob.multiple_coherence_upper,
            "1",
        )?;
        let tf_unit = format!("{unit}/rad");
        for a in &ob.axes {
            let ga = g.create_group(a.axis.name())?;
            unit_dataset(&ga, "coherence", &a.coherence, "1")?;
            unit_dataset(&ga, "coherence_lower", &a.coherence_lower, "1")?;
            unit_dataset(&ga, "coherence_upper", &a.coherence_upper, "1")?;
            unit_dataset::<Complex64>(&ga, "tf", &a.tf, &tf_unit)?;
            unit_dataset(&ga, "tf_radius", &a.tf_radius, &tf_unit)?;
            unit_dataset(&ga, "tf_sigma", &a.tf_sigma, &tf_unit)?;
            unit_dataset::<Complex64>(&ga, "model_tf", &a.model, &tf_unit)?;
            let resolved: Vec<u8> = a.model_resolved.iter().map(|&r| u8::from(r)).collect();
            unit_dataset(&ga, "model_resolved", &resolved, "1")?;
            if let Some(ag) = &a.agreement {
                scalar_attr(&ga, "agreement_factor_re", ag.factor.re)?;
                scalar_attr(&ga, "agreement_factor_im", ag.factor.im)?;
                scalar_attr(&ga, "agreement_sigma", ag.sigma)?;
                scalar_attr(&ga, "agreement_gain", ag.gain())?;
                scalar_attr(&ga, "agreement_phase_deg", ag.phase_deg())?;
                scalar_attr(&ga, "agreement_phase_sigma_deg", ag.phase_sigma_deg())?;
                scalar_attr(&ga, "agreement_chi2_per_dof", ag.chi2_per_dof)?;
                scalar_attr(&ga, "agreement_n_bins", ag.n_bins as u64)?;
                scalar_attr(&ga, "agreement_band_lo_hz", ag.band_hz.0)?;
                scalar_attr(&ga, "agreement_band_hi_hz", ag.band_hz.1)?;
            }
        }
    }
    file.close()
}
