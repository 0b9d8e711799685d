//! Joints as data (rapier style): one constraint implementation parametrised by which relative
//! translations and rotations are locked in a joint frame, plus optional prescribed motion and a
//! rotational spring/damper about the joint axis (local z).
//!
//! Relative rotation in joint frames `Rr = (R_A Q_A)^T (R_B Q_B)`; with a prescribed angle
//! `psi_p(t)` about z, `Rr <- Rz(psi_p)^T Rr`. Locked rotations use
//! `Phi = 1/2 axial(Rr - Rr^T)` components (clamp), `Rr_31, Rr_32` (revolute: z axes stay
//! aligned), `Rr_12` (universal). Translations: `Q_A^T R_A^T (x_B + R_B d_B - x_A - R_A d_A) - u(t)`.
//! Constraint forces `B^T lambda` with `B = dPhi/dq` obtained by nested dual numbers.
use super::kin::{EvalCtx, NodeKin, TimeTable};
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
    /// Unwrapped angle at the last converged step (for the spring and sensors).
    pub angle_prev: f64,
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
            angle_prev: 0.0,
        }
    }

    pub fn locks(&self) -> (usize, usize) {
        let rot = if self.prescribed_angle.is_some() {
            3
        } else {
            match self.kind {
                JointKind::Clamp => 3,
                JointKind::Revolute => 2,
                JointKind::Universal => 1,
                JointKind::Spherical => 0,
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
        out[..3].copy_from_slice(&d);
        let mut rr = self.rel_rot(a, b);
        let (_, nrot) = self.locks();
        if let Some(law) = &self.prescribed_angle {
            let ang = law.angle(t);
            let rz = [
                [c(ang.cos()), c(-ang.sin()), c(0.0)],
                [c(ang.sin()), c(ang.cos()), c(0.0)],
                [c(0.0), c(0.0), c(1.0)],
            ];
            rr = mtm(&rz, &rr);
        }
        match nrot {
            3 => {
                out[3] = (rr[2][1] - rr[1][2]).scale(0.5);
                out[4] = (rr[0][2] - rr[2][0]).scale(0.5);
                out[5] = (rr[1][0] - rr[0][1]).scale(0.5);
            }
            2 => {
                out[3] = rr[2][0];
                out[4] = rr[2][1];
            }
            1 => out[3] = rr[0][1],
            _ => {}
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
        // B columns by dual perturbation of each node dof
        let la: NodeKin<Dual<T>> = lift(a);
        let lb: NodeKin<Dual<T>> = lift(b);
        for j in 0..nn {
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
        if (self.spring_nm_per_rad != 0.0 || self.damper_nms_per_rad != 0.0)
            && self.prescribed_angle.is_none()
        {
            let ang = self.angle(a, b);
            let z = mv(&mm(&a.r, &m3c(&self.qa)), [c(0.0), c(0.0), c(1.0)]);
            let rate = dot(z, sub(b.w, a.w));
            let m = (ang.scale(self.spring_nm_per_rad)) + rate.scale(self.damper_nms_per_rad);
            for j in 0..3 {
                out[off_b + 3 + j] += m * z[j];
                if self.node_a.is_some() {
                    out[3 + j] -= m * z[j];
                }
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
