//! Checks of a budget's options that depend on which options were given and on the kind of
//! tilt input: an option of the other kind of input is refused rather than ignored, and the
//! percentile band needs segments. The command line and the Python package both call these,
//! and each spells the options its own way ([`OptionKey`]).

use crate::error::Shown;
use crate::option_key::{self, OptionKey};
use crate::options::OptionError;

/// Options (snake case) that apply to time-series input only, in the order they are reported.
pub const SERIES_ONLY_OPTIONS: [&str; 5] =
    ["nperseg", "overlap", "average", "segment_duration", "gaps"];

/// Options that apply to spectra input only.
pub const SPECTRA_ONLY_OPTIONS: [&str; 1] = ["freq"];

/// What a tilt input holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A time series, whose budget is on the Welch grid.
    Series,
    /// Spectra, interpolated onto the model grid.
    Spectra,
}

/// Refuses the first option of `given` (the snake-case names of the options the caller set)
/// that does not apply to the `kind` of input `source` (the file, as shown) holds.
pub fn refuse_options_for_input(
    given: &[&str],
    kind: InputKind,
    source: &str,
) -> Result<(), OptionError> {
    let (other_kind, what_instead) = match kind {
        InputKind::Spectra => (&SERIES_ONLY_OPTIONS[..], "spectra"),
        InputKind::Series => (&SPECTRA_ONLY_OPTIONS[..], "a time series"),
    };
    let Some(name) = other_kind.iter().find(|o| given.contains(o)) else {
        return Ok(());
    };
    let source = Shown(source);
    Err(OptionError::Conflict(match kind {
        InputKind::Spectra => format!(
            "{} applies to time-series input, and {source} holds {what_instead}; leave it out \
             (the model grid of spectra input is set with {})",
            OptionKey::new(name),
            OptionKey::FREQ
        ),
        InputKind::Series => format!(
            "{} applies to spectra input, and {source} holds {what_instead}, whose budget is on \
             the Welch grid (set its resolution with {})",
            OptionKey::new(name),
            OptionKey::NPERSEG
        ),
    }))
}

/// Refuses percentiles without a segment duration: the band is across segments.
pub fn require_segments_for_percentiles(segment_duration_given: bool) -> Result<(), OptionError> {
    if segment_duration_given {
        return Ok(());
    }
    Err(OptionError::Conflict(format!(
        "{} applies to the per-segment band and needs {} (e.g. {} with {} at 1 Hz: each \
         segment holds a Welch segment)",
        OptionKey::PERCENTILES,
        OptionKey::SEGMENT_DURATION,
        OptionKey::SEGMENT_DURATION.given("14400"),
        OptionKey::NPERSEG.given("4096")
    )))
}

/// The percentiles `(lower, upper)` of the band, `0 <= lower < upper <= 100`; `given` is
/// the value as the caller wrote it, for the message.
pub fn check_percentiles(given: &str, lower: f64, upper: f64) -> Result<(f64, f64), OptionError> {
    if 0.0 <= lower && lower < upper && upper <= 100.0 {
        return Ok((lower, upper));
    }
    Err(percentiles_error(given))
}

/// The error for percentiles that do not parse or are out of order or range.
pub fn percentiles_error(given: &str) -> OptionError {
    let form = option_key::pair("LOWER", "UPPER");
    OptionError::Conflict(format!(
        "{} {}: expected {form} with 0 <= LOWER < UPPER <= 100",
        OptionKey::PERCENTILES,
        Shown(given)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_of_the_other_kind_of_input_are_refused_by_name() {
        let given = ["overlap", "gaps"];
        let e = refuse_options_for_input(&given, InputKind::Spectra, "s.csv");
        assert_eq!(
            e.unwrap_err().to_string(),
            "overlap applies to time-series input, and s.csv holds spectra; leave it out (the \
             model grid of spectra input is set with freq)"
        );
        assert!(refuse_options_for_input(&given, InputKind::Series, "t.h5").is_ok());
        let e = refuse_options_for_input(&["freq"], InputKind::Series, "t.h5");
        assert_eq!(
            e.unwrap_err().to_string(),
            "freq applies to spectra input, and t.h5 holds a time series, whose budget is on \
             the Welch grid (set its resolution with nperseg)"
        );
    }

    #[test]
    fn percentiles_need_segments_and_order() {
        assert_eq!(
            require_segments_for_percentiles(false)
                .unwrap_err()
                .to_string(),
            "percentiles applies to the per-segment band and needs segment_duration (e.g. \
             segment_duration=14400 with nperseg=4096 at 1 Hz: each segment holds a Welch \
             segment)"
        );
        assert!(require_segments_for_percentiles(true).is_ok());
        assert_eq!(check_percentiles("5,95", 5.0, 95.0).unwrap(), (5.0, 95.0));
        for (lo, hi) in [(90.0, 10.0), (-1.0, 50.0), (50.0, 101.0), (f64::NAN, 50.0)] {
            let e = check_percentiles("x", lo, hi).unwrap_err();
            assert_eq!(
                e.to_string(),
                "percentiles x: expected (LOWER, UPPER) with 0 <= LOWER < UPPER <= 100"
            );
        }
        assert_eq!(
            percentiles_error("(90, 10)").to_string(),
            "percentiles (90, 10): expected (LOWER, UPPER) with 0 <= LOWER < UPPER <= 100"
        );
    }
}
