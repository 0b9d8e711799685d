//! The default `rotorsim bench` is converged: for every bench command of the README and docs/
//! (rotors/uh60a.toml and rotors/uh60a_damper_design.toml, the default sweep; the guide's
//! `--peak-velocity 6,10 --output-rate 5505`) and for the nominal damper at 0.1 mm and
//! 7.8 rad/s (the small-amplitude case where RK4 at 256 steps per cycle was 8x off), each
//! output of the default run is within 1 % of a run at 4 times its steps per cycle.
//!
//! The reference is the same code (device, harmonic run, first-harmonic integrals) with the
//! step and the hydraulic sub-step 4 times finer, the implicit scheme: it checks that the
//! default has converged in its discretisation (step, sub-step and output sampling), not that
//! the model is right (tests/bench_outputs.rs checks the bench against the dashpot's closed
//! forms, tests/hydraulics_*.rs the elements). The default picks its final steps from its own
//! estimate; the reference is a further 4x, beyond anything the default ran, so an estimate
//! that stopped too early shows here.
use rotorsim::checks::bench::BenchJob;
use rotorsim::hydraulics::bench::{
    harmonic_run_converged, harmonic_run_sampled, Convergence, RunError, IN_TO_M,
};
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};

mod support;
use support::{root, tmp};

/// Runs the default bench of `deck` (physical model) at `omega` and `peak_velocity` in
/// `unit`, then each amplitude at 4x its final steps per cycle, and checks every output to 1 %
/// of its scale ([`RunError::relative`]). Returns the default runs' equivalent damping.
fn check(
    name: &str,
    deck: &str,
    omega: f64,
    peak: &[f64],
    unit: &str,
    output_rate: Option<f64>,
) -> Vec<f64> {
    check_cycles(name, deck, omega, peak, unit, output_rate, 10)
}

/// [`check`] with `cycles` stroking cycles.
fn check_cycles(
    name: &str,
    deck: &str,
    omega: f64,
    peak: &[f64],
    unit: &str,
    output_rate: Option<f64>,
    cycles: usize,
) -> Vec<f64> {
    let out = tmp(name);
    let mut job = BenchJob::new(root().join(deck), out.join("bench"));
    job.cycles = cycles;
    job.damper = Some("physical".into());
    job.omega = omega;
    job.peak_velocity = peak.to_vec();
    job.velocity_unit = unit.into();
    job.output_rate = output_rate;
    let outcome = job.execute(&mut |_, _, _| {}, &mut |_| {}).unwrap();
    let (_, runs) = &outcome.sweep[0];
    let (_, ms) = &outcome.estimates[0];
    assert!(ms.refined, "{name}: the default bench refines");
    assert_eq!(ms.opts.scheme, Scheme::Implicit);
    let d = DamperDeck::from_file(&root().join(deck)).unwrap();
    let dev = d
        .build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Implicit,
                substeps: outcome.substeps,
            },
        )
        .unwrap();
    let mut c_eq = Vec::new();
    for (r, e) in runs.iter().zip(&ms.estimates) {
        assert_eq!(
            e.status,
            Convergence::Converged,
            "{name} at {} m/s",
            r.peak_velocity_m_s
        );
        assert!(e.relative_error <= 2e-3);
        let fine = harmonic_run_sampled(
            dev.as_ref(),
            omega,
            r.peak_velocity_m_s,
            job.cycles,
            4 * r.steps_per_cycle,
            r.samples_per_step,
            false,
        )
        .unwrap();
        let rel = RunError::between(r, &fine, omega, 1.0).relative(&fine);
        eprintln!(
            "{name}: {} m/s, {} steps per cycle, estimated {:.2e}, against 4x {rel:.2e}",
            r.peak_velocity_m_s, r.steps_per_cycle, e.relative_error
        );
        assert!(
            rel <= 0.01,
            "{name} at {} m/s: default ({} steps per cycle) differs from 4x by {rel} of scale",
            r.peak_velocity_m_s,
            r.steps_per_cycle
        );
        let a = r.amplitude_m;
        c_eq.push(r.dissipated_last_cycle_j / (std::f64::consts::PI * omega * a * a));
    }
    c_eq
}

#[test]
fn readme_bench_uh60a_is_converged() {
    check(
        "conv_uh60a",
        "rotors/uh60a.toml",
        27.02,
        &[0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0],
        "in/s",
        None,
    );
}

#[test]
fn guide_bench_fine_output_rate_is_converged() {
    check(
        "conv_fine",
        "rotors/uh60a.toml",
        27.02,
        &[6.0, 10.0],
        "in/s",
        Some(5505.0),
    );
}

#[test]
fn design_deck_bench_is_converged() {
    check(
        "conv_design",
        "rotors/uh60a_damper_design.toml",
        27.02,
        &[0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0],
        "in/s",
        None,
    );
}

/// tests/shipped_examples.rs's bench of every shipped damper deck (goldens
/// tests/golden/examples/*-bench.txt): 1 and 6 in/s, 2 cycles.
#[test]
fn shipped_example_benches_are_converged() {
    for (name, deck) in [
        ("conv_ex_nominal", "flightdata/damper_nominal.toml"),
        ("conv_ex_design", "rotors/uh60a_damper_design.toml"),
    ] {
        check_cycles(name, deck, 27.02, &[1.0, 6.0], "in/s", None, 2);
    }
}

/// The nominal damper deck, the oil alone (no seal friction: the chambers' stiffness makes
/// RK4's sub-steps unconverged at small amplitude).
fn oil_alone() -> String {
    let path = root().join("flightdata/damper_nominal.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        !text.contains("\nseal_friction_N"),
        "the nominal deck has a seal friction"
    );
    path.display().to_string()
}

/// 0.1 mm at 7.8 rad/s on the nominal damper (the oil alone) and on the design deck (with its
/// seal friction): RK4 at 256 steps per cycle and 25 sub-steps (the former default) was 8x off
/// on the oil alone.
#[test]
fn small_amplitude_nominal_damper_is_converged() {
    check("conv_small_oil", &oil_alone(), 7.8, &[7.8e-4], "m/s", None);
    check(
        "conv_small_seal",
        "rotors/uh60a_damper_design.toml",
        7.8,
        &[7.8e-4],
        "m/s",
        None,
    );
}

/// A bench run as asked (RK4, 256 steps per cycle, 25 sub-steps: the former default) is not
/// refined but reports its error from one run at twice the steps: at 0.1 mm and 7.8 rad/s the
/// estimate says the run is far from converged.
#[test]
fn explicit_choice_runs_as_asked_with_its_error() {
    let out = tmp("conv_explicit");
    let mut job = BenchJob::new(oil_alone(), out.join("b"));
    job.omega = 7.8;
    job.peak_velocity = vec![7.8e-4];
    job.velocity_unit = "m/s".into();
    job.scheme = Some("rk4".into());
    let outcome = job.execute(&mut |_, _, _| {}, &mut |_| {}).unwrap();
    let (_, ms) = &outcome.estimates[0];
    let r = &outcome.sweep[0].1[0];
    assert!(!ms.refined);
    assert_eq!((ms.opts.scheme, ms.opts.substeps), (Scheme::Rk4, 25));
    assert_eq!(r.steps_per_cycle, 256);
    assert_eq!(ms.estimates[0].status, Convergence::Estimated);
    assert!(
        ms.estimates[0].relative_error > 0.5,
        "{:?}",
        ms.estimates[0]
    );
    let csv = std::fs::read_to_string(out.join("b/bench_summary.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(
        ",history_file,steps_per_cycle,substeps,scheme,convergence,relative_error,\
peak_force_pos_error_N,peak_force_neg_error_N,K_storage_error_N_per_m,K_loss_error_N_per_m,\
energy_per_cycle_error_J,equivalent_damping_error_N_s_per_m"
    ));
    assert!(csv
        .lines()
        .nth(1)
        .unwrap()
        .contains(",256,25,rk4,estimated,"));
}

/// A run that cannot reach its tolerance within the cap says so.
#[test]
fn refinement_stops_at_its_cap_and_says_so() {
    let d = DamperDeck::from_file(&root().join("flightdata/damper_nominal.toml")).unwrap();
    let dev = d
        .build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Implicit,
                substeps: 4,
            },
        )
        .unwrap();
    let r = harmonic_run_converged(dev.as_ref(), 7.8, 7.8e-4, 2, 64, 1, false, 0.0, 1).unwrap();
    assert_eq!(r.estimate.status, Convergence::NotConverged);
    assert_eq!(r.estimate.steps_per_cycle, 128);
    assert!(r.estimate.relative_error > 0.0);
    let _ = IN_TO_M;
}
