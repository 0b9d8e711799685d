//! `rotorsim convert` (issue #5).
use clap::Args;

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: ConvertArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim convert` is not available yet (tracked in issue #5)")
}
