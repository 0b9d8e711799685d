//! `rotorsim sweep`: batch forced-response runs from a plan, on this machine or as the shards of
//! a Slurm job array (docs/sweep.md).
use crate::sweep::batch::BatchSettings;
use crate::sweep::job::SweepJob;
use crate::sweep::{self, Case, JobRunner, Plan, SweepProgress};
use anyhow::bail;
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    /// Sweep plan (TOML: [base], [vary], [[case]], [sweep]; docs/sweep.md).
    #[arg(required = true)]
    pub plan: Option<PathBuf>,
    /// Sweep folder: DIR/cases/<case id>/ (each a `rotorsim run` result folder), DIR/sweep.csv,
    /// DIR/sweep.html.
    #[arg(long, required = true)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub batch: BatchSettings,
}

#[derive(Subcommand, Debug)]
pub enum SweepCommand {
    /// Build DIR/sweep.csv and DIR/sweep.html from the case folders (after the shards ended).
    Merge {
        /// Sweep folder.
        dir: PathBuf,
    },
}

/// One progress bar on a terminal, plain lines otherwise (also the sensitivity's, which
/// prints lines only).
pub(crate) struct Console {
    /// The command the lines name (`rotorsim sweep`, `rotorsim sensitivity`).
    command: &'static str,
    bar: Option<ProgressBar>,
    done: AtomicUsize,
    total: AtomicUsize,
}

impl Console {
    /// Plain lines, one per case as it ends.
    pub(crate) fn lines(command: &'static str) -> Self {
        Console {
            command,
            bar: None,
            done: AtomicUsize::new(0),
            total: AtomicUsize::new(0),
        }
    }
}

impl SweepProgress for Console {
    fn start(&self, to_run: usize, total: usize) {
        self.total.store(to_run, Ordering::Relaxed);
        if let Some(b) = &self.bar {
            b.set_length(to_run as u64);
            b.set_message(format!("{total} cases in this sweep"));
        } else {
            errln!(
                "{}: {to_run} case(s) to run of {total} ({} already done or kept)",
                self.command,
                total - to_run
            );
        }
    }
    fn case_done(&self, case: &Case, result: &Result<(), String>, wall_s: f64) {
        let n = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        let total = self.total.load(Ordering::Relaxed);
        let what = match result {
            Ok(()) => "done".to_string(),
            Err(e) => format!("FAILED: {e}"),
        };
        match &self.bar {
            Some(b) => {
                b.inc(1);
                if result.is_err() {
                    b.println(format!("case {} {what}", case.id));
                }
            }
            None => errln!("[{n}/{total}] case {} {what} ({wall_s:.1} s)", case.id),
        }
    }
}

pub fn run(args: SweepArgs) -> anyhow::Result<()> {
    if let Some(SweepCommand::Merge { dir }) = &args.command {
        return merge(dir);
    }
    let (Some(plan_path), Some(out)) = (&args.plan, &args.out) else {
        bail!("expected a plan file and --out DIR (or `rotorsim sweep merge DIR`)");
    };
    let job = SweepJob {
        jobs: args.batch.jobs,
        shard: sweep::job::resolve_shard(args.batch.shard.as_deref())?,
        retry_failed: args.batch.retry_failed,
        warm_start: args.batch.warm_start(),
        ..SweepJob::new(plan_path, out)
    };
    let plan = job.read_plan()?;
    let jobs = job.jobs();
    let tty = std::io::stderr().is_terminal();
    if let Some(script) = &args.batch.emit_slurm {
        check_with_progress(&plan, &JobRunner::default(), jobs, tty)?;
        return emit_slurm(&args, &plan, plan_path, out, script);
    }
    let bar = tty.then(|| {
        let b = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr());
        b.set_style(
            ProgressStyle::with_template(
                "sweep [{bar:30}] {pos}/{len} cases ({elapsed}, ETA {eta}) {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        b
    });
    let console = Console {
        bar,
        ..Console::lines("rotorsim sweep")
    };
    let checking = CheckConsole::new(plan.cases.len(), tty);
    let outcome = job.execute(
        &plan,
        &|n, total| checking.checked(n, total),
        &console,
        &mut |n| errln!("note: {n}"),
    );
    checking.finish();
    let outcome = outcome?;
    let report = &outcome.report;
    let shard = outcome.shard;
    if let Some(b) = &console.bar {
        b.finish_and_clear();
    }
    let wall = outcome.wall_s;
    let shard_note = shard
        .map(|(k, n)| format!(" (shard {k}/{n})"))
        .unwrap_or_default();
    outln!(
        "sweep{shard_note}: {} case(s), {} run now ({} warm-started), {} already complete, {} failed, {jobs} at once, wall {wall:.1} s",
        report.total,
        report.ran.len(),
        report.warm_started,
        report.skipped.len(),
        report.failed().len()
    );
    for (id, why) in &report.failed_kept {
        outln!("failed earlier (kept; --retry-failed runs it again): {id}: {why}");
    }
    for (id, r) in &report.ran {
        if let Err(e) = r {
            outln!("failed: {id}: {e}");
        }
    }
    if let Some(merged) = &outcome.merged {
        let (ok, np, failed, not_run) = sweep::table::counts(&merged.rows);
        outln!(
            "rows: {ok} ok (periodic, or a stability map), {np} NOT periodic, {failed} failed, {not_run} not run; table: {}  plots: {}",
            out.join("sweep.csv").display(),
            out.join("sweep.html").display()
        );
    } else {
        outln!(
            "when every shard has ended: rotorsim sweep merge {}",
            out.display()
        );
    }
    let failed = report.failed();
    if !failed.is_empty() {
        bail!(
            "{} case(s) failed: {} (a run that failed is marked INCOMPLETE, one that is not periodic under require_periodic is complete with its best revolution; rerun with --retry-failed)",
            failed.len(),
            failed.join(", ")
        );
    }
    Ok(())
}

fn merge(dir: &Path) -> anyhow::Result<()> {
    let plan = sweep::read_plan_json(dir)?;
    let merged = sweep::table::write(&plan, dir)?;
    for (id, why) in &merged.failed {
        outln!("failed: {id}: {why}");
    }
    let (ok, np, failed, not_run) = sweep::table::counts(&merged.rows);
    outln!(
        "merged {} case(s): rows {ok} ok, {np} NOT periodic, {failed} failed, {not_run} not run; table: {}",
        plan.cases.len(),
        dir.join("sweep.csv").display()
    );
    if failed + not_run > 0 {
        bail!(
            "the sweep in {} is not complete: {failed} row(s) failed, {not_run} not run (sweep.csv says which)",
            dir.display()
        );
    }
    Ok(())
}

/// The pre-flight check's progress: a bar on a terminal, otherwise a line every few seconds
/// when checking takes long (a plan of many cases).
pub(crate) struct CheckConsole {
    bar: Option<ProgressBar>,
    t0: Instant,
    last: std::sync::Mutex<f64>,
}

impl CheckConsole {
    pub(crate) fn new(total: usize, tty: bool) -> Self {
        let bar = (tty && total > 1).then(|| {
            let b = ProgressBar::with_draw_target(Some(total as u64), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template(
                    "checking the plan [{bar:30}] {pos}/{len} cases ({elapsed}, ETA {eta})",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
            );
            b
        });
        CheckConsole {
            bar,
            t0: Instant::now(),
            last: std::sync::Mutex::new(0.0),
        }
    }
    pub(crate) fn checked(&self, n: usize, total: usize) {
        if let Some(b) = &self.bar {
            b.set_position(n as u64);
            return;
        }
        let now = self.t0.elapsed().as_secs_f64();
        if let Ok(mut l) = self.last.lock() {
            if now - *l >= CHECK_PROGRESS_EVERY_S {
                *l = now;
                errln!("rotorsim sweep: checked {n} of {total} cases ({now:.0} s)");
            }
        }
    }
    pub(crate) fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

/// Checks every case before any runs, its progress shown.
pub(crate) fn check_with_progress(
    plan: &Plan,
    runner: &JobRunner,
    jobs: usize,
    tty: bool,
) -> anyhow::Result<()> {
    let c = CheckConsole::new(plan.cases.len(), tty);
    let r = sweep::check(plan, runner, jobs, &|n, total| c.checked(n, total));
    c.finish();
    r
}

/// Seconds between plain lines of the pre-flight check's progress off a terminal.
const CHECK_PROGRESS_EVERY_S: f64 = 5.0;

fn emit_slurm(
    args: &SweepArgs,
    plan: &Plan,
    plan_path: &Path,
    out: &Path,
    script: &Path,
) -> anyhow::Result<()> {
    let groups = plan.groups().len();
    let shards = args.batch.emit_slurm(plan, plan_path, out, script)?;
    outln!(
        "wrote {}: a job array of {shards} task(s) over {} case(s) in {groups} warm-start group(s); submit with `sbatch {}`, then `rotorsim sweep merge {}`",
        script.display(),
        plan.cases.len(),
        script.display(),
        out.display()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{Cli, Command};
    use clap::Parser;

    /// `sweep` and `sensitivity` take the same warm-start flags, the last one given winning;
    /// without either the plan decides.
    #[test]
    fn one_warm_start_flag_pair_for_every_batch() {
        for base in [
            vec!["rotorsim", "sweep", "p.toml", "--out", "o"],
            vec!["rotorsim", "sensitivity", "--out", "o"],
        ] {
            for (extra, want) in [
                (vec![], None),
                (vec!["--warm-start"], Some(true)),
                (vec!["--no-warm-start"], Some(false)),
                (vec!["--warm-start", "--no-warm-start"], Some(false)),
                (vec!["--no-warm-start", "--warm-start"], Some(true)),
            ] {
                let argv: Vec<&str> = base.iter().chain(&extra).copied().collect();
                let batch = match Cli::try_parse_from(&argv).unwrap().command {
                    Command::Sweep(a) => a.batch,
                    Command::Sensitivity(a) => a.settings.batch,
                    _ => unreachable!(),
                };
                assert_eq!(batch.warm_start(), want, "{argv:?}");
            }
        }
    }
}
