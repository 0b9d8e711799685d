//! Closed-form joint residual and tangent against the nested-dual reference and central
//! differences, for every joint kind, grounded or not, with prescribed motion and spring/damper,
//! at random large-rotation configurations; and the assembler's two joint paths.
use rotorsim::solver::Assembler;
use rotorsim::structure::rotation::*;
use rotorsim::structure::*;

/// xorshift64*: deterministic, no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        u as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    fn uni(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn v3(&mut self, s: f64) -> [f64; 3] {
        std::array::from_fn(|_| self.uni(-s, s))
    }
    /// Rotation by an angle up to `max` about a random axis.
    fn rot(&mut self, max: f64) -> [[f64; 3]; 3] {
        let ax = loop {
            let v = self.v3(1.0);
            let n = dot(v, v).sqrt();
            if n > 0.1 && n <= 1.0 {
                break fmul(1.0 / n, v);
            }
        };
        exp_map(fmul(self.uni(0.0, max), ax))
    }
    fn kin(&mut self) -> NodeKin<f64> {
        NodeKin {
            x: self.v3(2.0),
            r: self.rot(0.9 * std::f64::consts::PI),
            v: self.v3(3.0),
            w: self.v3(5.0),
            a: self.v3(10.0),
            al: self.v3(10.0),
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Extra {
    None,
    Angle,
    Disp,
    SpringDamper,
    DispSpring,
}

const KINDS: [JointKind; 4] = [
    JointKind::Clamp,
    JointKind::Revolute,
    JointKind::Universal,
    JointKind::Spherical,
];
const EXTRAS: [Extra; 5] = [
    Extra::None,
    Extra::Angle,
    Extra::Disp,
    Extra::SpringDamper,
    Extra::DispSpring,
];

fn table() -> TimeTable {
    TimeTable {
        points: vec![(0.0, 0.0), (0.5, 0.7), (1.0, -0.3)],
    }
}

/// A joint with random frames and offsets, and its evaluation point.
struct Case {
    j: Joint,
    a: NodeKin<f64>,
    b: NodeKin<f64>,
    lam: Vec<f64>,
    ctx: EvalCtx,
    seeds: Vec<[Seed; 6]>,
}

fn case(rng: &mut Rng, kind: JointKind, grounded: bool, extra: Extra, dyn_seeds: bool) -> Case {
    let mut j = Joint::new(
        "j",
        kind,
        (!grounded).then_some((0, [0.0; 3], ident())),
        (1, [0.0; 3], ident()),
        [0.0; 3],
        ident(),
    );
    j.qa = rng.rot(3.0);
    j.qb = rng.rot(3.0);
    j.da = rng.v3(1.5);
    j.db = rng.v3(1.5);
    match extra {
        Extra::None => {}
        Extra::Angle => {
            j.prescribed_angle = Some(AngleLaw {
                omega_rad_s: rng.uni(-30.0, 30.0),
                table: Some(table()),
            })
        }
        Extra::Disp => j.displacement_m = Some((rng.v3(0.2), table())),
        Extra::SpringDamper | Extra::DispSpring => {
            j.spring_nm_per_rad = rng.uni(1e3, 1e5);
            j.damper_nms_per_rad = rng.uni(10.0, 1e3);
            if matches!(extra, Extra::DispSpring) {
                j.displacement_m = Some((rng.v3(0.2), table()));
            }
        }
    }
    j.angle_prev = rng.uni(-20.0, 20.0);
    let a = if grounded {
        NodeKin::ground()
    } else {
        rng.kin()
    };
    let b = rng.kin();
    let lam = (0..j.n_lambda()).map(|_| rng.uni(-1e3, 1e3)).collect();
    let ctx = EvalCtx {
        t: rng.uni(0.0, 1.0),
        cscale: rng.uni(0.5, 50.0),
        ..Default::default()
    };
    let nnodes = 1 + !grounded as usize;
    let seeds = (0..nnodes)
        .map(|_| {
            if dyn_seeds {
                // generalized-alpha seeds: dx = h e, dth = h T_L(h dq) e, dv = dw = cv e,
                // da = dal = ca e
                let h = rng.uni(1e-4, 1e-2);
                let tl = tangent_left(fmul(h, rng.v3(50.0)));
                let cv = rng.uni(0.5, 2.0) / h;
                let ca = cv / (0.3 * h);
                std::array::from_fn(|comp| Seed::generalized_alpha(comp, h, cv, ca, &tl))
            } else {
                // every part of every seed non-zero
                std::array::from_fn(|_| Seed {
                    dx: rng.v3(1.0),
                    dth: rng.v3(1.0),
                    dv: rng.v3(1.0),
                    dw: rng.v3(1.0),
                    da: rng.v3(1.0),
                    dal: rng.v3(1.0),
                })
            }
        })
        .collect();
    Case {
        j,
        a,
        b,
        lam,
        ctx,
        seeds,
    }
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

fn sizes(c: &Case) -> (usize, usize) {
    let nn = if c.j.node_a.is_some() { 12 } else { 6 };
    (nn, nn + c.j.n_lambda())
}

fn res_f64(c: &Case, a: &NodeKin<f64>, b: &NodeKin<f64>, lam: &[f64]) -> Vec<f64> {
    let mut r = vec![0.0; sizes(c).1];
    c.j.residual_f64(a, b, lam, &c.ctx, &mut r);
    r
}

/// Node kinematics moved by `eps` along a seed (rotation by `exp(eps dth) R`).
fn moved(k: &NodeKin<f64>, s: &Seed, eps: f64) -> NodeKin<f64> {
    let st = |x: [f64; 3], d: [f64; 3]| add(x, fmul(eps, d));
    NodeKin {
        x: st(k.x, s.dx),
        r: mm(&exp_map(fmul(eps, s.dth)), &k.r),
        v: st(k.v, s.dv),
        w: st(k.w, s.dw),
        a: st(k.a, s.da),
        al: st(k.al, s.dal),
    }
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
        let mut k = vec![f64::NAN; n * n];
        let mut kd = vec![f64::NAN; n * n];
        c.j.tangent(&c.a, &c.b, &c.lam, &c.ctx, &c.seeds, &mut k);
        c.j.tangent_dual(&c.a, &c.b, &c.lam, &c.ctx, &c.seeds, &mut kd);
        let scale = max_abs(&kd);
        for i in 0..n * n {
            let e = (k[i] - kd[i]).abs() / scale;
            worst = worst.max(e);
            assert!(
                e < 1e-10,
                "{tag}: entry ({}, {}): {} vs {}",
                i / n,
                i % n,
                k[i],
                kd[i]
            );
        }
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

/// Per-joint cost of the two paths (run with `--ignored --nocapture`, release).
#[test]
#[ignore]
fn joint_cost_closed_form_vs_dual() {
    use std::hint::black_box;
    use std::time::Instant;
    let mut rng = Rng(7);
    println!("kind       grounded | residual dual  closed | tangent dual  closed  [ns/call]");
    for kind in KINDS {
        for grounded in [false, true] {
            let c = case(&mut rng, kind, grounded, Extra::SpringDamper, true);
            let n = sizes(&c).1;
            let mut r = vec![0.0; n];
            let mut k = vec![0.0; n * n];
            // best of 5 batches: the least disturbed by other load on the machine
            let time = |f: &mut dyn FnMut()| {
                let reps = 4_000;
                (0..5)
                    .map(|_| {
                        let t0 = Instant::now();
                        for _ in 0..reps {
                            f();
                        }
                        t0.elapsed().as_nanos() as f64 / reps as f64
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let (a, b, lam, ctx, s) = (&c.a, &c.b, &c.lam[..], &c.ctx, &c.seeds[..]);
            let rd = time(&mut || c.j.residual::<f64>(a, b, lam, ctx, black_box(&mut r)));
            let rc = time(&mut || c.j.residual_f64(a, b, lam, ctx, black_box(&mut r)));
            let kd = time(&mut || c.j.tangent_dual(a, b, lam, ctx, s, black_box(&mut k)));
            let kc = time(&mut || c.j.tangent(a, b, lam, ctx, s, black_box(&mut k)));
            println!(
                "{:<10} {:<8} | {rd:>8.0} {rc:>7.0} | {kd:>8.0} {kc:>7.0}",
                format!("{kind:?}"),
                grounded
            );
        }
    }
}
