//! `rotorsim expand` (issue #6).
use clap::Args;

#[derive(Args, Debug)]
pub struct ExpandArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: ExpandArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim expand` is not available yet (tracked in issue #6)")
}
