//! Free decay of the TM-4760 blade's lag hinge (rotors/tm4760.toml, docs/validation_tm4760.md):
//! `cargo run --release --example tm4760_decay -- [STEP_S] [frame|inertial] [modified|full] [END_S] [RTOL] [RHO_INF]`
//! (defaults 0.005 frame modified 6 1e-8 0.9; the correction tolerance is the decay's, 1e-9). Prints the linearised rigid lag mode, the decay's damped
//! frequency and damping ratio (linear-prediction fit and log decrement over t >= 1 s), the
//! Newton iterations and factorizations per step and the CPU cost per step of this thread, and
//! writes the lag angle history to `tm4760_decay.csv` in the current folder.
use rotorsim::checks::decay::{analyse, decay_sim, modal_lag, steps, DecayRun, DecayRunOptions};
use rotorsim::rotor::hinged::HingedSpec;
use rotorsim::solver::NewtonMethod;
use std::path::Path;

fn cpu_seconds() -> f64 {
    // CLOCK_THREAD_CPUTIME_ID through /proc: utime + stime of this thread, in clock ticks
    let stat = std::fs::read_to_string("/proc/thread-self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let tick = 100.0;
    let ut: f64 = fields
        .get(11)
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    let st: f64 = fields
        .get(12)
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    (ut + st) / tick
}

fn main() -> anyhow::Result<()> {
    let a: Vec<String> = std::env::args().collect();
    let h: f64 = a.get(1).map_or(Ok(0.005), |v| v.parse())?;
    let frame = a.get(2).is_none_or(|v| v == "frame");
    let newton = if a.get(3).is_some_and(|v| v == "full") {
        NewtonMethod::Full
    } else {
        NewtonMethod::Modified
    };
    let end: f64 = a.get(4).map_or(Ok(6.0), |v| v.parse())?;
    let rtol: f64 = a.get(5).map_or(Ok(1e-8), |v| v.parse())?;
    let rho: f64 = a.get(6).map_or(Ok(0.9), |v| v.parse())?;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("rotors/tm4760.toml");
    let spec = HingedSpec::from_file(&path)?;
    let om = spec.rotor.omega_rad_s;
    let opts = DecayRunOptions {
        omega_rad_s: Some(om),
        time_step_s: h,
        duration_s: end,
        rotating_frame: frame,
        newton,
        newton_rtol: rtol,
        rho_inf: rho,
        ..Default::default()
    };
    let modal = modal_lag(&spec, &path, om)?;
    println!(
        "modal rigid lag: {:.6} Hz (damped), zeta {:.6}",
        modal.0, modal.1
    );
    let mut sim = decay_sim(&spec, &path, &opts)?;
    println!(
        "h = {h} s, {} frame, {} Newton, rtol {rtol:e}, rho_inf {rho}; initial lag {:.4} deg",
        if frame { "turning" } else { "inertial" },
        newton.name(),
        sim.lag_angle_rad().to_degrees()
    );
    let n = steps(&opts);
    let mut x = Vec::with_capacity(n);
    let c0 = cpu_seconds();
    let t0 = std::time::Instant::now();
    for k in 0..n {
        let f0 = sim.solver.factorizations;
        sim.step()?;
        if std::env::var("TM_DEBUG").is_ok() && (200..215).contains(&k) {
            eprintln!(
                "step {k}: refactor {} residuals {:?}",
                sim.solver.factorizations - f0,
                sim.solver.last_residuals
            );
        }
        x.push(sim.lag_angle_rad());
    }
    let wall = t0.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - c0;
    let (fit, ld) = analyse(&x, sim.lag_eq_rad, &opts);
    println!("fit: {fit:?} (Hz, zeta); log decrement: {ld:?}");
    if let Some((f, z)) = fit {
        println!(
            "fit vs modal: frequency {:+.3}%, damping ratio {:+.3}%",
            100.0 * (f - modal.0) / modal.0,
            100.0 * (z - modal.1) / modal.1
        );
    }
    let s = &sim.solver;
    println!(
        "{n} steps: {:.3} Newton iterations/step, {:.4} factorizations/step, CPU {:.4} ms/step, wall {:.4} ms/step",
        s.total_iterations as f64 / n as f64,
        s.factorizations as f64 / n as f64,
        1e3 * cpu / n as f64,
        1e3 * wall / n as f64
    );
    let run = DecayRun {
        options: opts,
        omega_rad_s: om,
        lag_eq_rad: sim.lag_eq_rad,
        lag_rad: x,
        modal: Some(modal),
        fit,
        log_decrement: ld,
        newton_iterations: s.total_iterations,
        factorizations: s.factorizations,
    };
    std::fs::write("tm4760_decay.csv", run.history_csv())?;
    Ok(())
}
