//! `rotorsim bench`: harmonic sweeps of a damper deck (paper Figs. 13-14) and replay
//! of measured bench tests.
use crate::hydraulics::bench::{self, HarmonicRun, History, SweepOptions, IN_TO_M, LB_TO_N};
use crate::hydraulics::{DamperDeck, DamperModel, Device, IntegratorOptions, Scheme};
use crate::io::{csv_from_columns, OutDir};
use crate::report::plot::{stacked_svg, Plot};
use anyhow::{bail, Context};
use clap::Args;
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
    /// Measured bench test(s) to replay instead of the harmonic sweep (bench CSV, docs/formats.md).
    #[arg(long)]
    pub measured: Vec<PathBuf>,
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
    // per amplitude and model: cycles x steps x sub-steps, every step kept (5 columns)
    let steps = args.cycles as f64 * args.steps_per_cycle as f64;
    crate::solver::budget::substeps(steps * args.substeps as f64)
        .plus(crate::solver::budget::samples(steps, 5.0))
        .check(
            &format!(
                "{} cycles x {} steps x {} sub-steps per amplitude",
                args.cycles, args.steps_per_cycle, args.substeps
            ),
            "check --cycles, --steps-per-cycle and --substeps",
        )?;
    let opts = IntegratorOptions {
        scheme,
        substeps: args.substeps,
    };
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
    if !args.measured.is_empty() {
        return run_replay(&args, &devices);
    }
    let factor = velocity_factor(&args.velocity_unit)?;
    if !(args.omega > 0.0 && args.omega.is_finite()) {
        bail!(
            "--omega must be a positive number of rad/s (got {})",
            args.omega
        );
    }
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
    let out = OutDir::create(&args.out, std::slice::from_ref(&args.deck))?;
    let mut all = Vec::new();
    for (model, dev) in &devices {
        let mut runs = Vec::with_capacity(sweep.peak_velocities_m_s.len());
        for &v in &sweep.peak_velocities_m_s {
            let r = bench::harmonic_run(
                dev.as_ref(),
                sweep.omega_rad_s,
                v,
                sweep.cycles,
                sweep.steps_per_cycle,
                true,
            );
            runs.push(r.map_err(|e| {
                let msg = format!(
                    "{} model at peak velocity {} {} ({v} m/s): {e}",
                    model.name(),
                    v / factor,
                    args.velocity_unit
                );
                let _ = out.mark_incomplete(&msg);
                anyhow::anyhow!(msg)
            })?);
        }
        let sub = if devices.len() > 1 {
            format!("{}/", model.name())
        } else {
            String::new()
        };
        write_sweep(&out, &sub, &deck, *model, &runs, &args, factor)?;
        print_table(*model, &runs, &args, factor, opts);
        all.push((*model, runs));
    }
    // Peak force vs peak velocity (paper Fig. 13).
    let cap = 3200.0 * LB_TO_N;
    let vmax = args.peak_velocity.iter().cloned().fold(0.0, f64::max);
    let mut p = Plot::new(
        &format!(
            "Peak force vs peak velocity (cf. paper Fig. 13), omega = {} rad/s ({})",
            args.omega, deck.source
        ),
        &format!("peak velocity [{}]", args.velocity_unit),
        "peak force [N]",
    );
    for (model, runs) in &all {
        let x: Vec<f64> = runs.iter().map(|r| r.peak_velocity_m_s / factor).collect();
        let pos: Vec<f64> = runs.iter().map(|r| r.peak_force_pos_n).collect();
        let neg: Vec<f64> = runs.iter().map(|r| -r.peak_force_neg_n).collect();
        p = p.line(&format!("{} +peak", model.name()), &x, &pos).dashed(
            &format!("{} -peak (magnitude)", model.name()),
            &x,
            &neg,
        );
    }
    p = p.dashed(
        "paper: relief cap 3200 lb (Fig. 16)",
        &[0.0, vmax],
        &[cap, cap],
    );
    out.write("peak_force_vs_velocity.svg", p.to_svg(800, 480)?.as_bytes())?;
    out.finish()?;
    outln!("wrote {}", args.out.display());
    Ok(())
}

fn history_csv(h: &History) -> String {
    let mut header = vec!["time_s", "stroke_m", "velocity_m_s", "force_N"];
    let mut cols: Vec<&[f64]> = vec![&h.time_s, &h.stroke_m, &h.velocity_m_s, &h.force_n];
    push_device_channels(h, &mut header, &mut cols);
    csv_from_columns(&header, &cols)
}

/// The device's channels after the bench's own, except those the bench already wrote (a
/// dashpot's only channel is the stroke rate, `velocity_m_s`): no column twice.
fn push_device_channels<'a>(h: &'a History, header: &mut Vec<&'a str>, cols: &mut Vec<&'a [f64]>) {
    for (n, c) in h.channel_names.iter().zip(&h.channels) {
        if !header.contains(n) {
            header.push(n);
            cols.push(c);
        }
    }
}

fn channel<'a>(h: &'a History, name: &str) -> Option<&'a [f64]> {
    h.channel_names
        .iter()
        .position(|n| *n == name)
        .map(|i| h.channels[i].as_slice())
}

fn write_sweep(
    out: &OutDir,
    sub: &str,
    deck: &DamperDeck,
    model: DamperModel,
    runs: &[HarmonicRun],
    args: &BenchArgs,
    factor: f64,
) -> anyhow::Result<()> {
    let rows: Vec<[f64; 3]> = runs
        .iter()
        .map(|r| [r.peak_velocity_m_s, r.peak_force_pos_n, r.peak_force_neg_n])
        .collect();
    out.write(
        &format!("{sub}peaks.csv"),
        crate::io::csv_string(
            &["peak_velocity_m_s", "peak_force_pos_N", "peak_force_neg_N"],
            &rows,
        )
        .as_bytes(),
    )?;
    for (k, r) in runs.iter().enumerate() {
        out.write(
            &format!("{sub}history_{k}.csv"),
            history_csv(&r.history).as_bytes(),
        )?;
    }
    // Time history at the amplitude closest to 2 in/s (paper Fig. 14), last two cycles.
    let target = 2.0 * IN_TO_M;
    let (k, r) = runs
        .iter()
        .enumerate()
        .min_by(|a, b| {
            (a.1.peak_velocity_m_s - target)
                .abs()
                .total_cmp(&(b.1.peak_velocity_m_s - target).abs())
        })
        .context("no runs")?;
    let h = &r.history;
    let from = h.time_s.len().saturating_sub(2 * args.steps_per_cycle + 1);
    let t = &h.time_s[from..];
    let title = format!(
        "{} model, peak velocity {} {} (cf. paper Fig. 14; history_{k}.csv), {}",
        model.name(),
        r.peak_velocity_m_s / factor,
        args.velocity_unit,
        deck.source
    );
    let mut plots =
        vec![Plot::new(&title, "time [s]", "force [N]").line("force", t, &h.force_n[from..])];
    if let (Some(p0), Some(p1)) = (channel(h, "p0_Pa"), channel(h, "p1_Pa")) {
        plots.push(
            Plot::new("chamber pressures", "time [s]", "pressure [Pa]")
                .line("p0", t, &p0[from..])
                .line("p1", t, &p1[from..]),
        );
    }
    if let (Some(x0), Some(x1)) = (channel(h, "x_valve0_m"), channel(h, "x_valve1_m")) {
        plots.push(
            Plot::new("relief valve lifts", "time [s]", "lift [m]")
                .line("valve 0", t, &x0[from..])
                .line("valve 1", t, &x1[from..]),
        );
    }
    let sv: Vec<f64> = h.stroke_m[from..].to_vec();
    plots.push(Plot::new("stroke", "time [s]", "stroke [m]").line("stroke", t, &sv));
    out.write(
        &format!("{sub}time_history.svg"),
        stacked_svg(&plots, 800, 300)?.as_bytes(),
    )?;
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
        "{} model, omega {} rad/s, {} cycles x {} steps, {:?} x {} substeps; peaks over the last cycle",
        model.name(),
        args.omega,
        args.cycles,
        args.steps_per_cycle,
        opts.scheme,
        opts.substeps
    );
    outln!(
        "{:>12} {:>12} {:>14} {:>14} {:>12} {:>12}",
        format!("v [{}]", args.velocity_unit),
        "v [m/s]",
        "F+ [N]",
        "F- [N]",
        "F+ [lb]",
        "F- [lb]"
    );
    for r in runs {
        outln!(
            "{:>12.3} {:>12.5} {:>14.1} {:>14.1} {:>12.1} {:>12.1}",
            r.peak_velocity_m_s / factor,
            r.peak_velocity_m_s,
            r.peak_force_pos_n,
            r.peak_force_neg_n,
            r.peak_force_pos_n / LB_TO_N,
            r.peak_force_neg_n / LB_TO_N
        );
    }
}

fn run_replay(args: &BenchArgs, devices: &[(DamperModel, Box<dyn Device>)]) -> anyhow::Result<()> {
    // Read every test before creating any output.
    let tests = args
        .measured
        .iter()
        .map(|p| bench::read_bench_csv(p))
        .collect::<Result<Vec<_>, _>>()?;
    let inputs: Vec<PathBuf> = std::iter::once(args.deck.clone())
        .chain(args.measured.iter().cloned())
        .collect();
    let out = OutDir::create(&args.out, &inputs)?;
    let mut summary = String::from("test,model,samples,rms_error_N\n");
    for (model, dev) in devices {
        for test in &tests {
            let r = bench::replay(dev.as_ref(), test).map_err(|e| {
                let _ = out.mark_incomplete(&format!("replay of {} failed: {e}", test.name));
                anyhow::anyhow!(
                    "replay of {} with the {} model: {e}",
                    test.name,
                    model.name()
                )
            })?;
            let h = &r.history;
            let stem = format!("{}_{}", test.name, model.name());
            let mut header = vec!["time_s", "stroke_m", "velocity_m_s", "force_model_N"];
            let mut cols: Vec<&[f64]> = vec![&h.time_s, &h.stroke_m, &h.velocity_m_s, &h.force_n];
            if let Some(m) = &test.force_n {
                header.push("force_measured_N");
                cols.push(m);
            }
            push_device_channels(h, &mut header, &mut cols);
            out.write(
                &format!("replay_{stem}.csv"),
                csv_from_columns(&header, &cols).as_bytes(),
            )?;
            let mut p = Plot::new(
                &format!(
                    "{}: force vs stroke, {} model over measurement",
                    test.name,
                    model.name()
                ),
                "stroke [m]",
                "force [N]",
            );
            if let Some(m) = &test.force_n {
                p = p.points("measured", &test.stroke_m, m);
            }
            p = p.line(&format!("{} model", model.name()), &h.stroke_m, &h.force_n);
            out.write(&format!("loop_{stem}.svg"), p.to_svg(800, 480)?.as_bytes())?;
            let rms = r.rms_error_n.map_or("".to_string(), |v| v.to_string());
            summary.push_str(&format!(
                "{},{},{},{}\n",
                test.name,
                model.name(),
                test.time_s.len(),
                rms
            ));
            match r.rms_error_n {
                Some(v) => outln!(
                    "{} ({} model): RMS error {:.1} N over {} samples",
                    test.name,
                    model.name(),
                    v,
                    test.time_s.len()
                ),
                None => outln!(
                    "{} ({} model): no measured force, model force written",
                    test.name,
                    model.name()
                ),
            }
        }
    }
    out.write("replay_summary.csv", summary.as_bytes())?;
    out.finish()?;
    outln!("wrote {}", args.out.display());
    Ok(())
}
