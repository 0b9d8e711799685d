//! A sweep's cases run as [`RunJob`]s in this process, showing nothing.
use super::{plan, Case, CaseRunner};
use crate::flight::FlightRecord;
use crate::resonance::StabilitySettings;
use crate::run::job::{self, RunJob, RunSettings};
use crate::run::settings::JobSettings;
use crate::run::stop::StopFlag;
use crate::run::Silent;
use anyhow::{anyhow, bail};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// A case with `stability_speeds`: the ground-resonance map of its rotor deck (its deck values
/// applied) over those speeds, run as `rotorsim stability` runs it. Its keys read as
/// [`StabilitySettings`] (`stability_speeds` is `speeds`, the dotted keys `set`; `rotor`
/// defaults to a run's); None for a case that is a run.
pub fn stability_settings(case: &Case) -> Option<anyhow::Result<StabilitySettings>> {
    case.option(plan::STABILITY_SPEEDS)?;
    Some((|| {
        let known = plan::stability_options();
        let mut given = serde_json::Map::new();
        for (k, v) in &case.settings {
            if k.contains('.') {
                continue; // a deck value: settings.set below
            }
            if !known.contains(k) {
                bail!(
                    "case {}: `{k} = {v}` is not an option of a stability case (those are {})",
                    case.id,
                    known.join(", ")
                );
            }
            let name = if k == plan::STABILITY_SPEEDS {
                "speeds"
            } else {
                k
            };
            given.insert(name.to_string(), serde_json::to_value(v)?);
        }
        given
            .entry("rotor")
            .or_insert_with(|| job::DEFAULT_ROTOR.into());
        let mut settings: StabilitySettings =
            serde_json::from_value(serde_json::Value::Object(given))
                .map_err(|e| anyhow!("case {}: {e}", case.id))?;
        settings.set = case.overrides();
        Ok(settings)
    })())
}

/// [`stability_settings`], its speeds, damper and deck checked with the case's names before
/// the job checks the rest.
fn stability_case(case: &Case) -> Option<anyhow::Result<StabilitySettings>> {
    let settings = stability_settings(case)?;
    Some(settings.and_then(|settings| {
        let speeds = settings.speeds.as_deref().unwrap_or_default();
        let what = format!("case {}: stability_speeds", case.id);
        let speeds = crate::resonance::parse_speeds(&what, speeds)?;
        let rotor = settings.rotor.clone().unwrap_or_default();
        let deck = crate::rotor::RotorDeck::from_file_with(&rotor, &settings.set)?;
        crate::resonance::check_rad_s(&what, &speeds, &deck)?;
        if deck.spec.airframe.is_none() {
            bail!(
                "case {}: rotor deck {} has no [airframe]: a stability case needs the airframe under the hub (docs/stability.md)",
                case.id,
                rotor.display()
            );
        }
        let model = match &settings.damper {
            Some(d) => d
                .parse::<crate::hydraulics::DamperModel>()
                .map_err(|e| anyhow!("case {}: damper `{d}`: {e}", case.id))?,
            None => deck.damper()?.model,
        };
        deck.damper()?.require(model)?;
        Ok(settings)
    }))
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
        if plan::NOT_PLAN_OPTIONS.contains(&k.as_str()) || !known.contains_key(k) {
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
            return c?.job(out)?.execute(&mut |_| {}).map(|_| ());
        }
        job_of(case, out, initial)?
            .execute_until(&Silent, &self.stop)
            .map(|_| ())
    }
}
