//! `rotorsim sensitivity`: the scan of a deck's ASSUMED labels, and a small run on the
//! rigid-blade reduction (one labelled value and one --vary) checked against plain runs.
use rotorsim::sensitivity::scan::{scan, targets};
use std::path::Path;
use std::process::{Command, Output};
mod support;
use support::{read_json, root, tmp};

const DECK: &str = r#"top_m = 1.0  # ASSUMED at the top
[a]
x_m = 0.5             # ASSUMED: why
y_N = 0.0             # ASSUMED zero
name = "q # ASSUMED"  # the label is inside the string: not labelled
plain_m = 2.0         # public
rows_m = [[1.0, 2.0],
          [3.0, 4.0]] # ASSUMED on a continuation line
v_m = [0.3, 0.0, 0.2] # ASSUMED vector
# ASSUMED: a note on a line of its own
t = { EA_N = 1.0 }    # ASSUMED inline table
[a.b]
"q_s" = 2.0           # ASSUMED quoted key
[[c]]
z_m = 1.0             # ASSUMED in an array of tables
[d]
n = 3                 # ASSUMED count
"#;

#[test]
fn the_scan_finds_labelled_keys_with_their_tables_and_reports_the_rest() {
    let root_t: toml::Table = DECK.parse().unwrap();
    let s = scan(DECK, &root_t);
    let keys: Vec<&str> = s.labelled.iter().map(|l| l.key.as_str()).collect();
    assert_eq!(
        keys,
        ["top_m", "a.x_m", "a.y_N", "a.v_m", "a.t", "a.b.q_s", "d.n"]
    );
    assert_eq!(s.labelled[1].line, 3);
    assert_eq!(s.labelled[1].comment, "ASSUMED: why");
    // lines the scan itself cannot use: continuation, own line, array of tables
    let lines: Vec<usize> = s.skipped.iter().map(|k| k.line).collect();
    assert_eq!(lines, [8, 10, 15], "{:?}", s.skipped);
    assert!(s.skipped[1].reason.contains("line of its own"));
    assert!(s.skipped[2].reason.contains("array of tables"));
    // numbers: nonzero scalars and vector components; zero, inline table, count skipped
    let mut names = Vec::new();
    let mut skipped = Vec::new();
    for l in &s.labelled {
        let (t, k) = targets(l);
        names.extend(t.iter().map(|t| t.name()));
        skipped.extend(k.iter().map(|k| k.key.clone().unwrap()));
    }
    assert_eq!(names, ["top_m", "a.x_m", "a.v_m[0]", "a.v_m[2]", "a.b.q_s"]);
    assert_eq!(skipped, ["a.y_N", "a.v_m[1]", "a.t", "d.n"]);
}

#[test]
fn the_shipped_deck_labels_sixteen_numbers_and_two_notes() {
    let text = std::fs::read_to_string(root().join("rotors/uh60a.toml")).unwrap();
    let s = scan(&text, &text.parse().unwrap());
    let names: Vec<String> = s
        .labelled
        .iter()
        .flat_map(|l| targets(l).0)
        .map(|t| t.name())
        .collect();
    for k in [
        "blade.damping_mu_s",
        "retention.horn_r_m",
        "bearing.flap_stiffness_Nm_per_rad",
        "bearing.pitch_loss_factor",
        "pitch_control.horn_tip_m[0]",
        "pitch_control.horn_tip_m[1]",
        "pitch_control.link_length_m",
        "damper_attachment.height_m",
        "damper_attachment.horn_mass_kg",
        "aero.tip_loss_factor",
    ] {
        assert!(names.iter().any(|n| n == k), "{k} not in {names:?}");
    }
    assert_eq!(names.len(), 16, "{names:?}");
    // the pitch-link stiffness note and the aerofoil note are comments of their own
    assert_eq!(s.skipped.len(), 2, "{:?}", s.skipped);
    assert!(s.skipped.iter().all(|k| k.key.is_none()));
}

fn sensitivity(dir: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(root())
        .args(["sensitivity", "--model", "rigid", "--jobs", "2", "--rotor"])
        .arg(dir.join("r.toml"))
        .arg("--out")
        .arg(dir.join("out"))
        .args(extra)
        .output()
        .unwrap()
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "stdout: {}\nstderr: {}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

/// The shipped deck with its files by absolute path and one ASSUMED label kept: the bearing's
/// lag loss factor.
fn one_label_deck(dir: &Path) {
    let r = root();
    let text = support::absolutize(
        std::fs::read_to_string(r.join("rotors/uh60a.toml"))
            .unwrap()
            .replace("# ASSUMED", "# assumed")
            .replace(
                "lag_loss_factor = 0.1                  # assumed",
                "lag_loss_factor = 0.1                  # ASSUMED",
            ),
    );
    std::fs::write(dir.join("r.toml"), text).unwrap();
}

fn f(s: &str) -> Option<f64> {
    (!s.is_empty()).then(|| s.parse().unwrap())
}

#[test]
fn a_rigid_sensitivity_matches_plain_runs_and_its_swing_is_high_minus_low() {
    let d = tmp("sensitivity-rigid");
    one_label_deck(&d);
    let o = sensitivity(
        &d,
        &["--vary", "bearing.lag_stiffness_Nm_per_rad=15000:30000"],
    );
    ok(&o);
    let out = d.join("out");
    let mut rd = csv::Reader::from_path(out.join("sensitivity.csv")).unwrap();
    let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
    let want_head = [
        "key",
        "unit",
        "source",
        "range",
        "nominal_value",
        "low_value",
        "high_value",
        "low_case_status",
        "high_case_status",
    ];
    assert_eq!(&header[..want_head.len()], want_head);
    for c in [
        "damper_force_peak_to_peak_low_N",
        "damper_force_peak_to_peak_nominal_N",
        "damper_force_peak_to_peak_high_N",
        "damper_force_peak_to_peak_swing_N",
        "damper_force_rms_error_swing_N",
        "pitch_link_force_half_p2p_swing_N",
        "pitch_link_force_1rev_swing_N",
        "root_chord_moment_half_p2p_swing_Nm",
        "root_flap_moment_half_p2p_swing_Nm",
        "lag_damping_ratio_low",
        "lag_damping_ratio_swing",
    ] {
        assert!(header.iter().any(|h| h == c), "{c} not in {header:?}");
    }
    assert_eq!(header.len(), want_head.len() + 7 * 4);
    let rows: Vec<csv::StringRecord> = rd.records().map(|r| r.unwrap()).collect();
    assert_eq!(rows.len(), 2);
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    assert_eq!(&rows[0][0], "bearing.lag_loss_factor");
    assert_eq!(&rows[0][1], "-");
    assert_eq!(f(&rows[0][col("low_value")]), Some(0.05));
    assert_eq!(f(&rows[0][col("high_value")]), Some(0.2));
    assert_eq!(&rows[1][0], "bearing.lag_stiffness_Nm_per_rad");
    assert_eq!(&rows[1][col("range")], "--vary");
    assert_eq!(f(&rows[1][col("low_value")]), Some(15000.0));

    // the nominal case equals a plain run of the same options, bit for bit
    let plain = d.join("plain");
    let p = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(root())
        .args(["run", "--model", "rigid", "--damper", "physical", "--rotor"])
        .arg(d.join("r.toml"))
        .arg("--out")
        .arg(&plain)
        .output()
        .unwrap();
    ok(&p);
    let s = read_json(&plain.join("summary.json"));
    let m = &s["models"]["physical"];
    let lag = &m["periodic"]["floquet_multipliers"][0];
    assert_eq!(lag["mode"], "lag");
    let expect = [
        (
            "damper_force_peak_to_peak",
            &m["damper_force_N"]["peak_to_peak"],
        ),
        ("damper_force_rms_error", &m["metrics"]["rms_error_N"]),
        ("lag_damping_ratio", &lag["damping_ratio"]),
    ];
    for row in &rows {
        for (name, v) in expect {
            let unit = if name == "lag_damping_ratio" {
                ""
            } else {
                "_N"
            };
            let got = f(&row[col(&format!("{name}_nominal{unit}"))]);
            assert_eq!(got, v.as_f64(), "{name}");
        }
    }
    let sum = read_json(&out.join("summary.json"));
    assert_eq!(
        sum["nominal"]["outputs"]["damper_force_peak_to_peak"].as_f64(),
        m["damper_force_N"]["peak_to_peak"].as_f64()
    );
    assert_eq!(sum["synthetic"], true);

    // the swing is high minus low; the low and high outputs are those of their cases
    for row in &rows {
        for name in [
            "damper_force_peak_to_peak_{}_N",
            "damper_force_rms_error_{}_N",
            "lag_damping_ratio_{}",
        ] {
            let c = |w: &str| f(&row[col(&name.replace("{}", w))]);
            let (lo, hi, sw) = (c("low").unwrap(), c("high").unwrap(), c("swing").unwrap());
            assert_eq!(sw, hi - lo, "{name}");
        }
        // the rigid model gives no blade loads: empty, not zero
        assert_eq!(&row[col("pitch_link_force_half_p2p_swing_N")], "");
    }
    let low_case = read_json(
        &out.join("cases/bearing.lag_loss_factor-low")
            .join("summary.json"),
    );
    assert_eq!(
        f(&rows[0][col("damper_force_peak_to_peak_low_N")]),
        low_case["models"]["physical"]["damper_force_N"]["peak_to_peak"].as_f64()
    );
    // more lag damping: a better damped lag mode
    assert!(
        f(&rows[0][col("lag_damping_ratio_swing")]).unwrap() > 0.0,
        "{:?}",
        &rows[0]
    );
    let html = std::fs::read_to_string(out.join("sensitivity.html")).unwrap();
    assert!(html.contains("SYNTHETIC"));
    assert!(html.contains("<svg"));
    assert!(html.contains("Not available: the rigid model"));
}
