//! UH-60A rotor forced response: the model builds with each damper model, runs two
//! revolutions under the shipped flight record, and the damper coupling obeys its conventions
//! (docs/formats.md: stroke positive in extension, force positive pushing the ends apart).
//! Run: `cargo test --release --test rotor_model`.
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::sim::{build_sim, relief_limits, RotorSim};
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions, BASE_CHANNELS};
use std::path::PathBuf;
mod support;

fn repo(p: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(p)
}

struct Run {
    sim: RotorSim,
    /// Per step: channels, lag angle [rad].
    rows: Vec<(Vec<f64>, f64)>,
}

fn run(model: DamperModel, revs: usize, spr: usize) -> Run {
    let deck = RotorDeck::from_file(&repo("rotors/uh60a.toml")).unwrap();
    let damper = deck.damper().unwrap();
    let rec = FlightRecord::read(&repo("flightdata/c8534like.meta.json")).unwrap();
    let opts = RunOptions {
        steps_per_rev: spr,
        ..Default::default()
    };
    let mut sim = build_sim(&deck.spec, &deck.path, &damper, model, &rec, &opts).unwrap();
    let n = sim.channel_names().len();
    let mut rows = vec![];
    for _ in 0..revs * spr {
        sim.step().unwrap();
        let mut ch = vec![0.0; n];
        sim.channels(&mut ch);
        rows.push((ch, sim.lag_angle_rad()));
    }
    Run { sim, rows }
}

/// Exact stroke of the attachment geometry for a lag angle z (aft positive): the blade end sits
/// at `arm` from the lag axis, the damper line is radial with length l0 at zero lag.
fn exact_stroke(arm: f64, l0: f64, z: f64) -> f64 {
    ((l0 + arm * z.sin()).powi(2) + (arm * z.cos() - arm).powi(2)).sqrt() - l0
}

fn check_common(r: &Run, label: &str) {
    let deck = RotorDeck::from_file(&repo("rotors/uh60a.toml")).unwrap();
    let arm = deck.spec.damper_attachment.arm_m;
    let l0 = deck.spec.damper_attachment.reference_length_m;
    assert_eq!(r.sim.label(), label);
    assert_eq!(
        &r.sim.channel_names()[..6],
        &BASE_CHANNELS.map(String::from)[..]
    );
    let period = r.sim.period_s();
    assert!((period - 2.0 * std::f64::consts::PI / 27.0).abs() < 1e-12);
    assert!((r.sim.azimuth_deg() - 720.0).abs() < 1e-6);
    let mut max_lag: f64 = 0.0;
    for (ch, lag) in &r.rows {
        assert!(ch.iter().all(|v| v.is_finite()));
        // stroke = arm x lag angle, lag aft lengthens the damper; the geometric stroke of the
        // hinge lag alone is `exact_stroke`, the rest (~3e-5 m) is the elastic stretch and
        // bending of the hub arm (segment 1) under the centrifugal force and lag moment
        let d = ch[1];
        let g = exact_stroke(arm, l0, *lag);
        assert!(d * lag > 0.0, "{label}: stroke {d} vs lag {lag}");
        assert!((d - g).abs() < 5e-5, "{label}: stroke {d} vs geometry {g}");
        assert!((d - arm * lag).abs() < 0.01 * (arm * lag).abs() + 1e-6);
        // tip lag (aft, hub frame) has the sign of the hinge lag angle and roughly its size
        let tip_lag = ch[4];
        let rigid = (8.1786 - 0.381) * lag;
        assert!(
            tip_lag * lag > 0.0,
            "{label}: tip lag {tip_lag} vs hinge lag {lag}"
        );
        assert!((tip_lag - rigid).abs() < 0.25 * rigid.abs());
        max_lag = max_lag.max(lag.abs());
    }
    // mean lag aft of a few degrees (drag against the lag spring and centrifugal stiffness)
    assert!(max_lag > 0.01 && max_lag < 0.2, "{label}: lag {max_lag}");
    let t = r.sim.timing();
    assert_eq!(t.steps, r.rows.len());
    assert!(t.iterations >= t.steps && t.total_s > 0.0);
}

#[test]
fn uh60a_linear_damper_two_revolutions() {
    let r = run(DamperModel::Linear, 2, 256);
    check_common(&r, "linear");
    let c = RotorDeck::from_file(&repo("rotors/uh60a.toml"))
        .unwrap()
        .damper()
        .unwrap()
        .linear_c_n_s_per_m
        .unwrap();
    let mut fmax: f64 = 0.0;
    for (ch, _) in &r.rows {
        // F = -c d_dot (docs/formats.md: a damper resists the motion)
        assert!((ch[0] + c * ch[2]).abs() <= 1e-9 * (c * ch[2]).abs() + 1e-9);
        fmax = fmax.max(ch[0].abs());
    }
    assert!(fmax > 100.0, "damper force stays below {fmax} N");
    assert_eq!(r.sim.force_limits_n(), None);
}

#[test]
fn uh60a_nonlinear_damper_two_revolutions() {
    let r = run(DamperModel::Nonlinear, 2, 256);
    check_common(&r, "nonlinear");
    for (ch, _) in &r.rows {
        if ch[2].abs() > 1e-3 {
            assert!(ch[0] * ch[2] < 0.0, "force {} at rate {}", ch[0], ch[2]);
        }
    }
}

#[test]
fn uh60a_physical_damper_two_revolutions() {
    let r = run(DamperModel::Physical, 2, 256);
    check_common(&r, "physical");
    let names = r.sim.channel_names();
    for c in support::PHYSICAL_CHANNELS {
        assert!(names.iter().any(|n| n == c), "missing channel {c}");
    }
    let ip0 = names.iter().position(|n| n == "p0_Pa").unwrap();
    let ip1 = names.iter().position(|n| n == "p1_Pa").unwrap();
    let deck = RotorDeck::from_file(&repo("rotors/uh60a.toml"))
        .unwrap()
        .damper()
        .unwrap();
    let p = deck.physical.clone().unwrap();
    // the force channel is Eq. (8) of the chamber pressures
    for (ch, _) in &r.rows {
        let f8 = ch[ip0] * p.chambers[0].area - ch[ip1] * p.chambers[1].area;
        assert!((ch[0] - f8).abs() < 1e-6 * (1.0 + f8.abs()));
    }
    // resists the motion: force and stroke rate anti-correlated over the run
    let n = r.rows.len() as f64;
    let (mf, mv) = r
        .rows
        .iter()
        .fold((0.0, 0.0), |a, (c, _)| (a.0 + c[0] / n, a.1 + c[2] / n));
    let (mut sfv, mut sff, mut svv) = (0.0, 0.0, 0.0);
    for (c, _) in &r.rows {
        sfv += (c[0] - mf) * (c[2] - mv);
        sff += (c[0] - mf).powi(2);
        svv += (c[2] - mv).powi(2);
    }
    let corr = sfv / (sff * svv).sqrt();
    assert!(corr < -0.5, "force/rate correlation {corr}");
    // relief limits from the cracking pressures (+/-3200 lb class for the shipped deck)
    let (lo, hi) = r.sim.force_limits_n().unwrap();
    assert_eq!(Some((lo, hi)), relief_limits(&deck));
    assert!(hi > 13000.0 && hi < 15500.0 && lo < -13000.0 && lo > -15500.0);
    let t = r.sim.timing();
    assert!(t.hydraulics_s > 0.0 && t.hydraulics_s < t.total_s);
}

#[test]
fn rotor_deck_unknown_key_names_file_line_key() {
    let text = std::fs::read_to_string(repo("rotors/uh60a.toml"))
        .unwrap()
        .replace("arm_m = 0.175", "arm_m = 0.175\narm_lenght_m = 0.2");
    let e = rotorsim::rotor::deck::RotorSpec::parse(&text, "x/uh60a.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("x/uh60a.toml"), "{e}");
    assert!(e.contains("arm_lenght_m"), "{e}");
    assert!(e.contains("line"), "{e}");
}

#[test]
fn outputs_table_is_checked_and_names_the_key() {
    let base = std::fs::read_to_string(repo("rotors/uh60a.toml")).unwrap();
    let parse = |extra: &str| {
        rotorsim::rotor::deck::RotorSpec::parse(&format!("{base}\n{extra}"), "x/uh60a.toml")
    };
    // the default stations: r/R 0.1 .. 0.9, the bearing and the horn
    let spec = parse("").unwrap();
    let st: Vec<f64> = spec.load_stations().iter().map(|s| s.1).collect();
    assert_eq!(st.len(), 11);
    assert!((st[0] - 0.381 / 8.1786).abs() < 1e-12 && (st[10] - 0.9).abs() < 1e-12);
    for (extra, key, what) in [
        (
            "[outputs]\nstations_r_over_R = [0.5, 1.2]",
            "outputs.stations_r_over_R",
            "1.2",
        ),
        (
            "[outputs]\nstations_r_over_R = [0.5, 0.501]",
            "outputs.stations_r_over_R",
            "same r/R",
        ),
        (
            "[outputs]\nsection_channels = [\"flap_momnet\"]",
            "outputs.section_channels",
            "flap_momnet",
        ),
        ("[outputs]\nstation = [0.5]", "station", "unknown"),
    ] {
        let e = parse(extra).unwrap_err().to_string();
        assert!(
            e.contains("x/uh60a.toml") && e.contains(key) && e.contains(what),
            "{extra}: {e}"
        );
    }
}

#[test]
fn expand_prints_a_model_deck_that_loads_back() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(["expand", "--rotor"])
        .arg(repo("rotors/uh60a.toml"))
        .arg("--flight")
        .arg(repo("flightdata/c8534like.meta.json"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    // paths in the expanded deck are relative to the rotor deck's folder
    let (deck, mut model) =
        rotorsim::structure::deck::parse_deck(&text, "expanded.toml", &repo("rotors")).unwrap();
    // 13 + 3 + 2 + 2 + 3 cubic elements
    let beams = |n: &str| model.beams.get(n).map(|v| v.len()).unwrap_or(0);
    assert_eq!(
        [
            beams("blade"),
            beams("seg1"),
            beams("seg2"),
            beams("seg3"),
            beams("pitch_link")
        ],
        [13, 3, 2, 2, 3]
    );
    // the damper as a [[hydraulic]] element reading the rotor deck's [damper] table
    assert_eq!(deck.hydraulic_probes.len(), 1);
    assert_eq!(model.step_elements.len(), 1);
    // bearing: lag, flap, pitch revolute joints at the hinge, each an elastomer whose storage
    // stiffness at its reference frequency is the deck's stiffness (no separate spring)
    use rotorsim::rotor::deck::BearingAxis;
    let spec = RotorDeck::from_file(&repo("rotors/uh60a.toml"))
        .unwrap()
        .spec;
    let om = spec.rotor.omega_rad_s;
    for (name, axis, k) in [
        ("lag", BearingAxis::Lag, spec.bearing.lag_k),
        ("flap", BearingAxis::Flap, spec.bearing.flap_k),
        ("pitch", BearingAxis::Pitch, spec.bearing.pitch_k),
    ] {
        let id = model.element_id(name).unwrap();
        match &model.elements[id] {
            rotorsim::structure::Element::Joint(j) => {
                assert_eq!(j.kind, rotorsim::structure::JointKind::Revolute);
                assert_eq!(j.spring_nm_per_rad, 0.0);
                let w = spec.bearing.elastomer(axis, om).unwrap().reference_rad_s;
                let e = j.elastomer.as_ref().expect("an elastomer");
                let storage = e.chain.complex(w).0;
                // the printed deck's numbers, read back
                assert!((storage / k - 1.0).abs() < 1e-9, "{name}: {storage} vs {k}");
            }
            _ => panic!("{name} is not a joint"),
        }
    }
    // a consistent, non-redundant constraint set
    let st = rotorsim::solver::State::from_model(&model);
    rotorsim::solver::statics::check_constraints(&mut model, &st).unwrap();
    // the swashplate law at t = 0: collective only (cyclic ramps in), z = horn_y sin(th0)
    let th0 = 11.4584f64.to_radians();
    assert!(
        (spec.swash_z(spec.pitch_rad(
            &rotorsim::rotor::expand::Controls {
                th0_deg: 11.4584,
                th1c_deg: 1.806,
                th1s_deg: -7.8657
            },
            0.0
        )) - 0.2 * th0.sin())
        .abs()
            < 1e-12
    );
}

#[test]
fn soft_flap_and_pitch_bearings_reach_their_rotating_equilibrium() {
    // The bearing's flap and pitch springs at an elastomer's relaxed stiffness (16177 and 1586
    // N m/rad) without dampers: full Newton from the undeformed rotor overshoots (its
    // corrections reach 6 rad and the residual 1e41 within 25 iterations), so the rotating
    // equilibrium needs the static solver's damped retry. The model builds and steps.
    let sets: Vec<rotorsim::overrides::Override> = [
        "bearing.flap_stiffness_Nm_per_rad=16177",
        "bearing.flap_damping_Nms_per_rad=0",
        "bearing.pitch_stiffness_Nm_per_rad=1586",
        "bearing.pitch_damping_Nms_per_rad=0",
    ]
    .iter()
    .map(|s| rotorsim::overrides::Override::parse(s).unwrap())
    .collect();
    let deck = RotorDeck::from_file_with(&repo("rotors/uh60a.toml"), &sets).unwrap();
    let damper = deck.damper().unwrap();
    let rec = FlightRecord::read(&repo("flightdata/c8534like.meta.json")).unwrap();
    let mut sim = build_sim(
        &deck.spec,
        &deck.path,
        &damper,
        DamperModel::Linear,
        &rec,
        &RunOptions::default(),
    )
    .unwrap();
    let names = sim.channel_names();
    let flap = names.iter().position(|c| c == "flap_hinge_rad").unwrap();
    let mut v = vec![0.0; names.len()];
    for _ in 0..64 {
        sim.step().unwrap();
    }
    sim.channels(&mut v);
    // a few degrees of flap up under the centrifugal field and the collective's lift, as with
    // the deck's own springs
    assert!(v[flap] > 0.01 && v[flap] < 0.2, "flap {} rad", v[flap]);
}
