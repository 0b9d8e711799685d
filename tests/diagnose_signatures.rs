//! Residual signatures on a SYNTHETIC campaign with seal friction hidden: the measured force's
//! step at velocity reversal is the Coulomb jump 2 F_c, the seal-friction candidate predicts the
//! same step, the baseline has none; every candidate's predicted signature is reported.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::{diagnose, Cause, DiagnoseOptions};

#[test]
fn seal_friction_signature_is_the_coulomb_step() {
    let h = support::hidden(Cause::SealFriction, 0.5);
    let data = support::campaign(&h.deck, &[1.0, 2.0, 3.0, 4.0, 6.0, 8.0], 4, 1000.0, 0.01, 5);
    let o = diagnose(&support::nominal_deck(), &data, &DiagnoseOptions::default()).unwrap();
    let d = &o.diagnosis;
    assert_eq!(d.cause, "seal_friction");
    let s = &d.signatures;
    assert_eq!(
        (s[0].source.as_str(), s[1].source.as_str()),
        ("measured", "baseline")
    );
    assert_eq!(s[1].reversal_step_N, 0.0);
    assert!(s[1].lag_ms.abs() < 1e-3, "{}", s[1].lag_ms);
    // Coulomb friction -F_c sign(v): the residual is -F_c extending, +F_c compressing.
    let step = 2.0 * h.value;
    assert!(
        (s[0].reversal_step_N / step - 1.0).abs() < 0.1,
        "measured step {} N vs 2 F_c = {step} N",
        s[0].reversal_step_N
    );
    let f = s.iter().find(|g| g.source == "seal_friction").unwrap();
    assert!(
        (f.reversal_step_N / s[0].reversal_step_N - 1.0).abs() < 0.05,
        "predicted {} vs measured {} N",
        f.reversal_step_N,
        s[0].reversal_step_N
    );
    let replayed = d.candidates.iter().filter(|c| c.failure.is_none()).count();
    assert_eq!(s.len(), 2 + replayed);
    let j = serde_json::to_value(d).unwrap();
    assert!(j["signatures"][0]["plateau_pos_N"].as_f64().unwrap() > 0.0);
}
