//! Example decks parse, and the decks reproduce the programmatic verification results.
use rotorsim::solver::{static_solve, DynamicSolver, State, StaticOptions};
use rotorsim::structure::deck::load_deck;
use rotorsim::structure::*;
use std::path::Path;

fn example(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs/examples")
        .join(name)
}

#[test]
fn all_example_decks_parse() {
    for e in std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/examples")).unwrap()
    {
        let p = e.unwrap().path();
        if p.extension().map(|x| x == "toml").unwrap_or(false) {
            let name = p.display().to_string();
            load_deck(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
}

#[test]
fn bend45_deck_matches_programmatic_model() {
    let (deck, mut m) = load_deck(&example("bend45.toml")).unwrap();
    let mut st = State::from_model(&m);
    let opts = StaticOptions {
        load_steps: deck.statics.load_steps,
        ..Default::default()
    };
    static_solve(&mut m, &mut st, &opts, |_, _, _, _| {}).unwrap();
    let tip = st.x[m.node_id("arc.n24").unwrap()];
    let prog = rotorsim::solver::verification::bend45(8).unwrap()[2].1;
    println!("deck tip {tip:?}, programmatic {prog:?}");
    for k in 0..3 {
        assert!((tip[k] - prog[k]).abs() < 1e-6);
    }
}

#[test]
fn compound_pendulum_on_revolute_and_spherical_joints() {
    // rigid body hanging below a pivot; small-amplitude period 2 pi sqrt(I_O / (m g d))
    for kind in [
        JointKind::Revolute,
        JointKind::Spherical,
        JointKind::Universal,
    ] {
        let mut m = Model::new();
        m.gravity = [0.0, 0.0, -9.81];
        let n = m.add_node("pivot", [0.0; 3], rotation::ident()).unwrap();
        // revolute/spherical: joint z = global y (the swing axis); universal: joint z = global x
        // (the locked relative rotation), swing about y stays free
        let q = if kind == JointKind::Universal {
            [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        } else {
            [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]
        };
        m.add_joint("hinge", kind, None, n, [0.0; 3], q).unwrap();
        let (mass, d, icm) = (3.0, 0.8, 0.2);
        m.add_element(Element::Rigid(RigidBody {
            name: "bob".into(),
            node: n,
            mass_kg: mass,
            cm_offset_m: [0.0, 0.0, -d],
            inertia_kgm2: [[icm, 0.0, 0.0], [0.0, icm, 0.0], [0.0, 0.0, icm]],
        }))
        .unwrap();
        let mut st = State::from_model(&m);
        let amp = 0.01;
        st.w[n] = [0.0, amp, 0.0];
        let io = icm + mass * d * d;
        let period = 2.0 * std::f64::consts::PI * (io / (mass * 9.81 * d)).sqrt();
        let h = period / 200.0;
        let mut s = DynamicSolver::new(m, st, h, 0.9).unwrap();
        let mut prev = 0.0;
        let mut crossings = vec![];
        for _ in 0..800 {
            s.step().unwrap();
            let wy = s.state.w[n][1];
            if prev > 0.0 && wy <= 0.0 || prev < 0.0 && wy >= 0.0 {
                crossings.push(s.state.t - h * wy / (wy - prev));
            }
            prev = wy;
        }
        let nn = crossings.len() - 1;
        let t_num = 2.0 * (crossings[nn] - crossings[0]) / nn as f64;
        let err = (t_num - period).abs() / period;
        println!("{kind:?}: period {t_num:.6} s, theory {period:.6} s, rel {err:.2e}");
        assert!(err < 1e-3, "{kind:?}");
        // the pivot does not move
        assert!(s.state.x[n].iter().all(|v| v.abs() < 1e-12));
    }
}

#[test]
fn actuator_pitches_a_beam_deck_follows_the_rigid_body_estimate() {
    let (deck, m) = load_deck(&example("actuator_pitch_beam_structure_only.toml")).unwrap();
    let st = State::from_model(&m);
    let mut s = DynamicSolver::new(
        m,
        st,
        deck.dynamic.time_step_s.unwrap(),
        deck.dynamic.rho_inf,
    )
    .unwrap();
    let h = s.sensor_header();
    let ia = h.iter().position(|x| x == "R.angle_rad").unwrap();
    let mut ang_1s = 0.0;
    for _ in 0..1000 {
        s.step().unwrap();
        ang_1s = s.sensor_values()[ia];
    }
    // rigid estimate: I_R = 10 * 0.8^2 + 2.4 * 0.8^3 / 3 + horn (2.4 * 0.2 * (0.24^2 + 0.2^2/3)),
    // moment 50 * 0.24 for 0.5 s then reversed: angle at 1 s = alpha * 0.5^2
    let i_r = 10.0 * 0.64 + 2.4 * 0.512 / 3.0 + 2.4 * 0.2 * (0.0576 + 0.04 / 3.0);
    let expect = 12.0 / i_r * 0.25;
    println!("pitch angle at 1 s: {ang_1s:.5} rad, rigid-body estimate {expect:.5} rad");
    assert!((ang_1s.abs() - expect).abs() / expect < 0.05);
}

#[test]
fn revolute_spring_damper_and_prescribed_displacement() {
    // flywheel on a revolute joint with torsional spring k and damper c: free vibration at
    // omega_d = omega_n sqrt(1 - zeta^2), decay exp(-zeta omega_n t)
    let (k, c, j) = (40.0, 0.4, 0.5);
    let mut m = Model::new();
    let n = m.add_node("hub", [0.0; 3], rotation::ident()).unwrap();
    let jid = m
        .add_joint(
            "shaft",
            JointKind::Revolute,
            None,
            n,
            [0.0; 3],
            rotation::ident(),
        )
        .unwrap();
    if let Element::Joint(jj) = &mut m.elements[jid] {
        jj.spring_nm_per_rad = k;
        jj.damper_nms_per_rad = c;
    }
    m.add_element(Element::Rigid(RigidBody {
        name: "wheel".into(),
        node: n,
        mass_kg: 1.0,
        cm_offset_m: [0.0; 3],
        inertia_kgm2: [[0.3, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, j]],
    }))
    .unwrap();
    m.add_sensor("shaft", SensorKind::Joint(jid));
    let mut st = State::from_model(&m);
    st.w[n] = [0.0, 0.0, 1.0];
    let wn = (k / j).sqrt();
    let zeta = c / (2.0 * (k * j).sqrt());
    let wd = wn * (1.0 - zeta * zeta).sqrt();
    let h = 2.0 * std::f64::consts::PI / wd / 400.0;
    let mut s = DynamicSolver::new(m, st, h, 1.0).unwrap();
    let ia = s
        .sensor_header()
        .iter()
        .position(|x| x == "shaft.angle_rad")
        .unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..800 {
        s.step().unwrap();
        let t = s.state.t;
        let exact = (1.0 / wd) * (-zeta * wn * t).exp() * (wd * t).sin();
        worst = worst.max((s.sensor_values()[ia] - exact).abs());
    }
    println!(
        "spring-damper flywheel: max |angle - exact| = {worst:.2e} rad (amplitude {:.3})",
        1.0 / wd
    );
    assert!(worst < 2e-3 * (1.0 / wd));

    // prescribed displacement: a node follows u(t) = (0.1, 0, -0.05) * table(t)
    let mut m = Model::new();
    let n = m.add_node("p", [1.0, 0.0, 0.0], rotation::ident()).unwrap();
    let jid = m
        .add_joint(
            "drive",
            JointKind::Clamp,
            None,
            n,
            [1.0, 0.0, 0.0],
            rotation::ident(),
        )
        .unwrap();
    if let Element::Joint(jj) = &mut m.elements[jid] {
        jj.displacement_m = Some((
            [0.1, 0.0, -0.05],
            TimeTable {
                points: vec![(0.0, 0.0), (1.0, 1.0), (2.0, -1.0)],
            },
        ));
    }
    m.add_element(Element::Rigid(RigidBody {
        name: "b".into(),
        node: n,
        mass_kg: 2.0,
        cm_offset_m: [0.0; 3],
        inertia_kgm2: [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
    }))
    .unwrap();
    let st = State::from_model(&m);
    let mut s = DynamicSolver::new(m, st, 0.01, 0.8).unwrap();
    for _ in 0..150 {
        s.step().unwrap();
    }
    // t = 1.5: factor 0 -> x = 1.0, z = 0
    let x = s.state.x[0];
    assert!((x[0] - 1.0).abs() < 1e-10 && x[2].abs() < 1e-10, "{x:?}");
    for _ in 0..20 {
        s.step().unwrap();
    }
    let x = s.state.x[0];
    // t = 1.7: factor -0.4
    assert!(
        (x[0] - 0.96).abs() < 1e-10 && (x[2] - 0.02).abs() < 1e-10,
        "{x:?}"
    );
}

#[test]
fn consistent_initial_accelerations_and_multipliers_with_constraints() {
    // compound pendulum released from the horizontal: alpha_0 = m g d / I_O, pivot reaction
    // vertical m g (1 - m d^2 / I_O); then energy is conserved with rho_inf = 1
    let mut m = Model::new();
    m.gravity = [0.0, 0.0, -9.81];
    let n = m.add_node("pivot", [0.0; 3], rotation::ident()).unwrap();
    let q = [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]; // joint z = global y
    let jid = m
        .add_joint("hinge", JointKind::Revolute, None, n, [0.0; 3], q)
        .unwrap();
    let (mass, d, icm) = (3.0, 0.8, 0.2);
    m.add_element(Element::Rigid(RigidBody {
        name: "bob".into(),
        node: n,
        mass_kg: mass,
        cm_offset_m: [d, 0.0, 0.0],
        inertia_kgm2: [[icm, 0.0, 0.0], [0.0, icm, 0.0], [0.0, 0.0, icm]],
    }))
    .unwrap();
    m.add_sensor("hinge", SensorKind::Joint(jid));
    let st = State::from_model(&m);
    let io = icm + mass * d * d;
    let mut s = DynamicSolver::new(m, st, 1e-3, 1.0).unwrap();
    s.init_accelerations().unwrap();
    let alpha = s.state.al[n][1];
    // gravity -z on a mass at +x: rotation about +y is positive (x -> -z)
    assert!(
        (alpha - mass * 9.81 * d / io).abs() < 1e-9 * alpha.abs(),
        "{alpha}"
    );
    let h = s.sensor_header();
    let v = s.sensor_values();
    let fz = v[h.iter().position(|x| x == "hinge.fz_N").unwrap()];
    let expect = mass * 9.81 * (1.0 - mass * d * d / io);
    println!("initial alpha {alpha:.6} rad/s^2, pivot force {fz:.6} N (expected {expect:.6})");
    assert!((fz - expect).abs() < 1e-8 * expect);
    let energy = |s: &DynamicSolver| {
        let (ke, _) = s.energy();
        let z = rotorsim::structure::rotation::mv(
            &rotorsim::structure::rotation::quat_to_arr(&s.state.q[n]),
            [d, 0.0, 0.0],
        )[2];
        ke + mass * 9.81 * z
    };
    let e0 = energy(&s);
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        s.step().unwrap();
        worst = worst.max((energy(&s) - e0).abs());
    }
    let scale = mass * 9.81 * d;
    println!(
        "pendulum from horizontal, 2 s, rho_inf = 1: max |E - E0| / (m g d) = {:.2e}",
        worst / scale
    );
    assert!(worst / scale < 1e-4);

    // spinning offset mass: the initial multipliers already carry the centripetal reaction
    let mut m = Model::new();
    let hub = m.add_node("hub", [0.0; 3], rotation::ident()).unwrap();
    let j = m
        .add_joint(
            "shaft",
            JointKind::Revolute,
            None,
            hub,
            [0.0; 3],
            rotation::ident(),
        )
        .unwrap();
    if let Element::Joint(jj) = &mut m.elements[j] {
        jj.prescribed_angle = Some(AngleLaw {
            omega_rad_s: 3.0,
            table: None,
        });
    }
    m.add_element(Element::Rigid(RigidBody {
        name: "mass".into(),
        node: hub,
        mass_kg: 2.0,
        cm_offset_m: [0.5, 0.0, 0.0],
        inertia_kgm2: [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]],
    }))
    .unwrap();
    m.add_sensor("shaft", SensorKind::Joint(j));
    let mut st = State::from_model(&m);
    st.set_rigid_rotation([0.0; 3], [0.0, 0.0, 3.0]);
    let mut s = DynamicSolver::new(m, st, 0.005, 1.0).unwrap();
    s.init_accelerations().unwrap();
    let h = s.sensor_header();
    let v = s.sensor_values();
    let fx = v[h.iter().position(|x| x == "shaft.fx_N").unwrap()];
    println!("initial centripetal reaction {fx:.9} N (m omega^2 r = -9 along x)");
    assert!((fx + 9.0).abs() < 1e-6, "{fx}");
    assert!(
        s.state.al[hub].iter().all(|a| a.abs() < 1e-6),
        "{:?}",
        s.state.al[hub]
    );
}
