//! The physical damper replayed on a 10,000-sample stroke history at 2 kHz, 25 RK4 sub-steps
//! (what `rotorsim.Damper.force` does): the whole replay with every channel recorded, and the
//! force alone. `cargo bench --bench damper_replay`; figures in docs/performance.md.
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::hydraulics::bench::{replay, replay_force, BenchTest};
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use std::hint::black_box;
use std::path::Path;

/// Two harmonics near the lag frequency and 4/rev, 6 mm and 1.5 mm: relief valves open.
fn history() -> BenchTest {
    let n = 10_000;
    let time_s: Vec<f64> = (0..n).map(|i| i as f64 / 2000.0).collect();
    let stroke_m = time_s
        .iter()
        .map(|t| {
            6e-3 * (2.0 * std::f64::consts::PI * 4.3 * t).sin()
                + 1.5e-3 * (2.0 * std::f64::consts::PI * 17.2 * t).sin()
        })
        .collect();
    BenchTest {
        name: "bench".into(),
        time_s,
        stroke_m,
        force_n: None,
        velocity_m_s: None,
        oil_temperature_k: None,
    }
}

fn damper(c: &mut Criterion) {
    let deck = DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/rotors/uh60a.toml"
    )))
    .unwrap();
    let dev = deck
        .build(DamperModel::Physical, IntegratorOptions::default())
        .unwrap();
    let test = history();
    let mut g = c.benchmark_group("damper_replay");
    g.sample_size(20);
    g.bench_function("replay_10k", |b| {
        b.iter(|| black_box(replay(dev.as_ref(), &test).unwrap()))
    });
    g.bench_function("force_10k", |b| {
        b.iter(|| black_box(replay_force(dev.as_ref(), &test.time_s, &test.stroke_m).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, damper);
criterion_main!(benches);
