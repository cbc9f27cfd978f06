//! Standard output and standard error of the commands. Everything a command prints goes
//! through one buffered [`Out`], whose failures are typed ([`StdoutError`]) so that `main` can
//! tell a reader that has gone (a closed pipe: end quietly, as Unix tools do) from a failed
//! write (a full disk: one error line). Messages on standard error are written with [`note`],
//! which never panics.

use std::fmt;
use std::io::{self, BufWriter, StdoutLock, Write};

/// Buffered standard output. Write to it with `write!` / `writeln!` and `?`.
pub struct Out {
    inner: BufWriter<StdoutLock<'static>>,
}

impl Out {
    /// Standard output, locked for the whole run.
    pub fn stdout() -> Out {
        Out {
            inner: BufWriter::with_capacity(1 << 16, io::stdout().lock()),
        }
    }

    /// What `write!` and `writeln!` call.
    pub fn write_fmt(&mut self, args: fmt::Arguments<'_>) -> Result<(), StdoutError> {
        self.inner.write_fmt(args).map_err(StdoutError)
    }

    /// Writes everything buffered.
    pub fn flush(&mut self) -> Result<(), StdoutError> {
        self.inner.flush().map_err(StdoutError)
    }
}

/// Standard output could not be written.
#[derive(Debug)]
pub struct StdoutError(io::Error);

impl StdoutError {
    /// The reader of a pipe has closed it (EPIPE): nobody reads what the run would print.
    pub fn is_closed_pipe(&self) -> bool {
        self.0.kind() == io::ErrorKind::BrokenPipe
    }
}

impl fmt::Display for StdoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot write to standard output: {}", self.0)
    }
}

impl std::error::Error for StdoutError {}

/// Whether `e` is (or was caused by) a closed pipe on standard output.
pub fn is_closed_pipe(e: &anyhow::Error) -> bool {
    e.chain()
        .filter_map(|c| c.downcast_ref::<StdoutError>())
        .any(StdoutError::is_closed_pipe)
}

/// Writes `text` and a newline to standard error. A standard error that cannot be written
/// loses the text; it never ends the run.
pub fn note(text: &str) {
    let mut err = io::stderr().lock();
    let _ = writeln!(err, "{text}");
}
