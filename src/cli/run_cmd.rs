//! `rotorsim run`: forced response of a rotor to a flight record with one or all
//! damper models, to a periodic solution; writes summary.json, <model>/last_rev.csv,
//! report.html and result.mcap (docs/run.md). The run itself is the library's
//! [`RunJob`]; this module turns the options into one and prints what it did.
use super::run_console::Console;
use crate::overrides::Override;
use crate::run::job::{NamedOptions, RunFailed, RunJob, RunOutcome};
use crate::run::{self, fmt_measure, summary};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// Rotor deck (docs/rotor_deck.md).
    #[arg(long, default_value = "rotors/uh60a.toml")]
    pub rotor: PathBuf,
    /// Flight record: MCAP file or CSV stem (docs/formats.md).
    #[arg(long, default_value = "flightdata/c8534like")]
    pub flight: PathBuf,
    /// Damper model: linear, nonlinear, physical, or all (the three in parallel).
    #[arg(long, default_value = "all")]
    pub damper: String,
    /// Damper deck overriding the rotor deck's [damper] table (e.g. from `diagnose --write-deck`).
    #[arg(long)]
    pub damper_deck: Option<PathBuf>,
    /// Most rotor revolutions integrated per model (shooting: perturbed and trial revolutions
    /// included); the run stops earlier once periodic. The reported revolution is the last
    /// accepted one.
    #[arg(long, default_value_t = 75)]
    pub revs: usize,
    /// Periodic solver: shooting (Newton-Picard on the revolution map, falling back to
    /// marching when it cannot converge) or march (revolution after revolution).
    #[arg(long, default_value = "shooting")]
    pub periodic: String,
    /// Periodicity residual at which a model stops: per monitored channel (damper force, tip
    /// flap, lag, twist) the change over one revolution relative to its peak-to-peak.
    #[arg(long, default_value_t = crate::run::periodic::DEFAULT_TOL)]
    pub periodic_tol: f64,
    /// Start from a saved periodic state: a periodic_state.json, or the directory of an
    /// earlier run (then each model starts from its own <model>/periodic_state.json).
    #[arg(long)]
    pub initial_state: Option<PathBuf>,
    /// Exit non-zero when a model does not reach the periodicity tolerance.
    #[arg(long)]
    pub require_periodic: bool,
    /// Also write <model>/all_revs.csv: every revolution integrated on the way to the periodic
    /// solution (marched revolutions and accepted shooting iterates, not perturbed ones).
    #[arg(long)]
    pub write_all_revs: bool,
    /// Structural steps per revolution.
    #[arg(long, default_value_t = 256)]
    pub steps_per_rev: usize,
    /// Hydraulic sub-steps per structural step.
    #[arg(long, default_value_t = 25)]
    pub substeps: usize,
    /// Hydraulic sub-step scheme: rk4 or implicit.
    #[arg(long, default_value = "rk4")]
    pub scheme: String,
    /// Rotor model: uh60a (the multibody model of the rotor deck), rigid (the rotor deck's blade
    /// rigid on its lag hinge, airloads projected with the control pitch: the reduced model of
    /// docs/rotor_model.md, "Rigid-blade reduction") or sdof (a fast TEST DOUBLE of the
    /// pipeline, not a rotor model).
    #[arg(long, default_value = "uh60a")]
    pub model: String,
    /// Newton method of the structural step: modified (the iteration matrix is factored once
    /// and reused across iterations and steps in the frame turning with the shaft, refreshed
    /// when it stops contracting) or full (factored at every iteration). Both converge to the
    /// same residual test.
    #[arg(long, default_value = "modified")]
    pub newton: String,
    /// Override a rotor-deck or damper-deck value by its dotted path, unit in the name
    /// (repeatable): `--set damper.physical.A_orf_m2=2.0e-6`. Applied before validation, so
    /// checked like the deck; `damper.*` keys go to `--damper-deck` when one is given.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_set)]
    pub set: Vec<Override>,
    /// Run every blade of the rotor on its driven hub, each its own model at its own azimuth
    /// (blade k (k-1) 360/N ahead of blade 1), the hub loads summed from their root loads;
    /// implied by per-blade differences (`[blades.K...]` in the deck, `--set blades.K...`).
    /// A deck with an `[airframe]` puts the hub on it: the blades then run as one model.
    /// Writes <model>/blade<K>/ for every blade (docs/run.md).
    #[arg(long)]
    pub all_blades: bool,
    /// Where the blade's airloads come from: measured (the record's, replayed), computed (a
    /// lifting line with the deck's [aero] table and an inflow model, under the record's
    /// controls: a prediction), hybrid (the record's airloads plus the lifting line's
    /// difference between the blade's motion and the record's measured blade motion, or the
    /// periodic solution's where the record has none) or hybrid-periodic (that difference
    /// from the periodic solution under the measured airloads: the measured answer, with
    /// aerodynamic damping of transients and in the Floquet multipliers).
    /// docs/aerodynamics.md.
    #[arg(long, default_value = "measured")]
    pub airloads: String,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

fn parse_set(s: &str) -> Result<Override, String> {
    Override::parse(s).map_err(|e| format!("{e:#}"))
}

impl RunArgs {
    /// The run these options ask for, checked as far as the options go.
    pub fn job(&self) -> anyhow::Result<RunJob> {
        let mut job = RunJob {
            rotor: self.rotor.clone(),
            flight: self.flight.clone(),
            damper_deck: self.damper_deck.clone(),
            revs: self.revs,
            periodic_tol: self.periodic_tol,
            initial_state: self.initial_state.clone(),
            require_periodic: self.require_periodic,
            write_all_revs: self.write_all_revs,
            steps_per_rev: self.steps_per_rev,
            substeps: self.substeps,
            overrides: self.set.clone(),
            all_blades: self.all_blades,
            ..RunJob::new(&self.out)
        };
        job.set_named(&NamedOptions {
            damper: &self.damper,
            scheme: &self.scheme,
            newton: &self.newton,
            periodic: &self.periodic,
            model: &self.model,
            airloads: &self.airloads,
        })?;
        Ok(job)
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
                    outln!(
                        "warning: {}: aerofoil tables clamped {} queries to their edges (not extrapolated): {}",
                        r.label, a.clamped_queries, a.clamps
                    );
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
