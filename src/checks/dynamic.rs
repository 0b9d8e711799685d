//! `rotorsim dynamic` as a library call: generalized-alpha time integration of a model deck into
//! its result folder (sensors.csv, summary.json; with [[hydraulic]] devices their plots).
use crate::io::{csv_string, OutDir};
use crate::solver::budget;
use crate::solver::statics::check_constraints;
use crate::solver::{static_solve, DynamicSolver, State, StaticOptions};
use crate::structure::deck::load_deck_within;
use anyhow::Context;
use std::path::PathBuf;

/// The options of `rotorsim dynamic` besides its deck and result folder (clap and serde).
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, Default, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct DynamicSettings {
    /// Spectral radius at infinite frequency of the generalized-alpha integrator, in [0, 1]
    /// (default: the deck's `dynamic.rho_inf`).
    #[arg(long, allow_negative_numbers = true)]
    pub rho_inf: Option<f64>,
    /// Newton tolerance, relative to the residual of the step's predictor, in (0, 1)
    /// (default 1e-9).
    #[arg(long)]
    pub newton_rtol: Option<f64>,
}

impl DynamicSettings {
    /// The time integration of model deck `deck` into `out`.
    pub fn job(&self, deck: impl Into<PathBuf>, out: impl Into<PathBuf>) -> DynamicJob {
        DynamicJob {
            deck: deck.into(),
            out: out.into(),
            rho_inf: self.rho_inf,
            newton_rtol: self.newton_rtol,
        }
    }
}

/// One dynamic analysis: the model deck, the result folder and the integrator's options (None:
/// the deck's, or the solver's default).
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicJob {
    pub deck: PathBuf,
    pub out: PathBuf,
    pub rho_inf: Option<f64>,
    pub newton_rtol: Option<f64>,
}

/// What a dynamic analysis did.
#[derive(Clone, Debug)]
pub struct DynamicOutcome {
    pub steps: usize,
    pub time_step_s: f64,
    pub newton_iterations: usize,
    pub wall_s: f64,
}

impl DynamicJob {
    /// The options' own ranges, before the deck is read.
    pub fn check_options(&self) -> anyhow::Result<()> {
        if let Some(r) = self.rho_inf {
            if !(0.0..=1.0).contains(&r) {
                anyhow::bail!(
                    "--rho-inf: expected a number in [0, 1] (the integrator's spectral radius at \
                     infinite frequency), got {r}"
                );
            }
        }
        if let Some(r) = self.newton_rtol {
            if !(r > 0.0 && r < 1.0) {
                anyhow::bail!(
                    "--newton-rtol: expected a number in (0, 1) (relative to the predictor's \
                     residual), got {r}"
                );
            }
        }
        Ok(())
    }

    /// Integrates the deck and writes the result folder; `say` gets a progress line every 5 %
    /// of the steps. A step that fails ends the analysis with an error, its output kept and
    /// marked incomplete.
    pub fn execute(&self, say: &dyn Fn(&str)) -> anyhow::Result<DynamicOutcome> {
        self.check_options()?;
        // Refused before the model is built when beyond sense: 3 Newton iterations a step is
        // typical (docs/performance.md); kept samples: the time and a channel a node at least.
        let (deck, mut model) = load_deck_within(&self.deck, |d| {
            let dy = &d.dynamic;
            let (Some(h), Some(t_end)) = (dy.time_step_s, dy.end_time_s) else {
                return Ok(());
            };
            let (ndof, nnz) = d.size_estimate();
            let steps = t_end / h;
            let rows = steps / dy.output_every.max(1) as f64;
            budget::time_integration_of(ndof, nnz, steps, 3.0)
                .plus(budget::samples(rows, 1.0 + ndof / 6.0))
                .check(
                    &format!("dynamic analysis of {steps:.3e} steps of {ndof:.0} unknowns"),
                    "check dynamic.end_time_s and dynamic.time_step_s (seconds), raise dynamic.output_every or use fewer elements",
                )
                .map_err(|e| e.to_string())
        })?;
        let file = self.deck.display().to_string();
        let dy = &deck.dynamic;
        let h = dy.time_step_s.ok_or_else(|| {
            anyhow::anyhow!("deck {file}, dynamic.time_step_s: required for a dynamic analysis")
        })?;
        let t_end = dy.end_time_s.ok_or_else(|| {
            anyhow::anyhow!("deck {file}, dynamic.end_time_s: required for a dynamic analysis")
        })?;
        if !(h > 0.0 && t_end > 0.0) {
            anyhow::bail!("deck {file}, dynamic: time_step_s and end_time_s must be positive");
        }
        let rho_inf = self.rho_inf.unwrap_or(dy.rho_inf);
        if !(0.0..=1.0).contains(&dy.rho_inf) {
            anyhow::bail!(
                "deck {file}, dynamic.rho_inf: must be in [0, 1], got {}",
                dy.rho_inf
            );
        }
        let mut st = State::from_model(&model);
        check_constraints(&mut model, &st).map_err(|e| anyhow::anyhow!("deck {file}: {e}"))?;
        let out = OutDir::create(&self.out, &deck.input_files(&self.deck))?;
        if dy.start_from_static {
            let opts = StaticOptions {
                load_steps: deck.statics.load_steps,
                ..Default::default()
            };
            if let Err(e) = static_solve(&mut model, &mut st, &opts, |_, _, _, _| {}) {
                out.mark_incomplete(&format!("initial static solution failed: {e}"))?;
                return Err(e).context("initial static solution");
            }
        }
        if let Some(om) = dy.initial_omega_rad_s {
            st.set_rigid_rotation([0.0; 3], om);
        }
        let mut solver = DynamicSolver::new(model, st, h, rho_inf)?;
        solver.newton.max_iterations = dy.max_iterations;
        if let Some(r) = self.newton_rtol {
            solver.newton.rtol = r;
        }
        solver.init_accelerations()?;
        let header = solver.sensor_header();
        let hs: Vec<&str> = header.iter().map(|s| s.as_str()).collect();
        let mut rows = vec![solver.sensor_values()];
        let nsteps = (t_end / h).round() as usize;
        let started = std::time::Instant::now();
        let mut failure = None;
        for k in 1..=nsteps {
            match solver.step() {
                Ok(_) => {}
                Err(e) => {
                    failure = Some(e);
                    break;
                }
            }
            if k % dy.output_every.max(1) == 0 {
                rows.push(solver.sensor_values());
            }
            if k % (nsteps / 20).max(1) == 0 {
                say(&format!(
                    "t = {:.6} s ({:3.0} %), {} Newton iterations so far",
                    solver.state.t,
                    100.0 * k as f64 / nsteps as f64,
                    solver.total_iterations
                ));
            }
        }
        out.write("sensors.csv", csv_string(&hs, &rows).as_bytes())?;
        let elapsed = started.elapsed().as_secs_f64();
        let hydraulics: Vec<serde_json::Value> = deck
            .hydraulic_probes
            .iter()
            .map(|(name, p)| {
                serde_json::json!({
                    "name": name,
                    "trial_steps": p.trials(),
                    "hydraulics_wall_time_s": p.hydraulics_seconds(),
                })
            })
            .collect();
        if !deck.hydraulic_probes.is_empty() {
            write_hydraulic_plots(&out, &deck.hydraulic_probes, &hs, &rows)?;
        }
        let summary = serde_json::json!({
            "deck": file,
            "time_step_s": h,
            "steps": solver.steps,
            "newton_iterations": solver.total_iterations,
            "wall_time_s": elapsed,
            "rho_inf": rho_inf,
            "newton_rtol": solver.newton.rtol,
            "complete": failure.is_none(),
            "error": failure.as_ref().map(|e| e.to_string()),
            "hydraulics": hydraulics,
        });
        out.write(
            "summary.json",
            serde_json::to_string_pretty(&summary)?.as_bytes(),
        )?;
        if let Some(e) = failure {
            out.mark_incomplete(&format!("dynamic analysis stopped: {e}"))?;
            anyhow::bail!(
                "dynamic analysis stopped (output in {} is incomplete): {e}",
                self.out.display()
            );
        }
        out.finish()?;
        Ok(DynamicOutcome {
            steps: solver.steps,
            time_step_s: h,
            newton_iterations: solver.total_iterations,
            wall_s: elapsed,
        })
    }
}

/// Column of `header` named `name`, if any.
fn column(header: &[&str], rows: &[Vec<f64>], name: &str) -> Option<Vec<f64>> {
    let i = header.iter().position(|h| *h == name)?;
    Some(rows.iter().map(|r| r[i]).collect())
}

/// plots.svg (all panels) and, per device, the paper's Figs. 9-12: force; stroke and stroke
/// rate; chamber pressures; flows (every `*_m3_s` channel that is not identically zero).
fn write_hydraulic_plots(
    out: &OutDir,
    probes: &[(String, std::sync::Arc<crate::structure::HydraulicProbe>)],
    header: &[&str],
    rows: &[Vec<f64>],
) -> anyhow::Result<()> {
    use crate::report::plot::{stacked_svg, Plot};
    let t = column(header, rows, "t_s").unwrap_or_else(|| rows.iter().map(|r| r[0]).collect());
    let mut all = vec![];
    for (name, probe) in probes {
        let col = |c: &str| column(header, rows, &format!("{name}.{c}"));
        let mut figs: Vec<(&str, Vec<Plot>)> = vec![];
        if let Some(f) = col("force_N") {
            figs.push((
                "fig9_force",
                vec![Plot::new(
                    &format!("{name}: device force (Eq. 8)"),
                    "time [s]",
                    "force [N]",
                )
                .line("force_N", &t, &f)],
            ));
        }
        if let (Some(d), Some(v)) = (col("stroke_m"), col("stroke_rate_m_s")) {
            figs.push((
                "fig10_stroke_rate",
                vec![
                    Plot::new(
                        &format!("{name}: piston displacement"),
                        "time [s]",
                        "stroke [m]",
                    )
                    .line("stroke_m", &t, &d),
                    Plot::new(
                        &format!("{name}: piston velocity"),
                        "time [s]",
                        "stroke rate [m/s]",
                    )
                    .line("stroke_rate_m_s", &t, &v),
                ],
            ));
        }
        if let (Some(p0), Some(p1)) = (col("p0_Pa"), col("p1_Pa")) {
            figs.push((
                "fig11_pressures",
                vec![Plot::new(
                    &format!("{name}: chamber pressures"),
                    "time [s]",
                    "pressure [Pa]",
                )
                .line("p0_Pa", &t, &p0)
                .line("p1_Pa", &t, &p1)],
            ));
        }
        let mut flows = Plot::new(
            &format!("{name}: volumetric flow rates"),
            "time [s]",
            "flow [m^3/s]",
        );
        for c in probe
            .channel_names()
            .iter()
            .filter(|c| c.ends_with("_m3_s"))
        {
            if let Some(q) = col(c).filter(|q| q.iter().any(|v| *v != 0.0)) {
                flows = flows.line(c, &t, &q);
            }
        }
        if !flows.series.is_empty() {
            figs.push(("fig12_flows", vec![flows]));
        }
        for (fig, plots) in figs {
            let svg = stacked_svg(&plots, 900, 320)?;
            out.write(&format!("{name}_{fig}.svg"), svg.as_bytes())?;
            all.extend(plots);
        }
    }
    if !all.is_empty() {
        out.write("plots.svg", stacked_svg(&all, 900, 300)?.as_bytes())?;
    }
    Ok(())
}
