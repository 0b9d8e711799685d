//! Model diagnosis: residual analysis of the baseline damper model against measured
//! stroke-driven data, a library of physical extensions fitted by nonlinear least squares
//! (Levenberg-Marquardt), ranking by BIC, validation on held-out data and the choice of a cause
//! (or `none`). See docs/diagnosis.md.
pub mod acquisition;
pub mod candidates;
pub mod data;
pub mod evidence;
pub mod fit;
pub mod identify;
pub mod pipeline;
pub mod report;
pub mod rotor;
pub mod settings;
pub mod support;

pub use candidates::Cause;
pub use data::{check_measurements, screen, Measurement, Screened};
pub use fit::{diagnose, Curves, DiagnoseOptions, Diagnosis, Outcome};
pub use support::{NoEffect, NotSupported, PartSupport};

/// Errors of the diagnosis: what cannot be decided and why.
#[derive(Debug, thiserror::Error)]
pub enum DiagnoseError {
    #[error("{test}: no measured force: a diagnosis compares the model force with the measured one (bench CSV needs a `force_N` or `force_lb` column)")]
    NoForce { test: String },
    #[error(
        "{test}: the {channel} is missing from {from_s:.6} s to {to_s:.6} s (a dropout): {reason}"
    )]
    Dropout {
        test: String,
        channel: &'static str,
        from_s: f64,
        to_s: f64,
        reason: String,
    },
    #[error("{test}: only {kept} of {samples} force samples are usable ({dropouts} rows missing a value, {clipped} clipped at the load cell's range): too few to compare; re-record the test (with a larger range where it clips)")]
    Unusable {
        test: String,
        kept: usize,
        samples: usize,
        dropouts: usize,
        clipped: usize,
    },
    #[error("{test}: sample rate too low for the cycle: {samples_per_cycle:.1} samples per stroke cycle (period {period_s:.4} s); at least {min} are needed to resolve reversals and relief-valve opening")]
    SampleRate {
        test: String,
        samples_per_cycle: f64,
        period_s: f64,
        min: usize,
    },
    #[error("{test}: {cycles:.1} stroke cycles found; at least {min} are needed (one to settle the model from its initial state, the rest to compare)")]
    TooShort {
        test: String,
        cycles: f64,
        min: usize,
    },
    #[error("{test}: the stroke does not oscillate (no cycle found): cannot estimate the stroking period")]
    NoCycle { test: String },
    #[error("no measurements given")]
    Empty,
    #[error(
        "the base deck has no [damper.physical] table: the diagnosis extends the physical model"
    )]
    NoPhysical,
    #[error("model replay of {test} failed: {source}")]
    Model {
        test: String,
        #[source]
        source: crate::hydraulics::HydraulicError,
    },
}
