//! Inputs that used to slip through: the rigid-blade reduction checks the record against the
//! deck as the elastic model does, and its Newton loop does not call a tiny update with a large
//! residual converged.
use std::path::PathBuf;
use std::process::Command;

mod support;
use support::tmp;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn rotorsim(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn rigid_reduction_refuses_a_record_of_another_rotor_speed() {
    let dir = tmp("rigid_speed");
    std::fs::create_dir_all(&dir).unwrap();
    let stem = dir.join("rec");
    let meta = std::fs::read_to_string(repo("flightdata/c8534like.meta.json")).unwrap();
    let mut j: serde_json::Value = serde_json::from_str(&meta).unwrap();
    j["rotor_speed_rad_s"] = serde_json::json!(25.0);
    std::fs::write(stem.with_extension("meta.json"), j.to_string()).unwrap();
    for ext in ["airloads.csv", "damper.csv"] {
        let src = repo(&format!("flightdata/c8534like.{ext}"));
        if src.exists() {
            std::fs::copy(src, dir.join(format!("rec.{ext}"))).unwrap();
        }
    }
    let out = dir.join("out");
    let o = rotorsim(&[
        "run",
        "--model",
        "rigid",
        "--flight",
        stem.to_str().unwrap(),
        "--revs",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("rotor speed 25 rad/s differs from the rotor deck's 27 rad/s"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_device_stiff_beyond_sense_fails_with_time_iteration_and_residual() {
    // bulk_alpha = 1e-30 /Pa: an oil column 1e20 times stiffer than oil; every Newton update
    // is tiny, the residual is not
    let dir = tmp("rigid_stiff");
    std::fs::create_dir_all(&dir).unwrap();
    let deck = repo("rotors/uh60a.toml");
    let text = std::fs::read_to_string(&deck)
        .unwrap()
        .replace("bulk_alpha_per_Pa = 6.667e-10", "bulk_alpha_per_Pa = 1e-30")
        .replace(
            "sections_csv = \"data/",
            &format!("sections_csv = \"{}/", repo("rotors/data").display()),
        );
    assert!(text.contains("1e-30"));
    let p = dir.join("stiff.toml");
    std::fs::write(&p, text).unwrap();
    let out = dir.join("out");
    let o = rotorsim(&[
        "run",
        "--model",
        "rigid",
        "--rotor",
        p.to_str().unwrap(),
        "--flight",
        repo("flightdata/c8534like").to_str().unwrap(),
        "--damper",
        "physical",
        "--revs",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !o.status.success(),
        "a stiff device must not pass as periodic"
    );
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("did not converge")
            && e.contains("t = ")
            && e.contains("iterations")
            && e.contains("residual"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn rotor_deck_values_are_checked_with_the_key_named() {
    let base = std::fs::read_to_string(repo("rotors/uh60a.toml")).unwrap();
    for (from, to, key) in [
        ("blades = 4 ", "blades = 0 ", "rotor.blades"),
        (
            "horn_tip_m = [0.381, 0.20, 0.0]",
            "horn_tip_m = [nan, 0.20, 0.0]",
            "pitch_control.horn_tip_m",
        ),
        ("[1.68344, 9.823]", "[1.68344, nan]", "blade.twist_deg"),
        (
            "segment1 = { elements = 3, section = { EA_N = 5.0e9",
            "segment1 = { elements = 3, section = { EA_N = -5.0e9",
            "retention.segment1.section.EA_N",
        ),
        (
            "m_kg_per_m = 47.4, I1_kgm = 0.08",
            "m_kg_per_m = 47.4, I1_kgm = -0.08",
            "retention.segment2.section.I1_kgm",
        ),
        (
            "link_section = { EA_N = 9.0e5",
            "link_section = { EA_N = nan",
            "pitch_control.link_section.EA_N",
        ),
    ] {
        assert!(base.contains(from), "{from}");
        let text = base.replacen(from, to, 1);
        let e = rotorsim::rotor::deck::RotorSpec::parse(&text, "x/uh60a.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x/uh60a.toml") && e.contains(key) && e.contains("expected"),
            "{to}: {e}"
        );
    }
}

#[test]
fn metadata_that_describes_the_data_must_agree_with_it() {
    let dir = tmp("meta_agrees");
    std::fs::create_dir_all(&dir).unwrap();
    let meta = std::fs::read_to_string(repo("flightdata/c8534like.meta.json")).unwrap();
    assert!(meta.contains("\"azimuths_per_revolution\": 256"));
    for ext in ["airloads.csv", "damper.csv"] {
        let src = repo(&format!("flightdata/c8534like.{ext}"));
        if src.exists() {
            std::fs::copy(src, dir.join(format!("r.{ext}"))).unwrap();
        }
    }
    std::fs::write(
        dir.join("r.meta.json"),
        meta.replace(
            "\"azimuths_per_revolution\": 256",
            "\"azimuths_per_revolution\": 251",
        ),
    )
    .unwrap();
    let o = rotorsim(&["inspect", dir.join("r").to_str().unwrap()]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("r.meta.json") && e.contains("azimuths_per_revolution") && e.contains("256"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_missing_metadata_file_or_record_is_named() {
    let dir = tmp("missing_meta");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::copy(
        repo("flightdata/c8534like.airloads.csv"),
        dir.join("r.airloads.csv"),
    )
    .unwrap();
    let o = rotorsim(&["inspect", dir.join("r").to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("r.meta.json is missing"),
        "{e}"
    );
    let o = rotorsim(&["inspect", dir.join("nothing").to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && e.contains("no such file or record"),
        "{e}"
    );
    // a cause is not printed twice
    let o = rotorsim(&["inspect", dir.join("r.airloads.csv").to_str().unwrap()]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(e.matches("os error 2").count(), 1, "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_warm_start_from_another_discretisation_or_deck_says_so() {
    let dir = tmp("warm_notes");
    std::fs::create_dir_all(&dir).unwrap();
    let (a, b) = (dir.join("a"), dir.join("b"));
    let common = ["run", "--model", "rigid", "--damper", "linear"];
    let o = rotorsim(&[&common[..], &["--out", a.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = rotorsim(
        &[
            &common[..],
            &[
                "--steps-per-rev",
                "128",
                "--set",
                "bearing.lag_loss_factor=0.11",
                "--initial-state",
                a.to_str().unwrap(),
                "--out",
                b.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(b.join("summary.json")).unwrap()).unwrap();
    let msg = s["models"]["linear"]["periodic"]["message"]
        .as_str()
        .unwrap()
        .to_string();
    for m in [&msg, &out.to_string()] {
        assert!(
            m.contains("256 steps per revolution started at 128")
                && m.contains("saved state of other inputs"),
            "{m}"
        );
    }
    // the same inputs: no note
    let c = dir.join("c");
    let o = rotorsim(
        &[
            &common[..],
            &[
                "--initial-state",
                a.to_str().unwrap(),
                "--out",
                c.to_str().unwrap(),
            ],
        ]
        .concat(),
    );
    assert!(o.status.success());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(c.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["models"]["linear"]["periodic"]["message"], "", "{s}");
    // another damper model's state: the structural state only, said so
    let d = dir.join("d");
    let o = rotorsim(&[
        "run",
        "--model",
        "rigid",
        "--damper",
        "nonlinear",
        "--initial-state",
        a.join("linear/periodic_state.json").to_str().unwrap(),
        "--out",
        d.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("note: nonlinear") && out.contains("structural state from the linear model"),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_long_diagnosis_is_never_silent() {
    // 40 s of a 4.3 Hz test sampled at 1 kHz: minutes of fitting; a heartbeat line must come
    // within the heartbeat interval (15 s) and a little
    let dir = tmp("diag_heartbeat");
    std::fs::create_dir_all(&dir).unwrap();
    let mut csv = String::from("time_s,stroke_m,force_N\n");
    for i in 0..40_000 {
        let t = i as f64 * 1e-3;
        let ph = 2.0 * std::f64::consts::PI * 4.3 * t + 0.3;
        // a deterministic pseudo-noise keeps the force from looking clipped
        let noise = 30.0 * ((i as f64 * 12.9898).sin() * 43758.5453).fract();
        csv.push_str(&format!(
            "{t:.4},{:.7e},{:.4}\n",
            1e-3 * ph.sin(),
            3000.0 * ph.cos() + noise
        ));
    }
    let p = dir.join("long.csv");
    std::fs::write(&p, csv).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args([
            "diagnose",
            "--deck",
            repo("flightdata/damper_nominal.toml").to_str().unwrap(),
            "--measured",
            p.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for l in std::io::BufReader::new(stderr)
            .lines()
            .map_while(Result::ok)
        {
            let _ = tx.send(l);
        }
    });
    let t0 = std::time::Instant::now();
    let mut lines = vec![];
    let mut beat = false;
    while t0.elapsed() < std::time::Duration::from_secs(40) && !beat {
        if let Ok(l) = rx.recv_timeout(std::time::Duration::from_millis(200)) {
            beat = l.contains("so far");
            lines.push(l);
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        lines.iter().any(|l| l.contains("40000 samples")),
        "{lines:?}"
    );
    assert!(beat, "no heartbeat within 40 s: {lines:?}");
}
