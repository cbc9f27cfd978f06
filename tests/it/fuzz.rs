//! Fuzzing of every reader of user files, on stable Rust: one test per target
//! ([`targets::ALL`]) feeds it mutated inputs ([`mutate`]: byte-level mutations of the seed
//! corpus in `tests/fuzz_corpus/<target>/`; [`hdf5_gen`]: structured HDF5 files) and fails
//! when a reader panics or breaks what a successful read promises. [`regressions`] replays every
//! input kept under `tests/fuzz_corpus/<target>/regressions/`.
//!
//! The budget comes from the environment (`docs/robustness.md`):
//!
//! * `TILTNOISE_FUZZ_SECONDS`: run each target this long (CI: 60);
//! * `TILTNOISE_FUZZ_ITERATIONS`: run exactly this many inputs (default 200, so that a plain
//!   `cargo test` stays fast; wins over the seconds);
//! * `TILTNOISE_FUZZ_SEED`: the run's seed, decimal or `0x` hex (default: fixed, or from the
//!   clock when a time budget is set);
//! * `TILTNOISE_FUZZ_FIRST`: the first iteration (default 0): each iteration draws its input
//!   from its own random stream, so `SEED`, `FIRST` and `ITERATIONS=1` regenerate one input;
//! * `TILTNOISE_FUZZ_CRASH_DIR`: where crashing inputs are written (default
//!   `target/tmp/fuzz_crashes/<target>/`);
//! * `TILTNOISE_FUZZ_STRICT`: also check the promises with open findings ([`targets`]).

mod hdf5_gen;
mod mutate;
mod targets;

use mutate::{mutate, Dice};
use std::cell::{Cell, RefCell};
use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{mpsc, Arc, Mutex};
use std::time::{Duration, Instant};
use targets::Target;

/// The seed of a run without `TILTNOISE_FUZZ_SEED` and without a time budget.
const DEFAULT_SEED: u64 = 0x7117_2013;
/// Inputs per target without a budget in the environment.
const DEFAULT_ITERATIONS: u64 = 200;
/// Crashing inputs written per target: one per distinct panic location, at most this many.
const MAX_SAVED: usize = 8;
/// An input whose readers run longer than this is a hang. Most take milliseconds; a few
/// damaged HDF5 files take the library about 20 s to refuse (`docs/robustness.md`).
const HANG: Duration = Duration::from_secs(120);

/// How long a target runs.
#[derive(Debug, Clone, Copy)]
enum Budget {
    Iterations(u64),
    Time(Duration),
}

/// The run's settings, from the environment.
#[derive(Debug, Clone, Copy)]
struct Config {
    seed: u64,
    first: u64,
    budget: Budget,
}

fn env_value(name: &str) -> Option<String> {
    std::env::var(name).ok().filter(|v| !v.trim().is_empty())
}

fn parse_u64(name: &str, text: &str) -> u64 {
    let t = text.trim();
    let parsed = match t.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(hex, 16),
        None => t.parse(),
    };
    parsed.unwrap_or_else(|_| panic!("{name}=`{text}`: not a whole number (decimal or 0x hex)"))
}

impl Config {
    fn from_env() -> Config {
        let iterations = env_value("TILTNOISE_FUZZ_ITERATIONS")
            .map(|v| parse_u64("TILTNOISE_FUZZ_ITERATIONS", &v));
        let seconds = env_value("TILTNOISE_FUZZ_SECONDS").map(|v| {
            v.trim()
                .parse::<f64>()
                .ok()
                .filter(|s| s.is_finite() && *s >= 0.0)
                .unwrap_or_else(|| panic!("TILTNOISE_FUZZ_SECONDS=`{v}`: not a number >= 0"))
        });
        let budget = match (iterations, seconds) {
            (Some(n), _) => Budget::Iterations(n),
            (None, Some(s)) => Budget::Time(Duration::from_secs_f64(s)),
            (None, None) => Budget::Iterations(DEFAULT_ITERATIONS),
        };
        let seed = match env_value("TILTNOISE_FUZZ_SEED") {
            Some(v) => parse_u64("TILTNOISE_FUZZ_SEED", &v),
            None if matches!(budget, Budget::Time(_)) => std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(DEFAULT_SEED, |d| d.as_nanos() as u64),
            None => DEFAULT_SEED,
        };
        let first =
            env_value("TILTNOISE_FUZZ_FIRST").map_or(0, |v| parse_u64("TILTNOISE_FUZZ_FIRST", &v));
        Config {
            seed,
            first,
            budget,
        }
    }
}

/// A line on standard error past the test harness's capture: seeds and counts belong in the
/// CI log even when the test passes, and the seed must be there if a signal ends the process.
fn say(line: &str) {
    let _ = std::io::stderr().write_all(format!("{line}\n").as_bytes());
}

thread_local! {
    /// The message and location of the last panic on this thread.
    static LAST_PANIC: RefCell<String> = const { RefCell::new(String::new()) };
    /// Whether panics on this thread are findings recorded by the fuzzer, not printed.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Records every panic's message and location for the report; panics inside a fuzzed reader
/// are not printed (thousands of them would bury the report), all others are, as before.
fn install_panic_recorder() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            LAST_PANIC.with(|p| *p.borrow_mut() = info.to_string());
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
}

/// Runs `f`, catching a panic: `Err(message with location)`.
fn guarded(f: impl FnOnce()) -> Result<(), String> {
    install_panic_recorder();
    QUIET.with(|q| q.set(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(false));
    result.map_err(|_| LAST_PANIC.with(|p| p.borrow().clone()))
}

/// Where a target's inputs come from.
enum Source {
    /// Mutations of the files in `tests/fuzz_corpus/<target>/`.
    Corpus,
    /// Written by a generator from the iteration's random stream.
    Generated(fn(&mut Dice, &Path)),
}

fn corpus_dir(target: &Target) -> PathBuf {
    Path::new(crate::REPO_ROOT)
        .join("tests/fuzz_corpus")
        .join(target.name)
}

/// The regular files of `dir`, sorted (none if it does not exist).
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.expect("a readable directory entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Where each input of `target` is written before its readers run: a fixed path, so that the
/// input is found there if a signal ends the process (an abort, a stack overflow).
fn in_flight(target: &Target) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz");
    std::fs::create_dir_all(&dir).expect("the scratch directory can be created");
    dir.join(format!("{}-input.{}", target.name, target.ext))
}

fn crash_dir(target: &Target) -> PathBuf {
    env_value("TILTNOISE_FUZZ_CRASH_DIR")
        .map_or_else(
            || Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz_crashes"),
            PathBuf::from,
        )
        .join(target.name)
}

/// The seed of `target`'s streams: the run's seed mixed with the target's name (FNV-1a), so
/// that targets of one run draw different inputs.
fn target_seed(seed: u64, target: &Target) -> u64 {
    target
        .name
        .bytes()
        .fold(seed ^ 0xcbf2_9ce4_8422_2325, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        })
}

/// A panicking input: the iteration, the panic and where the input was saved.
struct Crash {
    iteration: u64,
    panic: String,
    saved: Option<PathBuf>,
}

/// Fuzzes `target` with inputs from `source` for the budget of the environment.
fn fuzz(target: Target, source: Source) {
    crate::common::disable_hdf5_file_locking();
    let config = Config::from_env();
    let corpus: Vec<Vec<u8>> = match source {
        Source::Corpus => {
            let files = files_in(&corpus_dir(&target));
            assert!(
                !files.is_empty(),
                "no corpus in {}",
                corpus_dir(&target).display()
            );
            files.iter().map(|f| std::fs::read(f).unwrap()).collect()
        }
        Source::Generated(_) => Vec::new(),
    };
    let input = in_flight(&target);
    let seed = target_seed(config.seed, &target);
    if let Budget::Time(t) = config.budget {
        say(&format!(
            "fuzz {}: seed {:#x}, {} s from iteration {}; the input in flight is {}",
            target.name,
            config.seed,
            t.as_secs_f64(),
            config.first,
            input.display()
        ));
    }

    let start = Instant::now();
    let current = Arc::new(Mutex::new((config.first, start)));
    let (stop, watchdog) = watch_for_hangs(target, config.seed, &input, &current);
    let mut crashes: Vec<Crash> = Vec::new();
    let mut iteration = config.first;
    loop {
        let done = iteration - config.first;
        let over = match config.budget {
            Budget::Iterations(n) => done >= n,
            Budget::Time(t) => start.elapsed() >= t,
        };
        if over {
            break;
        }
        *current.lock().expect("never poisoned") = (iteration, Instant::now());
        let mut dice = Dice::new(seed, iteration);
        // A new file each time: overwriting one in place makes ext4 flush it to disk on
        // every close (its replace-via-truncate heuristic), which costs most of the time.
        let _ = std::fs::remove_file(&input);
        match source {
            Source::Corpus => std::fs::write(&input, mutate(&mut dice, &corpus)).unwrap(),
            Source::Generated(write) => {
                if let Err(panic) = guarded(|| write(&mut dice, &input)) {
                    panic!(
                        "the input generator of {} failed (seed {:#x}, iteration {iteration}): \
                         {panic}",
                        target.name, config.seed
                    );
                }
            }
        }
        if let Err(panic) = guarded(|| (target.read)(&input)) {
            let location = panic.lines().next().unwrap_or_default().to_string();
            let new = !crashes
                .iter()
                .any(|c| c.panic.lines().next() == Some(location.as_str()));
            let saved = (new && crashes.iter().filter(|c| c.saved.is_some()).count() < MAX_SAVED)
                .then(|| save_crash(&target, config.seed, iteration, &input, "panic"));
            crashes.push(Crash {
                iteration,
                panic,
                saved,
            });
        }
        iteration += 1;
    }
    drop(stop);
    watchdog.join().expect("the watchdog ends cleanly");

    let elapsed = start.elapsed().as_secs_f64();
    let done = iteration - config.first;
    say(&format!(
        "fuzz {}: {done} inputs (seed {:#x}, iterations {}..{iteration}) in {elapsed:.1} s, \
         {:.0}/s, {} panicked",
        target.name,
        config.seed,
        config.first,
        done as f64 / elapsed.max(1e-9),
        crashes.len()
    ));
    if !crashes.is_empty() {
        panic!("{}", report(&target, config.seed, done, &crashes));
    }
}

/// Starts a thread that ends the process when one input has run for longer than [`HANG`]: a
/// reader stuck in a loop (in C, say) cannot be stopped, and a test that never ends would only
/// show as a CI timeout. It saves the input and names the seed and iteration first. The
/// fuzzer sets `current` to (iteration, start time) before each input and drops the returned
/// sender when it is done.
fn watch_for_hangs(
    target: Target,
    seed: u64,
    input: &Path,
    current: &Arc<Mutex<(u64, Instant)>>,
) -> (mpsc::Sender<()>, std::thread::JoinHandle<()>) {
    let (stop, stopped) = mpsc::channel::<()>();
    let input = input.to_path_buf();
    let current = Arc::clone(current);
    let thread = std::thread::spawn(move || {
        while let Err(mpsc::RecvTimeoutError::Timeout) =
            stopped.recv_timeout(Duration::from_secs(1))
        {
            let (iteration, since) = *current.lock().expect("never poisoned");
            if since.elapsed() > HANG {
                let saved = save_crash(&target, seed, iteration, &input, "hang");
                say(&format!(
                    "fuzz target {}: iteration {iteration} (seed {seed:#x}) has run for more \
                     than {} s, a hang: input saved to {}; aborting the process",
                    target.name,
                    HANG.as_secs(),
                    saved.display()
                ));
                std::process::abort();
            }
        }
    });
    (stop, thread)
}

/// Copies the input of `iteration` to the crash directory; `kind` is `panic` or `hang`.
fn save_crash(target: &Target, seed: u64, iteration: u64, input: &Path, kind: &str) -> PathBuf {
    let dir = crash_dir(target);
    std::fs::create_dir_all(&dir).expect("the crash directory can be created");
    let path = dir.join(format!(
        "{}-seed{seed:#x}-iter{iteration}-{kind}.{}",
        target.name, target.ext
    ));
    std::fs::copy(input, &path).expect("the crashing input can be saved");
    path
}

fn report(target: &Target, seed: u64, done: u64, crashes: &[Crash]) -> String {
    let mut text = format!(
        "fuzz target {}: {} of {done} inputs panicked (seed {seed:#x}).\n",
        target.name,
        crashes.len()
    );
    for c in crashes.iter().filter(|c| c.saved.is_some()) {
        let saved = c.saved.as_ref().expect("filtered");
        text.push_str(&format!(
            "\niteration {}: {}\n  input: {}\n",
            c.iteration,
            c.panic,
            saved.display()
        ));
    }
    let first = crashes[0].iteration;
    text.push_str(&format!(
        "\nReplay one: TILTNOISE_FUZZ_SEED={seed:#x} TILTNOISE_FUZZ_FIRST={first} \
         TILTNOISE_FUZZ_ITERATIONS=1 cargo test --release -p tiltnoise --test it fuzz::{}\n\
         Keep it: copy the input to tests/fuzz_corpus/{}/regressions/ (replayed by \
         fuzz::regressions on every run).",
        target.name, target.name
    ));
    text
}

#[test]
fn tilt_csv() {
    fuzz(targets::TILT_CSV, Source::Corpus);
}

#[test]
fn tilt_h5_bytes() {
    fuzz(targets::TILT_H5_BYTES, Source::Corpus);
}

#[test]
fn h5_structured() {
    fuzz(
        targets::H5_STRUCTURED,
        Source::Generated(hdf5_gen::write_mutated),
    );
}

#[test]
fn measured_h5_bytes() {
    fuzz(targets::MEASURED_H5_BYTES, Source::Corpus);
}

#[test]
fn measured_csv() {
    fuzz(targets::MEASURED_CSV, Source::Corpus);
}

#[test]
fn miniseed() {
    fuzz(targets::MINISEED, Source::Corpus);
}

#[test]
fn measured_modes() {
    fuzz(targets::MEASURED_MODES, Source::Corpus);
}

#[test]
fn freq_file() {
    fuzz(targets::FREQ_FILE, Source::Corpus);
}

#[test]
fn freq_spec() {
    fuzz(targets::FREQ_SPEC, Source::Corpus);
}

#[test]
fn params_toml() {
    fuzz(targets::PARAMS_TOML, Source::Corpus);
}

#[test]
fn params_override() {
    fuzz(targets::PARAMS_OVERRIDE, Source::Corpus);
}

/// Every input kept under `tests/fuzz_corpus/<target>/regressions/` (inputs that once made a
/// reader panic), read again by its target.
#[test]
fn regressions() {
    crate::common::disable_hdf5_file_locking();
    let mut failures = Vec::new();
    let mut count = 0;
    for target in targets::ALL {
        for file in files_in(&corpus_dir(&target).join("regressions")) {
            count += 1;
            if let Err(panic) = guarded(|| (target.read)(&file)) {
                failures.push(format!("{} ({}): {panic}", file.display(), target.name));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {count} regression inputs panic:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

/// A global heap whose free-space object has size 0 once made the HDF5 library decode it
/// forever; the vendored library refuses it (vendor/README.md). Every HDF5 reader now answers
/// with an error, and so does the command line, with one line naming the file, exit 2. The
/// readers run on a thread watched by a bound far above any read's time: without the patch
/// the test fails at the bound instead of hanging the suite.
#[test]
fn a_global_heap_with_an_empty_free_space_object_is_refused() {
    crate::common::disable_hdf5_file_locking();
    let file = corpus_dir(&targets::TILT_H5_BYTES)
        .join("regressions")
        .join("global_heap_free_space_of_size_0.h5");
    assert!(file.is_file(), "{} is missing", file.display());
    let (done, finished) = std::sync::mpsc::channel();
    let on_thread = file.clone();
    std::thread::spawn(move || {
        let tilt = tiltnoise_io::input::read_tilt_series(&on_thread, &Default::default());
        let measured = tiltnoise_io::input::read_measured_input(&on_thread);
        let _ = done.send((tilt.is_err(), measured.is_err()));
    });
    let (tilt_refused, measured_refused) = finished
        .recv_timeout(std::time::Duration::from_secs(HDF5_HANG_BOUND_S))
        .unwrap_or_else(|_| {
            panic!(
                "the HDF5 readers did not return within {HDF5_HANG_BOUND_S} s on {}",
                file.display()
            )
        });
    assert!(
        tilt_refused && measured_refused,
        "a damaged heap was read as valid"
    );
    let out = crate::common::tiltnoise(&["budget", "--tilt", file.to_str().unwrap()]);
    let err = crate::common::stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("global_heap_free_space_of_size_0.h5"), "{err}");
}

/// The bound of the test above: a read of this 2 kB file takes milliseconds.
const HDF5_HANG_BOUND_S: u64 = 60;
