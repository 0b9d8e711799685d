//! The extensions of the hydraulic library (seal friction, free play, entrained air, ...) against
//! analytic results, their analytic Jacobian against finite differences, and the deck keys (defaults off: bit-for-bit the same).
use rotorsim::hydraulics::bench::{harmonic_run, replay, BenchTest};
use rotorsim::hydraulics::circuit::{State, IP0, IP1, NS};
use rotorsim::hydraulics::*;

mod deck_support;
use deck_support::nominal_text;

fn deck_with(ext: &str) -> DamperDeck {
    deck_support::deck_with(ext, "test deck")
}

fn opts() -> IntegratorOptions {
    IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 40,
    }
}

fn sealed(fluid: Fluid, p: [f64; 2]) -> CircuitParams {
    let ch = |lambda| Chamber {
        area: 1.6e-3,
        volume0: 6.0e-5,
        lambda,
    };
    CircuitParams {
        fluid,
        dp_laminar: 1e3,
        chambers: [ch(1.0), ch(-1.0)],
        orifice: None,
        relief: [None, None],
        check: None,
        entrance: None,
        p_s: 5.0e5,
        p_init: p,
        ext: HydraulicExtensions::default(),
    }
}

#[test]
fn default_extensions_are_bit_for_bit_the_paper_model() {
    let plain = DamperDeck::from_toml_str(&nominal_text(), "plain").unwrap();
    let zero = deck_with(
        "seal_friction_N = 0.0\nfree_play_m = 0.0\nair_fraction = 0.0\nleakage_m3_per_s_Pa = 0.0",
    );
    assert_eq!(plain.physical, zero.physical);
    for v in [0.02, 0.1] {
        let a = harmonic_run(
            plain.build(DamperModel::Physical, opts()).unwrap().as_ref(),
            27.02,
            v,
            3,
            256,
            true,
        )
        .unwrap();
        let b = harmonic_run(
            zero.build(DamperModel::Physical, opts()).unwrap().as_ref(),
            27.02,
            v,
            3,
            256,
            true,
        )
        .unwrap();
        assert_eq!(a.history.force_n, b.history.force_n);
        assert_eq!(a.history.channels, b.history.channels);
    }
    // A deck without the table writes no extension table and reads back identically.
    let back = DamperDeck::from_toml_str(&plain.to_toml(), "back").unwrap();
    assert!(!plain.to_toml().contains("extensions"));
    assert_eq!(back.physical, plain.physical);
    assert_eq!(back.linear_c_n_s_per_m, plain.linear_c_n_s_per_m);
    assert_eq!(back.nonlinear, plain.nonlinear);
}

#[test]
fn written_deck_reads_back_with_every_extension() {
    let d = deck_with(
        "seal_friction_N = 321.5\nstribeck_static_N = 400.0\nfree_play_m = 2.5e-4\nair_fraction = 0.013\nleakage_m3_per_s_Pa = 7.0e-12\nleakage_viscosity_length_Pa_s_m = 7.5e-4\nair_fraction_1 = 0.05\naccumulator_bleed_m3_per_s_Pa = 2.0e-12",
    );
    let back = DamperDeck::from_toml_str(&d.to_toml(), "back").unwrap();
    assert_eq!(back.physical, d.physical);
    assert_eq!(back.extensions, d.extensions);
    assert_eq!(back.extensions.friction.unwrap().f_s, 400.0);
}

#[test]
fn bad_extension_keys_are_named() {
    let text = format!(
        "{}\n[damper.physical.extensions]\nair_fraction = 1.5\n",
        nominal_text()
    );
    let e = DamperDeck::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("damper.physical.extensions.air_fraction"), "{e}");
    let text = format!(
        "{}\n[damper.physical.extensions]\nfriction_N = 1.0\n",
        nominal_text()
    );
    let e = DamperDeck::from_toml_str(&text, "x.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("unknown key") && e.contains("seal_friction_N"),
        "{e}"
    );
}

/// Constant-velocity stroking (after a settling ramp): friction adds exactly -F_c sign(v).
#[test]
fn coulomb_friction_adds_exactly_fc_in_steady_stroking() {
    let plain = DamperDeck::from_toml_str(&nominal_text(), "plain").unwrap();
    let fric = deck_with("seal_friction_N = 412.0");
    for v in [0.03, -0.03] {
        let n = 400;
        let dt = 1e-4;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let test = BenchTest {
            name: "ramp".into(),
            stroke_m: t.iter().map(|t| v * t).collect(),
            time_s: t,
            force_n: None,
            velocity_m_s: None,
            oil_temperature_k: None,
        };
        let a = replay(
            plain.build(DamperModel::Physical, opts()).unwrap().as_ref(),
            &test,
        )
        .unwrap();
        let b = replay(
            fric.build(DamperModel::Physical, opts()).unwrap().as_ref(),
            &test,
        )
        .unwrap();
        for k in 10..n {
            let d = b.force_model_n[k] - a.force_model_n[k];
            assert!(
                (d + 412.0 * v.signum()).abs() < 1e-9,
                "v {v}, sample {k}: friction force {d}"
            );
        }
    }
}

/// Free play: zero force while the stroke is inside the gap, the plain damper's force (of the
/// piston stroke, shifted by half the gap) once it is taken up.
#[test]
fn free_play_transmits_no_force_inside_the_gap() {
    let gap = 0.4e-3;
    let dk = deck_with(&format!("free_play_m = {gap}"));
    let dev = dk.build(DamperModel::Physical, opts()).unwrap();
    let n = 2000;
    let dt = 1e-4;
    let a = 1.0e-3;
    let w = 2.0 * std::f64::consts::PI / (n as f64 * dt);
    let t: Vec<f64> = (0..=n).map(|k| k as f64 * dt).collect();
    let d: Vec<f64> = t.iter().map(|t| a * (w * t).sin()).collect();
    let test = BenchTest {
        name: "play".into(),
        time_s: t.clone(),
        stroke_m: d.clone(),
        force_n: None,
        velocity_m_s: None,
        oil_temperature_k: None,
    };
    let r = replay(dev.as_ref(), &test).unwrap();
    // After the peak (k = n/4) the stroke turns back: inside the gap until it has come back by
    // the whole gap, d < a - gap.
    let mut inside = 0;
    for (k, &dk) in d.iter().enumerate().take(n / 2).skip(n / 4 + 1) {
        if dk > a - gap + 1e-9 {
            assert_eq!(r.force_model_n[k], 0.0, "sample {k}, stroke {dk}");
            inside += 1;
        } else if dk < a - gap - 2e-6 {
            assert!(
                r.force_model_n[k] > 0.0,
                "sample {k}: contact, pushing back"
            );
        }
    }
    assert!(inside > 50, "{inside} samples inside the gap");
}

/// Leakage of a sealed pair held still: dp = p0 - p1 decays as exp(-t/tau),
/// tau = 1 / (k B (1/V0 + 1/V1)) in the linear regime (dp << B; B of Eq. 3 at the mean
/// pressure, `B = 1/alpha + p` for beta = 0).
#[test]
fn leakage_decays_exponentially_with_the_analytic_time_constant() {
    let fluid = Fluid::constant_bulk(850.0, 1.5e9);
    let b = fluid.bulk(5.0e5).0;
    let k = 1.0e-12;
    let dp0 = 2.0e3;
    let mut p = sealed(fluid, [5.0e5 + dp0 / 2.0, 5.0e5 - dp0 / 2.0]);
    p.ext.leakage = Some(AnnularLeakage::laminar(k));
    let tau = 1.0 / (k * b * (2.0 / 6.0e-5));
    let mut dev = CircuitDevice::new(p, opts());
    let dt = tau / 50.0;
    for step in 1..=100 {
        dev.trial_step((step - 1) as f64 * dt, dt, 0.0, 0.0)
            .unwrap();
        dev.commit();
        let y = dev.state();
        let expect = dp0 * (-(step as f64) * dt / tau).exp();
        assert!(
            ((y[IP0] - y[IP1]) - expect).abs() < 1e-6 * dp0,
            "step {step}: {} vs {expect}",
            y[IP0] - y[IP1]
        );
        // Mass is conserved: the mean pressure stays.
        assert!(((y[IP0] + y[IP1]) / 2.0 - 5.0e5).abs() < 1e-6 * dp0);
    }
}

/// Annular leakage of a sealed pair stroked at constant velocity w: once the transient has
/// died (time constant 1 / (k B (1/V0 + 1/V1))) the leakage carries the swept flow,
/// `k dp + c w = -A w`, so `dp = -(A + c) w / k` with the Couette flow per unit velocity
/// `c = pi D h / 2` and `h = (12 mu L k / (pi D))^(1/3)` (Merritt 1967, Sec. 2.4), written out
/// here from the geometry. Without the drag (mu L = 0) the balance is `dp = -A w / k`.
#[test]
fn annular_leakage_at_constant_velocity_carries_the_swept_and_the_drag_flow() {
    let fluid = Fluid::constant_bulk(850.0, 1.5e9);
    let (k, mu_l, w, area) = (1.0e-10, 7.5e-4, 0.01, 1.6e-3);
    let tau = 1.0 / (k * fluid.bulk(5.0e5).0 * (2.0 / 6.0e-5));
    let d = 2.0 * (area / std::f64::consts::PI).sqrt();
    let h = (12.0 * mu_l * k / (std::f64::consts::PI * d)).cbrt();
    let c = 0.5 * std::f64::consts::PI * d * h;
    let steady = |mu_l: f64| {
        let mut p = sealed(fluid, [5.0e5; 2]);
        p.ext.leakage = Some(AnnularLeakage {
            conductance: k,
            viscosity_length: mu_l,
        });
        let mut dev = CircuitDevice::new(p, opts());
        // 12 time constants: the transient is down to exp(-12) = 6e-6.
        let n = 1200;
        let dt = 12.0 * tau / n as f64;
        for i in 0..n {
            let t = i as f64 * dt;
            dev.trial_step(t, dt, w * t, w * (t + dt)).unwrap();
            dev.commit();
        }
        let y = dev.state();
        y[IP0] - y[IP1]
    };
    let (with, without) = (steady(mu_l), steady(0.0));
    let (expect, laminar) = (-(area + c) * w / k, -area * w / k);
    assert!(
        (with / expect - 1.0).abs() < 2e-5,
        "dp {with} Pa, Poiseuille + Couette {expect} Pa"
    );
    assert!(
        (without / laminar - 1.0).abs() < 2e-5,
        "dp {without} Pa, Poiseuille {laminar} Pa"
    );
    // The drag is resolved: c / A = 0.9% here, far beyond the tolerance.
    assert!(c / area > 100.0 * 2e-5, "c/A = {}", c / area);
    assert_eq!(
        AnnularLeakage {
            conductance: k,
            viscosity_length: mu_l
        }
        .clearance(area),
        h
    );
}

/// The drag flow moves with the piston, so a damper behind a link (a very stiff mount, with and
/// without a moving mass) sees it as the rigid damper does.
#[test]
fn annular_leakage_drag_reaches_the_damper_behind_a_link() {
    let leak = "leakage_m3_per_s_Pa = 2.0e-11\nleakage_viscosity_length_Pa_s_m = 5.0e-3";
    let (a, w, n) = (2.0 * 0.0254 / 27.0, 27.0, 1024);
    let run = |ext: &str| -> Vec<f64> {
        let deck = deck_with(ext);
        let mut dev = deck.build(DamperModel::Physical, opts()).unwrap();
        let dt = 2.0 * std::f64::consts::PI / w / n as f64;
        let mut out = Vec::new();
        for i in 0..3 * n {
            let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
            let s = dev
                .trial_step(t0, dt, a * (w * t0).sin(), a * (w * t1).sin())
                .unwrap();
            dev.commit();
            if i >= 2 * n {
                out.push(s.force_end);
            }
        }
        out
    };
    let rms = |x: &[f64], y: &[f64]| {
        (x.iter().zip(y).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / x.len() as f64).sqrt()
    };
    let rigid = run(leak);
    let no_drag = run("leakage_m3_per_s_Pa = 2.0e-11");
    let drag = rms(&rigid, &no_drag);
    let peak = rigid.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    assert!(
        drag > 1e-3 * peak,
        "the drag changes the force by {drag} N RMS of a {peak} N peak"
    );
    for link in [
        "mount_stiffness_N_per_m = 1.0e11",
        "mount_stiffness_N_per_m = 1.0e11\nlink_mass_kg = 1.0e-3",
    ] {
        let linked = run(&format!("{leak}\n{link}"));
        let d = rms(&linked, &rigid);
        eprintln!("{link}: {d:.3} N RMS from the rigid damper (drag {drag:.1} N of {peak:.0} N)");
        assert!(
            d < 0.05 * drag,
            "{link}: {d} N RMS from the rigid damper (drag {drag} N)"
        );
    }
}

/// Entrained air: a sealed chamber compressed follows the mixture's sealed-volume law
/// `V/V_ref = (1 - a0) c_l(p_ref)/c_l(p) + a0 p_ref/p` (isothermal air, Eq. 3 liquid).
#[test]
fn entrained_air_sealed_compression_matches_the_mixture_law() {
    for beta in [0.0, 2.0e-18] {
        let fluid = Fluid {
            rho: 850.0,
            alpha: 6.667e-10,
            beta,
            p_cav: 0.0,
        };
        let air = EntrainedAir {
            fraction: 0.02,
            p_ref: 5.0e5,
        };
        let mut p = sealed(fluid, [5.0e5; 2]);
        p.ext.air = Some(air);
        let mut dev = CircuitDevice::new(p.clone(), opts());
        let n = 200;
        let d_end = -1.0e-3; // chamber 0 shrinks by 1.6e-6 m^3 (2.7%)
        for k in 0..n {
            let (a, b) = (
                d_end * k as f64 / n as f64,
                d_end * (k + 1) as f64 / n as f64,
            );
            dev.trial_step(k as f64 * 1e-4, 1e-4, a, b).unwrap();
            dev.commit();
        }
        let c = &p.chambers[0];
        let ratio = c.volume(d_end) / c.volume0;
        let p0 = dev.state()[IP0];
        let got = air.sealed_volume_ratio(&fluid, p0);
        assert!(
            (got - ratio).abs() < 1e-8,
            "beta {beta}: V/V0 at p0 = {p0} is {got}, chamber {ratio}"
        );
        // Air makes it softer than the oil alone.
        let oil = fluid.sealed_pressure(5.0e5, c.volume0, c.volume(d_end));
        assert!(p0 < 0.5 * oil, "{p0} vs oil only {oil}");
    }
}

#[test]
fn extension_jacobian_matches_finite_differences() {
    let mut p = DamperDeck::from_toml_str(&nominal_text(), "n")
        .unwrap()
        .physical
        .unwrap();
    // with the drag flow, which shifts each chamber's net inflow
    p.ext.leakage = Some(AnnularLeakage {
        conductance: 5e-12,
        viscosity_length: 1e-3,
    });
    p.ext.air = Some(EntrainedAir {
        fraction: 0.03,
        p_ref: 5.0e5,
    });
    p.ext.air_by_chamber[1] = Some(EntrainedAir {
        fraction: 0.08,
        p_ref: 5.0e5,
    });
    p.ext.bleed = Some(Leakage { conductance: 3e-12 });
    for (p0, p1) in [(3.0e6, 2.0e5), (6.0e5, 4.0e5), (5.0e4, 8.0e6)] {
        let mut y = State::zeros();
        y[IP0] = p0;
        y[IP1] = p1;
        let (_, j, _) = p.evaluate::<true>(0.0, 1e-3, 0.05, &y, None).unwrap();
        for c in [IP0, IP1] {
            let h = 1e-3 * (1.0 + y[c].abs() * 1e-6);
            let (mut yp, mut ym) = (y, y);
            yp[c] += h;
            ym[c] -= h;
            let fp = p.evaluate::<false>(0.0, 1e-3, 0.05, &yp, None).unwrap().0;
            let fm = p.evaluate::<false>(0.0, 1e-3, 0.05, &ym, None).unwrap().0;
            for r in 0..NS {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                let an = j[(r, c)];
                let scale = an.abs().max(fd.abs()).max(1e-12);
                assert!(
                    (fd - an).abs() <= 1e-5 * scale + 1e-9,
                    "p = ({p0}, {p1}): J[{r},{c}] analytic {an:e} vs FD {fd:e}"
                );
            }
        }
    }
}

/// Accumulator bleed of a sealed chamber held still: p - p_s decays as exp(-t/tau),
/// tau = V / (k B) in the linear regime.
#[test]
fn accumulator_bleed_relaxes_to_p_s_with_the_analytic_time_constant() {
    let fluid = Fluid::constant_bulk(850.0, 1.5e9);
    let dp0 = 2.0e3;
    let mut p = sealed(fluid, [5.0e5 + dp0, 5.0e5 - dp0]);
    let k = 1.0e-12;
    p.ext.bleed = Some(Leakage { conductance: k });
    let b = fluid.bulk(5.0e5).0;
    let tau = 6.0e-5 / (k * b);
    let mut dev = CircuitDevice::new(p, opts());
    let dt = tau / 50.0;
    for step in 1..=100 {
        dev.trial_step((step - 1) as f64 * dt, dt, 0.0, 0.0)
            .unwrap();
        dev.commit();
        let y = dev.state();
        let e = dp0 * (-(step as f64) * dt / tau).exp();
        assert!(
            (y[IP0] - 5.0e5 - e).abs() < 1e-6 * dp0,
            "step {step}: {}",
            y[IP0]
        );
        assert!(
            (y[IP1] - 5.0e5 + e).abs() < 1e-6 * dp0,
            "step {step}: {}",
            y[IP1]
        );
    }
}

/// Air in chamber 1 only: chamber 0 follows the oil's Eq. (3), chamber 1 the mixture law.
#[test]
fn air_by_chamber_acts_on_its_chamber_only() {
    let fluid = Fluid {
        rho: 850.0,
        alpha: 6.667e-10,
        beta: 0.0,
        p_cav: 0.0,
    };
    let air = EntrainedAir {
        fraction: 0.05,
        p_ref: 5.0e5,
    };
    let mut p = sealed(fluid, [5.0e5; 2]);
    p.ext.air_by_chamber[1] = Some(air);
    let mut dev = CircuitDevice::new(p.clone(), opts());
    let d_end = 1.0e-3; // chamber 0 grows, chamber 1 shrinks
    for k in 0..200 {
        let (a, b) = (d_end * k as f64 / 200.0, d_end * (k + 1) as f64 / 200.0);
        dev.trial_step(k as f64 * 1e-4, 1e-4, a, b).unwrap();
        dev.commit();
    }
    let c = &p.chambers;
    let p0 = fluid.sealed_pressure(5.0e5, c[0].volume0, c[0].volume(d_end));
    assert!((dev.state()[IP0] - p0).abs() < 1e-6 * p0.abs().max(1e5));
    let ratio = c[1].volume(d_end) / c[1].volume0;
    assert!((air.sealed_volume_ratio(&fluid, dev.state()[IP1]) - ratio).abs() < 1e-8);
}

/// Elastic mount in series with a linear dashpot is a Maxwell element: under `d = A sin(wt)` the
/// steady force is `F = -c w A cos(wt - phi) / sqrt(1 + (c w/k)^2)`, `phi = atan(c w/k)` lag.
#[test]
fn series_mount_with_a_dashpot_is_a_maxwell_element() {
    let (c, k, a, w) = (1.0e5, 2.0e7, 2.0e-3, 27.0);
    let mut dev = SeriesMount::new(Box::new(LinearDashpot::new(c)), k);
    let period = 2.0 * std::f64::consts::PI / w;
    let n = 20_000;
    let dt = period / n as f64;
    let cycles = 3;
    let (mut sc, mut ss) = (0.0, 0.0);
    for i in 0..cycles * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let sf = dev
            .trial_step(t0, dt, a * (w * t0).sin(), a * (w * t1).sin())
            .unwrap();
        dev.commit();
        if i >= (cycles - 1) * n {
            // The step's force belongs to the step's mean rate, at its midpoint.
            let tm = 0.5 * (t0 + t1);
            sc += sf.force_end * (w * tm).cos();
            ss += sf.force_end * (w * tm).sin();
        }
    }
    let (fc, fs) = (2.0 * sc / n as f64, 2.0 * ss / n as f64);
    let amp = (fc * fc + fs * fs).sqrt();
    let x = c * w / k;
    let amp_exact = c * w * a / (1.0 + x * x).sqrt();
    assert!(
        (amp - amp_exact).abs() < 1e-4 * amp_exact,
        "amplitude {amp} vs {amp_exact}"
    );
    // F = -F0 cos(wt - phi) = -F0 (cos phi cos wt + sin phi sin wt).
    let phi = (fs / fc).atan();
    assert!(
        (phi - x.atan()).abs() < 1e-3,
        "lag {phi} rad vs {} rad",
        x.atan()
    );
    assert!(fc < 0.0);
}

#[test]
fn series_mount_deck_key_wraps_the_damper() {
    let d = deck_with("mount_stiffness_N_per_m = 5.0e7\nseal_friction_N = 100.0");
    assert_eq!(d.extensions.mount_stiffness_n_per_m, Some(5.0e7));
    let back = DamperDeck::from_toml_str(&d.to_toml(), "back").unwrap();
    assert_eq!(back.extensions, d.extensions);
    // Stiff mounts: the rigid damper's force.
    let stiff = deck_with("mount_stiffness_N_per_m = 1.0e15");
    let plain = DamperDeck::from_toml_str(&nominal_text(), "plain").unwrap();
    let run = |dk: &DamperDeck| {
        harmonic_run(
            dk.build(DamperModel::Physical, opts()).unwrap().as_ref(),
            27.02,
            0.05,
            2,
            256,
            true,
        )
        .unwrap()
        .history
        .force_n
    };
    let (fa, fb) = (run(&stiff), run(&plain));
    for (x, y) in fa.iter().zip(&fb) {
        assert!((x - y).abs() < 0.5, "{x} vs {y}");
    }
}

/// A stiff mount in series with a dashpot whose force has a sharp kink (steep below 1 mm/s,
/// flat above, like a relief-limited damper): the inner solve must reach force balance,
/// `F = k (d_h - d)`, at every step, including where a plain secant stalls on the kink.
#[test]
fn series_mount_balances_force_across_a_kinked_device_law() {
    let table = rotorsim::hydraulics::dashpot::MonotoneTable::new(
        vec![0.0, 0.001, 0.4],
        vec![0.0, 14000.0, 14500.0],
    )
    .unwrap();
    let k = 5.0e7;
    let mut dev = SeriesMount::new(Box::new(NonlinearDashpot::new(table)), k);
    let (a, w) = (4.0e-3, 27.0);
    let n = 256;
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    let mut worst: f64 = 0.0;
    for i in 0..3 * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let d1 = a * (w * t1).sin();
        let sf = dev.trial_step(t0, dt, a * (w * t0).sin(), d1).unwrap();
        dev.commit();
        worst = worst.max((sf.force_end - k * (dev.device_stroke() - d1)).abs());
    }
    assert!(worst <= 0.1 + 1e-9, "largest force mismatch {worst} N");
}

/// Harmonic stroking `d = a sin(w t)`, `n` steps per cycle, `cycles` cycles: end-of-step forces.
fn drive(dev: &mut dyn Device, a: f64, w: f64, n: usize, cycles: usize) -> Vec<(f64, f64)> {
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    (0..cycles * n)
        .map(|i| {
            let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
            let d1 = a * (w * t1).sin();
            let sf = dev.trial_step(t0, dt, a * (w * t0).sin(), d1).unwrap();
            dev.commit();
            (d1, sf.force_end)
        })
        .collect()
}

/// Zero gap: the compliant free play is a pure series compliance, the SeriesMount's result (both
/// solves balance the force to 0.1 N), on the hydraulic damper and on a dashpot.
#[test]
fn compliant_free_play_with_zero_gap_is_the_series_mount() {
    let k = 5.0e7;
    let play = deck_with(&format!("free_play_contact_stiffness_N_per_m = {k}"));
    let mount = deck_with(&format!("mount_stiffness_N_per_m = {k}"));
    let mut a = play.build(DamperModel::Physical, opts()).unwrap();
    let mut b = mount.build(DamperModel::Physical, opts()).unwrap();
    let (w, n) = (27.02, 512);
    let fa = drive(a.as_mut(), 3.0e-3, w, n, 3);
    let fb = drive(b.as_mut(), 3.0e-3, w, n, 3);
    let peak = fb.iter().map(|x| x.1.abs()).fold(0.0, f64::max);
    let worst = fa
        .iter()
        .zip(&fb)
        .map(|(x, y)| (x.1 - y.1).abs())
        .fold(0.0, f64::max);
    assert!(peak > 5e3, "peak {peak} N");
    assert!(worst < 0.5, "largest difference {worst} N of {peak} N");
    let mut c = CompliantFreePlay::new(Box::new(LinearDashpot::new(1.0e5)), 0.0, k);
    let mut d = SeriesMount::new(Box::new(LinearDashpot::new(1.0e5)), k);
    let fc = drive(&mut c, 3.0e-3, w, n, 3);
    let fd = drive(&mut d, 3.0e-3, w, n, 3);
    for (x, y) in fc.iter().zip(&fd) {
        assert!((x.1 - y.1).abs() < 0.3, "{} vs {}", x.1, y.1);
    }
}

/// Infinite contact stiffness on a dashpot: the rigid play operator of `FreePlay`, whose piston
/// stroke gives the dashpot force `-c (d_h,f - d_h,i)/dt` (zero while the gap is open). The
/// remaining difference is the contact's deflection F/k per step, c |dF|/(k dt) << 1 N here.
#[test]
fn compliant_free_play_with_infinite_stiffness_is_the_rigid_gap() {
    let (c, gap, k) = (1.0e5, 0.4e-3, 1.0e13);
    let (a, w, n) = (2.0e-3, 27.02, 1024);
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    let mut dev = CompliantFreePlay::new(Box::new(LinearDashpot::new(c)), gap, k);
    let f = drive(&mut dev, a, w, n, 3);
    let rigid = FreePlay { gap };
    let mut d_h = 0.0;
    let mut inside = 0;
    for (i, &(d, fc)) in f.iter().enumerate() {
        let (next, contact) = rigid.follow(d_h, d);
        let fr = -c * (next - d_h) / dt;
        d_h = next;
        if i > n {
            assert!((fc - fr).abs() < 1.0, "step {i}: {fc} vs rigid {fr} N");
            if !contact {
                inside += 1;
                assert!(fc.abs() <= 0.1, "step {i}: {fc} N inside the gap");
            }
        }
    }
    assert!(inside > 40, "{inside} steps inside the gap");
}

/// A gap behind a contact spring on the hydraulic damper: the link force balances the damper's
/// at every step, `F = k dz(d_h - d)` with the dead band of half the gap, and no force is carried
/// while the link is inside the gap.
#[test]
fn compliant_free_play_balances_the_link_force() {
    let (gap, k) = (0.2e-3, 2.0e8);
    let dk = deck_with(&format!(
        "free_play_m = {gap}\nfree_play_contact_stiffness_N_per_m = {k}"
    ));
    assert_eq!(dk.extensions.free_play_contact_stiffness_n_per_m, Some(k));
    let back = DamperDeck::from_toml_str(&dk.to_toml(), "back").unwrap();
    assert_eq!(back.extensions, dk.extensions);
    let inner = dk
        .physical_device(opts())
        .expect("physical damper of the nominal deck");
    let mut dev = CompliantFreePlay::new(Box::new(inner), gap, k);
    let (a, w, n) = (2.0e-3, 27.02, 512);
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    let (mut worst, mut open) = (0.0f64, 0);
    for i in 0..3 * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let d1 = a * (w * t1).sin();
        let sf = dev.trial_step(t0, dt, a * (w * t0).sin(), d1).unwrap();
        dev.commit();
        let (fl, contact) = dev.link_force(dev.device_stroke() - d1);
        worst = worst.max((sf.force_end - fl).abs());
        if !contact {
            open += 1;
        }
    }
    assert!(worst <= 1.0, "largest force mismatch {worst} N");
    assert!(open > 10, "{open} steps with the gap open");
}

/// Checks a device's analytic tangent `dF_m/dd_f` against a central difference of `F_m` (trial
/// steps restart from the committed state) at every 4th step of two harmonic cycles; steps
/// whose `d_f +- h` straddle a kink (gap closing, tangent changing) are skipped. The link solves
/// stop at a force mismatch of 0.1 N, which bounds the difference's error by 0.2 N / (2 h).
/// The relative 1e-4 is the central difference's truncation on the dashpot tables (h^2 terms).
/// Returns (steps checked in contact, steps checked inside the gap).
fn check_tangent(dev: &mut dyn Device, label: &str) -> (usize, usize) {
    let (a, w, n) = (2.0e-3, 27.02, 512);
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    let h = 1.0e-6;
    let (mut contact, mut open) = (0, 0);
    for i in 0..2 * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let (d0, d1) = (a * (w * t0).sin(), a * (w * t1).sin());
        if i % 4 == 0 && i > n / 4 {
            let p = dev.trial_step(t0, dt, d0, d1 + h).unwrap();
            let m = dev.trial_step(t0, dt, d0, d1 - h).unwrap();
            let s = dev.trial_step(t0, dt, d0, d1).unwrap();
            let an = s.dforce_dstroke;
            // Same piece on both sides: the gap open (tangent exactly 0) or closed on all three.
            let same = |x: f64| (x == 0.0) == (an == 0.0) && (x - an).abs() <= 0.01 * an.abs();
            if same(p.dforce_dstroke) && same(m.dforce_dstroke) {
                let fd = (p.force_mean - m.force_mean) / (2.0 * h);
                assert!(
                    (fd - an).abs() <= 1e-4 * an.abs() + 0.2 / (2.0 * h),
                    "{label}, step {i}: analytic {an:e} vs FD {fd:e} N/m"
                );
                if an == 0.0 {
                    open += 1;
                } else {
                    contact += 1;
                }
            }
        }
        dev.trial_step(t0, dt, d0, d1).unwrap();
        dev.commit();
    }
    (contact, open)
}

/// The compliant free play's analytic tangent (contact spring k in series with the device's
/// tangent, `-k k_d/(k + k_d)`; zero while the gap is open) against finite differences, on
/// devices whose own tangent is exact and whose mean and end forces coincide (dashpots); the
/// series mount's alike.
#[test]
fn compliant_free_play_tangent_matches_finite_differences() {
    let table = || {
        rotorsim::hydraulics::dashpot::MonotoneTable::new(
            vec![0.0, 0.05, 0.2, 0.4],
            vec![0.0, 5000.0, 12000.0, 14500.0],
        )
        .unwrap()
    };
    for k in [5.0e7, 1.0e9] {
        let mut lin = CompliantFreePlay::new(Box::new(LinearDashpot::new(1.0e5)), 0.3e-3, k);
        let (c, o) = check_tangent(&mut lin, &format!("linear dashpot, k {k:e}"));
        assert!(
            c > 50 && o > 10,
            "linear: {c} steps in contact, {o} in the gap"
        );
        let mut nl = CompliantFreePlay::new(Box::new(NonlinearDashpot::new(table())), 0.3e-3, k);
        let (c, o) = check_tangent(&mut nl, &format!("nonlinear dashpot, k {k:e}"));
        assert!(
            c > 50 && o > 10,
            "nonlinear: {c} steps in contact, {o} in the gap"
        );
        let mut mount = SeriesMount::new(Box::new(NonlinearDashpot::new(table())), k);
        let (c, o) = check_tangent(&mut mount, &format!("series mount, k {k:e}"));
        assert!(c > 50 && o == 0, "mount: {c} steps checked");
    }
}

/// Force histories of a device driven at `rate` Hz by `0.01 m + a sin(w t)` over `cycles`,
/// sampled every `every`-th step.
fn drive_at(
    dev: &mut dyn Device,
    a: f64,
    w: f64,
    rate: f64,
    cycles: f64,
    every: usize,
) -> Vec<f64> {
    let n = (cycles * 2.0 * std::f64::consts::PI / w * rate).round() as usize;
    let dt = 1.0 / rate;
    let d = |t: f64| 0.01 + a * (w * t).sin();
    let mut out = Vec::new();
    for i in 0..n {
        let t = i as f64 * dt;
        let s = dev.trial_step(t, dt, d(t), d(t + dt)).unwrap();
        dev.commit();
        if (i + 1) % every == 0 {
            out.push(s.force_end);
        }
    }
    out
}

fn rms_diff(a: &[f64], b: &[f64], from: usize) -> f64 {
    let n = a.len().min(b.len());
    ((from..n).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>() / (n - from) as f64).sqrt()
}

/// The circuit and link integrated as one ODE (`LinkedCircuit`) and the force-balance solve
/// around every step (`CompliantFreePlay`, `SeriesMount`) are two discretizations of the same
/// quasi-static model. The solve moves the piston linearly over each step, an error of first
/// order in the step (its 200 kHz and 2 MHz histories differ by ~1 N at 8 in/s); the one ODE
/// resolves the piston's motion inside the step. Refined, both reach the same history: the one
/// ODE at 20 kHz (32 RK4 sub-steps) is within 0.3 N RMS of the solve at 2 MHz (its remaining
/// first-order error, ~0.1 N, plus its 0.1 N stopping tolerance), on a peak of 15 kN.
#[test]
fn linked_circuit_converges_to_the_force_balance_solve() {
    let dk = DamperDeck::from_toml_str(&nominal_text(), "nominal").unwrap();
    let rk4 = |substeps| IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps,
    };
    let (w, a) = (27.02, 8.0 * 0.0254 / 27.02);
    for (gap, k) in [(1.0e-4, 1.0e9), (3.0e-4, 5.0e7), (0.0, 1.0e8)] {
        let c = || dk.physical_device(rk4(1)).unwrap();
        let solve = |rate: f64| {
            let mut dev: Box<dyn Device> = if gap > 0.0 {
                Box::new(CompliantFreePlay::new(Box::new(c()), gap, k))
            } else {
                Box::new(SeriesMount::new(Box::new(c()), k))
            };
            drive_at(dev.as_mut(), a, w, rate, 2.0, (rate / 20.0e3) as usize)
        };
        let fine = solve(2.0e6);
        let coarse = solve(2.0e5);
        let mut one = LinkedCircuit::new(dk.physical_device(rk4(32)).unwrap(), gap, k);
        let f = drive_at(&mut one, a, w, 20.0e3, 2.0, 1);
        let from = f.len() / 2;
        let peak = f[from..].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let e_one = rms_diff(&f, &fine, from);
        let e_solve = rms_diff(&coarse, &fine, from);
        eprintln!(
            "gap {gap} m, k {k:e}: one ODE {e_one:.3} N, solve at 200 kHz {e_solve:.3} N RMS"
        );
        assert!(peak > 1.2e4, "peak {peak} N");
        assert!(
            e_one < 0.3,
            "gap {gap} m, k {k:e}: one ODE vs 2 MHz solve {e_one} N RMS"
        );
        // The solve's own first-order error at 200 kHz is what the one ODE does not have.
        if gap > 0.0 {
            assert!(
                e_solve > 3.0 * e_one,
                "solve at 200 kHz {e_solve} N, one ODE {e_one} N"
            );
        }
    }
}

/// The one-ODE link keeps its force balance at every committed step (`F = k dz(d_h - d)` in
/// contact, zero force with the gap open), and the deck builds it for a link on the bare
/// damper: its histories are the deck's bit for bit; its saved state is the force-balance
/// solve's layout and restores into either.
#[test]
fn linked_circuit_balances_the_link_and_is_what_the_deck_builds() {
    let (gap, k) = (0.2e-3, 2.0e8);
    let dk = deck_with(&format!(
        "free_play_m = {gap}\nfree_play_contact_stiffness_N_per_m = {k}"
    ));
    let mut dev = LinkedCircuit::new(dk.physical_device(opts()).unwrap(), gap, k);
    let (a, w, n) = (2.0e-3, 27.02, 512);
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    let (mut worst, mut open, mut forces) = (0.0f64, 0, Vec::new());
    for i in 0..3 * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let d1 = a * (w * t1).sin();
        let sf = dev.trial_step(t0, dt, a * (w * t0).sin(), d1).unwrap();
        dev.commit();
        let (fl, contact) = dev.link().force(dev.device_stroke() - d1);
        worst = worst.max((sf.force_end - fl).abs());
        if !contact {
            open += 1;
            assert!(
                sf.force_end.abs() < 1.0,
                "step {i}: {} N in the gap",
                sf.force_end
            );
        }
        forces.push(sf.force_end);
    }
    // Contact: the projection puts the link on the balance to round-off of k e.
    assert!(worst <= 1e-6 * 2.0e4, "largest force mismatch {worst} N");
    assert!(open > 10, "{open} steps with the gap open");
    let mut built = dk.build(DamperModel::Physical, opts()).unwrap();
    let mut again = Vec::new();
    for i in 0..3 * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let sf = built
            .trial_step(t0, dt, a * (w * t0).sin(), a * (w * t1).sin())
            .unwrap();
        built.commit();
        again.push(sf.force_end);
    }
    assert_eq!(forces, again, "the deck builds the one-ODE link");
    // With friction the link stays the force-balance solve around the extended damper.
    let with_friction = deck_with(&format!(
        "free_play_m = {gap}\nfree_play_contact_stiffness_N_per_m = {k}\nseal_friction_N = 100.0"
    ));
    let mut fr = with_friction.build(DamperModel::Physical, opts()).unwrap();
    assert!(fr.trial_step(0.0, dt, 0.0, 1e-5).is_ok());
    // State layout: [d_h, fresh, circuit state, t, d_h], as the force-balance solve's.
    let v = dev.state_values();
    let mut nested = CompliantFreePlay::new(Box::new(dk.physical_device(opts()).unwrap()), gap, k);
    nested.set_state_values(&v).unwrap();
    assert_eq!(nested.state_values(), v);
    let mut back = LinkedCircuit::new(dk.physical_device(opts()).unwrap(), gap, k);
    back.set_state_values(&v).unwrap();
    assert_eq!(back.state_values(), v);
    assert!(back.set_state_values(&v[..3]).is_err());
    let t0 = 3.0 * n as f64 * dt;
    let (d0, d1) = (a * (w * t0).sin(), a * (w * (t0 + dt)).sin());
    let (x, y) = (
        back.trial_step(t0, dt, d0, d1).unwrap(),
        dev.trial_step(t0, dt, d0, d1).unwrap(),
    );
    assert_eq!(x, y, "a restored state steps as the original");
}

/// Sealed damper force at piston stroke x: the integral of Eq. (1) with no flow, `Fluid::sealed_pressure`.
fn sealed_force(p: &CircuitParams, x: f64) -> f64 {
    let c = &p.chambers;
    let p0 = p
        .fluid
        .sealed_pressure(p.p_init[0], c[0].volume0, c[0].volume(x));
    let p1 = p
        .fluid
        .sealed_pressure(p.p_init[1], c[1].volume0, c[1].volume(x));
    p0 * c[0].area - p1 * c[1].area
}

/// The one-ODE link on a sealed damper (no flow paths: a nonlinear spring, Eq. 3 with beta > 0)
/// against its exact quasi-static force. The sealed damper is memoryless, so at end stroke d the
/// piston stroke x solves `k dz(x - d) = F_s(x)` (x = 0, no force, while |d| is inside the
/// half gap), found here by bisection on the exact sealed-chamber law. The sub-steps are split
/// where the link crosses the gap's edge, so each is RK4 on one smooth law (20 sub-steps of
/// 23 us against a 0.23 s period: a local error of order (w h)^5 ~ 1e-17): within 1e-10 of the
/// peak force, round-off of the ~1e5 N pressure forces over 1536 steps. Without the split the
/// error was 10 N, kept forever by a sealed damper, which has no flow to forget it.
#[test]
fn linked_circuit_on_a_sealed_damper_gives_the_exact_series_spring() {
    let fluid = Fluid {
        rho: 850.0,
        alpha: 6.667e-10,
        beta: 2.0e-18,
        p_cav: 0.0,
    };
    let p = sealed(fluid, [2.0e6; 2]);
    let o = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 20,
    };
    let (a, w, n) = (1.0e-3, 27.02, 512);
    let dt = 2.0 * std::f64::consts::PI / w / n as f64;
    for (gap, k) in [(0.0, 1.0e8), (0.2e-3, 1.0e8), (0.2e-3, 1.0e9)] {
        let link = |e: f64| {
            let h = 0.5 * gap;
            if e > h {
                k * (e - h)
            } else if e < -h {
                k * (e + h)
            } else {
                0.0
            }
        };
        let exact = |d: f64| {
            if d.abs() <= 0.5 * gap {
                return 0.0;
            }
            // H(x) = link(x - d) - F_s(x) increases in x; its root lies between 0 and d.
            let (mut lo, mut hi) = (d.min(0.0), d.max(0.0));
            for _ in 0..200 {
                let x = 0.5 * (lo + hi);
                if link(x - d) - sealed_force(&p, x) < 0.0 {
                    lo = x;
                } else {
                    hi = x;
                }
            }
            sealed_force(&p, 0.5 * (lo + hi))
        };
        let mut dev = LinkedCircuit::new(CircuitDevice::new(p.clone(), o), gap, k);
        let (mut worst, mut peak, mut open) = (0.0f64, 0.0f64, 0);
        for i in 0..3 * n {
            let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
            let d1 = a * (w * t1).sin();
            let s = dev.trial_step(t0, dt, a * (w * t0).sin(), d1).unwrap();
            dev.commit();
            let f = exact(d1);
            worst = worst.max((s.force_end - f).abs());
            peak = peak.max(f.abs());
            if f == 0.0 {
                open += 1;
            }
        }
        eprintln!(
            "gap {gap} k {k:e}: largest error {worst:.3e} N of {peak:.4e} N, {open} steps open"
        );
        assert!(peak > 2.0e4, "peak {peak} N");
        assert!(gap == 0.0 || open > 50, "{open} steps with the gap open");
        assert!(
            worst < 1e-10 * peak,
            "gap {gap}, k {k:e}: {worst} N of {peak} N"
        );
    }
}
