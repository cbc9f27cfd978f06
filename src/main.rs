//! The `tiltnoise` binary: parse, run, map errors to exit code 2 with a one-line message.

mod cli;

use clap::{CommandFactory, FromArgMatches};
use std::process::ExitCode;
use tiltnoise_core::error::shown_within;

/// The longest error line printed (characters); values inside it are already cut to 200.
const MAX_ERROR_CHARS: usize = 2000;

fn main() -> ExitCode {
    // `--version` names the HDF5 library linked in (bundled, static).
    let version = format!(
        "{} (HDF5 {}, static)",
        env!("CARGO_PKG_VERSION"),
        tiltnoise_io::hdf5_version()
    );
    let matches = cli::Cli::command().version(version).get_matches();
    let cli = match cli::Cli::from_arg_matches(&matches) {
        Ok(cli) => cli,
        Err(e) => e.exit(),
    };
    match cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        // The reader of standard output has gone (`tiltnoise tf | head -1`): nothing to say.
        Err(e) if cli::is_closed_pipe(&e) => ExitCode::SUCCESS,
        Err(e) => fail(&format!("{e:#}")),
    }
}

/// Prints `tiltnoise: error: MESSAGE` on one line, control characters escaped and the length
/// bounded whatever the message holds, and returns exit code 2.
fn fail(message: &str) -> ExitCode {
    cli::note(&format!(
        "tiltnoise: error: {}",
        shown_within(message, MAX_ERROR_CHARS)
    ));
    ExitCode::from(2)
}
