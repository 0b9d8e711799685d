//! `rotorsim verify`: runs the structural verification suite, writes DIR/verify.json
//! (`{case, quantity, computed, reference, rel_error, source, tolerance, pass}`) and a table.
//! The suite is the library's [`VerifyJob`]; this file prints its table.
use crate::checks::verify::{VerifyJob, VerifySettings};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct VerifyArgs {
    /// Output directory (verify.json).
    #[arg(long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub settings: VerifySettings,
}

impl VerifyArgs {
    /// The suite these options ask for.
    pub fn job(&self) -> VerifyJob {
        self.settings.job(&self.out)
    }
}

pub fn run(args: VerifyArgs) -> anyhow::Result<()> {
    let o = args.job().execute()?;
    outln!(
        "{:<44} {:<34} {:>14} {:>14} {:>10} {:>8}  pass",
        "case",
        "quantity",
        "computed",
        "reference",
        "rel_error",
        "tol"
    );
    for e in &o.entries {
        let c = &e.check;
        outln!(
            "{:<44} {:<34} {:>14.6} {:>14.6} {:>10.2e} {:>8}  {}",
            c.case,
            c.quantity,
            c.computed,
            c.reference,
            c.rel_error,
            e.tolerance
                .map(|t| format!("{t:.1e}"))
                .unwrap_or_else(|| "order>3".into()),
            if e.pass { "yes" } else { "NO" }
        );
    }
    o.verdict()?;
    outln!("all {} checks pass", o.entries.len());
    Ok(())
}
