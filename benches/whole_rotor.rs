//! Benchmark: the whole rotor on a driven hub (`rotorsim run --all-blades`) against the
//! single-blade run, in one run so that the ratios share the machine's load: the shipped deck
//! and record, physical damper, 256 steps x 25 RK4 sub-steps, a fixed work of 8 marched
//! revolutions (the revolutions to a periodic solution differ between blades and runs; the
//! cost per revolution does not). Each sample is a whole run, built, integrated and written.
//! 8 blades: the same deck with `rotor.blades = 8` and a copy of the record saying so.
//!
//! `cargo bench --bench whole_rotor`
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::hydraulics::DamperModel;
use rotorsim::overrides::Override;
use rotorsim::run::job::{DamperChoice, RunJob};
use rotorsim::run::periodic::PeriodicMethod;
use rotorsim::run::Silent;
use std::path::{Path, PathBuf};

const REVS: usize = 8;

/// The shipped record with `number_of_blades` set to `n`, in `dir`.
fn record_with_blades(dir: &Path, n: usize) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("flightdata");
    std::fs::create_dir_all(dir).unwrap();
    for ext in ["airloads.csv", "damper.csv"] {
        let f = format!("c8534like.{ext}");
        std::fs::copy(src.join(&f), dir.join(&f)).unwrap();
    }
    let meta = std::fs::read_to_string(src.join("c8534like.meta.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&meta).unwrap();
    v["number_of_blades"] = n.into();
    std::fs::write(
        dir.join("c8534like.meta.json"),
        serde_json::to_string_pretty(&v).unwrap(),
    )
    .unwrap();
    dir.join("c8534like")
}

fn job(blades: Option<usize>, record: &Path, out: &Path) -> RunJob {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    RunJob {
        rotor: root.join("rotors/uh60a.toml"),
        flight: record.to_path_buf(),
        damper: DamperChoice::One(DamperModel::Physical),
        periodic: PeriodicMethod::March,
        revs: REVS,
        all_blades: blades.is_some(),
        overrides: blades
            .filter(|n| *n != 4)
            .map(|n| vec![Override::parse(&format!("rotor.blades={n}")).unwrap()])
            .unwrap_or_default(),
        ..RunJob::new(out)
    }
}

fn bench(c: &mut Criterion) {
    let tmp = std::env::temp_dir().join(format!("rotorsim-bench-whole-{}", std::process::id()));
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("flightdata/c8534like");
    let eight = record_with_blades(&tmp.join("record8"), 8);
    let mut g = c.benchmark_group("whole_rotor");
    g.sample_size(10);
    for (name, blades, record) in [
        ("single_blade", None, &shipped),
        ("4_blades", Some(4), &shipped),
        ("8_blades", Some(8), &eight),
    ] {
        let out = tmp.join(name);
        let j = job(blades, record, &out);
        g.bench_function(name, |b| {
            b.iter(|| {
                let o = j.execute(&Silent).unwrap();
                assert!(o.failed.is_empty());
            })
        });
    }
    g.finish();
    let _ = std::fs::remove_dir_all(&tmp);
}

criterion_group!(benches, bench);
criterion_main!(benches);
