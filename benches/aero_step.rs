//! Benchmark: the cost the lifting line adds to the structural step, in one run so that the
//! ratio shares the machine's load. The shipped deck and record, linear damper (the step's
//! structure, not the hydraulics), 256 steps per revolution: one revolution of steps from the
//! same warmed-up state (two revolutions marched first) with the record's airloads replayed
//! (`measured`) and with the lifting line and its inflow (`computed`, `hybrid`).
//!
//! `cargo bench --bench aero_step`
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::aero::AirloadSource;
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions};
use std::path::Path;

fn sim(source: AirloadSource) -> Box<dyn ForcedResponse> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let deck = RotorDeck::from_file(&root.join("rotors/uh60a.toml")).unwrap();
    let record = FlightRecord::read(&root.join("flightdata/c8534like")).unwrap();
    let opts = RunOptions {
        airloads: source,
        // as shooting runs it: no delayed perturbation damping
        perturbation_damping: false,
        ..RunOptions::default()
    };
    let damper = deck.damper().unwrap();
    let mut s =
        rotorsim::rotor::build(&deck, &damper, DamperModel::Linear, &record, &opts).unwrap();
    for _ in 0..2 * opts.steps_per_rev {
        s.step().unwrap();
    }
    s
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("aero_step");
    g.sample_size(10);
    for source in [
        AirloadSource::Measured,
        AirloadSource::Computed,
        AirloadSource::Hybrid,
    ] {
        let mut s = sim(source);
        let start = s.save_state().unwrap();
        g.bench_function(format!("{}_revolution", source.name()), |b| {
            b.iter(|| {
                s.restore_state(&start).unwrap();
                for _ in 0..256 {
                    s.step().unwrap();
                }
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
