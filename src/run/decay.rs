//! Free decay of a hinged blade's lag hinge (`rotorsim decay`, examples/tm4760_decay.rs): the
//! linearised rigid lag mode at the shaft speed, the nonlinear free decay marched by the
//! generalized-alpha solver ([`DecaySim`]), and the decay's damped frequency and damping ratio
//! by a damped-sine fit and by logarithmic decrement (docs/validation_tm4760.md).
use crate::io::csv_string;
use crate::rotor::hinged::{
    blade_node_ids, fit_damped_sine, log_decrement, modes_at, track, DecayOptions, DecaySim,
    HingedSpec,
};
use crate::rotor::MAX_SPEED_FRACTION;
use crate::solver::NewtonMethod;
use std::path::Path;

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
