//! `rotorsim sweep PLAN --out DIR` as a library call: the plan read, checked, its cases of this
//! shard run and the tables written. The command line and the Python package both run through
//! [`SweepJob`]; the sbatch script (`--emit-slurm`) stays the command's.
use super::{table, JobRunner, Plan, SweepOptions, SweepProgress, SweepReport};
use crate::run::stop::StopFlag;
use anyhow::Context;
use std::path::PathBuf;
use std::time::Instant;

/// A sweep's options, typed ([`SweepJob::new`] gives the command's defaults).
#[derive(Clone, Debug)]
pub struct SweepJob {
    /// Sweep plan (TOML: [base], [vary], [[case]], [sweep]).
    pub plan: PathBuf,
    /// Sweep folder: DIR/cases/<case id>/, DIR/sweep.csv, DIR/sweep.html.
    pub out: PathBuf,
    /// Cases run at once (None: [`default_jobs`]).
    pub jobs: Option<usize>,
    /// Shard K of N of the cases (None: every case).
    pub shard: Option<(usize, usize)>,
    /// Run again the cases that failed in an earlier run into `out`.
    pub retry_failed: bool,
    /// Warm starts: on or off whatever the plan says (None: as the plan says).
    pub warm_start: Option<bool>,
    /// Raised: the running cases stop (published incomplete: failed, run again with
    /// `retry_failed`) and no other starts.
    pub stop: StopFlag,
}

/// What a sweep did, its case folders and (without a shard) its tables written.
#[derive(Debug)]
pub struct SweepOutcome {
    pub report: SweepReport,
    /// The tables (None for a shard: `rotorsim sweep merge` writes them once every shard ended).
    pub merged: Option<table::Merged>,
    /// Cases run at once.
    pub jobs: usize,
    pub shard: Option<(usize, usize)>,
    pub wall_s: f64,
}

impl SweepJob {
    /// The sweep of `plan` into `out` with the defaults of `rotorsim sweep`.
    pub fn new(plan: impl Into<PathBuf>, out: impl Into<PathBuf>) -> Self {
        SweepJob {
            plan: plan.into(),
            out: out.into(),
            jobs: None,
            shard: None,
            retry_failed: false,
            warm_start: None,
            stop: StopFlag::default(),
        }
    }

    /// The plan as this job runs it (its warm starts as `warm_start` says).
    pub fn read_plan(&self) -> anyhow::Result<Plan> {
        let mut plan = Plan::from_file(&self.plan)?;
        if let Some(w) = self.warm_start {
            plan.warm_start = w;
        }
        Ok(plan)
    }

    /// Cases run at once.
    pub fn jobs(&self) -> usize {
        self.jobs.unwrap_or_else(default_jobs).max(1)
    }

    /// Checks every case of `plan` (read by [`SweepJob::read_plan`]) before anything runs
    /// (`checked(n, total)` as it goes), locks `out`, runs the cases of this shard that are not
    /// done and, without a shard, writes sweep.csv and sweep.html. `note` gets the lock's notes
    /// (a stale lock taken over). Failed cases are in the report, not an error.
    pub fn execute(
        &self,
        plan: &Plan,
        checked: &(dyn Fn(usize, usize) + Sync),
        progress: &dyn SweepProgress,
        note: &mut dyn FnMut(&str),
    ) -> anyhow::Result<SweepOutcome> {
        let mut runner = JobRunner::default();
        runner.stop = self.stop.clone();
        let jobs = self.jobs();
        super::check(plan, &runner, jobs, checked)?;
        let out = &self.out;
        std::fs::create_dir_all(out)
            .with_context(|| format!("creating sweep folder {}", out.display()))?;
        let lock = super::lock(out, self.shard)?;
        for n in &lock.notes {
            note(n);
        }
        super::prepare(out, plan)?;
        let t0 = Instant::now();
        let opts = SweepOptions {
            jobs,
            shard: self.shard,
            retry_failed: self.retry_failed,
        };
        let report = super::execute(plan, out, &opts, &runner, progress)?;
        let wall_s = t0.elapsed().as_secs_f64();
        let merged = match self.shard {
            None => Some(table::write(plan, out)?),
            Some(_) => None,
        };
        Ok(SweepOutcome {
            report,
            merged,
            jobs,
            shard: self.shard,
            wall_s,
        })
    }
}

/// Cases run at once by default: SLURM_CPUS_PER_TASK, else the machine's CPUs.
pub fn default_jobs() -> usize {
    std::env::var("SLURM_CPUS_PER_TASK")
        .ok()
        .and_then(|s| s.parse().ok())
        .filter(|&n| n > 0)
        .unwrap_or_else(|| {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        })
}

/// The shard of a Slurm job array's task (SLURM_ARRAY_TASK_ID of SLURM_ARRAY_TASK_COUNT), when
/// both are set.
pub fn env_shard() -> anyhow::Result<Option<(usize, usize)>> {
    match (
        std::env::var("SLURM_ARRAY_TASK_ID"),
        std::env::var("SLURM_ARRAY_TASK_COUNT"),
    ) {
        (Ok(k), Ok(n)) => super::plan::parse_shard(&format!("{k}/{n}"))
            .map(Some)
            .context("from SLURM_ARRAY_TASK_ID/SLURM_ARRAY_TASK_COUNT"),
        _ => Ok(None),
    }
}

/// The shard given as "K/N" text, else the Slurm array task's ([`env_shard`]).
pub fn resolve_shard(text: Option<&str>) -> anyhow::Result<Option<(usize, usize)>> {
    match text {
        Some(s) => super::plan::parse_shard(s).map(Some),
        None => env_shard(),
    }
}
