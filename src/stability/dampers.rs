//! The reduced lag rotor with each blade's damper as a device outside the linear equations:
//! the damper sees its stroke (`arm * zeta`), its relief and check valves live, and returns
//! its force on the blade (resisting the stroke), whose moment `arm * F` acts on the lag hinge. What the linearised analysis
//! replaces by a stiffness and a damping at one amplitude, this integrates as it is.
//!
//! Step coupling: over a structural step the damper's moment is its time-averaged force
//! (`F_m`, the paper's Eq. 13) held constant, so the impulse it gives the blade is the
//! device's own over that stroke. `F_m` depends on the stroke at the step's end, which
//! depends on `F_m`: a fixed point, solved to round-off in a few iterations (the damper's
//! stroke moves by `h^2 arm^2 / I` per newton of force change, tiny at these steps).
use super::lag_rotor::{
    check_omega, range, LagRotor, PeriodicSystem, Result, StabilityError, TimeResponse,
};
use crate::hydraulics::Device;
use crate::solver::ode::Rk4;

/// A blade's damper: the device and its arm (stroke = `arm_m * zeta`).
#[derive(Debug)]
pub struct BladeDamper {
    pub device: Box<dyn Device>,
    pub arm_m: f64,
}

/// A free response with the dampers as devices.
#[derive(Clone, Debug)]
pub struct DeviceResponse {
    pub response: TimeResponse,
    /// Each step's time-averaged damper force per blade [N]: `force_n[i * blades + k]` over
    /// the step ending at `response.time_s[i + 1]`.
    pub force_n: Vec<f64>,
    /// Most coupling iterations a step took.
    pub max_iterations: usize,
}

/// Coupling iterations a step may take before the response stops with an error.
pub const MAX_COUPLING_ITERATIONS: usize = 30;
/// Relative change of the damper force at which a step's coupling has converged.
pub const COUPLING_TOL: f64 = 1e-9;

/// Forces of the dampers over one step: the last step's and the one before (the start of the
/// fixed point), and the iteration's.
pub(super) struct StepForces {
    pub mean: Vec<f64>,
    prev: Vec<f64>,
    next: Vec<f64>,
    moment: Vec<f64>,
}

impl StepForces {
    pub(super) fn new(dampers: &[BladeDamper]) -> Self {
        let f: Vec<f64> = dampers.iter().map(|d| d.device.committed_force()).collect();
        StepForces {
            prev: f.clone(),
            next: f.clone(),
            moment: vec![0.0; f.len()],
            mean: f,
        }
    }
}

/// One step of a free response with the dampers as devices (module docs): the step's moments
/// `arm * F_m` held constant, `advance(moments, trial)` integrating the blades from the
/// accepted state `y` (lag perturbations first) to `trial`, the devices' trial steps giving
/// the next `F_m`, to [`COUPLING_TOL`]; the devices committed on success. Returns the
/// iterations taken.
#[allow(clippy::too_many_arguments)]
pub(super) fn coupled_step(
    dampers: &mut [BladeDamper],
    forces: &mut StepForces,
    first: bool,
    t: f64,
    h: f64,
    y: &[f64],
    trial: &mut [f64],
    mut advance: impl FnMut(&[f64], &mut [f64]) -> Result<()>,
) -> Result<usize> {
    let nb = dampers.len();
    // the force extrapolated from the last two steps starts the fixed point
    for k in 0..nb {
        let f = forces.mean[k];
        forces.mean[k] = if first { f } else { 2.0 * f - forces.prev[k] };
        forces.prev[k] = f;
    }
    let mut change = f64::INFINITY;
    for it in 1..=MAX_COUPLING_ITERATIONS {
        for ((m, d), f) in forces
            .moment
            .iter_mut()
            .zip(dampers.iter())
            .zip(&forces.mean)
        {
            *m = d.arm_m * f;
        }
        advance(&forces.moment, trial)?;
        let mut scale = 1.0f64;
        change = 0.0;
        for (k, d) in dampers.iter_mut().enumerate() {
            let (d_i, d_f) = (d.arm_m * y[k], d.arm_m * trial[k]);
            let f = d.device.trial_step(t, h, d_i, d_f).map_err(|e| {
                StabilityError::Numerical(format!(
                    "the damper of blade {} at t = {t:.6} s: {e}",
                    k + 1
                ))
            })?;
            forces.next[k] = f.force_mean;
            scale = scale.max(d.device.force_scale()).max(f.force_mean.abs());
            change = change.max((f.force_mean - forces.mean[k]).abs());
        }
        forces.mean.copy_from_slice(&forces.next);
        if change <= COUPLING_TOL * scale {
            if trial.iter().any(|v| !v.is_finite()) {
                return Err(StabilityError::Numerical(format!(
                    "time response is not finite at t = {:.6} s",
                    t + h
                )));
            }
            // the last trial (its stroke from the accepted state) is the step taken
            for d in dampers.iter_mut() {
                d.device.commit();
            }
            return Ok(it);
        }
    }
    Err(StabilityError::Numerical(format!(
        "damper coupling did not converge at t = {t:.6} s: {MAX_COUPLING_ITERATIONS} iterations, last force change {change:.3e} N (a shorter step: more steps per revolution)"
    )))
}

/// Free response of `rotor` (its blades' stiffness and damping without the dampers, i.e. the
/// lag bearing's) with `dampers[k]` on blade `k`, from `initial` (ordered as
/// [`LagRotor::state_layout`], blade 1 at zero azimuth) at `t = 0` to `t_end_s`, RK4 steps of
/// at most `dt_s`. Each device starts from its own committed state. `stop_lag_rad`: the
/// response ends early once any blade's lag angle exceeds it.
pub fn free_response_with_dampers(
    rotor: &LagRotor,
    omega_rad_s: f64,
    dampers: &mut [BladeDamper],
    initial: &[f64],
    t_end_s: f64,
    dt_s: f64,
    stop_lag_rad: f64,
) -> Result<DeviceResponse> {
    rotor.validate()?;
    check_omega(omega_rad_s)?;
    let nb = rotor.blades.len();
    if dampers.len() != nb {
        return Err(StabilityError::Numerical(format!(
            "{} dampers for {nb} blades",
            dampers.len()
        )));
    }
    for (k, d) in dampers.iter().enumerate() {
        range(format!("dampers[{k}].arm_m"), d.arm_m, d.arm_m > 0.0, "> 0")?;
    }
    let m = rotor.state_len();
    let (steps, h) = rotor.response_steps(initial, t_end_s, dt_s)?;
    let mut sys = PeriodicSystem::new(rotor, omega_rad_s);
    let mut rk = Rk4::new(m);
    let mut y = initial.to_vec();
    let mut trial = vec![0.0; m];
    let mut forces = StepForces::new(dampers);
    let mut time_s = Vec::with_capacity(steps + 1);
    let mut states = Vec::with_capacity((steps + 1) * m);
    let mut force_n = Vec::with_capacity(steps * nb);
    time_s.push(0.0);
    states.extend_from_slice(&y);
    let mut max_iterations = 0;
    for step in 0..steps {
        let t = step as f64 * h;
        let it = coupled_step(
            dampers,
            &mut forces,
            step == 0,
            t,
            h,
            &y,
            &mut trial,
            |moment, trial| {
                sys.set_moments(t, h, moment, moment);
                trial.copy_from_slice(&y);
                rk.step(&mut sys, t, h, trial)
            },
        )?;
        max_iterations = max_iterations.max(it);
        y.copy_from_slice(&trial);
        force_n.extend_from_slice(&forces.mean);
        time_s.push(t + h);
        states.extend_from_slice(&y);
        if y[..nb].iter().any(|z| z.abs() > stop_lag_rad) {
            break;
        }
    }
    Ok(DeviceResponse {
        response: TimeResponse {
            time_s,
            states,
            state_len: m,
        },
        force_n,
        max_iterations,
    })
}
