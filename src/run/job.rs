//! One `rotorsim run` as library code: a [`RunJob`] (plain data) checked by [`RunJob::check`]
//! and run by [`RunJob::execute`] into its result folder. The command line, the sweep's cases
//! and the Python package all run through it; they differ only in what they show (a
//! [`RunObserver`]) and print (from the returned [`RunOutcome`]).
use crate::flight::FlightRecord;
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};
use crate::io::OutDir;
use crate::overrides::Override;
use crate::rotor::{ForcedResponse, RotorDeck, RunOptions};
use crate::run::outputs::{write_outputs, Written};
use crate::run::sdof::{rigid_reduction, LagHingeSdof, SdofParams, RIGID_LABEL};
use crate::run::stop::{RunStopped, StopFlag, STOPPED_PREFIX};
use crate::run::summary::{Measured, RunInfo};
use crate::run::{self, fmt_measure, ModelOutcome, ModelRun, PeriodicMethod, Progress, Silent};
use crate::solver::NewtonMethod;
use anyhow::{anyhow, bail, Context};
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Arc;
use std::time::Instant;

/// Defaults of a run (those of `rotorsim run`'s options).
pub const DEFAULT_ROTOR: &str = "rotors/uh60a.toml";
pub const DEFAULT_FLIGHT: &str = "flightdata/c8534like";
pub const DEFAULT_REVS: usize = 100;
pub const DEFAULT_STEPS_PER_REV: usize = 256;
pub const DEFAULT_SUBSTEPS: usize = 25;

/// The damper models a run compares: all three side by side, or one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DamperChoice {
    #[default]
    All,
    One(DamperModel),
}

impl DamperChoice {
    pub fn models(self) -> Vec<DamperModel> {
        match self {
            DamperChoice::All => vec![
                DamperModel::Linear,
                DamperModel::Nonlinear,
                DamperModel::Physical,
            ],
            DamperChoice::One(m) => vec![m],
        }
    }
}

impl FromStr for DamperChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "all" => Ok(DamperChoice::All),
            _ => s
                .parse()
                .map(DamperChoice::One)
                .map_err(|e: String| format!("{e} (or all for the three in parallel)")),
        }
    }
}

/// The rotor model a run drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RotorModel {
    /// The multibody model of the rotor deck.
    #[default]
    Uh60a,
    /// The rotor deck's blade rigid on its lag hinge (docs/rotor_model.md, "Rigid-blade
    /// reduction").
    Rigid,
    /// A fast test double of the pipeline, not a rotor model: reads only the `[damper]` table.
    Sdof,
}

impl RotorModel {
    pub fn name(self) -> &'static str {
        match self {
            RotorModel::Uh60a => "uh60a",
            RotorModel::Rigid => "rigid",
            RotorModel::Sdof => "sdof",
        }
    }
}

impl FromStr for RotorModel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        [RotorModel::Uh60a, RotorModel::Rigid, RotorModel::Sdof]
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown rotor model '{s}' (expected uh60a, rigid or sdof)"))
    }
}

impl FromStr for PeriodicMethod {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        [PeriodicMethod::Shooting, PeriodicMethod::March]
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown method '{s}' (expected shooting or march)"))
    }
}

/// A hydraulic sub-step scheme with the name it was given: summary.json records that name
/// (`sdirk3` stays `sdirk3`, an alias of `implicit`). `auto` (the default) is RK4, the paper's
/// scheme, with more sub-steps where a physical damper's viscous orifice would make an RK4
/// sub-step unstable ([`SchemeChoice::resolve`]); the run records the scheme and sub-steps
/// it used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SchemeChoice {
    pub scheme: Scheme,
    pub name: String,
    /// Chosen by the run (`auto`), not by the user.
    pub auto: bool,
}

/// The largest `h x rate` taken as stable for an RK4 sub-step: RK4's real-axis stability
/// limit is 2.785; the rest is margin for the rate's growth as a chamber is compressed.
pub const RK4_STABLE_H_RATE: f64 = 2.5;

impl Default for SchemeChoice {
    fn default() -> Self {
        SchemeChoice {
            scheme: Scheme::Rk4,
            name: "auto".into(),
            auto: true,
        }
    }
}

impl FromStr for SchemeChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "auto" {
            return Ok(Self::default());
        }
        Ok(SchemeChoice {
            scheme: s
                .parse()
                .map_err(|e: String| format!("{e}, or auto (the default)"))?,
            name: s.to_string(),
            auto: false,
        })
    }
}

impl SchemeChoice {
    /// The scheme and sub-steps to run for dampers whose fastest rates are `rates` [1/s] at
    /// hydraulic sub-steps of `h` [s] (`substeps` a structural step): `auto` is RK4 with the
    /// sub-steps raised until `h x rate` is within [`RK4_STABLE_H_RATE`] for every damper (an
    /// RK4 sub-step is far cheaper than an implicit one); an RK4 asked for by name at an
    /// unstable sub-step is an error that says what to do.
    pub fn resolve(&self, rates: &[f64], h: f64, substeps: usize) -> anyhow::Result<(Self, usize)> {
        let fastest = rates.iter().cloned().fold(0.0, f64::max);
        let unstable = self.scheme == Scheme::Rk4 && h * fastest > RK4_STABLE_H_RATE;
        let need = (substeps as f64 * h * fastest / RK4_STABLE_H_RATE).ceil() as usize;
        if self.auto {
            let rk4 = SchemeChoice {
                scheme: Scheme::Rk4,
                name: "rk4".into(),
                auto: false,
            };
            return Ok((rk4, if unstable { need } else { substeps }));
        }
        if unstable {
            anyhow::bail!(
                "--scheme {} --substeps {substeps}: the damper's viscous orifice relaxes the chambers' pressure difference at {fastest:.3e} 1/s, and an RK4 sub-step of {h:.3e} s (h x rate = {:.2}) is unstable above {RK4_STABLE_H_RATE}: use --substeps {need} or more, --scheme implicit (stable at any sub-step), or leave --scheme out (auto raises the sub-steps)",
                self.name,
                h * fastest
            );
        }
        Ok((self.clone(), substeps))
    }
}

/// `text` parsed as the value of option `flag`, an error naming the option.
pub fn parse_option<T: FromStr<Err = String>>(flag: &str, text: &str) -> anyhow::Result<T> {
    text.parse().map_err(|e: String| anyhow!("{flag}: {e}"))
}

/// The options of a run given by name (on the command line, in a sweep plan), as text.
#[derive(Clone, Debug)]
pub struct NamedOptions<'a> {
    pub damper: &'a str,
    pub scheme: &'a str,
    pub newton: &'a str,
    pub periodic: &'a str,
    pub model: &'a str,
    pub airloads: &'a str,
}

impl Default for NamedOptions<'_> {
    fn default() -> Self {
        NamedOptions {
            damper: "all",
            scheme: "auto",
            newton: "modified",
            periodic: "shooting",
            model: "uh60a",
            airloads: "measured",
        }
    }
}

/// Every option of a run but its result folder, as given: `rotorsim run`'s flags (clap), a
/// sweep plan's keys (serde) and the Python package's keyword arguments (serde, through JSON)
/// are this one type, so a new run option is a field here and where [`RunSettings::job`] reads
/// it (docs/architecture.md). [`RunSettings::default`] gives the command line's defaults.
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct RunSettings {
    /// Rotor deck (docs/rotor_deck.md).
    #[arg(long, default_value = DEFAULT_ROTOR)]
    pub rotor: PathBuf,
    /// Flight record: MCAP file or CSV stem (docs/formats.md).
    #[arg(long, default_value = DEFAULT_FLIGHT)]
    pub flight: PathBuf,
    /// Damper model: linear, nonlinear, physical, or all (the three in parallel).
    #[arg(long, default_value = "all")]
    pub damper: String,
    /// Damper deck overriding the rotor deck's [damper] table (e.g. from `diagnose --write-deck`).
    #[arg(long)]
    pub damper_deck: Option<PathBuf>,
    /// Most rotor revolutions integrated per model (shooting: perturbed and trial revolutions
    /// included); the run stops earlier once periodic. The reported revolution is the last
    /// accepted one.
    #[arg(long, default_value_t = DEFAULT_REVS)]
    pub revs: usize,
    /// Periodic solver: shooting (Newton-Picard on the revolution map, falling back to
    /// marching when it cannot converge) or march (revolution after revolution).
    #[arg(long, default_value = "shooting")]
    pub periodic: String,
    /// Periodicity residual at which a model stops: per monitored channel (damper force, tip
    /// flap, lag, twist) the change over one revolution relative to its peak-to-peak.
    #[arg(long, default_value_t = run::periodic::DEFAULT_TOL)]
    pub periodic_tol: f64,
    /// Start from a saved periodic state: a periodic_state.json, or the directory of an
    /// earlier run (then each model starts from its own <model>/periodic_state.json).
    #[arg(long)]
    pub initial_state: Option<PathBuf>,
    /// Exit non-zero when a model does not reach the periodicity tolerance.
    #[arg(long)]
    pub require_periodic: bool,
    /// Also write <model>/all_revs.csv: every revolution integrated on the way to the periodic
    /// solution (marched revolutions and accepted shooting iterates, not perturbed ones).
    #[arg(long)]
    pub write_all_revs: bool,
    /// Structural steps per revolution.
    #[arg(long, default_value_t = DEFAULT_STEPS_PER_REV)]
    pub steps_per_rev: usize,
    /// Hydraulic sub-steps per structural step.
    #[arg(long, default_value_t = DEFAULT_SUBSTEPS)]
    pub substeps: usize,
    /// Hydraulic sub-step scheme: auto (rk4, with the sub-steps raised where a physical
    /// damper's viscous orifice would make an RK4 sub-step unstable), rk4 or implicit.
    #[arg(long, default_value = "auto")]
    pub scheme: String,
    /// Rotor model: uh60a (the multibody model of the rotor deck), rigid (the rotor deck's blade
    /// rigid on its lag hinge, airloads projected with the control pitch: the reduced model of
    /// docs/rotor_model.md, "Rigid-blade reduction") or sdof (a fast TEST DOUBLE of the
    /// pipeline, not a rotor model).
    #[arg(long, default_value = "uh60a")]
    pub model: String,
    /// Newton method of the structural step: modified (the iteration matrix is factored once
    /// and reused across iterations and steps in the frame turning with the shaft, refreshed
    /// when it stops contracting) or full (factored at every iteration). Both converge to the
    /// same residual test.
    #[arg(long, default_value = "modified")]
    pub newton: String,
    /// Override a rotor-deck or damper-deck value by its dotted path, unit in the name
    /// (repeatable): `--set damper.physical.A_orf_m2=2.0e-6`. Applied before validation, so
    /// checked like the deck; `damper.*` keys go to `--damper-deck` when one is given.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_set)]
    #[serde(with = "set_texts")]
    pub set: Vec<Override>,
    /// Run every blade of the rotor on its driven hub, each its own model at its own azimuth
    /// (blade k (k-1) 360/N ahead of blade 1), the hub loads summed from their root loads;
    /// implied by per-blade differences (`[blades.K...]` in the deck, `--set blades.K...`).
    /// A deck with an `[airframe]` puts the hub on it: the blades then run as one model.
    /// Writes <model>/blade<K>/ for every blade (docs/run.md).
    #[arg(long)]
    pub all_blades: bool,
    /// Where the blade's airloads come from: measured (the record's, replayed), computed (a
    /// lifting line with the deck's [aero] table and an inflow model, under the record's
    /// controls: a prediction), hybrid (the record's airloads plus the lifting line's
    /// difference between the blade's motion and the record's measured blade motion, or the
    /// periodic solution's where the record has none) or hybrid-periodic (that difference
    /// from the periodic solution under the measured airloads: the measured answer, with
    /// aerodynamic damping of transients and in the Floquet multipliers).
    /// docs/aerodynamics.md.
    #[arg(long, default_value = "measured")]
    pub airloads: String,
}

/// `--set KEY=VALUE` as clap parses it.
pub fn parse_set(s: &str) -> Result<Override, String> {
    Override::parse(s).map_err(|e| format!("{e:#}"))
}

/// Overrides as `KEY=VALUE` texts (serde), each parsed as `--set` parses it.
pub(crate) mod set_texts {
    use crate::overrides::Override;
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(set: &[Override], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(set.iter().map(|o| format!("{}={}", o.key, o.value_text())))
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<Override>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|t| super::parse_set(t).map_err(serde::de::Error::custom))
            .collect()
    }
}

impl Default for RunSettings {
    fn default() -> Self {
        super::settings::command_line_defaults("run")
    }
}

impl super::settings::JobSettings for RunSettings {
    const COMMAND: &'static str = "run";
}

impl RunSettings {
    /// The run these settings ask for into `out`, checked as far as the settings go.
    pub fn job(&self, out: impl Into<PathBuf>) -> anyhow::Result<RunJob> {
        let mut job = RunJob {
            rotor: self.rotor.clone(),
            flight: self.flight.clone(),
            damper_deck: self.damper_deck.clone(),
            revs: self.revs,
            periodic_tol: self.periodic_tol,
            initial_state: self.initial_state.clone(),
            require_periodic: self.require_periodic,
            write_all_revs: self.write_all_revs,
            steps_per_rev: self.steps_per_rev,
            substeps: self.substeps,
            overrides: self.set.clone(),
            all_blades: self.all_blades,
            ..RunJob::new(out)
        };
        job.set_named(&NamedOptions {
            damper: &self.damper,
            scheme: &self.scheme,
            newton: &self.newton,
            periodic: &self.periodic,
            model: &self.model,
            airloads: &self.airloads,
        })?;
        Ok(job)
    }
}

/// One forced-response run (`rotorsim run`): every option, typed. [`RunJob::new`] gives the
/// command line's defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct RunJob {
    /// Rotor deck (docs/rotor_deck.md); the damper deck too without `damper_deck`.
    pub rotor: PathBuf,
    /// Flight record: MCAP file or CSV stem (docs/formats.md).
    pub flight: PathBuf,
    pub damper: DamperChoice,
    /// Damper deck overriding the rotor deck's `[damper]` table.
    pub damper_deck: Option<PathBuf>,
    /// Most revolutions integrated per model.
    pub revs: usize,
    pub periodic: PeriodicMethod,
    /// Periodicity residual at which a model stops.
    pub periodic_tol: f64,
    /// A periodic_state.json, or the folder of an earlier run (one state per model).
    pub initial_state: Option<PathBuf>,
    /// A model that does not reach `periodic_tol` makes the run an error.
    pub require_periodic: bool,
    /// Also write `<model>/all_revs.csv`.
    pub write_all_revs: bool,
    pub steps_per_rev: usize,
    pub substeps: usize,
    pub scheme: SchemeChoice,
    pub model: RotorModel,
    pub newton: NewtonMethod,
    /// Deck values overridden by dotted path, applied before validation.
    pub overrides: Vec<Override>,
    /// Every blade of the rotor on its driven hub, each its own model, or on the deck's
    /// airframe, all in one model (implied by an `[airframe]` and by per-blade
    /// differences in the deck or the overrides).
    pub all_blades: bool,
    /// Where the airloads come from (docs/aerodynamics.md).
    pub airloads: crate::rotor::aero::AirloadSource,
    /// Result folder.
    pub out: PathBuf,
}

/// What a run is about to do (after its checks, its result folder created).
#[derive(Clone, Debug)]
pub struct RunStart {
    pub models: Vec<DamperModel>,
    /// What runs side by side, in the index order of the progress events: the models, or in a
    /// whole-rotor run each model's blades ("physical b3").
    pub units: Vec<String>,
    /// Blades of a whole-rotor run.
    pub blades: Option<usize>,
    /// A whole rotor on an airframe (its blades in one model).
    pub airframe: bool,
    pub method: PeriodicMethod,
    pub tol: f64,
    pub revs: usize,
    pub steps_per_rev: usize,
    pub model: RotorModel,
}

/// What a caller sees of a run while it runs: its start, then the models' progress (from
/// their threads, model index as in [`RunStart::models`]).
pub trait RunObserver: Progress {
    fn start(&self, start: &RunStart);
}

impl RunObserver for Silent {
    fn start(&self, _: &RunStart) {}
}

/// The files of a result folder to open, as published.
#[derive(Clone, Debug)]
pub struct Published {
    pub folder: PathBuf,
    pub report: PathBuf,
    pub summary: PathBuf,
    pub mcap: PathBuf,
    /// `<model>/last_rev.csv` of each model that ran.
    pub last_rev: Vec<(DamperModel, PathBuf)>,
}

/// What a run did, its outputs written.
#[derive(Debug)]
pub struct RunOutcome {
    /// One per model, in the order of [`RunStart::models`].
    pub outcomes: Vec<ModelOutcome>,
    /// The record's measured damper force, or why there is none to compare with.
    pub measured: Result<Measured, String>,
    /// Which model comes closest to the measured force (None without a measurement).
    pub verdict: Option<String>,
    /// The failed models ("model: error").
    pub failed: Vec<String>,
    pub published: Published,
}

impl RunOutcome {
    /// The models that ran but did not reach the periodicity tolerance.
    pub fn not_periodic(&self) -> impl Iterator<Item = &ModelRun> {
        self.outcomes
            .iter()
            .filter_map(|o| o.result.as_ref().ok())
            .filter(|r| !r.converged())
    }
}

/// The error of a run that wrote its outputs and then failed (a model failed; a model not
/// periodic under `require_periodic`), with its outcome. Its message is the run's error.
#[derive(Debug)]
pub struct RunFailed {
    pub outcome: Box<RunOutcome>,
    error: anyhow::Error,
}

impl std::fmt::Display for RunFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        // the top message only: its causes follow as `source`, as in the error it wraps
        write!(f, "{}", self.error)
    }
}

impl std::error::Error for RunFailed {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.error.chain().nth(1)
    }
}

/// Reads the flight record at `path` as a run does.
pub fn read_record(path: &Path) -> anyhow::Result<Arc<FlightRecord>> {
    FlightRecord::read(path)
        .map(Arc::new)
        .with_context(|| format!("reading flight record {}", path.display()))
}

/// The damper deck file `path` with the `damper.*` overrides applied, each validated.
pub fn damper_deck_with(path: &Path, overrides: &[Override]) -> anyhow::Result<DamperDeck> {
    if overrides.is_empty() {
        return Ok(DamperDeck::from_file(path)?);
    }
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow!("damper deck {file}: cannot read: {e}"))?;
    DamperDeck::from_toml_str(&text, &file)?;
    let root = crate::overrides::parse_deck(&text, &file)?;
    let root = crate::overrides::apply_all(root, &file, overrides, |t, _| {
        DamperDeck::from_toml_table(t.clone(), &file)?;
        Ok(())
    })?;
    Ok(DamperDeck::from_toml_table(root, &file)?)
}

/// The units that run side by side: one per damper model, or per model and blade (separate
/// blades; a rotor on an airframe is one model, its blades coupled through the hub).
fn run_units_of(
    models: &[DamperModel],
    nb: usize,
    coupled: bool,
) -> Vec<(DamperModel, Option<usize>)> {
    models
        .iter()
        .flat_map(|&m| -> Vec<(DamperModel, Option<usize>)> {
            if nb == 0 || coupled {
                vec![(m, None)]
            } else {
                (1..=nb).map(|k| (m, Some(k))).collect()
            }
        })
        .collect()
}

/// The folder published incomplete and an error when a stop was requested and a unit
/// stopped; else the folder, to be written.
fn stopped(out: OutDir, stop: &StopFlag, outcomes: &[ModelOutcome]) -> anyhow::Result<OutDir> {
    if stop.requested() {
        // units that ended before the request keep nothing either: the run is not whole
        let stopped: Vec<&str> = outcomes
            .iter()
            .filter_map(|o| o.result.as_ref().err())
            .filter(|e| e.starts_with(STOPPED_PREFIX))
            .map(String::as_str)
            .collect();
        if !stopped.is_empty() {
            let message = stopped.join("; ");
            out.mark_incomplete(&message)?;
            let folder = out.path().to_path_buf();
            drop(out); // published incomplete
            return Err(anyhow::Error::new(RunStopped { message, folder }));
        }
    }
    Ok(out)
}

/// The outcomes as reported: a physical model's failure names the unusual deck values behind
/// it; a coupled rotor's result split by blade; separate blades combined into the whole rotor.
fn reviewed_outcomes(
    mut outcomes: Vec<ModelOutcome>,
    units: &[(DamperModel, Option<usize>)],
    deck: &DamperDeck,
    blades: &[(RotorDeck, DamperDeck)],
    coupled: bool,
) -> Vec<ModelOutcome> {
    let nb = blades.len();
    // a failure of the physical model names the deck values behind it, where they are
    // unusual
    for (o, (_, blade)) in outcomes.iter_mut().zip(units) {
        if o.model != DamperModel::Physical {
            continue;
        }
        let d = blade.map_or(deck, |k| &blades[k - 1].1);
        if let Err(e) = &mut o.result {
            *e = d.with_review(std::mem::take(e));
        }
    }
    if coupled {
        for o in &mut outcomes {
            let limits: Vec<Option<(f64, f64)>> = blades
                .iter()
                .map(|(_, d)| {
                    (o.model == DamperModel::Physical)
                        .then(|| crate::rotor::sim::relief_limits(d))
                        .flatten()
                })
                .collect();
            let taken = std::mem::replace(&mut o.result, Err(String::new()));
            o.result = taken.and_then(|r| {
                run::rotor::combine_coupled(r, nb, &limits).map_err(|e| format!("{e:#}"))
            });
        }
    } else if nb > 0 {
        outcomes = whole_rotor_outcomes(outcomes, units);
    }
    outcomes
}

/// Where the run's published files are.
fn published(out: &OutDir, outcomes: &[ModelOutcome]) -> Published {
    let published = |name: &str| out.published_path(&out.file(name));
    Published {
        folder: out.path().to_path_buf(),
        report: published("report.html"),
        summary: published("summary.json"),
        mcap: published("result.mcap"),
        last_rev: outcomes
            .iter()
            .filter(|o| o.result.is_ok())
            .map(|o| {
                (
                    o.model,
                    published(&format!("{}/last_rev.csv", o.model.name())),
                )
            })
            .collect(),
    }
}

/// A unit's periodic_state.json in the result folder `dir` of an earlier run.
fn state_file(dir: &Path, (m, blade): (DamperModel, Option<usize>)) -> PathBuf {
    let folder = dir.join(m.name());
    match blade {
        Some(k) => folder.join(format!("blade{k}")),
        None => folder,
    }
    .join("periodic_state.json")
}

/// The blades' outcomes (model-major, as `units`) combined into one outcome per model: the
/// rotor's run, or the failure of any of its blades.
fn whole_rotor_outcomes(
    outcomes: Vec<ModelOutcome>,
    units: &[(DamperModel, Option<usize>)],
) -> Vec<ModelOutcome> {
    let mut by_model: Vec<(DamperModel, Vec<run::ModelRun>, Vec<String>)> = Vec::new();
    for (o, (m, blade)) in outcomes.into_iter().zip(units) {
        if by_model.last().is_none_or(|b| b.0 != *m) {
            by_model.push((*m, Vec::new(), Vec::new()));
        }
        let Some(entry) = by_model.last_mut() else {
            continue;
        };
        let k = blade.unwrap_or(1);
        match o.result {
            Ok(mut r) => {
                r.blade = Some(k);
                entry.1.push(r);
            }
            Err(e) => entry.2.push(format!("blade {k}: {e}")),
        }
    }
    by_model
        .into_iter()
        .map(|(model, runs, errors)| ModelOutcome {
            model,
            result: if errors.is_empty() {
                run::rotor::combine(runs).map_err(|e| format!("{e:#}"))
            } else {
                Err(errors.join("; "))
            },
        })
        .collect()
}

impl RunJob {
    /// A run into `out` with the defaults of `rotorsim run`.
    pub fn new(out: impl Into<PathBuf>) -> Self {
        RunJob {
            rotor: DEFAULT_ROTOR.into(),
            flight: DEFAULT_FLIGHT.into(),
            damper: DamperChoice::All,
            damper_deck: None,
            revs: DEFAULT_REVS,
            periodic: PeriodicMethod::Shooting,
            periodic_tol: run::periodic::DEFAULT_TOL,
            initial_state: None,
            require_periodic: false,
            write_all_revs: false,
            steps_per_rev: DEFAULT_STEPS_PER_REV,
            substeps: DEFAULT_SUBSTEPS,
            scheme: SchemeChoice::default(),
            model: RotorModel::Uh60a,
            newton: NewtonMethod::Modified,
            overrides: Vec::new(),
            all_blades: false,
            airloads: crate::rotor::aero::AirloadSource::Measured,
            out: out.into(),
        }
    }

    /// Sets the options given by name, each checked, in the order `rotorsim run` checks its
    /// options (of several bad ones, the same is named); the counts and the tolerance must be
    /// set before.
    pub fn set_named(&mut self, n: &NamedOptions) -> anyhow::Result<()> {
        self.damper = parse_option("--damper", n.damper)?;
        self.scheme = parse_option("--scheme", n.scheme)?;
        self.newton = parse_option("--newton", n.newton)?;
        run::check_run_options(self.revs, self.steps_per_rev, self.substeps)?;
        self.periodic = parse_option("--periodic", n.periodic)?;
        self.check_tol()?;
        self.model = parse_option("--model", n.model)?;
        self.airloads = parse_option("--airloads", n.airloads)?;
        Ok(())
    }

    fn check_tol(&self) -> anyhow::Result<()> {
        if !(self.periodic_tol > 0.0 && self.periodic_tol.is_finite()) {
            bail!(
                "--periodic-tol must be positive and finite (got {})",
                self.periodic_tol
            );
        }
        Ok(())
    }

    /// The options' own checks (counts, cost, tolerance).
    fn check_options(&self) -> anyhow::Result<()> {
        run::check_run_options(self.revs, self.steps_per_rev, self.substeps)?;
        self.check_tol()
    }

    /// Checks the run as [`RunJob::execute`] does before it writes anything (options, record,
    /// decks with their overrides), without running.
    pub fn check(&self) -> anyhow::Result<()> {
        self.check_with(&read_record)
    }

    /// [`RunJob::check`] with the flight record read by `record` (a sweep reads each record
    /// once, not once per case: reading it is most of a case's check).
    pub fn check_with(
        &self,
        record: &dyn Fn(&Path) -> anyhow::Result<Arc<FlightRecord>>,
    ) -> anyhow::Result<()> {
        self.check_options()?;
        let record = record(&self.flight)?;
        let models = self.damper.models();
        let (rotor, _, blades) = self.decks_for(&models)?;
        self.check_rotor(rotor.as_ref(), &record, models.len() * blades.len().max(1))
    }

    /// The rotor deck, the damper deck and, for a whole-rotor run, each blade's decks, every
    /// damper deck holding the parameters of `models`.
    #[allow(clippy::type_complexity)]
    fn decks_for(
        &self,
        models: &[DamperModel],
    ) -> anyhow::Result<(Option<RotorDeck>, DamperDeck, Vec<(RotorDeck, DamperDeck)>)> {
        let require = |d: &DamperDeck| models.iter().try_for_each(|m| d.require(*m));
        let (rotor, deck) = self.load_decks()?;
        require(&deck)?;
        let blades = self.blade_decks(rotor.as_ref())?;
        for (_, d) in &blades {
            require(d)?;
        }
        Ok((rotor, deck, blades))
    }

    /// Whether this run is of the whole rotor: asked for, or implied by per-blade differences.
    pub fn whole_rotor(&self, rotor: Option<&RotorDeck>) -> anyhow::Result<bool> {
        let per_blade = rotor.is_some_and(|r| r.per_blade() || r.spec.airframe.is_some());
        if (self.all_blades || per_blade) && self.model != RotorModel::Uh60a {
            bail!(
                "{}: the whole rotor runs the elastic multibody model only (--model uh60a), not --model {}",
                if self.all_blades {
                    "--all-blades".to_string()
                } else {
                    format!("per-blade differences ([blades.K] tables or --set blades.K...) or an [airframe] in {}", self.rotor.display())
                },
                self.model.name()
            );
        }
        Ok(self.all_blades || per_blade)
    }

    /// Each blade's rotor and damper decks (blade 1 first), per-blade differences applied; empty
    /// unless the run is of the whole rotor.
    pub fn blade_decks(
        &self,
        rotor: Option<&RotorDeck>,
    ) -> anyhow::Result<Vec<(RotorDeck, DamperDeck)>> {
        if !self.whole_rotor(rotor)? {
            return Ok(Vec::new());
        }
        let Some(r) = rotor else {
            return Ok(Vec::new());
        };
        let damper_sets: Vec<Override> = self
            .overrides
            .iter()
            .filter(|o| o.is_damper())
            .cloned()
            .collect();
        (1..=r.spec.rotor.blades)
            .map(|k| {
                let rk = r.blade(k)?;
                let dk = match &self.damper_deck {
                    Some(p) => r.blade_damper_deck(k, p, &damper_sets)?,
                    None => rk.damper()?,
                };
                Ok((rk, dk))
            })
            .collect()
    }

    /// The saved state each unit starts from (`initial_state`): one file for all, or from an
    /// earlier run's folder each unit's own.
    fn initial_states(
        &self,
        units: &[(DamperModel, Option<usize>)],
    ) -> anyhow::Result<Vec<Option<run::PeriodicStateFile>>> {
        match &self.initial_state {
            None => Ok(vec![None; units.len()]),
            Some(p) if p.is_dir() => units
                .iter()
                .map(|u| run::PeriodicStateFile::read(&state_file(p, *u)).map(Some))
                .collect(),
            Some(p) => Ok(vec![Some(run::PeriodicStateFile::read(p)?); units.len()]),
        }
    }

    /// The rotor deck (None for the sdof test double) and the damper deck, overrides applied
    /// and validated.
    pub fn load_decks(&self) -> anyhow::Result<(Option<RotorDeck>, DamperDeck)> {
        let sdof = self.model == RotorModel::Sdof;
        let (damper_sets, rotor_sets): (Vec<Override>, Vec<Override>) =
            if self.damper_deck.is_some() || sdof {
                self.overrides.iter().cloned().partition(|o| o.is_damper())
            } else {
                (Vec::new(), self.overrides.clone())
            };
        if sdof {
            if let Some(o) = rotor_sets.first() {
                bail!(
                    "--set {o}: the sdof test double reads only the [damper] table (expected a damper.* key)"
                );
            }
        }
        let rotor = if sdof {
            None
        } else {
            Some(RotorDeck::from_file_with(&self.rotor, &rotor_sets)?)
        };
        let deck = match (&self.damper_deck, &rotor) {
            (Some(p), _) => {
                // the blades' damper.* differences apply to this file: refuse bad ones now
                if let Some(r) = &rotor {
                    for k in r.differing_blades() {
                        r.blade_damper_deck(k, p, &damper_sets)?;
                    }
                }
                damper_deck_with(p, &damper_sets)?
            }
            (None, Some(r)) => r.damper()?,
            (None, None) => damper_deck_with(&self.rotor, &damper_sets)?,
        };
        Ok((rotor, deck))
    }

    /// The record must be of the deck's rotor, and the elastic model's cost within the budget.
    fn check_rotor(
        &self,
        rotor: Option<&RotorDeck>,
        record: &FlightRecord,
        n_models: usize,
    ) -> anyhow::Result<()> {
        let Some(r) = rotor else { return Ok(()) };
        r.spec.check_record(record, &self.rotor)?;
        if self.airloads.aerodynamic() {
            if self.model != RotorModel::Uh60a {
                bail!(
                    "--airloads {}: the lifting line runs on the elastic blade model (--model uh60a), not --model {}",
                    self.airloads.name(),
                    self.model.name()
                );
            }
            // the deck's aerodynamics and the record's air, checked before anything runs
            crate::rotor::aero::blade_geometry(&r.spec, &self.rotor)?;
            crate::rotor::aero::rotor_air(&r.spec, record)?;
        }
        if self.model == RotorModel::Uh60a {
            let (ndof, nnz) = r.spec.size_estimate();
            let steps = (self.revs * self.steps_per_rev) as f64;
            // the models run side by side: their memory adds up, and their CPU time
            let e = crate::solver::budget::time_integration_of(ndof, nnz, steps, 3.0)
                .times(n_models as f64);
            r.spec.check_budget(
                &self.rotor,
                &format!(
                    "{n_models} model(s) x {} revolutions x {} steps",
                    self.revs, self.steps_per_rev
                ),
                e,
            )?;
        }
        Ok(())
    }

    /// The dampers at the record's oil temperature where the deck has the oil's law (the
    /// run's damper deck, then each blade's).
    fn at_record_oil_temperature(
        &self,
        record: &FlightRecord,
        deck: DamperDeck,
        blades: Vec<(RotorDeck, DamperDeck)>,
    ) -> anyhow::Result<(DamperDeck, Vec<(RotorDeck, DamperDeck)>)> {
        let deck = deck
            .at_known_oil_temperature(self.record_oil_temperature_k(record, None))?
            .into_owned();
        let blades = (1..)
            .zip(blades)
            .map(|(k, (r, d))| {
                let t = self.record_oil_temperature_k(record, Some(k));
                Ok((r, d.at_known_oil_temperature(t)?.into_owned()))
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        Ok((deck, blades))
    }

    /// This job with the hydraulic scheme and sub-steps [`SchemeChoice::resolve`] gives for
    /// its physical dampers (`deck`, and each blade's), or None when they are this job's.
    fn with_stable_substeps(
        &self,
        models: &[DamperModel],
        record: &FlightRecord,
        deck: &DamperDeck,
        blades: &[(RotorDeck, DamperDeck)],
    ) -> anyhow::Result<Option<RunJob>> {
        let rates: Vec<f64> = if models.contains(&DamperModel::Physical) {
            std::iter::once(deck)
                .chain(blades.iter().map(|(_, d)| d))
                .filter_map(|d| d.physical.as_ref()?.orifice_rate_per_s())
                .collect()
        } else {
            vec![]
        };
        let h = 2.0 * std::f64::consts::PI
            / record.meta.rotor_speed_rad_s
            / (self.steps_per_rev * self.substeps.max(1)) as f64;
        let (scheme, substeps) = self.scheme.resolve(&rates, h, self.substeps)?;
        Ok(
            (scheme != self.scheme || substeps != self.substeps).then(|| RunJob {
                scheme,
                substeps,
                ..self.clone()
            }),
        )
    }

    /// Runs the models side by side into the result folder `out` and writes every output.
    /// A failed model (the folder is then published incomplete) or, with `require_periodic`,
    /// a model not periodic (published complete) is an error: a [`RunFailed`] carrying the
    /// outcome. Errors before the outputs are written carry none.
    pub fn execute(&self, observer: &dyn RunObserver) -> anyhow::Result<RunOutcome> {
        self.execute_until(observer, &StopFlag::default())
    }

    /// [`RunJob::execute`] that stops when `stop` is raised: the units stop before their next
    /// structural step and the run returns a [`RunStopped`] error, its result folder published
    /// incomplete (nothing but the marker, which says where each unit stopped, and the
    /// manifest).
    pub fn execute_until(
        &self,
        observer: &dyn RunObserver,
        stop: &StopFlag,
    ) -> anyhow::Result<RunOutcome> {
        let t0 = Instant::now();
        let models = self.damper.models();
        self.check_options()?;
        let method = self.periodic;
        let (sdof, rigid) = (
            self.model == RotorModel::Sdof,
            self.model == RotorModel::Rigid,
        );
        let record = FlightRecord::read(&self.flight)
            .with_context(|| format!("reading flight record {}", self.flight.display()))?;
        let (rotor, deck, blades) = self.decks_for(&models)?;
        let (deck, blades) = self.at_record_oil_temperature(&record, deck, blades)?;
        // the hydraulic scheme for these dampers (auto chosen, or rk4 checked), then the run
        if let Some(job) = self.with_stable_substeps(&models, &record, &deck, &blades)? {
            return job.execute_until(observer, stop);
        }
        let nb = blades.len();
        // a rotor on an airframe is one model: its blades are coupled through the hub
        let coupled = nb > 0 && rotor.as_ref().is_some_and(|r| r.spec.airframe.is_some());
        // the units that run side by side: one per model, or per model and blade
        let units = run_units_of(&models, nb, coupled);
        self.check_rotor(rotor.as_ref(), &record, units.len())?;
        let initial = self.initial_states(&units)?;
        let hydraulics = IntegratorOptions {
            scheme: self.scheme.scheme,
            substeps: self.substeps,
        };
        let opts = RunOptions {
            steps_per_rev: self.steps_per_rev,
            hydraulics,
            newton: self.newton,
            // the delayed perturbation damping vanishes on the periodic solution: it only
            // speeds up marching, and its history would be part of the revolution map's state
            perturbation_damping: method == PeriodicMethod::March,
            airloads: self.airloads,
            ..RunOptions::default()
        };
        let sdof_params = if sdof {
            Some(SdofParams::from_record(&record)?)
        } else {
            None
        };
        let build = |u: usize| -> anyhow::Result<Box<dyn ForcedResponse>> {
            let (m, blade) = units[u];
            if coupled {
                let parts: Vec<(&crate::rotor::deck::RotorSpec, &DamperDeck)> =
                    blades.iter().map(|(r, d)| (&r.spec, d)).collect();
                return Ok(Box::new(crate::rotor::sim::build_rotor_sim(
                    &parts,
                    &self.rotor,
                    m,
                    &record,
                    &opts,
                )?));
            }
            if let Some(k) = blade {
                let (r, d) = &blades[k - 1];
                let o = RunOptions {
                    blade_azimuth_deg: Some(run::rotor::blade_azimuth_deg(k, nb)),
                    ..opts
                };
                return crate::rotor::build(r, d, m, &record, &o);
            }
            match (&rotor, &sdof_params) {
                (_, Some(p)) => Ok(Box::new(LagHingeSdof::new(
                    p.clone(),
                    &deck,
                    m,
                    hydraulics,
                    self.steps_per_rev,
                )?)),
                (Some(r), None) if rigid => {
                    Ok(Box::new(rigid_reduction(r, &deck, m, &record, &opts)?))
                }
                (Some(r), None) => crate::rotor::build(r, &deck, m, &record, &opts),
                (None, None) => unreachable!("one rotor model is selected"),
            }
        };
        let measured = Measured::from_record(&record);
        let (inputs, inputs_sha256) = self.inputs(rotor.as_ref(), &units)?;
        let out = OutDir::create(&self.out, &inputs)?;
        observer.start(&RunStart {
            units: units
                .iter()
                .map(|(m, b)| match b {
                    Some(k) => format!("{} b{k}", m.name()),
                    None => m.name().to_string(),
                })
                .collect(),
            blades: (nb > 0).then_some(nb),
            airframe: coupled,
            models: models.clone(),
            method,
            tol: self.periodic_tol,
            revs: self.revs,
            steps_per_rev: self.steps_per_rev,
            model: self.model,
        });
        let popts = self.periodic_options(initial, method, &inputs_sha256, stop);
        let unit_models: Vec<DamperModel> = units.iter().map(|u| u.0).collect();
        let outcomes = run::run_units(&unit_models, &popts, &build, observer);
        let out = stopped(out, stop, &outcomes)?;
        let outcomes = reviewed_outcomes(outcomes, &units, &deck, &blades, coupled);
        let mut info = self.info(sdof, rigid, inputs_sha256, &record, t0);
        info.damper_oil_temperature_k = deck.oil.map(|l| l.temperature_k);
        if nb > 0 {
            info.blades = Some(nb);
            info.blade_differences = rotor
                .as_ref()
                .map(|r| r.blade_differences())
                .unwrap_or_default();
            if coupled {
                info.airframe = rotor
                    .as_ref()
                    .and_then(|r| r.spec.airframe.as_ref())
                    .map(crate::rotor::deck::AirframeTable::describe)
                    .unwrap_or_default();
            }
        }
        let Written { failed, verdict } = write_outputs(&out, &info, &outcomes, &measured)?;
        let published = published(&out, &outcomes);
        let outcome = RunOutcome {
            outcomes,
            measured,
            verdict,
            failed,
            published,
        };
        match self.publish(out, &outcome) {
            Ok(()) => Ok(outcome),
            Err(error) => Err(anyhow::Error::new(RunFailed {
                outcome: Box::new(outcome),
                error,
            })),
        }
    }

    /// The run's input files (for the result folder's manifest) and their fingerprint (the
    /// files and the overrides; a saved initial state is listed, not fingerprinted).
    fn inputs(
        &self,
        rotor: Option<&RotorDeck>,
        units: &[(DamperModel, Option<usize>)],
    ) -> anyhow::Result<(Vec<PathBuf>, String)> {
        let mut inputs = FlightRecord::files(&self.flight)?;
        match (&rotor, &self.damper_deck) {
            (Some(r), _) => inputs.extend(r.input_files()),
            (None, None) => inputs.push(self.rotor.clone()),
            (None, Some(_)) => {}
        }
        inputs.extend(self.damper_deck.clone());
        let set_lines: Vec<String> = self
            .overrides
            .iter()
            .map(|o| format!("{}={}", o.key, o.value_text()))
            .collect();
        let inputs_sha256 = crate::io::inputs_fingerprint(&inputs, &set_lines)
            .map_err(|e| anyhow!("reading the inputs: {e}"))?;
        match &self.initial_state {
            Some(p) if p.is_dir() => {
                inputs.extend(units.iter().map(|u| state_file(p, *u)));
            }
            Some(p) => inputs.push(p.clone()),
            None => {}
        }
        Ok((inputs, inputs_sha256))
    }

    /// Each unit's periodic-solution options, from its initial state.
    fn periodic_options(
        &self,
        initial: Vec<Option<run::PeriodicStateFile>>,
        method: PeriodicMethod,
        inputs_sha256: &str,
        stop: &StopFlag,
    ) -> Vec<run::PeriodicOptions> {
        initial
            .into_iter()
            .map(|init| run::PeriodicOptions {
                method,
                tol: self.periodic_tol,
                max_revs: self.revs,
                stop_early: true,
                initial_state: init,
                min_floquet_dirs: 0,
                floquet_resolve: true,
                keep_all_revs: self.write_all_revs,
                inputs_sha256: Some(inputs_sha256.to_string()),
                stop: stop.clone(),
            })
            .collect()
    }

    /// Publishes the folder: complete, or incomplete when a model failed; an error when a
    /// model failed or (`require_periodic`) is not periodic.
    fn publish(&self, out: OutDir, outcome: &RunOutcome) -> anyhow::Result<()> {
        let failed = &outcome.failed;
        let not_periodic: Vec<String> = outcome
            .not_periodic()
            .map(|r| format!("{} (residual {})", r.label, fmt_measure(r.last_measure())))
            .collect();
        if failed.is_empty() && self.require_periodic && !not_periodic.is_empty() {
            let summary_path = out.file("summary.json");
            out.finish()?;
            bail!(
                "not periodic (--require-periodic): {}; results in {} (each model's best revolution)",
                not_periodic.join(", "),
                summary_path.display()
            );
        }
        if failed.is_empty() {
            out.finish()?;
            Ok(())
        } else {
            let mut msg = format!("model(s) failed: {}", failed.join("; "));
            if let Some(note) = self.overrides_note() {
                msg = format!("{msg}; {note}");
            }
            out.mark_incomplete(&msg)?;
            bail!(
                "{msg} (the other models' outputs are written in {})",
                out.path().display()
            )
        }
    }

    /// The flight record's oil temperature [K] for the damper of blade `blade` (None: the
    /// single blade's), unless `--set` gives the temperature for every blade or for that one.
    pub fn record_oil_temperature_k(
        &self,
        record: &FlightRecord,
        blade: Option<usize>,
    ) -> Option<f64> {
        const KEY: &str = "damper.physical.oil.temperature_K";
        let own = blade.map(|k| format!("{}.{k}.{KEY}", crate::rotor::blades::KEY));
        record.meta.damper_oil_temperature_k.filter(|_| {
            !self
                .overrides
                .iter()
                .any(|o| o.key == KEY || Some(&o.key) == own.as_ref())
        })
    }

    /// The run's settings as summary.json and the report record them.
    fn info(
        &self,
        sdof: bool,
        rigid: bool,
        inputs_sha256: String,
        record: &FlightRecord,
        t0: Instant,
    ) -> RunInfo {
        RunInfo {
            rotor: self.rotor.display().to_string(),
            rotor_model: if sdof {
                "lag-hinge sdof test double".into()
            } else if rigid {
                RIGID_LABEL.into()
            } else {
                "UH-60A multibody rotor".into()
            },
            flight: self.flight.display().to_string(),
            damper_deck: self
                .damper_deck
                .as_ref()
                .unwrap_or(&self.rotor)
                .display()
                .to_string(),
            revs: self.revs,
            steps_per_rev: self.steps_per_rev,
            substeps: self.substeps,
            scheme: self.scheme.name.clone(),
            newton: self.newton.name().into(),
            periodic: self.periodic.name().into(),
            periodic_tol: self.periodic_tol,
            initial_state: self.initial_state.as_ref().map(|p| p.display().to_string()),
            overrides: self
                .overrides
                .iter()
                .map(|o| (o.key.clone(), o.value_text()))
                .collect(),
            inputs_sha256: Some(inputs_sha256),
            synthetic: record.meta.synthetic,
            counter: record.meta.counter.clone(),
            wall_s: t0.elapsed().as_secs_f64(),
            blades: None,
            blade_differences: Vec::new(),
            airframe: Vec::new(),
            damper_oil_temperature_k: None,
        }
    }

    /// The deck values this run overrides, each with its deck file, for a failure's message:
    /// a value set with `--set` (or by a sweep's case) is the first suspect of a failed run.
    pub fn overrides_note(&self) -> Option<String> {
        if self.overrides.is_empty() {
            return None;
        }
        let items: Vec<String> = self
            .overrides
            .iter()
            .map(|o| {
                let deck = match (&self.damper_deck, o.is_damper()) {
                    (Some(d), true) => d,
                    _ => &self.rotor,
                };
                let value = crate::overrides::display(&o.value);
                format!("{} = {value} in deck {}", o.key, deck.display())
            })
            .collect();
        Some(format!("this run overrides {}", items.join(", ")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stability decks' viscous orifice relaxes at about 1.6e5 1/s; the run's default
    /// sub-step is 2 pi / 27 / 256 / 25 = 3.6e-5 s, h x rate = 5.8, where an RK4 sub-step
    /// amplifies 26-fold (1 + z + z^2/2 + z^3/6 + z^4/24 at z = -5.8).
    #[test]
    fn auto_raises_rk4_sub_steps_to_stability_and_a_named_rk4_is_refused() {
        let h = 2.0 * std::f64::consts::PI / 27.0 / 256.0 / 25.0;
        let rate = 5.8 / h;
        let auto = SchemeChoice::default();
        let (s, n) = auto.resolve(&[rate], h, 25).unwrap();
        assert_eq!((s.scheme, s.name.as_str(), n), (Scheme::Rk4, "rk4", 58));
        assert!(h * 25.0 / n as f64 * rate <= RK4_STABLE_H_RATE);
        // a gentle damper (Eq. 4's law: no rate) keeps the sub-steps
        assert_eq!(auto.resolve(&[], h, 25).unwrap().1, 25);
        let rk4: SchemeChoice = "rk4".parse().unwrap();
        let e = rk4.resolve(&[rate], h, 25).unwrap_err().to_string();
        assert!(
            e.contains("--substeps 58 or more") && e.contains("--scheme implicit"),
            "{e}"
        );
        let implicit: SchemeChoice = "implicit".parse().unwrap();
        assert_eq!(
            implicit.resolve(&[rate], h, 25).unwrap(),
            (implicit.clone(), 25)
        );
        // the RK4 amplification at the default sub-step, as the doc says
        let z: f64 = -5.8;
        let g = 1.0 + z + z * z / 2.0 + z.powi(3) / 6.0 + z.powi(4) / 24.0;
        assert!(g > 20.0, "{g}");
    }
}
