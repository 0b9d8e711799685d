//! `rotorsim bench`: harmonic sweeps of a damper deck (paper Figs. 13-14) and replay
//! of measured bench tests.
//! The bench is the library's [`BenchJob`] (checks and outputs, src/run/bench.rs); this file
//! turns the arguments into one and prints.
use crate::hydraulics::bench::{HarmonicRun, IN_TO_M, LB_TO_N};
use crate::hydraulics::{DamperModel, IntegratorOptions};
use crate::run::bench::BenchJob;
use clap::Args;
use std::f64::consts::PI;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Damper deck (any TOML file with a [damper] table, e.g. rotors/uh60a.toml).
    #[arg(long = "damper-deck", alias = "deck")]
    pub deck: PathBuf,
    /// Damper model: physical, linear, nonlinear, or all (default: the deck's `model`).
    #[arg(long)]
    pub damper: Option<String>,
    /// Circular frequency of the harmonic stroking [rad/s].
    #[arg(long, default_value_t = 27.02)]
    pub omega: f64,
    /// Peak velocities, comma separated, in --velocity-unit.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1,2,3,4,6,8,10")]
    pub peak_velocity: Vec<f64>,
    /// Unit of --peak-velocity: in/s, m/s or ft/s.
    #[arg(long, default_value = "in/s")]
    pub velocity_unit: String,
    /// Number of stroking cycles per amplitude (peaks are taken over the last one).
    #[arg(long, default_value_t = 10)]
    pub cycles: usize,
    /// Steps per cycle (the structural step of the coupled analysis).
    #[arg(long, default_value_t = 256)]
    pub steps_per_cycle: usize,
    /// Hydraulic sub-steps per step.
    #[arg(long, default_value_t = 25)]
    pub substeps: usize,
    /// Hydraulic sub-step scheme: rk4 or implicit.
    #[arg(long = "scheme", alias = "integrator", default_value = "rk4")]
    pub integrator: String,
    /// Output samples per second of the harmonic sweep (histories, peaks, loops): a multiple k
    /// of the step rate omega x --steps-per-cycle / 2 pi (rounded to the nearest; default k = 1,
    /// a sample at every step end). Each step is fed to the damper in k pieces with
    /// --substeps / k sub-steps each (rounded up), so the hydraulic sub-step does not grow.
    #[arg(long, value_name = "HZ")]
    pub output_rate: Option<f64>,
    /// Measured bench test(s) to replay instead of the harmonic sweep (bench CSV, docs/formats.md).
    #[arg(long)]
    pub measured: Vec<PathBuf>,
    /// Replay only: leave the first N cycles of each test out of the error metrics (the model
    /// starts at rest and settles over them). A cycle is the stroke's period: the median
    /// interval between upward crossings of its mid-range.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub skip_cycles: usize,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

impl BenchArgs {
    /// The bench these options ask for.
    pub fn job(&self) -> BenchJob {
        BenchJob {
            deck: self.deck.clone(),
            damper: self.damper.clone(),
            omega: self.omega,
            peak_velocity: self.peak_velocity.clone(),
            velocity_unit: self.velocity_unit.clone(),
            cycles: self.cycles,
            steps_per_cycle: self.steps_per_cycle,
            substeps: self.substeps,
            scheme: self.integrator.clone(),
            output_rate: self.output_rate,
            measured: self.measured.clone(),
            skip_cycles: self.skip_cycles,
            out: self.out.clone(),
        }
    }
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let job = args.job();
    let factor = velocity_factor(&args.velocity_unit);
    let outcome = job.execute(
        &mut |model, runs, opts| print_table(model, runs, &args, factor, opts),
        &mut |line| outln!("{line}"),
    )?;
    if !args.measured.is_empty() {
        outln!("wrote {} (open bench.html)", args.out.display());
        return Ok(());
    }
    if outcome.per_step > 1 {
        outln!(
            "output rate {:.1} Hz: {} samples per step of {:.3e} s, {} sub-steps each",
            outcome.output_rate_hz,
            outcome.per_step,
            2.0 * PI / args.omega / args.steps_per_cycle as f64,
            outcome.substeps
        );
    }
    outln!("wrote {} (open bench.html)", args.out.display());
    Ok(())
}

/// Metres per second in `unit` (the sweep's table; the job refuses an unknown unit first).
fn velocity_factor(unit: &str) -> f64 {
    match unit {
        "m/s" => 1.0,
        "ft/s" => 0.3048,
        _ => IN_TO_M,
    }
}

fn print_table(
    model: DamperModel,
    runs: &[HarmonicRun],
    args: &BenchArgs,
    factor: f64,
    opts: IntegratorOptions,
) {
    outln!(
        "{} model, omega {} rad/s, {} cycles x {} steps, {:?} x {} substeps; over the last cycle",
        model.name(),
        args.omega,
        args.cycles,
        args.steps_per_cycle,
        opts.scheme,
        opts.substeps
    );
    outln!(
        "{:>10} {:>9} {:>8} {:>10} {:>10} {:>9} {:>9} {:>11} {:>11} {:>9}",
        format!("v [{}]", args.velocity_unit),
        "v [m/s]",
        "A [mm]",
        "F+ [N]",
        "F- [N]",
        "F+ [lb]",
        "F- [lb]",
        "K' [N/m]",
        "K'' [N/m]",
        "E [J]"
    );
    for r in runs {
        outln!(
            "{:>10.3} {:>9.5} {:>8.3} {:>10.1} {:>10.1} {:>9.1} {:>9.1} {:>11.4e} {:>11.4e} {:>9.3}",
            r.peak_velocity_m_s / factor,
            r.peak_velocity_m_s,
            r.amplitude_m * 1e3,
            r.peak_force_pos_n,
            r.peak_force_neg_n,
            r.peak_force_pos_n / LB_TO_N,
            r.peak_force_neg_n / LB_TO_N,
            r.storage_stiffness_n_per_m,
            r.loss_stiffness_n_per_m,
            r.dissipated_last_cycle_j
        );
    }
}
