//! Checks of a budget's options that depend on which options were given: the percentile band
//! needs segments and ordered percentiles; and the kinds of tilt input, against which a budget
//! refuses the options of the other kind. Each front end spells the options its own way
//! ([`OptionKey`]).

use crate::error::Shown;
use crate::option_key::{self, OptionKey};
use crate::options::OptionError;

/// What a tilt input holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// A time series, whose budget is on the Welch grid.
    Series,
    /// Spectra, interpolated onto the model grid.
    Spectra,
}

/// Refuses percentiles without a segment duration: the band is across segments.
pub fn require_segments_for_percentiles(segment_duration_given: bool) -> Result<(), OptionError> {
    if segment_duration_given {
        return Ok(());
    }
    Err(OptionError::Conflict(crate::message!(
        "{} applies to the per-segment band and needs {} (e.g. {} with {} at 1 Hz: each \
         segment holds a Welch segment)",
        OptionKey::PERCENTILES,
        OptionKey::SEGMENT_DURATION,
        OptionKey::SEGMENT_DURATION.given("14400"),
        OptionKey::NPERSEG.given("4096")
    )))
}

/// The error for percentiles that do not parse or are out of order or range.
pub fn percentiles_error(given: &str) -> OptionError {
    let form = option_key::pair("LOWER", "UPPER");
    OptionError::Conflict(crate::message!(
        "{} {}: expected {form} with 0 <= LOWER < UPPER <= 100",
        OptionKey::PERCENTILES,
        Shown(given).to_string()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(
            percentiles_error("(90, 10)").to_string(),
            "percentiles (90, 10): expected (LOWER, UPPER) with 0 <= LOWER < UPPER <= 100"
        );
    }
}
