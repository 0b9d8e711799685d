//! Solution state (nodal configuration, velocities, accelerations, multipliers) and sensors.
use crate::structure::beam::Beam;
use crate::structure::kin::{EvalCtx, NodeKin};
use crate::structure::model::{Element, Model, SensorKind};
use crate::structure::rotation::*;
use nalgebra::UnitQuaternion;

#[derive(Clone, Debug)]
pub struct State {
    pub t: f64,
    pub x: Vec<[f64; 3]>,
    pub q: Vec<UnitQuaternion<f64>>,
    pub v: Vec<[f64; 3]>,
    pub w: Vec<[f64; 3]>,
    /// True accelerations (translational, angular; spatial).
    pub a: Vec<[f64; 3]>,
    pub al: Vec<[f64; 3]>,
    /// Physical Lagrange multipliers, one per constraint row (model element order).
    pub lambda: Vec<f64>,
}

impl State {
    /// Reference configuration at rest.
    pub fn from_model(m: &Model) -> Self {
        let n = m.nodes.len();
        State {
            t: 0.0,
            x: m.nodes.iter().map(|n| n.x0).collect(),
            q: m.nodes.iter().map(|n| n.q0).collect(),
            v: vec![[0.0; 3]; n],
            w: vec![[0.0; 3]; n],
            a: vec![[0.0; 3]; n],
            al: vec![[0.0; 3]; n],
            lambda: vec![0.0; m.n_lambda()],
        }
    }

    /// Rigid rotation about the axis through `center` with angular velocity `omega` (rad/s):
    /// sets v = omega x (x - center), w = omega (accelerations = steady centripetal).
    pub fn set_rigid_rotation(&mut self, center: [f64; 3], omega: [f64; 3]) {
        for i in 0..self.x.len() {
            let r = sub(self.x[i], center);
            self.v[i] = cross(omega, r);
            self.w[i] = omega;
            self.a[i] = cross(omega, cross(omega, r));
            self.al[i] = [0.0; 3];
        }
    }

    pub fn node_kin(&self, i: usize) -> NodeKin<f64> {
        NodeKin {
            x: self.x[i],
            r: quat_to_arr(&self.q[i]),
            v: self.v[i],
            w: self.w[i],
            a: self.a[i],
            al: self.al[i],
        }
    }

    pub fn kin(&self, out: &mut Vec<NodeKin<f64>>) {
        out.clear();
        out.extend((0..self.x.len()).map(|i| self.node_kin(i)));
    }

    pub fn rotation_vector(&self, i: usize) -> [f64; 3] {
        let v = self.q[i].scaled_axis();
        [v[0], v[1], v[2]]
    }
}

/// Column names of all sensors (units in names).
pub fn sensor_header(m: &Model) -> Vec<String> {
    let mut h = vec!["t_s".to_string()];
    for s in &m.sensors {
        let n = &s.name;
        let cols: &[&str] = match s.kind {
            SensorKind::Node(_) => &[
                "x_m", "y_m", "z_m", "rx_rad", "ry_rad", "rz_rad", "vx_m_s", "vy_m_s", "vz_m_s",
                "wx_rad_s", "wy_rad_s", "wz_rad_s",
            ],
            SensorKind::Joint(_) => &[
                "fx_N",
                "fy_N",
                "fz_N",
                "mx_Nm",
                "my_Nm",
                "mz_Nm",
                "angle_rad",
            ],
            SensorKind::Section { .. } => {
                &["s_m", "N1_N", "N2_N", "N3_N", "M1_Nm", "M2_Nm", "M3_Nm"]
            }
        };
        h.extend(cols.iter().map(|c| format!("{n}.{c}")));
    }
    for e in &m.step_elements {
        for (k, _) in e.sensors() {
            h.push(format!("{}.{}", e.name(), k));
        }
    }
    h
}

/// Sensor values in the order of [`sensor_header`].
pub fn sensor_values(m: &Model, st: &State, lam_offsets: &[usize]) -> Vec<f64> {
    let mut out = vec![st.t];
    for s in &m.sensors {
        match &s.kind {
            SensorKind::Node(i) => {
                out.extend(st.x[*i]);
                out.extend(st.rotation_vector(*i));
                out.extend(st.v[*i]);
                out.extend(st.w[*i]);
            }
            SensorKind::Joint(ei) => {
                if let Element::Joint(j) = &m.elements[*ei] {
                    let a = j
                        .node_a
                        .map(|i| st.node_kin(i))
                        .unwrap_or_else(NodeKin::ground);
                    let b = st.node_kin(j.node_b);
                    let nl = j.n_lambda();
                    let lam = &st.lambda[lam_offsets[*ei]..lam_offsets[*ei] + nl];
                    let mut r = [0.0; 24];
                    let ctx = EvalCtx {
                        t: st.t,
                        ..Default::default()
                    };
                    j.residual(&a, &b, lam, &ctx, &mut r);
                    let off = if j.node_a.is_some() { 6 } else { 0 };
                    // force exerted by the joint on node B = -(B^T lambda + spring)
                    for k in 0..6 {
                        out.push(-r[off + k]);
                    }
                    out.push(j.angle(&a, &b));
                }
            }
            SensorKind::Section { elements, s_m } => {
                let mut best = (f64::INFINITY, 0.0, [0.0; 6]);
                for &ei in elements {
                    if let Element::Beam(b) = &m.elements[ei] {
                        let k = b.nodes.map(|i| st.node_kin(i));
                        for (s, f) in Beam::section_forces(b, &k) {
                            if (s - s_m).abs() < best.0 {
                                best = ((s - s_m).abs(), s, f);
                            }
                        }
                    }
                }
                out.push(best.1);
                out.extend(best.2);
            }
        }
    }
    for e in &m.step_elements {
        out.extend(e.sensors().iter().map(|p| p.1));
    }
    out
}

/// Offsets of each element's multipliers in `State::lambda`.
pub fn lambda_offsets(m: &Model) -> Vec<usize> {
    let mut off = 0;
    m.elements
        .iter()
        .map(|e| {
            let o = off;
            off += e.n_lambda();
            o
        })
        .collect()
}
