//! `rotorsim static`: nonlinear static analysis of a model deck.
use crate::io::{csv_string, OutDir};
use crate::solver::budget;
use crate::solver::fdcheck::check_model;
use crate::solver::state::{lambda_offsets, sensor_header, sensor_values};
use crate::solver::statics::check_constraints;
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::deck::load_deck_within;
use crate::structure::EvalCtx;
use anyhow::Context;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct StaticArgs {
    /// Model deck (TOML, see docs/model_deck.md).
    pub deck: PathBuf,
    /// Output directory (static.csv, nodes.csv).
    #[arg(long)]
    pub out: PathBuf,
    /// Check every element's analytic tangent against central finite differences at the
    /// reference and at the solved state; fails if a relative error exceeds 1e-5.
    #[arg(long)]
    pub check_tangent: bool,
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

pub fn run(args: StaticArgs) -> anyhow::Result<()> {
    let (deck, mut model) = load_deck_within(&args.deck, |d| {
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
        .map_err(|e| anyhow::anyhow!("deck {}: {e}", args.deck.display()))?;
    let out = OutDir::create(&args.out, &deck.input_files(&args.deck))?;
    let mut worst: f64 = 0.0;
    let mut report = String::new();
    if args.check_tangent {
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
            errln!("load step {s}/{n}");
        }
        errln!("  iteration {it}: residual {r:.3e}");
    });
    let rep = match result {
        Ok(r) => r,
        Err(e) => {
            out.mark_incomplete(&format!("static analysis failed: {e}"))?;
            return Err(e).context(format!("static analysis of {}", args.deck.display()));
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
    outln!(
        "static: {} load steps, Newton iterations per step {:?}, final residual {:.3e}",
        rep.iterations.len(),
        rep.iterations,
        rep.residual
    );
    for (h, v) in header
        .iter()
        .zip(sensor_values(&model, &st, &lambda_offsets(&model)))
    {
        outln!("  {h:<32} {v}");
    }
    if args.check_tangent {
        let (w, s) = tangent_report(&model, &st, "solved state");
        worst = worst.max(w);
        report.push_str(&s);
        out!("{report}");
        out.write("tangent_check.txt", report.as_bytes())?;
        if worst > 1e-5 {
            out.mark_incomplete("tangent check failed")?;
            anyhow::bail!("tangent check failed: largest relative error {worst:.2e} > 1e-5");
        }
    }
    out.finish()?;
    Ok(())
}
