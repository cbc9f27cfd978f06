//! Integration tests of the `tiltnoise` command line and of the files and figures it writes, one
//! binary (linking dominates a test suite's build). The numerical core's tests are in
//! `crates/tiltnoise-core/tests/it`, whose helpers and named tolerances this binary shares.

/// The repository root: fixtures, reference data, examples and committed tilt data.
const REPO_ROOT: &str = env!("CARGO_MANIFEST_DIR");

mod common;
#[path = "../../crates/tiltnoise-core/tests/it/tolerances.rs"]
mod tolerances;

mod budget_at;
mod budget_open;
mod budget_outputs;
mod build_cmake;
mod cli;
mod cli_budget;
mod coherence_cli;
mod committed_figures;
mod crate_roles;
mod damping;
mod docs_run;
mod figures;
mod finiteness;
mod fit;
mod force_tf;
mod fuzz;
mod input_readers;
mod input_units;
mod io_roundtrip;
mod job_outcomes;
mod layout;
mod limits;
mod mc_outputs;
mod miniseed_input;
mod noise_models;
mod option_repeats;
mod output_conventions;
#[allow(
    unsafe_code,
    reason = "signals and resource limits of child processes (libc)"
)]
mod process;
mod romy_budget;
mod simulate_cli;
mod simulate_roundtrip;
mod six_component;
mod streaming;
mod subtract;
mod thermal;
mod translation_cli;
mod visibility_cli;
mod vocabulary;
