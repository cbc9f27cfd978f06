//! A measured record of the observables, for comparison with a budget
//! (`tiltnoise budget --measured FILE`), in one of three layouts:
//!
//! * **Spectrum, CSV**: header `freq_hz` then any of `X`, `Y`, `Z`, `theta`, `eta`, `phi`,
//!   `phi_a`; values are one-sided ASDs (m/sqrt(Hz) for X, Y, Z; rad/sqrt(Hz) for the angles).
//!   Frequencies strictly increasing within
//!   [`SPECTRUM_FREQUENCIES`](tiltnoise_core::limits::SPECTRUM_FREQUENCIES); ASDs within
//!   [`ASDS`](tiltnoise_core::limits::ASDS) ([`read_measured`]).
//! * **Time series, HDF5** (`.h5`, `.hdf5`): the layout `tiltnoise simulate` writes, root
//!   attribute `schema = tiltnoise.observable_series` (optional), root attribute
//!   `sample_rate_hz`, one 1-D float dataset per observable named as above, optional `units`
//!   attribute that must then be the observable's unit (`m` or `rad`), optional root attribute
//!   `start_time` (ISO 8601, time of sample 0). Other root datasets and all groups are ignored.
//! * **Time series, CSV**: header `time_s` then observables, uniformly sampled, values in m or
//!   rad; optional `# start_time:` line before the header.
//!
//! [`read_measured_input`] reads any of them; the budget turns a series into one-sided ASDs
//! with its own Welch settings.

use super::address::input_format;
use super::csv::{decimal_resolution, parse_field, CsvFile, Prelude};
use super::format_error::FormatError;
use super::h5::{self, h5err, AttrValue};
use std::path::Path;
use tiltnoise_core::budget::{add_measured, series_psds, BudgetError, MeasuredPsds};
use tiltnoise_core::error::{Num, Shown};
use tiltnoise_core::input::require_two;
use tiltnoise_core::input::{
    check_sample_rate, frequency_refusal, ChannelCtx, InputError, InputFormat,
};
use tiltnoise_core::limits::{ASDS, SAMPLES};
use tiltnoise_core::model::Observable;
use tiltnoise_core::noise::BudgetReport;

/// Schema name of an HDF5 time series of the observables (root attribute `schema`, optional);
/// the same string as `crate::io::SCHEMA_OBSERVABLE_SERIES`.
pub const SCHEMA_OBSERVABLE_SERIES: &str = "tiltnoise.observable_series";

/// A uniformly sampled record of some observables (SI units: m, rad).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSeries {
    /// Sampling frequency (Hz).
    pub sample_rate_hz: f64,
    /// `(observable, samples)`, all of equal length >= 2.
    pub channels: Vec<(Observable, Vec<f64>)>,
    /// Time of the first sample (ISO 8601, validated), if the file states it.
    pub start_time: Option<String>,
}

/// A measured record: spectra or a time series.
#[derive(Debug, Clone, PartialEq)]
pub enum MeasuredInput {
    /// One-sided ASDs on the file's grid.
    Spectra(MeasuredSpectra),
    /// A time series (to be turned into ASDs by the caller).
    Series(MeasuredSeries),
}

/// Reads a measured record in any of the layouts of the module docs: HDF5 by extension is a
/// time series; CSV is a spectrum when the header starts with `freq_hz`, a series when it
/// starts with `time_s`.
pub fn read_measured_input(path: &Path) -> Result<MeasuredInput, InputError> {
    match input_format(path)? {
        InputFormat::Hdf5 => read_series_hdf5(path).map(MeasuredInput::Series),
        InputFormat::Miniseed => Err(InputError::UnknownLayout {
            path: path.to_path_buf(),
            format: "miniseed",
            found: "a miniSEED file, whose channels are named by SEED code, not by observable"
                .to_string(),
            accepted: "measured observables as HDF5 or CSV (X, Y, Z, theta, eta, phi, phi_a)",
        }),
        InputFormat::Csv => {
            let (file, prelude) = CsvFile::open(path)?;
            if prelude.header.first().map(String::as_str) == Some("time_s") {
                let start_time = super::csv::start_time(path, &prelude, &mut Vec::new())?;
                let mut series = read_series_csv(path, file, &prelude.header, prelude.header_line)?;
                series.start_time = start_time;
                Ok(MeasuredInput::Series(series))
            } else {
                read_spectra_csv(path, file, &prelude).map(MeasuredInput::Spectra)
            }
        }
    }
}

/// Adds the terms `measured` and `residual` from the measured record in `path` (any layout of
/// the module docs) to a budget: a spectrum is interpolated log-log onto the budget grid (NaN
/// where it does not reach); a time series is first turned into one-sided PSDs with the
/// budget's own Welch settings ([`series_psds`]).
///
/// # Errors
///
/// [`BudgetError::Input`] when the file cannot be read or is not valid; the error of
/// [`series_psds`] when a series does not fit the budget's Welch settings (the caller names
/// the file and the option that gave it).
pub fn add_measured_file(report: &mut BudgetReport, path: &Path) -> Result<(), BudgetError> {
    let (freqs_hz, psds, description, welch) = match read_measured_input(path)? {
        MeasuredInput::Spectra(m) => {
            let psds = m
                .asd
                .iter()
                .map(|(o, asd)| (*o, asd.iter().map(|a| a * a).collect()))
                .collect();
            (m.freqs_hz, psds, "measured spectrum".to_string(), None)
        }
        MeasuredInput::Series(series) => {
            let m = series_psds(&series.channels, series.sample_rate_hz, &report.source)?;
            (m.freqs_hz, m.psds, m.description, m.welch)
        }
    };
    let measured = MeasuredPsds {
        freqs_hz,
        psds,
        description,
        welch,
    };
    add_measured(report, &measured, &path.display().to_string());
    Ok(())
}

const OBSERVABLE_UNITS: &str =
    "the observable's SI unit: m for X, Y, Z; rad for theta, eta, phi, phi_a";

fn read_series_hdf5(path: &Path) -> Result<MeasuredSeries, InputError> {
    let file = h5::open(path)?;
    const SCHEMA_ALLOWED: &str = "`tiltnoise.observable_series` (a time series of the \
         observables, as written by `tiltnoise simulate`) or no schema attribute";
    match h5::str_attr(path, &file, "/", "schema", SCHEMA_ALLOWED)? {
        None => {}
        Some(s) if s == SCHEMA_OBSERVABLE_SERIES => {}
        Some(other) => {
            return Err(InputError::BadAttribute {
                path: path.to_path_buf(),
                object: "/".to_string(),
                attribute: "schema",
                value: format!("`{other}`"),
                allowed: SCHEMA_ALLOWED,
            })
        }
    }
    let sample_rate_hz = h5::sample_rate_hz(path, &file)?;
    let start_time = h5::str_attr(
        path,
        &file,
        "/",
        "start_time",
        super::start_time::ISO8601_ALLOWED,
    )?
    .map(|s| super::start_time::checked(path, "/".to_string(), "start_time", s, &mut Vec::new()))
    .transpose()?;
    let mut channels: Vec<(Observable, Vec<f64>)> = Vec::new();
    let names = h5::root_datasets(path, &file)?;
    let n_observables = names
        .iter()
        .filter(|n| Observable::from_name(n).is_some())
        .count();
    for name in names {
        let Some(o) = Observable::from_name(&name) else {
            continue;
        };
        let object = format!("dataset /{name}");
        let ds = file.dataset(&name).map_err(h5err(path, object.clone()))?;
        let (float, dtype) = h5::is_float(&ds).map_err(h5err(path, object.clone()))?;
        let shape = ds.shape();
        if shape.len() != 1 || !float {
            return Err(FormatError::BadDataset {
                path: path.to_path_buf(),
                dataset: format!("/{name}"),
                found: format!("type {dtype} and shape {shape:?}"),
                allowed: "a 1-D float64 (or float32) dataset, one sample per entry".to_string(),
            }
            .into());
        }
        h5::check_storage(path, &ds, &format!("/{name}"))?;
        match h5::unit_attr(path, &ds, &object)? {
            None => {}
            Some(AttrValue::Str(u)) if u.trim() == o.unit() => {}
            Some(other) => {
                return Err(InputError::Units {
                    path: path.to_path_buf(),
                    location: format!("unit attribute of {object}"),
                    value: other.describe(),
                    allowed: OBSERVABLE_UNITS,
                })
            }
        }
        h5::check_whole_read(
            path,
            &format!("/{name}"),
            shape[0],
            n_observables,
            "samples",
        )?;
        let data: Vec<f64> = ds.read_raw::<f64>().map_err(h5err(path, object.clone()))?;
        channels.push((o, data));
    }
    let mut series = finish_series(path, sample_rate_hz, channels, None)?;
    series.start_time = start_time;
    Ok(series)
}

/// Common checks: at least one channel, equal lengths >= 2, finite samples within
/// [`SAMPLES`](tiltnoise_core::limits::SAMPLES). `lines` maps a sample index to its CSV line.
fn finish_series(
    path: &Path,
    sample_rate_hz: f64,
    mut channels: Vec<(Observable, Vec<f64>)>,
    lines: Option<&[usize]>,
) -> Result<MeasuredSeries, InputError> {
    if channels.is_empty() {
        return Err(FormatError::MissingDataset {
            path: path.to_path_buf(),
            dataset: "X (or Y, Z, theta, eta, phi, phi_a)".to_string(),
            expected: "at least one observable series (1-D float dataset or CSV column named \
                       after the observable)"
                .to_string(),
        }
        .into());
    }
    channels.sort_by_key(|(o, _)| o.index());
    let (o0, n) = (channels[0].0, channels[0].1.len());
    for (o, data) in &channels {
        if data.len() != n {
            return Err(InputError::LengthMismatch {
                path: path.to_path_buf(),
                channel_a: o0.name().to_string(),
                len_a: n,
                channel_b: o.name().to_string(),
                len_b: data.len(),
            });
        }
        let ctx = ChannelCtx {
            path,
            channel: o.name(),
            unit: o.unit(),
        };
        if let Some((index, &value)) = data
            .iter()
            .enumerate()
            .find(|(_, v)| !v.is_finite() || !SAMPLES.admits(**v))
        {
            let line = lines.map(|l| l[index]);
            ctx.check_sample(index, value, line)?;
            return Err(ctx.non_finite(index, value, line));
        }
    }
    require_two(path, &format!("channel {}", o0.name()), n, "samples")?;
    Ok(MeasuredSeries {
        sample_rate_hz,
        channels,
        start_time: None,
    })
}

fn read_series_csv(
    path: &Path,
    mut file: CsvFile,
    header: &[String],
    header_line: usize,
) -> Result<MeasuredSeries, InputError> {
    let csv_err = |line: usize, message: String| {
        InputError::from(FormatError::Csv {
            path: path.to_path_buf(),
            line,
            message,
        })
    };
    let mut observables = Vec::new();
    for name in &header[1..] {
        let o = Observable::from_name(name).ok_or_else(|| {
            csv_err(
                header_line,
                format!(
                    "measured series: unknown column `{}`; allowed: X, Y, Z, theta, eta, \
                     phi, phi_a (in m or rad)",
                    Shown(name)
                ),
            )
        })?;
        observables.push(o);
    }
    let mut times: Vec<f64> = Vec::new();
    let mut resolution: Vec<f64> = Vec::new();
    let mut lines: Vec<usize> = Vec::new();
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); observables.len()];
    file.for_each_record(header.len(), |line, fields| {
        let number = |i: usize| match parse_field(fields[i]) {
            Ok(Some(v)) => Ok(v),
            _ => Err(csv_err(
                line,
                format!(
                    "column `{}` = `{}` is not a number",
                    Shown(&header[i]),
                    Shown(fields[i])
                ),
            )),
        };
        let t = number(0)?;
        if !t.is_finite() {
            return Err(csv_err(
                line,
                format!(
                    "time_s = `{}` is not allowed: must be finite (s)",
                    fields[0]
                ),
            ));
        }
        if let Some(&previous) = times.last() {
            if t <= previous {
                return Err(FormatError::TimeNotIncreasing {
                    path: path.to_path_buf(),
                    line,
                    index: times.len(),
                    value: t,
                    previous,
                }
                .into());
            }
        }
        times.push(t);
        resolution.push(decimal_resolution(fields[0]));
        lines.push(line);
        for (c, column) in data.iter_mut().enumerate() {
            // Non-finite values are reported with their sample index by finish_series.
            column.push(number(c + 1).unwrap_or(f64::NAN));
        }
        Ok(())
    })?;
    let n = times.len();
    require_two(path, "column time_s", n, "samples")?;
    let dt = (times[n - 1] - times[0]) / (n - 1) as f64;
    for (index, &t) in times.iter().enumerate() {
        let expected = times[0] + index as f64 * dt;
        // The printed precision of the two times involved, plus rounding of the grid itself.
        let tolerance = resolution[index].max(resolution[0]) + 4.0 * f64::EPSILON * t.abs();
        if (t - expected).abs() > tolerance {
            return Err(FormatError::TimeNotUniform {
                path: path.to_path_buf(),
                line: lines[index],
                index,
                value: t,
                expected,
                deviation: (t - expected).abs(),
                tolerance,
                relative: tolerance / dt,
                dt,
            }
            .into());
        }
    }
    let rate = check_sample_rate(
        path,
        || format!("column time_s (dt = {} s)", Num(dt)),
        1.0 / dt,
    )?;
    finish_series(
        path,
        rate,
        observables.into_iter().zip(data).collect(),
        Some(&lines),
    )
}

/// Measured ASDs per observable on the file's own frequency grid.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasuredSpectra {
    /// Frequencies (Hz), strictly increasing, > 0.
    pub freqs_hz: Vec<f64>,
    /// `(observable, ASD per frequency)`.
    pub asd: Vec<(Observable, Vec<f64>)>,
}

/// Reads a measured-spectrum CSV (see the module docs).
pub fn read_measured(path: &Path) -> Result<MeasuredSpectra, InputError> {
    let (file, prelude) = CsvFile::open(path)?;
    read_spectra_csv(path, file, &prelude)
}

fn read_spectra_csv(
    path: &Path,
    mut file: CsvFile,
    prelude: &Prelude,
) -> Result<MeasuredSpectra, InputError> {
    let csv_err = |line: usize, message: String| {
        InputError::from(FormatError::Csv {
            path: path.to_path_buf(),
            line,
            message,
        })
    };
    if !super::csv::is_frequency_column(prelude.header.first()) {
        return Err(csv_err(
            prelude.header_line,
            "measured spectrum: the header must start with frequency_hz (or freq_hz), then observables \
             (X, Y, Z, theta, eta, phi, phi_a)"
                .into(),
        ));
    }
    let mut observables = Vec::new();
    for name in &prelude.header[1..] {
        let o = Observable::from_name(name).ok_or_else(|| {
            csv_err(
                prelude.header_line,
                format!(
                    "measured spectrum: unknown column `{}`; allowed: X, Y, Z, theta, \
                         eta, phi, phi_a",
                    Shown(name)
                ),
            )
        })?;
        observables.push(o);
    }
    let mut freqs: Vec<f64> = Vec::new();
    let mut asd: Vec<Vec<f64>> = vec![Vec::new(); observables.len()];
    file.for_each_record(prelude.header.len(), |line, fields| {
        let number = |i: usize| match parse_field(fields[i]) {
            Ok(Some(v)) => Ok(v),
            _ => Err(csv_err(
                line,
                format!(
                    "column `{}` = `{}` is not a number",
                    Shown(&prelude.header[i]),
                    Shown(fields[i])
                ),
            )),
        };
        let f = number(0)?;
        if let Some(allowed) = frequency_refusal(f, freqs.last().copied()) {
            return Err(InputError::Frequency {
                path: path.to_path_buf(),
                location: format!("line {line}, column {}", prelude.header[0]),
                value: f,
                allowed,
            });
        }
        freqs.push(f);
        for (c, (o, column)) in observables.iter().zip(asd.iter_mut()).enumerate() {
            let v = number(c + 1)?;
            if !ASDS.admits(v) {
                return Err(InputError::Asd {
                    path: path.to_path_buf(),
                    location: format!("line {line}"),
                    column: o.name().to_string(),
                    value: v,
                    unit: if o.unit() == "m" {
                        "m/sqrt(Hz)"
                    } else {
                        "rad/sqrt(Hz)"
                    },
                    power: false,
                });
            }
            column.push(v);
        }
        Ok(())
    })?;
    if freqs.len() < 2 {
        return Err(csv_err(
            prelude.header_line,
            "measured spectrum: need at least 2 rows".into(),
        ));
    }
    Ok(MeasuredSpectra {
        freqs_hz: freqs,
        asd: observables.into_iter().zip(asd).collect(),
    })
}
