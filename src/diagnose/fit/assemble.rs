//! The last stage: the Diagnosis and the extended deck from what the stages decided.
use super::choice::{Choice, HeldOutTest};
use super::pairs::Pairing;
use super::prepare::{Campaign, Ctx};
use super::singles::Singles;
use super::{
    free_play_limit, identifiability, name_screened, rms_over, Candidate, Curves, Diagnosis,
    Evaluated, IdContext, Outcome, TestSummary, Validation, Window, COMPANION_ALPHA,
};
use crate::diagnose::data::Measurement;
use crate::diagnose::evidence;
use crate::diagnose::support::{self, NotSupported};
use crate::hydraulics::{DamperDeck, OilTemperature};
use std::collections::BTreeMap;

/// What the companions' and the choice's stages decided.
pub(super) struct Decided<'e> {
    pub(super) pairing: Pairing,
    pub(super) test: HeldOutTest,
    pub(super) choice: Choice<'e>,
    pub(super) not_supported: Vec<NotSupported>,
}

/// The cause named before the screened faults, and its model (the baseline's for `none`).
struct Extended {
    cause: String,
    params: BTreeMap<String, f64>,
    sim: Vec<Vec<f64>>,
    deck: DamperDeck,
    rms: f64,
    held: f64,
}

fn extended(chosen: Option<&Evaluated>, s: &Singles, base: &DamperDeck) -> Extended {
    match chosen {
        Some((row, Some(sim), deck, _)) => Extended {
            cause: row.cause.clone(),
            params: row.parameters.clone(),
            sim: sim.clone(),
            deck: deck.clone(),
            rms: row.rms_N,
            held: row.held_out_rms_N,
        },
        _ => Extended {
            cause: "none".to_string(),
            params: BTreeMap::new(),
            sim: s.baseline.sim.clone(),
            deck: base.clone(),
            rms: s.baseline.rms,
            held: s.baseline.held,
        },
    }
}

/// Stage 11, the report: the Diagnosis, the extended deck and the curves.
pub(super) fn assemble(
    cx: &Ctx,
    s: &Singles,
    evaluated: &[Evaluated],
    mut campaign: Campaign,
    d: Decided,
) -> Outcome {
    let Decided {
        pairing,
        test,
        choice,
        not_supported,
    } = d;
    let (base_bic, base_held, threshold) = (s.baseline.bic, s.baseline.held, cx.threshold);
    let ext = extended(choice.chosen, s, cx.base);
    let param_iv = choice.param_iv;
    let free_play_limit = free_play_limit(&ext.cause, evaluated, &param_iv);
    let mut companions = pairing.companions;
    for c in &mut companions {
        c.kept = c.pair == ext.cause;
        if c.passes && !c.kept {
            c.reason
                .push_str("; passes, but another pair has the lower BIC");
        }
    }
    let one_amp = campaign.one_amp;
    if one_amp {
        campaign.limitations.extend(near_tie(
            evaluated,
            &ext.cause,
            threshold.max(0.05 * base_held),
        ));
    }
    let identifiability = identifiability(
        choice.chosen,
        evaluated,
        cx.data,
        &cx.all_w,
        IdContext {
            base_bic,
            base_held,
            // Several amplitudes: the held-out tests check how an effect scales, so the
            // noise-level threshold of the choice separates; one amplitude: held-out cycles
            // of the same test do not, and the near-tie margin of the limitations applies.
            margin: if one_amp {
                threshold.max(0.05 * base_held)
            } else {
                threshold
            },
            sigma: cx.sigma,
            one_amp,
            scales: cx.scales,
            base: cx.base,
            max_h: cx.opts.max_substep_s,
        },
    );
    let curves = curves(cx, &campaign.roles, &s.baseline.sim, &ext.sim);
    let tests = test_summaries(&curves, cx.data);
    // The cause's row carries the intervals it is reported with.
    let mut cand_rows: Vec<Candidate> = evaluated.iter().map(|e| e.0.clone()).collect();
    if let Some(r) = cand_rows.iter_mut().find(|r| r.cause == ext.cause) {
        r.intervals = param_iv.clone();
    }
    let mut evidence = evidence::evidence(
        &curves,
        cx.sigma,
        &ext.cause,
        &ext.params,
        &cand_rows,
        base_held,
        ext.held,
    );
    // A drift read by the oil law the deck gives: the warming it amounts to.
    if let (true, Some(law), Some(&f)) = (
        ext.cause.split('+').any(|c| c == "oil_drift"),
        campaign.given_oil.filter(|l| l.density_per_k > 0.0),
        ext.params.get("oil_density_drop_fraction"),
    ) {
        evidence.push(format!(
            "by the deck's oil law (density {:.2e} /K) the density's loss is the oil warming by {:.0} K from the first test to the last",
            law.density_per_k,
            OilTemperature::loss_exponent(f) / law.density_per_k
        ));
    }
    let signatures = signatures(cx, &curves, &s.baseline.sim, evaluated);
    let parameter_no_effect =
        support::no_effects(&ext.cause, &ext.params, &param_iv, &s.naming.ne_cx);
    let (cause, params, param_iv) = name_screened(
        &campaign.screened,
        (ext.cause, ext.params, param_iv),
        &mut evidence,
        &mut campaign.limitations,
    );
    let extended = extended_deck(ext.deck, cause.contains("oil_temperature"), &campaign);
    let r = &s.reference;
    let diagnosis = Diagnosis {
        gain: 1.0 - ext.held / base_held,
        cause,
        parameters: params,
        parameter_intervals: param_iv,
        parameter_spread: choice.spreads,
        free_play_limit,
        pair_stage: pairing.pair_stage,
        companions,
        baseline_rms_N: s.baseline.rms,
        extended_rms_N: ext.rms,
        validation: Validation {
            method: campaign.method,
            baseline_rms_N: base_held,
            extended_rms_N: ext.held,
        },
        candidates: cand_rows,
        evidence,
        noise_sigma_N: cx.sigma,
        threshold_N: threshold,
        baseline_bic: base_bic,
        criterion: format!(
            "BIC = n ln(RSS/n) + k ln n on the fit samples (n samples, k fitted parameters); the lowest BIC is chosen if it is below the reference's and improves the held-out RMS by more than 0.05 sigma + 3 sigma/sqrt(2 n_held) (sigma: noise from second differences); else none. The BIC's reference is the baseline aligned by the best lag within the timing uncertainty (here {:.4} ms: BIC {:.1} against the unaligned {base_bic:.1}; its held-out RMS {:.1} N); the held-out test is against the unaligned baseline ({base_held:.1} N)",
            1e3 * r.conv_lag, r.conv_bic, r.aligned_held
        ),
        criterion_companions: format!(
            "a companion is kept only if its pair also passes a held-out test: z = sum(e d)/(sigma ||d||) over the held-out samples (e: the single cause's residual, d: the pair's change to its prediction; standard normal when the single cause is the whole truth and the noise white) above z_(1 - {COMPANION_ALPHA}/m) = {:.2}, m = {} companions fitted (Bonferroni: a false-alarm rate of {COMPANION_ALPHA} over all of them)",
            test.z_required, test.fitted
        ),
        limitations: campaign.limitations,
        acquisition_screen: campaign.screened,
        signatures,
        identifiability,
        tests,
        parameter_no_effect,
        considered_not_supported: not_supported,
        criterion_naming: format!(
            "a cause (each cause of a pair, a physical cause and an acquisition fault beside it alike) is named only if the 95% interval of at least one of its parameters excludes that parameter's no-effect value (an end unbounded toward it does not); the lag's no-effect value is its timing uncertainty, +-{:.4} ms here (half the sample interval h = {:.4} ms, plus the replay's own delay {:.4} ms): its interval must lie wholly outside it; candidates that pass the tests but not this are listed in considered_not_supported",
            1e3 * s.naming.ne_cx.lag_timing_s,
            1e3 * s.naming.sample_h,
            1e3 * s.fcx.replay_delay_s.abs()
        ),
    };
    Outcome {
        diagnosis,
        extended,
        curves,
    }
}

/// One amplitude: the two best single causes whose held-out RMS differ by less than `margin`,
/// as a limitation (none for `none`).
fn near_tie(evaluated: &[Evaluated], cause: &str, margin: f64) -> Option<String> {
    let mut singles_ev = evaluated.iter().filter(|e| !e.0.cause.contains('+'));
    let (a, b) = (singles_ev.next()?, singles_ev.next()?);
    (cause != "none" && b.0.held_out_rms_N - a.0.held_out_rms_N < margin).then(|| {
        format!(
            "{} and {} fit these data about equally well (held-out RMS {:.1} vs {:.1} N): not decidable from one amplitude",
            a.0.cause, b.0.cause, a.0.held_out_rms_N, b.0.held_out_rms_N
        )
    })
}

/// The extended deck's oil. A drift is the campaign's, not the damper's: the deck keeps the
/// oil it was given. The law assumed for the oil (no coefficients, at the tests' median) is not
/// the deck's unless the oil's temperature is the cause.
fn extended_deck(deck: DamperDeck, oil_is_cause: bool, campaign: &Campaign) -> DamperDeck {
    if campaign.oil_drift {
        DamperDeck {
            oil: campaign.given_oil,
            ..deck
        }
    } else if campaign.oil_reference_unknown && !oil_is_cause {
        DamperDeck { oil: None, ..deck }
    } else {
        deck
    }
}

/// Measured, baseline and extended force of every test.
fn curves(cx: &Ctx, roles: &[String], baseline: &[Vec<f64>], ext_sim: &[Vec<f64>]) -> Vec<Curves> {
    cx.data
        .iter()
        .enumerate()
        .map(|(i, m)| Curves {
            name: m.name.clone(),
            role: roles[i].clone(),
            time_s: m.time_s.clone(),
            stroke_m: m.stroke_m.clone(),
            velocity_m_s: m.velocity_m_s.clone(),
            measured_n: m.force_n.clone(),
            baseline_n: baseline[i].clone(),
            extended_n: ext_sim[i].clone(),
            from: cx.all_w[i].from,
        })
        .collect()
}

fn test_summaries(curves: &[Curves], data: &[Measurement]) -> Vec<TestSummary> {
    curves
        .iter()
        .zip(data)
        .map(|(c, m)| {
            let w = [Window {
                test: 0,
                from: c.from,
                to: c.time_s.len(),
            }];
            let one = std::slice::from_ref(m);
            TestSummary {
                name: c.name.clone(),
                role: c.role.clone(),
                amplitude_m: m.amplitude_m(),
                peak_force_N: m.peak_force_n(),
                baseline_rms_N: rms_over(&w, std::slice::from_ref(&c.baseline_n), one),
                extended_rms_N: rms_over(&w, std::slice::from_ref(&c.extended_n), one),
            }
        })
        .collect()
}

/// Residual signatures of the measured force, the baseline and every candidate replayed.
fn signatures(
    cx: &Ctx,
    curves: &[Curves],
    baseline: &[Vec<f64>],
    evaluated: &[Evaluated],
) -> Vec<evidence::Signature> {
    let band = evidence::dwell_band(curves, cx.sigma);
    let measured: Vec<Vec<f64>> = cx.data.iter().map(|m| m.force_n.clone()).collect();
    let mut signatures = vec![
        evidence::signature(curves, &measured, "measured", band),
        evidence::signature(curves, baseline, "baseline", band),
    ];
    for e in evaluated {
        if let Some(sim) = &e.1 {
            signatures.push(evidence::signature(curves, sim, &e.0.cause, band));
        }
    }
    signatures
}
