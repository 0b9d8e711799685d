//! Bushing joints with locked axes: closed-form tangent against the dual reference and central
//! differences for several lock sets, free vibration along the one free translation and about
//! the one free rotation against the closed form, the locked axes' reactions against gravity
//! and a static load, and the deck's checks of the `locked` key.
use rotorsim::solver::state::{lambda_offsets, sensor_values};
use rotorsim::solver::{static_solve, DynamicSolver, State, StaticOptions};
use rotorsim::structure::deck::parse_deck;
use rotorsim::structure::rotation::*;
use rotorsim::structure::*;
use std::path::Path;

mod joint_support;
use joint_support::*;

fn model(text: &str) -> Model {
    parse_deck(text, "test.toml", Path::new(".")).unwrap().1
}

fn err(text: &str) -> String {
    parse_deck(text, "test.toml", Path::new("."))
        .err()
        .expect("deck should be refused")
        .to_string()
}

/// Lock sets (x, y, z, rx, ry, rz): none, rotations only, translations only, 5 of 6, mixed.
const LOCK_SETS: [[bool; 6]; 7] = [
    [false; 6],
    [false, false, false, true, true, true],
    [true, true, true, false, false, false],
    [false, true, true, true, true, true],
    [true, true, true, true, true, false],
    [false, true, false, false, false, true],
    [true, false, true, false, true, false],
];

/// A random bushing case with locks `locked`: random frames, offsets, coefficients, relative
/// rotation up to `max_angle`, multipliers.
fn locked_case(rng: &mut Rng, locked: [bool; 6], grounded: bool, max_angle: f64) -> Case {
    let dyn_seeds = rng.unit() < 0.5;
    let mut c = case(rng, JointKind::Bushing, grounded, Extra::None, dyn_seeds);
    let mut coef = |lo: f64, hi: f64| -> [f64; 3] { std::array::from_fn(|_| rng.uni(lo, hi)) };
    c.j.bushing = BushingCoeffs {
        k_n_per_m: coef(1e3, 1e5),
        c_ns_per_m: coef(10.0, 1e3),
        k_nm_per_rad: coef(1e3, 1e5),
        c_nms_per_rad: coef(10.0, 1e3),
    };
    c.j.bushing_locked = locked;
    c.lam = (0..c.j.n_lambda()).map(|_| rng.uni(-1e3, 1e3)).collect();
    let fa = mm(&c.a.r, &c.j.qa);
    let ax = rng.v3(1.0);
    let phi = fmul(rng.uni(0.0, max_angle) / dot(ax, ax).sqrt(), ax);
    c.b.r = mm(&mm(&fa, &exp_map(phi)), &transpose(&c.j.qb));
    c
}

fn res(c: &Case, a: &NodeKin<f64>, b: &NodeKin<f64>, lam: &[f64]) -> Vec<f64> {
    let mut r = vec![0.0; sizes(c).1];
    c.j.residual_f64(a, b, lam, &c.ctx, &mut r);
    r
}

#[test]
fn locks_count_in_multiplier_order() {
    let mut rng = Rng(3);
    for locked in LOCK_SETS {
        let c = locked_case(&mut rng, locked, true, 0.0);
        let nt = locked[..3].iter().filter(|&&l| l).count();
        let nr = locked[3..].iter().filter(|&&l| l).count();
        assert_eq!(c.j.locks(), (nt, nr));
        assert_eq!(c.j.n_lambda(), nt + nr);
    }
}

#[test]
fn tangent_matches_dual_reference_and_central_differences() {
    let mut rng = Rng(0x10c5_b005_7777_0001);
    let (mut worst_dual, mut worst_fd, mut worst_res, mut worst_phi): (f64, f64, f64, f64) =
        (0.0, 0.0, 0.0, 0.0);
    for locked in LOCK_SETS {
        for grounded in [false, true] {
            for (trial, max_angle) in [0.0, 1e-3, 0.4, 1.5, 2.8].iter().enumerate() {
                let c = locked_case(&mut rng, locked, grounded, *max_angle);
                let tag = format!("locked={locked:?} grounded={grounded} #{trial}");
                let (nn, n) = sizes(&c);
                // f64 and generic residuals agree; the multiplier rows are cscale phi
                let r = res(&c, &c.a, &c.b, &c.lam);
                let mut rg = vec![0.0; n];
                c.j.residual::<f64>(&c.a, &c.b, &c.lam, &c.ctx, &mut rg);
                for i in 0..n {
                    let e = (r[i] - rg[i]).abs() / max_abs(&rg);
                    worst_res = worst_res.max(e);
                    assert!(e < 1e-13, "{tag}: residual row {i}: {} vs {}", r[i], rg[i]);
                }
                let mut ph = [0.0; 6];
                c.j.phi(&c.a, &c.b, c.ctx.t, &mut ph);
                for k in 0..n - nn {
                    let e = (rg[nn + k] - c.ctx.cscale * ph[k]).abs() / c.ctx.cscale;
                    worst_phi = worst_phi.max(e);
                    assert!(e < 1e-13, "{tag}: phi {k}");
                }
                let (k, e) = tangent_against_dual(&c, &c.lam, n, 1e-12, &tag);
                worst_dual = worst_dual.max(e);
                // central differences of residual_f64: node columns along each seed (eps
                // |(dx, dth)| = 1e-5), multiplier columns (linear: exact up to round-off)
                let has_a = c.j.node_a.is_some();
                let r0 = max_abs(&r);
                for col in 0..n {
                    let (rp, rm, eps) = if col < nn {
                        let (l, comp) = (col / 6, col % 6);
                        let s = &c.seeds[l][comp];
                        let size = max_abs(&s.dx).max(max_abs(&s.dth));
                        let eps = 1e-5 / if size > 0.0 { size } else { max_abs(&s.dw) };
                        let ev = |e: f64| {
                            if has_a && l == 0 {
                                res(&c, &moved(&c.a, s, e), &c.b, &c.lam)
                            } else {
                                res(&c, &c.a, &moved(&c.b, s, e), &c.lam)
                            }
                        };
                        (ev(eps), ev(-eps), eps)
                    } else {
                        let eps = 1.0;
                        let ev = |e: f64| {
                            let mut l = c.lam.clone();
                            l[col - nn] += e;
                            res(&c, &c.a, &c.b, &l)
                        };
                        (ev(eps), ev(-eps), eps)
                    };
                    let an: Vec<f64> = (0..n).map(|i| k[i * n + col]).collect();
                    let cs = max_abs(&an).max(1e-6 * r0);
                    for i in 0..n {
                        let fd = (rp[i] - rm[i]) / (2.0 * eps);
                        let e = (an[i] - fd).abs() / cs;
                        worst_fd = worst_fd.max(e);
                        assert!(e < 1e-7, "{tag}: ({i}, {col}): closed {} fd {fd}", an[i]);
                    }
                }
            }
        }
    }
    println!(
        "locked bushing: residual f64 vs generic {worst_res:.1e}, phi rows {worst_phi:.1e}; tangent vs dual {worst_dual:.1e}, vs central differences {worst_fd:.1e} (of the column scale)"
    );
}

/// A rigid body on a grounded bushing at its node, with gravity and a joint sensor.
fn body_deck(mass: f64, inertia: [f64; 3], joint: &str) -> String {
    format!(
        "gravity_m_s2 = [0.0, 0.0, -9.81]\n\n[[node]]\nname = \"air\"\nposition_m = [1.0, 2.0, 3.0]\n\n[[rigid_body]]\nname = \"body\"\nnode = \"air\"\nmass_kg = {mass:?}\ninertia_kgm2 = [[{:?}, 0.0, 0.0], [0.0, {:?}, 0.0], [0.0, 0.0, {:?}]]\n\n[[joint]]\nname = \"mount\"\ntype = \"bushing\"\nnode_b = \"air\"\n{joint}\n\n[[sensor]]\nname = \"r\"\njoint = \"mount\"\n",
        inertia[0], inertia[1], inertia[2]
    )
}

/// Upward zero crossings of `x` (linear interpolation), from the time history `(t, x)`.
fn upward_crossings(h: &[(f64, f64)]) -> Vec<f64> {
    h.windows(2)
        .filter(|p| p[0].1 < 0.0 && p[1].1 >= 0.0)
        .map(|p| p[0].0 + (p[1].0 - p[0].0) * (-p[0].1) / (p[1].1 - p[0].1))
        .collect()
}

/// Marches `text` from rest with initial velocities `v`, `w` of the node for `periods` of
/// `omega` at `steps` per period; returns the measured angular frequency of `signal`, the
/// largest drift of `locked_motion`, and the sensor rows.
fn march(
    text: &str,
    v: [f64; 3],
    w: [f64; 3],
    omega: f64,
    signal: impl Fn(&State) -> f64,
    locked_motion: impl Fn(&State) -> f64,
) -> (f64, f64, Vec<Vec<f64>>, f64) {
    let m = model(text);
    let mut st = State::from_model(&m);
    st.v[0] = v;
    st.w[0] = w;
    let h = 2.0 * std::f64::consts::PI / omega / 400.0;
    let mut s = DynamicSolver::new(m, st, h, 1.0).unwrap();
    s.init_accelerations().unwrap();
    let s0 = signal(&s.state);
    let (mut hist, mut drift, mut sensors) = (vec![], 0.0f64, vec![]);
    for _ in 0..(8 * 400) {
        s.step().unwrap();
        hist.push((s.state.t, signal(&s.state) - s0));
        drift = drift.max(locked_motion(&s.state).abs());
        sensors.push(s.sensor_values());
    }
    let zc = upward_crossings(&hist);
    let n = zc.len() - 1;
    let td = (zc[n] - zc[0]) / n as f64;
    (2.0 * std::f64::consts::PI / td, drift, sensors, h)
}

#[test]
fn translation_free_in_x_vibrates_at_sqrt_k_over_m_and_z_reaction_carries_the_weight() {
    let (m_kg, k) = (500.0, 2e5);
    let text = body_deck(
        m_kg,
        [200.0, 300.0, 400.0],
        &format!(
            "stiffness_N_per_m = [{k:?}, 0.0, 0.0]\nlocked = [\"y\", \"z\", \"rx\", \"ry\", \"rz\"]"
        ),
    );
    let wn = (k / m_kg).sqrt();
    let x0 = [1.0, 2.0, 3.0];
    let (w, drift, sensors, h) = march(
        &text,
        [0.1, 0.0, 0.0],
        [0.0; 3],
        wn,
        |s| s.x[0][0],
        |s| max_abs(&sub(s.x[0], [s.x[0][0], x0[1], x0[2]])).max(max_abs(&s.rotation_vector(0))),
    );
    // trapezoidal rule (rho_inf = 1): period error (w h)^2 / 12
    let tol = 5.0 * (wn * h).powi(2) / 12.0;
    let e = (w - wn) / wn;
    // force of the joint on the node: -(spring) in x, the weight's balance in z
    let g = 9.81 * m_kg;
    let mut worst_fz: f64 = 0.0;
    for row in &sensors {
        // [t, fx, fy, fz, mx, my, mz, angle]
        worst_fz = worst_fz.max((row[3] - g).abs() / g);
        assert!(
            row[2].abs() < 1e-6 * g && max_abs(&row[4..7]) < 1e-6 * g,
            "{row:?}"
        );
    }
    println!(
        "x: omega {w:.6} (closed {wn:.6}, rel err {e:.1e}, tolerance {tol:.1e}); locked motion drift {drift:.1e}; z reaction vs m g {worst_fz:.1e}"
    );
    assert!(e.abs() < tol, "{w} vs {wn}");
    assert!(drift < 1e-9, "{drift}");
    assert!(worst_fz < 1e-9, "{worst_fz}");
}

#[test]
fn roll_free_oscillates_at_sqrt_kr_over_i() {
    let (ixx, kr) = (200.0, 4e5);
    let text = body_deck(
        500.0,
        [ixx, 300.0, 400.0],
        &format!(
            "rot_stiffness_Nm_per_rad = [{kr:?}, 0.0, 0.0]\nrot_damping_Nms_per_rad = [0.0, 0.0, 0.0]\nlocked = [\"x\", \"y\", \"z\", \"ry\", \"rz\"]"
        ),
    );
    let wn = (kr / ixx).sqrt();
    let (w, drift, _, h) = march(
        &text,
        [0.0; 3],
        [0.02, 0.0, 0.0],
        wn,
        |s| s.rotation_vector(0)[0],
        |s| {
            let p = s.rotation_vector(0);
            max_abs(&sub(s.x[0], [1.0, 2.0, 3.0]))
                .max(p[1].abs())
                .max(p[2].abs())
        },
    );
    let tol = 5.0 * (wn * h).powi(2) / 12.0;
    let e = (w - wn) / wn;
    println!(
        "roll: omega {w:.6} (closed {wn:.6}, rel err {e:.1e}, tolerance {tol:.1e}); locked motion drift {drift:.1e}"
    );
    assert!(e.abs() < tol, "{w} vs {wn}");
    assert!(drift < 1e-9, "{drift}");
}

#[test]
fn static_load_deflects_the_free_axis_and_the_locked_ones_react() {
    // tilted joint frame: z along (0, 1, 1), x along global x; y free with a spring, the rest
    // locked; a load with components along all joint axes
    let s = 0.5f64.sqrt();
    let q = [[1.0, 0.0, 0.0], [0.0, s, s], [0.0, -s, s]];
    let ky = 3e5;
    let p = [300.0, -500.0, 800.0];
    let text = format!(
        "[[node]]\nname = \"air\"\nposition_m = [1.0, 2.0, 3.0]\n\n[[joint]]\nname = \"mount\"\ntype = \"bushing\"\nnode_b = \"air\"\naxis = [0.0, 1.0, 1.0]\nx_direction = [1.0, 0.0, 0.0]\nstiffness_N_per_m = [0.0, {ky:?}, 0.0]\nlocked = [\"rz\", \"x\", \"z\", \"rx\", \"ry\"]\n\n[[load]]\nname = \"p\"\nnode = \"air\"\nforce_N = {p:?}\n\n[[sensor]]\nname = \"r\"\njoint = \"mount\"\n"
    );
    let mut m = model(&text);
    let mut st = State::from_model(&m);
    let opts = StaticOptions {
        load_steps: 2,
        ..Default::default()
    };
    static_solve(&mut m, &mut st, &opts, |_, _, _, _| {}).unwrap();
    let pj = mtv(&q, p);
    let d = mtv(&q, sub(st.x[0], [1.0, 2.0, 3.0]));
    let want = [0.0, pj[1] / ky, 0.0];
    let e = max_abs(&sub(d, want)) / max_abs(&want);
    assert!(e < 1e-9, "displacement {d:?} vs {want:?}");
    assert!(max_abs(&st.rotation_vector(0)) < 1e-12);
    // multipliers: x, z translations, then rx, ry, rz (the deck's order does not matter);
    // the node rows B^T lam = lam_k f_k balance the load's locked components
    let lam = &st.lambda;
    assert_eq!(lam.len(), 5);
    let er = (lam[0] - pj[0]).abs().max((lam[1] - pj[2]).abs()) / max_abs(&p);
    assert!(
        er < 1e-9,
        "multipliers {lam:?} vs load {pj:?} (joint frame)"
    );
    assert!(max_abs(&lam[2..]) < 1e-9 * max_abs(&p));
    let row = sensor_values(&m, &st, &lambda_offsets(&m));
    let f = [row[1], row[2], row[3]];
    let es = max_abs(&add(f, p)) / max_abs(&p);
    println!(
        "static: displacement in joint frame {d:?} (closed {want:?}, rel err {e:.1e}); multipliers {lam:?}; sensor force {f:?} vs -load (rel err {es:.1e})"
    );
    assert!(es < 1e-9, "sensor {f:?} vs load {p:?}");
}

const DECK: &str = r#"
[[node]]
name = "air"
position_m = [1.0, 2.0, 3.0]

[[joint]]
name = "mount"
type = "bushing"
node_b = "air"
stiffness_N_per_m = [2e5, 0.0, 0.0]
rot_stiffness_Nm_per_rad = [4e5, 0.0, 0.0]
"#;

#[test]
fn bad_locks_name_the_joint_and_the_key() {
    let ok = format!("{DECK}locked = [\"y\", \"z\", \"ry\", \"rz\"]\n");
    assert!(parse_deck(&ok, "test.toml", Path::new(".")).is_ok());
    // all coefficients zero is fine when something is locked
    let clamp_like = "[[node]]\nname = \"air\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[joint]]\nname = \"mount\"\ntype = \"bushing\"\nnode_b = \"air\"\nlocked = [\"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"]\n";
    let m = model(clamp_like);
    assert_eq!(m.n_lambda(), 6);
    let cases = [
        (
            format!("{DECK}locked = [\"y\", \"w\"]\n"),
            "joint[0] `mount`.locked",
            "unknown axis `w`",
        ),
        (
            format!("{DECK}locked = [\"y\", \"rz\", \"y\"]\n"),
            "joint[0] `mount`.locked",
            "axis `y` given twice",
        ),
        (
            "[[node]]\nname = \"hub\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[joint]]\nname = \"shaft\"\ntype = \"revolute\"\nnode_b = \"hub\"\nlocked = [\"x\"]\n".to_string(),
            "joint[0] `shaft`.locked",
            "only for type = \"bushing\"",
        ),
        (
            format!("{DECK}locked = [\"x\", \"y\"]\n"),
            "joint[0] `mount`.stiffness_N_per_m",
            "`x` is locked",
        ),
        (
            format!("{DECK}locked = [\"y\", \"rx\"]\n"),
            "joint[0] `mount`.rot_stiffness_Nm_per_rad",
            "`rx` is locked",
        ),
        (
            format!("{DECK}damping_Ns_per_m = [0.0, 0.0, 5.0]\nlocked = [\"z\"]\n"),
            "joint[0] `mount`.damping_Ns_per_m",
            "`z` is locked",
        ),
        (
            "[[node]]\nname = \"air\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[joint]]\nname = \"mount\"\ntype = \"bushing\"\nnode_b = \"air\"\nlocked = []\n".to_string(),
            "joint[0] `mount`.stiffness_N_per_m",
            "does nothing",
        ),
    ];
    for (text, key, what) in cases {
        let e = err(&text);
        println!("{e}");
        assert!(
            e.contains("test.toml") && e.contains(key) && e.contains(what),
            "{e}"
        );
    }
}

#[test]
fn grounded_locked_bushing_beside_a_driven_shaft_runs_under_modified_newton() {
    // The modified-Newton turn of grounded joints' reactions turns a bushing's multipliers
    // only when all three translations are locked (a full reaction vector); full and modified
    // Newton give the same motion either way.
    use rotorsim::solver::NewtonMethod;
    for locked in ["[\"x\", \"y\", \"z\"]", "[\"y\", \"z\", \"rx\"]"] {
        let text = format!(
            "[[node]]\nname = \"air\"\nposition_m = [1.0, 2.0, 3.0]\n\n[[rigid_body]]\nname = \"body\"\nnode = \"air\"\nmass_kg = 500.0\ninertia_kgm2 = [[200.0, 0.0, 0.0], [0.0, 300.0, 0.0], [0.0, 0.0, 400.0]]\n\n[[node]]\nname = \"hub\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[rigid_body]]\nname = \"hub_body\"\nnode = \"hub\"\nmass_kg = 50.0\ncm_offset_m = [0.1, 0.0, 0.0]\ninertia_kgm2 = [[20.0, 0.0, 0.0], [0.0, 20.0, 0.0], [0.0, 0.0, 40.0]]\n\n[[joint]]\nname = \"mount\"\ntype = \"bushing\"\nnode_b = \"air\"\nrot_stiffness_Nm_per_rad = [0.0, 9e5, 2e6]\nrot_damping_Nms_per_rad = [0.0, 100.0, 100.0]\nlocked = {locked}\n\n[[joint]]\nname = \"shaft\"\ntype = \"revolute\"\nnode_b = \"hub\"\nomega_rad_s = 20.0\n\n[[joint]]\nname = \"link\"\ntype = \"bushing\"\nnode_a = \"air\"\nnode_b = \"hub\"\nstiffness_N_per_m = [1e5, 1e5, 1e5]\nrot_stiffness_Nm_per_rad = [1e4, 1e4, 0.0]\n"
        );
        let mut finals = vec![];
        for method in [NewtonMethod::Full, NewtonMethod::Modified] {
            let m = model(&text);
            let mut st = State::from_model(&m);
            st.w[1] = [0.0, 0.0, 20.0];
            st.v[0] = [0.1, -0.05, 0.02];
            st.w[0] = [0.01, 0.02, -0.01];
            let mut s = DynamicSolver::new(m, st, 1e-3, 0.9).unwrap();
            s.newton.method = method;
            s.init_accelerations().unwrap();
            for _ in 0..200 {
                s.step().unwrap();
            }
            println!(
                "locked = {locked}, {method:?}: factorizations {}, iterations {}",
                s.factorizations, s.total_iterations
            );
            finals.push((s.state.x[0], s.state.lambda.clone()));
        }
        let d = max_abs(&sub(finals[0].0, finals[1].0));
        let dl = finals[0]
            .1
            .iter()
            .zip(&finals[1].1)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!("locked = {locked}: airframe position, full vs modified: {d:.1e} m; multipliers {dl:.1e}");
        assert!(d < 1e-8, "{d}");
        assert!(dl < 1e-4 * max_abs(&finals[0].1), "{dl}");
    }
}
