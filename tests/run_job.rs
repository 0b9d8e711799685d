//! The library's run entry point ([`RunJob`]), called directly: what it tells its observer,
//! the folder it writes (the same figures as `rotorsim run` with the same options), and an
//! error with the command line's message.
mod support;

use rotorsim::hydraulics::DamperModel;
use rotorsim::overrides::Override;
use rotorsim::run::job::{DamperChoice, RotorModel, RunJob, RunObserver, RunStart};
use rotorsim::run::Progress;
use serde_json::Value;
use std::path::Path;
use std::process::Command;
use std::sync::Mutex;

#[derive(Debug, Clone, PartialEq)]
enum Event {
    Start(Vec<DamperModel>),
    Revolution(usize),
    Finished(usize, bool),
}

#[derive(Default)]
struct Recorder(Mutex<Vec<Event>>);

impl Progress for Recorder {
    fn revolution(&self, i: usize, _rev: usize, _revs: usize, _m: Option<f64>) {
        self.0.lock().unwrap().push(Event::Revolution(i));
    }
    fn finished(&self, i: usize, ok: bool, _message: &str) {
        self.0.lock().unwrap().push(Event::Finished(i, ok));
    }
}

impl RunObserver for Recorder {
    fn start(&self, s: &RunStart) {
        self.0.lock().unwrap().push(Event::Start(s.models.clone()));
    }
}

/// The rigid reduction of the shipped deck, 3 revolutions (well under a second).
fn rigid_job(out: &Path) -> RunJob {
    let root = support::root();
    RunJob {
        rotor: root.join("rotors/uh60a.toml"),
        flight: root.join("flightdata/c8534like"),
        model: RotorModel::Rigid,
        damper: DamperChoice::All,
        revs: 3,
        ..RunJob::new(out)
    }
}

/// `rotorsim run` with the options of [`rigid_job`], then `extra`, into `out`.
fn run_cli(job: &RunJob, extra: &[&str], out: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(support::root())
        .args(["run", "--model", "rigid", "--revs", "3", "--rotor"])
        .arg(&job.rotor)
        .arg("--flight")
        .arg(&job.flight)
        .args(extra)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
}

/// Every number of `a` equals `b`'s at the same place (wall times aside).
fn same_figures(a: &Value, b: &Value, at: &str) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let keys = |o: &serde_json::Map<String, Value>| o.keys().cloned().collect::<Vec<_>>();
            assert_eq!(keys(x), keys(y), "keys at {at}");
            for (k, v) in x {
                if k.starts_with("wall") || k == "cost_per_step_s" {
                    continue;
                }
                same_figures(v, &y[k], &format!("{at}.{k}"));
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "length at {at}");
            for (i, (v, w)) in x.iter().zip(y).enumerate() {
                same_figures(v, w, &format!("{at}[{i}]"));
            }
        }
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= 1e-9 * x.abs().max(y.abs()),
                "{at}: {x} != {y}"
            );
        }
        _ => assert_eq!(a, b, "at {at}"),
    }
}

#[test]
fn a_job_reports_to_its_observer_and_writes_what_the_cli_writes() {
    let t = support::tmp("run-job");
    let job = rigid_job(&t.join("lib"));
    job.check().unwrap();
    let rec = Recorder::default();
    let outcome = job.execute(&rec).unwrap();

    let events = rec.0.lock().unwrap().clone();
    let models = DamperChoice::All.models();
    assert_eq!(events.first(), Some(&Event::Start(models.clone())));
    assert_eq!(
        events
            .iter()
            .filter(|e| matches!(e, Event::Start(_)))
            .count(),
        1
    );
    for i in 0..models.len() {
        let revs = events
            .iter()
            .filter(|e| **e == Event::Revolution(i))
            .count();
        assert!(revs >= 1, "model {i}: no progress in {events:?}");
        let finished: Vec<usize> = events
            .iter()
            .enumerate()
            .filter(|(_, e)| **e == Event::Finished(i, true))
            .map(|(k, _)| k)
            .collect();
        assert_eq!(finished.len(), 1, "model {i}: {events:?}");
        // nothing of a model after it finished
        assert!(events[finished[0]..]
            .iter()
            .all(|e| *e != Event::Revolution(i)));
    }

    assert_eq!(outcome.outcomes.len(), 3);
    assert!(outcome.failed.is_empty());
    assert!(outcome.verdict.is_some());
    assert_eq!(outcome.published.summary, t.join("lib/summary.json"));
    assert_eq!(outcome.published.last_rev.len(), 3);
    let manifest = support::read_json(&t.join("lib/manifest.json"));
    assert_eq!(manifest["complete"], Value::Bool(true));
    for p in [&outcome.published.report, &outcome.published.mcap] {
        assert!(p.is_file(), "{}", p.display());
    }

    let cli_out = t.join("cli");
    let o = run_cli(&job, &[], &cli_out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let lib = support::read_json(&t.join("lib/summary.json"));
    let cli = support::read_json(&cli_out.join("summary.json"));
    for key in [
        "models",
        "options",
        "measured",
        "closest",
        "rotor",
        "flight_record",
    ] {
        same_figures(&lib[key], &cli[key], key);
    }
    std::fs::remove_dir_all(&t).unwrap();
}

#[test]
fn a_bad_override_fails_with_the_cli_message() {
    let t = support::tmp("run-job-bad");
    let mut job = rigid_job(&t.join("out"));
    job.overrides = vec![Override::parse("bearing.no_such_key_m=1.0").unwrap()];
    let lib = rotorsim::cli::error_chain(&job.execute(&rotorsim::run::Silent).unwrap_err());
    let checked = rotorsim::cli::error_chain(&job.check().unwrap_err());
    assert_eq!(lib, checked);
    assert!(
        !t.join("out").exists(),
        "nothing is written before the checks pass"
    );

    let o = run_cli(
        &job,
        &["--set", "bearing.no_such_key_m=1.0"],
        &t.join("out"),
    );
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(stderr.trim_end(), format!("error: {lib}"), "{stderr}");
    std::fs::remove_dir_all(&t).unwrap();
}

/// Raises its stop flag at the first revolution reported.
struct StopAtFirstRevolution(rotorsim::run::stop::StopFlag);

impl Progress for StopAtFirstRevolution {
    fn revolution(&self, _i: usize, _rev: usize, _revs: usize, _m: Option<f64>) {
        self.0.request();
    }
    fn finished(&self, _i: usize, _ok: bool, _message: &str) {}
}

impl RunObserver for StopAtFirstRevolution {
    fn start(&self, _: &RunStart) {}
}

#[test]
fn a_stopped_job_publishes_its_folder_incomplete_saying_where_it_stopped() {
    use rotorsim::run::stop::{RunStopped, StopFlag};
    let out = support::tmp("job-stopped").join("run");
    let job = RunJob {
        revs: 30,
        ..rigid_job(&out)
    };
    let stop = StopFlag::new();
    let e = job
        .execute_until(&StopAtFirstRevolution(stop.clone()), &stop)
        .unwrap_err();
    let s = e.downcast_ref::<RunStopped>().expect("a RunStopped error");
    assert!(s.message.starts_with("stopped by the user at t = "), "{s}");
    assert!(s.message.contains("revolution 2"), "{s}");
    assert_eq!(s.folder, out);
    let manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(manifest["complete"], Value::Bool(false));
    assert!(out.join("INCOMPLETE").exists());
    assert!(!out.join("summary.json").exists());
}
