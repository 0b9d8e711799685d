//! `rotorsim run`: drive forced-response simulations ([`ForcedResponse`]) to a
//! periodic solution, revolution by revolution, and compare their last revolution with the
//! measured damper force of a flight record.
//!
//! The pipeline knows nothing of the rotor model: it asks a builder for one simulation per
//! damper model, runs them in parallel (one thread each; the structural solver factorizes
//! with `faer::Par::Seq`, so each run stays on its thread), drives each to its periodic solution
//! ([`drive_periodic`]: shooting or marching), keeps the reported revolution, and hands the results to
//! [`summary`] (summary.json, last_rev.csv), [`report`] (report.html) and [`mcap_out`]
//! (result.mcap). Conventions and alignment: docs/run.md.
//!
//! Beside it, the pipelines of the other commands that write result folders: [`bench`] (the
//! damper bench's sweep and replay outputs), [`stability`] (ground and air resonance over rotor
//! speeds), [`modes`] (a model deck's modes, a rotor deck's fan plot), [`decay`] (a hinged
//! blade's lag free decay) and [`outputs`] (the run outputs' writer, shared with the diagnosis'
//! rotor-level check); [`stop`] stops runs from outside (the Python package's Ctrl-C).
pub mod job;
pub mod loads;
pub mod mcap_out;
pub mod outputs;
pub mod periodic;
pub mod ranges;
pub mod report;
pub mod rotor;
pub mod sdof;
pub mod settings;
pub mod stop;
pub mod summary;

use crate::hydraulics::DamperModel;
use crate::rotor::{ForcedResponse, SimState, Timing};
use crate::solver::budget;
use periodic::{integrate, max_nan, Revolution, SimMap, FLOQUET_REPORTED};
pub use periodic::{PeriodicInfo, PeriodicMethod, PeriodicOptions, PeriodicStateFile};
use std::time::Instant;

/// Channels monitored for periodicity, with the floor of their scale (a channel that barely
/// moves, e.g. the tip twist of a rigid-blade model, is then judged on that floor).
pub const MONITORED: [(&str, f64); 4] = [
    ("damper_force_N", 10.0),
    ("tip_flap_m", 1e-4),
    ("tip_lag_m", 1e-4),
    ("tip_twist_rad", 1e-5),
];

/// Monitored as well when the simulation has it (computed airloads): the rotor's thrust [N],
/// judged at the revolution's boundary like [`MONITORED`] and for content at the step rate
/// (an every-step, alternating-sign component beyond 0.1% of the scale: a discrete
/// instability that the blade's channels filter out), both on the scale `max(peak-to-peak,
/// floor, 1% of the mean)`.
pub const MONITORED_IF_PRESENT: [(&str, f64); 1] = [("rotor_thrust_N", 10.0)];

/// Name of the step-rate entry of a monitored channel in the residuals (`NAME@step_rate`).
pub const STEP_RATE_SUFFIX: &str = "@step_rate";

/// Harmonics compared against the measurement: 0..=10/rev.
pub const N_HARMONICS: usize = 10;

/// The result of driving one model.
#[derive(Debug, Clone)]
pub struct ModelRun {
    /// Damper model name ("linear", "nonlinear", "physical").
    pub model: String,
    /// The simulation's own label (e.g. "physical (sdof)" for the test double).
    pub label: String,
    /// Revolutions integrated (shooting: perturbed and trial revolutions included).
    pub revolutions: usize,
    pub steps_per_rev: usize,
    pub period_s: f64,
    /// How periodic the reported revolution is, and how it was found.
    pub periodic: PeriodicInfo,
    /// State at the start of the reported revolution (None: the simulation cannot save it).
    pub periodic_state: Option<SimState>,
    /// Channel names (with units), [`crate::rotor::BASE_CHANNELS`] first.
    pub channel_names: Vec<String>,
    /// Azimuth of each sample of the last revolution [deg], in [0, 360): k 360/N exactly.
    pub azimuth_deg: Vec<f64>,
    /// Model time of each sample of the last revolution [s] (t = 0 at psi = 0 of the first).
    pub time_s: Vec<f64>,
    /// Every revolution along the way, when asked for (`PeriodicOptions::keep_all_revs`).
    pub all_revs: Vec<KeptRevolution>,
    /// `last_rev[c][i]`: channel `c` at sample `i` of the last revolution.
    pub last_rev: Vec<Vec<f64>>,
    pub force_limits_n: Option<(f64, f64)>,
    /// Relief-valve regulation of the device (physical damper), for the limit check.
    pub relief_regulation: Option<[crate::rotor::ReliefRegulation; 2]>,
    pub timing: Timing,
    /// Wall time of the whole run of this model, construction included [s].
    pub wall_s: f64,
    /// When the run began and ended (a whole rotor's blades share threads, so its wall time
    /// spans its first blade's start to its last blade's end).
    pub span: Option<(Instant, Instant)>,
    /// Wall time of building the simulation [s].
    pub build_s: f64,
    /// Equilibrium check of the blade loads (models with load channels).
    pub loads_check: Option<loads::EquilibriumCheck>,
    /// Identical blades of the rotor (for the hub loads built by symmetry).
    pub blades: Option<usize>,
    /// A blade of a whole-rotor run: its number, 1 to N.
    pub blade: Option<usize>,
    /// A whole-rotor run: every blade's run, blade 1 first (this run holds blade 1's channels
    /// and the hub's).
    pub blade_runs: Vec<ModelRun>,
    /// A rotor on an airframe: its equation of motion against the rotor's loads on it.
    pub airframe_check: Option<rotor::AirframeCheck>,
    /// The airloads' source, inflow and aerofoil-table clamps (lifting-line runs).
    pub airloads: Option<crate::rotor::AirloadInfo>,
}

/// One revolution kept along the way to the periodic solution.
#[derive(Clone, Debug)]
pub struct KeptRevolution {
    /// 0 for a marched revolution, k for the k-th accepted shooting iterate.
    pub shooting_iterate: usize,
    /// Model time at its first sample [s].
    pub start_t_s: f64,
    /// `samples[c][i]`: channel `c` at sample `i` (azimuths as in [`ModelRun::azimuth_deg`]).
    pub samples: Vec<Vec<f64>>,
}

impl ModelRun {
    /// Its folder in the result folder: `<model>`, or `<model>/blade<K>` for a blade of a
    /// whole-rotor run.
    pub fn folder(&self) -> String {
        match self.blade {
            Some(k) => format!("{}/blade{k}", self.model),
            None => self.model.clone(),
        }
    }
    /// Samples of the channel named `name` over the last revolution.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.channel_names
            .iter()
            .position(|n| n == name)
            .map(|i| self.last_rev[i].as_slice())
    }
    /// Periodicity residual history (see [`PeriodicInfo::residual_history`]).
    pub fn measure_history(&self) -> Vec<f64> {
        self.periodic.residual_history.clone()
    }
    /// The periodicity residual of the reported revolution.
    pub fn last_measure(&self) -> Option<f64> {
        Some(self.periodic.residual)
    }
    pub fn converged(&self) -> bool {
        self.periodic.converged
    }
    /// Largest difference of the monitored channels between this reported revolution and
    /// `reference`'s (sampled alike), relative to the reference's peak-to-peak (floors of
    /// [`MONITORED`]), with the channel it occurs on. None if a channel is missing or the
    /// revolutions are sampled differently.
    pub fn difference_from(&self, reference: &ModelRun) -> Option<(f64, &'static str)> {
        let mut worst = (0.0, MONITORED[0].0);
        for (name, floor) in MONITORED {
            let (a, b) = (self.channel(name)?, reference.channel(name)?);
            if a.len() != b.len() {
                return None;
            }
            let d = crate::analysis::periodicity::relative_change(a, b, floor);
            if d.is_nan() || d > worst.0 {
                worst = (d, name);
            }
        }
        Some(worst)
    }
}

/// Outcome of one model: its run, or the error that stopped it.
#[derive(Debug)]
pub struct ModelOutcome {
    pub model: DamperModel,
    pub result: Result<ModelRun, String>,
}

/// Progress events, called from the worker threads.
pub trait Progress: Sync {
    /// Revolution `rev` (1-based) of `revs` of model `index` done; `measure` is the latest
    /// periodicity measure.
    fn revolution(&self, index: usize, rev: usize, revs: usize, measure: Option<f64>);
    /// Model `index` finished (`ok`) or failed.
    fn finished(&self, index: usize, ok: bool, message: &str);
}

/// No progress output.
pub struct Silent;
impl Progress for Silent {
    fn revolution(&self, _: usize, _: usize, _: usize, _: Option<f64>) {}
    fn finished(&self, _: usize, _: bool, _: &str) {}
}

/// Drives `sim` for `revs` revolutions. Each revolution is sampled at the start of each of its
/// steps (azimuths 0, 360/N, ...), so the last revolution is exactly one period of samples.
/// The run options every rotor run needs: two revolutions at least (periodicity compares
/// consecutive ones), 8 steps per revolution, one hydraulic sub-step.
pub fn check_run_options(revs: usize, steps_per_rev: usize, substeps: usize) -> anyhow::Result<()> {
    if revs < 2 {
        anyhow::bail!(
            "--revs must be at least 2 (periodicity compares consecutive revolutions), got {revs}"
        );
    }
    if steps_per_rev < 8 || substeps == 0 {
        anyhow::bail!(
            "--steps-per-rev must be >= 8 and --substeps >= 1 (got {steps_per_rev} and {substeps})"
        );
    }
    // Beyond sense is refused before anything runs. Per model and step: the elastic blade's
    // ~300 unknowns at 3 Newton iterations (a lower bound: the rigid reduction is cheaper but
    // then sub-steps dominate) and the device's sub-steps; kept: up to 32 revolutions of ~100
    // channels (shooting's subspace and the last revolutions).
    let steps = revs as f64 * steps_per_rev as f64;
    let e = budget::time_integration_of(100.0, 0.0, steps, 3.0)
        .plus(budget::substeps(steps * substeps as f64))
        .plus(budget::samples(
            (revs.min(32) * steps_per_rev) as f64,
            100.0,
        ));
    e.check(
        &format!("{revs} revolutions x {steps_per_rev} steps x {substeps} sub-steps per model"),
        "check --revs, --steps-per-rev and --substeps",
    )?;
    Ok(())
}

pub fn drive(
    sim: &mut dyn ForcedResponse,
    model: DamperModel,
    revs: usize,
    progress: &dyn Fn(usize, Option<f64>),
) -> anyhow::Result<ModelRun> {
    if revs < 2 {
        anyhow::bail!("--revs must be at least 2 so that periodicity can be measured (got {revs})");
    }
    drive_periodic(sim, model, &PeriodicOptions::march(revs), progress)
}

/// Periodic-forcing revolutions marched before shooting starts: the first one after the
/// ramps lets the fast modes it excited decay, the second is the first shooting iterate.
pub const MARCH_BEFORE_SHOOTING: usize = 2;

/// Drives `sim` to its periodic solution (`o.method`), at most `o.max_revs` revolutions, and
/// keeps the reported revolution: sampled at the start of each of its steps (azimuths 0,
/// 360/N, ...), exactly one period of samples.
///
/// Hybrid airloads referenced to the periodic solution itself take two solutions: the one
/// under the measured airloads (the lifting line recording along it), then, from it and with
/// the lifting line's difference acting, the hybrid's, whose Floquet multipliers carry the
/// aerodynamic damping (its periodic answer is the first one's, within the tolerance).
pub fn drive_periodic(
    sim: &mut dyn ForcedResponse,
    model: DamperModel,
    o: &PeriodicOptions,
    progress: &dyn Fn(usize, Option<f64>),
) -> anyhow::Result<ModelRun> {
    if !sim.reference_pending() {
        return drive_periodic_once(sim, model, o, progress);
    }
    let t_start = Instant::now();
    // the first stage's multipliers are not reported: no directions to resolve them
    let first_opts = PeriodicOptions {
        floquet_resolve: false,
        ..o.clone()
    };
    let first = drive_periodic_once(sim, model, &first_opts, progress)?;
    let (true, Some(start)) = (first.periodic.converged, first.periodic_state.as_ref()) else {
        anyhow::bail!(
            "{}: hybrid airloads need the periodic solution under the measured airloads as their reference, and it was not found: residual {:.2e} after {} revolutions, above the tolerance {:.0e} (more --revs, --periodic shooting)",
            sim.label(),
            first.periodic.residual,
            first.revolutions,
            o.tol
        );
    };
    // the lifting line along the periodic solution, one clean revolution from its start
    sim.restore_state(start)?;
    let n = first.steps_per_rev;
    let mut rev = Revolution::new(first.channel_names.len(), n);
    integrate(
        sim,
        &mut rev,
        &format!("{} model, hybrid reference", model.name()),
        &o.stop,
    )?;
    sim.adopt_reference();
    sim.restore_state(start)?;
    let second_opts = PeriodicOptions {
        initial_state: None,
        max_revs: o.max_revs.saturating_sub(first.revolutions + 1).max(2),
        min_floquet_dirs: o.min_floquet_dirs.max(FLOQUET_REPORTED),
        ..o.clone()
    };
    let before = first.revolutions + 1;
    let mut run = drive_periodic_once(sim, model, &second_opts, &|p, r| progress(p + before, r))?;
    run.revolutions += before;
    run.periodic.revolutions_integrated += before;
    run.periodic.marched_revolutions += first.periodic.marched_revolutions;
    let note = format!(
        "hybrid reference: the periodic solution under the measured airloads ({} revolutions, residual {:.2e}) and one revolution recording the lifting line along it",
        first.revolutions, first.periodic.residual
    );
    run.periodic.message = match run.periodic.message.as_str() {
        "" => note,
        m => format!("{note}; {m}"),
    };
    run.wall_s = t_start.elapsed().as_secs_f64();
    Ok(run)
}

/// What every stage of [`drive_periodic_once`] reads: the options, the channels it watches.
struct DriveCtx<'a> {
    model: DamperModel,
    o: &'a PeriodicOptions,
    progress: &'a dyn Fn(usize, Option<f64>),
    /// The monitored channels ([`MONITORED`], [`MONITORED_IF_PRESENT`]).
    mon: Vec<periodic::Monitor>,
    /// Indices of the sub-step envelope channels.
    env_channels: Vec<usize>,
    can_save: bool,
    /// Shooting asked for, and the simulation can save its state.
    shooting: bool,
    /// Model time from which a revolution counts as periodic (half a step early).
    periodic_from: f64,
}

impl DriveCtx<'_> {
    /// The progress label of marched revolution `p`.
    fn march_label(&self, p: usize) -> String {
        format!(
            "{} model, revolution {p} of at most {}",
            self.model.name(),
            self.o.max_revs
        )
    }

    /// Keep `rev` (envelopes aligned) when every revolution is asked for.
    fn keep(&self, kept: &mut Vec<KeptRevolution>, rev: &Revolution, iterate: usize) {
        if self.o.keep_all_revs {
            kept.push(KeptRevolution {
                shooting_iterate: iterate,
                start_t_s: rev.start_t_s,
                samples: {
                    let mut v = rev.samples.clone();
                    align_envelopes(&mut v, &rev.end, &self.env_channels);
                    v
                },
            });
        }
    }
}

/// The periodic search as it goes: the last revolution, its start state, the counts.
struct DriveState {
    info: PeriodicInfo,
    rev: Revolution,
    kept: Vec<KeptRevolution>,
    start_state: Option<SimState>,
    periods: usize,
    /// Shooting's slowest decaying multiplier magnitude (below 1).
    slowest: Option<f64>,
    /// Shooting's own error estimate.
    step_estimate: Option<f64>,
}

/// Drive one simulation to its periodic solution: march, then shoot (or not), then report.
fn drive_periodic_once(
    sim: &mut dyn ForcedResponse,
    model: DamperModel,
    o: &PeriodicOptions,
    progress: &dyn Fn(usize, Option<f64>),
) -> anyhow::Result<ModelRun> {
    let t_start = Instant::now();
    if o.max_revs < 1 {
        anyhow::bail!("at least one revolution is needed (got {})", o.max_revs);
    }
    let (period, dt, n) = steps_per_period(sim)?;
    let names = sim.channel_names();
    let nc = names.len();
    let env_channels: Vec<usize> = (0..nc)
        .filter(|&c| crate::hydraulics::circuit::is_substep_envelope(&names[c]))
        .collect();
    let mon = monitored_channels(sim, &names)?;
    let mut warm_note = None;
    if let Some(f) = &o.initial_state {
        let (s, note) = f.start_state(sim, model.name(), o.inputs_sha256.as_deref())?;
        sim.restore_state(&s)
            .map_err(|e| e.context("starting from the saved state (--initial-state)"))?;
        warm_note = note;
    }
    let can_save = sim.save_state().is_some();
    let shooting = o.method == PeriodicMethod::Shooting && can_save;
    let mut info = new_info(o, &mon);
    if o.method == PeriodicMethod::Shooting && !can_save {
        info.message = format!("{} cannot save its state: marched", sim.label());
    }
    if let Some(n) = warm_note {
        push_message(&mut info.message, n);
    }
    let periodic_from = sim.periodic_from_s() - 0.5 * dt;
    let c = DriveCtx {
        model,
        o,
        progress,
        mon,
        env_channels,
        can_save,
        shooting,
        periodic_from,
    };
    let mut s = DriveState {
        info,
        rev: Revolution::new(nc, n),
        kept: vec![],
        start_state: None,
        periods: 0,
        slowest: None,
        step_estimate: None,
    };
    // March: all of it, or until shooting starts.
    let shoot_from = march_until_shooting(sim, &c, &mut s)?;
    if let Some(st0) = shoot_from.filter(|_| !s.info.converged || o.min_floquet_dirs > 0) {
        s = shoot_stage(sim, &c, s, st0)?;
    }
    conclude_info(&mut s, o);
    finish_revolution(
        &mut s.rev,
        &mut s.kept,
        &names,
        &c.env_channels,
        s.info.method_used == PeriodicMethod::Shooting,
    );
    let timing = sim.timing();
    let blades = sim.blades();
    let mut run = ModelRun {
        model: model.name().to_string(),
        label: sim.label().to_string(),
        revolutions: s.periods,
        steps_per_rev: n,
        period_s: period,
        periodic: s.info,
        periodic_state: s.start_state,
        channel_names: names,
        time_s: (0..n).map(|j| s.rev.start_t_s + j as f64 * dt).collect(),
        azimuth_deg: s.rev.azimuth,
        last_rev: s.rev.samples,
        all_revs: s.kept,
        force_limits_n: sim.force_limits_n(),
        relief_regulation: sim.relief_regulation(),
        timing,
        wall_s: t_start.elapsed().as_secs_f64(),
        span: None,
        build_s: 0.0,
        loads_check: None,
        blades,
        blade: None,
        blade_runs: Vec::new(),
        airframe_check: None,
        airloads: sim.airload_info(),
    };
    loads::finish(&mut run, blades);
    envelopes_last(&mut run);
    Ok(run)
}

/// The [`MONITORED`] channels among `names` (an error naming a missing one), then those of
/// [`MONITORED_IF_PRESENT`] that the simulation has, each at the boundary and at the step rate.
fn monitored_channels(
    sim: &dyn ForcedResponse,
    names: &[String],
) -> anyhow::Result<Vec<periodic::Monitor>> {
    let idx = |name: &str| -> anyhow::Result<usize> {
        names.iter().position(|n| n == name).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: channel {name} missing (channels: {})",
                sim.label(),
                names.join(", ")
            )
        })
    };
    let mut mon = MONITORED
        .iter()
        .map(|(n, floor)| {
            Ok(periodic::Monitor {
                index: idx(n)?,
                name: n.to_string(),
                floor: *floor,
                kind: periodic::MonitorKind::Boundary,
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    for (n, floor) in MONITORED_IF_PRESENT {
        if let Some(index) = names.iter().position(|c| c == n) {
            mon.push(periodic::Monitor {
                index,
                name: n.to_string(),
                floor,
                kind: periodic::MonitorKind::BoundaryOfMean,
            });
            mon.push(periodic::Monitor {
                index,
                name: format!("{n}{STEP_RATE_SUFFIX}"),
                floor,
                kind: periodic::MonitorKind::StepRate,
            });
        }
    }
    Ok(mon)
}

/// March revolution by revolution until periodic, out of revolutions, or time to shoot;
/// returns the state to shoot from, if shooting is to follow.
fn march_until_shooting(
    sim: &mut dyn ForcedResponse,
    c: &DriveCtx,
    s: &mut DriveState,
) -> anyhow::Result<Option<SimState>> {
    let o = c.o;
    let mut in_periodic = 0;
    let mut shoot_from: Option<SimState> = None;
    while s.periods < o.max_revs {
        let periodic = sim.time_s() >= c.periodic_from;
        let st0 = if c.can_save { sim.save_state() } else { None };
        integrate(sim, &mut s.rev, &c.march_label(s.periods + 1), &o.stop)?;
        c.keep(&mut s.kept, &s.rev, 0);
        s.periods += 1;
        in_periodic += usize::from(periodic);
        s.info.residual_by_channel = s.rev.residual(&c.mon);
        let r = max_nan(&s.info.residual_by_channel);
        s.info.residual_history.push(r);
        (c.progress)(s.periods, Some(r));
        s.start_state = st0;
        if periodic && r <= o.tol {
            s.info.converged = true;
            if o.stop_early {
                // periodic already: shooting only for the Floquet multipliers asked for
                if c.shooting && o.min_floquet_dirs > 0 {
                    shoot_from = s.start_state.clone();
                }
                break;
            }
        } else {
            s.info.converged = false;
        }
        if c.shooting && in_periodic >= MARCH_BEFORE_SHOOTING {
            shoot_from = s.start_state.clone();
            break;
        }
    }
    s.info.marched_revolutions = s.periods;
    Ok(shoot_from)
}

/// Shoot from `st0` (the start of the last marched revolution): the periodic state and the
/// Floquet multipliers; if it does not converge, march on from its best state.
fn shoot_stage(
    sim: &mut dyn ForcedResponse,
    c: &DriveCtx,
    mut s: DriveState,
    st0: SimState,
) -> anyhow::Result<DriveState> {
    let o = c.o;
    let model = c.model;
    let end = sim
        .save_state()
        .ok_or_else(|| anyhow::anyhow!("{}: cannot save its state", sim.label()))?;
    let label = format!("{} model", model.name());
    let plan = periodic::FloquetPlan::of(
        o,
        sim.airload_info().is_some(),
        sim.period_s(),
        &sim.relaxation_times_s(),
    );
    let mut map = SimMap::new(
        sim,
        c.mon.clone(),
        st0,
        end,
        s.rev,
        s.periods,
        c.progress,
        label,
    );
    map.stop = o.stop.clone();
    if o.keep_all_revs {
        map.kept = Some(vec![]);
    }
    s.info.residual_history = vec![max_nan(&map.residual_by_channel)];
    let out = crate::periodic::shoot(&mut map, &periodic::shooting_options(o, &plan));
    s.periods = map.periods;
    s.info.iterations = out.iterations;
    s.info.directions = out.directions;
    s.info.rejected_trials = out.rejected_trials;
    s.info.floquet_directions = out.resolve_directions;
    s.info.residual_history = out.residual_history.clone();
    s.info.residual_by_channel = map.residual_by_channel.clone();
    s.info.converged = out.converged();
    s.info.method_used = PeriodicMethod::Shooting;
    let (start, end) = (map.start.clone(), map.end.clone());
    s.rev = std::mem::replace(&mut map.rev, Revolution::new(0, 0));
    for (k, r) in map.kept.take().unwrap_or_default().iter().enumerate() {
        c.keep(&mut s.kept, r, k + 1);
    }
    drop(map);
    // shooting reports a stopped revolution as a failed one: stop here, not march on
    let periods = s.periods;
    o.stop.check(
        sim.time_s(),
        &format!("{} model, revolution {periods} (shooting)", model.name()),
    )?;
    s.start_state = Some(start);
    let mult = reported_multipliers(sim, &out.ritz, plan.reported);
    s.slowest = out
        .ritz
        .first()
        .map(|p| p.multiplier.magnitude)
        .filter(|m| *m < 1.0);
    s.step_estimate = out.error_estimate;
    s.info.floquet_multipliers = mult;
    if !s.info.converged {
        let why = stop_reason(&out.stop, o.max_revs);
        push_message(
            &mut s.info.message,
            format!(
                "shooting did not converge ({why}; residual {:.2e}); marching on from its best state",
                max_nan(&s.info.residual_by_channel)
            ),
        );
        // march on from the end of the best revolution
        sim.restore_state(&end)?;
        march_on(sim, c, &mut s)?;
    }
    Ok(s)
}

/// After shooting that did not converge: march on until periodic or out of revolutions.
fn march_on(sim: &mut dyn ForcedResponse, c: &DriveCtx, s: &mut DriveState) -> anyhow::Result<()> {
    let o = c.o;
    while s.periods < o.max_revs {
        let st0 = sim.save_state();
        integrate(sim, &mut s.rev, &c.march_label(s.periods + 1), &o.stop)?;
        c.keep(&mut s.kept, &s.rev, 0);
        s.periods += 1;
        s.info.residual_by_channel = s.rev.residual(&c.mon);
        let r = max_nan(&s.info.residual_by_channel);
        s.info.residual_history.push(r);
        (c.progress)(s.periods, Some(r));
        s.start_state = st0;
        s.info.method_used = PeriodicMethod::March;
        if r <= o.tol {
            s.info.converged = true;
            break;
        }
    }
    Ok(())
}

/// The search's closing figures: residual, error estimate, counts, and why not periodic.
fn conclude_info(s: &mut DriveState, o: &PeriodicOptions) {
    let info = &mut s.info;
    info.residual = max_nan(&info.residual_by_channel);
    // shooting: from the last step and the contraction it achieved; marching: a slow mode
    // decaying by |mu_1| per revolution is residual / (1 - |mu_1|) from its end
    info.error_estimate = match info.method_used {
        PeriodicMethod::Shooting => s.step_estimate,
        PeriodicMethod::March => s.slowest.map(|m| info.residual / (1.0 - m)),
    };
    let periods = s.periods;
    info.revolutions_integrated = periods;
    info.start_t_s = s.rev.start_t_s;
    if !info.converged && !info.message.contains("did not converge") {
        push_message(
            &mut info.message,
            format!(
                "not periodic: residual {:.2e} after {periods} revolutions, above the tolerance {:.0e}",
                info.residual, o.tol
            ),
        );
    }
}

/// The period, the time step and the steps per period (a whole number of at least 4).
fn steps_per_period(sim: &dyn ForcedResponse) -> anyhow::Result<(f64, f64, usize)> {
    let period = sim.period_s();
    let dt = sim.time_step_s();
    let ratio = period / dt;
    let n = ratio.round() as usize;
    if n < 4 || (ratio - n as f64).abs() > 1e-6 * ratio {
        anyhow::bail!(
            "{}: period {period} s is not a whole number of time steps {dt} s",
            sim.label()
        );
    }
    Ok((period, dt, n))
}

/// The periodic search before its first revolution.
fn new_info(o: &PeriodicOptions, monitored: &[periodic::Monitor]) -> PeriodicInfo {
    PeriodicInfo {
        monitored: monitored
            .iter()
            .map(|m| (m.name.clone(), m.floor))
            .collect(),
        method: o.method,
        method_used: PeriodicMethod::March,
        converged: false,
        tolerance: o.tol,
        residual: f64::NAN,
        residual_by_channel: vec![f64::NAN; monitored.len()],
        residual_history: vec![],
        revolutions_integrated: 0,
        marched_revolutions: 0,
        iterations: 0,
        directions: 0,
        rejected_trials: 0,
        floquet_directions: 0,
        floquet_multipliers: vec![],
        error_estimate: None,
        message: String::new(),
        start_t_s: 0.0,
    }
}

/// The Floquet multipliers reported, each with its mode's label: the lag mode first, then
/// least damped first (an oscillating one: a real multiplier is a decaying or half-per-rev
/// motion).
fn reported_multipliers(
    sim: &dyn ForcedResponse,
    ritz: &[crate::periodic::floquet::RitzPair],
    reported: usize,
) -> Vec<crate::periodic::Multiplier> {
    let mut mult: Vec<_> = ritz
        .iter()
        .map(|p| {
            let mut m = p.multiplier.clone();
            m.mode = sim.mode_label(&p.vector_re, &p.vector_im);
            m
        })
        .collect();
    if let Some(i) = mult
        .iter()
        .position(|m| m.mode == "lag" && m.im.abs() > 0.0 && m.frequency_per_rev < 0.5)
    {
        let lag = mult.remove(i);
        mult.insert(0, lag);
    }
    mult.truncate(reported);
    mult
}

/// Why shooting stopped without converging.
fn stop_reason(stop: &crate::periodic::shooting::Stop, max_revs: usize) -> String {
    use crate::periodic::shooting::Stop;
    match stop {
        Stop::Budget => format!("the budget of {max_revs} revolutions ran out"),
        Stop::LineSearch => {
            "no step along the Newton-Picard direction decreased the residual (non-smooth valves?)"
                .into()
        }
        Stop::Failed(e) => format!("a revolution failed: {e}"),
        Stop::Converged => String::new(),
    }
}

/// The reported revolution's sub-step envelopes aligned with its samples; after shooting
/// (`shot`), its first sample taken from its end.
fn finish_revolution(
    rev: &mut Revolution,
    kept: &mut [KeptRevolution],
    names: &[String],
    env_channels: &[usize],
    shot: bool,
) {
    if shot {
        // The reported revolution starts from a shooting iterate, restored: at its first
        // sample the accelerations are the iterate's (updated linearly, not from the
        // equations of motion) and the device reports its last step, of the revolution run
        // before. The revolution's end is the same point of the periodic solution (within
        // the residual, measured above) reached by a step: its values stand for the first
        // sample.
        let end = &rev.end;
        let first = |samples: &mut [Vec<f64>]| {
            for (c, v) in samples.iter_mut().enumerate() {
                if !env_channels.contains(&c) {
                    v[0] = end[c];
                }
            }
        };
        if let Some(k) = kept.last_mut().filter(|k| k.start_t_s == rev.start_t_s) {
            first(&mut k.samples);
        }
        first(&mut rev.samples);
    }
    align_envelopes(&mut rev.samples, &rev.end, env_channels);
    if shot {
        // the first step's sub-step envelope then also holds the first sample it starts from
        widen_first_envelope(&mut rev.samples, names, env_channels);
        if let Some(k) = kept.last_mut().filter(|k| k.start_t_s == rev.start_t_s) {
            widen_first_envelope(&mut k.samples, names, env_channels);
        }
    }
}

/// The sub-step envelope channels moved last, so the columns written before them keep their
/// places.
fn envelopes_last(run: &mut ModelRun) {
    let (env, point): (Vec<usize>, Vec<usize>) = (0..run.channel_names.len())
        .partition(|&c| crate::hydraulics::circuit::is_substep_envelope(&run.channel_names[c]));
    if env.is_empty() {
        return;
    }
    let order: Vec<usize> = point.into_iter().chain(env).collect();
    let reorder = |v: &mut Vec<Vec<f64>>| {
        let mut old = std::mem::take(v);
        let n = old.len();
        *v = order
            .iter()
            .filter(|&&c| c < n)
            .map(|&c| std::mem::take(&mut old[c]))
            .collect();
    };
    run.channel_names = order
        .iter()
        .map(|&c| run.channel_names[c].clone())
        .collect();
    reorder(&mut run.last_rev);
    for k in &mut run.all_revs {
        reorder(&mut k.samples);
    }
}

/// Row 0 of each sub-step envelope (`<q>_substep_min_<unit>`, `..._max_...`) widened to hold
/// its channel's first sample (`<q>_<unit>`).
fn widen_first_envelope(samples: &mut [Vec<f64>], names: &[String], env: &[usize]) {
    for &c in env {
        let Some(name) = names.get(c) else { continue };
        let (point, is_min) = if let Some((q, u)) = name.split_once("_substep_min_") {
            (format!("{q}_{u}"), true)
        } else if let Some((q, u)) = name.split_once("_substep_max_") {
            (format!("{q}_{u}"), false)
        } else {
            continue;
        };
        let Some(p) = names.iter().position(|n| *n == point) else {
            continue;
        };
        let (Some(&v), Some(&e)) = (samples[p].first(), samples[c].first()) else {
            continue;
        };
        samples[c][0] = if is_min { e.min(v) } else { e.max(v) };
    }
}

/// A sub-step envelope sampled at the start of step j covers the step before it: shifted so
/// that row j covers step j (from its azimuth to the next), the last row from the revolution's
/// end.
fn align_envelopes(samples: &mut [Vec<f64>], end: &[f64], env: &[usize]) {
    for &c in env {
        samples[c].rotate_left(1);
        if let Some(last) = samples[c].last_mut() {
            *last = end[c];
        }
    }
}

/// Builds and drives one simulation per unit in parallel (a model, or a blade of a whole
/// rotor: `build(i)` builds unit `i`, of damper model `models[i]`). A failed unit (build or
/// run) is returned as an error message; the others are unaffected.
pub fn run_units<B>(
    models: &[DamperModel],
    opts: &[PeriodicOptions],
    build: &B,
    progress: &dyn Progress,
) -> Vec<ModelOutcome>
where
    B: Fn(usize) -> anyhow::Result<Box<dyn ForcedResponse>> + Sync,
{
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let workers = workers_for(models.len(), cores);
    // Each unit runs on one thread only, so its results do not depend on how many run.
    let next = std::sync::atomic::AtomicUsize::new(0);
    let done: Vec<std::sync::Mutex<Option<ModelOutcome>>> =
        models.iter().map(|_| std::sync::Mutex::new(None)).collect();
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let (Some(&model), Some(o)) = (models.get(i), opts.get(i)) else {
                    break;
                };
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    run_one(i, model, o, build, progress)
                }))
                .unwrap_or_else(|_| ModelOutcome {
                    model,
                    result: Err("the model's thread panicked".into()),
                });
                if let Ok(mut slot) = done[i].lock() {
                    *slot = Some(r);
                }
            });
        }
    });
    done.into_iter()
        .zip(models)
        .map(|(d, &model)| {
            d.into_inner()
                .ok()
                .flatten()
                .unwrap_or_else(|| ModelOutcome {
                    model,
                    result: Err("the model's thread panicked".into()),
                })
        })
        .collect()
}

/// Threads for `units` equal units on `cores` cores: the fewest, at least `cores`, that give
/// every thread the same number of units. Three models on two cores get three threads, which
/// share both cores to the end (two threads would leave a core idle for the third's whole
/// run); four or eight blades get two, each running its blades in turn rather than eight
/// threads evicting each other's caches.
pub fn workers_for(units: usize, cores: usize) -> usize {
    let least = cores.clamp(1, units.max(1));
    (least..=units.max(1))
        .find(|w| units.is_multiple_of(*w))
        .unwrap_or(units.max(1))
}

fn run_one<B>(
    i: usize,
    model: DamperModel,
    opts: &PeriodicOptions,
    build: &B,
    progress: &dyn Progress,
) -> ModelOutcome
where
    B: Fn(usize) -> anyhow::Result<Box<dyn ForcedResponse>> + Sync,
{
    let t0 = Instant::now();
    let result = build(i)
        .map_err(|e| e.context(format!("building the {} model", model.name())))
        .and_then(|mut sim| {
            let build_s = t0.elapsed().as_secs_f64();
            let cb = |rev: usize, m: Option<f64>| progress.revolution(i, rev, opts.max_revs, m);
            let mut run = drive_periodic(sim.as_mut(), model, opts, &cb)?;
            run.build_s = build_s;
            run.wall_s = t0.elapsed().as_secs_f64();
            run.span = Some((t0, Instant::now()));
            Ok(run)
        })
        .map_err(|e| format!("{e:#}"));
    match &result {
        Ok(r) => progress.finished(
            i,
            true,
            &format!(
                "residual {} after {} revs ({})",
                fmt_measure(r.last_measure()),
                r.revolutions,
                r.periodic.method_used.name()
            ),
        ),
        Err(e) => progress.finished(i, false, e),
    }
    ModelOutcome { model, result }
}

/// A periodicity measure for humans.
pub fn fmt_measure(m: Option<f64>) -> String {
    match m {
        Some(x) if x.is_finite() => format!("{x:.2e}"),
        Some(_) => "NaN".into(),
        None => "n/a".into(),
    }
}

/// Appends `m` to a run's message (notes such as a warm start's are kept).
fn push_message(message: &mut String, m: String) {
    if !message.is_empty() {
        message.push_str("; ");
    }
    message.push_str(&m);
}

#[cfg(test)]
mod tests {
    use super::workers_for;

    #[test]
    fn every_thread_gets_the_same_number_of_units() {
        assert_eq!(workers_for(3, 2), 3);
        assert_eq!(workers_for(1, 2), 1);
        assert_eq!(workers_for(4, 2), 2);
        assert_eq!(workers_for(8, 2), 2);
        assert_eq!(workers_for(12, 2), 2);
        assert_eq!(workers_for(6, 4), 6);
        assert_eq!(workers_for(12, 8), 12);
        assert_eq!(workers_for(2, 16), 2);
        assert_eq!(workers_for(0, 2), 1);
    }
}
