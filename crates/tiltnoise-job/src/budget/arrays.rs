//! The floor's motion handed over as arrays (the Python package's `budget(tilt, fs)`): one
//! channel per input, described as the readers describe a file's channels (the unit of each,
//! the quantity of the tilt, the sensors), then checked for gaps, out-of-range samples and
//! units that are likely wrong, and read as a series. The caller only converts its arrays.
//!
//! The refusals ([`ArrayError`]) name the record `tilt` and its channels by input, in the
//! spelling of the one front end that hands over arrays (`tilt["eta_t"][100]`); the options
//! they name are spelled as the front end in use spells them.

use crate::error::JobError;
use std::fmt;
use std::path::Path;
use tiltnoise_core::cancel::Cancel;
use tiltnoise_core::error::Num;
use tiltnoise_core::ground::GroundQuantity;
use tiltnoise_core::input::{
    check_sensors, chunk_of, gap_note, ground_index, ground_inputs, motion_of, process_channel,
    unstated_excess, ChannelCtx, ChannelUnit, DetrendedRms, GapPolicy, GroundChannel, InputError,
    InputMeta, Motion, Quantity, Sensors, SeriesSource, UnstatedExcess,
};
use tiltnoise_core::limits::SAMPLE_RATES;
use tiltnoise_core::model::Input;
use tiltnoise_core::option_key::OptionKey;
use tiltnoise_core::repeats::refuse_repeats;

/// The `path` of a record of arrays, as its messages and the budget files name it.
pub const ARRAYS_PATH: &str = "(arrays)";

/// The `format` the budget files record for arrays (the Python package hands over numpy
/// arrays).
pub const ARRAYS_FORMAT: &str = "numpy";

/// What the caller says of its arrays besides the samples (by default: tilt angles in rad,
/// no translation, default sensors, gaps refused).
#[derive(Debug, Clone)]
pub struct ArrayOptions {
    /// The quantity of the tilt inputs without a unit (angle, rad; or rate, rad/s).
    pub quantity: Quantity,
    /// The units given, by input (`eta_t` = `urad`); every translation needs one.
    pub units: Vec<ChannelUnit>,
    /// Translation inputs whose tilt part is removed already.
    pub corrected: Vec<String>,
    /// Tilt inputs read by a pendulum tiltmeter.
    pub pendulum_tiltmeter: Vec<String>,
    /// Non-finite samples: refused (default) or bridged linearly.
    pub gaps: GapPolicy,
}

impl Default for ArrayOptions {
    fn default() -> Self {
        Self {
            quantity: Quantity::Angle,
            units: Vec::new(),
            corrected: Vec::new(),
            pendulum_tiltmeter: Vec::new(),
            gaps: GapPolicy::default(),
        }
    }
}

/// The floor's motion as arrays, described: a channel per input in canonical order, each
/// with its unit's factor into SI, all of one length. Built by [`ArrayRecord::new`], which
/// refuses what does not describe a record; its samples are checked when the budget runs.
#[derive(Debug, Clone)]
pub struct ArrayRecord {
    sample_rate_hz: f64,
    /// The samples, one channel per entry of `described.channels`, in the units given.
    data: Vec<Vec<f64>>,
    described: Described,
    gaps: GapPolicy,
    /// The notes of [`ArrayRecord::check_samples`] (gaps bridged).
    notes: Vec<String>,
}

/// What the arrays are: a channel per input, the factor of its unit into SI, the quantity of
/// the tilt and the provenance note on the units.
#[derive(Debug, Clone)]
struct Described {
    channels: Vec<GroundChannel>,
    /// `(factor into SI, unit given)` per channel.
    factors: Vec<(f64, bool)>,
    /// The quantity of the tilt inputs.
    quantity: Quantity,
    units_note: String,
}

/// Why arrays are not a record of the floor's motion.
#[derive(Debug)]
pub enum ArrayError {
    /// A name that is no input of the floor.
    NotAnInput {
        /// The name given.
        name: String,
    },
    /// No channel at all.
    NoInput,
    /// A sample rate outside [`SAMPLE_RATES`].
    SampleRate {
        /// The rate given (Hz).
        fs_hz: f64,
    },
    /// A unit given for an input the record does not have.
    UnitOfNoInput {
        /// The input named.
        channel: String,
        /// The record's inputs.
        inputs: Vec<Input>,
    },
    /// An input listed as `corrected` or `pendulum_tiltmeter` that is not one of the record's
    /// inputs of that motion.
    NotASensorOf {
        /// The list.
        option: OptionKey,
        /// The input named.
        name: String,
        /// The motion its sensors sense.
        motion: Motion,
        /// The record's inputs of that motion.
        inputs: Vec<Input>,
    },
    /// A unit of a rotation given to a translation, or the other way.
    UnitOfOtherMotion {
        /// The input.
        input: Input,
        /// The unit as given.
        unit: String,
        /// The motion of the unit.
        unit_motion: Motion,
    },
    /// A translation without a unit.
    TranslationWithoutUnit {
        /// The input.
        input: Input,
    },
    /// Tilt inputs in different quantities.
    TiltQuantities {
        /// The first tilt input and its quantity.
        first: (Input, Quantity),
        /// The one in another quantity.
        other: (Input, Quantity),
    },
    /// Sensors that cannot be corrected with the record's channels.
    Sensors(String),
    /// Channels of different lengths.
    Lengths {
        /// The first channel and its length.
        first: (Input, usize),
        /// The next one, of another length.
        other: (Input, usize),
    },
    /// A sample that is not finite (or out of range), or a gap that cannot be bridged.
    Samples(Box<InputError>),
    /// A tilt input without a unit whose values are too large for its quantity's SI unit.
    Unstated {
        /// The input.
        input: Input,
        /// The quantity it is read in.
        quantity: Quantity,
        /// By how much.
        excess: UnstatedExcess,
    },
}

/// `a, b, c`: the names of `inputs`.
fn names(inputs: &[Input]) -> String {
    inputs
        .iter()
        .map(|i| i.name())
        .collect::<Vec<_>>()
        .join(", ")
}

impl fmt::Display for ArrayError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let units = OptionKey::UNITS;
        match self {
            ArrayError::NotAnInput { name } => write!(
                f,
                "input {name:?} is not allowed: must be a tilt axis theta_t, eta_t or phi_t (the \
                 rotation taking the floor frame to the inertial frame) or a floor translation \
                 x_t, y_t or z_t"
            ),
            ArrayError::SampleRate { fs_hz } => write!(
                f,
                "{} = {} Hz is not allowed: the sample rate must be {} (the spectra would leave \
                 the range of f64; see docs/limits.md)",
                OptionKey::FS,
                Num(*fs_hz),
                SAMPLE_RATES.allowed("Hz")
            ),
            ArrayError::NoInput => write!(
                f,
                "{}: no input given; give at least one of {}",
                OptionKey::TILT,
                tiltnoise_core::options::floor_input_names()
            ),
            ArrayError::UnitOfNoInput { channel, inputs } => write!(
                f,
                "{units}: {channel:?} is not an input of tilt; it has {}",
                names(inputs)
            ),
            ArrayError::NotASensorOf {
                option,
                name,
                motion,
                inputs,
            } => write!(
                f,
                "{option}: {name:?} is not allowed: must be one of the {} inputs of tilt ({})",
                motion.name(),
                names(inputs)
            ),
            ArrayError::UnitOfOtherMotion {
                input,
                unit,
                unit_motion,
            } => write!(
                f,
                "{units}: {} is a {} of the floor, and {unit:?} is a unit of {}",
                input.name(),
                motion_of(*input).name(),
                unit_motion.name()
            ),
            ArrayError::TranslationWithoutUnit { input } => write!(
                f,
                "{units}: the translation {} has no unit; allowed: m, m/s, m/s^2 or a prefixed \
                 form, e.g. {}",
                input.name(),
                units.entry(input.name(), "m/s^2")
            ),
            ArrayError::TiltQuantities { first, other } => write!(
                f,
                "{units}: tilt inputs {} and {} are in different quantities ({} and {}); \
                 allowed: one quantity for every tilt input",
                first.0.name(),
                other.0.name(),
                first.1.unit(),
                other.1.unit()
            ),
            ArrayError::Sensors(e) => write!(f, "tilt: {e}"),
            ArrayError::Lengths { first, other } => write!(
                f,
                "tilt: {} has {} samples but {} has {}: the axes must have equal length",
                first.0.name(),
                first.1,
                other.0.name(),
                other.1
            ),
            ArrayError::Samples(e) => match e.as_ref() {
                InputError::NonFinite {
                    channel,
                    index,
                    value,
                    unit,
                    ..
                } => write!(
                    f,
                    "tilt[{channel:?}][{index}] is {value:?} {unit}; allowed: finite values (or \
                     {} to bridge interior gaps linearly)",
                    OptionKey::GAPS.given("\"interpolate\"")
                ),
                InputError::OutOfRange {
                    channel,
                    index,
                    value,
                    unit,
                    ..
                } => write!(
                    f,
                    "tilt[{channel:?}][{index}] is {} {unit}; allowed: {} (beyond that the \
                     spectra overflow or underflow f64; see docs/limits.md)",
                    Num(*value),
                    tiltnoise_core::limits::SAMPLES.allowed(unit)
                ),
                InputError::EdgeGap {
                    channel,
                    edge,
                    first,
                    last,
                    len,
                    ..
                } => write!(
                    f,
                    "tilt[{channel:?}] has a {edge} gap of non-finite samples at indices \
                     {first}..={last} (of {len}); gap interpolation needs a finite sample on \
                     both sides: trim the series"
                ),
                other => write!(f, "{other}"),
            },
            ArrayError::Unstated {
                input,
                quantity,
                excess,
            } => {
                let name = input.name();
                let unit = quantity.unit();
                let first = excess.likely.first().map_or("nrad", String::as_str);
                write!(
                    f,
                    "tilt[{name:?}] has no unit and is read in {unit}, but its detrended RMS is \
                     {} {unit}, above the {} {unit} no laboratory floor reaches; its values are \
                     likely in {}: give its unit, e.g. {}",
                    Num(excess.rms),
                    Num(excess.bound),
                    if excess.likely.is_empty() {
                        "a smaller unit".to_string()
                    } else {
                        excess.likely.join(" or ")
                    },
                    units.entry(name, first)
                )
            }
        }
    }
}

impl std::error::Error for ArrayError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ArrayError::Samples(e) => Some(e.as_ref()),
            _ => None,
        }
    }
}

impl From<ArrayError> for JobError {
    fn from(e: ArrayError) -> JobError {
        JobError::Arrays(Box::new(e))
    }
}

/// The input of the floor named `name` (`theta_t` .. `phi_t`, `x_t` .. `z_t`).
///
/// # Errors
///
/// [`ArrayError::NotAnInput`] naming what is allowed.
pub fn array_input(name: &str) -> Result<Input, JobError> {
    ground_inputs()
        .into_iter()
        .find(|a| a.name() == name)
        .ok_or_else(|| {
            ArrayError::NotAnInput {
                name: name.to_string(),
            }
            .into()
        })
}

impl ArrayRecord {
    /// The record of `channels` (`(input, samples)`, each input once, in any order) sampled
    /// at `sample_rate_hz` (within [`SAMPLE_RATES`]), described by `options` as the readers
    /// describe a file: each channel's unit (given, or the tilt's `quantity`), the sensors of
    /// the inputs listed `corrected` and `pendulum_tiltmeter`, all channels of one length.
    ///
    /// # Errors
    ///
    /// [`JobError::Arrays`] naming the input, unit or list that does not fit;
    /// [`JobError::Repeated`] for an input given twice.
    pub fn new(
        sample_rate_hz: f64,
        mut channels: Vec<(Input, Vec<f64>)>,
        options: ArrayOptions,
    ) -> Result<ArrayRecord, JobError> {
        if !SAMPLE_RATES.admits(sample_rate_hz) {
            return Err(ArrayError::SampleRate {
                fs_hz: sample_rate_hz,
            }
            .into());
        }
        let inputs: Vec<Input> = channels.iter().map(|(i, _)| *i).collect();
        refuse_repeats(OptionKey::AXES, "input", &inputs, |a| a.name().to_string())
            .map_err(JobError::Repeated)?;
        channels.sort_by_key(|(a, _)| ground_index(*a));
        if channels.is_empty() {
            return Err(ArrayError::NoInput.into());
        }
        let described = describe(&channels, &options)?;
        for w in channels.windows(2) {
            if w[0].1.len() != w[1].1.len() {
                return Err(ArrayError::Lengths {
                    first: (w[0].0, w[0].1.len()),
                    other: (w[1].0, w[1].1.len()),
                }
                .into());
            }
        }
        Ok(ArrayRecord {
            sample_rate_hz,
            data: channels.into_iter().map(|(_, d)| d).collect(),
            described,
            gaps: options.gaps,
            notes: Vec::new(),
        })
    }

    /// Makes every channel SI: scaled from its unit, its gaps refused or bridged as the
    /// options say (noted), and a tilt input without a unit refused when its values are too
    /// large for its quantity's. Each step is a pass over a whole channel; `cancel` is polled
    /// between them. Called once, before [`ArrayRecord::into_series`].
    pub(super) fn check_samples(&mut self, cancel: &Cancel) -> Result<(), JobError> {
        let d = &self.described;
        for ((samples, channel), &(factor, stated)) in
            self.data.iter_mut().zip(&d.channels).zip(&d.factors)
        {
            cancel.check().map_err(|_| JobError::Cancelled)?;
            let name = channel.input.name();
            if factor != 1.0 {
                samples.iter_mut().for_each(|v| *v *= factor);
            }
            let ctx = ChannelCtx {
                path: Path::new("tilt"),
                channel: name,
                unit: channel.unit(),
            };
            let bridged = process_channel(samples, self.gaps, &ctx)
                .map_err(|e| ArrayError::Samples(Box::new(e)))?;
            if bridged > 0 {
                self.notes.push(gap_note(name, bridged));
            }
            if !stated {
                cancel.check().map_err(|_| JobError::Cancelled)?;
                let rms = DetrendedRms::of(samples);
                if let Some(excess) = unstated_excess(rms, d.quantity, self.sample_rate_hz) {
                    return Err(ArrayError::Unstated {
                        input: channel.input,
                        quantity: d.quantity,
                        excess,
                    }
                    .into());
                }
            }
        }
        Ok(())
    }

    /// The series ([`ArrayRecord::check_samples`] made it SI) and its provenance: the notes
    /// of its samples, then the units'.
    pub(super) fn into_series(self) -> (impl SeriesSource + Send, InputMeta) {
        let ArrayRecord {
            sample_rate_hz,
            data,
            described:
                Described {
                    channels,
                    quantity,
                    units_note,
                    ..
                },
            mut notes,
            ..
        } = self;
        notes.push(units_note);
        let input = InputMeta {
            path: ARRAYS_PATH.into(),
            format: ARRAYS_FORMAT.into(),
            kind: "series".into(),
            quantity: quantity.name().into(),
            axis_map: channels
                .iter()
                .map(|c| format!("{0}={0}", c.input.name()))
                .collect::<Vec<_>>()
                .join(","),
            start_time: None,
            notes,
        };
        let series = ArraySeries {
            sample_rate_hz,
            channels,
            data,
        };
        (series, input)
    }
}

/// The description of `channels` (canonical order, at least one) by `options`, as the
/// readers describe a file's.
fn describe(channels: &[(Input, Vec<f64>)], options: &ArrayOptions) -> Result<Described, JobError> {
    let units = &options.units;
    let inputs: Vec<Input> = channels.iter().map(|(i, _)| *i).collect();
    for u in units {
        if !inputs.iter().any(|i| i.name() == u.channel) {
            return Err(ArrayError::UnitOfNoInput {
                channel: u.channel.clone(),
                inputs,
            }
            .into());
        }
    }
    let sensors = sensors(&inputs, options)?;
    let mut tilt_quantity: Option<(Quantity, Input)> = None;
    let mut out = Vec::new();
    let mut factors = Vec::new();
    for &input in &inputs {
        let given = units.iter().find(|u| u.channel == input.name());
        if let Some(u) = given {
            if u.unit.motion != motion_of(input) {
                return Err(ArrayError::UnitOfOtherMotion {
                    input,
                    unit: u.text.clone(),
                    unit_motion: u.unit.motion,
                }
                .into());
            }
        }
        let quantity = match (input, given) {
            (Input::Translation(_), None) => {
                return Err(ArrayError::TranslationWithoutUnit { input }.into())
            }
            (Input::Translation(_), Some(u)) => u.unit.quantity,
            (_, given) => {
                let q = given
                    .and_then(|u| u.unit.tilt_quantity())
                    .unwrap_or(options.quantity);
                match tilt_quantity {
                    Some((other, first)) if other != q => {
                        return Err(ArrayError::TiltQuantities {
                            first: (first, other),
                            other: (input, q),
                        }
                        .into())
                    }
                    _ => tilt_quantity = Some((q, input)),
                }
                match q {
                    Quantity::Angle => GroundQuantity::Displacement,
                    Quantity::Rate => GroundQuantity::Velocity,
                }
            }
        };
        out.push(GroundChannel {
            input,
            quantity,
            sensing: sensors.sensing(input),
        });
        factors.push((given.map_or(1.0, |u| u.unit.factor), given.is_some()));
    }
    check_sensors(&out).map_err(ArrayError::Sensors)?;
    let units_note = format!(
        "units: {}",
        out.iter()
            .zip(&factors)
            .map(|(c, (_, given))| format!(
                "{} {}{}",
                c.input.name(),
                c.unit(),
                if *given { "" } else { " (assumed)" }
            ))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(Described {
        channels: out,
        factors,
        quantity: tilt_quantity.map_or(options.quantity, |(q, _)| q),
        units_note,
    })
}

/// The sensors of the inputs `options` lists as `corrected` and `pendulum_tiltmeter`, each
/// once and each one of `inputs` of the motion its sensor senses.
fn sensors(inputs: &[Input], options: &ArrayOptions) -> Result<Sensors, JobError> {
    let mut sensors = Sensors::default();
    for (option, names, motion) in [
        (
            OptionKey::CORRECTED,
            &options.corrected,
            Motion::Translation,
        ),
        (
            OptionKey::PENDULUM_TILTMETER,
            &options.pendulum_tiltmeter,
            Motion::Rotation,
        ),
    ] {
        refuse_repeats(option, "input", names, |n| n.clone()).map_err(JobError::Repeated)?;
        for name in names {
            let input = array_input(name)?;
            if !inputs.contains(&input) || motion_of(input) != motion {
                return Err(ArrayError::NotASensorOf {
                    option,
                    name: name.clone(),
                    motion,
                    inputs: inputs
                        .iter()
                        .copied()
                        .filter(|i| motion_of(*i) == motion)
                        .collect(),
                }
                .into());
            }
            match input {
                Input::Tilt(a) => sensors.pendulum.push(a),
                Input::Translation(t) => sensors.corrected.push(t),
                Input::Force(_) => unreachable!("ground inputs only"),
            }
        }
    }
    Ok(sensors)
}

/// A record of arrays as a series: one channel per input, in canonical order, each in the SI
/// unit of its quantity; its chunks cut by core's one rule for records in memory
/// ([`chunk_of`]), as a series read whole is.
struct ArraySeries {
    sample_rate_hz: f64,
    channels: Vec<GroundChannel>,
    data: Vec<Vec<f64>>,
}

impl SeriesSource for ArraySeries {
    fn sample_rate_hz(&self) -> f64 {
        self.sample_rate_hz
    }

    fn len(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    fn channels(&self) -> Vec<GroundChannel> {
        self.channels.clone()
    }

    fn read_chunk(&mut self, start: usize, len: usize) -> Result<Vec<Vec<f64>>, InputError> {
        let channels: Vec<&[f64]> = self.data.iter().map(Vec::as_slice).collect();
        chunk_of(&channels, Path::new(ARRAYS_PATH), start, len)
    }
}
