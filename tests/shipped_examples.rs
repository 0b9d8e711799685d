//! Every shipped example runs: each deck under docs/examples/, rotors/, sweeps/ and flightdata/
//! (TOML files, and flightdata's records) is found by reading the folders, so a deck added later
//! is covered without touching this file, and a deck of no known kind fails the test naming it.
//! Each runs through the binary with the command its docs give, reduced where long (shorter
//! end time, fewer revolutions, cycles or cases), must exit 0 and, where the command writes a
//! result folder, leave manifest.json with `complete: true`.
//!
//! Kinds, by the deck's tables: a model deck (`[[beam]]`, ...) runs each of its `[static]`,
//! `[dynamic]` and `[modes]` analyses (docs/model_deck.md); a rotor deck (`[rotor]`): `expand`,
//! `modes --rotor`, with an `[airframe]` a `stability` map (docs/stability.md), and, with a
//! `[damper]` table, a rigid (not on an airframe: that is the whole rotor) and an elastic `run`
//! of 2 revolutions (docs/run.md; not for an airframe deck without `[aero]`, a ground-resonance
//! deck of no flight record's rotor); a damper deck (`[damper]` alone): `bench`; an actuator deck (`[actuator]`):
//! the dynamic analysis of docs/examples/actuator_pitch_beam.toml with it as the device; a sweep
//! plan (`[base]`/`[vary]`/`[[case]]`): `--emit-slurm` of the whole plan (every case checked) and
//! a local sweep of its first case, 2 revolutions (a stability case: its map) (docs/sweep.md); a flight record (CSV triple
//! or MCAP): `inspect`.
//!
//! Each result (and what `expand` and `inspect` print) must match its golden,
//! tests/golden/examples/<deck>-<what>.txt (tests/golden_support/mod.rs).
//!
//! Time: 24 s wall in release on 2 cores shared with other builds (load ~5), two runs at a time
//! (`JOBS`); the TM-4760 fan plot is 22 s of it, the rest ~1 s each or less.
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

mod golden_support;
mod support;
use support::{read_json, root, tmp};

/// Folders whose decks are shipped examples.
const FOLDERS: [&str; 4] = ["docs/examples", "rotors", "sweeps", "flightdata"];
/// Runs at a time (the rotor runs use up to 3 threads each; the test machine has 2 cores).
const JOBS: usize = 2;
/// End time of the dynamic analyses that run longer [s]: 0.05 s is 500 steps of the actuator
/// examples, past the opening of the entrance orifices (they open linearly over 0.5 s).
const SHORT_END_S: f64 = 0.05;

/// What a command must leave behind.
enum Check {
    /// A result folder whose manifest.json says `complete: true`.
    Folder(PathBuf),
    /// A sweep folder: sweep.csv, and every case folder complete.
    Sweep(PathBuf),
    /// Exit status only (the command writes a script or prints).
    Status,
}

/// One command: arguments (paths absolute), what it must leave behind.
struct Job {
    deck: PathBuf,
    args: Vec<String>,
    check: Check,
}

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// Every deck (TOML, recursively) and flight record (MCAP file, or the stem of a CSV triple
/// `STEM.meta.json`) under the folders.
fn shipped() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().unwrap().to_str().unwrap().to_string();
            if p.is_dir() {
                walk(&p, out);
            } else if name.ends_with(".toml") || name.ends_with(".mcap") {
                out.push(p);
            } else if let Some(stem) = name.strip_suffix(".meta.json") {
                out.push(p.with_file_name(stem));
            }
        }
    }
    let mut v = vec![];
    for f in FOLDERS {
        walk(&root().join(f), &mut v);
    }
    v
}

/// `table` with every relative path string that names a file next to `dir` made absolute (a
/// deck copied elsewhere keeps its device decks and section tables).
fn absolute_paths(v: &mut toml::Value, dir: &Path) {
    match v {
        toml::Value::String(t) => {
            let p = Path::new(t.as_str());
            if p.is_relative() && t.contains('.') && dir.join(p).is_file() {
                *t = s(&dir.join(p));
            }
        }
        toml::Value::Array(a) => a.iter_mut().for_each(|x| absolute_paths(x, dir)),
        toml::Value::Table(t) => t.iter_mut().for_each(|(_, x)| absolute_paths(x, dir)),
        _ => {}
    }
}

/// A copy of the model deck `deck` in `dir`, its paths absolute, edited by `edit`.
fn edited_deck(deck: &Path, dir: &Path, edit: impl FnOnce(&mut toml::Table)) -> PathBuf {
    let text = std::fs::read_to_string(deck).unwrap();
    let mut v = toml::Value::Table(toml::from_str(&text).unwrap());
    absolute_paths(&mut v, deck.parent().unwrap());
    let toml::Value::Table(mut t) = v else {
        unreachable!()
    };
    edit(&mut t);
    let p = dir.join(deck.file_name().unwrap());
    std::fs::write(&p, toml::to_string(&t).unwrap()).unwrap();
    p
}

/// The model deck's `[dynamic]` ended at `SHORT_END_S` if it runs longer.
fn shorten(t: &mut toml::Table) {
    if let Some(toml::Value::Table(d)) = t.get_mut("dynamic") {
        let end = d
            .get("end_time_s")
            .and_then(|v| v.as_float())
            .unwrap_or(0.0);
        if end > SHORT_END_S {
            d.insert("end_time_s".into(), toml::Value::Float(SHORT_END_S));
        }
    }
}

/// The commands that run `deck`, or why there is none.
fn jobs_for(deck: &Path, work: &Path, tag: &str) -> Result<Vec<Job>, String> {
    let name = deck.file_name().unwrap().to_str().unwrap();
    let out = |what: &str| work.join(format!("{tag}-{what}"));
    let job = |args: Vec<String>, check: Check| Job {
        deck: deck.to_path_buf(),
        args,
        check,
    };
    if !name.ends_with(".toml") {
        // a flight record
        return Ok(vec![job(vec!["inspect".into(), s(deck)], Check::Status)]);
    }
    let text = std::fs::read_to_string(deck).map_err(|e| e.to_string())?;
    let t: toml::Table = toml::from_str(&text).map_err(|e| format!("not TOML: {e}"))?;
    let has = |k: &str| t.contains_key(k);
    let mut v = vec![];
    if has("rotor") {
        // the fan plot at the nominal speed only
        let o = out("modes");
        v.push(job(
            vec![
                "modes".into(),
                "--rotor".into(),
                s(deck),
                "--speed-fractions".into(),
                "1".into(),
                "--count".into(),
                "6".into(),
                "--out".into(),
                s(&o),
            ],
            Check::Folder(o),
        ));
        // a hinged-blade deck has no pitch link or damper: only the fan plot reads it
        if !has("hinge") {
            v.push(job(
                vec!["expand".into(), "--rotor".into(), s(deck)],
                Check::Status,
            ));
        }
        if has("airframe") {
            // ground resonance over a few speeds (docs/stability.md)
            let o = out("stability");
            v.push(job(
                vec![
                    "stability".into(),
                    "--rotor".into(),
                    s(deck),
                    "--speeds".into(),
                    "5:40:5".into(),
                    "--out".into(),
                    s(&o),
                ],
                Check::Folder(o),
            ));
        }
        // a rotor on an airframe without aerodynamics is a ground-resonance deck: no flight
        // record is of its rotor
        if has("damper") && !has("hinge") && (has("aero") || !has("airframe")) {
            // a rotor on an airframe is the whole elastic rotor: the rigid reduction is one blade
            let models: &[&str] = if has("airframe") {
                &["uh60a"]
            } else {
                &["rigid", "uh60a"]
            };
            for &model in models {
                let o = out(&format!("run-{model}"));
                v.push(job(
                    vec![
                        "run".into(),
                        "--rotor".into(),
                        s(deck),
                        "--model".into(),
                        model.into(),
                        "--revs".into(),
                        "2".into(),
                        "--out".into(),
                        s(&o),
                    ],
                    Check::Folder(o),
                ));
            }
        }
    } else if has("damper") {
        let o = out("bench");
        v.push(job(
            vec![
                "bench".into(),
                "--damper-deck".into(),
                s(deck),
                "--peak-velocity".into(),
                "1,6".into(),
                "--cycles".into(),
                "2".into(),
                "--out".into(),
                s(&o),
            ],
            Check::Folder(o),
        ));
    } else if has("actuator") {
        let example = root().join("docs/examples/actuator_pitch_beam.toml");
        let dir = out("deck");
        std::fs::create_dir_all(&dir).unwrap();
        let m = edited_deck(&example, &dir, |t| {
            shorten(t);
            let h = t["hydraulic"].as_array_mut().unwrap();
            h[0]["deck"] = toml::Value::String(s(deck));
        });
        let o = out("dynamic");
        v.push(job(
            vec!["dynamic".into(), s(&m), "--out".into(), s(&o)],
            Check::Folder(o),
        ));
    } else if has("base") || has("vary") || has("case") {
        let o = out("slurm");
        v.push(job(
            vec![
                "sweep".into(),
                s(deck),
                "--out".into(),
                s(&o),
                "--emit-slurm".into(),
                s(&work.join(format!("{tag}-job.sh"))),
            ],
            Check::Status,
        ));
        // the first case alone, 2 revolutions
        let mut p = t.clone();
        if let Some(toml::Value::Table(vary)) = p.get_mut("vary") {
            for (_, vals) in vary.iter_mut() {
                if let Some(a) = vals.as_array_mut() {
                    a.truncate(1);
                }
            }
        }
        let product = p.contains_key("vary");
        if let Some(toml::Value::Array(cases)) = p.get_mut("case") {
            if product {
                cases.clear();
            } else {
                cases.truncate(1);
            }
        }
        // a run case 2 revolutions (a stability case is a map: no revolutions)
        if let Some(toml::Value::Table(b)) = p.get_mut("base") {
            if !b.contains_key("stability_speeds") {
                b.insert("revs".into(), toml::Value::Integer(2));
            }
        }
        let plan = work.join(format!("{tag}-plan.toml"));
        std::fs::write(&plan, toml::to_string(&p).unwrap()).unwrap();
        let o = out("sweep");
        v.push(job(
            vec!["sweep".into(), s(&plan), "--out".into(), s(&o)],
            Check::Sweep(o),
        ));
    } else if ["beam", "rigid_body", "joint", "node"]
        .iter()
        .any(|k| has(k))
    {
        for analysis in ["static", "dynamic", "modes"] {
            if !has(analysis) {
                continue;
            }
            let dir = out("deck");
            std::fs::create_dir_all(&dir).unwrap();
            let m = edited_deck(deck, &dir, shorten);
            let o = out(analysis);
            v.push(job(
                vec![analysis.into(), s(&m), "--out".into(), s(&o)],
                Check::Folder(o),
            ));
        }
        if v.is_empty() {
            return Err("a model deck with no [static], [dynamic] or [modes] analysis".into());
        }
    } else {
        return Err(format!(
            "no known way to run it (tables: {:?})",
            t.keys().collect::<Vec<_>>()
        ));
    }
    Ok(v)
}

/// Runs `job` from the package root (sweep plans name decks relative to it); an error names
/// the deck, the command and why.
fn run(job: &Job) -> Result<f64, String> {
    let t0 = Instant::now();
    let mut c = Command::new(golden_support::bin());
    c.current_dir(root()).args(&job.args);
    for v in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_CPUS_PER_TASK",
    ] {
        c.env_remove(v);
    }
    let o = c.output().map_err(|e| e.to_string())?;
    let what = format!(
        "{}: rotorsim {}",
        job.deck.strip_prefix(root()).unwrap_or(&job.deck).display(),
        job.args.join(" ")
    );
    if !o.status.success() {
        return Err(format!(
            "{what}: exit {:?}: {}",
            o.status.code(),
            String::from_utf8_lossy(&o.stderr)
        ));
    }
    let complete = |dir: &Path| {
        let m = dir.join("manifest.json");
        if !m.is_file() {
            return Err(format!("{what}: no {}", m.display()));
        }
        if read_json(&m)["complete"] != serde_json::json!(true) {
            return Err(format!("{what}: {} is not complete", m.display()));
        }
        Ok(())
    };
    // the golden case: the deck's path and what ran (the folder's name without its tag)
    let deck_name = job
        .deck
        .strip_prefix(root())
        .unwrap_or(&job.deck)
        .display()
        .to_string()
        .replace('/', "_");
    let golden = |dir: &Path, what: &str| {
        let work = if matches!(job.check, Check::Status) {
            dir
        } else {
            dir.parent().unwrap()
        };
        let paths = golden_support::Paths::new(dir, work);
        golden_support::check(&format!("examples/{deck_name}-{what}"), dir, &paths)
    };
    let what_of = |dir: &Path| {
        let n = dir.file_name().unwrap().to_str().unwrap();
        n.split_once('-').map_or(n, |(_, w)| w).to_string()
    };
    match &job.check {
        Check::Folder(dir) => {
            complete(dir)?;
            golden(dir, &what_of(dir))?;
        }
        Check::Sweep(dir) => {
            if !dir.join("sweep.csv").is_file() {
                return Err(format!("{what}: no sweep.csv"));
            }
            let cases: Vec<PathBuf> = std::fs::read_dir(dir.join("cases"))
                .map_err(|e| format!("{what}: cases/: {e}"))?
                .map(|e| e.unwrap().path())
                .collect();
            if cases.is_empty() {
                return Err(format!("{what}: no case ran"));
            }
            for c in cases {
                complete(&c)?;
            }
            golden(dir, &what_of(dir))?;
        }
        Check::Status => {
            // what `expand` and `inspect` print is their result
            let sub = job.args[0].as_str();
            if sub == "expand" || sub == "inspect" {
                let dir = std::env::temp_dir().join(format!(
                    "rotorsim-shipped-{}-{deck_name}-{sub}",
                    std::process::id()
                ));
                let _ = std::fs::remove_dir_all(&dir);
                std::fs::create_dir_all(&dir).unwrap();
                std::fs::write(dir.join("stdout.txt"), &o.stdout).unwrap();
                golden(&dir, sub)?;
                let _ = std::fs::remove_dir_all(&dir);
            }
        }
    }
    Ok(t0.elapsed().as_secs_f64())
}

#[test]
fn every_shipped_deck_runs() {
    let t0 = Instant::now();
    let work = tmp("shipped");
    let decks = shipped();
    let mut jobs = vec![];
    let mut failures = vec![];
    for (i, d) in decks.iter().enumerate() {
        match jobs_for(d, &work, &format!("d{i:02}")) {
            Ok(j) => jobs.extend(j),
            Err(e) => failures.push(format!(
                "{}: {e}",
                d.strip_prefix(root()).unwrap_or(d).display()
            )),
        }
    }
    // the folders hold at least the decks the docs name
    for must in [
        "docs/examples/actuator_pitch_beam_B1.53MPa.toml",
        "rotors/uh60a.toml",
        "sweeps/ci_rigid.toml",
        "flightdata/c8534like",
        "flightdata/c8534like.mcap",
    ] {
        assert!(decks.contains(&root().join(must)), "{must} not listed");
    }
    let next = AtomicUsize::new(0);
    let done = Mutex::new(vec![]);
    let failed = Mutex::new(failures);
    std::thread::scope(|sc| {
        for _ in 0..JOBS {
            sc.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = jobs.get(i) else { break };
                match run(job) {
                    Ok(t) => {
                        done.lock()
                            .unwrap()
                            .push(format!("{:6.1} s  {}", t, job.args.join(" ")))
                    }
                    Err(e) => failed.lock().unwrap().push(e),
                }
            });
        }
    });
    for l in done.lock().unwrap().iter() {
        println!("{l}");
    }
    println!(
        "{} decks, {} runs, {:.1} s wall",
        decks.len(),
        jobs.len(),
        t0.elapsed().as_secs_f64()
    );
    let failed = failed.into_inner().unwrap();
    assert!(failed.is_empty(), "{}", failed.join("\n\n"));
    let _ = std::fs::remove_dir_all(&work);
}
