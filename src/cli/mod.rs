//! Command line interface: one file per subcommand, each with its own clap `Args` and `run`.
//!
//! Everything printed goes through [`outln!`] / [`errln!`]: a closed or full standard output or
//! error never panics. A reader that went away (broken pipe, `rotorsim ... | head`) is not an
//! error; any other failure to write standard output (a full disk) fails the command at the end
//! with the reason, since what it printed is lost.
use clap::{Parser, Subcommand};
use std::io::Write as _;
use std::process::ExitCode;
use std::sync::Mutex;

/// The first failure to write standard output other than a broken pipe.
static STDOUT_ERROR: Mutex<Option<std::io::Error>> = Mutex::new(None);

#[doc(hidden)]
pub fn write_stdout(args: std::fmt::Arguments<'_>, newline: bool) {
    let mut o = std::io::stdout().lock();
    let r = o
        .write_fmt(args)
        .and_then(|_| if newline { o.write_all(b"\n") } else { Ok(()) })
        .and_then(|_| o.flush());
    if let Err(e) = r {
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            if let Ok(mut slot) = STDOUT_ERROR.lock() {
                slot.get_or_insert(e);
            }
        }
    }
}

#[doc(hidden)]
pub fn write_stderr(args: std::fmt::Arguments<'_>, newline: bool) {
    // nowhere left to report a failure to write the error stream
    let mut e = std::io::stderr().lock();
    let _ = e
        .write_fmt(args)
        .and_then(|_| if newline { e.write_all(b"\n") } else { Ok(()) });
}

/// `println!` that never panics (see the module documentation).
macro_rules! outln {
    () => { $crate::cli::write_stdout(format_args!(""), true) };
    ($($t:tt)*) => { $crate::cli::write_stdout(format_args!($($t)*), true) };
}
/// `print!` that never panics.
#[allow(unused_macros)]
macro_rules! out {
    ($($t:tt)*) => { $crate::cli::write_stdout(format_args!($($t)*), false) };
}
/// `eprintln!` that never panics.
macro_rules! errln {
    () => { $crate::cli::write_stderr(format_args!(""), true) };
    ($($t:tt)*) => { $crate::cli::write_stderr(format_args!($($t)*), true) };
}
/// `eprint!` that never panics.
#[allow(unused_macros)]
macro_rules! errout {
    ($($t:tt)*) => { $crate::cli::write_stderr(format_args!($($t)*), false) };
}

pub mod bench;
pub mod convert;
pub mod decay;
pub mod diagnose;
pub mod dynamic;
pub mod expand;
pub mod inspect;
pub mod modes;
pub mod run_cmd;
mod run_console;
pub mod sensitivity;
pub mod stability;
pub mod static_cmd;
pub mod sweep;
pub mod verify;

/// Exit status, the same for every command (also in docs/run.md); `run` adds the case of its
/// own --require-periodic.
macro_rules! exit_note {
    () => {
        exit_note!("")
    };
    ($extra:literal) => {
        concat!(
            "Exit status: 0 when the command did what was asked; 1 when it could not (bad input, \
a failed model, a numerical failure, ",
            $extra,
            "stdout lost), with the reason on stderr; 2 for a command line that cannot be parsed \
(unknown option, missing value)."
        )
    };
}

/// A command's outputs, then what every result folder holds, then the exit status (with the
/// command's own causes of exit 1, if any).
macro_rules! writes {
    ($own:literal) => {
        writes!($own, "")
    };
    ($own:literal, $extra:literal) => {
        concat!(
            $own,
            "\n\nEvery result folder also holds manifest.json (inputs and outputs with their \
sha256, command line, version, `complete`); a folder that did not finish holds an INCOMPLETE \
marker.\n\n",
            exit_note!($extra)
        )
    };
}

/// Output to stdout only, then the exit status.
macro_rules! prints {
    ($own:literal) => {
        concat!($own, "\n\n", exit_note!())
    };
}

#[derive(Parser, Debug)]
#[command(
    name = "rotorsim",
    version,
    about = "Rotor-blade loads with physics-based hydraulic lead-lag dampers",
    after_help = exit_note!()
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Virtual damper test bench: harmonic sweeps or replay of measured bench tests.
    #[command(after_long_help = writes!(
        "Writes DIR/: bench.html (paper Fig. 13 peak force vs velocity, force-stroke and \
force-velocity loops per amplitude, K' and K'' and energy per cycle vs amplitude), \
bench_summary.csv (per model and amplitude: peaks, K_storage_N_per_m, K_loss_N_per_m, \
energy_per_cycle_J, ...), peaks.csv, history_v<v>m_s.csv (one time history per peak velocity v \
in m/s, sampled at --output-rate), peak_force_vs_velocity.svg, time_history.svg; with --damper \
all the per-model files in DIR/<model>/. With --measured: bench.html (measured vs model over \
time and loops, error metrics), replay_<test>_<model>.csv, loop_<test>_<model>.svg and \
replay_summary.csv (errors over the samples after --skip-cycles)."
    ))]
    Bench(bench::BenchArgs),
    /// Nonlinear static analysis of a model deck.
    #[command(after_long_help = writes!(
        "Writes DIR/: static.csv (every sensor), nodes.csv and node_names.csv (the deformed \
configuration), tangent_check.txt with --check-tangent."
    ))]
    Static(static_cmd::StaticArgs),
    /// Dynamic (generalized-alpha) analysis of a model deck.
    #[command(after_long_help = writes!(
        "Writes DIR/: sensors.csv (time histories of every sensor), summary.json (steps, Newton \
iterations, wall time, `complete`); with [[hydraulic]] devices plots.svg and one SVG per \
paper figure 9-12 of each device."
    ))]
    Dynamic(dynamic::DynamicArgs),
    /// Natural frequencies and mode shapes (model deck, or rotor deck fan plot).
    #[command(after_long_help = writes!(
        "Writes DIR/: modes.csv and mode_shapes.csv (model deck); fan.csv, fan.svg and, with a \
reference table, fan_comparison.csv (rotor deck)."
    ))]
    Modes(modes::ModesArgs),
    /// Ground resonance of a rotor deck on its airframe over rotor speeds.
    #[command(after_long_help = writes!(
        "Writes DIR/: stability.csv (rotor_speed_rad_s, mode, frequency_Hz, damping_ratio, \
growth_rate_per_s, method = coleman | floquet), stability.html (Coleman diagram, damping \
against speed with the unstable ranges shaded, the reduced model) and summary.json. An unstable \
rotor is a result: exit 0, marked UNSTABLE."
    ))]
    Stability(stability::StabilityArgs),
    /// Free decay of a hinged blade's lag hinge beside its linearised mode.
    #[command(after_long_help = writes!(
        "Writes DIR/: decay.csv (lag angle history: time_s, lag_angle_rad, lag_angle_deg) and \
decay_summary.csv (frequency_Hz and damping_ratio of the linearised mode, of a damped-sine fit \
and of the log decrement over t >= 1 s)."
    ))]
    Decay(decay::DecayArgs),
    /// Run the verification suite and write verify.json.
    #[command(after_long_help = writes!("Writes DIR/verify.json: every check with its \
reference, value, tolerance and pass/fail."))]
    Verify(verify::VerifyArgs),
    /// Convert a flight record between the CSV triple and MCAP.
    #[command(after_long_help = prints!("Writes the converted record (STEM.meta.json, \
STEM.airloads.csv, STEM.damper.csv and, for a record with a blade motion, STEM.motion.csv; or \
FILE.mcap)."))]
    Convert(convert::ConvertArgs),
    /// Print what a flight record holds.
    #[command(after_long_help = prints!("Writes nothing; prints to stdout."))]
    Inspect(inspect::InspectArgs),
    /// Print the multibody model deck generated from a rotor deck.
    #[command(after_long_help = prints!("Writes nothing; prints the deck (TOML) to stdout."))]
    Expand(expand::ExpandArgs),
    /// Forced response of a rotor to a flight record, to a periodic solution, with report.
    #[command(after_long_help = writes!(
        "Writes DIR/: report.html (verdict, figures, tables: open this first), summary.json \
(every figure, with provenance), result.mcap (for a viewer such as Foxglove), and per damper \
model <model>/last_rev.csv (the periodic revolution with the measurement), \
<model>/periodic_state.json (for --initial-state) and, with --write-all-revs, \
<model>/all_revs.csv. The last lines printed are the verdict and the files to open.",
        "a run that is not periodic under --require-periodic, "
    ))]
    Run(run_cmd::RunArgs),
    /// Find what a damper model gets wrong in measured data, name the cause, extend the model.
    #[command(after_long_help = writes!(
        "Writes DIR/: diagnosis.json (cause, parameters, validation, candidates), \
diagnosis.html (evidence and figures), extended_deck.toml (also to --write-deck FILE); with \
--rotor-check the rotor runs of both decks in rotor_check/baseline/ and rotor_check/extended/."
    ))]
    Diagnose(diagnose::DiagnoseArgs),
    /// Batch forced-response runs from a plan: locally on all cores, or as Slurm array shards.
    #[command(after_long_help = writes!(
        "Writes DIR/: plan.json (the expanded plan), cases/<id>/ (what `run` writes, per case), \
sweep.csv (one row per case and damper model) and sweep.html; --emit-slurm FILE writes the \
sbatch array script only."
    ))]
    Sweep(sweep::SweepArgs),
    /// Sensitivity of the outputs to every value the rotor deck labels ASSUMED (and --vary).
    #[command(after_long_help = writes!(
        "Writes DIR/: sensitivity.csv (one row per parameter: its low, nominal and high value, \
each output at them and the swing), sensitivity.html (a tornado chart and a ranking per output), \
summary.json, sensitivity_plan.toml (the sweep plan of the cases) and what `rotorsim sweep` \
writes: plan.json, cases/<id>/ (a run folder per case), sweep.csv, sweep.html."
    ))]
    Sensitivity(sensitivity::SensitivityArgs),
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let r = run(cli);
    let lost = STDOUT_ERROR.lock().ok().and_then(|mut s| s.take());
    match (r, lost) {
        (Ok(()), None) => ExitCode::SUCCESS,
        (Ok(()), Some(e)) => {
            errln!("error: cannot write standard output: {e} (what it printed is lost)");
            ExitCode::FAILURE
        }
        (Err(e), _) => {
            errln!("error: {}", error_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes, `: `-separated, without repeating a cause that a message already
/// quotes (many errors show their source in their own message).
pub fn error_chain(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let c = cause.to_string();
        if out.contains(&c) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&c);
    }
    out
}

pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Bench(a) => bench::run(a),
        Command::Static(a) => static_cmd::run(a),
        Command::Dynamic(a) => dynamic::run(a),
        Command::Modes(a) => modes::run(a),
        Command::Decay(a) => decay::run(a),
        Command::Verify(a) => verify::run(a),
        Command::Convert(a) => convert::run(a),
        Command::Inspect(a) => inspect::run(a),
        Command::Expand(a) => expand::run(a),
        Command::Run(a) => run_cmd::run(a),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Sweep(a) => sweep::run(a),
        Command::Sensitivity(a) => sensitivity::run(a),
        Command::Stability(a) => stability::run(a),
    }
}
