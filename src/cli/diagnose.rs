//! `rotorsim diagnose` (issue #7).
use clap::Args;

#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: DiagnoseArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim diagnose` is not available yet (tracked in issue #7)")
}
