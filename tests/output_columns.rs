//! No CSV that a command writes has two columns of the same name (a join on names would pick
//! one silently). Every command that writes CSV, on quick inputs, all damper models.
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;

mod support;
use support::tmp;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn csv_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            csv_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "csv") {
            out.push(p);
        }
    }
}

#[test]
fn no_output_csv_has_duplicate_column_names() {
    let out = tmp("columns");
    let o = |name: &str| out.join(name).display().to_string();
    let deck = repo("docs/examples/cantilever.toml").display().to_string();
    let rotor = repo("rotors/uh60a.toml").display().to_string();
    let rec = repo("flightdata/c8534like").display().to_string();
    let runs: Vec<Vec<String>> = [
        vec!["static", &deck, "--out", &o("static")],
        vec!["dynamic", &deck, "--out", &o("dynamic")],
        vec!["modes", &deck, "--out", &o("modes")],
        vec!["convert", &rec, &o("convert/rec")],
        vec![
            "bench",
            "--deck",
            &rotor,
            "--damper",
            "all",
            "--peak-velocity",
            "1",
            "--cycles",
            "2",
            "--out",
            &o("bench"),
        ],
        vec![
            "run",
            "--model",
            "rigid",
            "--rotor",
            &rotor,
            "--flight",
            &rec,
            "--revs",
            "3",
            "--periodic",
            "march",
            "--out",
            &o("rigid"),
        ],
        vec![
            "run",
            "--model",
            "sdof",
            "--rotor",
            &rotor,
            "--flight",
            &rec,
            "--revs",
            "3",
            "--periodic",
            "march",
            "--out",
            &o("sdof"),
        ],
        vec![
            "run",
            "--rotor",
            &rotor,
            "--flight",
            &rec,
            "--revs",
            "2",
            "--periodic",
            "march",
            "--steps-per-rev",
            "64",
            "--substeps",
            "100",
            "--out",
            &o("uh60a"),
        ],
    ]
    .iter()
    .map(|v| v.iter().map(|s| s.to_string()).collect())
    .collect();
    for args in &runs {
        let r = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .args(args)
            .output()
            .unwrap();
        assert!(
            r.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    let mut files = vec![];
    csv_files(&out, &mut files);
    assert!(files.len() >= 10, "{} CSV files", files.len());
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let header = text
            .lines()
            .find(|l| !l.starts_with('#'))
            .unwrap_or_default();
        let mut seen = HashSet::new();
        for c in header.split(',') {
            assert!(seen.insert(c), "{}: column `{c}` twice", f.display());
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// Reads a CSV written by rotorsim: header and rows of strings.
fn read(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut rd = csv::Reader::from_path(path).unwrap();
    let h = rd.headers().unwrap().iter().map(String::from).collect();
    let rows = rd
        .records()
        .map(|r| r.unwrap().iter().map(String::from).collect())
        .collect();
    (h, rows)
}

#[test]
fn all_revs_ends_with_last_rev_channel_for_channel() {
    // The elastic model with its load channels (the equilibrium check's are dropped from the
    // outputs after the run, the hub's fixed-frame loads added, the physical damper's sub-step
    // envelopes moved last): the last revolution of all_revs.csv is last_rev.csv, every
    // channel by its name, to the last digit written.
    let out = tmp("all_revs_columns");
    let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(repo(""))
        .args([
            "run",
            "--damper",
            "all",
            "--revs",
            "2",
            "--periodic",
            "march",
            "--write-all-revs",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for model in ["linear", "nonlinear", "physical"] {
        let (hl, last) = read(&out.join(model).join("last_rev.csv"));
        let (ha, all) = read(&out.join(model).join("all_revs.csv"));
        assert_eq!(all.len(), 2 * last.len());
        let tail = &all[all.len() - last.len()..];
        let mut compared = 0;
        for (j, name) in hl.iter().enumerate() {
            if name.starts_with("measured_") {
                continue;
            }
            let i = ha
                .iter()
                .position(|c| c == name)
                .unwrap_or_else(|| panic!("{model}: all_revs.csv has no column {name}"));
            for (k, row) in last.iter().enumerate() {
                assert_eq!(tail[k][i], row[j], "{model}: {name}, sample {k}");
            }
            compared += 1;
        }
        // all_revs adds the revolution and the shooting iterate
        assert_eq!(compared + 2, ha.len(), "{model}: {ha:?}");
        assert!(hl.iter().any(|c| c == "hub_mz_fixed_Nm"));
    }
    let _ = std::fs::remove_dir_all(out);
}
