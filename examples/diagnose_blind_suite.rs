//! Blind suite of the diagnosis (docs/diagnosis.md "Blind suite"): SYNTHETIC campaigns by an
//! independent truth model, diagnosed, scored; one CSV row per campaign as it finishes, then the
//! rates.
//! `cargo run --release --example diagnose_blind_suite -- [OUT.csv] [CYCLES] [RATE_HZ] [ID_PREFIX...]`
//! `cargo run --release --example diagnose_blind_suite -- --effect-size [ID_PREFIX...]` (effect
//! vs noise only, of the campaigns whose id starts with a prefix; all without one)
//! `--suite 1|2|all` anywhere among the arguments: the first truth model's suite (the default),
//! the second's (`t2_` campaigns, truth2.rs; the CSV defaults to
//! docs/diagnosis_blind_suite_truth2.csv) or both. Without `--suite`, ID prefixes select from
//! both suites and no prefix runs the first. CYCLES and RATE_HZ apply to the first truth's
//! campaigns; a second-truth campaign runs its own bench programme (suite2.rs).
//! `cargo run --release --example diagnose_blind_suite -- --held-out ID [KEY=VALUE...]` (the
//! held-out RMS of the nominal deck with these keys set, e.g.
//! `damper.physical.extensions.free_play_m=8e-5`, on campaign ID's data: what a model reaches)
//! (defaults docs/diagnosis_blind_suite.csv, 4 cycles per harmonic test, 2 kHz, all campaigns;
//! with BLIND_JSON_DIR set, every diagnosis.json is written there as `<id>.json`).
//! CSV columns: id, kind (bench/flight), truth (first/second), hidden effect(s) (`+`-joined
//! causes, acquisition faults `force_lag`, `force_offset`, `force_gain`, `force_drift`,
//! `force_clipping`, `force_dropouts` among them), magnitudes, named cause,
//! exact, hidden among named, held-out gain, g* (best reachable gain), sub-noise, required gain,
//! then for each true parameter the named cause fitted (a fault's `lag_s`, `offset_N`, `gain`,
//! `drift_N_per_s` too): name, true value, fitted value, 95% interval, covered; and the wall
//! time. Whether the faults were named follows from `hidden` and `named`; the rates printed at
//! the end count it, per truth model.
#[path = "../tests/blind_support/mod.rs"]
mod blind;
use rotorsim::diagnose::rotor::flight_measurement;
use rotorsim::diagnose::{diagnose, DiagnoseOptions};
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperDeck;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which suites `--suite` asks for (None: not given).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Suites {
    First,
    Second,
    All,
}

/// The campaigns of the suites asked for; without `--suite`, both suites when prefixes select,
/// else the first.
fn campaigns(suites: Option<Suites>, prefixes: &[String]) -> Vec<blind::Campaign> {
    let all = match suites {
        Some(Suites::First) => blind::suite(),
        Some(Suites::Second) => blind::suite2(),
        Some(Suites::All) => blind::suite().into_iter().chain(blind::suite2()).collect(),
        None if prefixes.is_empty() => blind::suite(),
        None => blind::suite().into_iter().chain(blind::suite2()).collect(),
    };
    all.into_iter()
        .filter(|c| prefixes.is_empty() || prefixes.iter().any(|p| c.id.starts_with(p.as_str())))
        .collect()
}

fn main() -> anyhow::Result<()> {
    let mut a: Vec<String> = std::env::args().collect();
    let mut suites = None;
    if let Some(i) = a.iter().position(|x| x == "--suite") {
        let v = a.get(i + 1).cloned().unwrap_or_default();
        suites = Some(match v.as_str() {
            "1" => Suites::First,
            "2" => Suites::Second,
            "all" => Suites::All,
            _ => anyhow::bail!("--suite takes 1, 2 or all, not {v:?}"),
        });
        a.drain(i..(i + 2).min(a.len()));
    }
    if a.get(1).map(String::as_str) == Some("--effect-size") {
        // Effect size only (no diagnosis): RMS of the effect, noise sigma, best reachable gain.
        println!("id,truth,hidden,effect_rms_N,noise_sigma_N,best_gain");
        for cp in campaigns(suites, &a[2..]) {
            let (r, s, g) = blind::effect_size(&cp, 4, 2000.0).map_err(anyhow::Error::msg)?;
            println!(
                "{},{},{},{r:.1},{s:.1},{g:.3}",
                cp.id,
                cp.truth.name(),
                cp.hidden()
            );
        }
        return Ok(());
    }
    if a.get(1).map(String::as_str) == Some("--held-out") {
        return held_out(&a[2..]);
    }
    let out = PathBuf::from(a.get(1).cloned().unwrap_or_else(|| {
        if suites == Some(Suites::Second) {
            "docs/diagnosis_blind_suite_truth2.csv".into()
        } else {
            "docs/diagnosis_blind_suite.csv".into()
        }
    }));
    let cycles: usize = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(4);
    let rate: f64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(2000.0);
    let prefixes: Vec<String> = a.iter().skip(4).cloned().collect();
    let base = DamperDeck::from_file(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/flightdata/damper_nominal.toml"
    )))?;
    let records = std::env::temp_dir().join(format!("rotorsim_blind_{}", std::process::id()));
    std::fs::create_dir_all(&records)?;
    let mut csv = std::fs::File::create(&out)?;
    writeln!(csv, "{}", blind::csv_header())?;
    let mut rows = Vec::new();
    // Flight records first, then round-robin over the groups (first magnitude of every
    // effect, then the second, ...), so a partial run already spans the library.
    let mut seen = std::collections::HashMap::new();
    let mut order: Vec<(usize, usize, blind::Campaign)> = campaigns(suites, &prefixes)
        .into_iter()
        .map(|c| {
            let group =
                c.id.rsplit_once('_')
                    .map_or(c.id.clone(), |g| g.0.to_string());
            let n = seen.entry(group).or_insert(0usize);
            *n += 1;
            (usize::from(!c.flight), *n, c)
        })
        .collect();
    order.sort_by_key(|(f, n, _)| (*f, *n));
    for (_, _, cp) in order {
        let t0 = Instant::now();
        let data = if cp.flight {
            let stem = records.join(&cp.id);
            blind::write_flight_record(&cp, &stem).map_err(anyhow::Error::msg)?;
            let rec = FlightRecord::read(&stem)?;
            vec![flight_measurement(&rec, &stem, None)?]
        } else {
            blind::bench_campaign(&cp, cycles, rate).map_err(anyhow::Error::msg)?
        };
        let o = diagnose(&cp.base_deck(&base), &data, &DiagnoseOptions::default())?;
        if let Some(dir) = std::env::var_os("BLIND_JSON_DIR") {
            // Every diagnosis in full, for study (optional).
            std::fs::create_dir_all(&dir)?;
            let path = Path::new(&dir).join(format!("{}.json", cp.id));
            std::fs::write(path, serde_json::to_string_pretty(&o.diagnosis)?)?;
        }
        let wall = t0.elapsed().as_secs_f64();
        // g*, the truth's own held-out gain (the detectability rule), outside the timing
        let best = (!cp.effects.is_empty())
            .then(|| blind::effect_size(&cp, cycles, rate).map(|e| e.2))
            .transpose()
            .map_err(anyhow::Error::msg)?;
        let s = blind::score(&cp, &o.diagnosis, best);
        let row = blind::csv_row(&cp, &s, wall);
        println!("{row}");
        writeln!(csv, "{row}")?;
        csv.flush()?;
        rows.push((cp, s));
    }
    println!("{}", blind::rates_by_truth(&rows));
    if rows
        .iter()
        .any(|(c, _)| c.truth.name() != rows[0].0.truth.name())
    {
        println!("both truths:\n{}", blind::rates(&rows));
    }
    let _ = std::fs::remove_dir_all(&records);
    Ok(())
}

/// Held-out RMS of the nominal deck, and of it with `KEY=VALUE` set, on a bench campaign's data
/// (the diagnosis' own split and replay, no candidate fitted).
fn held_out(a: &[String]) -> anyhow::Result<()> {
    use rotorsim::diagnose::Measurement;
    let id = a
        .first()
        .ok_or_else(|| anyhow::anyhow!("--held-out ID [KEY=VALUE...]"))?;
    let cp = blind::suite()
        .into_iter()
        .chain(blind::suite2())
        .find(|c| &c.id == id && !c.flight)
        .ok_or_else(|| anyhow::anyhow!("no bench campaign {id}"))?;
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/flightdata/damper_nominal.toml"
    ));
    // The keys as `rotorsim run --set` takes them, each validated.
    let sets = a[1..]
        .iter()
        .map(|kv| rotorsim::overrides::Override::parse(kv))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let set = rotorsim::run::job::damper_deck_with(path, &sets)?;
    let nominal = DamperDeck::from_file(path)?;
    let data: Vec<Measurement> =
        blind::bench_campaign(&cp, 4, 2000.0).map_err(anyhow::Error::msg)?;
    let opts = DiagnoseOptions::baseline_only();
    let rms = |d: &DamperDeck| -> anyhow::Result<f64> {
        Ok(diagnose(&cp.base_deck(d), &data, &opts)?
            .diagnosis
            .validation
            .baseline_rms_N)
    };
    let (base, with) = (rms(&nominal)?, rms(&set)?);
    println!(
        "{id}: held-out RMS nominal {base:.2} N, with the keys {with:.2} N, gain {:.4}",
        1.0 - with / base
    );
    Ok(())
}
