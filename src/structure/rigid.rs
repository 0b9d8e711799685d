//! Rigid body attached to a node, with offset centre of mass and full inertia tensor.
use super::kin::{EvalCtx, NodeKin};
use super::real::Real;
use super::rotation::*;

#[derive(Clone, Debug, PartialEq)]
pub struct RigidBody {
    pub name: String,
    pub node: usize,
    pub mass_kg: f64,
    /// Centre of mass offset from the node, in the node frame [m].
    pub cm_offset_m: [f64; 3],
    /// Inertia tensor about the centre of mass, node frame [kg m^2].
    pub inertia_kgm2: [[f64; 3]; 3],
}

impl RigidBody {
    /// Inertia about the node (parallel-axis theorem), node frame.
    pub fn inertia_node(&self) -> [[f64; 3]; 3] {
        let xi = self.cm_offset_m;
        let x2 = dot(xi, xi);
        std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                self.inertia_kgm2[i][j]
                    + self.mass_kg * ((if i == j { x2 } else { 0.0 }) - xi[i] * xi[j])
            })
        })
    }

    /// Inertial force/moment minus gravity at the node: `f = m (a + al x eta + w x w x eta - g)`,
    /// `m = eta x m (a - g) + J al + w x J w`.
    pub fn residual<T: Real>(&self, k: &NodeKin<T>, ctx: &EvalCtx, out: &mut [T]) {
        let m = self.mass_kg;
        let zero = zero3();
        let (a, w, al) = if ctx.inertia {
            (k.a, k.w, k.al)
        } else {
            (zero, zero, zero)
        };
        let a = sub(a, v3c(&ctx.gravity));
        let eta = mv(&k.r, v3c(&self.cm_offset_m));
        let jr = mm(&mm(&k.r, &m3c(&self.inertia_node())), &transpose(&k.r));
        let f = fmul(m, add(a, add(cross(al, eta), cross(w, cross(w, eta)))));
        let mo = add(
            fmul(m, cross(eta, a)),
            add(mv(&jr, al), cross(w, mv(&jr, w))),
        );
        for j in 0..3 {
            out[j] += f[j];
            out[3 + j] += mo[j];
        }
    }

    pub fn kinetic_energy(&self, k: &NodeKin<f64>) -> f64 {
        let eta = mv(&k.r, self.cm_offset_m);
        let jr = mm(&mm(&k.r, &self.inertia_node()), &transpose(&k.r));
        0.5 * self.mass_kg * dot(k.v, k.v)
            + self.mass_kg * dot(k.v, cross(k.w, eta))
            + 0.5 * dot(k.w, mv(&jr, k.w))
    }
}

/// Point load on a node, fixed (global) or follower (node frame), scaled by a time table.
#[derive(Clone, Debug, PartialEq)]
pub struct PointLoad {
    pub name: String,
    pub node: usize,
    pub force_n: [f64; 3],
    pub moment_nm: [f64; 3],
    pub follower: bool,
    pub time: super::kin::TimeTable,
}

impl PointLoad {
    pub fn residual<T: Real>(&self, k: &NodeKin<T>, ctx: &EvalCtx, out: &mut [T]) {
        let fac = self.time.eval(ctx.t) * ctx.load_factor;
        let (f, m) = if self.follower {
            (mv(&k.r, v3c(&self.force_n)), mv(&k.r, v3c(&self.moment_nm)))
        } else {
            (v3c(&self.force_n), v3c(&self.moment_nm))
        };
        for j in 0..3 {
            out[j] -= f[j].scale(fac);
            out[3 + j] -= m[j].scale(fac);
        }
    }
}
