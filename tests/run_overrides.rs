//! `rotorsim run --set KEY=VALUE`: an override moves only what it addresses, is recorded in
//! summary.json and the manifest, and a bad one is refused naming the key.
use std::path::Path;
use std::process::{Command, Output};
mod support;
use support::{read_json, root, tmp};

fn run(out: &Path, extra: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(root())
        .args(["run", "--model", "rigid", "--revs", "20", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn a_physical_damper_key_leaves_the_dashpots_unchanged() {
    let d = tmp("overrides");
    let (a, b) = (d.join("nominal"), d.join("orifice"));
    ok(&run(&a, &[]));
    ok(&run(&b, &["--set", "damper.physical.A_orf_m2=2.0e-6"]));
    for m in ["linear", "nonlinear"] {
        let x = std::fs::read(a.join(m).join("last_rev.csv")).unwrap();
        let y = std::fs::read(b.join(m).join("last_rev.csv")).unwrap();
        assert!(x == y, "{m}: last_rev.csv changed by a physical-damper key");
        let (sa, sb) = (
            read_json(&a.join("summary.json")),
            read_json(&b.join("summary.json")),
        );
        assert_eq!(sa["models"][m]["metrics"], sb["models"][m]["metrics"]);
    }
    let x = std::fs::read(a.join("physical/last_rev.csv")).unwrap();
    let y = std::fs::read(b.join("physical/last_rev.csv")).unwrap();
    assert!(x != y, "the physical damper did not change");
    let s = read_json(&b.join("summary.json"));
    assert_eq!(
        s["options"]["overrides"][0]["key"],
        "damper.physical.A_orf_m2"
    );
    assert_eq!(
        s["options"]["overrides"][0]["value"]
            .as_str()
            .unwrap()
            .parse::<f64>()
            .unwrap(),
        2.0e-6
    );
    let m = read_json(&b.join("manifest.json"));
    let cl = m["command_line"].to_string();
    assert!(cl.contains("damper.physical.A_orf_m2=2.0e-6"), "{cl}");
}

#[test]
fn a_bad_override_is_refused_naming_the_key() {
    let d = tmp("overrides-bad");
    for (set, want) in [
        ("damper.physical.A_orf_m=2e-6", "damper.physical.A_orf_m"),
        ("damper.physical.A_orf_m2=abc", "expected a number"),
        ("damper.physical.A_orf_m2=-1", "damper.physical.A_orf_m2"),
        ("rotor.blades=2.5", "expected an integer"),
        ("rotor.bladez=2", "bladez"),
        ("rotor.radius_m.x=2", "rotor.radius_m"),
    ] {
        let out = d.join("x");
        let o = run(&out, &["--set", set]);
        assert!(!o.status.success(), "{set} accepted");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(want), "{set}: {e}");
        assert!(e.contains("--set"), "{set}: {e}");
        assert!(!e.contains("panicked"), "{set}: {e}");
        assert!(!out.exists(), "{set}: an output folder was written");
    }
}
