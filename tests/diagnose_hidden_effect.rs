//! Hidden effects in SYNTHETIC bench data are found, named, their parameter recovered within tolerance, with a positive held-out gain; no effect gives `none`;
//! bad or insufficient data gets a clear message. Larger seed sweep:
//! `cargo run --release --example diagnose_hit_rate -- 40 4 2000`.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::fit::simulate;
use rotorsim::diagnose::{diagnose, Cause, DiagnoseError, DiagnoseOptions};
use rotorsim::hydraulics::bench::{parse_bench_csv, replay, BenchTest};
use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};

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
    // Clipping: flat tops at the same value.
    let mut data = support::campaign(&h.deck, &[2.0, 8.0], 3, 1000.0, 0.01, 2);
    for f in &mut data[1].force_n {
        *f = f.min(9000.0);
    }
    let e = diagnose(&base, &data, &DiagnoseOptions::default()).unwrap_err();
    assert!(
        matches!(e, DiagnoseError::Clipping { value, .. } if value == 9000.0),
        "{e}"
    );
    assert!(e.to_string().contains("clipped"), "{e}");
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
