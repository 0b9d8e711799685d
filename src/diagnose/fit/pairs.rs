//! The companions: when the first cause leaves a systematic residual, pairs of it with every
//! other single cause (joint fits), and acquisition faults beside a physical cause.
use super::prepare::Ctx;
use super::search::Cand;
use super::singles::Singles;
use super::{
    bic, fault_candidate, has_fault, intervals, judge_pair, nested, residuals_x, rms_over, to_z,
    Candidate, Companion, Evaluated, PAIRS_CONVERGED,
};
use crate::diagnose::acquisition::{self, Fault};
use crate::diagnose::candidates::{apply_all, combined_name, combined_params, Cause, ParamSpec};
use crate::diagnose::data::Measurement;
use rayon::prelude::*;

/// What the companions' stage leaves for the choice.
pub(super) struct Pairing {
    /// Every companion tried, with its verdict so far.
    pub(super) companions: Vec<Companion>,
    /// Whether companions were tried, and why (`pair_stage`).
    pub(super) pair_stage: String,
    /// BIC and held-out RMS a pair must beat (its single's), once pairs were fitted.
    pub(super) pair_ref: Option<(f64, f64)>,
    /// The first cause refitted from a pair's values, when that fit is better.
    pub(super) refit_single: Option<Evaluated>,
    /// The first cause: the lowest-BIC candidate the data support.
    pub(super) first_cause: Option<String>,
}

/// Stage 6, companions: the first cause (the lowest-BIC candidate the data support; those
/// ahead of it that the data do not support are passed over) and, when it passes, its
/// companions. Their fits join `evaluated`.
pub(super) fn companions(cx: &Ctx, s: &Singles, evaluated: &mut Vec<Evaluated>) -> Pairing {
    let demoted = s.demoted.as_ref();
    let first = evaluated
        .iter()
        .filter(|e| e.1.is_some() && Some(&e.0.cause) != demoted)
        .find(|e| s.naming.supported(&e.0))
        .map(|e| (e.0.clone(), e.3.clone()));
    let passed_over: Vec<String> = evaluated
        .iter()
        .filter(|e| e.1.is_some() && Some(&e.0.cause) != demoted)
        .take_while(|e| first.as_ref().is_none_or(|f| f.0.cause != e.0.cause))
        .map(|e| e.0.cause.clone())
        .collect();
    let mut p = Pairing {
        companions: Vec::new(),
        pair_stage: String::from("no single cause passes: no companion is tried"),
        pair_ref: None,
        refit_single: None,
        first_cause: first.as_ref().map(|f| f.0.cause.clone()),
    };
    if let Some((row, x1)) = first {
        let (sigma, r) = (cx.sigma, &s.reference);
        let first_ok = row.bic < r.conv_bic && r.conv_held - row.held_out_rms_N > cx.threshold;
        let systematic = row.held_out_rms_N > 1.5 * sigma;
        p.pair_stage = if !first_ok {
            format!(
                "the best single cause ({}) does not pass: no companion is tried",
                row.cause
            )
        } else if !systematic {
            format!(
                "{} leaves a held-out RMS of {:.1} N, within 1.5 noise sigma ({:.1} N): no systematic residual left for a companion",
                row.cause, row.held_out_rms_N, 1.5 * sigma
            )
        } else if !cx.opts.pairs {
            "pairs switched off".into()
        } else {
            format!(
                "{} leaves a held-out RMS of {:.1} N, above 1.5 noise sigma ({:.1} N): paired with every other applicable cause",
                row.cause, row.held_out_rms_N, 1.5 * sigma
            )
        };
        if first_ok && systematic && cx.opts.pairs {
            physical_pairs(cx, s, evaluated, &row, &x1, &mut p);
        }
        if first_ok && cx.opts.pairs {
            fault_pairs(cx, s, evaluated, &row, systematic, &mut p);
        }
    }
    if !passed_over.is_empty() {
        p.pair_stage.push_str(&format!(
            "; passed over as the first cause (lower BIC, but an interval that includes no effect): {}",
            passed_over.join(", ")
        ));
    }
    p
}

/// Stage 6a, physical pairs: the first cause (or, when it is an acquisition fault, the best
/// physical single that passes) paired with every other single cause, joint fits from the two
/// single-cause fits; then the winning companion beside the next two single causes.
fn physical_pairs(
    cx: &Ctx,
    s: &Singles,
    evaluated: &mut Vec<Evaluated>,
    first: &Candidate,
    first_x: &[f64],
    p: &mut Pairing,
) {
    let (row, x1) = pair_anchor(cx, s, evaluated, first, first_x);
    let Some(c1) = s.find(&row.cause).map(|(c, _)| c[0]) else {
        return;
    };
    let (mut pairs, probe) = pair_candidates(cx, s, evaluated, &row, c1, &x1);
    probe_pairs(
        cx,
        s.baseline.bic,
        &row,
        (c1, &x1),
        probe,
        &mut pairs,
        &mut p.companions,
    );
    let mut ev = cx.fit_stage(&pairs, PAIRS_CONVERGED);
    let reference = refit_single(cx, s, &row, c1, &ev, p);
    p.pair_ref = Some(reference);
    let judge = |e: &Evaluated| judge_pair(e, reference, cx.threshold);
    for e in &ev {
        let (passes, reason) = judge(e);
        p.companions.push(Companion {
            pair: e.0.cause.clone(),
            companion: e.0.cause.split('+').nth(1).unwrap_or_default().to_string(),
            passes,
            kept: false,
            reason,
            held_out_z: None,
        });
    }
    // The best single need not be one of the pair's causes (a bleed can stand in for a
    // leakage until the air beside it is found): the winning pair's companion is also paired
    // with the next two single causes (a beam of width three over the first cause), each from
    // the two fits' values.
    let winner = ev
        .iter()
        .filter(|e| judge(e).0)
        .min_by(|a, b| a.0.bic.total_cmp(&b.0.bic));
    let k1 = x1.len();
    let c2 = winner.and_then(|w| {
        let name = w.0.cause.split('+').nth(1)?;
        let c2 = s.singles.iter().find(|(c, _)| c[0].name() == name)?.0[0];
        Some((c2, w.3[k1..].to_vec()))
    });
    if let Some((c2, x2)) = c2 {
        let swapped = swap_pairs(cx, s, evaluated, &row, c1, (c2, &x2));
        for e in &swapped {
            let (passes, reason) = judge(e);
            p.companions.push(Companion {
                pair: e.0.cause.clone(),
                companion: c2.name().to_string(),
                passes,
                kept: false,
                reason: format!(
                    "{} in place of {}: {reason}",
                    e.0.cause.split('+').next().unwrap_or_default(),
                    row.cause
                ),
                held_out_z: None,
            });
        }
        ev.extend(swapped);
    }
    evaluated.extend(ev);
}

/// The single the physical pairs are searched around: the first cause, or, when it holds an
/// acquisition fault (which can mimic two physical effects together: a lag stands in for air
/// beside friction), the best physical single that passes and leaves a systematic residual.
fn pair_anchor(
    cx: &Ctx,
    s: &Singles,
    evaluated: &[Evaluated],
    row: &Candidate,
    x1: &[f64],
) -> (Candidate, Vec<f64>) {
    if !has_fault(&row.cause) {
        return (row.clone(), x1.to_vec());
    }
    let r = &s.reference;
    evaluated
        .iter()
        .filter(|e| {
            e.1.is_some()
                && !e.0.cause.contains('+')
                && !has_fault(&e.0.cause)
                && Some(&e.0.cause) != s.demoted.as_ref()
        })
        .find(|e| {
            s.naming.supported(&e.0)
                && e.0.bic < r.conv_bic
                && r.conv_held - e.0.held_out_rms_N > cx.threshold
                && e.0.held_out_rms_N > 1.5 * cx.sigma
        })
        .map_or((row.clone(), x1.to_vec()), |e| (e.0.clone(), e.3.clone()))
}

/// A companion probed before it is fitted: the cause, the pair's parameters, its BIC alone.
type Probe = (Cause, Vec<ParamSpec>, f64);

/// The pairs of `c1` (fitted at `x1`): each starts from the two single-cause fits (the best
/// single's value and the companion's own). A companion that alone does not lower the
/// baseline's BIC may still be masked by the larger effect: it is returned to be probed.
fn pair_candidates(
    cx: &Ctx,
    s: &Singles,
    evaluated: &[Evaluated],
    row: &Candidate,
    c1: Cause,
    x1: &[f64],
) -> (Vec<Cand>, Vec<Probe>) {
    let mut pairs: Vec<Cand> = Vec::new();
    let mut probe: Vec<Probe> = Vec::new();
    for e in evaluated
        .iter()
        .filter(|e| e.1.is_some() && e.0.cause != row.cause)
    {
        let Some(c2) = s.find(&e.0.cause).map(|(c, _)| c[0]) else {
            continue;
        };
        if nested(c1, c2) {
            continue;
        }
        let Some(mut spec) = combined_params(&[c1, c2], cx.base, cx.scales) else {
            continue;
        };
        if e.0.bic >= s.baseline.bic {
            probe.push((c2, spec, e.0.bic));
            continue;
        }
        // The best single at its fitted value; the companion from its own single-cause fit
        // and its starting grid (scouted like a single cause's).
        let k1 = x1.len();
        for (i, p) in spec.iter_mut().enumerate() {
            if i < k1 {
                p.starts = vec![x1[i]];
            } else if let Some(&x) = e.3.get(i - k1) {
                if !p.starts.iter().any(|s| (s / x - 1.0).abs() < 1e-3) {
                    p.starts.insert(0, x);
                }
            }
        }
        pairs.push((vec![c1, c2], spec));
    }
    (pairs, probe)
}

/// Masked companions: one is tried when, added at one of its starting values to the best
/// single's fit, it earns its parameters without any fitting (BIC below the single's); the
/// others are recorded as not tried.
fn probe_pairs(
    cx: &Ctx,
    base_bic: f64,
    row: &Candidate,
    (c1, x1): (Cause, &[f64]),
    probe: Vec<Probe>,
    pairs: &mut Vec<Cand>,
    companions: &mut Vec<Companion>,
) {
    let k1 = x1.len();
    let points: Vec<(usize, Vec<f64>)> = probe
        .iter()
        .enumerate()
        .flat_map(|(pi, (_, spec, _))| {
            let mut grid: Vec<Vec<f64>> = vec![x1.to_vec()];
            for p in &spec[k1..] {
                grid = grid
                    .into_iter()
                    .flat_map(|g| {
                        p.starts.iter().map(move |&v| {
                            let mut t = g.clone();
                            t.push(v);
                            t
                        })
                    })
                    .collect();
            }
            grid.into_iter().map(move |g| (pi, g))
        })
        .collect();
    let probed: Vec<(usize, f64)> = points
        .par_iter()
        .filter_map(|(pi, x)| {
            let r = residuals_x(
                &[c1, probe[*pi].0],
                cx.scales,
                cx.base,
                x,
                cx.data,
                &cx.fit_w,
                cx.opts.max_substep_s,
                1.0,
            )?;
            Some((*pi, bic(r.norm_squared(), cx.n_fit, x.len())))
        })
        .collect();
    for (pi, (c2, mut spec, alone)) in probe.into_iter().enumerate() {
        let best = probed
            .iter()
            .filter(|(i, _)| *i == pi)
            .map(|(_, b)| *b)
            .fold(f64::INFINITY, f64::min);
        if best < row.bic {
            for p in spec.iter_mut().take(k1).zip(x1) {
                p.0.starts = vec![*p.1];
            }
            pairs.push((vec![c1, c2], spec));
            continue;
        }
        companions.push(Companion {
            pair: combined_name(&[c1, c2]),
            companion: c2.name().to_string(),
            passes: false,
            kept: false,
            reason: format!(
                "not tried: alone its BIC ({alone:.1}) is not below the baseline's ({base_bic:.1}), and added at its starting values to {} it lowers no BIC (best {best:.1} against {:.1})",
                row.cause, row.bic
            ),
            held_out_z: None,
        });
    }
}

/// A pair may beat the single only because its joint fit found a better optimum of the single
/// cause, its companion idle: the single is refitted from the two best pairs' values of its
/// own parameters (kept in `p.refit_single` when better), and the pairs are judged against the
/// best single found. Returns that reference: BIC and held-out RMS.
fn refit_single(
    cx: &Ctx,
    s: &Singles,
    row: &Candidate,
    c1: Cause,
    ev: &[Evaluated],
    p: &mut Pairing,
) -> (f64, f64) {
    let reference = (row.bic, row.held_out_rms_N);
    let Some((_, spec1)) = s.singles.iter().find(|(c, _)| c[..] == [c1]) else {
        return reference;
    };
    let mut better: Vec<&Evaluated> = ev
        .iter()
        .filter(|e| e.1.is_some() && e.0.bic < row.bic)
        .collect();
    better.sort_by(|a, b| a.0.bic.total_cmp(&b.0.bic));
    let restarts: Vec<Cand> = better
        .into_iter()
        .take(2)
        .map(|e| {
            let mut s = spec1.clone();
            for (p, &x) in s.iter_mut().zip(&e.3) {
                p.starts = vec![x];
            }
            (vec![c1], s)
        })
        .collect();
    if restarts.is_empty() {
        return reference;
    }
    let best = cx
        .fit_stage(&restarts, usize::MAX)
        .into_iter()
        .filter(|e| e.1.is_some())
        .min_by(|a, b| a.0.bic.total_cmp(&b.0.bic));
    let Some(mut b) = best.filter(|b| b.0.bic < row.bic) else {
        return reference;
    };
    b.0.fit_evaluations += row.fit_evaluations;
    p.pair_stage.push_str(&format!(
        "; refitted from a pair's values, {} reaches BIC {:.1} (was {:.1}) and held-out RMS {:.1} N (was {:.1} N), the reference of every pair",
        row.cause, b.0.bic, row.bic, b.0.held_out_rms_N, row.held_out_rms_N
    ));
    let reference = (b.0.bic, b.0.held_out_rms_N);
    p.refit_single = Some(b);
    reference
}

/// The winning companion `c2` (fitted at `x2`) beside the next two single causes below the
/// baseline's BIC, other than the first cause `c1` and its other forms, each from the two
/// fits' values.
fn swap_pairs(
    cx: &Ctx,
    s: &Singles,
    evaluated: &[Evaluated],
    row: &Candidate,
    c1: Cause,
    (c2, x2): (Cause, &[f64]),
) -> Vec<Evaluated> {
    let swaps: Vec<Cand> = evaluated
        .iter()
        .filter(|e| e.1.is_some() && e.0.bic < s.baseline.bic && e.0.cause != row.cause)
        .filter_map(|e| {
            let c = s.find(&e.0.cause)?.0[0];
            // Another form of the first cause is not another mechanism.
            (c != c2 && !nested(c, c2) && !nested(c, c1)).then(|| (c, e.3.clone()))
        })
        .take(2)
        .filter_map(|(c, xc)| {
            let mut spec = combined_params(&[c, c2], cx.base, cx.scales)?;
            for (p, &v) in spec.iter_mut().zip(xc.iter().chain(x2)) {
                p.starts = vec![v];
            }
            Some((vec![c, c2], spec))
        })
        .collect();
    cx.fit_stage(&swaps, usize::MAX)
}

/// Stage 6b, acquisition faults beside a physical cause ([`fault_pair`]): beside the first
/// cause when it is physical, or, when a fault is the first cause, that fault beside the three
/// physical singles of lowest BIC below the baseline's. They cost no replay of their own, so
/// they are tried whether or not the residual is systematic.
fn fault_pairs(
    cx: &Ctx,
    s: &Singles,
    evaluated: &mut Vec<Evaluated>,
    row: &Candidate,
    systematic: bool,
    p: &mut Pairing,
) {
    let reference = p.pair_ref.unwrap_or((row.bic, row.held_out_rms_N));
    let best_faults: Option<Vec<Fault>> = acquisition::only_faults(&row.cause)
        .then(|| row.cause.split('+').filter_map(Fault::from_name).collect());
    let ons: Vec<(Vec<Fault>, Evaluated)> = match &best_faults {
        Some(f) => evaluated
            .iter()
            .filter(|e| {
                e.1.is_some()
                    && !e.0.cause.contains('+')
                    && !has_fault(&e.0.cause)
                    && e.0.bic < s.baseline.bic
            })
            .take(3)
            .map(|e| (f.clone(), e.clone()))
            .collect(),
        None => p
            .refit_single
            .clone()
            .or_else(|| evaluated.iter().find(|e| e.0.cause == row.cause).cloned())
            .filter(|_| !has_fault(&row.cause))
            .map(|on| {
                s.fault_sets
                    .iter()
                    .map(|f| (f.clone(), on.clone()))
                    .collect()
            })
            .unwrap_or_default(),
    };
    let fault_pairs: Vec<Evaluated> = ons
        .par_iter()
        .filter_map(|(f, on)| fault_pair(cx, s, f, on))
        .collect();
    if !fault_pairs.is_empty() {
        p.pair_ref = Some(reference);
        p.pair_stage.push_str(&format!(
            "; acquisition faults (no replay of their own, so tried {}) beside {}, the physical cause refitted to the data the fault corrects",
            if systematic { "as companions" } else { "whatever the residual" },
            if best_faults.is_some() {
                format!("the three physical single causes of lowest BIC below the baseline's ({} fitted on top of each)", row.cause)
            } else {
                row.cause.clone()
            }
        ));
    }
    for e in &fault_pairs {
        let (passes, reason) = judge_pair(e, reference, cx.threshold);
        let names: Vec<&str> = e.0.cause.split('+').collect();
        let companion = if best_faults.is_some() {
            names[0].to_string()
        } else {
            names[1..].join("+")
        };
        p.companions.push(Companion {
            pair: e.0.cause.clone(),
            companion,
            passes,
            kept: false,
            reason,
            held_out_z: None,
        });
    }
    evaluated.extend(fault_pairs);
}

/// A fault beside a physical cause: the fault fitted on top of the cause's replay, then the
/// cause refitted to the data the fault corrects and the fault again on top, while the BIC
/// falls (at most twice): alternating least squares towards the joint fit.
fn fault_pair(cx: &Ctx, s: &Singles, f: &[Fault], on: &Evaluated) -> Option<Evaluated> {
    let (base, baseline) = (cx.base, &s.baseline.sim);
    let mut cur = fault_candidate(f, Some(on), baseline, base, &s.fcx)?;
    let (c, spec) = s.find(&on.0.cause)?;
    let mut x = on.3.clone();
    for _ in 0..2 {
        let v = &cur.3[cur.3.len().checked_sub(f.len())?..];
        let corrected: Vec<Measurement> = cx
            .data
            .iter()
            .map(|m| Measurement {
                force_n: acquisition::correct_all(f, v, &m.time_s, &m.force_n),
                ..m.clone()
            })
            .collect();
        let z0: Vec<f64> = spec.iter().zip(&x).map(|(p, &v)| to_z(p, v)).collect();
        let fit = super::fit_one(
            c,
            cx.scales,
            base,
            spec,
            z0,
            &corrected,
            &cx.fit_w,
            cx.opts,
            cx.opts.patience,
            cx.scale,
        )?;
        let deck = apply_all(c, base, cx.scales, &fit.x);
        let sim = cx.sim_all(&deck).ok()?;
        let held = rms_over(&cx.held_w, &sim, &corrected);
        let ms = (fit.rss / cx.n_fit.max(1) as f64).max(held * held);
        let iv = intervals(
            c,
            cx.scales,
            base,
            &fit.x,
            &corrected,
            &cx.fit_w,
            cx.opts.max_substep_s,
            cx.sigma,
            ms,
        );
        let mut phys = on.clone();
        phys.0.parameters.clear();
        phys.0.intervals.clear();
        for ((p, xv), i) in spec.iter().zip(&fit.x).zip(iv) {
            phys.0.parameters.insert(p.name.into(), *xv);
            phys.0.intervals.insert(p.name.into(), i);
        }
        phys.0.fit_evaluations = cur.0.fit_evaluations + fit.evals;
        phys.1 = Some(sim);
        phys.2 = deck;
        phys.3 = fit.x.clone();
        let mut next = fault_candidate(f, Some(&phys), baseline, base, &s.fcx)?;
        if next.0.bic >= cur.0.bic {
            break;
        }
        next.0.note = Some(format!(
            "{} refitted to the data {} corrects, alternating with the fault's fit",
            on.0.cause,
            f.iter().map(|f| f.name()).collect::<Vec<_>>().join("+")
        ));
        x = fit.x;
        cur = next;
    }
    Some(cur)
}
