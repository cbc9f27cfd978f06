//! The `tiltnoise` command line as a library: its clap command tree ([`cli::Cli`]), the run
//! of each subcommand and its interrupt handler ([`interrupt`]). The binary (`src/main.rs`)
//! parses, runs and maps errors to exit codes; the tests read the command tree from here to
//! check that every option means one thing across the commands, and install the handler in a
//! process of their own to interrupt a write at a moment of their choosing.

pub mod cli;
pub mod interrupt;
pub mod option_style;
