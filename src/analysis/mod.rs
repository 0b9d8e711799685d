//! Periodicity, harmonics, model-vs-measurement comparison, diagnosis.
pub mod compare;
pub mod harmonics;
pub mod periodicity;
