//! Closed-form tangent of the beam residual ([`Beam::residual`]) along the solver's seeds.
//!
//! Chain rule through the objective interpolation, with spatial rotation variations
//! (`dR = dth~ R`) everywhere:
//! - reference rotation (Eq. R1): `dth_r = (I - A) dth_1 + A dth_2`,
//!   `A = 1/2 R_r T_R(phi) T_L(2 phi)^-1 R_1^T`, `phi = 1/2 log(R_1^T R_2)`;
//! - local rotation vectors (Eq. R2): `dpsi_i = L_i (dth_i - dth_r)`, `L_i = T_L(psi_i)^-1 R_r^T`;
//! - section rotation (Eq. R3): `dth(s) = dth_r + R_r T_L(psi) dpsi(s)`;
//! - strains, spatial form (Eq. S1): `R dGamma = dx' + x'~ dth`,
//!   `R dkappa = R (T_R(psi) dpsi' + D(psi, psi') dpsi)`, `D` = derivative of `T_R(psi) u`;
//! - strain rates (Eq. S2): `R dGamma_dot = (v' - w x x')~ dth + dv' + x'~ dw - w~ dx'`,
//!   `R dkappa_dot = w'~ dth + dw'`;
//! - stresses (Eq. S3): `d(F, M) = c_s de_s - (F~, M~) dth` with the spatial section stiffness
//!   `c_s = diag(R, R) C diag(R, R)^T`;
//! - inertia with `eta = R xi`, `J = R J_ref R^T`: `deta = -eta~ dth`, `dJ = dth~ J - J dth~`;
//! - follower loads: `d(-R f) = (R f)~ dth`.
//!
//! The partial derivatives w.r.t. each node's (x, th, v, w, a, al) are assembled once as 24 x 3
//! blocks and then contracted with the seeds. The DualN path of [`Beam::residual`] stays the
//! reference (see the tests).
use super::beam::{Beam, GaussK};
use super::kin::{EvalCtx, NodeKin, Seed};
use super::rotation::*;

type V = [f64; 3];
type M = [[f64; 3]; 3];

const ZM: M = [[0.0; 3]; 3];
const IM: M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Partial derivatives: `p[j][t][k][row]` is d residual_row / d (component `k` of variable `t`
/// of node `j`), `t` = x, th, v, w, a, al. Stored by columns so that contracting with a seed is
/// a few contiguous 24-long updates.
type Block = [[f64; 24]; 3];
type Partials = [[Block; 6]; 4];
const TX: usize = 0;
const TTH: usize = 1;
const TV: usize = 2;
const TW: usize = 3;
const TA: usize = 4;
const TAL: usize = 5;

#[inline]
fn ms(s: f64, a: &M) -> M {
    mscale(s, a)
}
#[inline]
fn msub(a: &M, b: &M) -> M {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] - b[i][j]))
}
#[inline]
fn outer(a: V, b: V) -> M {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i] * b[j]))
}
/// `a + s b`
#[inline]
fn maxpy(a: &M, s: f64, b: &M) -> M {
    std::array::from_fn(|i| std::array::from_fn(|j| a[i][j] + s * b[i][j]))
}

/// Inverse of a 3x3 matrix by cofactors (used on tangent operators, well conditioned below
/// angles of 2 pi).
fn inv3(a: &M) -> M {
    let c0 = cross(a[1], a[2]);
    let c1 = cross(a[2], a[0]);
    let c2 = cross(a[0], a[1]);
    let inv_det = 1.0 / dot(a[0], c0);
    // columns of the inverse are the cofactor rows
    std::array::from_fn(|i| [c0[i] * inv_det, c1[i] * inv_det, c2[i] * inv_det])
}

/// Coefficients of `T_R = I - b psi~ + c psi~^2` and their derivatives w.r.t. `t^2 = |psi|^2`:
/// `b' = (a - 2b) / (2 t^2)`, `c' = (b - 3c) / (2 t^2)` with `a = sin t / t`; series below
/// `t^2 = 1e-2`, where the quotients cancel (truncation error below 1e-16).
fn tr_coeffs(t2: f64) -> (f64, f64, f64, f64) {
    let (a, b, c) = rot_coeffs(t2);
    if t2 < 1e-2 {
        let db = -1.0 / 24.0 + t2 * (1.0 / 360.0 - t2 * (1.0 / 13440.0 - t2 / 907200.0));
        let dc = -1.0 / 120.0 + t2 * (1.0 / 2520.0 - t2 * (1.0 / 120960.0 - t2 / 9979200.0));
        (b, c, db, dc)
    } else {
        (b, c, (a - 2.0 * b) / (2.0 * t2), (b - 3.0 * c) / (2.0 * t2))
    }
}

/// `D(psi, u) = d(T_R(psi) u)/d psi`, differentiating `T_R u = u - b psi x u + c psi x (psi x u)`
/// (Eq. D):
/// `D = -2 b' (psi~ u) psi^T + b u~ + 2 c' (psi~^2 u) psi^T - c ((psi~ u)~ + psi~ u~)`.
fn d_tr_u(psi: V, u: V) -> M {
    let (b, c, db, dc) = tr_coeffs(dot(psi, psi));
    let pu = cross(psi, u);
    let ppu = cross(psi, pu);
    let ps = skew(psi);
    let us = skew(u);
    let mut d = ms(b, &us);
    d = maxpy(&d, -2.0 * db, &outer(pu, psi));
    d = maxpy(&d, 2.0 * dc, &outer(ppu, psi));
    d = maxpy(&d, -c, &madd(&skew(pu), &mm(&ps, &us)));
    d
}

/// Add `s m` to rows `row0..row0 + 3` of a 24 x 3 block.
#[inline]
fn acc(blk: &mut Block, row0: usize, m: &M, s: f64) {
    for k in 0..3 {
        for r in 0..3 {
            blk[k][row0 + r] += s * m[r][k];
        }
    }
}

/// Add `s (top; bottom)` to the 6 rows of node `i`.
#[inline]
fn acc6(blk: &mut Block, i: usize, tb: &(M, M), s: f64) {
    acc(blk, 6 * i, &tb.0, s);
    acc(blk, 6 * i + 3, &tb.1, s);
}

/// Interpolation data shared by all quadrature points.
struct Interp {
    rr: M,
    psi: [V; 4],
    /// `dth_r = sum_j hr[j] dth_j` (Eq. R1); only nodes 1 and 2 contribute.
    hr: [M; 4],
    /// `L_i` of Eq. R2.
    l: [M; 4],
}

impl Interp {
    fn new(k: &[NodeKin<f64>; 4]) -> Self {
        let phi = fmul(0.5, log_map(&mtm(&k[1].r, &k[2].r)));
        let rr = mm(&k[1].r, &exp_map(phi));
        let psi: [V; 4] = std::array::from_fn(|i| log_map(&mtm(&rr, &k[i].r)));
        let a = ms(
            0.5,
            &mm(
                &mm(&rr, &tangent_right(phi)),
                &mm(&inv3(&tangent_left(fmul(2.0, phi))), &transpose(&k[1].r)),
            ),
        );
        let rrt = transpose(&rr);
        Interp {
            rr,
            psi,
            hr: [ZM, msub(&IM, &a), a, ZM],
            l: std::array::from_fn(|i| mm(&inv3(&tangent_left(psi[i])), &rrt)),
        }
    }

    /// At a point with shape functions `n`: `psi(s)`, and per node `j` the maps
    /// `dth(s) = th[j] dth_j` (Eq. R3) and `dpsi(s) = ps[j] dth_j`.
    fn at(&self, n: &[f64; 4]) -> (V, [M; 4], [M; 4]) {
        let mut psi = [0.0; 3];
        let mut lbar = ZM;
        for i in 0..4 {
            psi = add(psi, fmul(n[i], self.psi[i]));
            lbar = maxpy(&lbar, n[i], &self.l[i]);
        }
        let g = mm(&self.rr, &tangent_left(psi));
        let ps: [M; 4] = std::array::from_fn(|j| {
            let v = ms(n[j], &self.l[j]);
            if j == 1 || j == 2 {
                msub(&v, &mm(&lbar, &self.hr[j]))
            } else {
                v
            }
        });
        let th = std::array::from_fn(|j| madd(&self.hr[j], &mm(&g, &ps[j])));
        (psi, th, ps)
    }

    /// `dpsi'(s) = psd[j] dth_j` for the shape-function derivatives `ds`.
    fn derivative_at(&self, ds: &[f64; 4]) -> [M; 4] {
        let mut lbar = ZM;
        for i in 0..4 {
            lbar = maxpy(&lbar, ds[i], &self.l[i]);
        }
        std::array::from_fn(|j| {
            let v = ms(ds[j], &self.l[j]);
            if j == 1 || j == 2 {
                msub(&v, &mm(&lbar, &self.hr[j]))
            } else {
                v
            }
        })
    }
}

impl Beam {
    /// Tangent of [`Beam::residual`]: column `6 l + c` is the derivative of the 24 residual
    /// entries along `seeds[l][c]` applied to node `l` (rotation as `exp(eps dth) R`).
    /// Row-major `out[row * 24 + col]`, overwritten. Exact (same derivative as the dual-number
    /// evaluation, to round-off).
    pub fn tangent(
        &self,
        k: &[NodeKin<f64>; 4],
        ctx: &EvalCtx,
        seeds: &[[Seed; 6]; 4],
        out: &mut [f64; 576],
    ) {
        let parts = |s: &Seed| [s.dx, s.dth, s.dv, s.dw, s.da, s.dal];
        // partials that no seed uses (e.g. rates in statics) are not computed
        let need: [[bool; 6]; 4] = std::array::from_fn(|l| {
            std::array::from_fn(|t| seeds[l].iter().any(|s| parts(s)[t] != [0.0; 3]))
        });
        let mut p: Partials = [[[[0.0; 24]; 3]; 6]; 4];
        let ip = Interp::new(k);
        for g in &self.gk {
            self.internal_partials(g, k, &ip, &need, &mut p);
        }
        for q in 0..self.gm.len() {
            self.inertial_partials(q, k, &ip, ctx, &need, &mut p);
        }
        for l in 0..4 {
            for c in 0..6 {
                let mut col = [0.0; 24];
                for (t, sv) in parts(&seeds[l][c]).iter().enumerate() {
                    for kk in 0..3 {
                        if sv[kk] != 0.0 {
                            for (o, b) in col.iter_mut().zip(p[l][t][kk].iter()) {
                                *o += sv[kk] * b;
                            }
                        }
                    }
                }
                for (row, v) in col.iter().enumerate() {
                    out[row * 24 + 6 * l + c] = *v;
                }
            }
        }
    }

    /// Elastic and damping partials at one stiffness point.
    fn internal_partials(
        &self,
        g: &GaussK,
        k: &[NodeKin<f64>; 4],
        ip: &Interp,
        need: &[[bool; 6]; 4],
        p: &mut Partials,
    ) {
        let (psi, th, ps) = ip.at(&g.n);
        let psd = ip.derivative_at(&g.ds);
        let mut xp = [0.0; 3];
        let mut psp = [0.0; 3];
        for i in 0..4 {
            xp = add(xp, fmul(g.ds[i], k[i].x));
            psp = add(psp, fmul(g.ds[i], ip.psi[i]));
        }
        let r = mm(&ip.rr, &exp_map(psi));
        let tr = tangent_right(psi);
        let gam = sub(mtv(&r, xp), g.gamma0);
        let kap = sub(mv(&tr, psp), g.kappa0);
        let mut e = [gam[0], gam[1], gam[2], kap[0], kap[1], kap[2]];
        let mu = self.damping_mu_s;
        let (mut w, mut wp, mut gd) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        if mu != 0.0 {
            let mut vp = [0.0; 3];
            for i in 0..4 {
                vp = add(vp, fmul(g.ds[i], k[i].v));
                wp = add(wp, fmul(g.ds[i], k[i].w));
                w = add(w, fmul(g.n[i], k[i].w));
            }
            gd = sub(vp, cross(w, xp));
            let gdm = mtv(&r, gd);
            let kdm = mtv(&r, wp);
            for j in 0..3 {
                e[j] += mu * gdm[j];
                e[3 + j] += mu * kdm[j];
            }
        }
        let cm = &g.cmat;
        let mut s = [0.0; 6];
        for i in 0..6 {
            for j in 0..6 {
                s[i] += cm[i][j] * e[j];
            }
        }
        let f = mv(&r, [s[0], s[1], s[2]]);
        let mo = mv(&r, [s[3], s[4], s[5]]);
        // spatial section stiffness blocks c_ab = R C_ab R^T (Eq. S3)
        let rt = transpose(&r);
        let blk = |a: usize, b: usize| -> M {
            let cab: M = std::array::from_fn(|i| std::array::from_fn(|j| cm[3 * a + i][3 * b + j]));
            mm(&mm(&r, &cab), &rt)
        };
        let (c00, c01, c10, c11) = (blk(0, 0), blk(0, 1), blk(1, 0), blk(1, 1));
        let xs = skew(xp);
        // d(F, M) / d dth(s), / d dpsi', / d dpsi (Eqs. S1-S3)
        let gxs = maxpy(&xs, mu, &skew(gd));
        let wps = ms(mu, &skew(wp));
        let kth_f = msub(&madd(&mm(&c00, &gxs), &mm(&c01, &wps)), &skew(f));
        let kth_m = msub(&madd(&mm(&c10, &gxs), &mm(&c11, &wps)), &skew(mo));
        let rtr = mm(&r, &tr);
        let rd = mm(&r, &d_tr_u(psi, psp));
        let (kpp_f, kpp_m) = (mm(&c01, &rtr), mm(&c11, &rtr));
        let (kp_f, kp_m) = (mm(&c01, &rd), mm(&c11, &rd));
        // d(F, M) / d dx' (with the damping term -w x dx')
        let iw = maxpy(&IM, -mu, &skew(w));
        let (kx_f, kx_m) = (mm(&c00, &iw), mm(&c10, &iw));
        let (c00x, c10x) = (mm(&c00, &xs), mm(&c10, &xs));
        let wj = g.wj;
        // r_x,i = N_i' F, r_th,i = N_i' M - N_i x' x F: the 6 rows of node i from d(F, M)
        let rows = |df: &M, dm: &M| -> [(M, M); 4] {
            let xdf = mm(&xs, df);
            std::array::from_fn(|i| {
                let (a, b) = (wj * g.ds[i], wj * g.n[i]);
                (ms(a, df), maxpy(&ms(a, dm), -b, &xdf))
            })
        };
        // x_j, v_j, w_j enter through N_j and N_j' times fixed matrices: rows built once;
        // d(-N_i x' x F)/dx_j = N_i N_j' F~ joins the x rows
        let mut bx = rows(&kx_f, &kx_m);
        let fs = skew(f);
        for i in 0..4 {
            bx[i].1 = maxpy(&bx[i].1, wj * g.n[i], &fs);
        }
        let damp = mu != 0.0;
        let (bv, bw1, bw2) = if damp {
            (rows(&c00, &c10), rows(&c00x, &c10x), rows(&c01, &c11))
        } else {
            ([(ZM, ZM); 4], [(ZM, ZM); 4], [(ZM, ZM); 4])
        };
        for j in 0..4 {
            let (nj, dj) = (g.n[j], g.ds[j]);
            if need[j][TTH] {
                let df = madd(
                    &madd(&mm(&kth_f, &th[j]), &mm(&kpp_f, &psd[j])),
                    &mm(&kp_f, &ps[j]),
                );
                let dm = madd(
                    &madd(&mm(&kth_m, &th[j]), &mm(&kpp_m, &psd[j])),
                    &mm(&kp_m, &ps[j]),
                );
                let bt = rows(&df, &dm);
                for i in 0..4 {
                    acc6(&mut p[j][TTH], i, &bt[i], 1.0);
                }
            }
            for i in 0..4 {
                if need[j][TX] {
                    acc6(&mut p[j][TX], i, &bx[i], dj);
                }
                if damp && need[j][TV] {
                    acc6(&mut p[j][TV], i, &bv[i], mu * dj);
                }
                if damp && need[j][TW] {
                    acc6(&mut p[j][TW], i, &bw1[i], mu * nj);
                    acc6(&mut p[j][TW], i, &bw2[i], mu * dj);
                }
            }
        }
    }

    /// Inertial, gravity and applied-load partials at one inertia point.
    fn inertial_partials(
        &self,
        q: usize,
        k: &[NodeKin<f64>; 4],
        ip: &Interp,
        ctx: &EvalCtx,
        need: &[[bool; 6]; 4],
        p: &mut Partials,
    ) {
        let g = &self.gm[q];
        let (psi, th, _) = ip.at(&g.n);
        let r = mm(&ip.rr, &exp_map(psi));
        // d(f, mo)/d dth(s)
        let mut gth_f = ZM;
        let mut gth_m = ZM;
        let grav = ctx.gravity;
        // d(f, mo)/d(w, a, al) at the point, if inertia is on
        let mut dyn_blocks: Option<[(M, M); 3]> = None;
        if ctx.inertia || grav != [0.0; 3] {
            let (mut a, mut w, mut al) = ([0.0; 3], [0.0; 3], [0.0; 3]);
            if ctx.inertia {
                for i in 0..4 {
                    a = add(a, fmul(g.n[i], k[i].a));
                    w = add(w, fmul(g.n[i], k[i].w));
                    al = add(al, fmul(g.n[i], k[i].al));
                }
            }
            let a = sub(a, grav);
            let m = g.m;
            let eta = mv(&r, g.xi);
            let jr = mm(&mm(&r, &g.jref), &transpose(&r));
            let (es, ws, als, as_) = (skew(eta), skew(w), skew(al), skew(a));
            let jw = mv(&jr, w);
            let jw_s = skew(jw);
            // f = m (a + al x eta + w x (w x eta)): deta = -eta~ dth
            gth_f = ms(-m, &madd(&mm(&als, &es), &mm(&ws, &mm(&ws, &es))));
            // mo = m eta x a + J al + w x J w: dJ v = (J v~ - (J v)~) dth
            let wjw = msub(&mm(&jr, &ws), &jw_s);
            gth_m = madd(
                &ms(m, &mm(&as_, &es)),
                &madd(&msub(&mm(&jr, &als), &skew(mv(&jr, al))), &mm(&ws, &wjw)),
            );
            if ctx.inertia {
                let dfw = ms(-m, &madd(&skew(cross(w, eta)), &mm(&ws, &es)));
                let dmw = msub(&mm(&ws, &jr), &jw_s);
                dyn_blocks = Some([(dfw, dmw), (ms(m, &IM), ms(m, &es)), (ms(-m, &es), jr)]);
            }
        }
        for l in &self.loads {
            if l.follower {
                let fac = l.time.eval(ctx.t) * ctx.load_factor;
                gth_f = maxpy(&gth_f, fac, &skew(mv(&r, l.force_n_per_m)));
                gth_m = maxpy(&gth_m, fac, &skew(mv(&r, l.moment_nm_per_m)));
            }
        }
        let e = &self.ext[q];
        if e.follower && (e.force != [0.0; 3] || e.moment != [0.0; 3]) {
            gth_f = madd(&gth_f, &skew(mv(&r, e.force)));
            gth_m = madd(&gth_m, &skew(mv(&r, e.moment)));
        }
        for j in 0..4 {
            if !need[j][TTH] {
                continue;
            }
            let d = (mm(&gth_f, &th[j]), mm(&gth_m, &th[j]));
            for i in 0..4 {
                acc6(&mut p[j][TTH], i, &d, g.wj * g.n[i]);
            }
        }
        if let Some(bl) = dyn_blocks {
            for (t, d) in [TW, TA, TAL].into_iter().zip(bl.iter()) {
                for j in 0..4 {
                    if !need[j][t] {
                        continue;
                    }
                    for i in 0..4 {
                        acc6(&mut p[j][t], i, d, g.wj * g.n[i] * g.n[j]);
                    }
                }
            }
        }
    }
}

/// Fixture shared by the tangent tests and the tangent cost benchmark
/// (benches/structure_tangent.rs): a curved, pre-twisted element with coupled sections and
/// loads, random configurations and solver-shaped seeds, and the 24-lane dual reference.
#[doc(hidden)]
pub mod fixture {
    use super::*;
    use crate::structure::beam::{BeamLoad, SectionLoad};
    use crate::structure::kin::TimeTable;
    use crate::structure::real::DualN;
    use crate::structure::section::{SectionProps, SectionTable};

    /// xorshift64: deterministic, no dependency.
    pub struct Rng(pub u64);
    impl Rng {
        /// Uniform in [-1, 1).
        pub fn sym(&mut self) -> f64 {
            let mut x = self.0;
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            self.0 = x;
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
        pub fn vec(&mut self, s: f64) -> V {
            [s * self.sym(), s * self.sym(), s * self.sym()]
        }
        /// Random direction, norm uniform in [0, max].
        pub fn rotvec(&mut self, max: f64) -> V {
            let d = self.vec(1.0);
            let n = dot(d, d).sqrt().max(1e-12);
            fmul(max * 0.5 * (1.0 + self.sym()) / n, d)
        }
    }

    pub fn section(s: f64, f: f64) -> SectionProps {
        SectionProps {
            s_m: s,
            ea: 5e5 * f,
            ei2: 4e3 * f,
            ei3: 8e3 / f,
            gj: 2e3 * f,
            ga2: 2e5,
            ga3: 3e5 * f,
            m: 10.0 * f,
            i1: 0.2,
            i2: 0.05 * f,
            i3: 0.15,
            cm2: 0.03 * f,
            cm3: -0.02,
            sc2: 0.01,
            sc3: -0.015 * f,
            ca2: 0.02 * f,
            ca3: 0.01,
        }
    }

    /// Curved (arc of radius 3 m, 0.4 rad, with a rise), pre-twisted (0.6 rad) element, or a
    /// straight untwisted one, with coupled, spanwise-varying sections, cm offset, damping,
    /// follower and fixed loads.
    pub fn test_beam(rng: &mut Rng, mu: f64, curved: bool) -> (Beam, [V; 4], [M; 4]) {
        let mut x0 = [[0.0; 3]; 4];
        let mut r0 = [IM; 4];
        for i in 0..4 {
            let u = i as f64 / 3.0;
            let ang = 0.4 * u;
            if curved {
                x0[i] = [3.0 * ang.sin(), 3.0 * (1.0 - ang.cos()), 0.1 * u];
                r0[i] = mm(&exp_map([0.0, 0.0, ang]), &exp_map([0.6 * u, 0.0, 0.0]));
            } else {
                x0[i] = [1.2 * u, 0.0, 0.0];
            }
        }
        let table = SectionTable::new(vec![section(0.0, 1.0), section(2.0, 1.3)], "test").unwrap();
        let mut b = Beam::new("t", [0, 1, 2, 3], &x0, &r0, &table, 0.2, mu);
        b.loads.push(BeamLoad {
            force_n_per_m: [30.0, -20.0, 50.0],
            moment_nm_per_m: [5.0, 2.0, -3.0],
            follower: true,
            time: TimeTable {
                points: vec![(0.0, 0.5), (1.0, 1.5)],
            },
        });
        b.loads.push(BeamLoad {
            force_n_per_m: [-10.0, 40.0, 15.0],
            moment_nm_per_m: [-2.0, 4.0, 1.0],
            follower: false,
            time: TimeTable::constant(),
        });
        for q in 0..4 {
            b.ext[q] = SectionLoad {
                force: rng.vec(100.0),
                moment: rng.vec(10.0),
                follower: q % 2 == 0,
            };
        }
        (b, x0, r0)
    }

    /// Rigid rotation up to 0.9 pi of the reference, node rotations up to `dev` rad on top
    /// (relative rotations between nodes up to `2 dev` beyond the reference ones), random rates.
    pub fn config(rng: &mut Rng, x0: &[V; 4], r0: &[M; 4], dev: f64) -> [NodeKin<f64>; 4] {
        let rb = exp_map(rng.rotvec(0.9 * std::f64::consts::PI));
        let off = rng.vec(2.0);
        std::array::from_fn(|i| NodeKin {
            x: add(add(mv(&rb, x0[i]), off), rng.vec(0.2 * dev)),
            r: mm(&exp_map(rng.rotvec(dev)), &mm(&rb, &r0[i])),
            v: rng.vec(3.0),
            w: rng.vec(4.0),
            a: rng.vec(20.0),
            al: rng.vec(30.0),
        })
    }

    /// Seeds shaped like the dynamic solver's: `dx = h e`, `dth = h T e`, `dv = dw = cv e`,
    /// `da = dal = ca e`; `mask` keeps only some of the six parts (to test each separately).
    pub fn seeds(rng: &mut Rng, h: f64, cv: f64, ca: f64, mask: [bool; 6]) -> [[Seed; 6]; 4] {
        std::array::from_fn(|_| {
            let t = tangent_left(rng.rotvec(0.3));
            std::array::from_fn(|c| {
                let mut e = [0.0; 3];
                e[c % 3] = 1.0;
                let m = |k: usize, v: V| if mask[k] { v } else { [0.0; 3] };
                if c < 3 {
                    Seed {
                        dx: m(TX, fmul(h, e)),
                        dv: m(TV, fmul(cv, e)),
                        da: m(TA, fmul(ca, e)),
                        ..Default::default()
                    }
                } else {
                    Seed {
                        dth: m(TTH, fmul(h, mv(&t, e))),
                        dw: m(TW, fmul(cv, e)),
                        dal: m(TAL, fmul(ca, e)),
                        ..Default::default()
                    }
                }
            })
        })
    }

    /// Reference: one 24-lane dual evaluation of the residual (as the assembly's dual path).
    pub fn dual_tangent(
        b: &Beam,
        k: &[NodeKin<f64>; 4],
        ctx: &EvalCtx,
        s: &[[Seed; 6]; 4],
    ) -> Vec<f64> {
        let k24: [NodeKin<DualN<24>>; 4] = std::array::from_fn(|l| k[l].seeded_lanes(l, &s[l]));
        let mut o24 = [DualN::<24>::default(); 24];
        b.residual(&k24, ctx, &mut o24);
        (0..576).map(|i| o24[i / 24].d[i % 24]).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::fixture::*;
    use super::*;

    fn perturbed(k: &NodeKin<f64>, s: &Seed, eps: f64) -> NodeKin<f64> {
        let p = |a: V, d: V| add(a, fmul(eps, d));
        NodeKin {
            x: p(k.x, s.dx),
            r: mm(&exp_map(fmul(eps, s.dth)), &k.r),
            v: p(k.v, s.dv),
            w: p(k.w, s.dw),
            a: p(k.a, s.da),
            al: p(k.al, s.dal),
        }
    }

    /// Central differences of the f64 residual along each seed.
    fn fd_tangent(
        b: &Beam,
        k: &[NodeKin<f64>; 4],
        ctx: &EvalCtx,
        s: &[[Seed; 6]; 4],
        eps: f64,
    ) -> Vec<f64> {
        let mut t = vec![0.0; 576];
        for l in 0..4 {
            for c in 0..6 {
                let mut rp = [0.0; 24];
                let mut rm = [0.0; 24];
                let mut kp = *k;
                kp[l] = perturbed(&k[l], &s[l][c], eps);
                b.residual(&kp, ctx, &mut rp);
                kp[l] = perturbed(&k[l], &s[l][c], -eps);
                b.residual(&kp, ctx, &mut rm);
                for row in 0..24 {
                    t[row * 24 + 6 * l + c] = (rp[row] - rm[row]) / (2.0 * eps);
                }
            }
        }
        t
    }

    /// max |a - b| / max |b|
    fn rel_err(a: &[f64], b: &[f64]) -> (f64, f64) {
        let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let d = a
            .iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        (d / scale, scale)
    }

    const MASKS: [[bool; 6]; 7] = [
        [true, false, false, false, false, false],
        [false, true, false, false, false, false],
        [false, false, true, false, false, false],
        [false, false, false, true, false, false],
        [false, false, false, false, true, false],
        [false, false, false, false, false, true],
        [true; 6],
    ];

    fn ctx(inertia: bool) -> EvalCtx {
        EvalCtx {
            t: 0.3,
            load_factor: 0.7,
            gravity: [0.5, -1.0, -9.81],
            cscale: 1.0,
            inertia,
            dt: 0.0,
        }
    }

    /// The residual that reuses the load points' interpolation is the residual, bit for bit,
    /// and a configuration that moved is not served from the cache.
    #[test]
    fn cached_interpolation_gives_the_same_bits() {
        let mut rng = Rng(0x5851_f42d_4c95_7f2d);
        for case in 0..6 {
            let (mut b, x0, r0) = test_beam(&mut rng, 0.01, case > 0);
            let k = config(&mut rng, &x0, &r0, 0.25);
            let cx = ctx(true);
            let mut fresh = [0.0; 24];
            b.residual(&k, &cx, &mut fresh);
            let _ = b.load_points_cached(&k);
            let mut cached = [0.0; 24];
            b.residual_f64(&k, &cx, &mut cached);
            assert_eq!(fresh, cached, "case {case}");
            let mut moved = k;
            moved[2].r = mm(&exp_map([1e-9, 0.0, 0.0]), &k[2].r);
            let (mut a, mut c) = ([0.0; 24], [0.0; 24]);
            b.residual(&moved, &cx, &mut a);
            b.residual_f64(&moved, &cx, &mut c);
            assert_eq!(a, c, "case {case}: moved node");
        }
    }

    #[test]
    fn analytic_tangent_equals_dual_tangent() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let mut worst = [0.0f64; 7];
        for case in 0..24 {
            let mu = if case % 4 == 3 { 0.0 } else { 0.01 };
            // cases 0 and 1: straight beam, undeformed or nearly (small-angle branches)
            let (b, x0, r0) = test_beam(&mut rng, mu, case > 1);
            let dev = [0.0, 1e-4, 0.25][case.min(2)];
            let k = config(&mut rng, &x0, &r0, dev);
            let cx = ctx(case % 3 != 2);
            for (mi, mask) in MASKS.iter().enumerate() {
                let s = seeds(&mut rng, 2e-3, 1e3, 7e5, *mask);
                let reference = dual_tangent(&b, &k, &cx, &s);
                let mut t = [0.0; 576];
                b.tangent(&k, &cx, &s, &mut t);
                let (e, scale) = rel_err(&t, &reference);
                if scale == 0.0 {
                    continue;
                }
                worst[mi] = worst[mi].max(e);
                assert!(e < 1e-10, "case {case} mask {mi}: relative error {e:.2e}");
            }
        }
        println!(
            "analytic vs dual, worst relative error per seed part (x th v w a al all): {:?}",
            worst.map(|x| format!("{x:.1e}"))
        );
    }

    /// Central differences along unit-size seeds. In x and th the residual is transcendental:
    /// with eps = 1e-5 the truncation error `eps^2/6 |r'''|` is about 1e-10 of the tangent
    /// and round-off `1e-16 |r| / eps` about 1e-11. In v, w, a, al it is at most quadratic, so
    /// central differences are exact and eps = 1 leaves only round-off, `1e-16 |r|`, which is
    /// up to 3e-10 of the small d/d al block (|r| ~ 1e5, entries ~ 0.2). Observed worst: 3e-10;
    /// the bound 1e-8 keeps a factor 30.
    const EPS: [f64; 7] = [1e-5, 1e-5, 1.0, 1.0, 1.0, 1.0, 1e-5];

    #[test]
    fn analytic_tangent_matches_central_differences() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let mut worst = [0.0f64; 7];
        for case in 0..8 {
            let (b, x0, r0) = test_beam(&mut rng, 0.01, true);
            let k = config(&mut rng, &x0, &r0, 0.25);
            let cx = ctx(case % 3 != 2);
            for (mi, mask) in MASKS.iter().enumerate() {
                let s = seeds(&mut rng, 1.0, 1.0, 1.0, *mask);
                let mut t = [0.0; 576];
                b.tangent(&k, &cx, &s, &mut t);
                let fd = fd_tangent(&b, &k, &cx, &s, EPS[mi]);
                let (e, scale) = rel_err(&t, &fd);
                if scale == 0.0 {
                    continue;
                }
                worst[mi] = worst[mi].max(e);
                assert!(e < 1e-8, "case {case} mask {mi}: relative error {e:.2e}");
            }
        }
        println!(
            "analytic vs central differences, worst relative error (x th v w a al all): {:?}",
            worst.map(|x| format!("{x:.1e}"))
        );
    }
}
