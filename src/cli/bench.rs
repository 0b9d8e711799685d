//! `rotorsim bench`: harmonic sweeps of a damper deck (paper Figs. 13-14) and replay
//! of measured bench tests.
//! The outputs are built by [`crate::run::bench`]; this file checks the arguments and prints.
use crate::hydraulics::bench::{HarmonicRun, SweepOptions, IN_TO_M, LB_TO_N};
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};
use crate::run::bench::{self as pipeline, Config};
use anyhow::bail;
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

fn velocity_factor(unit: &str) -> anyhow::Result<f64> {
    Ok(match unit {
        "in/s" => IN_TO_M,
        "m/s" => 1.0,
        "ft/s" => 0.3048,
        _ => bail!("unknown --velocity-unit '{unit}' (expected in/s, m/s or ft/s)"),
    })
}

pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let deck = DamperDeck::from_file(&args.deck)?;
    let scheme: Scheme = args
        .integrator
        .parse()
        .map_err(|e| anyhow::anyhow!("--integrator {}: {e}", args.integrator))?;
    if args.substeps == 0 || args.steps_per_cycle < 4 || args.cycles == 0 {
        bail!("--substeps and --cycles must be >= 1 and --steps-per-cycle >= 4");
    }
    let replaying = !args.measured.is_empty();
    if replaying && args.output_rate.is_some() {
        bail!("--output-rate applies to the harmonic sweep; a replay (--measured) samples at the measurement's own instants");
    }
    if !replaying && args.skip_cycles > 0 {
        bail!("--skip-cycles applies to a replay (--measured); the harmonic sweep's peaks and loops are over its last cycle (--cycles)");
    }
    if !(args.omega > 0.0 && args.omega.is_finite()) {
        bail!(
            "--omega must be a positive number of rad/s (got {})",
            args.omega
        );
    }
    // Output samples per step (the harmonic sweep only).
    let step_rate = args.omega * args.steps_per_cycle as f64 / (2.0 * PI);
    let per_step = match args.output_rate {
        None => 1,
        Some(r) if !(r > 0.0 && r.is_finite()) => bail!(
            "--output-rate must be a positive number of samples per second (got {r})"
        ),
        Some(r) if r < 0.999 * step_rate => bail!(
            "--output-rate {r} Hz is below the step rate {step_rate:.1} Hz (--omega x --steps-per-cycle / 2 pi): the bench writes a sample at every step end at least"
        ),
        Some(r) => ((r / step_rate).round() as usize).max(1),
    };
    let substeps = args.substeps.div_ceil(per_step);
    // per amplitude and model: cycles x steps x pieces x sub-steps, every piece kept (5 columns)
    let samples = args.cycles as f64 * args.steps_per_cycle as f64 * per_step as f64;
    crate::solver::budget::substeps(samples * substeps as f64)
        .plus(crate::solver::budget::samples(samples, 5.0))
        .check(
            &format!(
                "{} cycles x {} steps x {} samples per step x {} sub-steps per amplitude",
                args.cycles, args.steps_per_cycle, per_step, substeps
            ),
            "check --cycles, --steps-per-cycle, --output-rate and --substeps",
        )?;
    let opts = IntegratorOptions { scheme, substeps };
    let models: Vec<DamperModel> = match args.damper.as_deref() {
        None => vec![deck.model],
        Some("all") => vec![
            DamperModel::Physical,
            DamperModel::Linear,
            DamperModel::Nonlinear,
        ],
        Some(s) => vec![s
            .parse()
            .map_err(|e| anyhow::anyhow!("--damper {s}: {e}"))?],
    };
    // Build every device first so that a deck error leaves no output at all.
    let devices = models
        .iter()
        .map(|&m| Ok((m, deck.build(m, opts)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    // A replay does not use the velocity unit: an unknown one is refused for the sweep only.
    let factor = velocity_factor(&args.velocity_unit);
    let cfg = Config {
        deck: args.deck.clone(),
        out: args.out.clone(),
        omega: args.omega,
        peak_velocity: args.peak_velocity.clone(),
        velocity_unit: args.velocity_unit.clone(),
        factor: factor.as_ref().map_or(1.0, |f| *f),
        cycles: args.cycles,
        steps_per_cycle: args.steps_per_cycle,
        per_step,
        opts,
        measured: args.measured.clone(),
        skip_cycles: args.skip_cycles,
    };
    if replaying {
        pipeline::replay(&cfg, &deck, &devices, &mut |line| outln!("{line}"))?;
        outln!("wrote {} (open bench.html)", args.out.display());
        return Ok(());
    }
    let factor = factor?;
    if args.peak_velocity.is_empty()
        || args
            .peak_velocity
            .iter()
            .any(|v| !(*v > 0.0 && v.is_finite()))
    {
        bail!(
            "--peak-velocity must be positive numbers (got {:?})",
            args.peak_velocity
        );
    }
    let sweep = SweepOptions {
        omega_rad_s: args.omega,
        peak_velocities_m_s: args.peak_velocity.iter().map(|v| v * factor).collect(),
        cycles: args.cycles,
        steps_per_cycle: args.steps_per_cycle,
    };
    let names: Vec<String> = sweep
        .peak_velocities_m_s
        .iter()
        .map(|&v| pipeline::history_name(v))
        .collect();
    for (i, a) in names.iter().enumerate() {
        if let Some(j) = names[..i].iter().position(|b| b == a) {
            bail!(
                "--peak-velocity {} and {} {} name the same history file {a} (peak velocities are told apart to 1 um/s)",
                args.peak_velocity[j],
                args.peak_velocity[i],
                args.velocity_unit
            );
        }
    }
    pipeline::sweep(&cfg, &deck, &devices, &mut |model, runs| {
        print_table(model, runs, &args, factor, opts)
    })?;
    let rate = step_rate * per_step as f64;
    if per_step > 1 {
        outln!(
            "output rate {rate:.1} Hz: {per_step} samples per step of {:.3e} s, {substeps} sub-steps each",
            2.0 * PI / args.omega / args.steps_per_cycle as f64
        );
    }
    outln!("wrote {} (open bench.html)", args.out.display());
    Ok(())
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
