//! Random joint cases (frames, offsets, prescribed motion, spring and damper, evaluation
//! point and generalized-alpha seeds) shared by the joint tangent tests and the joint cost
//! benchmark (benches/structure_tangent.rs).
#![allow(dead_code)]
use rotorsim::structure::elastomer::{Elastomer, ElastomerState, MaxwellChain};
use rotorsim::structure::rotation::*;
use rotorsim::structure::*;

/// xorshift64*: deterministic, no dependency.
pub struct Rng(pub u64);

impl Rng {
    pub fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let u = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11;
        u as f64 / (1u64 << 53) as f64
    }
    /// Uniform in [lo, hi).
    pub fn uni(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub fn v3(&mut self, s: f64) -> [f64; 3] {
        std::array::from_fn(|_| self.uni(-s, s))
    }
    /// Rotation by an angle up to `max` about a random axis.
    pub fn rot(&mut self, max: f64) -> [[f64; 3]; 3] {
        let ax = loop {
            let v = self.v3(1.0);
            let n = dot(v, v).sqrt();
            if n > 0.1 && n <= 1.0 {
                break fmul(1.0 / n, v);
            }
        };
        exp_map(fmul(self.uni(0.0, max), ax))
    }
    pub fn kin(&mut self) -> NodeKin<f64> {
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
pub enum Extra {
    None,
    Angle,
    Disp,
    SpringDamper,
    DispSpring,
    /// Spring, damper and an elastomer with history, inside a step or at a committed state.
    Elastomer,
}

pub const KINDS: [JointKind; 4] = [
    JointKind::Clamp,
    JointKind::Revolute,
    JointKind::Universal,
    JointKind::Spherical,
];

pub fn table() -> TimeTable {
    TimeTable {
        points: vec![(0.0, 0.0), (0.5, 0.7), (1.0, -0.3)],
    }
}

/// A joint with random frames and offsets, and its evaluation point.
pub struct Case {
    pub j: Joint,
    pub a: NodeKin<f64>,
    pub b: NodeKin<f64>,
    pub lam: Vec<f64>,
    pub ctx: EvalCtx,
    pub seeds: Vec<[Seed; 6]>,
}

pub fn case(rng: &mut Rng, kind: JointKind, grounded: bool, extra: Extra, dyn_seeds: bool) -> Case {
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
        Extra::Elastomer => {
            j.spring_nm_per_rad = rng.uni(1e3, 1e5);
            j.damper_nms_per_rad = rng.uni(10.0, 1e3);
            let w = rng.uni(5.0, 50.0);
            let chain =
                MaxwellChain::fit(rng.uni(1e3, 1e5), rng.uni(0.05, 0.3), 0.3 * w, 4.0 * w, w)
                    .expect("a passive chain");
            let mut e = Elastomer::new(chain);
            e.committed = ElastomerState {
                angle_rad: rng.uni(-20.0, 20.0),
                branch_nm: std::array::from_fn(|_| rng.uni(-1e3, 1e3)),
            };
            j.elastomer = Some(e);
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
        // inside a step (the elastomer's step moment) or at a committed state
        dt: if rng.uni(0.0, 1.0) < 0.5 {
            0.0
        } else {
            rng.uni(1e-4, 1e-2)
        },
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

pub fn sizes(c: &Case) -> (usize, usize) {
    let nn = if c.j.node_a.is_some() { 12 } else { 6 };
    (nn, nn + c.j.n_lambda())
}

/// Largest absolute entry.
pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// Node kinematics moved by `eps` along a seed (rotation by `exp(eps dth) R`).
pub fn moved(k: &NodeKin<f64>, s: &Seed, eps: f64) -> NodeKin<f64> {
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

/// The closed-form tangent of `c` (multipliers `lam`) against its dual-number reference:
/// every entry within `tol` of the largest dual entry, else a panic naming `tag`, the entry
/// and both values. Returns the closed-form tangent (n x n, row-major) and the worst error.
pub fn tangent_against_dual(
    c: &Case,
    lam: &[f64],
    n: usize,
    tol: f64,
    tag: &str,
) -> (Vec<f64>, f64) {
    let mut k = vec![f64::NAN; n * n];
    let mut kd = vec![f64::NAN; n * n];
    c.j.tangent(&c.a, &c.b, lam, &c.ctx, &c.seeds, &mut k);
    c.j.tangent_dual(&c.a, &c.b, lam, &c.ctx, &c.seeds, &mut kd);
    let scale = max_abs(&kd);
    let mut worst: f64 = 0.0;
    for i in 0..n * n {
        let e = (k[i] - kd[i]).abs() / scale;
        worst = worst.max(e);
        assert!(
            e < tol,
            "{tag}: entry ({}, {}): {} vs dual {}",
            i / n,
            i % n,
            k[i],
            kd[i]
        );
    }
    (k, worst)
}
