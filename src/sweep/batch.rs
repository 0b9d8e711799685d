//! How the cases of a batch run (`rotorsim sweep`, `rotorsim sensitivity`): the options both
//! commands share, one type read by the command line (clap) and by JSON (serde).
use crate::sweep::{self, Plan};
use anyhow::Context;
use std::path::{Path, PathBuf};

/// How the cases of a batch (a sweep, a sensitivity study) run: together on this machine, as one
/// shard of N, or as an sbatch job-array script.
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct BatchSettings {
    /// Cases run at once, at least 1 (default: the CPUs of the machine, or SLURM_CPUS_PER_TASK).
    #[arg(long, value_parser = at_least_one)]
    pub jobs: Option<usize>,
    /// Run only shard K of N of the cases (K from 0 to N-1); default from SLURM_ARRAY_TASK_ID
    /// and SLURM_ARRAY_TASK_COUNT when both are set. A shard writes only its own case folders;
    /// when all have ended, `rotorsim sweep merge DIR` (or the sensitivity command again,
    /// without a shard) writes the tables.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Run again the cases that failed in an earlier run into DIR (otherwise listed and kept).
    #[arg(long)]
    pub retry_failed: bool,
    /// Write an sbatch job-array script running the cases' shards to FILE, and prepare DIR;
    /// runs nothing.
    #[arg(long, value_name = "FILE")]
    pub emit_slurm: Option<PathBuf>,
    /// Array tasks of the emitted script, at least 1 (default: the warm-start groups, at most
    /// 64).
    #[arg(long, value_parser = at_least_one)]
    pub shards: Option<usize>,
    /// CPUs per array task of the emitted script, at least 1.
    #[arg(long, default_value_t = 1, value_parser = at_least_one)]
    pub cpus_per_task: usize,
    /// Start the cases of each warm-start group from its seed's periodic state (default: as
    /// the plan says; a sweep plan warm-starts unless `[sweep] warm_start = false`, a
    /// sensitivity study starts every case cold).
    #[arg(long, overrides_with = "no_warm_start")]
    pub warm_start: bool,
    /// Start every case cold, whatever the plan says.
    #[arg(long, overrides_with = "warm_start")]
    pub no_warm_start: bool,
}

impl BatchSettings {
    /// Warm starts as asked (None: as the plan says).
    pub fn warm_start(&self) -> Option<bool> {
        match (self.warm_start, self.no_warm_start) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        }
    }

    /// Writes the sbatch script `script` running the cases of `plan` (read from `plan_path`)
    /// into `out` as job-array shards, `out` prepared; returns the shards. The script's
    /// commands repeat the batch options that change what a shard runs.
    pub fn emit_slurm(
        &self,
        plan: &Plan,
        plan_path: &Path,
        out: &Path,
        script: &Path,
    ) -> anyhow::Result<usize> {
        let shards = self.shards.unwrap_or(plan.groups().len().clamp(1, 64));
        let cwd = std::env::current_dir().context("current folder")?;
        let abs = |p: &Path| {
            if p.is_absolute() {
                p.to_path_buf()
            } else {
                cwd.join(p)
            }
        };
        let exe = std::env::current_exe().context("locating the rotorsim executable")?;
        sweep::prepare(&abs(out), plan)?;
        let mut extra = Vec::new();
        match self.warm_start() {
            Some(true) => extra.push("--warm-start".to_string()),
            Some(false) => extra.push("--no-warm-start".to_string()),
            None => {}
        }
        if self.retry_failed {
            extra.push("--retry-failed".to_string());
        }
        let text = sweep::slurm_script(
            &exe,
            &cwd,
            &abs(plan_path),
            &abs(out),
            shards,
            self.cpus_per_task,
            &extra,
        );
        crate::io::write_atomic(script, text.as_bytes())
            .with_context(|| format!("writing {}", script.display()))?;
        Ok(shards)
    }
}

impl Default for BatchSettings {
    /// The command line's defaults: no option given, parsed (the `#[arg]`s are the only list).
    fn default() -> Self {
        use clap::{Args, FromArgMatches};
        let m = Self::augment_args(clap::Command::new("batch")).get_matches_from(["batch"]);
        Self::from_arg_matches(&m).unwrap_or_else(|e| unreachable!("batch without options: {e}"))
    }
}

/// A count of at least 1 (`--jobs`, `--shards`, `--cpus-per-task`): 0 would silently mean 1.
pub fn at_least_one(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        Ok(_) => Err("expected a whole number of at least 1, found 0".into()),
        Err(_) => Err(format!(
            "expected a whole number of at least 1, found `{s}`"
        )),
    }
}
