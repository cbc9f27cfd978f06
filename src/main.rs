//! The `tiltnoise` binary: parse, run, map errors to exit code 2 with a one-line message.

use clap::error::ErrorKind;
use clap::{CommandFactory, FromArgMatches};
use std::process::ExitCode;
use tiltnoise::{cli, interrupt, option_style};
use tiltnoise_core::error::shown_within;

/// The longest error line printed (characters); values inside it are already cut to 200.
const MAX_ERROR_CHARS: usize = 2000;

fn main() -> ExitCode {
    // First: SIGINT, SIGTERM and SIGHUP cancel the run, remove the staging directories of the
    // outputs being written, print one line and end the process with exit code 2.
    let cancel = interrupt::install();
    // `--version` names the HDF5 library linked in (bundled, static).
    let version = format!(
        "{} (HDF5 {}, static)",
        env!("CARGO_PKG_VERSION"),
        tiltnoise_job::files::hdf5_version()
    );
    let parsed = cli::Cli::command()
        .version(version)
        .try_get_matches()
        .and_then(|m| cli::Cli::from_arg_matches(&m));
    let cli = match parsed {
        Ok(cli) => cli,
        Err(e) => return clap_exit(&e),
    };
    match cli::run(cli, cancel.clone()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(_) if cancel.is_cancelled() => interrupt::wait_for_the_handler(),
        // The reader of standard output has gone (`tiltnoise tf | head -1`): nothing to say.
        Err(e) if cli::is_closed_pipe(&e) => ExitCode::SUCCESS,
        // The libraries' errors name options as flags (`--nperseg`) when rendered here.
        Err(e) => fail(&option_style::rendered(&format_args!("{e:#}"))),
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

/// `--help` and `--version` print as usual (exit code 0); a command-line error is one line,
/// clap's message without the usage block (exit code 2).
fn clap_exit(e: &clap::Error) -> ExitCode {
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
            // A closed standard output loses the text; nothing else to do.
            let _ = e.print();
            ExitCode::SUCCESS
        }
        ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand | ErrorKind::MissingSubcommand => {
            let names: Vec<String> = cli::Cli::command()
                .get_subcommands()
                .map(|c| c.get_name().to_string())
                .filter(|n| n != "help")
                .collect();
            fail(&format!(
                "no command given; allowed: {} (tiltnoise --help describes them)",
                names.join(", ")
            ))
        }
        _ => fail(&clap_message(&e.render().to_string())),
    }
}

/// clap's message on one line: its lines up to the usage block, joined (a list of missing
/// arguments, the possible values and tips follow the first line).
fn clap_message(text: &str) -> String {
    let mut lines = text
        .lines()
        .map(str::trim)
        .take_while(|l| !l.starts_with("Usage:") && !l.starts_with("For more information"))
        .filter(|l| !l.is_empty());
    let first = lines.next().unwrap_or_default();
    let mut message = first.strip_prefix("error: ").unwrap_or(first).to_string();
    for line in lines {
        message.push_str(if message.ends_with(':') { " " } else { "; " });
        message.push_str(line);
    }
    message
}
