//! Stability-map mode labels (docs/stability.md): unique at every speed, the families
//! assigned jointly, so that where the regressing lag meets the airframe both are named, and
//! an overdamped family's two real roots are told apart.
use rotorsim::hydraulics::DamperModel;
use rotorsim::overrides::Override;
use rotorsim::resonance::air::{air_resonance_map, HoverOptions};
use rotorsim::resonance::{stability_map, StabilityMap};
use rotorsim::rotor::RotorDeck;
use rotorsim::stability::ModeLabel;
use std::path::Path;

mod support;

/// `from:to:step` inclusive.
fn speeds(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    (0..=n).map(|i| from + i as f64 * step).collect()
}

fn deck(path: &str, set: &[&str]) -> RotorDeck {
    let set: Vec<Override> = set.iter().map(|s| Override::parse(s).unwrap()).collect();
    RotorDeck::from_file_with(Path::new(path), &set).unwrap()
}

fn physical() -> DamperModel {
    DamperModel::Physical
}

/// Every speed's names distinct.
fn assert_unique(map: &StabilityMap, what: &str) {
    for s in &map.speeds {
        let names: Vec<String> = s.modes.iter().map(|m| m.name()).collect();
        let mut sorted = names.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(
            sorted.len(),
            names.len(),
            "{what} at {} rad/s: {names:?}",
            s.omega_rad_s
        );
    }
}

/// The families present at the map's speed `w`.
fn families_at(map: &StabilityMap, w: f64) -> Vec<ModeLabel> {
    let s = map
        .speeds
        .iter()
        .find(|s| (s.omega_rad_s - w).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no speed {w}"));
    s.modes.iter().map(|m| m.label).collect()
}

fn print(map: &StabilityMap, what: &str) {
    for s in &map.speeds {
        let names: Vec<String> = s
            .modes
            .iter()
            .map(|m| {
                format!(
                    "{} {:.3} Hz {:+.4}",
                    m.name(),
                    m.frequency_hz,
                    m.growth_rate_per_s
                )
            })
            .collect();
        println!("{what} {}: {}", s.omega_rad_s, names.join("; "));
    }
}

/// Hammond's rotor with blade 4's damper inoperative (the README's map, Floquet): each
/// family once per speed, the airframe named through the coalescence (14-22 rad/s), and the
/// unstable zone the regressing lag's, as against MBDyn (data/stability/hammond1974.md).
#[test]
fn hammond_labels_are_unique_and_the_zone_is_the_regressing_lag() {
    let d = deck(
        "rotors/hammond1974.toml",
        &["blades.4.damper.linear.c_N_s_per_m=0"],
    );
    let model = d.damper().unwrap().model;
    let map = stability_map(&d, model, &speeds(1.0, 40.0, 0.5)).unwrap();
    print(&map, "hammond");
    assert_unique(&map, "hammond");
    for w in speeds(14.0, 22.0, 0.5) {
        let f = families_at(&map, w);
        for want in [
            ModeLabel::RegressingLag,
            ModeLabel::AirframeX,
            ModeLabel::AirframeY,
        ] {
            assert!(f.contains(&want), "{want} missing at {w} rad/s: {f:?}");
        }
    }
    let unstable: Vec<_> = map
        .unstable
        .iter()
        .map(|u| {
            (
                u.mode.as_str(),
                u.from_rad_s,
                u.to_rad_s,
                u.max_growth_rate_per_s,
            )
        })
        .collect();
    println!("unstable: {unstable:?}");
    assert_eq!(unstable.len(), 1, "{unstable:?}");
    let (mode, from, to, peak) = unstable[0];
    // the map's grid (0.5 rad/s, ends interpolated): 22.028 to 32.158 rad/s, +0.3254 1/s at
    // 26.5 rad/s, against MBDyn's 22.030 to 32.157 and +0.3258 at the peak
    // (tests/stability_hammond.rs bisects them)
    assert_eq!(mode, "regressing lag");
    assert!((from - 22.0284).abs() < 1e-4, "{from}");
    assert!((to - 32.1585).abs() < 1e-4, "{to}");
    assert!((peak - 0.32540).abs() < 1e-5, "{peak}");

    // all dampers working (Coleman, the reduced rotor of the test support)
    let r = support::hammond_rotor(None);
    for w in speeds(1.0, 40.0, 0.25) {
        let modes = r.coleman_eigenvalues(w).unwrap();
        let mut names: Vec<String> = modes.iter().map(|m| m.name()).collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n, "all dampers at {w} rad/s: {modes:?}");
    }
}

/// The UH-60A-like rotor on its assumed airframe (the README's ground map): unique names,
/// and at 40 and 70 rad/s, where the regressing lag meets the airframe, both airframe modes.
#[test]
fn uh60a_ground_labels_are_unique_and_name_the_airframe_at_the_coalescences() {
    let d = deck("rotors/uh60a_airframe.toml", &[]);
    let map = stability_map(&d, physical(), &speeds(20.0, 80.0, 2.0)).unwrap();
    print(&map, "uh60a ground");
    assert_unique(&map, "uh60a ground");
    for w in [40.0, 70.0] {
        let f = families_at(&map, w);
        for want in [
            ModeLabel::RegressingLag,
            ModeLabel::ProgressiveLag,
            ModeLabel::AirframeX,
            ModeLabel::AirframeY,
        ] {
            assert!(f.contains(&want), "{want} missing at {w} rad/s: {f:?}");
        }
    }
}

/// Air resonance in hover (the README's hover map): the slow free airframe's real roots are
/// numbered within their family, every name once a speed, and the coupled block's families
/// (regressing lag and flap, the airframe's roll and pitch) all present.
#[test]
fn uh60a_hover_labels_are_unique_and_real_roots_numbered() {
    let d = deck("rotors/uh60a_hover.toml", &[]);
    let map = air_resonance_map(
        &d,
        physical(),
        &speeds(15.0, 35.0, 1.0),
        &HoverOptions::default(),
    )
    .unwrap();
    print(&map, "uh60a hover");
    assert_unique(&map, "uh60a hover");
    for s in &map.speeds {
        for m in &s.modes {
            let same = s.modes.iter().filter(|o| o.label == m.label).count();
            assert_eq!(m.root == 0, same == 1, "{} at {}", m.name(), s.omega_rad_s);
            if m.root > 0 && m.eigenvalue.im == 0.0 {
                assert!(m.name().ends_with(&format!("(real root {})", m.root)));
            }
        }
        let f: Vec<ModeLabel> = s.modes.iter().map(|m| m.label).collect();
        for want in [ModeLabel::RegressingLag, ModeLabel::RegressingFlap] {
            assert!(f.contains(&want), "{want} missing at {}", s.omega_rad_s);
        }
    }
}
