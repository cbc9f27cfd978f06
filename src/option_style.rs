//! The command line's spelling of the options the libraries name in their messages
//! ([`OptionKey`]): the flag `--segment-duration` for the key `segment_duration`, a value after a
//! space (`--nperseg 8`), a mapping entry as `--units eta_t=urad`, a pair as `LOWER:UPPER`.

use std::fmt;
use tiltnoise_core::option_key::{render, OptionKey, OptionStyle};

/// `message` (an error of the libraries, or a chain of them) as the command line shows it:
/// every option it names spelled as a flag.
pub fn rendered(message: &dyn fmt::Display) -> String {
    render(&Flags, message)
}

/// The command line's [`OptionStyle`], with which `main` renders every error it prints.
pub struct Flags;

impl OptionStyle for Flags {
    fn option(&self, key: OptionKey) -> String {
        match key {
            OptionKey::DRAWN_OBSERVABLES => "--plot-observables".to_string(),
            // The inputs and observables of a transfer function (`inputs`, `outputs` in
            // Python).
            OptionKey::INPUTS => "--input".to_string(),
            OptionKey::OUTPUTS => "--observables".to_string(),
            // The grid of a model evaluation, `freq_hz` in Python.
            OptionKey::FREQ_HZ => "--freq".to_string(),
            _ => format!("--{}", key.key().replace('_', "-")),
        }
    }

    fn given(&self, key: OptionKey, value: &str) -> String {
        format!("{} {value}", self.option(key))
    }

    fn entry(&self, key: OptionKey, name: &str, value: &str) -> String {
        format!("{} {name}={value}", self.option(key))
    }

    fn pair(&self, first: &str, second: &str) -> String {
        format!("{first}:{second}")
    }
}
