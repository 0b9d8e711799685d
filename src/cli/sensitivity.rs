//! `rotorsim sensitivity --rotor DECK --out DIR`: every value the deck labels ASSUMED (and any
//! `--vary KEY=LOW:HIGH`) moved over its range through the sweep engine (pipeline:
//! src/sensitivity/, docs/sensitivity.md).
use super::sweep::{CheckConsole, Console};
use crate::sensitivity::job::{check_failures, Executed, SensitivitySettings};
use crate::sensitivity::table::OUTPUTS;
use crate::sensitivity::Setup;
use clap::Args;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct SensitivityArgs {
    #[command(flatten)]
    pub settings: SensitivitySettings,
    /// Output folder: sensitivity.csv, sensitivity.html, summary.json, sensitivity_plan.toml,
    /// and the sweep's plan.json, cases/<id>/, sweep.csv, sweep.html.
    // --help lists it after --flight (the settings' second option)
    #[arg(long, display_order = 1)]
    pub out: PathBuf,
}

pub fn run(args: SensitivityArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let job = args.settings.job(&args.out)?;
    let prepared = job.plan()?;
    let tty = std::io::stderr().is_terminal();
    let checking = CheckConsole::new(prepared.plan.cases.len(), tty);
    let checked = job.check(&prepared, &|n, total| checking.checked(n, total));
    checking.finish();
    checked?;
    print_setup(
        &prepared.setup,
        prepared.plan.cases.len(),
        &args.settings.model,
    );
    let cases = prepared.plan.cases.len();
    let progress = Console::lines("rotorsim sensitivity");
    let out = match job.execute(prepared, &progress)? {
        Executed::Slurm { script, shards } => {
            outln!(
                "wrote {}: a job array of {shards} task(s) over {cases} case(s); submit with `sbatch {}`, then run this command again without --emit-slurm (it finds the cases complete and writes the tables)",
                script.display(),
                script.display()
            );
            return Ok(());
        }
        Executed::Ran(out) => out,
    };
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
        "sensitivity: {} case(s), {} run now ({} warm-started), {} already complete, {} failed{}, {} at once, wall {:.1} s",
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
        job.options.sweep.jobs,
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
            .map(|(r, spread)| format!("{} (spread {spread:.4e})", r.param.name()))
            .collect();
        match t.nominal.values[k] {
            Some(v) => outln!(
                "{}: nominal {v:.4e}; most sensitive to (spread over low, nominal and high): {}",
                o.title,
                top.join(", ")
            ),
            None => outln!("{}: not available from the {} model", o.title, t.model),
        }
    }
    outln!(
        "open: {} (tornado charts, rankings)\n      {} (one row per parameter), {}",
        args.out.join("sensitivity.html").display(),
        args.out.join("sensitivity.csv").display(),
        args.out.join("summary.json").display()
    );
    check_failures(t)
}

/// The parameters and the labels not varied, before anything runs.
fn print_setup(setup: &Setup, cases: usize, model: &str) {
    outln!(
        "sensitivity: {} parameter(s), {cases} case(s) ({model} model, {} damper); {} ASSUMED label(s) not varied",
        setup.params.len(),
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
}
