//! Oil temperature (`[damper.physical.oil]`): the moved properties against their laws written
//! out here, the damper's steady orifice and leakage behaviour at two temperatures against the
//! analytic results, and the deck keys.
use rotorsim::hydraulics::circuit::{IP0, IP1};
use rotorsim::hydraulics::*;

mod deck_support;
use deck_support::nominal_text;

fn opts() -> IntegratorOptions {
    IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: 40,
    }
}

const LAW: OilTemperature = OilTemperature {
    temperature_k: 293.15,
    density_per_k: 7.0e-4,
    bulk_modulus_per_k: 5.0e-3,
    viscosity_per_k: 0.03,
};

/// A sealed pair of chambers (area 1.6e-3 m^2, 6e-5 m^3 each), constant bulk modulus 1.5 GPa.
fn pair(orifice: Option<Orifice>) -> CircuitParams {
    let ch = |lambda| Chamber {
        area: 1.6e-3,
        volume0: 6.0e-5,
        lambda,
    };
    CircuitParams {
        fluid: Fluid::constant_bulk(850.0, 1.5e9),
        dp_laminar: 1e3,
        chambers: [ch(1.0), ch(-1.0)],
        orifice,
        relief: [None, None],
        check: None,
        entrance: None,
        p_s: 5.0e5,
        p_init: [5.0e5; 2],
        ext: HydraulicExtensions::default(),
    }
}

#[test]
fn moving_the_oil_follows_the_laws_and_composes() {
    let mut c = pair(None);
    c.fluid.beta = 2.0e-18;
    c.ext.leakage = Some(AnnularLeakage {
        conductance: 1.0e-11,
        viscosity_length: 7.5e-4,
    });
    c.ext.bleed = Some(Leakage {
        conductance: 2.0e-12,
    });
    let base = c.clone();
    let dt: f64 = -60.0;
    let law = LAW.move_to(&mut c, LAW.temperature_k + dt);
    assert_eq!(law.temperature_k, LAW.temperature_k + dt);
    let rel = |a: f64, b: f64| (a / b - 1.0).abs();
    assert!(rel(c.fluid.rho, 850.0 * (0.042f64).exp()) < 1e-15);
    // Zero-pressure bulk modulus 1/alpha falls by exp(c_B dT): here it rises by exp(0.3).
    assert!(rel(1.0 / c.fluid.alpha, 1.5e9 * (0.3f64).exp()) < 1e-15);
    assert!(rel(c.fluid.beta, 2.0e-18 * (-0.6f64).exp()) < 1e-15);
    // Colder oil is more viscous (mu x exp(1.8)): the laminar conductances fall by it.
    let mu = (1.8f64).exp();
    let l = c.ext.leakage.unwrap();
    assert!(rel(l.conductance, 1.0e-11 / mu) < 1e-15);
    assert!(rel(l.viscosity_length, 7.5e-4 * mu) < 1e-15);
    assert!(rel(c.ext.bleed.unwrap().conductance, 2.0e-12 / mu) < 1e-15);
    // The clearance is the piston's: it does not move with the oil.
    let h0 = base.ext.leakage.unwrap().clearance(1.6e-3);
    assert!(rel(l.clearance(1.6e-3), h0) < 1e-14);
    // Two moves are one; and back is back.
    let mut two = base.clone();
    let mid = LAW.move_to(&mut two, 273.15);
    mid.move_to(&mut two, LAW.temperature_k + dt);
    assert!(rel(two.fluid.rho, c.fluid.rho) < 1e-14);
    assert!(rel(two.fluid.alpha, c.fluid.alpha) < 1e-14);
    assert!(rel(two.ext.leakage.unwrap().conductance, l.conductance) < 1e-14);
    law.move_to(&mut c, LAW.temperature_k);
    assert!(rel(c.fluid.rho, base.fluid.rho) < 1e-14);
    assert!(rel(c.fluid.alpha, base.fluid.alpha) < 1e-14);
    // Without coefficients nothing moves, bit for bit.
    let mut same = base.clone();
    OilTemperature {
        density_per_k: 0.0,
        bulk_modulus_per_k: 0.0,
        viscosity_per_k: 0.0,
        ..LAW
    }
    .move_to(&mut same, 233.15);
    assert_eq!(same, base);
}

/// Stroked at constant velocity w through a turbulent orifice, the pair settles where the
/// orifice passes the swept flow, `dp = rho (A w)^2 / (2 Cd^2 A_o^2)` (Eq. 4): the force
/// follows the density, 4.3% more at 60 K colder.
#[test]
fn the_loss_exponent_is_the_warming_that_loses_the_fraction() {
    // Warmed by loss_exponent(f) / c_rho, the density has lost f of its value: 1 - exp(-x)
    // written out (f = 0.04: x = 0.040822).
    for f in [1e-5, 0.04, 0.3] {
        let mut c = pair(None);
        let rho0 = c.fluid.rho;
        let dt = OilTemperature::loss_exponent(f) / LAW.density_per_k;
        LAW.move_to(&mut c, LAW.temperature_k + dt);
        let lost = 1.0 - c.fluid.rho / rho0;
        assert!((lost - f).abs() <= 1e-12 * f.max(1e-3), "{f}: {lost}");
    }
    assert!((OilTemperature::loss_exponent(0.04) - 0.040_821_994_520_255).abs() < 1e-14);
}

#[test]
fn steady_orifice_pressure_follows_the_oil_density() {
    let (w, area, cd, a_o) = (0.05, 1.6e-3, 0.7, 1.666e-5);
    let steady = |t_k: f64| {
        let mut c = pair(Some(Orifice { area: a_o, cd }));
        LAW.move_to(&mut c, t_k);
        let rho = c.fluid.rho;
        let mut dev = CircuitDevice::new(c, opts());
        // The pressure's approach has the time constant 1 / (B G (1/V0 + 1/V1)), G = Q/(2 dp)
        // the orifice's conductance: 1e-5 s here; 20 ms is 2000 of them, with RK4 sub-steps
        // of a quarter of one.
        let (n, dt) = (200, 1.0e-4);
        for i in 0..n {
            let t = i as f64 * dt;
            dev.trial_step(t, dt, w * t, w * (t + dt)).unwrap();
            dev.commit();
        }
        let y = dev.state();
        (y[IP1] - y[IP0], rho)
    };
    let (warm, rho_w) = steady(293.15);
    let (cold, rho_c) = steady(233.15);
    for (dp, rho) in [(warm, rho_w), (cold, rho_c)] {
        let expect = rho * (area * w).powi(2) / (2.0 * cd * cd * a_o * a_o);
        assert!(expect > 10.0 * 1e3, "turbulent: {expect} Pa");
        assert!(
            (dp / expect - 1.0).abs() < 1e-4,
            "dp {dp} Pa for {expect} Pa"
        );
    }
    assert!(
        (cold / warm - (0.042f64).exp()).abs() < 2e-4,
        "{}",
        cold / warm
    );
}

/// A sealed pair with piston leakage held still: dp decays as exp(-t/tau), tau = 1 / (k B (1/V0 +
/// 1/V1)), with k and B at the oil's temperature (B = 1/alpha + p at the mean pressure).
#[test]
fn leakage_decay_follows_the_viscosity_and_the_bulk_modulus() {
    for t_k in [233.15, 293.15, 353.15] {
        let dt = t_k - LAW.temperature_k;
        let k = 1.0e-12 * (LAW.viscosity_per_k * dt).exp();
        let b = 1.5e9 * (-LAW.bulk_modulus_per_k * dt).exp() + 5.0e5;
        let tau = 1.0 / (k * b * (2.0 / 6.0e-5));
        let dp0 = 2.0e3;
        let mut c = pair(None);
        c.p_init = [5.0e5 + dp0 / 2.0, 5.0e5 - dp0 / 2.0];
        c.ext.leakage = Some(AnnularLeakage::laminar(1.0e-12));
        LAW.move_to(&mut c, t_k);
        let mut dev = CircuitDevice::new(c, opts());
        let h = tau / 50.0;
        for step in 1..=100 {
            dev.trial_step((step - 1) as f64 * h, h, 0.0, 0.0).unwrap();
            dev.commit();
        }
        let y = dev.state();
        let expect = dp0 * (-2.0f64).exp();
        assert!(
            ((y[IP0] - y[IP1]) - expect).abs() < 1e-5 * dp0,
            "{t_k} K: {} vs {expect}",
            y[IP0] - y[IP1]
        );
    }
}

fn oil_deck(table: &str) -> Result<DamperDeck, DeckError> {
    DamperDeck::from_toml_str(
        &format!("{}\n[damper.physical.oil]\n{table}\n", nominal_text()),
        "oil.toml",
    )
}

#[test]
fn oil_table_moves_the_deck_and_writes_back() {
    let plain = DamperDeck::from_toml_str(&nominal_text(), "plain").unwrap();
    assert_eq!(plain.oil, None);
    let coefs = "density_thermal_coefficient_per_K = 7.0e-4\nbulk_modulus_thermal_coefficient_per_K = 5.0e-3\nviscosity_thermal_coefficient_per_K = 0.03";
    // At its reference the deck is the data sheet's, bit for bit.
    let at_ref = oil_deck(&format!("reference_temperature_K = 293.15\n{coefs}")).unwrap();
    assert_eq!(at_ref.physical, plain.physical);
    let cold = oil_deck(&format!(
        "reference_temperature_K = 293.15\ntemperature_K = 233.15\n{coefs}"
    ))
    .unwrap();
    let (p, c) = (
        plain.physical.as_ref().unwrap(),
        cold.physical.as_ref().unwrap(),
    );
    assert!((c.fluid.rho / (p.fluid.rho * (0.042f64).exp()) - 1.0).abs() < 1e-15);
    assert_eq!(cold.oil.unwrap().temperature_k, 233.15);
    // Written, it holds at 233.15 K and reads back the same.
    let back = DamperDeck::from_toml_str(&cold.to_toml(), "back").unwrap();
    assert_eq!(back.physical, cold.physical);
    assert_eq!(back.oil, cold.oil);
    // Moved back to the reference, the data sheet again (to rounding).
    let warm = cold.at_oil_temperature(293.15).unwrap();
    let w = warm.physical.as_ref().unwrap();
    assert!((w.fluid.rho / p.fluid.rho - 1.0).abs() < 1e-15);
    assert!((w.fluid.alpha / p.fluid.alpha - 1.0).abs() < 1e-15);
    // Without the table there is no law to move by.
    let e = plain.at_oil_temperature(233.15).unwrap_err().to_string();
    assert!(e.contains("damper.physical.oil"), "{e}");
}

#[test]
fn bad_oil_keys_are_named() {
    for (table, want) in [
        ("temperature_K = 233.15", "reference_temperature_K"),
        (
            "reference_temperature_K = -5.0",
            "damper.physical.oil.reference_temperature_K",
        ),
        (
            "reference_temperature_K = 293.15\nviscosity_thermal_coefficient_per_K = -0.03",
            "damper.physical.oil.viscosity_thermal_coefficient_per_K",
        ),
        (
            "reference_temperature_K = 293.15\ntemperature_C = 20.0",
            "temperature_K",
        ),
    ] {
        let e = oil_deck(table).unwrap_err().to_string();
        assert!(e.contains("oil.toml") && e.contains(want), "{table}: {e}");
    }
}

#[test]
fn bench_csv_reads_the_oil_temperature_in_kelvin_or_celsius() {
    use rotorsim::hydraulics::bench::{parse_bench_csv, parse_bench_csv_with_dropouts};
    let c = "time_s,stroke_m,force_N,oil_temperature_C\n0.0,0.0,1.0,20.0\n0.001,0.001,2.0,21.5\n";
    let t = parse_bench_csv(c, "c.csv", "c").unwrap();
    assert_eq!(t.oil_temperature_k, Some(vec![293.15, 294.65]));
    let k = "time_s,stroke_m,oil_temperature_K\n0.0,0.0,300.0\n0.001,0.001,301.0\n";
    let t = parse_bench_csv_with_dropouts(k, "k.csv", "k").unwrap();
    assert_eq!(t.oil_temperature_k, Some(vec![300.0, 301.0]));
    assert_eq!(
        parse_bench_csv("time_s,stroke_m\n0,0\n1,1\n", "n.csv", "n")
            .unwrap()
            .oil_temperature_k,
        None
    );
    for (text, want) in [
        (
            "time_s,stroke_m,oil_temperature_K\n0.0,0.0,300.0\n0.001,0.001,-3.0\n",
            "line 3",
        ),
        (
            "time_s,stroke_m,oil_temperature_F\n0.0,0.0,70.0\n0.001,0.001,71.0\n",
            "oil_temperature_C",
        ),
        (
            "time_s,stroke_m,oil_temperature_K\n0.0,0.0,300.0\n0.001,0.001,\n",
            "line 3",
        ),
    ] {
        let e = parse_bench_csv_with_dropouts(text, "bad.csv", "b")
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.csv") && e.contains(want), "{e}");
    }
}
