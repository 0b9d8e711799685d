//! DIR/diagnosis.html: residuals vs time, stroke and velocity; force-stroke and force-velocity
//! loops (measured, baseline, extended); the signatures (table and dot plots); the candidates
//! table.
use super::evidence::Signature;
use super::fit::{Curves, Diagnosis};
use crate::report::html::HtmlReport;
use crate::report::plot::{grid_svg, Plot, PlotError, OTHER_COLOURS};
use plotters::style::RGBColor;

/// The quantities of a [`Signature`] in the figure: JSON key, panel title, x axis label, value.
type Quantity = (
    &'static str,
    &'static str,
    &'static str,
    fn(&Signature) -> f64,
);
pub const SIGNATURE_QUANTITIES: [Quantity; 6] = [
    (
        "dwell_ms",
        "dwell near zero force",
        "time per zero crossing, smallest amplitude [ms]",
        |s| s.dwell_ms,
    ),
    (
        "reversal_step_N",
        "force step at reversal",
        "compressing - extending, vs baseline [N]",
        |s| s.reversal_step_N,
    ),
    (
        "lag_ms",
        "lag behind baseline (loop tilt)",
        "lag, smallest amplitude [ms]",
        |s| s.lag_ms,
    ),
    (
        "peak_ratio",
        "peak ratio",
        "|negative| / positive peak, largest amplitude [-]",
        |s| s.peak_ratio,
    ),
    (
        "plateau_pos_N",
        "positive plateau",
        "mean force above 90% of the peak [N]",
        |s| s.plateau_pos_N,
    ),
    (
        "plateau_neg_N",
        "negative plateau",
        "mean force below 90% of the negative peak [N]",
        |s| s.plateau_neg_N,
    ),
];

/// Colour of the candidates that are not the cause (grey: they stand back).
const ALSO_RAN: RGBColor = RGBColor(150, 150, 150);

/// Half-width of the measured noise band in noise standard deviations (about 95%).
pub const NOISE_BAND_SD: f64 = 2.0;

/// One dot plot per signature quantity: a row per source (measured, baseline, the chosen cause,
/// the other candidates), one dot series per source named by it; the measured value as a
/// dashed vertical line through every row, over the band measured +- 2 noise sd (`noise`, where
/// finite); the chosen cause ringed.
pub fn signature_plots(d: &Diagnosis, noise: Option<&Signature>, synthetic: bool) -> Vec<Plot> {
    let mut order: Vec<&Signature> = Vec::with_capacity(d.signatures.len());
    let is = |g: &&Signature, s: &str| g.source == s;
    // The candidate fitted (faults the data screen found are named beside it, not replayed).
    let chosen = super::acquisition::fitted_cause(&d.cause);
    order.extend(d.signatures.iter().filter(|g| is(g, "measured")));
    order.extend(d.signatures.iter().filter(|g| is(g, "baseline")));
    order.extend(d.signatures.iter().filter(|g| is(g, &chosen)));
    order.extend(
        d.signatures
            .iter()
            .filter(|g| !is(g, "measured") && !is(g, "baseline") && !is(g, &chosen)),
    );
    let rows: Vec<String> = order
        .iter()
        .map(|g| match g.source.as_str() {
            "measured" if synthetic => "measured (SYNTHETIC)".to_string(),
            s if s == chosen => format!("{s} (chosen)"),
            s => s.to_string(),
        })
        .collect();
    let n = order.len() as f64;
    let measured = order.iter().find(|g| is(g, "measured"));
    SIGNATURE_QUANTITIES
        .iter()
        .map(|&(_, title, x_label, f)| {
            let m = measured.map_or(f64::NAN, |g| f(g));
            let sd = noise.map_or(f64::NAN, f);
            let mut p = Plot::new(title, x_label, "")
                .y_categories(&rows)
                .no_legend();
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut widen = |v: f64| {
                if v.is_finite() {
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
            };
            if m.is_finite() && sd.is_finite() && sd > 0.0 {
                let (a, b) = (m - NOISE_BAND_SD * sd, m + NOISE_BAND_SD * sd);
                widen(a);
                widen(b);
                p = p.band("measured noise band", &[a, b], &[-0.5, n - 0.5]);
            }
            if m.is_finite() {
                p = p.dashed("measured value", &[m, m], &[-0.5, n - 0.5]);
            }
            for (i, g) in order.iter().enumerate() {
                let v = f(g);
                widen(v);
                p = p.dots(&g.source, &[v], &[i as f64]);
                p = match g.source.as_str() {
                    "measured" => p,
                    "baseline" => p.colour(OTHER_COLOURS[0]),
                    s if s == chosen => p.colour(OTHER_COLOURS[1]),
                    _ => p.colour(ALSO_RAN),
                };
                if g.source == chosen {
                    p = p.rings("", &[v], &[i as f64]).colour(OTHER_COLOURS[1]);
                }
            }
            if lo.is_finite() {
                let span = if hi > lo { hi - lo } else { lo.abs().max(1e-3) };
                p = p.x_range(lo - 0.08 * span, hi + 0.08 * span);
            }
            p
        })
        .collect()
}

/// The measured noise spread of the signatures ([`super::evidence::signature_noise`]) about the
/// chosen model's force (the baseline's for `none`).
pub fn noise_of(d: &Diagnosis, curves: &[Curves]) -> Signature {
    let reference: Vec<Vec<f64>> = curves.iter().map(|c| c.extended_n.clone()).collect();
    let band = super::evidence::dwell_band(curves, d.noise_sigma_N);
    super::evidence::signature_noise(curves, &reference, d.noise_sigma_N, band)
}

/// HTML report of a diagnosis; `source` describes the data and says SYNTHETIC where it is, which
/// puts the SYNTHETIC banner at the head of the report.
pub fn html(d: &Diagnosis, curves: &[Curves], source: &str) -> Result<String, PlotError> {
    html_with(d, curves, source, Some(&noise_of(d, curves)), |_| Ok(()))
}

/// As [`html`], with the signatures' noise spread given ([`noise_of`]) and extra sections (e.g.
/// the rotor-level check) after the headline and the limitations.
pub fn html_with(
    d: &Diagnosis,
    curves: &[Curves],
    source: &str,
    noise: Option<&Signature>,
    extra: impl FnOnce(&mut HtmlReport) -> Result<(), PlotError>,
) -> Result<String, PlotError> {
    let mut r = headline(d, source);
    extra(&mut r)?;
    evidence_section(&mut r, d, source, noise)?;
    identifiability_section(&mut r, d);
    not_supported_section(&mut r, d);
    spread_section(&mut r, d);
    candidates_section(&mut r, d);
    per_test_section(&mut r, d);
    for c in curves.iter().take(6) {
        curve_plots(&mut r, c)?;
    }
    Ok(r.finish())
}

/// The head of the report: the cause, its gain, the limitations.
fn headline(d: &Diagnosis, source: &str) -> HtmlReport {
    let mut r = HtmlReport::new(&format!("rotorsim diagnosis: {}", d.cause));
    if source.contains("SYNTHETIC") {
        r.banner(
            crate::report::html::Banner::Synthetic,
            "SYNTHETIC data: the \"measured\" force diagnosed here is synthetic, not a test measurement.",
        );
    }
    r.paragraph(source);
    let params: Vec<String> = d
        .parameters
        .iter()
        .map(|(k, v)| match d.parameter_intervals.get(k) {
            Some([lo, hi]) => format!("{k} = {v:.6e}, 95% interval {lo:.4e} - {hi:.4e}"),
            None => format!("{k} = {v:.6e}"),
        })
        .collect();
    let v = &d.validation;
    r.paragraph(&format!(
        "Cause: {}{}. RMS error over all compared samples: baseline {:.1} N, extended {:.1} N. Validation ({}): baseline {:.1} N, extended {:.1} N, gain {:.3}.",
        d.cause,
        if params.is_empty() { String::new() } else { format!(" ({})", params.join(", ")) },
        d.baseline_rms_N,
        d.extended_rms_N,
        v.method,
        v.baseline_rms_N,
        v.extended_rms_N,
        d.gain
    ));
    if let Some(l) = &d.free_play_limit {
        r.paragraph(&format!("Free play: {l}."));
    }
    for l in &d.limitations {
        r.notice(l);
    }
    r
}

/// The evidence and the signatures, measured beside each candidate's prediction.
fn evidence_section(
    r: &mut HtmlReport,
    d: &Diagnosis,
    source: &str,
    noise: Option<&Signature>,
) -> Result<(), PlotError> {
    r.heading(2, "Evidence");
    r.list(&d.evidence);
    r.heading(2, "Signatures: measured beside each candidate's prediction");
    let rows: Vec<Vec<String>> = d
        .signatures
        .iter()
        .map(|g| {
            vec![
                g.source.clone(),
                format!("{:.1}", g.dwell_ms),
                format!("{:+.1}", g.reversal_step_N),
                format!("{:+.2}", g.lag_ms),
                format!("{:.3}", g.peak_ratio),
                format!("{:.0}", g.plateau_pos_N),
                format!("{:.0}", g.plateau_neg_N),
            ]
        })
        .collect();
    r.table(
        &[
            "force",
            "dwell near zero [ms] (smallest amplitude)",
            "step at reversal vs baseline [N]",
            "lag behind baseline (loop tilt) [ms]",
            "|neg|/pos peak (largest amplitude)",
            "plateau + [N]",
            "plateau - [N]",
        ],
        &rows,
    );
    let synthetic = source.contains("SYNTHETIC");
    let plots = signature_plots(d, noise, synthetic);
    r.svg(
        &format!(
            "Signatures{}: each row one force, its dot the value of the quantity; black dashed line: the measured value, grey band: measured +- {NOISE_BAND_SD} sd of the spread the measurement noise alone gives (sigma {:.1} N, {} noisy copies of the chosen model's force); ringed: the chosen cause; grey dots: the other candidates. A cause that explains the data puts its dots on the measured line.",
            if synthetic { " (SYNTHETIC data)" } else { "" },
            d.noise_sigma_N,
            super::evidence::NOISE_REALIZATIONS
        ),
        &grid_svg(&plots, 2, 1100, 380)?,
    );
    Ok(())
}

/// Candidates the data cannot tell apart from the cause, and parameters they do not bound.
fn identifiability_section(r: &mut HtmlReport, d: &Diagnosis) {
    r.heading(2, "Identifiability");
    if d.identifiability.is_empty() {
        r.paragraph("No candidate is within the margin of the cause on held-out data and every parameter of the cause is bounded by the data.");
    } else {
        let rows: Vec<Vec<String>> = d
            .identifiability
            .iter()
            .map(|i| {
                vec![
                    i.candidates.join(" vs "),
                    i.why.clone(),
                    i.deciding_test
                        .as_ref()
                        .map_or("no proposed test can be simulated".into(), |t| {
                            t.statement.clone()
                        }),
                ]
            })
            .collect();
        r.table(&["not separable", "why", "test that would decide"], &rows);
    }
}

/// Candidates that pass the tests of their role but are not named.
fn not_supported_section(r: &mut HtmlReport, d: &Diagnosis) {
    if !d.considered_not_supported.is_empty() {
        r.heading(2, "Considered, not supported");
        r.paragraph("Candidates that pass the tests of their role (first cause or companion) but are not named: the 95% interval of each parameter of at least one of their causes includes its no-effect value (a lag: lies within the timing uncertainty), so the data do not tell that cause from no effect.");
        let rows: Vec<Vec<String>> = d
            .considered_not_supported
            .iter()
            .map(|n| {
                let params = n
                    .parameters
                    .iter()
                    .map(|(k, v)| {
                        let iv = n.intervals.get(k).map_or(String::new(), |[lo, hi]| {
                            format!(" (95% {lo:.3e} - {hi:.3e})")
                        });
                        let ne = n
                            .no_effect
                            .get(k)
                            .map_or("none of its own".into(), |e| e.describe());
                        format!("{k} = {v:.4e}{iv}, no effect at {ne}")
                    })
                    .collect::<Vec<_>>()
                    .join("; ");
                vec![
                    n.name.clone(),
                    n.role.clone(),
                    params,
                    n.parts_not_supported.join(", "),
                ]
            })
            .collect();
        r.table(
            &[
                "candidate",
                "role",
                "parameters (95% interval), no-effect value",
                "not supported",
            ],
            &rows,
        );
    }
}

/// The cause's parameters fitted test by test, and their spread.
fn spread_section(r: &mut HtmlReport, d: &Diagnosis) {
    if !d.parameter_spread.is_empty() {
        r.heading(2, "The cause's parameters test by test");
        r.paragraph("Each parameter of the cause fitted to each test alone. A model of the right form gives every test the same value up to noise; a value that moves with amplitude or frequency stands in for something the model does not have. The spread is the standard deviation of ln x across tests beyond the noise (DerSimonian-Laird); the 95% interval above includes it.");
        let names: Vec<&String> = d.parameter_spread.keys().collect();
        let tests: Vec<&String> = d
            .parameter_spread
            .values()
            .next()
            .map(|s| s.per_test.keys().collect())
            .unwrap_or_default();
        let mut rows: Vec<Vec<String>> = tests
            .iter()
            .map(|t| {
                let mut row = vec![(*t).clone()];
                for n in &names {
                    row.push(match d.parameter_spread[*n].per_test.get(*t) {
                        Some(Some(v)) => format!("{v:.4e}"),
                        _ => "not bounded".into(),
                    });
                }
                row
            })
            .collect();
        let mut joint = vec!["all tests (joint fit)".to_string()];
        let mut spread = vec!["spread (sd of ln x beyond noise; Q, tests)".to_string()];
        for n in &names {
            joint.push(
                d.parameters
                    .get(*n)
                    .map_or(String::new(), |v| format!("{v:.4e}")),
            );
            let sp = &d.parameter_spread[*n];
            spread.push(format!(
                "{:.1}% (Q {:.1}, {})",
                100.0 * sp.spread_ln,
                sp.heterogeneity_q,
                sp.tests
            ));
        }
        rows.push(joint);
        rows.push(spread);
        let mut head = vec!["test"];
        head.extend(names.iter().map(|n| n.as_str()));
        r.table(&head, &rows);
    }
}

/// Every candidate ranked by BIC, and the criterion.
fn candidates_section(r: &mut HtmlReport, d: &Diagnosis) {
    r.heading(2, "Candidates (ranked by BIC)");
    let rows: Vec<Vec<String>> = d
        .candidates
        .iter()
        .map(|c| {
            vec![
                c.cause.clone(),
                c.k.to_string(),
                format!("{:.1}", c.bic),
                format!("{:.1}", c.rms_N),
                format!("{:.1}", c.held_out_rms_N),
                c.parameters
                    .iter()
                    .map(|(k, v)| match c.intervals.get(k) {
                        Some([lo, hi]) => format!("{k} = {v:.4e} (95% {lo:.3e} - {hi:.3e})"),
                        None => format!("{k} = {v:.4e}"),
                    })
                    .collect::<Vec<_>>()
                    .join(", "),
                c.failure.clone().unwrap_or_default(),
            ]
        })
        .collect();
    r.table(
        &[
            "cause",
            "k",
            "BIC",
            "RMS all [N]",
            "RMS held-out [N]",
            "parameters (95% interval)",
            "failure",
        ],
        &rows,
    );
    r.paragraph(&format!(
        "Baseline BIC {:.1}; noise sigma {:.1} N; threshold {:.1} N. {}",
        d.baseline_bic, d.noise_sigma_N, d.threshold_N, d.criterion
    ));
}

/// Baseline and extended RMS of each test.
fn per_test_section(r: &mut HtmlReport, d: &Diagnosis) {
    r.heading(2, "Per test");
    let rows: Vec<Vec<String>> = d
        .tests
        .iter()
        .map(|t| {
            vec![
                t.name.clone(),
                t.role.clone(),
                format!("{:.3}", 1e3 * t.amplitude_m),
                format!("{:.0}", t.peak_force_N),
                format!("{:.1}", t.baseline_rms_N),
                format!("{:.1}", t.extended_rms_N),
            ]
        })
        .collect();
    r.table(
        &[
            "test",
            "role",
            "amplitude [mm]",
            "peak force [N]",
            "baseline RMS [N]",
            "extended RMS [N]",
        ],
        &rows,
    );
}

/// Residuals and loops of one test.
fn curve_plots(r: &mut HtmlReport, c: &Curves) -> Result<(), PlotError> {
    let s = c.from;
    let t = &c.time_s[s..];
    let res_b: Vec<f64> = (s..c.time_s.len())
        .map(|k| c.measured_n[k] - c.baseline_n[k])
        .collect();
    let res_e: Vec<f64> = (s..c.time_s.len())
        .map(|k| c.measured_n[k] - c.extended_n[k])
        .collect();
    r.heading(2, &format!("{} ({})", c.name, c.role));
    let p = Plot::new(
        &format!("{}: residual (measured - model) vs time", c.name),
        "time [s]",
        "residual [N]",
    )
    .points("baseline", t, &res_b)
    .points("extended", t, &res_e);
    r.svg("residual vs time", &p.to_svg(800, 320)?);
    let p = Plot::new(
        &format!("{}: residual vs stroke", c.name),
        "stroke [m]",
        "residual [N]",
    )
    .points("baseline", &c.stroke_m[s..], &res_b)
    .points("extended", &c.stroke_m[s..], &res_e);
    r.svg("residual vs stroke", &p.to_svg(800, 320)?);
    let p = Plot::new(
        &format!("{}: residual vs velocity", c.name),
        "stroke rate [m/s]",
        "residual [N]",
    )
    .points("baseline", &c.velocity_m_s[s..], &res_b)
    .points("extended", &c.velocity_m_s[s..], &res_e);
    r.svg("residual vs velocity", &p.to_svg(800, 320)?);
    let p = Plot::new(
        &format!("{}: force vs stroke", c.name),
        "stroke [m]",
        "force [N]",
    )
    .points("measured", &c.stroke_m[s..], &c.measured_n[s..])
    .line("baseline", &c.stroke_m[s..], &c.baseline_n[s..])
    .dashed("extended", &c.stroke_m[s..], &c.extended_n[s..]);
    r.svg("force-stroke loop", &p.to_svg(800, 420)?);
    let p = Plot::new(
        &format!("{}: force vs velocity", c.name),
        "stroke rate [m/s]",
        "force [N]",
    )
    .points("measured", &c.velocity_m_s[s..], &c.measured_n[s..])
    .line("baseline", &c.velocity_m_s[s..], &c.baseline_n[s..])
    .dashed("extended", &c.velocity_m_s[s..], &c.extended_n[s..]);
    r.svg("force-velocity loop", &p.to_svg(800, 420)?);
    Ok(())
}
