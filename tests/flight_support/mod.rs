//! Shared helpers of the flight-record tests.
#![allow(dead_code)]
use rotorsim::flight::{DamperSample, FlightMeta, FlightRecord};
use std::path::{Path, PathBuf};

pub fn meta(extra: serde_json::Value) -> FlightMeta {
    let mut m = serde_json::json!({
        "counter": "test", "synthetic": true, "description": "unit-test record",
        "rotor_speed_rad_s": 27.0, "radius_m": 8.178,
        "density_kg_m3": 1.0, "speed_of_sound_m_s": 336.0, "chord_m": 0.527,
        "controls_deg": {"collective": 11.0, "lateral_cyclic": 2.0, "longitudinal_cyclic": -8.0},
        "number_of_blades": 4
    });
    if let (Some(a), Some(b)) = (m.as_object_mut(), extra.as_object()) {
        for (k, v) in b {
            a.insert(k.clone(), v.clone());
        }
    }
    FlightMeta::from_json(m.as_object().unwrap().clone(), Path::new("test.meta.json")).unwrap()
}

/// A record whose loads are `f(q, rev, psi_deg, r_over_R)` on the given grid.
pub fn record(
    revs: &[u32],
    n_az: usize,
    stations: &[f64],
    f: impl Fn(usize, u32, f64, f64) -> f64,
) -> FlightRecord {
    let az: Vec<f64> = (0..n_az).map(|j| j as f64 * 360.0 / n_az as f64).collect();
    let mut v = [Vec::new(), Vec::new(), Vec::new()];
    for &r in revs {
        for &p in &az {
            for &s in stations {
                for (q, vq) in v.iter_mut().enumerate() {
                    vq.push(f(q, r, p, s));
                }
            }
        }
    }
    let damper = revs
        .iter()
        .flat_map(|&r| {
            az.iter().map(move |&p| DamperSample {
                revolution: r,
                azimuth_deg: p,
                force_N: 1000.0 * (p.to_radians()).sin() + r as f64,
                stroke_m: Some(0.01 * (p.to_radians()).cos()),
            })
        })
        .collect();
    let [n, c, m] = v;
    FlightRecord::new(
        meta(serde_json::json!({})),
        stations.to_vec(),
        revs.to_vec(),
        az,
        n,
        c,
        m,
        damper,
    )
    .unwrap()
}

pub fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rotorsim-flight-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn example_stem() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("flightdata/c8534like")
}

/// Every value of two records, bit for bit (the blade motion included).
pub fn assert_same_bits(a: &FlightRecord, b: &FlightRecord) {
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(a.revolutions(), b.revolutions());
    assert_eq!(bits(a.azimuths_deg()), bits(b.azimuths_deg()));
    assert_eq!(bits(a.stations_r_over_r()), bits(b.stations_r_over_r()));
    assert_eq!(bits(a.normal_n_per_m()), bits(b.normal_n_per_m()));
    assert_eq!(bits(a.chord_n_per_m()), bits(b.chord_n_per_m()));
    assert_eq!(bits(a.moment_n_m_per_m()), bits(b.moment_n_m_per_m()));
    assert_eq!(a.damper().len(), b.damper().len());
    for (x, y) in a.damper().iter().zip(b.damper()) {
        assert_eq!(x.revolution, y.revolution);
        assert_eq!(x.azimuth_deg.to_bits(), y.azimuth_deg.to_bits());
        assert_eq!(x.force_N.to_bits(), y.force_N.to_bits());
        assert_eq!(x.stroke_m.map(f64::to_bits), y.stroke_m.map(f64::to_bits));
    }
    assert_eq!(a.meta, b.meta);
    assert_eq!(
        a.motion.is_some(),
        b.motion.is_some(),
        "motion present in one only"
    );
    if let (Some(x), Some(y)) = (&a.motion, &b.motion) {
        assert_eq!(x.revolutions(), y.revolutions());
        assert_eq!(bits(x.azimuths_deg()), bits(y.azimuths_deg()));
        assert_eq!(bits(x.flap_deg()), bits(y.flap_deg()));
        assert_eq!(bits(x.lag_deg()), bits(y.lag_deg()));
        assert_eq!(bits(x.pitch_deg()), bits(y.pitch_deg()));
    }
}
