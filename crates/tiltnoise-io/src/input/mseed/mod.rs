//! Tilt time series from miniSEED 2 (`.mseed`, `.miniseed`, `.ms`), the FDSN format of
//! seismometers, tiltmeters and rotation sensors, decoded by this crate ([`record`], [`steim`]):
//! one channel per SEED code `NET.STA.LOC.CHA`, chosen with the axis map (full codes or bare
//! channel codes such as `LJE`; by default the rotation channels `?JE`, `?JN`, `?JZ`).
//!
//! miniSEED stores no units. The quantity comes from the options, else from the instrument
//! code (second letter of the channel code): `J` (rotation sensor) is a rate (rad/s), `A`
//! (tiltmeter) an angle (rad). Integer samples (INT16, INT32, Steim-1, Steim-2) are digitizer
//! counts and need a scale factor per channel ([`super::ChannelScale`]); floating-point
//! samples (FLOAT32, FLOAT64) are taken to be in rad or rad/s already, which the provenance
//! says. See `docs/input_formats.md`.

mod channels;
mod record;
mod steim;

use super::meta::{decide_quantity, Declared};
use super::{check_sample_rate, Provenance, Quantity, ReadOptions};
use super::{check_scales, gap_note, process_channel, require_two, scale_for, scale_note};
use super::{resolve, ChannelCtx, InputError, MapOrigin, TiltSeries};
use super::{AxisMap, AxisMapEntry, ChannelScale, GapPolicy, InputFormat, InputKind};
use channels::{Channel, Placed};
use std::io::Read;
use std::path::Path;
use tiltnoise_core::error::{shown_list, Shown};
use tiltnoise_core::limits::{
    check_file_len, check_memory, planned_bytes, MAX_DATA_FILE_BYTES, SERIES_BYTES_PER_SAMPLE,
};

/// What [`MAX_DATA_FILE_BYTES`] limits, for messages.
const DATA_FILE: &str = "a miniSEED input";

fn fault(path: &Path, record: Option<(usize, u64)>, message: String) -> InputError {
    InputError::Miniseed {
        path: path.to_path_buf(),
        record,
        message,
    }
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

/// The quantity an instrument code says: `J` rotation sensor -> rate, `A` tiltmeter -> angle.
fn code_quantity(id: &str) -> Option<(Quantity, &'static str)> {
    let cha = id.rsplit('.').next().unwrap_or("");
    match cha.as_bytes().get(1) {
        Some(b'J') => Some((Quantity::Rate, "instrument code J: rotation sensor, rad/s")),
        Some(b'A') => Some((Quantity::Angle, "instrument code A: tiltmeter, rad")),
        _ => None,
    }
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
    let resolved = resolve(path, &ids, origin, "channel")?;
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

    // Merge the mapped channels only: a file of many channels costs the memory of three.
    let mut groups: Vec<Option<Vec<Placed>>> = groups.into_iter().map(|(_, v)| Some(v)).collect();
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

    // One rate, one grid, the common span.
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
    let start_ns = chans.iter().map(|c| c.start_ns).max().unwrap_or(0);
    let mut spans = Vec::new();
    for ch in &chans {
        let offset = (start_ns - ch.start_ns) as f64 / ch.period_ns();
        let k = offset.round();
        let tolerance = chans
            .iter()
            .map(|c| c.time_resolution_ns)
            .max()
            .unwrap_or(0) as f64;
        if (offset - k).abs() * ch.period_ns() > tolerance {
            return Err(fault(
                path,
                None,
                format!(
                    "channel {} starts at {} and {} at {}: their samples are not on one time \
                     grid ({rate} Hz); allowed: channels sampled at the same instants",
                    ch.id,
                    ch.time(0),
                    first.id,
                    first.time(0)
                ),
            ));
        }
        spans.push(k as usize);
    }
    let len = chans
        .iter()
        .zip(&spans)
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
        .zip(&spans)
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
            chans[0].time(spans[0]),
            chans[0].time(spans[0] + len - 1)
        ));
    }
    notes.push(format!("sample rate {rate} Hz from the records"));

    // Quantity: the options, else the instrument codes.
    let mut declared = Vec::new();
    for ch in &chans {
        match code_quantity(&ch.id) {
            Some((q, why)) => {
                notes.push(format!(
                    "channel {}: {why} (miniSEED stores no units)",
                    ch.id
                ));
                declared.push(Declared {
                    channel: ch.id.clone(),
                    unit: q.unit().to_string(),
                    quantity: Some(q),
                    factor: 1.0,
                })
            }
            None if opts.quantity.is_none() => {
                return Err(fault(
                    path,
                    None,
                    format!(
                        "channel {}: miniSEED stores no units and the instrument code (second \
                         letter of the channel code) is neither J (rotation sensor, rad/s) nor A \
                         (tiltmeter, rad); allowed: give the quantity explicitly (angle or rate)",
                        ch.id
                    ),
                ))
            }
            None => {}
        }
    }
    let quantity = decide_quantity(path, opts.quantity, &declared, &[], &mut notes)?;
    let unit = quantity.unit();

    let mut data = Vec::new();
    for ((m, ch), &k) in resolved.channels.iter().zip(&chans).zip(&spans) {
        let factor = match (scale_for(&scales, &ch.id), ch.counts) {
            (Some(f), _) => {
                notes.push(scale_note(&ch.id, f, "given explicitly"));
                f
            }
            (None, true) => {
                return Err(InputError::Scale {
                    path: path.to_path_buf(),
                    channel: ch.id.clone(),
                    message: format!(
                        "holds digitizer counts ({}); allowed: give a scale CHANNEL=FACTOR \
                         with the {unit} per count of the instrument's response",
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
                1.0
            }
        };
        if opts.gaps == GapPolicy::Reject {
            if let Some(&(a, b)) = ch.gaps.iter().find(|&&(a, b)| b > k && a < k + len) {
                return Err(fault(
                    path,
                    None,
                    format!(
                        "channel {}: no records for {} samples from {} to {} (sample indices \
                         {}..={} of the series); allowed: no gaps, or gap interpolation to \
                         bridge interior gaps linearly",
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
        let s = m.sign.factor();
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
        data.push(v);
    }
    Ok(TiltSeries {
        sample_rate_hz: rate,
        axes: resolved.channels.iter().map(|m| m.axis).collect(),
        data,
        provenance: Provenance {
            path: path.to_path_buf(),
            format: InputFormat::Miniseed,
            kind: InputKind::Series,
            quantity,
            axis_map: resolved.map.to_string(),
            start_time: Some(chans[0].time(spans[0])),
            notes,
        },
    })
}

#[cfg(test)]
mod tests;
