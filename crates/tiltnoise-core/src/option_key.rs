//! Which option or key a message is about, named by its canonical key (`nperseg`,
//! `segment_duration`), and how the front end in use spells it.
//!
//! The library knows no option spelling: an error carries the [`OptionKey`] that failed, and the
//! front end that shows it (the command line, the Python package) renders it with its
//! [`OptionStyle`] through [`render`], so the same error reads `--nperseg 8` on the command line
//! and `nperseg=8` in Python. Nothing is installed for the process: outside [`render`] (the
//! library's own tests, another embedder's `to_string`) a key is shown as itself: `nperseg`,
//! `nperseg=8`. A message that names options is therefore kept unrendered until it is shown:
//! as typed fields of an error, or as a [`Message`] whose text is written when it is displayed.

use std::cell::Cell;
use std::fmt;
use std::sync::Arc;

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
    /// The co-located witness records of a subtraction.
    pub const COLOCATED: Self = Self("colocated");
    /// The frequency limits of a figure's axis (Hz).
    pub const XLIM: Self = Self("xlim");
    /// The limits of a figure's vertical axis.
    pub const YLIM: Self = Self("ylim");
    /// A file of the frequencies of a model evaluation.
    pub const FREQ_FILE: Self = Self("freq_file");
    /// The time-series figures a simulation is saved to.
    pub const SAVE_TIME: Self = Self("save_time");
    /// The sample rate of a record given as arrays (Hz).
    pub const FS: Self = Self("fs");
    /// A figure's resolution (dots per inch).
    pub const DPI: Self = Self("dpi");
    /// The relative width of the band a budget's value at a frequency is read over.
    pub const AT_BAND: Self = Self("at_band");
    /// How a budget's Welch segments are averaged (mean or median).
    pub const AVERAGE: Self = Self("average");
    /// The frequencies per block of a streamed transfer-function evaluation.
    pub const BLOCK_FREQS: Self = Self("block_freqs");
    /// The samples per chunk of a streamed simulation.
    pub const CHUNK_SAMPLES: Self = Self("chunk_samples");
    /// The delay of a driven simulation's sensors (s).
    pub const DRIVE_DELAY: Self = Self("drive_delay");
    /// The planner's account of every candidate method.
    pub const EXPLAIN: Self = Self("explain");
    /// The band a coherence fit uses (Hz).
    pub const FIT_BAND: Self = Self("fit_band");
    /// The frequencies of a model evaluation (Hz), as an array (Python's spelling of the grid).
    pub const FREQ_HZ: Self = Self("freq_hz");
    /// What a reader does with the gaps of a record.
    pub const GAPS: Self = Self("gaps");
    /// A record (or spectra) of the measured observables.
    pub const MEASURED: Self = Self("measured");
    /// The method that evaluates the transfer functions.
    pub const METHOD: Self = Self("method");
    /// The overlap of Welch segments (a fraction).
    pub const OVERLAP: Self = Self("overlap");
    /// The fine steps per record sample of a driven simulation.
    pub const OVERSAMPLE: Self = Self("oversample");
    /// What a streamed transfer-function output holds per row.
    pub const PER: Self = Self("per");
    /// The relative tolerance the transfer-function planner must meet.
    pub const REL_TOL: Self = Self("rel_tol");
    /// The draws of a Monte Carlo.
    pub const SAMPLES: Self = Self("samples");
    /// The files a command writes.
    pub const SAVE: Self = Self("save");
    /// The threads a command runs on.
    pub const THREADS: Self = Self("threads");
    /// A record of the floor's motion.
    pub const TILT: Self = Self("tilt");
}

impl fmt::Display for OptionKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match style_in_use() {
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
        match (&self.value, style_in_use()) {
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

thread_local! {
    /// The style of the [`render`] call running on this thread, if any.
    static RENDERING: Cell<Option<&'static dyn OptionStyle>> = const { Cell::new(None) };
}

fn style_in_use() -> Option<&'static dyn OptionStyle> {
    RENDERING.with(Cell::get)
}

/// Restores the style of the enclosing [`render`] (or none) when a rendering ends, also when
/// the message's `Display` panics.
struct Restore(Option<&'static dyn OptionStyle>);

impl Drop for Restore {
    fn drop(&mut self) {
        RENDERING.with(|r| r.set(self.0));
    }
}

/// `message` as the front end of `style` shows it: every [`OptionKey`], [`Given`] and [`Pair`]
/// inside it (at any depth of its `Display`, e.g. an error's chain formatted with `{:#}`) spelled
/// by `style`. The style holds only while this call formats; nothing outlives it.
///
/// ```
/// use tiltnoise_core::option_key::{render, OptionKey, OptionStyle};
/// struct Flags;
/// impl OptionStyle for Flags {
///     fn option(&self, key: OptionKey) -> String {
///         format!("--{}", key.key().replace('_', "-"))
///     }
///     fn given(&self, key: OptionKey, value: &str) -> String {
///         format!("{} {value}", self.option(key))
///     }
///     fn entry(&self, key: OptionKey, name: &str, value: &str) -> String {
///         format!("{} {name}={value}", self.option(key))
///     }
///     fn pair(&self, first: &str, second: &str) -> String {
///         format!("{first}:{second}")
///     }
/// }
/// let given = OptionKey::SEGMENT_DURATION.given(3600);
/// assert_eq!(render(&Flags, &given), "--segment-duration 3600");
/// assert_eq!(given.to_string(), "segment_duration=3600");
/// ```
pub fn render(style: &'static dyn OptionStyle, message: &dyn fmt::Display) -> String {
    let _restore = Restore(RENDERING.with(|r| r.replace(Some(style))));
    message.to_string()
}

/// The form of a pair of values, named `first` and `second`, spelled when shown: `LOWER:UPPER`
/// on the command line, `(LOWER, UPPER)` in Python and without a style.
pub fn pair(first: impl fmt::Display, second: impl fmt::Display) -> Pair {
    Pair(first.to_string(), second.to_string())
}

/// A pair of values in the style of the front end that shows it ([`pair`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Pair(String, String);

impl fmt::Display for Pair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match style_in_use() {
            Some(style) => f.write_str(&style.pair(&self.0, &self.1)),
            None => write!(f, "({}, {})", self.0, self.1),
        }
    }
}

type WriteMessage = dyn Fn(&mut fmt::Formatter<'_>) -> fmt::Result + Send + Sync;

/// A message that names options, written when it is shown (so that [`render`] spells its keys),
/// not when it is made; made with the [`message!`](crate::message) macro, as `format!`.
#[derive(Clone)]
pub struct Message(Arc<WriteMessage>);

impl Message {
    /// The message `write` writes.
    pub fn new(
        write: impl Fn(&mut fmt::Formatter<'_>) -> fmt::Result + Send + Sync + 'static,
    ) -> Self {
        Self(Arc::new(write))
    }
}

impl Message {
    /// The message of `value` (an error that names options), written when shown.
    pub fn shown(value: impl fmt::Display + Send + Sync + 'static) -> Self {
        Self::new(move |f| write!(f, "{value}"))
    }
}

impl fmt::Display for Message {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        (self.0)(f)
    }
}

impl fmt::Debug for Message {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Message({:?})", self.to_string())
    }
}

/// Two messages are equal when they read the same without a style.
impl PartialEq for Message {
    fn eq(&self, other: &Self) -> bool {
        self.to_string() == other.to_string()
    }
}

impl Eq for Message {}

impl From<String> for Message {
    fn from(text: String) -> Self {
        Self::new(move |f| f.write_str(&text))
    }
}

impl From<&str> for Message {
    fn from(text: &str) -> Self {
        Self::from(text.to_string())
    }
}

/// A [`Message`](crate::option_key::Message) from `format!`'s arguments, written when it is
/// shown. Each positional argument is evaluated here and moved into the message (so it must be
/// owned or `'static`: a [`Given`], a `String`, a number); keys named inside the format string
/// (`"{option}"`) are captured by value.
#[macro_export]
macro_rules! message {
    ($fmt:literal $(,)?) => {
        $crate::option_key::Message::new(move |f: &mut ::std::fmt::Formatter<'_>| {
            ::std::write!(f, $fmt)
        })
    };
    ($fmt:literal, $($arg:expr),+ $(,)?) => {
        $crate::message!(@bind $fmt; []; $($arg),+)
    };
    // Each step binds one argument to a name of its own (the names of different steps are
    // distinct by hygiene).
    (@bind $fmt:literal; [$($bound:ident)*]; $head:expr $(, $tail:expr)*) => {{
        let arg = $head;
        $crate::message!(@bind $fmt; [$($bound)* arg]; $($tail),*)
    }};
    (@bind $fmt:literal; [$($bound:ident)*];) => {
        $crate::option_key::Message::new(move |f: &mut ::std::fmt::Formatter<'_>| {
            ::std::write!(f, $fmt, $($bound),*)
        })
    };
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
        assert_eq!(pair("LOWER", "UPPER").to_string(), "(LOWER, UPPER)");
    }

    struct Upper;

    impl OptionStyle for Upper {
        fn option(&self, key: OptionKey) -> String {
            key.key().to_uppercase()
        }
        fn given(&self, key: OptionKey, value: &str) -> String {
            format!("{} {value}", self.option(key))
        }
        fn entry(&self, key: OptionKey, name: &str, value: &str) -> String {
            format!("{} {name}:{value}", self.option(key))
        }
        fn pair(&self, first: &str, second: &str) -> String {
            format!("{first}..{second}")
        }
    }

    #[test]
    fn a_style_holds_only_while_its_render_formats() {
        let key = OptionKey::NPERSEG;
        let made = crate::message!("{key} with {}", pair(1, 2));
        assert_eq!(render(&Upper, &made), "NPERSEG with 1..2");
        assert_eq!(made.to_string(), "nperseg with (1, 2)");
        assert_eq!(
            render(&Upper, &OptionKey::UNITS.entry("eta_t", "urad")),
            "UNITS eta_t:urad"
        );
    }

    struct Panics;

    impl fmt::Display for Panics {
        fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            write!(f, "{}", OptionKey::STEP)?;
            panic!("a Display that fails half-way")
        }
    }

    #[test]
    fn a_panic_inside_a_render_leaves_no_style_behind() {
        let caught = std::panic::catch_unwind(|| render(&Upper, &Panics));
        assert!(caught.is_err());
        assert_eq!(OptionKey::STEP.to_string(), "step");
    }

    #[test]
    fn renders_nest_and_restore_the_outer_style() {
        struct Inner;
        impl fmt::Display for Inner {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                let inner = render(&Upper, &OptionKey::DPI);
                write!(f, "{inner} then {}", OptionKey::SIZE)
            }
        }
        assert_eq!(Inner.to_string(), "DPI then size");
        assert_eq!(render(&Upper, &Inner), "DPI then SIZE");
    }
}
