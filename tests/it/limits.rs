//! Sizes over their limits (docs/limits.md) as a user meets them: refused with exit code 2 and
//! one line naming the option or file, the value and the limit, before anything large is
//! allocated, and without output files. Every run is guarded: killed and failed after
//! [`GUARD`], and (on Unix) limited to [`GUARD_MEMORY_KIB`] of address space, so that a
//! regression fails the test instead of hanging the suite or exhausting the machine.

use crate::common::{disable_hdf5_file_locking, listing, repo};
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Longest a refusal may take before the run is killed: far above the milliseconds it takes,
/// far below a hung or allocating run.
const GUARD: Duration = Duration::from_secs(60);

/// Address space a refused run may map (KiB): refusals need a few MiB; an allocation the
/// limits should have stopped fails instead of taking the machine's memory.
const GUARD_MEMORY_KIB: u64 = 4 << 20;

/// Runs `tiltnoise args` under the guards; its output goes to files, so that a run that
/// writes much cannot block on a full pipe.
fn run(args: &[&str]) -> Output {
    disable_hdf5_file_locking();
    let dir = tempfile::tempdir().unwrap();
    let (out, err) = (dir.path().join("stdout"), dir.path().join("stderr"));
    let exe = env!("CARGO_BIN_EXE_tiltnoise");
    let mut cmd = if cfg!(unix) {
        let mut c = Command::new("sh");
        c.arg("-c")
            .arg(format!(
                "ulimit -v {GUARD_MEMORY_KIB} && exec \"$0\" \"$@\""
            ))
            .arg(exe);
        c
    } else {
        Command::new(exe)
    };
    let mut child = cmd
        .args(args)
        .env("HDF5_USE_FILE_LOCKING", "FALSE")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("the binary runs");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > GUARD {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("{args:?}: still running after {GUARD:?}, killed");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    Output {
        status,
        stdout: std::fs::read(&out).unwrap(),
        stderr: std::fs::read(&err).unwrap(),
    }
}

/// `args` fail with exit code 2 and one line on standard error containing every `needle`
/// (the option or file, the value, the limit), and leave `dir` as it was.
fn refused_in(dir: &Path, args: &[&str], needles: &[&str]) {
    let before = listing(dir);
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    assert!(err.starts_with("tiltnoise: error: "), "{args:?}: {err}");
    for n in needles.iter().chain(&["(see docs/limits.md)"]) {
        assert!(err.contains(n), "{args:?}: `{n}` missing from: {err}");
    }
    assert_eq!(before, listing(dir), "{args:?} left files behind");
}

/// [`refused_in`] with a fresh directory for outputs.
fn refused(args: &[&str], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    refused_in(dir.path(), args, needles);
}

/// A path in `dir` as `&str` for the command line.
fn arg(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

#[test]
fn frequency_grids_over_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let save = arg(dir.path(), "tf.csv");
    for spec in [
        "1e-3:18446744073709551615:1",
        "1e-4:1000000000:30",
        "1e-4:99999999999999999999999:30",
    ] {
        refused_in(
            dir.path(),
            &["tf", "--freq", spec, "--save", &save],
            &[
                &format!("--freq {spec}: "),
                "frequency points, more than the 100000000 allowed",
            ],
        );
    }
    // Held in memory for a figure: the in-memory limit, before anything is computed.
    let png = arg(dir.path(), "tf.png");
    refused_in(
        dir.path(),
        &[
            "tf",
            "--freq",
            "1e-4:1000001:30",
            "--save",
            &save,
            "--save",
            &png,
        ],
        &[&format!(
            "--save {png}: a figure is drawn from at most 1000000 frequency points and --freq \
             asks for 1000001"
        )],
    );
    refused(
        &["methods", "--freq", "1e-5:1000000000:100"],
        &[
            "--freq 1e-5:1000000000:100: 1000000000 frequency points",
            "more than the 1000000 allowed",
        ],
    );
    // Frequencies above the highest one allowed, in a grid and in a frequency file.
    refused(
        &["methods", "--freq", "1e300:2:1e301"],
        &["frequency 1e301 Hz (FHI of log grid 1e300:2:1e301) is not allowed"],
    );
    let high = arg(dir.path(), "high.txt");
    std::fs::write(&high, "1e-3\n2e6\n").unwrap();
    refused(
        &["tf", "--freq-file", &high],
        &[&format!(
            "frequency 2000000 Hz ({high}, line 2) is not allowed"
        )],
    );
    std::fs::remove_file(&high).unwrap();
    let spectra = repo("tilt_data/peterson_tilt_asd.csv");
    refused(
        &[
            "budget",
            "--tilt",
            spectra.to_str().unwrap(),
            "--freq",
            "1e-4:1000001:30",
        ],
        &["--freq 1e-4:1000001:30: 1000001 frequency points, more than the 1000000 allowed"],
    );
}

#[test]
fn frequency_files_over_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let many = dir.path().join("many.txt");
    std::fs::write(&many, "1e-3\n".repeat(1_000_001)).unwrap();
    let long = dir.path().join("long.txt");
    std::fs::write(&long, format!("1e-3\n{}\n", "1".repeat(100_000))).unwrap();
    let out = tempfile::tempdir().unwrap();
    let save = arg(out.path(), "tf.csv");
    refused_in(
        out.path(),
        &["tf", "--freq-file", many.to_str().unwrap(), "--save", &save],
        &[
            &format!("frequency file {}: ", many.display()),
            "1000001 frequency points, more than the 1000000 allowed",
        ],
    );
    refused_in(
        out.path(),
        &["tf", "--freq-file", long.to_str().unwrap(), "--save", &save],
        &[
            &format!("frequency file {}, line 2: ", long.display()),
            "longer than 64 KiB (65536 bytes), the limit for one line",
        ],
    );
}

#[test]
fn monte_carlo_draws_and_threads_over_the_limits() {
    let dir = tempfile::tempdir().unwrap();
    let save = arg(dir.path(), "mc.h5");
    refused_in(
        dir.path(),
        &["mc", "--samples", "18446744073709551615", "--save", &save],
        &[
            "--samples 18446744073709551615: 1.8446744073709552e19 Monte Carlo draws",
            "more than the 10000000 allowed",
        ],
    );
    refused_in(
        dir.path(),
        &["mc", "--samples", "1000000000000", "--save", &save],
        &["--samples 1000000000000: 1000000000000 Monte Carlo draws, more than the 10000000 allowed"],
    );
    refused(
        &["mc", "--samples", "10", "--threads", "5000"],
        &["--threads 5000: 5000 threads, more than the 1024 allowed"],
    );
}

#[test]
fn simulations_over_the_sample_limit() {
    let dir = tempfile::tempdir().unwrap();
    let (h5, png) = (arg(dir.path(), "sim.h5"), arg(dir.path(), "fig.png"));
    refused_in(
        dir.path(),
        &[
            "simulate",
            "--duration",
            "9e7",
            "--save",
            &h5,
            "--save-time",
            &png,
        ],
        &["--duration 9e7 s at --step 0.1 s: 900000000 samples, more than the 33554432 allowed"],
    );
    refused(
        &["simulate", "--duration", "1e300", "--step", "1e-300"],
        &["--duration 1e300 s at --step 1e-300 s: inf samples, more than the 33554432 allowed"],
    );
    refused(
        &["simulate", "--duration", "3355443.3"],
        &["33554433 samples, more than the 33554432 allowed"],
    );
}

/// A Welch segment is limited by the record it cuts.
#[test]
fn welch_segments_longer_than_the_record() {
    let tilt = repo("tilt_data/lab_tilt_24h.h5");
    let huge = "18446744073709551615";
    for (args, needles) in [
        (
            vec![
                "budget",
                "--tilt",
                tilt.to_str().unwrap(),
                "--nperseg",
                huge,
            ],
            [
                "series of 86400 samples",
                "shorter than one Welch segment of 18446744073709551615 samples",
            ],
        ),
        (
            vec!["simulate", "--nperseg", huge],
            [
                "gives 432000 samples",
                "(--nperseg 18446744073709551615 = 1.8446744073709553e18 s)",
            ],
        ),
    ] {
        let out = run(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        for n in needles {
            assert!(err.contains(n), "{args:?}: `{n}` missing from: {err}");
        }
    }
}

#[test]
fn text_files_over_their_length() {
    let dir = tempfile::tempdir().unwrap();
    // A parameter file of 2 MiB of comments: valid TOML, but not a parameter file's size.
    let params = dir.path().join("p.toml");
    std::fs::write(&params, format!("{}\n", "# comment\n".repeat(200_000))).unwrap();
    refused(
        &["--params", params.to_str().unwrap(), "modes"],
        &[
            &format!("parameter file {}: ", params.display()),
            "longer than 1 MiB (1048576 bytes), the limit for a parameter file",
        ],
    );
    // A measured-frequency file with a line of 100 000 characters.
    let measured = dir.path().join("m.csv");
    std::fs::write(
        &measured,
        format!("mode,frequency_hz\n1,{}\n", "1".repeat(100_000)),
    )
    .unwrap();
    refused(
        &["fit", "--measured-modes", measured.to_str().unwrap()],
        &[
            &format!("measured frequencies {}, line 2: ", measured.display()),
            "the limit for one line",
        ],
    );
    // A CSV input with a 50 MB header line, and one of 3 GiB (sparse: nothing is written).
    let wide = dir.path().join("wide.csv");
    std::fs::write(
        &wide,
        format!("time_s,{}\n0,1\n1,2\n", "E".repeat(50_000_000)),
    )
    .unwrap();
    refused(
        &["budget", "--tilt", wide.to_str().unwrap()],
        &[
            &format!("input file {}, line 1: ", wide.display()),
            "longer than 64 KiB (65536 bytes), the limit for one line",
        ],
    );
    let huge = dir.path().join("huge.csv");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(3 << 30)
        .unwrap();
    let tilt = repo("tilt_data/lab_tilt_24h.h5");
    for args in [
        vec!["budget", "--tilt", huge.to_str().unwrap()],
        vec![
            "budget",
            "--tilt",
            tilt.to_str().unwrap(),
            "--measured",
            huge.to_str().unwrap(),
        ],
    ] {
        refused(
            &args,
            &[
                &format!("input file {}: ", huge.display()),
                "longer than 1 GiB (1073741824 bytes), the limit for a CSV input",
            ],
        );
    }
}

/// Writes an HDF5 file whose datasets claim `len` samples each without storing any (chunked,
/// never written: a file of a few KiB).
fn claimed_h5(path: &Path, datasets: &[&str], len: usize, sample_rate_hz: Option<f64>) {
    let file = hdf5::File::create(path).unwrap();
    for name in datasets {
        file.new_dataset::<f64>()
            .chunk(1 << 16)
            .shape(len)
            .create(*name)
            .unwrap();
    }
    if let Some(fs) = sample_rate_hz {
        file.new_attr::<f64>()
            .create("sample_rate_hz")
            .unwrap()
            .write_scalar(&fs)
            .unwrap();
    }
    file.close().unwrap();
    assert!(std::fs::metadata(path).unwrap().len() < 1 << 20);
}

#[test]
fn hdf5_datasets_that_claim_too_many_samples() {
    let dir = tempfile::tempdir().unwrap();
    let series = dir.path().join("series.h5");
    claimed_h5(&series, &["E", "N"], 1_000_000_000_000, Some(1.0));
    let spectra = dir.path().join("spectra.h5");
    claimed_h5(&spectra, &["frequency_hz"], 100_000_000_000, None);
    let measured = dir.path().join("measured.h5");
    claimed_h5(&measured, &["X"], 100_000_000, Some(10.0));
    let out = tempfile::tempdir().unwrap();
    let save = arg(out.path(), "b.h5");
    refused_in(
        out.path(),
        &[
            "budget",
            "--tilt",
            series.to_str().unwrap(),
            "--save",
            &save,
        ],
        &[
            &format!("input file {}, dataset /", series.display()),
            "1000000000000 samples, more than the 4294967296 allowed",
        ],
    );
    refused_in(
        out.path(),
        &[
            "budget",
            "--tilt",
            spectra.to_str().unwrap(),
            "--save",
            &save,
        ],
        &[
            &format!("input file {}, dataset /frequency_hz: ", spectra.display()),
            "100000000000 frequencies, more than the 33554432 allowed",
        ],
    );
    let tilt = repo("tilt_data/lab_tilt_24h.h5");
    refused_in(
        out.path(),
        &[
            "budget",
            "--tilt",
            tilt.to_str().unwrap(),
            "--measured",
            measured.to_str().unwrap(),
            "--save",
            &save,
        ],
        &[
            &format!("input file {}, dataset /X: ", measured.display()),
            "100000000 samples, more than the 33554432 allowed",
        ],
    );
}

/// The spectra a median keeps grow with the record and the overlap: 5e5 segments of 2.5e5
/// frequencies of 10^6 samples are 4 TB, more than any machine has (Linux: elsewhere the
/// memory available is unknown).
#[test]
fn a_welch_median_beyond_the_memory_available() {
    if !cfg!(target_os = "linux") {
        eprintln!("skipped a_welch_median_beyond_the_memory_available: needs /proc/meminfo");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let series = dir.path().join("series.h5");
    claimed_h5(&series, &["E", "N"], 1_000_000, Some(1.0));
    refused(
        &[
            "budget",
            "--tilt",
            series.to_str().unwrap(),
            "--nperseg",
            "500000",
            "--overlap",
            "0.999999",
            "--average",
            "median",
        ],
        &[
            &format!("budget of {}: ", series.display()),
            "500001 Welch segments of 500000 samples (overlap 499999) over 1000000 samples: \
             needs about",
            "of memory, more than half of the",
        ],
    );
}

/// Devices and pipes as inputs: read no further than the limits.
#[cfg(target_os = "linux")]
mod devices {
    use super::{refused, repo};
    use std::path::Path;

    /// A `.csv` name for a device, as the CSV readers want the extension.
    fn csv_link(dir: &Path, device: &str) -> String {
        let link = dir.join(format!("{}.csv", device.trim_start_matches("/dev/")));
        std::os::unix::fs::symlink(device, &link).unwrap();
        link.to_str().unwrap().to_string()
    }

    #[test]
    fn dev_zero_and_dev_urandom() {
        let dir = tempfile::tempdir().unwrap();
        let tilt = repo("tilt_data/lab_tilt_24h.h5");
        let tilt = tilt.to_str().unwrap();
        // Zeros never end a line; random bytes do, every 256 bytes on average.
        refused(
            &["--params", "/dev/zero", "modes"],
            &[
                "parameter file /dev/zero, line 1: longer than 64 KiB",
                "one line",
            ],
        );
        refused(
            &["--params", "/dev/urandom", "modes"],
            &["parameter file /dev/urandom: longer than 1 MiB (1048576 bytes)"],
        );
        refused(
            &["tf", "--freq-file", "/dev/zero"],
            &["frequency file /dev/zero, line 1: longer than 64 KiB"],
        );
        refused(
            &["tf", "--freq-file", "/dev/urandom"],
            &["frequency file /dev/urandom: longer than 64 MiB (67108864 bytes)"],
        );
        refused(
            &["fit", "--measured-modes", "/dev/zero"],
            &["measured frequencies /dev/zero, line 1: longer than 64 KiB"],
        );
        refused(
            &["fit", "--measured-modes", "/dev/urandom"],
            &["measured frequencies /dev/urandom: longer than 1 MiB"],
        );
        let zero = csv_link(dir.path(), "/dev/zero");
        refused(
            &["budget", "--tilt", &zero],
            &[&format!("input file {zero}, line 1: longer than 64 KiB")],
        );
        refused(
            &["budget", "--tilt", tilt, "--measured", &zero],
            &[&format!("input file {zero}, line 1: longer than 64 KiB")],
        );
    }

    /// A named pipe whose writer never stops: the parameter file is read up to its limit.
    #[test]
    fn a_fifo_that_never_ends() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("params.toml");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        // The writer is a child process, killed at the end: should the run never open the
        // pipe, the writer's open would block for ever.
        let mut writer = std::process::Command::new("sh")
            .arg("-c")
            .arg("exec yes '# a comment line that never ends the file' > \"$0\"")
            .arg(&fifo)
            .spawn()
            .unwrap();
        refused(
            &["--params", fifo.to_str().unwrap(), "modes"],
            &[&format!(
                "parameter file {}: longer than 1 MiB (1048576 bytes), the limit for a \
                 parameter file",
                fifo.display()
            )],
        );
        let _ = writer.kill();
        writer.wait().unwrap();
    }

    /// An HDF5 input that is a named pipe: HDF5 reads at random offsets and would wait for
    /// a writer for ever, so the file is refused before the library sees it.
    #[test]
    fn an_hdf5_input_through_a_fifo() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("tilt.h5");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(made.success());
        let out = super::run(&["budget", "--tilt", fifo.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        let expected = format!(
            "tiltnoise: error: cannot read input file {}: it is a FIFO, not a regular file",
            fifo.display()
        );
        assert!(err.starts_with(&expected), "{err}");
    }
}

#[cfg(not(target_os = "linux"))]
#[test]
fn devices_and_pipes() {
    eprintln!("skipped devices_and_pipes: /dev/zero, /dev/urandom and mkfifo are tested on Linux");
}
