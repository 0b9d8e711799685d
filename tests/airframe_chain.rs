//! The airframe under the hub as the expansion builds it (`[airframe]`, docs/rotor_deck.md): a
//! chain of bushings, one moving direction each. Each direction must see its own mass, spring
//! and damper: with a rigid hub mass on the chain, every mode is one direction alone at
//! `sqrt(k / (m + m_hub))` with damping ratio `c / (2 sqrt(k (m + m_hub)))` (analytic).
use rotorsim::rotor::deck::{AirframeRotation, AirframeTable, AirframeTranslation};
use rotorsim::rotor::expand::add_airframe;
use rotorsim::solver::modal::{modes, ModalOptions};
use rotorsim::solver::State;
use rotorsim::structure::deck::parse_deck;
use rotorsim::structure::deck_text::{to_toml, DeckBuilder};
use std::path::Path;

const HUB_KG: f64 = 400.0;
const HUB_KG_M2: f64 = 150.0;

fn t(m: f64, k: f64, c: f64) -> Option<AirframeTranslation> {
    Some(AirframeTranslation {
        mass_kg: m,
        stiffness: k,
        damping: c,
    })
}

fn r(i: f64, k: f64, c: f64) -> Option<AirframeRotation> {
    Some(AirframeRotation {
        inertia: i,
        stiffness: k,
        damping: c,
        center_z_m: 0.0,
    })
}

/// The chain's items as text, followed by the hub's (the analysis tables last).
fn chain_text(b: DeckBuilder) -> String {
    let text = to_toml(&b.finish());
    text.split("[static]")
        .next()
        .unwrap_or_default()
        .to_string()
}

#[test]
fn each_airframe_direction_has_its_own_mass_spring_and_damper() {
    // masses out of order (y is the heaviest, z the lightest), every direction
    let a = AirframeTable {
        x: t(5000.0, 8.0e5, 4.0e3),
        y: t(8000.0, 6.0e5, 1.0e3),
        z: t(2000.0, 3.0e6, 0.0),
        roll: r(9000.0, 2.0e6, 2.0e4),
        pitch: r(30000.0, 5.0e6, 0.0),
        mode: Vec::new(),
    };
    let mut b = DeckBuilder::new(vec![], "airframe chain");
    let mount = add_airframe(&mut b, &a).expect("a chain");
    let mut deck = chain_text(b);
    // a hub: a point mass with inertia, clamped on the chain's last node
    deck.push_str(&format!(
        "[[node]]\nname = \"hub\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[rigid_body]]\nname = \"hub_body\"\nnode = \"hub\"\nmass_kg = {HUB_KG}\ninertia_kgm2 = [[{HUB_KG_M2}, 0.0, 0.0], [0.0, {HUB_KG_M2}, 0.0], [0.0, 0.0, {HUB_KG_M2}]]\n\n[[joint]]\nname = \"shaft\"\ntype = \"clamp\"\nnode_a = \"{mount}\"\nnode_b = \"hub\"\n"
    ));
    let (_, mut model) = parse_deck(&deck, "airframe chain", Path::new(".")).unwrap();
    let st = State::from_model(&model);
    let found = modes(
        &mut model,
        &st,
        &ModalOptions {
            n_modes: 5,
            ..Default::default()
        },
    )
    .unwrap();
    let mut want: Vec<(f64, f64, &str)> = a
        .dofs()
        .iter()
        .map(|d| {
            let m = d.mass + if d.rotation { HUB_KG_M2 } else { HUB_KG };
            let wn = (d.stiffness / m).sqrt();
            let zeta = d.damping / (2.0 * (d.stiffness * m).sqrt());
            // the modal solver's frequency is |s| / 2 pi, the undamped natural frequency
            (wn / (2.0 * std::f64::consts::PI), zeta, d.name)
        })
        .collect();
    want.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut got: Vec<(f64, f64)> = found.iter().map(|m| (m.freq_hz, m.damping_ratio)).collect();
    got.sort_by(|p, q| p.0.total_cmp(&q.0));
    assert_eq!(got.len(), 5, "{got:?}");
    for ((f, z), (fw, zw, name)) in got.iter().zip(&want) {
        assert!((f - fw).abs() <= 1e-9 * fw, "{name}: {f} Hz, expected {fw}");
        assert!(
            (z - zw).abs() <= 1e-9,
            "{name}: damping ratio {z}, expected {zw}"
        );
    }
}

/// The modal form: each mode becomes one link of the chain (`M / phi^2` and its spring and
/// damper), a roll that carries the hub sideways (participation in roll and y) a roll about a
/// centre `y / roll` above the hub. With the hub's mass on the chain each mode's frequency is
/// `sqrt(k / (m + m_hub))`, for the offset roll `sqrt(k / (I + I_hub + m_hub c^2))`.
#[test]
fn airframe_modes_keep_their_frequency_damping_and_hub_participation() {
    use rotorsim::rotor::deck::{AirframeMode, Participation};
    let mode = |f: f64, zeta: f64, m: f64, p: Participation| AirframeMode {
        frequency_hz: f,
        damping_ratio: zeta,
        generalized_mass_kg: m,
        participation: p,
    };
    let a = AirframeTable {
        mode: vec![
            mode(
                3.0,
                0.03,
                4000.0,
                Participation {
                    x: 0.5,
                    ..Default::default()
                },
            ),
            mode(
                2.0,
                0.05,
                6000.0,
                Participation {
                    y: 1.2,
                    roll: 0.8,
                    ..Default::default()
                },
            ),
            mode(
                8.0,
                0.0,
                2500.0,
                Participation {
                    z: 1.0,
                    ..Default::default()
                },
            ),
            mode(
                5.0,
                0.02,
                9000.0,
                Participation {
                    pitch: 0.3,
                    ..Default::default()
                },
            ),
        ],
        ..Default::default()
    };
    let mut b = DeckBuilder::new(vec![], "airframe modes");
    let mount = add_airframe(&mut b, &a).expect("a chain");
    let mut deck = chain_text(b);
    deck.push_str(&format!(
        "[[node]]\nname = \"hub\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[rigid_body]]\nname = \"hub_body\"\nnode = \"hub\"\nmass_kg = {HUB_KG}\ninertia_kgm2 = [[{HUB_KG_M2}, 0.0, 0.0], [0.0, {HUB_KG_M2}, 0.0], [0.0, 0.0, {HUB_KG_M2}]]\n\n[[joint]]\nname = \"shaft\"\ntype = \"clamp\"\nnode_a = \"{mount}\"\nnode_b = \"hub\"\n"
    ));
    let (_, mut model) = parse_deck(&deck, "airframe modes", Path::new(".")).unwrap();
    let st = State::from_model(&model);
    let found = modes(
        &mut model,
        &st,
        &ModalOptions {
            n_modes: 4,
            ..Default::default()
        },
    )
    .unwrap();
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut want: Vec<(f64, f64)> = a
        .mode
        .iter()
        .map(|m| {
            let p = &m.participation;
            let w = two_pi * m.frequency_hz;
            let (phi, hub) = if p.roll != 0.0 {
                let c = p.y / p.roll;
                (p.roll, HUB_KG_M2 + HUB_KG * c * c)
            } else if p.pitch != 0.0 {
                (p.pitch, HUB_KG_M2)
            } else {
                (p.x + p.z, HUB_KG)
            };
            let mass = m.generalized_mass_kg / (phi * phi);
            let (k, c) = (mass * w * w, 2.0 * m.damping_ratio * w * mass);
            let total = mass + hub;
            ((k / total).sqrt() / two_pi, c / (2.0 * (k * total).sqrt()))
        })
        .collect();
    want.sort_by(|p, q| p.0.total_cmp(&q.0));
    let mut got: Vec<(f64, f64)> = found.iter().map(|m| (m.freq_hz, m.damping_ratio)).collect();
    got.sort_by(|p, q| p.0.total_cmp(&q.0));
    assert_eq!(got.len(), 4, "{got:?}");
    for ((f, z), (fw, zw)) in got.iter().zip(&want) {
        assert!((f - fw).abs() <= 1e-9 * fw, "{f} Hz, expected {fw}");
        assert!((z - zw).abs() <= 1e-9, "damping ratio {z}, expected {zw}");
    }
    // the offset roll moves the hub sideways by y / roll per radian: its mode shape at the hub
    let roll = found
        .iter()
        .find(|m| {
            let h = m.shape.last().unwrap();
            h[3].abs() > 1e-3 * h.iter().fold(0.0f64, |a, v| a.max(v.abs()))
        })
        .expect("a roll mode");
    let h = roll.shape.last().unwrap();
    assert!(
        (h[1] / h[3] - 1.5).abs() < 1e-9,
        "hub y / roll = {}",
        h[1] / h[3]
    );
}

/// A deck's values line by line: comments and the damper's small-amplitude keys (the
/// stability decks' viscous orifice and seal friction, which the record's deck has not) left
/// out.
fn values(text: &str) -> Vec<String> {
    let small = [
        "mu_Pa_s",
        "orifice_length_m",
        "seal_friction_N",
        "seal_presliding",
    ];
    text.lines()
        .map(|l| l.split('#').next().unwrap_or("").trim_end().to_string())
        .filter(|l| !l.trim().is_empty() && !small.iter().any(|k| l.starts_with(k)))
        .collect()
}

/// Whether the stability deck `with` is the record's deck `base` with tables after it.
fn begins_with(with: &str, base: &str) -> bool {
    let (w, b) = (values(with), values(base));
    w.len() >= b.len() && w[..b.len()] == b[..]
}

/// The shipped airframe example is the shipped deck (with its seal friction), unchanged, with
/// an `[airframe]` after it.
#[test]
fn the_airframe_example_is_the_shipped_deck_on_an_airframe() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors");
    let base = std::fs::read_to_string(root.join("uh60a.toml")).unwrap();
    let with = std::fs::read_to_string(root.join("uh60a_airframe.toml")).unwrap();
    assert!(
        begins_with(&with, &base),
        "rotors/uh60a_airframe.toml must begin with rotors/uh60a.toml"
    );
    let deck = rotorsim::rotor::RotorDeck::from_file(&root.join("uh60a_airframe.toml")).unwrap();
    let a = deck.spec.airframe.expect("an [airframe]");
    for d in a.dofs() {
        assert!((d.frequency_hz() - 15.0).abs() < 1e-3, "{d:?}");
        assert!((d.damping_ratio() - 0.02).abs() < 1e-4, "{d:?}");
    }
}

/// The shipped hover example is the shipped deck (with its seal friction), unchanged, with a
/// free-flight airframe after
/// it whose rotations turn about the centre of gravity 1.7 m below the hub.
#[test]
fn the_hover_example_is_the_shipped_deck_on_a_free_airframe() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors");
    let base = std::fs::read_to_string(root.join("uh60a.toml")).unwrap();
    let with = std::fs::read_to_string(root.join("uh60a_hover.toml")).unwrap();
    assert!(
        begins_with(&with, &base),
        "rotors/uh60a_hover.toml must begin with rotors/uh60a.toml"
    );
    let deck = rotorsim::rotor::RotorDeck::from_file(&root.join("uh60a_hover.toml")).unwrap();
    let dofs = deck.spec.airframe.expect("an [airframe]").dofs();
    assert_eq!(dofs.len(), 4);
    for d in dofs {
        assert!((d.frequency_hz() - 0.05).abs() < 1e-3, "{d:?}");
        assert_eq!(d.center_z_m, if d.rotation { -1.7 } else { 0.0 });
    }
}
