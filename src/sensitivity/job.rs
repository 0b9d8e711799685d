//! One `rotorsim sensitivity` as library code: its options ([`SensitivitySettings`], read by the
//! command line and from JSON) turned into a [`SensitivityJob`], which prepares the study (the
//! parameters, the plan, its checks) and then runs it or writes its Slurm script. The command
//! line only prints what each step returns.
use super::table::Sensitivity;
use super::{Outcome, SensitivityOptions, Setup, Vary};
use crate::sweep::batch::BatchSettings;
use crate::sweep::job::{default_jobs, env_shard};
use crate::sweep::{self, JobRunner, Plan, SweepOptions, SweepProgress};
use anyhow::{anyhow, bail};
use std::path::PathBuf;

/// Every option of `rotorsim sensitivity` but its result folder, as given (clap and serde):
/// each field's doc comment is its `--help` text and its `#[arg]` its default.
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct SensitivitySettings {
    /// Rotor deck whose values labelled `# ASSUMED` (a comment on the key's line) are varied.
    #[arg(long, default_value = "rotors/uh60a.toml")]
    pub rotor: PathBuf,
    /// Flight record (the damper force the RMS error is taken against).
    #[arg(long, default_value = "flightdata/c8534like")]
    pub flight: PathBuf,
    /// Also vary KEY from LOW to HIGH (repeatable; replaces the default range of a labelled
    /// value). KEY is a dotted deck key with its unit, `key[i]` for a component of an array:
    /// `--vary pitch_control.link_section.EA_N=7.2e5:1.8e6`.
    #[arg(long, value_name = "KEY=LOW:HIGH", value_parser = parse_vary)]
    #[serde(with = "vary_texts")]
    pub vary: Vec<Vary>,
    /// Vary only the --vary keys, not the deck's labelled values.
    #[arg(long)]
    pub only_vary: bool,
    /// Rotor model of every case: uh60a (the multibody model: every output), rigid (the
    /// rigid-blade reduction: fast, no blade loads) or sdof (a test double).
    #[arg(long, default_value = "uh60a")]
    pub model: String,
    /// Damper model of every case: linear, nonlinear or physical (default: the deck's
    /// `damper.model`).
    #[arg(long)]
    pub damper: Option<String>,
    // --warm-start starts the cases of each group of 3 from its seed's periodic state (the
    // nominal case and the seeds cold): faster, but a warm-started case's Floquet multipliers
    // can differ from a cold run's beyond its periodicity tolerance, hence cold by default.
    #[command(flatten)]
    pub batch: BatchSettings,
}

/// `--vary KEY=LOW:HIGH` as clap parses it.
pub fn parse_vary(s: &str) -> Result<Vary, String> {
    Vary::parse(s).map_err(|e| format!("{e:#}"))
}

/// `--vary` values as their `KEY=LOW:HIGH` texts (serde), each parsed as the option is.
mod vary_texts {
    use super::Vary;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(vary: &[Vary], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(vary.iter().map(|v| v.text.as_str()))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Vary>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|t| super::parse_vary(t).map_err(serde::de::Error::custom))
            .collect()
    }
}

impl Default for SensitivitySettings {
    /// The command line's defaults: no option given, parsed (the `#[arg]`s are the only list).
    fn default() -> Self {
        use clap::{Args, FromArgMatches};
        let m =
            Self::augment_args(clap::Command::new("sensitivity")).get_matches_from(["sensitivity"]);
        Self::from_arg_matches(&m)
            .unwrap_or_else(|e| unreachable!("sensitivity without options: {e}"))
    }
}

impl SensitivitySettings {
    /// The study these settings ask for into `out`. The shard comes from `shard`, else from
    /// the Slurm array's environment.
    pub fn job(&self, out: impl Into<PathBuf>) -> anyhow::Result<SensitivityJob> {
        let shard = match &self.batch.shard {
            Some(s) => Some(sweep::plan::parse_shard(s)?),
            None => env_shard()?,
        };
        let jobs = self.batch.jobs.unwrap_or_else(default_jobs).max(1);
        Ok(SensitivityJob {
            options: SensitivityOptions {
                rotor: self.rotor.clone(),
                flight: self.flight.clone(),
                model: self.model.clone(),
                damper: self.damper.clone(),
                vary: self.vary.clone(),
                only_vary: self.only_vary,
                out: out.into(),
                sweep: SweepOptions {
                    jobs,
                    shard,
                    retry_failed: self.batch.retry_failed,
                },
                warm_start: self.batch.warm_start() == Some(true),
            },
            batch: self.batch.clone(),
            runner: JobRunner::default(),
        })
    }

    /// Settings given as a JSON object of fields, every other the default; an unknown name or
    /// a wrong type is an error naming it.
    pub fn from_json(text: &str) -> anyhow::Result<Self> {
        serde_json::from_str(text).map_err(|e| anyhow!("sensitivity options: {e}"))
    }

    /// The settings' names with their default values (JSON).
    pub fn defaults_map() -> serde_json::Map<String, serde_json::Value> {
        serde_json::to_value(Self::default())
            .ok()
            .and_then(|v| v.as_object().cloned())
            .unwrap_or_default()
    }
}

/// One sensitivity study: its options, typed, and the runner of its cases.
pub struct SensitivityJob {
    pub options: SensitivityOptions,
    /// How the cases run (also what an emitted Slurm script repeats).
    pub batch: BatchSettings,
    pub runner: JobRunner,
}

/// A study ready to run: its parameters and its plan, written and checked.
#[derive(Debug)]
pub struct Prepared {
    pub setup: Setup,
    pub plan_path: PathBuf,
    pub plan: Plan,
}

/// What [`SensitivityJob::execute`] did.
#[derive(Debug)]
pub enum Executed {
    /// `--emit-slurm`: the script written, with its array tasks; nothing ran.
    Slurm { script: PathBuf, shards: usize },
    /// The cases ran (and without a shard the tables were written).
    Ran(Box<Outcome>),
}

impl SensitivityJob {
    /// Finds the parameters and writes DIR/sensitivity_plan.toml (errors name the option or
    /// the key).
    pub fn plan(&self) -> anyhow::Result<Prepared> {
        let setup = super::setup(&self.options, &self.runner)?;
        let (plan_path, plan) = super::write_plan(&self.options.out, &setup)?;
        Ok(Prepared {
            setup,
            plan_path,
            plan,
        })
    }

    /// Checks every case of the plan before any runs (`checked(n, total)` as cases are).
    pub fn check(
        &self,
        prepared: &Prepared,
        checked: &(dyn Fn(usize, usize) + Sync),
    ) -> anyhow::Result<()> {
        sweep::check(
            &prepared.plan,
            &self.runner,
            self.options.sweep.jobs,
            checked,
        )
    }

    /// Writes the Slurm script (`--emit-slurm`), or runs the cases and, without a shard, the
    /// fallback rounds and the tables.
    pub fn execute(
        &self,
        prepared: Prepared,
        progress: &dyn SweepProgress,
    ) -> anyhow::Result<Executed> {
        let Prepared {
            setup,
            plan_path,
            plan,
        } = prepared;
        if let Some(script) = &self.batch.emit_slurm {
            let shards = self
                .batch
                .emit_slurm(&plan, &plan_path, &self.options.out, script)?;
            return Ok(Executed::Slurm {
                script: script.clone(),
                shards,
            });
        }
        let out = super::run(&self.options, setup, &plan, &self.runner, progress)?;
        Ok(Executed::Ran(Box::new(out)))
    }
}

/// The study's error when a case failed or did not run (their outputs are empty).
pub fn check_failures(t: &Sensitivity) -> anyhow::Result<()> {
    let failures = t.failures();
    if !failures.is_empty() {
        bail!(
            "{} case(s) failed or did not run: {} (their outputs are empty; --retry-failed runs them again)",
            failures.len(),
            failures
                .iter()
                .map(|(id, why)| format!("{id}: {why}"))
                .collect::<Vec<_>>()
                .join("; ")
        );
    }
    Ok(())
}
