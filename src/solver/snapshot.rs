//! Saved states of a dynamic simulation: everything the next step depends on besides the
//! model's parameters. A periodic solver restarts revolutions from them (perturbed through
//! [`SolverSnapshot::set_coords`]) and a run writes the periodic one to disk for warm starts.
use super::DynamicSolver;
use crate::structure::joint::Joint;
use crate::structure::kin::NodeKin;
use crate::structure::model::Element;
use crate::structure::rotation::*;
use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

/// Values per node in [`SolverSnapshot::coords`]: position, rotation, velocity, angular
/// velocity, true accelerations (translational, angular), algorithmic accelerations (6).
pub const COORDS_PER_NODE: usize = 24;

/// Weight of the accelerations in the coordinates (`ACC_WEIGHT tau^2 a`): they follow the
/// positions and velocities within a few steps, so a periodic solver's norm should not be
/// dominated by them.
pub const ACC_WEIGHT: f64 = 1e-2;

/// The state of a [`DynamicSolver`] and of its model's stateful elements.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolverSnapshot {
    pub t_s: f64,
    /// Per node: position [m], rotation quaternion (w, i, j, k), velocity [m/s], angular
    /// velocity [rad/s], true accelerations [m/s^2, rad/s^2] (global).
    pub x_m: Vec<[f64; 3]>,
    pub q: Vec<[f64; 4]>,
    pub v_m_s: Vec<[f64; 3]>,
    pub w_rad_s: Vec<[f64; 3]>,
    pub a_m_s2: Vec<[f64; 3]>,
    pub al_rad_s2: Vec<[f64; 3]>,
    /// Generalized-alpha algorithmic accelerations per node (translation, rotation).
    pub acc: Vec<[f64; 6]>,
    /// Physical and scaled Lagrange multipliers.
    pub lambda: Vec<f64>,
    pub lambda_scaled: Vec<f64>,
    /// Predictor history of modified Newton (accelerations and scaled multipliers of the step
    /// before) and its convergence scale (0: none yet).
    pub prev_acc: Vec<[f64; 6]>,
    pub prev_lambda_scaled: Vec<f64>,
    pub residual_scale: f64,
    /// Largest reference residual seen (the force scale of the round-off floor); absent in
    /// older files (then the current step's scale is used).
    #[serde(default)]
    pub force_scale: f64,
    /// Tracked (unwrapped) angle of every joint, None for other elements.
    pub joint_angles_rad: Vec<Option<f64>>,
    /// Committed state of every step element (e.g. a hydraulic device).
    pub step_elements: Vec<Vec<f64>>,
    /// Committed branch moments [N m] of every joint's elastomer, empty for other elements and
    /// joints without one (absent in older files: the elastomers keep their state).
    #[serde(default)]
    pub joint_elastomers_nm: Vec<Vec<f64>>,
}

impl SolverSnapshot {
    /// Number of nodes.
    pub fn nodes(&self) -> usize {
        self.x_m.len()
    }

    /// The perturbable part of the state, per node
    /// `[x, theta, tau v, tau w, tau^2 a, tau^2 al, tau^2 acc]` with `theta = log(R0^T R)` the
    /// rotation from the node's reference orientation `r0[i]`, `acc` the generalized-alpha
    /// algorithmic accelerations and `tau` a time scale [s] that gives velocities and
    /// accelerations the unit of the configuration (e.g. 1/Omega for a rotor). Multipliers,
    /// predictor history and element states are not in it: the multipliers and the predictor
    /// only start Newton iterations, and element states (e.g. hydraulic pressures) are
    /// restored as saved.
    pub fn coords(&self, r0: &[[[f64; 3]; 3]], tau: f64) -> Vec<f64> {
        let mut out = Vec::with_capacity(COORDS_PER_NODE * self.nodes());
        for i in 0..self.nodes() {
            let r = quat_to_arr(&quat(self.q[i]));
            let th = log_map(&mtm(&r0[i], &r));
            out.extend_from_slice(&self.x_m[i]);
            out.extend_from_slice(&th);
            out.extend(self.v_m_s[i].iter().map(|v| tau * v));
            out.extend(self.w_rad_s[i].iter().map(|w| tau * w));
            let t2 = ACC_WEIGHT * tau * tau;
            out.extend(self.a_m_s2[i].iter().map(|a| t2 * a));
            out.extend(self.al_rad_s2[i].iter().map(|a| t2 * a));
            out.extend(self.acc[i].iter().map(|a| t2 * a));
        }
        out
    }

    /// Sets the perturbable part from `c` (layout of [`SolverSnapshot::coords`]).
    pub fn set_coords(&mut self, r0: &[[[f64; 3]; 3]], tau: f64, c: &[f64]) {
        assert_eq!(c.len(), COORDS_PER_NODE * self.nodes(), "coordinate layout");
        for i in 0..self.nodes() {
            let ci = &c[COORDS_PER_NODE * i..COORDS_PER_NODE * (i + 1)];
            self.x_m[i] = [ci[0], ci[1], ci[2]];
            let r = mm(&r0[i], &exp_map([ci[3], ci[4], ci[5]]));
            let q = UnitQuaternion::from_matrix(&nalgebra::Matrix3::from_fn(|a, b| r[a][b]));
            // keep the sign of the quaternion it replaces (the same rotation either way)
            let old = quat(self.q[i]);
            let q = if q.coords.dot(&old.coords) < 0.0 {
                UnitQuaternion::new_unchecked(-q.into_inner())
            } else {
                q
            };
            self.q[i] = [q.w, q.i, q.j, q.k];
            self.v_m_s[i] = [ci[6] / tau, ci[7] / tau, ci[8] / tau];
            self.w_rad_s[i] = [ci[9] / tau, ci[10] / tau, ci[11] / tau];
            let t2 = ACC_WEIGHT * tau * tau;
            self.a_m_s2[i] = [ci[12] / t2, ci[13] / t2, ci[14] / t2];
            self.al_rad_s2[i] = [ci[15] / t2, ci[16] / t2, ci[17] / t2];
            self.acc[i] = std::array::from_fn(|k| ci[18 + k] / t2);
        }
    }
}

fn quat(q: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::new_normalize(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]))
}

impl DynamicSolver {
    /// The current state (see [`SolverSnapshot`]).
    pub fn snapshot(&self) -> SolverSnapshot {
        let st = &self.state;
        let n = st.x.len();
        SolverSnapshot {
            t_s: st.t,
            x_m: st.x.clone(),
            q: st.q.iter().map(|q| [q.w, q.i, q.j, q.k]).collect(),
            v_m_s: st.v.clone(),
            w_rad_s: st.w.clone(),
            a_m_s2: st.a.clone(),
            al_rad_s2: st.al.clone(),
            acc: self.acc.clone(),
            lambda: st.lambda.clone(),
            lambda_scaled: self.lam_hat.clone(),
            prev_acc: if self.prev_vd.len() == n {
                self.prev_vd.clone()
            } else {
                vec![]
            },
            prev_lambda_scaled: self.prev_lam.clone(),
            residual_scale: self.r_ref,
            force_scale: self.r_scale,
            joint_angles_rad: self
                .model
                .elements
                .iter()
                .map(|e| match e {
                    Element::Joint(j) => Some(j.angle_prev),
                    _ => None,
                })
                .collect(),
            step_elements: self
                .model
                .step_elements
                .iter()
                .map(|s| s.state_values())
                .collect(),
            joint_elastomers_nm: self
                .model
                .elements
                .iter()
                .map(|e| match e {
                    Element::Joint(Joint {
                        elastomer: Some(el),
                        ..
                    }) => el.committed.branch_nm.to_vec(),
                    _ => vec![],
                })
                .collect(),
        }
    }

    /// Continue from `s` (a snapshot of this model: same nodes, constraints and elements).
    /// Counters (steps, iterations) and the stored factorization are kept.
    pub fn restore(&mut self, s: &SolverSnapshot) -> Result<(), String> {
        let n = self.state.x.len();
        let sizes = [
            ("nodes", s.x_m.len(), n),
            ("rotations", s.q.len(), n),
            ("velocities", s.v_m_s.len(), n),
            ("angular velocities", s.w_rad_s.len(), n),
            ("accelerations", s.a_m_s2.len(), n),
            ("angular accelerations", s.al_rad_s2.len(), n),
            ("algorithmic accelerations", s.acc.len(), n),
            ("multipliers", s.lambda.len(), self.state.lambda.len()),
            (
                "scaled multipliers",
                s.lambda_scaled.len(),
                self.lam_hat.len(),
            ),
            (
                "elements",
                s.joint_angles_rad.len(),
                self.model.elements.len(),
            ),
            (
                "step elements",
                s.step_elements.len(),
                self.model.step_elements.len(),
            ),
        ];
        for (what, got, want) in sizes {
            if got != want {
                return Err(format!(
                    "saved state has {got} {what}, the model {want} (not a state of this model)"
                ));
            }
        }
        if !s.prev_acc.is_empty() && s.prev_acc.len() != n {
            return Err(format!(
                "saved state has {} predictor accelerations, the model {n} nodes",
                s.prev_acc.len()
            ));
        }
        let finite = s.t_s.is_finite()
            && s.x_m.iter().flatten().all(|v| v.is_finite())
            && s.q.iter().flatten().all(|v| v.is_finite())
            && s.v_m_s
                .iter()
                .chain(&s.w_rad_s)
                .flatten()
                .all(|v| v.is_finite())
            && s.acc.iter().flatten().all(|v| v.is_finite());
        if !finite {
            return Err("saved state has non-finite values".into());
        }
        for (e, a) in self.model.elements.iter_mut().zip(&s.joint_angles_rad) {
            if let Element::Joint(j) = e {
                match a {
                    Some(a) if a.is_finite() => j.angle_prev = *a,
                    _ => return Err(format!("saved state has no angle for joint {}", j.name)),
                }
            }
        }
        let n_el = s.joint_elastomers_nm.len();
        if n_el != 0 && n_el != self.model.elements.len() {
            return Err(format!(
                "saved state has {n_el} elastomer entries, the model {} elements (not a state of this model)",
                self.model.elements.len()
            ));
        }
        for (k, e) in self.model.elements.iter_mut().enumerate() {
            if let Element::Joint(j) = e {
                // the committed angle is set below, from the restored configuration
                if let Some(el) = &mut j.elastomer {
                    if let Some(v) = s.joint_elastomers_nm.get(k) {
                        if v.len() != el.committed.branch_nm.len()
                            || v.iter().any(|x| !x.is_finite())
                        {
                            return Err(format!(
                                "saved state of joint {}'s elastomer: expected {} finite branch moments, got {:?}",
                                j.name,
                                el.committed.branch_nm.len(),
                                v
                            ));
                        }
                        el.committed.branch_nm.copy_from_slice(v);
                    }
                }
            }
        }
        for (e, v) in self.model.step_elements.iter_mut().zip(&s.step_elements) {
            e.set_state_values(v)?;
        }
        let st = &mut self.state;
        st.t = s.t_s;
        st.x.clone_from(&s.x_m);
        st.q = s.q.iter().map(|q| quat(*q)).collect();
        st.v.clone_from(&s.v_m_s);
        st.w.clone_from(&s.w_rad_s);
        st.a.clone_from(&s.a_m_s2);
        st.al.clone_from(&s.al_rad_s2);
        st.lambda.clone_from(&s.lambda);
        self.acc.clone_from(&s.acc);
        self.lam_hat.clone_from(&s.lambda_scaled);
        self.prev_vd.clone_from(&s.prev_acc);
        self.prev_lam.clone_from(&s.prev_lambda_scaled);
        if self.prev_lam.len() != self.lam_hat.len() {
            self.prev_vd.clear();
            self.prev_lam.clear();
        }
        self.r_ref = s.residual_scale;
        self.r_scale = s.force_scale;
        self.state.kin(&mut self.kin);
        // each joint's angle, and its elastomer's committed angle, from the configuration just
        // restored (the snapshot's record only picks the turn): a state whose coordinates were
        // moved (shooting's perturbed and trial states) is at that angle, with the branch
        // moments it carries; with the recorded angle the first step would read the move as
        // a strain of the bearing within one step (`k_i` times it in every branch)
        let kin = &self.kin;
        for e in self.model.elements.iter_mut() {
            if let Element::Joint(j) = e {
                let a = j.node_a.map(|i| kin[i]).unwrap_or_else(NodeKin::ground);
                let psi = j.angle(&a, &kin[j.node_b]);
                j.angle_prev = psi;
                if let Some(el) = &mut j.elastomer {
                    el.committed.angle_rad = psi;
                }
            }
        }
        Ok(())
    }
}
