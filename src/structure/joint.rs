//! Joints as data (rapier style): one constraint implementation parametrised by which relative
//! translations and rotations are locked in a joint frame, plus optional prescribed motion and a
//! rotational spring/damper about the joint axis (local z). A bushing puts springs and dampers
//! on all six relative motions and locks the axes chosen in `Joint::bushing_locked`.
//!
//! Relative rotation in joint frames `Rr = (R_A Q_A)^T (R_B Q_B)`; with a prescribed angle
//! `psi_p(t)` about z, `Rr <- Rz(psi_p)^T Rr`. Locked rotations use
//! `Phi = 1/2 axial(Rr - Rr^T)` components (clamp), `Rr_31, Rr_32` (revolute: z axes stay
//! aligned), `Rr_12` (universal). Translations: `Q_A^T R_A^T (x_B + R_B d_B - x_A - R_A d_A) - u(t)`.
//! Constraint forces `B^T lambda` with `B = dPhi/dq`: in closed form (`residual_f64`, `tangent`,
//! used by the assembler) and, as the reference, by nested dual numbers (`residual`,
//! `tangent_dual`).
use super::elastomer::Elastomer;
use super::kin::{EvalCtx, NodeKin, Seed, TimeTable};
use super::real::{c, Dual, Real};
use super::rotation::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// All relative motion locked.
    Clamp,
    /// Rotation about the joint z axis free.
    Revolute,
    /// Relative rotation about the joint z axis locked (x of A and y of B stay orthogonal).
    Universal,
    /// Only translations locked.
    Spherical,
    /// Springs and dampers on every relative motion ([`BushingCoeffs`]); the axes chosen in
    /// [`Joint::bushing_locked`] are locked.
    Bushing,
}

/// Bushing springs and dampers per joint axis (x, y, z of the joint frame of A). Translation:
/// `u = Q_A^T R_A^T (p_B - p_A)` and its time derivative; rotation: `phi = log(Rr)` and the
/// relative angular velocity `Q_A^T R_A^T (w_B - w_A)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BushingCoeffs {
    pub k_n_per_m: [f64; 3],
    pub c_ns_per_m: [f64; 3],
    pub k_nm_per_rad: [f64; 3],
    pub c_nms_per_rad: [f64; 3],
}

impl BushingCoeffs {
    /// Whether every coefficient is zero (the bushing would do nothing).
    pub fn is_zero(&self) -> bool {
        [
            self.k_n_per_m,
            self.c_ns_per_m,
            self.k_nm_per_rad,
            self.c_nms_per_rad,
        ]
        .iter()
        .flatten()
        .all(|&x| x == 0.0)
    }
}

/// `T_L(phi)^-1 = I - 1/2 phi~ + g phi~^2`, `g = (1 - t/2 cot(t/2)) / t^2`: `d log(exp(e~) R) =
/// T_L^-1 e` for `phi = log R` (series below `t^2 = 1e-2`, error ~1e-16).
pub fn tangent_left_inv(p: V3<f64>) -> M3<f64> {
    let t2 = dot(p, p);
    let g = if t2 < 1e-2 {
        1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 / 1209600.0))
    } else {
        let t = t2.sqrt();
        1.0 / t2 - (1.0 + t.cos()) / (2.0 * t * t.sin())
    };
    let k = skew(p);
    madd(&madd(&ident(), &mscale(-0.5, &k)), &mscale(g, &mm(&k, &k)))
}

#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    pub name: String,
    pub kind: JointKind,
    /// Node A (None = ground), node B.
    pub node_a: Option<usize>,
    pub node_b: usize,
    /// Joint frame in node frames (so that the joint frame is the same at reference).
    pub qa: [[f64; 3]; 3],
    pub qb: [[f64; 3]; 3],
    /// Joint point offsets in node frames (for ground: the global joint point).
    pub da: [f64; 3],
    pub db: [f64; 3],
    /// Prescribed translation of B relative to A in the joint frame, times a time table.
    pub displacement_m: Option<([f64; 3], TimeTable)>,
    /// Prescribed rotation angle about z: `omega t + table(t)` (revolute only: locks z).
    pub prescribed_angle: Option<AngleLaw>,
    pub spring_nm_per_rad: f64,
    pub damper_nms_per_rad: f64,
    /// Springs and dampers of a bushing (used only by `JointKind::Bushing`).
    pub bushing: BushingCoeffs,
    /// Locked axes of a bushing: translation along the joint axes x, y, z of A, then rotation
    /// about them (used only by `JointKind::Bushing`). Translation locks are those of the other
    /// joints; a rotation lock about axis i is the clamp's `1/2 (Rr_kj - Rr_jk)` for that axis,
    /// exact when it is the only rotation and coupled to the other rotations at second order
    /// (e.g. roll locked with pitch and yaw free keeps `1/2 (Rr_32 - Rr_23) = 0`, not
    /// `log(Rr)_x = 0`). Separate from `BushingCoeffs` so that its literals stay valid.
    pub bushing_locked: [bool; 6],
    /// Unwrapped angle at the last converged step (for the spring and sensors).
    pub angle_prev: f64,
    /// An elastomer about the joint axis (a Maxwell chain with its history), in parallel with
    /// the spring and damper; revolute joints only.
    pub elastomer: Option<Elastomer>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct AngleLaw {
    pub omega_rad_s: f64,
    /// Optional added angle table (t, angle_rad).
    pub table: Option<TimeTable>,
}

impl AngleLaw {
    pub fn angle(&self, t: f64) -> f64 {
        self.omega_rad_s * t + self.table.as_ref().map(|tb| tb.eval(t)).unwrap_or(0.0)
    }
}

impl Joint {
    /// Create with the joint frame `q` (columns = joint axes, global) located at point `p`,
    /// given the reference configuration of the nodes.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: &str,
        kind: JointKind,
        node_a: Option<(usize, [f64; 3], [[f64; 3]; 3])>,
        node_b: (usize, [f64; 3], [[f64; 3]; 3]),
        p: [f64; 3],
        q: [[f64; 3]; 3],
    ) -> Self {
        let (na, qa, da) = match node_a {
            Some((i, xa, ra)) => (Some(i), mtm(&ra, &q), mtv(&ra, sub(p, xa))),
            None => (None, q, p),
        };
        let (ib, xb, rb) = node_b;
        Joint {
            name: name.into(),
            kind,
            node_a: na,
            node_b: ib,
            qa,
            qb: mtm(&rb, &q),
            da,
            db: mtv(&rb, sub(p, xb)),
            displacement_m: None,
            prescribed_angle: None,
            spring_nm_per_rad: 0.0,
            damper_nms_per_rad: 0.0,
            bushing: BushingCoeffs::default(),
            bushing_locked: [false; 6],
            angle_prev: 0.0,
            elastomer: None,
        }
    }

    /// Locked (translations, rotations).
    pub fn locks(&self) -> (usize, usize) {
        if self.kind == JointKind::Bushing {
            let l = &self.bushing_locked;
            let n = |s: &[bool]| s.iter().filter(|&&x| x).count();
            return (n(&l[..3]), n(&l[3..]));
        }
        let rot = if self.prescribed_angle.is_some() {
            3
        } else {
            match self.kind {
                JointKind::Clamp => 3,
                JointKind::Revolute => 2,
                JointKind::Universal => 1,
                JointKind::Spherical | JointKind::Bushing => 0,
            }
        };
        (3, rot)
    }

    /// Number of Lagrange multipliers.
    pub fn n_lambda(&self) -> usize {
        let (t, r) = self.locks();
        t + r
    }

    fn rel_rot<T: Real>(&self, a: &NodeKin<T>, b: &NodeKin<T>) -> M3<T> {
        let fa = mm(&a.r, &m3c(&self.qa));
        let fb = mm(&b.r, &m3c(&self.qb));
        mtm(&fa, &fb)
    }

    /// Unwrapped relative angle about the joint z axis.
    pub fn angle<T: Real>(&self, a: &NodeKin<T>, b: &NodeKin<T>) -> T {
        let rr = self.rel_rot(a, b);
        let raw = (rr[1][0] - rr[0][1]).atan2(rr[0][0] + rr[1][1]);
        let turns = ((self.angle_prev - raw.re()) / (2.0 * std::f64::consts::PI)).round();
        raw + c(turns * 2.0 * std::f64::consts::PI)
    }

    /// Constraint functions (length `n_lambda`).
    pub fn phi<T: Real>(&self, a: &NodeKin<T>, b: &NodeKin<T>, t: f64, out: &mut [T]) {
        let fa = mm(&a.r, &m3c(&self.qa));
        let pa = add(a.x, mv(&a.r, v3c(&self.da)));
        let pb = add(b.x, mv(&b.r, v3c(&self.db)));
        let mut d = mtv(&fa, sub(pb, pa));
        if let Some((u, tb)) = &self.displacement_m {
            d = sub(d, fmul(tb.eval(t), v3c(u)));
        }
        let ls = self.lock_set();
        for (q, &k) in ls.trans().iter().enumerate() {
            out[q] = d[k];
        }
        let mut rr = self.rel_rot(a, b);
        if let Some(law) = &self.prescribed_angle {
            let ang = law.angle(t);
            let rz = [
                [c(ang.cos()), c(-ang.sin()), c(0.0)],
                [c(ang.sin()), c(ang.cos()), c(0.0)],
                [c(0.0), c(0.0), c(1.0)],
            ];
            rr = mtm(&rz, &rr);
        }
        for (m, terms) in ls.rot().iter().enumerate() {
            let mut p = c::<T>(0.0);
            for &(cf, i, j) in terms.iter() {
                p += rr[i][j].scale(cf);
            }
            out[ls.nt + m] = p;
        }
    }

    /// Residual: node rows `B^T (cscale lambda_hat)` + spring/damper; multiplier rows
    /// `cscale Phi`. Layout: [node A (6, if any), node B (6), lambda (n_lambda)].
    pub fn residual<T: Real>(
        &self,
        a: &NodeKin<T>,
        b: &NodeKin<T>,
        lam: &[T],
        ctx: &EvalCtx,
        out: &mut [T],
    ) {
        let nl = self.n_lambda();
        let off_b = if self.node_a.is_some() { 6 } else { 0 };
        let nn = off_b + 6;
        let mut ph = [c::<T>(0.0); 6];
        self.phi(a, b, ctx.t, &mut ph);
        for k in 0..nl {
            out[nn + k] += ph[k].scale(ctx.cscale);
        }
        // B columns by dual perturbation of each node dof (none without multipliers)
        let la: NodeKin<Dual<T>> = lift(a);
        let lb: NodeKin<Dual<T>> = lift(b);
        let ncols = if nl > 0 { nn } else { 0 };
        for j in 0..ncols {
            let (node_is_b, comp) = if j >= off_b {
                (true, j - off_b)
            } else {
                (false, j)
            };
            let mut pa = la;
            let mut pb = lb;
            let tgt = if node_is_b { &mut pb } else { &mut pa };
            let mut e = [Dual::cst(0.0); 3];
            if comp < 3 {
                tgt.x[comp] = Dual::new(tgt.x[comp].v, c(1.0));
            } else {
                e[comp - 3] = Dual::new(c(0.0), c(1.0));
                tgt.r = perturb_left(e, &tgt.r);
            }
            let mut phd = [Dual::<T>::cst(0.0); 6];
            self.phi(&pa, &pb, ctx.t, &mut phd);
            let mut s = c::<T>(0.0);
            for k in 0..nl {
                s += phd[k].d * lam[k];
            }
            out[j] += s.scale(ctx.cscale);
        }
        if self.kind == JointKind::Bushing {
            self.bushing_residual(a, b, out);
            return;
        }
        if self.has_spring() {
            let ang = self.angle(a, b);
            let z = mv(&mm(&a.r, &m3c(&self.qa)), [c(0.0), c(0.0), c(1.0)]);
            let rate = dot(z, sub(b.w, a.w));
            let (k, m0) = self.axis_law(ctx.dt);
            let m = ang.scale(k) + c::<T>(m0) + rate.scale(self.damper_nms_per_rad);
            for j in 0..3 {
                out[off_b + 3 + j] += m * z[j];
                if self.node_a.is_some() {
                    out[3 + j] -= m * z[j];
                }
            }
        }
    }
}

/// One rotation constraint `sum coef Rr'_ij` (i, j 0-based).
type RotTerm = &'static [(f64, usize, usize)];

/// Rotation constraints indexed by `nrot`: clamp/prescribed `1/2 axial(Rr' - Rr'^T)` (also a
/// bushing's rotation locks, one axis each), revolute `Rr_31, Rr_32`, universal `Rr_12`.
type RotTerms = &'static [RotTerm];
const ROT_TERMS: [RotTerms; 4] = [
    &[],
    &[&[(1.0, 0, 1)]],
    &[&[(1.0, 2, 0)], &[(1.0, 2, 1)]],
    &[
        &[(0.5, 2, 1), (-0.5, 1, 2)],
        &[(0.5, 0, 2), (-0.5, 2, 0)],
        &[(0.5, 1, 0), (-0.5, 0, 1)],
    ],
];

/// Locked translation axes and rotation constraints in multiplier order (translations first):
/// all three translations for every kind but the bushing, which locks any subset.
#[derive(Clone, Copy)]
struct LockSet {
    trans: [usize; 3],
    nt: usize,
    rot: [RotTerm; 3],
    nr: usize,
}

impl LockSet {
    fn trans(&self) -> &[usize] {
        &self.trans[..self.nt]
    }
    fn rot(&self) -> &[RotTerm] {
        &self.rot[..self.nr]
    }
    fn n(&self) -> usize {
        self.nt + self.nr
    }
}

/// Joint geometry at one configuration (f64), shared by `residual_f64` and `tangent`.
struct Geo {
    /// Joint axes of A, `f_k = R_A Q_A e_k` (translations are measured along them).
    f: [V3<f64>; 3],
    /// Axes of A turned by the prescribed angle, `a_i = R_A Q_A Rz e_i`, and of B,
    /// `b_j = R_B Q_B e_j`: `Rr'_ij = a_i . b_j`.
    ax: [V3<f64>; 3],
    bx: [V3<f64>; 3],
    /// Offsets `rho_A = R_A d_A`, `rho_B = R_B d_B`.
    rho_a: V3<f64>,
    rho_b: V3<f64>,
    /// `p_B - x_A` and `r = p_B - p_A` (joint points `p = x + rho`).
    pb_xa: V3<f64>,
    r: V3<f64>,
}

fn col(m: &M3<f64>, k: usize) -> V3<f64> {
    [m[0][k], m[1][k], m[2][k]]
}

impl Joint {
    fn geo(&self, a: &NodeKin<f64>, b: &NodeKin<f64>, t: f64) -> Geo {
        let fa = mm(&a.r, &self.qa);
        let fb = mm(&b.r, &self.qb);
        let f = [col(&fa, 0), col(&fa, 1), col(&fa, 2)];
        let mut ax = f;
        if let Some(law) = &self.prescribed_angle {
            let (sn, cs) = law.angle(t).sin_cos();
            ax[0] = add(fmul(cs, f[0]), fmul(sn, f[1]));
            ax[1] = sub(fmul(cs, f[1]), fmul(sn, f[0]));
        }
        let rho_a = mv(&a.r, self.da);
        let rho_b = mv(&b.r, self.db);
        let pb = add(b.x, rho_b);
        let pb_xa = sub(pb, a.x);
        Geo {
            f,
            ax,
            bx: [col(&fb, 0), col(&fb, 1), col(&fb, 2)],
            rho_a,
            rho_b,
            pb_xa,
            r: sub(pb_xa, rho_a),
        }
    }

    fn lock_set(&self) -> LockSet {
        let mut s = LockSet {
            trans: [0, 1, 2],
            nt: 3,
            rot: [&[]; 3],
            nr: 0,
        };
        if self.kind == JointKind::Bushing {
            s.nt = 0;
            for (k, _) in self.bushing_locked[..3].iter().enumerate().filter(|p| *p.1) {
                s.trans[s.nt] = k;
                s.nt += 1;
            }
            for (i, _) in self.bushing_locked[3..].iter().enumerate().filter(|p| *p.1) {
                s.rot[s.nr] = ROT_TERMS[3][i];
                s.nr += 1;
            }
        } else {
            let terms = ROT_TERMS[self.locks().1];
            s.rot[..terms.len()].copy_from_slice(terms);
            s.nr = terms.len();
        }
        s
    }

    /// Whether the spring/damper/elastomer about the joint axis acts (never on a bushing,
    /// whose springs are its own).
    fn has_spring(&self) -> bool {
        (self.spring_nm_per_rad != 0.0
            || self.damper_nms_per_rad != 0.0
            || self.elastomer.is_some())
            && self.prescribed_angle.is_none()
            && self.kind != JointKind::Bushing
    }

    /// The elastic part of the axis moment as `k psi + m0` at the end of a step of `dt` [s]
    /// (0: at the committed state): the spring plus the elastomer's step, affine in the end
    /// angle (src/structure/elastomer.rs).
    fn axis_law(&self, dt: f64) -> (f64, f64) {
        match &self.elastomer {
            None => (self.spring_nm_per_rad, 0.0),
            Some(e) => {
                let (slope, m0) = e.affine(dt);
                (self.spring_nm_per_rad + slope, m0)
            }
        }
    }

    /// Accepts the converged configuration at the end of a step of `dt` [s] (0: statics): the
    /// unwrapped angle and the elastomer's history.
    pub fn commit(&mut self, a: &NodeKin<f64>, b: &NodeKin<f64>, dt: f64) {
        let psi = self.angle(a, b);
        self.angle_prev = psi;
        if let Some(e) = &mut self.elastomer {
            e.commit(psi, dt);
        }
    }

    /// Constraint gradients w.r.t. the rotation of A of the rotation constraints,
    /// `w_m = sum coef a_i x b_j` (that w.r.t. B is `-w_m`), from `d(a_i . b_j) =
    /// th_A . (a_i x b_j) - th_B . (a_i x b_j)`.
    fn rot_grads(&self, g: &Geo, ls: &LockSet) -> [V3<f64>; 3] {
        let mut w = [[0.0; 3]; 3];
        for (m, terms) in ls.rot().iter().enumerate() {
            for &(cf, i, j) in terms.iter() {
                w[m] = add(w[m], fmul(cf, cross(g.ax[i], g.bx[j])));
            }
        }
        w
    }

    /// Resultants of the scaled multipliers: force `F = s sum lam_k f_k` on B and moment `M =
    /// s sum lam_m w_m` on A (`-M` on B).
    fn resultants(g: &Geo, lam: &[f64], s: f64, w: &[V3<f64>; 3], ls: &LockSet) -> [V3<f64>; 2] {
        let mut fo = [0.0; 3];
        for (q, &k) in ls.trans().iter().enumerate() {
            fo = add(fo, fmul(s * lam[q], g.f[k]));
        }
        let mut mo = [0.0; 3];
        for m in 0..ls.nr {
            mo = add(mo, fmul(s * lam[ls.nt + m], w[m]));
        }
        [fo, mo]
    }

    /// Residual in closed form, same value and layout as `residual::<f64>` (accumulated).
    /// Constraint gradients (left rotation increments `th`, `d f = th x f`):
    /// translation `k`: `B = [-f_k, f_k x (p_B - x_A), f_k, rho_B x f_k]` (the term
    /// `f_k . rho_A = Q_A e_k . d_A` is constant); rotation `m`: `B = [0, w_m, 0, -w_m]`.
    /// So `B^T s lam = [-F, F x (p_B - x_A) + M, F, rho_B x F - M]`.
    pub fn residual_f64(
        &self,
        a: &NodeKin<f64>,
        b: &NodeKin<f64>,
        lam: &[f64],
        ctx: &EvalCtx,
        out: &mut [f64],
    ) {
        let ls = self.lock_set();
        if self.kind == JointKind::Bushing {
            self.bushing_residual(a, b, out);
            if ls.n() == 0 {
                return;
            }
        }
        let has_a = self.node_a.is_some();
        let off_b = if has_a { 6 } else { 0 };
        let nn = off_b + 6;
        let g = self.geo(a, b, ctx.t);
        let s = ctx.cscale;
        let u = self.prescribed_disp(ctx.t);
        for (q, &k) in ls.trans().iter().enumerate() {
            out[nn + q] += s * (dot(g.f[k], g.r) - u[k]);
        }
        for (m, terms) in ls.rot().iter().enumerate() {
            let p: f64 = terms
                .iter()
                .map(|&(cf, i, j)| cf * dot(g.ax[i], g.bx[j]))
                .sum();
            out[nn + ls.nt + m] += s * p;
        }
        let w = self.rot_grads(&g, &ls);
        let [fo, mo] = Self::resultants(&g, lam, s, &w, &ls);
        let mut add_to = |o: usize, v: V3<f64>| {
            for i in 0..3 {
                out[o + i] += v[i];
            }
        };
        if has_a {
            add_to(0, fmul(-1.0, fo));
            add_to(3, add(cross(fo, g.pb_xa), mo));
        }
        add_to(off_b, fo);
        add_to(off_b + 3, sub(cross(g.rho_b, fo), mo));
        if self.has_spring() {
            let z = g.f[2];
            let mz = fmul(self.spring_moment(a, b, z, ctx.dt), z);
            add_to(off_b + 3, mz);
            if has_a {
                add_to(3, fmul(-1.0, mz));
            }
        }
    }

    fn prescribed_disp(&self, t: f64) -> V3<f64> {
        match &self.displacement_m {
            Some((u, tb)) => fmul(tb.eval(t), *u),
            None => [0.0; 3],
        }
    }

    /// The moment the joint transmits about its free z axis: its own spring, damper and
    /// elastomer, `k psi + c psi' + m_e` (psi the unwrapped [`Joint::angle`], psi' the relative
    /// angular velocity about the axis, `m_e` the elastomer's moment with its branches as
    /// committed), what node B's side exerts on node A's side about +z (B receives `-m z`); the
    /// constraint moments are normal to the axis. Zero for a joint without them, with a
    /// prescribed angle, or a bushing (whose springs act on six axes).
    pub fn axis_moment(&self, a: &NodeKin<f64>, b: &NodeKin<f64>) -> f64 {
        if !self.has_spring() {
            return 0.0;
        }
        let z = mv(&mm(&a.r, &self.qa), [0.0, 0.0, 1.0]);
        self.spring_moment(a, b, z, 0.0)
    }

    /// The elastomer's part of [`Joint::axis_moment`] (its branches as committed) [N m]; 0
    /// without one.
    pub fn elastomer_moment(&self, a: &NodeKin<f64>, b: &NodeKin<f64>) -> f64 {
        match (&self.elastomer, self.has_spring()) {
            (Some(e), true) => e.step(self.angle(a, b), 0.0).moment_nm,
            _ => 0.0,
        }
    }

    /// Spring/damper/elastomer moment `k psi + m0 + c z . (w_B - w_A)` about the joint axis
    /// `z` at the end of a step of `dt` ([`Joint::axis_law`]).
    fn spring_moment(&self, a: &NodeKin<f64>, b: &NodeKin<f64>, z: V3<f64>, dt: f64) -> f64 {
        let (k, m0) = self.axis_law(dt);
        self.angle(a, b) * k + m0 + dot(z, sub(b.w, a.w)) * self.damper_nms_per_rad
    }

    /// Tangent in closed form, same as `tangent_dual`: the directional derivative of
    /// `residual_f64` along each seed (columns of node dofs) and `d/d lam` (multiplier
    /// columns), local n x n, row-major, overwritten. Node columns differentiate the
    /// residual above with `d f = th_A x f`, `d b = th_B x b`, `d rho = th x rho` (geometric
    /// stiffness of the constraints) and, for the spring, `d psi = (th_A - th_B) . g_psi`
    /// (derivative of `atan2(Rr_21 - Rr_12, Rr_11 + Rr_22)`), `d z = th_A x z`.
    pub fn tangent(
        &self,
        a: &NodeKin<f64>,
        b: &NodeKin<f64>,
        lam: &[f64],
        ctx: &EvalCtx,
        seeds: &[[Seed; 6]],
        out: &mut [f64],
    ) {
        let ls = self.lock_set();
        let has_a = self.node_a.is_some();
        let off_b = if has_a { 6 } else { 0 };
        let nn = off_b + 6;
        let n = nn + ls.n();
        out[..n * n].iter_mut().for_each(|x| *x = 0.0);
        if ls.n() == 0 {
            // a bushing without locks: its springs alone
            self.bushing_tangent(a, b, seeds, n, out);
            return;
        }
        let g = self.geo(a, b, ctx.t);
        let s = ctx.cscale;
        let w = self.rot_grads(&g, &ls);
        let [fo, _] = Self::resultants(&g, lam, s, &w, &ls);
        let mut set = |row: usize, col: usize, v: V3<f64>| {
            for i in 0..3 {
                out[(row + i) * n + col] = v[i];
            }
        };
        // multiplier columns: s B^T
        for (q, &k) in ls.trans().iter().enumerate() {
            let fk = fmul(s, g.f[k]);
            if has_a {
                set(0, nn + q, fmul(-1.0, fk));
                set(3, nn + q, cross(fk, g.pb_xa));
            }
            set(off_b, nn + q, fk);
            set(off_b + 3, nn + q, cross(g.rho_b, fk));
        }
        for m in 0..ls.nr {
            let wm = fmul(s, w[m]);
            if has_a {
                set(3, nn + ls.nt + m, wm);
            }
            set(off_b + 3, nn + ls.nt + m, fmul(-1.0, wm));
        }
        // spring/damper: moment m z, d m = k d psi + c (d z . (w_B - w_A) + z . (dw_B - dw_A))
        let spring = self.has_spring().then(|| {
            let z = g.f[2];
            let (f0, f1, b0, b1) = (g.f[0], g.f[1], g.bx[0], g.bx[1]);
            let sn = dot(f1, b0) - dot(f0, b1);
            let cs = dot(f0, b0) + dot(f1, b1);
            let gs = sub(cross(f1, b0), cross(f0, b1));
            let gc = add(cross(f0, b0), cross(f1, b1));
            let gpsi = fmul(1.0 / (sn * sn + cs * cs), sub(fmul(cs, gs), fmul(sn, gc)));
            let k = self.axis_law(ctx.dt).0;
            (
                z,
                self.spring_moment(a, b, z, ctx.dt),
                gpsi,
                sub(b.w, a.w),
                k,
            )
        });
        let zero = [0.0; 3];
        for col in 0..nn {
            let (l, comp) = (col / 6, col % 6);
            let sd = &seeds[l][comp];
            let (dxa, ta, dwa, dxb, tb, dwb) = if has_a && l == 0 {
                (sd.dx, sd.dth, sd.dw, zero, zero, zero)
            } else {
                (zero, zero, zero, sd.dx, sd.dth, sd.dw)
            };
            let mut c = [0.0; 18];
            // constraint rows: s dPhi
            let drho_a = cross(ta, g.rho_a);
            let drho_b = cross(tb, g.rho_b);
            let dpb_xa = sub(add(dxb, drho_b), dxa);
            let dr = sub(dpb_xa, drho_a);
            for (q, &k) in ls.trans().iter().enumerate() {
                c[nn + q] = s * (dot(cross(ta, g.f[k]), g.r) + dot(g.f[k], dr));
            }
            let da: [V3<f64>; 3] = std::array::from_fn(|i| cross(ta, g.ax[i]));
            let db: [V3<f64>; 3] = std::array::from_fn(|j| cross(tb, g.bx[j]));
            let mut dmo = [0.0; 3];
            for (m, tm) in ls.rot().iter().enumerate() {
                let mut dp = 0.0;
                let mut dw = [0.0; 3];
                for &(cf, i, j) in tm.iter() {
                    dp += cf * (dot(da[i], g.bx[j]) + dot(g.ax[i], db[j]));
                    let t = add(cross(da[i], g.bx[j]), cross(g.ax[i], db[j]));
                    dw = add(dw, fmul(cf, t));
                }
                c[nn + ls.nt + m] = s * dp;
                dmo = add(dmo, fmul(s * lam[ls.nt + m], dw));
            }
            // node rows: d(B^T s lam), with d F = th_A x F
            let dfo = cross(ta, fo);
            let mut mom_a = add(add(cross(dfo, g.pb_xa), cross(fo, dpb_xa)), dmo);
            let mut mom_b = sub(add(cross(drho_b, fo), cross(g.rho_b, dfo)), dmo);
            if let Some((z, mz, gpsi, wr, k)) = spring {
                let dz = cross(ta, z);
                let dm = k * dot(sub(ta, tb), gpsi)
                    + self.damper_nms_per_rad * (dot(dz, wr) + dot(z, sub(dwb, dwa)));
                let dmz = add(fmul(dm, z), fmul(mz, dz));
                mom_a = sub(mom_a, dmz);
                mom_b = add(mom_b, dmz);
            }
            if has_a {
                c[..3].copy_from_slice(&fmul(-1.0, dfo));
                c[3..6].copy_from_slice(&mom_a);
            }
            c[off_b..off_b + 3].copy_from_slice(&dfo);
            c[off_b + 3..off_b + 6].copy_from_slice(&mom_b);
            for row in 0..n {
                out[row * n + col] = c[row];
            }
        }
        if self.kind == JointKind::Bushing {
            self.bushing_tangent(a, b, seeds, n, out);
        }
    }

    /// Reference tangent by dual numbers: one `residual::<Dual<f64>>` per column, node `l`
    /// seeded along `seeds[l][comp]` (rotations by the first-order `R + eps dth~ R`). Same
    /// signature and layout as `tangent`.
    pub fn tangent_dual(
        &self,
        a: &NodeKin<f64>,
        b: &NodeKin<f64>,
        lam: &[f64],
        ctx: &EvalCtx,
        seeds: &[[Seed; 6]],
        out: &mut [f64],
    ) {
        let has_a = self.node_a.is_some();
        let nn = if has_a { 12 } else { 6 };
        let nl = self.n_lambda();
        let n = nn + nl;
        let (ad0, bd0) = (a.seeded(None), b.seeded(None));
        let mut ld = [Dual::<f64>::cst(0.0); 6];
        for k in 0..nl {
            ld[k] = Dual::new(lam[k], 0.0);
        }
        let mut o = [Dual::<f64>::cst(0.0); 18];
        for col in 0..n {
            let (mut ad, mut bd) = (ad0, bd0);
            if col < nn {
                let (l, comp) = (col / 6, col % 6);
                let s = &seeds[l][comp];
                if has_a && l == 0 {
                    ad = a.seeded(Some(s));
                } else {
                    bd = b.seeded(Some(s));
                }
            } else {
                ld[col - nn].d = 1.0;
            }
            o[..n].iter_mut().for_each(|x| *x = Dual::cst(0.0));
            self.residual(&ad, &bd, &ld[..nl], ctx, &mut o[..n]);
            if col >= nn {
                ld[col - nn].d = 0.0;
            }
            for row in 0..n {
                out[row * n + col] = o[row].d;
            }
        }
    }
}

/// Bushing: spring/damper forces in the joint frame of A, `s_t = K_t u + C_t u_dot`,
/// `s_r = K_r phi + C_r Om`, with `u = F^T (p_B - p_A)`, `u_dot = F^T v_g`,
/// `v_g = v_B - v_A + w_B x rho_B - w_A x (p_B - x_A)` (exact rate of `u`), `phi = log(F^T R_B
/// Q_B)`, `Om = F^T (w_B - w_A)`, `F = R_A Q_A`. Global force `f = F s_t` at the joint point
/// `p_B` and moment `m = F s_r`: the force is the gradient of `1/2 u.K_t u` (same gradient as a
/// joint's translation multipliers), hence rows `[-f, f x (p_B - x_A) - m, f, rho_B x f + m]`
/// (equal and opposite about any point).
impl Joint {
    // out of line, so that the other joints' residual and tangent stay compact
    #[inline(never)]
    fn bushing_residual<T: Real>(&self, a: &NodeKin<T>, b: &NodeKin<T>, out: &mut [T]) {
        let k = &self.bushing;
        let fa = mm(&a.r, &m3c(&self.qa));
        let fb = mm(&b.r, &m3c(&self.qb));
        let rho_a = mv(&a.r, v3c(&self.da));
        let rho_b = mv(&b.r, v3c(&self.db));
        let pb_xa = sub(add(b.x, rho_b), a.x);
        let u = mtv(&fa, sub(pb_xa, rho_a));
        let vg = sub(add(sub(b.v, a.v), cross(b.w, rho_b)), cross(a.w, pb_xa));
        let ud = mtv(&fa, vg);
        let phi = log_map(&mtm(&fa, &fb));
        let om = mtv(&fa, sub(b.w, a.w));
        let st: V3<T> =
            std::array::from_fn(|i| u[i].scale(k.k_n_per_m[i]) + ud[i].scale(k.c_ns_per_m[i]));
        let sr: V3<T> = std::array::from_fn(|i| {
            phi[i].scale(k.k_nm_per_rad[i]) + om[i].scale(k.c_nms_per_rad[i])
        });
        let f = mv(&fa, st);
        let m = mv(&fa, sr);
        let off_b = if self.node_a.is_some() {
            let ma = sub(cross(f, pb_xa), m);
            for i in 0..3 {
                out[i] -= f[i];
                out[3 + i] += ma[i];
            }
            6
        } else {
            0
        };
        let mb = add(cross(rho_b, f), m);
        for i in 0..3 {
            out[off_b + i] += f[i];
            out[off_b + 3 + i] += mb[i];
        }
    }

    /// Closed-form bushing springs' tangent, added to the node rows and columns of `out` (row
    /// length `n`, same layout as `tangent`; the multiplier parts are the constraint code's). With `d F = th_A~ F`, `d rho = th x rho`:
    /// `du = F^T (dr - th_A x r)`, `du_dot = F^T (dv_g - th_A x v_g)`,
    /// `dphi = T_L(phi)^-1 F^T (th_B - th_A)`, `dOm = F^T (dw_B - dw_A - th_A x (w_B - w_A))`,
    /// `df = th_A x f + F ds_t`, `dm = th_A x m + F ds_r`; the damping parts enter through the
    /// seeds' `dv`, `dw` (generalized-alpha: `gamma/(beta h)`), as for beams' damping.
    // out of line, so that the other joints' residual and tangent stay compact
    #[inline(never)]
    fn bushing_tangent(
        &self,
        a: &NodeKin<f64>,
        b: &NodeKin<f64>,
        seeds: &[[Seed; 6]],
        n: usize,
        out: &mut [f64],
    ) {
        let k = &self.bushing;
        let has_a = self.node_a.is_some();
        let off_b = if has_a { 6 } else { 0 };
        let nn = off_b + 6;
        let fa = mm(&a.r, &self.qa);
        let fb = mm(&b.r, &self.qb);
        let rho_a = mv(&a.r, self.da);
        let rho_b = mv(&b.r, self.db);
        let pb_xa = sub(add(b.x, rho_b), a.x);
        let r = sub(pb_xa, rho_a);
        let u = mtv(&fa, r);
        let vg = sub(add(sub(b.v, a.v), cross(b.w, rho_b)), cross(a.w, pb_xa));
        let ud = mtv(&fa, vg);
        let phi = log_map(&mtm(&fa, &fb));
        let tinv = tangent_left_inv(phi);
        let wg = sub(b.w, a.w);
        let om = mtv(&fa, wg);
        let st: V3<f64> = std::array::from_fn(|i| k.k_n_per_m[i] * u[i] + k.c_ns_per_m[i] * ud[i]);
        let sr: V3<f64> =
            std::array::from_fn(|i| k.k_nm_per_rad[i] * phi[i] + k.c_nms_per_rad[i] * om[i]);
        let f = mv(&fa, st);
        let m = mv(&fa, sr);
        let zero = [0.0; 3];
        for col in 0..nn {
            let (l, comp) = (col / 6, col % 6);
            let sd = &seeds[l][comp];
            let (dxa, ta, dva, dwa, dxb, tb, dvb, dwb) = if has_a && l == 0 {
                (sd.dx, sd.dth, sd.dv, sd.dw, zero, zero, zero, zero)
            } else {
                (zero, zero, zero, zero, sd.dx, sd.dth, sd.dv, sd.dw)
            };
            let drho_a = cross(ta, rho_a);
            let drho_b = cross(tb, rho_b);
            let dpb_xa = sub(add(dxb, drho_b), dxa);
            let dr = sub(dpb_xa, drho_a);
            let du = mtv(&fa, sub(dr, cross(ta, r)));
            let dvg = add(
                add(sub(dvb, dva), add(cross(dwb, rho_b), cross(b.w, drho_b))),
                fmul(-1.0, add(cross(dwa, pb_xa), cross(a.w, dpb_xa))),
            );
            let dud = mtv(&fa, sub(dvg, cross(ta, vg)));
            let dphi = mv(&tinv, mtv(&fa, sub(tb, ta)));
            let dom = mtv(&fa, sub(sub(dwb, dwa), cross(ta, wg)));
            let dst: V3<f64> =
                std::array::from_fn(|i| k.k_n_per_m[i] * du[i] + k.c_ns_per_m[i] * dud[i]);
            let dsr: V3<f64> =
                std::array::from_fn(|i| k.k_nm_per_rad[i] * dphi[i] + k.c_nms_per_rad[i] * dom[i]);
            let df = add(cross(ta, f), mv(&fa, dst));
            let dm = add(cross(ta, m), mv(&fa, dsr));
            let mut c = [0.0; 12];
            if has_a {
                let dma = sub(add(cross(df, pb_xa), cross(f, dpb_xa)), dm);
                c[..3].copy_from_slice(&fmul(-1.0, df));
                c[3..6].copy_from_slice(&dma);
            }
            let dmb = add(add(cross(drho_b, f), cross(rho_b, df)), dm);
            c[off_b..off_b + 3].copy_from_slice(&df);
            c[off_b + 3..off_b + 6].copy_from_slice(&dmb);
            for row in 0..nn {
                out[row * n + col] += c[row];
            }
        }
    }
}

fn lift<T: Real>(k: &NodeKin<T>) -> NodeKin<Dual<T>> {
    let l = |v: &V3<T>| -> V3<Dual<T>> { std::array::from_fn(|i| Dual::new(v[i], c(0.0))) };
    NodeKin {
        x: l(&k.x),
        r: std::array::from_fn(|i| l(&k.r[i])),
        v: l(&k.v),
        w: l(&k.w),
        a: l(&k.a),
        al: l(&k.al),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_lock_sets_keep_the_old_layout_and_order_bushing_locks() {
        let mut j = Joint::new(
            "j",
            JointKind::Clamp,
            None,
            (0, [0.0; 3], ident()),
            [0.0; 3],
            ident(),
        );
        for (kind, nrot) in [
            (JointKind::Clamp, 3),
            (JointKind::Revolute, 2),
            (JointKind::Universal, 1),
            (JointKind::Spherical, 0),
        ] {
            j.kind = kind;
            let ls = j.lock_set();
            assert_eq!(ls.trans(), &[0, 1, 2]);
            assert_eq!(ls.rot(), ROT_TERMS[nrot]);
            assert_eq!(j.locks(), (3, nrot));
        }
        j.kind = JointKind::Bushing;
        assert_eq!(j.locks(), (0, 0));
        // deck order is irrelevant: translations in axis order, then rotations
        j.bushing_locked = [false, true, true, true, false, true];
        let ls = j.lock_set();
        assert_eq!(ls.trans(), &[1, 2]);
        assert_eq!(ls.rot(), &[ROT_TERMS[3][0], ROT_TERMS[3][2]]);
        assert_eq!((j.locks(), j.n_lambda()), ((2, 2), 4));
    }

    #[test]
    fn tangent_left_inv_inverts_tangent_left_on_both_branches() {
        // |phi|^2 across the series threshold 1e-2 and up to 2.9 rad
        for p in [
            [0.0, 0.0, 0.0],
            [1e-6, -2e-6, 5e-7],
            [0.05, -0.07, 0.02],
            [0.06, 0.05, -0.04],
            [0.1, 0.0, 0.02],
            [0.4, -0.7, 0.2],
            [2.0, 1.5, -1.2],
        ] {
            let m = mm(&tangent_left_inv(p), &tangent_left::<f64>(p));
            for (i, row) in m.iter().enumerate() {
                for (j, x) in row.iter().enumerate() {
                    let e = (x - if i == j { 1.0 } else { 0.0 }).abs();
                    assert!(e < 1e-14, "{p:?}: ({i}, {j}) {x}");
                }
            }
        }
    }
}
