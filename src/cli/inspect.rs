//! `rotorsim inspect` (issue #5).
use clap::Args;

#[derive(Args, Debug)]
pub struct InspectArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: InspectArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim inspect` is not available yet (tracked in issue #5)")
}
