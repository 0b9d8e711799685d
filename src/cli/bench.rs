//! `rotorsim bench`: harmonic sweeps of a damper deck (paper Figs. 13-14) and replay
//! of measured bench tests.
//! The bench is the library's [`BenchJob`](crate::checks::bench::BenchJob) (checks and outputs,
//! src/checks/bench.rs), read from its [`BenchSettings`]; this file parses and prints.
use crate::checks::bench::{BenchSettings, ModelSweep, DEFAULT_STEPS_PER_CYCLE};
use crate::hydraulics::bench::{HarmonicRun, IN_TO_M, LB_TO_N, REFINE_TOLERANCE};
use crate::hydraulics::DamperModel;
use clap::Args;
use std::f64::consts::PI;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub settings: BenchSettings,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let job = args.settings.job(&args.out)?;
    let s = &args.settings;
    let factor = velocity_factor(&s.velocity_unit);
    let outcome = job.execute(
        &mut |model, runs, ms| print_table(model, runs, s, factor, ms),
        &mut |line| {
            if line.starts_with("WARNING") {
                errln!("{line}");
            } else {
                outln!("{line}");
            }
        },
    )?;
    if !s.measured.is_empty() {
        outln!("wrote {} (open bench.html)", args.out.display());
        return Ok(());
    }
    if outcome.per_step > 1 {
        outln!(
            "output rate {:.1} Hz: {} samples per step of {:.3e} s, {} sub-steps each",
            outcome.output_rate_hz,
            outcome.per_step,
            2.0 * PI / s.omega / s.steps_per_cycle.unwrap_or(DEFAULT_STEPS_PER_CYCLE) as f64,
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
    args: &BenchSettings,
    factor: f64,
    ms: &ModelSweep,
) {
    let steps = if ms.refined {
        format!(
            "steps per cycle from {DEFAULT_STEPS_PER_CYCLE} doubled until converged to {} %",
            100.0 * REFINE_TOLERANCE
        )
    } else {
        format!(
            "{} steps per cycle as asked",
            args.steps_per_cycle.unwrap_or(DEFAULT_STEPS_PER_CYCLE)
        )
    };
    outln!(
        "{} model, omega {} rad/s, {} cycles, {steps}, {:?} x {} substeps; over the last cycle; err: estimated discretisation error (largest over the outputs, of scale)",
        model.name(),
        args.omega,
        args.cycles,
        ms.opts.scheme,
        ms.opts.substeps
    );
    outln!(
        "{:>10} {:>9} {:>8} {:>10} {:>10} {:>9} {:>9} {:>11} {:>11} {:>9} {:>6} {:>8} {}",
        format!("v [{}]", args.velocity_unit),
        "v [m/s]",
        "A [mm]",
        "F+ [N]",
        "F- [N]",
        "F+ [lb]",
        "F- [lb]",
        "K' [N/m]",
        "K'' [N/m]",
        "E [J]",
        "steps",
        "err [%]",
        "status"
    );
    for (r, e) in runs.iter().zip(&ms.estimates) {
        outln!(
            "{:>10.3} {:>9.5} {:>8.3} {:>10.1} {:>10.1} {:>9.1} {:>9.1} {:>11.4e} {:>11.4e} {:>9.3} {:>6} {:>8} {}",
            r.peak_velocity_m_s / factor,
            r.peak_velocity_m_s,
            r.amplitude_m * 1e3,
            r.peak_force_pos_n,
            r.peak_force_neg_n,
            r.peak_force_pos_n / LB_TO_N,
            r.peak_force_neg_n / LB_TO_N,
            r.storage_stiffness_n_per_m,
            r.loss_stiffness_n_per_m,
            r.dissipated_last_cycle_j,
            e.steps_per_cycle,
            if e.relative_error.is_nan() {
                "-".to_string()
            } else {
                format!("{:.3}", 100.0 * e.relative_error)
            },
            e.status.name()
        );
    }
}
