//! Driving a [`ForcedResponse`] to its periodic solution: by shooting (Newton-Picard on the
//! revolution map, [`crate::periodic`]) or by marching, both stopped by the same periodicity
//! residual (docs/periodic.md).
//!
//! Residual of a revolution started from state `x`: per monitored channel,
//! `|c(Phi(x)) - c(x)| / max(peak-to-peak of c over the revolution, floor)`, the largest over
//! channels: the channels seen at the end of the revolution against the start. The rotor's
//! thrust (computed airloads) is also judged for an every-step alternating component.
pub(super) use crate::analysis::periodicity::max_nan_poisoned as max_nan;
use crate::analysis::periodicity::{boundary_change, relative_change};
use crate::periodic::{Multiplier, PeriodMap, ShootingOptions};
use crate::rotor::{ForcedResponse, SimState};

/// How the periodic solution is found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PeriodicMethod {
    /// Newton-Picard shooting on the revolution map (falls back to marching).
    Shooting,
    /// Revolution after revolution.
    March,
}

impl PeriodicMethod {
    pub fn name(&self) -> &'static str {
        match self {
            PeriodicMethod::Shooting => "shooting",
            PeriodicMethod::March => "march",
        }
    }
}

/// Options of [`super::drive_periodic`].
#[derive(Clone, Debug)]
pub struct PeriodicOptions {
    pub method: PeriodicMethod,
    /// Periodicity residual at which a run stops.
    pub tol: f64,
    /// Most revolutions integrated (shooting: perturbed and trial revolutions included).
    pub max_revs: usize,
    /// Stop as soon as the residual is below `tol` (false: march all `max_revs`).
    pub stop_early: bool,
    /// Start from this saved state instead of the simulation's own initial state.
    pub initial_state: Option<PeriodicStateFile>,
    /// Directions of the shooting subspace at least (more Floquet multipliers).
    pub min_floquet_dirs: usize,
    /// Shooting: after convergence, more directions (one revolution each) to resolve the
    /// reported multipliers, as [`FloquetPlan::of`] sets them (on by default).
    pub floquet_resolve: bool,
    /// Keep every revolution along the way (marched ones and accepted shooting iterates).
    pub keep_all_revs: bool,
    /// Fingerprint of this run's inputs ([`crate::io::inputs_fingerprint`]): saved with the
    /// periodic state, and compared with a saved state's when starting from one.
    pub inputs_sha256: Option<String>,
    /// Checked before every structural step: a raised flag stops the run with
    /// [`super::stop::Stopped`].
    pub stop: super::stop::StopFlag,
}

impl PeriodicOptions {
    /// March exactly `revs` revolutions (the residual is still measured).
    pub fn march(revs: usize) -> Self {
        PeriodicOptions {
            method: PeriodicMethod::March,
            tol: DEFAULT_TOL,
            max_revs: revs,
            stop_early: false,
            initial_state: None,
            min_floquet_dirs: 0,
            floquet_resolve: true,
            keep_all_revs: false,
            inputs_sha256: None,
            stop: Default::default(),
        }
    }
    /// Shooting to `tol`, at most `max_revs` revolutions.
    pub fn shooting(tol: f64, max_revs: usize) -> Self {
        PeriodicOptions {
            method: PeriodicMethod::Shooting,
            tol,
            max_revs,
            stop_early: true,
            initial_state: None,
            min_floquet_dirs: 0,
            floquet_resolve: true,
            keep_all_revs: false,
            inputs_sha256: None,
            stop: Default::default(),
        }
    }
}

/// Default periodicity tolerance (`--periodic-tol`).
pub const DEFAULT_TOL: f64 = 1e-4;

/// Multipliers reported (least damped first, the lag mode at the top).
pub const FLOQUET_REPORTED: usize = 8;
/// After shooting converged, at most this many more directions (one revolution each) to
/// resolve the reported multipliers (residual at most 1% of |mu|) of magnitude at least
/// [`FLOQUET_RESOLVE_FLOOR`].
pub const FLOQUET_RESOLVE_DIRS: usize = 12;
pub const FLOQUET_RESOLVE_FLOOR: f64 = 0.1;
/// With the lifting line acting (computed and hybrid airloads) the first flap mode is
/// damped aerodynamically to |mu| ~ 0.1 per revolution, below modes the structure damps
/// less: the run reports more multipliers, resolves them down to a lower magnitude and
/// allows more directions for it.
pub const FLOQUET_REPORTED_AERO: usize = 10;
pub const FLOQUET_RESOLVE_DIRS_AERO: usize = 20;
pub const FLOQUET_RESOLVE_FLOOR_AERO: f64 = 0.05;

/// The Floquet multipliers a run reports and resolves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FloquetPlan {
    /// Multipliers reported, least damped first (the lag mode at the top).
    pub reported: usize,
    /// Of those, the ones of |mu| at least this are resolved (residual at most 1% of |mu|)...
    pub floor: f64,
    /// ...with at most this many directions after convergence (one revolution each).
    pub dirs: usize,
}

impl FloquetPlan {
    /// The plan of a run: with the lifting line acting (`aerodynamic`) the
    /// [`FLOQUET_REPORTED_AERO`] least damped multipliers, resolved down to
    /// [`FLOQUET_RESOLVE_FLOOR_AERO`] with up to [`FLOQUET_RESOLVE_DIRS_AERO`] directions;
    /// otherwise [`FLOQUET_REPORTED`], [`FLOQUET_RESOLVE_FLOOR`], [`FLOQUET_RESOLVE_DIRS`]. No
    /// directions when `o` does not resolve.
    ///
    /// The lifting line's plan is widened for a model with relaxation states of times `tau_s`
    /// [s] (the bearing elastomers' Maxwell branches) over a period `period_s`: each whose free
    /// multiplier `exp(-T / tau)` is at least half the floor (coupled to the blade it sits
    /// higher: 0.59 against 0.53 on the shipped bearing) takes one more reported place and two
    /// more directions, so that the aerodynamically damped first flap mode (|mu| ~ 0.1, below
    /// the relaxations) keeps its place (the README's hybrid-periodic run, physical damper, uses
    /// 29 of its 32 directions). The measured-airload plan is left as it is: its reported modes
    /// sit above the relaxations (the slowest, 0.59, would be ninth on the shipped deck).
    pub fn of(o: &PeriodicOptions, aerodynamic: bool, period_s: f64, tau_s: &[f64]) -> Self {
        let mut p = if aerodynamic {
            let n = tau_s
                .iter()
                .filter(|t| (-period_s / **t).exp() >= 0.5 * FLOQUET_RESOLVE_FLOOR_AERO)
                .count();
            FloquetPlan {
                reported: FLOQUET_REPORTED_AERO + n,
                floor: FLOQUET_RESOLVE_FLOOR_AERO,
                dirs: FLOQUET_RESOLVE_DIRS_AERO + 2 * n,
            }
        } else {
            FloquetPlan {
                reported: FLOQUET_REPORTED,
                floor: FLOQUET_RESOLVE_FLOOR,
                dirs: FLOQUET_RESOLVE_DIRS,
            }
        };
        if !o.floquet_resolve {
            p.dirs = 0;
        }
        p
    }
}

/// What the periodic solver did for one model.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PeriodicInfo {
    /// The method asked for, and the one that produced the reported revolution.
    pub method: PeriodicMethod,
    pub method_used: PeriodicMethod,
    pub converged: bool,
    pub tolerance: f64,
    /// Residual of the reported revolution.
    pub residual: f64,
    /// Per monitored channel.
    pub residual_by_channel: Vec<f64>,
    /// The monitored channels' names and floors, in the order of `residual_by_channel`.
    #[serde(skip)]
    pub monitored: Vec<(String, f64)>,
    /// Shooting: residual of each accepted iterate; marching: of each revolution.
    pub residual_history: Vec<f64>,
    /// Every revolution integrated (marched, perturbed and trial).
    pub revolutions_integrated: usize,
    /// Shooting: marched revolutions before it, Newton-Picard iterations, subspace
    /// directions (one revolution each) and rejected trials.
    pub marched_revolutions: usize,
    pub iterations: usize,
    pub directions: usize,
    pub rejected_trials: usize,
    /// Of `directions`, those added after the periodic solution was found to resolve the
    /// reported Floquet multipliers (one revolution each, in `revolutions_integrated`).
    #[serde(default)]
    pub floquet_directions: usize,
    /// Least-damped Floquet multipliers (shooting), lag mode first.
    pub floquet_multipliers: Vec<Multiplier>,
    /// `residual / (1 - |mu_1|)`: distance to the periodic solution implied by the
    /// least-damped multiplier (None without multipliers).
    pub error_estimate: Option<f64>,
    /// What happened, in words (fallbacks, budget).
    pub message: String,
    /// Time at the start of the reported revolution [s].
    #[serde(skip)]
    pub start_t_s: f64,
}

/// How a monitored channel is judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MonitorKind {
    /// The change over the revolution (end against start) on the scale `max(peak-to-peak,
    /// floor)`.
    Boundary,
    /// The same on the scale `max(peak-to-peak, floor, 1% of the mean's magnitude)` (a channel
    /// that is nearly constant about a large mean, the thrust in hover).
    BoundaryOfMean,
    /// The amplitude of the alternating-sign (every-step, Nyquist-rate) component over the
    /// revolution, `|sum (-1)^j c_j| / n`, on the scale of `BoundaryOfMean`, beyond an
    /// allowance of [`STEP_RATE_ALLOWANCE`] (the round-off and iteration-tolerance level of a
    /// sound run, ~1e-6, then counts 0): a discrete instability of the step-to-step coupling,
    /// which a periodic solution does not have (it gives ~0.5).
    StepRate,
}

/// A monitored channel: its index among the simulation's channels, its name (the residual's
/// label) and its floor.
#[derive(Clone, Debug)]
pub struct Monitor {
    pub index: usize,
    pub name: String,
    pub floor: f64,
    pub kind: MonitorKind,
}

/// Alternating content (relative to its scale) that [`MonitorKind::StepRate`] allows: a sound
/// run has ~1e-6, an every-step instability ~0.5.
pub const STEP_RATE_ALLOWANCE: f64 = 1e-3;

/// Fraction of the mean's magnitude in the scale of [`MonitorKind::BoundaryOfMean`] and
/// [`MonitorKind::StepRate`].
const MEAN_FRACTION: f64 = 0.01;

fn mean_scaled_floor(samples: &[f64], floor: f64) -> f64 {
    let n = samples.len().max(1) as f64;
    let mean = samples.iter().sum::<f64>() / n;
    floor.max(MEAN_FRACTION * mean.abs())
}

/// The amplitude of the alternating-sign component of `samples`, `|sum (-1)^j c_j| / n` (0 for
/// an odd count's last sample left out, so that a constant has none), relative to
/// `max(peak-to-peak, floor)`; NaN if a sample is.
pub fn step_rate_content(samples: &[f64], floor: f64) -> f64 {
    let m = samples.len() - samples.len() % 2;
    if m == 0 {
        return 0.0;
    }
    let s: f64 = samples[..m]
        .iter()
        .enumerate()
        .map(|(j, v)| if j % 2 == 0 { *v } else { -*v })
        .sum();
    let (lo, hi) = samples
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(*x), h.max(*x))
        });
    if s.is_nan() || lo.is_nan() || hi.is_nan() {
        return f64::NAN;
    }
    (s / m as f64).abs() / (hi - lo).max(floor)
}

/// Samples of one revolution: channel values at the start of every step, and at its end.
#[derive(Clone)]
pub(super) struct Revolution {
    pub samples: Vec<Vec<f64>>,
    pub azimuth: Vec<f64>,
    pub end: Vec<f64>,
    pub start_t_s: f64,
}

impl Revolution {
    pub fn new(nc: usize, n: usize) -> Self {
        Revolution {
            samples: vec![vec![0.0; n]; nc],
            azimuth: vec![0.0; n],
            end: vec![0.0; nc],
            start_t_s: 0.0,
        }
    }

    /// Per monitored channel: the residual.
    pub fn residual(&self, mon: &[Monitor]) -> Vec<f64> {
        mon.iter()
            .map(|m| {
                let s = &self.samples[m.index];
                match m.kind {
                    MonitorKind::Boundary => boundary_change(s, self.end[m.index], m.floor),
                    MonitorKind::BoundaryOfMean => {
                        boundary_change(s, self.end[m.index], mean_scaled_floor(s, m.floor))
                    }
                    MonitorKind::StepRate => {
                        let c = step_rate_content(s, mean_scaled_floor(s, m.floor));
                        if c.is_nan() {
                            c
                        } else {
                            (c - STEP_RATE_ALLOWANCE).max(0.0)
                        }
                    }
                }
            })
            .collect()
    }

    /// Per monitored channel: the largest change of any sample from `prev`, relative to this
    /// revolution's peak-to-peak.
    pub fn change_from(&self, prev: &Revolution, mon: &[Monitor]) -> Vec<f64> {
        mon.iter()
            .map(|m| {
                let (a, b) = (&prev.samples[m.index], &self.samples[m.index]);
                match m.kind {
                    MonitorKind::Boundary => relative_change(a, b, m.floor),
                    MonitorKind::BoundaryOfMean | MonitorKind::StepRate => {
                        relative_change(a, b, mean_scaled_floor(b, m.floor))
                    }
                }
            })
            .collect()
    }
}

/// One revolution of `sim` into `rev`.
pub(super) fn integrate(
    sim: &mut dyn ForcedResponse,
    rev: &mut Revolution,
    what: &str,
    stop: &super::stop::StopFlag,
) -> anyhow::Result<()> {
    let n = rev.azimuth.len();
    let mut buf = vec![0.0; rev.end.len()];
    rev.start_t_s = sim.time_s();
    let turns = (sim.azimuth_deg() / 360.0).round();
    for j in 0..n {
        sim.channels(&mut buf);
        for (c, v) in buf.iter().enumerate() {
            rev.samples[c][j] = *v;
        }
        let mut psi = (sim.azimuth_deg() - 360.0 * turns).rem_euclid(360.0);
        // keep floating-point drift from wrapping 359.99999 to 0 at the first sample
        if j == 0 && psi > 359.0 {
            psi = 0.0;
        }
        // sample j of a revolution is at k 360/N: written exactly, so that outputs join the
        // record's azimuths (the integrated azimuth carries ~1e-8 deg of rounding)
        let exact = j as f64 * 360.0 / n as f64;
        rev.azimuth[j] = if (psi - exact).abs() < 1e-6 {
            exact
        } else {
            psi
        };
        stop.check(sim.time_s(), what)?;
        sim.step().map_err(|e| {
            e.context(format!(
                "{what}, step {j} of {n} (t = {:.6} s)",
                sim.time_s()
            ))
        })?;
    }
    sim.channels(&mut rev.end);
    Ok(())
}

/// The revolution map of a simulation, for [`crate::periodic::shoot`].
pub(super) struct SimMap<'a> {
    pub sim: &'a mut dyn ForcedResponse,
    pub mon: Vec<Monitor>,
    pub start: SimState,
    pub end: SimState,
    pub rev: Revolution,
    trial: Option<(SimState, SimState, Revolution)>,
    /// Change of the accepted revolution made by the last accepted step.
    step_change: Option<f64>,
    pub periods: usize,
    pub residual_by_channel: Vec<f64>,
    pub progress: &'a dyn Fn(usize, Option<f64>),
    pub label: String,
    /// Accepted iterates, when the run keeps every revolution.
    pub kept: Option<Vec<Revolution>>,
    pub stop: super::stop::StopFlag,
}

impl<'a> SimMap<'a> {
    /// The map with `rev` (integrated from `start` to `end`) as the accepted point.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        sim: &'a mut dyn ForcedResponse,
        mon: Vec<Monitor>,
        start: SimState,
        end: SimState,
        rev: Revolution,
        periods: usize,
        progress: &'a dyn Fn(usize, Option<f64>),
        label: String,
    ) -> Self {
        let residual_by_channel = rev.residual(&mon);
        SimMap {
            sim,
            mon,
            start,
            end,
            rev,
            trial: None,
            step_change: None,
            periods,
            residual_by_channel,
            progress,
            label,
            kept: None,
            stop: Default::default(),
        }
    }

    /// One revolution from `from`; a trial keeps its start, end and samples for `accept`.
    fn run_from(&mut self, from: SimState, into_trial: bool) -> anyhow::Result<SimState> {
        self.sim.restore_state(&from)?;
        self.periods += 1;
        let what = format!("{}, revolution {} (shooting)", self.label, self.periods);
        let mut rev = Revolution::new(self.rev.end.len(), self.rev.azimuth.len());
        // a perturbed revolution is never reported: no output-only channels
        let was = self.sim.output_channels();
        self.sim.set_output_channels(was && into_trial);
        let r = integrate(self.sim, &mut rev, &what, &self.stop);
        self.sim.set_output_channels(was);
        r?;
        let end = self
            .sim
            .save_state()
            .ok_or_else(|| anyhow::anyhow!("{}: cannot save its state", self.label))?;
        let residual = into_trial.then(|| max_nan(&rev.residual(&self.mon)));
        (self.progress)(self.periods, residual);
        if into_trial {
            self.trial = Some((from, end.clone(), rev));
        }
        Ok(end)
    }
}

impl PeriodMap for SimMap<'_> {
    fn accepted(&self) -> (&[f64], &[f64]) {
        (&self.start.coords, &self.end.coords)
    }
    fn perturbed(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>> {
        let mut from = self.start.clone();
        from.coords.copy_from_slice(x);
        Ok(self.run_from(from, false)?.coords)
    }
    fn trial(&mut self, x: &[f64]) -> anyhow::Result<Vec<f64>> {
        let mut from = self.end.clone();
        from.coords.copy_from_slice(x);
        Ok(self.run_from(from, true)?.coords)
    }
    fn accept(&mut self) {
        if let Some((s, e, rev)) = self.trial.take() {
            self.start = s;
            self.end = e;
            self.step_change = Some(max_nan(&rev.change_from(&self.rev, &self.mon)));
            self.rev = rev;
            self.residual_by_channel = self.rev.residual(&self.mon);
            if let Some(k) = &mut self.kept {
                k.push(self.rev.clone());
            }
        }
    }
    fn residual(&self) -> f64 {
        max_nan(&self.residual_by_channel)
    }
    fn periods(&self) -> usize {
        self.periods
    }
    fn step_change(&self) -> Option<f64> {
        self.step_change
    }
}

/// Shooting options of a run (the tolerance and budget from `o`, the multipliers to resolve
/// from `plan`).
pub(super) fn shooting_options(o: &PeriodicOptions, plan: &FloquetPlan) -> ShootingOptions {
    ShootingOptions {
        tol: o.tol,
        max_periods: o.max_revs,
        min_dirs: o.min_floquet_dirs,
        resolve_wanted: plan.reported,
        resolve_floor: plan.floor,
        resolve_dirs: plan.dirs,
        ..Default::default()
    }
}

/// DIR/<model>/periodic_state.json: the state at the start of the reported revolution, for
/// `--initial-state` (docs/periodic.md).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct PeriodicStateFile {
    /// "rotorsim periodic state 1".
    pub format: String,
    /// Damper model and simulation label it was saved from.
    pub model: String,
    pub label: String,
    pub steps_per_rev: usize,
    pub period_s: f64,
    /// Whether the run converged, and its residual.
    pub converged: bool,
    pub residual: f64,
    /// Fingerprint of the inputs that define the model (deck, section table, damper deck,
    /// record and `--set` values; [`crate::io::inputs_fingerprint`]); absent in older files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inputs_sha256: Option<String>,
    /// The `--set` values of the run it was saved from.
    #[serde(default)]
    pub overrides: Vec<(String, String)>,
    pub state: SimState,
}

pub const STATE_FORMAT: &str = "rotorsim periodic state 1";

impl PeriodicStateFile {
    pub fn read(path: &std::path::Path) -> anyhow::Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("reading saved state {}: {e}", path.display()))?;
        let f: Self = serde_json::from_str(&text).map_err(|e| {
            anyhow::anyhow!(
                "{}: not a saved periodic state (line {}, column {}: {e}); expected the periodic_state.json of a run",
                path.display(),
                e.line(),
                e.column()
            )
        })?;
        if f.format != STATE_FORMAT {
            anyhow::bail!(
                "{}: format `{}`, expected `{STATE_FORMAT}`",
                path.display(),
                f.format
            );
        }
        Ok(f)
    }

    /// The state to start `sim` (damper model `model`, inputs fingerprint `inputs_sha256`)
    /// from: the saved one, with the device state replaced by the simulation's own when it was
    /// saved from another damper model, and the time moved to a whole number of periods after
    /// the simulation's ramps. The note says what differs from the run that saved it (another
    /// damper model, steps per revolution, deck, record or `--set` values): such a state is a
    /// starting guess, not the periodic solution of this run.
    pub fn start_state(
        &self,
        sim: &dyn ForcedResponse,
        model: &str,
        inputs_sha256: Option<&str>,
    ) -> anyhow::Result<(SimState, Option<String>)> {
        let own = sim
            .save_state()
            .ok_or_else(|| anyhow::anyhow!("{} cannot start from a saved state", sim.label()))?;
        let mut s = self.state.clone();
        let mut notes = vec![];
        if self.model != model {
            if let (Some(a), Some(b)) = (s.solver.as_mut(), own.solver.as_ref()) {
                a.step_elements.clone_from(&b.step_elements);
            }
            s.aux.clone_from(&own.aux);
            notes.push(format!(
                "structural state from the {} model's saved state, damper state its own initial one",
                self.model
            ));
        }
        let steps = (sim.period_s() / sim.time_step_s()).round() as usize;
        if self.steps_per_rev != steps {
            notes.push(format!(
                "saved state of {} steps per revolution started at {steps}",
                self.steps_per_rev
            ));
        }
        if let (Some(a), Some(b)) = (self.inputs_sha256.as_deref(), inputs_sha256) {
            if a != b {
                let set = if self.overrides.is_empty() {
                    "no --set values".to_string()
                } else {
                    let v: Vec<String> = self
                        .overrides
                        .iter()
                        .map(|(k, v)| format!("{k}={v}"))
                        .collect();
                    format!("--set {}", v.join(" "))
                };
                notes.push(format!(
                    "saved state of other inputs (deck, record or --set values differ; it was \
                     saved with {set})"
                ));
            }
        } else if self.inputs_sha256.is_none() {
            notes.push("saved state without an inputs fingerprint (an older file): not checked against this run's deck and record".into());
        }
        let note = (!notes.is_empty())
            .then(|| format!("warm start from {}: {}", self.label, notes.join("; ")));
        let period = sim.period_s();
        let k_min = (sim.periodic_from_s() / period - 1e-9).ceil().max(0.0);
        let k = (s.t_s / period).round().max(k_min);
        s.t_s = k * period;
        if let Some(sn) = s.solver.as_mut() {
            sn.t_s = s.t_s;
        }
        Ok((s, note))
    }
}
