//! `rotorsim stability --rotor DECK --speeds A:B:STEP --out DIR`: ground resonance of a rotor
//! deck on its airframe over rotor speeds (pipeline: src/run/stability.rs).
use crate::hydraulics::DamperModel;
use crate::io::OutDir;
use crate::overrides::Override;
use crate::rotor::RotorDeck;
use crate::run::stability::stability_map;
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

pub fn run(args: StabilityArgs) -> anyhow::Result<()> {
    let speeds = crate::run::stability::parse_speeds("--speeds", &args.speeds)?;
    let deck = RotorDeck::from_file_with(&args.rotor, &args.set)?;
    let model = match &args.damper {
        Some(d) => d
            .parse::<DamperModel>()
            .map_err(|e| anyhow::anyhow!("--damper {d}: {e}"))?,
        None => deck.damper()?.model,
    };
    // --time: read and sized before the result folder exists
    let time_opts = crate::run::stability::TimeOptions {
        kick_m_s: args.kick_m_s,
        duration_s: args.time_duration_s,
        fit_from_s: args.time_duration_s * 7.0 / 20.0,
        steps_per_rev: args.steps_per_rev,
    };
    let mut time_speeds: Vec<f64> = vec![];
    if let Some(t) = &args.time {
        time_speeds = crate::run::stability::parse_speeds("--time", t)?;
        for &w in &time_speeds {
            time_opts.check(w)?;
        }
    }
    // --amplitudes-m: read and checked before the result folder exists
    let amplitude = match &args.amplitudes_m {
        None => {
            if args.amplitude_at_rad_s.is_some() {
                anyhow::bail!("--amplitude-at-rad-s needs --amplitudes-m (the amplitudes to start from, or `default`)");
            }
            None
        }
        Some(a) => {
            let amplitudes_m = if a.trim() == "default" {
                crate::run::amplitude::DEFAULT_AMPLITUDES_M.to_vec()
            } else {
                crate::run::ranges::parse_range(
                    "--amplitudes-m",
                    a,
                    "expected stroke amplitudes in m, e.g. 1e-4,1e-3,1e-2, or `default`",
                    crate::run::amplitude::MAX_AMPLITUDES,
                    "an amplitude check may have",
                )?
            };
            let w = args
                .amplitude_at_rad_s
                .unwrap_or(deck.spec.rotor.omega_rad_s);
            if !(w.is_finite() && w > 0.0) {
                anyhow::bail!("--amplitude-at-rad-s {w}: expected a positive rotor speed in rad/s");
            }
            crate::run::amplitude::check_amplitudes(
                &amplitudes_m,
                deck.spec.damper_attachment.arm_m,
            )?;
            Some((w, amplitudes_m))
        }
    };
    let hover = crate::run::air_resonance::HoverOptions {
        collective_deg: args.collective_deg,
        density_kg_m3: args.density_kg_m3,
        speed_of_sound_m_s: args.speed_of_sound_m_s,
        strips: args.strips,
    };
    if args.hover {
        hover.check()?;
        if args.time.is_some() {
            anyhow::bail!("--hover: the whole rotor's time domain (--time) is for ground resonance; run it without --hover (the amplitude check, --amplitudes-m, runs in hover)");
        }
    }
    let out = OutDir::create(&args.out, &deck.input_files())?;
    let result = if args.hover {
        crate::run::air_resonance::air_resonance_map(&deck, model, &speeds, &hover)
    } else {
        stability_map(&deck, model, &speeds)
    };
    let map = match result {
        Ok(mut m) => {
            m.overrides = args
                .set
                .iter()
                .map(|o| (o.key.clone(), o.value_text()))
                .collect();
            m
        }
        Err(e) => {
            out.mark_incomplete(&format!("{e:#}"))?;
            return Err(e);
        }
    };
    let mut time = vec![];
    for &w in &time_speeds {
        outln!(
            "time domain at {w} rad/s ({} s of motion)...",
            args.time_duration_s
        );
        match crate::run::stability::time_check(&args.rotor, &args.set, model, w, &time_opts) {
            Ok(c) => time.push(c),
            Err(e) => {
                out.mark_incomplete(&format!("{e:#}"))?;
                return Err(e.context(format!("time domain at {w} rad/s")));
            }
        }
    }
    let amp = match amplitude {
        None => None,
        Some((w, amplitudes_m)) => {
            outln!(
                "amplitude check at {w} rad/s ({} starts, {} damper)...",
                amplitudes_m.len(),
                model.name()
            );
            let opts = crate::run::amplitude::AmplitudeOptions {
                amplitudes_m,
                hover: args.hover.then_some(hover),
                ..Default::default()
            };
            match crate::run::amplitude::amplitude_check(&deck, model, w, &opts) {
                Ok(c) => Some(c),
                Err(e) => {
                    out.mark_incomplete(&format!("{e:#}"))?;
                    return Err(e.context(format!("amplitude check at {w} rad/s")));
                }
            }
        }
    };
    crate::run::stability::write_all(&map, &time, amp.as_ref(), &deck, &out)?;
    out.finish()?;
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
