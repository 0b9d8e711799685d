//! Load channels in their documented frames (docs/loads.md): the section loads in the
//! unpitched blade frame against the deformed section frame, and the moments the bearing's
//! three joints carry about their axes against the deck's springs and dampers and against the
//! section loads at the bearing.
//! Run: `cargo test --release --test load_frames`.
mod support;

use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::loads::{element_at, section};
use rotorsim::rotor::deck::RotorSpec;
use rotorsim::rotor::expand::ExpandOptions;
use rotorsim::rotor::loads::{DamperStep, LoadChannels};
use rotorsim::rotor::sim::{build_sim, expanded_model};
use rotorsim::rotor::{ForcedResponse, RotorDeck, RunOptions};
use rotorsim::solver::State;
use rotorsim::structure::kin::EvalCtx;
use rotorsim::structure::model::Model;
use rotorsim::structure::rotation::{
    cross, dot, exp_map, log_map, mm, mtm, mv, norm3, quat_to_arr, sub, update_left,
};

fn deck() -> RotorDeck {
    RotorDeck::from_file(&support::root().join("rotors/uh60a.toml")).unwrap()
}

/// The shipped deck with its bearing's axes springs and dashpots instead of elastomers (the
/// deck's former 272 N m s/rad on each): a moment law `k psi + c psi'` to check against.
fn dashpot_deck() -> RotorDeck {
    let mut d = deck();
    let b = &mut d.spec.bearing;
    (b.lag_loss_factor, b.flap_loss_factor, b.pitch_loss_factor) = (None, None, None);
    (b.lag_c, b.flap_c, b.pitch_c) = (272.0, 272.0, 272.0);
    d
}

/// Channel values by name.
struct Channels {
    names: Vec<String>,
    values: Vec<f64>,
}

impl Channels {
    fn get(&self, name: &str) -> f64 {
        let i = self
            .names
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no channel {name} in {:?}", self.names));
        self.values[i]
    }
}

/// Every load channel of the blade at state `st`.
fn channels(spec: &RotorSpec, m: &Model, st: &State) -> Channels {
    let lc = LoadChannels::new(spec, m).unwrap();
    let nodes = [
        m.node_id("damper_hub_end").unwrap(),
        m.node_id("damper_blade_end").unwrap(),
    ];
    let damper = DamperStep {
        nodes,
        x_start: nodes.map(|n| st.x[n]),
        force_n: 0.0,
    };
    let mut values = vec![f64::NAN; lc.names().len()];
    lc.values(m, st, &damper, &mut values).unwrap();
    Channels {
        names: lc.names().to_vec(),
        values,
    }
}

/// The `[outputs]` station names (r/R to two decimals) of `spec`.
fn stations(spec: &RotorSpec) -> Vec<String> {
    spec.load_stations()
        .iter()
        .map(|(_, x)| format!("{x:.2}"))
        .collect()
}

/// The blade turned as a rigid body about the bearing's centre: lag `zeta` (about -z), flap
/// `beta` (about -y), pitch `theta` (about +x), in that order from the hub, each joint's
/// outboard nodes by the turns inboard of it; the hub and the retention's first segment
/// stay. Rotating at the rotor speed under gravity, so that the elements carry loads.
fn turned(spec: &RotorSpec, m: &mut Model, zeta: f64, beta: f64, theta: f64) -> State {
    m.gravity = [0.0, 0.0, -9.81];
    let mut st = State::from_model(m);
    let p = [spec.retention.hinge_r_m, 0.0, 0.0];
    let rl = exp_map([0.0, 0.0, -zeta]);
    let rf = mm(&rl, &exp_map([0.0, -beta, 0.0]));
    let rp = mm(&rf, &exp_map([theta, 0.0, 0.0]));
    for (i, node) in m.nodes.iter().enumerate() {
        let n = node.name.as_str();
        let turns: &[[f64; 3]] = if n == "bearing_lag" || n == "damper_blade_end" {
            &[[0.0, 0.0, -zeta]]
        } else if n == "bearing_flap" {
            &[[0.0, -beta, 0.0], [0.0, 0.0, -zeta]]
        } else if n.starts_with("seg2.") || n.starts_with("seg3.") || n.starts_with("blade.") {
            &[[theta, 0.0, 0.0], [0.0, -beta, 0.0], [0.0, 0.0, -zeta]]
        } else {
            continue;
        };
        let r = match turns.len() {
            1 => rl,
            2 => rf,
            _ => rp,
        };
        for t in turns {
            st.q[i] = update_left(&st.q[i], *t);
        }
        st.x[i] = rotorsim::structure::rotation::add(p, mv(&r, sub(st.x[i], p)));
    }
    st.set_rigid_rotation([0.0; 3], [0.0, 0.0, spec.rotor.omega_rad_s]);
    st
}

/// The UH-60A deck without built-in twist and its model at zero controls.
fn untwisted() -> (RotorSpec, Model) {
    let d = deck();
    let mut spec = d.spec.clone();
    spec.blade.twist_deg.clear();
    let m = expanded_model(&spec, &ExpandOptions::default(), &d.path).unwrap();
    (spec, m)
}

const PAIRS: [(&str, &str, &str); 2] = [
    ("flap_moment", "chord_moment", "Nm"),
    ("shear_flap", "shear_chord", "N"),
];

#[test]
fn at_zero_pitch_without_twist_the_unpitched_frame_is_the_section_frame() {
    // Lagged and flapped but not pitched, no built-in twist: every section's second axis
    // lies in the hub plane, so the two frames coincide; the loads are those of a blade
    // turning under gravity (nonzero), and they match to round-off.
    let (spec, mut m) = untwisted();
    let st = turned(&spec, &mut m, 3f64.to_radians(), 5f64.to_radians(), 0.0);
    let c = channels(&spec, &m, &st);
    let mut worst: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for x in stations(&spec) {
        for (a, b, unit) in PAIRS {
            for kind in [a, b] {
                let sec = c.get(&format!("{kind}_r{x}_{unit}"));
                let unp = c.get(&format!("{kind}_unpitched_r{x}_{unit}"));
                scale = scale.max(sec.abs());
                worst = worst.max((sec - unp).abs() / sec.abs().max(1.0));
            }
        }
    }
    eprintln!("zero pitch: largest difference {worst:.2e} (relative), largest load {scale:.3e}");
    assert!(scale > 1e3, "the sections carry loads ({scale})");
    assert!(worst < 1e-12, "{worst:e}");
}

#[test]
fn the_unpitched_pair_is_the_section_pair_turned_back_by_the_pitch() {
    // Pitched nose up by theta = 12 deg at the bearing (and lagged, flapped), no built-in
    // twist: every section is pitched by theta, so (flap, chord) in the unpitched frame is the
    // section pair turned by theta: flap_u = cos flap + sin chord, chord_u = cos chord - sin
    // flap (flap = -M.e2, chord = M.e3), the same for (shear_flap, shear_chord) with
    // shear_flap_u = sin shear_chord + cos shear_flap, shear_chord_u = cos shear_chord - sin
    // shear_flap. Torsion and axial force are written in one frame only.
    let (spec, mut m) = untwisted();
    let theta = 12f64.to_radians();
    let st = turned(&spec, &mut m, 3f64.to_radians(), 5f64.to_radians(), theta);
    let c = channels(&spec, &m, &st);
    let (s, co) = theta.sin_cos();
    let mut worst: f64 = 0.0;
    let mut mixed: f64 = 0.0;
    for x in stations(&spec) {
        let get = |k: &str, u: &str, unp: bool| {
            c.get(&if unp {
                format!("{k}_unpitched_r{x}_{u}")
            } else {
                format!("{k}_r{x}_{u}")
            })
        };
        for (a, b, u) in PAIRS {
            let (fa, fb) = (get(a, u, false), get(b, u, false));
            let (ua, ub) = (get(a, u, true), get(b, u, true));
            let (wa, wb) = (co * fa + s * fb, co * fb - s * fa);
            let big = fa.hypot(fb);
            worst = worst.max((ua - wa).abs().max((ub - wb).abs()) / big);
            mixed = mixed.max((ua - fa).abs() / big);
        }
        assert!(
            !c.names
                .iter()
                .any(|n| n.starts_with("torsion_moment_unpitched")
                    || n.starts_with("axial_force_unpitched")),
            "torsion and axial force are the same in both frames"
        );
    }
    eprintln!("pitch 12 deg: largest error of the turned pair {worst:.2e} of the pair's size; the frames differ by up to {mixed:.2e}");
    assert!(worst < 1e-9, "{worst:e}");
    // and the turn is not nothing: at 12 deg the frames differ by about sin(12 deg)
    assert!(mixed > 0.05, "{mixed}");
}

#[test]
fn the_unpitched_frame_is_built_from_the_section_axis_and_the_shaft() {
    // The shipped deck with its built-in twist, pitched 10 deg and lagged and flapped: the
    // unpitched components are the load vector's on e1, e2' = (z x e1)/|z x e1| (in the hub
    // plane, toward the leading edge), e3' = e1 x e2' -- a construction by cross products,
    // independent of the angle the code turns by -- whatever the twist at the station.
    let d = deck();
    let spec = d.spec.clone();
    let mut m = expanded_model(&spec, &ExpandOptions::default(), &d.path).unwrap();
    let st = turned(
        &spec,
        &mut m,
        2f64.to_radians(),
        4f64.to_radians(),
        10f64.to_radians(),
    );
    let c = channels(&spec, &m, &st);
    let ctx = EvalCtx {
        t: st.t,
        load_factor: 1.0,
        gravity: m.gravity,
        cscale: 1.0,
        inertia: true,
        dt: 0.0,
    };
    let r = &spec.retention;
    let mut worst: f64 = 0.0;
    let mut twist_seen: f64 = 0.0;
    for (radius, x) in spec.load_stations() {
        let (beam, s) = if radius >= spec.blade.root_r_m {
            ("blade", radius - spec.blade.root_r_m)
        } else if radius >= r.horn_r_m {
            ("seg3", radius - r.horn_r_m)
        } else {
            ("seg2", radius - r.hinge_r_m)
        };
        let e = element_at(&m, &m.beams[beam], s).unwrap();
        let sec = section(&m, &st, &ctx, e, s).unwrap();
        let col = |j: usize| [sec.frame[0][j], sec.frame[1][j], sec.frame[2][j]];
        let (e1, e2) = (col(0), col(1));
        let z = [0.0, 0.0, 1.0];
        let n = cross(z, e1);
        let u2 = n.map(|v| v / norm3(n));
        let u3 = cross(e1, u2);
        // the section's pitch beyond the bearing's: the built-in twist
        twist_seen =
            twist_seen.max((dot(e2, z).atan2(dot(cross(e1, e2), z)) - 10f64.to_radians()).abs());
        let (f, mo) = (sec.load.force, sec.load.moment);
        let want = [
            ("flap_moment", "Nm", -dot(mo, u2)),
            ("chord_moment", "Nm", dot(mo, u3)),
            ("shear_chord", "N", dot(f, u2)),
            ("shear_flap", "N", dot(f, u3)),
        ];
        let fscale = norm3(f);
        let mscale = norm3(mo);
        for (k, u, w) in want {
            let got = c.get(&format!("{k}_unpitched_r{x:.2}_{u}"));
            let sc = if u == "Nm" { mscale } else { fscale };
            worst = worst.max((got - w).abs() / sc);
        }
        // the deformed-frame channels are the same load (same recovery)
        let got = c.get(&format!("flap_moment_r{x:.2}_Nm"));
        assert!((got + dot(mo, e2)).abs() < 1e-12 * mscale, "r/R {x}");
    }
    eprintln!("twisted deck: largest error {worst:.2e} of the load's size; twist beyond the bearing pitch up to {:.2} deg", twist_seen.to_degrees());
    assert!(twist_seen > 1f64.to_radians(), "the deck's twist is seen");
    assert!(worst < 1e-12, "{worst:e}");
}

/// Rotation of node `i` (global).
fn rot(st: &State, i: usize) -> [[f64; 3]; 3] {
    quat_to_arr(&st.q[i])
}

#[test]
fn hinge_moments_are_the_decks_springs_and_dampers_in_motion() {
    // A forced response of the UH-60A rotor (linear damper, shipped record) past its ramp,
    // its bearing springs and dashpots: each bearing joint's moment is k psi + c psi', with k,
    // c the deck's values, psi the
    // reported joint angle and psi' the relative angular velocity of its two nodes about the
    // joint axis (lag -z of the retention's end node, flap -y of `bearing_lag`, pitch +x of
    // `bearing_flap`, their frames at reference being the hub's). The shipped elastomers'
    // moments are checked by their frequency response (below).
    let d = dashpot_deck();
    let damper = d.damper().unwrap();
    let rec = FlightRecord::read(&support::root().join("flightdata/c8534like")).unwrap();
    let mut sim = build_sim(
        &d.spec,
        &d.path,
        &damper,
        DamperModel::Linear,
        &rec,
        &RunOptions::default(),
    )
    .unwrap();
    let names = sim.channel_names();
    let mut v = vec![0.0; names.len()];
    let at = |n: &str| names.iter().position(|c| c == n).unwrap();
    let b = &d.spec.bearing;
    let joints = [
        ("lag", b.lag_k, b.lag_c, [0.0, 0.0, -1.0]),
        ("flap", b.flap_k, b.flap_c, [0.0, -1.0, 0.0]),
        ("pitch", b.pitch_k, b.pitch_c, [1.0, 0.0, 0.0]),
    ];
    let chan = [
        ("lag_hinge_rad", "lag_hinge_moment_Nm"),
        ("flap_hinge_rad", "flap_hinge_moment_Nm"),
        ("pitch_bearing_rad", "pitch_bearing_moment_Nm"),
    ];
    let mut worst: f64 = 0.0;
    let mut damping_share = [0.0f64; 3];
    let mut samples = 0;
    for step in 0..640 {
        sim.step().unwrap();
        if step < 512 || step % 16 != 0 {
            continue;
        }
        sim.channels(&mut v);
        let sol = sim.solver();
        let (m, st) = (&sol.model, &sol.state);
        let n1 = d.spec.retention.segment1.elements * 3;
        let inner = [
            m.node_id(&format!("seg1.n{n1}")).unwrap(),
            m.node_id("bearing_lag").unwrap(),
            m.node_id("bearing_flap").unwrap(),
        ];
        let outer = [inner[1], inner[2], m.node_id("seg2.n0").unwrap()];
        for q in 0..3 {
            let (_, k, c, axis) = joints[q];
            let a = mv(&rot(st, inner[q]), axis);
            let rate = dot(a, sub(st.w[outer[q]], st.w[inner[q]]));
            let psi = v[at(chan[q].0)];
            let want = k * psi + c * rate;
            let got = v[at(chan[q].1)];
            worst = worst.max((got - want).abs() / want.abs().max(1.0));
            damping_share[q] = damping_share[q].max((c * rate / want).abs());
        }
        samples += 1;
    }
    eprintln!(
        "hinge moments: largest relative error {worst:.2e} over {samples} samples; damper part up to {:.2e}, {:.2e}, {:.2e} of the moment",
        damping_share[0], damping_share[1], damping_share[2]
    );
    assert!(samples >= 8);
    assert!(worst < 1e-9, "{worst:e}");
    // the dampers' part is exercised, not only the springs'
    assert!(damping_share.iter().all(|&s| s > 1e-3), "{damping_share:?}");
}

#[test]
fn flap_and_pitch_bearing_moments_balance_the_section_at_the_bearing() {
    // The UH-60A rotor (linear damper, shipped record): first its initial state, the rotating
    // quasi-static equilibrium under the record's mean airloads and the collective, then in
    // motion past the cyclic ramp. The flap and pitch joints' outboard nodes (`bearing_flap`,
    // `seg2.n0`) carry no mass and the section at the bearing lies at the joints' common
    // centre, so the section's moment projected on the flap axis (-y of `bearing_lag`) is the
    // flap joint's moment and on the pitch axis (+x of `bearing_flap`) its torsion, to the
    // Newton tolerance of the solution, at rest and in motion. The unpitched flap moment at
    // the bearing is the flap hinge moment up to the retention's own bending inboard of the lag
    // joint, which turns the flap axis out of the hub plane by at most phi (the rotation of
    // the retention's end node relative to the hub): |difference| <= phi |M|. The bearing springs
    // and dashpots, so that the quasi-static flap moment is the spring's k beta.
    let d = dashpot_deck();
    let spec = d.spec.clone();
    let damper = d.damper().unwrap();
    let rec = FlightRecord::read(&support::root().join("flightdata/c8534like")).unwrap();
    let mut sim = build_sim(
        &spec,
        &d.path,
        &damper,
        DamperModel::Linear,
        &rec,
        &RunOptions::default(),
    )
    .unwrap();
    let names = sim.channel_names();
    let mut v = vec![0.0; names.len()];
    let x = format!("{:.2}", spec.retention.hinge_r_m / spec.rotor.radius_m);
    let n1 = spec.retention.segment1.elements * 3;
    let mut worst = [0.0f64; 4];
    let mut unp_margin = f64::INFINITY;
    let mut deformed_off: f64 = 0.0;
    for step in 0..=576 {
        if step > 0 {
            sim.step().unwrap();
        }
        if step != 0 && (step < 512 || step % 16 != 0) {
            continue;
        }
        sim.channels(&mut v);
        let get = |n: &str| v[names.iter().position(|c| c == n).unwrap()];
        let sol = sim.solver();
        let (m, st) = (&sol.model, &sol.state);
        let ctx = EvalCtx {
            t: st.t,
            load_factor: 1.0,
            gravity: m.gravity,
            cscale: 1.0,
            inertia: true,
            dt: 0.0,
        };
        let e = element_at(m, &m.beams["seg2"], 0.0).unwrap();
        let mo = section(m, st, &ctx, e, 0.0).unwrap().load.moment;
        let big = norm3(mo);
        let a_flap = mv(
            &rot(st, m.node_id("bearing_lag").unwrap()),
            [0.0, -1.0, 0.0],
        );
        let a_pitch = mv(
            &rot(st, m.node_id("bearing_flap").unwrap()),
            [1.0, 0.0, 0.0],
        );
        let flap_hinge = get("flap_hinge_moment_Nm");
        let pitch_bearing = get("pitch_bearing_moment_Nm");
        let errs = [
            (flap_hinge - dot(mo, a_flap)).abs() / big,
            (pitch_bearing - dot(mo, a_pitch)).abs() / big,
            (pitch_bearing - get(&format!("torsion_moment_r{x}_Nm"))).abs() / big,
            0.0,
        ];
        // the retention's bending inboard of the lag joint
        let end = rot(st, m.node_id(&format!("seg1.n{n1}")).unwrap());
        let hub = rot(st, m.node_id("hub").unwrap());
        let phi = norm3(log_map(&mtm(&hub, &end)));
        let unp = get(&format!("flap_moment_unpitched_r{x}_Nm"));
        let e_unp = (flap_hinge - unp).abs();
        let sect = get(&format!("flap_moment_r{x}_Nm"));
        if step == 0 {
            // at rest relative to the hub: the spring alone, k beta
            let beta = get("flap_hinge_rad");
            let e_spring = (flap_hinge - spec.bearing.flap_k * beta).abs() / flap_hinge.abs();
            eprintln!(
                "quasi-static: flap hinge {flap_hinge:.2} N m (beta {:.3} deg, spring alone to {e_spring:.1e}), section-frame flap {sect:.2}, unpitched {unp:.2} (differs by {e_unp:.2e} N m, bound phi |M| = {:.2e}, phi {phi:.1e} rad), |M| {big:.0} N m",
                beta.to_degrees(),
                phi * big
            );
            assert!(beta > 1f64.to_radians(), "the blade flaps up: {beta}");
            assert!(e_spring < 1e-6, "{e_spring:e}");
        }
        for k in 0..3 {
            worst[k] = worst[k].max(errs[k]);
        }
        worst[3] = worst[3].max(e_unp / big);
        unp_margin = unp_margin.min(phi * big - e_unp);
        deformed_off = deformed_off.max((sect - flap_hinge).abs() / big);
    }
    eprintln!(
        "balances (of |M|): flap axis {:.2e}, pitch axis {:.2e}, torsion channel {:.2e}; unpitched flap at the bearing off the flap hinge by up to {:.2e}, the deformed-frame flap by up to {deformed_off:.2e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    // the Newton test of a step, ||r|| <= 1e-9 ||r_0|| with r_0 ~ 1e6 N, leaves joint moments
    // of order 1e-3 N m against |M| ~ 2e3 N m
    for w in &worst[..3] {
        assert!(*w < 1e-6, "{worst:?}");
    }
    assert!(
        unp_margin >= 0.0,
        "unpitched flap outside phi |M| by {}",
        -unp_margin
    );
    // the deformed-frame flap moment mixes in the in-plane moment through the pitch
    assert!(
        deformed_off > 100.0 * worst[3],
        "{deformed_off} vs {}",
        worst[3]
    );
}

#[test]
fn the_bearing_moments_are_the_elastomers_frequency_response() {
    // The periodic solution of the shipped deck with each bearing axis an elastomer (loss
    // factor 0.1, the lag axis's stiffness at its frequency; linear damper): at steady state
    // each harmonic n of an axis's moment is the chain's complex
    // stiffness times that harmonic of its angle, M_n = K*(n Omega) psi_n (docs/structure.md,
    // Elastomer), with K* from the fitted chain's closed form, an independent reference for
    // the time-domain stepping of the branches inside the rotor. The step errs at second
    // order, (n Omega h)^2 / 12 = 5e-5 at 1/rev and 256 steps per revolution, and the
    // revolution is periodic to 1e-5: 1e-3 of the first harmonic's size holds at n = 1 to 3.
    use rotorsim::rotor::deck::BearingAxis;
    use rotorsim::structure::elastomer::MaxwellChain;
    let out = support::tmp("load_frames_elastomer");
    let sets = [
        "bearing.lag_loss_factor=0.1",
        "bearing.flap_loss_factor=0.1",
        "bearing.pitch_loss_factor=0.1",
        "bearing.lag_damping_Nms_per_rad=0",
        "bearing.flap_damping_Nms_per_rad=0",
        "bearing.pitch_damping_Nms_per_rad=0",
        "bearing.lag_reference_per_rev=0.28",
    ];
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(support::root())
        .args(["run", "--damper", "linear"])
        .args(sets.iter().flat_map(|s| ["--set", s]))
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let col = support::csv_columns(&out.join("linear/last_rev.csv"));
    // complex harmonic n of a sampled revolution
    let harmonic = |x: &[f64], n: usize| -> (f64, f64) {
        let len = x.len() as f64;
        x.iter().enumerate().fold((0.0, 0.0), |(re, im), (k, v)| {
            let a = 2.0 * std::f64::consts::PI * (n * k) as f64 / len;
            (re + 2.0 * v * a.cos() / len, im - 2.0 * v * a.sin() / len)
        })
    };
    let overrides: Vec<rotorsim::overrides::Override> = sets
        .iter()
        .map(|s| rotorsim::overrides::Override::parse(s).unwrap())
        .collect();
    let d =
        RotorDeck::from_file_with(&support::root().join("rotors/uh60a.toml"), &overrides).unwrap();
    let om = d.spec.rotor.omega_rad_s;
    let b = &d.spec.bearing;
    for (axis, angle, moment, k) in [
        (
            BearingAxis::Lag,
            "lag_hinge_rad",
            "lag_hinge_moment_Nm",
            b.lag_k,
        ),
        (
            BearingAxis::Flap,
            "flap_hinge_rad",
            "flap_hinge_moment_Nm",
            b.flap_k,
        ),
        (
            BearingAxis::Pitch,
            "pitch_bearing_rad",
            "pitch_bearing_moment_Nm",
            b.pitch_k,
        ),
    ] {
        let e = b.elastomer(axis, om).expect("an elastomeric axis");
        let c = MaxwellChain::fit(
            k,
            e.loss_factor,
            e.band_rad_s[0],
            e.band_rad_s[1],
            e.reference_rad_s,
        )
        .unwrap();
        let (psi, m) = (col(angle), col(moment));
        let size = {
            let (re, im) = harmonic(&m, 1);
            re.hypot(im)
        };
        for n in 1..=3 {
            let (pr, pi) = harmonic(&psi, n);
            let (mr, mi) = harmonic(&m, n);
            let (ks, kl) = c.complex(n as f64 * om);
            let (wr, wi) = (ks * pr - kl * pi, ks * pi + kl * pr);
            let err = (mr - wr).hypot(mi - wi) / size;
            eprintln!(
                "{angle} {n}/rev: |M_n| {:.2} N m, K* psi_n {:.2} N m, error {err:.1e} of |M_1|",
                mr.hypot(mi),
                wr.hypot(wi)
            );
            assert!(err < 1e-3, "{angle} {n}/rev: {err:.2e}");
        }
        // the loss part is there: the moment's 1/rev leads the angle's by atan(eta)
        let (pr, pi) = harmonic(&psi, 1);
        let (mr, mi) = harmonic(&m, 1);
        let lead = (mi * pr - mr * pi).atan2(mr * pr + mi * pi);
        let want = c.loss_factor(om).atan();
        assert!(
            (lead - want).abs() < 0.05 * want,
            "{angle}: lead {lead}, atan(eta) {want}"
        );
    }
    let _ = std::fs::remove_dir_all(out);
}
