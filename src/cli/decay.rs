//! `rotorsim decay --rotor DECK`: free decay of a hinged blade's lag hinge beside its
//! linearised mode (pipeline: src/run/decay.rs).
use crate::io::OutDir;
use crate::run::decay::{run_decay, DecayRunOptions};
use crate::solver::NewtonMethod;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct DecayArgs {
    /// Hinged-blade rotor deck (docs/rotor_deck.md, "Hinged-blade decks").
    #[arg(long)]
    pub rotor: PathBuf,
    /// Shaft speed [rad/s] (default: the deck's `[rotor] omega_rad_s`).
    #[arg(long, conflicts_with = "rpm")]
    pub speed_rad_s: Option<f64>,
    /// Shaft speed in rpm instead of --speed-rad-s.
    #[arg(long)]
    pub rpm: Option<f64>,
    /// Time step [s].
    #[arg(long, default_value_t = 0.005)]
    pub step_s: f64,
    /// Simulated time [s]; the decay is analysed from 1 s on.
    #[arg(long, default_value_t = 6.0)]
    pub duration_s: f64,
    /// Frame of the state: `rotating` (turning with the shaft, hub clamped) or `inertial`
    /// (hub driven).
    #[arg(long, default_value = "rotating", value_parser = ["rotating", "inertial"])]
    pub frame: String,
    /// Newton method: `modified` (stored factorization) or `full`.
    #[arg(long, default_value = "modified", value_parser = ["modified", "full"])]
    pub newton: String,
    /// Spectral radius at infinite frequency of the generalized-alpha integrator, in [0, 1]
    /// (1: no numerical damping; lower damps the elastic modes the release excites sooner).
    #[arg(long, default_value_t = 0.9, allow_negative_numbers = true)]
    pub rho_inf: f64,
    /// Newton tolerance, relative to the residual of the zero-acceleration predictor, in (0, 1)
    /// (docs/validation_tm4760.md, "Integrator settings and their cost").
    #[arg(long, default_value_t = 1e-8)]
    pub newton_rtol: f64,
    /// Newton correction tolerance, relative to the model's size, in (0, 1): a step also ends
    /// once its largest correction is below it and the residual at its round-off floor.
    #[arg(long, default_value_t = 1e-9)]
    pub newton_xtol: f64,
    /// Skip the linearised lag mode (its static solve and eigen analysis, more than half of a
    /// 2000-step run): decay_summary.csv then has the decay's estimates only.
    #[arg(long)]
    pub no_modal: bool,
    /// Output directory (decay.csv, decay_summary.csv).
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: DecayArgs) -> anyhow::Result<()> {
    let text = std::fs::read_to_string(&args.rotor)
        .map_err(|e| anyhow::anyhow!("--rotor {}: {e}", args.rotor.display()))?;
    if !crate::rotor::hinged::is_hinged(&text) {
        anyhow::bail!(
            "--rotor {}: not a hinged-blade deck (expected [[hinge]] tables and a [blade] with \
             segments, docs/rotor_deck.md)",
            args.rotor.display()
        );
    }
    let opts = DecayRunOptions {
        omega_rad_s: args
            .speed_rad_s
            .or(args.rpm.map(|r| r * std::f64::consts::PI / 30.0)),
        time_step_s: args.step_s,
        duration_s: args.duration_s,
        rotating_frame: args.frame == "rotating",
        newton: if args.newton == "full" {
            NewtonMethod::Full
        } else {
            NewtonMethod::Modified
        },
        rho_inf: args.rho_inf,
        newton_rtol: args.newton_rtol,
        newton_xtol: args.newton_xtol,
        modal: !args.no_modal,
        ..Default::default()
    };
    for (flag, v) in [("--speed-rad-s", args.speed_rad_s), ("--rpm", args.rpm)] {
        if let Some(r) = v.filter(|r| !(r.is_finite() && *r > 0.0)) {
            anyhow::bail!("{flag}: expected a positive number, got {r}");
        }
    }
    opts.validate(|k| {
        match k {
            "time_step" => "--step-s",
            "duration" => "--duration-s",
            "rho_inf" => "--rho-inf",
            "newton_rtol" => "--newton-rtol",
            "newton_xtol" => "--newton-xtol",
            _ if args.rpm.is_some() => "--rpm",
            _ => "--speed-rad-s",
        }
        .to_string()
    })?;
    let out = OutDir::create(&args.out, std::slice::from_ref(&args.rotor))?;
    let r = match run_decay(&args.rotor, &opts) {
        Ok(r) => r,
        Err(e) => {
            out.mark_incomplete(&e.to_string())?;
            return Err(e);
        }
    };
    out.write("decay.csv", r.history_csv().as_bytes())?;
    out.write("decay_summary.csv", r.summary_csv().as_bytes())?;
    out.finish()?;
    let n = r.lag_rad.len();
    outln!(
        "{:.2} rpm, h = {} s, {} steps ({} frame, {} Newton, rho_inf {}, rtol {:e}, xtol {:e}): {:.3} \
         iterations and {:.4} factorizations per step",
        r.omega_rad_s * 30.0 / std::f64::consts::PI,
        opts.time_step_s,
        n,
        args.frame,
        args.newton,
        opts.rho_inf,
        opts.newton_rtol,
        opts.newton_xtol,
        r.newton_iterations as f64 / n as f64,
        r.factorizations as f64 / n as f64
    );
    let show = |name: &str, v: Option<(f64, f64)>| match v {
        Some((f, z)) => outln!("{name:<18} {f:>10.5} Hz  damping ratio {z:.5}"),
        None => outln!("{name:<18} not found (too few peaks after 1 s)"),
    };
    if let Some(m) = r.modal {
        show("linearised modal", Some(m));
    }
    show("damped-sine fit", r.fit);
    show("log decrement", r.log_decrement);
    outln!("wrote {}", args.out.display());
    Ok(())
}
