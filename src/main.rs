//! The `tiltnoise` binary: parse, run, map errors to exit code 2 with a one-line message.

mod cli;

use clap::{CommandFactory, FromArgMatches};
use std::process::ExitCode;

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
        Err(e) => {
            eprintln!("tiltnoise: error: {e:#}");
            ExitCode::from(2)
        }
    }
}
