//! Residual signatures on a SYNTHETIC campaign with seal friction hidden: the measured force's
//! step at velocity reversal is the Coulomb jump 2 F_c, the seal-friction candidate predicts the
//! same step, the baseline has none; every candidate's predicted signature is reported, and
//! drawn in the report beside the measured one.
mod diagnose_support;
use diagnose_support as support;
use rotorsim::diagnose::report::{
    html, noise_of, signature_plots, NOISE_BAND_SD, SIGNATURE_QUANTITIES,
};
use rotorsim::diagnose::{diagnose, Cause, DiagnoseOptions};
use rotorsim::report::plot::SeriesKind;

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

    figure_draws_every_signature(&o);
}

/// The signature figure: one dot series per source in every panel, the measured value drawn
/// (dot, dashed line) equal to diagnosis.json's, the noise band measured +- 2 sd; the noise sd
/// of the reversal step against white noise's analytic one.
fn figure_draws_every_signature(o: &rotorsim::diagnose::Outcome) {
    let d = &o.diagnosis;
    let j = serde_json::to_value(d).unwrap();
    let noise = noise_of(d, &o.curves);
    // The step is a difference of two sample means of the noise: sd = sigma sqrt(1/n+ + 1/n-).
    let (mut np, mut nn) = (0usize, 0usize);
    for c in &o.curves {
        let vmax = c.velocity_m_s[c.from..]
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        np += c.velocity_m_s[c.from..]
            .iter()
            .filter(|&&v| v > 0.2 * vmax)
            .count();
        nn += c.velocity_m_s[c.from..]
            .iter()
            .filter(|&&v| v < -0.2 * vmax)
            .count();
    }
    let analytic = d.noise_sigma_N * (1.0 / np as f64 + 1.0 / nn as f64).sqrt();
    // 32 realizations: the sample sd is within ~13% (1 sd) of the true one.
    assert!(
        (noise.reversal_step_N / analytic - 1.0).abs() < 0.4,
        "noise sd of the step {} N vs analytic {analytic} N",
        noise.reversal_step_N
    );
    let plots = signature_plots(d, Some(&noise), true);
    assert_eq!(plots.len(), SIGNATURE_QUANTITIES.len());
    let sources: Vec<&str> = d.signatures.iter().map(|g| g.source.as_str()).collect();
    for (p, (key, title, _, f)) in plots.iter().zip(SIGNATURE_QUANTITIES) {
        assert_eq!(&p.title, title);
        let dots: Vec<&str> = p
            .series
            .iter()
            .filter(|s| s.kind == SeriesKind::Dots)
            .map(|s| s.name.as_str())
            .collect();
        let mut a = dots.clone();
        let mut b = sources.clone();
        a.sort_unstable();
        b.sort_unstable();
        assert_eq!(a, b, "{key}: one dot series per source");
        let want = j["signatures"][0][key].as_f64().unwrap();
        assert_eq!(j["signatures"][0]["source"], "measured");
        let m = p.series.iter().find(|s| s.name == "measured").unwrap();
        assert_eq!(m.x, vec![want], "{key}: measured dot");
        let line = p
            .series
            .iter()
            .find(|s| s.name == "measured value")
            .unwrap();
        assert_eq!(line.x, vec![want, want], "{key}: measured line");
        let band = p
            .series
            .iter()
            .find(|s| s.kind == SeriesKind::Band)
            .unwrap();
        let sd = f(&noise);
        assert!(sd > 0.0, "{key}: noise sd {sd}");
        assert_eq!(
            band.x,
            vec![want - NOISE_BAND_SD * sd, want + NOISE_BAND_SD * sd]
        );
        // the chosen cause is ringed at its own value
        let chosen = d.signatures.iter().find(|g| g.source == d.cause).unwrap();
        let ring = p
            .series
            .iter()
            .find(|s| s.kind == SeriesKind::Rings)
            .unwrap();
        assert_eq!(ring.x, vec![f(chosen)]);
        // rows: measured at the top, labelled SYNTHETIC
        let rows = p.y_categories.as_ref().unwrap();
        assert_eq!(rows[0], "measured (SYNTHETIC)");
        assert_eq!(m.y, vec![0.0]);
    }
    let page = html(d, &o.curves, "SYNTHETIC campaign").unwrap();
    let fig = page
        .find("dwell near zero force")
        .expect("signature figure");
    assert!(
        page[..fig].contains("<td>measured</td>"),
        "table kept, before the figure"
    );
    assert!(page.contains("Signatures (SYNTHETIC data)"));
    let svg = &page[page[..fig].rfind("<svg").unwrap()..];
    let svg = &svg[..svg.find("</svg>").unwrap()];
    for s in &sources {
        assert!(svg.contains(s), "{s} drawn");
    }
}
