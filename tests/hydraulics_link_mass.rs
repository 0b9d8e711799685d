//! The link's moving mass (piston, rod and rod end between the link and the oil) and the link's
//! damping: against the exact steady state of the linear two-spring oscillator, RK4's order,
//! the massless link as the mass vanishes, and the deck keys.
use rotorsim::hydraulics::*;
use std::f64::consts::PI;

mod deck_support;
use deck_support::{deck_text, nominal_text};

/// A sealed damper (no flow paths), beta = 0: for strokes of a tenth of a
/// micron, a linear spring of `k_oil = B (A0^2/V0 + A1^2/V1)` (Eq. 16, B at the initial pressure)
/// to a few parts per million.
fn sealed_linear() -> CircuitParams {
    let ch = |lambda| Chamber {
        area: 1.6e-3,
        volume0: 6.0e-5,
        lambda,
    };
    CircuitParams {
        fluid: Fluid {
            rho: 850.0,
            alpha: 6.667e-10,
            beta: 0.0,
            p_cav: 0.0,
        },
        dp_laminar: 1e3,
        chambers: [ch(1.0), ch(-1.0)],
        orifice: None,
        relief: [None, None],
        check: None,
        entrance: None,
        p_s: 5.0e5,
        p_init: [2.0e6; 2],
        ext: HydraulicExtensions::default(),
    }
}

/// `k_oil = B (A0^2/V0 + A1^2/V1)` (Eq. 16) at the initial pressure.
fn oil_stiffness(p: &CircuitParams) -> f64 {
    let b = p.fluid.bulk(p.p_init[0]).0;
    p.chambers
        .iter()
        .map(|c| b * c.area * c.area / c.volume0)
        .sum()
}

/// Force at the step ends over the last two drive periods of a mount (stiffness k, damping
/// ratio zeta, mass m) on the sealed damper, driven at `d = X sin(w t)` from rest (the stroke
/// linear within each of `n` steps per period), and the exact steady state of
/// `m x'' = -k_oil x - k (x - d) - c (x' - d')`, whose force at the end is
/// `F = k (x - d) + c (x' - d')`, taken with the step's stroke rate (what the device is given) in
/// its dashpot term; and the force amplitude.
fn mount_run(substeps: usize) -> (Vec<f64>, Vec<f64>, f64) {
    let p = sealed_linear();
    let (k, m, zeta): (f64, f64, f64) = (1.0e8, 1.5, 0.2);
    let c = 2.0 * zeta * (k * m).sqrt();
    let k_oil = oil_stiffness(&p);
    let w_n = ((k + k_oil) / m).sqrt();
    let (x_amp, w) = (1.0e-7, 0.6 * w_n);
    // Steady state, complex amplitudes of d = X e^{i w t}.
    let re_den = k + k_oil - m * w * w;
    let im_den = w * c;
    let (re_num, im_num) = (k, w * c);
    let den2 = re_den * re_den + im_den * im_den;
    // x / X = (k + i w c) / (k + k_oil - m w^2 + i w c)
    let xr = (re_num * re_den + im_num * im_den) / den2;
    let xi = (im_num * re_den - re_num * im_den) / den2;
    // F / X = (k + i w c)(x/X - 1)
    let fr = (re_num * (xr - 1.0) - im_num * xi) * x_amp;
    let fi = (re_num * xi + im_num * (xr - 1.0)) * x_amp;
    let amp = (fr * fr + fi * fi).sqrt();
    let o = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps,
    };
    let mut dev =
        LinkedCircuit::new(CircuitDevice::new(p.clone(), o), 0.0, k).with_mass(LinkMass {
            mass_kg: m,
            damping_ratio: zeta,
        });
    let period = 2.0 * PI / w;
    let n = STEPS_PER_PERIOD;
    let dt = period / n as f64;
    // Transients decay as exp(-c t / 2m): 60 periods leave e^-80.
    let cycles = 60;
    let (mut got, mut exact) = (Vec::new(), Vec::new());
    for i in 0..cycles * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let (d0, d1) = (x_amp * (w * t0).sin(), x_amp * (w * t1).sin());
        let s = dev.trial_step(t0, dt, d0, d1).unwrap();
        dev.commit();
        if i >= (cycles - 2) * n {
            // F(t) = Im((fr + i fi) e^{i w t})
            got.push(s.force_end);
            exact.push(fr * (w * t1).sin() + fi * (w * t1).cos());
        }
    }
    (got, exact, amp)
}

/// Steps per drive period: the device's parabola through three samples differs from the sine by
/// `(w dt)^3 / 16` = 2e-6 of the amplitude, its slope by `(w dt)^2 / 3` = 5e-5.
const STEPS_PER_PERIOD: usize = 512;

fn largest(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

#[test]
fn moving_mass_behind_a_mount_is_the_damped_two_spring_oscillator() {
    // Against the exact steady state: within the drive's parabola error (5e-5, amplified through
    // the resonance by ~3) and the sealed law's curvature (a few ppm). And the sub-steps the
    // device picks itself (h omega <= 1/2) against 2x and 16x as many: RK4's h^4 (ratio 16).
    let (own, exact, amp) = mount_run(1);
    let (twice, _, _) = mount_run(2 * own_substeps());
    let (fine, _, _) = mount_run(16 * own_substeps());
    let to_exact = largest(&own, &exact) / amp;
    let (e1, e2) = (largest(&own, &fine) / amp, largest(&twice, &fine) / amp);
    eprintln!(
        "force amplitude {amp:.4} N; error to the exact steady state {to_exact:.2e}; to 16x sub-steps {e1:.2e} (own), {e2:.2e} (2x) of it"
    );
    assert!(amp > 1.0, "amplitude {amp} N");
    assert!(to_exact < 1.5e-4, "{to_exact:e} of the amplitude");
    assert!(e1 / e2 > 12.0, "order: {e1:e} -> {e2:e}");
}

/// The sub-steps the device picks for `mount_run` (h omega <= 1/4 of the mass's frequency).
fn own_substeps() -> usize {
    let p = sealed_linear();
    let k_oil = oil_stiffness(&p);
    let w_n = ((1.0e8 + k_oil) / 1.5f64).sqrt();
    let dt = 2.0 * PI / (0.6 * w_n) / STEPS_PER_PERIOD as f64;
    (dt * w_n / 0.25).ceil() as usize
}

#[test]
fn a_sampled_stroke_gives_the_force_of_a_finely_sampled_one() {
    // The nominal damper behind a 0.3 mm gap and a 1e9 N/m contact with a 1.5 kg moving mass,
    // stroked at 4.3 Hz: the force at 2 kHz samples against a 64 kHz drive at the same instants.
    // Between samples the device takes the parabola through three of them; a chord's velocity
    // jump at every sample rang the contact mode (34 N RMS undamped, 6 N at 5% damping). What
    // is left is the sub-steps' (h omega = 1/4, the crossing of the gap's edge interpolated):
    // within an eighth of a bench test's 1% noise (37 N) undamped, a fortieth damped.
    let a = 2.0 * 0.0254 / (2.0 * PI * 4.3);
    for (zeta, tol) in [(0.0, 5.0), (0.05, 1.0)] {
        let ext = format!(
            "free_play_m = 3.0e-4\nfree_play_contact_stiffness_N_per_m = 1.0e9\nlink_mass_kg = 1.5\nlink_damping_ratio = {zeta:?}"
        );
        let deck = DamperDeck::from_toml_str(&deck_text(&ext), "t").unwrap();
        let run = |rate: f64| {
            let opts = IntegratorOptions {
                scheme: Scheme::Rk4,
                substeps: 10,
            };
            let mut dev = deck.build(DamperModel::Physical, opts).unwrap();
            let w = 2.0 * PI * 4.3;
            let dt = 1.0 / rate;
            let n = (3.0 / 4.3 * rate) as usize;
            let mut f = Vec::with_capacity(n);
            for i in 0..n {
                let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
                let s = dev
                    .trial_step(t0, dt, a * (w * t0).sin(), a * (w * t1).sin())
                    .unwrap();
                dev.commit();
                f.push(s.force_end);
            }
            f
        };
        let (coarse, fine) = (run(2000.0), run(64000.0));
        let m = coarse.len();
        let rms = ((m / 3..m)
            .map(|i| (coarse[i] - fine[(i + 1) * 32 - 1]).powi(2))
            .sum::<f64>()
            / (m - m / 3) as f64)
            .sqrt();
        let peak = fine.iter().fold(0.0f64, |x, y| x.max(y.abs()));
        eprintln!(
            "damping ratio {zeta}: 2 kHz against 64 kHz, {rms:.2} N RMS of a {peak:.0} N peak"
        );
        assert!(rms < tol, "damping ratio {zeta}: {rms} N RMS");
    }
}

fn drive(dev: &mut dyn Device, a: f64, w: f64, n: usize, cycles: usize) -> Vec<f64> {
    let dt = 2.0 * PI / w / n as f64;
    let mut out = Vec::new();
    for i in 0..cycles * n {
        let (t0, t1) = (i as f64 * dt, (i + 1) as f64 * dt);
        let s = dev
            .trial_step(t0, dt, a * (w * t0).sin(), a * (w * t1).sin())
            .unwrap();
        dev.commit();
        if i >= (cycles - 1) * n {
            out.push(s.force_end);
        }
    }
    out
}

#[test]
fn a_vanishing_moving_mass_tends_to_the_massless_link() {
    // The nominal damper behind a 0.15 mm gap and a 2.2e8 N/m contact, undamped: the force with
    // a moving mass tends to the massless (quasi-static) link's as the mass goes to zero.
    let opts = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 40,
    };
    let link = "free_play_m = 1.5e-4\nfree_play_contact_stiffness_N_per_m = 2.2e8";
    let massless = DamperDeck::from_toml_str(&deck_text(link), "t").unwrap();
    let (a, w, n) = (2.0 * 0.0254 / 27.0, 27.0, 2048);
    let reference = drive(
        massless
            .build(DamperModel::Physical, opts)
            .unwrap()
            .as_mut(),
        a,
        w,
        n,
        3,
    );
    let peak = reference.iter().fold(0.0f64, |x, f| x.max(f.abs()));
    let mut diffs = Vec::new();
    for m in [1.0, 0.1, 0.01] {
        let deck =
            DamperDeck::from_toml_str(&deck_text(&format!("{link}\nlink_mass_kg = {m:?}")), "t")
                .unwrap();
        let f = drive(
            deck.build(DamperModel::Physical, opts).unwrap().as_mut(),
            a,
            w,
            n,
            3,
        );
        let rms = (f
            .iter()
            .zip(&reference)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            / n as f64)
            .sqrt();
        eprintln!("mass {m} kg: RMS difference {rms:.2} N of a {peak:.0} N peak");
        diffs.push(rms);
    }
    assert!(peak > 3.0e3, "peak {peak}");
    assert!(diffs[0] > diffs[1] && diffs[1] > diffs[2], "{diffs:?}");
    assert!(diffs[2] < 1e-3 * peak, "10 g: {} N", diffs[2]);
}

#[test]
fn link_mass_keys_read_back_and_bad_ones_are_named() {
    let ext = "free_play_m = 1.0e-4\nfree_play_contact_stiffness_N_per_m = 1.0e8\nlink_mass_kg = 1.5\nlink_damping_ratio = 0.05";
    let deck = DamperDeck::from_toml_str(&deck_text(ext), "t").unwrap();
    assert_eq!(
        deck.extensions.link_mass,
        Some(LinkMass {
            mass_kg: 1.5,
            damping_ratio: 0.05
        })
    );
    let back = DamperDeck::from_toml_str(&deck.to_toml(), "t").unwrap();
    assert_eq!(back.extensions, deck.extensions);
    for (ext, key, says) in [
        (
            "mount_stiffness_N_per_m = 1e8\nlink_damping_ratio = 0.05",
            "link_damping_ratio",
            "give link_mass_kg",
        ),
        (
            "mount_stiffness_N_per_m = 1e8\nlink_mass_kg = -1.0",
            "link_mass_kg",
            "positive mass",
        ),
    ] {
        let e = DamperDeck::from_toml_str(&deck_text(ext), "deck.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(key) && e.contains(says) && e.contains("deck.toml"),
            "{e}"
        );
    }
    // Without a link the mass moves with the end: the bare circuit, bit for bit.
    let opts = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 10,
    };
    let bare = DamperDeck::from_toml_str(&nominal_text(), "t").unwrap();
    let inert = DamperDeck::from_toml_str(&deck_text("link_mass_kg = 1.5"), "t").unwrap();
    let (a, w, n) = (5.0e-3, 27.0, 256);
    assert_eq!(
        drive(
            bare.build(DamperModel::Physical, opts).unwrap().as_mut(),
            a,
            w,
            n,
            2
        ),
        drive(
            inert.build(DamperModel::Physical, opts).unwrap().as_mut(),
            a,
            w,
            n,
            2
        )
    );
    let friction = DamperDeck::from_toml_str(
        &deck_text("mount_stiffness_N_per_m = 1e8\nlink_mass_kg = 1.5\nseal_friction_N = 100.0"),
        "deck.toml",
    )
    .unwrap();
    let e = friction
        .build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Rk4,
                substeps: 10,
            },
        )
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("link_mass_kg") && e.contains("seal friction"),
        "{e}"
    );
}

#[test]
fn every_candidate_builds_on_a_data_sheet_with_a_moving_mass() {
    // The diagnosis on a data sheet that gives the moving mass: every single cause and every
    // pair builds a device; the mass stays behind one link on the bare circuit and is left out
    // beside seal friction, a rigid gap or a second link.
    use rotorsim::diagnose::candidates::{apply_all, combined_params, Scales};
    use rotorsim::diagnose::Cause;
    let base = DamperDeck::from_toml_str(&deck_text("link_mass_kg = 1.5"), "t").unwrap();
    let s = Scales {
        peak_force_n: 1.0e4,
        min_amplitude_m: 2.0e-3,
        oil_span_k: 0.0,
        oil_reference_unknown: false,
        oil_drift: true,
    };
    let opts = IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 10,
    };
    let mut with_mass = 0;
    for (i, &c1) in Cause::CANDIDATES.iter().enumerate() {
        for c2 in std::iter::once(None).chain(Cause::CANDIDATES[i + 1..].iter().map(Some)) {
            let causes: Vec<Cause> = std::iter::once(c1).chain(c2.copied()).collect();
            let Some(spec) = combined_params(&causes, &base, s) else {
                continue;
            };
            let x: Vec<f64> = spec.iter().map(|p| p.starts[0]).collect();
            let deck = apply_all(&causes, &base, s, &x);
            let mut dev = deck
                .build(DamperModel::Physical, opts)
                .unwrap_or_else(|e| panic!("{causes:?}: {e}"));
            dev.trial_step(0.0, 1e-3, 0.0, 1e-5).unwrap();
            let links = causes
                .iter()
                .filter(|c| matches!(c, Cause::CompliantFreePlay | Cause::MountCompliance))
                .count();
            let beside = causes
                .iter()
                .any(|c| matches!(c, Cause::SealFriction | Cause::FreePlay));
            let kept = deck.extensions.link_mass.is_some();
            assert_eq!(kept, links == 0 || (links == 1 && !beside), "{causes:?}");
            if kept && links == 1 {
                with_mass += 1;
            }
        }
    }
    assert!(
        with_mass >= 2,
        "{with_mass} candidates carry the mass behind a link"
    );
}
