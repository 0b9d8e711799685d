//! `rotorsim stability --rotor DECK --speeds A:B:STEP --out DIR`: ground resonance of a rotor
//! deck on its airframe over rotor speeds. The run is the library's
//! [`StabilityJob`](crate::resonance::StabilityJob) (src/resonance/mod.rs), read from its
//! [`StabilitySettings`]; this file parses and prints.
use crate::resonance::{StabilityOutcome, StabilitySettings};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StabilityArgs {
    #[command(flatten)]
    pub settings: StabilitySettings,
    /// Output directory (stability.csv, stability.html, summary.json).
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(args: StabilityArgs) -> anyhow::Result<()> {
    let job = args.settings.job(&args.out)?;
    let StabilityOutcome {
        map,
        model,
        speeds,
        time,
        amplitude: amp,
    } = job.execute(&mut |line| outln!("{line}"))?;
    if let Some(c) = &amp {
        outln!("amplitude check: {}", c.headline);
        outln!("amplitude check in full: {}", c.statement);
    }
    for c in &time {
        outln!(
            "whole rotor at {} rad/s: growth rate {:+.5} 1/s, {:.4} Hz (airframe x after a {} m/s kick){}",
            c.omega_rad_s,
            c.growth_rate_per_s,
            c.frequency_hz,
            c.kick_m_s,
            if c.growth_rate_per_s > 0.0 { ": UNSTABLE" } else { "" }
        );
    }
    let method = map.speeds.first().map_or("", |s| s.method.name());
    outln!(
        "rotorsim stability: {}{} ({} damper, {method}), {} speeds from {} to {} rad/s",
        job.rotor.display(),
        if args.settings.hover { ", hover" } else { "" },
        model.name(),
        map.speeds.len(),
        speeds[0],
        speeds[speeds.len() - 1]
    );
    if map.unstable.is_empty() {
        if let Some((z, mode, w)) = map.min_damping() {
            outln!("stable: least damping ratio {z:.4} ({mode} at {w} rad/s)");
        }
    } else {
        for u in &map.unstable {
            outln!(
                "linear map: {} grows {}",
                u.mode,
                crate::resonance::range_text(&map, u)
            );
        }
    }
    for v in &map.verdicts {
        outln!("{}", v.line());
    }
    for n in &map.notes {
        outln!("note: {n}");
    }
    outln!(
        "open: {}/stability.html (Coleman diagram, damping), {}/stability.csv",
        args.out.display(),
        args.out.display()
    );
    Ok(())
}
