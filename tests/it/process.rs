//! The process around the computation: a standard output that is closed or full, error
//! messages that stay one short line whatever the user or a file holds, command-line errors,
//! output paths checked before anything is computed and written all or none, and interrupts
//! during a computation or a write (and, in [`stall`], at every step of the staging of an
//! output). Every failure is one line on standard error with exit code 2, never a panic, and
//! leaves no file behind.
//!
//! Every child starts with the default action for the signals the tests send
//! ([`default_signals`]), whatever the test process inherited.

mod stall;

use crate::common;

use common::{assert_fails, assert_fails_without_output, listing, stderr, tiltnoise};
use std::io::{Read, Write};
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Output, Stdio};
use std::time::{Duration, Instant};

/// The binary, ready to spawn, with HDF5 file locking off (see [`common::tiltnoise`]) and the
/// default action for the signals the tests send ([`default_signals`]).
fn command(args: &[&str], dir: &Path) -> Command {
    common::disable_hdf5_file_locking();
    let mut c = Command::new(env!("CARGO_BIN_EXE_tiltnoise"));
    c.env("HDF5_USE_FILE_LOCKING", "FALSE")
        .current_dir(dir)
        .args(args);
    default_signals(&mut c);
    c
}

/// The signals the tests send, and which a child must receive with their default action.
const SENT_SIGNALS: [libc::c_int; 3] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP];

/// Makes `child` start with the default action for [`SENT_SIGNALS`]. An ignored signal survives
/// `exec`: under `nohup` SIGHUP is ignored, in a shell script's background job SIGINT is, and a
/// child would inherit that from the test process. (The signal mask is reset by `spawn`.)
fn default_signals(child: &mut Command) -> &mut Command {
    use std::os::unix::process::CommandExt;
    // SAFETY: between fork and exec the closure calls only signal(2), which is
    // async-signal-safe, with constant arguments.
    unsafe {
        child.pre_exec(|| {
            for signal in SENT_SIGNALS {
                if libc::signal(signal, libc::SIG_DFL) == libc::SIG_ERR {
                    return Err(std::io::Error::last_os_error());
                }
            }
            Ok(())
        })
    }
}

/// Asserts one line on standard error, and neither a panic nor a backtrace.
fn assert_one_line(what: &str, err: &str) {
    assert_eq!(err.trim_end().lines().count(), 1, "{what}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
}

/// Waits for `child` at most `limit`; a child still running then is killed and the test fails.
fn wait_bounded(child: &mut Child, limit: Duration) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("the child ran longer than {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Says on standard error, past the test harness's capture, that `test` was skipped and why.
fn skipped(test: &str, why: &str) {
    let line = format!("skipped {test}: {why}\n");
    std::io::stderr()
        .write_all(line.as_bytes())
        .expect("standard error is writable");
}

/// Standard error of a finished child.
fn child_stderr(child: &mut Child) -> String {
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    err
}

#[test]
fn a_reader_that_goes_away_ends_the_run_quietly() {
    let dir = tempfile::tempdir().unwrap();
    // `tiltnoise tf | head -c 1`: the CSV (megabytes) is far more than the pipe holds.
    let mut child = command(&["tf"], dir.path())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 1];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    assert_eq!(&first, b"#", "the CSV starts with its `#` lines");
    // The read end is closed here, with the rest unread.
    let status = wait_bounded(&mut child, Duration::from_secs(120));
    let err = child_stderr(&mut child);
    assert_eq!(status.code(), Some(0), "{err}");
    assert_eq!(err, "", "a closed pipe is not an error to report");

    // Standard output closed before the run prints anything: the outputs, staged until then,
    // are not committed.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = command(
        &[
            "tf",
            "--freq",
            "1e-4:50:30",
            "--save",
            "a.h5",
            "--save",
            "a.svg",
        ],
        dir.path(),
    )
    .stdout(writer)
    .output()
    .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert_eq!(stderr(&out), "");
    assert_eq!(listing(dir.path()), Vec::<std::path::PathBuf>::new());
}

#[test]
fn a_full_standard_output_is_one_error_line() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        skipped(
            "a_full_standard_output_is_one_error_line",
            "no /dev/full here",
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["tf", "--freq", "1e-4:50:30"][..],
        &["modes"],
        &["tf", "--freq", "1e-4:50:30", "--save", "a.h5"],
    ] {
        let out = command(args, dir.path())
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_one_line(&format!("{args:?}"), &err);
        assert!(
            err.starts_with("tiltnoise: error: cannot write to standard output: No space left"),
            "{args:?}: {err}"
        );
        assert!(listing(dir.path()).is_empty(), "{args:?} left files");
    }
}

#[test]
fn values_from_the_user_are_shown_on_one_short_line() {
    let long = format!("length.h_m={}", "x".repeat(100_000));
    let out = tiltnoise(&["--set", &long, "modes"]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2));
    assert_one_line("100 kB --set", &err);
    assert!(err.len() < 1000, "{} bytes: {err}", err.len());
    assert!(err.contains("... (100011 bytes)"), "{err}");

    // Control characters are escaped, so the message stays on one line and cannot drive the
    // terminal.
    assert_fails(
        &["--set", "length.h_m=1\n2\u{1b}[31m", "modes"],
        &["`1\\n2\\x1b[31m`", "not a number"],
    );
    assert_fails(
        &["tf", "--readout-typo"],
        &["unexpected argument '--readout-typo'"],
    );
    assert_fails(
        &["budget", "--tilt", "t.csv", "--readout", "X=9e-9\u{1b}"],
        &["--readout X=9e-9\\x1b: `9e-9\\x1b` is not a number"],
    );
    assert_fails(
        &["simulate", "--init", "phi_b=\u{7}"],
        &["--init phi_b=\\x07"],
    );
}

#[test]
fn values_from_files_are_shown_on_one_short_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let write = |name: &str, text: &str| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p.to_str().unwrap().to_string()
    };
    // A megabyte-long header and a field with a terminal escape.
    let header = write(
        "header.csv",
        &format!("time_s,{}\n0,1\n1,2\n", "A".repeat(1 << 20)),
    );
    // Many columns on a header line under the line-length limit (64 KiB): the list of them
    // in the message is cut.
    let columns = write(
        "columns.csv",
        &format!(
            "time_s,{}\n",
            (0..5_000)
                .map(|i| format!("c{i}"))
                .collect::<Vec<_>>()
                .join(",")
        ),
    );
    let field = write(
        "field.csv",
        "time_s,theta_t,eta_t\n0,1,2\n1,\u{1b}]0;title\u{7},3\n",
    );
    let freqs = write("f.txt", &format!("1\n{}\n", "z".repeat(100_000)));
    let toml = write("p.toml", &format!("[mass\n{}\n", "q".repeat(100_000)));
    for args in [
        vec!["budget", "--tilt", &header],
        vec!["budget", "--tilt", &columns],
        vec!["budget", "--tilt", &field],
        vec!["tf", "--freq-file", &freqs],
        vec!["--params", &toml, "modes"],
    ] {
        let out = tiltnoise(&args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_one_line(&format!("{args:?}"), &err);
        assert!(err.len() < 2000, "{args:?}: {} bytes: {err}", err.len());
        assert!(
            !err.trim_end().contains(|c: char| c.is_control()),
            "{args:?}: {err:?}"
        );
    }
    let err = stderr(&tiltnoise(&["budget", "--tilt", &columns]));
    assert!(err.contains("c0, c1, c2") && err.contains("more)"), "{err}");
    let err = stderr(&tiltnoise(&["budget", "--tilt", &field]));
    assert!(err.contains("`\\x1b]0;title\\x07`"), "{err}");
}

#[test]
fn command_line_errors_are_one_line_and_help_is_not_an_error() {
    for (args, needle) in [
        (
            &["tf", "--bogus"][..],
            "unexpected argument '--bogus' found",
        ),
        (
            &["modes", "--format", "xml"],
            "invalid value 'xml' for '--format <FORMAT>'; [possible values: table, json]",
        ),
        (
            &["budget"],
            "the following required arguments were not provided: --tilt <FILE>",
        ),
        (
            &["mc", "--samples", "-5"],
            "invalid value '-5' for '--samples",
        ),
        (&["frobnicate"], "unrecognized subcommand 'frobnicate'"),
        (&[], "no command given; allowed: params, modes, tf, budget"),
    ] {
        let out = tiltnoise(args);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_one_line(&format!("{args:?}"), &err);
        assert!(err.starts_with("tiltnoise: error: "), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("Usage"), "{args:?}: {err}");
    }
    // Negative numbers reach our own checks and their messages.
    assert_fails(
        &["tf", "--freq", "-1:10:1"],
        &["--freq -1:10:1: need 0 < FLO <= FHI"],
    );
    assert_fails(&["tf", "--rel-tol", "-1"], &["--rel-tol -1"]);
    assert_fails(
        &["fit", "--bound-sigmas", "-2"],
        &["--bound-sigmas -2 is not allowed"],
    );
    for args in [&["--help"][..], &["tf", "--help"], &["--version"]] {
        let out = tiltnoise(args);
        assert_eq!(out.status.code(), Some(0), "{args:?}");
        assert!(!out.stdout.is_empty() && out.stderr.is_empty(), "{args:?}");
    }
}

#[test]
fn the_planner_explains_its_refusal_only_when_asked() {
    let args = ["tf", "--freq", "1e-4:50:30", "--rel-tol", "1e-20"];
    let out = tiltnoise(&args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_one_line("refusal", &err);
    assert!(
        err.contains("no method meets the relative tolerance 1e-20")
            && err.contains("the most accurate, `polezero`")
            && err.contains("run with --explain for every candidate"),
        "{err}"
    );
    let out = tiltnoise(&[&args[..], &["--explain"]].concat());
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let lines: Vec<&str> = err.trim_end().lines().collect();
    for name in ["torsion2", "polezero", "block", "split", "modal", "direct"] {
        assert!(
            lines.iter().any(|l| l.starts_with(&format!("  {name} "))),
            "{name}: {err}"
        );
    }
    let last = lines.last().unwrap();
    assert!(
        last.starts_with("tiltnoise: error: no method meets") && !last.contains("--explain"),
        "{err}"
    );
}

#[test]
fn output_paths_are_checked_before_anything_is_computed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = |name: &str| d.join(name).to_str().unwrap().to_string();
    std::fs::create_dir(d.join("out")).unwrap();
    std::fs::create_dir(d.join("out/dir.h5")).unwrap();
    std::fs::write(d.join("f.txt"), "0.1\n1\n").unwrap();
    std::fs::write(d.join("params.toml"), stdout_of(&["params"])).unwrap();
    std::os::unix::fs::symlink(d.join("f.txt"), d.join("out/link.csv")).unwrap();
    let grid = ["--freq", "1e-4:50:30"];
    let cases: Vec<(Vec<String>, Vec<&str>)> = vec![
        (
            vec![
                "--save".into(),
                path("out/a.h5"),
                "--save".into(),
                path("nodir/b.svg"),
            ],
            vec!["cannot save", "nodir/b.svg", "does not exist"],
        ),
        (
            vec![
                "--save".into(),
                path("out/a.h5"),
                "--save".into(),
                path("out/a.h5"),
            ],
            vec!["out/a.h5", "given twice"],
        ),
        (
            vec![
                "--save".into(),
                path("out/a.h5"),
                "--save".into(),
                path("out/dir.h5/../a.h5"),
            ],
            vec!["same file as the output", "out/a.h5"],
        ),
        (
            vec!["--save".into(), path("out/dir.h5")],
            vec!["out/dir.h5", "it is a directory"],
        ),
        (
            vec!["--save".into(), path("f.txt/a.h5")],
            vec!["f.txt is not a directory"],
        ),
    ];
    for (save, needles) in cases {
        let args: Vec<&str> = ["tf"]
            .iter()
            .copied()
            .chain(grid)
            .chain(save.iter().map(String::as_str))
            .collect();
        assert_fails_without_output(&args, &d.join("out"), &needles);
    }
    // No output replaces an input of the run, whatever the spelling: a symbolic link to it,
    // or the same file through another path.
    assert_fails_without_output(
        &[
            "tf",
            "--freq-file",
            &path("f.txt"),
            "--save",
            &path("out/link.csv"),
        ],
        &d.join("out"),
        &["out/link.csv", "--freq-file", "must not replace an input"],
    );
    let tilt = d.join("out/tilt.csv");
    std::fs::copy(common::repo("tilt_data/peterson_tilt_asd.csv"), &tilt).unwrap();
    let tilt = tilt.to_str().unwrap();
    assert_fails_without_output(
        &[
            "budget",
            "--tilt",
            tilt,
            "--save",
            &path("out/dir.h5/../tilt.csv"),
        ],
        &d.join("out"),
        &["--tilt", "must not replace an input"],
    );
    // A parameter file is an input too (its name is free, here that of a fit report).
    let params = path("out/p.json");
    std::fs::copy(d.join("params.toml"), &params).unwrap();
    assert_fails_without_output(
        &["--params", &params, "fit", "--save", &params],
        &d.join("out"),
        &["--params", "must not replace an input"],
    );
}

#[test]
fn an_unwritable_directory_is_refused_before_computing() {
    use std::os::unix::fs::PermissionsExt;
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    let out = ro.join("a.h5");
    let mut child = command(
        &["mc", "--samples", "10", "--save", out.to_str().unwrap()],
        dir.path(),
    );
    // Root writes into a read-only directory: run the child as the unprivileged user
    // `nobody` (65534) instead, in a directory it may enter.
    // SAFETY: geteuid only reads the process's credentials.
    if unsafe { libc::geteuid() } == 0 {
        std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755)).unwrap();
        child.uid(65534).gid(65534);
    }
    let result = match child.output() {
        Ok(result) => result,
        Err(e) => {
            skipped(
                "an_unwritable_directory_is_refused_before_computing",
                &format!("cannot run the binary as an unprivileged user: {e}"),
            );
            return;
        }
    };
    let err = stderr(&result);
    assert_eq!(result.status.code(), Some(2), "{err}");
    assert_one_line("read-only directory", &err);
    assert!(
        err.contains("ro/a.h5")
            && err.contains("is not writable")
            && err.contains("Permission denied"),
        "{err}"
    );
    assert!(listing(&ro).is_empty());
}

#[test]
fn outputs_of_a_run_appear_all_or_none() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Files of the child are limited to 4 MB (SIGXFSZ ignored, so a larger write fails with
    // EFBIG): the figure (a few hundred kB) is written, the CSV of 20000 points (about 20 MB)
    // then fails. Neither may appear.
    let mut child = command(
        &[
            "tf",
            "--freq",
            "1e-4:20000:30",
            "--save",
            "tf.png",
            "--save",
            "tf.csv",
        ],
        d,
    );
    // SAFETY: between fork and exec the closure calls only setrlimit and signal, which are
    // async-signal-safe, on values it owns.
    unsafe {
        use std::os::unix::process::CommandExt;
        child.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 4 << 20,
                rlim_max: 4 << 20,
            };
            if libc::setrlimit(libc::RLIMIT_FSIZE, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
            Ok(())
        });
    }
    let out = child.output().unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_one_line("file size limit", &err);
    assert!(
        err.contains("cannot write") && err.contains("tf.csv"),
        "{err}"
    );
    assert_eq!(listing(d), Vec::<std::path::PathBuf>::new());
    // Without the limit both appear, and the `wrote` lines come after both are written.
    let out = command(
        &[
            "tf",
            "--freq",
            "1e-4:20000:30",
            "--save",
            "tf.png",
            "--save",
            "tf.csv",
        ],
        d,
    )
    .output()
    .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.ends_with("wrote tf.png\nwrote tf.csv\n"), "{text}");
    assert_eq!(listing(d), vec![d.join("tf.csv"), d.join("tf.png")]);
}

/// Runs `args` in an empty directory, sends `signal` as soon as the file of `target` exists in
/// its staging directory (the write is under way), and checks the end: exit code 2, one line
/// naming the signal, and no file left.
fn interrupt_during_write(args: &[&str], target: &str, signal: libc::c_int, name: &str) {
    let dir = tempfile::tempdir().unwrap();
    let mut child = command(args, dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let writing = loop {
        if writing_file(dir.path(), target) {
            break true;
        }
        if child.try_wait().unwrap().is_some() || start.elapsed() > Duration::from_secs(120) {
            break false;
        }
        std::thread::sleep(Duration::from_millis(1));
    };
    assert!(
        writing,
        "{args:?}: no file of {target} seen in a staging directory while running"
    );
    // SAFETY: kill only sends a signal to the child's process id, which is alive (its file
    // was just seen and it has not been waited for).
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
    let status = wait_bounded(&mut child, Duration::from_secs(60));
    let err = child_stderr(&mut child);
    assert_eq!(status.code(), Some(2), "{args:?}: {err}");
    assert_one_line(name, &err);
    assert!(
        err.starts_with(&format!("tiltnoise: error: interrupted by {name}; "))
            && err.trim_end().ends_with(", no output written"),
        "{err}"
    );
    assert_eq!(
        listing(dir.path()),
        Vec::<std::path::PathBuf>::new(),
        "{args:?} left files after {name}"
    );
}

/// Whether the file of `target` exists in a staging directory `.<target>.XXXXXX.tmp` of `dir`.
fn writing_file(dir: &Path, target: &str) -> bool {
    let prefix = format!(".{target}.");
    std::fs::read_dir(dir).unwrap().any(|e| {
        let e = e.unwrap();
        e.file_name().to_string_lossy().starts_with(&prefix) && e.path().join(target).exists()
    })
}

/// Runs `args` (a long computation that saves its outputs only at the end) in an empty
/// directory, sends `signal` while it computes, and checks the end as
/// [`interrupt_during_write`] does.
fn interrupt_while_computing(args: &[&str], signal: libc::c_int, name: &str) {
    let dir = tempfile::tempdir().unwrap();
    let mut child = command(args, dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Past the start-up (parsing, checking the outputs), well before the end.
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "{args:?} ended before it was interrupted: not a long computation"
    );
    // SAFETY: kill only sends a signal to the child's process id, which is alive (it has not
    // been waited for and was running just now).
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
    let status = wait_bounded(&mut child, Duration::from_secs(60));
    let err = child_stderr(&mut child);
    assert_eq!(status.code(), Some(2), "{args:?}: {err}");
    assert_one_line(name, &err);
    assert!(
        err.starts_with(&format!("tiltnoise: error: interrupted by {name}; "))
            && err.trim_end().ends_with(", no output written"),
        "{err}"
    );
    assert_eq!(
        listing(dir.path()),
        Vec::<std::path::PathBuf>::new(),
        "{args:?} left files after {name}"
    );
}

#[test]
fn an_interrupt_during_a_long_computation_ends_it_without_output() {
    interrupt_while_computing(
        &["mc", "--samples", "10000000", "--save", "mc.h5"],
        libc::SIGINT,
        "SIGINT",
    );
    interrupt_while_computing(
        &["simulate", "--duration", "3e6", "--save", "sim.h5"],
        libc::SIGTERM,
        "SIGTERM",
    );
}

#[test]
fn an_interrupt_during_a_write_leaves_no_file() {
    interrupt_during_write(
        &["tf", "--freq", "1e-4:200000:30", "--save", "big.h5"],
        "big.h5",
        libc::SIGINT,
        "SIGINT",
    );
    interrupt_during_write(
        &["simulate", "--duration", "2e5", "--save", "sim.h5"],
        "sim.h5",
        libc::SIGTERM,
        "SIGTERM",
    );
    interrupt_during_write(
        &["tf", "--freq", "1e-4:200000:30", "--save", "big.csv"],
        "big.csv",
        libc::SIGHUP,
        "SIGHUP",
    );
}

#[test]
fn a_hangup_ignored_as_under_nohup_lets_the_run_finish() {
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let mut child = command(
        &["tf", "--freq", "1e-4:200000:30", "--save", "big.csv"],
        dir.path(),
    );
    // SAFETY: between fork and exec (after the reset of [`default_signals`]) the closure calls
    // only signal(2), which is async-signal-safe, with constant arguments.
    unsafe {
        child.pre_exec(|| match libc::signal(libc::SIGHUP, libc::SIG_IGN) {
            libc::SIG_ERR => Err(std::io::Error::last_os_error()),
            _ => Ok(()),
        });
    }
    let mut child = child
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while !writing_file(dir.path(), "big.csv") {
        assert!(
            child.try_wait().unwrap().is_none() && start.elapsed() < Duration::from_secs(120),
            "no file of big.csv seen in a staging directory while running"
        );
        std::thread::sleep(Duration::from_millis(1));
    }
    let pid = child.id() as libc::pid_t;
    // SAFETY: kill only sends a signal to the child's process id, which is alive (its file
    // was just seen and it has not been waited for).
    assert_eq!(unsafe { libc::kill(pid, libc::SIGHUP) }, 0);
    let status = wait_bounded(&mut child, Duration::from_secs(120));
    let err = child_stderr(&mut child);
    assert_eq!(status.code(), Some(0), "{err}");
    assert_eq!(err, "");
    assert_eq!(listing(dir.path()), vec![dir.path().join("big.csv")]);
    // Whole: a line per frequency of the grid, up to its last one.
    let text = std::fs::read_to_string(dir.path().join("big.csv")).unwrap();
    let rows: Vec<&str> = text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .collect();
    assert!(rows.len() >= 200_000, "{} rows", rows.len());
    let last: f64 = rows[rows.len() - 1]
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(last, 30.0);
}

/// Standard output of a successful run.
fn stdout_of(args: &[&str]) -> Vec<u8> {
    let out: Output = tiltnoise(args);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    out.stdout
}
