//! `rotorsim static`: nonlinear static analysis of a model deck. The analysis is the library's
//! [`StaticJob`]; this file prints what it found.
use crate::checks::static_job::{StaticJob, StaticSettings};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StaticArgs {
    /// Model deck (TOML, see docs/model_deck.md).
    pub deck: PathBuf,
    /// Output directory (static.csv, nodes.csv).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub settings: StaticSettings,
}

impl StaticArgs {
    /// The analysis these options ask for.
    pub fn job(&self) -> StaticJob {
        self.settings.job(&self.deck, &self.out)
    }
}

pub fn run(args: StaticArgs) -> anyhow::Result<()> {
    let o = args.job().execute(&|line| errln!("{line}"))?;
    outln!(
        "static: {} load steps, Newton iterations per step {:?}, final residual {:.3e}",
        o.iterations.len(),
        o.iterations,
        o.residual
    );
    for (h, v) in &o.sensors {
        outln!("  {h:<32} {v}");
    }
    if let Some(t) = &o.tangent {
        out!("{}", t.report);
    }
    o.verdict()
}
