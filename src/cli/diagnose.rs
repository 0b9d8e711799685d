//! `rotorsim diagnose`: find what the damper model gets wrong in measured data, name
//! the cause, extend the model and measure the gain on held-out data. The diagnosis is the
//! library's [`pipeline::run`] (checks included); this file prints what it found.
use crate::diagnose::pipeline::{self, Config};
use crate::diagnose::settings::DiagnoseSettings;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    #[command(flatten)]
    pub settings: DiagnoseSettings,
    /// Output directory (diagnosis.json, diagnosis.html).
    // --help lists it after --flight (the settings' fourth option)
    #[arg(long, display_order = 3)]
    pub out: PathBuf,
}

impl DiagnoseArgs {
    /// Arguments with the command-line defaults (no data given).
    pub fn new(out: PathBuf) -> Self {
        DiagnoseArgs {
            settings: DiagnoseSettings::default(),
            out,
        }
    }

    /// The diagnosis these options ask for.
    pub fn job(&self) -> Config {
        self.settings.job(&self.out)
    }
}

pub fn run(args: DiagnoseArgs) -> anyhow::Result<()> {
    let cfg = args.job();
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
    if let Some(p) = &args.settings.write_deck {
        outln!("wrote extended deck {}", p.display());
    }
    Ok(())
}
