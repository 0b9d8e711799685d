//! Geometrically exact (Reissner-Simo) beam element, 4 nodes (cubic Lagrange).
//!
//! Objective interpolation (Crisfield & Jelenic 1999): a reference rotation `R_r` halfway
//! between the two interior nodes, local rotation vectors `psi_i = log(R_r^T R_i)` interpolated,
//! `R(s) = R_r exp(psi(s))`. Strains (material): `Gamma = R^T x' - Gamma_0`,
//! `kappa = T_R(psi) psi' - kappa_0`. Weak form with virtual displacements and spatial virtual
//! rotations interpolated with the same shape functions (as in BeamDyn / Simo & Vu-Quoc):
//! `r_x,i = int N_i' F`, `r_th,i = int (N_i' M - N_i x' x F)` with `F = R C_N eps`,
//! `M = R C_M eps`. Stiffness terms use reduced 3-point Gauss integration (shear locking),
//! inertia and loads 4 points. Elastic, dissipative, inertial and external parts are separate
//! functions; the tangent is their exact derivative, in closed form in `beam_tangent.rs` and by
//! dual numbers (the reference) when the residual is evaluated with `DualN`.
use super::kin::{EvalCtx, NodeKin, TimeTable};
use super::real::{c, Real};
use super::rotation::*;
use super::section::SectionTable;

pub const NPTS_K: usize = 3;
pub const NPTS_M: usize = 4;

/// Stiffness quadrature point data (computed once from the reference configuration).
#[derive(Clone, Debug)]
pub struct GaussK {
    pub wj: f64,
    pub n: [f64; 4],
    /// dN/ds (per unit reference arc length)
    pub ds: [f64; 4],
    pub s_m: f64,
    pub cmat: [[f64; 6]; 6],
    pub gamma0: [f64; 3],
    pub kappa0: [f64; 3],
}

/// Inertia/load quadrature point data.
#[derive(Clone, Debug)]
pub struct GaussM {
    pub wj: f64,
    pub n: [f64; 4],
    pub s_m: f64,
    pub m: f64,
    pub xi: [f64; 3],
    pub jref: [[f64; 3]; 3],
}

/// Constant distributed load per unit length, optionally follower (section frame).
#[derive(Clone, Debug, PartialEq)]
pub struct BeamLoad {
    pub force_n_per_m: [f64; 3],
    pub moment_nm_per_m: [f64; 3],
    pub follower: bool,
    pub time: TimeTable,
}

/// Externally supplied load density at an inertia quadrature point, cached per evaluation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SectionLoad {
    pub force: [f64; 3],
    pub moment: [f64; 3],
    /// `true`: components in the section frame (follower, rotates with the section).
    pub follower: bool,
}

/// Interpolation of one nodal configuration: reference rotation, local rotation vectors and
/// the section rotations at the inertia points.
#[derive(Clone, Copy, Debug)]
pub struct Interp {
    pub rr: M3<f64>,
    pub psi: [V3<f64>; 4],
    pub rg: [M3<f64>; NPTS_M],
}

/// Inertial minus applied load per unit length at an inertia point ([`Beam::point_densities`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointDensity {
    pub s_m: f64,
    pub weight_m: f64,
    pub x: [f64; 3],
    pub force_n_per_m: [f64; 3],
    /// About `x`.
    pub moment_nm_per_m: [f64; 3],
}

#[derive(Clone, Debug)]
pub struct Beam {
    pub name: String,
    pub nodes: [usize; 4],
    pub gk: [GaussK; NPTS_K],
    pub gm: [GaussM; NPTS_M],
    /// Stiffness-proportional damping coefficient mu [s]: forces `C (eps + mu eps_dot)`.
    pub damping_mu_s: f64,
    pub loads: Vec<BeamLoad>,
    /// Loads from [`DistributedLoad`](super::model::DistributedLoad) providers, per gm point.
    pub ext: [SectionLoad; NPTS_M],
    /// Reference arc length at the element ends.
    pub s_range: [f64; 2],
    /// Interpolation of the last [`Beam::load_points_cached`] configuration, reused by
    /// [`Beam::residual_f64`] at the same configuration (the distributed loads and the residual
    /// of one Newton iterate see the same nodes).
    pub cache: InterpCache,
}

/// Reference rotation, local rotation vectors and inertia-point rotations of one nodal
/// configuration (positions and rotations of the 4 nodes, compared bit for bit).
#[derive(Clone, Debug, Default)]
pub struct InterpCache {
    valid: bool,
    x: [[f64; 3]; 4],
    r: [M3<f64>; 4],
    rr: M3<f64>,
    psi: [V3<f64>; 4],
    rg: [M3<f64>; NPTS_M],
}

impl InterpCache {
    fn holds(&self, k: &[NodeKin<f64>; 4]) -> bool {
        self.valid && (0..4).all(|i| self.x[i] == k[i].x && self.r[i] == k[i].r)
    }
}

/// Gauss-Legendre points and weights on [-1, 1].
pub fn gauss(n: usize) -> (Vec<f64>, Vec<f64>) {
    match n {
        1 => (vec![0.0], vec![2.0]),
        2 => {
            let a = 1.0 / 3f64.sqrt();
            (vec![-a, a], vec![1.0, 1.0])
        }
        3 => {
            let a = (0.6f64).sqrt();
            (vec![-a, 0.0, a], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0])
        }
        4 => {
            let a = (3.0 / 7.0 - 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let b = (3.0 / 7.0 + 2.0 / 7.0 * (6.0f64 / 5.0).sqrt()).sqrt();
            let wa = (18.0 + 30f64.sqrt()) / 36.0;
            let wb = (18.0 - 30f64.sqrt()) / 36.0;
            (vec![-b, -a, a, b], vec![wb, wa, wa, wb])
        }
        _ => {
            // 5 points
            let a = 1.0 / 3.0 * (5.0 - 2.0 * (10.0f64 / 7.0).sqrt()).sqrt();
            let b = 1.0 / 3.0 * (5.0 + 2.0 * (10.0f64 / 7.0).sqrt()).sqrt();
            let wa = (322.0 + 13.0 * 70f64.sqrt()) / 900.0;
            let wb = (322.0 - 13.0 * 70f64.sqrt()) / 900.0;
            (vec![-b, -a, 0.0, a, b], vec![wb, wa, 128.0 / 225.0, wa, wb])
        }
    }
}

/// Cubic Lagrange shape functions on nodes -1, -1/3, 1/3, 1 and their xi-derivatives.
pub fn shape(xi: f64) -> ([f64; 4], [f64; 4]) {
    let nd = [-1.0, -1.0 / 3.0, 1.0 / 3.0, 1.0];
    let mut n = [0.0; 4];
    let mut d = [0.0; 4];
    for i in 0..4 {
        let mut den = 1.0;
        for j in 0..4 {
            if j != i {
                den *= nd[i] - nd[j];
            }
        }
        let mut p = 1.0;
        for j in 0..4 {
            if j != i {
                p *= xi - nd[j];
            }
        }
        n[i] = p / den;
        let mut s = 0.0;
        for k in 0..4 {
            if k == i {
                continue;
            }
            let mut q = 1.0;
            for j in 0..4 {
                if j != i && j != k {
                    q *= xi - nd[j];
                }
            }
            s += q;
        }
        d[i] = s / den;
    }
    (n, d)
}

impl Beam {
    /// Build from the reference configuration of its 4 nodes (positions, rotations whose first
    /// column is the beam axis), the section table and the arc length of node 0 along the beam.
    pub fn new(
        name: &str,
        nodes: [usize; 4],
        x0: &[[f64; 3]; 4],
        r0: &[[[f64; 3]; 3]; 4],
        sections: &SectionTable,
        s_start: f64,
        damping_mu_s: f64,
    ) -> Self {
        let jac = |xi: f64| {
            let (_, d) = shape(xi);
            let mut t = [0.0; 3];
            for i in 0..4 {
                t = add(t, fmul(d[i], x0[i]));
            }
            dot(t, t).sqrt()
        };
        let arc = |xi: f64| {
            // arc length from xi = -1 to xi by 5-point Gauss
            let (p, w) = gauss(5);
            let h = 0.5 * (xi + 1.0);
            (0..5)
                .map(|k| w[k] * h * jac(-1.0 + h * (p[k] + 1.0)))
                .sum::<f64>()
        };
        let len = arc(1.0);
        let (pk, wk) = gauss(NPTS_K);
        let gk: [GaussK; NPTS_K] = std::array::from_fn(|k| {
            let (n, d) = shape(pk[k]);
            let j = jac(pk[k]);
            let s = s_start + arc(pk[k]);
            GaussK {
                wj: wk[k] * j,
                n,
                ds: d.map(|v| v / j),
                s_m: s,
                cmat: sections.at(s).stiffness(),
                gamma0: [0.0; 3],
                kappa0: [0.0; 3],
            }
        });
        let (pm, wm) = gauss(NPTS_M);
        let gm: [GaussM; NPTS_M] = std::array::from_fn(|k| {
            let (n, _) = shape(pm[k]);
            let s = s_start + arc(pm[k]);
            let p = sections.at(s);
            GaussM {
                wj: wm[k] * jac(pm[k]),
                n,
                s_m: s,
                m: p.m,
                xi: p.cm_offset(),
                jref: p.inertia_ref(),
            }
        });
        let mut b = Beam {
            name: name.into(),
            nodes,
            gk,
            gm,
            damping_mu_s,
            loads: vec![],
            ext: [SectionLoad::default(); NPTS_M],
            s_range: [s_start, s_start + len],
            cache: InterpCache::default(),
        };
        // initial strains so that the reference configuration is stress free
        let kin: [NodeKin<f64>; 4] = std::array::from_fn(|i| NodeKin {
            x: x0[i],
            r: r0[i],
            ..NodeKin::ground()
        });
        let (rr, psi) = Self::local_rotations(&kin);
        for g in b.gk.iter_mut() {
            g.gamma0 = [0.0; 3];
            g.kappa0 = [0.0; 3];
            let (gam, kap, _, _, _) = Self::strains_at(g, &kin, &rr, &psi);
            g.gamma0 = gam;
            g.kappa0 = kap;
        }
        b
    }

    pub fn length(&self) -> f64 {
        self.s_range[1] - self.s_range[0]
    }

    /// Reference rotation and local rotation vectors (objective interpolation).
    pub fn local_rotations<T: Real>(k: &[NodeKin<T>; 4]) -> (M3<T>, [V3<T>; 4]) {
        let half = fmul(0.5, log_map(&mtm(&k[1].r, &k[2].r)));
        let rr = mm(&k[1].r, &exp_map(half));
        let psi = std::array::from_fn(|i| log_map(&mtm(&rr, &k[i].r)));
        (rr, psi)
    }

    /// Strains at a stiffness point: (Gamma, kappa, R, x', psi).
    #[allow(clippy::type_complexity)]
    fn strains_at<T: Real>(
        g: &GaussK,
        k: &[NodeKin<T>; 4],
        rr: &M3<T>,
        psi: &[V3<T>; 4],
    ) -> (V3<T>, V3<T>, M3<T>, V3<T>, V3<T>) {
        let mut xp = zero3();
        let mut ps = zero3();
        let mut psp = zero3();
        for i in 0..4 {
            xp = add(xp, fmul(g.ds[i], k[i].x));
            ps = add(ps, fmul(g.n[i], psi[i]));
            psp = add(psp, fmul(g.ds[i], psi[i]));
        }
        let r = mm(rr, &exp_map(ps));
        let gam = sub(mtv(&r, xp), v3c(&g.gamma0));
        let kap = sub(mv(&tangent_right(ps), psp), v3c(&g.kappa0));
        (gam, kap, r, xp, ps)
    }

    /// Elastic + dissipative internal forces. `out` has 24 entries (node-major, 6 each).
    pub fn internal<T: Real>(
        &self,
        k: &[NodeKin<T>; 4],
        rr: &M3<T>,
        psi: &[V3<T>; 4],
        out: &mut [T],
    ) {
        for g in &self.gk {
            let (gam, kap, r, xp, _) = Self::strains_at(g, k, rr, psi);
            let mut e = [gam[0], gam[1], gam[2], kap[0], kap[1], kap[2]];
            if self.damping_mu_s != 0.0 {
                // strain rates: Gamma_dot = R^T (v' - w x x'), kappa_dot = R^T w'
                let mut vp = zero3();
                let mut wp = zero3();
                let mut w = zero3();
                for i in 0..4 {
                    vp = add(vp, fmul(g.ds[i], k[i].v));
                    wp = add(wp, fmul(g.ds[i], k[i].w));
                    w = add(w, fmul(g.n[i], k[i].w));
                }
                let gd = mtv(&r, sub(vp, cross(w, xp)));
                let kd = mtv(&r, wp);
                let mu = self.damping_mu_s;
                for j in 0..3 {
                    e[j] += gd[j].scale(mu);
                    e[3 + j] += kd[j].scale(mu);
                }
            }
            let mut s = [c::<T>(0.0); 6];
            for (i, si) in s.iter_mut().enumerate() {
                for (j, ej) in e.iter().enumerate() {
                    let cij = g.cmat[i][j];
                    if cij != 0.0 {
                        *si += ej.scale(cij);
                    }
                }
            }
            let f = mv(&r, [s[0], s[1], s[2]]);
            let m = mv(&r, [s[3], s[4], s[5]]);
            let xf = cross(xp, f);
            for i in 0..4 {
                let (a, b) = (g.ds[i] * g.wj, g.n[i] * g.wj);
                for j in 0..3 {
                    out[6 * i + j] += f[j].scale(a);
                    out[6 * i + 3 + j] += m[j].scale(a) - xf[j].scale(b);
                }
            }
        }
    }

    /// Rotation at an inertia point.
    fn rot_at<T: Real>(g: &GaussM, rr: &M3<T>, psi: &[V3<T>; 4]) -> M3<T> {
        let mut ps = zero3();
        for i in 0..4 {
            ps = add(ps, fmul(g.n[i], psi[i]));
        }
        mm(rr, &exp_map(ps))
    }

    /// Inertial forces minus gravity and applied distributed loads.
    pub fn inertial_and_external<T: Real>(
        &self,
        k: &[NodeKin<T>; 4],
        rr: &M3<T>,
        psi: &[V3<T>; 4],
        ctx: &EvalCtx,
        out: &mut [T],
    ) {
        let rg = std::array::from_fn(|q| Self::rot_at(&self.gm[q], rr, psi));
        self.inertial_and_external_at(k, &rg, ctx, out);
    }

    /// [`Beam::inertial_and_external`] with the section rotations `rg` at the inertia points.
    fn inertial_and_external_at<T: Real>(
        &self,
        k: &[NodeKin<T>; 4],
        rg: &[M3<T>; NPTS_M],
        ctx: &EvalCtx,
        out: &mut [T],
    ) {
        for (q, g) in self.gm.iter().enumerate() {
            let (f, mo) = self.density_at(q, k, &rg[q], ctx);
            for i in 0..4 {
                let b = g.n[i] * g.wj;
                for j in 0..3 {
                    out[6 * i + j] += f[j].scale(b);
                    out[6 * i + 3 + j] += mo[j].scale(b);
                }
            }
        }
    }

    /// Inertial force and moment minus gravity and applied loads per unit reference length at
    /// inertia point `q` (section rotation `r`): the integrand of the element's
    /// inertial-and-external residual, the moment about the reference-line point.
    #[inline]
    fn density_at<T: Real>(
        &self,
        q: usize,
        k: &[NodeKin<T>; 4],
        r: &M3<T>,
        ctx: &EvalCtx,
    ) -> (V3<T>, V3<T>) {
        let g = &self.gm[q];
        let grav = ctx.gravity;
        let has_g = grav != [0.0; 3];
        let r = *r;
        let mut f = zero3();
        let mut mo = zero3();
        if ctx.inertia || has_g {
            let mut a = zero3();
            let mut w = zero3();
            let mut al = zero3();
            if ctx.inertia {
                for i in 0..4 {
                    a = add(a, fmul(g.n[i], k[i].a));
                    w = add(w, fmul(g.n[i], k[i].w));
                    al = add(al, fmul(g.n[i], k[i].al));
                }
            }
            let a = sub(a, v3c(&grav));
            let eta = mv(&r, v3c(&g.xi));
            let jr = mm(&mm(&r, &m3c(&g.jref)), &transpose(&r));
            let m = g.m;
            f = fmul(m, add(a, add(cross(al, eta), cross(w, cross(w, eta)))));
            mo = add(
                fmul(m, cross(eta, a)),
                add(mv(&jr, al), cross(w, mv(&jr, w))),
            );
        }
        for l in &self.loads {
            let fac = l.time.eval(ctx.t) * ctx.load_factor;
            let (fe, me) = if l.follower {
                (
                    mv(&r, v3c(&l.force_n_per_m)),
                    mv(&r, v3c(&l.moment_nm_per_m)),
                )
            } else {
                (v3c(&l.force_n_per_m), v3c(&l.moment_nm_per_m))
            };
            f = sub(f, fmul(fac, fe));
            mo = sub(mo, fmul(fac, me));
        }
        let e = &self.ext[q];
        if e.force != [0.0; 3] || e.moment != [0.0; 3] {
            let (fe, me) = if e.follower {
                (mv(&r, v3c(&e.force)), mv(&r, v3c(&e.moment)))
            } else {
                (v3c(&e.force), v3c(&e.moment))
            };
            f = sub(f, fe);
            mo = sub(mo, me);
        }
        (f, mo)
    }

    /// The interpolation of configuration `k`: from the cache when `k` is the configuration
    /// it was made for (the converged iterate), else computed.
    pub fn interp(&self, k: &[NodeKin<f64>; 4]) -> Interp {
        if self.cache.holds(k) {
            let c = &self.cache;
            Interp {
                rr: c.rr,
                psi: c.psi,
                rg: c.rg,
            }
        } else {
            let (rr, psi) = Self::local_rotations(k);
            let rg = std::array::from_fn(|q| Self::rot_at(&self.gm[q], &rr, &psi));
            Interp { rr, psi, rg }
        }
    }

    /// Per inertia point: the reference-line position, the quadrature weight (reference
    /// length), and the inertial minus applied force and moment per unit length (the moment
    /// about that point), as the residual integrates them. For load recovery
    /// ([`crate::loads`]).
    pub fn point_densities(&self, k: &[NodeKin<f64>; 4], ctx: &EvalCtx) -> [PointDensity; NPTS_M] {
        self.densities_with(k, &self.interp(k).rg, ctx)
    }

    /// [`Beam::point_densities`] with the section rotations `rg` at the inertia points.
    pub fn densities_with(
        &self,
        k: &[NodeKin<f64>; 4],
        rg: &[M3<f64>; NPTS_M],
        ctx: &EvalCtx,
    ) -> [PointDensity; NPTS_M] {
        std::array::from_fn(|q| {
            let g = &self.gm[q];
            let (f, m) = self.density_at(q, k, &rg[q], ctx);
            let mut x = [0.0; 3];
            for i in 0..4 {
                x = add(x, fmul(g.n[i], k[i].x));
            }
            PointDensity {
                s_m: g.s_m,
                weight_m: g.wj,
                x,
                force_n_per_m: f,
                moment_nm_per_m: m,
            }
        })
    }

    /// What load recovery needs of one element at configuration `k` beyond its densities `d`
    /// ([`Beam::densities_with`] of the same interpolation): the full residual (24 entries),
    /// and the position and section rotation at reference arc length `s_m`.
    pub fn recovery(
        &self,
        k: &[NodeKin<f64>; 4],
        ip: &Interp,
        d: &[PointDensity; NPTS_M],
        s_m: f64,
    ) -> ([f64; 24], [f64; 3], M3<f64>) {
        let mut r = [0.0; 24];
        self.internal(k, &ip.rr, &ip.psi, &mut r);
        // the inertial-and-external residual from the same densities
        for (g, p) in self.gm.iter().zip(d) {
            for i in 0..4 {
                let b = g.n[i] * g.wj;
                for j in 0..3 {
                    r[6 * i + j] += p.force_n_per_m[j] * b;
                    r[6 * i + 3 + j] += p.moment_nm_per_m[j] * b;
                }
            }
        }
        let xi = -1.0 + 2.0 * (s_m - self.s_range[0]) / (self.s_range[1] - self.s_range[0]);
        let (n, _) = shape(xi);
        let mut x = [0.0; 3];
        let mut ps = zero3();
        for i in 0..4 {
            x = add(x, fmul(n[i], k[i].x));
            ps = add(ps, fmul(n[i], ip.psi[i]));
        }
        (r, x, mm(&ip.rr, &exp_map(ps)))
    }

    /// Full element residual (24 entries, accumulated into `out`).
    pub fn residual<T: Real>(&self, k: &[NodeKin<T>; 4], ctx: &EvalCtx, out: &mut [T]) {
        let (rr, psi) = Self::local_rotations(k);
        self.internal(k, &rr, &psi, out);
        self.inertial_and_external(k, &rr, &psi, ctx, out);
    }

    /// [`Beam::residual`] in f64, reusing the interpolation of [`Beam::load_points_cached`]
    /// when `k` is the configuration it was made for (same bits as computing it afresh).
    pub fn residual_f64(&self, k: &[NodeKin<f64>; 4], ctx: &EvalCtx, out: &mut [f64]) {
        if self.cache.holds(k) {
            let c = &self.cache;
            self.internal(k, &c.rr, &c.psi, out);
            self.inertial_and_external_at(k, &c.rg, ctx, out);
        } else {
            self.residual(k, ctx, out);
        }
    }

    /// [`Beam::load_points`], keeping the interpolation for [`Beam::residual_f64`].
    #[allow(clippy::type_complexity)]
    pub fn load_points_cached(
        &mut self,
        k: &[NodeKin<f64>; 4],
    ) -> [([f64; 3], M3<f64>, [f64; 3], [f64; 3]); NPTS_M] {
        let (rr, psi) = Self::local_rotations(k);
        let pts = self.points_with(k, &rr, &psi);
        self.cache = InterpCache {
            valid: true,
            x: k.map(|n| n.x),
            r: k.map(|n| n.r),
            rr,
            psi,
            rg: pts.map(|p| p.1),
        };
        pts
    }

    /// Section forces and moments in the section frame at each stiffness point:
    /// (s_m, [N1, N2, N3, M1, M2, M3]).
    pub fn section_forces(&self, k: &[NodeKin<f64>; 4]) -> Vec<(f64, [f64; 6])> {
        let (rr, psi) = Self::local_rotations(k);
        self.gk
            .iter()
            .map(|g| {
                let (gam, kap, _, _, _) = Self::strains_at(g, k, &rr, &psi);
                let e = [gam[0], gam[1], gam[2], kap[0], kap[1], kap[2]];
                let s = std::array::from_fn(|i| (0..6).map(|j| g.cmat[i][j] * e[j]).sum());
                (g.s_m, s)
            })
            .collect()
    }

    /// Position, rotation and velocities at the inertia points (for external load providers).
    #[allow(clippy::type_complexity)]
    pub fn load_points(
        &self,
        k: &[NodeKin<f64>; 4],
    ) -> [([f64; 3], M3<f64>, [f64; 3], [f64; 3]); NPTS_M] {
        let (rr, psi) = Self::local_rotations(k);
        self.points_with(k, &rr, &psi)
    }

    #[allow(clippy::type_complexity)]
    fn points_with(
        &self,
        k: &[NodeKin<f64>; 4],
        rr: &M3<f64>,
        psi: &[V3<f64>; 4],
    ) -> [([f64; 3], M3<f64>, [f64; 3], [f64; 3]); NPTS_M] {
        // filled in place (a `from_fn` closure here was called out of line and its result copied)
        let mut out = [([0.0; 3], [[0.0; 3]; 3], [0.0; 3], [0.0; 3]); NPTS_M];
        for (q, o) in out.iter_mut().enumerate() {
            let g = &self.gm[q];
            let r = Self::rot_at(g, rr, psi);
            let mut x = [0.0; 3];
            let mut v = [0.0; 3];
            let mut w = [0.0; 3];
            for i in 0..4 {
                x = add(x, fmul(g.n[i], k[i].x));
                v = add(v, fmul(g.n[i], k[i].v));
                w = add(w, fmul(g.n[i], k[i].w));
            }
            *o = (x, r, v, w);
        }
        out
    }

    /// Kinetic energy of the element (4-point quadrature).
    pub fn kinetic_energy(&self, k: &[NodeKin<f64>; 4]) -> f64 {
        let (rr, psi) = Self::local_rotations(k);
        let mut e = 0.0;
        for g in &self.gm {
            let r = Self::rot_at(g, &rr, &psi);
            let mut v = [0.0; 3];
            let mut w = [0.0; 3];
            for i in 0..4 {
                v = add(v, fmul(g.n[i], k[i].v));
                w = add(w, fmul(g.n[i], k[i].w));
            }
            let eta = mv(&r, g.xi);
            let jr = mm(&mm(&r, &g.jref), &transpose(&r));
            e += g.wj
                * (0.5 * g.m * dot(v, v) + g.m * dot(v, cross(w, eta)) + 0.5 * dot(w, mv(&jr, w)));
        }
        e
    }

    /// Linear and angular momentum (about the origin) of the element.
    pub fn momentum(&self, k: &[NodeKin<f64>; 4]) -> ([f64; 3], [f64; 3]) {
        let (rr, psi) = Self::local_rotations(k);
        let mut p = [0.0; 3];
        let mut h = [0.0; 3];
        for g in &self.gm {
            let r = Self::rot_at(g, &rr, &psi);
            let mut x = [0.0; 3];
            let mut v = [0.0; 3];
            let mut w = [0.0; 3];
            for i in 0..4 {
                x = add(x, fmul(g.n[i], k[i].x));
                v = add(v, fmul(g.n[i], k[i].v));
                w = add(w, fmul(g.n[i], k[i].w));
            }
            let eta = mv(&r, g.xi);
            let jr = mm(&mm(&r, &g.jref), &transpose(&r));
            let pl = fmul(g.m, add(v, cross(w, eta)));
            // h about origin = x x p + m eta x v + J w
            let hl = add(cross(x, pl), add(fmul(g.m, cross(eta, v)), mv(&jr, w)));
            p = add(p, fmul(g.wj, pl));
            h = add(h, fmul(g.wj, hl));
        }
        (p, h)
    }

    /// Strain energy of the element (3-point quadrature, consistent with the stiffness terms).
    pub fn strain_energy(&self, k: &[NodeKin<f64>; 4]) -> f64 {
        let (rr, psi) = Self::local_rotations(k);
        let mut e = 0.0;
        for g in &self.gk {
            let (gam, kap, _, _, _) = Self::strains_at(g, k, &rr, &psi);
            let s = [gam[0], gam[1], gam[2], kap[0], kap[1], kap[2]];
            for i in 0..6 {
                for j in 0..6 {
                    e += 0.5 * g.wj * s[i] * g.cmat[i][j] * s[j];
                }
            }
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn shape_functions_partition_unity_and_interpolate() {
        for xi in [-1.0, -0.3, 0.2, 0.9] {
            let (n, d) = shape(xi);
            assert!((n.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            assert!(d.iter().sum::<f64>().abs() < 1e-13);
        }
        let (n, _) = shape(1.0 / 3.0);
        assert!((n[2] - 1.0).abs() < 1e-14);
        let (p, w) = gauss(4);
        let int: f64 = p.iter().zip(&w).map(|(x, w)| w * x.powi(6)).sum();
        assert!((int - 2.0 / 7.0).abs() < 1e-14);
    }
}
