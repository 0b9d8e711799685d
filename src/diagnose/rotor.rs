//! Rotor-level parts of the diagnosis: the damper stroke of a flight record that
//! has none, simulated by the full rotor run, and the rotor-level before/after check
//! of an extended damper deck (baseline deck vs extended deck, physical damper, in parallel).
//!
//! Conventions are those of docs/run.md: model time t = 0 is psi = 0 of the reference blade,
//! the record's samples sit at time `(rev*360 + psi)/Omega[deg/s]`, the model's last revolution
//! is interpolated (periodic, linear) at the record's azimuths, no shift, scaling or offset.
use super::data::{periodic_derivative, Measurement};
use crate::analysis::compare::{Periodic, PeriodicInterp};
use crate::flight::FlightRecord;
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};
use crate::rotor::{RotorDeck, RunOptions};
use crate::run::{drive, ModelRun};
use anyhow::{bail, Context};
use std::path::Path;
use std::time::Instant;

/// Options of a rotor run made by the diagnosis (those of `rotorsim run`, RK4 sub-steps).
#[derive(Clone, Copy, Debug)]
pub struct RotorRunOptions {
    /// Revolutions (at least 2); the last one is used.
    pub revs: usize,
    /// Structural steps per revolution (paper: 256).
    pub steps_per_rev: usize,
    /// Hydraulic RK4 sub-steps per structural step (paper: 25).
    pub substeps: usize,
    /// Run the rigid-blade reduction of the rotor deck (`rotorsim run --model rigid`) instead of
    /// the multibody rotor model.
    pub rigid: bool,
}

impl RotorRunOptions {
    pub fn check(&self) -> anyhow::Result<()> {
        crate::run::check_run_options(self.revs, self.steps_per_rev, self.substeps)
    }
    fn run_options(&self) -> RunOptions {
        RunOptions {
            steps_per_rev: self.steps_per_rev,
            hydraulics: IntegratorOptions {
                scheme: Scheme::Rk4,
                substeps: self.substeps,
            },
            ..RunOptions::default()
        }
    }
}

/// Builds and drives the rotor with the physical damper of `damper` (as `rotorsim run
/// --damper physical`); `progress(rev, measure)` after each revolution.
pub fn run_physical(
    rotor: &RotorDeck,
    damper: &DamperDeck,
    record: &FlightRecord,
    opts: &RotorRunOptions,
    progress: &dyn Fn(usize, Option<f64>),
) -> anyhow::Result<ModelRun> {
    opts.check()?;
    damper.require(DamperModel::Physical)?;
    // The damper at the record's oil temperature, as `run` takes it.
    let damper = &*damper.at_known_oil_temperature(record.meta.damper_oil_temperature_k)?;
    let t0 = Instant::now();
    let mut sim: Box<dyn crate::rotor::ForcedResponse> = if opts.rigid {
        Box::new(crate::run::sdof::rigid_reduction(
            rotor,
            damper,
            DamperModel::Physical,
            record,
            &opts.run_options(),
        )?)
    } else {
        crate::rotor::build(
            rotor,
            damper,
            DamperModel::Physical,
            record,
            &opts.run_options(),
        )
        .context("building the rotor model with the physical damper")?
    };
    let build_s = t0.elapsed().as_secs_f64();
    let mut run = drive(sim.as_mut(), DamperModel::Physical, opts.revs, progress)?;
    run.build_s = build_s;
    run.wall_s = t0.elapsed().as_secs_f64();
    Ok(run)
}

/// The damper samples of a record as a stroke-driven measurement. `stroke` is the record's own
/// stroke (`None`) or a periodic stroke history (one revolution of the rotor model) evaluated
/// at each sample's azimuth. Velocity by a periodic central difference (for the report).
pub fn flight_measurement(
    rec: &FlightRecord,
    path: &Path,
    simulated: Option<&PeriodicInterp>,
) -> anyhow::Result<Measurement> {
    let name = path.display();
    let omega_deg = rec.meta.rotor_speed_deg_s();
    let s = rec.damper();
    if s.is_empty() {
        bail!("{name}: the record has no damper samples");
    }
    let mut t = Vec::with_capacity(s.len());
    let mut d = Vec::with_capacity(s.len());
    let mut f = Vec::with_capacity(s.len());
    for x in s {
        t.push((x.revolution as f64 * 360.0 + x.azimuth_deg) / omega_deg);
        d.push(match simulated {
            Some(p) => p.at(x.azimuth_deg),
            None => x.stroke_m.unwrap_or(f64::NAN),
        });
        f.push(x.force_N);
    }
    if d.iter().any(|v| !v.is_finite()) {
        bail!("{name}: some damper samples lack a stroke");
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        bail!(
            "{name}: damper samples not in time order at sample {}",
            i + 1
        );
    }
    let revs = rec.damper_revolutions();
    if revs.windows(2).any(|w| w[1] != w[0] + 1) {
        bail!(
            "{name}: damper revolutions have gaps ({revs:?}); the stroke-driven replay needs a continuous record"
        );
    }
    if t.len() < 2 {
        bail!("{name}: a single damper sample");
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    // The record is periodic over whole revolutions: periodic derivative of the stroke.
    let v = periodic_derivative(&d, dt);
    Ok(Measurement {
        name: path
            .file_name()
            .map_or("flight".into(), |s| s.to_string_lossy().into_owned()),
        time_s: t,
        stroke_m: d,
        force_n: f,
        velocity_m_s: v,
        period_s: 360.0 / omega_deg,
        oil_temperature_k: rec.meta.damper_oil_temperature_k,
    })
}

/// The periodic damper stroke of a rotor run's last revolution, for interpolation.
pub fn periodic_stroke(run: &ModelRun) -> anyhow::Result<PeriodicInterp> {
    let d = run
        .channel("damper_stroke_m")
        .context("the rotor run has no damper_stroke_m channel")?;
    Ok(PeriodicInterp::new(Periodic {
        psi_deg: &run.azimuth_deg,
        value: d,
    })?)
}

/// Mean and half peak-to-peak of a signal.
pub fn mean_and_amplitude(v: &[f64]) -> (f64, f64) {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
            (l.min(*x), h.max(*x))
        });
    (
        v.iter().sum::<f64>() / v.len().max(1) as f64,
        0.5 * (hi - lo),
    )
}

/// The two rotor runs of the rotor-level check: physical damper with the baseline deck and with
/// the extended deck, in parallel (one rayon task each).
pub struct RotorCheckRuns {
    pub baseline: Result<ModelRun, String>,
    pub extended: Result<ModelRun, String>,
    /// Wall time of both (in parallel) [s].
    pub wall_s: f64,
}

pub fn rotor_check_runs(
    rotor: &RotorDeck,
    baseline: &DamperDeck,
    extended: &DamperDeck,
    record: &FlightRecord,
    opts: &RotorRunOptions,
    progress: &(dyn Fn(&str, usize, Option<f64>) + Sync),
) -> RotorCheckRuns {
    let t0 = Instant::now();
    let go = |deck: &DamperDeck, which: &str| {
        let cb = |rev: usize, m: Option<f64>| progress(which, rev, m);
        run_physical(rotor, deck, record, opts, &cb).map_err(|e| format!("{e:#}"))
    };
    let (b, e) = rayon::join(|| go(baseline, "baseline"), || go(extended, "extended"));
    RotorCheckRuns {
        baseline: b,
        extended: e,
        wall_s: t0.elapsed().as_secs_f64(),
    }
}
