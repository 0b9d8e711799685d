//! The outputs of `rotorsim bench`: the harmonic sweep of a damper deck (paper Figs. 13-14:
//! peaks.csv, history_v<v>m_s.csv, time_history.svg, bench_summary.csv,
//! peak_force_vs_velocity.svg, bench.html) and the replay of measured bench tests
//! (replay_*.csv, loop_*.svg, replay_summary.csv, bench.html). The devices come built from
//! the deck by [`BenchJob`], which checks the command's options; nothing here prints (the
//! command reports through the callbacks).
use crate::hydraulics::bench::{
    self, BenchTest, Convergence, HarmonicRun, History, ReplayMetrics, RunEstimate, SweepOptions,
    IN_TO_M, LB_TO_N, REFINE_MAX_DOUBLINGS, REFINE_TOLERANCE,
};
use crate::hydraulics::{DamperDeck, DamperModel, Device, IntegratorOptions, Scheme};
use crate::io::{csv_from_columns, OutDir};
use crate::report::html::{Banner, HtmlReport};
use crate::report::plot::{grid_svg, stacked_svg, Plot};
use anyhow::{bail, Context};
use std::f64::consts::PI;
use std::path::PathBuf;

/// What a bench run needs, checked by the command (units as on its command line).
#[derive(Debug, Clone)]
pub struct Config {
    /// The damper deck file (for the output manifest).
    pub deck: PathBuf,
    pub out: PathBuf,
    /// Circular frequency of the harmonic stroking [rad/s].
    pub omega: f64,
    /// Peak velocities in `velocity_unit`.
    pub peak_velocity: Vec<f64>,
    /// Unit of `peak_velocity` ("in/s", "m/s", "ft/s") and metres per second in it.
    pub velocity_unit: String,
    pub factor: f64,
    pub cycles: usize,
    /// Steps per cycle (the first of the refinement when `refine`).
    pub steps_per_cycle: usize,
    /// Output samples per step of the harmonic sweep.
    pub per_step: usize,
    /// Hydraulic sub-stepping of each output sample.
    pub opts: IntegratorOptions,
    /// Refine each run until it converges (the default); false: run as asked, the error
    /// estimated from one extra run at twice the steps per cycle.
    pub refine: bool,
    /// Measured tests to replay, and the cycles their metrics leave out.
    pub measured: Vec<PathBuf>,
    pub skip_cycles: usize,
}

/// Peak velocities of the harmonic sweep by default, in in/s.
pub const DEFAULT_PEAK_VELOCITIES_IN_S: [f64; 8] = [0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0, 10.0];

/// Every option of `rotorsim bench` but its result folder, as given: the command's flags (clap)
/// and the Python package's keyword arguments (serde, through JSON) are this one type;
/// [`BenchSettings::job`] reads it into a [`BenchJob`]. [`BenchSettings::default`] gives the
/// command line's defaults (the required `damper_deck` unset).
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct BenchSettings {
    /// Damper deck (any TOML file with a [damper] table, e.g. rotors/uh60a.toml).
    #[arg(long, alias = "deck", value_name = "DECK", required = true)]
    pub damper_deck: Option<PathBuf>,
    /// Damper model: physical, linear, nonlinear, or all (default: the deck's `model`).
    #[arg(long)]
    pub damper: Option<String>,
    /// Circular frequency of the harmonic stroking [rad/s].
    #[arg(long, default_value_t = 27.02)]
    pub omega: f64,
    /// Peak velocities, comma separated, in --velocity-unit.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1,2,3,4,6,8,10")]
    pub peak_velocity: Vec<f64>,
    /// Unit of --peak-velocity: in/s, m/s or ft/s.
    #[arg(long, default_value = "in/s")]
    pub velocity_unit: String,
    /// Number of stroking cycles per amplitude (peaks are taken over the last one).
    #[arg(long, default_value_t = 10)]
    pub cycles: usize,
    /// Steps per cycle (the structural step of the coupled analysis). Left out (with --substeps
    /// and --scheme), each run starts at 256 and doubles them until its outputs converge to
    /// 0.2 % (at most 16x); given, the bench runs at it as asked.
    #[arg(long)]
    pub steps_per_cycle: Option<usize>,
    /// Hydraulic sub-steps per step (default: 4 with the implicit scheme, 25 with rk4). Given,
    /// the bench runs as asked (no refinement).
    #[arg(long)]
    pub substeps: Option<usize>,
    /// Hydraulic sub-step scheme: implicit (the default) or rk4. Given, the bench runs as asked
    /// (no refinement).
    #[arg(long, alias = "integrator", value_name = "INTEGRATOR")]
    pub scheme: Option<String>,
    /// Output samples per second of the harmonic sweep (histories, peaks, loops): a multiple k
    /// of the step rate omega x --steps-per-cycle / 2 pi (rounded to the nearest; default k = 1,
    /// a sample at every step end). Each step is fed to the damper in k pieces with
    /// --substeps / k sub-steps each (rounded up), so the hydraulic sub-step does not grow.
    #[arg(long, value_name = "HZ")]
    pub output_rate: Option<f64>,
    /// Measured bench test(s) to replay instead of the harmonic sweep (bench CSV, docs/formats.md).
    #[arg(long)]
    pub measured: Vec<PathBuf>,
    /// Replay only: leave the first N cycles of each test out of the error metrics (the model
    /// starts at rest and settles over them). A cycle is the stroke's period: the median
    /// interval between upward crossings of its mid-range.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub skip_cycles: usize,
}

impl Default for BenchSettings {
    fn default() -> Self {
        crate::run::settings::command_line_defaults("bench")
    }
}

impl crate::run::settings::JobSettings for BenchSettings {
    const COMMAND: &'static str = "bench";
}

impl BenchSettings {
    /// The bench these settings ask for into `out` (its options checked when it runs).
    pub fn job(&self, out: impl Into<PathBuf>) -> anyhow::Result<BenchJob> {
        let deck = crate::run::settings::required(
            &self.damper_deck,
            "--damper-deck",
            "a damper deck (a TOML file with a [damper] table)",
        )?;
        Ok(BenchJob {
            deck: deck.clone(),
            damper: self.damper.clone(),
            omega: self.omega,
            peak_velocity: self.peak_velocity.clone(),
            velocity_unit: self.velocity_unit.clone(),
            cycles: self.cycles,
            steps_per_cycle: self.steps_per_cycle,
            substeps: self.substeps,
            scheme: self.scheme.clone(),
            output_rate: self.output_rate,
            measured: self.measured.clone(),
            skip_cycles: self.skip_cycles,
            out: out.into(),
        })
    }
}

/// `rotorsim bench` as a library call: the command's options, typed ([`BenchJob::new`] gives
/// its defaults), checked and run by [`BenchJob::execute`]. The command line and the Python
/// package both run through it.
#[derive(Debug, Clone)]
pub struct BenchJob {
    /// Damper deck (any TOML file with a `[damper]` table).
    pub deck: PathBuf,
    /// physical, linear, nonlinear or all (None: the deck's `model`).
    pub damper: Option<String>,
    /// Circular frequency of the harmonic stroking [rad/s].
    pub omega: f64,
    /// Peak velocities in `velocity_unit` (in/s, m/s or ft/s).
    pub peak_velocity: Vec<f64>,
    pub velocity_unit: String,
    pub cycles: usize,
    /// Steps per cycle, sub-steps per step and scheme (None: the defaults, 256 steps per cycle
    /// refined until converged, 4 implicit sub-steps; any of them given: run as asked).
    pub steps_per_cycle: Option<usize>,
    pub substeps: Option<usize>,
    /// Hydraulic sub-step scheme: implicit or rk4.
    pub scheme: Option<String>,
    /// Output samples per second of the harmonic sweep (None: one per step).
    pub output_rate: Option<f64>,
    /// Measured bench tests to replay instead of the harmonic sweep.
    pub measured: Vec<PathBuf>,
    /// Replay only: cycles left out of the error metrics.
    pub skip_cycles: usize,
    pub out: PathBuf,
}

/// Steps per cycle of the bench when not given: the first of the refinement.
pub const DEFAULT_STEPS_PER_CYCLE: usize = 256;
/// Hydraulic sub-steps per step when not given, by scheme.
pub const DEFAULT_SUBSTEPS_IMPLICIT: usize = 4;
pub const DEFAULT_SUBSTEPS_RK4: usize = 25;

/// One model's harmonic sweep as the bench ran it: the sub-stepping, whether it was refined,
/// and each run's error estimate (in `--peak-velocity` order).
#[derive(Debug, Clone)]
pub struct ModelSweep {
    pub opts: IntegratorOptions,
    pub refined: bool,
    pub estimates: Vec<RunEstimate>,
}

/// What a bench run did, its folder published.
#[derive(Debug)]
pub struct BenchOutcome {
    /// Harmonic sweep: each model's runs (empty for a replay).
    pub sweep: Vec<(DamperModel, Vec<HarmonicRun>)>,
    /// Each model's error estimates, as `sweep`.
    pub estimates: Vec<(DamperModel, ModelSweep)>,
    /// Output samples per step and hydraulic sub-steps per sample of the harmonic sweep.
    pub per_step: usize,
    pub substeps: usize,
    /// Output sample rate of the harmonic sweep [Hz].
    pub output_rate_hz: f64,
}

fn velocity_factor(unit: &str) -> anyhow::Result<f64> {
    Ok(match unit {
        "in/s" => IN_TO_M,
        "m/s" => 1.0,
        "ft/s" => 0.3048,
        _ => bail!("unknown --velocity-unit '{unit}' (expected in/s, m/s or ft/s)"),
    })
}

impl BenchJob {
    /// The bench of `deck` into `out` with the defaults of `rotorsim bench`.
    pub fn new(deck: impl Into<PathBuf>, out: impl Into<PathBuf>) -> Self {
        BenchJob {
            deck: deck.into(),
            damper: None,
            omega: 27.02,
            peak_velocity: DEFAULT_PEAK_VELOCITIES_IN_S.to_vec(),
            velocity_unit: "in/s".into(),
            cycles: 10,
            steps_per_cycle: None,
            substeps: None,
            scheme: None,
            output_rate: None,
            measured: vec![],
            skip_cycles: 0,
            out: out.into(),
        }
    }

    /// The sweep's peak velocities (in `--velocity-unit`, `factor` to m/s): positive, finite,
    /// and told apart by their history files' names.
    fn check_peak_velocities(&self, factor: f64) -> anyhow::Result<()> {
        if self.peak_velocity.is_empty()
            || self
                .peak_velocity
                .iter()
                .any(|v| !(*v > 0.0 && v.is_finite()))
        {
            bail!(
                "--peak-velocity must be positive numbers (got {:?})",
                self.peak_velocity
            );
        }
        let names: Vec<String> = self
            .peak_velocity
            .iter()
            .map(|&v| history_name(v * factor))
            .collect();
        for (i, a) in names.iter().enumerate() {
            if let Some(j) = names[..i].iter().position(|b| b == a) {
                bail!(
                    "--peak-velocity {} and {} {} name the same history file {a} (peak velocities are told apart to 1 um/s)",
                    self.peak_velocity[j],
                    self.peak_velocity[i],
                    self.velocity_unit
                );
            }
        }
        Ok(())
    }

    /// Checks the options and the deck, builds the devices, and runs the harmonic sweep (or
    /// the replay of `measured`) into `out`. `on_model` gets each model's sweep (and the
    /// hydraulic sub-stepping of its samples and each run's error estimate) once its files are
    /// written; `note` the replay's lines (each test's error metrics) and the sweep's warnings
    /// (a run that did not converge or whose error is not estimated).
    pub fn execute(
        &self,
        on_model: &mut dyn FnMut(DamperModel, &[HarmonicRun], &ModelSweep),
        note: &mut dyn FnMut(&str),
    ) -> anyhow::Result<BenchOutcome> {
        let deck = DamperDeck::from_file(&self.deck)?;
        let scheme: Scheme = match &self.scheme {
            None => Scheme::Implicit,
            Some(s) => s
                .parse()
                .map_err(|e| anyhow::anyhow!("--integrator {s}: {e}"))?,
        };
        let refine =
            self.scheme.is_none() && self.steps_per_cycle.is_none() && self.substeps.is_none();
        let steps_per_cycle = self.steps_per_cycle.unwrap_or(DEFAULT_STEPS_PER_CYCLE);
        let substeps_asked = self.substeps.unwrap_or(match scheme {
            Scheme::Implicit => DEFAULT_SUBSTEPS_IMPLICIT,
            Scheme::Rk4 => DEFAULT_SUBSTEPS_RK4,
        });
        if substeps_asked == 0 || steps_per_cycle < 4 || self.cycles == 0 {
            bail!(
                "--substeps ({substeps_asked}) and --cycles ({}) must be >= 1 and --steps-per-cycle ({steps_per_cycle}) >= 4",
                self.cycles
            );
        }
        let replaying = !self.measured.is_empty();
        if replaying && self.output_rate.is_some() {
            bail!("--output-rate applies to the harmonic sweep; a replay (--measured) samples at the measurement's own instants");
        }
        if !replaying && self.skip_cycles > 0 {
            bail!("--skip-cycles applies to a replay (--measured); the harmonic sweep's peaks and loops are over its last cycle (--cycles)");
        }
        if !(self.omega > 0.0 && self.omega.is_finite()) {
            bail!(
                "--omega must be a positive number of rad/s (got {})",
                self.omega
            );
        }
        // Output samples per step (the harmonic sweep only).
        let step_rate = self.omega * steps_per_cycle as f64 / (2.0 * PI);
        let per_step = match self.output_rate {
            None => 1,
            Some(r) if !(r > 0.0 && r.is_finite()) => bail!(
                "--output-rate must be a positive number of samples per second (got {r})"
            ),
            Some(r) if r < 0.999 * step_rate => bail!(
                "--output-rate {r} Hz is below the step rate {step_rate:.1} Hz (--omega x --steps-per-cycle / 2 pi): the bench writes a sample at every step end at least"
            ),
            Some(r) => ((r / step_rate).round() as usize).max(1),
        };
        let substeps = substeps_asked.div_ceil(per_step);
        // per amplitude and model: cycles x steps x pieces x sub-steps, every piece kept (5
        // columns), at the most steps per cycle the bench may run (the refinement's cap, or
        // the error estimate's run at twice the steps)
        let most_steps = steps_per_cycle * if refine { 1 << REFINE_MAX_DOUBLINGS } else { 2 };
        let samples = self.cycles as f64 * most_steps as f64 * per_step as f64;
        crate::solver::budget::substeps(samples * substeps as f64)
            .plus(crate::solver::budget::samples(samples, 5.0))
            .check(
                &format!(
                    "{} cycles x {} steps x {} samples per step x {} sub-steps per amplitude",
                    self.cycles, most_steps, per_step, substeps
                ),
                "check --cycles, --steps-per-cycle, --output-rate and --substeps",
            )?;
        let opts = IntegratorOptions { scheme, substeps };
        let models: Vec<DamperModel> = match self.damper.as_deref() {
            None => vec![deck.model],
            Some("all") => vec![
                DamperModel::Physical,
                DamperModel::Linear,
                DamperModel::Nonlinear,
            ],
            Some(s) => vec![s
                .parse()
                .map_err(|e| anyhow::anyhow!("--damper {s}: {e}"))?],
        };
        // Build every device first so that a deck error leaves no output at all.
        let devices = models
            .iter()
            .map(|&m| Ok((m, deck.build(m, opts)?)))
            .collect::<anyhow::Result<Vec<_>>>()?;
        // A replay does not use the velocity unit: an unknown one is refused for the sweep only.
        let factor = velocity_factor(&self.velocity_unit);
        let cfg = Config {
            deck: self.deck.clone(),
            out: self.out.clone(),
            omega: self.omega,
            peak_velocity: self.peak_velocity.clone(),
            velocity_unit: self.velocity_unit.clone(),
            factor: factor.as_ref().map_or(1.0, |f| *f),
            cycles: self.cycles,
            steps_per_cycle,
            per_step,
            opts,
            refine,
            measured: self.measured.clone(),
            skip_cycles: self.skip_cycles,
        };
        let mut outcome = BenchOutcome {
            sweep: vec![],
            estimates: vec![],
            per_step,
            substeps,
            output_rate_hz: step_rate * per_step as f64,
        };
        if replaying {
            replay(&cfg, &deck, &devices, note)?;
            return Ok(outcome);
        }
        self.check_peak_velocities(factor?)?;
        sweep(
            &cfg,
            &deck,
            &devices,
            &mut |model, runs, est| {
                let ms = ModelSweep {
                    opts,
                    refined: refine,
                    estimates: est.to_vec(),
                };
                on_model(model, runs, &ms);
                outcome.sweep.push((model, runs.to_vec()));
                outcome.estimates.push((model, ms));
            },
            note,
        )?;
        Ok(outcome)
    }
}

/// What [`sweep`] calls with each model's runs and their error estimates.
pub type SweepCallback<'a> = dyn FnMut(DamperModel, &[HarmonicRun], &[RunEstimate]) + 'a;

/// Runs the harmonic sweep of every device and writes its outputs into `cfg.out`;
/// `on_model` gets each model's runs and their error estimates once its files are written,
/// `note` a warning per run that did not converge or whose error is not estimated.
pub fn sweep(
    cfg: &Config,
    deck: &DamperDeck,
    devices: &[(DamperModel, Box<dyn Device>)],
    on_model: &mut SweepCallback,
    note: &mut dyn FnMut(&str),
) -> anyhow::Result<()> {
    let (factor, per_step, opts) = (cfg.factor, cfg.per_step, cfg.opts);
    let sweep = SweepOptions {
        omega_rad_s: cfg.omega,
        peak_velocities_m_s: cfg.peak_velocity.iter().map(|v| v * factor).collect(),
        cycles: cfg.cycles,
        steps_per_cycle: cfg.steps_per_cycle,
    };
    if devices.iter().any(|(m, _)| *m == DamperModel::Physical) {
        let v_max = sweep
            .peak_velocities_m_s
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        deck.check_stroke(
            v_max / sweep.omega_rad_s,
            &format!(
                "the bench's largest amplitude (peak velocity {} {} at {} rad/s)",
                v_max / factor,
                cfg.velocity_unit,
                sweep.omega_rad_s
            ),
        )
        .map_err(anyhow::Error::msg)?;
    }
    let out = OutDir::create(&cfg.out, std::slice::from_ref(&cfg.deck))?;
    let mut all = Vec::new();
    let mut all_est = Vec::new();
    let mut time_histories = Vec::new();
    for (model, dev) in devices {
        let mut runs = Vec::with_capacity(sweep.peak_velocities_m_s.len());
        let mut estimates = Vec::with_capacity(sweep.peak_velocities_m_s.len());
        for &v in &sweep.peak_velocities_m_s {
            let r = if cfg.refine {
                bench::harmonic_run_converged(
                    dev.as_ref(),
                    sweep.omega_rad_s,
                    v,
                    sweep.cycles,
                    sweep.steps_per_cycle,
                    per_step,
                    true,
                    REFINE_TOLERANCE,
                    REFINE_MAX_DOUBLINGS,
                )
            } else {
                bench::harmonic_run_estimated(
                    dev.as_ref(),
                    sweep.omega_rad_s,
                    v,
                    sweep.cycles,
                    sweep.steps_per_cycle,
                    per_step,
                    true,
                )
            };
            let r = r.map_err(|e| {
                let mut msg = format!(
                    "{} model at peak velocity {} {} ({v} m/s): {e}",
                    model.name(),
                    v / factor,
                    cfg.velocity_unit
                );
                if *model == DamperModel::Physical {
                    msg = deck.with_review(msg);
                }
                let _ = out.mark_incomplete(&msg);
                anyhow::anyhow!(msg)
            })?;
            if let Some(w) = estimate_warning(&r.estimate, *model, v / factor, cfg) {
                note(&w);
            }
            runs.push(r.run);
            estimates.push(r.estimate);
        }
        let sub = if devices.len() > 1 {
            format!("{}/", model.name())
        } else {
            String::new()
        };
        let th = write_sweep(&out, &sub, deck, *model, &runs, cfg, factor)?;
        time_histories.push(th);
        on_model(*model, &runs, &estimates);
        all.push((*model, runs));
        all_est.push(estimates);
    }
    out.write(
        "bench_summary.csv",
        summary_csv(&all, &all_est, cfg, devices.len() > 1).as_bytes(),
    )?;
    let fig13 = fig13_plot(&all, cfg, factor, deck);
    out.write(
        "peak_force_vs_velocity.svg",
        fig13.to_svg(900, 480)?.as_bytes(),
    )?;
    let html = sweep_html(
        &all,
        &all_est,
        cfg,
        factor,
        deck,
        per_step,
        opts,
        &time_histories,
    )?;
    out.write("bench.html", html.as_bytes())?;
    out.finish()?;
    Ok(())
}

/// The history file of a peak velocity: `history_v<v>m_s.csv` with v in m/s to 1 um/s and at
/// least one integer digit, so names sort as the velocities do below 10 m/s.
pub fn history_name(v_m_s: f64) -> String {
    format!("history_v{v_m_s:08.6}m_s.csv")
}

fn history_csv(h: &History) -> String {
    let mut header = vec!["time_s", "stroke_m", "velocity_m_s", "force_N"];
    let mut cols: Vec<&[f64]> = vec![&h.time_s, &h.stroke_m, &h.velocity_m_s, &h.force_n];
    push_device_channels(h, &mut header, &mut cols);
    csv_from_columns(&header, &cols)
}

/// The device's channels after the bench's own, except those the bench already wrote (a
/// dashpot's only channel is the stroke rate, `velocity_m_s`): no column twice.
fn push_device_channels<'a>(h: &'a History, header: &mut Vec<&'a str>, cols: &mut Vec<&'a [f64]>) {
    for (n, c) in h.channel_names.iter().zip(&h.channels) {
        if !header.contains(n) {
            header.push(n);
            cols.push(c);
        }
    }
}

fn channel<'a>(h: &'a History, name: &str) -> Option<&'a [f64]> {
    h.channel_names
        .iter()
        .position(|n| *n == name)
        .map(|i| h.channels[i].as_slice())
}

/// Index of the first sample of the last cycle.
fn last_cycle_start(r: &HarmonicRun) -> usize {
    r.history
        .time_s
        .len()
        .saturating_sub(r.steps_per_cycle * r.samples_per_step + 1)
}

/// Output samples per second of a run.
fn run_rate(r: &HarmonicRun, omega: f64) -> f64 {
    omega * (r.steps_per_cycle * r.samples_per_step) as f64 / (2.0 * PI)
}

/// The warning a run's estimate calls for: not converged within the cap, or not estimated.
fn estimate_warning(e: &RunEstimate, model: DamperModel, v: f64, cfg: &Config) -> Option<String> {
    let at = format!(
        "{} model at peak velocity {v} {}, {} rad/s",
        model.name(),
        cfg.velocity_unit,
        cfg.omega
    );
    match e.status {
        Convergence::NotConverged => Some(format!(
            "WARNING: {at}: not converged: estimated error {:.3} % of scale after refining to {} steps per cycle (tolerance {} %, cap {}x the first {}); its values are the finest run's (bench_summary.csv convergence = not_converged)",
            100.0 * e.relative_error,
            e.steps_per_cycle,
            100.0 * REFINE_TOLERANCE,
            1usize << REFINE_MAX_DOUBLINGS,
            cfg.steps_per_cycle
        )),
        Convergence::NotEstimated => Some(format!(
            "WARNING: {at}: discretisation error not estimated ({})",
            e.note
        )),
        Convergence::Estimated if e.relative_error > REFINE_TOLERANCE => Some(format!(
            "note: {at}: estimated discretisation error {:.3} % of scale at the {} steps per cycle asked (leave --steps-per-cycle, --substeps and --scheme out to refine until converged)",
            100.0 * e.relative_error,
            e.steps_per_cycle
        )),
        _ => None,
    }
}

/// Writes one model's peaks.csv, histories and time_history.svg; returns the time-history SVG.
fn write_sweep(
    out: &OutDir,
    sub: &str,
    deck: &DamperDeck,
    model: DamperModel,
    runs: &[HarmonicRun],
    cfg: &Config,
    factor: f64,
) -> anyhow::Result<String> {
    let rows: Vec<[f64; 3]> = runs
        .iter()
        .map(|r| [r.peak_velocity_m_s, r.peak_force_pos_n, r.peak_force_neg_n])
        .collect();
    out.write(
        &format!("{sub}peaks.csv"),
        crate::io::csv_string(
            &["peak_velocity_m_s", "peak_force_pos_N", "peak_force_neg_N"],
            &rows,
        )
        .as_bytes(),
    )?;
    for r in runs {
        out.write(
            &format!("{sub}{}", history_name(r.peak_velocity_m_s)),
            history_csv(&r.history).as_bytes(),
        )?;
    }
    // Time history at the amplitude closest to 2 in/s (paper Fig. 14), last two cycles.
    let target = 2.0 * IN_TO_M;
    let r = runs
        .iter()
        .min_by(|a, b| {
            (a.peak_velocity_m_s - target)
                .abs()
                .total_cmp(&(b.peak_velocity_m_s - target).abs())
        })
        .context("no runs")?;
    let h = &r.history;
    let from = h
        .time_s
        .len()
        .saturating_sub(2 * r.steps_per_cycle * r.samples_per_step + 1);
    let t = &h.time_s[from..];
    let title = format!(
        "{} model, peak velocity {} {} (cf. paper Fig. 14; {}), {}",
        model.name(),
        r.peak_velocity_m_s / factor,
        cfg.velocity_unit,
        history_name(r.peak_velocity_m_s),
        deck.source
    );
    let mut plots = vec![Plot::new(&title, "time [s]", "force [kN]")
        .y_scale(1e-3)
        .line(model.name(), t, &h.force_n[from..])];
    if let (Some(p0), Some(p1)) = (channel(h, "p0_Pa"), channel(h, "p1_Pa")) {
        plots.push(
            Plot::new("chamber pressures", "time [s]", "pressure [MPa]")
                .y_scale(1e-6)
                .line("p0", t, &p0[from..])
                .line("p1", t, &p1[from..]),
        );
    }
    if let (Some(x0), Some(x1)) = (channel(h, "x_valve0_m"), channel(h, "x_valve1_m")) {
        plots.push(
            Plot::new("relief valve lifts", "time [s]", "lift [mm]")
                .y_scale(1e3)
                .line("valve 0", t, &x0[from..])
                .line("valve 1", t, &x1[from..]),
        );
    }
    let sv: Vec<f64> = h.stroke_m[from..].to_vec();
    plots.push(
        Plot::new("stroke", "time [s]", "stroke [mm]")
            .y_scale(1e3)
            .line("stroke", t, &sv),
    );
    // One legend width for the stack, so the time axes line up (trailing spaces do not show).
    let w = plots
        .iter()
        .flat_map(|p| p.series.iter().map(|s| s.name.chars().count()))
        .max()
        .unwrap_or(0);
    for p in &mut plots {
        for s in &mut p.series {
            s.name = format!("{:<w$}", s.name);
        }
    }
    let svg = stacked_svg(&plots, 900, 260)?;
    out.write(&format!("{sub}time_history.svg"), svg.as_bytes())?;
    Ok(svg)
}

/// bench_summary.csv: one row per model and amplitude.
fn summary_csv(
    all: &[(DamperModel, Vec<HarmonicRun>)],
    est: &[Vec<RunEstimate>],
    cfg: &Config,
    sub_dirs: bool,
) -> String {
    let mut s = String::from(
        "model,peak_velocity_m_s,peak_velocity_in_s,amplitude_m,omega_rad_s,output_rate_Hz,\
peak_force_pos_N,peak_force_neg_N,K_storage_N_per_m,K_loss_N_per_m,energy_per_cycle_J,\
equivalent_damping_N_s_per_m,history_file,steps_per_cycle,substeps,scheme,convergence,\
relative_error,peak_force_pos_error_N,peak_force_neg_error_N,K_storage_error_N_per_m,\
K_loss_error_N_per_m,energy_per_cycle_error_J,equivalent_damping_error_N_s_per_m\n",
    );
    let scheme = match cfg.opts.scheme {
        Scheme::Implicit => "implicit",
        Scheme::Rk4 => "rk4",
    };
    for ((model, runs), est) in all.iter().zip(est) {
        for (r, e) in runs.iter().zip(est) {
            let rate = run_rate(r, cfg.omega);
            let a = r.amplitude_m;
            let c_eq = r.dissipated_last_cycle_j / (PI * cfg.omega * a * a);
            let dir = if sub_dirs {
                format!("{}/", model.name())
            } else {
                String::new()
            };
            let errs = e.error.map_or_else(
                || ",,,,,".to_string(),
                |x| {
                    format!(
                        "{},{},{},{},{},{}",
                        x.peak_force_pos_n,
                        x.peak_force_neg_n,
                        x.storage_stiffness_n_per_m,
                        x.loss_stiffness_n_per_m,
                        x.dissipated_last_cycle_j,
                        x.equivalent_damping_n_s_per_m
                    )
                },
            );
            let rel = if e.relative_error.is_nan() {
                String::new()
            } else {
                e.relative_error.to_string()
            };
            s.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{},{},{}{},{},{},{},{},{},{}\n",
                model.name(),
                r.peak_velocity_m_s,
                // to 1e-9 in/s, so 6 in/s reads 6 and not 5.999999999999999
                (r.peak_velocity_m_s / IN_TO_M * 1e9).round() / 1e9,
                a,
                cfg.omega,
                rate,
                r.peak_force_pos_n,
                r.peak_force_neg_n,
                r.storage_stiffness_n_per_m,
                r.loss_stiffness_n_per_m,
                r.dissipated_last_cycle_j,
                c_eq,
                dir,
                history_name(r.peak_velocity_m_s),
                r.steps_per_cycle,
                cfg.opts.substeps * r.samples_per_step,
                scheme,
                e.status.name(),
                rel,
                errs
            ));
        }
    }
    s
}

/// Peak force vs peak velocity (paper Fig. 13), every model, with the paper's relief cap.
fn fig13_plot(
    all: &[(DamperModel, Vec<HarmonicRun>)],
    cfg: &Config,
    factor: f64,
    deck: &DamperDeck,
) -> Plot {
    let cap = 3200.0 * LB_TO_N;
    let vmax = cfg.peak_velocity.iter().cloned().fold(0.0, f64::max) * factor;
    let mut p = Plot::new(
        &format!(
            "Peak force vs peak velocity (cf. paper Fig. 13), omega = {} rad/s ({})",
            cfg.omega, deck.source
        ),
        &format!("peak velocity [{}]", cfg.velocity_unit),
        "peak force [kN]",
    )
    .x_scale(1.0 / factor)
    .y_scale(1e-3);
    for (model, runs) in all {
        let x: Vec<f64> = runs.iter().map(|r| r.peak_velocity_m_s).collect();
        let pos: Vec<f64> = runs.iter().map(|r| r.peak_force_pos_n).collect();
        let neg: Vec<f64> = runs.iter().map(|r| -r.peak_force_neg_n).collect();
        p = p.line(&format!("{} +peak", model.name()), &x, &pos).dashed(
            &format!("{} |-peak|", model.name()),
            &x,
            &neg,
        );
    }
    from_zero(p.dashed("paper cap 3200 lb (Fig. 16)", &[0.0, vmax], &[cap, cap]))
}

/// The y axis from zero to a little above the largest value (peaks, K'', energy are >= 0 and
/// read against zero, as in the paper's Fig. 13).
fn from_zero(p: Plot) -> Plot {
    let top = p
        .series
        .iter()
        .flat_map(|s| s.y.iter())
        .filter(|y| y.is_finite())
        .fold(0.0f64, |a, &y| a.max(y));
    if top > 0.0 {
        p.y_range(0.0, 1.08 * top)
    } else {
        p
    }
}

fn fmt_num(v: f64, d: usize) -> String {
    format!("{v:.d$}")
}

#[allow(clippy::too_many_arguments)]
fn sweep_html(
    all: &[(DamperModel, Vec<HarmonicRun>)],
    est: &[Vec<RunEstimate>],
    cfg: &Config,
    factor: f64,
    deck: &DamperDeck,
    per_step: usize,
    opts: IntegratorOptions,
    time_histories: &[String],
) -> anyhow::Result<String> {
    let unit = &cfg.velocity_unit;
    let mut r = HtmlReport::new("rotorsim bench: harmonic sweep");
    r.banner(
        Banner::Info,
        &format!(
            "Virtual bench: every curve is computed by rotorsim's damper models from the deck {} (no measurement is shown). The dashed 3200 lb line is the paper's relief cap.",
            deck.source
        ),
    );
    let bad = est
        .iter()
        .flatten()
        .filter(|e| e.status == Convergence::NotConverged)
        .count();
    if bad > 0 {
        r.banner(
            Banner::Bad,
            &format!(
                "{bad} run(s) did NOT converge: their estimated discretisation error exceeds {} % after refining to {}x the first steps per cycle (bench_summary.csv: convergence = not_converged, relative_error).",
                100.0 * REFINE_TOLERANCE,
                1usize << REFINE_MAX_DOUBLINGS
            ),
        );
    }
    let steps = if cfg.refine {
        format!(
            "from {} steps per cycle, doubled until every output's estimated discretisation error is within {} % of its scale (at most {}x; the steps per cycle of each run in the table)",
            cfg.steps_per_cycle,
            100.0 * REFINE_TOLERANCE,
            1usize << REFINE_MAX_DOUBLINGS
        )
    } else {
        format!(
            "{} steps per cycle as asked (error estimated from one run at twice the steps)",
            cfg.steps_per_cycle
        )
    };
    r.paragraph(&format!(
        "Stroke d(t) = A sin(omega t), A = v/omega, omega = {} rad/s; {} cycles per amplitude from a fresh damper, {steps}, {} sample(s) per step, {:?} with {} sub-step(s) per sample. Peaks, loops, K', K'' and the energy are over the last cycle.",
        cfg.omega, cfg.cycles, per_step, opts.scheme, opts.substeps
    ));
    let header = [
        "model",
        &format!("v [{unit}]"),
        "A [mm]",
        "F+ [kN]",
        "F- [kN]",
        "K' [N/m]",
        "K'' [N/m]",
        "energy/cycle [J]",
        "history",
        "steps/cycle",
        "est. error",
        "convergence",
    ];
    let mut rows = Vec::new();
    for ((model, runs), est) in all.iter().zip(est) {
        let dir = if all.len() > 1 {
            format!("{}/", model.name())
        } else {
            String::new()
        };
        for (x, e) in runs.iter().zip(est) {
            rows.push(vec![
                model.name().to_string(),
                fmt_num(x.peak_velocity_m_s / factor, 3),
                fmt_num(x.amplitude_m * 1e3, 3),
                fmt_num(x.peak_force_pos_n * 1e-3, 3),
                fmt_num(x.peak_force_neg_n * 1e-3, 3),
                format!("{:.4e}", x.storage_stiffness_n_per_m),
                format!("{:.4e}", x.loss_stiffness_n_per_m),
                fmt_num(x.dissipated_last_cycle_j, 2),
                format!("{dir}{}", history_name(x.peak_velocity_m_s)),
                x.steps_per_cycle.to_string(),
                if e.relative_error.is_nan() {
                    "-".into()
                } else {
                    format!("{:.3} %", 100.0 * e.relative_error)
                },
                e.status.name().to_string(),
            ]);
        }
    }
    let hdr: Vec<&str> = header.iter().map(|s| s.as_ref()).collect();
    r.heading(2, "Summary (bench_summary.csv)");
    r.table(&hdr, &rows);

    r.heading(2, "Peak force vs peak velocity (paper Fig. 13)");
    r.svg(
        "Peak force over the last cycle against peak stroke velocity; solid: largest force, dashed: magnitude of the most negative force. Paper's Fig. 13 is this plot for the physical damper.",
        &fig13_plot(all, cfg, factor, deck).to_svg(1000, 460)?,
    );

    stiffness_figures(&mut r, all, cfg, deck)?;
    loop_figures(&mut r, all, cfg, factor)?;
    r.heading(2, "Time history (paper Fig. 14)");
    for (svg, (model, _)) in time_histories.iter().zip(all) {
        r.svg(
            &format!(
                "{} model, amplitude closest to 2 in/s, last two cycles (time_history.svg).",
                model.name()
            ),
            svg,
        );
    }
    r.paragraph("Files: bench_summary.csv (this table, SI), peaks.csv, history_v<v>m_s.csv (every sample; v = peak velocity in m/s), peak_force_vs_velocity.svg, time_history.svg; columns and units in docs/formats.md.");
    Ok(r.finish())
}

/// Dynamic stiffness and energy per cycle against amplitude.
fn stiffness_figures(
    r: &mut HtmlReport,
    all: &[(DamperModel, Vec<HarmonicRun>)],
    cfg: &Config,
    deck: &DamperDeck,
) -> anyhow::Result<()> {
    let lin_c = deck.linear_c_n_s_per_m;
    let mut ks = Plot::new(
        "Storage stiffness K' vs stroke amplitude",
        "stroke amplitude [mm]",
        "K' [MN/m]",
    )
    .x_scale(1e3)
    .y_scale(1e-6);
    let mut kl = Plot::new(
        "Loss stiffness K'' vs stroke amplitude",
        "stroke amplitude [mm]",
        "K'' [MN/m]",
    )
    .x_scale(1e3)
    .y_scale(1e-6);
    let mut en = Plot::new(
        "Energy dissipated per cycle vs stroke amplitude",
        "stroke amplitude [mm]",
        "energy per cycle [J]",
    )
    .x_scale(1e3);
    for (model, runs) in all {
        let a: Vec<f64> = runs.iter().map(|x| x.amplitude_m).collect();
        let k1: Vec<f64> = runs.iter().map(|x| x.storage_stiffness_n_per_m).collect();
        let k2: Vec<f64> = runs.iter().map(|x| x.loss_stiffness_n_per_m).collect();
        let e: Vec<f64> = runs.iter().map(|x| x.dissipated_last_cycle_j).collect();
        ks = ks.line(model.name(), &a, &k1).points("", &a, &k1);
        kl = kl.line(model.name(), &a, &k2).points("", &a, &k2);
        en = en.line(model.name(), &a, &e).points("", &a, &e);
        if let (DamperModel::Linear, Some(c)) = (model, lin_c) {
            let w = cfg.omega;
            let ca: Vec<f64> = a.iter().map(|_| c * w).collect();
            let ea: Vec<f64> = a.iter().map(|x| PI * c * w * x * x).collect();
            kl = kl.dashed("linear analytic", &a, &ca);
            en = en.dashed("linear analytic", &a, &ea);
        }
    }
    r.heading(2, "Dynamic stiffness and energy per cycle vs amplitude");
    r.paragraph("K' and K'' are the first harmonic of the reaction -F over the last cycle, in phase with the stroke and with the stroke rate, per metre of amplitude: -F ~ K' d + (K''/omega) d'. The energy per cycle is the work of the damper force over the last cycle (Eq. 11), all harmonics included; for the first harmonic alone it is pi A^2 K''.");
    let has_lin = all.iter().any(|(m, _)| *m == DamperModel::Linear) && lin_c.is_some();
    let dashed_note = |what: &str| {
        if has_lin {
            format!(" (dashed: the linear model's analytic {what})")
        } else {
            String::new()
        }
    };
    r.svg(
        &format!("K' (storage, in phase with the stroke) and K'' (loss, in phase with the stroke rate); a pure dashpot c has K' = 0 and K'' = c omega{}.", dashed_note("c omega")),
        &grid_svg(&[ks, from_zero(kl)], 2, 1100, 380)?,
    );
    r.svg(
        &format!(
            "Energy dissipated per cycle; a dashpot c dissipates pi c omega A^2{}.",
            dashed_note("value")
        ),
        &from_zero(en).to_svg(1000, 420)?,
    );

    Ok(())
}

/// Hysteresis loops per amplitude, every model in its colour.
fn loop_figures(
    r: &mut HtmlReport,
    all: &[(DamperModel, Vec<HarmonicRun>)],
    cfg: &Config,
    factor: f64,
) -> anyhow::Result<()> {
    let unit = &cfg.velocity_unit;
    r.heading(2, "Hysteresis loops per amplitude (last cycle)");
    let n_amp = all.first().map_or(0, |(_, runs)| runs.len());
    let mut loops = Vec::new();
    for k in 0..n_amp {
        let v0 = all[0].1[k].peak_velocity_m_s;
        let a0 = all[0].1[k].amplitude_m;
        let mut fs = Plot::new(
            &format!(
                "v = {:.3} {unit}, A = {:.2} mm: force vs stroke",
                v0 / factor,
                a0 * 1e3
            ),
            "stroke [mm]",
            "force [kN]",
        )
        .x_scale(1e3)
        .y_scale(1e-3);
        let mut fv = Plot::new(
            &format!("v = {:.3} {unit}: force vs velocity", v0 / factor),
            &format!("stroke velocity [{unit}]"),
            "force [kN]",
        )
        .x_scale(1.0 / factor)
        .y_scale(1e-3);
        for (model, runs) in all {
            let x = &runs[k];
            let h = &x.history;
            let from = last_cycle_start(x);
            fs = fs.line(model.name(), &h.stroke_m[from..], &h.force_n[from..]);
            fv = fv.line(model.name(), &h.velocity_m_s[from..], &h.force_n[from..]);
        }
        loops.push(fs);
        loops.push(fv);
    }
    r.svg(
        "Left: force against stroke; right: force against stroke velocity; last cycle of each amplitude. Force F as in docs/formats.md: positive when the damper pushes its ends apart, so a damper's F falls with the stroke velocity (F ~ -c d').",
        &grid_svg(&loops, 2, 1100, 330)?,
    );

    Ok(())
}

/// Where a test's metrics start: the first instant plus `--skip-cycles` stroke periods.
pub struct Window {
    pub period_s: Option<f64>,
    pub from_s: f64,
}

pub fn window(cfg: &Config, test: &BenchTest, path: &std::path::Path) -> anyhow::Result<Window> {
    let period = bench::stroke_period(&test.time_s, &test.stroke_m);
    let t0 = test.time_s[0];
    let t1 = test.time_s[test.time_s.len() - 1];
    if cfg.skip_cycles == 0 {
        return Ok(Window {
            period_s: period,
            from_s: t0,
        });
    }
    let Some(p) = period else {
        bail!(
            "--skip-cycles {}: {} has no cycle to count (its stroke crosses its mid-range upward fewer than twice; a cycle is the stroke's period)",
            cfg.skip_cycles,
            path.display()
        );
    };
    let from = t0 + cfg.skip_cycles as f64 * p;
    if from > t1 {
        bail!(
            "--skip-cycles {} leaves no sample of {}: it holds {:.2} cycles of the stroke's period {:.6} s",
            cfg.skip_cycles,
            path.display(),
            (t1 - t0) / p,
            p
        );
    }
    Ok(Window {
        period_s: Some(p),
        from_s: from,
    })
}

/// Every n-th point so a plot holds at most about `max` points.
fn thin(x: &[f64], max: usize) -> Vec<f64> {
    let s = x.len().div_ceil(max.max(1)).max(1);
    x.iter().step_by(s).copied().collect()
}

fn is_synthetic(path: &std::path::Path) -> bool {
    path.file_name().is_some_and(|n| {
        n.to_string_lossy()
            .to_ascii_lowercase()
            .contains("synthetic")
    })
}

/// The measured tests of `cfg` read, each with its metric window, and checked before any
/// output is made: sampled fast enough for a model that steps once per sample, and (for the
/// physical damper) within the deck's stroke.
fn read_tests(
    cfg: &Config,
    deck: &DamperDeck,
    devices: &[(DamperModel, Box<dyn Device>)],
) -> anyhow::Result<(Vec<BenchTest>, Vec<Window>)> {
    let tests = cfg
        .measured
        .iter()
        .map(|p| bench::read_bench_csv(p))
        .collect::<Result<Vec<_>, _>>()?;
    let windows = tests
        .iter()
        .zip(&cfg.measured)
        .map(|(t, p)| window(cfg, t, p))
        .collect::<anyhow::Result<Vec<_>>>()?;
    // the model steps once per sample: a test sampled slower than any damper bench is a unit
    // error (milliseconds in `time_s`) far more often than a test
    for (t, p) in tests.iter().zip(&cfg.measured) {
        if median_interval_s(t) >= MAX_SAMPLE_INTERVAL_S {
            anyhow::bail!(
                "bench file {}: column time_s: samples slower than {} Hz, where the model steps once per sample{}",
                p.display(),
                1.0 / MAX_SAMPLE_INTERVAL_S,
                sampling_hint(t)
            );
        }
    }
    if devices.iter().any(|(m, _)| *m == DamperModel::Physical) {
        for (t, p) in tests.iter().zip(&cfg.measured) {
            let d = t.stroke_m.iter().fold(0.0f64, |a, d| a.max(d.abs()));
            deck.check_stroke(d, &format!("bench file {}", p.display()))
                .map_err(anyhow::Error::msg)?;
        }
    }
    Ok((tests, windows))
}

/// Replays every measured test (`cfg.measured`) through every device and writes
/// replay_*.csv, loop_*.svg, replay_summary.csv and bench.html into `cfg.out`; `note` gets one
/// line per test and model (its error metrics).
pub fn replay(
    cfg: &Config,
    deck: &DamperDeck,
    devices: &[(DamperModel, Box<dyn Device>)],
    note: &mut dyn FnMut(&str),
) -> anyhow::Result<()> {
    // Read every test and find its cycles before creating any output.
    let (tests, windows) = read_tests(cfg, deck, devices)?;
    let inputs: Vec<PathBuf> = std::iter::once(cfg.deck.clone())
        .chain(cfg.measured.iter().cloned())
        .collect();
    let out = OutDir::create(&cfg.out, &inputs)?;
    let mut summary = String::from(
        "test,model,samples,rms_error_N,samples_used,skip_cycles,cycle_period_s,from_time_s,\
rms_error_rel,max_abs_error_N,rms_error_all_N\n",
    );
    let mut html = HtmlReport::new("rotorsim bench: replay of bench tests");
    replay_intro(&mut html, cfg, deck);
    let mut rows = Vec::new();
    let mut figures = Vec::new();
    for ((test, path), win) in tests.iter().zip(&cfg.measured).zip(&windows) {
        let syn = if is_synthetic(path) { "SYNTHETIC " } else { "" };
        let mut tp = Plot::new(
            &format!("{}: force over time", test.name),
            "time [s]",
            "force [kN]",
        )
        .y_scale(1e-3);
        let mut lp = Plot::new(
            &format!("{}: force vs stroke (metric window)", test.name),
            "stroke [mm]",
            "force [kN]",
        )
        .x_scale(1e3)
        .y_scale(1e-3);
        let first = test.time_s.partition_point(|&t| t < win.from_s);
        for (model, dev) in devices {
            let r = replay_model(&out, deck, test, path, *model, dev.as_ref(), syn)?;
            let h = &r.history;
            tp = tp.line(
                model.name(),
                &thin(&h.time_s, 3000),
                &thin(&h.force_n, 3000),
            );
            lp = lp.line(
                model.name(),
                &thin(&h.stroke_m[first..], 3000),
                &thin(&h.force_n[first..], 3000),
            );
            let met: Option<ReplayMetrics> =
                bench::replay_metrics(test, &r.force_model_n, win.from_s);
            let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
            summary.push_str(&format!(
                "{},{},{},{},{},{},{},{},{},{},{}\n",
                test.name,
                model.name(),
                test.time_s.len(),
                opt(met.as_ref().map(|m| m.rms_error_n)),
                met.as_ref()
                    .map_or(String::new(), |m| m.samples_used.to_string()),
                cfg.skip_cycles,
                opt(win.period_s),
                win.from_s,
                opt(met.as_ref().map(|m| m.rms_error_rel)),
                opt(met.as_ref().map(|m| m.max_abs_error_n)),
                opt(r.rms_error_n),
            ));
            match &met {
                Some(m) => {
                    note(&format!(
                        "{} ({} model): RMS error {:.1} N over {} of {} samples (from t = {:.4} s, {} cycle(s) skipped)",
                        test.name,
                        model.name(),
                        m.rms_error_n,
                        m.samples_used,
                        test.time_s.len(),
                        m.from_s,
                        cfg.skip_cycles
                    ));
                    rows.push(vec![
                        format!("{syn}{}", test.name),
                        model.name().to_string(),
                        format!("{} of {}", m.samples_used, test.time_s.len()),
                        cfg.skip_cycles.to_string(),
                        win.period_s.map_or("-".into(), |p| format!("{p:.5}")),
                        format!("{:.1}", m.rms_error_n),
                        format!("{:.3}", m.rms_error_rel),
                        format!("{:.1}", m.max_abs_error_n),
                        r.rms_error_n.map_or("-".into(), |v| format!("{v:.1}")),
                    ]);
                }
                None => note(&format!(
                    "{} ({} model): no measured force, model force written",
                    test.name,
                    model.name()
                )),
            }
        }
        // the measurement last, drawn over the models
        if let Some(m) = &test.force_n {
            tp = tp.points(
                &format!("{syn}measured"),
                &thin(&test.time_s, 3000),
                &thin(m, 3000),
            );
            lp = lp.points(
                &format!("{syn}measured"),
                &thin(&test.stroke_m[first..], 3000),
                &thin(&m[first..], 3000),
            );
        }
        if cfg.skip_cycles > 0 {
            let (lo, hi) = test
                .force_n
                .iter()
                .flatten()
                .fold((0.0f64, 0.0f64), |(a, b), &f| (a.min(f), b.max(f)));
            tp = tp.dashed(
                &format!("end of {} skipped cycle(s)", cfg.skip_cycles),
                &[win.from_s, win.from_s],
                &[lo, hi],
            );
        }
        figures.push((test.name.clone(), tp, lp));
    }
    replay_figures(&mut html, &rows, figures)?;
    out.write("replay_summary.csv", summary.as_bytes())?;
    out.write("bench.html", html.finish().as_bytes())?;
    out.finish()?;
    Ok(())
}

/// The replay report's banners: synthetic data named, what is driven, what the metrics leave
/// out.
fn replay_intro(html: &mut HtmlReport, cfg: &Config, deck: &DamperDeck) {
    let synthetic: Vec<&PathBuf> = cfg.measured.iter().filter(|p| is_synthetic(p)).collect();
    if !synthetic.is_empty() {
        html.banner(
            Banner::Synthetic,
            &format!(
                "SYNTHETIC bench data: {} (named synthetic), not a measurement of a real damper.",
                synthetic
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        );
    }
    html.banner(
        Banner::Info,
        &format!(
            "Each model (deck {}) is driven by the measured stroke, one step per sample interval, from rest; its force is compared with the measured force.",
            deck.source
        ),
    );
    html.paragraph(&format!(
        "--skip-cycles {}: the error metrics leave out the samples before the first instant plus {} cycle(s); a cycle is the stroke's period, the median interval between upward crossings of the stroke's mid-range.",
        cfg.skip_cycles, cfg.skip_cycles
    ));
}

/// One model driven through one test: its time history and loop written, its result returned.
fn replay_model(
    out: &OutDir,
    deck: &DamperDeck,
    test: &bench::BenchTest,
    path: &std::path::Path,
    model: DamperModel,
    dev: &dyn Device,
    syn: &str,
) -> anyhow::Result<bench::Replay> {
    let r = bench::replay(dev, test).map_err(|e| {
        let _ = out.mark_incomplete(&format!("replay of {} failed: {e}", test.name));
        let mut msg = format!(
            "replay of {} ({}) with the {} model: {e}{}",
            test.name,
            path.display(),
            model.name(),
            sampling_hint(test)
        );
        if model == DamperModel::Physical {
            msg = deck.with_review(msg);
        }
        anyhow::Error::msg(msg)
    })?;
    let h = &r.history;
    let stem = format!("{}_{}", test.name, model.name());
    let mut header = vec!["time_s", "stroke_m", "velocity_m_s", "force_model_N"];
    let mut cols: Vec<&[f64]> = vec![&h.time_s, &h.stroke_m, &h.velocity_m_s, &h.force_n];
    if let Some(m) = &test.force_n {
        header.push("force_measured_N");
        cols.push(m);
    }
    push_device_channels(h, &mut header, &mut cols);
    out.write(
        &format!("replay_{stem}.csv"),
        csv_from_columns(&header, &cols).as_bytes(),
    )?;
    let mut p = Plot::new(
        &format!(
            "{}: force vs stroke, {} model over measurement",
            test.name,
            model.name()
        ),
        "stroke [mm]",
        "force [kN]",
    )
    .x_scale(1e3)
    .y_scale(1e-3);
    if let Some(m) = &test.force_n {
        p = p.points(&format!("{syn}measured"), &test.stroke_m, m);
    }
    p = p.line(&format!("{} model", model.name()), &h.stroke_m, &h.force_n);
    out.write(&format!("loop_{stem}.svg"), p.to_svg(900, 480)?.as_bytes())?;
    Ok(r)
}

/// The replay report's metrics table and each test's figures.
fn replay_figures(
    html: &mut HtmlReport,
    rows: &[Vec<String>],
    figures: Vec<(String, Plot, Plot)>,
) -> anyhow::Result<()> {
    if !rows.is_empty() {
        html.heading(2, "Error metrics (replay_summary.csv)");
        html.table(
            &[
                "test",
                "model",
                "samples used",
                "cycles skipped",
                "period [s]",
                "RMS error [N]",
                "RMS error / RMS measured",
                "max |error| [N]",
                "RMS error, all samples [N]",
            ],
            rows,
        );
    }
    for (name, tp, lp) in figures {
        html.heading(2, &format!("Test {name}"));
        html.svg(
            "Measured force (points) and each model's force over time; the dashed line ends the skipped cycles.",
            &tp.to_svg(1000, 420)?,
        );
        html.svg(
            "Force against stroke over the samples the metrics use.",
            &lp.to_svg(1000, 460)?,
        );
    }
    Ok(())
}

/// Longest median sample interval of a measured test [s] (10 Hz; benches sample at 1 kHz or
/// more).
pub const MAX_SAMPLE_INTERVAL_S: f64 = 0.1;

/// The median sample interval of a test [s] (0 for fewer than two samples).
fn median_interval_s(test: &bench::BenchTest) -> f64 {
    let mut dt: Vec<f64> = test.time_s.windows(2).map(|w| w[1] - w[0]).collect();
    if dt.is_empty() {
        return 0.0;
    }
    dt.sort_by(f64::total_cmp);
    dt[dt.len() / 2]
}

/// A hint when a test samples slower than a damper bench does (the model steps once per
/// sample): the median interval, and the likely cause, a time column in milliseconds.
fn sampling_hint(test: &bench::BenchTest) -> String {
    let med = median_interval_s(test);
    if med >= 0.01 {
        format!(
            "; the file samples every {med} s (median), where damper benches sample at 1 kHz or \
             more and the model steps once per sample: if its time column holds milliseconds, \
             name it `time_ms` (docs/formats.md)"
        )
    } else {
        String::new()
    }
}
