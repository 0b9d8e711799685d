//! The options of `sensitivity`, `diagnose`, `static`, `dynamic` and `verify` are each defined
//! once, by a settings type: every field is an option of its command and a JSON key giving the
//! same settings, the defaults are the command line's, and `diagnose`'s are the keywords of the
//! Python package's `diagnose` (its stub lists them).
use clap::Parser;
use rotorsim::cli::{Cli, Command};
use rotorsim::diagnose::settings::DiagnoseSettings;
use rotorsim::sensitivity::job::SensitivitySettings;
use serde::{de::DeserializeOwned, Serialize};
use serde_json::{json, Value};
use std::fmt::Debug;
use std::path::PathBuf;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A value of option `key` other than its default `d`, as JSON and as the command line's text.
fn other_value(key: &str, d: &Value) -> (Value, Vec<String>) {
    let flag = format!("--{}", key.replace('_', "-"));
    let text = |v: &str| (Value::from(v), vec![flag.clone(), v.to_string()]);
    let list = |v: &str| (json!([v]), vec![flag.clone(), v.to_string()]);
    match (key, d) {
        ("vary", _) => list("bearing.lag_loss_factor=0.05:0.2"),
        ("measured", _) => list("some/test.csv"),
        ("damper", _) => text("physical"),
        ("model", _) => text("rigid"),
        ("shard", _) => text("0/2"),
        ("jobs" | "shards", _) => (3.into(), vec![flag, "3".into()]),
        ("rho_inf", _) => (0.5.into(), vec![flag, "0.5".into()]),
        ("newton_rtol", _) => (1e-6.into(), vec![flag, "1e-6".into()]),
        (_, Value::Bool(_)) => (true.into(), vec![flag]),
        (_, Value::Number(n)) if n.is_u64() => (64.into(), vec![flag, "64".into()]),
        (_, Value::Number(_)) => (0.25.into(), vec![flag, "0.25".into()]),
        (_, Value::String(_) | Value::Null) => text("some/file.toml"),
        (k, d) => panic!("option {k}: no test value for a default of {d}"),
    }
}

/// Every field (a nested object's fields as `object.field`) with its default.
fn fields(defaults: &Value) -> Vec<(Vec<String>, Value)> {
    let mut out = vec![];
    for (k, v) in defaults.as_object().expect("settings are a JSON object") {
        match v {
            Value::Object(m) => {
                for (k2, v2) in m {
                    out.push((vec![k.clone(), k2.clone()], v2.clone()));
                }
            }
            v => out.push((vec![k.clone()], v.clone())),
        }
    }
    out
}

/// For every field of `S`: the command line's value and the JSON key's give the same settings,
/// not the default, and the settings round-trip through JSON. `parse` reads the settings off a
/// command line of `head` and the options.
fn check_settings<S>(head: &[&str], parse: impl Fn(Command) -> S) -> Vec<String>
where
    S: Serialize + DeserializeOwned + PartialEq + Debug + Default,
{
    let cli = |args: &[String]| {
        let argv: Vec<String> = head
            .iter()
            .map(|s| s.to_string())
            .chain(args.iter().cloned())
            .collect();
        let parsed = Cli::try_parse_from(&argv).unwrap_or_else(|e| panic!("{argv:?}: {e}"));
        parse(parsed.command)
    };
    assert_eq!(cli(&[]), S::default(), "{head:?}: defaults");
    let from = |v: &Value| -> S {
        serde_json::from_value(v.clone()).unwrap_or_else(|e| panic!("{head:?}: {v}: {e}"))
    };
    assert_eq!(from(&json!({})), S::default(), "{head:?}: {{}}");
    let defaults = serde_json::to_value(S::default()).unwrap();
    let mut names = vec![];
    for (path, d) in fields(&defaults) {
        let key = path.last().unwrap();
        let (v, args) = other_value(key, &d);
        assert_ne!(v, d, "{key}: the test value is the default");
        let given = cli(&args);
        assert_ne!(given, S::default(), "{head:?} {args:?} changed nothing");
        let j = match path.as_slice() {
            [k] => json!({ k.as_str(): v }),
            [k, k2] => json!({ k.as_str(): { k2.as_str(): v } }),
            _ => unreachable!(),
        };
        assert_eq!(from(&j), given, "{head:?} {key}");
        let text = serde_json::to_string(&given).unwrap();
        let back: S = serde_json::from_str(&text).unwrap();
        assert_eq!(back, given, "{head:?} {key}: JSON round trip");
        names.push(key.clone());
    }
    // an unknown name is refused
    assert!(serde_json::from_value::<S>(json!({"no_such_option": 1})).is_err());
    names
}

#[test]
fn sensitivity_options_are_cli_options_and_json_keys() {
    let names = check_settings(&["rotorsim", "sensitivity", "--out", "o"], |c| match c {
        Command::Sensitivity(a) => a.settings,
        c => panic!("not sensitivity: {c:?}"),
    });
    for k in [
        "rotor",
        "vary",
        "only_vary",
        "jobs",
        "shard",
        "emit_slurm",
        "warm_start",
    ] {
        assert!(names.iter().any(|n| n == k), "{k}");
    }
    assert_eq!(
        SensitivitySettings::from_json("{}").unwrap(),
        SensitivitySettings::default()
    );
}

#[test]
fn diagnose_options_are_cli_options_json_keys_and_python_keywords() {
    let names = check_settings(&["rotorsim", "diagnose", "--out", "o"], |c| match c {
        Command::Diagnose(a) => a.settings,
        c => panic!("not diagnose: {c:?}"),
    });
    assert_eq!(names.len(), DiagnoseSettings::defaults_map().len());
    // the aliases of renamed options still parse
    for (old, new) in [("--deck", "--damper-deck"), ("--rotor-model", "--model")] {
        let parse = |flag: &str| match Cli::try_parse_from([
            "rotorsim", "diagnose", "--out", "o", flag, "rigid",
        ])
        .unwrap()
        .command
        {
            Command::Diagnose(a) => a.settings,
            _ => unreachable!(),
        };
        assert_eq!(parse(old), parse(new), "{old}");
    }
    let stub = std::fs::read_to_string(repo().join("python/rotorsim/__init__.pyi")).unwrap();
    let f = &stub[stub.find("def diagnose(").unwrap()..];
    let f = &f[..f.find(") -> DiagnoseResult").unwrap()];
    for k in DiagnoseSettings::defaults_map().keys() {
        assert!(
            f.contains(&format!("\n    {k}: ")),
            "python/rotorsim/__init__.pyi: diagnose() lacks {k}"
        );
    }
    let init = std::fs::read_to_string(repo().join("python/rotorsim/__init__.py")).unwrap();
    assert!(init.contains("DIAGNOSE_OPTIONS = _json.loads(_native.diagnose_options())"));
}

#[test]
fn static_dynamic_and_verify_options_are_cli_options_and_json_keys() {
    let names = check_settings(
        &["rotorsim", "static", "d.toml", "--out", "o"],
        |c| match c {
            Command::Static(a) => a.settings,
            c => panic!("not static: {c:?}"),
        },
    );
    assert_eq!(names, ["check_tangent"]);
    let names = check_settings(
        &["rotorsim", "dynamic", "d.toml", "--out", "o"],
        |c| match c {
            Command::Dynamic(a) => a.settings,
            c => panic!("not dynamic: {c:?}"),
        },
    );
    assert_eq!(names.len(), 2);
    let names = check_settings(&["rotorsim", "verify", "--out", "o"], |c| match c {
        Command::Verify(a) => a.settings,
        c => panic!("not verify: {c:?}"),
    });
    assert!(names.is_empty());
}
