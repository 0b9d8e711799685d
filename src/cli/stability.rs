//! `rotorsim stability --rotor DECK --speeds A:B:STEP --out DIR`: ground resonance of a rotor
//! deck on its airframe over rotor speeds. The run is the library's [`StabilityJob`]
//! (src/run/stability.rs); this file turns the options into one and prints.
use crate::overrides::Override;
use crate::run::air_resonance::HoverOptions;
use crate::run::stability::{StabilityJob, StabilityOutcome, TimeOptions};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// Rotor deck with an `[airframe]` (docs/rotor_deck.md); per-blade differences
    /// (`[blades.K...]`, `--set blades.K...`) make the rotor anisotropic.
    #[arg(long)]
    pub rotor: PathBuf,
    /// Rotor speeds [rad/s]: START:STOP:STEP (inclusive) or a comma-separated list, increasing.
    #[arg(long)]
    pub speeds: String,
    /// Damper model linearised at each speed: linear, nonlinear or physical (default: the
    /// deck's `damper.model`).
    #[arg(long)]
    pub damper: Option<String>,
    /// Also march the whole multibody rotor on its airframe at these speeds [rad/s] (a list):
    /// kicked along x, its growth rate fitted (method `time` in stability.csv).
    #[arg(long)]
    pub time: Option<String>,
    /// Velocity of the time-domain kick along x [m/s].
    #[arg(long, default_value_t = 1e-4)]
    pub kick_m_s: f64,
    /// Simulated time of each time-domain run [s] (a growing one stops when the airframe
    /// moves 10 mm); the fit starts at 7/20 of it.
    #[arg(long, default_value_t = 20.0)]
    pub time_duration_s: f64,
    /// Structural steps per revolution of the time-domain runs (256 is up to 4.5% off in the
    /// growth rate near a coalescence, 512 within 1%).
    #[arg(long, default_value_t = 512)]
    pub steps_per_rev: usize,
    /// Nonlinear amplitude check: start the reduced rotor on its regressing lag mode at these
    /// damper stroke amplitudes [m] (an increasing list; `default` for 0.1 to 30 mm), each
    /// blade's damper a device with its valves live; growth rate against amplitude and the
    /// limit cycles (amplitude.csv).
    #[arg(long)]
    pub amplitudes_m: Option<String>,
    /// Rotor speed of the amplitude check [rad/s] (default: the deck's rotor.omega_rad_s).
    #[arg(long)]
    pub amplitude_at_rad_s: Option<f64>,
    /// Air resonance in hover instead of ground resonance: rigid blades that lag and flap,
    /// quasi-steady aerodynamics (the deck's `[aero]`), on the airframe's x, y, roll and pitch.
    #[arg(long)]
    pub hover: bool,
    /// Hover: blade pitch at 0.75 R [deg] (the deck's twist about it).
    #[arg(long, default_value_t = 8.0)]
    pub collective_deg: f64,
    /// Hover: air density [kg/m^3] (sea-level standard by default).
    #[arg(long, default_value_t = 1.225)]
    pub density_kg_m3: f64,
    /// Hover: speed of sound [m/s] (the aerofoil tables' Mach number).
    #[arg(long, default_value_t = 340.3)]
    pub speed_of_sound_m_s: f64,
    /// Hover: strips per blade from the hinge to the tip (mass and aerodynamics).
    #[arg(long, default_value_t = crate::run::air_resonance::DEFAULT_STRIPS)]
    pub strips: usize,
    /// Override a deck value by its dotted path before validation (repeatable), as for run.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_set)]
    pub set: Vec<Override>,
    /// Output directory (stability.csv, stability.html, summary.json).
    #[arg(long)]
    pub out: PathBuf,
}

fn parse_set(s: &str) -> Result<Override, String> {
    Override::parse(s).map_err(|e| format!("{e:#}"))
}

impl StabilityArgs {
    /// The stability run these options ask for.
    pub fn job(&self) -> StabilityJob {
        StabilityJob {
            rotor: self.rotor.clone(),
            speeds: self.speeds.clone(),
            damper: self.damper.clone(),
            time_speeds: self.time.clone(),
            time: TimeOptions {
                kick_m_s: self.kick_m_s,
                duration_s: self.time_duration_s,
                fit_from_s: self.time_duration_s * 7.0 / 20.0,
                steps_per_rev: self.steps_per_rev,
            },
            amplitudes_m: self.amplitudes_m.clone(),
            amplitude_at_rad_s: self.amplitude_at_rad_s,
            hover: self.hover,
            hover_options: HoverOptions {
                collective_deg: self.collective_deg,
                density_kg_m3: self.density_kg_m3,
                speed_of_sound_m_s: self.speed_of_sound_m_s,
                strips: self.strips,
            },
            set: self.set.clone(),
            out: self.out.clone(),
        }
    }
}

pub fn run(args: StabilityArgs) -> anyhow::Result<()> {
    let StabilityOutcome {
        map,
        model,
        speeds,
        time,
        amplitude: amp,
    } = args.job().execute(&mut |line| outln!("{line}"))?;
    if let Some(c) = &amp {
        outln!("amplitude check: {}", c.statement);
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
        args.rotor.display(),
        if args.hover { ", hover" } else { "" },
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
                "UNSTABLE: {} from {:.3} to {:.3} rad/s, growth rate up to {:.4} 1/s",
                u.mode,
                u.from_rad_s,
                u.to_rad_s,
                u.max_growth_rate_per_s
            );
        }
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
