//! Section-load recovery (src/loads) against closed-form answers: a cantilever under a
//! uniform load, a rotating uniform blade, a blade on a free flap hinge, a blade held in pitch
//! by a pitch link.
mod structure_common;
use rotorsim::loads::{element_at, section, SectionComponents};
use rotorsim::solver::{static_solve, State, StaticOptions};
use rotorsim::structure::rotation::ident;
use rotorsim::structure::*;
use structure_common as common;

fn solve(m: &mut Model, omega: Option<[f64; 3]>) -> State {
    let mut st = State::from_model(m);
    let mut opts = StaticOptions {
        load_steps: 2,
        omega,
        ..Default::default()
    };
    opts.newton.rtol = 1e-12;
    static_solve(m, &mut st, &opts, |_, _, _, _| {}).unwrap();
    if let Some(w) = omega {
        st.set_rigid_rotation([0.0; 3], w);
    }
    st
}

fn ctx() -> EvalCtx {
    EvalCtx::default()
}

/// Section components of beam `name` at arc length `s`.
fn at(m: &Model, st: &State, name: &str, s: f64) -> SectionComponents {
    let e = element_at(m, &m.beams[name], s).unwrap();
    section(m, st, &ctx(), e, s).unwrap().components()
}

#[test]
fn cantilever_under_a_uniform_load_has_the_exact_shear_and_moment() {
    // q = 100 N/m up, L = 10 m, 5 elements: V = q (L - x), M = q (L - x)^2 / 2, at element
    // boundaries and between them. The linear theory holds to the slope (qL^3/6EI = 1.7e-5)
    // in the deformed section frame: squared on V and M, to first order across (axial)
    let (l, q) = (10.0, 100.0);
    let sec = common::uniform(1e10, 1e10, 1e9, 1e9, 1e9, 1.0, 0.02, 0.01, 0.01);
    let mut m = Model::new();
    let ids = m
        .add_straight_beam(
            "b",
            5,
            [0.0; 3],
            [l, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &sec,
            0.0,
            None,
        )
        .unwrap();
    m.clamp("root", ids[0]).unwrap();
    m.add_beam_load(
        "b",
        BeamLoad {
            force_n_per_m: [0.0, 0.0, q],
            moment_nm_per_m: [0.0; 3],
            follower: false,
            time: TimeTable::constant(),
        },
    )
    .unwrap();
    let st = solve(&mut m, None);
    let m_ref = q * l * l / 2.0;
    for x in [0.0, 0.7, 2.0, 3.1, 4.0, 5.55, 8.0, 9.3, 9.99, 10.0] {
        let c = at(&m, &st, "b", x);
        let (v, mo) = (q * (l - x), q * (l - x).powi(2) / 2.0);
        assert!(
            (c.shear_flap_n - v).abs() < 1e-8 * q * l,
            "x {x}: V {} vs {v}",
            c.shear_flap_n
        );
        assert!(
            (c.flap_nm - mo).abs() < 1e-8 * m_ref,
            "x {x}: M {} vs {mo}",
            c.flap_nm
        );
        assert!(c.axial_n.abs() < 2e-5 * q * l, "x {x}: {c:?}");
        assert!(c.shear_chord_n.abs() < 1e-9 * q * l, "x {x}: {c:?}");
        for other in [c.torsion_nm, c.chord_nm] {
            assert!(other.abs() < 1e-9 * m_ref, "x {x}: {c:?}");
        }
    }
}

#[test]
fn rotating_uniform_blade_carries_the_centrifugal_axial_force() {
    // N(r) = m Omega^2 (R^2 - r^2) / 2 for an inextensible blade; the stretch changes it by
    // about m Omega^2 R^2 / EA = 2e-7 (a stiffer EA loses the strain to round-off)
    let (r_tip, mass, om) = (5.0, 10.0, 30.0);
    let sec = common::uniform(1e12, 1e12, 1e8, 1e9, 1e9, mass, 0.02, 0.01, 0.01);
    let mut m = Model::new();
    let ids = m
        .add_straight_beam(
            "b",
            4,
            [0.0; 3],
            [r_tip, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &sec,
            0.0,
            None,
        )
        .unwrap();
    m.clamp("hub", ids[0]).unwrap();
    let st = solve(&mut m, Some([0.0, 0.0, om]));
    let n0 = mass * om * om * r_tip * r_tip / 2.0;
    for r in [0.0, 0.4, 1.25, 2.0, 3.3, 4.9] {
        let c = at(&m, &st, "b", r);
        let want = mass * om * om * (r_tip * r_tip - r * r) / 2.0;
        assert!(
            (c.axial_n - want).abs() < 5e-7 * n0,
            "r {r}: {} vs {want}",
            c.axial_n
        );
        assert!(c.shear_flap_n.abs() < 1e-9 * n0 && c.flap_nm.abs() < 1e-9 * n0 * r_tip);
    }
}

#[test]
fn a_blade_on_a_free_flap_hinge_has_no_flap_moment_at_the_hinge() {
    // hinge at e = 0.5 m (axis -y, free), blade to 5 m, lift 200 N/m, rotating at 25 rad/s:
    // the blade cones until centrifugal and lift moments balance about the hinge
    let (e, r_tip, om) = (0.5, 5.0, 25.0);
    let sec = common::uniform(1e10, 1e9, 1e5, 2e5, 1e6, 8.0, 0.02, 0.01, 0.01);
    let mut m = Model::new();
    let ids = m
        .add_straight_beam(
            "b",
            6,
            [e, 0.0, 0.0],
            [r_tip, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &sec,
            0.0,
            None,
        )
        .unwrap();
    // joint frame: z along the hinge axis -y
    let q = [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]];
    m.add_joint("flap", JointKind::Revolute, None, ids[0], [e, 0.0, 0.0], q)
        .unwrap();
    m.add_beam_load(
        "b",
        BeamLoad {
            force_n_per_m: [0.0, 0.0, 200.0],
            moment_nm_per_m: [0.0; 3],
            follower: false,
            time: TimeTable::constant(),
        },
    )
    .unwrap();
    let st = solve(&mut m, Some([0.0, 0.0, om]));
    let root = at(&m, &st, "b", 0.0);
    let mid = at(&m, &st, "b", 0.5 * (r_tip - e));
    assert!(mid.flap_nm.abs() > 10.0, "{mid:?}");
    assert!(
        root.flap_nm.abs() < 1e-9 * mid.flap_nm.abs().max(root.axial_n),
        "flap moment at the hinge {} (mid-span {})",
        root.flap_nm,
        mid.flap_nm
    );
    // the hinge carries the lift and the centrifugal force
    assert!(root.axial_n > 0.0 && root.shear_flap_n.abs() > 0.0);
}

#[test]
fn pitch_link_load_times_the_horn_arm_balances_the_pitching_moment() {
    // blade on a free pitch bearing (axis x) at the origin, horn tip 0.2 m ahead (y), link
    // 0.45 m straight down to a universal joint on the ground; a nose-up moment of 50 N m/m
    // over 4 m must be carried by the link alone: T x 0.2 m = 200 N m (tension)
    let (arm, mu, l) = (0.2, 50.0, 4.0);
    let blade = common::uniform(1e10, 1e9, 1e6, 1e7, 1e7, 5.0, 0.02, 0.01, 0.01);
    let link = common::uniform(2e8, 1e8, 1e3, 1e4, 1e4, 1.0, 1e-3, 5e-4, 5e-4);
    let mut m = Model::new();
    let b = m
        .add_straight_beam(
            "blade",
            4,
            [0.0; 3],
            [l, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            &blade,
            0.0,
            None,
        )
        .unwrap();
    let k = m
        .add_straight_beam(
            "link",
            3,
            [0.0, arm, -0.45],
            [0.0, arm, 0.0],
            [0.0, 1.0, 0.0],
            &link,
            0.0,
            None,
        )
        .unwrap();
    // pitch bearing: revolute about x (joint z along x)
    let qx = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    m.add_joint("pitch", JointKind::Revolute, None, b[0], [0.0; 3], qx)
        .unwrap();
    m.add_joint(
        "lower",
        JointKind::Universal,
        None,
        k[0],
        [0.0, arm, -0.45],
        ident(),
    )
    .unwrap();
    m.add_joint(
        "upper",
        JointKind::Spherical,
        Some(b[0]),
        *k.last().unwrap(),
        [0.0, arm, 0.0],
        ident(),
    )
    .unwrap();
    m.add_beam_load(
        "blade",
        BeamLoad {
            force_n_per_m: [0.0; 3],
            moment_nm_per_m: [mu, 0.0, 0.0],
            follower: false,
            time: TimeTable::constant(),
        },
    )
    .unwrap();
    let st = solve(&mut m, None);
    let t = at(&m, &st, "link", 0.225).axial_n;
    assert!(
        (t * arm - mu * l).abs() < 1e-6 * mu * l,
        "link load {t} N x {arm} m = {} N m vs {} N m",
        t * arm,
        mu * l
    );
    // the same load at every station of the (massless-ish, unloaded) link
    for s in [0.0, 0.1, 0.44] {
        let ts = at(&m, &st, "link", s).axial_n;
        assert!((ts - t).abs() < 1e-6 * t.abs(), "s {s}: {ts} vs {t}");
    }
}
