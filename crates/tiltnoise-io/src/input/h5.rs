//! HDF5 helpers: opening, layout detection, typed attribute reading with precise errors.

use super::format_error::FormatError;
use super::start_time::{self, ISO8601_ALLOWED};
use hdf5::types::{FixedAscii, FixedUnicode, TypeDescriptor, VarLenAscii, VarLenUnicode};
use hdf5::{Attribute, Location, LocationType};
use std::path::Path;
use tiltnoise_core::error::shown_list;
use tiltnoise_core::input::Motion;
use tiltnoise_core::input::{check_sample_rate, InputError};
use tiltnoise_core::input::{resolve, MapOrigin, Resolved};
use tiltnoise_core::input::{
    AxisMap, InputKind, ReadOptions, ACCEPTED_LAYOUTS, INPUT_SCHEMA_VERSION, SCHEMA_TILT_SERIES,
    SCHEMA_TILT_SPECTRA,
};
use tiltnoise_core::limits::{
    check_count, check_memory, planned_bytes, MAX_SERIES_SAMPLES, SERIES_BYTES_PER_SAMPLE,
};

/// Maps an HDF5 error to [`FormatError::Hdf5`] naming `object`.
pub(crate) fn h5err(
    path: &Path,
    object: impl Into<String>,
) -> impl FnOnce(hdf5::Error) -> InputError {
    let path = path.to_path_buf();
    let object = object.into();
    move |e| {
        InputError::from(FormatError::Hdf5 {
            path,
            object,
            message: crate::messages::first_line(&e.to_string()),
        })
    }
}

/// Opens `path` read-only. Only a regular file is handed to HDF5, which reads at random
/// offsets: a FIFO or a character device would block it forever or feed it endless bytes.
pub(crate) fn open(path: &Path) -> Result<hdf5::File, InputError> {
    let io_error = |reason| InputError::Io {
        path: path.to_path_buf(),
        reason,
    };
    let kind = std::fs::metadata(path).map_err(io_error)?.file_type();
    if !kind.is_file() {
        return Err(io_error(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "it is {}, not a regular file; an HDF5 file is read at random offsets, so \
                 copy it to a regular file first",
                crate::messages::file_kind(&kind)
            ),
        )));
    }
    hdf5::File::open(path).map_err(h5err(path, "file (is it an HDF5 file?)"))
}

/// Refuses a contiguous dataset whose storage is smaller than its extent: HDF5 then returns
/// fill values (or, for a partial read, other bytes) for the entries past the end, so the
/// numbers read would be made up. A dataset that was never written has no storage at all.
pub(crate) fn check_storage(
    path: &Path,
    ds: &hdf5::Dataset,
    dataset: &str,
) -> Result<(), InputError> {
    if ds.layout() != hdf5::dataset::Layout::Contiguous {
        return Ok(());
    }
    let entry_bytes = ds.dtype().map(|t| t.size() as u64).unwrap_or(0);
    let need = (ds.size() as u64).saturating_mul(entry_bytes);
    let have = ds.storage_size();
    if have >= need {
        return Ok(());
    }
    Err(FormatError::BadDataset {
        path: path.to_path_buf(),
        dataset: dataset.to_string(),
        found: format!(
            "{have} bytes of storage for {} entries of {entry_bytes} bytes ({need} bytes)",
            ds.size()
        ),
        allowed: "storage for every entry (this dataset is truncated, damaged or was never \
                  written)"
            .to_string(),
    }
    .into())
}

/// Refuses to read `channels` datasets of `len` samples (or frequencies) each into memory when
/// `len` is over [`MAX_SERIES_SAMPLES`] or they do not fit into the memory available: the
/// length comes from the file's metadata, which a file of a few KiB can set to 10^12.
pub(crate) fn check_whole_read(
    path: &Path,
    dataset: &str,
    len: usize,
    channels: usize,
    unit: &'static str,
) -> Result<(), InputError> {
    let what = || format!("input file {}, dataset {dataset}", path.display());
    check_count(what, len as f64, unit, MAX_SERIES_SAMPLES)?;
    let per_sample = SERIES_BYTES_PER_SAMPLE.saturating_mul(channels as u64);
    check_memory(what, planned_bytes(len, per_sample))?;
    Ok(())
}

/// A decoded attribute value.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum AttrValue {
    /// A numeric scalar (or 1-element array).
    Num(f64),
    /// A string scalar (or 1-element array).
    Str(String),
    /// A 1-D array of several strings.
    StrList(Vec<String>),
    /// Anything else, described.
    Other(String),
}

impl AttrValue {
    /// Description for messages.
    pub fn describe(&self) -> String {
        match self {
            AttrValue::Num(v) => format!("{v}"),
            AttrValue::Str(s) => format!("`{s}`"),
            AttrValue::StrList(v) => format!("{v:?}"),
            AttrValue::Other(d) => d.clone(),
        }
    }
}

/// The raw bytes of a string attribute's elements; `None` for a non-string type. Bytes, not
/// `&str`: the library's `as_str()` trusts the file's bytes to be valid UTF-8 (ASCII), which a
/// damaged or hostile file need not be; [`text`] validates them.
fn read_strings(a: &Attribute, desc: &TypeDescriptor) -> hdf5::Result<Option<Vec<Vec<u8>>>> {
    Ok(Some(match desc {
        TypeDescriptor::VarLenUnicode => a
            .read_raw::<VarLenUnicode>()?
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect(),
        TypeDescriptor::VarLenAscii => a
            .read_raw::<VarLenAscii>()?
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect(),
        TypeDescriptor::FixedAscii(_) => a
            .read_raw::<FixedAscii<4096>>()?
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect(),
        TypeDescriptor::FixedUnicode(_) => a
            .read_raw::<FixedUnicode<4096>>()?
            .iter()
            .map(|s| s.as_bytes().to_vec())
            .collect(),
        _ => return Ok(None),
    }))
}

/// Validates the bytes of a string read from a file as UTF-8, naming the file, the object
/// and the first invalid byte otherwise.
fn text(path: &Path, what: &str, bytes: Vec<u8>) -> Result<String, InputError> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let byte = e.as_bytes()[at];
        InputError::from(FormatError::InvalidText {
            path: path.to_path_buf(),
            object: what.to_string(),
            detail: format!("byte 0x{byte:02x} at offset {at} is not valid UTF-8"),
        })
    })
}

/// The unit attribute of `loc`: `unit` (what tiltnoise writes, gwpy's name) or `units`.
pub(crate) fn unit_attr(
    path: &Path,
    loc: &Location,
    object: &str,
) -> Result<Option<AttrValue>, InputError> {
    match attr(path, loc, object, "unit")? {
        None => attr(path, loc, object, "units"),
        some => Ok(some),
    }
}

/// Reads attribute `name` of `loc` (`None` if absent).
pub(crate) fn attr(
    path: &Path,
    loc: &Location,
    object: &str,
    name: &str,
) -> Result<Option<AttrValue>, InputError> {
    let what = || format!("attribute `{name}` of {object}");
    let names = loc.attr_names().map_err(h5err(path, object))?;
    if !names.iter().any(|n| n == name) {
        return Ok(None);
    }
    let a = loc.attr(name).map_err(h5err(path, what()))?;
    let desc = a
        .dtype()
        .and_then(|t| t.to_descriptor())
        .map_err(h5err(path, what()))?;
    let shape = a.shape();
    let value = match desc {
        TypeDescriptor::Float(_)
        | TypeDescriptor::Integer(_)
        | TypeDescriptor::Unsigned(_)
        | TypeDescriptor::Boolean => {
            if a.size() == 1 {
                AttrValue::Num(a.read_raw::<f64>().map_err(h5err(path, what()))?[0])
            } else {
                AttrValue::Other(format!("a numeric array of shape {shape:?}"))
            }
        }
        _ => match read_strings(&a, &desc)
            .map_err(h5err(path, what()))?
            .map(|v| {
                v.into_iter()
                    .map(|b| text(path, &what(), b))
                    .collect::<Result<Vec<String>, InputError>>()
            })
            .transpose()?
        {
            Some(mut v) if shape.is_empty() || (shape.len() == 1 && v.len() == 1) => {
                AttrValue::Str(v.pop().unwrap_or_default())
            }
            Some(v) if shape.len() == 1 => AttrValue::StrList(v),
            Some(_) => AttrValue::Other(format!("a string array of shape {shape:?}")),
            None => AttrValue::Other(format!("a value of type {desc} and shape {shape:?}")),
        },
    };
    Ok(Some(value))
}

/// A string attribute; `None` if absent, an error if not a string.
pub(crate) fn str_attr(
    path: &Path,
    loc: &Location,
    object: &str,
    name: &'static str,
    allowed: &'static str,
) -> Result<Option<String>, InputError> {
    match attr(path, loc, object, name)? {
        None => Ok(None),
        Some(AttrValue::Str(s)) => Ok(Some(s)),
        Some(other) => Err(InputError::BadAttribute {
            path: path.to_path_buf(),
            object: object.to_string(),
            attribute: name,
            value: other.describe(),
            allowed,
        }),
    }
}

/// Names of the datasets directly under the root, in HDF5's (alphabetical) order.
/// The root attribute `sample_rate_hz` of a time-series file (Hz, finite and > 0), required.
pub(crate) fn sample_rate_hz(path: &Path, file: &hdf5::File) -> Result<f64, InputError> {
    const RATE_ALLOWED: &str = "the sample rate in Hz: a finite number > 0";
    match attr(path, file, "/", "sample_rate_hz")? {
        None => Err(FormatError::MissingAttribute {
            path: path.to_path_buf(),
            object: "/".to_string(),
            attribute: "sample_rate_hz",
            expected: RATE_ALLOWED,
        }
        .into()),
        Some(AttrValue::Num(v)) if v.is_finite() && v > 0.0 => {
            check_sample_rate(path, || "attribute sample_rate_hz of /".to_string(), v)
        }
        Some(other) => Err(InputError::BadAttribute {
            path: path.to_path_buf(),
            object: "/".to_string(),
            attribute: "sample_rate_hz",
            value: other.describe(),
            allowed: RATE_ALLOWED,
        }),
    }
}

/// The members of the root group that are, or may be, datasets: a member whose type cannot
/// be read (a dangling soft or external link, say) is kept, so that mapping it as a channel
/// fails when it is opened, naming it, instead of the channel being dropped silently.
pub(crate) fn root_datasets(path: &Path, file: &hdf5::Group) -> Result<Vec<String>, InputError> {
    let names = file
        .member_names()
        .map_err(h5err(path, format!("group {}", file.name())))?;
    Ok(names
        .into_iter()
        .filter(|n| {
            !matches!(
                file.loc_type_by_name(n),
                Ok(LocationType::Group | LocationType::NamedDatatype)
            )
        })
        .collect())
}

/// Paths of the datasets anywhere in the file (`/group/dataset`), depth first, at most 50 (then
/// `...`): what an error lists when the layout is not found.
pub(crate) fn all_datasets(file: &hdf5::File) -> Vec<String> {
    fn walk(g: &hdf5::Group, prefix: &str, out: &mut Vec<String>, depth: usize) {
        let Ok(names) = g.member_names() else { return };
        for n in names {
            if out.len() > 50 {
                return;
            }
            let full = format!("{prefix}/{n}");
            match g.loc_type_by_name(&n) {
                Ok(LocationType::Group) if depth < 8 => {
                    if let Ok(sub) = g.group(&n) {
                        walk(&sub, &full, out, depth + 1);
                    }
                }
                Ok(LocationType::Dataset) => out.push(full),
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    if let Ok(root) = file.group("/") {
        walk(&root, "", &mut out, 0);
    }
    if out.len() > 50 {
        out.truncate(50);
        out.push("...".to_string());
    }
    out
}

/// Whether dataset `name` of `group` carries gwpy's TimeSeries attributes (`dx`, and `xunit`
/// `s` if it has one).
pub(crate) fn is_gwpy_series(path: &Path, group: &hdf5::Group, name: &str) -> bool {
    let Ok(ds) = group.dataset(name) else {
        return false;
    };
    let object = format!("dataset {name}");
    let dx = matches!(attr(path, &ds, &object, "dx"), Ok(Some(AttrValue::Num(_))));
    let xunit = match attr(path, &ds, &object, "xunit") {
        Ok(Some(AttrValue::Str(u))) => u.trim() == "s",
        Ok(None) => true,
        _ => false,
    };
    dx && xunit
}

/// Decides series vs spectra: root attribute `schema` if present, else `sample_rate_hz` ->
/// series, dataset `/frequency_hz` -> spectra, else `fallback` (the kind the caller insists
/// on, so that its own "missing" error names what is missing) or an
/// [`InputError::UnknownLayout`]. Also checks `schema_version` if present.
pub(crate) fn detect_kind(
    path: &Path,
    file: &hdf5::File,
    fallback: Option<InputKind>,
) -> Result<InputKind, InputError> {
    const SCHEMA_ALLOWED: &str = "`tiltnoise.tilt_series` or `tiltnoise.tilt_spectra` (or no \
         schema attribute)";
    let schema = str_attr(path, file, "/", "schema", SCHEMA_ALLOWED)?;
    let has_rate = attr(path, file, "/", "sample_rate_hz")?.is_some();
    let has_freq = root_datasets(path, file)?
        .iter()
        .any(|n| n == "frequency_hz");
    let kind = match schema.as_deref() {
        Some(SCHEMA_TILT_SERIES) => InputKind::Series,
        Some(SCHEMA_TILT_SPECTRA) => InputKind::Spectra,
        Some(other) => {
            return Err(InputError::BadAttribute {
                path: path.to_path_buf(),
                object: "/".to_string(),
                attribute: "schema",
                value: format!("`{other}`"),
                allowed: SCHEMA_ALLOWED,
            })
        }
        None => match (has_rate, has_freq) {
            (false, false)
                if root_datasets(path, file)?
                    .iter()
                    .any(|n| is_gwpy_series(path, file, n)) =>
            {
                InputKind::Series
            }
            (true, false) => InputKind::Series,
            (false, true) => InputKind::Spectra,
            (true, true) => {
                return Err(InputError::UnknownLayout {
                    path: path.to_path_buf(),
                    format: "hdf5",
                    found: "both a root attribute sample_rate_hz (series) and a dataset \
                            /frequency_hz (spectra), and no schema attribute to decide"
                        .to_string(),
                    accepted: ACCEPTED_LAYOUTS,
                })
            }
            (false, false) => match fallback {
                Some(kind) => kind,
                None => {
                    let found = all_datasets(file);
                    return Err(InputError::UnknownLayout {
                        path: path.to_path_buf(),
                        format: "hdf5",
                        found: format!(
                            "neither a root attribute sample_rate_hz (required for a time \
                             series) nor a dataset /frequency_hz (spectra) nor gwpy \
                             TimeSeries datasets at the root (address one in a group as \
                             FILE.h5:/group or FILE.h5:/group/dataset); datasets: {}",
                            if found.is_empty() {
                                "(none)".to_string()
                            } else {
                                shown_list(&found)
                            }
                        ),
                        accepted: ACCEPTED_LAYOUTS,
                    });
                }
            },
        },
    };
    match attr(path, file, "/", "schema_version")? {
        None => {}
        Some(AttrValue::Num(v)) if v == INPUT_SCHEMA_VERSION as f64 => {}
        Some(other) => {
            return Err(InputError::BadAttribute {
                path: path.to_path_buf(),
                object: "/".to_string(),
                attribute: "schema_version",
                value: other.describe(),
                allowed: "the integer 1 (the version this reader supports)",
            })
        }
    }
    Ok(kind)
}

/// Optional root attributes `start_time` (validated ISO 8601) and `description` (note).
pub(crate) fn start_and_description(
    path: &Path,
    file: &hdf5::File,
    notes: &mut Vec<String>,
) -> Result<Option<String>, InputError> {
    let start = str_attr(path, file, "/", "start_time", ISO8601_ALLOWED)?
        .map(|s| start_time::checked(path, "/".to_string(), "start_time", s, notes))
        .transpose()?;
    if let Some(d) = str_attr(path, file, "/", "description", "a string")? {
        notes.push(format!("description: {d}"));
    }
    Ok(start)
}

/// Optional root attribute `axis_map`, parsed.
pub(crate) fn axis_map(path: &Path, file: &hdf5::File) -> Result<Option<AxisMap>, InputError> {
    let Some(spec) = str_attr(
        path,
        file,
        "/",
        "axis_map",
        "a string such as `theta_t=-E,eta_t=-N`",
    )?
    else {
        return Ok(None);
    };
    let origin = format!("{}, root attribute axis_map", path.display());
    AxisMap::parse_from(&spec, &origin).map(Some)
}

/// Resolves the explicit axis map of `opts`, else the root attribute `axis_map` (`file_map`,
/// see [`axis_map`]), else the default, against the channels `available` of `path` (`kind`:
/// `dataset` or `axis name`), of which `motions` says what each measures, and appends the
/// provenance notes to `notes`.
pub(crate) fn resolve_axes(
    path: &Path,
    available: &[String],
    motions: &[Option<Motion>],
    kind: &'static str,
    opts: &ReadOptions,
    file_map: Option<&AxisMap>,
    notes: &mut Vec<String>,
) -> Result<Resolved, InputError> {
    let origin = match (&opts.axis_map, file_map) {
        (Some(m), _) => MapOrigin::Options(m),
        (None, Some(m)) => MapOrigin::File(m, "root attribute axis_map of the file"),
        (None, None) => MapOrigin::Default,
    };
    let resolved = resolve(path, available, motions, origin, kind)?;
    notes.extend(resolved.notes.iter().cloned());
    if let (Some(_), Some(m)) = (&opts.axis_map, file_map) {
        notes.push(format!(
            "the explicit axis map overrides the file's axis_map attribute {m}"
        ));
    }
    Ok(resolved)
}

/// Whether a dataset holds a floating-point type.
pub(crate) fn is_float(ds: &hdf5::Dataset) -> hdf5::Result<(bool, String)> {
    let d = ds.dtype()?.to_descriptor()?;
    Ok((matches!(d, TypeDescriptor::Float(_)), d.to_string()))
}

/// Whether a dataset holds a complex type (compound of two floats `r`, `i`, as h5py writes).
pub(crate) fn is_complex(ds: &hdf5::Dataset) -> hdf5::Result<(bool, String)> {
    let d = ds.dtype()?.to_descriptor()?;
    let ok = match &d {
        TypeDescriptor::Compound(c) => {
            c.fields.len() == 2
                && c.fields[0].name == "r"
                && c.fields[1].name == "i"
                && c.fields
                    .iter()
                    .all(|f| matches!(f.ty, TypeDescriptor::Float(_)))
        }
        _ => false,
    };
    Ok((ok, d.to_string()))
}

/// The group an HDF5 address names, or the parent group of the one dataset it names.
pub(crate) struct Located {
    pub group: hdf5::Group,
    /// The group's path without a trailing `/` (empty for the root), to prefix dataset names.
    pub prefix: String,
    /// The dataset, when the address names one.
    pub only: Option<String>,
}

/// Finds `object` (`None`: the root) in `file`.
pub(crate) fn locate(
    path: &Path,
    file: &hdf5::File,
    object: Option<&str>,
) -> Result<Located, InputError> {
    let (group_name, only) = match object {
        None => ("/".to_string(), None),
        Some(o) => match file.loc_type_by_name(o) {
            Ok(LocationType::Group) => (o.to_string(), None),
            Ok(LocationType::Dataset) => {
                let (parent, name) = o.rsplit_once('/').unwrap_or(("", o));
                let parent = if parent.is_empty() { "/" } else { parent };
                (parent.to_string(), Some(name.to_string()))
            }
            _ => {
                return Err(FormatError::MissingDataset {
                    path: path.to_path_buf(),
                    dataset: o.to_string(),
                    expected: format!(
                        "a group or a dataset of the file; datasets: {}",
                        shown_list(&all_datasets(file))
                    ),
                }
                .into())
            }
        },
    };
    let group = file
        .group(&group_name)
        .map_err(h5err(path, format!("group {group_name}")))?;
    let prefix = group_name.trim_end_matches('/').to_string();
    Ok(Located {
        group,
        prefix,
        only,
    })
}

/// The `xunit` attribute of dataset `name` of `group` (gwpy: `s` for a TimeSeries, `Hz` for a
/// FrequencySeries), if it has a string one.
pub(crate) fn xunit(path: &Path, group: &hdf5::Group, name: &str) -> Option<String> {
    let ds = group.dataset(name).ok()?;
    match attr(path, &ds, &format!("dataset {name}"), "xunit") {
        Ok(Some(AttrValue::Str(u))) => Some(u.trim().to_string()),
        _ => None,
    }
}
