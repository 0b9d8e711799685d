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
