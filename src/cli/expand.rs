//! `rotorsim expand --rotor DECK` (issue #6): print the multibody model deck generated from a
//! rotor deck (docs/rotor_deck.md -> docs/model_deck.md).
use crate::rotor::expand::{Controls, ExpandOptions};
use crate::rotor::RotorDeck;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExpandArgs {
    /// Rotor deck (TOML, see docs/rotor_deck.md).
    #[arg(long)]
    pub rotor: PathBuf,
    /// Flight record whose controls set the swashplate law (default: zero controls).
    #[arg(long)]
    pub flight: Option<PathBuf>,
    /// Revolutions covered by the swashplate displacement table.
    #[arg(long, default_value_t = 2)]
    pub revs: usize,
}

pub fn run(args: ExpandArgs) -> anyhow::Result<()> {
    let deck = RotorDeck::from_file(&args.rotor)?;
    // the [damper] table must be readable too (it is part of the rotor)
    let damper = deck.damper()?;
    let controls = match &args.flight {
        Some(p) => Controls::from_record(&crate::flight::FlightRecord::read(p)?.meta.controls_deg),
        None => Controls::default(),
    };
    let note = format!(
        "Damper ({} model by default, table [damper] of {}): acts between `damper_hub_end` and\n\
         `damper_blade_end`, reference length {} m (zero stroke); added by `rotorsim run` as a\n\
         step element (no [[hydraulic]] table in model decks yet).",
        damper.model.name(),
        args.rotor.display(),
        deck.spec.damper_attachment.reference_length_m
    );
    let text = deck.expand(&ExpandOptions {
        controls,
        table_revs: args.revs.max(1),
        damper_note: Some(note),
        ..Default::default()
    });
    print!("{text}");
    Ok(())
}
