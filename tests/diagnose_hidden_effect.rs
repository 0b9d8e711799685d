//! Hidden effects in SYNTHETIC bench data are found, named, their parameter recovered within tolerance, with a positive held-out gain; no effect gives `none`;
//! bad or insufficient data gets a clear message. Larger seed sweep:
//! `cargo run --release --example diagnose_hit_rate -- 40 4 2000`.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::fit::simulate;
use rotorsim::diagnose::{diagnose, Cause, DiagnoseError, DiagnoseOptions};
use rotorsim::hydraulics::bench::{parse_bench_csv, replay, BenchTest};
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, OilTemperature, Scheme};

/// 4 cycles at 1 kHz keep the test fast; the hit-rate example uses the full campaign.
fn run(h: &support::Hidden, seed: u64) -> rotorsim::diagnose::Outcome {
    let data = support::campaign(
        &h.deck,
        &[1.0, 2.0, 3.0, 4.0, 6.0, 8.0],
        4,
        1000.0,
        0.01,
        seed,
    );
    diagnose(&support::nominal_deck(), &data, &DiagnoseOptions::default()).unwrap()
}

fn assert_found(h: &support::Hidden, seed: u64) {
    check_found(h, seed, &run(h, seed));
}

fn check_found(h: &support::Hidden, seed: u64, o: &rotorsim::diagnose::Outcome) {
    let d = &o.diagnosis;
    assert_eq!(d.cause, h.cause.name(), "seed {seed}: {h:?}\n{d:#?}");
    let got = d.parameters[h.param];
    let rel = (got - h.value).abs() / h.value;
    assert!(
        rel <= h.tolerance,
        "seed {seed}: {} = {got:e}, true {:e} (rel. error {rel:.3} > {})",
        h.param,
        h.value,
        h.tolerance
    );
    assert!(d.gain > 0.0, "seed {seed}: gain {}", d.gain);
    assert!(d.validation.extended_rms_N < d.validation.baseline_rms_N);
    // The held-out RMS of the extended model is at the noise level.
    assert!(
        d.validation.extended_rms_N < 1.1 * d.noise_sigma_N,
        "seed {seed}: extended {} vs noise {}",
        d.validation.extended_rms_N,
        d.noise_sigma_N
    );
    assert!(d.validation.method.starts_with("held-out tests"));
    assert!(!d.evidence.is_empty());
    // The written deck reproduces the extended model through `bench` (same deck reader).
    let text = o.extended.to_toml();
    let back = DamperDeck::from_toml_str(&text, "written").unwrap();
    let m = &o.curves[0];
    let test = BenchTest {
        name: "t".into(),
        time_s: m.time_s.clone(),
        stroke_m: m.stroke_m.clone(),
        force_n: None,
        velocity_m_s: None,
        oil_temperature_k: None,
    };
    let dt = m.time_s[1] - m.time_s[0];
    let dev = back
        .build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Rk4,
                substeps: (dt / DiagnoseOptions::default().max_substep_s).ceil() as usize,
            },
        )
        .unwrap();
    let r = replay(dev.as_ref(), &test).unwrap();
    assert_eq!(r.force_model_n, m.extended_n, "written deck differs");
}

/// Seeds of the fast subset of the sweep.
const SEEDS: [u64; 3] = [0, 7, 11];

/// Seeded random draws (kind and magnitude): the fast subset of the sweep.
#[test]
fn hidden_effects_drawn_at_random_are_found() {
    for seed in SEEDS {
        let h = support::draw(seed);
        assert_found(&h, seed);
    }
}

/// Every kind the random draws above did not hit, once (mid-range magnitude).
#[test]
fn every_kind_is_found() {
    let drawn: Vec<Cause> = SEEDS.iter().map(|&s| support::draw(s).cause).collect();
    for (i, k) in support::KINDS.iter().enumerate() {
        if drawn.contains(k) {
            continue;
        }
        let h = support::hidden(*k, 0.3 + 0.05 * i as f64);
        assert_found(&h, 100 + i as u64);
    }
}

#[test]
fn no_effect_gives_none() {
    let h = support::hidden(Cause::None, 0.0);
    let o = run(&h, 5);
    let d = &o.diagnosis;
    assert_eq!(d.cause, "none", "{d:#?}");
    assert!(d.parameters.is_empty());
    assert_eq!(d.gain, 0.0);
    // Baseline at the noise level.
    assert!(d.validation.baseline_rms_N < 1.1 * d.noise_sigma_N);
}

#[test]
fn one_amplitude_is_reported_as_a_limitation() {
    let h = support::hidden(Cause::SealFriction, 0.5);
    let data = support::campaign(&h.deck, &[3.0], 6, 1000.0, 0.01, 3);
    let o = diagnose(&support::nominal_deck(), &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    assert!(
        d.validation.method.starts_with("held-out cycles"),
        "{}",
        d.validation.method
    );
    assert!(
        d.limitations
            .iter()
            .any(|l| l.contains("one stroke amplitude")),
        "{:?}",
        d.limitations
    );
}

#[test]
fn bad_data_gets_a_clear_message() {
    let base = support::nominal_deck();
    let h = support::hidden(Cause::None, 0.0);
    // Sample rate too low: 20 samples per cycle.
    let rate = 20.0 / (2.0 * std::f64::consts::PI / support::OMEGA);
    let data = support::campaign(&h.deck, &[2.0, 4.0], 4, rate, 0.01, 1);
    let e = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap_err();
    assert!(matches!(e, DiagnoseError::SampleRate { .. }), "{e}");
    assert!(e.to_string().contains("samples per stroke cycle"), "{e}");
    // Clipped beyond use: a rail so low that fewer than half the samples are measured.
    let mut data = support::campaign(&h.deck, &[2.0, 8.0], 3, 1000.0, 0.01, 2);
    for f in &mut data[1].force_n {
        *f = f.clamp(-500.0, 500.0);
    }
    let e = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap_err();
    assert!(matches!(e, DiagnoseError::Unusable { .. }), "{e}");
    assert!(
        e.to_string().contains("clipped at the load cell's range"),
        "{e}"
    );
    // A stroke dropout longer than a straight line bridges (1/64 of the period).
    let mut data = support::campaign(&h.deck, &[2.0, 8.0], 3, 1000.0, 0.01, 2);
    for k in 100..110 {
        data[0].stroke_m[k] = f64::NAN;
    }
    let e = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap_err();
    assert!(matches!(e, DiagnoseError::Dropout { .. }), "{e}");
    assert!(e.to_string().contains("1/64 of the stroking period"), "{e}");
    // Too short: one cycle.
    let data = support::campaign(&h.deck, &[2.0, 4.0], 1, 1000.0, 0.01, 2);
    let e = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            DiagnoseError::TooShort { .. } | DiagnoseError::NoCycle { .. }
        ),
        "{e}"
    );
    // No force column.
    let t = parse_bench_csv("time_s,stroke_m\n0,0\n0.001,1e-4\n", "nf.csv", "nf").unwrap();
    let e = rotorsim::diagnose::Measurement::from_bench(&t).unwrap_err();
    assert!(e.to_string().contains("no measured force"), "{e}");
}

/// The generator's truth is the damper model itself (finer integrator): sanity of the data.
#[test]
fn generator_is_seeded_and_noisy_at_one_percent() {
    let h = support::draw(3);
    let a = support::campaign(&h.deck, &[2.0], 2, 1000.0, 0.01, 3);
    let b = support::campaign(&h.deck, &[2.0], 2, 1000.0, 0.01, 3);
    assert_eq!(a[0].force_n, b[0].force_n);
    let mut clean = Vec::new();
    simulate(&h.deck, &a[0], a[0].time_s.len(), 1e-5, &mut clean).unwrap();
    let peak = clean.iter().fold(0.0f64, |x, f| x.max(f.abs()));
    let n = clean.len() as f64;
    let rms = (a[0]
        .force_n
        .iter()
        .zip(&clean)
        .map(|(x, y)| (x - y).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    assert!(
        (rms / peak - 0.01).abs() < 0.001,
        "noise {rms} vs peak {peak}"
    );
}

/// Free play as in hardware, a gap behind a contact stiffness: named as such (not as a mount
/// compliance), the gap recovered, every parameter reported with a 95% interval, and the limit
/// the data support stated.
#[test]
fn compliant_free_play_is_found_with_its_gap() {
    for (i, u) in [0.3, 0.7].into_iter().enumerate() {
        let h = support::hidden(Cause::CompliantFreePlay, u);
        let o = run(&h, 200 + i as u64);
        let d = &o.diagnosis;
        check_found(&h, 200 + i as u64, &o);
        assert!(d.free_play_limit.is_some());
        let k_true = h
            .deck
            .extensions
            .free_play_contact_stiffness_n_per_m
            .unwrap();
        let k = d.parameters["contact_stiffness_N_per_m"];
        assert!(
            (k - k_true).abs() < 0.25 * k_true,
            "stiffness {k:e} vs {k_true:e}"
        );
        for (k, v) in &d.parameters {
            let [lo, hi] = d.parameter_intervals[k];
            assert!(lo <= *v && *v <= hi, "{k} = {v} outside [{lo}, {hi}]");
        }
    }
}

/// Clipping and dropouts are named as acquisition faults, their samples left out of the
/// comparison: a nominal damper's data clipped at 9 kN in one test and with rows lost in the
/// other is `force_clipping+force_dropouts`, the rail read exactly, the damper `none`.
#[test]
fn clipping_and_dropouts_are_named_and_not_compared() {
    let base = support::nominal_deck();
    let h = support::hidden(Cause::None, 0.0);
    let mut data = support::campaign(&h.deck, &[2.0, 8.0], 3, 1000.0, 0.01, 2);
    for f in &mut data[1].force_n {
        *f = f.min(9000.0);
    }
    let clipped = data[1].force_n.iter().filter(|&&f| f == 9000.0).count();
    assert!(clipped > 20, "the test clips: {clipped}");
    for k in [200, 201, 350] {
        data[0].stroke_m[k] = f64::NAN;
        data[0].force_n[k] = f64::NAN;
    }
    data[0].velocity_m_s[500] = f64::NAN;
    let o = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    assert_eq!(
        d.cause, "force_clipping+force_dropouts",
        "{:#?}",
        d.candidates
    );
    assert_eq!(d.parameters["clip_high_N"], 9000.0);
    assert!(!d.parameters.contains_key("clip_low_N"));
    assert_eq!(d.parameters["dropout_rows"], 4.0);
    let s = &d.acquisition_screen;
    assert_eq!(
        (s[0].dropout_rows, s[0].bridged_rows, s[0].clipped_samples),
        (4, 4, 0)
    );
    assert_eq!(
        (s[1].dropout_rows, s[1].clip_high_N, s[1].clipped_samples),
        (0, Some(9000.0), clipped)
    );
    assert!(d.evidence.iter().any(|e| e.starts_with("the data acquisition: the force channel is clipped at +9000 N")), "{:#?}", d.evidence);
    assert!(
        d.limitations.iter().any(|l| l.starts_with("force clipped")),
        "{:#?}",
        d.limitations
    );
    // Nothing not measured reaches a figure: the noise, RMS and BIC are finite.
    assert!(
        d.noise_sigma_N.is_finite() && d.baseline_rms_N.is_finite() && d.baseline_bic.is_finite()
    );
    assert!(
        d.candidates.iter().all(|c| !c.bic.is_nan()),
        "{:#?}",
        d.candidates
    );
    // The stroke is bridged on a straight line; the force there stays not measured.
    let c = &o.curves[0];
    assert!(c.stroke_m.iter().all(|x| x.is_finite()));
    assert!(c.measured_n[200].is_nan() && c.measured_n[500].is_nan());
    let (t, x) = (&c.time_s, &c.stroke_m);
    let line = x[199] + (x[202] - x[199]) * (t[200] - t[199]) / (t[202] - t[199]);
    assert!((x[200] - line).abs() < 1e-15, "{} vs {line}", x[200]);
    // The clipped samples are not compared: the baseline's RMS over the clipped test equals its
    // RMS over the samples below the rail.
    let (b, m) = (&o.curves[1].baseline_n, &data[1].force_n);
    let from = o.curves[1].from;
    let (mut ss, mut n) = (0.0, 0);
    for k in from..m.len() {
        if m[k] < 9000.0 {
            ss += (b[k] - m[k]).powi(2);
            n += 1;
        }
    }
    let rms = (ss / n as f64).sqrt();
    let t1 = &d.tests[1];
    assert!(
        (t1.baseline_rms_N - rms).abs() < 1e-9 * rms,
        "{} vs {rms}",
        t1.baseline_rms_N
    );
}

/// The oil warms from test to test (20 to 80 C over a campaign of six amplitudes, hottest
/// last) with the density and bulk-modulus laws of a mineral oil; the diagnosis, given each
/// test's temperature and the data sheet without a temperature law, names the oil's
/// temperature and recovers the coefficients and the data sheet's temperature (SYNTHETIC: this
/// library's damper generates the data; the blind suite's independent truth has laws of its own).
#[test]
fn a_warming_oil_is_named_with_its_density_coefficient() {
    let base = support::nominal_deck();
    let (c_rho, c_b) = (7.0e-4, 5.0e-3);
    let law = |t_ref: f64| {
        let mut d = base.clone();
        d.oil = Some(OilTemperature {
            temperature_k: t_ref,
            density_per_k: c_rho,
            bulk_modulus_per_k: c_b,
            viscosity_per_k: 0.0,
        });
        d
    };
    let v = [1.0, 2.0, 3.0, 4.0, 6.0, 8.0];
    let mut data = support::campaign(&base, &v, 4, 1000.0, 0.0, 5);
    let temps: Vec<f64> = (0..v.len())
        .map(|i| 293.15 + 60.0 * i as f64 / (v.len() - 1) as f64)
        .collect();
    // The data sheet holds at the tests' median temperature (what the diagnosis assumes).
    let truth = law(0.5 * (temps[2] + temps[3]));
    let mut rng = support::Rng::new(41);
    let mut peak: f64 = 0.0;
    for (m, &t) in data.iter_mut().zip(&temps) {
        m.oil_temperature_k = Some(t);
        let n = m.time_s.len();
        let mut f = Vec::new();
        simulate(&truth, m, n, 1.0e-5, &mut f).unwrap();
        peak = peak.max(f.iter().fold(0.0f64, |a, x| a.max(x.abs())));
        m.force_n = f;
    }
    for m in &mut data {
        for f in &mut m.force_n {
            *f += 0.01 * peak * rng.normal();
        }
    }
    let o = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    eprintln!("{}: {}; {}", d.cause, d.criterion, d.pair_stage);
    assert_eq!(d.cause, "oil_temperature", "{:#?}", d.candidates);
    let got = d.parameters["density_thermal_coefficient_per_K"];
    eprintln!(
        "oil: {:?}, intervals {:?}, gain {:.3}",
        d.parameters, d.parameter_intervals, d.gain
    );
    assert!((got / c_rho - 1.0).abs() < 0.25, "c_rho {got} for {c_rho}");
    // The deck states no temperature: the data sheet's is fitted beside the coefficients.
    for (k, truth) in [
        ("density_thermal_coefficient_per_K", c_rho),
        ("bulk_modulus_thermal_coefficient_per_K", c_b),
        ("oil_reference_temperature_K", 0.5 * (temps[2] + temps[3])),
    ] {
        let iv = d.parameter_intervals[k];
        assert!(iv[0] <= truth && truth <= iv[1], "{k}: {iv:?} for {truth}");
    }
    assert!(
        d.evidence
            .iter()
            .any(|e| e.starts_with("the oil's temperature")),
        "{:#?}",
        d.evidence
    );
    // Without temperatures the candidate is not there (nothing to fit it to).
    for m in &mut data {
        m.oil_temperature_k = None;
    }
    let o = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap();
    assert!(o
        .diagnosis
        .candidates
        .iter()
        .all(|c| !c.cause.contains("oil_temperature")));
}

/// The same warming with no temperature recorded: the tests, given in the order they were run
/// (amplitude order here), carry the oil's drift, and the diagnosis names it with the fractions
/// of density and bulk modulus lost from the first test to the last (SYNTHETIC: this library's
/// damper generates the data, the data sheet holding at the first test's temperature).
#[test]
fn an_unrecorded_warming_is_named_as_a_drift_of_the_oil() {
    let base = support::nominal_deck();
    let (c_rho, c_b, warming) = (7.0e-4, 5.0e-3, 60.0);
    let mut truth = base.clone();
    truth.oil = Some(OilTemperature {
        temperature_k: 293.15,
        density_per_k: c_rho,
        bulk_modulus_per_k: c_b,
        viscosity_per_k: 0.0,
    });
    let v = [1.0, 2.0, 3.0, 4.0, 6.0, 8.0];
    let mut data = support::campaign(&base, &v, 4, 1000.0, 0.0, 5);
    let mut rng = support::Rng::new(43);
    let mut peak: f64 = 0.0;
    let n_tests = data.len();
    for (i, m) in data.iter_mut().enumerate() {
        m.oil_temperature_k = Some(293.15 + warming * i as f64 / (n_tests - 1) as f64);
        let n = m.time_s.len();
        let mut f = Vec::new();
        simulate(&truth, m, n, 1.0e-5, &mut f).unwrap();
        peak = peak.max(f.iter().fold(0.0f64, |a, x| a.max(x.abs())));
        m.force_n = f;
        m.oil_temperature_k = None;
    }
    for m in &mut data {
        for f in &mut m.force_n {
            *f += 0.01 * peak * rng.normal();
        }
    }
    let o = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    eprintln!(
        "drift: {:?}, intervals {:?}, gain {:.3}",
        d.parameters, d.parameter_intervals, d.gain
    );
    assert_eq!(d.cause, "oil_drift", "{:#?}", d.candidates);
    // The library's laws are exponential: the fractions lost over the warming.
    for (k, c) in [
        ("oil_density_drop_fraction", c_rho),
        ("oil_bulk_modulus_drop_fraction", c_b),
    ] {
        let truth = 1.0 - (-c * warming).exp();
        let iv = d.parameter_intervals[k];
        assert!(iv[0] <= truth && truth <= iv[1], "{k}: {iv:?} for {truth}");
    }
    assert!(d.evidence.iter().any(|e| e.starts_with("the oil warming")));
    // The drift is the campaign's: the extended deck is the data sheet's, with no oil law.
    assert_eq!(o.extended.oil, None);
    assert_eq!(o.extended, base);
    // A deck with the oil's law (at the first test's temperature) reads the drift as a warming:
    // the density's 95% interval, 3.9-4.7%, is 57-68 K by the law.
    let o = diagnose(&truth, &data, &DiagnoseOptions::default()).unwrap();
    assert_eq!(o.diagnosis.cause, "oil_drift");
    let got: f64 = o
        .diagnosis
        .evidence
        .iter()
        .find_map(|e| e.split("the oil warming by ").nth(1))
        .and_then(|t| t.split(' ').next())
        .and_then(|k| k.parse().ok())
        .unwrap_or_else(|| panic!("{:#?}", o.diagnosis.evidence));
    assert!((got - warming).abs() < 8.0, "{got} K for {warming} K");
    assert_eq!(o.extended, truth);
}

/// Temperatures in some tests only: the oil is not fitted either way, and the diagnosis says so.
#[test]
fn temperatures_in_some_tests_only_are_named_as_a_limitation() {
    let base = support::nominal_deck();
    let mut data = support::campaign(&base, &[1.0, 3.0, 6.0], 3, 1000.0, 0.01, 7);
    data[1].oil_temperature_k = Some(300.0);
    let opts = DiagnoseOptions::baseline_only();
    let d = diagnose(&base, &data, &opts).unwrap().diagnosis;
    assert!(
        d.limitations
            .iter()
            .any(|l| l.starts_with("1 of 3 tests record the oil temperature")),
        "{:#?}",
        d.limitations
    );
}
