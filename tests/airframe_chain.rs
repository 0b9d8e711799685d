//! The airframe under the hub as the expansion builds it (`[airframe]`, docs/rotor_deck.md): a
//! chain of bushings, one moving direction each. Each direction must see its own mass, spring
//! and damper: with a rigid hub mass on the chain, every mode is one direction alone at
//! `sqrt(k / (m + m_hub))` with damping ratio `c / (2 sqrt(k (m + m_hub)))` (analytic).
use rotorsim::rotor::deck::{AirframeRotation, AirframeTable, AirframeTranslation};
use rotorsim::rotor::expand::write_airframe;
use rotorsim::solver::modal::{modes, ModalOptions};
use rotorsim::solver::State;
use rotorsim::structure::deck::parse_deck;
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
    })
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
    };
    let mut deck = String::from("title = \"airframe chain\"\n");
    let mount = write_airframe(&mut deck, &a).expect("a chain");
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
