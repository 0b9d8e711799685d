//! Benchmark: cost of the `rotorsim run` forced response per structural step, for each damper
//! model on the UH-60A rotor with its joints and damper (rotors/uh60a.toml,
//! flightdata/c8534like, 256 steps per revolution, RK4 with 25 sub-steps), full and modified
//! Newton in the same run, with the structure/hydraulics split from `timing()`. Runs a few
//! revolutions per model (ROTORSIM_BENCH_REVS, default 3), one model at a time on one thread,
//! and extrapolates to the default 75-revolution run. Wall and CPU time of the thread (CPU time
//! is insensitive to other processes sharing the cores). The rigid-blade reduction
//! (`--model rigid`) and the lag-hinge test double are timed too, for scale.
//!
//! `cargo bench --bench rotor_run`
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions};
use rotorsim::run::drive;
use rotorsim::run::sdof::{LagHingeSdof, SdofParams};
use rotorsim::solver::NewtonMethod;
use std::path::Path;
use std::time::Instant;

mod support;
use support::cpu_s;

const DEFAULT_REVS: usize = 75;
const STEPS: usize = 256;

fn time_model(
    name: &str,
    model: DamperModel,
    revs: usize,
    build: impl FnOnce() -> anyhow::Result<Box<dyn ForcedResponse>>,
) {
    let t0 = Instant::now();
    let mut sim = match build() {
        Ok(s) => s,
        Err(e) => {
            println!("{name:<28} not available: {e:#}");
            return;
        }
    };
    let build_s = t0.elapsed().as_secs_f64();
    let c0 = cpu_s();
    let r = match drive(sim.as_mut(), model, revs, &|_, _| {}) {
        Ok(r) => r,
        Err(e) => {
            println!("{name:<28} failed: {e:#}");
            return;
        }
    };
    let cpu = cpu_s() - c0;
    let t = r.timing;
    let steps = t.steps.max(1) as f64;
    let per_step = t.total_s / steps;
    let hyd = t.hydraulics_s / t.total_s.max(1e-300);
    println!(
        "{name:<30} build {build_s:6.2} s | {revs} revs: {:8.2} s, {:9.4} ms/step wall, {:9.4} ms/step CPU ({:.2} Newton it/step, {:.3} factorizations/step), structure {:5.1}%, hydraulics {:5.1}% | 75 revs x {STEPS} steps: {:8.1} s (extrapolated) | periodicity after {revs} revs {}",
        t.total_s,
        1e3 * per_step,
        1e3 * cpu / steps,
        t.iterations as f64 / steps,
        t.factorizations as f64 / steps,
        100.0 * (1.0 - hyd),
        100.0 * hyd,
        per_step * (DEFAULT_REVS * STEPS) as f64 + build_s,
        rotorsim::run::fmt_measure(r.last_measure()),
    );
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let revs: usize = std::env::var("ROTORSIM_BENCH_REVS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let record = FlightRecord::read(&root.join("flightdata/c8534like")).expect("shipped record");
    let rotor_path = root.join("rotors/uh60a.toml");
    let opts = RunOptions {
        steps_per_rev: STEPS,
        hydraulics: IntegratorOptions::default(),
        ..RunOptions::default()
    };
    println!(
        "rotor_run: {revs} revolutions per model, {STEPS} steps/rev, RK4 x {} sub-steps, one thread",
        opts.hydraulics.substeps
    );
    let models = [
        DamperModel::Linear,
        DamperModel::Nonlinear,
        DamperModel::Physical,
    ];
    for m in models {
        for newton in [NewtonMethod::Full, NewtonMethod::Modified] {
            let name = format!("uh60a {} {} Newton", m.name(), newton.name());
            time_model(&name, m, revs, || {
                let rotor = RotorDeck::from_file(&rotor_path)?;
                let deck = rotor.damper()?;
                let opts = RunOptions { newton, ..opts };
                rotorsim::rotor::build(&rotor, &deck, m, &record, &opts)
            });
        }
    }
    let deck = DamperDeck::from_file(&rotor_path).expect("damper table");
    let rotor = RotorDeck::from_file(&rotor_path).expect("rotor deck");
    let pr = SdofParams::from_rotor(&rotor.spec, &rotor.path, &record).expect("reduction");
    for m in models {
        time_model(
            &format!("rigid-blade reduction {}", m.name()),
            m,
            revs,
            || {
                Ok(Box::new(LagHingeSdof::new(
                    pr.clone(),
                    &deck,
                    m,
                    opts.hydraulics,
                    STEPS,
                )?))
            },
        );
    }
    let p = SdofParams::from_record(&record).expect("lag moment");
    for m in models {
        time_model(&format!("sdof test double {}", m.name()), m, revs, || {
            Ok(Box::new(LagHingeSdof::new(
                p.clone(),
                &deck,
                m,
                opts.hydraulics,
                STEPS,
            )?))
        });
    }
}
