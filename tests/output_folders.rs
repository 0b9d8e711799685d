//! Result folders (docs/run.md, "Result folders"): staged and published whole with a
//! manifest.json listing exactly the files present, never mixed with an earlier run's files,
//! published incomplete when the run fails, and locked against a second run into the same
//! folder.
use serde_json::Value;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod support;
use support::{read_json, root, tmp};

fn example() -> PathBuf {
    root().join("flightdata/c8534like")
}

fn rotor() -> PathBuf {
    root().join("rotors/uh60a.toml")
}

/// `rotorsim run --model sdof --revs 3 --periodic march` into `out`, with extra arguments.
fn run_sdof(out: &Path, extra: &[&str]) -> Output {
    let rotor = rotor();
    let flight = example();
    let mut a = vec![
        "run",
        "--model",
        "sdof",
        "--rotor",
        rotor.to_str().unwrap(),
        "--flight",
        flight.to_str().unwrap(),
        "--revs",
        "3",
        "--periodic",
        "march",
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(&a)
        .output()
        .expect("run rotorsim")
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "stdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn sha256(path: &Path) -> String {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// Every file under `dir` (relative, `/`-separated) but the top-level manifest.json.
fn files(dir: &Path) -> Vec<String> {
    fn go(root: &Path, d: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                go(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap();
                let rel: Vec<_> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                out.push(rel.join("/"));
            }
        }
    }
    let mut v = Vec::new();
    go(dir, dir, &mut v);
    v.retain(|f| f != "manifest.json");
    v.sort();
    v
}

/// The manifest of `dir`, checked against the folder: it lists exactly the files present, each
/// with its sha256 and size.
fn checked_manifest(dir: &Path) -> Value {
    let m = read_json(&dir.join("manifest.json"));
    let listed: BTreeMap<String, &Value> = m["outputs"]
        .as_array()
        .expect("outputs")
        .iter()
        .map(|o| (o["path"].as_str().unwrap().to_string(), o))
        .collect();
    assert_eq!(
        listed.keys().cloned().collect::<Vec<_>>(),
        files(dir),
        "manifest outputs vs folder"
    );
    for (rel, o) in &listed {
        let p = dir.join(rel);
        assert_eq!(o["sha256"], sha256(&p), "{rel}");
        assert_eq!(o["size"], std::fs::metadata(&p).unwrap().len(), "{rel}");
    }
    for k in [
        "run_id",
        "start_time",
        "end_time",
        "rotorsim_version",
        "git_commit",
    ] {
        assert!(
            m[k].as_str().is_some_and(|s| !s.is_empty()),
            "{k}: {}",
            m[k]
        );
    }
    assert_eq!(m["rotorsim_version"], env!("CARGO_PKG_VERSION"));
    assert!(m["command_line"].as_array().is_some_and(|a| a.len() > 2));
    for k in ["start_time", "end_time"] {
        let t = m[k].as_str().unwrap();
        assert!(
            t.len() == 24 && t.ends_with('Z') && &t[10..11] == "T",
            "{k}: {t}"
        );
    }
    m
}

/// Names in `dir` (no lock, staging or trash sibling may be left beside a result folder).
fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    v.sort();
    v
}

#[test]
fn a_reused_folder_holds_only_the_new_runs_files() {
    let root = tmp("outfolders-reuse");
    let out = root.join("A");
    ok(&run_sdof(&out, &[]));
    assert!(out.join("nonlinear").is_dir() && out.join("physical").is_dir());
    let first = checked_manifest(&out);
    assert_eq!(first["complete"], true);
    ok(&run_sdof(&out, &["--damper", "linear"]));
    let mut top = names(&out);
    top.retain(|n| n != "manifest.json");
    assert_eq!(
        top,
        ["linear", "report.html", "result.mcap", "summary.json"]
    );
    let m = checked_manifest(&out);
    assert_eq!(m["complete"], true);
    assert!(m["incomplete_reason"].is_null());
    assert_ne!(m["run_id"], first["run_id"]);
    assert!(m["command_line"]
        .as_array()
        .unwrap()
        .iter()
        .any(|a| a == "linear"));
    assert_eq!(names(&root), ["A"]);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_failed_run_is_published_incomplete() {
    let root = tmp("outfolders-failed");
    let out = root.join("F");
    ok(&run_sdof(&out, &[]));
    // RK4 with one sub-step per structural step: the physical model fails (tests/run_pipeline.rs)
    let o = run_sdof(&out, &["--substeps", "1"]);
    assert!(!o.status.success());
    let m = checked_manifest(&out);
    assert_eq!(m["complete"], false);
    assert!(m["incomplete_reason"]
        .as_str()
        .is_some_and(|r| r.contains("physical")));
    let marker = std::fs::read_to_string(out.join("INCOMPLETE")).unwrap();
    assert!(marker.contains("physical"), "{marker}");
    assert!(files(&out).contains(&"INCOMPLETE".to_string()));
    // the earlier run's physical/ is gone, not shown beside the failure
    assert!(!out.join("physical").exists());
    assert_eq!(names(&root), ["F"]);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_held_lock_refuses_and_a_stale_lock_is_taken_over() {
    let root = tmp("outfolders-lock");
    let out = root.join("L");
    ok(&run_sdof(&out, &["--damper", "linear"]));
    let before = read_json(&out.join("manifest.json"));
    let lock = root.join(".L.lock");
    // held: the pid of this test process, which is running
    std::fs::write(&lock, format!("{}\n", std::process::id())).unwrap();
    let o = run_sdof(&out, &["--damper", "nonlinear"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains(out.to_str().unwrap()) && e.contains(&std::process::id().to_string()),
        "{e}"
    );
    assert_eq!(read_json(&out.join("manifest.json")), before);
    assert!(out.join("linear").is_dir() && !out.join("nonlinear").exists());
    assert!(lock.exists(), "the other run's lock is left alone");
    // stale: a pid that is not running
    std::fs::write(&lock, "999999999\n").unwrap();
    ok(&run_sdof(&out, &["--damper", "nonlinear"]));
    assert!(out.join("nonlinear").is_dir() && !out.join("linear").exists());
    checked_manifest(&out);
    assert_eq!(names(&root), ["L"]);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_killed_runs_staging_sibling_is_removed_by_the_next_run() {
    let root = tmp("outfolders-stale");
    let out = root.join("S");
    let stale = root.join(".S.staging-19700101T000000.000Z-1-0");
    std::fs::create_dir_all(&stale).unwrap();
    std::fs::write(stale.join("INCOMPLETE"), "job started, not finished\n").unwrap();
    ok(&run_sdof(&out, &["--damper", "linear"]));
    assert_eq!(names(&root), ["S"]);
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn the_manifest_lists_the_inputs_with_their_sha256() {
    let root = tmp("outfolders-inputs");
    let out = root.join("I");
    ok(&run_sdof(&out, &["--damper", "linear"]));
    let m = checked_manifest(&out);
    let inputs: BTreeMap<String, String> = m["inputs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| {
            (
                i["path"].as_str().unwrap().to_string(),
                i["sha256"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    let stem = example().display().to_string();
    let expected = [
        rotor(),
        PathBuf::from(format!("{stem}.meta.json")),
        PathBuf::from(format!("{stem}.airloads.csv")),
        PathBuf::from(format!("{stem}.damper.csv")),
        // read too: the record's optional measured blade motion
        PathBuf::from(format!("{stem}.motion.csv")),
    ];
    for p in &expected {
        let got = inputs
            .get(&p.display().to_string())
            .unwrap_or_else(|| panic!("{} not in {inputs:?}", p.display()));
        assert_eq!(*got, sha256(p), "{}", p.display());
    }
    assert_eq!(inputs.len(), expected.len(), "{inputs:?}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn git_commit_is_recorded() {
    let root = tmp("outfolders-git");
    let out = root.join("G");
    ok(&run_sdof(&out, &["--damper", "linear"]));
    let m = read_json(&out.join("manifest.json"));
    let c = m["git_commit"].as_str().unwrap();
    assert!(!c.is_empty() && !c.contains(char::is_whitespace), "{c}");
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn a_killed_dynamic_run_leaves_the_earlier_result_whole_and_its_own_visibly_unfinished() {
    // A finished dynamic analysis into D, then a long one into D killed mid-run: D is still
    // the first run's folder, complete and matching its manifest; the killed run's files are
    // only in its staging sibling, marked INCOMPLETE, never beside `"complete": true`.
    let root = tmp("outfolders-killed-dynamic");
    std::fs::create_dir_all(&root).unwrap();
    // the cantilever's section is inline: the deck can be copied anywhere
    let text =
        std::fs::read_to_string(support::root().join("docs/examples/cantilever.toml")).unwrap();
    let short = root.join("short.toml");
    std::fs::write(&short, &text).unwrap();
    let long = root.join("long.toml");
    let long_text = text
        .lines()
        .map(|l| {
            if l.starts_with("end_time_s") {
                "end_time_s = 1.0e5".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert!(long_text.contains("end_time_s = 1.0e5"));
    std::fs::write(&long, long_text).unwrap();
    let out = root.join("D");
    let bin = env!("CARGO_BIN_EXE_rotorsim");
    ok(&Command::new(bin)
        .args([
            "dynamic",
            short.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap());
    let before = checked_manifest(&out);
    assert_eq!(before["complete"], true);
    let mut child = Command::new(bin)
        .args([
            "dynamic",
            long.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // wait until the run has started writing (its staging sibling exists), then kill it
    let t0 = std::time::Instant::now();
    while !names(&root).iter().any(|n| n.starts_with(".D.staging-")) {
        assert!(t0.elapsed().as_secs() < 60, "no staging folder appeared");
        assert!(
            child.try_wait().unwrap().is_none(),
            "the long run ended early"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(std::time::Duration::from_millis(300));
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(
        checked_manifest(&out),
        before,
        "D is the first run's, unchanged"
    );
    let staging: Vec<String> = names(&root)
        .into_iter()
        .filter(|n| n.starts_with(".D.staging-"))
        .collect();
    assert_eq!(staging.len(), 1, "{staging:?}");
    let s = root.join(&staging[0]);
    assert!(s.join("INCOMPLETE").exists());
    if let Ok(summary) = std::fs::read_to_string(s.join("summary.json")) {
        assert!(!summary.contains("\"complete\": true"), "{summary}");
    }
    let _ = std::fs::remove_dir_all(&root);
}
