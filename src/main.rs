//! The `tiltnoise` binary: parse, run, map errors to exit code 2 with a one-line message.

use clap::Parser;
use std::process::ExitCode;
use tiltnoise::cli::{run, Cli};

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("tiltnoise: error: {e:#}");
            ExitCode::from(2)
        }
    }
}
