//! `rotorsim diagnose` end to end: the shipped (SYNTHETIC) flight record, the docs/formats.md JSON
//! keys, the written deck through `rotorsim bench`, and the clear errors.
use rotorsim::checks::bench::BenchSettings;
use rotorsim::cli::bench::{run as bench, BenchArgs};
use rotorsim::cli::diagnose::{run as diagnose, DiagnoseArgs};
use rotorsim::diagnose::settings::DiagnoseSettings;
use std::path::PathBuf;
mod support;
use support::{assert_diagnosis_keys, read_json, root, tmp};

fn args(out: PathBuf) -> DiagnoseArgs {
    DiagnoseArgs {
        settings: DiagnoseSettings {
            damper_deck: None,
            measured: vec![],
            rotor: Some(root().join("flightdata/damper_nominal.toml")),
            flight: Some(root().join("flightdata/c8534like")),
            write_deck: None,
            ..DiagnoseSettings::default()
        },
        out,
    }
}

#[test]
fn flight_record_diagnosis_writes_the_formats_json_and_a_usable_deck() {
    let dir = tmp("flight");
    let deck = dir.join("extended.toml");
    diagnose(DiagnoseArgs {
        settings: DiagnoseSettings {
            write_deck: Some(deck.clone()),
            ..args(dir.join("out")).settings
        },
        out: dir.join("out"),
    })
    .unwrap();
    let j = read_json(&dir.join("out/diagnosis.json"));
    assert_diagnosis_keys(&j);
    for k in ["method", "baseline_rms_N", "extended_rms_N"] {
        assert!(j["validation"].get(k).is_some(), "missing validation.{k}");
    }
    for c in j["candidates"].as_array().unwrap() {
        for k in ["cause", "rms_N", "bic", "parameters"] {
            assert!(c.get(k).is_some(), "candidate lacks {k}");
        }
    }
    assert_ne!(j["cause"], "none");
    // One test: the cause's parameters revolution by revolution, from the second.
    let spread = j["parameter_spread"].as_object().expect("parameter_spread");
    for (name, s) in spread {
        assert!(s["tests"].as_u64().unwrap() >= 3, "{name}: {s}");
        assert!(s["per_test"]
            .as_object()
            .unwrap()
            .keys()
            .all(|k| k.contains(" cycle ")));
        assert!(j["parameters"].get(name).is_some(), "{name}");
    }
    assert!(!spread.is_empty());
    assert!(j["gain"].as_f64().unwrap() > 0.0);
    assert!(dir.join("out/diagnosis.html").exists());
    assert!(!dir.join("out/INCOMPLETE").exists());
    let html = std::fs::read_to_string(dir.join("out/diagnosis.html")).unwrap();
    // the SYNTHETIC banner heads the report, before the first section, under one title
    let banner = html
        .find("class=\"banner synthetic\"")
        .expect("SYNTHETIC banner");
    assert!(banner < html.find("<h2").unwrap());
    assert_eq!(html.matches("<h1>").count(), 1);
    // The written deck is a damper deck `bench` accepts.
    let text = std::fs::read_to_string(&deck).unwrap();
    assert!(text.contains("[damper.physical.extensions]"));
    bench(BenchArgs {
        settings: BenchSettings {
            damper_deck: Some(deck),
            peak_velocity: vec![2.0],
            cycles: 2,
            ..Default::default()
        },
        out: dir.join("bench"),
    })
    .unwrap();
}

/// `--write-deck` inside `--out` (the README's command): the deck is in the published folder,
/// also when an earlier result is replaced.
#[test]
fn a_deck_written_inside_the_result_folder_is_kept() {
    let dir = tmp("deck_inside");
    let out = dir.join("out");
    let deck = out.join("extended.toml");
    for _ in 0..2 {
        diagnose(DiagnoseArgs {
            settings: DiagnoseSettings {
                write_deck: Some(deck.clone()),
                ..args(out.clone()).settings
            },
            out: out.clone(),
        })
        .unwrap();
        let text = std::fs::read_to_string(&deck).expect("the written deck");
        assert!(text.contains("[damper.physical.extensions]"));
        assert_eq!(
            text,
            std::fs::read_to_string(out.join("extended_deck.toml")).unwrap()
        );
    }
}

#[test]
fn flight_record_without_stroke_needs_a_rotor_deck_for_the_rotor_run() {
    let dir = tmp("nostroke");
    let src = root().join("flightdata");
    for ext in ["meta.json", "airloads.csv"] {
        std::fs::copy(
            src.join(format!("c8534like.{ext}")),
            dir.join(format!("r.{ext}")),
        )
        .unwrap();
    }
    let damper = std::fs::read_to_string(src.join("c8534like.damper.csv")).unwrap();
    let stripped: String = damper
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect();
    std::fs::write(dir.join("r.damper.csv"), stripped).unwrap();
    let e = diagnose(DiagnoseArgs {
        settings: DiagnoseSettings {
            flight: Some(dir.join("r")),
            ..args(dir.join("out")).settings
        },
        out: dir.join("out"),
    })
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("no damper stroke") && e.contains("needs a rotor deck"),
        "{e}"
    );
}

/// `diagnose` of one bench file against the nominal damper deck, the result in `dir/out`.
fn bench_args(dir: &std::path::Path, file: PathBuf) -> DiagnoseArgs {
    DiagnoseArgs {
        settings: DiagnoseSettings {
            damper_deck: Some(root().join("flightdata/damper_nominal.toml")),
            measured: vec![file],
            rotor: None,
            flight: None,
            ..args(dir.join("out")).settings
        },
        out: dir.join("out"),
    }
}

#[test]
fn bench_file_without_force_is_named() {
    let dir = tmp("noforce");
    let f = dir.join("t.csv");
    let mut s = String::from("time_s,stroke_m\n");
    for k in 0..2000 {
        let t = k as f64 * 5e-4;
        s.push_str(&format!("{t},{}\n", 1e-3 * (27.0 * t).sin()));
    }
    std::fs::write(&f, s).unwrap();
    let e = diagnose(bench_args(&dir, f)).unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("t.csv") && msg.contains("no measured force"),
        "{msg}"
    );
    assert!(!dir.join("out").exists(), "no output on bad input");
}

#[test]
fn bench_file_dropouts_are_read_and_one_too_long_is_named() {
    // Empty cells are dropouts to the diagnosis' reader; a stroke gap longer than a straight
    // line bridges (1/64 of the 0.233 s period) stops it, naming the file, channel and times.
    let dir = tmp("dropout");
    let f = dir.join("t.csv");
    let mut s = String::from("time_s,stroke_m,force_N\n");
    for k in 0..2000 {
        let t = k as f64 * 5e-4;
        if (400..420).contains(&k) {
            s.push_str(&format!("{t},,\n"));
        } else {
            s.push_str(&format!(
                "{t},{},{}\n",
                1e-3 * (27.0 * t).sin(),
                1e3 * (27.0 * t).cos()
            ));
        }
    }
    std::fs::write(&f, s).unwrap();
    let e = diagnose(bench_args(&dir, f)).unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("t.csv")
            && msg.contains("the stroke is missing from 0.200000 s to 0.209500 s")
            && msg.contains("1/64 of the stroking period"),
        "{msg}"
    );
    assert!(!dir.join("out").exists(), "no output on bad input");
}

#[test]
fn a_calibration_gain_and_a_zero_offset_together_are_both_named() {
    // The shipped SYNTHETIC record read 5% high and 400 N off zero: two linear acquisition
    // faults, fitted together beside the record's own (physical) effect.
    let dir = tmp("gain_offset");
    std::fs::create_dir_all(&dir).unwrap();
    for ext in ["damper.csv", "meta.json", "motion.csv", "airloads.csv"] {
        let from = root().join(format!("flightdata/c8534like.{ext}"));
        let text = std::fs::read_to_string(&from).unwrap();
        let text = if ext == "damper.csv" {
            let mut lines = text.lines();
            let header = lines.next().unwrap();
            let col = header
                .split(',')
                .position(|c| c == "damper_force_N")
                .unwrap();
            let mut out = vec![header.to_string()];
            for l in lines {
                let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
                let v: f64 = f[col].parse().unwrap();
                f[col] = format!("{:.3}", 1.05 * v + 400.0);
                out.push(f.join(","));
            }
            out.join("\n") + "\n"
        } else {
            text
        };
        std::fs::write(dir.join(format!("c8534like.{ext}")), text).unwrap();
    }
    diagnose(DiagnoseArgs {
        settings: DiagnoseSettings {
            flight: Some(dir.join("c8534like")),
            ..args(dir.join("out")).settings
        },
        out: dir.join("out"),
    })
    .unwrap();
    let j = read_json(&dir.join("out/diagnosis.json"));
    let cause = j["cause"].as_str().unwrap();
    let names: Vec<&str> = cause.split('+').collect();
    assert!(
        names.contains(&"force_gain") && names.contains(&"force_offset"),
        "{cause}"
    );
    for (p, truth) in [("gain", 1.05), ("offset_N", 400.0)] {
        let iv = &j["parameter_intervals"][p];
        let (lo, hi) = (iv[0].as_f64().unwrap(), iv[1].as_f64().unwrap());
        assert!(
            lo <= truth && truth <= hi,
            "{p}: [{lo}, {hi}] against {truth}"
        );
    }
}
