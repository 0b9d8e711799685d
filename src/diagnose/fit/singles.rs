//! The single causes: every candidate alone and every acquisition fault on the baseline, the
//! naming rule's no-effect values of these data, and the reference a single cause must beat.
use super::prepare::{Baseline, Ctx};
use super::search::Cand;
use super::{
    bic, demote_compliant_play, fault_candidate, replay_delay, rms_over, sample_interval_s, spans,
    Candidate, Evaluated, FaultContext,
};
use crate::diagnose::acquisition::{self, Fault};
use crate::diagnose::support::{self, NoEffect, NoEffectContext, PartSupport};
use crate::diagnose::DiagnoseError;
use std::collections::BTreeMap;

/// The naming rule (src/diagnose/support.rs) with the no-effect values of these data: a cause
/// is named only where the 95% interval of one of its parameters excludes its no-effect value;
/// the lag's is a band, the timing uncertainty (half the sample interval plus the replay's own
/// delay).
pub(super) struct Naming {
    pub(super) ne_cx: NoEffectContext,
    /// The tests' sample interval [s].
    pub(super) sample_h: f64,
}

impl Naming {
    pub(super) fn no_effect_of(
        &self,
        r: &Candidate,
        iv: &BTreeMap<String, [f64; 2]>,
    ) -> BTreeMap<String, NoEffect> {
        support::no_effects(&r.cause, &r.parameters, iv, &self.ne_cx)
    }

    pub(super) fn parts_of(&self, r: &Candidate) -> Vec<PartSupport> {
        support::support(
            &r.cause,
            &r.parameters,
            &r.intervals,
            &self.no_effect_of(r, &r.intervals),
        )
    }

    pub(super) fn supported(&self, r: &Candidate) -> bool {
        support::all_supported(&self.parts_of(r))
    }
}

/// The reference a single cause must beat: the baseline aligned by the best lag within the
/// timing band (what the data's sampling convention alone can do). A cause that only mimics a
/// sub-sample skew (a very stiff mount is a lag of the force) does not beat it. Held-out data
/// are judged against the unaligned baseline: an effect that is partly a phase shift, a warming
/// oil's stiffness, keeps its held-out improvement.
pub(super) struct Reference {
    /// The aligning lag [s].
    pub(super) conv_lag: f64,
    pub(super) conv_bic: f64,
    pub(super) conv_held: f64,
    /// Held-out RMS of the aligned baseline [N].
    pub(super) aligned_held: f64,
}

/// What the single causes leave for the companions and the choice.
pub(super) struct Singles<'a> {
    /// Every single cause that applies to the deck, with its parameters.
    pub(super) singles: Vec<Cand>,
    /// Each fault alone and the linear ones two at a time.
    pub(super) fault_sets: Vec<Vec<Fault>>,
    pub(super) fcx: FaultContext<'a>,
    pub(super) baseline: &'a Baseline,
    pub(super) naming: Naming,
    pub(super) reference: Reference,
    /// A compliant free play that gave way to one of its limits.
    pub(super) demoted: Option<String>,
}

impl Singles<'_> {
    /// The single cause of a name.
    pub(super) fn find(&self, name: &str) -> Option<&Cand> {
        self.singles
            .iter()
            .find(|(c, _)| crate::diagnose::candidates::combined_name(c) == name)
    }
}

/// Stage 5, single causes: every candidate alone and every acquisition fault on the baseline,
/// ranked by BIC (`evaluated`), and what the later stages judge them by.
pub(super) fn singles<'a>(
    cx: &'a Ctx,
    baseline: &'a Baseline,
) -> Result<(Singles<'a>, Vec<Evaluated>), DiagnoseError> {
    let (base, data, opts) = (cx.base, cx.data, cx.opts);
    let singles: Vec<Cand> = opts
        .candidates
        .iter()
        .filter_map(|&c| c.params(base, cx.scales).map(|s| (vec![c], s)))
        .collect();
    let mut evaluated = cx.fit_stage(&singles, usize::MAX);
    // Acquisition faults on the baseline: fitted on its replays, no replay of their own.
    // Each fault alone, and the linear ones two at a time (a calibration error with a zero
    // offset, a drifting zero beside either): one least-squares solve, no replay.
    let fault_sets: Vec<Vec<Fault>> = opts
        .faults
        .iter()
        .map(|&f| vec![f])
        .chain(
            acquisition::linear_pairs()
                .into_iter()
                .filter(|p| p.iter().all(|f| opts.faults.contains(f)))
                .map(|p| p.to_vec()),
        )
        .collect();
    let fcx = FaultContext {
        data,
        fit_w: &cx.fit_w,
        held_w: &cx.held_w,
        all_w: &cx.all_w,
        sigma: cx.sigma,
        replay_delay_s: if opts.faults.contains(&Fault::Lag) {
            replay_delay(
                base,
                data,
                &baseline.sim,
                &spans(&cx.fit_w),
                opts.max_substep_s,
            )?
        } else {
            0.0
        },
    };
    evaluated.extend(
        fault_sets
            .iter()
            .filter_map(|f| fault_candidate(f, None, &baseline.sim, base, &fcx)),
    );
    evaluated.sort_by(|a, b| a.0.bic.total_cmp(&b.0.bic));
    let sample_h = sample_interval_s(data);
    let naming = Naming {
        ne_cx: NoEffectContext::new(base, sample_h, fcx.replay_delay_s),
        sample_h,
    };
    let (conv_lag, aligned) = acquisition::aligned_within(
        data,
        &baseline.sim,
        &spans(&cx.fit_w),
        naming.ne_cx.lag_timing_s,
    );
    let reference = Reference {
        conv_lag,
        conv_held: baseline.held,
        aligned_held: rms_over(&cx.held_w, &aligned, data),
        conv_bic: bic(
            rms_over(&cx.fit_w, &aligned, data).powi(2) * cx.n_fit as f64,
            cx.n_fit,
            0,
        )
        .min(baseline.bic),
    };
    // A compliant free play that is not decisively better than one of its limits gives way to
    // that limit (one parameter fewer): it moves behind the limit and may not be chosen.
    let demoted = demote_compliant_play(&mut evaluated);
    Ok((
        Singles {
            singles,
            fault_sets,
            fcx,
            baseline,
            naming,
            reference,
            demoted,
        },
        evaluated,
    ))
}
