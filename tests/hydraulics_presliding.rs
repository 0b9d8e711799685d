//! Seal friction with presliding (`seal_presliding_m`): the step law against the exact solution
//! of `dF/ds = (F* - F)/x_p` along the stroke, its tangent against finite differences, its order
//! when the rate varies, the sliding law as the presliding vanishes, and the deck key.
use rotorsim::hydraulics::*;
use std::f64::consts::PI;

mod deck_support;
use deck_support::nominal_text;

fn deck(ext: &str) -> DamperDeck {
    deck_support::deck_with(ext, "deck.toml")
}

#[test]
fn presliding_step_is_exact_at_a_constant_rate() {
    // At a constant rate the force relaxes to the sliding law exponentially in the stroke: the
    // end value against the closed form, the mean against a fine midpoint quadrature of it.
    let f = SealFriction {
        presliding_m: 2.0e-5,
        ..SealFriction::coulomb(500.0)
    };
    for (f0, v, dd) in [
        (500.0, -0.05, -3.0e-5),
        (-200.0, 0.01, 1.0e-5),
        (0.0, 0.2, 4.0e-4),
    ] {
        let target = f.force(v);
        let (end, mean) = f.presliding_step(f0, v, dd);
        let exact = |s: f64| target + (f0 - target) * (-s / 2.0e-5).exp();
        assert!(
            (end - exact(dd.abs())).abs() < 1e-9,
            "{end} vs {}",
            exact(dd.abs())
        );
        let n = 100_000;
        let quad = (0..n)
            .map(|i| exact((i as f64 + 0.5) / n as f64 * dd.abs()))
            .sum::<f64>()
            / n as f64;
        assert!((mean - quad).abs() < 1e-6, "{mean} vs {quad}");
    }
    // No stroke, no change.
    assert_eq!(f.presliding_step(123.0, 0.0, 0.0), (123.0, 123.0));
}

#[test]
fn presliding_tangent_matches_finite_differences() {
    // d(mean force)/d(end stroke) of a step against central differences of the step law, at
    // reversals (small strokes, the force far from the sliding law), mid-stroke and with a
    // Stribeck peak, and below lambda = 1e-4 where M and M' are series; steps in the stroke of 1e-4
    // of the step's own.
    let f = SealFriction {
        f_s: 650.0,
        presliding_m: 2.0e-5,
        ..SealFriction::coulomb(500.0)
    };
    let dt = 5.0e-4;
    let mut checked = 0;
    for &f0 in &[-500.0, -120.0, 0.0, 300.0, 640.0] {
        for &dd in &[
            -4.0e-4, -3.0e-5, -2.0e-6, -1.0e-7, -1.0e-9, 1.0e-9, 1.0e-7, 2.0e-6, 3.0e-5, 4.0e-4,
        ] {
            let an = f.presliding_tangent(f0, dd, dt);
            let h = 1e-4 * dd.abs();
            let mean = |x: f64| f.presliding_step(f0, x / dt, x).1;
            let fd = (mean(dd + h) - mean(dd - h)) / (2.0 * h);
            assert!(
                (an - fd).abs() <= 1e-5 * fd.abs().max(an.abs()) + 1e-3,
                "f0 {f0}, dd {dd:e}: analytic {an:e}, FD {fd:e} N/m"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 50);
}

/// The friction force over the last cycle of a harmonic stroke taken in `n` steps per cycle.
fn cycle(f: SealFriction, n: usize) -> Vec<f64> {
    let (a, w) = (2.0e-4, 27.0);
    let dt = 2.0 * PI / w / n as f64;
    let mut force = 0.0;
    let mut out = Vec::new();
    for i in 0..2 * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let (d0, d1) = (a * (w * t0).sin(), a * (w * t1).sin());
        force = f.presliding_step(force, (d1 - d0) / dt, d1 - d0).0;
        if i >= n {
            out.push(force);
        }
    }
    out
}

#[test]
fn presliding_converges_at_second_order_when_the_rate_varies() {
    // A 0.2 mm stroke at 27 rad/s against 20 um of presliding: the law is exact per step at the
    // step's chord rate, which is the rate at the step's middle to second order in the step.
    let f = SealFriction {
        presliding_m: 2.0e-5,
        ..SealFriction::coulomb(500.0)
    };
    let reference = cycle(f, 64 * 1024);
    let err = |n: usize| {
        let c = cycle(f, n);
        let k = 64 * 1024 / n;
        c.iter()
            .enumerate()
            .map(|(i, x)| (x - reference[(i + 1) * k - 1]).abs())
            .fold(0.0f64, f64::max)
    };
    let (e1, e2) = (err(256), err(512));
    eprintln!("largest error at 256 steps {e1:.3} N, at 512 {e2:.3} N (of 500 N)");
    assert!(e1 < 0.05 * 500.0, "{e1}");
    assert!(e1 / e2 > 3.0 && e1 / e2 < 5.0, "second order: {e1} -> {e2}");
}

#[test]
fn friction_with_vanishing_presliding_is_the_sliding_law() {
    // On the nominal damper at 2 in/s: the device's force with 1 nm of presliding against the
    // memoryless law (a step's stroke, up to 6 um, is thousands of x_p); then the key's
    // round trip and its error without a friction.
    let opts = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 20,
    };
    let run = |ext: &str| {
        let mut dev = deck(ext).build(DamperModel::Physical, opts).unwrap();
        let (a, w, n) = (2.0 * 0.0254 / 27.0, 27.0, 2048);
        let dt = 2.0 * PI / w / n as f64;
        let mut f = Vec::new();
        for i in 0..2 * n {
            let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
            let s = dev
                .trial_step(t0, dt, a * (w * t0).sin(), a * (w * t1).sin())
                .unwrap();
            dev.commit();
            f.push(s.force_end);
        }
        f
    };
    let sliding = run("seal_friction_N = 400.0");
    let tiny = run("seal_friction_N = 400.0\nseal_presliding_m = 1.0e-9");
    let worst = sliding
        .iter()
        .zip(&tiny)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f64, f64::max);
    eprintln!("1 nm of presliding against the sliding law: largest difference {worst:.3} N");
    assert!(worst < 1.0, "{worst} N");
    let d = deck("seal_friction_N = 400.0\nseal_presliding_m = 2.0e-5");
    let back = DamperDeck::from_toml_str(&d.to_toml(), "t").unwrap();
    assert_eq!(back.extensions, d.extensions);
    let e = DamperDeck::from_toml_str(
        &format!(
            "{}\n[damper.physical.extensions]\nseal_presliding_m = 2.0e-5\n",
            nominal_text()
        ),
        "deck.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("seal_presliding_m") && e.contains("seal_friction_N"),
        "{e}"
    );
}
