//! Element and device tests against analytic results.
use rotorsim::hydraulics::bench::{harmonic_run, IN_TO_M};
use rotorsim::hydraulics::circuit::{IP0, IP1, IV0, IX0};
use rotorsim::hydraulics::*;
use std::path::Path;

fn deck() -> DamperDeck {
    DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/rotors/uh60a.toml"
    )))
    .unwrap()
}

fn opts(scheme: Scheme, substeps: usize) -> IntegratorOptions {
    IntegratorOptions { scheme, substeps }
}

/// Two chambers, no flow element at all.
fn sealed(fluid: Fluid, p_init: f64) -> CircuitParams {
    CircuitParams {
        fluid,
        dp_laminar: 1e3,
        chambers: [
            Chamber {
                area: 1.6e-3,
                volume0: 6.0e-5,
                lambda: 1.0,
            },
            Chamber {
                area: 1.6e-3,
                volume0: 6.0e-5,
                lambda: -1.0,
            },
        ],
        orifice: None,
        relief: [None, None],
        check: None,
        entrance: None,
        p_s: p_init,
        p_init: [p_init; 2],
        ext: Default::default(),
    }
}

#[test]
fn sealed_chamber_follows_the_integral_of_eq3() {
    // Pressure-dependent bulk modulus (beta > 0) and the constant-B limit.
    for beta in [0.0, 2.0e-18] {
        let fluid = Fluid {
            rho: 850.0,
            alpha: 6.667e-10,
            beta,
            p_cav: 0.0,
        };
        let params = sealed(fluid, 5.0e6);
        for scheme in [Scheme::Rk4, Scheme::Implicit] {
            let mut dev = CircuitDevice::new(params.clone(), opts(scheme, 25));
            // Stroke 0 -> 3 mm in 10 steps: chamber 0 grows, chamber 1 shrinks.
            let n = 10;
            let d_end = 1.0e-4;
            for k in 0..n {
                let (a, b) = (
                    d_end * k as f64 / n as f64,
                    d_end * (k + 1) as f64 / n as f64,
                );
                dev.trial_step(k as f64 * 1e-3, 1e-3, a, b).unwrap();
                dev.commit();
            }
            let c = &params.chambers;
            let p0 = fluid.sealed_pressure(5.0e6, c[0].volume0, c[0].volume(d_end));
            let p1 = fluid.sealed_pressure(5.0e6, c[1].volume0, c[1].volume(d_end));
            let y = dev.state();
            assert!(
                (y[IP0] - p0).abs() < 1e-7 * p0.abs(),
                "{scheme:?} beta {beta}: p0 {} vs {p0}",
                y[IP0]
            );
            assert!(
                (y[IP1] - p1).abs() < 1e-7 * p1.abs(),
                "{scheme:?} beta {beta}: p1 {} vs {p1}",
                y[IP1]
            );
            assert!(p1 > 5.0e6 && p0 < 5.0e6);
        }
    }
}

#[test]
fn eq16_tangent_has_the_sign_and_size_of_the_sealed_device() {
    // For a sealed device the step-average force is F_i - K (d_f - d_i)/2 to first order, so
    // dF_m/dd_f = -K/2 with K of Eq. (16): compare with a finite difference of force_mean.
    let params = sealed(Fluid::constant_bulk(850.0, 1.5e9), 5.0e6);
    let mut dev = CircuitDevice::new(params, IntegratorOptions::default());
    let a = dev.trial_step(0.0, 1e-3, 0.0, 1e-5).unwrap();
    let h = 1e-9;
    let b = dev.trial_step(0.0, 1e-3, 0.0, 1e-5 + h).unwrap();
    let fd = (b.force_mean - a.force_mean) / h;
    assert!(a.dforce_dstroke < 0.0);
    assert!(
        (fd - a.dforce_dstroke).abs() < 1e-3 * fd.abs(),
        "fd {fd} vs {}",
        a.dforce_dstroke
    );
}

#[test]
fn trial_steps_restart_from_the_committed_state() {
    let mut dev = deck()
        .build(DamperModel::Physical, IntegratorOptions::default())
        .unwrap();
    let a = dev.trial_step(0.0, 1e-3, 0.0, 2e-5).unwrap();
    let _ = dev.trial_step(0.0, 1e-3, 0.0, -7e-5).unwrap();
    let b = dev.trial_step(0.0, 1e-3, 0.0, 2e-5).unwrap();
    assert_eq!(a, b);
    let copy = dev.clone_device();
    dev.commit();
    let mut ch = vec![0.0; dev.channel_names().len()];
    let mut ch_copy = ch.clone();
    dev.channels(&mut ch);
    copy.channels(&mut ch_copy);
    assert_ne!(ch[0], ch_copy[0], "the clone must not see the commit");
}

#[test]
fn orifice_flow_is_odd_and_c1_at_the_laminar_transition() {
    let law = FlowLaw {
        rho: 850.0,
        dp_laminar: 1.0e3,
    };
    let o = Orifice {
        area: 1.8e-6,
        cd: 0.611,
    };
    for dp in [0.0, 3.0, 500.0, 1.0e3, 2.0e5, 9.0e6] {
        let (q, dq) = o.flow(&law, dp);
        let (qm, dqm) = o.flow(&law, -dp);
        assert_eq!(q, -qm);
        assert_eq!(dq, dqm);
    }
    let e = 1e-6;
    let (ql, dl) = o.flow(&law, 1.0e3 - e);
    let (qh, dh) = o.flow(&law, 1.0e3 + e);
    assert!((ql - qh).abs() <= 1e-9 * qh && (dl - dh).abs() <= 1e-6 * dh);
    // Turbulent branch: Eq. (4).
    let (q, _) = o.flow(&law, 4.0e6);
    assert!((q - 0.611 * 1.8e-6 * (2.0 * 4.0e6 / 850.0f64).sqrt()).abs() < 1e-18);
}

/// Valve 0 only, chambers precharged high enough that nothing cavitates.
fn relief_only() -> (CircuitParams, ReliefValve) {
    let d = deck();
    let rv = d.physical.as_ref().unwrap().relief[0].unwrap();
    let mut p = sealed(Fluid::constant_bulk(850.0, 1.5e9), 2.0e7);
    p.relief[0] = Some(rv);
    (p, rv)
}

#[test]
fn relief_valve_cracks_at_the_preload_and_reseats() {
    let (params, rv) = relief_only();
    for scheme in [Scheme::Rk4, Scheme::Implicit] {
        let mut dev = CircuitDevice::new(params.clone(), opts(scheme, 25));
        // Compress chamber 0 (d < 0) to 0.3 mm in 0.1 s, then back to 0.
        let n = 400;
        let dt = 2.0e-4 / 1.0;
        let stroke = |k: usize| -3.0e-4 * (std::f64::consts::PI * k as f64 / n as f64).sin();
        let mut cracked_at = None;
        let mut last_open = 0;
        let mut f_hist = Vec::new();
        for k in 0..n {
            let f_before = rv.opening_force(dev.state()[IP0], dev.state()[IP1]);
            dev.trial_step(k as f64 * dt, dt, stroke(k), stroke(k + 1))
                .unwrap();
            dev.commit();
            let y = *dev.state();
            let f_open = rv.opening_force(y[IP0], y[IP1]);
            f_hist.push(f_open);
            assert!(y[IX0] >= 0.0, "poppet through its seat");
            if y[IX0] > 0.0 {
                last_open = k;
            }
            if cracked_at.is_none() {
                if y[IX0] > 0.0 {
                    // It opened during this step: p0 A0 - p1 A1 crossed F_p within the step.
                    assert!(
                        f_before <= 0.0 && f_open > 0.0,
                        "{scheme:?}: cracked with {f_before} -> {f_open}"
                    );
                    cracked_at = Some(k);
                } else {
                    // Closed and below the preload: exactly on the seat, at rest.
                    assert!(f_open <= 0.0 && y[IV0] == 0.0, "{scheme:?}: step {k}");
                }
            }
        }
        let cracked = cracked_at.expect("valve never cracked");
        // It reseats once the stroke reverses and stays seated, at rest, with F < F_p.
        assert!(
            last_open > cracked && last_open < n - 10,
            "{scheme:?}: last open at {last_open}"
        );
        assert!(f_hist[last_open + 1..].iter().all(|f| *f <= 0.0));
        assert_eq!((dev.state()[IX0], dev.state()[IV0]), (0.0, 0.0));
        // While open, the opening force stays near the spring force k x (pressure regulation).
    }
}

#[test]
fn check_valve_holds_the_expanding_chamber_at_the_analytic_deficit() {
    // A chamber expanding at a constant rate A v is fed by its check valve; the steady deficit
    // dp* solves Cd A_cv u(dp*) = A v (the stated tolerance of "p >= p_s").
    let d = deck();
    let phys = d.physical.clone().unwrap();
    let cv = phys.check.unwrap();
    let mut params = sealed(phys.fluid, phys.p_s);
    params.check = Some(cv);
    params.fluid.p_cav = 0.0;
    let law = FlowLaw {
        rho: phys.fluid.rho,
        dp_laminar: phys.dp_laminar,
    };
    let v = 0.01; // m/s
    let q = params.chambers[0].area * v;
    // Solve for dp* by bisection on the monotone law.
    let (mut lo, mut hi) = (0.0, 1.0e8);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cv.inflow(&law, phys.p_s, phys.p_s - mid).0 < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let dp_star = 0.5 * (lo + hi);
    for scheme in [Scheme::Rk4, Scheme::Implicit] {
        let mut dev = CircuitDevice::new(params.clone(), opts(scheme, 25));
        let dt = 1e-4;
        for k in 0..200 {
            dev.trial_step(
                k as f64 * dt,
                dt,
                v * k as f64 * dt,
                v * (k + 1) as f64 * dt,
            )
            .unwrap();
            dev.commit();
            assert!(
                dev.state()[IP0] >= phys.p_s - dp_star * (1.0 + 1e-9),
                "{scheme:?}"
            );
        }
        let p0 = dev.state()[IP0];
        assert!(
            (phys.p_s - p0 - dp_star).abs() < 1e-3 * dp_star,
            "{scheme:?}: deficit {} vs {dp_star}",
            phys.p_s - p0
        );
    }
}

#[test]
fn every_model_dissipates_energy_over_every_cycle() {
    let d = deck();
    let omega = 27.02;
    for model in [
        DamperModel::Physical,
        DamperModel::Linear,
        DamperModel::Nonlinear,
    ] {
        for v_in in [0.5, 2.0, 10.0] {
            let v = v_in * IN_TO_M;
            let mut dev = d.build(model, IntegratorOptions::default()).unwrap();
            let n = 256;
            let dt = 2.0 * std::f64::consts::PI / omega / n as f64;
            let stroke = |k: usize| v / omega * (omega * k as f64 * dt).sin();
            for cycle in 0..4 {
                let mut work = 0.0;
                for k in cycle * n..(cycle + 1) * n {
                    let sf = dev
                        .trial_step(k as f64 * dt, dt, stroke(k), stroke(k + 1))
                        .unwrap();
                    dev.commit();
                    work += sf.force_mean * (stroke(k + 1) - stroke(k));
                }
                assert!(
                    work < 0.0,
                    "{model:?} at {v_in} in/s, cycle {cycle}: work {work} J"
                );
            }
        }
    }
}

#[test]
fn check_valves_keep_the_damper_above_background_minus_the_deficit() {
    // Over the last cycle at 10 in/s, chamber pressures stay above p_s - dp*(A v_peak).
    let d = deck();
    let phys = d.physical.clone().unwrap();
    let law = FlowLaw {
        rho: phys.fluid.rho,
        dp_laminar: phys.dp_laminar,
    };
    let cv = phys.check.unwrap();
    let v = 10.0 * IN_TO_M;
    let q = phys.chambers[0].area * v;
    let (mut lo, mut hi) = (0.0, 1.0e9);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cv.inflow(&law, phys.p_s, phys.p_s - mid).0 < q {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let bound = phys.p_s - hi;
    let dev = d
        .build(DamperModel::Physical, IntegratorOptions::default())
        .unwrap();
    let r = harmonic_run(dev.as_ref(), 27.02, v, 10, 256, true).unwrap();
    let h = &r.history;
    let n = h.time_s.len();
    for name in ["p0_Pa", "p1_Pa"] {
        let c = h.channel_names.iter().position(|c| *c == name).unwrap();
        let min = h.channels[c][n - 257..]
            .iter()
            .cloned()
            .fold(f64::INFINITY, f64::min);
        assert!(min >= bound.max(0.0), "{name}: min {min} < {bound}");
        assert!(min > 0.0);
    }
}

#[test]
fn actuator_chambers_settle_at_the_entrance_pressures() {
    let mut params = ActuatorParams::paper_table1();
    params.p_entrance_pa = [1.25e6, 1.1e6];
    // Paper: 48 sub-steps of the 1e-4 s structural step (RK4 is unstable near zero flow with 25).
    let mut dev = CircuitDevice::new(params.to_circuit(), opts(Scheme::Rk4, 48));
    for k in 0..200 {
        dev.trial_step(k as f64 * 1e-4, 1e-4, 0.0, 0.0).unwrap();
        dev.commit();
    }
    let y = dev.state();
    assert!(
        (y[IP0] - 1.25e6).abs() < 1.0 && (y[IP1] - 1.1e6).abs() < 1.0,
        "{y:?}"
    );
    // With the area schedule at zero the chambers are sealed: pressure follows the stroke.
    dev.set_orifice_area_schedule(PiecewiseLinear::new(vec![0.0], vec![0.0]).unwrap());
    let p_before = dev.state()[IP1];
    dev.trial_step(0.02, 1e-3, 0.0, 1e-5).unwrap();
    dev.commit();
    assert!(dev.state()[IP1] > p_before);
}

#[test]
fn finite_difference_tangent_includes_the_orifice_relaxation() {
    // At a flowing state the true dF_m/dd_f is below the Eq. (16) static value in magnitude
    // (the orifice relieves part of the compression within the step); the FD tangent must
    // match an external difference of force_mean and have the same (negative) sign.
    let d = deck();
    let mut dev = d.physical_device(IntegratorOptions::default()).unwrap();
    let dt = 9.08e-4;
    for k in 0..60 {
        let s = |k: usize| 3.0e-3 * (27.02 * k as f64 * dt).sin();
        dev.trial_step(k as f64 * dt, dt, s(k), s(k + 1)).unwrap();
        dev.commit();
    }
    let (t, di, df) = (60.0 * dt, 1.0e-3, 1.05e-3);
    let eq16 = dev.trial_step(t, dt, di, df).unwrap();
    dev.set_tangent(Tangent::FiniteDifference);
    let fd = dev.trial_step(t, dt, di, df).unwrap();
    assert_eq!(eq16.force_mean, fd.force_mean);
    eprintln!(
        "tangent: eq16 {} fd {}",
        eq16.dforce_dstroke, fd.dforce_dstroke
    );
    let h = 1e-6;
    let up = dev.trial_step(t, dt, di, df + h).unwrap();
    let dn = dev.trial_step(t, dt, di, df - h).unwrap();
    let central = (up.force_mean - dn.force_mean) / (2.0 * h);
    assert!(fd.dforce_dstroke < 0.0 && eq16.dforce_dstroke < 0.0);
    assert!(
        (fd.dforce_dstroke - central).abs() < 1e-3 * central.abs(),
        "{} vs {central}",
        fd.dforce_dstroke
    );
    assert!(
        fd.dforce_dstroke.abs() <= eq16.dforce_dstroke.abs() * 1.001,
        "{} vs {}",
        fd.dforce_dstroke,
        eq16.dforce_dstroke
    );
}

#[test]
fn actuator_table_matches_paper_table1_and_rejects_unknown_keys() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/rotors/paper_table1_actuator.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    assert_eq!(
        actuator_from_toml_str(&text, path).unwrap(),
        ActuatorParams::paper_table1()
    );
    let e = actuator_from_toml_str(&text.replace("B_Pa", "B_MPa"), "act.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("act.toml") && e.contains("actuator.B_MPa"),
        "{e}"
    );
}

#[test]
fn simple_damper_matches_the_incompressible_orifice_law_at_low_frequency() {
    // Chambers + orifice only (the paper's simple damper). Slow stroking: the oil is nearly
    // incompressible, so Q = A d' and F = -A dp with dp = (rho/2) (A d'/(C_d A_orf))^2 (Eq. 4).
    let phys = deck().physical.unwrap();
    let mut params = sealed(phys.fluid, 5.0e6);
    params.orifice = phys.orifice;
    params.dp_laminar = phys.dp_laminar;
    let o = phys.orifice.unwrap();
    let (omega, v) = (2.0, 0.05);
    let dev = CircuitDevice::new(params.clone(), IntegratorOptions::default());
    let r = harmonic_run(&dev, omega, v, 2, 512, false).unwrap();
    let a = params.chambers[0].area;
    let dp = 0.5 * params.fluid.rho * (a * v / (o.cd * o.area)).powi(2);
    let analytic = a * dp;
    for peak in [r.peak_force_pos_n, -r.peak_force_neg_n] {
        assert!(
            (peak - analytic).abs() < 2e-3 * analytic,
            "peak {peak} vs {analytic}"
        );
    }
}

/// The linked circuit's force balance takes Eq. (1)'s factors once per state: the same bits as
/// the chamber's pressure rate at every net inflow, both signs, with and without cavitation.
#[test]
fn chamber_rate_from_its_factors_is_the_pressure_rate_bit_for_bit() {
    let ch = elements::Chamber {
        area: 7.85e-5,
        volume0: 9.42e-6,
        lambda: -1.0,
    };
    for p_cav in [0.0, 2e5] {
        let fluid = Fluid {
            p_cav,
            ..Fluid::constant_bulk(850.0, 1.53e9)
        };
        for p in [-1e4, 0.0, 3e4, 1e6, 2e7] {
            let v = ch.volume(1.3e-3);
            let (b, db) = fluid.bulk(p);
            let s = fluid.cavitation_factor(p).0;
            let f = elements::Chamber::rate_factors(b, s, v);
            for q in [-3e-5, -1e-9, 0.0, 2e-6, 4e-5] {
                for d_dot in [-0.3, 0.0, 0.2] {
                    let (rate, _, g) = ch.pressure_rate_with_bulk(&fluid, (b, db), p, v, q, d_dot);
                    let (r2, g2) = ch.rate_with(&f, q, d_dot);
                    assert_eq!(rate.to_bits(), r2.to_bits(), "p {p} q {q} d_dot {d_dot}");
                    assert_eq!(g.to_bits(), g2.to_bits(), "p {p} q {q} d_dot {d_dot}");
                }
            }
        }
    }
}
