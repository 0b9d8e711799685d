//! `rotorsim modes`: natural frequencies and mode shapes of a model deck, about the
//! static equilibrium, optionally in a frame rotating at each of `[modes] speeds_rad_s` (fan).
//! `rotorsim modes --rotor DECK --speed-fractions 0:1.2:0.1`: fan plot of a rotor deck with
//! the digitized UH-60A reference over it (src/rotor/fan.rs). The run is the library's
//! [`ModesJob`] (src/run/modes.rs); this file turns the options into one and prints.
use crate::run::modes::{ModesAnalysis, ModesJob, SpeedModes};
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ModesArgs {
    /// Model deck (TOML, see docs/model_deck.md); or give --rotor.
    #[arg(required_unless_present = "rotor", conflicts_with = "rotor")]
    pub deck: Option<PathBuf>,
    /// Rotor deck (docs/rotor_deck.md): fan plot over the speeds of --speeds or
    /// --speed-fractions.
    #[arg(long)]
    pub rotor: Option<PathBuf>,
    /// Rotor speeds [rad/s], START:STOP:STEP (inclusive) or a comma-separated list.
    #[arg(long, conflicts_with = "speed_fractions")]
    pub speeds: Option<String>,
    /// Rotor speeds as fractions of the deck's nominal speed (rotor.omega_rad_s) instead of
    /// --speeds, START:STOP:STEP (inclusive) or a comma-separated list.
    #[arg(long, default_value = crate::run::modes::DEFAULT_SPEEDS)]
    pub speed_fractions: String,
    /// Digitized reference fan plot drawn over the model's (default: the UH-60A fan plot of
    /// ../shared/data/uh60a/raw/ next to the source tree, when present).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Modes per speed (rotor decks).
    #[arg(long, default_value_t = crate::run::modes::DEFAULT_COUNT)]
    pub count: usize,
    /// Output directory (modes.csv, mode_shapes.csv, fan.csv).
    #[arg(long)]
    pub out: PathBuf,
}

impl ModesArgs {
    /// The modes run these options ask for.
    pub fn job(&self) -> ModesJob {
        ModesJob {
            deck: self.deck.clone(),
            rotor: self.rotor.clone(),
            speeds: self.speed_fractions.clone(),
            speeds_rad_s: self.speeds.clone(),
            reference: self.reference.clone(),
            count: self.count,
            out: self.out.clone(),
        }
    }
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
    let model_deck = args.rotor.is_none();
    let outcome = args.job().execute(&mut |at| {
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
