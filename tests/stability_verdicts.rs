//! A stability verdict carries the band that could flip it (docs/stability.md, "Verdicts and
//! their band"): on the shipped hover deck without its seal friction (the oil alone) the
//! regressing lag at the operating speed grows by the linear map, but the bearing's ASSUMED lag
//! damping at twice its value damps it, so the verdict is "marginal" and names that value; the
//! band is checked against maps of the deck with the value overridden, run as a user would.
//! With the shipped seal friction the seal's values decide the verdict.
use std::path::Path;
use std::process::Command;

mod support;
use support::{read_json, root, tmp};

fn stability(args: &[&str], out: &Path) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .arg("stability")
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        o.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    text
}

/// The regressing lag's growth rate at the single speed of a map's summary.
fn regressing_growth(dir: &Path) -> f64 {
    let csv = std::fs::read_to_string(dir.join("stability.csv")).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|c| c[1] == "regressing lag")
        .map(|c| c[4].parse::<f64>().unwrap())
        .fold(f64::NEG_INFINITY, f64::max)
}

#[test]
fn hover_operating_speed_is_marginal_and_names_the_bearing_damping() {
    let deck = root().join("rotors/uh60a_hover.toml");
    let deck = deck.to_str().unwrap();
    let base = [
        "--rotor",
        deck,
        "--hover",
        "--speeds",
        "27",
        "--damper",
        "physical",
        "--set",
        "damper.physical.seal_friction_N=0",
    ];
    let out = tmp("verdict_hover");
    let text = stability(&base, &out);
    let s = read_json(&out.join("summary.json"));
    let v = s["verdicts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["at"] == "operating speed")
        .unwrap_or_else(|| panic!("no operating-speed verdict: {s}"));
    assert_eq!(v["mode"], "regressing lag", "{v}");
    let g0 = v["growth_rate_per_s"].as_f64().unwrap();
    let band = [
        v["band_per_s"][0].as_f64().unwrap(),
        v["band_per_s"][1].as_f64().unwrap(),
    ];
    assert!(g0 > 0.0, "the linear map grows at 27 rad/s: {g0}");
    assert!(band[0] < 0.0 && band[1] > 0.0, "{band:?}");
    assert_eq!(v["call"], "marginal");
    let first = &v["deciding"][0];
    assert_eq!(first["key"], "bearing.lag_loss_factor", "{v}");
    let line = text
        .lines()
        .find(|l| l.starts_with("marginal: regressing lag"))
        .unwrap();
    assert!(
        line.contains("band") && line.contains("bearing.lag_loss_factor"),
        "{line}"
    );
    // the deciding value's ends are the maps a user gets by setting it
    for (end, key) in [
        ("low", "growth_rate_at_low_per_s"),
        ("high", "growth_rate_at_high_per_s"),
    ] {
        let x = first[end].as_f64().unwrap();
        let o = tmp(&format!("verdict_hover_{end}"));
        let set = format!("bearing.lag_loss_factor={x}");
        let mut a = base.to_vec();
        a.extend(["--set", &set]);
        stability(&a, &o);
        let g = regressing_growth(&o);
        let want = first[key].as_f64().unwrap();
        assert!(
            (g - want).abs() <= 1e-12 * g.abs().max(1e-6),
            "{end}: map {g}, band {want}"
        );
        let _ = std::fs::remove_dir_all(&o);
    }
    // doubling the bearing's damping damps the mode: the value that flips the verdict
    assert!(
        first["growth_rate_at_high_per_s"].as_f64().unwrap() < 0.0,
        "{first}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn the_free_airframes_flight_modes_are_named_for_what_they_are() {
    let deck = root().join("rotors/uh60a_hover.toml");
    let out = tmp("verdict_flight");
    let text = stability(
        &[
            "--rotor",
            deck.to_str().unwrap(),
            "--hover",
            "--speeds",
            "26:28:1",
            "--damper",
            "linear",
        ],
        &out,
    );
    let line = text
        .lines()
        .find(|l| {
            l.contains("airframe y") && (l.starts_with("UNSTABLE") || l.starts_with("marginal"))
        })
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        line.contains("flight dynamics of the free airframe"),
        "{line}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn with_the_shipped_seal_friction_the_seal_decides() {
    let deck = root().join("rotors/uh60a_hover.toml");
    let out = tmp("verdict_seal");
    stability(
        &[
            "--rotor",
            deck.to_str().unwrap(),
            "--hover",
            "--speeds",
            "27",
            "--damper",
            "physical",
        ],
        &out,
    );
    let s = read_json(&out.join("summary.json"));
    let v = s["verdicts"]
        .as_array()
        .unwrap()
        .iter()
        .find(|v| v["at"] == "operating speed")
        .unwrap();
    let keys: Vec<&str> = v["deciding"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["key"].as_str().unwrap())
        .collect();
    assert!(
        keys.iter().any(|k| k.starts_with("damper.physical.seal_")),
        "{keys:?}"
    );
    // the call follows the band
    let band = [
        v["band_per_s"][0].as_f64().unwrap(),
        v["band_per_s"][1].as_f64().unwrap(),
    ];
    let call = if band[0] > 0.0 {
        "unstable"
    } else if band[1] < 0.0 {
        "stable"
    } else {
        "marginal"
    };
    assert_eq!(v["call"], call, "{v}");
    let _ = std::fs::remove_dir_all(&out);
}
