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
    let clamped = a["clamped_queries"].as_u64().unwrap();
    let lookups = a["table_queries"].as_u64().unwrap();
    assert!(clamped > 0 && clamped < lookups, "{a}");
    assert!(a["clamps"]
        .as_str()
        .unwrap()
        .contains("below the table's Mach range (Mach 0.2)"));
    let ct = a["CT_over_sigma_mean"].as_f64().unwrap();
    assert!(ct > 0.0 && ct < 0.2, "CT/sigma {ct}");
    // each output station reports the lifting line at its own radius: its lift coefficient is
    // the table's at the station's angle of attack and Mach number (0.965 R lies inboard of
    // the tip-loss radius 0.97 R, between a lifting point and one outboard of it)
    let table =
        rotorsim::aero::c81::C81Table::from_file(&root.join("data/airfoils/naca0012.c81")).unwrap();
    let col = |name: &str| header.iter().position(|c| *c == name).unwrap();
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    for station in ["0.775", "0.965"] {
        let (ia, im, ic) = (
            col(&format!("aero_alpha_deg_r{station}")),
            col(&format!("aero_mach_r{station}")),
            col(&format!("aero_cl_r{station}")),
        );
        let peak = rows.iter().map(|r| r[ic].abs()).fold(0.0, f64::max);
        let worst = rows
            .iter()
            .map(|r| (r[ic] - table.cl.eval(r[ia], r[im]).0).abs())
            .fold(0.0, f64::max);
        assert!(
            peak > 0.1 && worst <= 5e-3 * peak,
            "r/R {station}: cl differs from the table's by {worst} (peak {peak})"
        );
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("<h2 id=\"airloads\">Airloads"));
    assert!(html.contains("a plausibility comparison"));
    assert!(html.contains("SYNTHETIC"));
    let _ = std::fs::remove_dir_all(&out);
}
