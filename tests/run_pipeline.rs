//! `rotorsim run` end to end, with the lag-hinge test double (`--model sdof`) so the
//! pipeline is exercised in seconds: outputs, keys, units, periodicity, known-answer metrics,
//! bad inputs.
use rotorsim::flight::{DamperSample, FlightRecord};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

mod support;
use support::tmp;

fn rotorsim(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(args)
        .output()
        .expect("run rotorsim")
}

/// `rotorsim run --model sdof` on `flight` into `out`, with extra arguments.
fn run_sdof(flight: &Path, out: &Path, extra: &[&str]) -> Output {
    let rotor = repo().join("rotors/uh60a.toml");
    let mut a = vec![
        "run",
        "--model",
        "sdof",
        "--rotor",
        rotor.to_str().unwrap(),
        "--flight",
        flight.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    rotorsim(&a)
}

fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "stdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
}

fn summary(out: &Path) -> Value {
    support::read_json(&out.join("summary.json"))
}

fn example() -> PathBuf {
    repo().join("flightdata/c8534like")
}

/// The example record with its damper channel replaced.
fn with_damper(damper: Vec<DamperSample>, path: &Path) {
    let r = FlightRecord::read(&example()).unwrap();
    let rec = FlightRecord::new(
        r.meta.clone(),
        r.stations_r_over_r().to_vec(),
        r.revolutions().to_vec(),
        r.azimuths_deg().to_vec(),
        r.normal_n_per_m().to_vec(),
        r.chord_n_per_m().to_vec(),
        r.moment_n_m_per_m().to_vec(),
        damper,
    )
    .unwrap();
    rec.write_mcap(path).unwrap();
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let mut cols = vec![Vec::new(); header.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse::<f64>().unwrap());
        }
    }
    (header, cols)
}

#[test]
fn all_three_models_write_every_output() {
    let out = tmp("all");
    let o = run_sdof(&example(), &out, &["--revs", "4", "--periodic", "march"]);
    ok(&o);
    for f in [
        "summary.json",
        "report.html",
        "result.mcap",
        "linear/last_rev.csv",
        "nonlinear/last_rev.csv",
        "physical/last_rev.csv",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    assert!(!out.join("INCOMPLETE").exists());
    let s = summary(&out);
    assert_eq!(s["synthetic"], Value::Bool(true));
    assert_eq!(s["options"]["revs"], 4);
    assert_eq!(s["options"]["steps_per_rev"], 256);
    assert_eq!(s["measured"]["available"], Value::Bool(true));
    assert_eq!(s["measured"]["revolutions_averaged"], 5);
    for m in ["linear", "nonlinear", "physical"] {
        let j = &s["models"][m];
        assert_eq!(j["status"], "ok", "{m}: {j}");
        // One residual per marched revolution; the last one per monitored channel.
        let h = j["periodicity"]["history"].as_array().unwrap();
        assert!(!h.is_empty() && h.len() <= 4, "{m}");
        assert!(h.iter().all(|x| x.as_f64().unwrap() >= 0.0));
        assert_eq!(
            j["periodicity"]["last_by_channel"]
                .as_array()
                .unwrap()
                .len(),
            4
        );
        assert!(j["periodicity"]["converged"].is_boolean());
        for k in ["min", "max", "mean", "peak_to_peak", "rms"] {
            assert!(j["damper_force_N"][k].is_number(), "{m} {k}");
        }
        let f = &j["damper_force_N"];
        assert!(f["max"].as_f64().unwrap() > 0.0 && f["min"].as_f64().unwrap() < 0.0);
        for k in ["rms_error_N", "peak_to_peak_error_N", "correlation"] {
            assert!(j["metrics"][k].is_number(), "{m} {k}");
        }
        assert_eq!(
            j["metrics"]["harmonics_model"].as_array().unwrap().len(),
            11
        );
        assert_eq!(
            j["metrics"]["harmonics_measured"].as_array().unwrap().len(),
            11
        );
        for k in ["total", "structure", "hydraulics"] {
            assert!(j["wall_time_s"][k].as_f64().unwrap() >= 0.0, "{m} {k}");
        }
        assert_eq!(j["steps"], 4 * 256);
    }
    // The physical damper has relief-valve limits; the dashpots have none.
    let lim = &s["models"]["physical"]["relief_valve_limits"];
    assert!(
        lim["within"].is_boolean() && lim["margin_n"].is_number(),
        "{lim}"
    );
    assert_eq!(
        s["models"]["linear"]["relief_valve_limits"]["applies"],
        Value::Bool(false)
    );
    assert!(s["closest"]["statement"]
        .as_str()
        .unwrap()
        .contains("comes closest"));

    // CSV: units in every column, one revolution of samples, azimuths 0..360.
    let (h, cols) = read_csv(&out.join("physical/last_rev.csv"));
    assert_eq!(
        &h[..7],
        &[
            "time_s",
            "azimuth_deg",
            "measured_damper_force_N",
            "measured_damper_stroke_m",
            "damper_force_N",
            "damper_stroke_m",
            "damper_stroke_rate_m_s"
        ]
    );
    for want in support::PHYSICAL_CHANNELS {
        assert!(h.iter().any(|x| x == want), "{want} missing from {h:?}");
    }
    let units = ["_s", "_deg", "_N", "_m", "_m_s", "_Pa", "_m3_s", "_rad"];
    for c in &h {
        assert!(
            units.iter().any(|u| c.ends_with(u)),
            "column {c} has no unit"
        );
    }
    assert_eq!(cols[1].len(), 256);
    assert_eq!(cols[1][0], 0.0);
    assert_eq!(cols[1][255], 360.0 - 360.0 / 256.0);
    // Stroke = arm x lag angle and the stroke rate is its derivative: check d(stroke)/dt
    // against the rate by central differences (trapezoidal rule => exact for the mean rate).
    let dt = 2.0 * std::f64::consts::PI / 27.0 / 256.0;
    let (d, v) = (&cols[5], &cols[6]);
    for i in 1..255 {
        let mean_rate = (d[i + 1] - d[i]) / dt;
        assert!(
            (mean_rate - 0.5 * (v[i] + v[i + 1])).abs() < 1e-9 + 1e-9 * v[i].abs(),
            "sample {i}"
        );
    }

    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("SYNTHETIC"));
    assert!(html.contains("TEST DOUBLE"));
    assert!(html.contains("<svg"));
    assert!(html.contains("comes closest"));
    // Self-contained: nothing loaded from elsewhere.
    for ext in ["src=\"http", "href=\"http", "<link", "<script"] {
        assert!(!html.contains(ext), "{ext}");
    }

    // MCAP: one message per step of the last revolution per model, plus the measurement.
    let bytes = std::fs::read(out.join("result.mcap")).unwrap();
    let mut counts = std::collections::BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        *counts.entry(m.channel.topic.clone()).or_insert(0) += 1;
        if m.channel.topic == "/run/physical" {
            let v: Value = serde_json::from_slice(&m.data).unwrap();
            assert!(v["p0_Pa"].is_number() && v["azimuth_deg"].is_number());
        }
    }
    for m in ["linear", "nonlinear", "physical"] {
        assert_eq!(counts[&format!("/run/{m}")], 256, "{counts:?}");
    }
    assert_eq!(counts["/run/measured"], 256);
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn measured_equal_to_the_model_gives_zero_error_and_a_shift_gives_the_known_error() {
    // First run: the model's own last revolution becomes the "measurement" of a copy of the
    // record (same azimuth grid), then the run is repeated against it (deterministic).
    let out = tmp("known");
    ok(&run_sdof(
        &example(),
        &out,
        &["--damper", "linear", "--revs", "3"],
    ));
    let (h, cols) = read_csv(&out.join("linear/last_rev.csv"));
    let force = &cols[h.iter().position(|c| c == "damper_force_N").unwrap()];
    let r = FlightRecord::read(&example()).unwrap();
    let az = r.azimuths_deg().to_vec();
    assert_eq!(az.len(), cols[0].len());
    let make = |offset: f64| -> Vec<DamperSample> {
        az.iter()
            .zip(force)
            .map(|(p, f)| DamperSample {
                revolution: 0,
                azimuth_deg: *p,
                force_N: f + offset,
                stroke_m: None,
            })
            .collect()
    };
    let same = out.join("same.mcap");
    with_damper(make(0.0), &same);
    let o2 = tmp("known-same");
    ok(&run_sdof(
        &same,
        &o2,
        &["--damper", "linear", "--revs", "3"],
    ));
    let m = &summary(&o2)["models"]["linear"]["metrics"];
    assert!(m["rms_error_N"].as_f64().unwrap() < 1e-6, "{m}");
    assert!((m["correlation"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    assert!(m["peak_to_peak_error_N"].as_f64().unwrap().abs() < 1e-6);
    assert_eq!(m["samples"], 256);

    // A constant offset of 250 N: RMS error 250 N, no peak-to-peak error, correlation 1,
    // 0/rev of the residual 250 N... measured mean 250 N above the model's.
    let shifted = out.join("shifted.mcap");
    with_damper(make(-250.0), &shifted);
    let o3 = tmp("known-shift");
    ok(&run_sdof(
        &shifted,
        &o3,
        &["--damper", "linear", "--revs", "3"],
    ));
    let s = summary(&o3);
    let m = &s["models"]["linear"]["metrics"];
    assert!(
        (m["rms_error_N"].as_f64().unwrap() - 250.0).abs() < 1e-6,
        "{m}"
    );
    assert!(m["peak_to_peak_error_N"].as_f64().unwrap().abs() < 1e-6);
    assert!((m["correlation"].as_f64().unwrap() - 1.0).abs() < 1e-12);
    let res = &s["models"]["linear"]["residual"];
    assert!((res["harmonics"][0]["amplitude_N"].as_f64().unwrap() - 250.0).abs() < 1e-6);
    for d in [out, o2, o3] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn periodicity_of_the_linear_model_decays_at_the_lag_mode_damping_rate() {
    // Linear dashpot on the lag hinge: a linear SDOF whose transient decays as exp(-s t) with
    // s = c a^2 / (2 I), so the measure falls by exp(-s T) per revolution. The per-revolution
    // maximum samples the envelope of a 0.29/rev oscillation (within a factor ~0.8), so the
    // rate is taken from a least-squares fit of log(measure) over 30 revolutions.
    let out = tmp("decay");
    ok(&run_sdof(
        &example(),
        &out,
        &[
            "--damper",
            "linear",
            "--revs",
            "40",
            "--periodic",
            "march",
            "--periodic-tol",
            "1e-12",
        ],
    ));
    let s = summary(&out);
    let h: Vec<f64> = s["models"]["linear"]["periodicity"]["history"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(h.len(), 40);
    let h = &h[1..];
    let (i, c, a) = (2087.0, 68000.0, 0.175);
    let period = 2.0 * std::f64::consts::PI / 27.0;
    let expect = (-c * a * a / (2.0 * i) * period).exp();
    let pts: Vec<(f64, f64)> = (8..39).map(|k| (k as f64, h[k].ln())).collect();
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
        / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    let ratio = slope.exp();
    assert!(
        (ratio - expect).abs() < 0.01 * expect,
        "decay per revolution {ratio} vs analytic {expect} (history {h:?})"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_damper_channel_too_coarse_to_compare_runs_without_metrics() {
    // Flight records always carry a damper force (docs/formats.md: the column is required), but one
    // with 8 azimuths per revolution cannot give harmonics 0-10/rev: the run goes on, the
    // metrics are absent with a note saying why.
    let out = tmp("coarse");
    let rec = out.join("coarse.mcap");
    let damper = (0..8)
        .map(|k| DamperSample {
            revolution: 0,
            azimuth_deg: 45.0 * k as f64,
            force_N: 1000.0 * (45.0 * k as f64).to_radians().sin(),
            stroke_m: None,
        })
        .collect();
    with_damper(damper, &rec);
    let o = run_sdof(
        &rec,
        &out.join("o"),
        &["--damper", "nonlinear", "--revs", "2"],
    );
    ok(&o);
    let s = summary(&out.join("o"));
    assert_eq!(s["measured"]["available"], Value::Bool(false));
    let note = s["measured"]["note"].as_str().unwrap();
    assert!(
        note.contains("8 azimuths") && note.contains("no comparison metrics"),
        "{note}"
    );
    let m = &s["models"]["nonlinear"];
    assert_eq!(m["status"], "ok");
    assert!(m["metrics"]["rms_error_N"].is_null());
    assert!(m["metrics"]["note"].is_string());
    assert!(s["closest"].is_null());
    assert!(String::from_utf8_lossy(&o.stdout).contains("no comparison metrics"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bad_inputs_are_named() {
    let out = tmp("bad");
    let o = run_sdof(&out.join("nope"), &out.join("o"), &["--revs", "2"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("nope"), "{e}");
    assert!(!out.join("o").exists(), "no output for a bad record");

    let o = run_sdof(&example(), &out.join("o"), &["--damper", "viscous"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("viscous") && e.contains("linear"), "{e}");

    let o = run_sdof(&example(), &out.join("o"), &["--scheme", "euler"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("euler"));

    let o = run_sdof(&example(), &out.join("o"), &["--revs", "1"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("--revs"));

    // A damper deck without the requested model's table.
    let deck = out.join("only_linear.toml");
    std::fs::write(
        &deck,
        "[damper]\nmodel = \"linear\"\n[damper.linear]\nc_N_s_per_m = 1.0\n",
    )
    .unwrap();
    let o = run_sdof(
        &example(),
        &out.join("o"),
        &[
            "--damper",
            "physical",
            "--damper-deck",
            deck.to_str().unwrap(),
        ],
    );
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("only_linear.toml") && e.contains("damper.physical"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn lag_hinge_double_matches_the_analytic_forced_response() {
    // Linear dashpot, pure 1/rev lag moment M1 cos(psi): steady stroke amplitude
    // a M1 / sqrt((K - I W^2)^2 + (c a^2 W)^2), K = e S W^2 + k, phase lag atan2(c a^2 W, K - I W^2).
    use rotorsim::analysis::harmonics::{harmonics, Harmonic};
    use rotorsim::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
    use rotorsim::run::sdof::{LagHingeSdof, SdofParams};
    let m1 = 5000.0;
    let h = |n, cos| Harmonic {
        n,
        cos,
        sin: 0.0,
        amplitude: cos,
        phase_deg: 0.0,
    };
    let p = SdofParams::uh60a_like(27.0, vec![h(0, 0.0), h(1, m1)]);
    let deck = DamperDeck::from_file(&repo().join("rotors/uh60a.toml")).unwrap();
    let mut sim = LagHingeSdof::new(
        p.clone(),
        &deck,
        DamperModel::Linear,
        IntegratorOptions::default(),
        256,
    )
    .unwrap();
    let run = rotorsim::run::drive(&mut sim, DamperModel::Linear, 150, &|_, _| {}).unwrap();
    assert!(run.converged(), "{:?}", run.last_measure());
    let d = run.channel("damper_stroke_m").unwrap();
    let hd = harmonics(&run.azimuth_deg, d, 2).unwrap();
    let w = p.omega_rad_s;
    let k = p.hinge_offset_m * p.first_moment_kg_m * w * w + p.lag_spring_n_m_per_rad;
    let ca2 = 68000.0 * p.damper_arm_m.powi(2);
    let re = k - p.inertia_kg_m2 * w * w;
    let amp = p.damper_arm_m * m1 / (re * re + (ca2 * w).powi(2)).sqrt();
    // Trapezoidal rule: frequency error O((W h)^2 / 12) = 5e-5 at 256 steps/rev.
    assert!(
        (hd[1].amplitude - amp).abs() < 1e-3 * amp,
        "{} vs {amp}",
        hd[1].amplitude
    );
    let phase = ca2 * w;
    let expect_deg = phase.atan2(re).to_degrees();
    assert!(
        (hd[1].phase_deg - expect_deg).abs() < 0.1,
        "{} vs {expect_deg}",
        hd[1].phase_deg
    );
    // Damper force of the linear dashpot: -c times the stroke rate (docs/formats.md sign).
    let f = run.channel("damper_force_N").unwrap();
    let hf = harmonics(&run.azimuth_deg, f, 2).unwrap();
    assert!((hf[1].amplitude - 68000.0 * w * amp).abs() < 1e-3 * hf[1].amplitude);
}

#[test]
fn a_failed_model_is_reported_and_the_others_are_written() {
    // RK4 with one sub-step per structural step is beyond the explicit stability limit of the
    // physical damper's oil column: that model fails, the dashpots do not need sub-steps.
    let out = tmp("failed");
    let o = run_sdof(&example(), &out, &["--revs", "2", "--substeps", "1"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("physical") && e.contains("revolution 1"), "{e}");
    let marker = std::fs::read_to_string(out.join("INCOMPLETE")).unwrap();
    assert!(marker.contains("physical"), "{marker}");
    let s = summary(&out);
    assert_eq!(s["models"]["physical"]["status"], "failed");
    assert!(s["models"]["physical"]["error"]
        .as_str()
        .unwrap()
        .contains("t = "));
    for m in ["linear", "nonlinear"] {
        assert_eq!(s["models"][m]["status"], "ok");
        assert!(out.join(m).join("last_rev.csv").exists());
    }
    assert!(!out.join("physical").exists());
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("physical model FAILED"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn short_run_of_the_uh60a_rotor_with_the_three_dampers() {
    // The real rotor model (src/rotor), 2 revolutions at 128 steps (50 RK4 sub-steps keep the
    // physical damper's sub-step at the 256 x 25 value): the pipeline end to end on it.
    let out = tmp("uh60a");
    let rotor = repo().join("rotors/uh60a.toml");
    let o = rotorsim(&[
        "run",
        "--rotor",
        rotor.to_str().unwrap(),
        "--flight",
        example().to_str().unwrap(),
        "--revs",
        "2",
        "--periodic",
        "march",
        "--steps-per-rev",
        "128",
        "--substeps",
        "50",
        "--out",
        out.to_str().unwrap(),
    ]);
    ok(&o);
    let s = summary(&out);
    assert_eq!(s["rotor_model"], "UH-60A multibody rotor");
    for m in ["linear", "nonlinear", "physical"] {
        let j = &s["models"][m];
        assert_eq!(j["status"], "ok", "{m}: {j}");
        assert_eq!(j["steps"], 256);
        assert_eq!(j["periodicity"]["history"].as_array().unwrap().len(), 2);
        assert!(j["metrics"]["rms_error_N"].as_f64().unwrap().is_finite());
        // The damper works against the lag motion: force and stroke rate are anti-correlated.
        let (h, cols) = read_csv(&out.join(m).join("last_rev.csv"));
        assert_eq!(cols[0].len(), 128);
        let col = |name: &str| &cols[h.iter().position(|c| c == name).unwrap()];
        let (f, v) = (col("damper_force_N"), col("damper_stroke_rate_m_s"));
        let fv: f64 = f.iter().zip(v).map(|(a, b)| a * b).sum();
        assert!(fv < 0.0, "{m}: damper force does positive work");
        // Blade loads (docs/loads.md): the channels in last_rev.csv and summary.json, the
        // equilibrium check met, and the 4-blade hub loads free of non-multiples of 4/rev.
        for want in [
            "flap_moment_r0.50_Nm",
            "chord_moment_r0.50_Nm",
            "torsion_moment_r0.50_Nm",
            "shear_flap_r0.50_N",
            "shear_chord_r0.50_N",
            "axial_force_r0.50_N",
            "flap_moment_r0.05_Nm",
            "torsion_moment_r0.07_Nm",
            "flap_moment_unpitched_r0.05_Nm",
            "chord_moment_unpitched_r0.50_Nm",
            "shear_flap_unpitched_r0.50_N",
            "shear_chord_unpitched_r0.50_N",
            "lag_hinge_moment_Nm",
            "flap_hinge_moment_Nm",
            "pitch_bearing_moment_Nm",
            "pitch_link_force_N",
            "root_fx_N",
            "root_mz_Nm",
            "hub_fz_fixed_N",
            "hub_mz_fixed_Nm",
        ] {
            assert!(
                h.iter().any(|c| c == want),
                "{m}: no {want} in last_rev.csv"
            );
            assert!(
                j["loads"]["channels"][want]["harmonics"]
                    .as_array()
                    .unwrap()
                    .len()
                    == 11,
                "{m}: {want} in summary.json"
            );
        }
        assert!(!h.iter().any(|c| c.starts_with("check_")), "{m}");
        let eq = &j["loads"]["equilibrium_check"];
        assert_eq!(eq["passed"], true, "{m}: {eq}");
        assert!(eq["max_rel_error"].as_f64().unwrap() < 5e-3, "{m}: {eq}");
        for ch in [
            "hub_fx_fixed_N",
            "hub_fy_fixed_N",
            "hub_fz_fixed_N",
            "hub_mx_fixed_Nm",
            "hub_my_fixed_Nm",
            "hub_mz_fixed_Nm",
        ] {
            let hs = j["loads"]["channels"][ch]["harmonics"].as_array().unwrap();
            let amp = |x: &Value| x["amplitude"].as_f64().unwrap();
            let big = hs.iter().map(amp).fold(0.0, f64::max);
            for x in hs {
                let n = x["n_per_rev"].as_u64().unwrap();
                if n % 4 != 0 {
                    assert!(
                        amp(x) < 1e-9 * big,
                        "{m} {ch}: {n}/rev amplitude {} of {big}",
                        amp(x)
                    );
                }
            }
        }
        // The blade moves: tip flap and lag are not zero.
        for ch in ["tip_flap_m", "tip_lag_m"] {
            let i = h.iter().position(|x| x == ch).unwrap();
            assert!(cols[i].iter().any(|x| x.abs() > 1e-4), "{m} {ch}");
        }
    }
    let (h, _) = read_csv(&out.join("physical/last_rev.csv"));
    for want in [
        "p0_Pa",
        "p1_Pa",
        "q_orifice_m3_s",
        "x_valve0_m",
        "q_valve1_m3_s",
    ] {
        assert!(h.iter().any(|x| x == want), "{want} missing from {h:?}");
    }
    assert!(!std::fs::read_to_string(out.join("report.html"))
        .unwrap()
        .contains("TEST DOUBLE"));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_run_that_is_not_periodic_says_so_and_fails_only_when_asked() {
    // Three revolutions are too few for the 1e-4 tolerance by either method.
    for method in ["march", "shooting"] {
        let out = tmp(&format!("notperiodic_{method}"));
        let o = run_sdof(
            &example(),
            &out,
            &["--revs", "3", "--damper", "linear", "--periodic", method],
        );
        ok(&o);
        let s = summary(&out);
        let p = &s["models"]["linear"]["periodic"];
        assert_eq!(p["converged"], false, "{method}: {p}");
        assert!(p["residual"].as_f64().unwrap() > 1e-4, "{method}: {p}");
        assert!(
            p["message"].as_str().unwrap().contains("not"),
            "{method}: {p}"
        );
        // the best revolution is kept: its state can start the next run
        assert!(out.join("linear/periodic_state.json").exists());
        let html = std::fs::read_to_string(out.join("report.html")).unwrap();
        // the red banner heads the report, before the verdict box
        let banner = html
            .find("<div class=\"banner bad\">NOT periodic: linear")
            .unwrap_or_else(|| panic!("{method}: no NOT periodic banner"));
        assert!(
            html.find("Closest to").is_none_or(|v| banner < v),
            "{method}"
        );
        // and the printed end of the run says so beside the verdict
        assert!(
            String::from_utf8_lossy(&o.stdout).contains("caution: NOT periodic: linear"),
            "{method}: {}",
            String::from_utf8_lossy(&o.stdout)
        );

        let o = run_sdof(
            &example(),
            &out,
            &[
                "--revs",
                "3",
                "--damper",
                "linear",
                "--periodic",
                method,
                "--require-periodic",
            ],
        );
        assert!(!o.status.success(), "{method}: --require-periodic");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains("not periodic (--require-periodic)"), "{e}");
        // the results are still written, complete
        assert_eq!(summary(&out)["models"]["linear"]["status"], "ok");
        assert!(!out.join("INCOMPLETE").exists());
        let _ = std::fs::remove_dir_all(&out);
    }
    // a run that reaches the periodic solution passes with the flag
    let out = tmp("periodic_required");
    let o = run_sdof(
        &example(),
        &out,
        &["--damper", "linear", "--require-periodic"],
    );
    ok(&o);
    assert_eq!(
        summary(&out)["models"]["linear"]["periodic"]["converged"],
        true
    );
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn last_rev_joins_the_record_and_all_revs_holds_every_revolution() {
    // last_rev.csv: time_s, azimuths exactly k 360/N, the record's revolution-averaged force
    // and stroke on them (averaged here from the record's own CSV); --write-all-revs: every
    // revolution, the last one being the reported revolution.
    let out = tmp("last-rev-join");
    ok(&run_sdof(
        &example(),
        &out,
        &["--damper", "linear", "--write-all-revs"],
    ));
    let (h, c) = read_csv(&out.join("linear/last_rev.csv"));
    assert_eq!(
        &h[..4],
        [
            "time_s",
            "azimuth_deg",
            "measured_damper_force_N",
            "measured_damper_stroke_m"
        ]
    );
    let n = c[0].len();
    assert_eq!(n, 256);
    let (rh, rec) = read_csv(&repo().join("flightdata/c8534like.damper.csv"));
    let col = |name: &str| &rec[rh.iter().position(|c| c == name).unwrap()];
    let (ra, rf, rd) = (
        col("azimuth_deg"),
        col("damper_force_N"),
        col("damper_stroke_m"),
    );
    let period = summary(&out)["models"]["linear"]["period_s"]
        .as_f64()
        .unwrap();
    for k in 0..n {
        assert_eq!(c[1][k], k as f64 * 360.0 / n as f64, "row {k}");
        if k > 0 {
            assert!((c[0][k] - c[0][k - 1] - period / n as f64).abs() < 1e-12);
        }
        let same: Vec<usize> = (0..ra.len())
            .filter(|&i| (ra[i] - c[1][k]).abs() < 1e-6)
            .collect();
        assert!(!same.is_empty(), "the record has azimuth {}", c[1][k]);
        let avg = |v: &[f64]| same.iter().map(|&i| v[i]).sum::<f64>() / same.len() as f64;
        assert!((c[2][k] - avg(rf)).abs() <= 1e-9 * avg(rf).abs(), "row {k}");
        assert!((c[3][k] - avg(rd)).abs() <= 1e-9 * avg(rd).abs(), "row {k}");
    }
    let (ah, all) = read_csv(&out.join("linear/all_revs.csv"));
    assert_eq!(
        &ah[..4],
        ["revolution", "shooting_iterate", "time_s", "azimuth_deg"]
    );
    assert_eq!(all[0].len() % n, 0);
    let revs = all[0].len() / n;
    assert!(revs >= 2, "{revs}");
    let f_all = &all[ah.iter().position(|c| c == "damper_force_N").unwrap()];
    let f_last = &c[h.iter().position(|c| c == "damper_force_N").unwrap()];
    for j in 0..n {
        let i = (revs - 1) * n + j;
        assert_eq!(all[0][i], revs as f64);
        assert_eq!(all[3][i], c[1][j]);
        assert_eq!(all[2][i], c[0][j]);
        assert_eq!(f_all[i], f_last[j], "sample {j}");
    }
    let _ = std::fs::remove_dir_all(&out);
}
