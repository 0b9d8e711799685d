//! Benchmark of the paper's bench sweep: 8 amplitudes x 10 cycles x 256 steps per
//! cycle x 25 RK4 sub-steps on the shipped UH-60A-like damper, one thread, no history kept.
//! `cargo bench --bench bench_sweep`; figures in docs/performance.md.
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::hydraulics::bench::{harmonic_sweep, SweepOptions};
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};
use std::hint::black_box;
use std::path::Path;

fn sweep(c: &mut Criterion) {
    let deck = DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/rotors/uh60a.toml"
    )))
    .unwrap();
    let opts = SweepOptions::default();
    let mut g = c.benchmark_group("bench_sweep");
    g.sample_size(10);
    for (name, scheme) in [("rk4_n25", Scheme::Rk4), ("implicit_n25", Scheme::Implicit)] {
        let dev = deck
            .build(
                DamperModel::Physical,
                IntegratorOptions {
                    scheme,
                    substeps: 25,
                },
            )
            .unwrap();
        g.bench_function(name, |b| {
            b.iter(|| black_box(harmonic_sweep(dev.as_ref(), &opts, false).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, sweep);
criterion_main!(benches);
