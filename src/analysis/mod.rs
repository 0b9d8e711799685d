//! Periodicity, harmonics, model-vs-measurement comparison, diagnosis.
