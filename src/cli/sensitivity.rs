//! `rotorsim sensitivity --rotor DECK --out DIR`: every value the deck labels ASSUMED (and any
//! `--vary KEY=LOW:HIGH`) moved over its range through the sweep engine (pipeline:
//! src/sensitivity/, docs/sensitivity.md).
use super::sweep::{check_with_progress, BatchArgs, Console};
use crate::sensitivity::{self, table::OUTPUTS, SensitivityOptions, Vary};
use crate::sweep::job::{default_jobs, env_shard};
use crate::sweep::{self, JobRunner, SweepOptions};
use anyhow::bail;
use clap::Args;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct SensitivityArgs {
    /// Rotor deck whose values labelled `# ASSUMED` (a comment on the key's line) are varied.
    #[arg(long, default_value = "rotors/uh60a.toml")]
    pub rotor: PathBuf,
    /// Flight record (the damper force the RMS error is taken against).
    #[arg(long, default_value = "flightdata/c8534like")]
    pub flight: PathBuf,
    /// Output folder: sensitivity.csv, sensitivity.html, summary.json, sensitivity_plan.toml,
    /// and the sweep's plan.json, cases/<id>/, sweep.csv, sweep.html.
    #[arg(long)]
    pub out: PathBuf,
    /// Also vary KEY from LOW to HIGH (repeatable; replaces the default range of a labelled
    /// value). KEY is a dotted deck key with its unit, `key[i]` for a component of an array:
    /// `--vary pitch_control.link_section.EA_N=7.2e5:1.8e6`.
    #[arg(long, value_name = "KEY=LOW:HIGH", value_parser = parse_vary)]
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
    pub batch: BatchArgs,
}

fn parse_vary(s: &str) -> Result<Vary, String> {
    Vary::parse(s).map_err(|e| format!("{e:#}"))
}

pub fn run(args: SensitivityArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let shard = match &args.batch.shard {
        Some(s) => Some(sweep::plan::parse_shard(s)?),
        None => env_shard()?,
    };
    let jobs = args.batch.jobs.unwrap_or_else(default_jobs).max(1);
    let opts = SensitivityOptions {
        rotor: args.rotor.clone(),
        flight: args.flight.clone(),
        model: args.model.clone(),
        damper: args.damper.clone(),
        vary: args.vary.clone(),
        only_vary: args.only_vary,
        out: args.out.clone(),
        sweep: SweepOptions {
            jobs,
            shard,
            retry_failed: args.batch.retry_failed,
        },
        warm_start: args.batch.warm_start() == Some(true),
    };
    let runner = JobRunner::default();
    let setup = sensitivity::setup(&opts, &runner)?;
    let (plan_path, plan) = sensitivity::write_plan(&args.out, &setup)?;
    let tty = std::io::stderr().is_terminal();
    check_with_progress(&plan, &runner, jobs, tty)?;
    outln!(
        "sensitivity: {} parameter(s), {} case(s) ({} model, {} damper); {} ASSUMED label(s) not varied",
        setup.params.len(),
        plan.cases.len(),
        args.model,
        setup.damper,
        setup.skipped.len()
    );
    for p in &setup.params {
        outln!(
            "  {} [{}]: {} .. {} (nominal {}; {}; {})",
            p.name(),
            p.unit(),
            p.low,
            p.high,
            p.target.nominal,
            p.range,
            p.source
        );
    }
    for s in &setup.skipped {
        outln!(
            "  not varied: line {}{}: {}",
            s.line,
            s.key
                .as_ref()
                .map(|k| format!(" ({k})"))
                .unwrap_or_default(),
            s.reason
        );
    }
    if let Some(script) = &args.batch.emit_slurm {
        let shards = args
            .batch
            .emit_slurm(&plan, &plan_path, &args.out, script)?;
        outln!(
            "wrote {}: a job array of {shards} task(s) over {} case(s); submit with `sbatch {}`, then run this command again without --emit-slurm (it finds the cases complete and writes the tables)",
            script.display(),
            plan.cases.len(),
            script.display()
        );
        return Ok(());
    }
    let progress = Console::lines("rotorsim sensitivity");
    let out = sensitivity::run(&opts, setup, &plan, &runner, &progress)?;
    for n in &out.notes {
        errln!("note: {n}");
    }
    let report = &out.report;
    let fallbacks = out
        .setup
        .params
        .iter()
        .filter(|p| p.low_round + p.high_round > 0)
        .count();
    outln!(
        "sensitivity: {} case(s), {} run now ({} warm-started), {} already complete, {} failed{}, {jobs} at once, wall {:.1} s",
        report.total,
        report.ran.len(),
        report.warm_started,
        report.skipped.len(),
        report.failed().len(),
        if fallbacks > 0 {
            format!(" ({fallbacks} side(s) run again nearer the nominal value: fallback below)")
        } else {
            String::new()
        },
        t0.elapsed().as_secs_f64()
    );
    for (id, r) in &report.ran {
        if let Err(e) = r {
            outln!("failed: {id}: {e}");
        }
    }
    for p in out
        .setup
        .params
        .iter()
        .filter(|p| p.low_round + p.high_round > 0)
    {
        outln!("fallback: {}: {}", p.name(), p.range);
    }
    for (id, why) in &report.failed_kept {
        outln!("failed earlier (kept; --retry-failed runs it again): {id}: {why}");
    }
    let Some(t) = &out.table else {
        outln!(
            "when every shard has ended: run this command again without --shard (it writes the tables into {})",
            args.out.display()
        );
        return Ok(());
    };
    if t.synthetic {
        outln!("SYNTHETIC flight record: the RMS error is against synthetic data");
    }
    for (k, o) in OUTPUTS.iter().enumerate() {
        let top: Vec<String> = t
            .top3(k)
            .iter()
            .map(|(r, spread)| {
                let swing = r.swing(k).unwrap_or(*spread);
                format!("{} (swing {swing:+.4e})", r.param.name())
            })
            .collect();
        match t.nominal.values[k] {
            Some(v) => outln!("{}: nominal {v:.4e}; top: {}", o.title, top.join(", ")),
            None => outln!("{}: not available from the {} model", o.title, t.model),
        }
    }
    outln!(
        "open: {} (tornado charts, rankings)\n      {} (one row per parameter), {}",
        args.out.join("sensitivity.html").display(),
        args.out.join("sensitivity.csv").display(),
        args.out.join("summary.json").display()
    );
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
