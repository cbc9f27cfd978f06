//! [`InputError`]: everything that can be wrong with an input file (floor tilt, or a measured
//! series or spectrum for the budget).
//!
//! Every message names the file, the dataset, column, attribute or key, the offending value or
//! index, the unit where there is one, and what is allowed. Sample indices are 0-based (the
//! sample index in the series); CSV line numbers are 1-based (as shown by an editor). Problems
//! only a file format can describe come from the reader in [`InputError::Format`].

use crate::error::{Num, Shown};
use crate::option_key::OptionKey;
use std::path::{Path, PathBuf};

/// Formats an optional CSV line number as ` (line N)`.
fn at_line(line: &Option<usize>) -> String {
    match line {
        Some(l) => format!(" (line {l})"),
        None => String::new(),
    }
}

/// An input file (floor tilt, or a measured series or spectrum) that cannot be read or is not valid.
#[derive(Debug, thiserror::Error)]
pub enum InputError {
    /// The file could not be opened or read.
    #[error("cannot read input file {path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said (in the message, so not also a `source()`).
        reason: std::io::Error,
    },

    /// A file, line, dataset or record count over its size limit ([`crate::limits`]).
    #[error(transparent)]
    TooLarge(#[from] crate::limits::LimitError),

    /// The extension names no supported format.
    #[error(
        "input file {path}: extension `{}` is not supported; allowed: .h5 or .hdf5 \
         (HDF5), .csv (comma-separated text), .mseed, .miniseed or .ms (miniSEED 2)",
        Shown(.extension)
    )]
    Extension {
        /// The file.
        path: PathBuf,
        /// The extension found (empty if none).
        extension: String,
    },

    /// A problem that only the file's format can describe: the HDF5 library's failure, a CSV
    /// line or field, a miniSEED record. The reader that found it (`tiltnoise-io`, whose
    /// `FormatError` this holds) owns those concepts; the message names the file and place.
    #[error(transparent)]
    Format(Box<dyn std::error::Error + Send + Sync>),

    /// The content matches none of the accepted layouts.
    #[error("input file {path} ({format}): {found}; accepted layouts: {accepted}")]
    UnknownLayout {
        /// The file.
        path: PathBuf,
        /// `hdf5` or `csv`.
        format: &'static str,
        /// What was found instead.
        found: String,
        /// The accepted layouts (see `docs/input_formats.md`).
        accepted: &'static str,
    },

    /// A time series was asked for and the file holds spectra, or the other way round.
    #[error("input file {path}: expected {expected} but the file holds {found}")]
    WrongKind {
        /// The file.
        path: PathBuf,
        /// `series` or `spectra`.
        expected: &'static str,
        /// `series` or `spectra`.
        found: &'static str,
    },

    /// An HDF5 attribute (or CSV metadata key) with a value or type that is not allowed.
    #[error(
        "input file {path}: attribute `{attribute}` of {} = {} is not allowed: must be {allowed}",
        Shown(.object),
        Shown(.value)
    )]
    BadAttribute {
        /// The file.
        path: PathBuf,
        /// The object carrying it, e.g. `/` or `dataset /E`.
        object: String,
        /// The attribute name (CSV: the metadata key, e.g. `# start_time:`).
        attribute: &'static str,
        /// The offending value (or its type).
        value: String,
        /// What is allowed, with unit.
        allowed: &'static str,
    },

    /// A NaN or infinite sample while gaps are rejected.
    #[error(
        "input file {path}: channel `{}` sample index {index}{} is {value:?} {unit}; \
         allowed: finite values (or select gap interpolation to bridge interior gaps linearly)",
        Shown(.channel),
        at_line(.line)
    )]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// The source channel (dataset or column name).
        channel: String,
        /// 0-based sample index.
        index: usize,
        /// The value read.
        value: f64,
        /// Unit of the channel.
        unit: &'static str,
        /// 1-based CSV line, when the input is CSV.
        line: Option<usize>,
    },

    /// A finite sample outside the magnitudes every spectrum and fit derived from it stays
    /// finite and normal for ([`SAMPLES`](crate::limits::SAMPLES)), in the channel's unit after
    /// the file's unit and any scale factor.
    #[error(
        "input file {path}: channel `{}` sample index {index}{} is {} {unit} (with the file's \
         unit and any scale factor applied); allowed: {} (beyond them the spectra and fits \
         derived from the samples overflow or underflow f64: check the units and the scale \
         factor; see docs/limits.md)",
        Shown(.channel),
        at_line(.line),
        Num(*.value),
        crate::limits::SAMPLES.allowed(.unit)
    )]
    OutOfRange {
        /// The file.
        path: PathBuf,
        /// The source channel (dataset or column name).
        channel: String,
        /// 0-based sample index.
        index: usize,
        /// The value, in `unit`.
        value: f64,
        /// Unit of the channel.
        unit: &'static str,
        /// 1-based CSV line, when the input is CSV.
        line: Option<usize>,
    },

    /// A sample rate (from an attribute, a header, or the spacing of a time column) outside
    /// [`SAMPLE_RATES`](crate::limits::SAMPLE_RATES).
    #[error(
        "input file {path}: {source_of} gives a sample rate of {} Hz; allowed: {} (the \
         spectra of the record would leave the range of f64; see docs/limits.md)",
        Num(*.rate_hz),
        crate::limits::SAMPLE_RATES.allowed("Hz")
    )]
    SampleRate {
        /// The file.
        path: PathBuf,
        /// Where the rate comes from, e.g. `attribute sample_rate_hz of /`, `column time_s
        /// (dt = 1e-300 s)`.
        source_of: String,
        /// The rate (Hz).
        rate_hz: f64,
    },

    /// A run of non-finite samples touching the start or the end of a channel, which linear
    /// interpolation cannot bridge.
    #[error(
        "input file {path}: channel `{}` has a {edge} gap of non-finite samples at \
         indices {first}..={last} (of {len} samples, unit {unit}); gap interpolation needs a \
         finite sample on both sides: trim the series",
        Shown(.channel)
    )]
    EdgeGap {
        /// The file.
        path: PathBuf,
        /// The source channel.
        channel: String,
        /// `leading` or `trailing`.
        edge: &'static str,
        /// First index of the gap.
        first: usize,
        /// Last index of the gap (inclusive).
        last: usize,
        /// Length of the channel.
        len: usize,
        /// Unit of the channel.
        unit: &'static str,
    },

    /// Two channels of different lengths.
    #[error(
        "input file {path}: channel `{}` has {len_a} samples but `{}` has {len_b}; all \
         channels must have the same length",
        Shown(.channel_a),
        Shown(.channel_b)
    )]
    LengthMismatch {
        /// The file.
        path: PathBuf,
        /// First channel.
        channel_a: String,
        /// Its length.
        len_a: usize,
        /// Second channel.
        channel_b: String,
        /// Its length.
        len_b: usize,
    },

    /// Too few samples or frequencies.
    #[error("input file {path}: {} has {len} {unit}; at least {min} required", Shown(.what))]
    TooShort {
        /// The file.
        path: PathBuf,
        /// What is short, e.g. `channel E` or `column freq_hz`.
        what: String,
        /// Its length.
        len: usize,
        /// `samples` or `frequencies`.
        unit: &'static str,
        /// The minimum.
        min: usize,
    },

    /// A malformed axis-map specification.
    #[error(
        "{origin}: axis map `{}`, entry `{}`: {message}; syntax: \
         TARGET=[+|-]SOURCE[,TARGET=[+|-]SOURCE...] with TARGET one of theta_t, eta_t, phi_t \
         (tilt) or x_t, y_t, z_t (translation), e.g. theta_t=-E,eta_t=-N,x_t=LHE",
        Shown(.spec),
        Shown(.entry)
    )]
    AxisMapSyntax {
        /// Where the specification came from: `axis map`, or `<file>, attribute axis_map`.
        origin: String,
        /// The whole specification.
        spec: String,
        /// The offending entry.
        entry: String,
        /// What is wrong.
        message: String,
    },

    /// The axis map names a channel that the file does not have.
    #[error(
        "input file {path}: the axis map assigns {target} to {kind} `{}`, which the file does \
         not have; available {kind}s: {available}",
        Shown(.source_name)
    )]
    AxisMapSource {
        /// The file.
        path: PathBuf,
        /// The target axis name (`theta_t`, ...).
        target: &'static str,
        /// `dataset` or `column`.
        kind: &'static str,
        /// The source name asked for.
        source_name: String,
        /// The channels the file has.
        available: String,
    },

    /// No channel could be assigned to an input of the floor's motion.
    #[error(
        "input file {path}: no tilt or translation channel found among {kind}s {found}; \
         allowed without an axis map: theta_t, eta_t, phi_t, x_t, y_t, z_t (used as they are), \
         the rotation channels E, N, Z (or SEED rotation codes ?JE, ?JN, ?JZ; default mapping \
         theta_t=-E, eta_t=-N, phi_t=-Z), or translation channels (a unit of length, velocity \
         or acceleration, or a seismometer code such as LHE; x_t=E, y_t=N, z_t=Z); otherwise \
         give an axis map such as theta_t=-E,eta_t=-N"
    )]
    NoAxes {
        /// The file.
        path: PathBuf,
        /// `dataset` or `column`.
        kind: &'static str,
        /// The channel names found.
        found: String,
    },

    /// Several channels qualify for the same axis under the default mapping.
    #[error(
        "input file {path}: {kind}s {candidates} all qualify for {axis} under the default \
         mapping; allowed: exactly one, so give an explicit axis map (e.g. {axis}=-{})",
        Shown(.first)
    )]
    AmbiguousAxis {
        /// The file.
        path: PathBuf,
        /// `dataset` or `column`.
        kind: &'static str,
        /// The target axis name.
        axis: &'static str,
        /// The candidates, comma separated.
        candidates: String,
        /// One of them, for the hint.
        first: String,
    },

    /// An explicit axis map that feeds a tilt axis from a translation channel, or the other way
    /// round.
    #[error(
        "input file {path}: the axis map assigns {} to {kind} `{}`, which is a {} channel by \
         its unit or SEED instrument code; allowed: rotation channels for theta_t, eta_t, \
         phi_t, translation channels for x_t, y_t, z_t",
        .target.name(),
        Shown(.channel),
        .motion.name()
    )]
    ChannelMotion {
        /// The file.
        path: PathBuf,
        /// `dataset`, `column` or `channel`.
        kind: &'static str,
        /// The source channel.
        channel: String,
        /// The input the map assigns it to.
        target: crate::model::Input,
        /// What the channel measures.
        motion: super::unit::Motion,
    },

    /// A channel's unit that is missing where it is needed, given twice with different values,
    /// given for a channel the file does not have, or contradicting the channel's instrument
    /// code.
    #[error("input file {path}: channel `{}` {message}", Shown(.channel))]
    ChannelUnit {
        /// The file.
        path: PathBuf,
        /// The source channel.
        channel: String,
        /// What is wrong and what is allowed.
        message: crate::option_key::Message,
    },

    /// A series whose unit nobody states (taken as rad or rad/s) with a detrended RMS that no
    /// laboratory floor reaches ([`super::unstated_rms_bound`]): most likely in a smaller unit.
    #[error(
        "input file {path}: channel `{}` states no unit and is read in {}, but its detrended RMS \
         is {} {}, above the {} {} no laboratory floor reaches; its values are likely in {}: \
         state the unit in the file (a `# units:` line, a `units` attribute) or with the units \
         option ({})",
        Shown(.channel),
        .quantity.unit(),
        Num(*.rms),
        .quantity.unit(),
        Num(*.bound),
        .quantity.unit(),
        .likely,
        OptionKey::UNITS.entry(Shown(.channel), .likely.split(' ').next().unwrap_or(""))
    )]
    UnstatedUnit {
        /// The file.
        path: PathBuf,
        /// The source channel.
        channel: String,
        /// Its detrended RMS, in the quantity's SI unit.
        rms: f64,
        /// Angle or rate.
        quantity: super::Quantity,
        /// The bound it exceeds.
        bound: f64,
        /// The likely units, e.g. `urad or nrad`.
        likely: String,
    },

    /// A sensor declaration (a channel said to be corrected, or read by a pendulum tiltmeter)
    /// that names no channel of the right kind, or sensors whose readings cannot be told apart.
    #[error("input file {path}: channel `{}` {message}", Shown(.channel))]
    Sensor {
        /// The file.
        path: PathBuf,
        /// The source channel.
        channel: String,
        /// What is wrong and what is allowed.
        message: String,
    },

    /// A unit string that is not understood.
    #[error(
        "input file {path}: {location} has units `{}`; allowed: {allowed}",
        Shown(.value)
    )]
    Units {
        /// The file.
        path: PathBuf,
        /// Where, e.g. `attribute units of dataset /E` or `line 2 (# units:), column LJN`.
        location: String,
        /// The unit string found.
        value: String,
        /// The accepted unit strings.
        allowed: &'static str,
    },

    /// Channels with different quantities (angle and rate) in one file.
    #[error(
        "input file {path}: channel `{}` is in {unit_a} but `{}` is in {unit_b}; allowed: all \
         channels in rad (angle) or all in rad/s (rate), or an explicit quantity override",
        Shown(.channel_a),
        Shown(.channel_b)
    )]
    MixedQuantity {
        /// The file.
        path: PathBuf,
        /// First channel.
        channel_a: String,
        /// Its unit (`rad` or `rad/s`).
        unit_a: &'static str,
        /// Second channel.
        channel_b: String,
        /// Its unit.
        unit_b: &'static str,
    },

    /// A frequency that is not positive, not finite, or not strictly increasing.
    #[error(
        "input file {path}: {location}: frequency {value:?} Hz is not allowed: must be {allowed}"
    )]
    Frequency {
        /// The file.
        path: PathBuf,
        /// Where, e.g. `line 7 (row 3), column freq_hz` or `/frequency_hz[3]`.
        location: String,
        /// The value found (Hz).
        value: f64,
        /// What is allowed, e.g. `finite and > 0` or `greater than the previous 0.5 Hz`.
        allowed: String,
    },

    /// Finite values whose spectrum overflows f64 (an ASD above about 1.3e154 squares to
    /// infinity; a rate spectrum is divided by `(2 pi f)^2`).
    #[error(
        "input file {path}: the tilt cross-spectral density {entry} at {} Hz overflows f64 \
         ({value:?} rad^2/Hz): the values are far too large for tilt (check the file's units \
         and the quantity)",
        crate::error::Num(*.freq_hz)
    )]
    SpectrumOverflow {
        /// The file.
        path: PathBuf,
        /// The entry, e.g. `S(theta_t, eta_t)`.
        entry: String,
        /// Its frequency (Hz).
        freq_hz: f64,
        /// The value (real or imaginary part) that is not finite.
        value: f64,
    },

    /// A negative or non-finite amplitude (or power) spectral density, or one outside
    /// [`ASDS`](crate::limits::ASDS) ([`PSDS`](crate::limits::PSDS)): its PSD, and what is
    /// derived from it, would overflow or underflow.
    #[error(
        "input file {path}: {location}, column `{}`: {} {value:?} {unit} is not allowed: must \
         be {} (see docs/limits.md)",
        Shown(.column),
        if *.power { "PSD" } else { "ASD" },
        if *.power { crate::limits::PSDS } else { crate::limits::ASDS }.allowed(.unit)
    )]
    Asd {
        /// The file.
        path: PathBuf,
        /// Where, e.g. `line 7 (row 3)` or `/asd[3, 1]`.
        location: String,
        /// The axis (column) name.
        column: String,
        /// The value found.
        value: f64,
        /// Unit of the value.
        unit: &'static str,
        /// Whether the value is a PSD (else an ASD).
        power: bool,
    },

    /// A `--scale CHANNEL=FACTOR` that names no channel of the file, or a channel in counts
    /// without one.
    #[error("input file {path}: channel `{}` {message}", Shown(.channel))]
    Scale {
        /// The file.
        path: PathBuf,
        /// The channel named.
        channel: String,
        /// What is wrong and what is allowed.
        message: String,
    },

    /// A chunk request outside the series.
    #[error(
        "input file {path}: chunk of {len} samples starting at sample index {start} is out of \
         range; allowed: start + len <= {available} (the series length)"
    )]
    ChunkOutOfRange {
        /// The file.
        path: PathBuf,
        /// Requested start index.
        start: usize,
        /// Requested length.
        len: usize,
        /// Length of the series.
        available: usize,
    },
}

/// Checks that `what` of `path` has at least the 2 `unit` (`samples` or `frequencies`) every
/// series or spectrum needs; else [`InputError::TooShort`].
pub fn require_two(
    path: &Path,
    what: &str,
    len: usize,
    unit: &'static str,
) -> Result<(), InputError> {
    if len < 2 {
        return Err(InputError::TooShort {
            path: path.to_path_buf(),
            what: what.to_string(),
            len,
            unit,
            min: 2,
        });
    }
    Ok(())
}

/// The sample rate `rate_hz` of `path`, if it is within
/// [`SAMPLE_RATES`](crate::limits::SAMPLE_RATES); else [`InputError::SampleRate`] saying where
/// it comes from (`source_of`, built only then).
pub fn check_sample_rate(
    path: &Path,
    source_of: impl FnOnce() -> String,
    rate_hz: f64,
) -> Result<f64, InputError> {
    if crate::limits::SAMPLE_RATES.admits(rate_hz) {
        return Ok(rate_hz);
    }
    Err(InputError::SampleRate {
        path: path.to_path_buf(),
        source_of: source_of(),
        rate_hz,
    })
}

#[cfg(test)]
mod tests {
    /// Callers wrap `InputError` in their own error enums: keep it small enough that the
    /// wrapper (one more discriminant word) stays below clippy's 128-byte `result_large_err`
    /// threshold.
    #[test]
    fn error_is_small() {
        let n = std::mem::size_of::<super::InputError>();
        assert!(n <= 112, "size_of::<InputError>() = {n}");
    }
}
