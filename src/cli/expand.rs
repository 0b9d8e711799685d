//! `rotorsim expand --rotor DECK`: print the multibody model deck generated from a
//! rotor deck (docs/rotor_deck.md -> docs/model_deck.md).
use crate::hydraulics::DamperModel;
use crate::rotor::expand::{Controls, ExpandOptions, HydraulicRef};
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
    /// Damper model of the `[[hydraulic]]` table: linear, nonlinear or physical (default: the
    /// deck's `[damper] model`).
    #[arg(long)]
    pub damper: Option<String>,
    /// Hydraulic sub-steps per structural step.
    #[arg(long, default_value_t = 25)]
    pub substeps: usize,
    /// The whole rotor: every blade (its per-blade deck values) on one hub, blade k named
    /// `b<k>.` and turned (k-1) 360/N deg ahead of blade 1; the hub driven, or turning on the
    /// deck's `[airframe]`.
    #[arg(long)]
    pub all_blades: bool,
}

pub fn run(args: ExpandArgs) -> anyhow::Result<()> {
    if args.revs == 0 {
        anyhow::bail!("--revs 0: expected at least 1 revolution");
    }
    if args.substeps == 0 {
        anyhow::bail!("--substeps 0: expected at least 1 sub-step per step");
    }
    let deck = RotorDeck::from_file(&args.rotor)?;
    // the printed deck refers to the section table: it must be readable
    let sections = deck.input_files()[1].clone();
    crate::structure::section::SectionTable::from_csv(&sections).map_err(|e| {
        anyhow::anyhow!(
            "rotor deck {}, blade.sections_csv: {e}",
            args.rotor.display()
        )
    })?;
    // the [damper] table must be readable too (it is part of the rotor)
    let damper = deck.damper()?;
    let controls = match &args.flight {
        Some(p) => Controls::from_record(&crate::flight::FlightRecord::read(p)?.meta.controls_deg),
        None => Controls::default(),
    };
    let deck_name = args
        .rotor
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let model = match &args.damper {
        Some(m) => m
            .parse::<DamperModel>()
            .map_err(|e| anyhow::anyhow!("--damper {m}: {e}"))?,
        None => damper.model,
    };
    damper.require(model)?;
    let opts = ExpandOptions {
        controls,
        table_revs: args.revs,
        hydraulic: Some(HydraulicRef {
            deck: deck_name,
            model: model.name().into(),
            scheme: "rk4".into(),
            substeps: args.substeps,
        }),
        ..Default::default()
    };
    let text = if args.all_blades || deck.per_blade() {
        let specs = (1..=deck.spec.rotor.blades)
            .map(|k| {
                let b = deck.blade(k)?;
                // the printed deck names one damper table, the rotor deck's
                if b.damper()? != damper {
                    anyhow::bail!(
                        "rotor deck {}: blade {k}'s damper differs from the deck's ({}): the expanded model deck names one [damper] table for all blades; `rotorsim run` gives each blade its own",
                        args.rotor.display(),
                        deck.blade_differences().join(", ")
                    );
                }
                Ok(b.spec)
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        crate::rotor::expand::expand_rotor(&specs, &opts)
    } else {
        deck.expand(&opts)
    };
    out!("{text}");
    Ok(())
}
