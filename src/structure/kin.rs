//! Nodal kinematics passed to element residuals, and evaluation context.
use super::real::{c, Real};
use super::rotation::{M3, V3};

/// Position, rotation, spatial velocities and accelerations of a node in scalar type `T`.
/// `w` is the spatial angular velocity, `al` its time derivative.
#[derive(Clone, Copy, Debug)]
pub struct NodeKin<T> {
    pub x: V3<T>,
    pub r: M3<T>,
    pub v: V3<T>,
    pub w: V3<T>,
    pub a: V3<T>,
    pub al: V3<T>,
}

impl<T: Real> NodeKin<T> {
    pub fn ground() -> Self {
        let z = [c(0.0); 3];
        NodeKin {
            x: z,
            r: super::rotation::ident(),
            v: z,
            w: z,
            a: z,
            al: z,
        }
    }
}

impl NodeKin<f64> {
    /// As 24-lane duals with the 6 seeds `s` of local node `l` in lanes `6l..6l+6` (one
    /// evaluation of a 4-node element then gives all 24 tangent columns).
    pub fn seeded_lanes(&self, l: usize, s: &[Seed; 6]) -> NodeKin<super::real::DualN<24>> {
        use super::rotation::{mm, skew};
        let mut out: NodeKin<super::real::DualN<24>> = self.lift();
        for (c, sd) in s.iter().enumerate() {
            let lane = 6 * l + c;
            let dr = mm(&skew(sd.dth), &self.r);
            for i in 0..3 {
                out.x[i].d[lane] = sd.dx[i];
                out.v[i].d[lane] = sd.dv[i];
                out.w[i].d[lane] = sd.dw[i];
                out.a[i].d[lane] = sd.da[i];
                out.al[i].d[lane] = sd.dal[i];
                for j in 0..3 {
                    out.r[i][j].d[lane] = dr[i][j];
                }
            }
        }
        out
    }

    /// As single-lane duals whose derivative parts are the seed `s` (rotation by the
    /// first-order `R + eps dth~ R`); none: constants.
    pub fn seeded(&self, s: Option<&Seed>) -> NodeKin<super::real::Dual<f64>> {
        use super::real::Dual;
        use super::rotation::{mm, skew};
        let z = Seed::default();
        let s = s.unwrap_or(&z);
        let d = |v: &[f64; 3], e: &[f64; 3]| -> [Dual<f64>; 3] {
            std::array::from_fn(|i| Dual::new(v[i], e[i]))
        };
        let dr = mm(&skew(s.dth), &self.r);
        NodeKin {
            x: d(&self.x, &s.dx),
            r: std::array::from_fn(|i| d(&self.r[i], &dr[i])),
            v: d(&self.v, &s.dv),
            w: d(&self.w, &s.dw),
            a: d(&self.a, &s.da),
            al: d(&self.al, &s.dal),
        }
    }

    /// Lift to a dual-capable scalar with zero derivative parts.
    pub fn lift<T: Real>(&self) -> NodeKin<T> {
        use super::rotation::{m3c, v3c};
        NodeKin {
            x: v3c(&self.x),
            r: m3c(&self.r),
            v: v3c(&self.v),
            w: v3c(&self.w),
            a: v3c(&self.a),
            al: v3c(&self.al),
        }
    }
}

/// Direction of a seeded derivative on one node: configuration perturbation (`dx`, `dth`
/// spatial rotation increment), and velocity/acceleration perturbations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Seed {
    pub dx: [f64; 3],
    pub dth: [f64; 3],
    pub dv: [f64; 3],
    pub dw: [f64; 3],
    pub da: [f64; 3],
    pub dal: [f64; 3],
}

impl Seed {
    /// Generalized-alpha seed of dof `comp` (0-2 translation, 3-5 rotation) of a node:
    /// `dx = h e`, `dth = h T_L e` (`tl` the tangent of the iterate's rotation increment),
    /// `dv = dw = cv e`, `da = dal = ca e`.
    #[inline]
    pub fn generalized_alpha(comp: usize, h: f64, cv: f64, ca: f64, tl: &[[f64; 3]; 3]) -> Self {
        use super::rotation::{fmul, mv};
        let mut e = [0.0; 3];
        e[comp % 3] = 1.0;
        if comp < 3 {
            Seed {
                dx: fmul(h, e),
                dv: fmul(cv, e),
                da: fmul(ca, e),
                ..Default::default()
            }
        } else {
            Seed {
                dth: fmul(h, mv(tl, e)),
                dw: fmul(cv, e),
                dal: fmul(ca, e),
                ..Default::default()
            }
        }
    }
}

/// Evaluation context common to all elements.
#[derive(Clone, Copy, Debug)]
pub struct EvalCtx {
    /// Time [s] (pseudo-time in static analyses).
    pub t: f64,
    /// Multiplier applied to all applied loads (load stepping in static analyses).
    pub load_factor: f64,
    pub gravity: [f64; 3],
    /// Constraint scaling: multipliers are `cscale * lambda_hat`, constraint rows `cscale * Phi`.
    pub cscale: f64,
    /// Whether inertial forces are included.
    pub inertia: bool,
    /// Length of the dynamic step being solved [s] (the residual is at its end, `t`); 0
    /// outside a step (statics, a report at a committed state), where elements with history
    /// (elastomers) hold their committed state.
    pub dt: f64,
}

impl Default for EvalCtx {
    fn default() -> Self {
        EvalCtx {
            t: 0.0,
            load_factor: 1.0,
            gravity: [0.0; 3],
            cscale: 1.0,
            inertia: true,
            dt: 0.0,
        }
    }
}

/// Piecewise-linear time function given as (t, factor) pairs; empty means constant 1.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TimeTable {
    pub points: Vec<(f64, f64)>,
}

impl TimeTable {
    pub fn constant() -> Self {
        TimeTable { points: vec![] }
    }
    pub fn eval(&self, t: f64) -> f64 {
        let p = &self.points;
        if p.is_empty() {
            return 1.0;
        }
        if t <= p[0].0 {
            return p[0].1;
        }
        if t >= p[p.len() - 1].0 {
            return p[p.len() - 1].1;
        }
        let k = p.partition_point(|q| q.0 <= t) - 1;
        let w = (t - p[k].0) / (p[k + 1].0 - p[k].0);
        p[k].1 + w * (p[k + 1].1 - p[k].1)
    }
}
