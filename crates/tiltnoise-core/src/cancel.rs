//! Cancellation of long computations: a [`Cancel`] token that a front end sets (the command
//! line from its signal handler, Python from its own signal check) and that every long loop of
//! the crate polls between units of work small enough to stop any call within a fraction of a
//! second. A cancelled call returns its error type's `Cancelled` variant, wrapping
//! [`Cancelled`], and no partial result.
//!
//! The crate installs no signal handler and reads no global state: the token is handed in, in
//! the options of the call ([`Cancel::never`] by default).

use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A cheap, clonable handle on one cancellation flag; clones share the flag. Setting it is
/// final. [`Cancel::never`] (the default) is a token nobody can set, and polling it costs a
/// branch.
#[derive(Clone, Default)]
pub struct Cancel(Option<Arc<AtomicBool>>);

/// The computation was cancelled through its [`Cancel`] token before it finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cancelled before the computation finished")]
pub struct Cancelled;

impl Cancel {
    /// A new token, not set, to hand to a computation and set from elsewhere.
    pub fn new() -> Cancel {
        Cancel(Some(Arc::new(AtomicBool::new(false))))
    }

    /// A token that is never set: for callers that do not cancel.
    pub fn never() -> Cancel {
        Cancel(None)
    }

    /// Sets the flag: every computation polling this token (or a clone) stops at its next
    /// check. Does nothing on [`Cancel::never`].
    pub fn cancel(&self) {
        if let Some(flag) = &self.0 {
            flag.store(true, Ordering::Relaxed);
        }
    }

    /// Whether the flag is set.
    pub fn is_cancelled(&self) -> bool {
        self.0.as_ref().is_some_and(|f| f.load(Ordering::Relaxed))
    }

    /// `Err(Cancelled)` once the flag is set: `cancel.check()?` between units of work.
    ///
    /// # Errors
    ///
    /// [`Cancelled`] when the flag is set.
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }
}

impl fmt::Debug for Cancel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            None => f.write_str("Cancel::never()"),
            Some(_) => write!(f, "Cancel(cancelled: {})", self.is_cancelled()),
        }
    }
}

/// Two tokens are equal when they share one flag, or are both [`Cancel::never`] (so that options
/// holding a token can still be compared).
impl PartialEq for Cancel {
    fn eq(&self, other: &Cancel) -> bool {
        match (&self.0, &other.0) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_the_flag_and_never_stays_unset() {
        let token = Cancel::new();
        let clone = token.clone();
        assert_eq!(clone.check(), Ok(()));
        token.cancel();
        assert!(clone.is_cancelled());
        assert_eq!(clone.check(), Err(Cancelled));
        let never = Cancel::never();
        never.cancel();
        assert_eq!(never.check(), Ok(()));
        assert_eq!(Cancel::default(), never);
        assert_ne!(token, Cancel::new());
        assert_eq!(token, clone);
    }
}
