//! Shared helpers of the integration tests (`mod support;` in a test file). Each test binary
//! uses a part of it.
#![allow(dead_code)]
use std::path::{Path, PathBuf};

/// The package root (rotors/, flightdata/, docs/ below it).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh, empty temporary folder `rotorsim-<name>-<pid>` (pid: one per test binary, so test
/// binaries never share one; names must differ within a binary).
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotorsim-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `rotorsim <args> --out <out>` from the package root: (success, stdout then stderr).
pub fn rotorsim_out(args: &[&str], out: &Path) -> (bool, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(root())
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    (o.status.success(), text)
}

/// A JSON file, parsed.
pub fn read_json(path: &Path) -> serde_json::Value {
    let text =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("parsing {}: {e}", path.display()))
}

/// The top-level keys of diagnosis.json in docs/formats.md.
pub const DIAGNOSIS_KEYS: [&str; 8] = [
    "cause",
    "parameters",
    "baseline_rms_N",
    "extended_rms_N",
    "gain",
    "validation",
    "candidates",
    "evidence",
];

pub fn assert_diagnosis_keys(j: &serde_json::Value) {
    for k in DIAGNOSIS_KEYS {
        assert!(j.get(k).is_some(), "diagnosis.json: missing key {k}");
    }
}

/// Device channels of the physical damper after the base channels, as the rotor run reports
/// them (docs/rotor_model.md, "Channels").
pub const PHYSICAL_CHANNELS: [&str; 9] = [
    "p0_Pa",
    "p1_Pa",
    "q_orifice_m3_s",
    "x_valve0_m",
    "x_valve1_m",
    "v_valve0_m_s",
    "v_valve1_m_s",
    "q_valve0_m3_s",
    "q_valve1_m3_s",
];

/// Hammond's 1974 ground-resonance rotor as the reduced lag model, from the source's numbers
/// (data/stability/hammond1974.md); blade `inoperative` (0-based) without its lag damper.
pub fn hammond_rotor(inoperative: Option<usize>) -> rotorsim::stability::LagRotor {
    use rotorsim::stability::{AirframeAxis, LagBlade, LagRotor};
    let mut blades = vec![
        LagBlade {
            mass_kg: 94.9,
            first_moment_kg_m: 289.1,
            inertia_kg_m2: 1084.7,
            hinge_offset_m: 0.3048,
            stiffness_nm_per_rad: 0.0,
            damping_nms_per_rad: 4067.5,
        };
        4
    ];
    if let Some(k) = inoperative {
        blades[k].damping_nms_per_rad = 0.0;
    }
    LagRotor {
        blades,
        x: Some(AirframeAxis {
            mass_kg: 8026.6,
            stiffness_n_per_m: 1_240_481.8,
            damping_ns_per_m: 51_078.7,
        }),
        y: Some(AirframeAxis {
            mass_kg: 3283.6,
            stiffness_n_per_m: 1_240_481.8,
            damping_ns_per_m: 25_539.3,
        }),
    }
}

/// Upward zero crossings (linear interpolation) of a sampled history.
pub fn upward_crossings(h: &[(f64, f64)]) -> Vec<f64> {
    h.windows(2)
        .filter(|p| p[0].1 < 0.0 && p[1].1 >= 0.0)
        .map(|p| p[0].0 + (p[1].0 - p[0].0) * (-p[0].1) / (p[1].1 - p[0].1))
        .collect()
}

/// Copies of shipped decks refer to shipped files by absolute path.
pub fn absolutize(text: String) -> String {
    let r = root();
    text.replace(
        "sections_csv = \"data/",
        &format!("sections_csv = \"{}/", r.join("rotors/data").display()),
    )
    .replace(
        "csv = \"data/",
        &format!("csv = \"{}/", r.join("rotors/data").display()),
    )
    .replace(
        "deck = \"../../rotors/",
        &format!("deck = \"{}/", r.join("rotors").display()),
    )
    .replace(
        "c81 = \"../data/",
        &format!("c81 = \"{}/", r.join("data").display()),
    )
}

/// The columns of a CSV file with a header, by name (a cell that is not a number reads NaN).
pub fn csv_columns(path: &Path) -> impl Fn(&str) -> Vec<f64> {
    let mut rd = csv::Reader::from_path(path).unwrap();
    let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    let rows: Vec<Vec<f64>> = rd
        .records()
        .map(|r| {
            r.unwrap()
                .iter()
                .map(|x| x.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    move |name: &str| {
        let i = header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name}"));
        rows.iter().map(|r| r[i]).collect()
    }
}
