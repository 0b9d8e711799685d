//! Hydraulic elements on pressure states (chamber, orifice, relief valve, check valve), composed
//! into devices (actuator, dampers, dashpots), with sub-stepping integrators. Paper Eqs. (1)-(8),
//! coupling quantities of Eqs. (13) and (16).
//!
//! Every device implements [`Device`]: the structure hands it the strokes at the ends of a
//! structural step, the device integrates its internal (hydraulic) state over the step with
//! `N` sub-steps and returns the step-averaged force `F_m` of Eq. (13) and its derivative.
/// The [`Device`] methods other than the trial step and the commit of a device in series with
/// an inner one through a hidden stroke `d_h` (fields `inner`, `d_h`, `fresh`, `trial`):
/// channels and force are the inner device's, the state is `[d_h, fresh, inner state...]`.
macro_rules! series_link_state_methods {
    ($what:literal) => {
        fn channel_names(&self) -> &'static [&'static str] {
            self.inner.channel_names()
        }

        fn channels(&self, out: &mut [f64]) {
            self.inner.channels(out)
        }

        fn committed_force(&self) -> f64 {
            self.inner.committed_force()
        }

        fn clone_device(&self) -> Box<dyn Device> {
            Box::new(self.clone())
        }

        fn reset(&mut self) {
            self.inner.reset();
            self.d_h = 0.0;
            self.fresh = true;
            self.trial = None;
        }

        fn state_values(&self) -> Vec<f64> {
            let mut v = vec![self.d_h, f64::from(u8::from(self.fresh))];
            v.extend(self.inner.state_values());
            v
        }

        fn set_state_values(&mut self, v: &[f64]) -> Result<(), HydraulicError> {
            if v.len() < 2 {
                return super::check_state_len($what, v, 2);
            }
            self.inner.set_state_values(&v[2..])?;
            self.d_h = v[0];
            self.fresh = v[1] != 0.0;
            self.trial = None;
            Ok(())
        }
    };
}

pub mod bench;
pub mod circuit;
pub mod dashpot;
pub mod deck;
pub mod elements;
pub mod extensions;
pub mod fluid;
pub mod integrators;
pub mod link;
pub mod path;
pub mod temperature;

pub use circuit::{
    ActuatorParams, CircuitDevice, CircuitParams, EntranceOrifices, PiecewiseLinear, Tangent,
};
pub use dashpot::{LinearDashpot, NonlinearDashpot};
pub use deck::{actuator_from_toml_str, DamperDeck, DamperModel, DeckError, DeviceExtensions};
pub use elements::{Chamber, CheckValve, FlowLaw, Orifice, ReliefValve};
pub use extensions::{
    AnnularLeakage, CompliantFreePlay, EntrainedAir, ExtendedDamper, FreePlay, HydraulicExtensions,
    Leakage, SealFriction, SeriesMount,
};
pub use fluid::Fluid;
pub use integrators::{IntegratorOptions, Scheme};
pub use link::{LinkMass, LinkedCircuit};
pub use path::{sample_rates, StrokePath};
pub use temperature::OilTemperature;

/// Result of one trial step of a device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepForce {
    /// Time average of the device force over the step [N]: the `F_m` of Eq. (13).
    pub force_mean: f64,
    /// Signed derivative `dF_m/dd_f` [N/m] with respect to the end-of-step stroke. For the
    /// physical devices it is the Eq. (16) static-stiffness estimate, `-(1/2)(B A0^2/V0 + B A1^2/V1)`:
    /// negative (a longer damper pushes less) and halved because `d_m = (d_i + d_f)/2`.
    pub dforce_dstroke: f64,
    /// Device force at the end of the step [N] (Eq. 8).
    pub force_end: f64,
}

/// Errors of the hydraulic models, with the time at which they occurred.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HydraulicError {
    #[error("non-finite hydraulic state at t = {t} s (component {component}); {}", stability_advice(*.substep_s, *.rate_per_s))]
    NonFinite {
        t: f64,
        component: usize,
        /// The sub-step that failed [s] (NaN when unknown).
        substep_s: f64,
        /// The fastest rate of the state where it was last finite, max |df_i/dy_i| [1/s]
        /// (NaN when unknown).
        rate_per_s: f64,
    },
    #[error("chamber {chamber} volume {volume_m3:.4e} m^3 is not positive at stroke {stroke_m:.4e} m (t = {t} s): the chamber (area A{chamber}_m2 = {area_m2} m^2, volume V{chamber}_m3 = {volume0_m3} m^3 at zero stroke) has a travel of V/A = {:.4e} m, and the stroke is beyond it; check the deck's areas and volumes", .volume0_m3 / .area_m2)]
    ChamberVolume {
        chamber: usize,
        volume_m3: f64,
        stroke_m: f64,
        t: f64,
        area_m2: f64,
        volume0_m3: f64,
    },
    #[error("implicit sub-step did not converge at t = {t} s: stage {stage}, iteration {iteration}, scaled residual {residual:.3e}")]
    NewtonDiverged {
        t: f64,
        stage: usize,
        iteration: usize,
        residual: f64,
    },
    #[error("singular Newton matrix at t = {t} s, stage {stage}")]
    SingularJacobian { t: f64, stage: usize },
    #[error("invalid step at t = {t} s: {reason}")]
    BadStep { t: f64, reason: String },
    #[error("invalid device state: {reason}")]
    BadState { reason: String },
}

/// RK4 is stable for h |lambda| below about 2.8 (the real-axis limit of its stability region).
pub const RK4_STABILITY_LIMIT: f64 = 2.785;

/// What a non-finite state says about the sub-step: h times the fastest rate against RK4's
/// limit, and what to change.
fn stability_advice(h: f64, rate: f64) -> String {
    if h.is_finite() && rate.is_finite() && rate > 0.0 {
        let x = h * rate;
        if x > RK4_STABILITY_LIMIT {
            let need = h * RK4_STABILITY_LIMIT / x;
            return format!(
                "the fastest rate of the hydraulic state at the step's start is {rate:.3e} 1/s \
                 (a chamber's bulk modulus times its flow conductance over its volume), so the \
                 sub-step of {h:.3e} s gives h x rate = {x:.3e}, beyond RK4's stability limit of \
                 2.8: sub-steps below {need:.3e} s (more sub-steps) or the implicit scheme; a \
                 sub-step far below a microsecond means a deck value beyond sense (check the \
                 bulk modulus 1/bulk_alpha_per_Pa, the areas and the volumes)"
            );
        }
        return format!(
            "the sub-step of {h:.3e} s is within RK4's stability limit for the rate {rate:.3e} 1/s \
             where the state was last finite: the state diverged within the sub-step (check the \
             deck's values and the stroke history)"
        );
    }
    "with RK4 this is usually the explicit stability limit: more sub-steps or the implicit scheme"
        .into()
}

/// What a device's step gives: the force over the step, or why it could not step.
pub type StepResult = Result<StepForce, HydraulicError>;

/// A hydraulic (or dashpot) device connecting two structural points, as seen by the structure.
///
/// Protocol: `trial_step` advances from the committed state and keeps the result as a trial
/// state; calling it again restarts from the committed state (structural Newton iterations);
/// `commit` accepts the last trial state.
pub trait Device: Send + Sync + std::fmt::Debug {
    /// Advance from the committed state at `t_i` along `path` (the stroke over the step). The
    /// result is kept as the trial state.
    fn trial_step_path(&mut self, t_i: f64, path: &StrokePath) -> StepResult {
        path.check(t_i)?;
        self.step_along(t_i, path)
    }
    /// [`Device::trial_step_path`] on a path already checked against `t_i`: what each device
    /// implements.
    fn step_along(&mut self, t_i: f64, path: &StrokePath) -> StepResult;
    /// Advance from the committed state at `t_i` over `dt`, the stroke moving linearly from
    /// `d_i` to `d_f` (constant rate): what a structural step knows.
    fn trial_step(
        &mut self,
        t_i: f64,
        dt: f64,
        d_i: f64,
        d_f: f64,
    ) -> Result<StepForce, HydraulicError> {
        self.trial_step_path(t_i, &StrokePath::linear(dt, d_i, d_f))
    }
    /// Accept the last trial state (no-op when there is none).
    fn commit(&mut self);
    /// Names (with units) of the internal channels, e.g. `p0_Pa`.
    fn channel_names(&self) -> &'static [&'static str];
    /// Values of the channels at the committed state; `out.len() == channel_names().len()`.
    fn channels(&self, out: &mut [f64]);
    /// Device force at the committed state [N] (Eq. 8 for the hydraulic devices).
    fn committed_force(&self) -> f64;
    /// Size of the forces the device force is the sum of, at the committed state [N]: the
    /// round-off of the device force is relative to it (Newton's convergence floor). A circuit:
    /// `|p0| A0 + |p1| A1`, since Eq. (8) subtracts the two chamber forces; default: the
    /// committed force itself.
    fn force_scale(&self) -> f64 {
        self.committed_force().abs()
    }
    /// Deep copy (parameters are shared copy-on-write, so this is cheap).
    fn clone_device(&self) -> Box<dyn Device>;
    /// Back to the initial state (start of a new test).
    fn reset(&mut self);
    /// The committed state as numbers (saved periodic states, warm starts); any trial state
    /// is not part of it.
    fn state_values(&self) -> Vec<f64>;
    /// Restores a state of [`Device::state_values`] (same device kind and layout) and drops
    /// any trial state.
    fn set_state_values(&mut self, v: &[f64]) -> Result<(), HydraulicError>;
    /// Whether the steps record what moves within them (the relief valves' sub-step envelope
    /// channels: one more evaluation per sub-step). On by default; a replay that reads only
    /// the force turns it off, and the envelope channels are then NaN. Default: nothing to
    /// record.
    fn set_substep_envelope(&mut self, _on: bool) {}
}

/// `v` has `n` values, else a [`HydraulicError::BadState`] naming `what`.
pub(crate) fn check_state_len(what: &str, v: &[f64], n: usize) -> Result<(), HydraulicError> {
    if v.len() != n || v.iter().any(|x| !x.is_finite()) {
        return Err(HydraulicError::BadState {
            reason: format!(
                "{what} state needs {n} finite values, got {} ({:?})",
                v.len(),
                &v[..v.len().min(8)]
            ),
        });
    }
    Ok(())
}

impl Clone for Box<dyn Device> {
    fn clone(&self) -> Self {
        self.clone_device()
    }
}

pub(crate) fn check_step(t_i: f64, dt: f64, d_i: f64, d_f: f64) -> Result<(), HydraulicError> {
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(HydraulicError::BadStep {
            t: t_i,
            reason: format!("time step {dt} s must be positive and finite"),
        });
    }
    if !(d_i.is_finite() && d_f.is_finite() && t_i.is_finite()) {
        return Err(HydraulicError::BadStep {
            t: t_i,
            reason: format!("non-finite stroke ({d_i}, {d_f}) m or time"),
        });
    }
    Ok(())
}
