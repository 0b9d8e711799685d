//! `rotorsim bench` outputs: dynamic stiffness and energy per cycle against the linear dashpot's
//! closed form, output rate (sampling only), stroke period and `--skip-cycles` of a replay,
//! files named by amplitude, CSV columns with units, bench.html with its figures.
use rotorsim::hydraulics::bench::{self, harmonic_run_sampled, IN_TO_M};
use rotorsim::hydraulics::*;
use std::f64::consts::PI;
use std::process::Command;

mod support;
use support::{root, tmp};

fn deck() -> DamperDeck {
    DamperDeck::from_file(&root().join("rotors/uh60a.toml")).unwrap()
}

fn rotorsim(args: &[&str]) -> std::process::Output {
    let o = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(args)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// (sin h / h)^2 with h = omega dt / 2 = pi / steps per cycle: the stroke is linear over a step
/// (output samples within it included), so a dashpot's force is c times the step's mean stroke
/// rate, whose first harmonic is the stroke rate's times sin(h)/h; the step's exact integral of
/// cos takes that factor once more. So the discrete K'' = c omega (sin h/h)^2 and energy
/// pi c omega A^2 (sin h/h)^2, both below the continuous values by about h^2/3 (5e-5 at 256
/// steps per cycle).
fn attenuation(steps_per_cycle: usize) -> f64 {
    let h = PI / steps_per_cycle as f64;
    (h.sin() / h).powi(2)
}

#[test]
fn linear_dashpot_gives_its_closed_form_loss_stiffness_and_energy_and_no_storage() {
    let d = deck();
    let c = d.linear_c_n_s_per_m.unwrap();
    let dev = d
        .build(DamperModel::Linear, IntegratorOptions::default())
        .unwrap();
    let omega = 27.02;
    for (spc, per_step) in [(64, 1), (256, 1), (64, 4)] {
        for v in [0.5 * IN_TO_M, 10.0 * IN_TO_M] {
            let r = harmonic_run_sampled(dev.as_ref(), omega, v, 2, spc, per_step, false).unwrap();
            let a = v / omega;
            assert_eq!(r.amplitude_m, a);
            let att = attenuation(spc);
            let h = PI / spc as f64;
            // the discrete closed form, to round-off
            let k2 = r.loss_stiffness_n_per_m / (c * omega * att);
            let e = r.dissipated_last_cycle_j / (PI * c * omega * a * a * att);
            assert!((k2 - 1.0).abs() < 1e-10, "spc {spc} x {per_step}: K'' {k2}");
            assert!((e - 1.0).abs() < 1e-10, "spc {spc} x {per_step}: E {e}");
            // the continuous c omega and pi c omega A^2, within the discretization's h^2/3
            for (x, exact) in [
                (r.loss_stiffness_n_per_m, c * omega),
                (r.dissipated_last_cycle_j, PI * c * omega * a * a),
            ] {
                let rel = (x - exact).abs() / exact;
                assert!(rel <= h * h / 3.0, "{x} vs {exact}: {rel:e} > h^2/3");
            }
            // no in-phase part: the cos-sin products cancel over a full cycle
            assert!(
                r.storage_stiffness_n_per_m.abs() < 1e-9 * c * omega,
                "K' {}",
                r.storage_stiffness_n_per_m
            );
        }
    }
}

#[test]
fn output_rate_changes_only_the_sampling() {
    // 5 samples per step with 5 sub-steps each integrate with the same sub-step as 1 sample
    // with 25: every 5th sample is the step-end sample, and the peaks can only grow.
    let d = deck();
    let build = |n| {
        d.build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Rk4,
                substeps: n,
            },
        )
        .unwrap()
    };
    let (coarse, fine) = (build(25), build(5));
    let v = 10.0 * IN_TO_M;
    let a = harmonic_run_sampled(coarse.as_ref(), 27.02, v, 4, 256, 1, true).unwrap();
    let b = harmonic_run_sampled(fine.as_ref(), 27.02, v, 4, 256, 5, true).unwrap();
    assert_eq!(b.history.time_s.len(), 5 * (a.history.time_s.len() - 1) + 1);
    let scale = a.peak_force_pos_n;
    for (k, (&fa, &ta)) in a.history.force_n.iter().zip(&a.history.time_s).enumerate() {
        let (fb, tb) = (b.history.force_n[5 * k], b.history.time_s[5 * k]);
        assert!((ta - tb).abs() < 1e-12, "t {ta} vs {tb}");
        assert!((fa - fb).abs() < 1e-6 * scale, "sample {k}: {fa} vs {fb}");
    }
    assert!(b.peak_force_pos_n >= a.peak_force_pos_n - 1e-6 * scale);
    assert!(b.peak_force_neg_n <= a.peak_force_neg_n + 1e-6 * scale);
    let de = (b.dissipated_last_cycle_j - a.dissipated_last_cycle_j).abs();
    assert!(
        de < 1e-6 * a.dissipated_last_cycle_j,
        "energy differs by {de} J"
    );
    eprintln!(
        "10 in/s: peak {:.1} N at the step rate, {:.1} N at 5 samples per step ({:+.2} %)",
        a.peak_force_pos_n,
        b.peak_force_pos_n,
        100.0 * (b.peak_force_pos_n / a.peak_force_pos_n - 1.0)
    );
}

#[test]
fn stroke_period_is_found_from_the_mid_range_crossings() {
    let period = 0.23254;
    let t: Vec<f64> = (0..3000).map(|i| 0.3 + i as f64 * 1e-3).collect();
    // 1.5 mm amplitude, 0.2 mm offset, deterministic noise of +-2 % of the amplitude
    let x: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let noise = 3e-5 * ((i as f64 * 12.9898).sin() * 43758.5453).fract();
            2e-4 + 1.5e-3 * (2.0 * PI * t / period + 0.7).sin() + noise
        })
        .collect();
    let p = bench::stroke_period(&t, &x).unwrap();
    assert!((p / period - 1.0).abs() < 2e-3, "{p}");
    let ramp: Vec<f64> = t.iter().map(|t| t * 1e-3).collect();
    assert_eq!(bench::stroke_period(&t, &ramp), None);
}

fn csv_column(text: &str, name: &str) -> Vec<String> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let i = header
        .iter()
        .position(|h| *h == name)
        .unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    lines
        .map(|l| l.split(',').nth(i).unwrap().to_string())
        .collect()
}

#[test]
fn skip_cycles_leaves_the_settling_out_of_the_replay_error() {
    // Steady-state "measurement" (SYNTHETIC: made by the physical model itself, replayed as
    // `bench --measured` replays, so that only the settling differs): cycles 8-13 of a replay
    // from rest. A replay starts at rest, so its first cycles carry the settling (the check
    // valves pump the mean pressure up) and its error; skipping them lowers it.
    let d = deck();
    let dev = d
        .build(DamperModel::Physical, IntegratorOptions::default())
        .unwrap();
    let spc = 128;
    let omega = 27.02;
    let amp = 3.0 * IN_TO_M / omega;
    let dt = 2.0 * PI / omega / spc as f64;
    let time_s: Vec<f64> = (0..=14 * spc).map(|k| k as f64 * dt).collect();
    let stroke_m: Vec<f64> = time_s.iter().map(|&t| amp * (omega * t).sin()).collect();
    let force_n = bench::replay_force(dev.as_ref(), &time_s, &stroke_m).unwrap();
    let first = 8 * spc;
    let t0 = time_s[first];
    let mut text = String::from("time_s,stroke_m,force_N\n");
    for i in first..time_s.len() {
        text.push_str(&format!(
            "{},{},{}\n",
            time_s[i] - t0,
            stroke_m[i],
            force_n[i]
        ));
    }
    let n = time_s.len() - first;
    let dir = tmp("bench-skip");
    let csv = dir.join("steady_synthetic.csv");
    std::fs::write(&csv, text).unwrap();
    let run = |skip: &str| {
        let out = dir.join(format!("out{skip}"));
        let o = rotorsim(&[
            "bench",
            "--damper-deck",
            "rotors/uh60a.toml",
            "--damper",
            "physical",
            "--measured",
            csv.to_str().unwrap(),
            "--skip-cycles",
            skip,
            "--out",
            out.to_str().unwrap(),
        ]);
        let s = std::fs::read_to_string(out.join("replay_summary.csv")).unwrap();
        let rms: f64 = csv_column(&s, "rms_error_N")[0].parse().unwrap();
        let used: usize = csv_column(&s, "samples_used")[0].parse().unwrap();
        let period: f64 = csv_column(&s, "cycle_period_s")[0].parse().unwrap();
        let html = std::fs::read_to_string(out.join("bench.html")).unwrap();
        (
            rms,
            used,
            period,
            String::from_utf8_lossy(&o.stdout).to_string(),
            html,
        )
    };
    let (rms0, used0, period, _, _) = run("0");
    let (rms2, used2, _, stdout, html) = run("2");
    assert!((period / (2.0 * PI / 27.02) - 1.0).abs() < 1e-3, "{period}");
    assert_eq!(used0, n);
    // samples from t0 + 2 T on: sample 2 spc sits on the boundary (to the period's round-off)
    assert!(
        used2 == n - 2 * spc || used2 == n - 2 * spc - 1,
        "{used2} of {n}"
    );
    assert!(rms2 < rms0, "skip 2: {rms2} N, no skip: {rms0} N");
    // the same model settles onto the same periodic state: past the settling, no error left
    assert!(rms2 < 1e-2 * rms0, "skip 2: {rms2} N, no skip: {rms0} N");
    eprintln!("replay from rest of steady data: RMS {rms0:.1} N, skipping 2 cycles {rms2:.1} N");
    assert!(
        stdout.contains(&format!("over {used2} of {n} samples")),
        "{stdout}"
    );
    assert!(html.contains("SYNTHETIC") && html.contains("Error metrics") && html.contains("<svg"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sweep_writes_summary_histories_by_amplitude_and_bench_html() {
    let dir = tmp("bench-outputs");
    let out = dir.join("all");
    rotorsim(&[
        "bench",
        "--damper-deck",
        "rotors/uh60a.toml",
        "--damper",
        "all",
        "--peak-velocity",
        "1,4",
        "--cycles",
        "2",
        "--out",
        out.to_str().unwrap(),
    ]);
    let s = std::fs::read_to_string(out.join("bench_summary.csv")).unwrap();
    let header = s.lines().next().unwrap();
    assert_eq!(
        header,
        "model,peak_velocity_m_s,peak_velocity_in_s,amplitude_m,omega_rad_s,output_rate_Hz,\
peak_force_pos_N,peak_force_neg_N,K_storage_N_per_m,K_loss_N_per_m,energy_per_cycle_J,\
equivalent_damping_N_s_per_m,history_file,steps_per_cycle,substeps,scheme,convergence,\
relative_error,peak_force_pos_error_N,peak_force_neg_error_N,K_storage_error_N_per_m,\
K_loss_error_N_per_m,energy_per_cycle_error_J,equivalent_damping_error_N_s_per_m"
    );
    // every numeric column carries its unit (counts, names and the relative error have none)
    for col in header.split(',') {
        assert!(
            [
                "model",
                "history_file",
                "steps_per_cycle",
                "substeps",
                "scheme",
                "convergence",
                "relative_error",
            ]
            .contains(&col)
                || ["_m", "_s", "_Hz", "_N", "_J", "_per_m"]
                    .iter()
                    .any(|u| col.ends_with(u)),
            "{col}"
        );
    }
    assert_eq!(s.lines().count(), 1 + 3 * 2);
    let files = csv_column(&s, "history_file");
    for f in &files {
        assert!(out.join(f).exists(), "{f}");
    }
    for m in ["physical", "linear", "nonlinear"] {
        for v in ["0.025400", "0.101600"] {
            assert!(
                files.contains(&format!("{m}/history_v{v}m_s.csv")),
                "{files:?}"
            );
        }
        assert!(!out.join(m).join("history_0.csv").exists());
        assert!(out.join(m).join("peaks.csv").exists());
    }
    // the linear rows: K'' and energy of the closed form through the CLI too
    let c = deck().linear_c_n_s_per_m.unwrap();
    let models = csv_column(&s, "model");
    let kl = csv_column(&s, "K_loss_N_per_m");
    let ks = csv_column(&s, "K_storage_N_per_m");
    // the default refines: each row at its own steps per cycle
    let steps = csv_column(&s, "steps_per_cycle");
    for i in (0..models.len()).filter(|&i| models[i] == "linear") {
        let k2: f64 = kl[i].parse().unwrap();
        let n: usize = steps[i].parse().unwrap();
        assert!(
            (k2 / (c * 27.02 * attenuation(n)) - 1.0).abs() < 1e-10,
            "{k2}"
        );
        assert!(ks[i].parse::<f64>().unwrap().abs() < 1e-9 * k2);
    }
    let html = std::fs::read_to_string(out.join("bench.html")).unwrap();
    for want in [
        "Peak force vs peak velocity (paper Fig. 13)",
        "Storage stiffness K",
        "Loss stiffness K",
        "Energy dissipated per cycle vs stroke amplitude",
        "Hysteresis loops per amplitude",
        "force vs stroke",
        "force vs velocity",
        "peak force [kN]",
        "stroke amplitude [mm]",
        "Virtual bench",
    ] {
        assert!(html.contains(want), "bench.html lacks {want}");
    }
    // Fig. 13 + K' and K'' + energy + loops + one time history per model
    assert!(
        html.matches("<svg").count() >= 7,
        "{}",
        html.matches("<svg").count()
    );
    assert!(!html.contains("<?xml"), "inline SVG");
    // one model: the files directly in DIR
    let one = dir.join("one");
    rotorsim(&[
        "bench",
        "--damper-deck",
        "rotors/uh60a.toml",
        "--damper",
        "linear",
        "--peak-velocity",
        "2",
        "--cycles",
        "1",
        "--output-rate",
        "5505",
        "--out",
        one.to_str().unwrap(),
    ]);
    let s = std::fs::read_to_string(one.join("bench_summary.csv")).unwrap();
    assert_eq!(csv_column(&s, "history_file"), ["history_v0.050800m_s.csv"]);
    let rate: f64 = csv_column(&s, "output_rate_Hz")[0].parse().unwrap();
    // k = 5 samples per step of the first 256 steps per cycle, kept when the default refines
    let n: usize = csv_column(&s, "steps_per_cycle")[0].parse().unwrap();
    assert!(
        (rate - 5.0 * 27.02 * n as f64 / (2.0 * PI)).abs() < 1e-6,
        "{rate}"
    );
    let h = std::fs::read_to_string(one.join("history_v0.050800m_s.csv")).unwrap();
    assert_eq!(h.lines().count(), 1 + n * 5 + 1);
    assert!(one.join("bench.html").exists());
    let _ = std::fs::remove_dir_all(&dir);
}
