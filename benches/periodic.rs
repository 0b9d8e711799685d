//! Benchmark: the periodic solution by shooting against marching, per damper model, on the
//! default run (rotors/uh60a.toml, flightdata/c8534like, 256 steps per revolution, RK4 with 25
//! sub-steps). For each model, one at a time on one thread:
//! - shooting to the default tolerance (1e-4), the deck's perturbation damping off (as `run`);
//! - marching to the same tolerance, perturbation damping on (as `run --periodic march`), at
//!   most ROTORSIM_BENCH_MAX_REVS revolutions (default 300);
//! - a reference: ROTORSIM_BENCH_REF_REVS revolutions marched to the end (default 200; 0 skips
//!   it), against which both reported revolutions are compared (true error, relative to each
//!   monitored channel's peak-to-peak).
//!
//! Prints revolutions integrated, wall and thread-CPU time, the residual each method stopped
//! at, the true error, and the march/shooting ratios of revolutions and CPU time (measured in
//! the same process, so they hold on a loaded machine).
//!
//! ROTORSIM_BENCH_TOL sets the tolerance, ROTORSIM_BENCH_MODEL one model only.
//!
//! `cargo bench --bench periodic`
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::{DamperModel, IntegratorOptions};
use rotorsim::rotor::{RotorDeck, RunOptions};
use rotorsim::run::periodic::DEFAULT_TOL;
use rotorsim::run::{drive_periodic, ModelRun, PeriodicOptions};
use std::path::Path;
use std::time::Instant;

mod support;
use support::cpu_s;

const STEPS: usize = 256;

fn env_usize(key: &str, default: usize) -> usize {
    std::env::var(key)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

struct Timed {
    run: ModelRun,
    wall_s: f64,
    cpu_s: f64,
}

fn timed(
    rotor: &RotorDeck,
    record: &FlightRecord,
    model: DamperModel,
    o: &PeriodicOptions,
    perturbation_damping: bool,
) -> Timed {
    let opts = RunOptions {
        steps_per_rev: STEPS,
        hydraulics: IntegratorOptions::default(),
        perturbation_damping,
        ..RunOptions::default()
    };
    let (t0, c0) = (Instant::now(), cpu_s());
    let deck = rotor.damper().expect("damper table");
    let mut sim = rotorsim::rotor::build(rotor, &deck, model, record, &opts).expect("model");
    let run = drive_periodic(sim.as_mut(), model, o, &|_, _| {}).expect("run");
    Timed {
        run,
        wall_s: t0.elapsed().as_secs_f64(),
        cpu_s: cpu_s() - c0,
    }
}

fn error(t: &Timed, reference: Option<&Timed>) -> String {
    match reference.and_then(|r| t.run.difference_from(&r.run)) {
        Some((d, ch)) => format!("{d:.1e} ({ch})"),
        None => "-".into(),
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let max_revs = env_usize("ROTORSIM_BENCH_MAX_REVS", 300);
    let ref_revs = env_usize("ROTORSIM_BENCH_REF_REVS", 200);
    let tol: f64 = std::env::var("ROTORSIM_BENCH_TOL")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(DEFAULT_TOL);
    let only = std::env::var("ROTORSIM_BENCH_MODEL").ok();
    let record = FlightRecord::read(&root.join("flightdata/c8534like")).expect("shipped record");
    let rotor = RotorDeck::from_file(&root.join("rotors/uh60a.toml")).expect("rotor deck");
    println!(
        "periodic: tolerance {tol:.0e}, {STEPS} steps/rev, RK4 x {} sub-steps, one thread; march at most {max_revs} revs; reference {ref_revs} marched revs",
        IntegratorOptions::default().substeps
    );
    println!(
        "{:<10} {:<9} {:>5} {:>8} {:>8} {:>9} {:>10} {:>9}  true error (channel)",
        "model", "method", "revs", "wall s", "CPU s", "periodic", "residual", "estimate"
    );
    for model in [
        DamperModel::Linear,
        DamperModel::Nonlinear,
        DamperModel::Physical,
    ] {
        if only.as_deref().is_some_and(|m| m != model.name()) {
            continue;
        }
        let reference = (ref_revs > 0).then(|| {
            timed(
                &rotor,
                &record,
                model,
                &PeriodicOptions::march(ref_revs),
                true,
            )
        });
        let shot = timed(
            &rotor,
            &record,
            model,
            &PeriodicOptions::shooting(tol, 75),
            false,
        );
        let march_opts = PeriodicOptions {
            stop_early: true,
            tol,
            ..PeriodicOptions::march(max_revs)
        };
        let march = timed(&rotor, &record, model, &march_opts, true);
        if let Some(r) = &reference {
            println!(
                "{:<10} {:<9} {:>5} {:>8.2} {:>8.2} {:>9} {:>10.1e}",
                model.name(),
                "reference",
                r.run.periodic.revolutions_integrated,
                r.wall_s,
                r.cpu_s,
                "",
                r.run.periodic.residual,
            );
        }
        for (name, t) in [("shooting", &shot), ("march", &march)] {
            println!(
                "{:<10} {:<9} {:>5} {:>8.2} {:>8.2} {:>9} {:>10.1e} {:>9}  {}",
                model.name(),
                name,
                t.run.periodic.revolutions_integrated,
                t.wall_s,
                t.cpu_s,
                if t.run.converged() { "yes" } else { "NO" },
                t.run.periodic.residual,
                t.run
                    .periodic
                    .error_estimate
                    .map_or("-".into(), |e| format!("{e:.1e}")),
                error(t, reference.as_ref()),
            );
        }
        println!(
            "{:<10} march/shooting: revolutions {:.1}, CPU time {:.1}",
            model.name(),
            march.run.periodic.revolutions_integrated as f64
                / shot.run.periodic.revolutions_integrated as f64,
            march.cpu_s / shot.cpu_s
        );
    }
}
