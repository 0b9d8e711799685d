//! Newton iteration options and failure reporting.
use super::assembly::LinearError;
use crate::structure::model::ElementError;
use thiserror::Error;

/// How the iteration matrix is kept: refactored at every iterate (full Newton) or reused across
/// iterations and steps while it contracts (modified Newton).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum NewtonMethod {
    #[default]
    Full,
    Modified,
}

impl NewtonMethod {
    pub fn name(self) -> &'static str {
        match self {
            NewtonMethod::Full => "full",
            NewtonMethod::Modified => "modified",
        }
    }
}

impl std::str::FromStr for NewtonMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "full" => Ok(NewtonMethod::Full),
            "modified" => Ok(NewtonMethod::Modified),
            _ => Err(format!(
                "unknown Newton method '{s}' (expected full or modified)"
            )),
        }
    }
}

#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    pub max_iterations: usize,
    /// Convergence when ||r|| <= rtol * ||r_0|| (r_0: residual of the predictor / load step).
    pub rtol: f64,
    /// ... or when the largest configuration correction <= xtol * model size and the residual
    /// is below `floor(r_0)`.
    pub xtol: f64,
    /// Dynamic solver only: full or modified Newton.
    pub method: NewtonMethod,
    /// Modified Newton: the stored matrix is refreshed at the current iterate as soon as an
    /// iteration reduces the residual by less than this factor (contraction-rate rule).
    pub max_contraction: f64,
}

impl NewtonOptions {
    /// The residual a correction below `xtol` must reach to end the iterations: sqrt(rtol) of
    /// the force scale (the largest initial residual of the analysis so far: a later load or
    /// time step may start at round-off). Below it the update is round-off; above it a tiny
    /// update means a stiffness beyond sense (or a wrong tangent), not convergence.
    pub fn floor(&self, scale: f64) -> f64 {
        self.rtol.sqrt() * scale
    }
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            max_iterations: 25,
            rtol: 1e-9,
            xtol: 1e-11,
            method: NewtonMethod::Full,
            max_contraction: 0.2,
        }
    }
}

#[derive(Debug, Error)]
pub enum NewtonError {
    #[error("Newton iterations did not converge at t = {t} s: {iterations} iterations, residual norm {residual:.3e} (initial {initial:.3e})")]
    Diverged {
        t: f64,
        iterations: usize,
        residual: f64,
        initial: f64,
    },
    #[error("static Newton iterations did not converge at load factor {load_factor}: {iterations} iterations, residual norm {residual:.3e} (initial {initial:.3e}); try more load steps, and check that every rigid-body motion and mechanism dof is restrained (a free revolute has no static equilibrium under load)")]
    StaticDiverged {
        load_factor: f64,
        iterations: usize,
        residual: f64,
        initial: f64,
    },
    #[error("non-finite residual or correction at t = {t} s, {}", at_iterate(*.iteration, *.residual))]
    NonFinite {
        t: f64,
        iteration: usize,
        /// Residual norm of the last finite iterate (NaN if none).
        residual: f64,
    },
    #[error("at t = {t} s, iteration {iteration}: {source}")]
    Linear {
        t: f64,
        iteration: usize,
        source: LinearError,
    },
    #[error("at t = {t} s, {}: {source}", at_iterate(*.iteration, *.residual))]
    Element {
        t: f64,
        iteration: usize,
        /// Residual norm of the last iterate (NaN before the first).
        residual: f64,
        source: ElementError,
    },
}

/// Where a Newton loop stopped: the iteration and, once there is one, the last residual norm.
fn at_iterate(iteration: usize, residual: f64) -> String {
    if residual.is_finite() {
        format!("Newton iteration {iteration}, residual norm {residual:.3e} at the last iterate")
    } else {
        format!("Newton iteration {iteration}")
    }
}

pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Size of the model (for the increment criterion): bounding-box diagonal, at least 1.
pub fn model_size(x: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in x {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d: f64 = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    d.max(1.0)
}
