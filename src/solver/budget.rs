//! What a run will cost, estimated before it starts: a run beyond sense stops at once and says
//! its estimate, instead of running for years or failing for memory deep inside a factorization.
use crate::structure::Model;
use thiserror::Error;

/// CPU time above which a run is refused: a week. rotorsim's runs take seconds to minutes; a
/// week means a typo in a deck (an end time in ms read as s) or an option.
pub const MAX_CPU_S: f64 = 7.0 * 86400.0;

/// CPU seconds per structural dof and Newton iteration, taken low so that only runs beyond
/// sense are refused: the 40-element cantilever costs 2.2 ms per full Newton iteration at 732
/// dofs (3 us a dof), the elastic UH-60A blade with modified Newton 0.1 ms per iteration
/// (docs/performance.md).
pub const CPU_S_PER_DOF_ITERATION: f64 = 1.0e-7;

/// CPU seconds per hydraulic sub-step of a device (RK4 on its pressure states), taken low as
/// above: the rigid-blade reduction runs ~1 us a sub-step.
pub const CPU_S_PER_SUBSTEP: f64 = 2.0e-7;

#[derive(Debug, Error)]
pub enum BudgetError {
    #[error("{what}: estimated {} of CPU time, beyond the {} a run may take; {hint}", duration(*.cpu_s), duration(MAX_CPU_S))]
    Time {
        what: String,
        cpu_s: f64,
        hint: String,
    },
    #[error("{what}: estimated {} of memory, beyond this machine's {}; {hint}", bytes(*.need), bytes(*.have))]
    Memory {
        what: String,
        need: f64,
        have: f64,
        hint: String,
    },
}

/// A cost estimate: CPU seconds and peak bytes.
#[derive(Clone, Debug, Default)]
pub struct Estimate {
    pub cpu_s: f64,
    pub bytes: f64,
}

impl Estimate {
    /// Refused with `what` (the run, named for the user) and `hint` (what to change) when
    /// beyond [`MAX_CPU_S`] or the machine's memory.
    pub fn check(&self, what: &str, hint: &str) -> Result<(), BudgetError> {
        if let Some(have) = memory_bytes() {
            if self.bytes.is_nan() || self.bytes > have {
                return Err(BudgetError::Memory {
                    what: what.into(),
                    need: self.bytes,
                    have,
                    hint: hint.into(),
                });
            }
        }
        if self.cpu_s.is_nan() || self.cpu_s > MAX_CPU_S {
            return Err(BudgetError::Time {
                what: what.into(),
                cpu_s: self.cpu_s,
                hint: hint.into(),
            });
        }
        Ok(())
    }

    /// `k` such runs one after the other (CPU) or side by side (memory).
    pub fn times(self, k: f64) -> Estimate {
        Estimate {
            cpu_s: self.cpu_s * k,
            bytes: self.bytes * k,
        }
    }

    pub fn plus(self, o: Estimate) -> Estimate {
        Estimate {
            cpu_s: self.cpu_s + o.cpu_s,
            bytes: self.bytes + o.bytes,
        }
    }
}

/// Dofs (node dofs and multipliers) and stored matrix entries of `model`, as the assembler
/// will lay them out (dense element blocks).
pub fn dofs_and_entries(model: &Model) -> (f64, f64) {
    let mut ndof = 6.0 * model.nodes.len() as f64;
    let mut nnz = ndof;
    for e in &model.elements {
        let d = 6.0 * e.node_list().len() as f64 + e.n_lambda() as f64;
        ndof += e.n_lambda() as f64;
        nnz += d * d;
    }
    nnz += 36.0 * model.step_elements.len() as f64;
    (ndof, nnz)
}

/// Time integration of `model` over `steps` steps with `iterations` Newton iterations each.
pub fn time_integration(model: &Model, steps: f64, iterations: f64) -> Estimate {
    let (ndof, nnz) = dofs_and_entries(model);
    time_integration_of(ndof, nnz, steps, iterations)
}

/// Time integration of `ndof` unknowns and `nnz` stored matrix entries. Memory: the model, the
/// sparse pattern, its LU and workspaces, ~50 bytes per entry and ~400 per dof (a 4000-element
/// cantilever, 72 000 dofs and 2.3 million entries, peaks at 155 MB).
pub fn time_integration_of(ndof: f64, nnz: f64, steps: f64, iterations: f64) -> Estimate {
    Estimate {
        cpu_s: steps * iterations * ndof * CPU_S_PER_DOF_ITERATION,
        bytes: 50.0 * nnz + 400.0 * ndof,
    }
}

/// Dense eigen-analysis of `ndof` unknowns: a handful of dense ndof x ndof matrices and
/// O(ndof^3) flops at ~1 GFLOP/s.
pub fn dense_modal_of(ndof: f64) -> Estimate {
    Estimate {
        cpu_s: 30.0 * ndof.powi(3) * 1e-9,
        bytes: 8.0 * 8.0 * ndof * ndof,
    }
}

/// Samples kept in memory: `rows` rows of `columns` f64 values.
pub fn samples(rows: f64, columns: f64) -> Estimate {
    Estimate {
        cpu_s: 0.0,
        bytes: 8.0 * rows * columns,
    }
}

/// Hydraulic sub-steps of one device.
pub fn substeps(n: f64) -> Estimate {
    Estimate {
        cpu_s: n * CPU_S_PER_SUBSTEP,
        bytes: 0.0,
    }
}

/// Physical memory of this machine (Linux: MemTotal of /proc/meminfo); None where unknown.
pub fn memory_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// A count for messages: whole below a million, else with an exponent (1.00e18).
pub fn count(n: f64) -> String {
    if n < 1e6 {
        format!("{n:.0}")
    } else {
        format!("{n:.2e}")
    }
}

fn duration(s: f64) -> String {
    if !s.is_finite() {
        "an unbounded amount".into()
    } else if s >= 365.25 * 86400.0 {
        format!("{} years", sig(s / (365.25 * 86400.0)))
    } else if s >= 86400.0 {
        format!("{} days", sig(s / 86400.0))
    } else if s >= 3600.0 {
        format!("{} hours", sig(s / 3600.0))
    } else {
        format!("{} s", sig(s))
    }
}

/// Three significant figures, in exponent form from 10^4.
fn sig(x: f64) -> String {
    if x >= 1e4 {
        format!("{x:.2e}")
    } else if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else {
        format!("{x:.2}")
    }
}

fn bytes(b: f64) -> String {
    if !b.is_finite() {
        "an unbounded amount".into()
    } else {
        format!("{} GiB", sig(b / (1024.0 * 1024.0 * 1024.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_week_passes_and_more_does_not() {
        let ok = Estimate {
            cpu_s: MAX_CPU_S * 0.99,
            bytes: 1e6,
        };
        assert!(ok.check("x", "y").is_ok());
        let slow = Estimate {
            cpu_s: 1e12,
            bytes: 1e6,
        };
        let e = slow.check("run", "shorten it").unwrap_err().to_string();
        assert!(e.contains("run: estimated 3.17e4 years of CPU time"), "{e}");
        assert!(e.contains("shorten it"), "{e}");
        let nan = Estimate {
            cpu_s: f64::NAN,
            bytes: 1e6,
        };
        assert!(nan.check("x", "y").is_err());
    }

    #[test]
    fn memory_beyond_the_machine_is_refused() {
        let Some(have) = memory_bytes() else { return };
        let big = Estimate {
            cpu_s: 1.0,
            bytes: 2.0 * have,
        };
        let e = big
            .check("modes", "fewer elements")
            .unwrap_err()
            .to_string();
        assert!(e.contains("of memory, beyond this machine's"), "{e}");
    }
}
