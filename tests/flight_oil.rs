//! A flight record's damper oil temperature (meta `damper_oil_temperature_K`): read and written
//! in both forms, refused out of sense, and the diagnosis replays the damper at it.
use rotorsim::diagnose::fit::simulate;
use rotorsim::diagnose::rotor::flight_measurement;
use rotorsim::diagnose::{diagnose, DiagnoseOptions};
use rotorsim::flight::{FlightMeta, FlightRecord};
use rotorsim::hydraulics::{DamperDeck, OilTemperature};
use std::path::Path;
mod support;
use support::{root, tmp};

/// The shipped record with its meta given the oil temperature `t_k`.
fn record_at(t_k: serde_json::Value) -> FlightRecord {
    let mut rec = FlightRecord::read(&root().join("flightdata/c8534like")).unwrap();
    let mut raw = rec.meta.raw.clone();
    raw.insert("damper_oil_temperature_K".into(), t_k);
    rec.meta = FlightMeta::from_json(raw, Path::new("cold.meta.json")).unwrap();
    rec
}

#[test]
fn the_oil_temperature_survives_csv_and_mcap() {
    let rec = record_at(233.15.into());
    assert_eq!(rec.meta.damper_oil_temperature_k, Some(233.15));
    let dir = tmp("flight_oil_roundtrip");
    rec.write_csv(&dir.join("cold")).unwrap();
    rec.write_mcap(&dir.join("cold.mcap")).unwrap();
    for p in [dir.join("cold"), dir.join("cold.mcap")] {
        let back = FlightRecord::read(&p).unwrap();
        assert_eq!(back.meta.damper_oil_temperature_k, Some(233.15), "{p:?}");
    }
}

#[test]
fn an_oil_temperature_out_of_sense_is_refused_by_key() {
    let rec = FlightRecord::read(&root().join("flightdata/c8534like")).unwrap();
    for (v, why) in [
        (serde_json::json!(-40.0), "positive"),
        (serde_json::json!(40.0), "150 to 600"),
        (serde_json::json!("cold"), "expected a number"),
    ] {
        let mut raw = rec.meta.raw.clone();
        raw.insert("damper_oil_temperature_K".into(), v.clone());
        let e = FlightMeta::from_json(raw, Path::new("x.meta.json"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("x.meta.json") && e.contains("damper_oil_temperature_K") && e.contains(why),
            "{v}: {e}"
        );
    }
}

#[test]
fn the_diagnosis_replays_the_damper_at_the_record_s_oil_temperature() {
    let mut deck = DamperDeck::from_file(&root().join("flightdata/damper_nominal.toml")).unwrap();
    deck.oil = Some(OilTemperature {
        temperature_k: 293.15,
        density_per_k: 7.0e-4,
        bulk_modulus_per_k: 5.0e-3,
        viscosity_per_k: 0.0,
    });
    let path = Path::new("cold");
    let m = flight_measurement(&record_at(233.15.into()), path, None).unwrap();
    assert_eq!(m.oil_temperature_k, Some(233.15));
    let n = m.time_s.len();
    let mut at_record = Vec::new();
    simulate(&deck, &m, n, 1.0e-5, &mut at_record).unwrap();
    // The same as the deck moved to -40 C by hand, bit for bit.
    let unmoved = rotorsim::diagnose::Measurement {
        oil_temperature_k: None,
        ..m.clone()
    };
    let mut cold = Vec::new();
    simulate(
        &deck.at_oil_temperature(233.15).unwrap(),
        &unmoved,
        n,
        1.0e-5,
        &mut cold,
    )
    .unwrap();
    assert_eq!(at_record, cold);
    // ...and not the deck at its reference: the cold oil is denser and stiffer.
    let mut warm = Vec::new();
    simulate(&deck, &unmoved, n, 1.0e-5, &mut warm).unwrap();
    let rms = |f: &mut dyn Iterator<Item = f64>| {
        let v: Vec<f64> = f.collect();
        (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
    };
    let change =
        rms(&mut cold.iter().zip(&warm).map(|(c, w)| c - w)) / rms(&mut warm.iter().copied());
    assert!(
        change > 0.01,
        "the cold oil changes the force by {change} of its RMS"
    );
    // A deck without the law cannot use the temperature: the diagnosis says so.
    let opts = DiagnoseOptions::baseline_only();
    let bare = DamperDeck { oil: None, ..deck };
    let d = diagnose(&bare, &[m], &opts).unwrap().diagnosis;
    assert!(
        d.limitations
            .iter()
            .any(|l| l.starts_with("the oil temperature recorded (233.2 K) moves nothing")),
        "{:#?}",
        d.limitations
    );
}

/// `rotorsim run` on a record stating its oil temperature: the damper runs at it as when the
/// temperature is set by hand (bit for bit), and `--set` of the temperature takes precedence.
#[test]
fn a_run_takes_the_damper_to_the_record_s_oil_temperature() {
    use std::process::Command;
    let dir = tmp("flight_oil_run");
    let deck = dir.join("oil.toml");
    std::fs::write(
        &deck,
        format!(
            "{}\n[damper.physical.oil]\nreference_temperature_K = 293.15\ndensity_thermal_coefficient_per_K = 7.0e-4\nbulk_modulus_thermal_coefficient_per_K = 5.0e-3\n",
            std::fs::read_to_string(root().join("flightdata/damper_nominal.toml")).unwrap()
        ),
    )
    .unwrap();
    let cold = dir.join("cold");
    record_at(233.15.into()).write_csv(&cold).unwrap();
    let run = |out: &str, flight: &Path, set: Option<&str>| {
        let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
            .current_dir(root())
            .args([
                "run", "--model", "rigid", "--revs", "20", "--damper", "physical",
            ])
            .arg("--damper-deck")
            .arg(&deck)
            .arg("--flight")
            .arg(flight)
            .arg("--out")
            .arg(dir.join(out))
            .args(set.map(|s| vec!["--set", s]).unwrap_or_default())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let s = support::read_json(&dir.join(out).join("summary.json"));
        let rev = std::fs::read(dir.join(out).join("physical/last_rev.csv")).unwrap();
        (s["damper_oil_temperature_K"].as_f64(), rev)
    };
    let shipped = root().join("flightdata/c8534like");
    let (t_rec, by_record) = run("by_record", &cold, None);
    let (t_set, by_hand) = run(
        "by_hand",
        &shipped,
        Some("damper.physical.oil.temperature_K=233.15"),
    );
    assert_eq!((t_rec, t_set), (Some(233.15), Some(233.15)));
    assert!(
        by_record == by_hand,
        "the record's temperature is not the one set by hand"
    );
    let (t_over, overridden) = run(
        "overridden",
        &cold,
        Some("damper.physical.oil.temperature_K=293.15"),
    );
    assert_eq!(t_over, Some(293.15));
    assert!(overridden != by_record, "--set did not take precedence");
}

/// `--set` of the temperature for every blade, or for one: that blade's damper keeps the value
/// set, the others take the record's.
#[test]
fn a_set_temperature_takes_precedence_blade_by_blade() {
    use rotorsim::overrides::Override;
    let rec = record_at(233.15.into());
    let mut job = rotorsim::run::job::RunJob::new(tmp("flight_oil_blades"));
    assert_eq!(job.record_oil_temperature_k(&rec, None), Some(233.15));
    job.overrides =
        vec![Override::parse("blades.2.damper.physical.oil.temperature_K=300").unwrap()];
    assert_eq!(job.record_oil_temperature_k(&rec, Some(2)), None);
    for blade in [None, Some(1), Some(3), Some(12)] {
        assert_eq!(
            job.record_oil_temperature_k(&rec, blade),
            Some(233.15),
            "{blade:?}"
        );
    }
    job.overrides = vec![Override::parse("damper.physical.oil.temperature_K=300").unwrap()];
    for blade in [None, Some(1), Some(2)] {
        assert_eq!(job.record_oil_temperature_k(&rec, blade), None, "{blade:?}");
    }
}
