//! Command line interface: one file per subcommand, each with its own clap `Args` and `run`.
use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod bench;
pub mod convert;
pub mod diagnose;
pub mod dynamic;
pub mod expand;
pub mod inspect;
pub mod modes;
pub mod run_cmd;
pub mod static_cmd;
pub mod verify;

#[derive(Parser, Debug)]
#[command(
    name = "rotorsim",
    version,
    about = "Rotor-blade loads with physics-based hydraulic lead-lag dampers"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Virtual damper test bench: harmonic sweeps or replay of measured bench tests.
    Bench(bench::BenchArgs),
    /// Nonlinear static analysis of a model deck.
    Static(static_cmd::StaticArgs),
    /// Dynamic (generalized-alpha) analysis of a model deck.
    Dynamic(dynamic::DynamicArgs),
    /// Natural frequencies and mode shapes (model deck, or rotor deck fan plot).
    Modes(modes::ModesArgs),
    /// Run the verification suite and write verify.json.
    Verify(verify::VerifyArgs),
    /// Convert a flight record between the CSV triple and MCAP.
    Convert(convert::ConvertArgs),
    /// Print what a flight record holds.
    Inspect(inspect::InspectArgs),
    /// Print the multibody model deck generated from a rotor deck.
    Expand(expand::ExpandArgs),
    /// Forced response of a rotor to a flight record, to a periodic solution, with report.
    Run(run_cmd::RunArgs),
    /// Find what a damper model gets wrong in measured data, name the cause, extend the model.
    Diagnose(diagnose::DiagnoseArgs),
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Bench(a) => bench::run(a),
        Command::Static(a) => static_cmd::run(a),
        Command::Dynamic(a) => dynamic::run(a),
        Command::Modes(a) => modes::run(a),
        Command::Verify(a) => verify::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Inspect(a) => inspect::run(a),
        Command::Expand(a) => expand::run(a),
        Command::Run(a) => run_cmd::run(a),
        Command::Diagnose(a) => diagnose::run(a),
    }
}
