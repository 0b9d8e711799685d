//! Batch forced-response sweeps (`rotorsim sweep`, docs/sweep.md): a plan expands to cases, each
//! case is a `rotorsim run` into its own result folder `DIR/cases/<id>/`, and DIR/sweep.csv and
//! DIR/sweep.html summarize them.
//!
//! Scheduling. Cases run in parallel on a pool of `jobs` threads, each case's models on their
//! own threads as in `run`, so a case's result does not depend on what runs beside it. Warm
//! starts follow the plan's groups ([`plan::Plan::groups`]): each group's seed runs cold first,
//! then the others start from the seed's periodic state. The groups depend on the plan only,
//! so results are the same for any number of threads or shards.
//!
//! Resume. A case folder whose manifest says `complete: true` is done and skipped; one that is
//! published incomplete is failed, listed, and run again only with `retry_failed`. DIR/plan.json
//! holds the expanded plan; a sweep into a DIR of another plan is refused.
//!
//! Shards. Shard K of N runs the groups `g` with `g % N == K` and writes only their case folders
//! (and plan.json, the same bytes for every shard), so shards never collide; [`table`] builds
//! sweep.csv from the case folders whoever ran them.
pub mod batch;
pub mod job;
pub mod plan;
pub mod runner;
pub mod table;

pub use plan::{Case, Plan};
pub use runner::JobRunner;

use anyhow::{anyhow, bail, Context};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Runs one case: [`JobRunner`] (a [`crate::run::job::RunJob`] per case), or a stand-in in tests.
pub trait CaseRunner: Sync {
    /// Checks the case without running it: options, decks with their overrides, the record.
    fn check(&self, case: &Case) -> anyhow::Result<()>;
    /// Runs `case` into the result folder `out`, starting from the periodic states of the
    /// completed case folder `initial` when given.
    fn run(&self, case: &Case, out: &Path, initial: Option<&Path>) -> anyhow::Result<()>;
}

/// Progress of a sweep, reported as cases end (from any thread).
pub trait SweepProgress: Sync {
    /// `to_run` cases will run now, of `total` in this shard.
    fn start(&self, to_run: usize, total: usize);
    fn case_done(&self, case: &Case, result: &Result<(), String>, wall_s: f64);
}

/// State of a case folder.
#[derive(Clone, Debug, PartialEq)]
pub enum CaseState {
    /// Published with `complete: true`, its files as its manifest lists them.
    Done,
    /// Published incomplete (the reason); its files as its manifest lists them.
    Failed(String),
    /// Its files do not match its manifest, or the manifest is missing or broken (the
    /// reason): nothing of it is read. Counted failed.
    Damaged(String),
    /// No result folder yet.
    Pending,
}

impl CaseState {
    /// Why the case is failed (None: done or pending).
    pub fn failure(&self) -> Option<&str> {
        match self {
            CaseState::Failed(why) | CaseState::Damaged(why) => Some(why),
            _ => None,
        }
    }
}

/// Folder of case `id` in sweep folder `dir`.
pub fn case_dir(dir: &Path, id: &str) -> PathBuf {
    dir.join("cases").join(id)
}

/// State of the case folder `path`, by its manifest, checked against the folder's files
/// ([`crate::io::verify_folder`]) so that nothing changed after the run is read as its result.
pub fn case_state(path: &Path) -> CaseState {
    if !path.join(crate::io::MANIFEST).exists() {
        let marker = path.join(crate::io::INCOMPLETE_MARKER);
        let empty = std::fs::read_dir(path).map_or(true, |mut d| d.next().is_none());
        return if marker.exists() {
            CaseState::Failed(
                std::fs::read_to_string(marker)
                    .unwrap_or_default()
                    .trim()
                    .to_string(),
            )
        } else if empty {
            CaseState::Pending
        } else {
            CaseState::Damaged("manifest.json missing (the folder cannot be verified)".into())
        };
    }
    match crate::io::verify_folder(path) {
        Err(why) => CaseState::Damaged(why),
        Ok(m) if m["complete"] == serde_json::Value::Bool(true) => CaseState::Done,
        Ok(m) => CaseState::Failed(
            m["incomplete_reason"]
                .as_str()
                .unwrap_or("incomplete")
                .trim()
                .to_string(),
        ),
    }
}

/// State of the folder of `case` in sweep folder `dir`: [`case_state`], and a case whose
/// summary.json records other settings than the case's (a folder copied from another case,
/// manifest and all) is damaged too.
pub fn state_of(dir: &Path, case: &Case) -> CaseState {
    let path = case_dir(dir, &case.id);
    let state = case_state(&path);
    if !matches!(state, CaseState::Done | CaseState::Failed(_)) {
        return state;
    }
    let Ok(text) = std::fs::read_to_string(path.join("summary.json")) else {
        return state; // a run that failed before its summary
    };
    match serde_json::from_str::<serde_json::Value>(&text) {
        Err(e) => CaseState::Damaged(format!("summary.json is not JSON ({e})")),
        Ok(s) => match settings_differ(case, &s) {
            Some(why) => CaseState::Damaged(format!("summary.json is of another case: {why}")),
            None => state,
        },
    }
}

/// Where summary.json `s` records other settings than `case`'s: its deck overrides and the
/// run options it echoes as given.
fn settings_differ(case: &Case, s: &serde_json::Value) -> Option<String> {
    let mut want: Vec<(String, String)> = case
        .overrides()
        .iter()
        .map(|o| (o.key.clone(), o.value_text()))
        .collect();
    want.sort();
    let mut got: Vec<(String, String)> = s["options"]["overrides"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|o| {
                    let t = |k: &str| o[k].as_str().unwrap_or_default().to_string();
                    (t("key"), t("value"))
                })
                .collect()
        })
        .unwrap_or_default();
    got.sort();
    let show = |v: &[(String, String)]| {
        v.iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if want != got {
        return Some(format!(
            "it records the overrides [{}], the case sets [{}]",
            show(&got),
            show(&want)
        ));
    }
    for (opt, at) in [
        ("revs", &s["options"]["revs"]),
        ("steps_per_rev", &s["options"]["steps_per_rev"]),
        ("substeps", &s["options"]["substeps"]),
        ("rotor", &s["rotor"]),
        ("flight", &s["flight_record"]),
    ] {
        let Some(v) = case.option(opt) else { continue };
        let same = match v {
            toml::Value::Integer(i) => at.as_i64() == Some(*i),
            toml::Value::String(t) => at.as_str() == Some(t.as_str()),
            _ => true,
        };
        if !same {
            return Some(format!(
                "it records {opt} = {at}, the case sets {}",
                plan::display(v)
            ));
        }
    }
    None
}

/// Whether every model of the case folder `path` reached its periodicity tolerance (by its
/// summary.json; false when it cannot be read).
fn all_periodic(path: &Path) -> bool {
    let Ok(text) = std::fs::read_to_string(path.join("summary.json")) else {
        return false;
    };
    let Ok(s) = serde_json::from_str::<serde_json::Value>(&text) else {
        return false;
    };
    s["models"].as_object().is_some_and(|m| {
        m.values()
            .all(|v| v["periodic"]["converged"] == serde_json::Value::Bool(true))
    })
}

/// How to run a sweep.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// Cases run at once.
    pub jobs: usize,
    /// Shard K of N (None: every case).
    pub shard: Option<(usize, usize)>,
    /// Run failed cases again.
    pub retry_failed: bool,
}

/// What a sweep did.
#[derive(Clone, Debug, Default)]
pub struct SweepReport {
    /// Cases of this shard.
    pub total: usize,
    /// Cases found complete and skipped.
    pub skipped: Vec<String>,
    /// Cases run now, with their error when they failed.
    pub ran: Vec<(String, Result<(), String>)>,
    /// Failed cases left as they were (no `retry_failed`), with the reason.
    pub failed_kept: Vec<(String, String)>,
    /// Cases started from a neighbour's periodic state.
    pub warm_started: usize,
}

impl SweepReport {
    /// Failed cases: run now and failed, or failed before and kept.
    pub fn failed(&self) -> Vec<String> {
        self.ran
            .iter()
            .filter(|(_, r)| r.is_err())
            .map(|(id, _)| id.clone())
            .chain(self.failed_kept.iter().map(|(id, _)| id.clone()))
            .collect()
    }
}

/// The expanded plan as stored in DIR/plan.json.
pub fn plan_json(plan: &Plan) -> anyhow::Result<String> {
    let v = serde_json::json!({
        "format": "rotorsim sweep plan 1",
        "keys": plan.keys,
        "warm_start": plan.warm_start,
        "group_size": plan.group_size,
        "cases": plan.cases,
    });
    Ok(serde_json::to_string_pretty(&v)? + "\n")
}

/// Reads DIR/plan.json (`sweep merge`); `file` is the plan file named in messages.
pub fn read_plan_json(dir: &Path) -> anyhow::Result<Plan> {
    let p = dir.join("plan.json");
    let text = std::fs::read_to_string(&p).map_err(|e| {
        anyhow!(
            "{}: cannot read ({e}); expected the folder of a `rotorsim sweep` (it writes plan.json first)",
            p.display()
        )
    })?;
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| anyhow!("{}: {e}", p.display()))?;
    let bad = |k: &str| anyhow!("{}: missing or malformed `{k}`", p.display());
    Ok(Plan {
        file: p.display().to_string(),
        keys: serde_json::from_value(v["keys"].clone()).map_err(|_| bad("keys"))?,
        cases: serde_json::from_value(v["cases"].clone()).map_err(|_| bad("cases"))?,
        warm_start: v["warm_start"].as_bool().ok_or_else(|| bad("warm_start"))?,
        group_size: v["group_size"].as_u64().ok_or_else(|| bad("group_size"))? as usize,
    })
}

/// Creates DIR (and DIR/cases) and writes DIR/plan.json, or checks that the plan.json already
/// there is this plan's.
pub fn prepare(dir: &Path, plan: &Plan) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir.join("cases"))
        .with_context(|| format!("creating sweep folder {}", dir.display()))?;
    let json = plan_json(plan)?;
    let p = dir.join("plan.json");
    match std::fs::read_to_string(&p) {
        Ok(old) if old == json => Ok(()),
        Ok(_) => bail!(
            "sweep folder {} holds a sweep of another plan (its plan.json differs from {}): choose another --out or remove it",
            dir.display(),
            plan.file
        ),
        Err(_) => {
            crate::io::write_atomic(&p, json.as_bytes())?;
            Ok(())
        }
    }
}

/// Checks every case with `runner` before any runs, on `jobs` threads; an error names the
/// plan file and the first failing case in plan order. `progress(checked, total)` is called
/// as cases are checked (from any thread).
pub fn check(
    plan: &Plan,
    runner: &dyn CaseRunner,
    jobs: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> anyhow::Result<()> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .map_err(|e| anyhow!("cannot start {jobs} worker threads: {e}"))?;
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = plan.cases.len();
    let first_bad = pool.install(|| {
        plan.cases.par_iter().find_map_first(|c| {
            let r = runner.check(c).err().map(|e| (c, e));
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(n, total);
            r
        })
    });
    match first_bad {
        None => Ok(()),
        Some((c, e)) => Err(anyhow!(
            "sweep plan {}: case {} ({}): {e:#}",
            plan.file,
            c.id,
            varied_text(plan, c)
        )),
    }
}

/// `key = value, ...` of the varied keys `case` sets, for messages.
pub fn varied_text(plan: &Plan, case: &Case) -> String {
    plan.keys
        .iter()
        .filter_map(|k| Some(format!("{k} = {}", plan::display(case.settings.get(k)?))))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The lock of a sweep (or of one shard of it) on its folder, held until dropped.
#[derive(Debug)]
pub struct SweepLock {
    _lock: crate::io::FolderLock,
    /// Stale locks of killed sweeps taken over or removed (say so to the user).
    pub notes: Vec<String>,
}

/// Lock file of a sweep into DIR: `DIR/.sweep.lock`, or `DIR/.sweep-shard-K-of-N.lock` for a
/// shard (the shards of one array run at once into DIR: each locks only its own cases).
pub fn lock_file(dir: &Path, shard: Option<(usize, usize)>) -> PathBuf {
    match shard {
        None => dir.join(".sweep.lock"),
        Some((k, n)) => dir.join(format!(".sweep-shard-{k}-of-{n}.lock")),
    }
}

/// The shard a lock file name stands for (Some(None): the whole sweep), None for other files.
fn lock_scope(name: &str) -> Option<Option<(usize, usize)>> {
    if name == ".sweep.lock" {
        return Some(None);
    }
    let kn = name.strip_prefix(".sweep-shard-")?.strip_suffix(".lock")?;
    let (k, n) = kn.split_once("-of-")?;
    Some(Some((k.parse().ok()?, n.parse().ok()?)))
}

/// The error of a sweep folder held by another sweep (`holder`, its lock file `lock`).
fn in_use(dir: &Path, holder: &str, lock: &Path) -> anyhow::Error {
    anyhow!(
        "sweep folder {} is in use by another rotorsim sweep ({holder}, lock file {}); wait for it to end, or remove the lock file if that process is not running",
        dir.display(),
        lock.display()
    )
}

/// Takes the lock of a sweep (or shard) into DIR, which must exist: refused while another
/// sweep runs cases that may be ours (the whole sweep, or a shard of another count; the other
/// shards of the same count have other cases), naming its lock file and pid. Locks of
/// processes no longer running are stale: taken over or removed, with a note.
pub fn lock(dir: &Path, shard: Option<(usize, usize)>) -> anyhow::Result<SweepLock> {
    use crate::io::{lock_holder, FolderLock, LockHolder};
    let mine = lock_file(dir, shard);
    let held = FolderLock::acquire(dir, &mine).map_err(|e| match e {
        crate::io::OutputError::Locked { holder, lock, .. } => in_use(dir, &holder, &lock),
        e => anyhow!("{e}"),
    })?;
    let mut notes: Vec<String> = held.took_over.iter().cloned().collect();
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("listing sweep folder {}", dir.display()))?;
    let mut others: Vec<(PathBuf, Option<(usize, usize)>)> = entries
        .flatten()
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            Some((e.path(), lock_scope(&name)?))
        })
        .filter(|(p, _)| *p != mine)
        .collect();
    others.sort();
    for (other, scope) in others {
        let overlaps = match (shard, scope) {
            (Some((_, n)), Some((_, m))) => n != m,
            _ => true,
        };
        match lock_holder(&other) {
            LockHolder::Stale { pid } => {
                let _ = std::fs::remove_file(&other);
                notes.push(format!(
                    "removed the stale lock file {} of pid {pid} (no longer running)",
                    other.display()
                ));
            }
            LockHolder::Live { pid, host } if overlaps => {
                return Err(in_use(dir, &LockHolder::describe(pid, &host), &other))
            }
            LockHolder::Unreadable if overlaps => bail!(
                "sweep folder {}: lock file {} holds no pid; remove it if no rotorsim sweep is running into {}",
                dir.display(),
                other.display(),
                dir.display()
            ),
            _ => {}
        }
    }
    Ok(SweepLock { _lock: held, notes })
}

/// Group indices of shard `shard` (all without one).
pub fn shard_groups(n_groups: usize, shard: Option<(usize, usize)>) -> Vec<usize> {
    (0..n_groups)
        .filter(|g| shard.is_none_or(|(k, n)| g % n == k))
        .collect()
}

/// Runs the plan's cases of this shard into DIR that are not done (and the failed ones with
/// `retry_failed`). [`prepare`] and [`check`] first.
pub fn execute(
    plan: &Plan,
    dir: &Path,
    opts: &SweepOptions,
    runner: &dyn CaseRunner,
    progress: &dyn SweepProgress,
) -> anyhow::Result<SweepReport> {
    let groups = plan.groups();
    let mine = shard_groups(groups.len(), opts.shard);
    let mut report = SweepReport::default();
    let needs = |i: usize, report: &mut SweepReport| -> bool {
        let c = &plan.cases[i];
        let mut state = state_of(dir, c);
        // a case that asked for periodicity and did not reach it is published complete (its
        // best revolution), but it has not done what was asked: failed for the resume
        let requires = c.option("require_periodic") == Some(&toml::Value::Boolean(true));
        if state == CaseState::Done && requires && !all_periodic(&case_dir(dir, &c.id)) {
            state = CaseState::Failed("not periodic (require_periodic)".into());
        }
        match state {
            CaseState::Done => {
                report.skipped.push(c.id.clone());
                false
            }
            CaseState::Failed(why) | CaseState::Damaged(why) if !opts.retry_failed => {
                report.failed_kept.push((c.id.clone(), why));
                false
            }
            CaseState::Damaged(why) => {
                // The sweep's own case folder that cannot be verified (no manifest: a run
                // killed before it published) is not a result: a run refuses to replace a
                // folder it cannot recognise, so the retry clears it first.
                let folder = case_dir(dir, &c.id);
                if folder.is_dir() && !folder.join("manifest.json").exists() {
                    if let Err(e) = std::fs::remove_dir_all(&folder) {
                        report.failed_kept.push((
                            c.id.clone(),
                            format!(
                                "{why}; cannot clear {} to run it again: {e}",
                                folder.display()
                            ),
                        ));
                        return false;
                    }
                }
                true
            }
            _ => true,
        }
    };
    let mut seeds = Vec::new();
    let mut members = Vec::new();
    for &g in &mine {
        let gr = &groups[g];
        report.total += 1 + gr.members.len();
        if needs(gr.seed, &mut report) {
            seeds.push(gr.seed);
        }
        for &(i, warm) in &gr.members {
            if needs(i, &mut report) {
                members.push((i, warm.then_some(gr.seed)));
            }
        }
    }
    progress.start(seeds.len() + members.len(), report.total);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.jobs.max(1))
        .build()
        .map_err(|e| anyhow!("cannot start {} worker threads: {e}", opts.jobs))?;
    let run_one = |i: usize, from: Option<usize>| -> (String, Result<(), String>, bool) {
        let c = &plan.cases[i];
        let init = from
            .filter(|&s| state_of(dir, &plan.cases[s]) == CaseState::Done)
            .map(|s| case_dir(dir, &plan.cases[s].id));
        let t0 = std::time::Instant::now();
        let r = runner
            .run(c, &case_dir(dir, &c.id), init.as_deref())
            .map_err(|e| format!("{e:#}"));
        progress.case_done(c, &r, t0.elapsed().as_secs_f64());
        (c.id.clone(), r, init.is_some())
    };
    for wave in [
        seeds.iter().map(|&i| (i, None)).collect::<Vec<_>>(),
        members,
    ] {
        let done: Vec<(String, Result<(), String>, bool)> =
            pool.install(|| wave.par_iter().map(|&(i, f)| run_one(i, f)).collect());
        for (id, r, warm) in done {
            report.warm_started += warm as usize;
            report.ran.push((id, r));
        }
    }
    Ok(report)
}

/// An sbatch array script running shard `$SLURM_ARRAY_TASK_ID` of `shards` of the plan (each
/// task on `cpus` CPUs), then nothing else: `rotorsim sweep merge DIR` builds sweep.csv once
/// the array has ended.
pub fn slurm_script(
    exe: &Path,
    workdir: &Path,
    plan: &Path,
    out: &Path,
    shards: usize,
    cpus: usize,
    extra: &[String],
) -> String {
    let q = |p: &Path| shell_quote(&p.display().to_string());
    let extra: String = extra
        .iter()
        .map(|a| format!(" {}", shell_quote(a)))
        .collect();
    format!(
        "#!/bin/bash\n\
         #SBATCH --job-name=rotorsim-sweep\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --ntasks=1\n\
         #SBATCH --cpus-per-task={cpus}\n\
         #SBATCH --output={log}/slurm-%A_%a.out\n\
         # rotorsim sweep as a Slurm job array: task K runs shard K of {shards} (its own case\n\
         # folders only). When the array has ended: {exe} sweep merge {outq}\n\
         set -euo pipefail\n\
         cd {wd}\n\
         exec {exe} sweep {plan} --out {outq} --jobs \"${{SLURM_CPUS_PER_TASK:-{cpus}}}\" \
         --shard \"${{SLURM_ARRAY_TASK_ID}}/{shards}\"{extra}\n",
        last = shards.saturating_sub(1),
        log = q(out),
        exe = q(exe),
        wd = q(workdir),
        plan = q(plan),
        outq = q(out),
    )
}

fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-=+:,@%".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', "'\\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_locks_conflict_only_across_shard_counts() {
        let d = std::env::temp_dir().join(format!("rotorsim-sweep-lock-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        assert_eq!(lock_scope(".sweep.lock"), Some(None));
        assert_eq!(lock_scope(".sweep-shard-1-of-4.lock"), Some(Some((1, 4))));
        assert_eq!(lock_scope("plan.json"), None);
        let a = lock(&d, Some((0, 2))).unwrap();
        let b = lock(&d, Some((1, 2))).unwrap();
        let e = lock(&d, None).unwrap_err().to_string();
        assert!(e.contains(".sweep-shard-0-of-2.lock"), "{e}");
        let e = lock(&d, Some((0, 3))).unwrap_err().to_string();
        assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
        drop((a, b));
        let _whole = lock(&d, None).unwrap();
        assert!(lock(&d, Some((0, 2))).is_err());
        drop(_whole);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
