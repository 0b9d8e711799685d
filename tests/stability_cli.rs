//! `rotorsim stability` on the shipped decks: the Hammond 1974 deck's reduced model is the
//! source's (data/stability/hammond1974.md), its map equals the lag-rotor analysis of the
//! source's numbers written here, an unstable rotor is a result (exit 0, marked), and the
//! outputs hold what the docs say.
use rotorsim::stability::LagRotor;
use std::path::{Path, PathBuf};

mod support;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn stability(args: &[&str], out: &Path) -> (bool, String) {
    let mut all = vec!["stability"];
    all.extend_from_slice(args);
    support::rotorsim_out(&all, out)
}

/// The source's rotor (data/stability/hammond1974.md), blade `out` (0-based) without its damper.
fn source_rotor(out: Option<usize>) -> LagRotor {
    support::hammond_rotor(out)
}

/// stability.csv rows: (speed, mode, frequency, damping ratio, growth rate, method).
fn rows(dir: &Path) -> Vec<(f64, String, f64, f64, f64, String)> {
    let text = std::fs::read_to_string(dir.join("stability.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "rotor_speed_rad_s,mode,frequency_Hz,damping_ratio,growth_rate_per_s,method"
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[0].parse().unwrap(),
                f[1].to_string(),
                f[2].parse().unwrap(),
                f[3].parse().unwrap(),
                f[4].parse().unwrap(),
                f[5].to_string(),
            )
        })
        .collect()
}

/// Every row's eigenvalue against the lag-rotor analysis of the source's numbers (the deck's equivalent
/// mass distribution reproduces them to the section table's trapezoid, ~1e-8).
fn check_against_source(dir: &Path, rotor: &LagRotor) {
    let method = "coleman";
    let rs = rows(dir);
    assert!(!rs.is_empty());
    let mut worst = 0.0f64;
    for (w, mode, f, _, g, m) in &rs {
        assert_eq!(m, method);
        let modes = rotor.coleman_eigenvalues(*w).unwrap();
        let r = modes
            .iter()
            // the nearest eigenvalue (an overdamped mode's two real roots share a label)
            .min_by(|a, b| {
                let d = |x: &rotorsim::stability::Mode| {
                    (x.growth_rate_per_s - g)
                        .hypot(2.0 * std::f64::consts::PI * (x.frequency_hz - f))
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap_or_else(|| panic!("{mode} at {w} rad/s"));
        let scale = r.eigenvalue.re.hypot(r.eigenvalue.im);
        let d = ((r.growth_rate_per_s - g).abs() / scale)
            .max((r.frequency_hz - f).abs() * 2.0 * std::f64::consts::PI / scale);
        assert!(
            d < 1e-6,
            "{mode} at {w} rad/s: {f} Hz {g} 1/s against {r:?}"
        );
        worst = worst.max(d);
    }
    println!("{method}: largest difference from the source's rotor {worst:.2e} of |lambda|");
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn hammond_deck_all_dampers_working_is_stable() {
    let out = support::tmp("stability_hammond_all");
    let (ok, text) = stability(
        &[
            "--rotor",
            repo("rotors/hammond1974.toml").to_str().unwrap(),
            "--speeds",
            "1:40:0.5",
        ],
        &out,
    );
    println!("{text}");
    assert!(ok, "{text}");
    assert!(text.contains("stable: least damping ratio"), "{text}");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["stable"], true);
    assert_eq!(s["method"], "coleman");
    // the deck's blade is the source's: mass, first and second moment about the hinge
    let b = &s["blades_at_last_speed"][0];
    for (key, v) in [
        ("mass_kg", 94.9),
        ("first_moment_kg_m", 289.1),
        ("inertia_kg_m2", 1084.7),
        ("hinge_offset_m", 0.3048),
        ("lag_damping_Nms_per_rad", 4067.5),
    ] {
        let got = b[key].as_f64().unwrap();
        assert!((got / v - 1.0).abs() < 1e-6, "{key}: {got} against {v}");
    }
    check_against_source(&out, &source_rotor(None));
    let html = std::fs::read_to_string(out.join("stability.html")).unwrap();
    assert!(html.contains("Coleman diagram") && html.contains("Stable over"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn hammond_deck_with_one_damper_out_is_unstable_and_a_result() {
    let out = support::tmp("stability_hammond_one_out");
    let (ok, text) = stability(
        &[
            "--rotor",
            repo("rotors/hammond1974.toml").to_str().unwrap(),
            "--speeds",
            "1:40:0.5",
            "--set",
            "blades.4.damper.linear.c_N_s_per_m=0",
        ],
        &out,
    );
    println!("{text}");
    assert!(ok, "an unstable rotor is a result: {text}");
    assert!(
        text.contains("linear map: regressing lag grows from"),
        "{text}"
    );
    // every UNSTABLE or marginal verdict names its band and the values that decide it
    for l in text.lines() {
        if l.starts_with("UNSTABLE") || l.starts_with("marginal") {
            assert!(l.contains(" band ") && l.contains("decided by"), "{l}");
        }
    }
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["stable"], false);
    assert_eq!(s["method"], "floquet");
    // the range's ends interpolated on the 0.5 rad/s map, against the bisected 22.0300 and
    // 32.1569 rad/s of tests/stability_hammond.rs: within the interpolation's error
    let u = &s["unstable"][0];
    let (from, to) = (
        u["from_rad_s"].as_f64().unwrap(),
        u["to_rad_s"].as_f64().unwrap(),
    );
    assert!(
        (from - 22.0300).abs() < 0.02 && (to - 32.1569).abs() < 0.02,
        "{from} {to}"
    );
    // the least stable mode at every speed (the overdamped real roots' labels and frequencies
    // may resolve differently in two nearly equal rotors; what decides stability does not)
    let rotor = source_rotor(Some(3));
    let rs = rows(&out);
    let mut worst = 0.0f64;
    let mut w_prev = f64::NAN;
    for (w, ..) in &rs {
        if *w == w_prev {
            continue;
        }
        w_prev = *w;
        let deck = rs
            .iter()
            .filter(|r| r.0 == *w)
            .map(|r| r.4)
            .fold(f64::NEG_INFINITY, f64::max);
        let src = rotor.floquet(*w, 512).unwrap();
        let m = src
            .iter()
            .max_by(|a, b| a.growth_rate_per_s.total_cmp(&b.growth_rate_per_s))
            .unwrap();
        let scale = m.eigenvalue.re.hypot(m.eigenvalue.im);
        worst = worst.max((m.growth_rate_per_s - deck).abs() / scale);
    }
    println!(
        "floquet: least stable growth rate from the source's rotor within {worst:.2e} of |lambda|"
    );
    assert!(worst < 1e-6, "{worst}");
    let html = std::fs::read_to_string(out.join("stability.html")).unwrap();
    assert!(html.contains("growing regressing lag") && html.contains("unstable: regressing lag"));
    let _ = std::fs::remove_dir_all(&out);
}

/// The amplitude check through the command: amplitude.csv with its columns, the report's
/// section, summary.json's statement; the result folder complete.
#[test]
fn the_amplitude_check_writes_its_table_section_and_statement() {
    let out = support::tmp("stability_amplitude_cli");
    let (ok, text) = stability(
        &[
            "--rotor",
            repo("rotors/uh60a_airframe.toml").to_str().unwrap(),
            "--speeds",
            "20,27,34",
            "--damper",
            "physical",
            "--amplitudes-m",
            "1e-4,1e-3",
        ],
        &out,
    );
    assert!(ok, "{text}");
    assert!(text.contains("amplitude check: at 27.000 rad/s"), "{text}");
    let csv = std::fs::read_to_string(out.join("amplitude.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "rotor_speed_rad_s,start_stroke_amplitude_m,stroke_amplitude_m,growth_rate_per_s,equivalent_growth_rate_per_s,linearised_growth_rate_per_s,equivalent_damping_Nms_per_rad,frequency_Hz,max_damper_force_N,mac,runner_up_mac,fit_from_s,fit_to_s,fitted_revolutions,settle_cycles,settle_change,bisection,end_of_travel_stroke_m,end_of_travel_s"
    );
    assert_eq!(lines.count(), 2);
    let html = std::fs::read_to_string(out.join("stability.html")).unwrap();
    assert!(html.contains("Amplitude: where the linear analysis stops being true"));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let a = &s["amplitude_check"];
    assert_eq!(a["rotor_speed_rad_s"], 27.0);
    assert_eq!(a["points"].as_array().unwrap().len(), 2);
    assert!(a["statement"].as_str().unwrap().contains("no limit cycle"));
    assert!(!out.join("INCOMPLETE").exists());
}

/// Air resonance in hover on the shipped hover deck: every group of modes the model has is
/// labelled, the summary carries the hover state and its momentum theory closes, and the
/// report says what was run.
#[test]
fn hover_map_on_the_shipped_deck() {
    let out = support::tmp("stability-hover");
    let (ok, text) = stability(
        &[
            "--rotor",
            repo("rotors/uh60a_hover.toml").to_str().unwrap(),
            "--hover",
            "--speeds",
            "20,27",
            "--damper",
            "linear",
        ],
        &out,
    );
    assert!(ok, "{text}");
    assert!(text.contains(", hover (linear damper, coleman)"), "{text}");
    let r = rows(&out);
    for label in [
        "regressing lag",
        "progressive lag",
        "collective lag",
        "differential lag",
        "regressing flap",
        "progressive flap",
        "collective flap",
        "differential flap",
    ] {
        assert!(
            r.iter().any(|x| x.1 == label && x.0 == 27.0),
            "{label} missing: {r:?}"
        );
    }
    assert!(r.iter().all(|x| x.5 == "coleman"));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["condition"], "hover");
    let h = &s["hover"];
    let radius: f64 = 8.1786;
    for st in h["states"].as_array().unwrap() {
        let (t, vi) = (
            st["thrust_n"].as_f64().unwrap(),
            st["induced_velocity_m_s"].as_f64().unwrap(),
        );
        assert!(t > 0.0 && st["coning_deg"].as_f64().unwrap() > 0.0, "{st}");
        let momentum = (t / (2.0 * 1.225 * std::f64::consts::PI * radius * radius)).sqrt();
        assert!(
            (vi - momentum).abs() < 1e-9 * momentum,
            "{vi} vs {momentum}"
        );
    }
    assert_eq!(h["options"]["collective_deg"], 8.0);
    let html = std::fs::read_to_string(out.join("stability.html")).unwrap();
    assert!(html.contains("Air resonance in hover") && html.contains("Hover equilibrium"));
    // the least damping over the map is the csv's
    let min = r.iter().map(|x| x.3).fold(f64::INFINITY, f64::min);
    assert_eq!(s["min_damping_ratio"].as_f64().unwrap(), min);
}
