//! `rotorsim decay`: the TM-4760 lag free decay from the command line (docs/validation_tm4760.md):
//! the files and their columns, the fit and log decrement within 1% of the linearised mode (as
//! tests/rotor_tm4760.rs pins for the library), and bad input named by its flag.
use std::process::{Command, Output};

mod support;
use support::{root, tmp};

fn decay(extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .arg("decay")
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn decay_writes_history_and_summary_beside_the_linearised_mode() {
    let out = tmp("decay_cli_ok");
    let deck = root().join("rotors/tm4760.toml");
    let o = decay(&[
        "--rotor",
        deck.to_str().unwrap(),
        "--rpm",
        "660",
        "--step-s",
        "0.005",
        "--duration-s",
        "6",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let hist = std::fs::read_to_string(out.join("decay.csv")).unwrap();
    let mut lines = hist.lines();
    assert_eq!(lines.next(), Some("time_s,lag_angle_rad,lag_angle_deg"));
    assert_eq!(lines.count(), 1200);
    let sum = std::fs::read_to_string(out.join("decay_summary.csv")).unwrap();
    let rows: Vec<Vec<&str>> = sum.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0], ["method", "frequency_Hz", "damping_ratio"]);
    let get = |name: &str| -> (f64, f64) {
        let r = rows.iter().find(|r| r[0] == name).unwrap();
        (r[1].parse().unwrap(), r[2].parse().unwrap())
    };
    let modal = get("linearised_modal");
    for m in ["damped_sine_fit", "log_decrement"] {
        let (f, z) = get(m);
        assert!(
            (f - modal.0).abs() <= 0.01 * modal.0,
            "{m}: {f} Hz vs {}",
            modal.0
        );
        assert!(
            (z - modal.1).abs() <= 0.01 * modal.1,
            "{m}: {z} vs {}",
            modal.1
        );
    }
    assert!(out.join("manifest.json").exists());
    assert!(stdout.contains("damped-sine fit"), "{stdout}");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn decay_bad_input_names_the_flag() {
    let deck = root().join("rotors/tm4760.toml");
    let d = deck.to_str().unwrap();
    let out = tmp("decay_cli_bad");
    let o = out.to_str().unwrap();
    let other = root().join("rotors/uh60a.toml");
    let cases: [(Vec<&str>, &str); 5] = [
        (vec!["--rotor", d, "--step-s=-1", "--out", o], "--step-s"),
        (
            vec!["--rotor", d, "--duration-s", "0.5", "--out", o],
            "--duration-s",
        ),
        (vec!["--rotor", d, "--rpm", "0", "--out", o], "--rpm"),
        (
            vec!["--rotor", other.to_str().unwrap(), "--out", o],
            "not a hinged-blade deck",
        ),
        (vec!["--rotor", "no_such_deck.toml", "--out", o], "--rotor"),
    ];
    for (args, want) in cases {
        let r = decay(&args);
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn decay_without_the_mode_marches_the_same_history() {
    let deck = root().join("rotors/tm4760.toml");
    let run = |name: &str, extra: &[&str]| {
        let out = tmp(name);
        let o = out.to_str().unwrap();
        let mut args = vec![
            "--rotor",
            deck.to_str().unwrap(),
            "--duration-s",
            "1.5",
            "--out",
            o,
        ];
        args.extend_from_slice(extra);
        let r = decay(&args);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let hist = std::fs::read_to_string(out.join("decay.csv")).unwrap();
        let sum = std::fs::read_to_string(out.join("decay_summary.csv")).unwrap();
        let _ = std::fs::remove_dir_all(&out);
        (hist, sum)
    };
    let (h_with, s_with) = run("decay_cli_modal", &[]);
    let (h_without, s_without) = run("decay_cli_no_modal", &["--no-modal"]);
    assert_eq!(h_with, h_without, "the mode changed the march");
    assert!(s_with.contains("linearised_modal,"), "{s_with}");
    assert!(!s_without.contains("linearised_modal"), "{s_without}");
    // the decay's own estimates are those of the run with the mode
    let rows = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| !l.starts_with("linearised_modal"))
            .map(String::from)
            .collect()
    };
    assert_eq!(rows(&s_with), rows(&s_without));
}
