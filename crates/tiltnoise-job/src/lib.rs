//! The jobs of tiltnoise: for each command, a typed request (plain values, paths and parsed
//! options, no option spellings) and one `run` that opens each input once, picks streaming or
//! a whole read, checks the options against the input and the results, and returns a typed
//! result that the writers and figures take. The command line and the Python package are
//! adapters around these: they parse their own syntax into a request, run it and render the
//! result; neither orchestrates a job itself.
//!
//! Errors ([`JobError`]) name the option or key that failed by its snake-case name
//! (`segment_duration`); each front end renders them in its own spelling with
//! [`JobError::message`]. Every run takes a [`Cancel`] token that the front end sets (the
//! command line from its signal handler, Python from its own signal check).

#![forbid(unsafe_code)]

pub mod budget;
pub mod coherence;
mod error;
mod figure;
pub mod figures;
pub mod files;
pub mod fit;
mod given;
pub mod methods;
pub mod modes;
pub mod monte_carlo;
pub mod outcome;
pub mod params;
pub mod progress;
pub mod simulate;
pub mod subtract;
pub mod tf;
pub mod visibility;

pub use error::JobError;
pub use figure::save_image;
pub use given::{read_given, witness_noise, AsdSpec, ReadoutItem, TermItem, WitnessItem};
pub use outcome::{output_kind, Invocation, Outcome, Provenance};
pub use progress::{Progress, Silent};
pub use tiltnoise_core::cancel::Cancel;
