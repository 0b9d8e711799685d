//! `rotorsim modes`: natural frequencies and mode shapes of a model deck, about the
//! static equilibrium, optionally in a frame rotating at each of `[modes] speeds_rad_s` (fan).
//! `rotorsim modes --rotor DECK --speed-fractions 0:1.2:0.1`: fan plot of a rotor deck with
//! the digitized UH-60A reference over it (src/rotor/fan.rs). The run is the library's
//! [`ModesJob`](crate::checks::modes::ModesJob) (src/checks/modes.rs), read from its
//! [`ModesSettings`]; this file parses and prints.
use crate::checks::modes::{ModesAnalysis, ModesSettings, SpeedModes};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ModesArgs {
    #[command(flatten)]
    pub settings: ModesSettings,
    /// Output directory (modes.csv, mode_shapes.csv, fan.csv).
    #[arg(long)]
    pub out: PathBuf,
}

/// A model deck's modes at one speed, as they are found.
fn print_speed(at: &SpeedModes) {
    outln!("Omega = {} rad/s", at.omega_rad_s);
    for (i, m) in at.modes.iter().enumerate() {
        outln!(
            "  mode {:>2}: {:>12.6} Hz  {:<8} damping {:.2e}",
            i + 1,
            m.freq_hz,
            m.kind.as_str(),
            m.damping_ratio
        );
    }
}

pub fn run(args: ModesArgs) -> anyhow::Result<()> {
    let model_deck = args.settings.rotor.is_none();
    let outcome = args.settings.job(&args.out)?.execute(&mut |at| {
        if model_deck {
            print_speed(at)
        }
    })?;
    let path = outcome.deck.display();
    match outcome.analysis {
        ModesAnalysis::Model => return Ok(()),
        ModesAnalysis::Rotor => {
            outln!("rotor {path}: damper as lag-hinge spring/damper (stroke = arm x lag)");
            outln!(
                "{:>6} {:>9} {:>10} {:>10} {:>8}",
                "x",
                "mode",
                "model_Hz",
                "ref_Hz",
                "err_%"
            );
            for c in outcome.comparison.iter().flatten() {
                outln!(
                    "{:>6.2} {:>9} {:>10.4} {:>10.4} {:>8.2}",
                    c.speed,
                    c.mode,
                    c.model_hz,
                    c.reference_hz,
                    c.error_pct
                );
            }
        }
        ModesAnalysis::Hinged { rpm_nominal } => {
            outln!("hinged-blade rotor {path}: {rpm_nominal} rpm nominal");
            if let Some(cmp) = &outcome.comparison {
                outln!(
                    "{:>6} {:>10} {:>10} {:>10} {:>8}",
                    "rpm",
                    "mode",
                    "model_Hz",
                    "ref_Hz",
                    "err_%"
                );
                for c in cmp {
                    outln!(
                        "{:>6.0} {:>10} {:>10.4} {:>10.2} {:>8.2}",
                        c.speed,
                        c.mode,
                        c.model_hz,
                        c.reference_hz,
                        c.error_pct
                    );
                }
            }
        }
    }
    outln!("wrote {}", args.out.display());
    Ok(())
}
