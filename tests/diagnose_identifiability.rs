//! Identifiability on SYNTHETIC campaigns: one stroke amplitude with piston leakage hidden
//! cannot tell the leakage from a candidate that fits the same cycles about as well, and names a
//! test outside the campaign that would decide; the same leakage at six amplitudes is separated.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::{diagnose, Cause, DiagnoseOptions};

#[test]
fn one_amplitude_leaves_leakage_undecided_and_proposes_a_test() {
    let h = support::hidden(Cause::PistonLeakage, 0.5);
    let data = support::campaign(&h.deck, &[3.0], 6, 1000.0, 0.01, 3);
    let o = diagnose(&support::nominal_deck(), &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    assert_eq!(d.cause, "piston_leakage", "{d:#?}");
    let tie = d
        .identifiability
        .iter()
        .find(|i| i.candidates.len() == 2 && i.candidates[0] == "piston_leakage")
        .unwrap_or_else(|| panic!("no tie reported: {:#?}", d.identifiability));
    assert!(tie.why.contains("one stroke amplitude"), "{}", tie.why);
    let t = tie.deciding_test.as_ref().expect("a deciding test");
    // Not a condition the campaign has: another amplitude or another frequency.
    let (a, w) = (
        data[0].amplitude_m(),
        2.0 * std::f64::consts::PI / data[0].period_s,
    );
    assert!(
        (t.amplitude_m / a - 1.0).abs() > 0.15 || (t.frequency_rad_s / w - 1.0).abs() > 0.15,
        "{t:?}"
    );
    // There the two fitted models differ by more than on the campaign, and clearly above noise.
    assert!(
        t.predicted_difference_rms_N > 2.0 * t.campaign_difference_rms_N
            && t.predicted_difference_rms_N > 3.0 * d.noise_sigma_N,
        "{t:?}"
    );
    let j = serde_json::to_value(d).unwrap();
    assert!(j["identifiability"][0]["deciding_test"]["amplitude_m"].is_number());
}

#[test]
fn several_amplitudes_separate_the_leakage() {
    let h = support::hidden(Cause::PistonLeakage, 0.5);
    let data = support::campaign(&h.deck, &[1.0, 2.0, 3.0, 4.0, 6.0, 8.0], 4, 1000.0, 0.01, 3);
    let o = diagnose(&support::nominal_deck(), &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    assert_eq!(d.cause, "piston_leakage");
    assert!(
        !d.identifiability
            .iter()
            .any(|i| i.candidates.iter().any(|c| c == "piston_leakage") && i.candidates.len() == 2),
        "{:#?}",
        d.identifiability
    );
}
