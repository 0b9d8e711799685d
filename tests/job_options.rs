//! Each job's options are defined once, in its settings type (`StabilitySettings`,
//! `BenchSettings`, `ModesSettings`, `DecaySettings`): every field is an option of its command,
//! a JSON key giving the same settings (the Python package's keywords, listed in its stub) and,
//! for stability, a key of a sweep plan's stability case read into the same settings.
use clap::Parser;
use rotorsim::checks::bench::BenchSettings;
use rotorsim::checks::decay::DecaySettings;
use rotorsim::checks::modes::ModesSettings;
use rotorsim::cli::{Cli, Command};
use rotorsim::resonance::StabilitySettings;
use rotorsim::run::settings::JobSettings;
use rotorsim::sweep::Plan;
use serde_json::{json, Value};
use std::fmt::Debug;
use std::path::PathBuf;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// An option's test value (not its default) as JSON and as command-line arguments.
type Other = (&'static str, Value, Vec<&'static str>);

/// The command line `rotorsim <job> <args> --out o`, its settings.
fn cli<S>(job: &str, args: &[&str], pick: fn(Command) -> Option<S>) -> S {
    let mut argv = vec!["rotorsim", job];
    argv.extend_from_slice(args);
    argv.extend(["--out", "o"]);
    let parsed = Cli::try_parse_from(&argv).unwrap_or_else(|e| panic!("{argv:?}: {e}"));
    pick(parsed.command).unwrap_or_else(|| panic!("{job}: another command"))
}

/// Checks a job's settings type against `others` (every field, none left out but those the
/// caller tests `apart`): the command line with only the `required` arguments is the defaults
/// with those; each option given on the command line and as JSON gives the same settings, not
/// the defaults.
fn check_job<S: JobSettings + PartialEq + Debug>(
    job: &str,
    required: (&[&str], Value),
    others: &[Other],
    apart: &[&str],
    pick: fn(Command) -> Option<S>,
) {
    let keys: Vec<&str> = others.iter().map(|o| o.0).collect();
    for k in S::defaults_map().keys() {
        let given_by_required = required.1.get(k).is_some() || apart.contains(&k.as_str());
        assert!(
            keys.contains(&k.as_str()) || given_by_required,
            "{job}: option {k} has no test value here"
        );
    }
    assert_eq!(S::from_json("{}").unwrap(), S::default(), "{job}");
    let base = S::from_json(&required.1.to_string()).unwrap();
    assert_eq!(cli(job, required.0, pick), base, "{job}: defaults");
    for (k, v, args) in others {
        assert_ne!(
            S::defaults_map().get(*k),
            Some(v),
            "{job} {k}: the test value is the default"
        );
        let mut all = required.0.to_vec();
        all.extend(args.iter().copied());
        let from_cli = cli(job, &all, pick);
        assert_ne!(from_cli, base, "{job} {k}: changed nothing");
        let mut j = required.1.clone();
        j[*k] = v.clone();
        let from_json = S::from_json(&j.to_string()).unwrap_or_else(|e| panic!("{job} {k}: {e:#}"));
        assert_eq!(from_cli, from_json, "{job} {k}");
    }
}

/// The keywords of `def <name>(` in the Python stub.
fn python_stub(name: &str, result: &str) -> String {
    let stub = std::fs::read_to_string(repo().join("python/rotorsim/__init__.pyi")).unwrap();
    let f = &stub[stub.find(&format!("def {name}(")).unwrap()..];
    f[..f.find(&format!(") -> {result}")).unwrap()].to_string()
}

fn assert_in_stub<S: JobSettings>(name: &str, result: &str) {
    let f = python_stub(name, result);
    for k in S::defaults_map().keys() {
        assert!(
            f.contains(&format!("\n    {k}: ")),
            "python/rotorsim/__init__.pyi: {name}() lacks {k}"
        );
    }
}

fn stability_others() -> Vec<Other> {
    vec![
        ("damper", json!("physical"), vec!["--damper", "physical"]),
        ("time", json!("25,27"), vec!["--time", "25,27"]),
        ("kick_m_s", json!(0.25), vec!["--kick-m-s", "0.25"]),
        (
            "time_duration_s",
            json!(5.0),
            vec!["--time-duration-s", "5"],
        ),
        ("steps_per_rev", json!(64), vec!["--steps-per-rev", "64"]),
        (
            "amplitudes_m",
            json!("default"),
            vec!["--amplitudes-m", "default"],
        ),
        (
            "amplitude_at_rad_s",
            json!(25.0),
            vec!["--amplitude-at-rad-s", "25"],
        ),
        ("hover", json!(true), vec!["--hover"]),
        ("collective_deg", json!(-2.5), vec!["--collective-deg=-2.5"]),
        ("density_kg_m3", json!(1.0), vec!["--density-kg-m3", "1"]),
        (
            "speed_of_sound_m_s",
            json!(330.0),
            vec!["--speed-of-sound-m-s", "330"],
        ),
        ("strips", json!(12), vec!["--strips", "12"]),
        (
            "set",
            json!(["damper.linear.c_N_s_per_m=1000"]),
            vec!["--set", "damper.linear.c_N_s_per_m=1000"],
        ),
    ]
}

#[test]
fn stability_options_are_cli_json_and_python() {
    let required = json!({"rotor": "rotors/uh60a_airframe.toml", "speeds": "20:34:2"});
    check_job::<StabilitySettings>(
        "stability",
        (
            &[
                "--rotor",
                "rotors/uh60a_airframe.toml",
                "--speeds",
                "20:34:2",
            ],
            required,
        ),
        &stability_others(),
        &[],
        |c| match c {
            Command::Stability(a) => Some(a.settings),
            _ => None,
        },
    );
    assert_in_stub::<StabilitySettings>("stability", "StabilityResult");
}

/// Every stability option but `speeds` (the plan's `stability_speeds`) and `set` (its dotted
/// keys) is a key of a plan's stability case, read into the settings JSON gives.
#[test]
fn stability_options_are_plan_keys() {
    let mut others = stability_others();
    others.push(("rotor", json!("rotors/hammond1974.toml"), vec![]));
    for (k, v, _) in &others {
        let base = json!({"rotor": "rotors/uh60a_airframe.toml", "speeds": "20:34:2"});
        let mut want = base.clone();
        want[*k] = v.clone();
        let toml_value = |v: &Value| match v {
            Value::String(s) => format!("{s:?}"),
            v => v.to_string(),
        };
        let text = if *k == "set" {
            // a plan sets deck values by their dotted keys
            let (key, value) = v[0].as_str().unwrap().split_once('=').unwrap();
            format!(
                "[base]\nrotor = \"rotors/uh60a_airframe.toml\"\nstability_speeds = \"20:34:2\"\n\"{key}\" = {value}.0\n[vary]\nstrips = [{}]\n",
                StabilitySettings::default().strips
            )
        } else {
            let mut t = "[base]\nstability_speeds = \"20:34:2\"\n".to_string();
            if *k != "rotor" {
                t.push_str("rotor = \"rotors/uh60a_airframe.toml\"\n");
            }
            t.push_str(&format!("{k} = {}\n", toml_value(v)));
            // a plan sweeps something: the default strips, or (for strips) the test value
            let strips = if *k == "strips" {
                v.to_string()
            } else {
                StabilitySettings::default().strips.to_string()
            };
            t.push_str(&format!("[vary]\nstrips = [{strips}]\n"));
            t
        };
        let plan = Plan::parse(&text, "p.toml").unwrap_or_else(|e| panic!("{k}: {e:#}"));
        let got = rotorsim::sweep::runner::stability_settings(&plan.cases[0])
            .expect("a stability case")
            .unwrap_or_else(|e| panic!("{k}: {e:#}"));
        let want = StabilitySettings::from_json(&want.to_string()).unwrap();
        if *k == "set" {
            assert_eq!(got.set.len(), 1, "{k}");
            assert_eq!(got.set[0].key, "damper.linear.c_N_s_per_m", "{k}");
            assert_eq!(
                StabilitySettings { set: vec![], ..got },
                StabilitySettings {
                    set: vec![],
                    ..want
                }
            );
        } else {
            assert_eq!(got, want, "{k}");
        }
    }
    // without `rotor`, a run's default deck
    let plan = Plan::parse(
        "[base]\nstability_speeds = \"20:34:2\"\n[vary]\nstrips = [24]\n",
        "p.toml",
    )
    .unwrap();
    let got = rotorsim::sweep::runner::stability_settings(&plan.cases[0])
        .unwrap()
        .unwrap();
    assert_eq!(
        got.rotor,
        Some(PathBuf::from(rotorsim::run::job::DEFAULT_ROTOR))
    );
}

#[test]
fn bench_options_are_cli_json_and_python() {
    check_job::<BenchSettings>(
        "bench",
        (
            &["--damper-deck", "rotors/uh60a.toml"],
            json!({"damper_deck": "rotors/uh60a.toml"}),
        ),
        &[
            ("damper", json!("all"), vec!["--damper", "all"]),
            ("omega", json!(20.5), vec!["--omega", "20.5"]),
            (
                "peak_velocity",
                json!([1.0, 2.5]),
                vec!["--peak-velocity", "1,2.5"],
            ),
            (
                "velocity_unit",
                json!("m/s"),
                vec!["--velocity-unit", "m/s"],
            ),
            ("cycles", json!(3), vec!["--cycles", "3"]),
            (
                "steps_per_cycle",
                json!(128),
                vec!["--steps-per-cycle", "128"],
            ),
            ("substeps", json!(5), vec!["--substeps", "5"]),
            ("scheme", json!("implicit"), vec!["--scheme", "implicit"]),
            ("output_rate", json!(2000.0), vec!["--output-rate", "2000"]),
            (
                "measured",
                json!(["a.csv", "b.csv"]),
                vec!["--measured", "a.csv", "--measured", "b.csv"],
            ),
            ("skip_cycles", json!(2), vec!["--skip-cycles", "2"]),
        ],
        &[],
        |c| match c {
            Command::Bench(a) => Some(a.settings),
            _ => None,
        },
    );
    assert_in_stub::<BenchSettings>("bench", "BenchResult");
    // the earlier names on the command line
    let by_alias = cli(
        "bench",
        &["--deck", "d.toml", "--integrator", "implicit"],
        |c| match c {
            Command::Bench(a) => Some(a.settings),
            _ => None,
        },
    );
    assert_eq!(by_alias.damper_deck, Some(PathBuf::from("d.toml")));
    assert_eq!(by_alias.scheme.as_deref(), Some("implicit"));
}

#[test]
fn modes_options_are_cli_json_and_python() {
    let pick = |c| match c {
        Command::Modes(a) => Some(a.settings),
        _ => None,
    };
    check_job::<ModesSettings>(
        "modes",
        (
            &["--rotor", "rotors/uh60a.toml"],
            json!({"rotor": "rotors/uh60a.toml"}),
        ),
        &[
            ("speeds", json!("10:20:5"), vec!["--speeds", "10:20:5"]),
            (
                "speed_fractions",
                json!("0.5,1"),
                vec!["--speed-fractions", "0.5,1"],
            ),
            (
                "reference",
                json!("ref.csv"),
                vec!["--reference", "ref.csv"],
            ),
            ("count", json!(6), vec!["--count", "6"]),
        ],
        &["deck"],
        pick,
    );
    // the model deck is the command's argument
    let deck = cli("modes", &["deck.toml"], pick);
    assert_eq!(
        deck,
        ModesSettings::from_json(r#"{"deck": "deck.toml"}"#).unwrap()
    );
    assert_in_stub::<ModesSettings>("modes", "ModesResult");
    // --speeds and --speed-fractions exclude each other, on the command line and as JSON
    let both = [
        "modes",
        "--rotor",
        "r.toml",
        "--speeds",
        "1,2",
        "--speed-fractions",
        "0.5",
    ];
    assert!(Cli::try_parse_from(["rotorsim"].iter().chain(both.iter())).is_err());
    let json = ModesSettings::from_json(
        r#"{"rotor": "r.toml", "speeds": "1,2", "speed_fractions": "0.5"}"#,
    )
    .unwrap();
    let e = json.job("o").unwrap_err().to_string();
    assert!(
        e.contains("--speeds") && e.contains("--speed-fractions"),
        "{e}"
    );
}

#[test]
fn decay_options_are_cli_and_json() {
    let pick = |c| match c {
        Command::Decay(a) => Some(a.settings),
        _ => None,
    };
    check_job::<DecaySettings>(
        "decay",
        (
            &["--rotor", "rotors/tm4760.toml"],
            json!({"rotor": "rotors/tm4760.toml"}),
        ),
        &[
            ("speed_rad_s", json!(30.0), vec!["--speed-rad-s", "30"]),
            ("rpm", json!(300.0), vec!["--rpm", "300"]),
            ("step_s", json!(0.01), vec!["--step-s", "0.01"]),
            ("duration_s", json!(3.0), vec!["--duration-s", "3"]),
            ("frame", json!("inertial"), vec!["--frame", "inertial"]),
            ("newton", json!("full"), vec!["--newton", "full"]),
            ("rho_inf", json!(0.5), vec!["--rho-inf", "0.5"]),
            ("newton_rtol", json!(1e-6), vec!["--newton-rtol", "1e-6"]),
            ("newton_xtol", json!(1e-7), vec!["--newton-xtol", "1e-7"]),
            ("no_modal", json!(true), vec!["--no-modal"]),
        ],
        &[],
        pick,
    );
    // --speed-rad-s and --rpm exclude each other, on the command line and as JSON
    let both = [
        "decay",
        "--rotor",
        "r.toml",
        "--speed-rad-s",
        "30",
        "--rpm",
        "300",
    ];
    assert!(Cli::try_parse_from(["rotorsim"].iter().chain(both.iter())).is_err());
    let json =
        DecaySettings::from_json(r#"{"rotor": "r.toml", "speed_rad_s": 30, "rpm": 300}"#).unwrap();
    let e = json.job("o").unwrap_err().to_string();
    assert!(e.contains("--speed-rad-s") && e.contains("--rpm"), "{e}");
    // a value the command line refuses is refused as JSON, naming the option
    let json = DecaySettings::from_json(r#"{"rotor": "r.toml", "frame": "sideways"}"#).unwrap();
    let e = json.job("o").unwrap_err().to_string();
    assert!(e.contains("--frame sideways"), "{e}");
}

/// The required options are required on the command line, and an unknown JSON key names itself.
#[test]
fn required_options_and_unknown_keys() {
    for args in [
        vec!["stability", "--speeds", "1,2"],
        vec!["stability", "--rotor", "r.toml"],
        vec!["bench"],
        vec!["decay"],
        vec!["modes"],
    ] {
        let mut argv = vec!["rotorsim"];
        argv.extend(args.iter().copied());
        argv.extend(["--out", "o"]);
        assert!(Cli::try_parse_from(&argv).is_err(), "{argv:?}");
    }
    let e = StabilitySettings::from_json(r#"{"speed": "1,2"}"#).unwrap_err();
    assert!(format!("{e:#}").contains("speed"), "{e:#}");
    let e = StabilitySettings::default()
        .job("o")
        .unwrap_err()
        .to_string();
    assert!(e.contains("--rotor"), "{e}");
}
