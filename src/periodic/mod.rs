//! Periodic solutions of a periodically forced system by shooting on its period map
//! `x -> Phi(x)` (docs/periodic.md).
//!
//! The solver knows nothing of rotors: it sees a [`PeriodMap`], a map on perturbable
//! coordinates that integrates one period, and finds `x = Phi(x)` by Newton-Picard iterations
//! ([`shooting`]); [`floquet`] turns the subspace it builds into Floquet multipliers.
pub mod floquet;
pub mod shooting;

pub use floquet::Multiplier;
pub use shooting::{shoot, ShootingOptions, ShootingOutcome};

/// One period of a system, on perturbable coordinates.
///
/// The map keeps an *accepted point* `x_k` with its period `Phi(x_k)` integrated; the solver
/// asks for perturbed periods about it (Jacobian-vector products), for trial points, and
/// accepts trials.
pub trait PeriodMap {
    /// The accepted point and its image `(x_k, Phi(x_k))`.
    fn accepted(&self) -> (&[f64], &[f64]);
    /// `Phi(x)` from the state of the accepted point with its coordinates replaced by `x`
    /// (a perturbed period; the accepted point is unchanged).
    fn perturbed(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>>;
    /// `Phi(x)` for a trial point `x` (the rest of the state taken from the end of the
    /// accepted period); [`PeriodMap::accept`] makes it the accepted point.
    fn trial(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>>;
    /// Accept the last trial.
    fn accept(&mut self);
    /// The periodicity residual of the accepted point, as its owner measures it (e.g. per
    /// output channel, relative to its range); the solver stops when it is below the
    /// tolerance.
    fn residual(&self) -> f64;
    /// Periods integrated so far (every one: marched, perturbed and trial).
    fn periods(&self) -> usize;
    /// How much the last accepted step changed the accepted period, in the measure of
    /// [`PeriodMap::residual`] but over the whole period (e.g. every sample of an output
    /// channel, relative to its range); None before the first step. The solver turns it
    /// into the distance to the periodic solution.
    fn step_change(&self) -> Option<f64>;
}
