//! The shipped nominal damper deck, with `[damper.physical.extensions]` keys added, for the
//! hydraulics tests.
#![allow(dead_code)]
use rotorsim::hydraulics::DamperDeck;

/// flightdata/damper_nominal.toml as text, without the deck's own (Dahl) seal friction: the
/// hydraulics tests measure the circuit and their elements against the bare circuit
/// (tests/damper_small_amplitude.rs covers the seal friction).
pub fn nominal_text() -> String {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/flightdata/damper_nominal.toml"
    ))
    .unwrap();
    let bare: Vec<&str> = text
        .lines()
        .filter(|l| {
            let l = l.trim_start();
            !(l.starts_with("seal_friction_N") || l.starts_with("seal_presliding_stiffness"))
        })
        .collect();
    bare.join("\n") + "\n"
}

/// The nominal deck's text with the extension keys `ext`.
pub fn deck_text(ext: &str) -> String {
    format!("{}\n[damper.physical.extensions]\n{ext}\n", nominal_text())
}

/// The nominal deck with the extension keys `ext`, read as source `source`.
pub fn deck_with(ext: &str, source: &str) -> DamperDeck {
    DamperDeck::from_toml_str(&deck_text(ext), source).unwrap()
}
