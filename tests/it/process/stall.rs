//! An interrupt at any step of the staging of an output leaves nothing behind, however long a
//! writer stalls there: between registering its staging directory and creating its file,
//! while the file is open and half written, and once it is staged, waiting for the commit;
//! and writers racing the handler (creating, writing, committing as fast as they can) leave
//! only whole runs.
//!
//! The tool has no hook for this: this test binary runs itself again as a child process
//! ([`child_command`]) which installs the command line's own interrupt handler
//! (`tiltnoise::interrupt::install`) and drives `tiltnoise-io`'s staging API directly,
//! stalling where [`STEP`] (an environment variable only this file reads) says. The parent
//! sends the signal during the stall and checks the end: exit code 2, the handler's one line,
//! and nothing left in the directory.

use super::{child_stderr, default_signals, wait_bounded};
use crate::common::listing;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;
use tiltnoise_io::{AtomicFile, Staging};

/// The step a child stalls at (the name of a [`Step`]), or `race`; unset in the parent.
const STEP: &str = "TILTNOISE_TEST_STALL_STEP";

/// The directory a child writes in.
const DIR: &str = "TILTNOISE_TEST_STALL_DIR";

/// What a child prints on standard output, on a line of its own (after libtest's `test NAME
/// ... `), when it has reached its stall.
const STALLED: &str = "stalled at";

/// How long a child stalls: far longer than the parent takes to send its signal, so a child
/// that is still running afterwards (the handler did not end it) fails the test by its exit
/// status, not by a timeout.
const STALL: Duration = Duration::from_secs(30);

/// Where a child stalls.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    /// The staging directory is created and registered; the file is not created yet.
    Registered,
    /// The file is created, open and half written (HDF5, a dataset written, not closed).
    Writing,
    /// The file is finished and handed to the run's `Staging`, which is not committed yet.
    Staged,
}

impl Step {
    const ALL: [Step; 3] = [Step::Registered, Step::Writing, Step::Staged];

    fn name(self) -> &'static str {
        match self {
            Step::Registered => "registered",
            Step::Writing => "writing",
            Step::Staged => "staged",
        }
    }
}

/// The name libtest knows the test `test` of this module by (`process::stall::TEST`).
fn test_name(test: &str) -> String {
    let module = module_path!();
    let module = module.split_once("::").map_or(module, |(_, rest)| rest);
    format!("{module}::{test}")
}

/// This test binary, running only `test` as a child in `dir` with `step`, its standard output
/// and error piped and the default action for the signals sent.
fn child_command(test: &str, step: &str, dir: &Path) -> Command {
    let mut c = Command::new(std::env::current_exe().expect("the test binary's path"));
    c.args([
        &test_name(test),
        "--exact",
        "--nocapture",
        "--test-threads=1",
    ])
    .env(STEP, step)
    .env(DIR, dir)
    .env("HDF5_USE_FILE_LOCKING", "FALSE")
    .stdin(Stdio::null())
    .stdout(Stdio::piped())
    .stderr(Stdio::piped());
    default_signals(&mut c);
    c
}

/// Reads the child's standard output up to the line that says it has stalled, and returns
/// that line; panics if the child ends before.
fn wait_for_stall(child: &mut Child) -> String {
    let out = child.stdout.take().expect("piped");
    let mut lines = BufReader::new(out).lines();
    loop {
        match lines.next() {
            Some(Ok(line)) if line.starts_with(STALLED) => return line,
            Some(Ok(_)) => continue,
            other => {
                let _ = child.kill();
                let status = child.wait().unwrap();
                panic!(
                    "the child ended before its stall ({other:?}, {status}): {}",
                    child_stderr(child)
                );
            }
        }
    }
}

/// Sends `signal` to `child`.
fn send(child: &Child, signal: libc::c_int) {
    // SAFETY: kill only sends a signal to the child's process id, which is alive (it has not
    // been waited for).
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
}

/// The only entry of `dir`, which must be a staging directory of `target`.
fn staging_dir_of(dir: &Path, target: &str) -> PathBuf {
    let entries = listing(dir);
    assert_eq!(entries.len(), 1, "{entries:?}");
    let name = entries[0]
        .file_name()
        .unwrap()
        .to_str()
        .unwrap()
        .to_string();
    assert!(
        name.starts_with(&format!(".{target}.")) && name.ends_with(".tmp") && entries[0].is_dir(),
        "{name}"
    );
    entries[0].clone()
}

#[test]
fn an_interrupt_at_any_step_of_a_write_leaves_nothing() {
    if let Ok(step) = std::env::var(STEP) {
        let step = Step::ALL.into_iter().find(|s| s.name() == step);
        stalled_writer(
            step.expect("a step"),
            Path::new(&std::env::var(DIR).unwrap()),
        );
    }
    let signals = [
        (libc::SIGINT, "SIGINT"),
        (libc::SIGTERM, "SIGTERM"),
        (libc::SIGHUP, "SIGHUP"),
    ];
    for step in Step::ALL {
        for (signal, name) in signals {
            let dir = tempfile::tempdir().unwrap();
            let mut child = child_command(
                "an_interrupt_at_any_step_of_a_write_leaves_nothing",
                step.name(),
                dir.path(),
            )
            .spawn()
            .unwrap();
            let line = wait_for_stall(&mut child);
            assert_eq!(line, format!("{STALLED} {}", step.name()));
            // During the stall: the staging directory and, from the creation on, the file in
            // it; nothing at the target.
            let staging = staging_dir_of(dir.path(), "out.h5");
            assert_eq!(staging.join("out.h5").exists(), step != Step::Registered);
            send(&child, signal);
            let status = wait_bounded(&mut child, Duration::from_secs(20));
            let err = child_stderr(&mut child);
            assert_eq!(status.code(), Some(2), "{step:?}, {name}: {err}");
            assert_eq!(
                err,
                format!(
                    "tiltnoise: error: interrupted by {name}; 1 staged output(s) removed, no \
                     output written\n"
                ),
                "{step:?}"
            );
            assert_eq!(
                listing(dir.path()),
                Vec::<PathBuf>::new(),
                "{step:?}, {name}"
            );
        }
    }
}

/// The child of [`an_interrupt_at_any_step_of_a_write_leaves_nothing`]: writes `dir/out.h5`
/// as the HDF5 writers do, stalling at `step`. Never returns: the handler ends the process
/// (exit code 2) during the stall; if it does not, the write goes on and the process ends
/// with exit code 0 (or a panic: the directory was removed), which fails the parent.
fn stalled_writer(step: Step, dir: &Path) -> ! {
    let _cancel = tiltnoise::interrupt::install();
    let stall = |at: Step| {
        if at == step {
            let mut out = std::io::stdout();
            writeln!(out, "\n{STALLED} {}", at.name()).unwrap();
            out.flush().unwrap();
            std::thread::sleep(STALL);
        }
    };
    let stage = Staging::new();
    let out = AtomicFile::create(&dir.join("out.h5")).unwrap();
    stall(Step::Registered);
    let file = hdf5::File::create(out.temp_path()).unwrap();
    file.new_dataset_builder()
        .with_data(&ndarray::arr1(&[1.0f64, 2.0, 3.0]))
        .create("half")
        .unwrap();
    stall(Step::Writing);
    file.new_dataset_builder()
        .with_data(&ndarray::arr1(&[4.0f64]))
        .create("rest")
        .unwrap();
    file.close().unwrap();
    out.finish(&stage).unwrap();
    stall(Step::Staged);
    stage.commit().unwrap();
    std::process::exit(0)
}

/// Threads of the racing child, and the delays (ms) after which the parent interrupts it.
const RACERS: usize = 3;
const RACE_DELAYS_MS: [u64; 8] = [0, 1, 2, 3, 5, 8, 13, 21];

/// What every output of the racing child holds.
const WHOLE: &str = "whole\n";

#[test]
fn writers_racing_an_interrupt_leave_only_whole_runs() {
    if std::env::var(STEP).as_deref() == Ok("race") {
        racing_writers(Path::new(&std::env::var(DIR).unwrap()));
    }
    for (i, delay_ms) in RACE_DELAYS_MS.into_iter().enumerate() {
        let (signal, name) = match i % 2 {
            0 => (libc::SIGINT, "SIGINT"),
            _ => (libc::SIGTERM, "SIGTERM"),
        };
        let dir = tempfile::tempdir().unwrap();
        let mut child = child_command(
            "writers_racing_an_interrupt_leave_only_whole_runs",
            "race",
            dir.path(),
        )
        .spawn()
        .unwrap();
        wait_for_stall(&mut child);
        std::thread::sleep(Duration::from_millis(delay_ms));
        send(&child, signal);
        let status = wait_bounded(&mut child, Duration::from_secs(20));
        let err = child_stderr(&mut child);
        assert_eq!(status.code(), Some(2), "{delay_ms} ms, {name}: {err}");
        // `... interrupted by SIGINT; N staged output(s) removed, M output(s) written before`
        // (or `no output written`): M is what the commits renamed before the handler ran.
        let head = format!("tiltnoise: error: interrupted by {name}; ");
        let rest = err
            .strip_prefix(&head)
            .and_then(|r| r.strip_suffix('\n'))
            .unwrap_or_else(|| panic!("{err}"));
        assert!(!rest.contains('\n') && !rest.contains("could not"), "{err}");
        let committed: usize = match rest.split_once(", ") {
            Some((_, "no output written")) => 0,
            Some((_, w)) => w
                .strip_suffix(" output(s) written before")
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("{err}")),
            None => panic!("{err}"),
        };
        // No staging directory, nothing else; every run's two outputs together and whole.
        let names: Vec<String> = listing(dir.path())
            .iter()
            .map(|p| p.file_name().unwrap().to_str().unwrap().to_string())
            .collect();
        assert_eq!(names.len(), committed, "{delay_ms} ms: {names:?}");
        for n in &names {
            assert!(n.ends_with(".a.csv") || n.ends_with(".b.csv"), "{n}");
            let pair = match n.strip_suffix(".a.csv") {
                Some(run) => format!("{run}.b.csv"),
                None => format!("{}.a.csv", n.strip_suffix(".b.csv").unwrap()),
            };
            assert!(names.contains(&pair), "{n} without {pair}");
            let text = std::fs::read_to_string(dir.path().join(n)).unwrap();
            assert_eq!(text, WHOLE, "{n}");
        }
    }
}

/// The child of [`writers_racing_an_interrupt_leave_only_whole_runs`]: [`RACERS`] threads, each
/// writing runs of two outputs (`T.R.a.csv`, `T.R.b.csv`) and committing every other run, as
/// fast as they can, until the handler ends the process. Errors are ignored: once the handler
/// has removed a staging directory, the writer in it fails (ENOENT), which is the point.
fn racing_writers(dir: &Path) -> ! {
    let _cancel = tiltnoise::interrupt::install();
    for t in 0..RACERS {
        let dir = dir.to_path_buf();
        std::thread::spawn(move || {
            for run in 0.. {
                let _ = write_run(&dir, t, run);
            }
        });
    }
    let mut out = std::io::stdout();
    writeln!(out, "\n{STALLED} race").unwrap();
    out.flush().unwrap();
    std::thread::sleep(STALL);
    std::process::exit(0)
}

/// Run `run` of thread `t` of [`racing_writers`]: its two outputs, committed when `run` is even.
fn write_run(dir: &Path, t: usize, run: usize) -> Result<(), tiltnoise_io::OutputError> {
    let stage = Staging::new();
    for part in ["a", "b"] {
        let path = dir.join(format!("{t}.{run}.{part}.csv"));
        stage.write(&path, |tmp| {
            std::fs::write(tmp, WHOLE).map_err(|e| e.to_string())
        })?;
    }
    if run % 2 == 0 {
        stage.commit()?;
    }
    Ok(())
}
