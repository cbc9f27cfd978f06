//! The units of a time series' channels, for every series reader: what the file states (a
//! `# units:` line, `units` attributes, a miniSEED instrument code) merged with what the options
//! give (`ReadOptions::units`), what each unit says the channel measures (so that the default
//! axis map tells rotation from translation), and, once the channels are mapped, the plan of
//! each: its quantity, the factor into SI, and whether its unit was stated at all (a series
//! whose unit nobody states is checked against [`tiltnoise_core::input::unstated_rms_bound`]).

use super::meta::{decide_quantity, Declared};
use std::path::Path;
use tiltnoise_core::error::{shown_list, Shown};
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::input::{channel_motions, check_sensors, motion_of, scale_for, scale_note};
use tiltnoise_core::input::{parse_unit, Mapped, Provenance, TiltSeries};
use tiltnoise_core::input::{unstated_excess, DetrendedRms, UNITS_ALLOWED};
use tiltnoise_core::input::{
    ChannelUnit, GroundChannel, InputError, Motion, ParsedUnit, Quantity, ReadOptions,
};
use tiltnoise_core::input::{Resolved, Sensors, TranslationChannel, Unit};
use tiltnoise_core::model::Input;
use tiltnoise_core::option_key::OptionKey;

/// A channel's unit as stated, and where.
#[derive(Debug, Clone)]
pub(crate) struct Stated {
    /// The unit as written.
    pub text: String,
    /// What it says; `None` for a string that is no unit this reader knows (refused if the
    /// channel is read).
    pub parsed: Option<ParsedUnit>,
    /// Where it is stated, for messages: `line 2 (# units:)`, `attribute units of dataset /E`,
    /// `the units option`, `instrument code J (rotation sensor)`.
    pub origin: String,
    /// Inferred rather than stated (a miniSEED instrument code's quantity): the options may
    /// replace it, and the series is still checked as one whose unit nobody states.
    pub assumed: bool,
    /// The file holds digitizer counts: a scale factor is required, and `parsed` is what the
    /// scaled values are (from the options), if known.
    pub counts: bool,
}

impl Stated {
    /// A unit the file states at `origin`.
    pub fn in_file(text: &str, origin: String) -> Stated {
        let parsed = parse_unit(text);
        Stated {
            text: text.to_string(),
            counts: parsed == Some(ParsedUnit::Counts),
            parsed,
            origin,
            assumed: false,
        }
    }

    /// The physical unit, if one is known.
    pub fn unit(&self) -> Option<Unit> {
        match self.parsed {
            Some(ParsedUnit::Physical(u)) => Some(u),
            _ => None,
        }
    }
}

const GIVEN: &str = "the units option";

/// The units of the channels `available` of `path` (`kind`: `column`, `dataset`, `channel`):
/// the file's (`from_file[i]`), with the options' `given` (keyed by the names in `available`)
/// where the file states none, or where it states counts (the unit of the scaled values), or
/// where its unit is only inferred.
///
/// # Errors
///
/// [`InputError::ChannelUnit`] for a given unit of a channel the file does not have, or one
/// that disagrees with the unit the file states.
pub(crate) fn merge_given(
    path: &Path,
    available: &[String],
    mut from_file: Vec<Option<Stated>>,
    given: &[ChannelUnit],
    kind: &'static str,
    notes: &mut Vec<String>,
) -> Result<Vec<Option<Stated>>, InputError> {
    for g in given {
        let Some(i) = available.iter().position(|a| *a == g.channel) else {
            return Err(InputError::ChannelUnit {
                path: path.to_path_buf(),
                channel: g.channel.clone(),
                message: format!(
                    "is given the unit `{}`, but is not a {kind} of the file; available \
                     {kind}s: {}",
                    Shown(&g.text),
                    shown_list(available)
                )
                .into(),
            });
        };
        let mine = Stated {
            text: g.text.clone(),
            parsed: Some(ParsedUnit::Physical(g.unit)),
            origin: GIVEN.to_string(),
            assumed: false,
            counts: false,
        };
        from_file[i] = Some(match from_file[i].take() {
            None => mine,
            Some(s) if s.counts => Stated {
                counts: true,
                ..mine
            },
            Some(s) if s.assumed => {
                if s.unit() != Some(g.unit) {
                    notes.push(format!(
                        "channel `{}`: unit {} given explicitly (its {} says {})",
                        g.channel, g.text, s.origin, s.text
                    ));
                }
                mine
            }
            Some(s) if s.unit() == Some(g.unit) => s,
            Some(s) if s.origin == GIVEN => {
                return Err(InputError::ChannelUnit {
                    path: path.to_path_buf(),
                    channel: g.channel.clone(),
                    message: format!(
                        "is given the units `{}` and `{}` by {GIVEN}; allowed: one unit per \
                         channel",
                        Shown(&s.text),
                        Shown(&g.text)
                    )
                    .into(),
                })
            }
            Some(s) => {
                return Err(InputError::ChannelUnit {
                    path: path.to_path_buf(),
                    channel: g.channel.clone(),
                    message: format!(
                        "is in `{}` by the {}, but the units option gives `{}`; allowed: the \
                         unit the file states (leave the option out for this {kind}), or a \
                         file that states none",
                        Shown(&s.text),
                        s.origin,
                        Shown(&g.text)
                    )
                    .into(),
                })
            }
        });
    }
    Ok(from_file)
}

/// What each channel measures, by its stated unit or its SEED instrument code.
pub(crate) fn motions(
    path: &Path,
    available: &[String],
    stated: &[Option<Stated>],
) -> Result<Vec<Option<Motion>>, InputError> {
    let units: Vec<Option<Motion>> = stated
        .iter()
        .map(|s| s.as_ref().and_then(Stated::unit).map(|u| u.motion))
        .collect();
    channel_motions(path, available, &units)
}

/// One mapped channel as it will be read.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Planned {
    /// The input, its quantity and its sensor.
    pub channel: GroundChannel,
    /// Multiplies the values as stored into SI (unit prefix times scale), before the sign.
    pub factor: f64,
    /// Nobody states its unit (a tilt channel taken in rad or rad/s): checked against
    /// [`tiltnoise_core::input::unstated_rms_bound`] once read.
    pub unstated: bool,
}

impl Planned {
    /// The SI unit of its values.
    pub fn unit(&self) -> &'static str {
        self.channel.unit()
    }
}

/// The plan of every mapped channel of a series.
#[derive(Debug, Clone)]
pub(crate) struct Plan {
    /// The quantity of the tilt channels (angle when there are none).
    pub quantity: Quantity,
    /// One per `resolved.channels`, in that order.
    pub channels: Vec<Planned>,
    /// The sensors declared other than the default.
    pub sensors: Sensors,
}

/// Plans the mapped channels of `resolved` with their `stated` units (indexed by source
/// index): tilt channels share one quantity ([`decide_quantity`]: the options', else the
/// stated units', else angle); translation channels need a stated unit of length, velocity or
/// acceleration; factors are the units' prefixes times the options' scales (required for
/// counts); the sensors declared in the options must name mapped channels of the right motion
/// and be told apart ([`check_sensors`]). Appends the provenance notes.
pub(crate) fn plan(
    path: &Path,
    resolved: &Resolved,
    stated: &[Option<Stated>],
    opts: &ReadOptions,
    notes: &mut Vec<String>,
) -> Result<Plan, InputError> {
    let at = |m: &Mapped| stated[m.index].as_ref();
    for m in &resolved.channels {
        if let Some(s) = at(m).filter(|s| s.parsed.is_none()) {
            return Err(InputError::Units {
                path: path.to_path_buf(),
                location: s.origin.clone(),
                value: s.text.clone(),
                allowed: UNITS_ALLOWED,
            });
        }
    }
    let tilts: Vec<&Mapped> = resolved
        .channels
        .iter()
        .filter(|m| motion_of(m.input) == Motion::Rotation)
        .collect();
    let mut declared = Vec::new();
    let mut undeclared = Vec::new();
    for m in &tilts {
        match at(m) {
            Some(s) => declared.push(Declared {
                channel: m.source.clone(),
                unit: s.text.clone(),
                quantity: s.unit().and_then(|u| u.tilt_quantity()),
            }),
            _ => undeclared.push(m.source.clone()),
        }
    }
    let quantity = if tilts.is_empty() {
        Quantity::Angle
    } else {
        decide_quantity(path, opts.quantity, &declared, &undeclared, notes)?
    };
    let sensors = sensors(path, resolved, opts)?;
    let mut channels = Vec::new();
    for m in &resolved.channels {
        let s = at(m);
        let unit = s.and_then(Stated::unit);
        let ground_quantity = match m.input {
            Input::Tilt(_) => match quantity {
                Quantity::Angle => GroundQuantity::Displacement,
                Quantity::Rate => GroundQuantity::Velocity,
            },
            _ => match unit {
                Some(u) => u.quantity,
                None => {
                    return Err(InputError::ChannelUnit {
                        path: path.to_path_buf(),
                        channel: m.source.clone(),
                        message: tiltnoise_core::message!(
                            "feeds {}, a translation of the floor, and {}; allowed: a unit of \
                             length, velocity or acceleration (m, m/s, m/s^2 or a prefixed \
                             form), stated in the file (a `# units:` line, a `units` \
                             attribute) or with the units option ({})",
                            m.input.name(),
                            if s.is_some_and(|s| s.counts) {
                                "is in counts with no unit for its scaled values"
                            } else {
                                "has no unit"
                            },
                            OptionKey::UNITS.entry(&m.source, "m/s^2")
                        ),
                    })
                }
            },
        };
        let mut factor = unit.map_or(1.0, |u| u.factor);
        if let (Some(s), Some(u)) = (s, unit) {
            if u.factor != 1.0 {
                notes.push(scale_note(
                    &m.source,
                    u.factor,
                    &format!("units `{}` to {}", s.text, u.si()),
                ));
            }
        }
        let counts = s.is_some_and(|s| s.counts);
        let scale = scale_for(&opts.scale, &m.source);
        match (scale, counts) {
            (Some(f), _) => {
                factor *= f;
                notes.push(scale_note(&m.source, f, "given explicitly"));
            }
            (None, true) => {
                return Err(InputError::Scale {
                    path: path.to_path_buf(),
                    channel: m.source.clone(),
                    message: "is in counts; allowed: give a scale CHANNEL=FACTOR with the SI \
                              units (rad, rad/s, m, m/s or m/s^2) per count of the instrument's \
                              response"
                        .to_string(),
                })
            }
            (None, false) => {}
        }
        channels.push(Planned {
            channel: GroundChannel {
                input: m.input,
                quantity: ground_quantity,
                sensing: sensors.sensing(m.input),
            },
            factor,
            unstated: scale.is_none() && s.is_none_or(|s| s.assumed),
        });
    }
    let grounds: Vec<GroundChannel> = channels.iter().map(|p| p.channel).collect();
    if let Err(message) = check_sensors(&grounds) {
        let named = opts.pendulum.first().or(opts.corrected.first());
        return Err(InputError::Sensor {
            path: path.to_path_buf(),
            channel: named.cloned().unwrap_or_default(),
            message: format!("and the record's other channels: {message}"),
        });
    }
    Ok(Plan {
        quantity,
        channels,
        sensors,
    })
}

/// The sensors the options declare, by the mapped channels they name.
fn sensors(path: &Path, resolved: &Resolved, opts: &ReadOptions) -> Result<Sensors, InputError> {
    let mut sensors = Sensors::default();
    for (names, motion, what) in [
        (
            &opts.pendulum,
            Motion::Rotation,
            "read by a pendulum tiltmeter",
        ),
        (&opts.corrected, Motion::Translation, "corrected"),
    ] {
        for name in names {
            let m = resolved.channels.iter().find(|m| m.source == *name);
            let refuse = |message: String| InputError::Sensor {
                path: path.to_path_buf(),
                channel: name.clone(),
                message,
            };
            let Some(m) = m else {
                let mapped: Vec<&str> = resolved
                    .channels
                    .iter()
                    .map(|m| m.source.as_str())
                    .collect();
                return Err(refuse(format!(
                    "is declared {what}, but is not a channel the record reads; allowed: one of \
                     {}",
                    shown_list(&mapped)
                )));
            };
            match (m.tilt_axis(), m.translation_axis(), motion) {
                (Some(a), _, Motion::Rotation) => sensors.pendulum.push(a),
                (_, Some(t), Motion::Translation) => sensors.corrected.push(t),
                _ => {
                    return Err(refuse(format!(
                        "is declared {what}, but feeds {}; allowed: {} channels",
                        m.input.name(),
                        match motion {
                            Motion::Rotation => "tilt (rotation)",
                            Motion::Translation => "translation",
                        }
                    )))
                }
            }
        }
    }
    Ok(sensors)
}

/// Refuses a channel whose unit nobody states (`planned.unstated`) and whose detrended RMS
/// (`rms`, in the SI unit it is taken in) exceeds [`tiltnoise_core::input::unstated_rms_bound`] at `sample_rate_hz`:
/// its values are most likely in urad or nrad.
pub(crate) fn check_unstated(
    path: &Path,
    channel: &str,
    planned: &Planned,
    rms: f64,
    sample_rate_hz: f64,
) -> Result<(), InputError> {
    let quantity = match planned.channel.quantity {
        GroundQuantity::Displacement => Quantity::Angle,
        _ => Quantity::Rate,
    };
    if !planned.unstated {
        return Ok(());
    }
    let Some(excess) = unstated_excess(rms, quantity, sample_rate_hz) else {
        return Ok(());
    };
    Err(InputError::UnstatedUnit {
        path: path.to_path_buf(),
        channel: channel.to_string(),
        rms,
        quantity,
        bound: excess.bound,
        likely: if excess.likely.is_empty() {
            format!("a unit smaller than n{}", quantity.unit())
        } else {
            excess.likely.join(" or ")
        },
    })
}

/// [`check_unstated`] of a whole channel held in memory.
pub(crate) fn check_unstated_data(
    path: &Path,
    channel: &str,
    planned: &Planned,
    data: &[f64],
    sample_rate_hz: f64,
) -> Result<(), InputError> {
    if !planned.unstated {
        return Ok(());
    }
    check_unstated(
        path,
        channel,
        planned,
        DetrendedRms::of(data),
        sample_rate_hz,
    )
}

/// The units of the record's channels for the provenance: `theta_t: rad/s, x_t: m/s^2`.
pub(crate) fn units_note(plan: &Plan) -> String {
    let items: Vec<String> = plan
        .channels
        .iter()
        .map(|p| format!("{}: {}", p.channel.input.name(), p.unit()))
        .collect();
    format!(
        "channel units (after any prefix and scale): {}",
        items.join(", ")
    )
}

/// The series of the planned channels' `data` (one per planned channel, in SI, signed): tilt
/// channels as `axes` and `data`, translations as [`TranslationChannel`]s, with the plan's
/// sensors.
pub(crate) fn into_series(
    plan: &Plan,
    data: Vec<Vec<f64>>,
    sample_rate_hz: f64,
    mut provenance: Provenance,
) -> TiltSeries {
    let mut axes = Vec::new();
    let mut tilt = Vec::new();
    let mut translations = Vec::new();
    for (p, d) in plan.channels.iter().zip(data) {
        match p.channel.input {
            Input::Tilt(a) => {
                axes.push(a);
                tilt.push(d);
            }
            Input::Translation(axis) => translations.push(TranslationChannel {
                axis,
                quantity: p.channel.quantity,
                data: d,
            }),
            Input::Force(_) => unreachable!("axis maps feed the floor's inputs only"),
        }
    }
    provenance.quantity = plan.quantity;
    TiltSeries {
        sample_rate_hz,
        axes,
        data: tilt,
        translations,
        sensors: plan.sensors.clone(),
        provenance,
    }
}
