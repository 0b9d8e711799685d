//! docs/guide.md runs as written: every command of its ```sh blocks is run here, in order, from
//! the repository root, and must succeed. `rotorsim` in a command is this build's binary, and the
//! guide's `out/...` folders are put in a temporary folder. The guide's first block (the build:
//! `cargo build --release` and the PATH export) is checked to be exactly that and not run: the
//! test harness has just built the binary it runs. Each `--out` folder must then hold a
//! manifest.json, i.e. be a published result folder (a sweep folder: its plan.json).
use std::path::Path;
use std::process::Command;
mod support;
use support::{root, tmp};

const BUILD: [&str; 2] = [
    "cargo build --release",
    "export PATH=\"$PWD/target/release:$PATH\"",
];

/// The commands of each ```sh block (a line ending in `\` continues on the next).
fn sh_blocks(text: &str) -> Vec<Vec<String>> {
    let mut blocks = Vec::new();
    let mut cur: Option<Vec<String>> = None;
    let mut pending = String::new();
    for line in text.lines() {
        let t = line.trim();
        match &mut cur {
            None if t == "```sh" => cur = Some(Vec::new()),
            None => {}
            Some(b) if t == "```" => {
                assert!(pending.is_empty(), "a ```sh block ends in a continuation");
                blocks.push(std::mem::take(b));
                cur = None;
            }
            Some(b) => {
                if t.is_empty() || t.starts_with('#') {
                    continue;
                }
                if let Some(head) = t.strip_suffix('\\') {
                    pending.push_str(head);
                    pending.push(' ');
                } else {
                    pending.push_str(t);
                    b.push(std::mem::take(&mut pending));
                }
            }
        }
    }
    assert!(cur.is_none(), "docs/guide.md: a ```sh block is not closed");
    blocks
}

/// `cmd` with `rotorsim` (as a command word) replaced by `bin` and `out/` by `out`.
fn localize(cmd: &str, bin: &str, out: &Path) -> String {
    let mut words: Vec<String> = Vec::new();
    let mut command_position = true;
    for w in cmd.split(' ') {
        let w2 = if command_position && w == "rotorsim" {
            bin.to_string()
        } else if let Some(rest) = w.strip_prefix("out/") {
            format!("{}/{rest}", out.display())
        } else {
            w.to_string()
        };
        command_position = matches!(w, "||" | "&&" | ";" | "|");
        words.push(w2);
    }
    words.join(" ")
}

#[test]
fn every_command_of_the_guide_runs() {
    let text = std::fs::read_to_string(root().join("docs/guide.md")).unwrap();
    let blocks = sh_blocks(&text);
    assert!(blocks.len() >= 8, "{} ```sh blocks", blocks.len());
    assert_eq!(blocks[0], BUILD, "the guide's first block is the build");
    let out = tmp("guide");
    let bin = env!("CARGO_BIN_EXE_rotorsim");
    let mut outs = Vec::new();
    for cmd in blocks.iter().skip(1).flatten() {
        assert!(
            cmd.starts_with("rotorsim "),
            "a guide command that is not rotorsim: {cmd}"
        );
        let local = localize(cmd, bin, &out);
        let t0 = std::time::Instant::now();
        let o = Command::new("sh")
            .arg("-c")
            .arg(&local)
            .current_dir(root())
            .output()
            .unwrap();
        eprintln!("{cmd}: {:.1} s", t0.elapsed().as_secs_f64());
        assert!(
            o.status.success(),
            "docs/guide.md: `{cmd}` failed ({})\nstdout: {}\nstderr: {}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        let words: Vec<&str> = cmd.split(' ').collect();
        if let Some(i) = words.iter().position(|w| *w == "--out") {
            outs.push(words[i + 1].trim_start_matches("out/").to_string());
        }
    }
    assert!(outs.len() >= 8, "{outs:?}");
    for d in &outs {
        // A sweep folder holds plan.json and one result folder per case.
        assert!(
            out.join(d).join("manifest.json").is_file() || out.join(d).join("plan.json").is_file(),
            "out/{d}: no manifest.json"
        );
    }
    // What the guide tells the reader to open.
    for f in [
        "run/report.html",
        "run/summary.json",
        "run/result.mcap",
        "run/physical/last_rev.csv",
        "bench/peaks.csv",
        "diag/diagnosis.json",
        "diag/extended_deck.toml",
        "sweep/sweep.csv",
        "sweep/sweep.html",
        "fan/fan.svg",
        "fan/fan.csv",
    ] {
        assert!(out.join(f).is_file(), "out/{f} missing");
    }
    let s = support::read_json(&out.join("orifice/summary.json"));
    assert_eq!(
        s["options"]["overrides"].as_array().map(|a| a.len()),
        Some(1),
        "{}",
        s["options"]
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn localize_replaces_the_command_and_the_output_folder() {
    let o = Path::new("/t");
    assert_eq!(
        localize(
            "rotorsim run --rotor rotors/uh60a.toml --out out/a || echo rotorsim",
            "/b/rotorsim",
            o
        ),
        "/b/rotorsim run --rotor rotors/uh60a.toml --out /t/a || echo rotorsim"
    );
    assert_eq!(localize("x || rotorsim run", "B", o), "x || B run");
}
