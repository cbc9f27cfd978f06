//! The `tiltnoise` binary: parse, run, map errors to exit code 2 with a one-line message.

mod cli;

use clap::Parser;
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = cli::Cli::parse();
    match cli::run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tiltnoise: error: {e:#}");
            ExitCode::from(2)
        }
    }
}
