//! `rotorsim dynamic` (issue #3).
use clap::Args;

#[derive(Args, Debug)]
pub struct DynamicArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: DynamicArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim dynamic` is not available yet (tracked in issue #3)")
}
