//! Assembly, Newton iterations, generalized-alpha time integration, static and modal analyses.
// Index loops mirror the component formulas of the formulation.
#![allow(clippy::needless_range_loop)]
pub mod assembly;
pub mod bordered;
pub mod budget;
pub mod dynamic;
pub mod fdcheck;
pub mod modal;
pub mod newton;
pub mod ode;
pub mod snapshot;
pub mod state;
pub mod statics;
pub mod verification;

pub use assembly::Assembler;

pub use dynamic::{DynamicSolver, GenAlphaParams, StepInfo};
pub use newton::{NewtonError, NewtonMethod, NewtonOptions};
pub use snapshot::SolverSnapshot;
pub use state::State;
pub use statics::{static_solve, StaticOptions, StaticReport};
