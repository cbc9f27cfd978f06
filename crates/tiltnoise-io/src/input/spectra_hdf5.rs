//! Tilt spectra from HDF5 (schema `tiltnoise.tilt_spectra`): `/frequency_hz` and either `/asd`
//! `[n, n_axes]` or `/csd` `[n, n_axes, n_axes]` (complex), root attribute `axes`.

use super::format_error::FormatError;
use super::h5::{self, h5err, AttrValue};
use super::meta::{
    asd_unit, csd_unit, decide_quantity, Declared, SpectrumUnit, ASD_UNITS, CSD_UNITS,
};
use crate::input::spectra_checks::{no_scale_for_spectra, refuse_translation_spectra};
use num_complex::Complex64;
use std::path::Path;
use tiltnoise_core::input::{assemble, check_csd_finite, TiltSpectra, CSD_RTOL};
use tiltnoise_core::input::{frequency_refusal, require_two, InputError};
use tiltnoise_core::input::{
    InputFormat, InputKind, Provenance, Quantity, ReadOptions, ACCEPTED_LAYOUTS,
};
use tiltnoise_core::limits::{ASDS, PSDS};

const AXES_ALLOWED: &str = "a 1-D array of strings naming the axes of the last dimension(s) of \
     /asd or /csd, e.g. [\"theta_t\", \"eta_t\"]";

pub(crate) fn read(
    path: &Path,
    file: &hdf5::File,
    opts: &ReadOptions,
) -> Result<TiltSpectra, InputError> {
    no_scale_for_spectra(path, opts)?;
    let mut notes = Vec::new();
    let start_time = h5::start_and_description(path, file, &mut notes)?;
    let datasets = h5::root_datasets(path, file)?;
    let has = |n: &str| datasets.iter().any(|d| d == n);

    if !has("frequency_hz") {
        return Err(FormatError::MissingDataset {
            path: path.to_path_buf(),
            dataset: "/frequency_hz".to_string(),
            expected: "a 1-D float64 dataset of frequencies in Hz, > 0, strictly increasing"
                .to_string(),
        }
        .into());
    }
    let freqs = frequencies(path, file)?;
    match (has("asd"), has("csd")) {
        (true, true) => {
            return Err(InputError::UnknownLayout {
                path: path.to_path_buf(),
                format: "hdf5",
                found: "both /asd and /csd".to_string(),
                accepted: ACCEPTED_LAYOUTS,
            })
        }
        (false, false) => {
            return Err(FormatError::MissingDataset {
                path: path.to_path_buf(),
                dataset: "/asd or /csd".to_string(),
                expected: "/asd float64 [n_freq, n_axes] (rad/sqrt(Hz)) or /csd complex128 \
                           [n_freq, n_axes, n_axes] (rad^2/Hz)"
                    .to_string(),
            }
            .into())
        }
        _ => {}
    }

    let names = axis_names(path, file)?;
    let m = names.len();

    // Spectral values: src[(k * m + a) * m + b], source axis order.
    let (src, declared): (Vec<Complex64>, Option<Declared>) = if has("asd") {
        read_asd(path, file, &freqs, &names)?
    } else {
        read_csd(path, file, &freqs, &names)?
    };

    let file_map = h5::axis_map(path, file)?;
    let resolved = h5::resolve_axes(
        path,
        &names,
        &vec![None; names.len()],
        "axis name",
        opts,
        file_map.as_ref(),
        &mut notes,
    )?;
    refuse_translation_spectra(path, &resolved)?;
    let mapped: Vec<String> = resolved.channels.iter().map(|c| c.source.clone()).collect();
    let (declared, undeclared) = match declared {
        Some(d) => (
            mapped
                .iter()
                .map(|c| Declared {
                    channel: c.clone(),
                    ..d.clone()
                })
                .collect(),
            Vec::new(),
        ),
        None => (Vec::new(), mapped),
    };
    let quantity = decide_quantity(path, opts.quantity, &declared, &undeclared, &mut notes)?;
    let csd = assemble(&freqs, &resolved.channels, quantity, |k, a, b| {
        src[(k * m + a) * m + b]
    });
    let axes: Vec<_> = resolved
        .channels
        .iter()
        .filter_map(|c| c.tilt_axis())
        .collect();
    check_csd_finite(path, &freqs, &axes, &csd)?;
    Ok(TiltSpectra {
        freqs_hz: freqs,
        axes,
        csd,
        provenance: Provenance {
            path: path.to_path_buf(),
            format: InputFormat::Hdf5,
            kind: InputKind::Spectra,
            quantity,
            axis_map: resolved.map.to_string(),
            start_time,
            notes,
        },
    })
}

/// `/frequency_hz`: 1-D float, each frequency allowed, strictly increasing, at least two.
fn frequencies(path: &Path, file: &hdf5::File) -> Result<Vec<f64>, InputError> {
    let fds = file
        .dataset("frequency_hz")
        .map_err(h5err(path, "dataset /frequency_hz"))?;
    let (float, dtype) = h5::is_float(&fds).map_err(h5err(path, "dataset /frequency_hz"))?;
    if fds.ndim() != 1 || !float {
        return Err(FormatError::BadDataset {
            path: path.to_path_buf(),
            dataset: "/frequency_hz".to_string(),
            found: format!("type {dtype} and shape {:?}", fds.shape()),
            allowed: "a 1-D float64 dataset (Hz)".to_string(),
        }
        .into());
    }
    h5::check_storage(path, &fds, "/frequency_hz")?;
    // The values: one CSD matrix of up to 3 x 3 complex (2 x 9 `f64`) per frequency.
    h5::check_whole_read(path, "/frequency_hz", fds.size(), 19, "frequencies")?;
    let freqs: Vec<f64> = fds
        .read_raw::<f64>()
        .map_err(h5err(path, "dataset /frequency_hz"))?;
    for (k, &f) in freqs.iter().enumerate() {
        let err = |allowed: String| InputError::Frequency {
            path: path.to_path_buf(),
            location: format!("/frequency_hz[{k}]"),
            value: f,
            allowed,
        };
        if let Some(allowed) = frequency_refusal(f, k.checked_sub(1).map(|p| freqs[p])) {
            return Err(err(allowed));
        }
    }
    require_two(path, "dataset /frequency_hz", freqs.len(), "frequencies")?;

    Ok(freqs)
}

/// The root attribute `axes`: the source axis names, each once.
fn axis_names(path: &Path, file: &hdf5::File) -> Result<Vec<String>, InputError> {
    let names = match h5::attr(path, file, "/", "axes")? {
        None => {
            return Err(FormatError::MissingAttribute {
                path: path.to_path_buf(),
                object: "/".to_string(),
                attribute: "axes",
                expected: AXES_ALLOWED,
            }
            .into())
        }
        Some(AttrValue::Str(s)) => vec![s],
        Some(AttrValue::StrList(v)) => v,
        Some(other) => {
            return Err(InputError::BadAttribute {
                path: path.to_path_buf(),
                object: "/".to_string(),
                attribute: "axes",
                value: other.describe(),
                allowed: AXES_ALLOWED,
            })
        }
    };
    if let Some((i, n)) = names
        .iter()
        .enumerate()
        .find(|(i, n)| names[..*i].contains(n))
    {
        return Err(InputError::BadAttribute {
            path: path.to_path_buf(),
            object: "/".to_string(),
            attribute: "axes",
            value: format!("{names:?} (`{n}` repeated at position {i})"),
            allowed: "unique axis names",
        });
    }
    Ok(names)
}

type Values = (Vec<Complex64>, Option<Declared>);

/// The `units` attribute of `/name`, classified.
fn units(
    path: &Path,
    ds: &hdf5::Dataset,
    name: &str,
    classify: fn(&str) -> Option<SpectrumUnit>,
    allowed: &'static str,
) -> Result<Option<Declared>, InputError> {
    let object = format!("dataset /{name}");
    let bad = |value: String| InputError::Units {
        path: path.to_path_buf(),
        location: format!("unit attribute of {object}"),
        value,
        allowed,
    };
    match h5::unit_attr(path, ds, &object)? {
        None => Ok(None),
        Some(AttrValue::Str(u)) => match classify(&u) {
            Some(q) => Ok(Some(Declared {
                channel: String::new(),
                unit: u,
                quantity: q.quantity,
            })),
            None => Err(bad(u)),
        },
        Some(other) => Err(bad(other.describe())),
    }
}

/// What the spectral dataset `/asd` or `/csd` holds.
struct ValuesKind {
    /// Dataset name without the leading `/`.
    name: &'static str,
    /// Checks the element type; returns whether it fits and the type's description.
    is_type: fn(&hdf5::Dataset) -> hdf5::Result<(bool, String)>,
    /// Recognises the units of its `units` attribute.
    classify: fn(&str) -> Option<SpectrumUnit>,
    /// The accepted units, for messages.
    units_allowed: &'static str,
}

const ASD: ValuesKind = ValuesKind {
    name: "asd",
    is_type: h5::is_float,
    classify: asd_unit,
    units_allowed: ASD_UNITS,
};

const CSD: ValuesKind = ValuesKind {
    name: "csd",
    is_type: h5::is_complex,
    classify: csd_unit,
    units_allowed: CSD_UNITS,
};

/// Opens the dataset of `kind`, checks its element type and its shape against `shape`
/// (`allowed` describes both for the error), and reads its `units` attribute.
fn open_values(
    path: &Path,
    file: &hdf5::File,
    kind: &ValuesKind,
    shape: &[usize],
    allowed: String,
) -> Result<(hdf5::Dataset, Option<Declared>), InputError> {
    let object = format!("dataset /{}", kind.name);
    let ds = file.dataset(kind.name).map_err(h5err(path, &object))?;
    let (right_type, dtype) = (kind.is_type)(&ds).map_err(h5err(path, &object))?;
    if ds.shape() != shape || !right_type {
        return Err(FormatError::BadDataset {
            path: path.to_path_buf(),
            dataset: format!("/{}", kind.name),
            found: format!("type {dtype} and shape {:?}", ds.shape()),
            allowed,
        }
        .into());
    }
    h5::check_storage(path, &ds, &format!("/{}", kind.name))?;
    let declared = units(path, &ds, kind.name, kind.classify, kind.units_allowed)?;
    Ok((ds, declared))
}

/// The quantity the `units` attribute declares; angle without one.
fn declared_quantity(declared: &Option<Declared>) -> Quantity {
    declared
        .as_ref()
        .and_then(|d| d.quantity)
        .unwrap_or(Quantity::Angle)
}

fn read_asd(
    path: &Path,
    file: &hdf5::File,
    freqs: &[f64],
    names: &[String],
) -> Result<Values, InputError> {
    let (nf, m) = (freqs.len(), names.len());
    let (ds, declared) = open_values(
        path,
        file,
        &ASD,
        &[nf, m],
        format!("float64 of shape [{nf}, {m}] ([len(/frequency_hz), len(axes)]), rad/sqrt(Hz)"),
    )?;
    let unit = declared_quantity(&declared).asd_unit();
    let asd = ds.read_raw::<f64>().map_err(h5err(path, "dataset /asd"))?;
    let mut src = vec![Complex64::new(0.0, 0.0); nf * m * m];
    for k in 0..nf {
        for a in 0..m {
            let v = asd[k * m + a];
            if !ASDS.admits(v) {
                return Err(InputError::Asd {
                    path: path.to_path_buf(),
                    location: format!("/asd[{k}, {a}] at {} Hz", freqs[k]),
                    column: names[a].clone(),
                    value: v,
                    unit,
                    power: false,
                });
            }
            src[(k * m + a) * m + a] = Complex64::new(v * v, 0.0);
        }
    }
    Ok((src, declared))
}

fn read_csd(
    path: &Path,
    file: &hdf5::File,
    freqs: &[f64],
    names: &[String],
) -> Result<Values, InputError> {
    let (nf, m) = (freqs.len(), names.len());
    let (ds, declared) = open_values(
        path,
        file,
        &CSD,
        &[nf, m, m],
        format!(
            "complex128 (compound {{r: float64, i: float64}}, as h5py writes) of shape \
             [{nf}, {m}, {m}] ([len(/frequency_hz), len(axes), len(axes)]), rad^2/Hz"
        ),
    )?;
    let unit = declared_quantity(&declared).csd_unit();
    let mut src = ds
        .read_raw::<Complex64>()
        .map_err(h5err(path, "dataset /csd"))?;
    for (k, &f) in freqs.iter().enumerate() {
        let at = |i: usize, j: usize| src[(k * m + i) * m + j];
        let err = |i: usize, j: usize, detail: String, allowed: String| {
            FormatError::Csd {
                path: path.to_path_buf(),
                index: k,
                freq_hz: f,
                i,
                j,
                pair: format!("{}, {}", names[i], names[j]),
                problem: format!("{detail} ({unit}); allowed: {allowed}"),
            }
            .into()
        };
        for i in 0..m {
            for j in 0..m {
                let s = at(i, j);
                if !(s.re.is_finite() && s.im.is_finite()) {
                    return Err(err(
                        i,
                        j,
                        format!("entry {s} is not finite"),
                        "finite values".to_string(),
                    ));
                }
                if !PSDS.admits(s.norm()) {
                    return Err(err(
                        i,
                        j,
                        format!("entry {s} has the magnitude {:e}", s.norm()),
                        format!("{} (see docs/limits.md)", PSDS.allowed("")),
                    ));
                }
            }
        }
        for i in 0..m {
            let s = at(i, i);
            if s.re < 0.0 || s.im.abs() > CSD_RTOL * s.re {
                return Err(err(
                    i,
                    i,
                    format!("diagonal entry {s} is not a real PSD >= 0"),
                    format!("real part >= 0 and |imaginary part| <= {CSD_RTOL:.2e} * real part"),
                ));
            }
        }
        for i in 0..m {
            for j in i + 1..m {
                let (sij, sji) = (at(i, j), at(j, i));
                let d = (at(i, i).re * at(j, j).re).sqrt();
                let asym = (sij - sji.conj()).norm();
                if asym > CSD_RTOL * d {
                    return Err(err(
                        i,
                        j,
                        format!(
                            "not Hermitian: S_ij = {sij}, S_ji = {sji}, |S_ij - conj(S_ji)| = \
                             {asym:.3e}"
                        ),
                        format!(
                            "|S_ij - conj(S_ji)| <= {CSD_RTOL:.2e} * sqrt(S_ii S_jj) = {:.3e}",
                            CSD_RTOL * d
                        ),
                    ));
                }
                if sij.norm() > (1.0 + CSD_RTOL) * d {
                    return Err(err(
                        i,
                        j,
                        format!(
                            "|S_ij| = {:.6e} exceeds sqrt(S_ii S_jj) = {d:.6e} (coherence > 1)",
                            sij.norm()
                        ),
                        format!("|S_ij| <= (1 + {CSD_RTOL:.2e}) sqrt(S_ii S_jj)"),
                    ));
                }
            }
        }
        // Exactly Hermitian from here on.
        for i in 0..m {
            let idx = (k * m + i) * m + i;
            src[idx] = Complex64::new(src[idx].re, 0.0);
            for j in i + 1..m {
                let (a, b) = ((k * m + i) * m + j, (k * m + j) * m + i);
                let h = (src[a] + src[b].conj()) * 0.5;
                src[a] = h;
                src[b] = h.conj();
            }
        }
    }
    Ok((src, declared))
}
