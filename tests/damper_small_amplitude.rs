//! The damper at small amplitude: the orifice's laminar-to-turbulent law (`mu_Pa_s`,
//! `orifice_length_m`) on the bench against the closed form of the Maxwell element that the
//! orifice and the two chambers make, the seal's Dahl friction (`seal_friction_N`,
//! `seal_presliding_stiffness_N_per_m`) against its exact loop, the viscosity's temperature law,
//! and the deck keys. Closed forms are written out here, independently of the code under test.
use rotorsim::hydraulics::bench::harmonic_run;
use rotorsim::hydraulics::*;
use std::f64::consts::PI;

mod deck_support;
use deck_support::nominal_text;

/// The nominal deck's text with `keys` added to `[damper.physical]` (the first occurrence of
/// the table header: the keys land in it).
fn nominal_with(keys: &str) -> String {
    nominal_text().replacen(
        "[damper.physical]\n",
        &format!("[damper.physical]\n{keys}\n"),
        1,
    )
}

/// The nominal deck with its viscosity keys removed (whatever the shipped deck says), then
/// `keys` added.
fn deck(keys: &str) -> DamperDeck {
    let text: String = nominal_text()
        .lines()
        .filter(|l| {
            ![
                "mu_Pa_s",
                "orifice_length_m",
                "seal_friction_N",
                "seal_presliding_stiffness_N_per_m",
            ]
            .iter()
            .any(|k| l.trim_start().starts_with(k))
        })
        .collect::<Vec<_>>()
        .join("\n");
    let text = text.replacen(
        "[damper.physical]\n",
        &format!("[damper.physical]\n{keys}\n"),
        1,
    );
    DamperDeck::from_toml_str(&text, "deck.toml").unwrap()
}

/// Laminar resistance written out: the sharp edge's `C_d = delta sqrt(Re)` (Merritt 1967,
/// Sec. 3.2, delta = 0.2) in Eq. (4) gives `dp = mu Q/(2 delta^2 d A)`; Hagen-Poiseuille through
/// the bore `dp = 128 mu L Q/(pi d^4)`; `d = sqrt(4 A/pi)`.
fn r_lam(mu: f64, l: f64, a: f64) -> f64 {
    let d = (4.0 * a / PI).sqrt();
    mu / (2.0 * 0.2 * 0.2 * d * a) + 128.0 * mu * l / (PI * d.powi(4))
}

struct Maxwell {
    /// piston area, chamber stiffness sum, laminar resistance, turbulent coefficient
    a: f64,
    k_h: f64,
    r: f64,
    k: f64,
}

impl Maxwell {
    /// The damper with equal areas A at mean pressure p: the piston compresses one chamber and
    /// expands the other, so the flow path sees the chambers' capacitances V/B in series and the
    /// piston their stiffnesses in parallel, `k_h = A^2 B (1/V0 + 1/V1)` (Eq. 1 for each chamber
    /// with Q = dp/R: `F' = -(k_h/c0) F - k_h d'`, a spring k_h in series with a dashpot
    /// `c0 = A^2 R`). Complex stiffness `K* = i w c0 k_h/(k_h + i w c0)`, so the first harmonic's
    /// equivalent damping is `c_eq = K''/w = c0/(1 + (w c0/k_h)^2)`. The turbulent term
    /// `k Q|Q|` enters by its describing function: a sinusoidal flow of amplitude Q_a has the
    /// first harmonic `(8/(3 pi)) k Q_a Q` (exact for the first harmonic when Q is sinusoidal:
    /// wherever compressibility is negligible), so `R -> R + 8 k Q_a/(3 pi)`, Q_a the orifice
    /// flow amplitude `|F|/(A R_eq)`, solved by fixed point.
    fn new(c: &CircuitParams, p_mean: f64) -> Self {
        let a = c.chambers[0].area;
        assert_eq!(a, c.chambers[1].area, "the closed form is for equal areas");
        let (al, be) = (c.fluid.alpha, c.fluid.beta);
        let b = (1.0 + al * p_mean + be * p_mean * p_mean) / (al + 2.0 * be * p_mean);
        let k_h = a * a * b * (1.0 / c.chambers[0].volume0 + 1.0 / c.chambers[1].volume0);
        let o = c.orifice.unwrap();
        let v = c.ext.orifice_viscosity.unwrap();
        let cda = o.cd * o.area;
        Maxwell {
            a,
            k_h,
            r: r_lam(v.mu, v.length, o.area),
            k: c.fluid.rho / (2.0 * cda * cda),
        }
    }

    /// c_eq at stroke amplitude x and frequency w (and the laminar c0 = A^2 R).
    fn c_eq(&self, x: f64, w: f64) -> (f64, f64) {
        let c0_lam = self.a * self.a * self.r;
        let mut r_eq = self.r;
        let mut c_eq = 0.0;
        for _ in 0..200 {
            let c0 = self.a * self.a * r_eq;
            let g = w * c0 / self.k_h;
            c_eq = c0 / (1.0 + g * g);
            // |K*| = k_h g/sqrt(1 + g^2); force amplitude |K*| x; dp = F/A; Q_a = dp/R_eq
            let f_a = self.k_h * g / (1.0 + g * g).sqrt() * x;
            let q_a = f_a / (self.a * r_eq);
            r_eq = self.r + 8.0 * self.k * q_a / (3.0 * PI);
        }
        (c_eq, c0_lam)
    }
}

/// The deck's physical damper with the chambers precharged `dp` above p_s so that the check
/// valves stay shut at small amplitude (as once the check valves' ratchet has settled): the
/// orifice and the chambers alone.
fn precharged(d: &DamperDeck, dp: f64, opts: IntegratorOptions) -> (CircuitDevice, f64) {
    let mut dev = d.physical_device(opts).unwrap();
    let p = dev.params().p_s + dp;
    dev.params_mut().p_init = [p; 2];
    dev.reset();
    (dev, p)
}

/// c_eq = K''/w of the bench's last cycle. The discrete K'' of a dashpot is `(sin h/h)^2` low,
/// `h = pi/steps`: 1.3e-5 at 512 steps, removed.
fn bench_c_eq(dev: &dyn Device, x: f64, w: f64, cycles: usize, steps: usize) -> f64 {
    let run = harmonic_run(dev, w, x * w, cycles, steps, false).unwrap();
    let h = PI / steps as f64;
    run.loss_stiffness_n_per_m / w / (h.sin() / h).powi(2)
}

#[test]
fn shipped_orifice_at_the_lag_frequency_is_its_laminar_law_plus_the_turbulent_describing_function()
{
    // Shipped geometry, MIL-PRF-5606 at 40 C (nu 13 mm^2/s, rho 850: mu 0.01105 Pa s), 3 mm
    // bore. At w = 7.8 rad/s, w c0/k_h ~ 1e-4: compressibility does not matter, Q is the
    // piston's A x w cos(w t) and the first harmonic is exact. RK4 with 256 steps per cycle and
    // 256 sub-steps: h x (fastest rate C/R ~ 1.6e5 1/s) = 2.0, within RK4's limit; 6 cycles
    // (the Maxwell relaxation time c0/k_h ~ 6 us).
    let d = deck("mu_Pa_s = 0.01105\norifice_length_m = 3.0e-3");
    for (x, w) in [(5.0e-5, 7.8f64), (1.0e-4, 7.8), (5.0e-5, 2.0)] {
        // the same sub-step at every frequency
        let opts = IntegratorOptions {
            scheme: Scheme::Rk4,
            substeps: (256.0 * 7.8 / w).ceil() as usize,
        };
        let (dev, p) = precharged(&d, 2.0e4, opts);
        let m = Maxwell::new(dev.params(), p);
        let (want, c0) = m.c_eq(x, w);
        let got = bench_c_eq(&dev, x, w, 6, 256);
        eprintln!(
            "x = {x:e} m, w = {w} rad/s: c_eq bench {got:.2} N s/m, closed form {want:.2} \
             (laminar c0 = A^2 R = {c0:.2}; R = {:.4e} Pa s/m^3, k = {:.4e}, k_h = {:.4e} N/m)",
            m.r, m.k, m.k_h
        );
        assert!(
            (got / want - 1.0).abs() < 0.02,
            "x {x}, w {w}: {got} vs {want}"
        );
    }
}

#[test]
fn laminar_orifice_on_the_bench_is_a_maxwell_element() {
    // A capillary orifice (viscous oil of 5 Pa s, 20 mm bore) where at 0.05 mm the laminar term
    // dominates (k Q/R ~ 2e-3) and w c0/k_h = 1 falls at ~64 rad/s: there compressibility halves
    // the damping; at 2 rad/s it does not matter. Implicit scheme (the reference of
    // docs/integrators.md for stiff circuits), 512 steps per cycle, 4 sub-steps, 8 cycles.
    let d = deck("mu_Pa_s = 5.0\norifice_length_m = 0.02");
    let opts = IntegratorOptions {
        scheme: Scheme::Implicit,
        substeps: 4,
    };
    let (dev, p) = precharged(&d, 2.0e4, opts);
    let m = Maxwell::new(dev.params(), p);
    let c0 = m.a * m.a * m.r;
    let w_c = m.k_h / c0;
    for (w, what) in [(2.0, "incompressible"), (w_c, "w c0 = k_h")] {
        let x = 5.0e-5;
        let (want, _) = m.c_eq(x, w);
        let got = bench_c_eq(&dev, x, w, 8, 512);
        eprintln!(
            "{what}: w = {w:.2} rad/s, c_eq bench {got:.1} N s/m, closed form {want:.1} \
             (c0 = {c0:.1}, c0/(1 + (w c0/k_h)^2) = {:.1})",
            c0 / (1.0 + (w * c0 / m.k_h).powi(2))
        );
        assert!((got / want - 1.0).abs() < 0.02, "{what}: {got} vs {want}");
    }
    // compressibility matters there: c_eq about c0/2
    let (at_wc, _) = m.c_eq(5.0e-5, w_c);
    assert!((at_wc / c0 - 0.5).abs() < 0.02, "{at_wc} vs {c0}");
}

// ---- seal friction (Dahl) -------------------------------------------------------------

/// Dahl's loop for exponent 1 at stroke amplitude X, x_p = F_c/sigma0: on the rising branch
/// `F(x) = F_c - (F_c + F_top) exp(-(x + X)/x_p)` with `F_top = F(X) = F_c tanh(X/x_p)`, so the
/// energy per cycle is `2 int_{-X}^{X} F dx = 4 F_c (X - x_p tanh(X/x_p))`: `4 F_c X` at large X,
/// `(4/3) F_c X^3/x_p^2` (third order: no dissipation to first order) at small X.
fn dahl_energy(f_c: f64, x_p: f64, x: f64) -> f64 {
    4.0 * f_c * (x - x_p * (x / x_p).tanh())
}

/// The friction's share of a bench run: the run with it less the run without (the friction
/// is a force in parallel on the same stroke, so the hydraulic part is the same bits).
fn friction_run(f_c: f64, sigma0: f64, x: f64, w: f64, scheme: Scheme) -> (f64, f64, f64) {
    let keys = format!("seal_friction_N = {f_c:?}\nseal_presliding_stiffness_N_per_m = {sigma0:?}");
    let opts = IntegratorOptions {
        scheme,
        substeps: 25,
    };
    let with = deck(&keys).build(DamperModel::Physical, opts).unwrap();
    let without = deck("").build(DamperModel::Physical, opts).unwrap();
    // the start's memory fades as exp(-travel/x_p), 4 X of travel a cycle
    let x_p = f_c / sigma0;
    let cycles = 3 + (20.0 * x_p / (4.0 * x)).ceil() as usize;
    let run = |dev: &dyn Device| harmonic_run(dev, w, x * w, cycles, 512, false).unwrap();
    let (a, b) = (run(with.as_ref()), run(without.as_ref()));
    (
        a.dissipated_last_cycle_j - b.dissipated_last_cycle_j,
        a.loss_stiffness_n_per_m - b.loss_stiffness_n_per_m,
        a.storage_stiffness_n_per_m - b.storage_stiffness_n_per_m,
    )
}

#[test]
fn dahl_friction_dissipates_its_exact_loop() {
    let (f_c, sigma0) = (150.0, 150.0 / 3.0e-5);
    let x_p = f_c / sigma0;
    let w = 7.8;
    for scheme in [Scheme::Rk4, Scheme::Implicit] {
        for x in [3.0e-6, 3.0e-5, 1.0e-4, 1.0e-3] {
            let (e, kpp, _) = friction_run(f_c, sigma0, x, w, scheme);
            let want = dahl_energy(f_c, x_p, x);
            eprintln!(
                "{scheme:?} X = {x:e}: friction energy {e:.6e} J, exact loop {want:.6e}, \
                 4 F_c X = {:.6e}; c_eq {:.2} N s/m vs 4 F_c/(pi w X) = {:.2}",
                4.0 * f_c * x,
                kpp / w,
                4.0 * f_c / (PI * w * x)
            );
            // the stroke is piecewise linear between 512 samples whose extremes are +-X to
            // round-off, and the Dahl law is rate-independent: the loop is exact
            assert!((e / want - 1.0).abs() < 1e-6, "{x}: {e} vs {want}");
            // the first harmonic carries all the energy of a sinusoidal stroke
            assert!((PI * x * x * kpp / e - 1.0).abs() < 1e-6);
        }
        // (a), (b): large amplitude, X = 100 x_p: 4 F_c X and 4 F_c/(pi w X) within x_p/X
        let x = 100.0 * x_p;
        let (e, kpp, _) = friction_run(f_c, sigma0, x, w, scheme);
        assert!((e / (4.0 * f_c * x) - 1.0).abs() < 1.1 * x_p / x);
        let c_df = 4.0 * f_c / (PI * w * x);
        assert!((kpp / w / c_df - 1.0).abs() < 1.1 * x_p / x);
        // (c): X = x_p/30: a stiffness sigma0 (K' within (X/x_p)^2) and next to no dissipation
        let x = x_p / 30.0;
        let (e, _, kp) = friction_run(f_c, sigma0, x, w, scheme);
        assert!(
            (kp / sigma0 - 1.0).abs() < (x / x_p).powi(2),
            "{kp} vs {sigma0}"
        );
        assert!(e < 1e-2 * f_c * x, "{e}");
    }
}

#[test]
fn dahl_step_tangent_is_the_finite_difference() {
    // The step's dF_m/dd_f against central differences of the step's mean force, from states
    // in the presliding regime and sliding, both directions; the hydraulic part removed.
    let (f_c, sigma0) = (150.0, 150.0 / 3.0e-5);
    let keys = format!("seal_friction_N = {f_c:?}\nseal_presliding_stiffness_N_per_m = {sigma0:?}");
    let opts = IntegratorOptions {
        scheme: Scheme::Implicit,
        substeps: 10,
    };
    let d = deck(&keys);
    let fr = d.extensions.friction.unwrap();
    let dt = 1e-3;
    let mut checked = 0;
    for &f0 in &[-140.0, -30.0, 0.0, 60.0, 149.0] {
        for &dd in &[-2.0e-4f64, -1.0e-5, -1.0e-6, 2.0e-6, 4.0e-5, 3.0e-4] {
            let mean = |dd: f64| fr.presliding_step(f0, dd / dt, dd).1;
            let h = 1e-4 * dd.abs();
            let fd = (mean(dd + h) - mean(dd - h)) / (2.0 * h);
            let an = fr.presliding_tangent(f0, dd, dt);
            assert!(
                (fd - an).abs() <= 1e-5 * an.abs().max(1.0),
                "f0 {f0} dd {dd}: {an} vs {fd}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 30);
    // through the device: the friction's share of dF_m/dd_f, with and without it
    let mut with = d.build(DamperModel::Physical, opts).unwrap();
    let mut without = deck("").build(DamperModel::Physical, opts).unwrap();
    for dev in [&mut with, &mut without] {
        dev.trial_step(0.0, dt, 0.0, 1e-5).unwrap();
        dev.commit();
    }
    let share = |dev: &mut Box<dyn Device>, d_f: f64| dev.trial_step(dt, dt, 1e-5, d_f).unwrap();
    let d_f = 1.2e-5;
    let h = 1e-10;
    let fd = ((share(&mut with, d_f + h).force_mean - share(&mut without, d_f + h).force_mean)
        - (share(&mut with, d_f - h).force_mean - share(&mut without, d_f - h).force_mean))
        / (2.0 * h);
    let an = share(&mut with, d_f).dforce_dstroke - share(&mut without, d_f).dforce_dstroke;
    assert!((fd - an).abs() < 1e-3 * an.abs(), "{an} vs {fd}");
}

// ---- temperature ----------------------------------------------------------------------

#[test]
fn orifice_viscosity_follows_the_oil_temperature_and_composes() {
    // the nominal deck with the viscous orifice and an oil law (c_mu 0.03/K, reference 40 C)
    let oil = "\n[damper.physical.oil]\nreference_temperature_K = 313.15\n\
               viscosity_thermal_coefficient_per_K = 0.03\n";
    let base = deck("mu_Pa_s = 0.01105\norifice_length_m = 3.0e-3");
    assert!(
        base.oil.is_none(),
        "the shipped nominal deck has no oil law"
    );
    let d = DamperDeck::from_toml_str(&(base.to_toml() + oil), "deck.toml").unwrap();
    let law = d.oil.unwrap();
    let mu = |d: &DamperDeck| {
        d.physical
            .as_ref()
            .unwrap()
            .ext
            .orifice_viscosity
            .unwrap()
            .mu
    };
    let t0 = law.temperature_k;
    let mu0 = mu(&d);
    for dt in [-60.0, -20.0, 40.0] {
        let moved = d.at_oil_temperature(t0 + dt).unwrap();
        let want = mu0 * (-law.viscosity_per_k * dt).exp();
        assert!((mu(&moved) / want - 1.0).abs() < 1e-14);
    }
    // composition: t0 -> t0 - 20 -> t0 - 60 is t0 -> t0 - 60
    let two = d
        .at_oil_temperature(t0 - 20.0)
        .unwrap()
        .at_oil_temperature(t0 - 60.0)
        .unwrap();
    let one = d.at_oil_temperature(t0 - 60.0).unwrap();
    assert!((mu(&two) / mu(&one) - 1.0).abs() < 1e-14);
    // and back
    let back = one.at_oil_temperature(t0).unwrap();
    assert!((mu(&back) / mu0 - 1.0).abs() < 1e-14);
}

// ---- deck -----------------------------------------------------------------------------

#[test]
fn deck_keys_are_checked_and_written_back() {
    let err = |keys: &str| {
        DamperDeck::from_toml_str(&nominal_with(keys), "d.toml")
            .unwrap_err()
            .to_string()
    };
    // (only on a deck without the keys: a shipped deck that has them gives a duplicate key)
    if !nominal_text().contains("mu_Pa_s") {
        let m = err("mu_Pa_s = 0.011");
        assert!(
            m.contains("d.toml") && m.contains("damper.physical.mu_Pa_s"),
            "{m}"
        );
        assert!(m.contains("orifice_length_m"), "{m}");
        let m = err("orifice_length_m = 0.003");
        assert!(m.contains("damper.physical.orifice_length_m") && m.contains("mu_Pa_s"));
        let m = err("mu_Pa_s = 0.0\norifice_length_m = 0.003");
        assert!(
            m.contains("mu_Pa_s") && m.contains("above 0 and below 10"),
            "{m}"
        );
        let m = err("mu_Pa_s = 12.0\norifice_length_m = 0.003");
        assert!(m.contains("mu_Pa_s") && m.contains("below 10"), "{m}");
        let m = err("mu_Pa_s = 0.01\norifice_length_m = -0.003");
        assert!(
            m.contains("orifice_length_m") && m.contains("at least 0"),
            "{m}"
        );
        let m = err("mu_Pa_s = 0.01\norifice_length_m = 1.5");
        assert!(
            m.contains("orifice_length_m") && m.contains("below 1"),
            "{m}"
        );
    }
    if !nominal_text().contains("seal_friction_N") {
        let m = err("seal_friction_N = 150.0");
        assert!(
            m.contains("damper.physical.seal_friction_N")
                && m.contains("seal_presliding_stiffness_N_per_m"),
            "{m}"
        );
        let m = err("seal_presliding_stiffness_N_per_m = 5e6");
        assert!(m.contains("damper.physical.seal_presliding_stiffness_N_per_m"));
        let m = err("seal_friction_N = 150.0\nseal_presliding_stiffness_N_per_m = 0.0");
        assert!(m.contains("seal_presliding_stiffness_N_per_m") && m.contains("positive"));
        // the extensions' friction law takes the data sheet's place
        let text = nominal_with("seal_friction_N = 150.0\nseal_presliding_stiffness_N_per_m = 5e6")
            + "\n[damper.physical.extensions]\nseal_friction_N = 100.0\n";
        let d = DamperDeck::from_toml_str(&text, "d.toml").unwrap();
        let f = d.extensions.friction.unwrap();
        assert!(f.f_c == 100.0 && !f.is_dahl());
        let back = DamperDeck::from_toml_str(&d.to_toml(), "d.toml").unwrap();
        assert_eq!(back.extensions, d.extensions);
        // 0: none
        let d =
            DamperDeck::from_toml_str(&nominal_with("seal_friction_N = 0.0"), "d.toml").unwrap();
        assert!(d.extensions.friction.is_none());
    }
    // round trip
    let d = deck(
        "mu_Pa_s = 0.01105\norifice_length_m = 3.0e-3\nseal_friction_N = 150.0\n\
         seal_presliding_stiffness_N_per_m = 7.0e6",
    );
    let text = d.to_toml();
    assert!(text.contains("mu_Pa_s = 0.01105"), "{text}");
    assert!(
        text.contains("seal_presliding_stiffness_N_per_m = 7000000.0"),
        "{text}"
    );
    let mut back = DamperDeck::from_toml_str(&text, "deck.toml").unwrap();
    back.source = d.source.clone();
    assert_eq!(back, d);
    // what the deck says of its small-amplitude damping
    let say = d.small_amplitude_damping().unwrap();
    assert!(
        say.contains("mu_Pa_s") && say.contains("seal friction 150"),
        "{say}"
    );
    let say = deck("").small_amplitude_damping().unwrap();
    assert!(say.contains("dp_laminar_Pa = 1000"), "{say}");
    // the regularised law's zero-amplitude damping, A^2 dp_l/(1.25 Cd A_orf sqrt(2 dp_l/rho))
    let u_l = (2.0e3f64 / 850.0).sqrt();
    let c_reg = 1.6e-3f64.powi(2) * 1.0e3 / (1.25 * 0.611 * 1.8e-6 * u_l);
    assert!(
        say.contains(&format!("{c_reg:.1} N s/m")),
        "{say} vs {c_reg}"
    );
    // without the keys: the old law
    let old = deck("");
    assert!(old.physical.unwrap().ext.orifice_viscosity.is_none());
    assert!(old.extensions.friction.is_none());
}
