//! The `bushing` joint: closed-form tangent against the dual reference and central differences,
//! natural frequencies and free decay of a rigid body on a grounded bushing against the closed
//! form, static deflections (small and large rotations), equal and opposite loads, and a
//! grounded bushing next to a driven shaft under modified Newton.
mod support;
use rotorsim::solver::fdcheck::check_model;
use rotorsim::solver::modal::{modes, ModalOptions};
use rotorsim::solver::{
    static_solve, Assembler, DynamicSolver, NewtonMethod, State, StaticOptions,
};
use rotorsim::structure::deck::parse_deck;
use rotorsim::structure::rotation::*;
use rotorsim::structure::*;
use std::path::Path;
use support::upward_crossings;

mod joint_support;
use joint_support::*;

fn model(text: &str) -> Model {
    parse_deck(text, "bushing.toml", Path::new(".")).unwrap().1
}

/// A random bushing case: random frames, offsets (`offset`: joint point away from node_b),
/// coefficients (each axis zero with probability 1/4), and node B turned so that the relative
/// rotation is `phi` with `|phi| <= max_angle` (away from the log map's singularity at pi).
fn bushing_case(
    rng: &mut Rng,
    grounded: bool,
    offset: bool,
    dyn_seeds: bool,
    max_angle: f64,
) -> Case {
    let mut c = case(rng, JointKind::Bushing, grounded, Extra::None, dyn_seeds);
    let mut coef = |lo: f64, hi: f64| -> [f64; 3] {
        std::array::from_fn(|_| {
            if rng.unit() < 0.25 {
                0.0
            } else {
                rng.uni(lo, hi)
            }
        })
    };
    c.j.bushing = BushingCoeffs {
        k_n_per_m: coef(1e3, 1e5),
        c_ns_per_m: coef(10.0, 1e3),
        k_nm_per_rad: coef(1e3, 1e5),
        c_nms_per_rad: coef(10.0, 1e3),
    };
    if !offset {
        c.j.db = [0.0; 3];
    }
    let fa = mm(&c.a.r, &c.j.qa);
    let phi = fmul(rng.uni(0.0, max_angle), {
        let v = rng.v3(1.0);
        fmul(1.0 / dot(v, v).sqrt(), v)
    });
    c.b.r = mm(&mm(&fa, &exp_map(phi)), &transpose(&c.j.qb));
    c
}

fn res(c: &Case, a: &NodeKin<f64>, b: &NodeKin<f64>) -> Vec<f64> {
    let mut r = vec![0.0; sizes(c).1];
    c.j.residual_f64(a, b, &[], &c.ctx, &mut r);
    r
}

fn for_all_cases(mut f: impl FnMut(&Case, &str)) {
    let mut rng = Rng(0x5eed_b005_1234_9876);
    for grounded in [false, true] {
        for offset in [false, true] {
            for dyn_seeds in [true, false] {
                // trial 0 at the reference relative orientation (series branches of log and
                // T_L^-1), then small, then large relative rotations up to 2.8 rad
                for (trial, max_angle) in [0.0, 1e-3, 0.3, 1.5, 2.8, 2.8].iter().enumerate() {
                    let c = bushing_case(&mut rng, grounded, offset, dyn_seeds, *max_angle);
                    let tag =
                        format!("grounded={grounded} offset={offset} dyn={dyn_seeds} #{trial}");
                    f(&c, &tag);
                }
            }
        }
    }
}

#[test]
fn tangent_matches_dual_reference_and_central_differences() {
    let (mut worst_dual, mut worst_fd, mut worst_res): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for_all_cases(|c, tag| {
        let (nn, n) = sizes(c);
        assert_eq!(nn, n, "a bushing has no multipliers");
        // the generic residual (nested-dual reference path) and the f64 one agree
        let r = res(c, &c.a, &c.b);
        let mut rg = vec![0.0; n];
        c.j.residual::<f64>(&c.a, &c.b, &[], &c.ctx, &mut rg);
        for i in 0..n {
            worst_res = worst_res.max((r[i] - rg[i]).abs() / max_abs(&rg));
        }
        let (k, e) = tangent_against_dual(c, &[], n, 1e-12, tag);
        worst_dual = worst_dual.max(e);
        // central differences along each seed: eps |(dx, dth)| = 1e-5, truncation ~1e-10 and
        // round-off ~1e-11 of the column scale (as in tests/structure_joint_tangent.rs)
        let has_a = c.j.node_a.is_some();
        let r0 = max_abs(&r);
        for col in 0..n {
            let (l, comp) = (col / 6, col % 6);
            let s = &c.seeds[l][comp];
            let size = max_abs(&s.dx).max(max_abs(&s.dth));
            let eps = 1e-5 / if size > 0.0 { size } else { max_abs(&s.dw) };
            let ev = |e: f64| {
                if has_a && l == 0 {
                    res(c, &moved(&c.a, s, e), &c.b)
                } else {
                    res(c, &c.a, &moved(&c.b, s, e))
                }
            };
            let (rp, rm) = (ev(eps), ev(-eps));
            let an: Vec<f64> = (0..n).map(|i| k[i * n + col]).collect();
            let cs = max_abs(&an).max(1e-6 * r0);
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * eps);
                let e = (an[i] - fd).abs() / cs;
                worst_fd = worst_fd.max(e);
                assert!(e < 1e-7, "{tag}: ({i}, {col}): closed {} fd {fd}", an[i]);
            }
        }
    });
    println!(
        "bushing: residual f64 vs generic {worst_res:.1e}; tangent vs dual {worst_dual:.1e}, vs central differences {worst_fd:.1e} (of the column scale)"
    );
}

const AIRFRAME: &str = r#"
[[node]]
name = "air"
position_m = [1.0, 2.0, 3.0]

[[rigid_body]]
name = "body"
node = "air"
mass_kg = 500.0
inertia_kgm2 = [[200.0, 0.0, 0.0], [0.0, 300.0, 0.0], [0.0, 0.0, 400.0]]

[[joint]]
name = "mount"
type = "bushing"
node_b = "air"
"#;

#[test]
fn assembled_tangent_passes_the_model_fd_check_and_both_joint_paths_agree() {
    // two airframe-like bodies, one grounded through a bushing with its point off the node,
    // the other hung on the first through a second bushing; random state
    let text = format!(
        "{AIRFRAME}stiffness_N_per_m = [2e5, 0.0, 5e5]\ndamping_Ns_per_m = [300.0, 200.0, 0.0]\nrot_stiffness_Nm_per_rad = [4e5, 9e5, 0.0]\nrot_damping_Nms_per_rad = [0.0, 50.0, 80.0]\nposition_m = [1.5, 1.7, 2.6]\naxis = [0.3, 0.2, 1.0]\nx_direction = [1.0, -0.4, 0.0]\n\n[[node]]\nname = \"hub\"\nposition_m = [1.0, 2.0, 4.0]\nrotation_vector_rad = [0.2, -0.1, 0.5]\n\n[[rigid_body]]\nname = \"hub_body\"\nnode = \"hub\"\nmass_kg = 50.0\ninertia_kgm2 = [[20.0, 0.0, 0.0], [0.0, 20.0, 0.0], [0.0, 0.0, 40.0]]\n\n[[joint]]\nname = \"link\"\ntype = \"bushing\"\nnode_a = \"air\"\nnode_b = \"hub\"\nposition_m = [1.1, 2.1, 3.6]\naxis = [0.0, 1.0, 0.2]\nstiffness_N_per_m = [1e5, 2e5, 3e5]\ndamping_Ns_per_m = [10.0, 20.0, 30.0]\nrot_stiffness_Nm_per_rad = [1e4, 0.0, 3e4]\nrot_damping_Nms_per_rad = [5.0, 6.0, 0.0]\n"
    );
    let mut m = model(&text);
    let mut st = State::from_model(&m);
    for i in 0..st.x.len() {
        let f = i as f64 + 1.0;
        st.x[i] = add(st.x[i], [0.05 * f, -0.03, 0.02 * f]);
        st.q[i] = update_left(&st.q[i], [0.4 * f, -0.7, 0.3 * f]);
        st.v[i] = [0.3 * f, -0.2, 0.1];
        st.w[i] = [0.5, 0.2 * f, -0.3];
        st.a[i] = [1.0, f, -0.5];
        st.al[i] = [0.2, -0.1 * f, 0.4];
    }
    let mut kin = vec![];
    st.kin(&mut kin);
    let ctx = EvalCtx::default();
    let checks = check_model(&m, &kin, &[], &ctx);
    for ch in &checks {
        println!("{:>9}: fd check rel error {:.2e}", ch.element, ch.rel_error);
        assert!(ch.rel_error < 1e-6, "{} {}", ch.element, ch.rel_error);
    }
    // closed form (default) and nested duals through the assembler, generalized-alpha seeds
    let h = 2e-3;
    let tl: Vec<[[f64; 3]; 3]> = (0..2)
        .map(|i| tangent_left(fmul(h, [3.0, -(i as f64), 2.0])))
        .collect();
    let seed = |node: usize, comp: usize| Seed::generalized_alpha(comp, h, 600.0, 4e5, &tl[node]);
    let mut out = vec![];
    for dual in [false, true] {
        let mut asm = Assembler::new(&m).unwrap();
        asm.joint_tangent_dual = dual;
        let mut r = vec![0.0; asm.ndof];
        asm.assemble(&mut m, &kin, &[], &ctx, &seed, None, true, &mut r)
            .unwrap();
        out.push((r, asm.values.clone()));
    }
    let (rs, ks) = (max_abs(&out[1].0), max_abs(&out[1].1));
    for i in 0..out[0].0.len() {
        assert!((out[0].0[i] - out[1].0[i]).abs() < 1e-13 * rs, "res {i}");
    }
    for p in 0..out[0].1.len() {
        assert!((out[0].1[p] - out[1].1[p]).abs() < 1e-12 * ks, "value {p}");
    }
}

#[test]
fn rigid_body_on_grounded_bushing_has_the_closed_form_frequencies() {
    let (m_kg, i_kgm2): (f64, [f64; 3]) = (500.0, [200.0, 300.0, 400.0]);
    let k: [f64; 3] = [2e5, 3e5, 5e5];
    let kr: [f64; 3] = [4e5, 9e5, 2e6];
    let text = format!("{AIRFRAME}stiffness_N_per_m = {k:?}\nrot_stiffness_Nm_per_rad = {kr:?}\n");
    let mut m = model(&text);
    let st = State::from_model(&m);
    let opts = ModalOptions {
        n_modes: 6,
        omega: None,
        shift_rad_s: 0.0,
    };
    let got = modes(&mut m, &st, &opts).unwrap();
    let mut want: Vec<f64> = (0..3)
        .map(|i| (k[i] / m_kg).sqrt())
        .chain((0..3).map(|i| (kr[i] / i_kgm2[i]).sqrt()))
        .collect();
    want.sort_by(f64::total_cmp);
    let mut w: Vec<f64> = got.iter().map(|md| md.omega_rad_s).collect();
    w.sort_by(f64::total_cmp);
    assert_eq!(w.len(), 6);
    let mut worst: f64 = 0.0;
    for (g, e) in w.iter().zip(&want) {
        let rel = (g - e).abs() / e;
        worst = worst.max(rel);
        assert!(rel < 1e-6, "omega {g} vs closed form {e}");
    }
    println!("modal: worst relative frequency error {worst:.1e} ({w:?})");
}

/// Upward zero crossings of `x` (linear interpolation), from the time history `(t, x)`.

#[test]
fn free_decay_gives_the_damped_frequency_and_logarithmic_decrement() {
    // x translation and roll of the airframe, decoupled (joint point at the node, no cm
    // offset); a rotation about one fixed axis makes the log map linear, so the closed form
    // is exact and only the time integration errs.
    let (m_kg, ixx) = (500.0, 200.0);
    let (k, c) = (2e5, 400.0);
    let (kr, cr) = (4e5, 800.0);
    let text = format!(
        "{AIRFRAME}stiffness_N_per_m = [{k}, 3e5, 5e5]\ndamping_Ns_per_m = [{c}, 0.0, 0.0]\nrot_stiffness_Nm_per_rad = [{kr}, 9e5, 2e6]\nrot_damping_Nms_per_rad = [{cr}, 0.0, 0.0]\n"
    );
    let closed = |k: f64, c: f64, m: f64| {
        let wn = (k / m).sqrt();
        let zeta = c / (2.0 * (k * m).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        (
            wn,
            wd,
            2.0 * std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt(),
        )
    };
    let (wn_t, wd_t, dec_t) = closed(k, c, m_kg);
    let (wn_r, wd_r, dec_r) = closed(kr, cr, ixx);
    // step: 400 steps per period of the faster (roll) motion; generalized-alpha with rho_inf =
    // 1 is the trapezoidal rule: relative period error (w h)^2 / 12 = 2.1e-5 for roll, 8e-6 for
    // x, and a decay-rate error of the same relative order.
    let td_r = 2.0 * std::f64::consts::PI / wd_r;
    let h = td_r / 400.0;
    let m = model(&text);
    let mut st = State::from_model(&m);
    st.v[0] = [0.1, 0.0, 0.0];
    st.w[0] = [0.02, 0.0, 0.0];
    let mut s = DynamicSolver::new(m, st, h, 1.0).unwrap();
    s.init_accelerations().unwrap();
    let x0 = s.state.x[0][0];
    let (mut hx, mut hr) = (vec![], vec![]);
    let n_steps = (8.0 * 2.0 * std::f64::consts::PI / wd_t / h) as usize;
    for _ in 0..n_steps {
        s.step().unwrap();
        hx.push((s.state.t, s.state.x[0][0] - x0));
        hr.push((s.state.t, s.state.rotation_vector(0)[0]));
    }
    let measure = |hist: &[(f64, f64)], wd: f64| {
        let zc = upward_crossings(hist);
        let n = zc.len() - 1;
        let td = (zc[n] - zc[0]) / n as f64;
        // x(t + Td) = exp(-sigma Td) x(t) for every t: the decrement from samples one measured
        // period apart, where |x| is largest (at the first crossing + Td / 4)
        let amp_at = |t: f64| {
            let i = hist.partition_point(|p| p.0 < t);
            let (p, q) = (hist[i - 1], hist[i]);
            p.1 + (q.1 - p.1) * (t - p.0) / (q.0 - p.0)
        };
        let t1 = zc[0] + 0.25 * 2.0 * std::f64::consts::PI / wd;
        let dec = (amp_at(t1) / amp_at(t1 + (n as f64) * td)).ln() / n as f64;
        (2.0 * std::f64::consts::PI / td, dec)
    };
    let (wd_x, dec_x) = measure(&hx, wd_t);
    let (wd_rm, dec_rm) = measure(&hr, wd_r);
    let ew = |g: f64, e: f64| (g - e).abs() / e;
    println!(
        "x: wd {wd_x:.6} (closed {wd_t:.6}, err {:.1e}), decrement {dec_x:.6} (closed {dec_t:.6}, err {:.1e}); wn h = {:.3e}",
        ew(wd_x, wd_t),
        ew(dec_x, dec_t),
        wn_t * h
    );
    println!(
        "roll: wd {wd_rm:.6} (closed {wd_r:.6}, err {:.1e}), decrement {dec_rm:.6} (closed {dec_r:.6}, err {:.1e}); wn h = {:.3e}",
        ew(wd_rm, wd_r),
        ew(dec_rm, dec_r),
        wn_r * h
    );
    // tolerances: 5x the trapezoidal estimate (w h)^2 / 12 of each motion
    for (g, e, wn) in [
        (wd_x, wd_t, wn_t),
        (dec_x, dec_t, wn_t),
        (wd_rm, wd_r, wn_r),
        (dec_rm, dec_r, wn_r),
    ] {
        let tol = 5.0 * (wn * h).powi(2) / 12.0;
        assert!(
            ew(g, e) < tol,
            "{g} vs closed form {e} (tolerance {tol:.1e})"
        );
    }
}

fn static_deck(extra: &str) -> String {
    format!(
        "[[node]]\nname = \"air\"\nposition_m = [1.0, 2.0, 3.0]\n\n[[joint]]\nname = \"mount\"\ntype = \"bushing\"\nnode_b = \"air\"\nstiffness_N_per_m = [2e5, 3e5, 5e5]\nrot_stiffness_Nm_per_rad = [1e3, 2e3, 4e3]\naxis = [0.0, 1.0, 1.0]\nx_direction = [1.0, 0.0, 0.0]\n{extra}\n"
    )
}

fn solve_static(text: &str) -> State {
    let mut m = model(text);
    let mut st = State::from_model(&m);
    let opts = StaticOptions {
        load_steps: 4,
        ..Default::default()
    };
    static_solve(&mut m, &mut st, &opts, |_, _, _, _| {}).unwrap();
    st
}

/// Joint frame of `static_deck`: z along (0, 1, 1), x along global x.
fn joint_frame() -> [[f64; 3]; 3] {
    let s = 0.5f64.sqrt();
    // columns x, y = z x x, z
    [[1.0, 0.0, 0.0], [0.0, s, s], [0.0, -s, s]]
}

#[test]
fn static_load_and_moment_give_the_closed_form_deflections() {
    let q = joint_frame();
    let (k, kr) = ([2e5, 3e5, 5e5], [1e3, 2e3, 4e3]);
    let expect = |load: [f64; 3], kk: [f64; 3]| -> [f64; 3] {
        let l = mtv(&q, load);
        mv(&q, std::array::from_fn(|i| l[i] / kk[i]))
    };
    // force: displacement P / k in the joint frame (exact: no rotation)
    let p = [300.0, -500.0, 800.0];
    let st = solve_static(&static_deck(&format!(
        "[[load]]\nname = \"p\"\nnode = \"air\"\nforce_N = {p:?}\n"
    )));
    let d = sub(st.x[0], [1.0, 2.0, 3.0]);
    let want = expect(p, k);
    let e = max_abs(&sub(d, want)) / max_abs(&want);
    println!("force: displacement {d:?}, closed form {want:?}, rel err {e:.1e}");
    assert!(e < 1e-9);
    assert!(max_abs(&st.rotation_vector(0)) < 1e-12);
    // moments, small and large: K_r phi equals the applied (fixed) moment for any rotation,
    // so the rotation vector is the moment divided by the stiffness in the joint frame
    let mut worst: f64 = 0.0;
    for scale in [1e-3, 1.0, 3.0] {
        let mo = fmul(scale, [0.5e3, 0.8e3, -1.0e3]);
        let st = solve_static(&static_deck(&format!(
            "[[load]]\nname = \"m\"\nnode = \"air\"\nmoment_Nm = {mo:?}\n"
        )));
        let phi = st.rotation_vector(0);
        let want = expect(mo, kr);
        let e = max_abs(&sub(phi, want)) / max_abs(&want);
        worst = worst.max(e);
        println!(
            "moment {mo:?}: rotation vector {phi:?} (|phi| = {:.3} rad), closed form {want:?}, rel err {e:.1e}",
            dot(phi, phi).sqrt()
        );
        assert!(e < 1e-9);
        assert!(max_abs(&sub(st.x[0], [1.0, 2.0, 3.0])) < 1e-12);
    }
    println!("moments: worst rel error {worst:.1e}");
}

#[test]
fn loads_on_the_two_nodes_are_equal_and_opposite() {
    let mut rng = Rng(7);
    let mut worst: f64 = 0.0;
    for trial in 0..20 {
        let c = bushing_case(&mut rng, false, trial % 2 == 0, true, 2.5);
        let r = res(&c, &c.a, &c.b);
        let fa = [r[0], r[1], r[2]];
        let fb = [r[6], r[7], r[8]];
        // moments about the origin: node moment + x_node x force
        let ma = add([r[3], r[4], r[5]], cross(c.a.x, fa));
        let mb = add([r[9], r[10], r[11]], cross(c.b.x, fb));
        let scale = max_abs(&r);
        let e = max_abs(&add(fa, fb)).max(max_abs(&add(ma, mb))) / scale;
        worst = worst.max(e);
        assert!(e < 1e-13, "trial {trial}: {e:.2e}");
    }
    println!("sum of forces and moments / largest load entry: {worst:.1e}");
}

#[test]
fn grounded_bushing_beside_a_driven_shaft_runs_under_modified_newton() {
    // A grounded bushing has no multipliers: the modified-Newton turn of grounded joints'
    // reactions must skip it (it is the last element, so its multiplier start is past the
    // end of the unknowns). Modified and full Newton give the same motion.
    let text = format!(
        "{AIRFRAME}stiffness_N_per_m = [2e5, 3e5, 5e5]\ndamping_Ns_per_m = [100.0, 100.0, 100.0]\nrot_stiffness_Nm_per_rad = [4e5, 9e5, 2e6]\n\n[[node]]\nname = \"hub\"\nposition_m = [0.0, 0.0, 0.0]\n\n[[rigid_body]]\nname = \"hub_body\"\nnode = \"hub\"\nmass_kg = 50.0\ncm_offset_m = [0.1, 0.0, 0.0]\ninertia_kgm2 = [[20.0, 0.0, 0.0], [0.0, 20.0, 0.0], [0.0, 0.0, 40.0]]\n\n[[joint]]\nname = \"shaft\"\ntype = \"revolute\"\nnode_b = \"hub\"\nomega_rad_s = 20.0\n\n[[joint]]\nname = \"mount2\"\ntype = \"bushing\"\nnode_b = \"air\"\nstiffness_N_per_m = [1e4, 0.0, 0.0]\n"
    );
    let mut finals = vec![];
    for method in [NewtonMethod::Full, NewtonMethod::Modified] {
        let m = model(&text);
        let mut st = State::from_model(&m);
        st.w[1] = [0.0, 0.0, 20.0];
        st.v[0] = [0.1, -0.05, 0.02];
        let mut s = DynamicSolver::new(m, st, 1e-3, 0.9).unwrap();
        s.newton.method = method;
        s.init_accelerations().unwrap();
        for _ in 0..200 {
            s.step().unwrap();
        }
        println!(
            "{method:?}: factorizations {}, iterations {}",
            s.factorizations, s.total_iterations
        );
        finals.push(s.state.x[0]);
    }
    let d = max_abs(&sub(finals[0], finals[1]));
    println!("airframe position, full vs modified Newton: {d:.1e} m");
    assert!(d < 1e-8, "{d}");
}
