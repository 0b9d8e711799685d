//! One stage of fits: every candidate of a list (single causes, pairs) from its grid of
//! starts, scouted and, for the best, run to convergence, then replayed and ranked.
use super::prepare::Ctx;
use super::{
    bic, fit_one, intervals, residuals_x, rms_over, to_x, to_z, Candidate, Evaluated, Fit,
    SCOUT_PATIENCE, SCREEN_STARTS,
};
use crate::diagnose::candidates::{apply_all, combined_name, Cause, ParamSpec};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// A candidate of a stage: its causes and their parameters (with their starts).
pub(super) type Cand = (Vec<Cause>, Vec<ParamSpec>);
type Cands = [Cand];

/// A fit job: a candidate's index and a start (transformed parameters).
type Job = (usize, Vec<f64>);

impl Ctx<'_> {
    /// Fits every candidate of `cands`; fit jobs are (candidate, start) pairs, in parallel.
    /// `keep`: when fewer than the candidates, every candidate is scouted and only the `keep`
    /// best after scouting are run to convergence (the others keep their scouted fit).
    pub(super) fn fit_stage(&self, cands: &Cands, keep: usize) -> Vec<Evaluated> {
        let mut jobs = start_jobs(cands);
        let screen = keep < cands.len();
        let start_evals = if screen {
            self.screen_starts(cands, &mut jobs)
        } else {
            vec![0usize; cands.len()]
        };
        // Several starts: each is scouted with a short run, and only the best one is run on
        // to convergence (the starts pick the basin; the descent inside it is the same).
        let mut n_starts = vec![0usize; cands.len()];
        for (ci, _) in &jobs {
            n_starts[*ci] += 1;
        }
        let patience = |ci: usize| {
            if n_starts[ci] > 1 || screen {
                SCOUT_PATIENCE.min(self.opts.patience)
            } else {
                self.opts.patience
            }
        };
        let (best, mut evals) = self.scout(cands, jobs, &patience, start_evals);
        let mut rank: Vec<usize> = (0..cands.len()).filter(|&ci| best[ci].is_some()).collect();
        rank.sort_by(|&a, &b| {
            let rss = |ci: usize| best[ci].as_ref().map_or(f64::INFINITY, |f| f.rss);
            rss(a).total_cmp(&rss(b))
        });
        let mut continued = vec![false; cands.len()];
        for &ci in rank.iter().take(keep) {
            continued[ci] = true;
        }
        let best = self.continue_best(cands, best, &mut evals, &patience, &continued);
        cands
            .par_iter()
            .zip(best.par_iter())
            .zip(evals.par_iter())
            .enumerate()
            .map(|(ci, (((c, spec), f), &ev))| {
                let mut row = Candidate {
                    cause: combined_name(c),
                    rms_N: f64::NAN,
                    bic: f64::INFINITY,
                    parameters: BTreeMap::new(),
                    held_out_rms_N: f64::NAN,
                    intervals: BTreeMap::new(),
                    k: spec.len(),
                    fit_evaluations: ev,
                    failure: None,
                    note: (!continued[ci]).then(|| {
                        format!("screened: after a short run its fit ranked below the best {keep} of {} tried together; not run to convergence", cands.len())
                    }),
                };
                let Some(f) = f else {
                    row.failure = Some("model failed at every starting point".into());
                    return (row, None, self.base.clone(), vec![]);
                };
                self.evaluate(c, spec, f, row)
            })
            .collect()
    }

    /// Screening many candidates (the pairs): each start is first judged by its residual alone
    /// (one replay) and only the best [`SCREEN_STARTS`] of a candidate are kept in `jobs`.
    /// Returns the replays spent per candidate.
    fn screen_starts(&self, cands: &Cands, jobs: &mut Vec<Job>) -> Vec<usize> {
        let mut start_evals = vec![0usize; cands.len()];
        let start_rss: Vec<f64> = jobs
            .par_iter()
            .map(|(ci, z0)| {
                let (c, spec) = &cands[*ci];
                residuals_x(
                    c,
                    self.scales,
                    self.base,
                    &to_x(spec, z0),
                    self.data,
                    &self.fit_w,
                    self.opts.max_substep_s,
                    self.scale,
                )
                .map_or(f64::INFINITY, |r| r.norm_squared())
            })
            .collect();
        let mut order: Vec<usize> = (0..jobs.len()).collect();
        order.sort_by(|&a, &b| start_rss[a].total_cmp(&start_rss[b]));
        let mut taken = vec![0usize; cands.len()];
        let mut kept = vec![false; jobs.len()];
        for &j in &order {
            let ci = jobs[j].0;
            start_evals[ci] += 1;
            if taken[ci] < SCREEN_STARTS && start_rss[j].is_finite() {
                taken[ci] += 1;
                kept[j] = true;
            }
        }
        let mut k = kept.into_iter();
        jobs.retain(|_| k.next().unwrap_or(false));
        start_evals
    }

    /// Every job run with its candidate's patience; the best fit of each candidate and the
    /// evaluations spent on it (after `evals`, those of the screen).
    fn scout(
        &self,
        cands: &Cands,
        jobs: Vec<Job>,
        patience: &(dyn Fn(usize) -> usize + Sync),
        mut evals: Vec<usize>,
    ) -> (Vec<Option<Fit>>, Vec<usize>) {
        let fits: Vec<(usize, Option<Fit>)> = jobs
            .into_par_iter()
            .map(|(ci, z0)| {
                let (c, spec) = &cands[ci];
                (ci, self.fit(c, spec, z0, patience(ci)))
            })
            .collect();
        let mut best: Vec<Option<Fit>> = (0..cands.len()).map(|_| None).collect();
        for (ci, f) in fits.into_iter() {
            if let Some(f) = f {
                evals[ci] += f.evals;
                if best[ci].as_ref().is_none_or(|b| f.rss < b.rss) {
                    best[ci] = Some(f);
                }
            }
        }
        (best, evals)
    }

    /// Continuation of the best scouted start of every `continued` candidate (its evaluations
    /// count for the candidate).
    fn continue_best(
        &self,
        cands: &Cands,
        best: Vec<Option<Fit>>,
        evals: &mut [usize],
        patience: &(dyn Fn(usize) -> usize + Sync),
        continued: &[bool],
    ) -> Vec<Option<Fit>> {
        let best: Vec<(Option<Fit>, usize)> = best
            .into_par_iter()
            .enumerate()
            .map(|(ci, f)| {
                let Some(f) = f else {
                    return (None, 0);
                };
                if patience(ci) == self.opts.patience || !continued[ci] {
                    return (Some(f), 0);
                }
                let (c, spec) = &cands[ci];
                match self.fit(c, spec, f.z.clone(), self.opts.patience) {
                    Some(g) if g.rss <= f.rss => {
                        let e = g.evals;
                        (Some(g), e)
                    }
                    Some(g) => (Some(f), g.evals),
                    None => (Some(f), 0),
                }
            })
            .collect();
        best.into_iter()
            .zip(evals.iter_mut())
            .map(|((f, e), ev)| {
                *ev += e;
                f
            })
            .collect()
    }

    /// One Levenberg-Marquardt run of a candidate on the fit windows from `z0`.
    pub(super) fn fit(
        &self,
        c: &[Cause],
        spec: &[ParamSpec],
        z0: Vec<f64>,
        patience: usize,
    ) -> Option<Fit> {
        fit_one(
            c,
            self.scales,
            self.base,
            spec,
            z0,
            self.data,
            &self.fit_w,
            self.opts,
            patience,
            self.scale,
        )
    }

    /// A fitted candidate replayed on every test: its intervals, RMS, held-out RMS and BIC.
    fn evaluate(&self, c: &[Cause], spec: &[ParamSpec], f: &Fit, mut row: Candidate) -> Evaluated {
        let deck = apply_all(c, self.base, self.scales, &f.x);
        let sim = self.sim_all(&deck);
        // The model-form error is measured where the model predicts as well as where it was
        // fitted: the larger mean square of the two.
        let ms_fit = f.rss / self.n_fit.max(1) as f64;
        let ms = match &sim {
            Ok(sim) => ms_fit.max(rms_over(&self.held_w, sim, self.data).powi(2)),
            Err(_) => ms_fit,
        };
        let iv = intervals(
            c,
            self.scales,
            self.base,
            &f.x,
            self.data,
            &self.fit_w,
            self.opts.max_substep_s,
            self.sigma,
            ms,
        );
        for ((p, x), i) in spec.iter().zip(&f.x).zip(iv) {
            row.parameters.insert(p.name.into(), *x);
            row.intervals.insert(p.name.into(), i);
        }
        match sim {
            Ok(sim) => {
                row.rms_N = rms_over(&self.all_w, &sim, self.data);
                row.held_out_rms_N = rms_over(&self.held_w, &sim, self.data);
                row.bic = bic(f.rss, self.n_fit, spec.len());
                (row, Some(sim), deck, f.x.clone())
            }
            Err(e) => {
                row.failure = Some(e.to_string());
                (row, None, deck, f.x.clone())
            }
        }
    }
}

/// Grid of starts of every candidate: the product of each parameter's starting values.
fn start_jobs(cands: &Cands) -> Vec<Job> {
    let mut jobs = Vec::new();
    for (ci, (_, spec)) in cands.iter().enumerate() {
        let mut starts: Vec<Vec<f64>> = vec![vec![]];
        for p in spec {
            starts = starts
                .into_iter()
                .flat_map(|s| {
                    p.starts.iter().map(move |&x| {
                        let mut t = s.clone();
                        t.push(to_z(p, x));
                        t
                    })
                })
                .collect();
        }
        for z0 in starts {
            jobs.push((ci, z0));
        }
    }
    jobs
}
