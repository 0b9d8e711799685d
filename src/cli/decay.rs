//! `rotorsim decay --rotor DECK`: free decay of a hinged blade's lag hinge beside its
//! linearised mode. The run is the library's [`DecayJob`](crate::checks::decay::DecayJob)
//! (src/checks/decay.rs), read from its [`DecaySettings`]; this file parses and prints.
use crate::checks::decay::DecaySettings;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct DecayArgs {
    #[command(flatten)]
    pub settings: DecaySettings,
    /// Output directory (decay.csv, decay_summary.csv).
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: DecayArgs) -> anyhow::Result<()> {
    let job = args.settings.job(&args.out)?;
    let r = job.execute()?;
    let opts = &job.options;
    let n = r.lag_rad.len();
    outln!(
        "{:.2} rpm, h = {} s, {} steps ({} frame, {} Newton, rho_inf {}, rtol {:e}, xtol {:e}): {:.3} \
         iterations and {:.4} factorizations per step",
        r.omega_rad_s * 30.0 / std::f64::consts::PI,
        opts.time_step_s,
        n,
        args.settings.frame,
        args.settings.newton,
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
