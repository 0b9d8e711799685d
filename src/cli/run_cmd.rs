//! `rotorsim run`: forced response of a rotor to a flight record with one or all
//! damper models, to a periodic solution; writes summary.json, <model>/last_rev.csv,
//! report.html and result.mcap (docs/run.md).
use crate::flight::FlightRecord;
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions, Scheme};
use crate::io::OutDir;
use crate::overrides::Override;
use crate::rotor::{ForcedResponse, RotorDeck, RunOptions};
use crate::run::outputs::{write_outputs, Written};
use crate::run::sdof::{rigid_reduction, LagHingeSdof, SdofParams, RIGID_LABEL};
use crate::run::summary::{self, Measured, RunInfo};
use crate::run::{self, fmt_measure, ModelOutcome, Progress, Silent};
use crate::solver::NewtonMethod;
use anyhow::{bail, Context};
use clap::Args;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// Rotor deck (docs/rotor_deck.md).
    #[arg(long, default_value = "rotors/uh60a.toml")]
    pub rotor: PathBuf,
    /// Flight record: MCAP file or CSV stem (docs/formats.md).
    #[arg(long, default_value = "flightdata/c8534like")]
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
    #[arg(long, default_value_t = 75)]
    pub revs: usize,
    /// Periodic solver: shooting (Newton-Picard on the revolution map, falling back to
    /// marching when it cannot converge) or march (revolution after revolution).
    #[arg(long, default_value = "shooting")]
    pub periodic: String,
    /// Periodicity residual at which a model stops: per monitored channel (damper force, tip
    /// flap, lag, twist) the change over one revolution relative to its peak-to-peak.
    #[arg(long, default_value_t = crate::run::periodic::DEFAULT_TOL)]
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
    #[arg(long, default_value_t = 256)]
    pub steps_per_rev: usize,
    /// Hydraulic sub-steps per structural step.
    #[arg(long, default_value_t = 25)]
    pub substeps: usize,
    /// Hydraulic sub-step scheme: rk4 or implicit.
    #[arg(long, default_value = "rk4")]
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
    pub set: Vec<Override>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Print nothing (a case of `rotorsim sweep`).
    #[arg(skip)]
    pub quiet: bool,
}

fn parse_set(s: &str) -> Result<Override, String> {
    Override::parse(s).map_err(|e| format!("{e:#}"))
}

/// The damper deck file `path` with the `damper.*` overrides applied, each validated.
fn damper_deck_with(path: &std::path::Path, overrides: &[Override]) -> anyhow::Result<DamperDeck> {
    if overrides.is_empty() {
        return Ok(DamperDeck::from_file(path)?);
    }
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("damper deck {file}: cannot read: {e}"))?;
    DamperDeck::from_toml_str(&text, &file)?;
    let text = crate::overrides::apply_all(&text, &file, overrides, |t, _| {
        DamperDeck::from_toml_str(t, &file)?;
        Ok(())
    })?;
    Ok(DamperDeck::from_toml_str(&text, &file)?)
}

/// The rotor deck (None for the sdof test double) and the damper deck of `args`, `--set`
/// overrides applied and validated.
pub fn load_decks(args: &RunArgs, sdof: bool) -> anyhow::Result<(Option<RotorDeck>, DamperDeck)> {
    let (damper_sets, rotor_sets): (Vec<Override>, Vec<Override>) =
        if args.damper_deck.is_some() || sdof {
            args.set.iter().cloned().partition(|o| o.is_damper())
        } else {
            (Vec::new(), args.set.clone())
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
        Some(RotorDeck::from_file_with(&args.rotor, &rotor_sets)?)
    };
    let deck = match (&args.damper_deck, &rotor) {
        (Some(p), _) => damper_deck_with(p, &damper_sets)?,
        (None, Some(r)) => r.damper()?,
        (None, None) => damper_deck_with(&args.rotor, &damper_sets)?,
    };
    Ok((rotor, deck))
}

fn parse_models(s: &str) -> anyhow::Result<Vec<DamperModel>> {
    Ok(match s {
        "all" => vec![
            DamperModel::Linear,
            DamperModel::Nonlinear,
            DamperModel::Physical,
        ],
        _ => vec![s.parse().map_err(|e: String| {
            anyhow::anyhow!("--damper: {e} (or all for the three in parallel)")
        })?],
    })
}

/// Progress bars, one per model, on a terminal.
struct Bars {
    bars: Vec<ProgressBar>,
}

impl Bars {
    fn new(models: &[DamperModel], revs: usize) -> Self {
        let mp = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template(
            "{prefix:>10} [{bar:30}] rev {pos}/{len} {msg} ({elapsed})",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar())
        .progress_chars("=> ");
        let bars = models
            .iter()
            .map(|m| {
                let b = mp.add(ProgressBar::new(revs as u64));
                b.set_style(style.clone());
                b.set_prefix(m.name());
                b.set_message("starting");
                b
            })
            .collect();
        Bars { bars }
    }
}

impl Progress for Bars {
    fn revolution(&self, i: usize, rev: usize, _revs: usize, m: Option<f64>) {
        let b = &self.bars[i];
        b.set_position(rev as u64);
        b.set_message(format!("periodicity {}", fmt_measure(m)));
    }
    fn finished(&self, i: usize, ok: bool, message: &str) {
        let b = &self.bars[i];
        if ok {
            b.finish_with_message(message.to_string());
        } else {
            b.abandon_with_message(format!("FAILED: {message}"));
        }
    }
}

/// Seconds between plain progress lines when stderr is not a terminal (logs, batch jobs).
const PLAIN_PROGRESS_EVERY_S: f64 = 5.0;

/// Plain progress lines on a stderr that is not a terminal: per model, a line at most every
/// `every` seconds (revolution, periodicity, elapsed time), and one when it ends.
struct Lines {
    names: Vec<&'static str>,
    every: f64,
    start: Instant,
    last: std::sync::Mutex<Vec<f64>>,
}

impl Lines {
    fn new(models: &[DamperModel], every: f64) -> Self {
        Lines {
            names: models.iter().map(|m| m.name()).collect(),
            every,
            start: Instant::now(),
            last: std::sync::Mutex::new(vec![f64::NEG_INFINITY; models.len()]),
        }
    }
}

impl Progress for Lines {
    fn revolution(&self, i: usize, rev: usize, revs: usize, m: Option<f64>) {
        let now = self.start.elapsed().as_secs_f64();
        let due = match self.last.lock() {
            Ok(mut last) if now - last[i] >= self.every => {
                last[i] = now;
                true
            }
            _ => false,
        };
        if due {
            errln!(
                "{}: revolution {rev} of at most {revs}, periodicity {}, {now:.0} s",
                self.names[i],
                fmt_measure(m)
            );
        }
    }
    fn finished(&self, i: usize, ok: bool, message: &str) {
        let now = self.start.elapsed().as_secs_f64();
        let state = if ok { "done" } else { "FAILED" };
        errln!("{}: {state} after {now:.1} s: {message}", self.names[i]);
    }
}

/// Checks `args` as `run` does before it writes anything (options, record, decks with their
/// overrides), without running.
pub fn check(args: &RunArgs) -> anyhow::Result<()> {
    check_with(args, &check_record)
}

/// Reads the flight record at `path` as `run` does (the check of [`check`]).
pub fn check_record(path: &Path) -> anyhow::Result<std::sync::Arc<FlightRecord>> {
    FlightRecord::read(path)
        .map(std::sync::Arc::new)
        .with_context(|| format!("reading flight record {}", path.display()))
}

/// [`check`] with the flight record checked by `record` (a sweep checks each record once, not
/// once per case: reading it is most of a case's check).
pub fn check_with(
    args: &RunArgs,
    record: &dyn Fn(&Path) -> anyhow::Result<std::sync::Arc<FlightRecord>>,
) -> anyhow::Result<()> {
    let models = parse_models(&args.damper)?;
    args.scheme
        .parse::<Scheme>()
        .map_err(|e: String| anyhow::anyhow!("--scheme: {e}"))?;
    args.newton
        .parse::<NewtonMethod>()
        .map_err(|e: String| anyhow::anyhow!("--newton: {e}"))?;
    run::check_run_options(args.revs, args.steps_per_rev, args.substeps)?;
    if !matches!(args.periodic.as_str(), "shooting" | "march") {
        bail!(
            "--periodic: unknown method '{}' (expected shooting or march)",
            args.periodic
        );
    }
    if !(args.periodic_tol > 0.0 && args.periodic_tol.is_finite()) {
        bail!(
            "--periodic-tol must be positive and finite (got {})",
            args.periodic_tol
        );
    }
    let sdof = match args.model.as_str() {
        "uh60a" | "rigid" => false,
        "sdof" => true,
        m => bail!("--model: unknown rotor model '{m}' (expected uh60a, rigid or sdof)"),
    };
    let record = record(&args.flight)?;
    let (rotor, deck) = load_decks(args, sdof)?;
    for m in &models {
        deck.require(*m)?;
    }
    check_rotor(args, rotor.as_ref(), &record, models.len())
}

/// The record must be of the deck's rotor, and the elastic model's cost within the budget.
fn check_rotor(
    args: &RunArgs,
    rotor: Option<&RotorDeck>,
    record: &FlightRecord,
    n_models: usize,
) -> anyhow::Result<()> {
    let Some(r) = rotor else { return Ok(()) };
    r.spec.check_record(record, &args.rotor)?;
    if args.model == "uh60a" {
        let (ndof, nnz) = r.spec.size_estimate();
        let steps = (args.revs * args.steps_per_rev) as f64;
        // the models run side by side: their memory adds up, and their CPU time
        let e = crate::solver::budget::time_integration_of(ndof, nnz, steps, 3.0)
            .times(n_models as f64);
        r.spec.check_budget(
            &args.rotor,
            &format!(
                "{n_models} model(s) x {} revolutions x {} steps",
                args.revs, args.steps_per_rev
            ),
            e,
        )?;
    }
    Ok(())
}

pub fn run(args: RunArgs) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let models = parse_models(&args.damper)?;
    let scheme: Scheme = args
        .scheme
        .parse()
        .map_err(|e: String| anyhow::anyhow!("--scheme: {e}"))?;
    let newton: NewtonMethod = args
        .newton
        .parse()
        .map_err(|e: String| anyhow::anyhow!("--newton: {e}"))?;
    run::check_run_options(args.revs, args.steps_per_rev, args.substeps)?;
    let method = match args.periodic.as_str() {
        "shooting" => run::PeriodicMethod::Shooting,
        "march" => run::PeriodicMethod::March,
        m => bail!("--periodic: unknown method '{m}' (expected shooting or march)"),
    };
    if !(args.periodic_tol > 0.0 && args.periodic_tol.is_finite()) {
        bail!(
            "--periodic-tol must be positive and finite (got {})",
            args.periodic_tol
        );
    }
    let initial = match &args.initial_state {
        None => vec![None; models.len()],
        Some(p) if p.is_dir() => models
            .iter()
            .map(|m| {
                run::PeriodicStateFile::read(&p.join(m.name()).join("periodic_state.json"))
                    .map(Some)
            })
            .collect::<anyhow::Result<_>>()?,
        Some(p) => vec![Some(run::PeriodicStateFile::read(p)?); models.len()],
    };
    let (sdof, rigid) = match args.model.as_str() {
        "uh60a" => (false, false),
        "rigid" => (false, true),
        "sdof" => (true, false),
        m => bail!("--model: unknown rotor model '{m}' (expected uh60a, rigid or sdof)"),
    };
    let record = FlightRecord::read(&args.flight)
        .with_context(|| format!("reading flight record {}", args.flight.display()))?;
    let (rotor, deck) = load_decks(&args, sdof)?;
    for m in &models {
        deck.require(*m)?;
    }
    check_rotor(&args, rotor.as_ref(), &record, models.len())?;
    let hydraulics = IntegratorOptions {
        scheme,
        substeps: args.substeps,
    };
    let opts = RunOptions {
        steps_per_rev: args.steps_per_rev,
        hydraulics,
        newton,
        // the delayed perturbation damping vanishes on the periodic solution: it only speeds
        // up marching, and its history would be part of the revolution map's state
        perturbation_damping: method == run::PeriodicMethod::March,
        ..RunOptions::default()
    };
    let sdof_params = if sdof {
        Some(SdofParams::from_record(&record)?)
    } else {
        None
    };
    let build = |m: DamperModel| -> anyhow::Result<Box<dyn ForcedResponse>> {
        match (&rotor, &sdof_params) {
            (_, Some(p)) => Ok(Box::new(LagHingeSdof::new(
                p.clone(),
                &deck,
                m,
                hydraulics,
                args.steps_per_rev,
            )?)),
            (Some(r), None) if rigid => Ok(Box::new(rigid_reduction(r, &deck, m, &record, &opts)?)),
            (Some(r), None) => crate::rotor::build(r, &deck, m, &record, &opts),
            (None, None) => unreachable!("one rotor model is selected"),
        }
    };
    let measured = Measured::from_record(&record);
    let mut inputs = FlightRecord::files(&args.flight)?;
    match (&rotor, &args.damper_deck) {
        (Some(r), _) => inputs.extend(r.input_files()),
        (None, None) => inputs.push(args.rotor.clone()),
        (None, Some(_)) => {}
    }
    inputs.extend(args.damper_deck.clone());
    let set_lines: Vec<String> = args
        .set
        .iter()
        .map(|o| format!("{}={}", o.key, o.value_text()))
        .collect();
    let inputs_sha256 = crate::io::inputs_fingerprint(&inputs, &set_lines)
        .map_err(|e| anyhow::anyhow!("reading the inputs: {e}"))?;
    match &args.initial_state {
        Some(p) if p.is_dir() => inputs.extend(
            models
                .iter()
                .map(|m| p.join(m.name()).join("periodic_state.json")),
        ),
        Some(p) => inputs.push(p.clone()),
        None => {}
    }
    let out = OutDir::create(&args.out, &inputs)?;
    let tty = std::io::stderr().is_terminal() && !args.quiet;
    if !args.quiet {
        errln!(
        "rotorsim run: {} model(s) {}, {} to a residual of {:.0e}, at most {} revolutions x {} steps{}",
        models.len(),
        models
            .iter()
            .map(|m| m.name())
            .collect::<Vec<_>>()
            .join(", "),
        method.name(),
        args.periodic_tol,
        args.revs,
        args.steps_per_rev,
        if sdof {
            " (lag-hinge TEST DOUBLE, --model sdof)"
        } else if rigid {
            " (rigid-blade reduction of the rotor deck, --model rigid)"
        } else {
            ""
        }
    );
    }
    let popts: Vec<run::PeriodicOptions> = initial
        .into_iter()
        .map(|init| run::PeriodicOptions {
            method,
            tol: args.periodic_tol,
            max_revs: args.revs,
            stop_early: true,
            initial_state: init,
            min_floquet_dirs: 0,
            keep_all_revs: args.write_all_revs,
            inputs_sha256: Some(inputs_sha256.clone()),
        })
        .collect();
    let mut outcomes = if args.quiet {
        run::run_models(&models, &popts, &build, &Silent)
    } else if tty {
        let bars = Bars::new(&models, args.revs);
        run::run_models(&models, &popts, &build, &bars)
    } else {
        let lines = Lines::new(&models, PLAIN_PROGRESS_EVERY_S);
        run::run_models(&models, &popts, &build, &lines)
    };
    // a failure of the physical model names the deck values behind it, where they are unusual
    for o in outcomes
        .iter_mut()
        .filter(|o| o.model == DamperModel::Physical)
    {
        if let Err(e) = &mut o.result {
            *e = deck.with_review(std::mem::take(e));
        }
    }
    let info = RunInfo {
        rotor: args.rotor.display().to_string(),
        rotor_model: if sdof {
            "lag-hinge sdof test double".into()
        } else if rigid {
            RIGID_LABEL.into()
        } else {
            "UH-60A multibody rotor".into()
        },
        flight: args.flight.display().to_string(),
        damper_deck: args
            .damper_deck
            .as_ref()
            .unwrap_or(&args.rotor)
            .display()
            .to_string(),
        revs: args.revs,
        steps_per_rev: args.steps_per_rev,
        substeps: args.substeps,
        scheme: args.scheme.clone(),
        newton: newton.name().into(),
        periodic: method.name().into(),
        periodic_tol: args.periodic_tol,
        initial_state: args.initial_state.as_ref().map(|p| p.display().to_string()),
        overrides: args
            .set
            .iter()
            .map(|o| (o.key.clone(), o.value_text()))
            .collect(),
        inputs_sha256: Some(inputs_sha256),
        synthetic: record.meta.synthetic,
        counter: record.meta.counter.clone(),
        wall_s: t0.elapsed().as_secs_f64(),
    };
    let Written { failed, verdict } = write_outputs(&out, &info, &outcomes, &measured)?;
    if !args.quiet {
        print_summary(&outcomes, &measured);
    }
    let not_periodic: Vec<String> = outcomes
        .iter()
        .filter_map(|o| o.result.as_ref().ok())
        .filter(|r| !r.converged())
        .map(|r| format!("{} (residual {})", r.label, fmt_measure(r.last_measure())))
        .collect();
    if !args.quiet {
        print_verdict(&out, &verdict, &outcomes);
    }
    if failed.is_empty() && args.require_periodic && !not_periodic.is_empty() {
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
        if let Some(note) = overrides_note(&args) {
            msg = format!("{msg}; {note}");
        }
        out.mark_incomplete(&msg)?;
        bail!(
            "{msg} (the other models' outputs are written in {})",
            out.path().display()
        )
    }
}

/// The deck values this run overrides, each with its deck file, for a failure's message: a
/// value set with `--set` (or by a sweep's case) is the first suspect of a failed run.
fn overrides_note(args: &RunArgs) -> Option<String> {
    if args.set.is_empty() {
        return None;
    }
    let items: Vec<String> = args
        .set
        .iter()
        .map(|o| {
            let deck = match (&args.damper_deck, o.is_damper()) {
                (Some(d), true) => d,
                _ => &args.rotor,
            };
            let value = crate::sweep::plan::display(&o.value);
            format!("{} = {value} in deck {}", o.key, deck.display())
        })
        .collect();
    Some(format!("this run overrides {}", items.join(", ")))
}

fn print_summary(outcomes: &[ModelOutcome], measured: &Result<Measured, String>) {
    for o in outcomes {
        match &o.result {
            Ok(r) => {
                let cmp = measured.as_ref().ok().and_then(|m| {
                    let f = r.channel("damper_force_N")?;
                    crate::analysis::compare::compare(
                        crate::analysis::compare::Periodic {
                            psi_deg: &r.azimuth_deg,
                            value: f,
                        },
                        crate::analysis::compare::Periodic {
                            psi_deg: &m.azimuth_deg,
                            value: &m.force_n,
                        },
                        run::N_HARMONICS,
                    )
                    .ok()
                });
                let t = r.timing;
                outln!(
                    "{:<22} residual {} ({}, {} revs, {}){}  wall {:.1} s (structure {:.1} s, hydraulics {:.1} s)",
                    r.label,
                    fmt_measure(r.last_measure()),
                    if r.converged() { "periodic" } else { "NOT periodic" },
                    r.periodic.revolutions_integrated,
                    r.periodic.method_used.name(),
                    cmp.map(|m| format!(
                        "  RMS error {:.0} N, correlation {:.3}",
                        m.rms_error, m.correlation
                    ))
                    .unwrap_or_default(),
                    r.wall_s,
                    t.total_s - t.hydraulics_s,
                    t.hydraulics_s
                );
                if let Some(c) = r.loads_check.as_ref().filter(|c| !c.passed) {
                    outln!(
                        "warning: {}: blade root loads differ from the resultant of the applied, inertial, damper and pitch-link loads by {:.2e} of {}'s peak-to-peak (above {:.1e}): the structural solution is not in equilibrium to the accuracy the loads need",
                        r.label, c.max_rel_error, c.channel, c.tolerance
                    );
                }
                if r.converged() && r.periodic.message.starts_with("warm start") {
                    outln!("note: {}: {}", r.label, r.periodic.message);
                }
                if !r.converged() {
                    outln!(
                        "warning: {}: {}",
                        r.label,
                        summary::periodicity_statement(r)
                    );
                }
            }
            Err(e) => outln!("{:<22} FAILED: {e}", o.model.name()),
        }
    }
    if let Err(note) = measured {
        outln!("note: {note}");
    }
}

/// The last lines of a run: the verdict and the files to open (paths as published).
fn print_verdict(out: &OutDir, verdict: &Option<String>, outcomes: &[ModelOutcome]) {
    if let Some(v) = verdict {
        outln!("verdict: {v}");
    }
    let not_periodic: Vec<&str> = outcomes
        .iter()
        .filter(|o| matches!(&o.result, Ok(r) if !r.converged()))
        .map(|o| o.model.name())
        .collect();
    if !not_periodic.is_empty() {
        outln!(
            "caution: NOT periodic: {} (the verdict compares revolutions that are not a periodic solution)",
            not_periodic.join(", ")
        );
    }
    let published = |name: &str| out.published_path(&out.file(name)).display().to_string();
    outln!(
        "open: {} (verdict, figures, tables)",
        published("report.html")
    );
    outln!(
        "      {} (every figure), {} (for a viewer such as Foxglove)",
        published("summary.json"),
        published("result.mcap")
    );
    for o in outcomes.iter().filter(|o| o.result.is_ok()) {
        outln!(
            "      {} (the periodic revolution, with the measurement)",
            published(&format!("{}/last_rev.csv", o.model.name()))
        );
    }
}
