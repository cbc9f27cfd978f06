//! The `tiltnoise` command line as a library: its clap command tree ([`cli::Cli`]) and the run
//! of each subcommand. The binary (`src/main.rs`) parses, runs and maps errors to exit codes;
//! the tests read the command tree from here to check that every option means one thing
//! across the commands.

pub mod cli;
