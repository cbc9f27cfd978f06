//! Floor-tilt inputs as data: tilt **time series** and tilt **spectra**, their conventions, the
//! channel-to-axis map, rate to angle, gaps, provenance and the typed [`InputError`]. The
//! readers that fill them from HDF5 or CSV files are in `tiltnoise-io` (`tiltnoise_io::input`);
//! this module reads no file. The exact file layouts are documented in `docs/input_formats.md`.
//!
//! # Conventions
//!
//! **Tilt sign.** The crate's tilt `t = (theta_t, eta_t, phi_t)` (rad) is the small
//! right-handed rotation taking the **floor** frame to the **inertial** frame: the floor itself
//! rotates by `-t` (see [`crate::model::tilt`]). Lab axes: `x`, `y` horizontal (the crossbar
//! arm along `y`, the test mass at `(0, -d, .)`; `x` perpendicular to the arm, the test mass's
//! X), `z` up. Every value returned by this module is `t` in
//! this convention: a series in rad (angle) or rad/s (its rate), spectra as one-sided PSD/CSD
//! of the angle in rad²/Hz.
//!
//! **Instrument axes and the default mapping.** Seismological rotation channels give the
//! right-handed rotation (or rotation rate) *of the ground* about North, East (and Up). Unless
//! an axis map is given, `tiltnoise` **assumes** lab `x` = East, `y` = North, `z` = Up, so
//!
//! ```text
//! theta_t = -E,   eta_t = -N,   phi_t = -Z
//! ```
//!
//! (the minus because `t` is minus the floor rotation). Channels named `E`, `N`, `Z`, or with
//! a SEED rotation-sensor code `?JE`, `?JN`, `?JZ` (band letter, instrument `J`, orientation;
//! e.g. `LJE`), are mapped this way; channels already named `theta_t`, `eta_t`, `phi_t` map to
//! themselves with `+1`. Other channels are ignored (listed in the provenance notes). Two
//! channels qualifying for one axis are an error ([`InputError::AmbiguousAxis`]).
//!
//! **Axis map.** An explicit [`AxisMap`] (from [`ReadOptions::axis_map`], or from the file:
//! HDF5 root attribute `axis_map`, CSV line `# axes: ...`; the options win) replaces the
//! default: `theta_t=-E,eta_t=-N` means `theta_t = -(channel E)`, `eta_t = -(channel N)`. Each
//! target is `[+|-]SOURCE`; only the mapped axes are read.
//!
//! **Quantity.** A channel is a tilt angle (rad) or a tilt rate (rad/s) ([`Quantity`]). The
//! quantity comes from [`ReadOptions::quantity`] if given (it overrides the file, with a note),
//! else from the file's metadata (HDF5 attribute `units` on each channel dataset: `rad` or
//! `rad/s`; CSV: a `# units:` line), else it **defaults to angle** and the provenance says so.
//! A rate is **kept as a rate** in a time series ([`TiltSeries::quantity`],
//! [`SeriesSource::channels`]) and converted to angle where spectra are formed: its one-sided
//! CSD divided by `(2 pi f)²` at every `f > 0`, exactly up to Nyquist; the DC bin carries no
//! angle information and is excluded ([`rate`]). Spectra of a rate are divided by `(2 pi f)²`
//! as they are read.
//!
//! **Translation.** A channel whose unit is one of length, velocity or acceleration ([`Unit`],
//! [`ChannelUnit`] for files that state none) is the floor's translation `x_t`, `y_t`, `z_t`
//! ([`TranslationChannel`]); inertial sensors sense tilt too, and [`GroundMap`] carries every
//! channel's spectra to the inputs' displacements with that corrected ([`motion`]). A tilt
//! channel whose unit nobody states is bounded ([`unstated_rms_bound`]).
//!
//! **Gaps.** NaN or infinite samples are refused ([`InputError::NonFinite`], naming channel
//! and sample index) unless [`GapPolicy::Interpolate`] is selected: then each interior run of
//! non-finite samples is replaced by the straight line between its finite neighbours, in the
//! signed channel; a run touching either end is an error
//! ([`InputError::EdgeGap`]). In CSV an empty field is a non-finite sample.
//!
//! # What the readers return
//!
//! * [`TiltInput`]: a [`TiltSeries`] or [`TiltSpectra`], each with its [`Provenance`] for the
//!   output files.
//! * A [`SeriesSource`]: chunked, sequential access to a series (the noise budget streams long
//!   records through it); [`TiltSeries`] is one, held in memory.

mod axis_map;
mod error;
pub mod motion;
pub mod rate;
mod scale;
mod series;
mod source;
mod spectra;
mod unit;

pub use axis_map::{
    channel_motions, default_assignment, ground_index, ground_inputs, instrument_motion, motion_of,
    resolve, AxisMap, AxisMapEntry, MapOrigin, Mapped, Resolved, Sign,
};
pub use error::{check_sample_rate, require_two, InputError};
pub use motion::{check_sensors, GroundChannel, GroundMap, Sensing, Sensors};
pub use scale::{check_scales, scale_for, scale_note, ChannelScale};
pub use series::{
    gap_note, process_channel, ChannelCtx, Gap, GapScanner, TiltSeries, TranslationChannel,
};
pub use source::{chunk_of, SeriesSource};
pub use spectra::{assemble, check_csd_finite, frequency_refusal, TiltSpectra, CSD_RTOL};
pub use unit::{
    likely_units, normalize_unit, parse_unit, si_unit, unstated_excess, unstated_rms_bound,
    ChannelUnit, DetrendedRms, Motion, ParsedUnit, Unit, UnstatedExcess, PHYSICAL_UNITS,
    UNITS_ALLOWED, UNSTATED_ANGLE_RMS_MAX_RAD,
};

use crate::error::Shown;
use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

/// Schema name of HDF5 tilt time series (root attribute `schema`, optional).
pub const SCHEMA_TILT_SERIES: &str = "tiltnoise.tilt_series";
/// Schema name of HDF5 tilt spectra (root attribute `schema`, optional).
pub const SCHEMA_TILT_SPECTRA: &str = "tiltnoise.tilt_spectra";
/// The schema version these readers understand (root attribute `schema_version`, optional).
pub const INPUT_SCHEMA_VERSION: i64 = 1;

/// What the accepted layouts are, for error messages.
pub const ACCEPTED_LAYOUTS: &str = "HDF5 time series (root attribute sample_rate_hz, \
     one 1-D dataset per channel), HDF5 spectra (datasets /frequency_hz and /asd or /csd, root \
     attribute axes), CSV time series (header starting with time_s), CSV spectra (header \
     starting with freq_hz), miniSEED 2 time series (.mseed, .miniseed, .ms); see \
     docs/input_formats.md";

/// Physical quantity of the input channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// Tilt angle, rad (spectra: rad/sqrt(Hz) or rad²/Hz).
    Angle,
    /// Tilt rate, rad/s (spectra: rad/s/sqrt(Hz) or rad²/s²/Hz); converted to angle in the
    /// frequency domain ([`rate`]).
    Rate,
}

impl Quantity {
    /// `angle` or `rate`.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Angle => "angle",
            Quantity::Rate => "rate",
        }
    }

    /// Unit of a time-series sample: `rad` or `rad/s`.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Angle => "rad",
            Quantity::Rate => "rad/s",
        }
    }

    /// Unit of an amplitude spectral density value: `rad/sqrt(Hz)` or `rad/s/sqrt(Hz)`.
    pub fn asd_unit(self) -> &'static str {
        match self {
            Quantity::Angle => "rad/sqrt(Hz)",
            Quantity::Rate => "rad/s/sqrt(Hz)",
        }
    }

    /// Unit of a cross-spectral density value: `rad^2/Hz` or `rad^2/s^2/Hz`.
    pub fn csd_unit(self) -> &'static str {
        match self {
            Quantity::Angle => "rad^2/Hz",
            Quantity::Rate => "rad^2/s^2/Hz",
        }
    }
}

impl fmt::Display for Quantity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Quantity {
    type Err = String;
    /// `angle` or `rate` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "angle" => Ok(Quantity::Angle),
            "rate" => Ok(Quantity::Rate),
            _ => Err(format!(
                "quantity `{}` is not allowed: must be angle (rad) or rate (rad/s)",
                Shown(s)
            )),
        }
    }
}

/// What to do with NaN or infinite samples in a time series.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum GapPolicy {
    /// Refuse the file, naming the channel and the sample index (default).
    #[default]
    Reject,
    /// Bridge interior gaps linearly between the finite neighbours; gaps at either end are
    /// still an error.
    Interpolate,
}

impl GapPolicy {
    /// `reject` or `interpolate`.
    pub fn name(self) -> &'static str {
        match self {
            GapPolicy::Reject => "reject",
            GapPolicy::Interpolate => "interpolate",
        }
    }
}

impl FromStr for GapPolicy {
    type Err = String;
    /// `reject` or `interpolate` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "reject" => Ok(GapPolicy::Reject),
            "interpolate" => Ok(GapPolicy::Interpolate),
            _ => Err(format!(
                "gap policy `{}` is not allowed: must be reject or interpolate",
                Shown(s)
            )),
        }
    }
}

/// How to read a tilt input. `Default` = default axis mapping, quantity from the file (else
/// angle), gaps rejected, translation channels taken as inertial sensors.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadOptions {
    /// Explicit axis map; overrides the file's `axis_map` / `# axes:` and the default mapping.
    pub axis_map: Option<AxisMap>,
    /// Explicit quantity of the tilt channels; overrides the file's units of tilt channels.
    pub quantity: Option<Quantity>,
    /// Units of source channels the file does not state them for (time series only): required
    /// for translation channels of files without units (miniSEED, CSV without a `# units:`
    /// line); where the file states one it must agree.
    pub units: Vec<ChannelUnit>,
    /// Translation channels (source names) whose tilt part is removed already, or whose sensor
    /// has none: not corrected with the record's tilt ([`motion`]).
    pub corrected: Vec<String>,
    /// Tilt channels (source names) read by a pendulum tiltmeter, which senses `t + a / g`:
    /// corrected with the record's translation of that axis ([`motion`]).
    pub pendulum: Vec<String>,
    /// Treatment of NaN / infinite samples (time series only).
    pub gaps: GapPolicy,
    /// Factors for source channels (time series only): required for channels in counts,
    /// applied to the samples as read, before the axis map's sign.
    pub scale: Vec<ChannelScale>,
}

/// File format of an input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InputFormat {
    /// HDF5 (`.h5`, `.hdf5`).
    Hdf5,
    /// Comma-separated text (`.csv`).
    Csv,
    /// miniSEED 2 (`.mseed`, `.miniseed`, `.ms`): a time series per SEED channel.
    Miniseed,
}

impl InputFormat {
    /// `hdf5`, `csv` or `miniseed`.
    pub fn name(self) -> &'static str {
        match self {
            InputFormat::Hdf5 => "hdf5",
            InputFormat::Csv => "csv",
            InputFormat::Miniseed => "miniseed",
        }
    }
}

impl fmt::Display for InputFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Kind of input: a time series or spectra.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InputKind {
    /// Time series of tilt angle or rate.
    Series,
    /// One-sided amplitude or cross spectral densities.
    Spectra,
}

impl InputKind {
    /// `series` or `spectra`.
    pub fn name(self) -> &'static str {
        match self {
            InputKind::Series => "series",
            InputKind::Spectra => "spectra",
        }
    }
}

impl fmt::Display for InputKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Where an input came from and how it was interpreted, for the output files.
#[derive(Debug, Clone, PartialEq)]
pub struct Provenance {
    /// The file read.
    pub path: PathBuf,
    /// Its format.
    pub format: InputFormat,
    /// Series or spectra.
    pub kind: InputKind,
    /// The quantity of the file's channels: the unit of a series' samples; spectra are
    /// converted to angle as they are read.
    pub quantity: Quantity,
    /// The effective axis map in [`AxisMap`] syntax, e.g. `theta_t=-LJE,eta_t=-LJN`.
    pub axis_map: String,
    /// Start time (ISO 8601) if the file gives one.
    pub start_time: Option<String>,
    /// Human-readable notes: where the map and quantity came from, assumptions, ignored
    /// channels, interpolated gaps, band restriction.
    pub notes: Vec<String>,
}

/// The content of a tilt input file.
#[derive(Debug, Clone, PartialEq)]
pub enum TiltInput {
    /// A time series (angle in rad or rate in rad/s, [`TiltSeries::quantity`]).
    Series(TiltSeries),
    /// Spectra (one-sided CSD, rad²/Hz).
    Spectra(TiltSpectra),
}

impl TiltInput {
    /// The provenance of either kind.
    pub fn provenance(&self) -> &Provenance {
        match self {
            TiltInput::Series(s) => &s.provenance,
            TiltInput::Spectra(s) => &s.provenance,
        }
    }
}

/// Provenance of the tilt input of a budget run, stored in the budget's HDF5 file and shown in
/// its figure. Plain strings, so that this module does not depend on [`crate::input`]; the
/// caller fills it from the reader's `tiltnoise_core::input::Provenance`.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct InputMeta {
    /// The input file, as given.
    pub path: String,
    /// File format: `hdf5` or `csv`.
    pub format: String,
    /// `series` (time series) or `spectra`.
    pub kind: String,
    /// Quantity of the file's channels before conversion to angle: `angle` or `rate`.
    pub quantity: String,
    /// The effective axis map, e.g. `theta_t=-LJE,eta_t=-LJN`.
    pub axis_map: String,
    /// Start time of the record (ISO 8601), if the file gives one.
    pub start_time: Option<String>,
    /// The reader's notes: where the map and quantity came from, assumptions, gaps.
    pub notes: Vec<String>,
}

impl From<&Provenance> for InputMeta {
    fn from(p: &Provenance) -> InputMeta {
        InputMeta {
            path: p.path.display().to_string(),
            format: p.format.name().to_string(),
            kind: p.kind.name().to_string(),
            quantity: p.quantity.name().to_string(),
            axis_map: p.axis_map.clone(),
            start_time: p.start_time.clone(),
            notes: p.notes.clone(),
        }
    }
}
