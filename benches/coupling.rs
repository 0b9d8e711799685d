//! Benchmark: cost per structural step of the paper's first example
//! (docs/examples/actuator_pitch_beam.toml: 4 cubic beam elements, revolute joint, hydraulic
//! actuator with 48 RK4 sub-steps, dt = 1e-4 s) on one core, with the share spent in the device.
//! Variants: the implicit hydraulic scheme (N = 4) and the paper's F_m (applied_force = "mean",
//! which goes unstable once the throttle closes, docs/coupling.md).
//! Windows: 0-0.2 s (throttle open) and 1.0-1.2 s (closed, stiff).
use rotorsim::solver::{DynamicSolver, State};
use rotorsim::structure::deck::parse_deck;
use std::path::PathBuf;
use std::time::Instant;

fn solver(
    edit: &dyn Fn(String) -> String,
) -> (
    DynamicSolver,
    Option<std::sync::Arc<rotorsim::structure::HydraulicProbe>>,
) {
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("docs/examples");
    let text = edit(std::fs::read_to_string(base.join("actuator_pitch_beam.toml")).unwrap());
    let (deck, model) = parse_deck(&text, "actuator_pitch_beam.toml", &base).unwrap();
    let probe = deck.hydraulic_probes.first().map(|p| p.1.clone());
    let st = State::from_model(&model);
    let mut s = DynamicSolver::new(model, st, 1e-4, deck.dynamic.rho_inf).unwrap();
    s.init_accelerations().unwrap();
    (s, probe)
}

fn main() {
    let steps = 2000;
    type Edit = Box<dyn Fn(String) -> String>;
    let variants: Vec<(&str, Edit)> = vec![
        ("rk4 N=48 (paper)", Box::new(|t| t)),
        (
            "implicit N=4",
            Box::new(|t: String| {
                t.replace("substeps = 48", "substeps = 4")
                    .replace("scheme = \"rk4\"", "scheme = \"implicit\"")
            }),
        ),
        (
            "rk4 N=48, applied_force = mean",
            Box::new(|t: String| {
                t.replace("substeps = 48", "substeps = 48\napplied_force = \"mean\"")
            }),
        ),
    ];
    println!(
        "| variant | window [s] | ms/step | Newton it./step | device trials/step | device share |"
    );
    println!("|---|---|---|---|---|---|");
    for (name, edit) in &variants {
        let (mut s, probe) = solver(edit.as_ref());
        for (t0, t1) in [(0.0, 0.2), (1.0, 1.2)] {
            // advance to the window start (not timed)
            while s.state.t < t0 - 0.5e-4 {
                if s.step().is_err() {
                    break;
                }
            }
            let (it0, tr0, hs0) = (
                s.total_iterations,
                probe.as_ref().map_or(0, |p| p.trials()),
                probe.as_ref().map_or(0.0, |p| p.hydraulics_seconds()),
            );
            let start = Instant::now();
            let mut done = 0;
            let mut failed = None;
            for _ in 0..steps {
                match s.step() {
                    Ok(_) => done += 1,
                    Err(e) => {
                        failed = Some(e.to_string());
                        break;
                    }
                }
            }
            let wall = start.elapsed().as_secs_f64();
            if let Some(e) = failed {
                println!(
                    "| {name} | {t0}-{t1} | failed after {done} steps: {} | | | |",
                    e.lines().next().unwrap_or("")
                );
                break;
            }
            let n = done as f64;
            let hs = probe.as_ref().map_or(0.0, |p| p.hydraulics_seconds()) - hs0;
            let tr = probe.as_ref().map_or(0, |p| p.trials()) - tr0;
            println!(
                "| {name} | {t0}-{t1} | {:.4} | {:.2} | {:.2} | {:.1} % |",
                1e3 * wall / n,
                (s.total_iterations - it0) as f64 / n,
                tr as f64 / n,
                100.0 * hs / wall
            );
        }
    }
}
