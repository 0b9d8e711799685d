//! The README holds: its commands run as written (every command of the table names a real
//! subcommand, options that subcommand has and files that exist), its links resolve, no
//! paragraph is longer than eight lines, the quick start's test command is CI's, and the minimum
//! Rust version it names is Cargo.toml's.
use std::path::PathBuf;
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn readme() -> String {
    std::fs::read_to_string(repo().join("README.md")).unwrap()
}

/// The `cargo run --release -- ...` commands of the README, as argument lists.
fn commands(text: &str) -> Vec<Vec<String>> {
    let prefix = "cargo run --release -- ";
    let mut out = vec![];
    for span in text.split('`').skip(1).step_by(2) {
        if let Some(rest) = span.strip_prefix(prefix) {
            out.push(rest.split_whitespace().map(String::from).collect());
        }
    }
    out
}

#[test]
fn every_command_names_a_subcommand_its_options_and_existing_files() {
    let text = readme();
    // One way to call the binary: no bare `rotorsim ...` command line.
    for span in text.split('`').skip(1).step_by(2) {
        assert!(
            !span.starts_with("rotorsim "),
            "README calls a bare `{span}`: the binary is not on PATH; use cargo run --release --"
        );
    }
    let cmds = commands(&text);
    assert!(cmds.len() >= 8, "{} commands", cmds.len());
    for args in &cmds {
        let sub = &args[0];
        if sub == "help" {
            continue;
        }
        let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .args([sub.as_str(), "--help"])
            .output()
            .unwrap();
        assert!(o.status.success(), "`{sub}` is not a rotorsim command");
        let help = String::from_utf8_lossy(&o.stdout);
        for a in &args[1..] {
            if a.starts_with("--") {
                let flag = a.split('=').next().unwrap();
                assert!(
                    help.contains(&format!("{flag} ")) || help.contains(&format!("{flag}\n")),
                    "`{}`: {sub} has no option {flag}",
                    args.join(" ")
                );
            } else if ["rotors/", "flightdata/", "sweeps/"]
                .iter()
                .any(|p| a.starts_with(p))
            {
                let p = repo().join(a);
                let stem_ok = p.with_extension("meta.json").exists();
                assert!(p.exists() || stem_ok, "`{}`: no file {a}", args.join(" "));
            }
        }
    }
}

#[test]
fn links_resolve_paragraphs_are_short_and_the_quick_start_is_ci() {
    let text = readme();
    for part in text.split("](").skip(1) {
        let target = &part[..part.find(')').unwrap()];
        assert!(
            repo().join(target).exists(),
            "README links to missing {target}"
        );
    }
    let mut run = 0;
    for line in text.lines() {
        let prose = !line.trim().is_empty()
            && !line.starts_with('|')
            && !line.starts_with('#')
            && !line.starts_with("```");
        // a list item starts a paragraph of its own
        run = match (prose, line.starts_with("- ")) {
            (false, _) => 0,
            (true, true) => 1,
            (true, false) => run + 1,
        };
        assert!(run <= 8, "a README paragraph runs over 8 lines, at: {line}");
    }
    let quick = &text[text.find("## Quick start").unwrap()..];
    let block = &quick[quick.find("```sh").unwrap() + 5..];
    let block: Vec<&str> = block[..block.find("```").unwrap()]
        .lines()
        .filter(|l| !l.trim().is_empty())
        .collect();
    assert_eq!(block.len(), 2, "the quick start is two commands: {block:?}");
    let ci = std::fs::read_to_string(repo().join(".ci/run")).unwrap();
    assert!(
        ci.lines().any(|l| l.trim() == block[1]),
        "CI runs the README's test command `{}`",
        block[1]
    );
    let manifest = std::fs::read_to_string(repo().join("Cargo.toml")).unwrap();
    let msrv = manifest
        .lines()
        .find_map(|l| l.strip_prefix("rust-version = \""))
        .map(|v| v.trim_end_matches('"'))
        .expect("Cargo.toml states rust-version");
    assert!(
        text.contains(&format!("Rust {msrv} or newer")),
        "README names the minimum Rust version {msrv}"
    );
}
