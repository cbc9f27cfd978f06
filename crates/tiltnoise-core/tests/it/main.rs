//! Integration tests of `tiltnoise-core`, one binary (linking dominates a test suite's build):
//! every transfer-function method against the double-double reference, the reference against
//! mpmath, modes, Monte Carlo, simulation and Welch against committed reference data. The tests
//! of files, figures and the command line are in the root package's `tests/it`.

/// The repository root: fixtures in `tests/fixtures/`, reference data in `scripts/reference/`.
const REPO_ROOT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

mod common;
mod tolerances;

mod as_built;
mod budget_summary;
mod cancel;
mod coherence;
mod energy_crosscheck;
mod freq_grid;
mod low_frequency;
mod mc;
mod methods;
mod modes;
mod polezero;
mod polezero_batch;
mod rate_spectra;
mod reference_precision;
mod scenes;
mod segment_projection;
mod simulate;
mod stability;
mod subtract;
mod subtract_ground;
mod subtract_pulls;
mod synthetic;
mod tilt_tf;
mod tiny_asymmetry;
mod translation_tf;
mod visibility_fit;
mod welch_scipy;
