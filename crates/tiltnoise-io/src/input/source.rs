//! [`TiltSeriesSource`]: streaming access to an HDF5 time series of the floor's motion (schema
//! `tiltnoise.tilt_series`), chunk by chunk, in bounded memory.

use super::address::input_format;
use super::address::split_hdf5_address;
use super::format_error::FormatError;
use super::h5::{self, h5err, AttrValue};
use super::series_units::{self, check_unstated, into_series, Plan, Stated};
use std::path::{Path, PathBuf};
use tiltnoise_core::error::Num;
use tiltnoise_core::input::check_scales;
use tiltnoise_core::input::Mapped;
use tiltnoise_core::input::{check_sample_rate, require_two, InputError};
use tiltnoise_core::input::{
    gap_note, ChannelCtx, DetrendedRms, Gap, GapScanner, GroundChannel, TiltSeries,
};
use tiltnoise_core::input::{
    GapPolicy, InputFormat, InputKind, Provenance, Quantity, ReadOptions, SeriesSource,
};
use tiltnoise_core::limits::{check_count, MAX_STREAMED_SAMPLES};

/// Samples per channel read at a time by the scanning pass at open (2 MiB of `f64`).
const SCAN_BLOCK: usize = 1 << 18;

/// An open HDF5 time series of the floor's motion read in chunks.
///
/// [`TiltSeriesSource::read_chunk`] returns samples `start .. start + len` of every channel
/// ([`TiltSeriesSource::channels`]: tilt angle in rad or rate in rad/s, translations in m, m/s
/// or m/s^2; nothing is integrated: the spectra are converted, see
/// [`tiltnoise_core::input::GroundMap`]) in the crate's sign convention: the axis map and sign
/// applied, finiteness validated (errors name the absolute sample index) or gaps bridged. The
/// values are **bit-identical** to those of [`super::read_tilt_series`] for any chunking, and
/// chunks may be read in any order.
///
/// # Cost and memory
///
/// At most [`MAX_STREAMED_SAMPLES`] per channel. Opening reads only metadata, except when gaps
/// are interpolated or a tilt channel's unit is not stated: then one streaming pass over every
/// mapped channel (in blocks of 2^18 samples) records the interior gaps (32 bytes per gap) and
/// checks the detrended RMS of the channels without a unit. A chunk costs
/// `n_channels * len * 8` bytes.
#[derive(Debug)]
pub struct TiltSeriesSource {
    path: PathBuf,
    _file: hdf5::File,
    datasets: Vec<hdf5::Dataset>,
    channels: Vec<Mapped>,
    /// Per channel: the factor into SI (units prefix, scale), before the sign.
    factors: Vec<f64>,
    plan: Plan,
    sample_rate_hz: f64,
    len: usize,
    policy: GapPolicy,
    gaps: Vec<Vec<Gap>>,
    provenance: Provenance,
}

impl TiltSeriesSource {
    /// Opens an HDF5 tilt time series.
    ///
    /// # Errors
    ///
    /// [`InputError::Extension`] unless the extension is `.h5`/`.hdf5`;
    /// [`InputError::WrongKind`] for spectra; [`FormatError::MissingAttribute`] without a root
    /// attribute `sample_rate_hz`; any validation error of the layout (see
    /// `docs/input_formats.md`); with gap interpolation, also the errors of the scanning pass
    /// (edge gaps).
    pub fn open(path: &Path, opts: &ReadOptions) -> Result<Self, InputError> {
        let format = input_format(path)?;
        if format != InputFormat::Hdf5 {
            return Err(InputError::UnknownLayout {
                path: path.to_path_buf(),
                format: format.name(),
                found: format!("a {} file, which cannot be streamed", format.name()),
                accepted: "HDF5 time series (use read_tilt_series for CSV or miniSEED)",
            });
        }
        let (file_path, object) = split_hdf5_address(path);
        let file = h5::open(&file_path)?;
        if object.is_some() {
            return Self::from_file(&file_path, file, opts, object.as_deref());
        }
        match h5::detect_kind(path, &file, Some(InputKind::Series))? {
            InputKind::Series => Self::from_file(path, file, opts, None),
            InputKind::Spectra => Err(InputError::WrongKind {
                path: path.to_path_buf(),
                expected: "series",
                found: "spectra",
            }),
        }
    }

    /// Reads the series of `file`: the root's datasets (root attribute `sample_rate_hz`, or
    /// gwpy TimeSeries attributes), or those of the group or the one dataset `object` names.
    pub(crate) fn from_file(
        path: &Path,
        file: hdf5::File,
        opts: &ReadOptions,
        object: Option<&str>,
    ) -> Result<Self, InputError> {
        let mut notes = Vec::new();
        let h5::Located {
            group,
            prefix,
            only,
        } = h5::locate(path, &file, object)?;
        if let Some(o) = object {
            notes.push(format!("HDF5 object {o} of the file"));
        }
        let start_time = h5::start_and_description(path, &file, &mut notes)?;
        let file_map = h5::axis_map(path, &file)?;
        let available = match &only {
            Some(name) => vec![name.clone()],
            None => h5::root_datasets(path, &group)?,
        };
        let mut unit_notes = Vec::new();
        let in_file = available
            .iter()
            .map(|n| stated_unit(path, &group, &prefix, n))
            .collect::<Result<Vec<_>, _>>()?;
        let stated = series_units::merge_given(
            path,
            &available,
            in_file,
            &opts.units,
            "dataset",
            &mut unit_notes,
        )?;
        let motions = series_units::motions(path, &available, &stated)?;
        let resolved = h5::resolve_axes(
            path,
            &available,
            &motions,
            "dataset",
            opts,
            file_map.as_ref(),
            &mut notes,
        )?;
        notes.extend(unit_notes);
        let has_rate = object.is_none() && h5::attr(path, &file, "/", "sample_rate_hz")?.is_some();
        let gwpy = resolved
            .channels
            .first()
            .is_some_and(|m| h5::is_gwpy_series(path, &group, &m.source));
        let sample_rate_hz = if has_rate || (object.is_none() && !gwpy) {
            h5::sample_rate_hz(path, &file)?
        } else {
            gwpy_rate(path, &group, &prefix, &resolved.channels, &mut notes)?
        };

        let mut datasets = Vec::new();
        let mut first_len: Option<(String, usize)> = None;
        for m in &resolved.channels {
            let name = format!("{prefix}/{}", m.source);
            let ds = group
                .dataset(&m.source)
                .map_err(h5err(path, format!("dataset {name}")))?;
            let shape = ds.shape();
            let (float, dtype) =
                h5::is_float(&ds).map_err(h5err(path, format!("dataset {name}")))?;
            if shape.len() != 1 || !float {
                return Err(FormatError::BadDataset {
                    path: path.to_path_buf(),
                    dataset: name,
                    found: format!("type {dtype} and shape {shape:?}"),
                    allowed: "a 1-D float64 (or float32) dataset, one sample per entry".to_string(),
                }
                .into());
            }
            h5::check_storage(path, &ds, &name)?;
            match &first_len {
                None => first_len = Some((m.source.clone(), shape[0])),
                Some((a, n)) if *n != shape[0] => {
                    return Err(InputError::LengthMismatch {
                        path: path.to_path_buf(),
                        channel_a: a.clone(),
                        len_a: *n,
                        channel_b: m.source.clone(),
                        len_b: shape[0],
                    })
                }
                Some(_) => {}
            }
            datasets.push(ds);
        }
        check_scales(path, &opts.scale, &available, "dataset")?;
        let plan = series_units::plan(path, &resolved, &stated, opts, &mut notes)?;
        let factors = plan.channels.iter().map(|p| p.factor).collect();
        let (first_name, len) = first_len.unwrap_or_default();
        require_two(path, &format!("dataset /{first_name}"), len, "samples")?;
        check_count(
            || format!("input file {}, dataset /{first_name}", path.display()),
            len as f64,
            "samples",
            MAX_STREAMED_SAMPLES,
        )?;
        if has_rate {
            notes.push(format!(
                "sample rate {sample_rate_hz} Hz from root attribute sample_rate_hz"
            ));
        }

        let quantity = plan.quantity;
        let mut src = TiltSeriesSource {
            path: path.to_path_buf(),
            _file: file,
            datasets,
            channels: resolved.channels.clone(),
            factors,
            plan,
            sample_rate_hz,
            len,
            policy: opts.gaps,
            gaps: vec![Vec::new(); resolved.channels.len()],
            provenance: Provenance {
                path: path.to_path_buf(),
                format: InputFormat::Hdf5,
                kind: InputKind::Series,
                quantity,
                axis_map: resolved.map.to_string(),
                start_time,
                notes,
            },
        };
        src.provenance
            .notes
            .push(series_units::units_note(&src.plan));
        for ch in 0..src.channels.len() {
            if opts.gaps == GapPolicy::Interpolate || src.plan.channels[ch].unstated {
                src.scan(ch)?;
            }
        }
        Ok(src)
    }

    /// The scanning pass over channel `ch`: its interior gaps (when they are interpolated; a
    /// rejected gap is found where it is read), and the detrended RMS of a channel whose unit
    /// is not stated, checked against its bound.
    fn scan(&mut self, ch: usize) -> Result<(), InputError> {
        let source = self.channels[ch].source.clone();
        let planned = self.plan.channels[ch];
        let ctx = ChannelCtx {
            path: &self.path,
            channel: &source,
            unit: planned.unit(),
        };
        let mut scanner = GapScanner::new(self.policy, self.len);
        let mut rms = DetrendedRms::new(self.len);
        let mut pos = 0;
        while pos < self.len {
            let n = SCAN_BLOCK.min(self.len - pos);
            let mut block = self.read_raw(ch, pos, n)?;
            let (s, f) = (self.channels[ch].sign.factor(), self.factors[ch]);
            for v in &mut block {
                *v = s * (f * *v);
            }
            if self.policy == GapPolicy::Interpolate {
                scanner.push(&block, &ctx)?;
            }
            rms.push(&block);
            pos += n;
        }
        let gaps = scanner.finish(&ctx)?;
        check_unstated(
            &self.path,
            &source,
            &planned,
            rms.finish(),
            self.sample_rate_hz,
        )?;
        let bridged: usize = gaps.iter().map(|g| g.after - g.before - 1).sum();
        if bridged > 0 {
            self.provenance.notes.push(gap_note(&source, bridged));
        }
        self.gaps[ch] = gaps;
        Ok(())
    }

    /// Raw samples of channel `ch` as stored.
    fn read_raw(&self, ch: usize, start: usize, len: usize) -> Result<Vec<f64>, InputError> {
        let arr = self.datasets[ch]
            .read_slice_1d::<f64, _>(start..start + len)
            .map_err(h5err(
                &self.path,
                format!(
                    "dataset /{} samples {start}..{}",
                    self.channels[ch].source,
                    start + len
                ),
            ))?;
        let (v, offset) = arr.into_raw_vec_and_offset();
        debug_assert!(offset.unwrap_or(0) == 0);
        Ok(v)
    }

    /// Signed, validated or gap-bridged samples of channel `ch`.
    fn load(&self, ch: usize, start: usize, len: usize) -> Result<Vec<f64>, InputError> {
        let mut v = self.read_raw(ch, start, len)?;
        let (s, f) = (self.channels[ch].sign.factor(), self.factors[ch]);
        let ctx = ChannelCtx {
            path: &self.path,
            channel: &self.channels[ch].source,
            unit: self.plan.channels[ch].unit(),
        };
        for (i, x) in v.iter_mut().enumerate() {
            let y = s * (f * *x);
            if y.is_finite() {
                ctx.check_sample(start + i, y, None)?;
                *x = y;
            } else {
                let k = start + i;
                let gap = match self.policy {
                    GapPolicy::Reject => None,
                    GapPolicy::Interpolate => Gap::find(&self.gaps[ch], k),
                };
                *x = gap.ok_or_else(|| ctx.non_finite(k, *x, None))?.value(k);
            }
        }
        Ok(v)
    }

    /// Sample rate (Hz).
    pub fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    /// Number of samples per channel.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are no samples (never true for an open source: at least 2 are required).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The channels, in canonical input order; [`TiltSeriesSource::read_chunk`] returns one
    /// vector per entry.
    pub fn channels(&self) -> Vec<GroundChannel> {
        self.plan.channels.iter().map(|p| p.channel).collect()
    }

    /// The quantity of the tilt channels: angle (rad) or rate (rad/s), as stored in the file.
    pub fn quantity(&self) -> Quantity {
        self.plan.quantity
    }

    /// Provenance (the notes include the gaps bridged during the scanning pass).
    pub fn provenance(&self) -> &Provenance {
        &self.provenance
    }

    /// Samples `start .. start + len` of every channel, in the SI unit of its quantity.
    ///
    /// # Errors
    ///
    /// [`InputError::ChunkOutOfRange`] if `start + len > self.len()`;
    /// [`InputError::NonFinite`] naming the absolute sample index (gaps rejected);
    /// [`InputError::Format`] (the HDF5 library's failure) on a read failure.
    pub fn read_chunk(&mut self, start: usize, len: usize) -> Result<Vec<Vec<f64>>, InputError> {
        if start.checked_add(len).is_none_or(|end| end > self.len) {
            return Err(InputError::ChunkOutOfRange {
                path: self.path.clone(),
                start,
                len,
                available: self.len,
            });
        }
        if len == 0 {
            return Ok(vec![Vec::new(); self.channels.len()]);
        }
        (0..self.channels.len())
            .map(|ch| self.load(ch, start, len))
            .collect()
    }

    /// Reads the whole series into memory.
    ///
    /// # Errors
    ///
    /// [`InputError::TooLarge`] for more than
    /// [`tiltnoise_core::limits::MAX_SERIES_SAMPLES`] samples or more than the memory
    /// available; otherwise as [`TiltSeriesSource::read_chunk`].
    pub fn read_all(&mut self) -> Result<TiltSeries, InputError> {
        let first = self
            .channels
            .first()
            .map_or(String::new(), |m| format!("/{}", m.source));
        h5::check_whole_read(&self.path, &first, self.len, self.channels.len(), "samples")?;
        let data = self.read_chunk(0, self.len)?;
        Ok(into_series(
            &self.plan,
            data,
            self.sample_rate_hz,
            self.provenance.clone(),
        ))
    }
}

impl SeriesSource for TiltSeriesSource {
    fn sample_rate_hz(&self) -> f64 {
        TiltSeriesSource::sample_rate_hz(self)
    }

    fn len(&self) -> usize {
        TiltSeriesSource::len(self)
    }

    fn channels(&self) -> Vec<GroundChannel> {
        TiltSeriesSource::channels(self)
    }

    fn read_chunk(&mut self, start: usize, len: usize) -> Result<Vec<Vec<f64>>, InputError> {
        TiltSeriesSource::read_chunk(self, start, len)
    }
}

/// The unit attribute (`units`, else `unit`) of dataset `name` of `group`, if it has one; a
/// dataset that cannot be opened has none here (opening it fails, naming it, if it is mapped).
fn stated_unit(
    path: &Path,
    group: &hdf5::Group,
    prefix: &str,
    name: &str,
) -> Result<Option<Stated>, InputError> {
    let Ok(ds) = group.dataset(name) else {
        return Ok(None);
    };
    let object = format!("dataset {prefix}/{name}");
    let units = match h5::attr(path, &ds, &object, "units")? {
        None => h5::attr(path, &ds, &object, "unit")?,
        some => some,
    };
    let origin = format!("attribute `units` of {object}");
    Ok(match units {
        None => None,
        Some(AttrValue::Str(u)) => Some(Stated::in_file(&u, origin)),
        Some(other) => Some(Stated {
            text: other.describe(),
            parsed: None,
            origin,
            assumed: false,
            counts: false,
        }),
    })
}

/// The sample rate of gwpy TimeSeries datasets: `1 / dx` of their attribute `dx` (s), which
/// must be the same for every mapped dataset, as must `x0` (GPS s).
fn gwpy_rate(
    path: &Path,
    group: &hdf5::Group,
    prefix: &str,
    channels: &[Mapped],
    notes: &mut Vec<String>,
) -> Result<f64, InputError> {
    const DX: &str = "the sampling interval in s (gwpy's dx): a finite number > 0, the same for \
                      every channel (or a root attribute sample_rate_hz)";
    let mut first: Option<(String, f64, Option<f64>)> = None;
    for m in channels {
        let name = format!("{prefix}/{}", m.source);
        let object = format!("dataset {name}");
        let ds = group
            .dataset(&m.source)
            .map_err(h5err(path, object.clone()))?;
        let dx = match h5::attr(path, &ds, &object, "dx")? {
            Some(h5::AttrValue::Num(v)) if v.is_finite() && v > 0.0 => v,
            None => {
                return Err(FormatError::MissingAttribute {
                    path: path.to_path_buf(),
                    object,
                    attribute: "dx",
                    expected: DX,
                }
                .into())
            }
            Some(other) => {
                return Err(InputError::BadAttribute {
                    path: path.to_path_buf(),
                    object,
                    attribute: "dx",
                    value: other.describe(),
                    allowed: DX,
                })
            }
        };
        if let Some(h5::AttrValue::Str(u)) = h5::attr(path, &ds, &object, "xunit")? {
            if u.trim() != "s" {
                return Err(InputError::BadAttribute {
                    path: path.to_path_buf(),
                    object,
                    attribute: "xunit",
                    value: format!("`{u}`"),
                    allowed: "`s` (a gwpy TimeSeries; a FrequencySeries is not a tilt series)",
                });
            }
        }
        let x0 = match h5::attr(path, &ds, &object, "x0")? {
            Some(h5::AttrValue::Num(v)) => Some(v),
            _ => None,
        };
        match &first {
            None => first = Some((name, dx, x0)),
            Some((a, dx_a, x0_a)) => {
                if dx != *dx_a || x0 != *x0_a {
                    return Err(InputError::BadAttribute {
                        path: path.to_path_buf(),
                        object,
                        attribute: "dx",
                        value: format!("dx = {dx} s, x0 = {x0:?} s (dataset {a}: dx = {dx_a} s, x0 = {x0_a:?} s)"),
                        allowed: "the same dx and x0 for every mapped dataset",
                    });
                }
            }
        }
    }
    let (name, dx, x0) = first.expect("at least one mapped channel");
    let rate = check_sample_rate(
        path,
        || format!("attribute dx = {} s of {name}", Num(dx)),
        1.0 / dx,
    )?;
    notes.push(format!(
        "sample rate {} Hz from attribute dx = {dx} s of {name} (gwpy TimeSeries layout){}",
        1.0 / dx,
        x0.map_or(String::new(), |x| format!(
            "; x0 = {x} s (GPS time in gwpy's convention)"
        ))
    ));
    Ok(rate)
}
