//! Benchmark: cost of the blade load channels (src/rotor/loads.rs), on the default run
//! (rotors/uh60a.toml, flightdata/c8534like, 256 steps per revolution, physical damper), thread
//! CPU time on one thread:
//! 1. per sample against the structural step they are sampled at (steps and channel
//!    evaluations timed alternately);
//! 2. the share of a model's periodic solution (`drive_periodic`, shooting, as `rotorsim run`):
//!    the per-sample ratio times the fraction of revolutions that compute loads (timing whole
//!    runs with and without loads was tried: on this shared machine pairs scatter by +-20%).
//!
//! `cargo bench --bench loads`
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::{RotorDeck, RunOptions};
use std::path::Path;

mod support;
use support::cpu_s;

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let record = FlightRecord::read(&root.join("flightdata/c8534like")).expect("shipped record");
    let rotor = RotorDeck::from_file(&root.join("rotors/uh60a.toml")).expect("rotor deck");
    let deck = rotor.damper().expect("damper table");
    let opts = RunOptions::default();
    let mut sim = rotorsim::rotor::build(&rotor, &deck, DamperModel::Physical, &record, &opts)
        .expect("model");
    let names = sim.channel_names();
    let n_loads = names
        .iter()
        .filter(|n| rotorsim::run::loads::is_load_channel(n) || n.starts_with("check_"))
        .count();
    let mut out = vec![0.0; names.len()];
    // past the ramps, then alternate: one step, then the channels `reps` times
    for _ in 0..3 * 256 {
        sim.step().expect("step");
    }
    let (steps, reps) = (512, 10);
    let (mut t_step, mut t_chan) = (0.0, 0.0);
    for _ in 0..steps {
        let c0 = cpu_s();
        sim.step().expect("step");
        let c1 = cpu_s();
        for _ in 0..reps {
            sim.channels(&mut out);
        }
        let c2 = cpu_s();
        t_step += c1 - c0;
        t_chan += (c2 - c1) / reps as f64;
    }
    println!(
        "loads: {} channels ({n_loads} load and check channels) | step {:.3} ms, all channels {:.4} ms per sample | channels / step = {:.2}%",
        names.len(),
        1e3 * t_step / steps as f64,
        1e3 * t_chan / steps as f64,
        100.0 * t_chan / t_step
    );
    // the share of a run: loads are computed on the revolutions that can be reported
    // (marched, trial) and not on the perturbed ones of shooting
    let opts = RunOptions {
        perturbation_damping: false,
        ..RunOptions::default()
    };
    let mut sim = rotorsim::rotor::build(&rotor, &deck, DamperModel::Physical, &record, &opts)
        .expect("model");
    let r = rotorsim::run::drive_periodic(
        sim.as_mut(),
        DamperModel::Physical,
        &rotorsim::run::PeriodicOptions::shooting(1e-4, 75),
        &|_, _| {},
    )
    .expect("run");
    let p = &r.periodic;
    let with_loads = p.marched_revolutions + p.iterations + p.rejected_trials;
    println!(
        "periodic solution: {} revolutions, {with_loads} with load channels: loads ~ {:.2}% of the run's structural time",
        p.revolutions_integrated,
        100.0 * t_chan / t_step * with_loads as f64 / p.revolutions_integrated as f64
    );
}
