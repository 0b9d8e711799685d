//! A run's options are defined once (`rotorsim::run::job::RunSettings`): every one of them is
//! an option of `rotorsim run`, a key of a sweep plan (but those the sweep decides) and a
//! keyword of the Python package's `run` (its stub lists them), each read into the same run.
use clap::Parser;
use rotorsim::cli::{Cli, Command};
use rotorsim::run::job::RunSettings;
use rotorsim::run::settings::JobSettings;
use rotorsim::sweep::plan::NOT_PLAN_OPTIONS;
use rotorsim::sweep::Plan;
use std::path::PathBuf;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A value of every option other than its default, as JSON and as the command line's text.
fn other_values() -> Vec<(String, serde_json::Value, Vec<String>)> {
    let mut out = vec![];
    for (k, d) in RunSettings::defaults_map() {
        let flag = format!("--{}", k.replace('_', "-"));
        let (v, args): (serde_json::Value, Vec<String>) = match (k.as_str(), &d) {
            ("set", _) => (
                serde_json::json!(["damper.physical.A_orf_m2=2e-6"]),
                vec![flag, "damper.physical.A_orf_m2=2e-6".into()],
            ),
            ("damper", _) => ("physical".into(), vec![flag, "physical".into()]),
            ("scheme", _) => ("implicit".into(), vec![flag, "implicit".into()]),
            ("newton", _) => ("full".into(), vec![flag, "full".into()]),
            ("periodic", _) => ("march".into(), vec![flag, "march".into()]),
            ("model", _) => ("rigid".into(), vec![flag, "rigid".into()]),
            ("airloads", _) => ("computed".into(), vec![flag, "computed".into()]),
            (_, serde_json::Value::Bool(_)) => (true.into(), vec![flag]),
            (_, serde_json::Value::Number(n)) if n.is_u64() => (64.into(), vec![flag, "64".into()]),
            (_, serde_json::Value::Number(_)) => (0.25.into(), vec![flag, "0.25".into()]),
            (_, serde_json::Value::String(_) | serde_json::Value::Null) => {
                ("some/file.toml".into(), vec![flag, "some/file.toml".into()])
            }
            (k, d) => panic!("option {k}: no test value for a default of {d}"),
        };
        assert_ne!(v, d, "{k}: the test value is the default");
        out.push((k, v, args));
    }
    out
}

fn cli_settings(args: &[String]) -> RunSettings {
    let mut argv = vec!["rotorsim".to_string(), "run".into()];
    argv.extend(args.iter().cloned());
    argv.extend(["--out".into(), "o".into()]);
    match Cli::try_parse_from(&argv).unwrap().command {
        Command::Run(a) => a.settings,
        _ => panic!("not a run"),
    }
}

#[test]
fn defaults_are_the_command_lines() {
    assert_eq!(cli_settings(&[]), RunSettings::default());
    assert_eq!(
        RunSettings::from_json("{}").unwrap(),
        RunSettings::default()
    );
}

#[test]
fn every_option_is_a_cli_option_a_json_key_and_a_plan_key() {
    let values = other_values();
    // the six Python's run lacked are among them
    for k in [
        "scheme",
        "newton",
        "damper_deck",
        "initial_state",
        "require_periodic",
        "write_all_revs",
    ] {
        assert!(values.iter().any(|v| v.0 == k), "{k}");
    }
    for (k, v, args) in &values {
        // the command line and JSON (Python's keywords) give the same settings
        let cli = cli_settings(args);
        assert_ne!(cli, RunSettings::default(), "--{k} changed nothing");
        let json = RunSettings::from_json(&serde_json::json!({ k.as_str(): v }).to_string())
            .unwrap_or_else(|e| panic!("{k}: {e:#}"));
        assert_eq!(cli, json, "{k}");
        if NOT_PLAN_OPTIONS.contains(&k.as_str()) {
            continue;
        }
        // a plan's [base] key, read into the same run
        let toml_value = match v {
            serde_json::Value::String(s) => format!("{s:?}"),
            v => v.to_string(),
        };
        let text = format!("[base]\n{k} = {toml_value}\n[vary]\nrevs = [3]\n");
        let plan = Plan::parse(&text, "p.toml").unwrap_or_else(|e| panic!("{k}: {e:#}"));
        let case = &plan.cases[0];
        let job = rotorsim::sweep::runner::job_of(case, "o".as_ref(), None)
            .unwrap_or_else(|e| panic!("{k}: {e:#}"));
        let want = RunSettings { revs: 3, ..json }.job("o").unwrap();
        assert_eq!(job, want, "{k}");
    }
}

#[test]
fn the_python_package_takes_every_option() {
    let stub = std::fs::read_to_string(repo().join("python/rotorsim/__init__.pyi")).unwrap();
    let run = &stub[stub.find("def run(").unwrap()..];
    let run = &run[..run.find(") -> RunResult").unwrap()];
    for k in RunSettings::defaults_map().keys() {
        assert!(
            run.contains(&format!("\n    {k}: ")),
            "python/rotorsim/__init__.pyi: run() lacks {k}"
        );
    }
    // the package reads the options from the library (no list of its own to keep)
    let init = std::fs::read_to_string(repo().join("python/rotorsim/__init__.py")).unwrap();
    assert!(init.contains("RUN_OPTIONS = _json.loads(_native.run_options())"));
    assert!(
        init.contains("def run(out=None, progress=True, models=None, rotor_model=None, **options)")
    );
}
