//! Rotor speeds are rad/s in every command (docs/architecture.md, "Names and units"): speeds
//! that look like fractions of the nominal speed are refused naming the option and the nominal
//! in rad/s; fractions only through `modes --speed-fractions`, rpm only through `decay --rpm`,
//! each the same answer as the speed in rad/s.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod support;
use support::tmp;

fn repo(p: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(p)
        .display()
        .to_string()
}

fn rotorsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(args)
        .output()
        .unwrap()
}

fn failed_with(o: &Output, words: &[&str]) {
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{e}");
    for w in words {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
}

#[test]
fn fractions_given_as_rad_s_are_refused_by_name() {
    let out = tmp("cli_units_fractions");
    let o = out.join("s").display().to_string();
    // the silent case: a fraction list given to stability (Hammond's nominal 25 rad/s)
    let r = rotorsim(&[
        "stability",
        "--rotor",
        &repo("rotors/hammond1974.toml"),
        "--speeds",
        "0.5:1.2:0.1",
        "--out",
        &o,
    ]);
    failed_with(&r, &["--speeds", "rad/s", "25", "rotor.omega_rad_s"]);
    assert!(!Path::new(&o).exists());
    // and to its time-domain runs
    let r = rotorsim(&[
        "stability",
        "--rotor",
        &repo("rotors/uh60a_airframe.toml"),
        "--speeds",
        "20:30:5",
        "--time",
        "1",
        "--out",
        &o,
    ]);
    failed_with(&r, &["--time", "27", "rad/s"]);
    let r = rotorsim(&[
        "modes",
        "--rotor",
        &repo("rotors/uh60a.toml"),
        "--speeds",
        "0.5,1",
        "--out",
        &o,
    ]);
    failed_with(&r, &["--speeds", "27", "rad/s"]);
    // one of the two only
    let r = rotorsim(&[
        "modes",
        "--rotor",
        &repo("rotors/uh60a.toml"),
        "--speeds",
        "13.5",
        "--speed-fractions",
        "0.5",
        "--out",
        &o,
    ]);
    assert_eq!(r.status.code(), Some(2));
    assert!(!Path::new(&o).exists());
}

#[test]
fn rad_s_and_fractions_give_the_same_fan() {
    let out = tmp("cli_units_fan");
    let fan = |flag: &str, speeds: &str, name: &str| -> String {
        let dir = out.join(name);
        let o = rotorsim(&[
            "modes",
            "--rotor",
            &repo("rotors/uh60a.toml"),
            flag,
            speeds,
            "--count",
            "6",
            "--out",
            dir.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(dir.join("fan.csv")).unwrap()
    };
    // 13.5 and 27 rad/s are 0.5 and 1 of the nominal 27 rad/s exactly
    assert_eq!(
        fan("--speeds", "13.5,27", "rad_s"),
        fan("--speed-fractions", "0.5,1", "fractions")
    );
}

#[test]
fn decay_takes_rad_s_or_rpm() {
    let out = tmp("cli_units_decay");
    let decay = |speed: &[&str], name: &str| -> String {
        let dir = out.join(name);
        let mut args = vec!["decay", "--rotor"];
        let deck = repo("rotors/tm4760.toml");
        args.push(&deck);
        args.extend_from_slice(speed);
        let d = dir.display().to_string();
        args.extend_from_slice(&["--duration-s", "1.5", "--no-modal", "--out", &d]);
        let o = rotorsim(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        std::fs::read_to_string(dir.join("decay.csv")).unwrap()
    };
    let rad_s = format!("{}", 600.0 * std::f64::consts::PI / 30.0);
    assert_eq!(
        decay(&["--speed-rad-s", &rad_s], "rad_s"),
        decay(&["--rpm", "600"], "rpm")
    );
    let o = rotorsim(&[
        "decay",
        "--rotor",
        &repo("rotors/tm4760.toml"),
        "--speed-rad-s",
        "60",
        "--rpm",
        "600",
        "--out",
        out.join("both").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let o = rotorsim(&[
        "decay",
        "--rotor",
        &repo("rotors/tm4760.toml"),
        "--speed-rad-s",
        "0",
        "--out",
        out.join("neg").to_str().unwrap(),
    ]);
    failed_with(&o, &["--speed-rad-s"]);
}
