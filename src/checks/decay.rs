//! Free decay of a hinged blade's lag hinge (`rotorsim decay`, examples/tm4760_decay.rs): the
//! linearised rigid lag mode at the shaft speed, the nonlinear free decay marched by the
//! generalized-alpha solver ([`DecaySim`]), and the decay's damped frequency and damping ratio
//! by a damped-sine fit and by logarithmic decrement (docs/validation_tm4760.md).
use crate::io::csv_string;
use crate::io::OutDir;
use crate::rotor::hinged::{
    blade_node_ids, fit_damped_sine, log_decrement, modes_at, track, DecayOptions, DecaySim,
    HingedSpec,
};
use crate::rotor::MAX_SPEED_FRACTION;
use crate::solver::NewtonMethod;
use std::path::{Path, PathBuf};

/// Options of a decay run (the defaults are the validation run's).
#[derive(Clone, Debug)]
pub struct DecayRunOptions {
    /// Shaft speed [rad/s] (None: the deck's).
    pub omega_rad_s: Option<f64>,
    pub time_step_s: f64,
    pub duration_s: f64,
    /// March in the frame turning with the shaft (else inertial, hub driven).
    pub rotating_frame: bool,
    pub newton: NewtonMethod,
    pub newton_rtol: f64,
    /// A step's iterations also end once the largest correction of a node's position (or
    /// rotation) is below this fraction of the model's size (or this angle [rad]), with the
    /// residual below its round-off floor: a correction of nanometres changes nothing the decay
    /// measures, yet at 1e-11 it cost one iteration in four at the 5 ms step.
    pub newton_xtol: f64,
    pub rho_inf: f64,
    /// Static lag moment removed at the start [N m], over `release_time_s`.
    pub release_moment_nm: f64,
    pub release_time_s: f64,
    /// The fit and the log decrement use the history from this time on [s] (the elastic
    /// modes excited by the release have died out).
    pub analyse_from_s: f64,
    /// Compute the linearised lag mode beside the decay (a static solve and a dense eigen
    /// analysis: more than half of a 2000-step run's CPU on the TM-4760 blade).
    pub modal: bool,
}

impl Default for DecayRunOptions {
    fn default() -> Self {
        DecayRunOptions {
            omega_rad_s: None,
            time_step_s: 0.005,
            duration_s: 6.0,
            rotating_frame: true,
            newton: NewtonMethod::Modified,
            newton_rtol: 1e-8,
            newton_xtol: 1e-9,
            rho_inf: 0.9,
            release_moment_nm: 4.5,
            release_time_s: 0.01,
            analyse_from_s: 1.0,
            modal: true,
        }
    }
}

impl DecayRunOptions {
    /// Checks the options, naming the option at fault (`what` maps an option to the name the
    /// user gave it, e.g. a command-line flag).
    pub fn validate(&self, what: impl Fn(&str) -> String) -> anyhow::Result<()> {
        let pos = |v: f64, k: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(anyhow::anyhow!(
                    "{}: expected a positive number, got {v}",
                    what(k)
                ))
            }
        };
        if let Some(om) = self.omega_rad_s {
            pos(om, "omega")?;
        }
        pos(self.time_step_s, "time_step")?;
        if !(0.0..=1.0).contains(&self.rho_inf) {
            anyhow::bail!(
                "{}: expected a number in [0, 1] (the integrator's spectral radius at infinite \
                 frequency), got {}",
                what("rho_inf"),
                self.rho_inf
            );
        }
        if !(self.newton_xtol > 0.0 && self.newton_xtol < 1.0) {
            anyhow::bail!(
                "{}: expected a number in (0, 1) (a correction relative to the model's size), \
                 got {}",
                what("newton_xtol"),
                self.newton_xtol
            );
        }
        if !(self.newton_rtol > 0.0 && self.newton_rtol < 1.0) {
            anyhow::bail!(
                "{}: expected a number in (0, 1) (relative to the predictor's residual), got {}",
                what("newton_rtol"),
                self.newton_rtol
            );
        }
        pos(self.duration_s, "duration")?;
        let need = self.analyse_from_s + 20.0 * self.time_step_s;
        if self.duration_s < need {
            anyhow::bail!(
                "{}: {} s is too short: the decay is analysed from {} s on, so at least {need} s \
                 is needed",
                what("duration"),
                self.duration_s,
                self.analyse_from_s
            );
        }
        Ok(())
    }
}

/// Linearised rigid lag mode of the blade at `omega_rad_s`: (damped frequency [Hz], damping
/// ratio).
pub fn modal_lag(spec: &HingedSpec, file: &Path, omega_rad_s: f64) -> anyhow::Result<(f64, f64)> {
    let (model, ms) = modes_at(spec, file, omega_rad_s, 14)?;
    let (hz, zeta) = track(&ms, &blade_node_ids(spec, &model)?);
    Ok((hz[0], zeta[0]))
}

/// The decay simulation of `opts` at its first step.
pub fn decay_sim(
    spec: &HingedSpec,
    file: &Path,
    opts: &DecayRunOptions,
) -> anyhow::Result<DecaySim> {
    let mut sim = DecaySim::new(
        spec,
        file,
        &DecayOptions {
            omega_rad_s: opts.omega_rad_s.unwrap_or(spec.rotor.omega_rad_s),
            release_moment_nm: opts.release_moment_nm,
            release_time_s: opts.release_time_s,
            time_step_s: opts.time_step_s,
            rho_inf: opts.rho_inf,
            newton: opts.newton,
            newton_rtol: opts.newton_rtol,
            rotating_frame: opts.rotating_frame,
        },
    )?;
    sim.solver.newton.xtol = opts.newton_xtol;
    Ok(sim)
}

/// Number of steps of the run.
pub fn steps(opts: &DecayRunOptions) -> usize {
    (opts.duration_s / opts.time_step_s).round() as usize
}

/// (damped-sine fit, log decrement), each (damped Hz, damping ratio) when found.
pub type DecayFit = (Option<(f64, f64)>, Option<(f64, f64)>);

/// Frequency and damping of the decay `lag_rad` (one sample per step, the first at `h`) from
/// `analyse_from_s` on.
pub fn analyse(lag_rad: &[f64], lag_eq_rad: f64, opts: &DecayRunOptions) -> DecayFit {
    let h = opts.time_step_s;
    let k0 = ((opts.analyse_from_s / h).round() as usize).min(lag_rad.len());
    let w = &lag_rad[k0..];
    let ld = log_decrement(w, lag_eq_rad, h);
    let fit = ld.and_then(|g| fit_damped_sine(w, h, g));
    (fit, ld)
}

/// A finished decay run.
#[derive(Clone, Debug)]
pub struct DecayRun {
    pub options: DecayRunOptions,
    pub omega_rad_s: f64,
    /// Lag angle after each step [rad] (positive aft), the first at one step.
    pub lag_rad: Vec<f64>,
    pub lag_eq_rad: f64,
    /// Linearised rigid lag mode (damped Hz, damping ratio), when asked for.
    pub modal: Option<(f64, f64)>,
    pub fit: Option<(f64, f64)>,
    pub log_decrement: Option<(f64, f64)>,
    pub newton_iterations: usize,
    pub factorizations: usize,
}

/// Runs the decay of `opts` on the hinged-blade deck `file`.
pub fn run_decay(file: &Path, opts: &DecayRunOptions) -> anyhow::Result<DecayRun> {
    let spec = HingedSpec::from_file(file)?;
    let om = opts.omega_rad_s.unwrap_or(spec.rotor.omega_rad_s);
    let nominal = spec.rotor.omega_rad_s;
    if om > MAX_SPEED_FRACTION * nominal {
        anyhow::bail!(
            "--speed-rad-s {} (--rpm {}): {:.3} times the nominal speed of {} \
             (rotor.omega_rad_s = {} rad/s, {} rpm), beyond sense: expected at most \
             {MAX_SPEED_FRACTION} times (rotors run within about 1.2 of their nominal speed)",
            round6(om),
            round6(om * 30.0 / std::f64::consts::PI),
            om / nominal,
            file.display(),
            round6(nominal),
            round6(spec.rpm())
        );
    }
    let mut sim = decay_sim(&spec, file, opts)?;
    let steps_f = opts.duration_s / opts.time_step_s;
    // Newton iterations per step ~4 (docs/performance.md); the history is 3 columns
    crate::solver::budget::time_integration(&sim.solver.model, steps_f, 4.0)
        .plus(crate::solver::budget::samples(steps_f, 3.0))
        .check(
            &format!(
                "{}: the lag decay of {} steps (--duration-s {} / --step-s {})",
                file.display(),
                crate::solver::budget::count(steps_f),
                fmt_num(opts.duration_s),
                fmt_num(opts.time_step_s)
            ),
            "shorten --duration-s or lengthen --step-s (the decay is analysed from 1 s on; a few seconds of a 5 ms step suffice)",
        )?;
    let modal = if opts.modal {
        Some(modal_lag(&spec, file, om)?)
    } else {
        None
    };
    let n = steps(opts);
    let mut lag_rad = Vec::with_capacity(n);
    for _ in 0..n {
        sim.step()?;
        lag_rad.push(sim.lag_angle_rad());
    }
    let (fit, log_decrement) = analyse(&lag_rad, sim.lag_eq_rad, opts);
    Ok(DecayRun {
        options: opts.clone(),
        omega_rad_s: om,
        lag_eq_rad: sim.lag_eq_rad,
        lag_rad,
        modal,
        fit,
        log_decrement,
        newton_iterations: sim.solver.total_iterations,
        factorizations: sim.solver.factorizations,
    })
}

impl DecayRun {
    /// decay.csv: the lag angle history (docs/formats.md).
    pub fn history_csv(&self) -> String {
        let h = self.options.time_step_s;
        let rows = self
            .lag_rad
            .iter()
            .enumerate()
            .map(|(k, &x)| [(k + 1) as f64 * h, x, x.to_degrees()]);
        csv_string(&["time_s", "lag_angle_rad", "lag_angle_deg"], rows)
    }

    /// decay_summary.csv: frequency and damping ratio by method (docs/formats.md); no
    /// `linearised_modal` row when the mode was not asked for.
    pub fn summary_csv(&self) -> String {
        let mut s = String::from("method,frequency_Hz,damping_ratio\n");
        let mut row = |name: &str, v: Option<(f64, f64)>| {
            let (f, z) = v.unwrap_or((f64::NAN, f64::NAN));
            s.push_str(&format!("{name},{f},{z}\n"));
        };
        if let Some(m) = self.modal {
            row("linearised_modal", Some(m));
        }
        row("damped_sine_fit", self.fit);
        row("log_decrement", self.log_decrement);
        s
    }
}

/// `x` rounded to 6 decimals (an rpm converted to rad/s and back prints as given).
fn round6(x: f64) -> f64 {
    (x * 1e6).round() / 1e6
}

/// A number for messages: plain in [1e-3, 1e5), else with an exponent.
fn fmt_num(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e5).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// Every option of `rotorsim decay` but its result folder, as given: the command's flags
/// (clap) and JSON (serde) are this one type; [`DecaySettings::job`] reads it into a
/// [`DecayJob`]. [`DecaySettings::default`] gives the command line's defaults (the required
/// `rotor` unset).
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct DecaySettings {
    /// Hinged-blade rotor deck (docs/rotor_deck.md, "Hinged-blade decks").
    #[arg(long, required = true)]
    pub rotor: Option<PathBuf>,
    /// Shaft speed [rad/s] (default: the deck's `[rotor] omega_rad_s`).
    #[arg(long, conflicts_with = "rpm")]
    pub speed_rad_s: Option<f64>,
    /// Shaft speed in rpm instead of --speed-rad-s.
    #[arg(long)]
    pub rpm: Option<f64>,
    /// Time step [s].
    #[arg(long, default_value_t = 0.005)]
    pub step_s: f64,
    /// Simulated time [s]; the decay is analysed from 1 s on.
    #[arg(long, default_value_t = 6.0)]
    pub duration_s: f64,
    /// Frame of the state: `rotating` (turning with the shaft, hub clamped) or `inertial`
    /// (hub driven).
    #[arg(long, default_value = "rotating", value_parser = FRAMES)]
    pub frame: String,
    /// Newton method: `modified` (stored factorization) or `full`.
    #[arg(long, default_value = "modified", value_parser = NEWTON_METHODS)]
    pub newton: String,
    /// Spectral radius at infinite frequency of the generalized-alpha integrator, in [0, 1]
    /// (1: no numerical damping; lower damps the elastic modes the release excites sooner).
    #[arg(long, default_value_t = 0.9, allow_negative_numbers = true)]
    pub rho_inf: f64,
    /// Newton tolerance, relative to the residual of the zero-acceleration predictor, in (0, 1)
    /// (docs/validation_tm4760.md, "Integrator settings and their cost").
    #[arg(long, default_value_t = 1e-8)]
    pub newton_rtol: f64,
    /// Newton correction tolerance, relative to the model's size, in (0, 1): a step also ends
    /// once its largest correction is below it and the residual at its round-off floor.
    #[arg(long, default_value_t = 1e-9)]
    pub newton_xtol: f64,
    /// Skip the linearised lag mode (its static solve and eigen analysis, more than half of a
    /// 2000-step run): decay_summary.csv then has the decay's estimates only.
    #[arg(long)]
    pub no_modal: bool,
}

/// The values of `--frame` and `--newton`.
const FRAMES: [&str; 2] = ["rotating", "inertial"];
const NEWTON_METHODS: [&str; 2] = ["modified", "full"];

impl Default for DecaySettings {
    fn default() -> Self {
        crate::run::settings::command_line_defaults("decay")
    }
}

impl crate::run::settings::JobSettings for DecaySettings {
    const COMMAND: &'static str = "decay";
}

impl DecaySettings {
    /// The decay these settings ask for into `out` (the deck and the values checked when it
    /// runs).
    pub fn job(&self, out: impl Into<PathBuf>) -> anyhow::Result<DecayJob> {
        let rotor = crate::run::settings::required(&self.rotor, "--rotor", "a hinged-blade deck")?;
        // the command line refuses these; settings read from JSON are checked here
        for (flag, v, all) in [
            ("--frame", &self.frame, FRAMES),
            ("--newton", &self.newton, NEWTON_METHODS),
        ] {
            if !all.contains(&v.as_str()) {
                anyhow::bail!("{flag} {v}: expected {}", all.join(" or "));
            }
        }
        let speed = match (self.speed_rad_s, self.rpm) {
            (Some(_), Some(_)) => {
                anyhow::bail!("--speed-rad-s and --rpm: give one (the shaft speed in rad/s or rpm)")
            }
            (Some(w), None) => Some(("--speed-rad-s", w)),
            (None, Some(r)) => Some(("--rpm", r)),
            (None, None) => None,
        };
        Ok(DecayJob {
            rotor: rotor.clone(),
            options: DecayRunOptions {
                omega_rad_s: self
                    .speed_rad_s
                    .or(self.rpm.map(|r| r * std::f64::consts::PI / 30.0)),
                time_step_s: self.step_s,
                duration_s: self.duration_s,
                rotating_frame: self.frame == "rotating",
                newton: if self.newton == "full" {
                    NewtonMethod::Full
                } else {
                    NewtonMethod::Modified
                },
                rho_inf: self.rho_inf,
                newton_rtol: self.newton_rtol,
                newton_xtol: self.newton_xtol,
                modal: !self.no_modal,
                ..Default::default()
            },
            speed,
            out: out.into(),
        })
    }
}

/// `rotorsim decay` as a library call: checked and run by [`DecayJob::execute`] into its
/// result folder.
#[derive(Clone, Debug)]
pub struct DecayJob {
    /// Hinged-blade rotor deck.
    pub rotor: PathBuf,
    pub options: DecayRunOptions,
    /// The shaft speed as given, by its option (`--speed-rad-s` or `--rpm`), for messages.
    pub speed: Option<(&'static str, f64)>,
    pub out: PathBuf,
}

impl DecayJob {
    /// Checks the deck and the options (before the result folder exists), then runs the decay
    /// and writes decay.csv and decay_summary.csv. A failure after the folder exists leaves it
    /// marked incomplete.
    pub fn execute(&self) -> anyhow::Result<DecayRun> {
        let rotor = &self.rotor;
        let text = std::fs::read_to_string(rotor)
            .map_err(|e| anyhow::anyhow!("--rotor {}: {e}", rotor.display()))?;
        if crate::rotor::RotorKind::of_text(&text) != crate::rotor::RotorKind::Hinged {
            anyhow::bail!(
                "--rotor {}: not a hinged-blade deck (expected [[hinge]] tables and a [blade] with \
                 segments, docs/rotor_deck.md)",
                rotor.display()
            );
        }
        if let Some((flag, r)) = self.speed.filter(|(_, r)| !(r.is_finite() && *r > 0.0)) {
            anyhow::bail!("{flag}: expected a positive number, got {r}");
        }
        let speed_flag = self.speed.map_or("--speed-rad-s", |(f, _)| f);
        self.options.validate(|k| {
            match k {
                "time_step" => "--step-s",
                "duration" => "--duration-s",
                "rho_inf" => "--rho-inf",
                "newton_rtol" => "--newton-rtol",
                "newton_xtol" => "--newton-xtol",
                _ => speed_flag,
            }
            .to_string()
        })?;
        let out = OutDir::create(&self.out, std::slice::from_ref(rotor))?;
        let r = match run_decay(rotor, &self.options) {
            Ok(r) => r,
            Err(e) => {
                out.mark_incomplete(&e.to_string())?;
                return Err(e);
            }
        };
        out.write("decay.csv", r.history_csv().as_bytes())?;
        out.write("decay_summary.csv", r.summary_csv().as_bytes())?;
        out.finish()?;
        Ok(r)
    }
}
