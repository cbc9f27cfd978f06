//! Which option or key a message is about, named by its canonical key (`nperseg`,
//! `segment_duration`), and how the front end in use spells it.
//!
//! The library knows no option spelling: an error carries the [`OptionKey`] that failed, and the
//! front end that runs (the command line, the Python package) installs its [`OptionStyle`] once
//! at start-up, so the same error reads `--nperseg 8` on the command line and `nperseg=8` in
//! Python. Without an installed style (the library's own tests, another embedder) a key is shown
//! as itself: `nperseg`, `nperseg=8`.

use std::fmt;
use std::sync::OnceLock;

/// An option or key of a request, by its canonical snake-case name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct OptionKey(&'static str);

impl OptionKey {
    /// The key `key` (snake case, as a keyword argument: `segment_duration`).
    pub const fn new(key: &'static str) -> Self {
        Self(key)
    }

    /// The canonical snake-case key.
    pub const fn key(self) -> &'static str {
        self.0
    }

    /// This option set to `value`, for a message: `--nperseg 8` or `nperseg=8`.
    pub fn given(self, value: impl fmt::Display) -> Given {
        Given {
            key: self,
            value: Value::Whole(value.to_string()),
        }
    }

    /// One entry `name` -> `value` of this option's mapping, for a message:
    /// `--units eta_t=urad` or `units={"eta_t": "urad"}`.
    pub fn entry(self, name: impl fmt::Display, value: impl fmt::Display) -> Given {
        Given {
            key: self,
            value: Value::Entry(name.to_string(), value.to_string()),
        }
    }

    /// A parameter assignment `KEY=VALUE` that overrides the parameter file.
    pub const SET: Self = Self("set");
    /// The frequency grid of a model evaluation.
    pub const FREQ: Self = Self("freq");
    /// The Welch segment length (samples).
    pub const NPERSEG: Self = Self("nperseg");
    /// The duration of the segments of a per-segment budget (s).
    pub const SEGMENT_DURATION: Self = Self("segment_duration");
    /// The percentiles of a per-segment band.
    pub const PERCENTILES: Self = Self("percentiles");
    /// The inputs of a transfer-function request (tilt angles, translations, forces).
    pub const INPUTS: Self = Self("inputs");
    /// The observables of a transfer-function request.
    pub const OUTPUTS: Self = Self("outputs");
    /// The observables a command computes.
    pub const OBSERVABLES: Self = Self("observables");
    /// The tilt axes read from a record.
    pub const AXES: Self = Self("axes");
    /// The units of a record's channels.
    pub const UNITS: Self = Self("units");
    /// Translation channels whose tilt part is removed already.
    pub const CORRECTED: Self = Self("corrected");
    /// Tilt channels read by a pendulum tiltmeter.
    pub const PENDULUM_TILTMETER: Self = Self("pendulum_tiltmeter");
    /// The factors a record's channels are multiplied by (counts to physical units).
    pub const SCALE: Self = Self("scale");
    /// The white readout noise of an observable.
    pub const READOUT: Self = Self("readout");
    /// A user noise term of a budget.
    pub const TERM: Self = Self("term");
    /// The frequencies a budget is reported at (Hz).
    pub const AT: Self = Self("at");
    /// The free parameters of a fit.
    pub const FREE: Self = Self("free");
    /// The half-width of a fit's box, in error bars.
    pub const BOUND_SIGMAS: Self = Self("bound_sigmas");
    /// The initial coordinates of a simulation.
    pub const INIT: Self = Self("init");
    /// The initial rates of a simulation.
    pub const INIT_RATE: Self = Self("init_rate");
    /// The gain of a drive of a simulation, by input.
    pub const DRIVE_GAIN: Self = Self("drive_gain");
    /// The kick test's static displacement of X (m).
    pub const KICK_X: Self = Self("kick_x");
    /// The energy per mode of an equal-energy start (J).
    pub const MODE_ENERGY: Self = Self("mode_energy");
    /// The sampling step of a simulation (s).
    pub const STEP: Self = Self("step");
    /// The duration of a simulation (s).
    pub const DURATION: Self = Self("duration");
    /// The fit band of a subtraction (Hz).
    pub const BAND: Self = Self("band");
    /// The band a subtraction reports on (Hz).
    pub const REPORT_BAND: Self = Self("report_band");
    /// The parameters a subtraction fits.
    pub const FIT: Self = Self("fit");
    /// The largest delay a subtraction fits (s).
    pub const MAX_DELAY: Self = Self("max_delay");
    /// The noise of a witness channel.
    pub const WITNESS_NOISE: Self = Self("witness_noise");
    /// The held-out fraction of a subtraction's segments.
    pub const HOLDOUT: Self = Self("holdout");
    /// The ratio of noise ASDs of co-located witnesses.
    pub const COLOCATED_RATIO: Self = Self("colocated_ratio");
    /// The observables a figure draws (a subset of those computed).
    pub const DRAWN_OBSERVABLES: Self = Self("drawn_observables");
    /// A figure's size (pixels).
    pub const SIZE: Self = Self("size");
    /// A figure's resolution (dots per inch).
    pub const DPI: Self = Self("dpi");
}

impl fmt::Display for OptionKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match STYLE.get() {
            Some(style) => f.write_str(&style.option(*self)),
            None => f.write_str(self.0),
        }
    }
}

/// An option with the value given, shown as the front end in use spells it
/// ([`OptionKey::given`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Given {
    key: OptionKey,
    value: Value,
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Value {
    Whole(String),
    Entry(String, String),
}

impl fmt::Display for Given {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let key = self.key;
        match (&self.value, STYLE.get()) {
            (Value::Whole(v), Some(style)) => f.write_str(&style.given(key, v)),
            (Value::Entry(n, v), Some(style)) => f.write_str(&style.entry(key, n, v)),
            (Value::Whole(v), None) => write!(f, "{}={v}", key.0),
            (Value::Entry(n, v), None) => write!(f, "{} {n}={v}", key.0),
        }
    }
}

/// How a front end spells its options in messages.
pub trait OptionStyle: Send + Sync {
    /// The option alone: `--segment-duration` or `segment_duration`.
    fn option(&self, key: OptionKey) -> String;
    /// The option with the value given: `--segment-duration 3600` or `segment_duration=3600`.
    fn given(&self, key: OptionKey, value: &str) -> String;
    /// One entry of the option's mapping: `--units eta_t=urad` or `units={"eta_t": "urad"}`.
    fn entry(&self, key: OptionKey, name: &str, value: &str) -> String;
    /// The form of a pair of values, named `first` and `second`: `LOWER,UPPER` or
    /// `(LOWER, UPPER)`.
    fn pair(&self, first: &str, second: &str) -> String {
        format!("({first}, {second})")
    }
}

static STYLE: OnceLock<&'static dyn OptionStyle> = OnceLock::new();

/// Installs the front end's spelling of options for every message of this process; a front end
/// calls it once at start-up, before any message is shown. Returns false (and changes nothing)
/// if a style was already installed.
pub fn install_style(style: &'static dyn OptionStyle) -> bool {
    STYLE.set(style).is_ok()
}

/// The form of a pair of values in the installed style (`(LOWER, UPPER)` without one).
pub fn pair(first: &str, second: &str) -> String {
    match STYLE.get() {
        Some(style) => style.pair(first, second),
        None => format!("({first}, {second})"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_a_style_a_key_is_shown_as_itself() {
        assert_eq!(OptionKey::SEGMENT_DURATION.to_string(), "segment_duration");
        assert_eq!(OptionKey::NPERSEG.given(4096).to_string(), "nperseg=4096");
        assert_eq!(
            OptionKey::UNITS.entry("eta_t", "urad").to_string(),
            "units eta_t=urad"
        );
        assert_eq!(pair("LOWER", "UPPER"), "(LOWER, UPPER)");
    }
}
