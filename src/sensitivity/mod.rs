//! `rotorsim sensitivity` (docs/sensitivity.md): every value the rotor deck labels `# ASSUMED`
//! (and any `--vary KEY=LOW:HIGH`) moved to a low and a high value, one at a time, through the
//! sweep engine, and the change of the key outputs tabulated per parameter.
//!
//! The cases are a sweep plan written into the output folder (`DIR/sensitivity_plan.toml`) and
//! run by the same code as `rotorsim sweep` ([`crate::sweep::execute`]): in parallel, resumable,
//! and as the shards of a Slurm array. Every case starts cold by default, as a plain `rotorsim
//! run` does: a warm-started case's Floquet multipliers (the lag damping) can differ from a cold
//! run's well beyond the periodicity tolerance. With warm starts the case order puts the
//! nominal case in the middle of the first warm-start group (groups of 3), so it still starts
//! cold.
//!
//! [`scan`] finds the labelled values in the deck text; [`table`] reads the case folders into
//! the sensitivity table and writes sensitivity.csv, sensitivity.html and summary.json.
pub mod job;
pub mod scan;
pub mod table;

use crate::sweep::{self, CaseRunner, Plan, SweepOptions, SweepProgress, SweepReport};
use anyhow::{anyhow, bail, Context};
use scan::{Skipped, Target};
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// Default relative factors of a labelled value, tried in turn on each side until the deck's
/// validation accepts the value: below the nominal value, then above it.
pub const LOW_FACTORS: [f64; 3] = [0.5, 0.8, 0.95];
pub const HIGH_FACTORS: [f64; 3] = [2.0, 1.25, 1.05];

/// Warm-start group size of the plan: (low, nominal, high) of the first parameter is the first
/// group, with the nominal case as its cold-started seed.
pub const GROUP_SIZE: i64 = 3;

/// Id of the nominal case (the deck as it is).
pub const NOMINAL: &str = "nominal";

/// Name of the plan file written into the output folder.
pub const PLAN_FILE: &str = "sensitivity_plan.toml";

/// A `--vary KEY=LOW:HIGH` as given.
#[derive(Clone, Debug, PartialEq)]
pub struct Vary {
    pub text: String,
    pub key: String,
    pub low: f64,
    pub high: f64,
}

impl Vary {
    /// Parses `KEY=LOW:HIGH` (KEY may name an array component, `key[i]`).
    pub fn parse(s: &str) -> anyhow::Result<Self> {
        let bad = |why: String| anyhow!("--vary {s}: {why}");
        let (key, range) = s.split_once('=').ok_or_else(|| {
            bad("expected KEY=LOW:HIGH (e.g. bearing.lag_damping_Nms_per_rad=136:544)".into())
        })?;
        let (lo, hi) = range.split_once(':').ok_or_else(|| {
            bad(format!(
                "expected LOW:HIGH after `=`, found `{range}` (e.g. 136:544)"
            ))
        })?;
        let num = |what: &str, t: &str| -> anyhow::Result<f64> {
            match t.trim().parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => Err(bad(format!("{what} `{}` is not a finite number", t.trim()))),
            }
        };
        let (low, high) = (num("LOW", lo)?, num("HIGH", hi)?);
        if low >= high {
            return Err(bad(format!("LOW ({low}) must be below HIGH ({high})")));
        }
        let key = key.trim();
        if key.is_empty() {
            return Err(bad("KEY is empty".into()));
        }
        Ok(Vary {
            text: s.to_string(),
            key: key.to_string(),
            low,
            high,
        })
    }
}

/// One parameter of the sensitivity: the number moved, its low and high values, and whether
/// each side runs (a side whose every default factor the deck refuses stays at the nominal
/// value and is not run).
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub target: Target,
    pub low: f64,
    pub high: f64,
    pub low_runs: bool,
    pub high_runs: bool,
    /// Factors of the nominal value still to try on each side when its case fails to run
    /// (default ranges only; empty for `--vary`).
    pub low_next: Vec<f64>,
    pub high_next: Vec<f64>,
    /// Which folder holds each side's case: 0 the output folder, k its `fallback-k/`.
    pub low_round: usize,
    pub high_round: usize,
    /// How the range was chosen, for tables (`x0.5 .. x2`, `--vary`, and any factor refused).
    pub range: String,
    /// Where the parameter comes from: `ASSUMED (line N)` or `--vary`.
    pub source: String,
}

impl Param {
    pub fn name(&self) -> String {
        self.target.name()
    }
    /// Case ids of the low and high sides.
    pub fn case_ids(&self) -> (String, String) {
        let base: String = self
            .name()
            .chars()
            .map(|c| match c {
                '[' => '.',
                ']' => '_',
                c => c,
            })
            .collect();
        let base = base.trim_end_matches('_').to_string();
        (format!("{base}-low"), format!("{base}-high"))
    }
    pub fn unit(&self) -> String {
        scan::unit_of(&self.target.key)
    }
}

/// What `rotorsim sensitivity` runs: the rotor deck, the run options every case shares, the
/// `--vary` ranges and how the sweep runs.
#[derive(Clone, Debug)]
pub struct SensitivityOptions {
    pub rotor: PathBuf,
    pub flight: PathBuf,
    /// Rotor model: `uh60a` (multibody), `rigid` or `sdof`.
    pub model: String,
    /// One damper model (None: the deck's `[damper] model`, else physical).
    pub damper: Option<String>,
    pub vary: Vec<Vary>,
    /// Only the `--vary` parameters, not the deck's labelled values.
    pub only_vary: bool,
    pub out: PathBuf,
    pub sweep: SweepOptions,
    /// Warm starts within groups of 3 (default off: every case cold).
    pub warm_start: bool,
}

/// The parameters and the plan of a sensitivity, before anything runs.
#[derive(Clone, Debug)]
pub struct Setup {
    pub params: Vec<Param>,
    pub skipped: Vec<Skipped>,
    pub damper: String,
    /// The plan TOML written to DIR/sensitivity_plan.toml.
    pub plan_text: String,
}

fn base_settings(o: &SensitivityOptions, damper: &str) -> Table {
    let mut base = Table::new();
    let s = |p: &Path| Value::String(p.display().to_string());
    base.insert("rotor".into(), s(&o.rotor));
    base.insert("flight".into(), s(&o.flight));
    base.insert("model".into(), Value::String(o.model.clone()));
    base.insert("damper".into(), Value::String(damper.to_string()));
    base
}

fn case_with(base: &Table, id: &str, setting: Option<(&str, Value)>) -> sweep::Case {
    let mut settings: std::collections::BTreeMap<String, Value> =
        base.iter().map(|(k, v)| (k.clone(), v.clone())).collect();
    if let Some((k, v)) = setting {
        settings.insert(k.to_string(), v);
    }
    sweep::Case {
        id: id.to_string(),
        settings,
    }
}

/// Why the deck's `[aero]` values are not varied: a study's runs replay the record's measured
/// airloads, which do not read them (a swing of zero would rank them as mattering nothing).
const UNUSED_AERO: &str = "an [aero] value: the study's runs replay the record's measured airloads, which do not use the lifting line (its values act only with --airloads computed or hybrid)";

/// Finds the parameters (the deck's labelled values, then `--vary`), chooses and checks their
/// ranges with `runner` (the deck's own validation, as the sweep checks its cases), and writes
/// the plan text. Errors name the option or the key.
pub fn setup(o: &SensitivityOptions, runner: &dyn CaseRunner) -> anyhow::Result<Setup> {
    let file = o.rotor.display().to_string();
    let deck = crate::rotor::RotorDeck::from_file(&o.rotor)
        .with_context(|| format!("--rotor {file}: reading the rotor deck"))?;
    let root = deck.table();
    let damper = match &o.damper {
        Some(d) if d == "all" => bail!(
            "--damper all: a sensitivity follows one damper model (linear, nonlinear or physical)"
        ),
        Some(d) => d.clone(),
        None => scan::lookup(root, "damper.model")
            .and_then(|v| v.as_str())
            .unwrap_or("physical")
            .to_string(),
    };
    let found = deck.assumed();
    let mut skipped = found.skipped.clone();
    let mut targets: Vec<Target> = Vec::new();
    if !o.only_vary {
        for l in &found.labelled {
            if l.key == "aero" || l.key.starts_with("aero.") {
                skipped.push(Skipped {
                    line: l.line,
                    key: Some(l.key.clone()),
                    text: format!("{} = {}  # {}", l.key, l.value, l.comment),
                    reason: UNUSED_AERO.into(),
                });
                continue;
            }
            let (t, s) = scan::targets(l);
            targets.extend(t);
            skipped.extend(s);
        }
    }
    if targets.is_empty() && o.vary.is_empty() {
        let why = if o.only_vary {
            "--only-vary without any --vary KEY=LOW:HIGH".to_string()
        } else if found.labelled.is_empty() && found.skipped.is_empty() {
            format!("--rotor {file}: the deck labels no value `# ASSUMED` (a comment on the key's line) and no --vary KEY=LOW:HIGH was given")
        } else {
            format!(
                "--rotor {file}: none of the deck's ASSUMED labels gives a number to vary ({}) and no --vary KEY=LOW:HIGH was given",
                skipped
                    .iter()
                    .map(|s| format!("line {}: {}", s.line, s.reason))
                    .collect::<Vec<_>>()
                    .join("; ")
            )
        };
        bail!("nothing to vary: {why}");
    }
    let base = base_settings(o, &damper);
    // the options and the deck as they are, before any range is chosen
    runner.check(&case_with(&base, NOMINAL, None))?;
    let mut params: Vec<Param> = Vec::new();
    let check = |t: &Target, x: f64| -> anyhow::Result<()> {
        runner.check(&case_with(
            &base,
            "range-check",
            Some((t.key.as_str(), t.value_at(x))),
        ))
    };
    for t in targets {
        if o.vary.iter().any(|v| v.key == t.name()) {
            continue; // --vary gives its range
        }
        params.push(default_param(t, &check));
    }
    for v in &o.vary {
        let t = scan::target_of(root, &v.key)
            .map_err(|e| anyhow!("--vary {}: deck {file}: {e}", v.text))?;
        if t.integer && (v.low.fract() != 0.0 || v.high.fract() != 0.0) {
            bail!(
                "--vary {}: `{}` is an integer in the deck: LOW and HIGH must be whole numbers",
                v.text,
                v.key
            );
        }
        for x in [v.low, v.high] {
            check(&t, x).map_err(|e| anyhow!("--vary {}: {e:#}", v.text))?;
        }
        if let Some(p) = params.iter().position(|p| p.name() == t.name()) {
            params.remove(p);
        }
        params.push(Param {
            low: v.low,
            high: v.high,
            low_runs: true,
            high_runs: true,
            low_next: vec![],
            high_next: vec![],
            low_round: 0,
            high_round: 0,
            range: "--vary".into(),
            source: match t.line {
                Some(n) => format!("--vary (deck line {n})"),
                None => "--vary".into(),
            },
            target: t,
        });
    }
    let plan_text = plan_text(o, &base, &params)?;
    Ok(Setup {
        params,
        skipped,
        damper,
        plan_text,
    })
}

/// A labelled value's parameter with its default range: each side at the first of its factors
/// the deck accepts (`check`), the refused ones noted.
fn default_param(t: Target, check: &dyn Fn(&Target, f64) -> anyhow::Result<()>) -> Param {
    let mut notes = Vec::new();
    let mut side = |factors: &[f64]| -> (Option<f64>, Vec<f64>) {
        let mut refused = Vec::new();
        let mut why = String::new();
        for f in factors {
            let x = t.nominal * f;
            match check(&t, x) {
                Ok(()) => break,
                Err(e) => {
                    refused.push(format!("x{f}"));
                    if why.is_empty() {
                        // the deck's reason, without the override and file it names
                        let line = first_line(&e);
                        let at = format!("{}: ", t.key);
                        why = match line.find(&at) {
                            Some(i) => line[i + at.len()..].to_string(),
                            None => line,
                        };
                    }
                }
            }
        }
        if !refused.is_empty() {
            notes.push(format!("{} refused: {why}", refused.join(", ")));
        }
        let k = refused.len();
        (
            factors.get(k).copied(),
            factors.get(k + 1..).unwrap_or_default().to_vec(),
        )
    };
    let ((down, down_next), (up, up_next)) = (side(&LOW_FACTORS), side(&HIGH_FACTORS));
    // numeric order: a negative nominal value is lowest at the larger factor
    let (fl, fh, low_next, high_next) = if t.nominal > 0.0 {
        (down, up, down_next, up_next)
    } else {
        (up, down, up_next, down_next)
    };
    let (low_runs, high_runs) = (fl.is_some(), fh.is_some());
    let fs = |f: Option<f64>| f.map_or("x1 (none accepted)".to_string(), |f| format!("x{f}"));
    let mut range = format!("{} .. {}", fs(fl), fs(fh));
    if !notes.is_empty() {
        range.push_str(&format!(" ({})", notes.join("; ")));
    }
    Param {
        low: t.nominal * fl.unwrap_or(1.0),
        high: t.nominal * fh.unwrap_or(1.0),
        low_runs,
        high_runs,
        low_next,
        high_next,
        low_round: 0,
        high_round: 0,
        range,
        source: format!("ASSUMED (line {})", t.line.unwrap_or(0)),
        target: t,
    }
}

/// The deck's own words of a refusal: the first line, without the `--set KEY=VALUE: ` prefix.
fn first_line(e: &anyhow::Error) -> String {
    let s = format!("{e:#}");
    let line = s.lines().next().unwrap_or_default();
    match line.strip_prefix("--set ") {
        Some(rest) => rest.split_once(": ").map_or(rest, |(_, r)| r).to_string(),
        None => line.to_string(),
    }
}

/// The sweep plan of the parameters: the first parameter's low case, the nominal case, its
/// high case, then the low and high cases of the others, in groups of [`GROUP_SIZE`].
fn plan_text(o: &SensitivityOptions, base: &Table, params: &[Param]) -> anyhow::Result<String> {
    let mut cases: Vec<(String, Option<(String, Value)>)> = Vec::new();
    let mut nominal_placed = false;
    for p in params {
        let (lo, hi) = p.case_ids();
        if p.low_runs {
            cases.push((lo, Some((p.target.key.clone(), p.target.value_at(p.low)))));
        }
        if !nominal_placed {
            cases.push((NOMINAL.into(), None));
            nominal_placed = true;
        }
        if p.high_runs {
            cases.push((hi, Some((p.target.key.clone(), p.target.value_at(p.high)))));
        }
    }
    plan_of(
        o.warm_start,
        base,
        cases,
        "the nominal case and a\n# low and a high case per parameter",
    )
}

fn plan_of(
    warm_start: bool,
    base: &Table,
    cases: Vec<(String, Option<(String, Value)>)>,
    what: &str,
) -> anyhow::Result<String> {
    let cases: Vec<Value> = cases
        .into_iter()
        .map(|(id, kv)| {
            let mut t = Table::new();
            t.insert("id".into(), Value::String(id));
            if let Some((k, v)) = kv {
                t.insert(k, v);
            }
            Value::Table(t)
        })
        .collect();
    let mut root = Table::new();
    root.insert("base".into(), Value::Table(base.clone()));
    let mut sw = Table::new();
    sw.insert("warm_start".into(), Value::Boolean(warm_start));
    sw.insert("group_size".into(), Value::Integer(GROUP_SIZE));
    root.insert("sweep".into(), Value::Table(sw));
    root.insert("case".into(), Value::Array(cases));
    let body = toml::to_string(&root).map_err(|e| anyhow!("writing the sensitivity plan: {e}"))?;
    Ok(format!(
        "# The sweep plan of `rotorsim sensitivity` (docs/sensitivity.md): {what}.\n# `rotorsim sweep {PLAN_FILE} --out DIR` runs the same cases.\n{body}"
    ))
}

/// Writes DIR/sensitivity_plan.toml and reads it back as a sweep plan (the file is what the
/// sweep runs, also as a Slurm array).
pub fn write_plan(out: &Path, setup: &Setup) -> anyhow::Result<(PathBuf, Plan)> {
    std::fs::create_dir_all(out)
        .with_context(|| format!("creating the output folder {}", out.display()))?;
    let path = out.join(PLAN_FILE);
    crate::io::write_atomic(&path, setup.plan_text.as_bytes())?;
    let plan = Plan::from_file(&path)?;
    Ok((path, plan))
}

/// What [`run`] did.
#[derive(Debug)]
pub struct Outcome {
    pub setup: Setup,
    pub report: SweepReport,
    /// The table (None for a shard: the last shard's `rotorsim sensitivity` run builds it).
    pub table: Option<table::Sensitivity>,
    /// Stale lock files of killed sweeps taken over (say so to the user).
    pub notes: Vec<String>,
}

/// Rounds of fallback cases at most (one per remaining default factor).
pub const MAX_FALLBACK_ROUNDS: usize = 2;

/// Folder of fallback round `k` (0: the output folder itself).
pub fn round_dir(out: &Path, k: usize) -> PathBuf {
    if k == 0 {
        out.to_path_buf()
    } else {
        out.join(format!("fallback-{k}"))
    }
}

/// Runs the cases of the plan (those not done) and, without a shard, the fallback rounds and
/// writes DIR/sensitivity.csv, DIR/sensitivity.html and DIR/summary.json (and the sweep's
/// sweep.csv and sweep.html).
///
/// Fallback: a side of a default range whose case fails to run (the model does not reach its
/// initial equilibrium at x2 of a length, say) is tried again at the next factor towards the
/// nominal value (x1.25, then x1.05; x0.8, then x0.95), as a sweep of those cases in
/// `DIR/fallback-1/`, then `DIR/fallback-2/`. The rounds depend only on which cases failed, so
/// running the command again resumes them too.
pub fn run(
    o: &SensitivityOptions,
    mut setup: Setup,
    plan: &Plan,
    runner: &dyn CaseRunner,
    progress: &dyn SweepProgress,
) -> anyhow::Result<Outcome> {
    let lock = sweep::lock(&o.out, o.sweep.shard)?;
    let notes = lock.notes.clone();
    sweep::prepare(&o.out, plan)?;
    let t0 = std::time::Instant::now();
    let mut report = sweep::execute(plan, &o.out, &o.sweep, runner, progress)?;
    if o.sweep.shard.is_some() {
        return Ok(Outcome {
            setup,
            report,
            table: None,
            notes,
        });
    }
    sweep::table::write(plan, &o.out)?;
    let base = base_settings(o, &setup.damper);
    let mut plans = vec![plan.clone()];
    for round in 1..=MAX_FALLBACK_ROUNDS {
        let prev = &plans[round - 1];
        let prev_dir = round_dir(&o.out, round - 1);
        let mut cases = Vec::new();
        for p in setup.params.iter_mut() {
            let (lo_id, hi_id) = p.case_ids();
            for high in [false, true] {
                let (runs, at, id) = if high {
                    (p.high_runs, p.high_round, &hi_id)
                } else {
                    (p.low_runs, p.low_round, &lo_id)
                };
                if !runs || at != round - 1 {
                    continue;
                }
                let r = table::read_case(prev, &prev_dir, id, &setup.damper);
                if r.status != "failed" {
                    continue;
                }
                let next = if high {
                    &mut p.high_next
                } else {
                    &mut p.low_next
                };
                let old = if high { p.high } else { p.low };
                let mut chosen = None;
                while !next.is_empty() {
                    let f = next.remove(0);
                    let x = p.target.nominal * f;
                    let c = case_with(
                        &base,
                        id,
                        Some((p.target.key.as_str(), p.target.value_at(x))),
                    );
                    if runner.check(&c).is_ok() {
                        chosen = Some((f, x));
                        break;
                    }
                }
                let Some((f, x)) = chosen else { continue };
                p.range.push_str(&format!(
                    "; {} failed to run, x{f} ({}) used",
                    crate::overrides::display(&Value::Float(old)),
                    crate::overrides::display(&Value::Float(x))
                ));
                if high {
                    p.high = x;
                    p.high_round = round;
                } else {
                    p.low = x;
                    p.low_round = round;
                }
                cases.push((
                    id.clone(),
                    Some((p.target.key.clone(), p.target.value_at(x))),
                ));
            }
        }
        if cases.is_empty() {
            break;
        }
        let dir = round_dir(&o.out, round);
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("creating the fallback folder {}", dir.display()))?;
        let text = plan_of(
            o.warm_start,
            &base,
            cases,
            &format!("fallback round {round}, the sides of the default ranges that failed to run, nearer the nominal value"),
        )?;
        let path = dir.join(PLAN_FILE);
        crate::io::write_atomic(&path, text.as_bytes())?;
        let fplan = Plan::from_file(&path)?;
        sweep::check(&fplan, runner, o.sweep.jobs, &|_, _| {})?;
        sweep::prepare(&dir, &fplan)?;
        let r = sweep::execute(&fplan, &dir, &o.sweep, runner, progress)?;
        sweep::table::write(&fplan, &dir)?;
        report.total += r.total;
        report.skipped.extend(r.skipped);
        report.ran.extend(r.ran);
        report.failed_kept.extend(r.failed_kept);
        report.warm_started += r.warm_started;
        plans.push(fplan);
    }
    let t = table::collect(o, &setup, &plans, t0.elapsed().as_secs_f64())?;
    table::write(&o.out, &t)?;
    drop(lock);
    Ok(Outcome {
        setup,
        report,
        table: Some(t),
        notes,
    })
}
