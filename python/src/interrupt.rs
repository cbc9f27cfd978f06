//! Interrupting a long computation with Ctrl-C, without replacing Python's SIGINT handler.
//!
//! Python's own handler only sets a flag that the interpreter reads when it runs bytecode, or
//! when an extension calls `PyErr_CheckSignals`; a computation in Rust does neither. So
//! [`watch`] runs the computation on a worker thread (with the GIL released, as every
//! computation runs) while the calling thread, the one Python delivers signals to, asks every
//! [`POLL`] whether a signal came: if one did, it sets the computation's
//! [`Cancel`] token, waits for the worker to stop at its next check of the token (the library
//! polls it often enough to stop any call within a fraction of a second) and raises what the
//! signal's handler raised (`KeyboardInterrupt` for Ctrl-C), never the computation's
//! `Cancelled` error nor a partial result.

use pyo3::prelude::*;
use std::sync::{Condvar, Mutex};
use std::time::Duration;
use tiltnoise_core::cancel::Cancel;

/// How often the calling thread asks Python whether a signal came: a tenth of the half second
/// an interrupt may take, and rare enough that waking up costs nothing measurable.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work` on a worker thread with the GIL released, `cancel` (the token the work polls)
/// set when a signal's Python handler raises, and that exception returned once the worker
/// has stopped. A panic of the worker is raised again on the calling thread (where PyO3 turns it
/// into `PanicException`).
///
/// Python delivers signals to its main thread only: called from another thread, `work` runs to
/// its end, as any call would.
pub fn watch<T, W>(py: Python<'_>, cancel: &Cancel, work: W) -> PyResult<T>
where
    T: Send,
    W: FnOnce() -> PyResult<T> + Send,
{
    // Whether the worker is done, and the signal it gives when it is.
    let done = (Mutex::new(false), Condvar::new());
    let finished = || {
        *done.0.lock().unwrap_or_else(|e| e.into_inner()) = true;
        done.1.notify_one();
    };
    std::thread::scope(|scope| {
        let worker = scope.spawn(|| {
            let result = work();
            finished();
            result
        });
        let mut interrupted = None;
        loop {
            let wait = || {
                let flag = done.0.lock().unwrap_or_else(|e| e.into_inner());
                let (flag, _) = done
                    .1
                    .wait_timeout_while(flag, POLL, |done| !*done)
                    .unwrap_or_else(|e| e.into_inner());
                *flag
            };
            // A worker that panicked never says it is done, but is finished.
            if py.detach(wait) || worker.is_finished() {
                break;
            }
            if let Err(e) = py.check_signals() {
                cancel.cancel();
                interrupted = Some(e);
                break;
            }
        }
        let outcome = py.detach(|| worker.join());
        match (interrupted, outcome) {
            (Some(e), _) => Err(e),
            (None, Ok(result)) => result,
            (None, Err(panic)) => std::panic::resume_unwind(panic),
        }
    })
}

/// [`watch`] when `long`, else `work` on the calling thread with the GIL released: a call of a
/// millisecond or less ends before anyone could interrupt it, and starting a thread would be
/// most of its cost.
pub fn watch_if<T, W>(py: Python<'_>, long: bool, cancel: &Cancel, work: W) -> PyResult<T>
where
    T: Send,
    W: FnOnce() -> PyResult<T> + Send,
{
    match long {
        true => watch(py, cancel, work),
        false => py.detach(work),
    }
}
