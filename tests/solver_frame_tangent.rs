//! The dynamic solver's iteration matrix in the frame turning with the shaft
//! (`DynamicSolver::frame_omega`: centrifugal and Coriolis terms through the seeds,
//! `frame_seed`) against central finite differences of the assembled residual, column by
//! column, on the TM-4760 hinged blade (rotors/tm4760.toml) at 660 rpm during the lag free
//! decay; and the same comparison for the matrix assembled without the frame terms, which must
//! fail by far, so that the check is not vacuous.
use rotorsim::rotor::hinged::{DecayOptions, DecaySim, HingedSpec};
use rotorsim::solver::NewtonMethod;
use std::path::Path;

/// Central difference of the residual in Newton unknown `j` at `d0` with step `e`.
fn central(sim: &mut DecaySim, d0: &[f64], j: usize, e: f64) -> Vec<f64> {
    let mut d = d0.to_vec();
    d[j] = d0[j] + e;
    let (rp, _) = sim.solver.iteration_system(&d, true).unwrap();
    d[j] = d0[j] - e;
    let (rm, _) = sim.solver.iteration_system(&d, true).unwrap();
    rp.iter()
        .zip(&rm)
        .map(|(p, m)| (p - m) / (2.0 * e))
        .collect()
}

fn inf(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}

/// Tolerance of entry (i, j), the bound on the error of the central difference `D(e/2)`
/// plus the round-off of both sides:
/// - truncation: `D(e) - D(e/2) = 3/4 C e^2` at leading order while `D(e/2)` is off by
///   `C e^2 / 4`, so `|D(e) - D(e/2)|` (column maximum) bounds it with a factor 3 to spare;
/// - round-off of the difference quotient: the scatter between `D(e/2)` and `D(e/2 (1 + 2^-10))`
///   (same truncation, independent round-off), twice;
/// - round-off of the assembled entry and residual: the row's terms reach its largest entry
///   `s_i` (stiffness and inertia rows of ~1e7 beside entries of ~1e2), summed in double
///   precision: `ROUND eps s_i`.
const ROUND: f64 = 64.0;

#[test]
fn turning_frame_iteration_matrix_matches_central_differences() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors/tm4760.toml");
    let spec = HingedSpec::from_file(&path).unwrap();
    let mut sim = DecaySim::new(
        &spec,
        &path,
        &DecayOptions {
            omega_rad_s: spec.rotor.omega_rad_s,
            release_moment_nm: 4.5,
            release_time_s: 0.01,
            time_step_s: 0.005,
            rho_inf: 0.9,
            newton: NewtonMethod::Full,
            newton_rtol: 1e-10,
            rotating_frame: true,
        },
    )
    .unwrap();
    // past the release: the blade moves in the turning frame (Coriolis forces act)
    for _ in 0..6 {
        sim.step().unwrap();
    }
    let ndof = 6 * sim.solver.model.nodes.len() + sim.solver.state.lambda.len();
    // the next step's Newton system at its predictor (where full Newton factors first)
    let d0 = vec![0.0; ndof];
    let (_, jac) = sim.solver.iteration_system(&d0, true).unwrap();
    let (_, jac0) = sim.solver.iteration_system(&d0, false).unwrap();
    let row_scale: Vec<f64> = jac.iter().map(|r| inf(r.iter().copied())).collect();
    // unknowns are velocity-level corrections: e = 1e-3 moves nodes by h e = 5 um and turns
    // them by 5 urad, accelerations by ca e ~ 0.4 m/s^2
    let e = 1e-3;
    let (mut worst, mut worst0, mut frame_max) = (0.0f64, 0.0f64, 0.0f64);
    let (mut at, mut at0) = ((0, 0), (0, 0));
    for j in 0..ndof {
        let d1 = central(&mut sim, &d0, j, e);
        let d2 = central(&mut sim, &d0, j, 0.5 * e);
        let d3 = central(&mut sim, &d0, j, 0.5 * e * (1.0 + 1.0 / 1024.0));
        let trunc = inf(d1.iter().zip(&d2).map(|(a, b)| a - b));
        let noise = inf(d3.iter().zip(&d2).map(|(a, b)| a - b));
        for i in 0..ndof {
            let tol = trunc + 2.0 * noise + ROUND * f64::EPSILON * row_scale[i];
            let r = (jac[i][j] - d2[i]).abs() / tol;
            let r0 = (jac0[i][j] - d2[i]).abs() / tol;
            frame_max = frame_max.max((jac[i][j] - jac0[i][j]).abs() / tol);
            if r > worst {
                (worst, at) = (r, (i, j));
            }
            if r0 > worst0 {
                (worst0, at0) = (r0, (i, j));
            }
        }
    }
    eprintln!(
        "{ndof} unknowns; largest |J - FD| / tolerance: {worst:.3} at {at:?}; \
         without the frame terms {worst0:.3e} at {at0:?} (frame terms up to {frame_max:.3e} \
         tolerances)"
    );
    assert!(worst <= 1.0, "{worst} at {at:?}");
    // the frame terms are resolved: dropping them misses by far more than the tolerance
    assert!(worst0 >= 1e3, "{worst0}");
}
