//! `rotorsim diagnose`: find what the damper model gets wrong in measured data, name
//! the cause, extend the model and measure the gain on held-out data. The diagnosis is the
//! library's [`pipeline::run`] (checks included); this file prints what it found.
use crate::diagnose::pipeline::{self, Config};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Damper deck of the baseline model (any TOML file with a [damper] table).
    #[arg(long = "damper-deck", alias = "deck")]
    pub deck: Option<PathBuf>,
    /// Measured bench test(s) (bench CSV of docs/formats.md, with force).
    #[arg(long)]
    pub measured: Vec<PathBuf>,
    /// Rotor deck (flight-record diagnosis; its [damper] table is the baseline unless --damper-deck).
    #[arg(long)]
    pub rotor: Option<PathBuf>,
    /// Flight record (MCAP file or CSV stem, e.g. flightdata/c8534like).
    #[arg(long)]
    pub flight: Option<PathBuf>,
    /// Output directory (diagnosis.json, diagnosis.html).
    #[arg(long)]
    pub out: PathBuf,
    /// Write the extended model as a damper deck.
    #[arg(long)]
    pub write_deck: Option<PathBuf>,
    /// Cycles simulated per fit test (the first settles the model).
    #[arg(long, default_value_t = 3)]
    pub fit_cycles: usize,
    /// Largest RK4 sub-step of the hydraulic model [s].
    #[arg(long, default_value_t = 3.0e-5)]
    pub max_substep: f64,
    /// Flight record without damper stroke: revolutions of the rotor run (physical damper,
    /// baseline deck) whose last, periodic revolution gives the simulated stroke.
    #[arg(long, default_value_t = 40)]
    pub revs: usize,
    /// Rotor runs (simulated stroke, --rotor-check): structural steps per revolution.
    #[arg(long, default_value_t = 256)]
    pub steps_per_rev: usize,
    /// Rotor runs (simulated stroke, --rotor-check): hydraulic RK4 sub-steps per structural step.
    #[arg(long, default_value_t = 25)]
    pub substeps: usize,
    /// Flight records: also run the rotor (--rotor must be a rotor deck) with the physical
    /// damper of the baseline deck and of the extended deck, in parallel, and compare both with
    /// the record's damper force (the rotor-level before/after; DIR/rotor_check/).
    #[arg(long)]
    pub rotor_check: bool,
    /// Revolutions of each rotor run of --rotor-check (as `rotorsim run --revs`).
    #[arg(long, default_value_t = 75)]
    pub check_revs: usize,
    /// Rotor model of the rotor runs: uh60a (the multibody model of the rotor deck) or rigid
    /// (its rigid-blade reduction, as `rotorsim run --model rigid`; seconds instead of minutes).
    #[arg(long = "model", alias = "rotor-model", default_value = "uh60a")]
    pub rotor_model: String,
}

impl DiagnoseArgs {
    /// Arguments with the command-line defaults (no data given): `diagnose --out OUT` parsed,
    /// so the defaults are the `#[arg]`s above only.
    pub fn new(out: PathBuf) -> Self {
        use clap::FromArgMatches;
        let cmd = <Self as Args>::augment_args(clap::Command::new("diagnose"));
        let m = cmd.get_matches_from([
            std::ffi::OsStr::new("diagnose"),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        Self::from_arg_matches(&m).unwrap_or_else(|e| unreachable!("diagnose --out: {e}"))
    }
}

impl DiagnoseArgs {
    /// The diagnosis these options ask for.
    pub fn config(&self) -> Config {
        Config {
            deck: self.deck.clone(),
            measured: self.measured.clone(),
            rotor: self.rotor.clone(),
            flight: self.flight.clone(),
            out: self.out.clone(),
            write_deck: self.write_deck.clone(),
            fit_cycles: self.fit_cycles,
            max_substep: self.max_substep,
            revs: self.revs,
            steps_per_rev: self.steps_per_rev,
            substeps: self.substeps,
            rotor_check: self.rotor_check,
            check_revs: self.check_revs,
            rotor_model: self.rotor_model.clone(),
        }
    }
}

pub fn run(args: DiagnoseArgs) -> anyhow::Result<()> {
    let cfg = args.config();
    let say = |s: &str| errln!("{s}");
    let report = pipeline::run(&cfg, &say)?;
    let d = &report.outcome.diagnosis;
    outln!("cause: {}", d.cause);
    for (k, v) in &d.parameters {
        outln!("  {k} = {v:.6e}");
    }
    let (v, gain) = (&d.validation, d.gain);
    outln!(
        "RMS error: baseline {:.1} N, extended {:.1} N; held-out ({}): baseline {:.1} N, extended {:.1} N, gain {gain:.3}",
        d.baseline_rms_N, d.extended_rms_N, v.method, v.baseline_rms_N, v.extended_rms_N
    );
    outln!(
        "{:<18} {:>3} {:>14} {:>12} {:>14}",
        "candidate",
        "k",
        "BIC",
        "RMS [N]",
        "held-out [N]"
    );
    for c in &d.candidates {
        outln!(
            "{:<18} {:>3} {:>14.1} {:>12.1} {:>14.1}",
            c.cause,
            c.k,
            c.bic,
            c.rms_N,
            c.held_out_rms_N
        );
    }
    for l in &d.limitations {
        outln!("limitation: {l}");
    }
    for i in &d.identifiability {
        outln!(
            "not separable: {} ({}){}",
            i.candidates.join(" vs "),
            i.why,
            i.deciding_test
                .as_ref()
                .map_or(String::new(), |t| format!("; to decide: {}", t.statement))
        );
    }
    if let Some(s) = &report.stroke_info {
        if s["kind"] == "simulated" {
            outln!("stroke: {}", s["statement"].as_str().unwrap_or_default());
            if let Some(w) = s.get("warning") {
                outln!("warning: {}", w.as_str().unwrap_or_default());
            }
        }
    }
    if let Some(c) = &report.check {
        outln!("{}", c.statement);
        outln!(
            "{:<52} {:>14} {:>14}  change",
            "rotor check",
            "baseline",
            "extended"
        );
        for row in &c.rows {
            outln!("{:<52} {:>14} {:>14}  {}", row[0], row[1], row[2], row[3]);
        }
    }
    outln!(
        "wrote {}/diagnosis.json and diagnosis.html",
        args.out.display()
    );
    if let Some(p) = &args.write_deck {
        outln!("wrote extended deck {}", p.display());
    }
    Ok(())
}
