//! Sub-step convergence study of the paper's first example (docs/examples/actuator_pitch_beam.toml):
//! error of the actuator force and chamber pressures vs the number N of hydraulic sub-steps per
//! structural step (dt = 1e-4 s), for RK4 (the paper's scheme) and the implicit SDIRK scheme.
//!
//! Two parts:
//! 1. Replay (1.5 s, cheap): the stroke history of a coupled reference run (implicit, N = 64) is
//!    replayed through the device alone with each (scheme, N); reference: implicit N = 512
//!    (checked against RK4 N = 1024). This isolates the hydraulic integration error.
//! 2. Coupled (the whole model, window 0-1.2 s to keep the run short: ~7 s per run): RK4 with
//!    N = 12-96 and implicit N = 1, 4, 16 against the coupled reference, through the throttle
//!    closure and the check-valve event.
//!
//! `cargo run --release --example actuator_substeps` (about 2.5 minutes on one core).
use rotorsim::hydraulics::{
    actuator_from_toml_str, CircuitDevice, Device, IntegratorOptions, PiecewiseLinear, Scheme,
};
use rotorsim::solver::{DynamicSolver, State};
use rotorsim::structure::deck::parse_deck;
use std::path::PathBuf;
use std::time::Instant;

const H: f64 = 1e-4;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Force and pressure histories (one value per structural step end).
#[derive(Default, Clone)]
struct Hist {
    force: Vec<f64>,
    p0: Vec<f64>,
    p1: Vec<f64>,
    stroke: Vec<f64>,
}

fn scheme_name(s: Scheme) -> &'static str {
    match s {
        Scheme::Rk4 => "rk4",
        Scheme::Implicit => "implicit",
    }
}

/// Coupled run of the example deck with (scheme, N) up to `t_end`; Err(message) on failure.
fn coupled(scheme: Scheme, n: usize, t_end: f64) -> Result<(Hist, f64), String> {
    let base = repo().join("docs/examples");
    let text = std::fs::read_to_string(base.join("actuator_pitch_beam.toml"))
        .map_err(|e| e.to_string())?
        .replace("substeps = 48", &format!("substeps = {n}"))
        .replace(
            "scheme = \"rk4\"",
            &format!("scheme = \"{}\"", scheme_name(scheme)),
        );
    let (deck, model) =
        parse_deck(&text, "actuator_pitch_beam.toml", &base).map_err(|e| e.to_string())?;
    let probe = deck.hydraulic_probes[0].1.clone();
    let names = probe.channel_names().to_vec();
    let ip0 = names.iter().position(|c| c == "p0_Pa").unwrap();
    let ip1 = names.iter().position(|c| c == "p1_Pa").unwrap();
    let st = State::from_model(&model);
    let mut s =
        DynamicSolver::new(model, st, H, deck.dynamic.rho_inf).map_err(|e| e.to_string())?;
    s.init_accelerations().map_err(|e| e.to_string())?;
    let steps = (t_end / H).round() as usize;
    let mut h = Hist::default();
    let mut v = vec![0.0; names.len()];
    let started = Instant::now();
    for _ in 0..steps {
        s.step().map_err(|e| e.to_string())?;
        probe.read_into(&mut v);
        h.force.push(v[0]);
        h.stroke.push(v[1]);
        h.p0.push(v[ip0]);
        h.p1.push(v[ip1]);
    }
    Ok((h, started.elapsed().as_secs_f64()))
}

/// The example's actuator (deck file and throttle schedule of actuator_pitch_beam.toml).
fn device(opts: IntegratorOptions) -> CircuitDevice {
    let path = repo().join("rotors/paper_table1_actuator_extend.toml");
    let text = std::fs::read_to_string(&path).expect("actuator deck");
    let p = actuator_from_toml_str(&text, &path.display().to_string()).expect("actuator deck");
    let mut d = CircuitDevice::new(p.to_circuit(), opts);
    d.set_orifice_area_schedule(
        PiecewiseLinear::new(vec![0.0, 0.5, 1.0], vec![0.0, 1.0, 0.0]).expect("schedule"),
    );
    d
}

/// Replays the stroke history through the device alone.
fn replay(strokes: &[f64], opts: IntegratorOptions) -> Result<(Hist, f64), String> {
    let mut d = device(opts);
    let mut h = Hist::default();
    let mut ch = vec![0.0; d.channel_names().len()];
    let mut d_i = 0.0;
    let started = Instant::now();
    for (k, &d_f) in strokes.iter().enumerate() {
        let t_i = k as f64 * H;
        d.trial_step(t_i, H, d_i, d_f)
            .map_err(|e| format!("t = {t_i:.4} s: {e}"))?;
        d.commit();
        d.channels(&mut ch);
        h.force.push(d.committed_force());
        h.p0.push(ch[0]);
        h.p1.push(ch[1]);
        d_i = d_f;
    }
    Ok((h, started.elapsed().as_secs_f64()))
}

/// (max |F - F_ref| [N], max |p - p_ref| [Pa]) over the steps where both exist.
fn errors(a: &Hist, r: &Hist) -> (f64, f64) {
    let n = a.force.len().min(r.force.len());
    let mut ef: f64 = 0.0;
    let mut ep: f64 = 0.0;
    for k in 0..n {
        ef = ef.max((a.force[k] - r.force[k]).abs());
        ep = ep
            .max((a.p0[k] - r.p0[k]).abs())
            .max((a.p1[k] - r.p1[k]).abs());
    }
    (ef, ep)
}

fn main() {
    println!("# Sub-step convergence, paper example 1 (dt = {H} s)");
    eprintln!("coupled reference run (implicit, N = 64, 1.5 s) ...");
    let (cref, tref) = coupled(Scheme::Implicit, 64, 1.5).expect("coupled reference run");
    let fmax = cref.force.iter().fold(0.0f64, |m, f| m.max(f.abs()));
    println!("coupled reference: implicit N = 64, {tref:.1} s wall, max |F| = {fmax:.1} N");

    // Part 1: replay
    let strokes = &cref.stroke;
    let imp = |n| IntegratorOptions {
        scheme: Scheme::Implicit,
        substeps: n,
    };
    let rk = |n| IntegratorOptions {
        scheme: Scheme::Rk4,
        substeps: n,
    };
    let (rref, _) = replay(strokes, imp(512)).expect("replay reference");
    let (rrk, _) = replay(strokes, rk(1024)).expect("replay RK4 N = 1024");
    let (ef, ep) = errors(&rrk, &rref);
    println!(
        "\n## Replay of the reference stroke history (1.5 s)\nreference implicit N = 512; RK4 N = 1024 differs by {ef:.2e} N, {ep:.2e} Pa\n"
    );
    println!("| scheme | N | max force error [N] | rel. to max abs(F) | max pressure error [Pa] | device time [s] |");
    println!("|---|---|---|---|---|---|");
    let cases: Vec<IntegratorOptions> = [4, 8, 12, 16, 20, 24, 28, 32, 40, 48, 64, 96, 128]
        .into_iter()
        .map(rk)
        .chain([1, 2, 4, 8, 16, 32, 64].into_iter().map(imp))
        .collect();
    for o in cases {
        match replay(strokes, o) {
            Ok((h, secs)) => {
                let (ef, ep) = errors(&h, &rref);
                println!(
                    "| {} | {} | {ef:.3e} | {:.2e} | {ep:.3e} | {secs:.3} |",
                    scheme_name(o.scheme),
                    o.substeps,
                    ef / fmax
                );
            }
            Err(e) => println!(
                "| {} | {} | failed: {e} | | | |",
                scheme_name(o.scheme),
                o.substeps
            ),
        }
    }

    // Part 2: coupled
    let t_end = 1.2;
    println!("\n## Coupled runs, window 0-{t_end} s, vs the coupled reference (implicit N = 64)\n");
    println!("| scheme | N | max force error [N] | max pressure error [Pa] | wall [s] |");
    println!("|---|---|---|---|---|");
    let coupled_cases: Vec<IntegratorOptions> = [12, 16, 20, 24, 28, 32, 40, 48, 64, 96]
        .into_iter()
        .map(rk)
        .chain([1, 4, 16].into_iter().map(imp))
        .collect();
    for o in coupled_cases {
        eprintln!("coupled {} N = {} ...", scheme_name(o.scheme), o.substeps);
        match coupled(o.scheme, o.substeps, t_end) {
            Ok((h, secs)) => {
                let (ef, ep) = errors(&h, &cref);
                println!(
                    "| {} | {} | {ef:.3e} | {ep:.3e} | {secs:.1} |",
                    scheme_name(o.scheme),
                    o.substeps
                );
            }
            Err(e) => println!(
                "| {} | {} | failed: {} | | |",
                scheme_name(o.scheme),
                o.substeps,
                e.lines().next().unwrap_or("")
            ),
        }
    }
}
