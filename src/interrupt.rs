//! SIGINT, SIGTERM and SIGHUP (unless SIGHUP is ignored, as under `nohup`) end the run: the
//! handler sets the run's [`Cancel`] token (so that the computation stops where it polls it),
//! removes the staging directory of every output being written or staged
//! ([`tiltnoise_job::files::remove_staging_for_exit`], which keeps any from being created afterwards),
//! prints one line naming the signal and ends the process with exit code 2, at once, whatever
//! the main thread is doing. An output is only ever created inside a staging directory that
//! exists and is registered, so nothing is left, however far a writer had got.

use tiltnoise_core::cancel::Cancel;

/// Starts the handler (a thread of signal-hook's iterator) and returns the token it sets. Call
/// it once, early in `main`. On platforms without POSIX signals the token is never set.
pub fn install() -> Cancel {
    let cancel = Cancel::new();
    #[cfg(unix)]
    unix::install(&cancel);
    cancel
}

/// For the main thread when the run failed because the token was set: the handler is ending
/// the process and prints the run's one line, so this thread waits for that instead of
/// printing a second one.
pub fn wait_for_the_handler() -> ! {
    loop {
        std::thread::park();
    }
}

#[cfg(unix)]
mod unix {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    use signal_hook::iterator::Signals;
    use std::io::Write as _;
    use tiltnoise_core::cancel::Cancel;

    pub(super) fn install(cancel: &Cancel) {
        let mut wanted = vec![SIGINT, SIGTERM];
        // A hangup (the terminal closed) ends the run as well, unless it is ignored, as under
        // `nohup`: then the run goes on.
        if !ignored(SIGHUP) {
            wanted.push(SIGHUP);
        }
        // Without a handler (the registration failed) the signals keep their default action,
        // which ends the process too, only without removing the temporary files.
        let Ok(mut signals) = Signals::new(&wanted) else {
            return;
        };
        let cancel = cancel.clone();
        std::thread::spawn(move || {
            let Some(signal) = signals.forever().next() else {
                return;
            };
            cancel.cancel();
            let cleanup = tiltnoise_job::files::remove_staging_for_exit();
            let name = match signal {
                SIGINT => "SIGINT",
                SIGHUP => "SIGHUP",
                _ => "SIGTERM",
            };
            // Not eprintln!: a panic on a closed standard error would end this thread before
            // the process.
            let _ = writeln!(std::io::stderr(), "{}", message(name, &cleanup));
            // `_exit`: no atexit handlers, whose clean-up (the HDF5 library's) would race with a
            // write in progress on another thread.
            signal_hook::low_level::exit(2);
        });
    }

    /// The one line the handler prints.
    fn message(signal: &str, cleanup: &tiltnoise_job::files::ExitCleanup) -> String {
        let mut line = format!(
            "tiltnoise: error: interrupted by {signal}; {} staged output(s) removed",
            cleanup.removed
        );
        match cleanup.committed {
            0 => line.push_str(", no output written"),
            n => line.push_str(&format!(", {n} output(s) written before")),
        }
        if let Some((dir, why)) = cleanup.left.first() {
            line.push_str(&format!(
                "; could not remove {} ({why}){}",
                dir.display(),
                match cleanup.left.len() {
                    1 => String::new(),
                    n => format!(" and {} more", n - 1),
                }
            ));
        }
        line
    }

    /// Whether `signal`'s disposition is "ignore" (inherited from the parent, as `nohup` sets
    /// it for SIGHUP).
    #[allow(
        unsafe_code,
        reason = "sigaction reads the disposition; no safe API does"
    )]
    fn ignored(signal: libc::c_int) -> bool {
        // SAFETY: sigaction with a null new action only writes the current one to `old`, a
        // valid, properly aligned `sigaction` that lives across the call; zeroed is a valid
        // value of that plain C struct.
        unsafe {
            let mut old: libc::sigaction = std::mem::zeroed();
            libc::sigaction(signal, std::ptr::null(), &mut old) == 0
                && old.sa_sigaction == libc::SIG_IGN
        }
    }
}
