//! How a job reports its progress: it calls a [`Progress`] the front end gives it. The command
//! line draws a bar on a terminal, Python calls the user's callback or does nothing; the job
//! never knows which.

/// The receiver of a job's progress: `done` of `total` units of work (samples read, draws
/// made, frequencies written), called from the job's threads.
pub trait Progress: Sync {
    /// `done` of `total` units are done (`done <= total`; called with increasing `done`).
    fn report(&self, done: u64, total: u64);
    /// The work is over (called once, also when the job fails or is cancelled).
    fn finish(&self) {}
}

/// A [`Progress`] that shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl Progress for Silent {
    fn report(&self, _done: u64, _total: u64) {}
}
