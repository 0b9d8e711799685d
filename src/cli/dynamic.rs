//! `rotorsim dynamic`: generalized-alpha time integration of a model deck. The analysis is the
//! library's [`DynamicJob`]; this file prints what it did.
use crate::checks::dynamic::{DynamicJob, DynamicSettings};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct DynamicArgs {
    /// Model deck (TOML, see docs/model_deck.md) with a [dynamic] table.
    pub deck: PathBuf,
    /// Output directory (sensors.csv time histories, summary.json; with [[hydraulic]] elements
    /// also plots.svg and one SVG per paper figure 9-12 of each device).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub settings: DynamicSettings,
}

impl DynamicArgs {
    /// The analysis these options ask for.
    pub fn job(&self) -> DynamicJob {
        self.settings.job(&self.deck, &self.out)
    }
}

pub fn run(args: DynamicArgs) -> anyhow::Result<()> {
    let o = args.job().execute(&|line| errln!("{line}"))?;
    outln!(
        "dynamic: {} steps of {} s, {} Newton iterations ({:.2} per step), {:.2} s wall",
        o.steps,
        o.time_step_s,
        o.newton_iterations,
        o.newton_iterations as f64 / o.steps.max(1) as f64,
        o.wall_s
    );
    Ok(())
}
