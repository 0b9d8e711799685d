//! The structural step of the rotor run does not allocate (the hot loop: residuals, closed-form
//! tangents, the damper's sub-steps, the airload replay, solves with the stored matrix); only
//! a refactorization does, inside faer's supernodal LU. Counted with a wrapping global
//! allocator in this test binary, step by step over a revolution after a warm-up, for full and
//! modified Newton and the physical damper.
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::sim::build_sim;
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions};
use rotorsim::solver::NewtonMethod;
use std::path::PathBuf;

mod alloc_support;
use alloc_support::{allocations, assert_counting};

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

const WARMUP: usize = 512;

#[test]
fn rotor_steps_do_not_allocate() {
    let deck = RotorDeck::from_file(&repo("rotors/uh60a.toml")).unwrap();
    let damper = deck.damper().unwrap();
    let rec = FlightRecord::read(&repo("flightdata/c8534like")).unwrap();
    assert_counting();
    for newton in [NewtonMethod::Modified, NewtonMethod::Full] {
        let opts = RunOptions {
            newton,
            ..RunOptions::default()
        };
        let mut sim = build_sim(
            &deck.spec,
            &deck.path,
            &damper,
            DamperModel::Physical,
            &rec,
            &opts,
        )
        .unwrap();
        let mut ch = vec![0.0; sim.channel_names().len()];
        // warm-up: workspaces reach their size
        for _ in 0..WARMUP {
            sim.step().unwrap();
        }
        let (mut plain, mut refactored) = (0, 0);
        for _ in 0..256 {
            let a0 = allocations();
            let f0 = sim.timing().factorizations;
            sim.step().unwrap();
            sim.channels(&mut ch);
            let allocs = allocations() - a0;
            let f = sim.timing().factorizations - f0;
            if f == 0 {
                plain += 1;
                assert_eq!(
                    allocs, 0,
                    "{newton:?}: a step without refactorization allocated"
                );
            } else {
                // faer's supernodal numeric LU allocates its per-supernode update blocks on
                // every call (~76 here); nothing else in the step does
                refactored += 1;
                assert!(
                    allocs <= 100 * f,
                    "{newton:?}: {allocs} allocations, {f} LU"
                );
            }
        }
        assert!(refactored > 0, "{newton:?}: no refactorization seen");
        if newton == NewtonMethod::Modified {
            assert!(
                plain > 200,
                "{newton:?}: {refactored} of 256 steps refactored"
            );
        }
    }
}

/// The whole rotor on its airframe (one model, factored as a bordered LU of the blades): its
/// steps without a refactorization do not allocate either, solves of the blocks included.
#[test]
fn airframe_steps_do_not_allocate() {
    use rotorsim::hydraulics::DamperDeck;
    use rotorsim::rotor::deck::RotorSpec;
    use rotorsim::rotor::sim::build_rotor_sim;
    let path = repo("rotors/uh60a_airframe.toml");
    let deck = RotorDeck::from_file(&path).unwrap();
    let blades: Vec<(RotorDeck, DamperDeck)> = (1..=deck.spec.rotor.blades)
        .map(|k| {
            let b = deck.blade(k).unwrap();
            let d = b.damper().unwrap();
            (b, d)
        })
        .collect();
    let parts: Vec<(&RotorSpec, &DamperDeck)> = blades.iter().map(|(b, d)| (&b.spec, d)).collect();
    let rec = FlightRecord::read(&repo("flightdata/c8534like")).unwrap();
    assert_counting();
    let opts = RunOptions {
        newton: NewtonMethod::Modified,
        ..RunOptions::default()
    };
    let mut sim = build_rotor_sim(&parts, &path, DamperModel::Physical, &rec, &opts).unwrap();
    let mut ch = vec![0.0; sim.channel_names().len()];
    for _ in 0..WARMUP {
        sim.step().unwrap();
    }
    let mut plain = 0;
    for _ in 0..256 {
        let a0 = allocations();
        let f0 = sim.timing().factorizations;
        sim.step().unwrap();
        sim.channels(&mut ch);
        if sim.timing().factorizations == f0 {
            plain += 1;
            assert_eq!(
                allocations() - a0,
                0,
                "a step without refactorization allocated"
            );
        }
    }
    assert!(plain > 100, "{plain} of 256 steps without refactorization");
}
