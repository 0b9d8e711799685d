//! The choice: the companions' held-out test and naming, the cause's spread across tests, the
//! lowest BIC the data support, and the candidates passed over.
use super::pairs::Pairing;
use super::prepare::Ctx;
use super::singles::Singles;
use super::{
    causes_of, held_out_z, normal_quantile, parameter_spread, Evaluated, ParameterSpread, Window,
    COMPANION_ALPHA, Z95,
};
use crate::diagnose::candidates::combined_params;
use crate::diagnose::support::{self, NotSupported};
use std::collections::BTreeMap;

/// The companions' held-out test as it was run: the z each had to exceed and how many were
/// fitted.
pub(super) struct HeldOutTest {
    pub(super) z_required: f64,
    pub(super) fitted: usize,
}

/// Stage 7, the companions' held-out test: every companion fitted, corrected for their number
/// (Bonferroni). The pair's change to the single's prediction on the held-out data,
/// `d = mu_pair - mu_single`, against the single's residual `e`: `z = sum(e d) / (sigma ||d||)`
/// is standard normal if the single cause is the whole truth and the noise white, and large
/// where the companion predicts what the single leaves. A companion passes at a family-wise
/// false-alarm rate of `COMPANION_ALPHA` when `z > z_(1 - alpha/m)`, m the companions fitted.
/// Those that fail it are added to `refused`.
pub(super) fn held_out_test(
    cx: &Ctx,
    evaluated: &[Evaluated],
    p: &mut Pairing,
    refused: &mut Vec<String>,
) -> HeldOutTest {
    let reference_sim: Option<Vec<Vec<f64>>> = p
        .refit_single
        .as_ref()
        .and_then(|b| b.1.clone())
        .or_else(|| {
            let first = p.first_cause.as_deref()?;
            evaluated.iter().find(|e| e.0.cause == first)?.1.clone()
        });
    let fitted: Vec<usize> = p
        .companions
        .iter()
        .enumerate()
        .filter(|(_, c)| {
            evaluated
                .iter()
                .any(|e| e.0.cause == c.pair && e.1.is_some())
        })
        .map(|(i, _)| i)
        .collect();
    let z_required = normal_quantile(1.0 - COMPANION_ALPHA / fitted.len().max(1) as f64);
    if let Some(rs) = &reference_sim {
        for &i in &fitted {
            let c = &mut p.companions[i];
            let Some(sim) = evaluated
                .iter()
                .find(|e| e.0.cause == c.pair)
                .and_then(|e| e.1.as_ref())
            else {
                continue;
            };
            let z = held_out_z(&cx.held_w, rs, sim, cx.data, cx.sigma);
            c.held_out_z = Some(z);
            let ok = z > z_required;
            c.reason.push_str(&format!(
                "; held-out test z = {z:.1} {} {z_required:.2} ({} companions fitted, false-alarm rate {COMPANION_ALPHA} over all of them)",
                if ok { "above" } else { "not above" },
                fitted.len()
            ));
            if c.passes && !ok {
                c.passes = false;
                refused.push(c.pair.clone());
            }
        }
    }
    HeldOutTest {
        z_required,
        fitted: fitted.len(),
    }
}

/// Stage 8, the naming rule on every companion that passes its tests: each cause of the pair
/// with its own interval (the first cause's too, refitted beside the companion). Those not
/// supported are added to `refused` and `not_supported`.
pub(super) fn name_companions(
    s: &Singles,
    evaluated: &[Evaluated],
    p: &mut Pairing,
    refused: &mut Vec<String>,
    not_supported: &mut Vec<NotSupported>,
) {
    for c in p.companions.iter_mut().filter(|c| c.passes) {
        let Some(e) = evaluated
            .iter()
            .find(|e| e.0.cause == c.pair && e.1.is_some())
        else {
            continue;
        };
        let parts = s.naming.parts_of(&e.0);
        if support::all_supported(&parts) {
            continue;
        }
        let ns = NotSupported::new(
            &e.0.cause,
            "companion",
            &e.0.parameters,
            &e.0.intervals,
            s.naming.no_effect_of(&e.0, &e.0.intervals),
            &parts,
            "passes the companions' tests (BIC, held-out RMS, held-out z)",
        );
        c.passes = false;
        c.reason.push_str(&format!(
            "; not named: the data do not support {} (considered_not_supported)",
            ns.parts_not_supported.join(" and ")
        ));
        refused.push(c.pair.clone());
        not_supported.push(ns);
    }
}

/// Windows of the parameters' spread and their labels: three tests or more, test by test;
/// fewer (a flight record), cycle by cycle from the second.
fn spread_windows(cx: &Ctx) -> (Vec<Window>, Vec<String>) {
    let data = cx.data;
    if data.len() >= 3 {
        let labels = data.iter().map(|m| m.name.clone()).collect();
        return (cx.all_w.clone(), labels);
    }
    data.iter()
        .enumerate()
        .flat_map(|(i, m)| {
            let per_cycle = m.cycle_start(1.0).max(1);
            (1..m.cycles().ceil() as usize).filter_map(move |c| {
                let w = Window {
                    test: i,
                    from: m.cycle_start(c as f64),
                    to: m.cycle_start(c as f64 + 1.0).min(m.time_s.len()),
                };
                // A last cycle cut short counts when at least half of it was recorded.
                (2 * (w.to - w.from) >= per_cycle)
                    .then(|| (w, format!("{} cycle {}", m.name, c + 1)))
            })
        })
        .unzip()
}

/// The chosen candidate, the intervals it is reported with (widened by its spread across
/// tests) and that spread per parameter.
pub(super) struct Choice<'e> {
    pub(super) chosen: Option<&'e Evaluated>,
    pub(super) param_iv: BTreeMap<String, [f64; 2]>,
    pub(super) spreads: BTreeMap<String, ParameterSpread>,
    /// Candidates refused once their intervals took their spread.
    pub(super) spread_refused: Vec<String>,
}

/// Stage 9, the choice: the lowest BIC among the candidates the data support, if it beats the
/// baseline's BIC and improves the held-out RMS by more than the noise-level threshold. A pair
/// must beat the single it extends as the single beat the baseline. The cause's intervals then
/// take its spread across tests: a cause the data no longer support with them is passed over
/// too (recorded in `not_supported`), and the choice made again.
pub(super) fn choose<'e>(
    cx: &Ctx,
    s: &Singles,
    evaluated: &'e [Evaluated],
    p: &Pairing,
    refused: &[String],
    not_supported: &mut Vec<NotSupported>,
) -> Choice<'e> {
    let (spread_w, labels) = spread_windows(cx);
    let mut spread_refused: Vec<String> = Vec::new();
    loop {
        let Some(chosen) = next_in_line(cx, s, evaluated, p, refused, &spread_refused) else {
            return Choice {
                chosen: None,
                param_iv: BTreeMap::new(),
                spreads: BTreeMap::new(),
                spread_refused,
            };
        };
        let row = &chosen.0;
        let (param_iv, spreads) = with_spread(cx, chosen, &spread_w, &labels);
        let ne = s.naming.no_effect_of(row, &param_iv);
        let parts = support::support(&row.cause, &row.parameters, &param_iv, &ne);
        if support::all_supported(&parts) {
            return Choice {
                chosen: Some(chosen),
                param_iv,
                spreads,
                spread_refused,
            };
        }
        not_supported.push(NotSupported::new(
            &row.cause,
            if p.companions.iter().any(|c| c.pair == row.cause) {
                "companion"
            } else {
                "cause"
            },
            &row.parameters,
            &param_iv,
            ne,
            &parts,
            "passes the tests of the choice, but with its parameters' spread across the tests",
        ));
        spread_refused.push(row.cause.clone());
    }
}

/// The first candidate that passes the choice's tests, if it is the lowest-BIC candidate the
/// data support: only it may be chosen, unless it is a pair that fails its own test (then the
/// best single is next in line) or a demoted compliant free play.
fn next_in_line<'e>(
    cx: &Ctx,
    s: &Singles,
    evaluated: &'e [Evaluated],
    p: &Pairing,
    refused: &[String],
    spread_refused: &[String],
) -> Option<&'e Evaluated> {
    let demoted = s.demoted.as_ref();
    let chosen = evaluated.iter().find(|(row, sim, _, _)| {
        let (ref_bic, ref_held) = if row.cause.contains('+') {
            p.pair_ref.unwrap_or((f64::NEG_INFINITY, f64::NEG_INFINITY))
        } else {
            (s.reference.conv_bic, s.reference.conv_held)
        };
        sim.is_some()
            && Some(&row.cause) != demoted
            && !refused.contains(&row.cause)
            && !spread_refused.contains(&row.cause)
            && row.bic < ref_bic
            && ref_held - row.held_out_rms_N > cx.threshold
            && s.naming.supported(row)
    });
    chosen.filter(|c| {
        evaluated
            .iter()
            .take_while(|e| !std::ptr::eq(*e, *c))
            .all(|e| {
                e.0.cause.contains('+')
                    || Some(&e.0.cause) == demoted
                    || spread_refused.contains(&e.0.cause)
                    || !s.naming.supported(&e.0)
            })
    })
}

/// The cause's parameters test by test: their spread beyond the noise widens the intervals
/// (in ln x, in quadrature with the noise and model-form half-width).
fn with_spread(
    cx: &Ctx,
    chosen: &Evaluated,
    spread_w: &[Window],
    labels: &[String],
) -> (
    BTreeMap<String, [f64; 2]>,
    BTreeMap<String, ParameterSpread>,
) {
    let row = &chosen.0;
    let mut param_iv = row.intervals.clone();
    let mut spreads = BTreeMap::new();
    let (Some(_), true) = (&chosen.1, spread_w.len() >= 3) else {
        return (param_iv, spreads);
    };
    let x = &chosen.3;
    let Some(causes) = causes_of(&row.cause) else {
        return (param_iv, spreads);
    };
    let Some(spec) = combined_params(&causes, cx.base, cx.scales) else {
        return (param_iv, spreads);
    };
    let spread = parameter_spread(
        &causes, cx.scales, cx.base, &spec, x, cx.data, spread_w, labels, cx.opts, cx.sigma,
        cx.scale,
    );
    for ((p, xc), sp) in spec.iter().zip(x).zip(spread) {
        if let Some(iv) = param_iv.get_mut(p.name) {
            if iv[1].is_finite() && iv[0] > 0.0 && sp.spread_ln > 0.0 {
                let half = (iv[1] / xc).ln().max((xc / iv[0]).ln());
                let half = half.hypot(Z95 * sp.spread_ln);
                *iv = [xc * (-half).exp(), xc * half.exp()];
            }
        }
        spreads.insert(p.name.to_string(), sp);
    }
    (param_iv, spreads)
}

/// Stage 10, candidates passed over as the first cause: every one ahead of the first supported
/// candidate that passes the choice's tests against the baseline, recorded in `not_supported`.
pub(super) fn passed_over(
    cx: &Ctx,
    s: &Singles,
    evaluated: &[Evaluated],
    p: &Pairing,
    spread_refused: &[String],
    not_supported: &mut Vec<NotSupported>,
) {
    let (base_bic, base_held, threshold) = (s.baseline.bic, s.baseline.held, cx.threshold);
    for e in evaluated
        .iter()
        .filter(|e| e.1.is_some() && Some(&e.0.cause) != s.demoted.as_ref())
        .filter(|e| !p.companions.iter().any(|c| c.pair == e.0.cause))
        .take_while(|e| !s.naming.supported(&e.0) || spread_refused.contains(&e.0.cause))
    {
        let r = &e.0;
        if spread_refused.contains(&r.cause)
            || !(r.bic < base_bic && base_held - r.held_out_rms_N > threshold)
        {
            continue;
        }
        not_supported.push(NotSupported::new(
            &r.cause,
            "cause",
            &r.parameters,
            &r.intervals,
            s.naming.no_effect_of(r, &r.intervals),
            &s.naming.parts_of(r),
            &format!(
                "BIC {:.1} below the baseline's {base_bic:.1} and held-out RMS {:.1} N below the baseline's {base_held:.1} N by more than the threshold {threshold:.1} N",
                r.bic, r.held_out_rms_N
            ),
        ));
    }
}
