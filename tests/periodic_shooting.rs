//! Periodic solutions by shooting (docs/periodic.md): Floquet multipliers against the
//! analytic roots of a rigid lag hinge, and the shooting solution against a 200-revolution
//! march for the rigid reduction (64 steps per revolution) and the elastic model (128: at 64 its
//! Newton diverges in the transient), all three damper models, the hydraulic sub-step kept at
//! that of 256 x 25.
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::{DamperModel, IntegratorOptions};
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions};
use rotorsim::run::sdof::{rigid_reduction, LagHingeSdof, SdofParams};
use rotorsim::run::{drive_periodic, PeriodicOptions};
mod support;
use support::root;

const MODELS: [DamperModel; 3] = [
    DamperModel::Linear,
    DamperModel::Nonlinear,
    DamperModel::Physical,
];

/// Elastic-model options at 128 steps per revolution (hydraulic sub-step as at 256 x 25).
fn elastic_opts(perturbation_damping: bool) -> RunOptions {
    RunOptions {
        steps_per_rev: 128,
        hydraulics: IntegratorOptions {
            substeps: 50,
            ..Default::default()
        },
        perturbation_damping,
        ..Default::default()
    }
}

fn setup() -> (RotorDeck, FlightRecord) {
    let deck = RotorDeck::from_file(&root().join("rotors/uh60a.toml")).unwrap();
    let rec = FlightRecord::read(&root().join("flightdata/c8534like")).unwrap();
    (deck, rec)
}

/// `I z'' + C z' + K z = M(t)` with the linear dashpot: the lag-hinge model integrates it by
/// the trapezoidal rule, so its monodromy matrix over N steps has the eigenvalues
/// `((1 + h s/2) / (1 - h s/2))^N`, s the roots of `I s^2 + C s + K`, and tends to `e^{sT}`.
#[test]
fn floquet_multipliers_of_a_rigid_lag_hinge_match_the_analytic_roots() {
    let (deck, rec) = setup();
    let damper = deck.damper().unwrap();
    let p = SdofParams::from_rotor(&deck.spec, &deck.path, &rec).unwrap();
    let c_dashpot = damper.linear_c_n_s_per_m.unwrap();
    let (i, k) = (
        p.inertia_kg_m2,
        p.hinge_offset_m * p.first_moment_kg_m * p.omega_rad_s.powi(2) + p.lag_spring_n_m_per_rad,
    );
    let c = p.lag_damping_n_m_s_per_rad + p.damper_arm_m.powi(2) * c_dashpot;
    let steps = 1024;
    let period = 2.0 * std::f64::consts::PI / p.omega_rad_s;
    let h = period / steps as f64;
    let mut sim = LagHingeSdof::new(
        p,
        &damper,
        DamperModel::Linear,
        IntegratorOptions::default(),
        steps,
    )
    .unwrap();
    let o = PeriodicOptions {
        min_floquet_dirs: 2,
        ..PeriodicOptions::shooting(1e-9, 40)
    };
    let run = drive_periodic(&mut sim, DamperModel::Linear, &o, &|_, _| {}).unwrap();
    assert!(run.converged(), "{:?}", run.periodic);
    let mu = &run.periodic.floquet_multipliers[0];
    // roots: s = -C/2I +- i sqrt(K/I - (C/2I)^2)
    let (sr, si) = (-c / (2.0 * i), (k / i - (c / (2.0 * i)).powi(2)).sqrt());
    let cont = (
        (sr * period).exp() * (si * period).cos(),
        (sr * period).exp() * (si * period).sin(),
    );
    // discrete: z = (1 + h s/2) / (1 - h s/2), then z^N
    let (ar, ai) = (1.0 + 0.5 * h * sr, 0.5 * h * si);
    let (br, bi) = (1.0 - 0.5 * h * sr, -0.5 * h * si);
    let d = br * br + bi * bi;
    let (zr, zi) = ((ar * br + ai * bi) / d, (ai * br - ar * bi) / d);
    let (mag, arg) = (zr.hypot(zi).powi(steps as i32), zi.atan2(zr) * steps as f64);
    let disc = (mag * arg.cos(), mag * arg.sin().abs());
    let err = |a: (f64, f64)| (mu.re - a.0).hypot(mu.im.abs() - a.1.abs());
    eprintln!(
        "multiplier {} {:+}i, discrete {:?} ({:.1e}), continuous {:?} ({:.1e}), damping ratio {}",
        mu.re,
        mu.im,
        disc,
        err(disc),
        cont,
        err(cont),
        mu.damping_ratio
    );
    // the map is affine: the multiplier is exact up to rounding in the finite differences
    // the map is affine: exact up to the finite differences, whose error is the lag-hinge
    // Newton tolerance (1e-12 rad) over the step (1e-4): 1e-8
    assert!(err(disc) < 1e-8, "discrete: {}", err(disc));
    // and the trapezoidal rule at 1024 steps per revolution is within ~5e-7 of e^{sT}
    assert!(err(cont) < 1e-6, "continuous: {}", err(cont));
    let zeta = -sr / sr.hypot(si);
    assert!(
        (mu.damping_ratio - zeta).abs() < 1e-5,
        "{} vs {zeta}",
        mu.damping_ratio
    );
    assert_eq!(mu.mode, "lag");
}

/// Shooting at tolerance `tol` against a 200-revolution march (perturbation damping on):
/// within 1e-4 of every monitored channel's peak-to-peak.
fn check_against_march(
    name: &str,
    tol: f64,
    build: &dyn Fn(DamperModel, bool) -> Box<dyn ForcedResponse>,
) {
    for model in MODELS {
        let mut sim = build(model, true);
        let march = drive_periodic(
            sim.as_mut(),
            model,
            &PeriodicOptions::march(200),
            &|_, _| {},
        )
        .unwrap();
        let mut sim = build(model, false);
        let shot = drive_periodic(
            sim.as_mut(),
            model,
            &PeriodicOptions::shooting(tol, 75),
            &|_, _| {},
        )
        .unwrap();
        let (d, worst) = shot.difference_from(&march).unwrap();
        eprintln!(
            "{name} {}: shooting {} revolutions, residual {:.2e}, estimated distance {:.2e}; march residual {:.2e}; difference {d:.2e} ({worst})",
            model.name(),
            shot.periodic.revolutions_integrated,
            shot.periodic.residual,
            shot.periodic.error_estimate.unwrap_or(f64::NAN),
            march.periodic.residual
        );
        assert!(
            shot.converged(),
            "{name} {}: {:?}",
            model.name(),
            shot.periodic
        );
        assert!(shot.periodic.residual < tol);
        assert!(
            d < 1e-4,
            "{name} {}: shooting differs from the 200-revolution march by {d:.2e} of the peak-to-peak ({worst})",
            model.name()
        );
    }
}

#[test]
fn shooting_matches_a_200_revolution_march_rigid_reduction() {
    let (deck, rec) = setup();
    let damper = deck.damper().unwrap();
    check_against_march("rigid", 1e-4, &|m, _| {
        let opts = RunOptions {
            steps_per_rev: 64,
            hydraulics: IntegratorOptions {
                substeps: 100,
                ..Default::default()
            },
            ..Default::default()
        };
        Box::new(rigid_reduction(&deck, &damper, m, &rec, &opts).unwrap())
    });
}

#[test]
fn shooting_matches_a_200_revolution_march_elastic_model() {
    let (deck, rec) = setup();
    let damper = deck.damper().unwrap();
    // the first flap mode is nearly neutral under prescribed airloads (|mu| 0.997: no
    // aerodynamic damping, and the bearing's loss factor acts on the 1.3% of the flap
    // stiffness its spring gives), so a residual of 1e-4 leaves up to 1.2e-4 of tip flap:
    // the solver is held to the march at a tenth of the run's tolerance (docs/periodic.md)
    check_against_march("elastic", 1e-5, &|m, damping| {
        rotorsim::rotor::build(&deck, &damper, m, &rec, &elastic_opts(damping)).unwrap()
    });
}

/// A run started from its own saved periodic state is periodic from the first revolution.
#[test]
fn warm_start_from_a_saved_state_is_periodic_at_once() {
    let (deck, rec) = setup();
    let damper = deck.damper().unwrap();
    let opts = elastic_opts(false);
    let m = DamperModel::Physical;
    let mut sim = rotorsim::rotor::build(&deck, &damper, m, &rec, &opts).unwrap();
    let first = drive_periodic(
        sim.as_mut(),
        m,
        &PeriodicOptions::shooting(1e-4, 75),
        &|_, _| {},
    )
    .unwrap();
    assert!(first.converged());
    let file = rotorsim::run::PeriodicStateFile {
        format: rotorsim::run::periodic::STATE_FORMAT.into(),
        model: first.model.clone(),
        label: first.label.clone(),
        steps_per_rev: 128,
        period_s: first.period_s,
        converged: true,
        residual: first.periodic.residual,
        inputs_sha256: None,
        overrides: vec![],
        state: first.periodic_state.clone().unwrap(),
    };
    let json = serde_json::to_string(&file).unwrap();
    let back: rotorsim::run::PeriodicStateFile = serde_json::from_str(&json).unwrap();
    let mut sim = rotorsim::rotor::build(&deck, &damper, m, &rec, &opts).unwrap();
    let o = PeriodicOptions {
        initial_state: Some(back),
        ..PeriodicOptions::shooting(1e-4, 75)
    };
    let warm = drive_periodic(sim.as_mut(), m, &o, &|_, _| {}).unwrap();
    assert!(warm.converged(), "{:?}", warm.periodic);
    assert_eq!(
        warm.periodic.revolutions_integrated, 1,
        "{:?}",
        warm.periodic
    );
    let (d, worst) = warm.difference_from(&first).unwrap();
    assert!(d < 1e-4, "warm start differs by {d:.2e} ({worst})");
}
