//! Time series of the floor's motion from CSV: header `time_s,CH1,CH2,...`, optional `#`
//! metadata lines.

use super::csv::{self, decimal_resolution, parse_field, CsvFile, Prelude};
use super::format_error::FormatError;
use super::series_units::{check_unstated_data, into_series, units_note};
use tiltnoise_core::error::Num;
use tiltnoise_core::input::{check_sample_rate, require_two, InputError};
use tiltnoise_core::input::{gap_note, process_channel, ChannelCtx, TiltSeries};
use tiltnoise_core::input::{GapPolicy, InputFormat, InputKind, Provenance, ReadOptions};

/// Reads the records of a CSV series whose prelude has been read (`prelude.header[0]` is
/// `time_s`).
pub(crate) fn read(
    mut file: CsvFile,
    prelude: Prelude,
    opts: &ReadOptions,
) -> Result<TiltSeries, InputError> {
    let path = file.path.clone();
    let csv::InterpretedSeries {
        resolved,
        plan,
        start_time,
        mut notes,
    } = csv::interpret_series(&path, &prelude, opts)?;

    let mut times: Vec<f64> = Vec::new();
    let mut resolution: Vec<f64> = Vec::new();
    let mut lines: Vec<usize> = Vec::new();
    let mut data: Vec<Vec<f64>> = vec![Vec::new(); resolved.channels.len()];
    file.for_each_record(prelude.header.len(), |line, fields| {
        let index = times.len();
        let t = match parse_field(fields[0]) {
            Ok(Some(t)) if t.is_finite() => t,
            _ => {
                return Err(FormatError::CsvNumber {
                    path: path.clone(),
                    line,
                    column: "time_s".to_string(),
                    text: fields[0].to_string(),
                    unit: "s",
                    empty_allowed: false,
                }
                .into())
            }
        };
        if let Some(&previous) = times.last() {
            if t <= previous {
                return Err(FormatError::TimeNotIncreasing {
                    path: path.clone(),
                    line,
                    index,
                    value: t,
                    previous,
                }
                .into());
            }
        }
        times.push(t);
        resolution.push(decimal_resolution(fields[0]));
        lines.push(line);
        for ((m, out), p) in resolved
            .channels
            .iter()
            .zip(data.iter_mut())
            .zip(&plan.channels)
        {
            let (factor, unit) = (p.factor, p.unit());
            let text = fields[m.index + 1];
            let raw = match parse_field(text) {
                Ok(Some(v)) => v,
                Ok(None) => f64::NAN,
                Err(()) => {
                    return Err(FormatError::CsvNumber {
                        path: path.clone(),
                        line,
                        column: m.source.clone(),
                        text: text.to_string(),
                        unit,
                        empty_allowed: true,
                    }
                    .into())
                }
            };
            if !raw.is_finite() && opts.gaps == GapPolicy::Reject {
                return Err(InputError::NonFinite {
                    path: path.clone(),
                    channel: m.source.clone(),
                    index,
                    value: raw,
                    unit,
                    line: Some(line),
                });
            }
            let value = m.sign.factor() * (factor * raw);
            let ctx = ChannelCtx {
                path: &path,
                channel: &m.source,
                unit,
            };
            ctx.check_sample(index, value, Some(line))?;
            out.push(value);
        }
        Ok(())
    })?;

    require_two(&path, "column time_s", times.len(), "samples")?;
    let dt = check_uniform(&path, &times, &resolution, &lines)?;
    let sample_rate_hz = check_sample_rate(
        &path,
        || format!("column time_s (dt = {} s)", Num(dt)),
        1.0 / dt,
    )?;
    notes.push(format!(
        "sample rate {sample_rate_hz} Hz from column time_s (dt = {dt} s, uniform within the \
         printed precision)"
    ));
    if times[0] != 0.0 {
        notes.push(format!("time_s starts at {} s", times[0]));
    }

    for ((m, ch), p) in resolved
        .channels
        .iter()
        .zip(data.iter_mut())
        .zip(&plan.channels)
    {
        let ctx = ChannelCtx {
            path: &path,
            channel: &m.source,
            unit: p.unit(),
        };
        let bridged = process_channel(ch, opts.gaps, &ctx)?;
        if bridged > 0 {
            notes.push(gap_note(&m.source, bridged));
        }
        check_unstated_data(&path, &m.source, p, ch, sample_rate_hz)?;
    }

    notes.push(units_note(&plan));
    let provenance = Provenance {
        path,
        format: InputFormat::Csv,
        kind: InputKind::Series,
        quantity: plan.quantity,
        axis_map: resolved.map.to_string(),
        start_time,
        notes,
    };
    Ok(into_series(&plan, data, sample_rate_hz, provenance))
}

/// Checks that the (strictly increasing) times are uniform and returns `dt`.
///
/// With `dt = (t_last - t_0) / (n - 1)` and every printed time `t_i` off the true time by at
/// most half its printed resolution `res_i`, the uniform grid `t_0 + i dt` built from the
/// printed end points is off the true grid by at most `max(res_0, res_last) / 2`. So row `i` is
/// accepted when `|t_i - (t_0 + i dt)| <= res_i / 2 + max(res_0, res_last) / 2 + 4 eps |t|max`.
fn check_uniform(
    path: &std::path::Path,
    times: &[f64],
    resolution: &[f64],
    lines: &[usize],
) -> Result<f64, InputError> {
    let n = times.len();
    let (t0, t_last) = (times[0], times[n - 1]);
    let dt = (t_last - t0) / (n - 1) as f64;
    let res_ends = resolution[0].max(resolution[n - 1]);
    let t_max = t0.abs().max(t_last.abs());
    for (i, (&t, &res)) in times.iter().zip(resolution).enumerate() {
        let expected = t0 + i as f64 * dt;
        let deviation = (t - expected).abs();
        let tolerance = 0.5 * res + 0.5 * res_ends + 4.0 * f64::EPSILON * t_max;
        if deviation > tolerance {
            return Err(FormatError::TimeNotUniform {
                path: path.to_path_buf(),
                line: lines[i],
                index: i,
                value: t,
                expected,
                deviation,
                tolerance,
                relative: tolerance / dt,
                dt,
            }
            .into());
        }
    }
    Ok(dt)
}
