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
