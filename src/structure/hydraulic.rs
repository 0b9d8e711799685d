//! Hydraulic device between two structural nodes (paper Eqs. 9-16): the coupling element.
//!
//! The device is attached by spherical joints, so only the translations of the two nodes enter.
//! With `u = x_b - x_a` and `l = |u|`, the stroke is `d = l - L_ref` (docs/formats.md: positive in
//! extension). Over a structural step from `t_i` to `t_f = t_i + dt` the device integrates its
//! hydraulic states with the constant stroke rate `(d_f - d_i)/dt` and returns a step force `F_s`
//! (the paper's step mean `F_m`, or the end-of-step force, see [`AppliedForce`]); the nodal
//! forces are those of Eq. (13),
//!
//! `F_a = -F_s e_m`, `F_b = +F_s e_m`, `e_m = u_m / l_m`, `u_m = (u_i + u_f)/2`, `l_m = (l_i + l_f)/2`,
//!
//! so that their work over the step is `F_s e_m^T (u_f - u_i) = F_s (l_f - l_i) = F_s (d_f - d_i)`
//! exactly (Eqs. 11-12). `l_m` is a mean *length* (`d` of Eq. 11 is the length `|u|`), so `e_m`
//! has no singularity when `d_f = d_i` (e.g. a rigid rotation of the device); only a device of
//! zero length is degenerate and is reported as an error.
//!
//! Tangent, Eq. (15): with `e_f = u_f / l_f` and the signed `dF_s/dd_f`,
//! `d(F_s e_m)/du_f = F_s/(2 l_m) (U - e_m e_f^T) + dF_s/dd_f e_m e_f^T`
//! (for `F_m`: `dF_m/dd_f = (1/2) dF_m/dd_m` of the paper since `d_m = (d_i + d_f)/2`).
//!
//! Static analyses (`dt = 0`): no time passes, so no oil flows and the states are not advanced;
//! the element applies the committed device force along `e_m` (then `e_f`), and its tangent is
//! the geometric term above with `dF/dd = 0`, consistent with that force.
use super::model::{ElementError, ElementOutput, StepElement};
use super::rotation::norm3;
use crate::hydraulics::{Device, StepForce};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// Sensor names common to every hydraulic element, before the device channels.
pub const ELEMENT_CHANNELS: [&str; 3] = ["force_N", "stroke_m", "stroke_rate_m_s"];

/// Read-only view of a [`HydraulicForceElement`] that stays valid after the element has been
/// moved into a model (shared through an `Arc`). Values are those of the last converged
/// (committed) step: `[force_N, stroke_m, stroke_rate_m_s, device channels...]`, in the order of
/// [`HydraulicProbe::channel_names`] (the same as the element's `sensors()`).
#[derive(Debug)]
pub struct HydraulicProbe {
    names: Vec<String>,
    values: Mutex<Vec<f64>>,
    hydraulics_nanos: AtomicU64,
    trials: AtomicU64,
}

impl HydraulicProbe {
    fn new(device: &dyn Device) -> Self {
        let names: Vec<String> = ELEMENT_CHANNELS
            .iter()
            .chain(device.channel_names().iter())
            .map(|s| s.to_string())
            .collect();
        let mut values = vec![0.0; names.len()];
        values[0] = device.committed_force();
        device.channels(&mut values[3..]);
        Self {
            names,
            values: Mutex::new(values),
            hydraulics_nanos: AtomicU64::new(0),
            trials: AtomicU64::new(0),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<f64>> {
        // A panic while holding the lock cannot leave the plain numbers inconsistent.
        self.values.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Channel names with units: `force_N`, `stroke_m`, `stroke_rate_m_s`, then the device's.
    pub fn channel_names(&self) -> &[String] {
        &self.names
    }

    /// Committed values, in the order of [`Self::channel_names`] (allocates; see `read_into`).
    pub fn values(&self) -> Vec<f64> {
        self.lock().clone()
    }

    /// Copies the committed values into `out` (`out.len()` values at most; no allocation).
    pub fn read_into(&self, out: &mut [f64]) {
        let v = self.lock();
        let n = out.len().min(v.len());
        out[..n].copy_from_slice(&v[..n]);
    }

    /// Device force (Eq. 8) at the end of the last converged step [N].
    pub fn force_n(&self) -> f64 {
        self.lock()[0]
    }

    /// Stroke at the end of the last converged step [m] (positive in extension).
    pub fn stroke_m(&self) -> f64 {
        self.lock()[1]
    }

    /// Constant stroke rate of the last converged step [m/s].
    pub fn stroke_rate_m_s(&self) -> f64 {
        self.lock()[2]
    }

    /// Wall time spent inside `Device::trial_step` (all Newton iterates) [s].
    pub fn hydraulics_seconds(&self) -> f64 {
        self.hydraulics_nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// Number of device trial steps (one per Newton iterate of a dynamic step).
    pub fn trials(&self) -> u64 {
        self.trials.load(Ordering::Relaxed)
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Trial {
    force_applied: f64,
    stroke_m: f64,
    rate_m_s: f64,
}

/// Relative stroke increment (of `L_ref`) of the forward difference of `F_end`.
const FD_REL: f64 = 1e-10;

/// Which step force the element applies along `e_m` of Eq. (13).
///
/// The structural solver (generalized-alpha, equations of motion enforced at `t_f`) is
/// unstable when a stiff device contributes its step *mean* force `F_m ~ -k (d_i + d_f)/2`:
/// the amplification matrix of a mass on such a spring has spectral radius 1.16-1.38 for
/// `omega h` = 1-5 at `rho_inf` = 0.8 (docs/coupling.md). The paper's `F_m` belongs to its
/// mid-point-type energy-decaying schemes. With `End`, the force at `t_f` (consistent with the
/// solver) is applied along the same `e_m`; the step's work is then exactly `F_end (d_f - d_i)`,
/// which is at most the device's exact work `F_m (d_f - d_i)` for a spring (dissipative).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AppliedForce {
    /// Device force at the end of the step (Eq. 8 at `t_f`); tangent `dF_end/dd_f` by a
    /// forward difference of the device step (one extra trial step).
    #[default]
    End,
    /// The paper's `F_m` of Eq. (13), time average over the step; tangent from the device's
    /// `dforce_dstroke` (Eq. 16 estimate for the physical devices).
    Mean,
}

/// Hydraulic (or dashpot) device between nodes `a` and `b`, paper Eqs. (9)-(16).
#[derive(Debug)]
pub struct HydraulicForceElement {
    name: String,
    nodes: [usize; 2],
    device: Box<dyn Device>,
    /// `L_ref` [m]; `None` until the first evaluation takes the initial distance.
    reference_length_m: Option<f64>,
    probe: Arc<HydraulicProbe>,
    applied: AppliedForce,
    trial: Option<Trial>,
    committed: Trial,
    /// Last step force of a dynamic trial (for diagnostics and tests).
    last_step: Option<StepForce>,
    /// Step force applied at the last evaluation [N].
    last_applied: f64,
    channel_buf: Vec<f64>,
    /// Whether evaluations need `dF/dd_f` (the finite-difference trial of `F_end`).
    want_jacobian: bool,
}

impl HydraulicForceElement {
    /// Device `device` between nodes `node_a` and `node_b` (indices into `Model::nodes`);
    /// the reference length defaults to their distance at the first evaluation.
    pub fn new(
        name: impl Into<String>,
        node_a: usize,
        node_b: usize,
        device: Box<dyn Device>,
    ) -> Self {
        let probe = Arc::new(HydraulicProbe::new(device.as_ref()));
        let nch = device.channel_names().len();
        Self {
            name: name.into(),
            nodes: [node_a, node_b],
            device,
            reference_length_m: None,
            want_jacobian: true,
            probe,
            applied: AppliedForce::default(),
            trial: None,
            committed: Trial::default(),
            last_step: None,
            last_applied: 0.0,
            channel_buf: vec![0.0; nch],
        }
    }

    /// Length `L_ref` [m] at which the stroke is zero (the deck's reference length of the device).
    pub fn with_reference_length(mut self, l_m: f64) -> Self {
        self.reference_length_m = Some(l_m);
        self
    }

    /// Shared view of the committed outputs and timing.
    pub fn probe(&self) -> Arc<HydraulicProbe> {
        Arc::clone(&self.probe)
    }

    /// `L_ref` [m], if already known.
    pub fn reference_length_m(&self) -> Option<f64> {
        self.reference_length_m
    }

    /// The device (committed state readable through it).
    pub fn device(&self) -> &dyn Device {
        self.device.as_ref()
    }

    /// Step force `F_s` applied along `e_m` at the last evaluation [N].
    pub fn last_applied_force(&self) -> f64 {
        self.last_applied
    }

    /// Device result of the last dynamic trial (`None` before the first dynamic evaluation).
    pub fn last_step_force(&self) -> Option<StepForce> {
        self.last_step
    }

    /// Selects the step force applied along `e_m` (default [`AppliedForce::End`]).
    pub fn with_applied_force(mut self, applied: AppliedForce) -> Self {
        self.applied = applied;
        self
    }

    /// Which step force is applied.
    pub fn applied_force(&self) -> AppliedForce {
        self.applied
    }

    /// Step force and its derivative with respect to `d_f` (device trial steps; the last one
    /// run is the nominal step, so that `commit` accepts it).
    fn dynamic_force(
        &mut self,
        t_i: f64,
        dt: f64,
        d_i: f64,
        d_f: f64,
        l_ref: f64,
    ) -> Result<(f64, f64), crate::hydraulics::HydraulicError> {
        match self.applied {
            AppliedForce::Mean => {
                self.probe.trials.fetch_add(1, Ordering::Relaxed);
                let sf = self.device.trial_step(t_i, dt, d_i, d_f)?;
                self.last_step = Some(sf);
                Ok((sf.force_mean, sf.dforce_dstroke))
            }
            AppliedForce::End if !self.want_jacobian => {
                // residual only (modified Newton): the nominal step alone
                self.probe.trials.fetch_add(1, Ordering::Relaxed);
                let sf = self.device.trial_step(t_i, dt, d_i, d_f)?;
                self.last_step = Some(sf);
                Ok((sf.force_end, 0.0))
            }
            AppliedForce::End => {
                // d F_end / d d_f by a forward difference of the whole step (flows included);
                // the perturbed step runs first so that the nominal one stays the trial state.
                // (backward when d_f + h is beyond the device's travel).
                let mut h = FD_REL * l_ref.abs().max(1e-3);
                self.probe.trials.fetch_add(2, Ordering::Relaxed);
                let sp = match self.device.trial_step(t_i, dt, d_i, d_f + h) {
                    Ok(s) => s,
                    Err(_) => {
                        h = -h;
                        self.probe.trials.fetch_add(1, Ordering::Relaxed);
                        self.device.trial_step(t_i, dt, d_i, d_f + h)?
                    }
                };
                let sf = self.device.trial_step(t_i, dt, d_i, d_f)?;
                self.last_step = Some(sf);
                Ok((sf.force_end, (sp.force_end - sf.force_end) / h))
            }
        }
    }

    fn err(&self, msg: String) -> ElementError {
        ElementError {
            element: self.name.clone(),
            msg,
        }
    }
}

#[inline]
fn sub3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

impl StepElement for HydraulicForceElement {
    fn name(&self) -> &str {
        &self.name
    }

    fn nodes(&self) -> [usize; 2] {
        self.nodes
    }

    fn evaluate(
        &mut self,
        t_i: f64,
        dt: f64,
        x_i: [[f64; 3]; 2],
        x_f: [[f64; 3]; 2],
        out: &mut ElementOutput,
    ) -> Result<(), ElementError> {
        let u_i = sub3(x_i[1], x_i[0]);
        let u_f = sub3(x_f[1], x_f[0]);
        let (l_i, l_f) = (norm3(u_i), norm3(u_f));
        let l_ref = *self.reference_length_m.get_or_insert(l_i);
        // Eq. (13) needs a direction: a device of (numerically) zero length has none.
        let tiny = 1e-12 * l_ref.abs().max(1e-3);
        if !(l_i > tiny && l_f > tiny && l_i.is_finite() && l_f.is_finite()) {
            return Err(self.err(format!(
                "attachment points coincide or are not finite at t = {t_i} s (lengths {l_i} m at t_i, {l_f} m at t_f)"
            )));
        }
        let (d_i, d_f) = (l_i - l_ref, l_f - l_ref);
        let (force, dfdd, rate) = if dt > 0.0 {
            let started = Instant::now();
            let r = self.dynamic_force(t_i, dt, d_i, d_f, l_ref);
            let ns = started.elapsed().as_nanos() as u64;
            self.probe.hydraulics_nanos.fetch_add(ns, Ordering::Relaxed);
            let (f, k) = r.map_err(|e| {
                self.err(format!(
                    "hydraulic step from t = {t_i} s (dt = {dt} s, stroke {d_i:.6e} -> {d_f:.6e} m) failed: {e}"
                ))
            })?;
            (f, k, (d_f - d_i) / dt)
        } else {
            (self.device.committed_force(), 0.0, 0.0)
        };
        if !force.is_finite() || !dfdd.is_finite() {
            return Err(self.err(format!(
                "non-finite device force {force} N (dF/dd {dfdd} N/m) at t = {t_i} s"
            )));
        }
        self.last_applied = force;
        self.trial = Some(Trial {
            force_applied: force,
            stroke_m: d_f,
            rate_m_s: rate,
        });
        // Eq. (12)-(13): e_m = u_m / l_m with the mean length.
        let l_m = 0.5 * (l_i + l_f);
        let e_m: [f64; 3] = std::array::from_fn(|k| 0.5 * (u_i[k] + u_f[k]) / l_m);
        let e_f: [f64; 3] = std::array::from_fn(|k| u_f[k] / l_f);
        for k in 0..3 {
            out.force[0][k] = -force * e_m[k];
            out.force[1][k] = force * e_m[k];
        }
        // Eq. (15): K = F/(2 l_m) (U - e_m e_f^T) + dF/dd_f e_m e_f^T = d F_b / d x_f,b.
        let g = force / (2.0 * l_m);
        for i in 0..3 {
            for j in 0..3 {
                let id = if i == j { 1.0 } else { 0.0 };
                let kij = g * (id - e_m[i] * e_f[j]) + dfdd * e_m[i] * e_f[j];
                out.jac[1][1][i][j] = kij;
                out.jac[1][0][i][j] = -kij;
                out.jac[0][1][i][j] = -kij;
                out.jac[0][0][i][j] = kij;
            }
        }
        Ok(())
    }

    fn want_jacobian(&mut self, yes: bool) {
        self.want_jacobian = yes;
    }

    fn force_scale(&self) -> f64 {
        self.device.force_scale()
    }

    fn commit(&mut self) {
        self.device.commit();
        if let Some(t) = self.trial.take() {
            self.committed = t;
        }
        self.device.channels(&mut self.channel_buf);
        let mut v = self.probe.lock();
        v[0] = self.device.committed_force();
        v[1] = self.committed.stroke_m;
        v[2] = self.committed.rate_m_s;
        v[3..].copy_from_slice(&self.channel_buf);
    }

    fn sensors(&self) -> Vec<(String, f64)> {
        let v = self.probe.values();
        self.probe.channel_names().iter().cloned().zip(v).collect()
    }

    /// `[L_ref (-1: not yet taken), force_applied, stroke, rate, last applied, device...]`.
    fn state_values(&self) -> Vec<f64> {
        let mut v = vec![
            self.reference_length_m.unwrap_or(-1.0),
            self.committed.force_applied,
            self.committed.stroke_m,
            self.committed.rate_m_s,
            self.last_applied,
        ];
        v.extend(self.device.state_values());
        v
    }

    fn set_state_values(&mut self, v: &[f64]) -> Result<(), String> {
        if v.len() < 5 || v[..5].iter().any(|x| !x.is_finite()) {
            return Err(format!(
                "hydraulic element {}: state needs 5 finite values and the device's, got {}",
                self.name,
                v.len()
            ));
        }
        self.device
            .set_state_values(&v[5..])
            .map_err(|e| format!("hydraulic element {}: {e}", self.name))?;
        self.reference_length_m = (v[0] > 0.0).then_some(v[0]);
        self.committed = Trial {
            force_applied: v[1],
            stroke_m: v[2],
            rate_m_s: v[3],
        };
        self.last_applied = v[4];
        self.trial = None;
        self.last_step = None;
        // the probe shows the committed state, as after a commit
        self.commit();
        Ok(())
    }
}

impl HydraulicForceElement {
    /// Step force applied over the last converged step [N] (`F_m` of Eq. 13 or `F_end`).
    pub fn committed_step_force(&self) -> f64 {
        self.committed.force_applied
    }
}
