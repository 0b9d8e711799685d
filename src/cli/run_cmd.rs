//! `rotorsim run`: forced response of a rotor to a flight record with one or all
//! damper models, to a periodic solution; writes summary.json, <model>/last_rev.csv,
//! report.html and result.mcap (docs/run.md). The run itself is the library's
//! [`RunJob`]; this module turns the options into one and prints what it did.
use super::run_console::Console;
use crate::run::job::{RunFailed, RunJob, RunOutcome, RunSettings};
use crate::run::{self, fmt_measure, summary};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    #[command(flatten)]
    pub settings: RunSettings,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

impl RunArgs {
    /// The run these options ask for, checked as far as the options go.
    pub fn job(&self) -> anyhow::Result<RunJob> {
        self.settings.job(&self.out)
    }
}

pub fn run(args: RunArgs) -> anyhow::Result<()> {
    let job = args.job()?;
    let result = job.execute(&Console::default());
    // a run that failed after writing its outputs prints them as one that did not
    let outcome = match &result {
        Ok(o) => Some(o),
        Err(e) => e.downcast_ref::<RunFailed>().map(|f| f.outcome.as_ref()),
    };
    if let Some(o) = outcome {
        print_summary(o);
        print_verdict(o);
    }
    result.map(|_| ())
}

fn print_summary(outcome: &RunOutcome) {
    let measured = &outcome.measured;
    for o in &outcome.outcomes {
        match &o.result {
            Ok(r) => {
                let cmp = measured.as_ref().ok().and_then(|m| {
                    let f = r.channel("damper_force_N")?;
                    crate::analysis::compare::compare(
                        crate::analysis::compare::Periodic {
                            psi_deg: &r.azimuth_deg,
                            value: f,
                        },
                        crate::analysis::compare::Periodic {
                            psi_deg: &m.azimuth_deg,
                            value: &m.force_n,
                        },
                        run::N_HARMONICS,
                    )
                    .ok()
                });
                let t = r.timing;
                outln!(
                    "{:<22} residual {} ({}, {} revs, {}){}  wall {:.1} s (structure {:.1} s, hydraulics {:.1} s)",
                    r.label,
                    fmt_measure(r.last_measure()),
                    if r.converged() { "periodic" } else { "NOT periodic" },
                    r.periodic.revolutions_integrated,
                    r.periodic.method_used.name(),
                    cmp.map(|m| format!(
                        "  RMS error {:.0} N, correlation {:.3}",
                        m.rms_error, m.correlation
                    ))
                    .unwrap_or_default(),
                    r.wall_s,
                    t.total_s - t.hydraulics_s,
                    t.hydraulics_s
                );
                for line in summary::blade_force_lines(r) {
                    outln!("{:<22} {line}", "");
                }
                if let Some(c) = r.loads_check.as_ref().filter(|c| !c.passed) {
                    outln!(
                        "warning: {}: blade root loads differ from the resultant of the applied, inertial, damper and pitch-link loads by {:.2e} of {}'s peak-to-peak (above {:.1e}): the structural solution is not in equilibrium to the accuracy the loads need",
                        r.label, c.max_rel_error, c.channel, c.tolerance
                    );
                }
                if let (Some(a), Some(ct)) = (&r.airloads, r.channel("rotor_CT_over_sigma")) {
                    let mean = ct.iter().sum::<f64>() / ct.len().max(1) as f64;
                    outln!(
                        "{:<22} {} airloads ({} inflow): thrust coefficient over solidity {:.4}{}",
                        "",
                        a.source_text(),
                        a.inflow,
                        mean,
                        a.record_ct_over_sigma
                            .map(|v| format!(
                                " (the record's {v:.4}{}; a plausibility comparison)",
                                if a.record_synthetic {
                                    ", SYNTHETIC"
                                } else {
                                    ""
                                }
                            ))
                            .unwrap_or_default()
                    );
                }
                if let Some(a) = r.airloads.as_ref().filter(|a| a.clamped_queries > 0) {
                    errln!("warning: {}: {}", r.label, a.clamp_statement());
                }
                if r.converged() && r.periodic.message.starts_with("warm start") {
                    outln!("note: {}: {}", r.label, r.periodic.message);
                }
                if !r.converged() {
                    outln!(
                        "warning: {}: {}",
                        r.label,
                        summary::periodicity_statement(r)
                    );
                }
            }
            Err(e) => outln!("{:<22} FAILED: {e}", o.model.name()),
        }
    }
    if let Err(note) = measured {
        outln!("note: {note}");
    }
}

/// The last lines of a run: the verdict and the files to open (paths as published).
fn print_verdict(outcome: &RunOutcome) {
    if let Some(v) = &outcome.verdict {
        outln!("verdict: {v}");
    }
    let not_periodic: Vec<&str> = outcome.not_periodic().map(|r| r.model.as_str()).collect();
    if !not_periodic.is_empty() {
        outln!(
            "caution: NOT periodic: {} (the verdict compares revolutions that are not a periodic solution)",
            not_periodic.join(", ")
        );
    }
    let p = &outcome.published;
    outln!("open: {} (verdict, figures, tables)", p.report.display());
    outln!(
        "      {} (every figure), {} (for a viewer such as Foxglove)",
        p.summary.display(),
        p.mcap.display()
    );
    for (_, path) in &p.last_rev {
        outln!(
            "      {} (the periodic revolution, with the measurement)",
            path.display()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Cli, Command};
    use crate::run::job::RunJob;
    use clap::Parser;

    /// The library's defaults are the command line's.
    #[test]
    fn defaults_match_the_library() {
        let cli = Cli::try_parse_from(["rotorsim", "run", "--out", "x"]).unwrap();
        let Command::Run(args) = cli.command else {
            panic!("not a run")
        };
        assert_eq!(args.job().unwrap(), RunJob::new("x"));
    }
}
