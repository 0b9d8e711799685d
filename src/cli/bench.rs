//! `rotorsim bench` (issue #2).
use clap::Args;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Arguments of a command that is not available yet.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub rest: Vec<String>,
}

pub fn run(_args: BenchArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorsim bench` is not available yet (tracked in issue #2)")
}
