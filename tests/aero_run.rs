//! A computed-airload run writes what docs/aerodynamics.md says: the lifting line's channels in
//! last_rev.csv, `models.<m>.airloads` in summary.json (with the clamped table queries) and the
//! report's "Airloads" section beside the record's (SYNTHETIC) values.
mod support;

use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::aero::AirloadSource;
use rotorsim::run::job::{DamperChoice, RunJob};
use rotorsim::run::periodic::PeriodicMethod;
use rotorsim::run::Silent;

#[test]
fn computed_run_writes_the_lifting_line_outputs() {
    let root = support::root();
    let out = support::tmp("aero_run");
    let job = RunJob {
        rotor: root.join("rotors/uh60a.toml"),
        flight: root.join("flightdata/c8534like"),
        damper: DamperChoice::One(DamperModel::Linear),
        periodic: PeriodicMethod::March,
        revs: 3,
        airloads: AirloadSource::Computed,
        ..RunJob::new(&out)
    };
    job.execute(&Silent).unwrap();
    let csv = std::fs::read_to_string(out.join("linear/last_rev.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    for c in [
        "rotor_thrust_N",
        "rotor_power_W",
        "rotor_CT_over_sigma",
        "inflow_ratio_mean",
        "aero_alpha_deg_r0.775",
        "aero_mach_r0.775",
        "aero_cl_r0.775",
        "aero_cd_r0.775",
        "aero_cm_r0.775",
        "aero_inflow_ratio_r0.775",
        "aero_normal_N_per_m_r0.775",
        "aero_normal_minus_measured_N_per_m_r0.775",
    ] {
        assert!(header.contains(&c), "{c} in {header:?}");
    }
    let s = support::read_json(&out.join("summary.json"));
    let a = &s["models"]["linear"]["airloads"];
    assert_eq!(a["source"], "computed");
    assert_eq!(a["inflow"], "drees");
    assert_eq!(a["record_synthetic"], true);
    // the shipped NACA 0012 table's moment starts at Mach 0.2: inboard sections clamp there
    assert!(a["clamped_queries"].as_u64().unwrap() > 0, "{a}");
    assert!(a["clamps"]
        .as_str()
        .unwrap()
        .contains("below the table's Mach range"));
    let ct = a["CT_over_sigma_mean"].as_f64().unwrap();
    assert!(ct > 0.0 && ct < 0.2, "CT/sigma {ct}");
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<h2 id=\"airloads\">Airloads"));
    assert!(html.contains("a plausibility comparison"));
    assert!(html.contains("SYNTHETIC"));
    let _ = std::fs::remove_dir_all(&out);
}
