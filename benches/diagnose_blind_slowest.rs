//! The three slowest campaigns of the diagnosis' blind suites, both truth models (SYNTHETIC,
//! docs/diagnosis.md "Blind suite"; slowest in their timing columns). Each is diagnosed as the
//! suite does (the first truth's campaigns at 4 cycles per harmonic test, 2 kHz; the second
//! truth's on their own bench programme); the data are generated once, outside the timing.
//! Target: < 30 s each on a quiet 2-core machine.
//! `cargo bench --bench diagnose_blind_slowest`
#[path = "../tests/blind_support/mod.rs"]
mod blind;
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::diagnose::{diagnose, DiagnoseOptions};
use rotorsim::hydraulics::DamperDeck;
use std::hint::black_box;
use std::path::Path;

/// The slowest three of the suite's last quiet run.
const SLOWEST: [&str; 3] = ["pair_6", "pair_0", "t2_pair_1"];

fn bench(c: &mut Criterion) {
    let base = DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/flightdata/damper_nominal.toml"
    )))
    .expect("nominal deck");
    let opts = DiagnoseOptions::default();
    let mut g = c.benchmark_group("diagnose_blind_slowest");
    g.sample_size(10);
    for id in SLOWEST {
        let cp = blind::suite()
            .into_iter()
            .chain(blind::suite2())
            .find(|c| c.id == id)
            .expect("campaign");
        let data = blind::bench_campaign(&cp, 4, 2000.0).expect("campaign data");
        let base = cp.base_deck(&base);
        g.bench_function(id, |b| {
            b.iter(|| diagnose(black_box(&base), black_box(&data), &opts).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
