//! The one-ODE link's steps do not allocate (hot loop of every replay of the diagnosis and of the
//! rotor run's hydraulic sub-steps): counted with a wrapping global allocator in this test binary.
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};

mod alloc_support;
use alloc_support::{allocations, assert_counting};

#[test]
fn link_steps_do_not_allocate() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/flightdata/damper_nominal.toml"
    ))
    .unwrap();
    let opts = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 17,
    };
    for ext in [
        "free_play_m = 1.0e-4\nfree_play_contact_stiffness_N_per_m = 1.0e8",
        "mount_stiffness_N_per_m = 1.0e8",
        "free_play_m = 1.0e-4\nfree_play_contact_stiffness_N_per_m = 1.0e8\nlink_mass_kg = 1.0\nlink_damping_ratio = 0.05",
    ] {
        let deck = DamperDeck::from_toml_str(
            &format!("{text}\n[damper.physical.extensions]\n{ext}\n"),
            "link deck",
        )
        .unwrap();
        let mut dev = deck.build(DamperModel::Physical, opts).unwrap();
        let (a, w, dt) = (5.0e-3, 27.02, 5.0e-4);
        let d = |t: f64| a * (w * t).sin();
        // One step first: the device settles its link from its initial force.
        dev.trial_step(0.0, dt, d(0.0), d(dt)).unwrap();
        dev.commit();
        assert_counting();
        let before = allocations();
        let mut acc = 0.0;
        for i in 1..2000 {
            let t = i as f64 * dt;
            let s = dev.trial_step(t, dt, d(t), d(t + dt)).unwrap();
            dev.commit();
            acc += s.force_end + s.force_mean + s.dforce_dstroke;
        }
        assert!(acc.is_finite());
        assert_eq!(allocations(), before, "{ext}: a step allocated");
    }
}
