//! Every deck reader reports its errors as the one `DeckError` (which deck, the file, the key
//! and what was expected): the elastomeric and hinged rotor decks, `[blades]` tables, the
//! damper deck and model decks. A caller (the command line, Python) can tell a missing file
//! from a bad key without reading the message.
use rotorsim::hydraulics::{deck::Problem, DamperDeck, DeckError};
use rotorsim::rotor::deck::RotorSpec;
use rotorsim::rotor::hinged::HingedSpec;
use rotorsim::rotor::RotorDeck;
use std::path::Path;

mod support;
use support::{root, tmp};

fn edited(src: &str, from: &str, to: &str, name: &str) -> std::path::PathBuf {
    let text = std::fs::read_to_string(root().join(src)).unwrap();
    assert!(text.contains(from), "{src} has no `{from}`");
    let dir = tmp(name);
    // the shipped decks refer to their data relative to themselves
    let text = text
        .replacen(from, to, 1)
        .replace("\"data/", &format!("\"{}/rotors/data/", root().display()));
    let p = dir.join("r.toml");
    std::fs::write(&p, text).unwrap();
    p
}

/// The key the error names and the deck it calls the file.
fn key_of(e: &DeckError) -> (&str, &str) {
    match e {
        DeckError::Key { deck, key, .. } => (deck, key),
        other => panic!("expected a key error, got {other}"),
    }
}

#[test]
fn an_elastomeric_rotor_deck_names_the_key() {
    let p = edited(
        "rotors/uh60a.toml",
        "omega_rad_s = ",
        "omega_rad_s = -",
        "deck_err_omega",
    );
    let e = RotorSpec::from_file(&p).unwrap_err();
    assert_eq!(key_of(&e), ("rotor deck", "rotor.omega_rad_s"));
    assert!(e.to_string().contains("expected a positive number"), "{e}");
    // the same error through the reader of a run, carried by anyhow
    let e = RotorDeck::from_file(&p).unwrap_err();
    let d = e.downcast_ref::<DeckError>().expect("a DeckError");
    assert_eq!(key_of(d).1, "rotor.omega_rad_s");
}

#[test]
fn a_hinged_rotor_deck_names_the_key() {
    let p = edited(
        "rotors/tm4760.toml",
        "elements = 1",
        "elements = 0",
        "deck_err_hinged",
    );
    let e = HingedSpec::from_file(&p).unwrap_err();
    assert_eq!(
        key_of(&e),
        ("hinged-blade rotor deck", "blade.segment[0].elements")
    );
    // the rotor table's shared rule, in the hinged deck's words
    let p = edited(
        "rotors/tm4760.toml",
        "blades = ",
        "blades = 0 #",
        "deck_err_hinged_n",
    );
    let e = HingedSpec::from_file(&p).unwrap_err();
    assert_eq!(key_of(&e).1, "rotor.blades");
}

#[test]
fn a_missing_deck_is_a_read_error_of_every_reader() {
    let p = Path::new("/nonexistent/deck.toml");
    let not_found = |e: &DeckError| match e {
        DeckError::Read { source, .. } => source.kind() == std::io::ErrorKind::NotFound,
        _ => false,
    };
    assert!(not_found(&RotorSpec::from_file(p).unwrap_err()));
    assert!(not_found(&HingedSpec::from_file(p).unwrap_err()));
    assert!(not_found(&DamperDeck::from_file(p).unwrap_err()));
    let e = RotorDeck::from_file(p).unwrap_err();
    assert!(not_found(e.downcast_ref::<DeckError>().unwrap()), "{e:#}");
}

#[test]
fn a_per_blade_table_names_its_key() {
    let p = edited(
        "rotors/uh60a.toml",
        "[rotor]",
        "[blades.9.bearing]\nlag_damping_Nms_per_rad = 1.0\n\n[rotor]",
        "deck_err_blades",
    );
    let e = RotorDeck::from_file(&p).unwrap_err();
    let d = e.downcast_ref::<DeckError>().expect("a DeckError");
    assert_eq!(key_of(d), ("rotor deck", "blades.9"));
    assert!(matches!(
        d,
        DeckError::Key {
            problem: Problem::Invalid(_),
            ..
        }
    ));
}
