//! Limits on every size the user controls: frequency points, Monte Carlo draws, simulated and
//! read samples, file and line lengths. A request over a limit is refused with a
//! [`LimitError`] naming the option or file, the value and the limit, before anything is
//! allocated; `docs/limits.md` lists them for users.
//!
//! Each limit is derived from the memory a run at the limit takes: bytes per point (measured
//! peaks of the release binary, rounded up) times the count must fit comfortably, at most a
//! few GiB, into a lab workstation of 16 GiB, while the runs the tool is made for (a 12 h
//! simulation, a day of tilt data, 10 000 Monte Carlo draws, the 2000-point default grid)
//! stay far below it and within the 256 MB the long runs target. Where the honest bound is the
//! machine rather than a fixed number, [`check_memory`] refuses a planned allocation of more
//! than half of the memory available: `MemAvailable` in `/proc/meminfo`, or less when the
//! process's address space is limited (`ulimit -v`, `RLIMIT_AS`: the limit less what is mapped
//! already) (Linux; elsewhere only the fixed limits apply). The other half is for the rest of
//! the machine and for the copies the per-item estimates leave out.
//!
//! Text inputs are read through [`BoundedReader`], which stops at the file's byte limit plus
//! one and at [`MAX_LINE_BYTES`] within a line, so a device (`/dev/zero`, `/dev/urandom`), a
//! pipe or a huge file costs at most its limit in time and memory. Regular files larger than
//! their limit are refused from their metadata without being read ([`check_file_len`]).
//!
//! The magnitudes a value may have where it enters (samples, spectra, sample rates,
//! frequencies, factors) are in [`magnitude`], re-exported here: one place for every limit.
//!
//! Depends on `error` (number formatting) only; reads no file except `/proc/meminfo`,
//! `/proc/self/limits` and `/proc/self/status`.

pub mod magnitude;

pub use magnitude::*;

use crate::num_text::Num;
use crate::option_key::Message;
use std::fmt;
use std::io::{self, Read};

/// Where users find the limits, named in every message.
const DOCS: &str = "docs/limits.md";

/// Most points of a frequency grid the model is evaluated on (`--freq FLO:N:FHI` in `tf`,
/// `budget` and `methods`, the lines of a `--freq-file`). A result costs 16 bytes per complex
/// entry plus about as much again for its CSV text or HDF5 copy (measured: 1.9 KB per point
/// for the 7x15 request of every input, 0.4 KB for the 7x3 tilt matrix), so 10^6 points take
/// 0.4 to 2 GB and about a minute; they resolve relative steps of 1.3e-5 over 0.1 mHz to
/// 30 Hz, 500 times more than the 2000-point default grid.
pub const MAX_GRID_POINTS: usize = 1_000_000;

/// Most points of a log-spaced grid that `tf` evaluates and writes block by block, in memory
/// that does not grow with the grid (`--freq FLO:N:FHI` without a figure): 10^8 points take
/// about 10 minutes per tilt matrix and write 34 GB of HDF5 (7 x 3 complex values a point),
/// the most a run of the tool sensibly produces; beyond that the bound is the disk, and a
/// typo in N.
pub const MAX_STREAMED_GRID_POINTS: usize = 100_000_000;

/// Bytes planned per complex entry and frequency point of a transfer-function result: the
/// 16-byte value and as much again for the output written from it ([`MAX_GRID_POINTS`]).
pub const GRID_BYTES_PER_ENTRY: u64 = 32;

/// Most Monte Carlo draws (`mc --samples`). A draw keeps its eight frequencies, its number and
/// a slot while the threads run: 150 bytes measured, so 10^7 draws take 1.5 GB and a few
/// minutes on two cores. The default is 10^4; at 10^7 the standard deviation of a mode is
/// known to 0.02 %, far below the parameter errors it reflects.
pub const MAX_MC_DRAWS: usize = 10_000_000;

/// Bytes planned per Monte Carlo draw (150 measured, with the HDF5 and figure outputs 158).
pub const MC_BYTES_PER_DRAW: u64 = 160;

/// Most worker threads (`mc --threads`): more threads than cores only add overhead, and each
/// reserves a stack; 1024 is beyond any workstation's core count.
pub const MAX_THREADS: usize = 1024;

/// Most samples of a simulation held in memory whole (the library's `simulate`, the Python
/// package's `Model.simulate`). A sample costs 64 bytes of
/// coordinates and 56 of observables; with the spectra and the outputs (HDF5, figures) 175
/// bytes were measured, so 2^24 samples take 3 GB: 19 days at the paper's 0.1 s, 39 times its
/// 12-hour run.
pub const MAX_SIM_SAMPLES: usize = 1 << 24;

/// Bytes planned per simulated sample, outputs included ([`MAX_SIM_SAMPLES`]).
pub const SIM_BYTES_PER_SAMPLE: u64 = 192;

/// Bytes per sample of a Welch segment while a record streams through one accumulator per
/// channel: the segment, the windowed copy, the spectrum and its running sum (8 bytes each
/// per sample) and the FFT's scratch and twiddles (measured: about as much again).
pub const STREAMED_WELCH_BYTES_PER_SAMPLE: u64 = 64;

/// Most samples of a simulation produced in chunks and written as it goes (`tiltnoise
/// simulate`, whose memory does not grow with the duration): 2^25, a file of 1.9 GB of
/// observables, which is what the budget reads back whole as a measured record
/// ([`MAX_SERIES_SAMPLES`]). 38 days at the paper's 0.1 s.
pub const MAX_STREAMED_SIM_SAMPLES: usize = MAX_SERIES_SAMPLES;

/// Most samples (or frequency points) per channel of an input held in memory whole: a CSV
/// tilt series or spectrum, an HDF5 spectrum, a measured series (`budget --measured`), an HDF5
/// series read at once. 2^25 samples are a year at 1 Hz or 39 days at 10 Hz, 8 bytes each per
/// channel: 1 GiB for four columns. Twice [`MAX_SIM_SAMPLES`] and equal to
/// [`MAX_STREAMED_SIM_SAMPLES`], so that every simulation can be
/// read back. HDF5 tilt series streamed by the budget are not held whole and not limited by it.
pub const MAX_SERIES_SAMPLES: usize = 1 << 25;

/// Most samples per channel of an HDF5 tilt series the budget streams (in chunks, in bounded
/// memory, so the bound is time): at the streaming throughput of `scripts/bench/README.md`
/// (`stream_budget.py`), 2^32 samples take several minutes to half an hour. They are 13 years at 10 Hz; the limit stops a file of
/// a few KiB whose metadata claims 10^12 samples.
pub const MAX_STREAMED_SAMPLES: usize = 1 << 32;

/// Bytes planned per sample and channel of an input held in memory: the 8-byte value and its
/// copy while it is processed.
pub const SERIES_BYTES_PER_SAMPLE: u64 = 16;

/// Highest frequency (Hz) of any grid (`--freq`, a frequency file, an array from Python): a
/// million times the highest mode of the pendulum (about 10 Hz). Far above it the dynamic
/// stiffness is `-w^2 M` to the last bit and every method is singular or meaningless.
pub const MAX_FREQUENCY_HZ: f64 = 1e6;

/// Largest parameter file (`--params`) or measured mode-frequency file (`fit --measured`):
/// hand-written files of a few KiB (the full parameter set is 3 KiB), parsed into trees
/// several times their size. 1 MiB is 300 times that.
pub const MAX_SETTINGS_FILE_BYTES: u64 = 1 << 20;

/// Largest frequency file (`tf --freq-file`), read whole: [`MAX_GRID_POINTS`] lines of up to
/// 64 characters.
pub const MAX_FREQ_FILE_BYTES: u64 = 64 << 20;

/// Largest CSV data input (tilt series or spectra, measured spectra or series), streamed
/// line by line into columns of `f64` (a line of 30 to 60 characters becomes 16 to 32 bytes):
/// 1 GiB of text is 2e7 to 3e7 rows, at most [`MAX_SERIES_SAMPLES`]. Longer records belong in
/// HDF5, which the budget streams.
pub const MAX_DATA_FILE_BYTES: u64 = 1 << 30;

/// Longest line of any text input: 64 KiB, a hundred times the longest real line (a header of
/// many channels, a description). Bounds the memory of a line that never ends (`/dev/zero`).
pub const MAX_LINE_BYTES: u64 = 64 << 10;

// Every simulation can be read back, in memory and streamed; a frequency file holds every
// grid at 64 characters a line.
const _: () = {
    assert!(MAX_SIM_SAMPLES <= MAX_SERIES_SAMPLES);
    assert!(MAX_STREAMED_SIM_SAMPLES <= MAX_SERIES_SAMPLES);
    assert!(MAX_SERIES_SAMPLES <= MAX_STREAMED_SAMPLES);
    assert!(MAX_GRID_POINTS as u64 * 64 <= MAX_FREQ_FILE_BYTES);
    assert!(MAX_GRID_POINTS <= MAX_STREAMED_GRID_POINTS);
};

/// A size over its limit. The message names the option or file (`what`), the value and the
/// limit, and where the limits are documented.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LimitError {
    /// A count (points, draws, samples) over its fixed limit.
    #[error("{what}: {} {unit}, more than the {limit} allowed (see {DOCS})", Count(*.value))]
    TooMany {
        /// The option with its value, or the file, e.g. `--samples 1000000000000`.
        what: Message,
        /// The count requested (a float: it may be derived, e.g. duration / step).
        value: f64,
        /// What is counted, plural, e.g. `Monte Carlo draws`.
        unit: &'static str,
        /// The limit.
        limit: u64,
    },
    /// A file, stream or line longer than its limit.
    #[error("{what}: longer than {} ({limit} bytes), the limit for {of} (see {DOCS})", Bytes(*.limit))]
    TooLong {
        /// The file, with the line when a line is too long.
        what: Message,
        /// The limit in bytes.
        limit: u64,
        /// What the limit is for, e.g. `a parameter file`, `one line`.
        of: &'static str,
    },
    /// An allocation that does not fit into the memory available.
    #[error(
        "{what}: needs about {} of memory, more than half of the {} available; ask for less \
         (see {DOCS})",
        Bytes(*.needed),
        Bytes(*.available)
    )]
    Memory {
        /// The option with its value, or the file, and the size that needs the memory.
        what: Message,
        /// Bytes the run would allocate (`u64::MAX` when the product overflows).
        needed: u64,
        /// `MemAvailable` at the time of the check (at most half of it may be planned).
        available: u64,
    },
}

/// A count as messages show it: every digit of a whole number below 10^15 (exact in `f64`),
/// else as [`Num`] (`1.8446744073709552e19`, `inf`).
#[derive(Debug, Clone, Copy)]
struct Count(f64);

impl fmt::Display for Count {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x.fract() == 0.0 && x.abs() < 1e15 {
            write!(f, "{x:.0}")
        } else {
            write!(f, "{}", Num(x))
        }
    }
}

/// Bytes as messages show them: `1 MiB`, `64 KiB`, `3.2 GiB`.
#[derive(Debug, Clone, Copy)]
struct Bytes(u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const UNITS: [&str; 7] = ["bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
        let mut x = self.0 as f64;
        let mut u = 0;
        while x >= 1024.0 && u + 1 < UNITS.len() {
            x /= 1024.0;
            u += 1;
        }
        if u == 0 {
            write!(f, "{} bytes", self.0)
        } else if x.fract() == 0.0 || x >= 100.0 {
            write!(f, "{x:.0} {}", UNITS[u])
        } else {
            write!(f, "{x:.1} {}", UNITS[u])
        }
    }
}

/// Refuses `value` above `limit`: [`LimitError::TooMany`] with `what()` (built only then).
pub fn check_count<W: Into<Message>>(
    what: impl FnOnce() -> W,
    value: f64,
    unit: &'static str,
    limit: usize,
) -> Result<(), LimitError> {
    if value.is_nan() || value > limit as f64 {
        return Err(LimitError::TooMany {
            what: what().into(),
            value,
            unit,
            limit: limit as u64,
        });
    }
    Ok(())
}

/// `count` items of `bytes_each` bytes, or `u64::MAX` when the product overflows (which no
/// machine has: [`check_memory`] refuses it).
pub fn planned_bytes(count: usize, bytes_each: u64) -> u64 {
    (count as u64).saturating_mul(bytes_each)
}

/// Allocations up to this size are not checked against the machine: every machine the tool
/// runs on has them, and reading `/proc` costs tens of microseconds, more than a small
/// computation (a Python `transfer` of a few points) takes.
pub const UNCHECKED_BYTES: u64 = 64 << 20;

/// Refuses an allocation of `needed` bytes larger than half of the memory available now
/// ([`available_memory_bytes`]); without that information (not Linux), or for at most
/// [`UNCHECKED_BYTES`], it accepts.
pub fn check_memory<W: Into<Message>>(
    what: impl FnOnce() -> W,
    needed: u64,
) -> Result<(), LimitError> {
    if needed <= UNCHECKED_BYTES {
        return Ok(());
    }
    check_memory_against(what, needed, available_memory_bytes())
}

/// [`check_memory`] against a given amount of available memory (`None`: unknown).
pub fn check_memory_against<W: Into<Message>>(
    what: impl FnOnce() -> W,
    needed: u64,
    available: Option<u64>,
) -> Result<(), LimitError> {
    match available {
        Some(available) if needed > available / 2 => Err(LimitError::Memory {
            what: what().into(),
            needed,
            available,
        }),
        _ => Ok(()),
    }
}

/// The memory this process can allocate, in bytes: `MemAvailable` of `/proc/meminfo` (the
/// kernel's estimate of what can be allocated without swapping), or the address space left
/// under the process's limit (`ulimit -v`) if that is less; `None` when neither can be read
/// (not Linux).
pub fn available_memory_bytes() -> Option<u64> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let machine = read("/proc/meminfo").and_then(|t| parse_mem_available(&t));
    let headroom = read("/proc/self/limits")
        .and_then(|t| parse_address_space_limit(&t))
        .and_then(|limit| {
            let mapped = read("/proc/self/status").and_then(|t| parse_vm_size(&t))?;
            Some(limit.saturating_sub(mapped))
        });
    match (machine, headroom) {
        (Some(m), Some(h)) => Some(m.min(h)),
        (m, h) => m.or(h),
    }
}

/// The soft limit of the line `Max address space` of `/proc/self/limits` text, in bytes;
/// `None` when it is `unlimited` or absent.
pub fn parse_address_space_limit(limits: &str) -> Option<u64> {
    let line = limits
        .lines()
        .find_map(|l| l.strip_prefix("Max address space"))?;
    line.split_whitespace().next()?.parse().ok()
}

/// `VmSize` of `/proc/self/status` text (the address space mapped), in bytes.
pub fn parse_vm_size(status: &str) -> Option<u64> {
    let line = status.lines().find_map(|l| l.strip_prefix("VmSize:"))?;
    let mut parts = line.split_whitespace();
    let value: u64 = parts.next()?.parse().ok()?;
    match parts.next() {
        Some("kB") => value.checked_mul(1024),
        _ => None,
    }
}

/// The `MemAvailable:` line of `/proc/meminfo` text (`MemAvailable:   20486532 kB`), in bytes.
pub fn parse_mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo
        .lines()
        .find_map(|l| l.strip_prefix("MemAvailable:"))?;
    let mut parts = line.split_whitespace();
    let value: u64 = parts.next()?.parse().ok()?;
    match parts.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// Refuses a regular file whose length `len` (from its metadata) is over `limit`, before
/// anything is read: [`LimitError::TooLong`] naming `what` and `of`.
pub fn check_file_len(
    what: impl FnOnce() -> String,
    len: u64,
    limit: u64,
    of: &'static str,
) -> Result<(), LimitError> {
    if len > limit {
        return Err(LimitError::TooLong {
            what: what().into(),
            limit,
            of,
        });
    }
    Ok(())
}

/// Why a [`BoundedReader`] stopped: carried as the payload of an [`io::Error`] of kind
/// `Other`, found again with [`Overrun::of`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Overrun {
    /// More than `limit` bytes in all.
    Total {
        /// The limit in bytes.
        limit: u64,
    },
    /// A line longer than `limit` bytes (its terminating `\n` not counted).
    Line {
        /// 1-based number of the line.
        line: usize,
        /// The limit in bytes.
        limit: u64,
    },
}

impl fmt::Display for Overrun {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Overrun::Total { limit } => write!(f, "more than {limit} bytes"),
            Overrun::Line { line, limit } => write!(f, "line {line} is longer than {limit} bytes"),
        }
    }
}

impl std::error::Error for Overrun {}

impl Overrun {
    /// The overrun an I/O error reports, if it comes from a [`BoundedReader`].
    pub fn of(e: &io::Error) -> Option<Overrun> {
        e.get_ref()?.downcast_ref::<Overrun>().copied()
    }

    /// The error for users: `file` names the input (e.g. `parameter file p.toml`), `of` says
    /// what the total limit is for (e.g. `a parameter file`).
    pub fn to_limit_error(self, file: &str, of: &'static str) -> LimitError {
        match self {
            Overrun::Total { limit } => LimitError::TooLong {
                what: file.to_string().into(),
                limit,
                of,
            },
            Overrun::Line { line, limit } => LimitError::TooLong {
                what: format!("{file}, line {line}").into(),
                limit,
                of: "one line",
            },
        }
    }
}

/// A reader that fails with an [`Overrun`] once more than `max_bytes` bytes have come from
/// `inner`, or a line runs over `max_line` bytes. It never asks `inner` for more than
/// `max_bytes + 1` bytes (`Read::take`), so an endless source costs at most that.
#[derive(Debug)]
pub struct BoundedReader<R> {
    inner: io::Take<R>,
    max_bytes: u64,
    max_line: u64,
    total: u64,
    /// 1-based number of the line being read and its length so far.
    line: usize,
    line_len: u64,
}

impl<R: Read> BoundedReader<R> {
    /// `inner` limited to `max_bytes` in all and `max_line` bytes per line.
    pub fn new(inner: R, max_bytes: u64, max_line: u64) -> Self {
        BoundedReader {
            inner: inner.take(max_bytes.saturating_add(1)),
            max_bytes,
            max_line,
            total: 0,
            line: 1,
            line_len: 0,
        }
    }
}

impl<R: Read> Read for BoundedReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.total += n as u64;
        if self.total > self.max_bytes {
            return Err(io::Error::other(Overrun::Total {
                limit: self.max_bytes,
            }));
        }
        for (k, piece) in buf[..n].split(|&b| b == b'\n').enumerate() {
            if k > 0 {
                self.line += 1;
                self.line_len = 0;
            }
            self.line_len += piece.len() as u64;
            if self.line_len > self.max_line {
                return Err(io::Error::other(Overrun::Line {
                    line: self.line,
                    limit: self.max_line,
                }));
            }
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_over_the_limit_and_nan_are_refused() {
        assert!(check_count(|| "x", 10.0, "points", 10).is_ok());
        let e = check_count(|| "freq=1:11:2", 11.0, "frequency points", 10)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "freq=1:11:2: 11 frequency points, more than the 10 allowed (see docs/limits.md)"
        );
        assert!(check_count(|| "x", f64::NAN, "samples", 10).is_err());
        let e = check_count(|| "x", 1.8446744073709552e19, "draws", 10).unwrap_err();
        assert!(e.to_string().contains("1.8446744073709552e19 draws"), "{e}");
    }

    #[test]
    fn limits_fit_the_memory_they_are_derived_from() {
        const GIB: u64 = 1 << 30;
        // The largest request (7 observables x 15 inputs) at the grid limit, the draws, the
        // simulation and a four-column series at theirs: each within 4 GiB.
        assert!(planned_bytes(MAX_GRID_POINTS, 7 * 15 * GRID_BYTES_PER_ENTRY) <= 4 * GIB);
        assert!(planned_bytes(MAX_MC_DRAWS, MC_BYTES_PER_DRAW) <= 4 * GIB);
        assert!(planned_bytes(MAX_SIM_SAMPLES, SIM_BYTES_PER_SAMPLE) <= 4 * GIB);
        assert!(planned_bytes(MAX_SERIES_SAMPLES, 4 * SERIES_BYTES_PER_SAMPLE) <= 4 * GIB);
        assert_eq!(planned_bytes(usize::MAX, 16), u64::MAX);
    }

    #[test]
    fn memory_check_against_what_is_available() {
        assert!(check_memory_against(|| "x", 10, None).is_ok());
        assert!(check_memory_against(|| "x", 10, Some(20)).is_ok());
        assert!(check_memory_against(|| "x", 11, Some(20)).is_err());
        let e = check_memory_against(|| "samples=5", 3 << 30, Some(4 << 30))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "samples=5: needs about 3 GiB of memory, more than half of the 4 GiB available; \
             ask for less (see docs/limits.md)"
        );
        // The machine running the tests has some memory, and not 16 EiB.
        assert!(check_memory(|| "x", 1).is_ok());
        assert!(check_memory(|| "x", u64::MAX).is_err() || !cfg!(target_os = "linux"));
    }

    #[test]
    fn meminfo_parsing() {
        let text = "MemTotal:       24522148 kB\nMemFree:        16975736 kB\n\
                    MemAvailable:   20486532 kB\nBuffers:          123 kB\n";
        assert_eq!(parse_mem_available(text), Some(20486532 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 1 kB\n"), None);
        assert_eq!(parse_mem_available("MemAvailable: x kB\n"), None);
        let limits = "Limit                     Soft Limit           Hard Limit           Units\n\
                      Max cpu time              unlimited            unlimited            seconds\n\
                      Max address space         4294967296           unlimited            bytes\n";
        assert_eq!(parse_address_space_limit(limits), Some(4 << 30));
        let unlimited =
            "Max address space         unlimited            unlimited            bytes\n";
        assert_eq!(parse_address_space_limit(unlimited), None);
        assert_eq!(
            parse_vm_size("Name:\tx\nVmSize:\t  10248 kB\n"),
            Some(10248 * 1024)
        );
        assert_eq!(parse_vm_size("VmPeak: 1 kB\n"), None);
        if cfg!(target_os = "linux") {
            assert!(available_memory_bytes().is_some_and(|b| b > 0));
        }
    }

    #[test]
    fn counts_read_like_counts() {
        assert_eq!(Count(1e12).to_string(), "1000000000000");
        assert_eq!(Count(10000001.0).to_string(), "10000001");
        assert_eq!(Count(u64::MAX as f64).to_string(), "1.8446744073709552e19");
        assert_eq!(Count(1.5e9).to_string(), "1500000000");
        assert_eq!(Count(f64::INFINITY).to_string(), "inf");
    }

    #[test]
    fn bytes_read_like_sizes() {
        assert_eq!(Bytes(100).to_string(), "100 bytes");
        assert_eq!(Bytes(1 << 20).to_string(), "1 MiB");
        assert_eq!(Bytes(64 << 10).to_string(), "64 KiB");
        assert_eq!(Bytes(3 * (1 << 29)).to_string(), "1.5 GiB");
        assert_eq!(Bytes(u64::MAX).to_string(), "16 EiB");
    }

    fn read_all(input: &[u8], max_bytes: u64, max_line: u64) -> Result<Vec<u8>, Overrun> {
        let mut out = Vec::new();
        BoundedReader::new(input, max_bytes, max_line)
            .read_to_end(&mut out)
            .map_err(|e| Overrun::of(&e).expect("an overrun"))?;
        Ok(out)
    }

    #[test]
    fn bounded_reader_stops_at_the_limits() {
        assert_eq!(read_all(b"ab\ncd\n", 6, 2).unwrap(), b"ab\ncd\n");
        assert_eq!(
            read_all(b"ab\ncd\ne", 6, 2),
            Err(Overrun::Total { limit: 6 })
        );
        assert_eq!(
            read_all(b"ab\ncde\n", 100, 2),
            Err(Overrun::Line { line: 2, limit: 2 })
        );
        // An endless source is read no further than the limit plus one byte.
        let mut zero = io::repeat(0).take(1 << 40);
        let mut reader = BoundedReader::new(&mut zero, 1000, 1 << 20);
        let e = io::copy(&mut reader, &mut io::sink()).unwrap_err();
        assert_eq!(Overrun::of(&e), Some(Overrun::Total { limit: 1000 }));
        assert_eq!(zero.limit(), (1 << 40) - 1001);
        let e = Overrun::Line {
            line: 3,
            limit: 65536,
        }
        .to_limit_error("input file a.csv", "x");
        assert_eq!(
            e.to_string(),
            "input file a.csv, line 3: longer than 64 KiB (65536 bytes), the limit for one line \
             (see docs/limits.md)"
        );
    }
}
