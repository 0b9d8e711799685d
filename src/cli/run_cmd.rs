//! `rotorsim run` (issue #6).
use clap::Args;

#[derive(Args, Debug)]
pub struct RunArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: RunArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim run` is not available yet (tracked in issue #6)")
}
