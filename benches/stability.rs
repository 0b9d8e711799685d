//! Benchmark: ground resonance on the UH-60A-like airframe deck with the physical damper, the
//! linear map over 30 rotor speeds (the damper linearised on the bench at each) and one
//! nonlinear amplitude check (the reduced rotor with four live dampers, started at the default
//! eight stroke amplitudes, side by side on the cores); air resonance in hover on the
//! UH-60A-like hover deck, 30 speeds, physical damper.
//!
//! `cargo bench --bench stability`
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::hydraulics::DamperModel;
use rotorsim::resonance::air::{air_resonance_map, HoverOptions};
use rotorsim::resonance::amplitude::{amplitude_check, AmplitudeOptions};
use rotorsim::resonance::stability_map;
use rotorsim::rotor::RotorDeck;
use std::path::Path;

fn deck_named(name: &str) -> RotorDeck {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    RotorDeck::from_file_with(&root.join("rotors").join(name), &[]).unwrap()
}

fn deck() -> RotorDeck {
    deck_named("uh60a_airframe.toml")
}

fn stability(c: &mut Criterion) {
    let deck = deck();
    let speeds: Vec<f64> = (1..=30).map(|k| 5.0 * k as f64).collect();
    let mut g = c.benchmark_group("stability");
    g.sample_size(10);
    g.bench_function("map_30_speeds_physical", |b| {
        b.iter(|| stability_map(&deck, DamperModel::Physical, &speeds).unwrap())
    });
    let om = deck.spec.rotor.omega_rad_s;
    g.bench_function("amplitude_check_physical", |b| {
        b.iter(|| {
            amplitude_check(
                &deck,
                DamperModel::Physical,
                om,
                &AmplitudeOptions::default(),
            )
            .unwrap()
        })
    });
    let hover = deck_named("uh60a_hover.toml");
    let hover_speeds: Vec<f64> = (0..30).map(|k| 15.0 + 20.0 * k as f64 / 29.0).collect();
    g.bench_function("hover_map_30_speeds_physical", |b| {
        b.iter(|| {
            air_resonance_map(
                &hover,
                DamperModel::Physical,
                &hover_speeds,
                &HoverOptions::default(),
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, stability);
criterion_main!(benches);
