//! `rotorsim static` as a library call: the nonlinear static solution of a model deck into its
//! result folder (static.csv, nodes.csv, node_names.csv; tangent_check.txt when asked).
use crate::io::{csv_string, OutDir};
use crate::solver::budget;
use crate::solver::fdcheck::check_model;
use crate::solver::state::{lambda_offsets, sensor_header, sensor_values};
use crate::solver::statics::check_constraints;
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::deck::load_deck_within;
use crate::structure::EvalCtx;
use anyhow::Context;
use std::path::PathBuf;

/// Largest relative error of an element's analytic tangent that the tangent check accepts.
pub const TANGENT_TOL: f64 = 1e-5;

/// The options of `rotorsim static` besides its deck and result folder (clap and serde).
#[derive(
    clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, Default, PartialEq, Eq,
)]
#[serde(default, deny_unknown_fields)]
pub struct StaticSettings {
    /// Check every element's analytic tangent against central finite differences at the
    /// reference and at the solved state; fails if a relative error exceeds 1e-5.
    #[arg(long)]
    pub check_tangent: bool,
}

impl StaticSettings {
    /// The static analysis of model deck `deck` into `out`.
    pub fn job(&self, deck: impl Into<PathBuf>, out: impl Into<PathBuf>) -> StaticJob {
        StaticJob {
            deck: deck.into(),
            out: out.into(),
            check_tangent: self.check_tangent,
        }
    }
}

/// One static analysis: the model deck, the result folder and whether to check the tangents.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StaticJob {
    pub deck: PathBuf,
    pub out: PathBuf,
    pub check_tangent: bool,
}

/// The tangent check's table (both states) and its largest relative error.
#[derive(Clone, Debug)]
pub struct TangentCheck {
    pub report: String,
    pub worst: f64,
}

/// What a static analysis found.
#[derive(Clone, Debug)]
pub struct StaticOutcome {
    /// Newton iterations of each load step.
    pub iterations: Vec<usize>,
    pub residual: f64,
    /// Every sensor with its value at the solution.
    pub sensors: Vec<(String, f64)>,
    /// With `check_tangent`: the check (the folder is marked incomplete when it failed).
    pub tangent: Option<TangentCheck>,
}

impl StaticOutcome {
    /// The tangent check's failure, if it failed.
    pub fn verdict(&self) -> anyhow::Result<()> {
        match &self.tangent {
            Some(t) if t.worst > TANGENT_TOL => anyhow::bail!(
                "tangent check failed: largest relative error {:.2e} > 1e-5",
                t.worst
            ),
            _ => Ok(()),
        }
    }
}

/// Run the tangent check and print a table; returns the largest relative error.
pub fn tangent_report(model: &crate::structure::Model, st: &State, label: &str) -> (f64, String) {
    let mut kin = vec![];
    st.kin(&mut kin);
    let ctx = EvalCtx {
        t: st.t,
        gravity: model.gravity,
        ..Default::default()
    };
    let res = check_model(model, &kin, &st.lambda, &ctx);
    let mut s = format!("tangent check ({label}): element, max relative |K_analytic - K_fd|\n");
    let mut worst: f64 = 0.0;
    for r in &res {
        s.push_str(&format!("  {:<24} {:.2e}\n", r.element, r.rel_error));
        worst = worst.max(r.rel_error);
    }
    (worst, s)
}

impl StaticJob {
    /// Solves the deck and writes the result folder; `say` gets the Newton progress lines. A
    /// failed tangent check is in the outcome ([`StaticOutcome::verdict`]), its folder marked
    /// incomplete.
    pub fn execute(&self, say: &dyn Fn(&str)) -> anyhow::Result<StaticOutcome> {
        let (deck, mut model) = load_deck_within(&self.deck, |d| {
            let (ndof, nnz) = d.size_estimate();
            let iterations = (d.statics.load_steps.max(1) * d.statics.max_iterations) as f64;
            budget::time_integration_of(ndof, nnz, 1.0, iterations)
                .check(
                    &format!("static analysis of {ndof:.0} unknowns"),
                    "use fewer or longer elements, or fewer statics.load_steps",
                )
                .map_err(|e| e.to_string())
        })?;
        let mut st = State::from_model(&model);
        check_constraints(&mut model, &st)
            .map_err(|e| anyhow::anyhow!("deck {}: {e}", self.deck.display()))?;
        let out = OutDir::create(&self.out, &deck.input_files(&self.deck))?;
        let mut worst: f64 = 0.0;
        let mut report = String::new();
        if self.check_tangent {
            let (w, s) = tangent_report(&model, &st, "reference state");
            worst = worst.max(w);
            report.push_str(&s);
        }
        let opts = StaticOptions {
            load_steps: deck.statics.load_steps,
            omega: deck.statics.omega_rad_s,
            newton: crate::solver::NewtonOptions {
                max_iterations: deck.statics.max_iterations,
                ..Default::default()
            },
            ..Default::default()
        };
        let result = static_solve(&mut model, &mut st, &opts, |s, n, it, r| {
            if it == 0 {
                say(&format!("load step {s}/{n}"));
            }
            say(&format!("  iteration {it}: residual {r:.3e}"));
        });
        let rep = match result {
            Ok(r) => r,
            Err(e) => {
                out.mark_incomplete(&format!("static analysis failed: {e}"))?;
                return Err(e).context(format!("static analysis of {}", self.deck.display()));
            }
        };
        let header = sensor_header(&model);
        let hs: Vec<&str> = header.iter().map(|s| s.as_str()).collect();
        let vals = sensor_values(&model, &st, &lambda_offsets(&model));
        out.write("static.csv", csv_string(&hs, [vals]).as_bytes())?;
        let rows: Vec<Vec<f64>> = (0..st.x.len())
            .map(|i| {
                let r = st.rotation_vector(i);
                vec![
                    i as f64, st.x[i][0], st.x[i][1], st.x[i][2], r[0], r[1], r[2],
                ]
            })
            .collect();
        out.write(
            "nodes.csv",
            csv_string(
                &[
                    "node_index",
                    "x_m",
                    "y_m",
                    "z_m",
                    "rx_rad",
                    "ry_rad",
                    "rz_rad",
                ],
                rows,
            )
            .as_bytes(),
        )?;
        let names: String = model
            .nodes
            .iter()
            .enumerate()
            .map(|(i, n)| format!("{i},{}\n", n.name))
            .collect();
        out.write(
            "node_names.csv",
            format!("node_index,name\n{names}").as_bytes(),
        )?;
        let sensors = header
            .iter()
            .cloned()
            .zip(sensor_values(&model, &st, &lambda_offsets(&model)))
            .collect();
        let mut outcome = StaticOutcome {
            iterations: rep.iterations.clone(),
            residual: rep.residual,
            sensors,
            tangent: None,
        };
        if self.check_tangent {
            let (w, s) = tangent_report(&model, &st, "solved state");
            worst = worst.max(w);
            report.push_str(&s);
            out.write("tangent_check.txt", report.as_bytes())?;
            outcome.tangent = Some(TangentCheck { report, worst });
            if worst > TANGENT_TOL {
                out.mark_incomplete("tangent check failed")?;
                return Ok(outcome);
            }
        }
        out.finish()?;
        Ok(outcome)
    }
}
