//! Closed-form joint residual and tangent against the nested-dual reference and central
//! differences, for every joint kind, grounded or not, with prescribed motion and spring/damper,
//! at random large-rotation configurations; and the assembler's two joint paths.
use rotorsim::solver::Assembler;
use rotorsim::structure::rotation::*;
use rotorsim::structure::*;

mod joint_support;
use joint_support::*;

const EXTRAS: [Extra; 6] = [
    Extra::None,
    Extra::Angle,
    Extra::Disp,
    Extra::SpringDamper,
    Extra::DispSpring,
    Extra::Elastomer,
];

fn res_f64(c: &Case, a: &NodeKin<f64>, b: &NodeKin<f64>, lam: &[f64]) -> Vec<f64> {
    let mut r = vec![0.0; sizes(c).1];
    c.j.residual_f64(a, b, lam, &c.ctx, &mut r);
    r
}

/// All cases: kinds x grounded x extras x seed types x trials.
fn for_all_cases(mut f: impl FnMut(&Case, &str)) {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for kind in KINDS {
        for grounded in [false, true] {
            for extra in EXTRAS {
                for dyn_seeds in [true, false] {
                    for trial in 0..4 {
                        let c = case(&mut rng, kind, grounded, extra, dyn_seeds);
                        let tag = format!(
                            "{kind:?} grounded={grounded} {extra:?} dyn_seeds={dyn_seeds} #{trial}"
                        );
                        f(&c, &tag);
                    }
                }
            }
        }
    }
}

#[test]
fn closed_form_residual_matches_dual_residual() {
    let mut worst: f64 = 0.0;
    for_all_cases(|c, tag| {
        let r = res_f64(c, &c.a, &c.b, &c.lam);
        let mut rd = vec![0.0; r.len()];
        c.j.residual::<f64>(&c.a, &c.b, &c.lam, &c.ctx, &mut rd);
        let scale = max_abs(&rd);
        for i in 0..r.len() {
            let e = (r[i] - rd[i]).abs() / scale;
            worst = worst.max(e);
            assert!(e < 1e-13, "{tag}: row {i}: {} vs {}", r[i], rd[i]);
        }
    });
    println!("residual: max |r_closed - r_dual| / max |r| = {worst:.2e}");
}

#[test]
fn closed_form_tangent_matches_dual_tangent() {
    let mut worst: f64 = 0.0;
    for_all_cases(|c, tag| {
        let n = sizes(c).1;
        let (_, e) = tangent_against_dual(c, &c.lam, n, 1e-10, tag);
        worst = worst.max(e);
    });
    println!("tangent: max |K_closed - K_dual| / max |K_dual| = {worst:.2e}");
}

#[test]
fn closed_form_tangent_matches_central_differences() {
    // Step: eps |(dx, dth)| = 1e-5 (lengths and angles are O(1) here). Truncation error of the
    // central difference ~ (eps |seed|)^2 / 6 |r'''| ~ 1e-11 relative, round-off ~ 1e-16 |r| /
    // (eps |seed|) ~ 1e-11 relative (residual entries up to ~1e6 from multipliers and spring,
    // columns of that order times the seed); 1e-7 of the column scale leaves a wide margin
    // while any wrong term (O(1) relative) fails.
    let mut worst: f64 = 0.0;
    for_all_cases(|c, tag| {
        let (nn, n) = sizes(c);
        let mut k = vec![0.0; n * n];
        c.j.tangent(&c.a, &c.b, &c.lam, &c.ctx, &c.seeds, &mut k);
        let has_a = c.j.node_a.is_some();
        let r0 = max_abs(&res_f64(c, &c.a, &c.b, &c.lam));
        for col in 0..n {
            let (rp, rm, step) = if col < nn {
                let (l, comp) = (col / 6, col % 6);
                let s = &c.seeds[l][comp];
                // the residual is linear in w, so only |dx|, |dth| set the step (dw ~ dx / h^2
                // would otherwise shrink it into round-off)
                let size = max_abs(&s.dx).max(max_abs(&s.dth));
                let eps = 1e-5 / if size > 0.0 { size } else { max_abs(&s.dw) };
                let on_a = has_a && l == 0;
                let ev = |e: f64| {
                    if on_a {
                        res_f64(c, &moved(&c.a, s, e), &c.b, &c.lam)
                    } else {
                        res_f64(c, &c.a, &moved(&c.b, s, e), &c.lam)
                    }
                };
                (ev(eps), ev(-eps), eps)
            } else {
                // linear in lam: no truncation error, a large step keeps round-off small
                let eps = 1.0;
                let ev = |e: f64| {
                    let mut l = c.lam.clone();
                    l[col - nn] += e;
                    res_f64(c, &c.a, &c.b, &l)
                };
                (ev(eps), ev(-eps), eps)
            };
            let fd: Vec<f64> = (0..n).map(|i| (rp[i] - rm[i]) / (2.0 * step)).collect();
            let an: Vec<f64> = (0..n).map(|i| k[i * n + col]).collect();
            // column scale: its largest entry, floored by the round-off level of the residual
            let scale = max_abs(&an).max(1e-6 * r0);
            for i in 0..n {
                let e = (an[i] - fd[i]).abs() / scale;
                worst = worst.max(e);
                assert!(
                    e < 1e-7,
                    "{tag}: entry ({i}, {col}): closed {} fd {}",
                    an[i],
                    fd[i]
                );
            }
        }
    });
    println!("tangent vs central differences: max error / column scale = {worst:.2e}");
}

#[test]
fn assembler_closed_form_and_dual_paths_agree() {
    // chain of nodes joined by every kind of joint, two of them grounded, at a random state
    let mut rng = Rng(42);
    let mut m = Model::new();
    let mut ids = vec![];
    for i in 0..5 {
        let x = [i as f64, 0.3 * i as f64, 0.0];
        ids.push(m.add_node(&format!("n{i}"), x, rng.rot(2.0)).unwrap());
    }
    m.add_joint(
        "g0",
        JointKind::Revolute,
        None,
        ids[0],
        [0.0; 3],
        rng.rot(2.0),
    )
    .unwrap();
    m.add_joint(
        "g1",
        JointKind::Clamp,
        None,
        ids[4],
        [4.0, 1.2, 0.1],
        rng.rot(2.0),
    )
    .unwrap();
    for (i, kind) in KINDS.iter().enumerate() {
        let p = add([i as f64, 0.3 * i as f64, 0.0], rng.v3(0.5));
        m.add_joint(
            &format!("j{i}"),
            *kind,
            Some(ids[i]),
            ids[i + 1],
            p,
            rng.rot(2.0),
        )
        .unwrap();
    }
    if let Element::Joint(j) = &mut m.elements[3] {
        j.spring_nm_per_rad = 2e3;
        j.damper_nms_per_rad = 30.0;
    }
    if let Element::Joint(j) = &mut m.elements[0] {
        j.prescribed_angle = Some(AngleLaw {
            omega_rad_s: 4.0,
            table: None,
        });
    }
    let kin: Vec<NodeKin<f64>> = (0..ids.len()).map(|_| rng.kin()).collect();
    let lam: Vec<f64> = (0..m.n_lambda()).map(|_| rng.uni(-10.0, 10.0)).collect();
    let ctx = EvalCtx {
        t: 0.3,
        cscale: 7.0,
        ..Default::default()
    };
    let h = 2e-3;
    let tl: Vec<[[f64; 3]; 3]> = (0..ids.len())
        .map(|_| tangent_left(fmul(h, rng.v3(20.0))))
        .collect();
    let seed = |node: usize, comp: usize| {
        let mut e = [0.0; 3];
        e[comp % 3] = 1.0;
        if comp < 3 {
            Seed {
                dx: fmul(h, e),
                dv: fmul(600.0, e),
                ..Default::default()
            }
        } else {
            Seed {
                dth: fmul(h, mv(&tl[node], e)),
                dw: fmul(600.0, e),
                ..Default::default()
            }
        }
    };
    let nd = 6 * ids.len() + lam.len();
    let mut out = vec![];
    for dual in [false, true] {
        let mut asm = Assembler::new(&m).unwrap();
        asm.joint_tangent_dual = dual;
        let mut res = vec![0.0; nd];
        asm.assemble(&mut m, &kin, &lam, &ctx, &seed, None, true, &mut res)
            .unwrap();
        out.push((res, asm.values.clone()));
    }
    let (rs, ks) = (max_abs(&out[1].0), max_abs(&out[1].1));
    for i in 0..nd {
        assert!((out[0].0[i] - out[1].0[i]).abs() < 1e-13 * rs, "res {i}");
    }
    for p in 0..out[0].1.len() {
        assert!((out[0].1[p] - out[1].1[p]).abs() < 1e-12 * ks, "value {p}");
    }
}
