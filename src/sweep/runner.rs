//! A sweep's cases run as [`RunJob`]s in this process, showing nothing.
use super::{Case, CaseRunner};
use crate::flight::FlightRecord;
use crate::run::job::{self, RunJob, RunSettings};
use crate::run::stop::StopFlag;
use crate::run::Silent;
use anyhow::{anyhow, bail};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use toml::Value;

/// Options a stability case may set besides deck values.
const STABILITY_OPTIONS: &[&str] = &["stability_speeds", "rotor", "damper"];

/// A case with `stability_speeds`: the ground-resonance map of its rotor deck (its deck values
/// applied) with its damper model over those speeds, as `rotorsim stability` makes it.
struct StabilityCase {
    deck: crate::rotor::RotorDeck,
    model: crate::hydraulics::DamperModel,
    speeds: Vec<f64>,
}

fn stability_case(case: &Case) -> Option<anyhow::Result<StabilityCase>> {
    let Some(Value::String(speeds)) = case.option("stability_speeds") else {
        return None;
    };
    Some((|| {
        for (k, v) in &case.settings {
            if !k.contains('.') && !STABILITY_OPTIONS.contains(&k.as_str()) {
                bail!(
                    "case {}: `{k} = {v}` is not an option of a stability case (those are {})",
                    case.id,
                    STABILITY_OPTIONS.join(", ")
                );
            }
        }
        let speeds = crate::run::stability::parse_speeds(
            &format!("case {}: stability_speeds", case.id),
            speeds,
        )?;
        let rotor = match case.option("rotor") {
            Some(Value::String(r)) => PathBuf::from(r),
            _ => PathBuf::from(job::DEFAULT_ROTOR),
        };
        let deck = crate::rotor::RotorDeck::from_file_with(&rotor, &case.overrides())?;
        crate::run::stability::check_rad_s(
            &format!("case {}: stability_speeds", case.id),
            &speeds,
            &deck,
        )?;
        if deck.spec.airframe.is_none() {
            bail!(
                "case {}: rotor deck {} has no [airframe]: a stability case needs the airframe under the hub (docs/stability.md)",
                case.id,
                rotor.display()
            );
        }
        let model = match case.option("damper") {
            Some(Value::String(d)) => d
                .parse::<crate::hydraulics::DamperModel>()
                .map_err(|e| anyhow!("case {}: damper `{d}`: {e}", case.id))?,
            _ => deck.damper()?.model,
        };
        deck.damper()?.require(model)?;
        Ok(StabilityCase {
            deck,
            model,
            speeds,
        })
    })())
}

/// The run of `case` into `out`, starting from the periodic states of the result folder
/// `initial` when given. The plan has checked the settings' names and types; its run options
/// are [`RunSettings`] fields, read as the command line reads them.
pub fn job_of(case: &Case, out: &Path, initial: Option<&Path>) -> anyhow::Result<RunJob> {
    let known = RunSettings::defaults_map();
    let mut given = serde_json::Map::new();
    for (k, v) in &case.settings {
        if k.contains('.') {
            continue; // a deck value: job.overrides below
        }
        if crate::sweep::plan::NOT_PLAN_OPTIONS.contains(&k.as_str()) || !known.contains_key(k) {
            bail!("case {}: `{k} = {v}` is not a run option", case.id);
        }
        if matches!(k.as_str(), "rotor" | "flight" | "damper_deck")
            && v.as_str().is_some_and(|s| s.trim().is_empty())
        {
            bail!("case {}: `{k}` is empty (expected a file path)", case.id);
        }
        given.insert(k.clone(), serde_json::to_value(v)?);
    }
    let settings: RunSettings = serde_json::from_value(serde_json::Value::Object(given))
        .map_err(|e| anyhow!("case {}: {e}", case.id))?;
    let mut job = settings.job(out)?;
    job.overrides = case.overrides();
    job.initial_state = initial.map(Path::to_path_buf);
    Ok(job)
}

/// Runs each case as `rotorsim run` would, showing nothing. Reads each flight record once (by
/// path) for the checks, however many cases use it.
#[derive(Default)]
pub struct JobRunner {
    records: Mutex<HashMap<PathBuf, Result<Arc<FlightRecord>, String>>>,
    /// Raised: running cases stop before their next structural step (published incomplete),
    /// cases not started yet do not start (no folder: they stay to run).
    pub stop: StopFlag,
}

impl CaseRunner for JobRunner {
    fn check(&self, case: &Case) -> anyhow::Result<()> {
        let record = |p: &Path| -> anyhow::Result<Arc<FlightRecord>> {
            let known = self.records.lock().ok().and_then(|m| m.get(p).cloned());
            let r = match known {
                Some(r) => r,
                None => {
                    let r = job::read_record(p).map_err(|e| format!("{e:#}"));
                    if let Ok(mut m) = self.records.lock() {
                        m.insert(p.to_path_buf(), r.clone());
                    }
                    r
                }
            };
            r.map_err(|e| anyhow!(e))
        };
        if let Some(c) = stability_case(case) {
            return c.map(|_| ());
        }
        job_of(case, Path::new("unused"), None)?.check_with(&record)
    }
    fn run(&self, case: &Case, out: &Path, initial: Option<&Path>) -> anyhow::Result<()> {
        self.stop
            .check(0.0, &format!("case {} not started", case.id))?;
        if let Some(c) = stability_case(case) {
            let c = c?;
            let dir = crate::io::OutDir::create(out, &c.deck.input_files())?;
            return match crate::run::stability::stability_map(&c.deck, c.model, &c.speeds) {
                Ok(mut map) => {
                    map.overrides = case
                        .overrides()
                        .iter()
                        .map(|o| (o.key.clone(), o.value_text()))
                        .collect();
                    crate::run::stability::write(&map, &c.deck, &dir)?;
                    Ok(dir.finish()?)
                }
                Err(e) => {
                    dir.mark_incomplete(&format!("{e:#}"))?;
                    Err(e)
                }
            };
        }
        job_of(case, out, initial)?
            .execute_until(&Silent, &self.stop)
            .map(|_| ())
    }
}
