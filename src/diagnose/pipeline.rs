//! The `rotorsim diagnose` pipeline: read the data (bench tests, or a flight record whose
//! stroke is simulated by a rotor run when it has none), diagnose, write DIR/diagnosis.json,
//! DIR/diagnosis.html and the extended deck, and run the rotor-level before/after. It prints
//! nothing: progress goes to a callback, and the command prints the [`Report`].
use super::rotor::{
    flight_measurement, mean_and_amplitude, periodic_stroke, rotor_check_runs, run_physical,
    RotorRunOptions,
};
use super::{DiagnoseOptions, Measurement, Outcome};
use crate::flight::FlightRecord;
use crate::hydraulics::bench::read_bench_csv_with_dropouts;
use crate::hydraulics::DamperDeck;
use crate::io::{write_atomic, OutDir};
use crate::report::html::HtmlReport;
use crate::report::plot::{Plot, PlotError};
use crate::rotor::RotorDeck;
use crate::run::summary::{self, Measured, RunInfo};
use crate::run::{fmt_measure, ModelOutcome, ModelRun};
use anyhow::{bail, Context};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A progress line for the user (the command prints it on stderr).
pub type Say<'a> = &'a (dyn Fn(&str) + Sync);

/// What to diagnose and how, typed: `rotorsim diagnose`'s options
/// ([`super::settings::DiagnoseSettings::job`]; [`Config::new`] gives its defaults), checked by
/// [`run`]. The command line and the Python package both run through it.
#[derive(Debug, Clone)]
pub struct Config {
    /// Damper deck of the baseline model.
    pub deck: Option<PathBuf>,
    /// Measured bench tests.
    pub measured: Vec<PathBuf>,
    /// Rotor deck (a flight record's baseline damper unless `deck`; the rotor runs).
    pub rotor: Option<PathBuf>,
    /// Flight record.
    pub flight: Option<PathBuf>,
    /// Output directory.
    pub out: PathBuf,
    /// Also write the extended deck here.
    pub write_deck: Option<PathBuf>,
    /// Cycles simulated per fit test.
    pub fit_cycles: usize,
    /// Largest RK4 sub-step of the hydraulic model [s].
    pub max_substep: f64,
    /// Revolutions of the stroke run (records without stroke).
    pub revs: usize,
    pub steps_per_rev: usize,
    pub substeps: usize,
    /// Run the rotor-level before/after (flight records).
    pub rotor_check: bool,
    pub check_revs: usize,
    /// Rotor model of the rotor runs: uh60a (the multibody model) or rigid (its rigid-blade
    /// reduction).
    pub rotor_model: String,
}

impl Config {
    /// A diagnosis into `out` with the defaults of `rotorsim diagnose` (no data given).
    pub fn new(out: impl Into<PathBuf>) -> Self {
        super::settings::DiagnoseSettings::default().job(out)
    }

    /// The options' own checks, before anything is read ([`run`] starts with them).
    pub fn check(&self) -> anyhow::Result<()> {
        if self.fit_cycles < 2 {
            bail!("--fit-cycles must be >= 2 (one settles the model, the rest are compared)");
        }
        if !(self.max_substep > 0.0 && self.max_substep.is_finite()) {
            bail!("--max-substep must be a positive number of seconds");
        }
        if !matches!(self.rotor_model.as_str(), "uh60a" | "rigid") {
            bail!(
                "--model: unknown rotor model '{}' (expected uh60a or rigid)",
                self.rotor_model
            );
        }
        if self.rotor_check && self.flight.is_none() {
            bail!("--rotor-check needs a flight record (--rotor ROTOR --flight RECORD): it compares rotor runs with the record's damper force");
        }
        match (&self.flight, self.measured.is_empty()) {
            (Some(_), false) => bail!("give either --flight or --measured, not both"),
            (None, true) => bail!(
                "nothing to diagnose: give --damper-deck DECK --measured TEST.csv [...] or --rotor ROTOR --flight RECORD"
            ),
            _ => {}
        }
        Ok(())
    }

    /// The rotor runs use the rigid-blade reduction (else the multibody model).
    fn rigid(&self) -> bool {
        self.rotor_model == "rigid"
    }

    fn rotor_opts(&self, revs: usize) -> RotorRunOptions {
        RotorRunOptions {
            revs,
            steps_per_rev: self.steps_per_rev,
            substeps: self.substeps,
            rigid: self.rigid(),
        }
    }
    /// Label of the rotor model of the rotor runs (summary.json `rotor_model`).
    fn rotor_model_label(&self) -> &'static str {
        if self.rigid() {
            crate::run::sdof::RIGID_LABEL
        } else {
            "UH-60A multibody rotor"
        }
    }
}

/// What the command prints.
pub struct Report {
    pub outcome: Outcome,
    /// How the stroke was obtained (flight records: `stroke_source` of diagnosis.json).
    pub stroke_info: Option<Value>,
    /// The rotor-level before/after (`--rotor-check`).
    pub check: Option<RotorCheck>,
}

/// Progress of a rotor run, every 5 revolutions.
fn progress_line(say: Say, what: &str, rev: usize, revs: usize, m: Option<f64>) {
    if rev.is_multiple_of(5) || rev == revs {
        say(&format!(
            "rotorsim diagnose: {what}: revolution {rev}/{revs}, periodicity {}",
            fmt_measure(m)
        ));
    }
}

/// JSON facts of a rotor run made by the diagnosis.
fn run_json(r: &ModelRun, opts: &RotorRunOptions) -> Value {
    json!({
        "revolutions": r.revolutions,
        "steps_per_rev": r.steps_per_rev,
        "substeps": opts.substeps,
        "scheme": "rk4",
        "periodicity_last": r.last_measure(),
        "periodic": r.converged(),
        "periodicity_statement": summary::periodicity_statement(r),
        "wall_time_s": r.wall_s,
    })
}

/// A record without stroke: the stroke of the rotor model with the baseline (physical) damper,
/// after `opts.revs` revolutions, at the record's azimuths.
fn simulated_measurement(
    rec: &FlightRecord,
    fl: &Path,
    rotor_path: &Path,
    deck: &DamperDeck,
    opts: &RotorRunOptions,
    say: Say,
) -> anyhow::Result<(Measurement, Value, String)> {
    let rotor = RotorDeck::from_file(rotor_path).with_context(|| {
        format!(
            "{}: the record has no damper stroke, so the stroke is simulated by the full rotor run, which needs a rotor deck: --rotor {} is not one",
            fl.display(),
            rotor_path.display()
        )
    })?;
    say(&format!(
        "rotorsim diagnose: {} has no damper stroke: running the rotor {} (physical damper, baseline deck) for {} revolutions x {} steps to simulate it",
        fl.display(),
        rotor_path.display(),
        opts.revs,
        opts.steps_per_rev
    ));
    let cb = |rev: usize, m: Option<f64>| progress_line(say, "stroke run", rev, opts.revs, m);
    let run = run_physical(&rotor, deck, rec, opts, &cb)
        .context("simulating the damper stroke by the rotor run")?;
    let interp = periodic_stroke(&run)?;
    let m = flight_measurement(rec, fl, Some(&interp))?;
    let d = run.channel("damper_stroke_m").unwrap_or_default();
    let (mean, amp) = mean_and_amplitude(d);
    let periodic = run.converged();
    let statement = format!(
        "The stroke is SIMULATED, not measured: the record has no damper stroke, so the damper is driven by the periodic stroke of the rotor model ({} of {}, physical damper of the baseline deck, last of {} revolutions, {}; mean {:.2} mm, amplitude {:.2} mm), interpolated at the record's azimuths, and compared with the record's measured force. Any error of the rotor model's stroke (amplitude, phase, mean) shows up as a damper discrepancy: a named cause is a cause of the force-vs-simulated-stroke mismatch, not necessarily of the damper alone.",
        if opts.rigid {
            "rigid-blade reduction"
        } else {
            "multibody model"
        },
        rotor_path.display(),
        run.revolutions,
        summary::periodicity_statement(&run),
        1e3 * mean,
        1e3 * amp
    );
    let mut info = json!({
        "kind": "simulated",
        "statement": statement,
        "rotor": rotor_path.display().to_string(),
        "rotor_model": if opts.rigid { "rigid" } else { "uh60a" },
        "damper_model": "physical",
        "stroke_mean_m": mean,
        "stroke_amplitude_m": amp,
    });
    info["rotor_run"] = run_json(&run, opts);
    if !periodic {
        info["warning"] = json!(format!(
            "the rotor run is NOT periodic after {} revolutions: the simulated stroke is not yet the periodic one; run more revolutions (--revs)",
            run.revolutions
        ));
    }
    Ok((m, info, statement))
}

/// The rotor-level before/after: JSON object, HTML rows, console lines.
pub struct RotorCheck {
    pub json: Value,
    /// (metric, baseline, extended, change) rows.
    pub rows: Vec<Vec<String>>,
    pub statement: String,
    /// Last revolution of each model and the measurement, for the figure.
    pub curves: Vec<(String, Vec<f64>, Vec<f64>)>,
}

fn harmonic_rows(
    rows: &mut Vec<Vec<String>>,
    b: &crate::analysis::compare::Metrics,
    e: &crate::analysis::compare::Metrics,
) {
    for n in 1..=4usize {
        let (hb, he, hm) = (
            &b.harmonics_model[n],
            &e.harmonics_model[n],
            &b.harmonics_measured[n],
        );
        rows.push(vec![
            format!("{n}/rev amplitude [N] (measured {:.0})", hm.amplitude),
            format!("{:.0}", hb.amplitude),
            format!("{:.0}", he.amplitude),
            format!("{:+.0}", he.amplitude - hb.amplitude),
        ]);
        rows.push(vec![
            format!("{n}/rev phase [deg] (measured {:.1})", hm.phase_deg),
            format!("{:.1}", hb.phase_deg),
            format!("{:.1}", he.phase_deg),
            format!(
                "{:+.1}",
                (he.phase_deg - hb.phase_deg + 180.0).rem_euclid(360.0) - 180.0
            ),
        ]);
    }
}

/// Stroke and damper 1/rev dynamic stiffness rows (records with a stroke): what the rotor
/// (stroke) and what the damper (force for that stroke) contribute.
fn stroke_rows(rows: &mut Vec<Vec<String>>, b: &summary::StrokeCheck, e: &summary::StrokeCheck) {
    // (label, measured, baseline, extended, scientific notation)
    let (kb, ke, km) = (
        &b.stiffness_1rev_model,
        &e.stiffness_1rev_model,
        &b.stiffness_1rev_measured,
    );
    let table: [(&str, f64, f64, f64, bool); 4] = [
        (
            "1/rev stroke [mm]",
            1e3 * b.rev1_measured.amplitude,
            1e3 * b.rev1_model.amplitude,
            1e3 * e.rev1_model.amplitude,
            false,
        ),
        (
            "1/rev stroke phase [deg]",
            b.rev1_measured.phase_deg,
            b.rev1_model.phase_deg,
            e.rev1_model.phase_deg,
            false,
        ),
        (
            "damper 1/rev storage K' [N/m]",
            km.storage_N_per_m,
            kb.storage_N_per_m,
            ke.storage_N_per_m,
            true,
        ),
        (
            "damper 1/rev loss K'' [N/m]",
            km.loss_N_per_m,
            kb.loss_N_per_m,
            ke.loss_N_per_m,
            true,
        ),
    ];
    for (label, m, vb, ve, sci) in table {
        let f = |v: f64, sign: bool| match (sci, sign) {
            (true, false) => format!("{v:.3e}"),
            (true, true) => format!("{v:+.3e}"),
            (false, false) => format!("{v:.3}"),
            (false, true) => format!("{v:+.3}"),
        };
        rows.push(vec![
            format!("{label} (measured {})", f(m, false)),
            f(vb, false),
            f(ve, false),
            f(ve - vb, true),
        ]);
    }
}

#[allow(clippy::too_many_arguments)]
fn rotor_check(
    args: &Config,
    out: &OutDir,
    rec: &FlightRecord,
    fl: &Path,
    base: &DamperDeck,
    base_label: &str,
    extended_path: &Path,
    cause: &str,
    say: Say,
) -> anyhow::Result<RotorCheck> {
    debug_assert_ne!(cause, "none");
    let rotor_path = args
        .rotor
        .as_ref()
        .context("--rotor-check needs --rotor ROTOR (a rotor deck)")?;
    let rotor = RotorDeck::from_file(rotor_path).with_context(|| {
        format!(
            "--rotor-check runs the rotor: --rotor {} must be a rotor deck",
            rotor_path.display()
        )
    })?;
    let extended = DamperDeck::from_file(extended_path)?;
    let opts = args.rotor_opts(args.check_revs);
    opts.check()?;
    let measured = Measured::from_record(rec);
    let meas = measured
        .as_ref()
        .map_err(|e| anyhow::anyhow!("--rotor-check: {e}"))?;
    say(&format!(
        "rotorsim diagnose: rotor check: {} revolutions x {} steps, physical damper, baseline deck and extended deck in parallel",
        opts.revs, opts.steps_per_rev
    ));
    let revs = opts.revs;
    let cb = |which: &str, rev: usize, m: Option<f64>| {
        progress_line(say, &format!("rotor check {which}"), rev, revs, m)
    };
    let runs = rotor_check_runs(&rotor, base, &extended, rec, &opts, &cb);
    // Each run's own outputs, exactly as `rotorsim run --damper physical` writes them.
    let cmd = |deck: Option<&Path>| {
        format!(
            "rotorsim run --rotor {}{} --flight {} --damper physical{} --revs {} --steps-per-rev {} --substeps {} --scheme rk4",
            rotor_path.display(),
            if opts.rigid { " --model rigid" } else { "" },
            fl.display(),
            deck.map(|p| format!(" --damper-deck {}", p.display()))
                .unwrap_or_default(),
            opts.revs,
            opts.steps_per_rev,
            opts.substeps
        )
    };
    let base_deck_arg = args.deck.as_deref();
    let mut parts = Vec::new();
    let mut strokes = Vec::new();
    for (which, res, deck_label, command) in [
        (
            "baseline",
            &runs.baseline,
            base_label.to_string(),
            cmd(base_deck_arg),
        ),
        (
            "extended",
            &runs.extended,
            out.published_path(extended_path).display().to_string(),
            cmd(Some(&out.published_path(extended_path))),
        ),
    ] {
        let sub = out.sub_dir(&format!("rotor_check/{which}"))?;
        let outcome = ModelOutcome {
            model: crate::hydraulics::DamperModel::Physical,
            result: res.clone(),
        };
        let oil = match which {
            "baseline" => base.oil,
            _ => extended.oil,
        };
        let wall_s = res.as_ref().map_or(runs.wall_s, |r| r.wall_s);
        let info = check_run_info(args, &opts, (rec, fl), rotor_path, &deck_label, wall_s, oil);
        let failed = crate::run::outputs::write_outputs(&sub, &info, &[outcome], &measured)?.failed;
        if failed.is_empty() {
            sub.finish()?;
        } else {
            sub.mark_incomplete(&failed.join("; "))?;
        }
        let run = res
            .as_ref()
            .map_err(|e| anyhow::anyhow!("rotor check, {which} deck: {e}"))?;
        let figs = summary::figures(run, Some(meas))?;
        let metrics = figs.metrics.context("rotor check: no comparison metrics")?;
        strokes.push(figs.stroke);
        parts.push((which, run, deck_label, command, metrics));
    }
    let (b, e) = (&parts[0].4, &parts[1].4);
    let gain = 1.0 - e.rms_error / b.rms_error;
    let improved = e.rms_error < b.rms_error;
    let (rb, re) = (parts[0].1, parts[1].1);
    let periodic_note = periodic_note(rb, re, opts.revs);
    let statement = format!(
            "Rotor level ({}, physical damper, last of {} revolutions vs the record's averaged damper force): the extended deck ({cause}) {} the RMS error from {:.1} N to {:.1} N (gain {:.3}{}); peak-to-peak error {:+.0} N -> {:+.0} N; correlation {:.4} -> {:.4}; {periodic_note}.",
            args.rotor_model_label(),
            opts.revs,
            if improved { "lowers" } else { "does NOT improve: it raises" },
            b.rms_error,
            e.rms_error,
            gain,
            if improved { "" } else { ", no rotor-level gain" },
            b.peak_to_peak_error,
            e.peak_to_peak_error,
            b.correlation,
            e.correlation
    );
    let side = |p: &Side, st: &Option<summary::StrokeCheck>| side_json(p, st, &opts);
    let json = json!({
        "statement": statement,
        "rotor": rotor_path.display().to_string(),
        "rotor_model": args.rotor_model_label(),
        "flight": fl.display().to_string(),
        "damper_model": "physical",
        "revs": opts.revs,
        "steps_per_rev": opts.steps_per_rev,
        "substeps": opts.substeps,
        "scheme": "rk4",
        "wall_time_s": runs.wall_s,
        "baseline": side(&parts[0], &strokes[0]),
        "extended": side(&parts[1], &strokes[1]),
        "change": {
            "rms_error_N": e.rms_error - b.rms_error,
            "gain": gain,
            "improved": improved,
            "peak_to_peak_error_N": e.peak_to_peak_error - b.peak_to_peak_error,
            "correlation": e.correlation - b.correlation,
        },
    });
    let mut rows = metric_rows(b, e, gain);
    harmonic_rows(&mut rows, b, e);
    if let (Some(sb), Some(se)) = (&strokes[0], &strokes[1]) {
        stroke_rows(&mut rows, sb, se);
    }
    rows.extend(run_rows(rb, re, runs.wall_s));
    let curves = check_curves(meas, &parts);
    Ok(RotorCheck {
        json,
        rows,
        statement,
        curves,
    })
}

/// One side of the rotor check: which deck, its run, deck label, command and metrics.
type Side<'r> = (
    &'static str,
    &'r ModelRun,
    String,
    String,
    crate::analysis::compare::Metrics,
);

/// `rotor_check.baseline` / `.extended` of diagnosis.json.
fn side_json(p: &Side, st: &Option<summary::StrokeCheck>, opts: &RotorRunOptions) -> Value {
    json!({
        "damper_deck": p.2,
        "command": p.3,
        "summary": format!("rotor_check/{}/summary.json", p.0),
        "run": run_json(p.1, opts),
        "metrics": summary::with_unit(serde_json::to_value(&p.4).unwrap_or_default(), "N"),
        "stroke_check": summary::with_unit(serde_json::to_value(st).unwrap_or_default(), "m"),
    })
}

/// The periodicity and wall-time rows of the two runs.
fn run_rows(rb: &ModelRun, re: &ModelRun, wall_s: f64) -> [Vec<String>; 2] {
    [
        vec![
            "periodicity (last revolution)".into(),
            fmt_measure(rb.last_measure()),
            fmt_measure(re.last_measure()),
            String::new(),
        ],
        vec![
            "wall time [s]".into(),
            format!("{:.1}", rb.wall_s),
            format!("{:.1}", re.wall_s),
            format!("both in parallel {:.1}", wall_s),
        ],
    ]
}

/// The record's revolution-averaged damper force and each run's last revolution.
fn check_curves(meas: &Measured, parts: &[Side]) -> Vec<(String, Vec<f64>, Vec<f64>)> {
    let mut curves = vec![(
        "measured (revolution average)".to_string(),
        meas.azimuth_deg.clone(),
        meas.force_n.clone(),
    )];
    for p in parts {
        if let Some(fz) = p.1.channel("damper_force_N") {
            curves.push((
                format!("{} deck", p.0),
                p.1.azimuth_deg.clone(),
                fz.to_vec(),
            ));
        }
    }
    curves
}

/// What a rotor-check run writes beside its outputs (as `rotorsim run --damper physical`).
fn check_run_info(
    args: &Config,
    opts: &RotorRunOptions,
    (rec, fl): (&FlightRecord, &Path),
    rotor_path: &Path,
    deck_label: &str,
    wall_s: f64,
    oil: Option<crate::hydraulics::OilTemperature>,
) -> RunInfo {
    RunInfo {
        rotor: rotor_path.display().to_string(),
        rotor_model: args.rotor_model_label().into(),
        flight: fl.display().to_string(),
        damper_deck: deck_label.to_string(),
        revs: opts.revs,
        steps_per_rev: opts.steps_per_rev,
        substeps: opts.substeps,
        scheme: "rk4".into(),
        newton: crate::solver::NewtonMethod::Modified.name().into(),
        periodic: crate::run::PeriodicMethod::March.name().into(),
        periodic_tol: crate::run::periodic::DEFAULT_TOL,
        initial_state: None,
        overrides: Vec::new(),
        inputs_sha256: None,
        synthetic: rec.meta.synthetic,
        counter: rec.meta.counter.clone(),
        wall_s,
        blades: None,
        blade_differences: Vec::new(),
        airframe: Vec::new(),
        damper_oil_temperature_k: oil
            .map(|l| rec.meta.damper_oil_temperature_k.unwrap_or(l.temperature_k)),
    }
}

/// Whether both rotor-check runs are periodic, or each one's last measure.
fn periodic_note(rb: &ModelRun, re: &ModelRun, revs: usize) -> String {
    if rb.converged() && re.converged() {
        return format!("both runs periodic after {revs} revolutions");
    }
    let verdict = |r: &ModelRun| {
        if r.converged() {
            "periodic"
        } else {
            "NOT periodic"
        }
    };
    format!(
        "periodicity after {revs} revolutions: baseline {} ({}), extended {} ({})",
        fmt_measure(rb.last_measure()),
        verdict(rb),
        fmt_measure(re.last_measure()),
        verdict(re)
    )
}

/// The (metric, baseline, extended, change) rows of the damper force's comparison.
fn metric_rows(
    b: &crate::analysis::compare::Metrics,
    e: &crate::analysis::compare::Metrics,
    gain: f64,
) -> Vec<Vec<String>> {
    let f = |x: f64| format!("{x:.1}");
    vec![
        vec![
            "RMS error [N]".into(),
            f(b.rms_error),
            f(e.rms_error),
            format!("{:+.1} (gain {:.3})", e.rms_error - b.rms_error, gain),
        ],
        vec![
            "RMS error / measured RMS".into(),
            format!("{:.3}", b.rms_error_rel),
            format!("{:.3}", e.rms_error_rel),
            format!("{:+.3}", e.rms_error_rel - b.rms_error_rel),
        ],
        vec![
            "max |error| [N]".into(),
            f(b.max_abs_error),
            f(e.max_abs_error),
            format!("{:+.1}", e.max_abs_error - b.max_abs_error),
        ],
        vec![
            format!("peak-to-peak [N] (measured {:.0})", b.peak_to_peak_measured),
            format!("{:.0}", b.peak_to_peak_model),
            format!("{:.0}", e.peak_to_peak_model),
            format!("{:+.0}", e.peak_to_peak_model - b.peak_to_peak_model),
        ],
        vec![
            "peak-to-peak error [N]".into(),
            format!("{:+.0}", b.peak_to_peak_error),
            format!("{:+.0}", e.peak_to_peak_error),
            String::new(),
        ],
        vec![
            format!("mean [N] (measured {:.0})", b.mean_measured),
            format!("{:.0}", b.mean_model),
            format!("{:.0}", e.mean_model),
            format!("{:+.0}", e.mean_model - b.mean_model),
        ],
        vec![
            "correlation".into(),
            format!("{:.4}", b.correlation),
            format!("{:.4}", e.correlation),
            format!("{:+.4}", e.correlation - b.correlation),
        ],
    ]
}

fn rotor_check_html(r: &mut HtmlReport, c: &RotorCheck, synthetic: bool) -> Result<(), PlotError> {
    r.heading(2, "Rotor-level check (before / after)");
    r.paragraph(&c.statement);
    if c.rows.is_empty() {
        return Ok(());
    }
    r.table(
        &["metric", "baseline deck", "extended deck", "change"],
        &c.rows,
    );
    r.paragraph(&format!(
        "Commands (equivalent): {} ; {}. Outputs of each run: rotor_check/baseline/ and rotor_check/extended/ (summary.json, report.html, last_rev.csv).",
        c.json["baseline"]["command"].as_str().unwrap_or(""),
        c.json["extended"]["command"].as_str().unwrap_or("")
    ));
    let syn = if synthetic { " (SYNTHETIC record)" } else { "" };
    let mut p = Plot::new(
        &format!("Damper force over the last revolution{syn}"),
        "azimuth [deg]",
        "damper force [N]",
    );
    for (i, (name, x, y)) in c.curves.iter().enumerate() {
        p = match i {
            0 => p.points(name, x, y),
            1 => p.line(name, x, y),
            _ => p.dashed(name, x, y),
        };
    }
    r.svg(
        "rotor-level damper force: measured, baseline and extended deck",
        &p.to_svg(800, 420)?,
    );
    Ok(())
}

/// The baseline deck, the data and what they are, as `run` reads them.
struct Inputs {
    deck: DamperDeck,
    data: Vec<Measurement>,
    /// What the data are (the report's first paragraph).
    source: String,
    stroke_info: Option<Value>,
    /// Without a measured stroke there is no stroke channel for the force to lag: a lag
    /// between the force and the simulated stroke is the rotor model's phase error.
    stroke_simulated: bool,
    record: Option<(FlightRecord, PathBuf)>,
    deck_label: String,
}

/// A flight record: its measured damper stroke replayed, or, without one, the stroke the full
/// rotor run simulates.
fn flight_inputs(args: &Config, fl: &Path, say: Say) -> anyhow::Result<Inputs> {
    let stroke_info: Option<Value>;
    let mut stroke_simulated = false;
    let deck_path =
        args.deck.clone().or(args.rotor.clone()).context(
            "--flight needs --rotor ROTOR (or --damper-deck DECK) for the baseline damper",
        )?;
    let deck = DamperDeck::from_file(&deck_path)?;
    let deck_label = deck_path.display().to_string();
    let rec = FlightRecord::read(fl)?;
    let synth = if rec.meta.synthetic {
        " SYNTHETIC record (labelled synthetic in its metadata)."
    } else {
        ""
    };
    let (m, src) = if rec.has_stroke() {
        let m = flight_measurement(&rec, fl, None)?;
        stroke_info = Some(json!({
            "kind": "measured",
            "statement": "The stroke is the record's measured damper stroke (stroke-driven replay).",
        }));
        let src = format!(
            "Flight record {} (stroke-driven replay of the damper, Omega = {} rad/s), baseline deck {}.{synth}",
            fl.display(),
            rec.meta.rotor_speed_rad_s,
            deck_path.display()
        );
        (m, src)
    } else {
        let rotor_path = args.rotor.clone().with_context(|| {
            format!(
                "{}: the record has no damper stroke: the stroke is simulated by the full rotor run, which needs --rotor ROTOR (a rotor deck)",
                fl.display()
            )
        })?;
        let opts = args.rotor_opts(args.revs);
        opts.check()?;
        let (m, info, statement) = simulated_measurement(&rec, fl, &rotor_path, &deck, &opts, say)?;
        stroke_info = Some(info);
        stroke_simulated = true;
        let src = format!(
            "Flight record {} WITHOUT damper stroke (Omega = {} rad/s), baseline deck {}. {statement}{synth}",
            fl.display(),
            rec.meta.rotor_speed_rad_s,
            deck_path.display()
        );
        (m, src)
    };
    Ok(Inputs {
        deck,
        data: vec![m],
        source: src,
        stroke_info,
        stroke_simulated,
        record: Some((rec, fl.to_path_buf())),
        deck_label,
    })
}

/// Bench tests, each checked alone so that a test unfit for a diagnosis is named by its file.
fn bench_inputs(args: &Config) -> anyhow::Result<Inputs> {
    let deck_path = args
        .deck
        .clone()
        .context("--measured needs --damper-deck DECK")?;
    let deck = DamperDeck::from_file(&deck_path)?;
    let data = args
        .measured
        .iter()
        .map(|p| {
            let t = read_bench_csv_with_dropouts(p)?;
            let m = Measurement::from_bench(&t)
                .with_context(|| format!("bench file {}", p.display()))?;
            // a test unfit for a diagnosis is named by its file
            let one = std::slice::from_ref(&m);
            super::data::screen(one).with_context(|| format!("bench file {}", p.display()))?;
            super::check_measurements(one)
                .with_context(|| format!("bench file {}", p.display()))?;
            Ok(m)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    // Bench files carry no metadata: a file named synthetic is labelled so (as bench does).
    let synthetic = args.measured.iter().any(|p| {
        p.file_name().is_some_and(|n| {
            n.to_string_lossy()
                .to_ascii_lowercase()
                .contains("synthetic")
        })
    });
    let src = format!(
        "Bench tests {} (stroke-driven replay), baseline deck {}.{}",
        args.measured
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
        deck_path.display(),
        if synthetic {
            " SYNTHETIC tests (named synthetic)."
        } else {
            ""
        }
    );
    Ok(Inputs {
        deck,
        data,
        source: src,
        stroke_info: None,
        stroke_simulated: false,
        record: None,
        deck_label: String::new(),
    })
}

/// The rotor-level check is not run when the extended deck is the baseline deck: no cause, or
/// a cause that is the data acquisition's.
fn skipped_check(cause: &str) -> Option<RotorCheck> {
    if cause == "none" {
        return Some(RotorCheck {
            json: json!({
                "statement": "No extension was chosen (cause none): the extended deck is the baseline deck, so the rotor-level comparison cannot change; the rotor runs were not made.",
                "skipped": true,
            }),
            rows: vec![],
            statement: "Rotor-level check skipped: no extension was chosen (cause none), the extended deck is the baseline deck.".into(),
            curves: vec![],
        });
    }
    super::acquisition::only_faults(cause).then(|| RotorCheck {
            json: json!({
                "statement": format!("The cause is the data acquisition ({}), not the damper: the extended deck is the baseline deck, so the rotor-level comparison cannot change; the rotor runs were not made.", cause),
                "skipped": true,
            }),
            rows: vec![],
            statement: format!("Rotor-level check skipped: the cause is the data acquisition ({}), the extended deck is the baseline deck.", cause),
            curves: vec![],
        })
}

/// Checks the options, reads the data, diagnoses it and writes every output into `args.out`.
pub fn run(args: &Config, say: Say) -> anyhow::Result<Report> {
    args.check()?;
    let inputs = match (&args.flight, args.measured.is_empty()) {
        (Some(fl), true) => flight_inputs(args, fl, say)?,
        (None, false) => bench_inputs(args)?,
        (Some(_), false) => bail!("give either --flight or --measured, not both"),
        (None, true) => bail!(
            "nothing to diagnose: give --damper-deck DECK --measured TEST.csv [...] or --rotor ROTOR --flight RECORD"
        ),
    };
    let Inputs {
        deck,
        data,
        source,
        stroke_info,
        stroke_simulated,
        record,
        deck_label,
    } = inputs;
    let mut opts = DiagnoseOptions {
        fit_cycles: args.fit_cycles,
        max_substep_s: args.max_substep,
        ..Default::default()
    };
    if stroke_simulated {
        opts.faults.retain(|f| *f != super::acquisition::Fault::Lag);
    }
    let mut outcome = diagnose_with_progress(&deck, &data, &opts, say)?;
    if stroke_simulated {
        outcome.diagnosis.limitations.push(
            "force_lag not tried: the stroke is simulated, so a lag of the force behind it is the rotor model's phase error, not the data acquisition's".into(),
        );
    }
    let d = &outcome.diagnosis;
    let mut inputs: Vec<PathBuf> = args.deck.iter().cloned().collect();
    if let Some(r) = &args.rotor {
        match crate::rotor::RotorDeck::from_file(r) {
            Ok(d) => inputs.extend(d.input_files()),
            Err(_) => inputs.push(r.clone()), // read as a damper deck only
        }
    }
    if let Some(fl) = &args.flight {
        inputs.extend(FlightRecord::files(fl)?);
    }
    inputs.extend(args.measured.iter().cloned());
    let out = OutDir::create(&args.out, &inputs)?;
    let deck_text = format!(
        "# Extended damper deck written by `rotorsim diagnose` (cause: {}), from {}\n{}",
        d.cause,
        deck.source,
        outcome.extended.to_toml()
    );
    let deck_file = out.write("extended_deck.toml", deck_text.as_bytes())?;
    if let Some(p) = &args.write_deck {
        write_atomic(p, deck_text.as_bytes())?;
    }
    // The rotor-level before/after runs the deck as written (what `rotorsim run --damper-deck`
    // reads).
    let check = match &record {
        Some(_) if args.rotor_check && skipped_check(&d.cause).is_some() => skipped_check(&d.cause),
        Some((rec, fl)) if args.rotor_check => {
            let deck_path = args.write_deck.clone().unwrap_or(deck_file);
            Some(rotor_check(
                args,
                &out,
                rec,
                fl,
                &deck,
                &deck_label,
                &deck_path,
                &d.cause,
                say,
            )?)
        }
        _ => None,
    };
    // diagnosis.json: the docs/formats.md keys and the existing extras, plus new keys only.
    let noise = super::report::noise_of(d, &outcome.curves);
    let mut json = serde_json::to_value(d)?;
    if let Some(obj) = json.as_object_mut() {
        obj.insert("signature_noise".into(), serde_json::to_value(&noise)?);
        if let Some(s) = &stroke_info {
            obj.insert("stroke_source".into(), s.clone());
        }
        if let Some(c) = &check {
            obj.insert("rotor_check".into(), c.json.clone());
        }
    }
    out.write(
        "diagnosis.json",
        serde_json::to_string_pretty(&json)?.as_bytes(),
    )?;
    let synthetic = record.as_ref().is_some_and(|(r, _)| r.meta.synthetic);
    let html = super::report::html_with(d, &outcome.curves, &source, Some(&noise), |r| {
        if let Some(w) = stroke_info.as_ref().and_then(|s| s.get("warning")) {
            r.notice(w.as_str().unwrap_or_default());
        }
        match &check {
            Some(c) => rotor_check_html(r, c, synthetic),
            None => Ok(()),
        }
    })?;
    out.write("diagnosis.html", html.as_bytes())?;
    out.finish()?;
    // A deck asked for inside the result folder went with the folder it replaced: written again
    // into the published one.
    if let Some(p) = &args.write_deck {
        if !p.exists() {
            write_atomic(p, deck_text.as_bytes())?;
        }
    }
    Ok(Report {
        outcome,
        stroke_info,
        check,
    })
}

/// Interval of the diagnosis's heartbeat lines [s].
const HEARTBEAT_S: u64 = 15;

/// The diagnosis of `data`, its cost bounded from below first (refused when even that is beyond
/// the budget, named with its samples), then a line every [`HEARTBEAT_S`] while it runs: a long
/// bench file is never silent.
fn diagnose_with_progress(
    deck: &crate::hydraulics::DamperDeck,
    data: &[super::Measurement],
    opts: &super::DiagnoseOptions,
    say: Say,
) -> anyhow::Result<super::Outcome> {
    let samples: usize = data.iter().map(|m| m.time_s.len()).sum();
    // sub-steps of one replay of every test (a sample interval is cut to max_substep_s)
    let substeps: f64 = data
        .iter()
        .map(|m| {
            m.time_s
                .windows(2)
                .map(|w| ((w[1] - w[0]) / opts.max_substep_s).ceil().max(1.0))
                .sum::<f64>()
        })
        .sum();
    // full replays: the baseline and each candidate's, its held-out test and its intervals
    // (~4 per candidate); the fits run on a few cycles and are not counted (a lower bound)
    let replays = 4.0 * (opts.candidates.len() as f64 + 1.0);
    let estimate = crate::solver::budget::substeps(substeps * replays).plus(
        crate::solver::budget::samples(samples as f64, 8.0 * replays),
    );
    estimate.check(
        &format!(
            "the diagnosis of {samples} samples in {} test(s) ({} candidates; a lower bound)",
            data.len(),
            opts.candidates.len()
        ),
        "give fewer or shorter tests (a few dozen cycles per amplitude suffice), or a larger --max-substep",
    )?;
    if samples > 20_000 {
        say(&format!(
            "diagnose: {samples} samples in {} test(s), {} candidates: a long diagnosis (a few \
             dozen cycles per amplitude suffice); progress every {HEARTBEAT_S} s",
            data.len(),
            opts.candidates.len()
        ));
    }
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    let t0 = std::time::Instant::now();
    std::thread::scope(|s| {
        s.spawn(move || {
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) =
                rx.recv_timeout(std::time::Duration::from_secs(HEARTBEAT_S))
            {
                say(&format!(
                    "diagnose: fitting the candidates, {:.0} s so far",
                    t0.elapsed().as_secs_f64()
                ));
            }
        });
        let r = super::diagnose(deck, data, opts);
        drop(tx);
        r.map_err(Into::into)
    })
}
