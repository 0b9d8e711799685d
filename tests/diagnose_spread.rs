//! The cause's parameters fitted test by test (`parameter_spread` of diagnosis.json): a model of
//! the right form gives every test the same value up to noise; a parameter that truly moves
//! across the campaign (here a leakage that drifts from test to test, as a clearance does when
//! the oil warms) shows a spread of the size it has, and the interval takes it.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::{diagnose, Cause, DiagnoseOptions, Measurement};

/// Six harmonic tests (1-8 in/s, 4 cycles, 1 kHz), test i with the leakage `k0 exp(delta_i)`,
/// plus Gaussian noise of 1% of the campaign's peak force (one sigma for every test).
fn drifting(deltas: &[f64; 6], seed: u64) -> Vec<Measurement> {
    let base = support::nominal_deck();
    let k0 = 8.0e-12;
    let v = [1.0, 2.0, 3.0, 4.0, 6.0, 8.0];
    let mut data: Vec<Measurement> = v
        .iter()
        .zip(deltas)
        .map(|(&v, d)| {
            let deck = Cause::PistonLeakage.apply(&base, &[k0 * d.exp()]);
            support::campaign(&deck, &[v], 4, 1000.0, 0.0, seed)
                .pop()
                .unwrap()
        })
        .collect();
    let peak = data
        .iter()
        .flat_map(|m| m.force_n.iter())
        .fold(0.0f64, |a, f| a.max(f.abs()));
    let mut rng = support::Rng::new(seed);
    for m in &mut data {
        for f in &mut m.force_n {
            *f += 0.01 * peak * rng.normal();
        }
    }
    data
}

#[test]
fn parameter_spread_is_noise_for_the_right_model_and_the_drift_for_a_drifting_one() {
    let base = support::nominal_deck();
    let opts = DiagnoseOptions::default();
    // Constant leakage: Cochran's Q of the six per-test values is chi-square with 5 degrees of
    // freedom; below its 0.999 quantile (20.5).
    let same = diagnose(&base, &drifting(&[0.0; 6], 3), &opts)
        .unwrap()
        .diagnosis;
    assert_eq!(same.cause, "piston_leakage", "{:#?}", same.candidates);
    let s = &same.parameter_spread["leakage_m3_per_s_Pa"];
    eprintln!("constant leakage: {s:?}");
    assert_eq!(s.tests, 6, "{s:?}");
    assert!(s.heterogeneity_q < 20.5, "{s:?}");
    // Drift of +-20% in ln k (standard deviation 0.2 across the tests): the spread finds it
    // (DerSimonian-Laird weights the tests by their noise, so within 35%), and the interval
    // grows to at least 1.96 x the spread either side.
    let deltas = [0.2, -0.2, 0.2, -0.2, 0.2, -0.2];
    let d = diagnose(&base, &drifting(&deltas, 3), &opts)
        .unwrap()
        .diagnosis;
    assert_eq!(d.cause, "piston_leakage", "{:#?}", d.candidates);
    let s = &d.parameter_spread["leakage_m3_per_s_Pa"];
    eprintln!("drifting leakage: {s:?}");
    assert!(s.heterogeneity_q > 100.0, "{s:?}");
    assert!(
        (s.spread_ln - 0.2).abs() < 0.35 * 0.2,
        "spread {} against 0.2: {s:?}",
        s.spread_ln
    );
    for (test, v) in &s.per_test {
        assert!(v.is_some(), "{test} bounds the leakage: {s:?}");
    }
    let x = d.parameters["leakage_m3_per_s_Pa"];
    let iv = d.parameter_intervals["leakage_m3_per_s_Pa"];
    assert!(
        (iv[1] / x).ln() >= 1.96 * s.spread_ln && (x / iv[0]).ln() >= 1.96 * s.spread_ln,
        "{iv:?} around {x:e}, spread {}",
        s.spread_ln
    );
    let row = d.candidates.iter().find(|c| c.cause == d.cause).unwrap();
    assert_eq!(row.intervals, d.parameter_intervals);
}
