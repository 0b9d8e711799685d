//! Stopping runs from outside (the Python package's Ctrl-C): a [`StopFlag`] shared with the
//! runs, checked before every structural step, and the [`Stopped`] error a stopped run returns.
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// A request to stop, shared by whoever may ask and the runs that check it. The default flag
/// is never raised unless a clone of it is (the command line never raises one).
#[derive(Clone, Debug, Default)]
pub struct StopFlag(Arc<AtomicBool>);

impl StopFlag {
    pub fn new() -> Self {
        Self::default()
    }
    /// Asks every run holding a clone of this flag to stop at its next step.
    pub fn request(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
    pub fn requested(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
    /// `Err(Stopped)` once a stop is requested: the run at model time `t_s`, in `what` (e.g.
    /// "physical model, revolution 12 of at most 75").
    pub fn check(&self, t_s: f64, what: &str) -> Result<(), Stopped> {
        if self.requested() {
            return Err(Stopped {
                t_s,
                what: what.to_string(),
            });
        }
        Ok(())
    }
}

/// How a [`Stopped`] message starts (a unit's error reaches the job as text).
pub const STOPPED_PREFIX: &str = "stopped by the user";

/// The error of a run stopped by a [`StopFlag`] (its message starts with [`STOPPED_PREFIX`]).
#[derive(Debug, Clone, thiserror::Error)]
#[error("stopped by the user at t = {t_s:.4} s, {what}")]
pub struct Stopped {
    /// Model time of the step it stopped before [s].
    pub t_s: f64,
    /// The model and revolution it stopped in.
    pub what: String,
}

/// A run stopped by the user, its result folder published as incomplete. Its message lists
/// where each unit stopped.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{message} (the result folder {folder} is marked incomplete)")]
pub struct RunStopped {
    pub message: String,
    pub folder: std::path::PathBuf,
}
