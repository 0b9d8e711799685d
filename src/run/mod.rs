//! `rotorsim run`: drive forced-response simulations ([`ForcedResponse`]) to a
//! periodic solution, revolution by revolution, and compare their last revolution with the
//! measured damper force of a flight record.
//!
//! The pipeline knows nothing of the rotor model: it asks a builder for one simulation per
//! damper model, runs them in parallel (one thread each; the structural solver factorizes
//! with `faer::Par::Seq`, so each run stays on its thread), monitors periodicity once per revolution
//! with [`PeriodicityMonitor`], keeps the last revolution, and hands the results to
//! [`summary`] (summary.json, last_rev.csv), [`report`] (report.html) and [`mcap_out`]
//! (result.mcap). Conventions and alignment: docs/run.md.
pub mod mcap_out;
pub mod report;
pub mod sdof;
pub mod summary;

use crate::analysis::periodicity::PeriodicityMonitor;
use crate::hydraulics::DamperModel;
use crate::rotor::{ForcedResponse, Timing};
use std::time::Instant;

/// Periodicity tolerance: the measure must fall below it by the last revolution.
pub const PERIODICITY_TOL: f64 = 1e-3;

/// Channels monitored for periodicity, with the floor of their scale (a channel that barely
/// moves, e.g. the tip twist of a rigid-blade model, is then judged on that floor).
pub const MONITORED: [(&str, f64); 4] = [
    ("damper_force_N", 10.0),
    ("tip_flap_m", 1e-4),
    ("tip_lag_m", 1e-4),
    ("tip_twist_rad", 1e-5),
];

/// Harmonics compared against the measurement: 0..=10/rev.
pub const N_HARMONICS: usize = 10;

/// The result of driving one model.
#[derive(Debug, Clone)]
pub struct ModelRun {
    /// Damper model name ("linear", "nonlinear", "physical").
    pub model: String,
    /// The simulation's own label (e.g. "physical (sdof)" for the test double).
    pub label: String,
    /// Revolutions completed.
    pub revolutions: usize,
    pub steps_per_rev: usize,
    pub period_s: f64,
    /// Per revolution (from the second): measure of each monitored channel.
    pub periodicity: PeriodicityMonitor,
    /// Channel names (with units), [`crate::rotor::BASE_CHANNELS`] first.
    pub channel_names: Vec<String>,
    /// Azimuth of each sample of the last revolution [deg], in [0, 360).
    pub azimuth_deg: Vec<f64>,
    /// `last_rev[c][i]`: channel `c` at sample `i` of the last revolution.
    pub last_rev: Vec<Vec<f64>>,
    pub force_limits_n: Option<(f64, f64)>,
    /// Relief-valve regulation of the device (physical damper), for the limit check.
    pub relief_regulation: Option<[crate::rotor::ReliefRegulation; 2]>,
    pub timing: Timing,
    /// Wall time of the whole run of this model, construction included [s].
    pub wall_s: f64,
    /// Wall time of building the simulation [s].
    pub build_s: f64,
}

impl ModelRun {
    /// Samples of the channel named `name` over the last revolution.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.channel_names
            .iter()
            .position(|n| n == name)
            .map(|i| self.last_rev[i].as_slice())
    }
    /// Max-over-channels periodicity measure after each revolution (from revolution 1).
    pub fn measure_history(&self) -> Vec<f64> {
        self.periodicity
            .history
            .iter()
            .map(|v| {
                if v.iter().any(|x| x.is_nan()) {
                    f64::NAN
                } else {
                    v.iter().fold(0.0f64, |m, x| m.max(*x))
                }
            })
            .collect()
    }
    /// The periodicity measure of the last revolution.
    pub fn last_measure(&self) -> Option<f64> {
        self.periodicity.latest()
    }
    pub fn converged(&self) -> bool {
        self.periodicity.converged(PERIODICITY_TOL)
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
    Ok(())
}

pub fn drive(
    sim: &mut dyn ForcedResponse,
    model: DamperModel,
    revs: usize,
    progress: &dyn Fn(usize, Option<f64>),
) -> anyhow::Result<ModelRun> {
    let t_start = Instant::now();
    if revs < 2 {
        anyhow::bail!("--revs must be at least 2 so that periodicity can be measured (got {revs})");
    }
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
    let names = sim.channel_names();
    let nc = names.len();
    let idx = |name: &str| -> anyhow::Result<usize> {
        names.iter().position(|n| n == name).ok_or_else(|| {
            anyhow::anyhow!(
                "{}: channel {name} missing (channels: {})",
                sim.label(),
                names.join(", ")
            )
        })
    };
    let monitored: Vec<usize> = MONITORED
        .iter()
        .map(|(n, _)| idx(n))
        .collect::<anyhow::Result<_>>()?;
    let mut monitor = PeriodicityMonitor::new(&MONITORED);
    // Current revolution: samples[c][j]; allocated once, swapped out per revolution.
    let mut samples = vec![vec![0.0; n]; nc];
    let mut azimuth = vec![0.0; n];
    let mut buf = vec![0.0; nc];
    for r in 0..revs {
        for j in 0..n {
            sim.channels(&mut buf);
            for (c, v) in buf.iter().enumerate() {
                samples[c][j] = *v;
            }
            azimuth[j] = (sim.azimuth_deg() - 360.0 * r as f64).rem_euclid(360.0);
            // Keep floating-point drift from wrapping 359.99999 to 0 at the first sample.
            if j == 0 && azimuth[j] > 359.0 {
                azimuth[j] = 0.0;
            }
            sim.step().map_err(|e| {
                e.context(format!(
                    "{} model, revolution {} of {revs}, step {j} of {n} (t = {:.6} s)",
                    model.name(),
                    r + 1,
                    sim.time_s()
                ))
            })?;
        }
        let mon: Vec<Vec<f64>> = monitored.iter().map(|&c| samples[c].clone()).collect();
        let m = monitor.push_revolution(mon);
        progress(r + 1, m);
    }
    let timing = sim.timing();
    Ok(ModelRun {
        model: model.name().to_string(),
        label: sim.label().to_string(),
        revolutions: revs,
        steps_per_rev: n,
        period_s: period,
        periodicity: monitor,
        channel_names: names,
        azimuth_deg: azimuth,
        last_rev: samples,
        force_limits_n: sim.force_limits_n(),
        relief_regulation: sim.relief_regulation(),
        timing,
        wall_s: t_start.elapsed().as_secs_f64(),
        build_s: 0.0,
    })
}

/// Builds and drives one simulation per model in parallel. A failed model (build or run) is
/// returned as an error message; the others are unaffected.
pub fn run_models<B>(
    models: &[DamperModel],
    revs: usize,
    build: &B,
    progress: &dyn Progress,
) -> Vec<ModelOutcome>
where
    B: Fn(DamperModel) -> anyhow::Result<Box<dyn ForcedResponse>> + Sync,
{
    // One thread per model, not a pool of one per core: three models on two cores then share
    // both cores to the end instead of two running first and the third alone while a core
    // idles. Each model runs on its own thread only, so its results do not depend on how
    // many there are.
    std::thread::scope(|scope| {
        let handles: Vec<_> = models
            .iter()
            .enumerate()
            .map(|(i, &model)| scope.spawn(move || run_one(i, model, revs, build, progress)))
            .collect();
        handles
            .into_iter()
            .zip(models)
            .map(|(h, &model)| {
                h.join().unwrap_or_else(|_| ModelOutcome {
                    model,
                    result: Err("the model's thread panicked".into()),
                })
            })
            .collect()
    })
}

fn run_one<B>(
    i: usize,
    model: DamperModel,
    revs: usize,
    build: &B,
    progress: &dyn Progress,
) -> ModelOutcome
where
    B: Fn(DamperModel) -> anyhow::Result<Box<dyn ForcedResponse>> + Sync,
{
    let t0 = Instant::now();
    let result = build(model)
        .map_err(|e| e.context(format!("building the {} model", model.name())))
        .and_then(|mut sim| {
            let build_s = t0.elapsed().as_secs_f64();
            let cb = |rev: usize, m: Option<f64>| progress.revolution(i, rev, revs, m);
            let mut run = drive(sim.as_mut(), model, revs, &cb)?;
            run.build_s = build_s;
            run.wall_s = t0.elapsed().as_secs_f64();
            Ok(run)
        })
        .map_err(|e| format!("{e:#}"));
    match &result {
        Ok(r) => progress.finished(
            i,
            true,
            &format!(
                "periodicity {} after {} revs",
                fmt_measure(r.last_measure()),
                r.revolutions
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
