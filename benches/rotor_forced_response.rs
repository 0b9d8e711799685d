//! Cost per step of the UH-60A forced response (issue #6), each damper model: build, then
//! `REVS` revolutions at 256 steps (default 4; ROTOR_BENCH_REVS overrides), release build.
//! Prints wall and CPU-thread time per step and per Newton iteration and the hydraulic share.
//! Run: `cargo bench --bench rotor_forced_response`.
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::{build, RotorDeck, RunOptions};
use std::path::PathBuf;

fn cpu_s() -> f64 {
    // per-thread CPU time: insensitive to other processes sharing the cores
    let mut ts = libc_timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    unsafe { clock_gettime(3, &mut ts) }; // CLOCK_THREAD_CPUTIME_ID
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

#[repr(C)]
struct libc_timespec {
    tv_sec: i64,
    tv_nsec: i64,
}

extern "C" {
    fn clock_gettime(clk: i32, tp: *mut libc_timespec) -> i32;
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let revs: usize = std::env::var("ROTOR_BENCH_REVS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4);
    let deck = RotorDeck::from_file(&root.join("rotors/uh60a.toml")).unwrap();
    let damper = deck.damper().unwrap();
    let rec = FlightRecord::read(&root.join("flightdata/c8534like.meta.json")).unwrap();
    let opts = RunOptions::default();
    println!("model      revs  steps  iter/step  wall_ms/step  cpu_ms/step  cpu_ms/iter  hydraulics_%  est_75rev_cpu_s");
    for model in [
        DamperModel::Linear,
        DamperModel::Nonlinear,
        DamperModel::Physical,
    ] {
        let mut sim = build(&deck, &damper, model, &rec, &opts).unwrap();
        let n = revs * opts.steps_per_rev;
        let c0 = cpu_s();
        for _ in 0..n {
            sim.step().unwrap();
        }
        let cpu = cpu_s() - c0;
        let t = sim.timing();
        println!(
            "{:<10} {:>4} {:>6} {:>10.2} {:>13.2} {:>12.2} {:>12.2} {:>13.2} {:>16.0}",
            model.name(),
            revs,
            t.steps,
            t.iterations as f64 / t.steps as f64,
            t.total_s / t.steps as f64 * 1e3,
            cpu / t.steps as f64 * 1e3,
            cpu / t.iterations as f64 * 1e3,
            100.0 * t.hydraulics_s / t.total_s,
            cpu / t.steps as f64 * 75.0 * 256.0
        );
    }
}
