//! [`ChannelScale`]: a factor that turns one source channel's samples into rad or rad/s, for
//! records in digitizer counts (`--scale CHANNEL=FACTOR`). It multiplies the samples as read,
//! before the axis map's sign; the provenance says so.

use super::error::InputError;
use crate::error::{shown_list, Shown};
use crate::option_key::OptionKey;
use crate::repeats::refuse_repeats;
use std::fmt;
use std::path::Path;
use std::str::FromStr;

/// `CHANNEL=FACTOR`: multiply the samples of source channel `CHANNEL` by `FACTOR` (rad or
/// rad/s per count, or per unit of the file).
///
/// ```
/// use tiltnoise_core::input::ChannelScale;
/// let s: ChannelScale = "BJE=2.5e-9".parse().unwrap();
/// assert_eq!((s.channel.as_str(), s.factor), ("BJE", 2.5e-9));
/// assert!("BJE=0".parse::<ChannelScale>().is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelScale {
    /// The source channel (CSV column, HDF5 dataset, or SEED code `NET.STA.LOC.CHA` / `CHA`).
    pub channel: String,
    /// The factor, finite and non-zero.
    pub factor: f64,
}

impl FromStr for ChannelScale {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let syntax = "syntax: CHANNEL=FACTOR, e.g. BJE=2.5e-9 (rad or rad/s per count)";
        let Some((channel, factor)) = s.split_once('=') else {
            return Err(format!("`{}` has no `=`; {syntax}", Shown(s)));
        };
        let channel = channel.trim();
        if channel.is_empty() {
            return Err(format!("`{}` names no channel; {syntax}", Shown(s)));
        }
        let factor = factor.trim();
        match factor.parse::<f64>() {
            Ok(v) if v.is_finite() && v != 0.0 => Ok(ChannelScale {
                channel: channel.to_string(),
                factor: v,
            }),
            _ => Err(format!(
                "factor `{}` of channel `{}` is not allowed: must be a finite, non-zero number; \
                 {syntax}",
                Shown(factor),
                Shown(channel)
            )),
        }
    }
}

impl fmt::Display for ChannelScale {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.channel, self.factor)
    }
}

/// The factor given for `channel`, if any.
pub fn scale_for(scales: &[ChannelScale], channel: &str) -> Option<f64> {
    scales
        .iter()
        .find(|s| s.channel == channel)
        .map(|s| s.factor)
}

/// Checks that every scale names one of the channels `available` of `path` (`kind`:
/// `column`, `dataset` or `channel`) and none twice.
pub fn check_scales(
    path: &Path,
    scales: &[ChannelScale],
    available: &[String],
    kind: &'static str,
) -> Result<(), InputError> {
    let channels: Vec<&str> = scales.iter().map(|s| s.channel.as_str()).collect();
    refuse_repeats(OptionKey::SCALE, "channel", &channels, |c| c.to_string()).map_err(|e| {
        InputError::Scale {
            path: path.to_path_buf(),
            channel: e.name,
            message: "is given a scale twice; allowed: once".to_string(),
        }
    })?;
    for s in scales {
        if !available.contains(&s.channel) {
            return Err(InputError::Scale {
                path: path.to_path_buf(),
                channel: s.channel.clone(),
                message: format!(
                    "is not a {kind} of the file; available {kind}s: {}",
                    shown_list(available)
                ),
            });
        }
    }
    Ok(())
}

/// Provenance note of a channel's factor.
pub fn scale_note(channel: &str, factor: f64, why: &str) -> String {
    format!("channel `{channel}`: samples multiplied by {factor:e} ({why}) before the axis map")
}
