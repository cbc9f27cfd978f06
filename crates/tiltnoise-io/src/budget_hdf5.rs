//! Noise budget as HDF5 (schema `tiltnoise.budget`, documented in `docs/schemas.md`).

use super::h5util::{dataset, provenance, scalar_attr, str_attr, strs_attr};
use crate::atomic::Staging;
use crate::run_meta::RunMeta;
use crate::tf_hdf5::SIGN_CONVENTION;
use std::path::Path;
use tiltnoise_core::error::OutputError;
use tiltnoise_core::input::InputMeta;
use tiltnoise_core::noise::equivalent::referred_terms;
use tiltnoise_core::noise::{
    BudgetReport, Component, Evaluation, SpectralSource, SummaryAt, TermKind, TOTAL_NAME,
};

/// Value of the root attribute `schema`.
pub const SCHEMA_BUDGET: &str = "tiltnoise.budget";

/// Value of the root attribute `schema_version`. Bumped on any change that can break a reader.
pub const SCHEMA_VERSION_BUDGET: i64 = 2;

/// Value of the root attribute `spectral_convention`.
pub const SPECTRAL_CONVENTION: &str =
    "one-sided; PSD in unit^2/Hz, ASD = sqrt(PSD) in unit/sqrt(Hz)";

/// Writes a budget report with the run's provenance `meta` and the tilt input's provenance
/// `input` as an HDF5 file of schema [`SCHEMA_BUDGET`], atomically (see
/// [`Staging::write`]).
///
/// Layout: root attributes (schema, provenance, conventions, how the tilt spectra were
/// obtained); `/frequency_hz`; one group per observable (`/X`, `/phi`, `/phi_a`) holding one
/// group per term (`/X/tilt`, `/X/tilt.eta_t`, `/X/readout`, `/X/total`, ...; `/X/translation`,
/// `/X/translation.x_t` and `/X/ground` for a record of the floor's translation) with datasets
/// `psd` and `asd`; `/segments` with the percentile band of the term of the floor's motion
/// that adds to the total (`tilt`, `translation` or `ground`) when the report has one; `/summary` with the budget read at chosen frequencies. A damped budget adds `thermal`, `thermal.<element>` term groups and, per observable,
/// an `equivalent` group with every term referred to the test mass's acceleration (X) or
/// torque (phi, phi_a). Every item is described in `docs/schemas.md`.
///
/// # Errors
///
/// [`OutputError::Write`] naming `path` if the report is inconsistent (a spectrum whose length
/// differs from the frequency grid) or on any I/O or HDF5 failure; nothing is left at `path`.
pub fn write_budget_hdf5(
    stage: &Staging,
    path: &Path,
    report: &BudgetReport,
    meta: &RunMeta,
    input: &InputMeta,
) -> Result<(), OutputError> {
    stage.write(path, |temp| {
        report.check()?;
        write_file(temp, report, meta, input)
            .map_err(|e| format!("HDF5: {}", crate::messages::first_line(&e.to_string())))
    })
}

/// The names of the report's floor inputs: its translations, or its tilt axes.
fn input_names(report: &BudgetReport, translation: bool) -> Vec<&'static str> {
    report
        .inputs
        .iter()
        .filter(|i| matches!(i, tiltnoise_core::model::Input::Translation(_)) == translation)
        .map(|i| i.name())
        .collect()
}

fn write_file(
    path: &Path,
    report: &BudgetReport,
    meta: &RunMeta,
    input: &InputMeta,
) -> hdf5::Result<()> {
    let file = hdf5::File::create(path)?;

    provenance(&file, SCHEMA_BUDGET, SCHEMA_VERSION_BUDGET, meta)?;
    str_attr(&file, "parameters_toml", &meta.params_toml)?;
    str_attr(&file, "sign_convention", SIGN_CONVENTION)?;
    str_attr(&file, "spectral_convention", SPECTRAL_CONVENTION)?;

    str_attr(&file, "input_path", &input.path)?;
    str_attr(&file, "input_format", &input.format)?;
    str_attr(&file, "input_kind", &input.kind)?;
    str_attr(&file, "input_quantity", &input.quantity)?;
    str_attr(&file, "input_axis_map", &input.axis_map)?;
    if let Some(t) = &input.start_time {
        str_attr(&file, "input_start_time", t)?;
    }
    let notes: Vec<&str> = input
        .notes
        .iter()
        .chain(&report.notes)
        .map(String::as_str)
        .collect();
    strs_attr(&file, "notes", &notes)?;

    match &report.source {
        SpectralSource::Welch {
            sample_rate_hz,
            segment_len,
            overlap,
            averaging,
            n_welch_segments,
            n_samples,
        } => {
            str_attr(&file, "source", "welch")?;
            scalar_attr(&file, "sample_rate_hz", *sample_rate_hz)?;
            scalar_attr(&file, "welch_segment_len", int(*segment_len)?)?;
            scalar_attr(&file, "welch_overlap", int(*overlap)?)?;
            str_attr(&file, "welch_averaging", averaging)?;
            scalar_attr(&file, "welch_n_segments", int(*n_welch_segments)?)?;
            scalar_attr(&file, "n_samples", int(*n_samples)?)?;
        }
        SpectralSource::Spectra { data_band_hz } => {
            str_attr(&file, "source", "spectra")?;
            let band = [data_band_hz.0, data_band_hz.1];
            file.new_attr_builder()
                .with_data(band.as_slice())
                .create("data_band_hz")?;
        }
    }
    strs_attr(&file, "tilt_axes", input_names(report, false))?;
    strs_attr(&file, "translation_axes", input_names(report, true))?;
    let observables: Vec<&str> = report
        .budget
        .observables
        .iter()
        .map(|b| b.observable.name())
        .collect();
    strs_attr(&file, "observables", &observables)?;

    let grid = even_grid(&report.budget.freqs_hz);
    let freq = dataset(&file, "frequency_hz", &report.budget.freqs_hz)?;
    str_attr(&freq, "unit", "Hz")?;

    for ob in &report.budget.observables {
        let o = ob.observable;
        let unit = o.unit();
        let group = file.create_group(o.name())?;
        str_attr(&group, "unit", unit)?;
        let components = ob.components();
        let names: Vec<String> = components.iter().map(|(c, _)| c.name()).collect();
        let terms: Vec<&str> = names.iter().map(String::as_str).collect();
        strs_attr(&group, "terms", &terms)?;
        if let Some(asd) = report.readout.of(o) {
            scalar_attr(&group, "readout_asd", asd)?;
            str_attr(&group, "readout_asd_unit", &asd_unit(unit))?;
        }
        if let Some(given) = report.readout.given_of(o) {
            str_attr(&group, "readout_given", given.origin())?;
        }
        for (component, psd) in &components {
            let g = group.create_group(&component.name())?;
            write_psd_asd(&g, "psd", "asd", psd, unit, grid)?;
            let Component::Term(kind) = component else {
                str_attr(&g, "group", TOTAL_NAME)?;
                continue;
            };
            str_attr(&g, "group", kind.group().name())?;
            if let TermKind::UserNamed(name) = kind {
                if let Some(t) = report.user_terms.iter().find(|t| &t.name == name) {
                    str_attr(&g, "source", t.source.name())?;
                    str_attr(&g, "source_asd_unit", &t.source.asd_unit())?;
                    str_attr(&g, "given", t.asd.origin())?;
                }
            }
        }
        if let Some(referred) = referred_terms(ob) {
            write_equivalent(&group, &referred, unit, grid)?;
        }
    }

    if !report.segment_bands.is_empty() {
        let segments = file.create_group("segments")?;
        let first = &report.segment_bands[0].1;
        if let Some(d) = report.segment_duration_s {
            scalar_attr(&segments, "segment_duration_s", d)?;
        }
        scalar_attr(&segments, "n_segments", int(first.n_segments)?)?;
        scalar_attr(&segments, "lower_pct", first.lower_pct)?;
        scalar_attr(&segments, "upper_pct", first.upper_pct)?;
        let term = first.term.name();
        str_attr(&segments, "term", &term)?;
        for (o, band) in &report.segment_bands {
            let unit = o.unit();
            let g = segments.create_group(o.name())?;
            str_attr(&g, "unit", unit)?;
            scalar_attr(&g, "n_segments", int(band.n_segments)?)?;
            scalar_attr(&g, "lower_pct", band.lower_pct)?;
            scalar_attr(&g, "upper_pct", band.upper_pct)?;
            for (suffix, psd) in [
                ("median", &band.median),
                ("lower", &band.lower),
                ("upper", &band.upper),
            ] {
                write_psd_asd(
                    &g,
                    &format!("{term}_psd_{suffix}"),
                    &format!("{term}_asd_{suffix}"),
                    psd,
                    unit,
                    grid,
                )?;
            }
        }
    }

    if !report.summary.is_empty() {
        write_summary(&file, &report.summary)?;
    }

    file.close()
}

/// `/summary`: one group per frequency (`/summary/0`, `/summary/1`, ... in request order), one
/// group per observable in it and one per term (and `total`), with scalar attributes: `psd`,
/// `asd`, `evaluation` (`exact` or `band_mean`); a band mean adds `n_bins`, `first_bin_hz`,
/// `last_bin_hz` and, when known, `dof` and `asd_rel_std` (`psd_std / (2 psd)`).
fn write_summary(file: &hdf5::File, summary: &[SummaryAt]) -> hdf5::Result<()> {
    let root = file.create_group("summary")?;
    let freqs: Vec<f64> = summary.iter().map(|a| a.freq_hz).collect();
    root.new_attr_builder()
        .with_data(freqs.as_slice())
        .create("frequency_hz")?;
    let rel = |psd: f64, std: f64| if psd > 0.0 { std / (2.0 * psd) } else { 0.0 };
    for (i, at) in summary.iter().enumerate() {
        let g = root.create_group(&i.to_string())?;
        scalar_attr(&g, "frequency_hz", at.freq_hz)?;
        scalar_attr(&g, "band_lo_hz", at.band_hz.0)?;
        scalar_attr(&g, "band_hi_hz", at.band_hz.1)?;
        for ob in &at.observables {
            let og = g.create_group(ob.observable.name())?;
            str_attr(&og, "asd_unit", &asd_unit(ob.observable.unit()))?;
            let mut names: Vec<String> = ob.terms.iter().map(|t| t.kind.name()).collect();
            names.push(tiltnoise_core::noise::TOTAL_NAME.to_string());
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            strs_attr(&og, "terms", &names)?;
            for t in &ob.terms {
                let tg = og.create_group(&t.kind.name())?;
                scalar_attr(&tg, "psd", t.psd)?;
                scalar_attr(&tg, "asd", t.psd.sqrt())?;
                str_attr(&tg, "evaluation", t.evaluation.name())?;
                if let Evaluation::BandMean(b) = &t.evaluation {
                    scalar_attr(&tg, "n_bins", int(b.n_bins)?)?;
                    scalar_attr(&tg, "first_bin_hz", b.first_bin_hz)?;
                    scalar_attr(&tg, "last_bin_hz", b.last_bin_hz)?;
                    if let (Some(dof), Some(std)) = (b.dof, t.psd_std()) {
                        scalar_attr(&tg, "dof", dof)?;
                        scalar_attr(&tg, "asd_rel_std", rel(t.psd, std))?;
                    }
                }
            }
            let total = og.create_group(tiltnoise_core::noise::TOTAL_NAME)?;
            let psd = ob.total_psd();
            scalar_attr(&total, "psd", psd)?;
            scalar_attr(&total, "asd", psd.sqrt())?;
            if let Some(std) = ob.total_psd_std() {
                scalar_attr(&total, "asd_rel_std", rel(psd, std))?;
            }
        }
    }
    Ok(())
}

/// `/<obs>/equivalent`: every noise term referred to the equivalent input (see
/// [`tiltnoise_core::noise::equivalent`]), `psd = S_o / |R_o|^2`, plus `response_abs = |R_o|`.
fn write_equivalent(
    group: &hdf5::Group,
    referred: &tiltnoise_core::noise::equivalent::Referred<'_>,
    unit: &str,
    grid: Option<(f64, f64)>,
) -> hdf5::Result<()> {
    let g = group.create_group("equivalent")?;
    str_attr(&g, "input", referred.input)?;
    str_attr(&g, "quantity", referred.quantity)?;
    str_attr(&g, "unit", referred.unit)?;
    let names: Vec<String> = referred.terms.iter().map(|(c, _)| c.name()).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    strs_attr(&g, "terms", &names)?;
    let abs: Vec<f64> = referred.response_psd.iter().map(|p| p.sqrt()).collect();
    let d = dataset(&g, "response_abs", &abs)?;
    str_attr(&d, "unit", &format!("{unit}/({})", referred.unit))?;
    for (component, psd) in &referred.terms {
        let t = g.create_group(&component.name())?;
        write_psd_asd(&t, "psd", "asd", psd, referred.unit, grid)?;
    }
    Ok(())
}

/// `m` -> `m/sqrt(Hz)`.
fn asd_unit(unit: &str) -> String {
    format!("{unit}/sqrt(Hz)")
}

/// Datasets `psd_name` (unit^2/Hz) and `asd_name` (sqrt of it, unit/sqrt(Hz)) in `group`,
/// each with a `unit` attribute and, on an evenly spaced grid, `f0` and `df` (Hz): exactly
/// the attributes gwpy's `FrequencySeries.read(file, path=...)` takes as keywords.
fn write_psd_asd(
    group: &hdf5::Group,
    psd_name: &str,
    asd_name: &str,
    psd: &[f64],
    unit: &str,
    grid: Option<(f64, f64)>,
) -> hdf5::Result<()> {
    let asd: Vec<f64> = psd.iter().map(|p| p.sqrt()).collect();
    for (name, values, unit) in [
        (psd_name, psd, format!("{}/Hz", squared(unit))),
        (asd_name, asd.as_slice(), asd_unit(unit)),
    ] {
        let d = dataset(group, name, values)?;
        str_attr(&d, "unit", &unit)?;
        if let Some((f0, df)) = grid {
            scalar_attr(&d, "f0", f0)?;
            scalar_attr(&d, "df", df)?;
        }
    }
    Ok(())
}

/// The square of a unit written as space-separated factors `base` or `base^exp`:
/// `m` -> `m^2`, `m s^-2` -> `m^2 s^-4`, `N m` -> `N^2 m^2` (the form astropy parses; `m s^-2^2`
/// would not be a unit).
fn squared(unit: &str) -> String {
    unit.split_whitespace()
        .map(|factor| match factor.split_once('^') {
            Some((base, exp)) => match exp.parse::<i32>() {
                Ok(e) => format!("{base}^{}", 2 * e),
                Err(_) => format!("({factor})^2"),
            },
            None => format!("{factor}^2"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// `(f0, df)` if `freqs_hz[k] = f0 + k df` for every `k` to within 4 ulp (a Welch grid), else
/// `None` (spectra given at arbitrary frequencies).
pub(crate) fn even_grid(freqs_hz: &[f64]) -> Option<(f64, f64)> {
    let (&f0, &f1) = (freqs_hz.first()?, freqs_hz.get(1)?);
    let df = f1 - f0;
    let even = df > 0.0
        && freqs_hz.iter().enumerate().all(|(k, &f)| {
            let expected = f0 + k as f64 * df;
            (f - expected).abs() <= 4.0 * f64::EPSILON * f.abs()
        });
    even.then_some((f0, df))
}

fn int(n: usize) -> hdf5::Result<i64> {
    i64::try_from(n).map_err(|e| e.to_string().into())
}

#[cfg(test)]
mod tests {
    use super::squared;

    #[test]
    fn units_are_squared_factor_by_factor() {
        assert_eq!(squared("m"), "m^2");
        assert_eq!(squared("rad"), "rad^2");
        assert_eq!(squared("m s^-2"), "m^2 s^-4");
        assert_eq!(squared("N m"), "N^2 m^2");
    }
}
