//! The README's two commands build once: the dev-dependencies switch on no feature of a crate
//! the main build shares, so `cargo test --release` after `cargo run --release` compiles only the
//! test targets (Cargo.toml lists the crates whose features are unified for that reason).
use std::collections::{BTreeMap, BTreeSet};
use std::process::Command;

/// Features of every package in the resolve: (name version) -> the feature lists of its builds.
fn features(edges: Option<&str>) -> BTreeMap<String, BTreeSet<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(env!("CARGO_MANIFEST_DIR")).args([
        "tree",
        "--offline",
        "--prefix",
        "none",
        "-f",
        "{p} [{f}]",
    ]);
    if let Some(e) = edges {
        cmd.args(["-e", e]);
    }
    let o = cmd.output().expect("cargo runs");
    assert!(
        o.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let mut m: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in String::from_utf8_lossy(&o.stdout).lines() {
        let line = line.trim_end_matches(" (*)");
        let (Some(open), Some(close)) = (line.rfind('['), line.rfind(']')) else {
            continue;
        };
        let mut words = line[..open].split_whitespace();
        let (Some(name), Some(version)) = (words.next(), words.next()) else {
            continue;
        };
        m.entry(format!("{name} {version}"))
            .or_default()
            .insert(line[open + 1..close].to_string());
    }
    m
}

#[test]
fn test_build_switches_on_no_feature_of_the_main_build() {
    let main = features(Some("no-dev"));
    let with_tests = features(None);
    assert!(main.len() > 50, "{} packages", main.len());
    let differ: Vec<String> = main
        .iter()
        .filter(|(k, v)| with_tests.get(*k) != Some(v))
        .map(|(k, v)| format!("{k}: {v:?} -> {:?}", with_tests.get(k)))
        .collect();
    assert!(
        differ.is_empty(),
        "the dev-dependencies switch on features the main build does not, so `cargo test` \
         recompiles these and everything above them; add the features to [dependencies]:\n{}",
        differ.join("\n")
    );
}
