//! Tilt time series from miniSEED 2 (`.mseed`, `.miniseed`, `.ms`), the FDSN format of
//! seismometers, tiltmeters and rotation sensors, decoded by this crate ([`record`], [`steim`]):
//! one channel per SEED code `NET.STA.LOC.CHA`, chosen with the axis map (full codes or bare
//! channel codes such as `LJE`; by default the rotation channels `?JE`, `?JN`, `?JZ`).
//!
//! miniSEED stores no units. A channel's unit comes from the options (`ReadOptions::units`),
//! else, for a tilt channel, from the options' quantity or the instrument code (second letter
//! of the channel code): `J` (rotation sensor) is a rate (rad/s), `A` (tiltmeter) an angle
//! (rad). Seismometer and accelerometer channels (`H`, `L`, `N`, `P`) are translations and
//! need their unit from the options. Integer samples (INT16, INT32, Steim-1, Steim-2) are
//! digitizer counts and need a scale factor per channel ([`super::ChannelScale`]);
//! floating-point samples (FLOAT32, FLOAT64) are taken to be in their unit already, which the
//! provenance says. See `docs/input_formats.md`.

mod channels;
mod record;
mod steim;

use super::format_error::FormatError;
use super::series_units::{self, check_unstated_data, into_series, units_note, Planned, Stated};
use channels::{Channel, Placed};
use std::io::Read;
use std::path::Path;
use tiltnoise_core::error::{shown_list, Shown};
use tiltnoise_core::input::TiltSeries;
use tiltnoise_core::input::{check_sample_rate, Provenance, Quantity, ReadOptions};
use tiltnoise_core::input::{check_scales, gap_note, process_channel, require_two, scale_for};
use tiltnoise_core::input::{
    resolve, ChannelCtx, ChannelUnit, InputError, MapOrigin, Mapped, Resolved,
};
use tiltnoise_core::input::{
    AxisMap, AxisMapEntry, ChannelScale, GapPolicy, InputFormat, InputKind,
};
use tiltnoise_core::limits::{
    check_file_len, check_memory, planned_bytes, MAX_DATA_FILE_BYTES, SERIES_BYTES_PER_SAMPLE,
};

/// What [`MAX_DATA_FILE_BYTES`] limits, for messages.
const DATA_FILE: &str = "a miniSEED input";

fn fault(path: &Path, record: Option<(usize, u64)>, message: String) -> InputError {
    InputError::from(FormatError::Miniseed {
        path: path.to_path_buf(),
        record,
        message,
    })
}

/// Reads the file whole, at most [`MAX_DATA_FILE_BYTES`].
fn read_bytes(path: &Path) -> Result<Vec<u8>, InputError> {
    let io = |reason| InputError::Io {
        path: path.to_path_buf(),
        reason,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    let what = || format!("input file {}", path.display());
    if meta.is_file() {
        check_file_len(what, meta.len(), MAX_DATA_FILE_BYTES, DATA_FILE)?;
    }
    let mut bytes = Vec::new();
    file.take(MAX_DATA_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    check_file_len(what, bytes.len() as u64, MAX_DATA_FILE_BYTES, DATA_FILE)?;
    Ok(bytes)
}

/// The records of each SEED code, in order of first appearance.
type Groups = Vec<(String, Vec<Placed>)>;

/// The data records of the file grouped by SEED code, in order of first appearance; the
/// number of ASCII log records skipped.
fn records(path: &Path, bytes: &[u8]) -> Result<(Groups, usize), InputError> {
    let mut groups: Groups = Vec::new();
    let mut text = 0;
    let mut offset = 0usize;
    let mut index = 0usize;
    while offset < bytes.len() {
        let at = Some((index, offset as u64));
        let record = record::decode(&bytes[offset..]).map_err(|m| fault(path, at, m))?;
        let len = record.len;
        if record.n_samples() == 0 {
            if matches!(record.samples, record::Samples::Text) {
                text += 1;
            }
        } else {
            let placed = Placed {
                record,
                index,
                offset: offset as u64,
            };
            match groups.iter_mut().find(|(id, _)| *id == placed.record.id) {
                Some((_, v)) => v.push(placed),
                None => groups.push((placed.record.id.clone(), vec![placed])),
            }
        }
        offset += len;
        index += 1;
    }
    if groups.is_empty() {
        return Err(fault(
            path,
            None,
            format!(
                "{index} records and no samples{}; allowed: miniSEED 2 data records",
                if bytes.is_empty() {
                    " (the file is empty)"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok((groups, text))
}

/// The full SEED code a user's channel name stands for: the code itself, or the one code whose
/// channel part (`CHA`) it is. `Ok(None)` when it names none.
fn full_code(path: &Path, name: &str, ids: &[String]) -> Result<Option<String>, InputError> {
    if ids.iter().any(|i| i == name) {
        return Ok(Some(name.to_string()));
    }
    let matches: Vec<&String> = ids
        .iter()
        .filter(|i| i.rsplit('.').next() == Some(name))
        .collect();
    match matches.as_slice() {
        [] => Ok(None),
        [one] => Ok(Some((*one).clone())),
        more => Err(fault(
            path,
            None,
            format!(
                "channel code `{}` matches {}; allowed: a channel code that one SEED code has, \
                 or the full code NET.STA.LOC.CHA",
                Shown(name),
                shown_list(more)
            ),
        )),
    }
}

/// The axis map (explicit, else none) with channel codes replaced by full SEED codes.
fn full_map(path: &Path, map: &AxisMap, ids: &[String]) -> Result<AxisMap, InputError> {
    let mut entries = Vec::new();
    for e in map.entries() {
        let source = full_code(path, &e.source, ids)?.unwrap_or_else(|| e.source.clone());
        entries.push(AxisMapEntry {
            target: e.target,
            sign: e.sign,
            source,
        });
    }
    Ok(AxisMap::from_entries(entries))
}

/// The scales with channel codes replaced by full SEED codes, checked against `ids`.
fn full_scales(
    path: &Path,
    scales: &[ChannelScale],
    ids: &[String],
) -> Result<Vec<ChannelScale>, InputError> {
    let mut out = Vec::new();
    for s in scales {
        let channel = full_code(path, &s.channel, ids)?.unwrap_or_else(|| s.channel.clone());
        out.push(ChannelScale {
            channel,
            factor: s.factor,
        });
    }
    check_scales(path, &out, ids, "channel")?;
    Ok(out)
}

/// The units given in the options, with channel codes replaced by full SEED codes.
fn full_units(
    path: &Path,
    units: &[ChannelUnit],
    ids: &[String],
) -> Result<Vec<ChannelUnit>, InputError> {
    units
        .iter()
        .map(|u| {
            Ok(ChannelUnit {
                channel: full_code(path, &u.channel, ids)?.unwrap_or_else(|| u.channel.clone()),
                ..u.clone()
            })
        })
        .collect()
}

/// Channel names of the options (sensor declarations) as full SEED codes.
fn full_names(path: &Path, names: &[String], ids: &[String]) -> Result<Vec<String>, InputError> {
    names
        .iter()
        .map(|n| Ok(full_code(path, n, ids)?.unwrap_or_else(|| n.clone())))
        .collect()
}

/// The quantity an instrument code says: `J` rotation sensor -> rate, `A` tiltmeter -> angle.
fn code_quantity(id: &str) -> Option<(Quantity, &'static str)> {
    let cha = id.rsplit('.').next().unwrap_or("");
    match cha.as_bytes().get(1) {
        Some(b'J') => Some((Quantity::Rate, "instrument code J: rotation sensor, rad/s")),
        Some(b'A') => Some((Quantity::Angle, "instrument code A: tiltmeter, rad")),
        _ => None,
    }
}

/// The unit an instrument code implies, as an assumption the options may replace.
fn code_unit(id: &str) -> Option<Stated> {
    let (quantity, why) = code_quantity(id)?;
    Some(Stated {
        assumed: true,
        ..Stated::in_file(quantity.unit(), why.to_string())
    })
}

/// Reads a miniSEED 2 file as a tilt time series.
pub(crate) fn read(path: &Path, opts: &ReadOptions) -> Result<TiltSeries, InputError> {
    let bytes = read_bytes(path)?;
    let (groups, text) = records(path, &bytes)?;
    drop(bytes);
    let ids: Vec<String> = groups.iter().map(|(id, _)| id.clone()).collect();
    let map = opts
        .axis_map
        .as_ref()
        .map(|m| full_map(path, m, &ids))
        .transpose()?;
    let origin = match &map {
        Some(m) => MapOrigin::Options(m),
        None => MapOrigin::Default,
    };
    let given = full_units(path, &opts.units, &ids)?;
    let mut unit_notes = Vec::new();
    let stated = series_units::merge_given(
        path,
        &ids,
        ids.iter().map(|id| code_unit(id)).collect(),
        &given,
        "channel",
        &mut unit_notes,
    )?;
    let motions = series_units::motions(path, &ids, &stated)?;
    let resolved = resolve(path, &ids, &motions, origin, "channel")?;
    let scales = full_scales(path, &opts.scale, &ids)?;
    let mut notes = vec![format!(
        "miniSEED 2: {} records, channels {}{}",
        groups.iter().map(|(_, v)| v.len()).sum::<usize>() + text,
        shown_list(&ids),
        if text > 0 {
            format!("; {text} ASCII log records skipped")
        } else {
            String::new()
        }
    )];
    notes.extend(resolved.notes.iter().cloned());
    notes.extend(unit_notes);

    let groups: Vec<Option<Vec<Placed>>> = groups.into_iter().map(|(_, v)| Some(v)).collect();
    let chans = merge_mapped(path, groups, &resolved)?;
    let span = common_span(path, &chans, &mut notes)?;
    check_tilt_units(path, &resolved, &chans, &stated, opts.quantity, &mut notes)?;
    let sensor_opts = ReadOptions {
        scale: scales.clone(),
        corrected: full_names(path, &opts.corrected, &ids)?,
        pendulum: full_names(path, &opts.pendulum, &ids)?,
        ..opts.clone()
    };
    let plan = series_units::plan(path, &resolved, &stated, &sensor_opts, &mut notes)?;
    let mut data = Vec::new();
    for (((m, ch), &k), planned) in resolved
        .channels
        .iter()
        .zip(&chans)
        .zip(&span.starts)
        .zip(&plan.channels)
    {
        let part = ChannelPart {
            start: k,
            len: span.len,
        };
        let v = channel_samples(path, m, ch, part, planned, &scales, opts, &mut notes)?;
        check_unstated_data(path, &m.source, planned, &v, span.rate)?;
        data.push(v);
    }
    notes.push(units_note(&plan));
    let provenance = Provenance {
        path: path.to_path_buf(),
        format: InputFormat::Miniseed,
        kind: InputKind::Series,
        quantity: plan.quantity,
        axis_map: resolved.map.to_string(),
        start_time: Some(chans[0].time(span.starts[0])),
        notes,
    };
    Ok(into_series(&plan, data, span.rate, provenance))
}

/// Merges the records of the mapped channels only (a file of many channels costs the memory of
/// three), each checked for its sample rate and the memory its samples take.
fn merge_mapped(
    path: &Path,
    mut groups: Vec<Option<Vec<Placed>>>,
    resolved: &Resolved,
) -> Result<Vec<Channel>, InputError> {
    let mut chans: Vec<Channel> = Vec::new();
    for m in &resolved.channels {
        let recs = groups[m.index].take().unwrap_or_default();
        let ch = channels::merge(&m.source, recs).map_err(|(at, msg)| fault(path, at, msg))?;
        check_sample_rate(
            path,
            || format!("the records of channel {}", ch.id),
            ch.sample_rate_hz,
        )?;
        let what = || format!("input file {}, channel {}", path.display(), m.source);
        check_memory(
            what,
            planned_bytes(ch.data.len(), SERIES_BYTES_PER_SAMPLE * 3),
        )?;
        chans.push(ch);
    }
    Ok(chans)
}

/// The stretch every mapped channel covers, on one time grid.
struct Span {
    /// The common sample rate (Hz).
    rate: f64,
    /// Per channel, its first sample in the span.
    starts: Vec<usize>,
    /// Samples in the span.
    len: usize,
}

/// One rate, one grid, the common span of `chans` (at least two samples), with a note when
/// it trims a channel.
fn common_span(
    path: &Path,
    chans: &[Channel],
    notes: &mut Vec<String>,
) -> Result<Span, InputError> {
    let first = &chans[0];
    let rate = first.sample_rate_hz;
    for ch in &chans[1..] {
        if ch.sample_rate_hz != rate {
            return Err(fault(
                path,
                None,
                format!(
                    "channel {} is sampled at {} Hz but {} at {rate} Hz; allowed: one sample \
                     rate for every mapped channel",
                    ch.id, ch.sample_rate_hz, first.id
                ),
            ));
        }
    }
    // The common record starts with the channel that starts last: every other channel is
    // judged against it (and named with it when its samples fall between its grid's).
    let latest = chans
        .iter()
        .max_by_key(|c| c.start_ns)
        .expect("at least one mapped channel");
    let start_ns = latest.start_ns;
    let tolerance = chans
        .iter()
        .map(|c| c.time_resolution_ns)
        .max()
        .unwrap_or(0) as f64;
    let mut starts = Vec::new();
    for ch in chans {
        let offset = (start_ns - ch.start_ns) as f64 / ch.period_ns();
        let k = offset.round();
        if (offset - k).abs() * ch.period_ns() > tolerance {
            return Err(fault(
                path,
                None,
                format!(
                    "channel {} starts at {} and {} at {}: their samples are not on one time \
                     grid ({rate} Hz); allowed: channels sampled at the same instants",
                    ch.id,
                    ch.time(0),
                    latest.id,
                    latest.time(0)
                ),
            ));
        }
        starts.push(k as usize);
    }
    let len = chans
        .iter()
        .zip(&starts)
        .map(|(c, &k)| c.data.len().saturating_sub(k))
        .min()
        .unwrap_or(0);
    require_two(
        path,
        "the common span of the mapped channels",
        len,
        "samples",
    )?;
    let trimmed = chans
        .iter()
        .zip(&starts)
        .any(|(c, &k)| k > 0 || c.data.len() != k + len);
    if trimmed {
        let ranges: Vec<String> = chans
            .iter()
            .map(|c| format!("{} {}..{}", c.id, c.time(0), c.time(c.data.len() - 1)))
            .collect();
        notes.push(format!(
            "channels cover different spans ({}); read over their common span {} to {} \
             ({len} samples)",
            ranges.join(", "),
            chans[0].time(starts[0]),
            chans[0].time(starts[0] + len - 1)
        ));
    }
    notes.push(format!("sample rate {rate} Hz from the records"));
    Ok(Span { rate, starts, len })
}

/// Notes the units the instrument codes imply (miniSEED stores none), and refuses a tilt
/// channel whose unit nothing gives: neither the options, nor the quantity, nor its code.
fn check_tilt_units(
    path: &Path,
    resolved: &Resolved,
    chans: &[Channel],
    stated: &[Option<Stated>],
    quantity: Option<Quantity>,
    notes: &mut Vec<String>,
) -> Result<(), InputError> {
    for (m, ch) in resolved.channels.iter().zip(chans) {
        match &stated[m.index] {
            Some(s) if s.assumed => notes.push(format!(
                "channel {}: {} (miniSEED stores no units)",
                ch.id, s.origin
            )),
            Some(_) => {}
            None if quantity.is_none() && m.tilt_axis().is_some() => {
                return Err(fault(
                    path,
                    None,
                    format!(
                        "channel {}: miniSEED stores no units and the instrument code (second \
                         letter of the channel code) is neither J (rotation sensor, rad/s) nor A \
                         (tiltmeter, rad); allowed: give its unit (units {}=rad/s) or the \
                         quantity explicitly (angle or rate)",
                        ch.id, ch.id
                    ),
                ))
            }
            None => {}
        }
    }
    Ok(())
}

/// Samples `start .. start + len` of a channel.
#[derive(Clone, Copy)]
struct ChannelPart {
    start: usize,
    len: usize,
}

/// The samples of channel `ch` (mapped by `m`, planned as `planned`) in `part`, scaled into
/// its unit, signed by the map and with gaps handled by the gap policy; notes for each
/// assumption.
#[allow(clippy::too_many_arguments)]
fn channel_samples(
    path: &Path,
    m: &Mapped,
    ch: &Channel,
    part: ChannelPart,
    planned: &Planned,
    scales: &[ChannelScale],
    opts: &ReadOptions,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, InputError> {
    let (k, len) = (part.start, part.len);
    let unit = planned.unit();
    match (scale_for(scales, &ch.id), ch.counts) {
        (Some(_), _) => {}
        (None, true) => {
            return Err(InputError::Scale {
                path: path.to_path_buf(),
                channel: ch.id.clone(),
                message: format!(
                    "holds digitizer counts ({}); allowed: give a scale CHANNEL=FACTOR with the \
                     {unit} per count of the instrument's response",
                    ch.encodings.join(", ")
                ),
            })
        }
        (None, false) => {
            notes.push(format!(
                "channel {}: {} samples taken to be in {unit} already (miniSEED stores no \
                 units); give a scale if they are not",
                ch.id,
                ch.encodings.join(", ")
            ));
        }
    }
    if opts.gaps == GapPolicy::Reject {
        if let Some(&(a, b)) = ch.gaps.iter().find(|&&(a, b)| b > k && a < k + len) {
            return Err(fault(
                path,
                None,
                format!(
                    "channel {}: no records for {} samples from {} to {} (sample indices \
                     {}..={} of the series); allowed: no gaps, or gap interpolation to bridge \
                     interior gaps linearly",
                    ch.id,
                    b - a,
                    ch.time(a),
                    ch.time(b - 1),
                    a.max(k) - k,
                    b.min(k + len) - 1 - k
                ),
            ));
        }
    }
    if !ch.gaps.is_empty() || ch.overlapping > 0 {
        notes.push(format!(
            "channel {}: {} records, {} gaps ({} samples, filled with NaN before the gap \
             policy), {} samples in identical overlaps kept once",
            ch.id,
            ch.records,
            ch.gaps.len(),
            ch.gaps.iter().map(|(a, b)| b - a).sum::<usize>(),
            ch.overlapping
        ));
    }
    let (s, factor) = (m.sign.factor(), planned.factor);
    let mut v: Vec<f64> = ch.data[k..k + len]
        .iter()
        .map(|x| s * (factor * x))
        .collect();
    let ctx = ChannelCtx {
        path,
        channel: &m.source,
        unit,
    };
    let bridged = process_channel(&mut v, opts.gaps, &ctx)?;
    if bridged > 0 {
        notes.push(gap_note(&m.source, bridged));
    }
    Ok(v)
}

#[cfg(test)]
mod tests;
