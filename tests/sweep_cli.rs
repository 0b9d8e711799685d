//! `rotorsim sweep`: a bad plan is refused before any case runs, naming the plan file and the
//! key; a local sweep equals its shards merged and is the same at 1 and 2 jobs (wall times
//! aside); completed cases are skipped on resume, failed ones kept until `--retry-failed`.
use std::path::Path;
use std::process::{Command, Output};
mod support;
use support::{root, tmp};

fn sweep(args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_rotorsim"));
    c.current_dir(root()).arg("sweep").args(args);
    for v in [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_COUNT",
        "SLURM_CPUS_PER_TASK",
    ] {
        c.env_remove(v);
    }
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn ok(o: &Output) -> String {
    assert!(
        o.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// sweep.csv without the wall-time column.
fn table(dir: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(dir.join("sweep.csv")).unwrap();
    let rows: Vec<Vec<String>> = text
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    let w = rows[0].iter().position(|c| c == "wall_time_s").unwrap();
    rows.into_iter()
        .map(|mut r| {
            r.remove(w);
            r
        })
        .collect()
}

const PLAN: &str = "sweeps/ci_rigid.toml";

#[test]
fn a_bad_plan_is_refused_before_any_case_runs() {
    let d = tmp("sweep-bad");
    for (name, text, key) in [
        ("unknown.toml", "[vary]\nbogus = [1, 2]\n", "bogus"),
        (
            "unit.toml",
            "[base]\nmodel = \"rigid\"\n[vary]\n\"damper.physical.A_orf_mm2\" = [1e-6]\n",
            "damper.physical.A_orf_mm2",
        ),
        (
            "type.toml",
            "[base]\nmodel = \"rigid\"\n[vary]\n\"damper.physical.A_orf_m2\" = [\"big\"]\n",
            "damper.physical.A_orf_m2",
        ),
        ("revs.toml", "[vary]\nrevs = [10, \"x\"]\n", "revs"),
        (
            "record.toml",
            "[base]\nmodel = \"rigid\"\n[vary]\nflight = [\"flightdata/c8534like\", \"flightdata/nope\"]\n",
            "flightdata/nope",
        ),
        (
            "blank.toml",
            "[base]\nmodel = \"rigid\"\n[vary]\nrotor = [\"rotors/uh60a.toml\", \"\"]\n",
            "`rotor` is empty (expected a file path)",
        ),
        ("empty.toml", "[base]\nmodel = \"rigid\"\n[vary]\n", "[vary]"),
        ("none.toml", "[base]\nmodel = \"rigid\"\n", "[vary]"),
    ] {
        let plan = d.join(name);
        std::fs::write(&plan, text).unwrap();
        let out = d.join(format!("out-{name}"));
        let o = sweep(
            &[plan.to_str().unwrap(), "--out", out.to_str().unwrap()],
            &[],
        );
        assert!(!o.status.success(), "{name} accepted");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(name), "{name}: the plan file is not named: {e}");
        assert!(e.contains(key), "{name}: the key is not named: {e}");
        assert!(!e.contains("panicked"), "{name}: {e}");
        assert!(!out.exists(), "{name}: a case ran or the folder was made");
    }
}

#[test]
fn shards_merged_equal_a_local_sweep_at_any_job_count() {
    let d = tmp("sweep-shards");
    let (one, two, sh) = (d.join("one"), d.join("two"), d.join("sharded"));
    ok(&sweep(
        &[PLAN, "--out", one.to_str().unwrap(), "--jobs", "1"],
        &[],
    ));
    ok(&sweep(
        &[PLAN, "--out", two.to_str().unwrap(), "--jobs", "2"],
        &[],
    ));
    assert_eq!(table(&one), table(&two));
    let t = table(&one);
    assert_eq!(t.len(), 1 + 4 * 3, "one row per case and damper model");
    assert!(t[1..].iter().all(|r| r.contains(&"ok".to_string())));
    // shard 1 from the command line, shard 0 from Slurm's environment
    ok(&sweep(
        &[PLAN, "--out", sh.to_str().unwrap(), "--shard", "1/2"],
        &[],
    ));
    let c = std::fs::read_dir(sh.join("cases")).unwrap().count();
    assert_eq!(c, 2, "a shard writes only its own case folders");
    assert!(!sh.join("sweep.csv").exists());
    ok(&sweep(
        &[PLAN, "--out", sh.to_str().unwrap()],
        &[
            ("SLURM_ARRAY_TASK_ID", "0"),
            ("SLURM_ARRAY_TASK_COUNT", "2"),
        ],
    ));
    ok(&sweep(&["merge", sh.to_str().unwrap()], &[]));
    assert_eq!(table(&sh), t);
    let html = std::fs::read_to_string(sh.join("sweep.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("damper.physical.A_orf_m2"));
    // the emitted array script runs the shards of the plan
    let script = d.join("job.sh");
    let em = d.join("emitted");
    ok(&sweep(
        &[
            PLAN,
            "--out",
            em.to_str().unwrap(),
            "--emit-slurm",
            script.to_str().unwrap(),
        ],
        &[],
    ));
    let s = std::fs::read_to_string(&script).unwrap();
    assert!(s.contains("#SBATCH --array=0-1"), "{s}");
    assert!(s.contains("--shard \"${SLURM_ARRAY_TASK_ID}/2\""), "{s}");
    assert!(em.join("plan.json").exists());
}

#[test]
fn completed_cases_are_skipped_and_failed_ones_kept_until_retried() {
    let d = tmp("sweep-resume");
    let out = d.join("s");
    let o = out.to_str().unwrap();
    ok(&sweep(&[PLAN, "--out", o], &[]));
    let before = table(&out);
    let again = ok(&sweep(&[PLAN, "--out", o], &[]));
    assert!(again.contains("0 run now"), "{again}");
    assert!(again.contains("4 already complete"), "{again}");
    // mark c001 failed as a run that did not finish would leave it
    let m = out.join("cases/c001/manifest.json");
    let text = std::fs::read_to_string(&m).unwrap();
    std::fs::write(
        &m,
        text.replace("\"complete\": true", "\"complete\": false"),
    )
    .unwrap();
    let kept = sweep(&[PLAN, "--out", o], &[]);
    assert!(!kept.status.success(), "a failed case must fail the sweep");
    let so = String::from_utf8_lossy(&kept.stdout);
    assert!(so.contains("c001"), "{so}");
    assert!(so.contains("--retry-failed"), "{so}");
    let retried = ok(&sweep(&[PLAN, "--out", o, "--retry-failed"], &[]));
    assert!(retried.contains("1 run now"), "{retried}");
    assert_eq!(table(&out), before);
    // another plan into the same folder is refused
    let other = d.join("other.toml");
    std::fs::write(
        &other,
        "[base]\nmodel = \"rigid\"\nrevs = 10\n[vary]\nsubsteps = [5]\n",
    )
    .unwrap();
    let o2 = sweep(&[other.to_str().unwrap(), "--out", o], &[]);
    assert!(!o2.status.success());
    assert!(String::from_utf8_lossy(&o2.stderr).contains("another plan"));
}

#[test]
fn a_case_that_must_be_periodic_and_is_not_is_kept_failed_until_retried() {
    // require_periodic with 2 revolutions: no case reaches the tolerance. Each case folder is
    // published complete (its best revolution), but the sweep fails, and a resume keeps the
    // cases as failed, with the reason, until --retry-failed runs them again.
    let d = tmp("sweep-not-periodic");
    std::fs::create_dir_all(&d).unwrap();
    let plan = d.join("np.toml");
    std::fs::write(
        &plan,
        "[base]\nmodel = \"rigid\"\ndamper = \"linear\"\nrevs = 2\nrequire_periodic = true\n[vary]\nsubsteps = [5, 6]\n",
    )
    .unwrap();
    let (p, out) = (plan.to_str().unwrap(), d.join("s"));
    let o = out.to_str().unwrap();
    let first = sweep(&[p, "--out", o], &[]);
    assert!(!first.status.success());
    let again = sweep(&[p, "--out", o], &[]);
    assert!(!again.status.success());
    let so = String::from_utf8_lossy(&again.stdout);
    assert!(so.contains("0 run now"), "{so}");
    assert!(so.contains("not periodic (require_periodic)"), "{so}");
    let retried = sweep(&[p, "--out", o, "--retry-failed"], &[]);
    let so = String::from_utf8_lossy(&retried.stdout);
    assert!(so.contains("2 run now"), "{so}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The rows of sweep.csv of case `id`.
fn rows_of(t: &[Vec<String>], id: &str) -> Vec<Vec<String>> {
    t.iter().filter(|r| r[0] == id).cloned().collect()
}

#[test]
fn a_case_folder_that_does_not_match_its_manifest_is_never_merged() {
    let d = tmp("sweep-tamper");
    let out = d.join("s");
    let o = out.to_str().unwrap();
    ok(&sweep(&[PLAN, "--out", o], &[]));
    let good = table(&out);
    let case = |id: &str| out.join("cases").join(id);
    // c002's summary.json replaced by c001's; c003's manifest garbage; a file of c004 deleted
    std::fs::copy(
        case("c001").join("summary.json"),
        case("c002").join("summary.json"),
    )
    .unwrap();
    std::fs::write(case("c003").join("manifest.json"), "garbage").unwrap();
    std::fs::remove_file(case("c004").join("linear/last_rev.csv")).unwrap();
    let m = sweep(&["merge", o], &[]);
    assert!(!m.status.success(), "a merge of damaged cases must fail");
    let so = String::from_utf8_lossy(&m.stdout);
    assert!(
        so.contains("failed: c002: summary.json size differs from its manifest"),
        "{so}"
    );
    assert!(so.contains("file changed after the run"), "{so}");
    assert!(
        so.contains("failed: c003: manifest.json is not a manifest (not JSON"),
        "{so}"
    );
    assert!(
        so.contains("failed: c004: linear/last_rev.csv is listed in its manifest but missing"),
        "{so}"
    );
    let t = table(&out);
    assert_eq!(rows_of(&t, "c001"), rows_of(&good, "c001"));
    for id in ["c002", "c003", "c004"] {
        let r = rows_of(&t, id);
        assert_eq!(r.len(), 1, "{id}: one row without results");
        assert!(r[0].contains(&"failed".to_string()), "{id}: {:?}", r[0]);
        let numbers = r[0]
            .iter()
            .skip(1 + 2 + 2)
            .filter(|v| !v.is_empty())
            .count();
        assert_eq!(
            numbers, 0,
            "{id}: a damaged case's numbers were merged: {:?}",
            r[0]
        );
    }
    // the whole folder of c001 (manifest and all) in place of c002's: consistent with its
    // manifest, but not c002's settings
    std::fs::remove_dir_all(case("c002")).unwrap();
    let cp = std::process::Command::new("cp")
        .args(["-r"])
        .arg(case("c001"))
        .arg(case("c002"))
        .status()
        .unwrap();
    assert!(cp.success());
    let m = sweep(&["merge", o], &[]);
    assert!(!m.status.success());
    let so = String::from_utf8_lossy(&m.stdout);
    assert!(
        so.contains("failed: c002: summary.json is of another case"),
        "{so}"
    );
    assert!(so.contains("damper.physical.A_orf_m2 = 0.0000018"), "{so}");
    // c001's manifest gone (a run killed before it published): a folder no run would replace
    std::fs::remove_file(case("c001").join("manifest.json")).unwrap();
    // a resume keeps them failed, by id and reason; --retry-failed runs them again (clearing
    // the sweep's own folder that cannot be verified)
    let kept = sweep(&[PLAN, "--out", o], &[]);
    assert!(!kept.status.success());
    let so = String::from_utf8_lossy(&kept.stdout);
    assert!(so.contains("0 run now"), "{so}");
    assert!(so.contains("c003: manifest.json is not a manifest"), "{so}");
    assert!(so.contains("c001: manifest.json missing"), "{so}");
    let retried = ok(&sweep(&[PLAN, "--out", o, "--retry-failed"], &[]));
    assert!(retried.contains("4 run now"), "{retried}");
    assert_eq!(table(&out), good);
    ok(&sweep(&["merge", o], &[]));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_second_sweep_into_a_locked_folder_is_refused_and_a_stale_lock_taken_over() {
    let d = tmp("sweep-lock");
    std::fs::create_dir_all(&d).unwrap();
    let plan = d.join("one.toml");
    std::fs::write(
        &plan,
        "[base]\nmodel = \"rigid\"\ndamper = \"linear\"\nrevs = 2\n[vary]\nsubsteps = [5]\n",
    )
    .unwrap();
    let (p, out) = (plan.to_str().unwrap(), d.join("s"));
    let o = out.to_str().unwrap();
    std::fs::create_dir_all(&out).unwrap();
    // held by a running process (this test)
    let lock = out.join(".sweep.lock");
    std::fs::write(&lock, format!("{}\n", std::process::id())).unwrap();
    let r = sweep(&[p, "--out", o], &[]);
    assert!(!r.status.success(), "a sweep into a locked folder ran");
    let e = String::from_utf8_lossy(&r.stderr);
    assert!(e.contains(".sweep.lock"), "{e}");
    assert!(e.contains(&format!("pid {}", std::process::id())), "{e}");
    assert!(
        !out.join("cases/c001").exists(),
        "a case ran under another's lock"
    );
    // a shard of the locked sweep is refused too
    let r = sweep(&[p, "--out", o, "--shard", "0/1"], &[]);
    assert!(!r.status.success());
    // left by a killed sweep: taken over, with a note
    std::fs::write(&lock, "999999999\n").unwrap();
    let r = sweep(&[p, "--out", o], &[]);
    let e = String::from_utf8_lossy(&r.stderr);
    assert!(e.contains("took over the stale lock file"), "{e}");
    assert!(e.contains("pid 999999999"), "{e}");
    assert!(out.join("cases/c001/manifest.json").exists());
    assert!(!lock.exists(), "the lock outlived its sweep");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_case_that_fails_at_run_time_names_the_deck_key_and_value() {
    // a density that passes the deck's validation but makes the hydraulics blow up
    let d = tmp("sweep-run-failure");
    std::fs::create_dir_all(&d).unwrap();
    let plan = d.join("rho.toml");
    std::fs::write(
        &plan,
        "[base]\nmodel = \"rigid\"\ndamper = \"physical\"\nrevs = 3\n[vary]\n\"damper.physical.rho_kg_m3\" = [1.0e-9]\n",
    )
    .unwrap();
    let out = d.join("s");
    let r = sweep(
        &[plan.to_str().unwrap(), "--out", out.to_str().unwrap()],
        &[],
    );
    assert!(!r.status.success());
    let so = String::from_utf8_lossy(&r.stdout);
    let line = so
        .lines()
        .find(|l| l.starts_with("failed: c001"))
        .unwrap_or_default();
    assert!(
        line.contains("damper.physical.rho_kg_m3 = 1e-9 in deck rotors/uh60a.toml"),
        "{so}"
    );
    let reason = std::fs::read_to_string(out.join("cases/c001/INCOMPLETE")).unwrap();
    assert!(
        reason.contains("damper.physical.rho_kg_m3 = 1e-9"),
        "{reason}"
    );
    let m: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("cases/c001/manifest.json")).unwrap(),
    )
    .unwrap();
    assert!(m["incomplete_reason"]
        .as_str()
        .unwrap()
        .contains("in deck rotors/uh60a.toml"));
    let _ = std::fs::remove_dir_all(&d);
}

/// A stability sweep: each case is the ground-resonance map of its deck values; sweep.csv's
/// least damping ratio equals the map's computed directly (the library call the command
/// makes), and an option of a run is refused in a stability case before anything runs.
#[test]
fn a_stability_sweep_tables_each_cases_least_damping() {
    let dir = tmp("sweep_stability");
    let plan = dir.join("plan.toml");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        &plan,
        "[base]\nrotor = \"rotors/uh60a_airframe.toml\"\ndamper = \"linear\"\nstability_speeds = \"20:34:2\"\n\n[vary]\n\"damper.linear.c_N_s_per_m\" = [0.0, 68000.0]\n",
    )
    .unwrap();
    let out = dir.join("out");
    ok(&sweep(
        &[plan.to_str().unwrap(), "--out", out.to_str().unwrap()],
        &[],
    ));
    let rows = table(&out);
    let col = |name: &str| rows[0].iter().position(|c| c == name).unwrap();
    let (z, stable, status) = (col("min_damping_ratio"), col("stable"), col("status"));
    assert_eq!(rows.len(), 3);
    let speeds: Vec<f64> = (0..8).map(|k| 20.0 + 2.0 * k as f64).collect();
    for (row, c) in rows[1..].iter().zip(["0", "68000"]) {
        assert_eq!(row[status], "ok");
        let set = rotorsim::overrides::Override::parse(&format!("damper.linear.c_N_s_per_m={c}"))
            .unwrap();
        let deck = rotorsim::rotor::RotorDeck::from_file_with(
            &root().join("rotors/uh60a_airframe.toml"),
            &[set],
        )
        .unwrap();
        let map = rotorsim::resonance::stability_map(
            &deck,
            rotorsim::hydraulics::DamperModel::Linear,
            &speeds,
        )
        .unwrap();
        let (want, _, _) = map.min_damping().unwrap();
        let got: f64 = row[z].parse().unwrap();
        assert_eq!(got, want, "c = {c}");
        assert_eq!(row[stable], map.unstable.is_empty().to_string());
    }
    // the damper adds damping to the least damped mode
    let least = |r: &Vec<String>| r[z].parse::<f64>().unwrap();
    assert!(least(&rows[2]) > least(&rows[1]), "{rows:?}");

    std::fs::write(
        &plan,
        "[base]\nrotor = \"rotors/uh60a_airframe.toml\"\nstability_speeds = \"20:34:2\"\nrevs = 3\n\n[vary]\n\"damper.linear.c_N_s_per_m\" = [0.0]\n",
    )
    .unwrap();
    let o = sweep(
        &[
            plan.to_str().unwrap(),
            "--out",
            dir.join("bad").to_str().unwrap(),
        ],
        &[],
    );
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("revs") && e.contains("not an option of a stability case"),
        "{e}"
    );
}

struct Quiet;
impl rotorsim::sweep::SweepProgress for Quiet {
    fn start(&self, _: usize, _: usize) {}
    fn case_done(&self, _: &rotorsim::sweep::Case, _: &Result<(), String>, _: f64) {}
}

#[test]
fn a_stopped_sweep_starts_no_case_and_leaves_them_to_run() {
    use rotorsim::run::stop::STOPPED_PREFIX;
    use rotorsim::sweep::job::SweepJob;
    let d = tmp("sweep-stopped");
    let job = SweepJob {
        jobs: Some(2),
        ..SweepJob::new(root().join(PLAN), d.join("s"))
    };
    // cargo runs the tests from the package root, where the plan's paths resolve
    let plan = job.read_plan().unwrap();
    job.stop.request();
    let o = job.execute(&plan, &|_, _| {}, &Quiet, &mut |_| {}).unwrap();
    assert_eq!(o.report.ran.len(), 4);
    for (id, r) in &o.report.ran {
        let e = r.as_ref().unwrap_err();
        assert!(e.starts_with(STOPPED_PREFIX), "{id}: {e}");
        assert!(e.contains(&format!("case {id} not started")), "{e}");
        assert!(!d.join("s/cases").join(id).exists(), "{id} has a folder");
    }
    // run again, not stopped: every case runs (none was left failed)
    let again = SweepJob {
        jobs: Some(2),
        ..SweepJob::new(root().join(PLAN), d.join("s"))
    };
    let o = again
        .execute(&plan, &|_, _| {}, &Quiet, &mut |_| {})
        .unwrap();
    assert_eq!(o.report.ran.len(), 4);
    assert!(o.report.failed().is_empty(), "{:?}", o.report.failed());
}
