//! Diagnosis of a 6-test SYNTHETIC bench campaign (8 cycles each, 2 kHz, 1% noise, hidden seal
//! friction): all candidates fitted, ranked and validated. Target: < 30 s on 2 cores.
//! `cargo bench --bench diagnose_campaign`
#[path = "../tests/diagnose_support/mod.rs"]
mod support;
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::diagnose::{diagnose, Cause, DiagnoseOptions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let h = support::hidden(Cause::SealFriction, 0.5);
    let data = support::standard(&h.deck, 8, 2000.0, 1);
    let base = support::nominal_deck();
    let opts = DiagnoseOptions::default();
    let mut g = c.benchmark_group("diagnose_campaign");
    g.sample_size(10);
    g.bench_function("6_tests_8_cycles_2kHz", |b| {
        b.iter(|| {
            let o = diagnose(black_box(&base), black_box(&data), &opts).unwrap();
            assert_eq!(o.diagnosis.cause, "seal_friction");
            o
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
